//! Turning `qem batch`'s INPUT arguments into a sorted list of files, each with the
//! path its output keeps under `--out-dir`.
//!
//! - A file is an input whatever its extension (an unsupported one then fails with a
//!   message that lists the supported extensions); its output keeps its file name.
//! - A directory is walked recursively (symbolic links followed, loops refused) and
//!   every file with a supported extension (`.obj .ply .stl .off .gltf
//!   .glb`, optionally `.gz`) is an input; other files (materials, textures, notes) are listed as ignored. The
//!   output keeps the path relative to the directory. The output directory itself is
//!   never walked, so a second run does not take the first run's outputs as inputs.
//! - Anything else containing `*`, `?` or `[` is a glob pattern (`**` for any depth);
//!   every match is an input as above, and the output keeps the path relative to the
//!   pattern's leading directories without wildcards (`meshes/**/*.ply` → relative to
//!   `meshes`).
//! - An argument that is none of these (a missing file, a pattern that matches
//!   nothing), or a directory without a single mesh file, is a failed input of its own.

use qem_mesh::io::Format;
use std::path::{Component, Path, PathBuf};
use walkdir::WalkDir;

/// One file to simplify.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub struct Input {
    /// The file, as found (the argument, or joined onto it).
    pub path: PathBuf,
    /// Where its output goes under the output directory, before the extension change.
    pub relative: PathBuf,
}

/// What the arguments expanded to.
#[derive(Debug, Default)]
pub struct Expanded {
    /// Files to simplify, sorted by path, without repeats.
    pub inputs: Vec<Input>,
    /// Arguments (or walked entries) that could not be used, with the cause.
    pub failures: Vec<(String, String)>,
    /// Files in walked directories whose extension is not a mesh format, sorted.
    pub ignored: Vec<PathBuf>,
}

/// Expands `args` (see the module docs); `out_dir` is never walked into.
pub fn expand(args: &[PathBuf], out_dir: &Path) -> Expanded {
    let out_canonical = out_dir.canonicalize().ok();
    let mut found = Expanded::default();
    for arg in args {
        if arg.is_dir() && arg.canonicalize().ok() == out_canonical {
            found.failures.push((
                arg.display().to_string(),
                "is the output directory; its outputs would overwrite the inputs, \
                 choose another --out-dir"
                    .to_string(),
            ));
        } else if arg.is_dir() {
            let before = found.inputs.len();
            walk(arg, arg, out_canonical.as_deref(), &mut found);
            if found.inputs.len() == before {
                found.failures.push((
                    arg.display().to_string(),
                    format!(
                        "no mesh file in this directory (looked for {})",
                        qem_mesh::io::SUPPORTED_EXTENSIONS
                    ),
                ));
            }
        } else if arg.exists() {
            let relative = arg
                .file_name()
                .map(PathBuf::from)
                .unwrap_or_else(|| arg.clone());
            found.inputs.push(Input {
                path: arg.clone(),
                relative,
            });
        } else if let Some(pattern) = arg.to_str().filter(|s| is_pattern(s)) {
            expand_pattern(pattern, out_canonical.as_deref(), &mut found);
        } else {
            found.failures.push((
                arg.display().to_string(),
                "no such file or directory; check the path (globs need *, ? or [ ])".to_string(),
            ));
        }
    }
    found.inputs.sort();
    found.inputs.dedup();
    found.failures.sort();
    found.ignored.sort();
    found.ignored.dedup();
    found
}

fn is_pattern(s: &str) -> bool {
    s.contains(['*', '?', '['])
}

fn expand_pattern(pattern: &str, out_dir: Option<&Path>, found: &mut Expanded) {
    let paths = match glob::glob(pattern) {
        Ok(paths) => paths,
        Err(e) => {
            found.failures.push((
                pattern.to_string(),
                format!("not a valid glob pattern: {e}"),
            ));
            return;
        }
    };
    let base = literal_prefix(Path::new(pattern));
    let mut matched = false;
    for entry in paths {
        matched = true;
        match entry {
            Ok(path) if path.is_dir() => walk(&path, &base, out_dir, found),
            Ok(path) => {
                let relative = path.strip_prefix(&base).unwrap_or(&path).to_path_buf();
                found.inputs.push(Input { path, relative });
            }
            Err(e) => found
                .failures
                .push((e.path().display().to_string(), e.error().to_string())),
        }
    }
    if !matched {
        found.failures.push((
            pattern.to_string(),
            "the pattern matches no file; check the path and the quoting".to_string(),
        ));
    }
}

