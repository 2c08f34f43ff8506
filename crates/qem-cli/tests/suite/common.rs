//! Helpers shared by the CLI tests: run the built binary, find the shipped mesh and the
//! corpus, make small procedural meshes.
#![allow(dead_code)]

use qem_mesh::IndexedMesh;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Runs the built `qem` with `args`.
pub fn qem(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_qem"))
        .args(args)
        .output()
        .expect("qem runs")
}

/// The shipped cow, `assets/spot.obj` (5,856 triangles).
pub fn spot() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/spot.obj")
}

/// Runs `qem simplify assets/spot.obj -o out --ratio ratio` with `extra` arguments.
pub fn simplify_spot(out: &Path, ratio: &str, extra: &[&str]) -> Output {
    let spot = spot();
    let mut args = vec!["simplify", s(&spot), "-o", s(out), "--ratio", ratio];
    args.extend_from_slice(extra);
    qem(&args)
}

/// stderr as text.
pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// stdout as text.
pub fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// A path as `&str` (the temporary directories used here are UTF-8).
pub fn s(p: &Path) -> &str {
    p.to_str().expect("UTF-8 path")
}

/// Reads a JSON file.
pub fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).expect("read JSON")).expect("JSON")
}

/// The shared real-mesh corpus: `$QEM_CORPUS`, or `../shared/corpus` beside the
/// workspace; `None` (with a SKIPPED message) when it is absent.
pub fn corpus_dir() -> Option<PathBuf> {
    let dir = match std::env::var_os("QEM_CORPUS") {
        Some(d) => PathBuf::from(d),
        None => Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/corpus"),
    };
    if dir.join("manifest.tsv").is_file() {
        Some(dir)
    } else {
        eprintln!(
            "SKIPPED: no corpus at {} (set QEM_CORPUS to the directory holding manifest.tsv)",
            dir.display()
        );
        None
    }
}

/// An `n` x `n` grid of quads (2 n² triangles) over a bumpy height field; `seed`
/// changes the bumps so meshes differ.
pub fn bumpy_grid(n: u32, seed: u32) -> IndexedMesh {
    let mut positions = Vec::new();
    for y in 0..=n {
        for x in 0..=n {
            let (fx, fy) = (x as f64 / n as f64, y as f64 / n as f64);
            let z = 0.1 * ((fx * (3 + seed) as f64).sin() * (fy * (2 + seed) as f64).cos());
            positions.push([fx, fy, z]);
        }
    }
    let mut triangles = Vec::new();
    let row = n + 1;
    for y in 0..n {
        for x in 0..n {
            let v = y * row + x;
            triangles.push([v, v + 1, v + row]);
            triangles.push([v + 1, v + row + 1, v + row]);
        }
    }
    IndexedMesh::new(positions, triangles)
}
