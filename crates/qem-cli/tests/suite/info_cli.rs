//! `qem info`: exact counts on the shipped mesh, and on every corpus mesh the same
//! counts as the corpus manifest's columns with the same definitions.

use crate::common;

use common::{corpus_dir, qem, s, spot, stderr};
use qem_mesh::io::write_path;
use qem_mesh::IndexedMesh;
use serde_json::Value;

fn info_json(path: &std::path::Path) -> Value {
    let o = qem(&["info", s(path), "--json"]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}: {}",
        path.display(),
        stderr(&o)
    );
    serde_json::from_slice(&o.stdout).expect("info --json prints JSON")
}

#[test]
fn spot_is_one_closed_manifold_part() {
    let j = info_json(&spot());
    assert_eq!(j["vertices"], 2930);
    assert_eq!(j["triangles"], 5856);
    for key in [
        "welded_vertices",
        "unreferenced_vertices",
        "boundary_edges",
        "boundary_loops",
        "nonmanifold_edges",
        "nonmanifold_vertices",
        "duplicate_faces",
        "degenerate_faces",
    ] {
        assert_eq!(j[key], 0, "{key}");
    }
    assert_eq!(j["components"], 1);
    // The manifest gives 2.58809 for the same mesh (c3d_spot).
    assert!((j["bbox_diagonal"].as_f64().unwrap() - 2.58809).abs() < 1e-5);
    assert_eq!(j["bbox_min"].as_array().unwrap().len(), 3);
}

#[test]
fn text_output_names_every_count() {
    let o = qem(&["info", s(&spot())]);
    assert_eq!(o.status.code(), Some(0));
    let text = String::from_utf8(o.stdout).unwrap();
    for label in [
        "vertices",
        "triangles",
        "components",
        "boundary edges",
        "boundary loops",
        "non-manifold edges",
        "non-manifold vertices",
        "duplicate faces",
        "degenerate faces",
        "bbox diagonal",
    ] {
        assert!(
            text.lines().any(|l| l.starts_with(label)),
            "{label}: {text}"
        );
    }
}

#[test]
fn soup_with_a_hole_and_a_fin() {
    // An open box (5 squares, no top) as an STL-like soup, plus a fin: one extra
    // triangle on the bottom edge 0-1.
    let corners = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [1.0, 0.0, 1.0],
        [1.0, 1.0, 1.0],
        [0.0, 1.0, 1.0],
    ];
    let quads = [
        [0, 3, 2, 1],
        [0, 1, 5, 4],
        [1, 2, 6, 5],
        [2, 3, 7, 6],
        [3, 0, 4, 7],
    ];
    let mut positions: Vec<[f64; 3]> = Vec::new();
    let mut triangles = Vec::new();
    let mut tri = |t: [[f64; 3]; 3]| {
        let base = positions.len() as u32;
        positions.extend(t);
        triangles.push([base, base + 1, base + 2]);
    };
    for [a, b, c, d] in quads {
        tri([corners[a], corners[b], corners[c]]);
        tri([corners[a], corners[c], corners[d]]);
    }
    tri([corners[0], corners[1], [0.5, -1.0, 0.5]]);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("box.stl");
    write_path(&path, &IndexedMesh::new(positions, triangles)).unwrap();
    let j = info_json(&path);
    assert_eq!(j["triangles"], 11);
    assert_eq!(j["vertices"], 33);
    assert_eq!(j["welded_vertices"], 24);
    assert_eq!(j["components"], 1);
    // The top rim (4 edges) plus the fin's two free edges.
    assert_eq!(j["boundary_edges"], 6);
    // The rim and the fin's border (0 - apex - 1) share no vertex: two loops.
    assert_eq!(j["boundary_loops"], 2);
    assert_eq!(j["nonmanifold_edges"], 1);
    assert_eq!(j["nonmanifold_vertices"], 0);
}

#[test]
fn unreadable_file_is_one_line_naming_it() {
    let o = qem(&["info", "no/such/mesh.ply"]);
    assert_eq!(o.status.code(), Some(1));
    let e = stderr(&o);
    assert_eq!(e.lines().count(), 1, "{e}");
    assert!(e.starts_with("qem: error: no/such/mesh.ply: "), "{e}");
}

/// Meshes where `degenerate_faces` is below the manifest's count: the manifest flags
/// more near-zero-area faces than the 1e-14 x diagonal² test that qem (and the
/// project's meshcheck) use; the faces with a repeated index agree. Measured:
/// mf_offset1 17 vs 48, stanford_dragon_vrip 111 vs 274.
const LOOSER_MANIFEST_ZERO_AREA: [&str; 2] = ["mf_offset1.obj", "stanford_dragon_vrip.obj"];

#[test]
fn corpus_counts_match_the_manifest() {
    let Some(dir) = corpus_dir() else { return };
    let text = std::fs::read_to_string(dir.join("manifest.tsv")).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split('\t').collect();
    let col = |name: &str| {
        header
            .iter()
            .position(|h| *h == name)
            .unwrap_or_else(|| panic!("manifest has no column {name}"))
    };
    // info key → manifest column, the same definition (after welding bit-identical
    // positions; see `qem info --help`).
    let exact = [
        ("triangles", "triangles"),
        ("components", "components"),
        ("boundary_edges", "boundary_edges"),
        ("nonmanifold_edges", "nonmanifold_edges"),
        ("nonmanifold_vertices", "nonmanifold_vertices"),
        ("duplicate_faces", "duplicate_faces"),
    ];
    let mut mismatches = Vec::new();
    let mut checked = 0;
    for line in lines.filter(|l| !l.trim().is_empty()) {
        let cells: Vec<&str> = line.split('\t').collect();
        let name = cells[col("file")].rsplit('/').next().unwrap();
        let j = info_json(&dir.join(name));
        for (key, column) in exact {
            let want: u64 = cells[col(column)].parse().unwrap();
            if j[key].as_u64() != Some(want) {
                mismatches.push(format!("{name}: {key} {} != manifest {want}", j[key]));
            }
        }
        let diag: f64 = cells[col("bbox_diag")].parse().unwrap();
        let ours = j["bbox_diagonal"].as_f64().unwrap();
        // The manifest rounds to 6 significant digits.
        if (ours - diag).abs() > 1e-5 * diag {
            mismatches.push(format!("{name}: bbox_diagonal {ours} != manifest {diag}"));
        }
        let degenerate: u64 = cells[col("degenerate_faces")].parse().unwrap();
        let ours = j["degenerate_faces"].as_u64().unwrap();
        let known = LOOSER_MANIFEST_ZERO_AREA.contains(&name);
        if (known && ours >= degenerate) || (!known && ours != degenerate) {
            mismatches.push(format!(
                "{name}: degenerate_faces {ours} vs manifest {degenerate}"
            ));
        }
        checked += 1;
    }
    assert!(checked >= 49, "only {checked} corpus meshes");
    assert!(mismatches.is_empty(), "{}", mismatches.join("\n"));
}