/// The leading components of a glob pattern that contain no wildcard.
fn literal_prefix(pattern: &Path) -> PathBuf {
    let mut base = PathBuf::new();
    for c in pattern.components() {
        if let Component::Normal(s) = c {
            if s.to_str().is_some_and(is_pattern) {
                break;
            }
        }
        base.push(c);
    }
    // The last literal component of `dir/file.obj` would be the file itself; a pattern
    // always has a wildcard, so the prefix stops before it.
    base
}

/// Adds every mesh file under `dir`, relative to `base`.
fn walk(dir: &Path, base: &Path, out_dir: Option<&Path>, found: &mut Expanded) {
    let walker = WalkDir::new(dir)
        .follow_links(true)
        .sort_by_file_name()
        .into_iter()
        .filter_entry(|e| {
            !(e.file_type().is_dir()
                && out_dir.is_some_and(|o| e.path().canonicalize().is_ok_and(|c| c == o)))
        });
    for entry in walker {
        match entry {
            Ok(e) if e.file_type().is_file() => {
                let path = e.into_path();
                if Format::from_path(&path).is_ok() {
                    let relative = path.strip_prefix(base).unwrap_or(&path).to_path_buf();
                    found.inputs.push(Input { path, relative });
                } else {
                    found.ignored.push(path);
                }
            }
            Ok(_) => {}
            Err(e) => {
                let at = e
                    .path()
                    .map(|p| p.display().to_string())
                    .unwrap_or_else(|| dir.display().to_string());
                let cause = match e.io_error() {
                    Some(io) => format!("cannot read: {io}"),
                    None => e.to_string(),
                };
                found.failures.push((at, cause));
            }
        }
    }
}

/// The output file for `input` under `out_dir`: the relative path with its extension
/// (and a trailing `.gz`) replaced by `format`'s, or by the input's own format when
/// `format` is `None`. `None` when the input's extension is not a format qem reads:
/// such an input fails without claiming an output name another input may need.
pub fn output_path(input: &Input, out_dir: &Path, format: Option<Format>) -> Option<PathBuf> {
    let own = Format::from_path(&input.path).ok()?;
    let format = format.unwrap_or(own);
    let name = input.relative.file_name()?.to_string_lossy().into_owned();
    let stem = name
        .len()
        .checked_sub(3)
        .filter(|&cut| name.is_char_boundary(cut) && name[cut..].eq_ignore_ascii_case(".gz"))
        .map_or(name.as_str(), |cut| &name[..cut]);
    let stem = Path::new(stem)
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let file = format!("{stem}.{}", format.extension());
    Some(out_dir.join(input.relative.with_file_name(file)))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn input(path: &str, relative: &str) -> Input {
        Input {
            path: PathBuf::from(path),
            relative: PathBuf::from(relative),
        }
    }

    #[test]
    fn outputs_keep_the_relative_path_and_change_the_extension() {
        let out = Path::new("out");
        let i = input("in/sub/a.PLY.gz", "sub/a.PLY.gz");
        assert_eq!(
            output_path(&i, out, None),
            Some(PathBuf::from("out/sub/a.ply"))
        );
        assert_eq!(
            output_path(&i, out, Some(Format::Obj)),
            Some(PathBuf::from("out/sub/a.obj"))
        );
        let i = input("x/b.stl", "b.stl");
        assert_eq!(output_path(&i, out, None), Some(PathBuf::from("out/b.stl")));
        assert_eq!(output_path(&input("n.txt", "n.txt"), out, None), None);
        assert_eq!(
            output_path(&input("n.txt", "n.txt"), out, Some(Format::Obj)),
            None
        );
    }

    #[test]
    fn pattern_prefix_stops_at_the_first_wildcard() {
        assert_eq!(
            literal_prefix(Path::new("meshes/**/*.ply")),
            PathBuf::from("meshes")
        );
        assert_eq!(literal_prefix(Path::new("*.obj")), PathBuf::new());
        assert_eq!(
            literal_prefix(Path::new("/a/b[12]/c.obj")),
            PathBuf::from("/a")
        );
    }
}
