//! Linker arguments for an extension module that does not link libpython (see
//! `.cargo/config.toml`): on macOS the linker must be told that Python's symbols come
//! from the process that loads the module; elsewhere this adds nothing.

fn main() {
    pyo3_build_config::add_extension_module_link_args();
}
