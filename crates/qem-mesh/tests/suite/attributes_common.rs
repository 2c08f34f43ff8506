//! Helpers of the attribute I/O tests (PLY, OFF, glTF): load, encode, expect an error.

use qem_mesh::io::{read_bytes, write_to, Format, LoadedMesh};
use qem_mesh::IndexedMesh;

/// `bytes` read in `format`; panics with the reader's message when refused.
pub fn load(bytes: &[u8], format: Format) -> LoadedMesh {
    read_bytes(bytes, format).unwrap_or_else(|e| panic!("{format:?} refused: {e}"))
}

/// `mesh` written in `format`.
pub fn encode(mesh: &IndexedMesh, format: Format) -> Vec<u8> {
    let mut out = Vec::new();
    write_to(&mut out, mesh, format).unwrap_or_else(|e| panic!("{format:?} not written: {e}"));
    out
}

/// The reader's message for `bytes`, which must be refused.
pub fn err(bytes: &[u8], format: Format) -> String {
    match read_bytes(bytes, format) {
        Ok(m) => panic!(
            "expected an error, loaded {} triangles",
            m.mesh.triangle_count()
        ),
        Err(e) => e.to_string(),
    }
}
