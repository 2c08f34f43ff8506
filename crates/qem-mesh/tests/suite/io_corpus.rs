//! Loads every mesh of the shared real-mesh corpus and compares triangle counts with
//! its `manifest.tsv`. The corpus is not part of the repository: set `QEM_CORPUS` to
//! its directory, or keep it at `../shared/corpus` beside the checkout; the tests skip
//! with a message when it is absent.
#![cfg(feature = "io")]
#![allow(clippy::unwrap_used)]

use crate::common;

use common::corpus_dir;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

use qem_mesh::io::{read_path, IoError, ReadErrorKind};

/// File name (without directories) → expected triangle count, for both the converted
/// OBJ (`file`) and the original (`original_file`).
fn manifest(dir: &Path) -> HashMap<String, usize> {
    let text = std::fs::read_to_string(dir.join("manifest.tsv")).expect("read manifest.tsv");
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().expect("manifest header").split('\t').collect();
    let col = |name: &str| {
        header
            .iter()
            .position(|h| *h == name)
            .unwrap_or_else(|| panic!("manifest has no column {name}"))
    };
    let (file, tris, orig) = (col("file"), col("triangles"), col("original_file"));
    let base = |p: &str| p.rsplit('/').next().unwrap_or(p).to_string();
    let mut map = HashMap::new();
    for line in lines.filter(|l| !l.trim().is_empty()) {
        let cells: Vec<&str> = line.split('\t').collect();
        let n: usize = cells[tris].parse().expect("triangle count");
        map.insert(base(cells[file]), n);
        map.insert(base(cells[orig]), n);
    }
    map
}

fn check_dir(dir: &Path, only_obj: bool, expected: &HashMap<String, usize>) -> usize {
    let mut checked = 0;
    let mut failures = Vec::new();
    let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)
        .expect("read corpus dir")
        .map(|e| e.expect("dir entry").path())
        .filter(|p| p.is_file())
        .collect();
    entries.sort();
    for path in entries {
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        if name == "manifest.tsv" || name == "README.md" {
            continue;
        }
        if only_obj && !name.ends_with(".obj") {
            continue;
        }
        let want = *expected
            .get(&name)
            .unwrap_or_else(|| panic!("{name} is not in manifest.tsv"));
        if name.ends_with(".js") {
            // npm_bunny.js is JavaScript source, not a mesh file.
            match read_path(&path) {
                Err(IoError::Read { source, .. })
                    if matches!(source.kind(), ReadErrorKind::UnsupportedExtension { .. }) =>
                {
                    let msg = source.to_string();
                    assert!(msg.contains("\".js\""), "{msg}");
                    assert!(msg.contains(".obj, .ply, .stl, .off"), "{msg}");
                }
                other => failures.push(format!(
                    "{name}: expected unsupported extension, got {other:?}"
                )),
            }
            continue;
        }
        match read_path(&path) {
            Ok(loaded) => {
                let got = loaded.mesh.triangle_count();
                if got != want {
                    failures.push(format!("{name}: {got} triangles, manifest says {want}"));
                }
                checked += 1;
            }
            Err(e) => failures.push(format!("{e}")),
        }
    }
    assert!(
        failures.is_empty(),
        "corpus mismatches:\n{}",
        failures.join("\n")
    );
    checked
}

#[test]
fn corpus_originals_load_with_manifest_triangle_counts() {
    let Some(dir) = corpus_dir() else { return };
    let expected = manifest(&dir);
    let n = check_dir(&dir.join("originals"), false, &expected);
    eprintln!("checked {n} originals");
    assert!(n >= 40, "only {n} originals found");
}

#[test]
fn corpus_objs_load_with_manifest_triangle_counts() {
    let Some(dir) = corpus_dir() else { return };
    let expected = manifest(&dir);
    let n = check_dir(&dir, true, &expected);
    eprintln!("checked {n} OBJ files");
    assert!(n >= 40, "only {n} OBJ files found");
}
