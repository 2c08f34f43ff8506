//! The files an OBJ output's material libraries name (the `.mtl` files, and the
//! textures those use), copied from beside the input to beside the output, so that the
//! output opens with its materials wherever it was written.
//!
//! Why copy rather than point back: an OBJ names its libraries relative to itself, and
//! a viewer looks for them (and for their textures) beside the file it opens. A
//! simplified copy written to another directory would open grey.
//!
//! Nothing the user has is overwritten: a file of that name already beside the output
//! (or one that appears while the copy is made) is kept, and reported when it differs.
//! Names that would leave the output's directory (absolute, or with `..`) are not
//! followed, nor links beside the input to files outside its directory. A file that
//! cannot be copied is a note in the report, never a failed run: the mesh itself was
//! written. Texture names may hold spaces; `\` between directories (Windows
//! exporters) is read as `/`; names must be UTF-8 text.

use qem_mesh::io::{directory_of, write_new_atomically};
use serde::Serialize;
use std::collections::BTreeSet;
use std::path::{Component, Path};

/// At most this much of a material library is read for the textures it names (a
/// library is a few kilobytes of text; a larger file is copied but not searched).
const MAX_LIBRARY_BYTES: u64 = 16 << 20;

/// The statements of a material library whose last word names a texture file
/// (Wavefront's MTL, with the common extensions for normal and PBR maps).
const TEXTURE_STATEMENTS: [&str; 16] = [
    "map_ka", "map_kd", "map_ks", "map_ns", "map_d", "map_bump", "bump", "disp", "decal", "refl",
    "norm", "map_pr", "map_pm", "map_ps", "map_ke", "map_tr",
];

/// What the copy did, for the report: the files copied beside the output, those that
/// were there already with the same bytes, and those not copied with the reason
/// (names relative to the output's directory, as the output names them).
#[derive(Serialize, Debug, Clone, Default)]
pub struct MaterialFilesJson {
    copied: Vec<String>,
    already_there: Vec<String>,
    not_copied: Vec<NotCopiedJson>,
}

/// A file the output's materials name that was not copied, and why.
#[derive(Serialize, Debug, Clone)]
pub struct NotCopiedJson {
    file: String,
    reason: String,
}

impl MaterialFilesJson {
    /// `material files copied beside the output: spot.mtl, spot.png`, with those not
    /// copied and why; `None` when there was nothing to copy.
    pub fn summary(&self) -> Option<String> {
        let mut parts = Vec::new();
        if !self.copied.is_empty() {
            parts.push(format!(
                "material files copied beside the output: {}",
                self.copied.join(", ")
            ));
        }
        if !self.not_copied.is_empty() {
            let why: Vec<String> = self
                .not_copied
                .iter()
                .map(|n| format!("{} ({})", n.file, n.reason))
                .collect();
            parts.push(format!("material files not copied: {}", why.join(", ")));
        }
        (!parts.is_empty()).then(|| parts.join("; "))
    }

    fn not_copied(&mut self, file: &str, reason: &str) {
        self.not_copied.push(NotCopiedJson {
            file: file.to_string(),
            reason: reason.to_string(),
        });
    }
}

/// Copies the material libraries `libraries` (as an OBJ's `mtllib` lines name them,
/// relative to `input`'s directory) and the textures they name to beside `output`.
/// Nothing to do when both files are in one directory.
pub fn copy_beside(input: &Path, output: &Path, libraries: &[Vec<u8>]) -> MaterialFilesJson {
    let mut json = MaterialFilesJson::default();
    let (from, to) = (directory_of(input), directory_of(output));
    if libraries.is_empty() || same_directory(&from, &to) {
        return json;
    }
    let mut done = BTreeSet::new();
    for line in libraries {
        let Ok(line) = std::str::from_utf8(line) else {
            json.not_copied(&String::from_utf8_lossy(line), "the name is not UTF-8 text");
            continue;
        };
        // One `mtllib` line may name several libraries, separated by spaces; a single
        // name with spaces in it is taken whole when such a file exists.
        let names: Vec<&str> = if from.join(line).is_file() {
            vec![line]
        } else {
            line.split_ascii_whitespace().collect()
        };
        for name in names {
            if !done.insert(name.to_string()) {
                continue;
            }
            if copy_one(&from, &to, name, &mut json) {
                for texture in textures_of(&from.join(name)) {
                    let texture = relative_to_library(name, &texture);
                    if done.insert(texture.clone()) {
                        copy_one(&from, &to, &texture, &mut json);
                    }
                }
            }
        }
    }
    json
}

/// Whether two directory names are one directory.
fn same_directory(a: &Path, b: &Path) -> bool {
    match (a.canonicalize(), b.canonicalize()) {
        (Ok(a), Ok(b)) => a == b,
        _ => a == b,
    }
}

/// A texture's name as the output's directory sees it: textures are named relative to
/// their library, which may itself be in a subdirectory.
fn relative_to_library(library: &str, texture: &str) -> String {
    match Path::new(library).parent() {
        Some(dir) if !dir.as_os_str().is_empty() => dir.join(texture).display().to_string(),
        _ => texture.to_string(),
    }
}

/// Copies `name` from `from` to `to`; whether the file beside the output is the
/// input's (copied, or there already with the same bytes), so that what it names
/// should follow it.
fn copy_one(from: &Path, to: &Path, name: &str, json: &mut MaterialFilesJson) -> bool {
    let relative = Path::new(name);
    let stays_inside = !name.is_empty()
        && relative
            .components()
            .all(|c| matches!(c, Component::Normal(_) | Component::CurDir));
    if !stays_inside {
        json.not_copied(name, "the name leaves the output's directory");
        return false;
    }
    let (source, target) = (from.join(relative), to.join(relative));
    if !source.is_file() {
        json.not_copied(name, "not found beside the input");
        return false;
    }
    // A link beside the input may point anywhere (a key, another user's file); only
    // what really lies below the input's directory is copied.
    let inside = match (from.canonicalize(), source.canonicalize()) {
        (Ok(root), Ok(real)) => real.starts_with(root),
        _ => false,
    };
    if !inside {
        json.not_copied(name, "it links to a file outside the input's directory");
        return false;
    }
    let mut file = match std::fs::File::open(&source) {
        Ok(file) => file,
        Err(e) => {
            json.not_copied(name, &format!("cannot read it: {e}"));
            return false;
        }
    };
    // (A dangling link is something there too: it is the user's, and kept.)
    if std::fs::symlink_metadata(&target).is_ok() {
        return kept_or_same(&source, &target, name, json);
    }
    if let Some(dir) = target.parent() {
        if let Err(e) = std::fs::create_dir_all(dir) {
            json.not_copied(name, &format!("cannot create its directory: {e}"));
            return false;
        }
    }
    // Published only if nothing took the name meanwhile (another job of a batch
    // copying a texture of the same name, say).
    match write_new_atomically(&target, |out| std::io::copy(&mut file, out).map(|_| ())) {
        Ok(true) => {
            json.copied.push(name.to_string());
            true
        }
        Ok(false) => kept_or_same(&source, &target, name, json),
        Err(e) => {
            json.not_copied(name, &e.to_string());
            false
        }
    }
}

/// For a file already beside the output: `already_there` when it has the input's
/// bytes (true), `not_copied` when it differs (false: what the input's file names is
/// not followed either, since the file there may name other things).
fn kept_or_same(source: &Path, target: &Path, name: &str, json: &mut MaterialFilesJson) -> bool {
    if same_bytes(source, target) {
        json.already_there.push(name.to_string());
        true
    } else {
        json.not_copied(
            name,
            "a different file of that name is beside the output; kept it",
        );
        false
    }
}

/// Whether two files hold the same bytes (false when either cannot be read), compared
/// a block at a time.
fn same_bytes(a: &Path, b: &Path) -> bool {
    use std::io::Read;
    let size = |p: &Path| std::fs::metadata(p).map(|m| m.len()).ok();
    if size(a).is_none() || size(a) != size(b) {
        return false;
    }
    let (Ok(a), Ok(b)) = (std::fs::File::open(a), std::fs::File::open(b)) else {
        return false;
    };
    let (mut a, mut b) = (std::io::BufReader::new(a), std::io::BufReader::new(b));
    let (mut x, mut y) = (vec![0u8; 1 << 16], vec![0u8; 1 << 16]);
    loop {
        let Ok(n) = a.read(&mut x) else {
            return false;
        };
        if n == 0 {
            return b.read(&mut y[..1]).is_ok_and(|m| m == 0);
        }
        if b.read_exact(&mut y[..n]).is_err() || x[..n] != y[..n] {
            return false;
        }
    }
}

/// The texture files a material library names (what follows each texture statement's
/// options, spaces included), in order, each once; Windows' `\` between directories
/// read as `/`.
fn textures_of(library: &Path) -> Vec<String> {
    let Ok(meta) = std::fs::metadata(library) else {
        return Vec::new();
    };
    if meta.len() > MAX_LIBRARY_BYTES {
        return Vec::new();
    }
    let Ok(bytes) = std::fs::read(library) else {
        return Vec::new();
    };
    let text = String::from_utf8_lossy(&bytes);
    let mut names: Vec<String> = Vec::new();
    for line in text.lines() {
        let Some(file) = texture_of(line) else {
            continue;
        };
        let file = file.replace('\\', "/");
        if !names.contains(&file) {
            names.push(file);
        }
    }
    names
}

/// The file a texture statement names: the rest of the line after the statement and
/// its options (MTL's `-o u v w`, `-bm 0.5`, `-clamp on`...), trimmed; `None` for any
/// other line.
fn texture_of(line: &str) -> Option<&str> {
    let line = line.trim();
    let (statement, mut rest) = line.split_once(|c: char| c.is_ascii_whitespace())?;
    if !TEXTURE_STATEMENTS.contains(&statement.to_ascii_lowercase().as_str()) {
        return None;
    }
    loop {
        rest = rest.trim_start();
        let (word, after) = rest
            .split_once(|c: char| c.is_ascii_whitespace())
            .unwrap_or((rest, ""));
        // Options and how many values follow each (`-o`, `-s` and `-t` take one to
        // three numbers).
        let values = match word {
            "-blendu" | "-blendv" | "-bm" | "-boost" | "-cc" | "-clamp" | "-imfchan"
            | "-texres" | "-type" => 1..=1,
            "-mm" => 2..=2,
            "-o" | "-s" | "-t" => 1..=3,
            _ => break,
        };
        rest = after;
        for taken in 1..=*values.end() {
            rest = rest.trim_start();
            let (value, after) = rest
                .split_once(|c: char| c.is_ascii_whitespace())
                .unwrap_or((rest, ""));
            if taken > *values.start() && value.parse::<f64>().is_err() {
                break;
            }
            rest = after;
        }
    }
    let file = rest.trim();
    (!file.is_empty()).then_some(file)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn texture_statements_give_the_file_after_their_options() {
        let dir = tempfile::tempdir().unwrap();
        let mtl = dir.path().join("m.mtl");
        std::fs::write(
            &mtl,
            "newmtl a\nKd 1 1 1\nmap_Kd -s 1 1 1 tex/a.png\nbump b.png\nmap_kd tex/a.png\n\
             # map_Kd commented.png\nnewmtl b\nmap_Bump -bm 0.5 n.png\n",
        )
        .unwrap();
        assert_eq!(textures_of(&mtl), ["tex/a.png", "b.png", "n.png"]);
    }

    #[test]
    fn texture_names_keep_their_spaces_and_lose_windows_separators() {
        for (line, name) in [
            ("map_Kd my texture.png", Some("my texture.png")),
            (
                "map_Kd -o 0.5 0.5 -s 2 2 2 wood grain.jpg",
                Some("wood grain.jpg"),
            ),
            ("map_Kd -o 1 tex.png", Some("tex.png")),
            ("map_Kd -mm 0 1 -clamp on a.png", Some("a.png")),
            (
                "  map_bump -bm 0.3   textures\\n.png ",
                Some("textures\\n.png"),
            ),
            ("Kd 1 1 1", None),
            ("map_Kd", None),
            ("map_Kd -clamp on", None),
        ] {
            assert_eq!(texture_of(line), name, "{line}");
        }
        let dir = tempfile::tempdir().unwrap();
        let mtl = dir.path().join("m.mtl");
        std::fs::write(&mtl, "map_Kd textures\\wood.jpg\n").unwrap();
        assert_eq!(textures_of(&mtl), ["textures/wood.jpg"]);
    }

    #[test]
    fn names_that_leave_the_directory_are_not_followed() {
        let (from, to) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
        let mut json = MaterialFilesJson::default();
        for name in ["../x.mtl", "/etc/passwd", ""] {
            assert!(!copy_one(from.path(), to.path(), name, &mut json));
        }
        assert_eq!(json.not_copied.len(), 3);
        assert!(json.copied.is_empty());
    }
}
