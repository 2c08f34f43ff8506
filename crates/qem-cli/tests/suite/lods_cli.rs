//! `qem simplify --lods`: one run, one file per level, nested counts, a report with
//! every level.

use crate::common;

use common::{json, qem, s, spot, stderr};
use qem_mesh::io::read_path;

#[test]
fn levels_are_written_nested_and_reported() {
    let dir = tempfile::tempdir().unwrap();
    let pattern = dir.path().join("spot_{lod}.obj");
    let report = dir.path().join("lods.json");
    let o = qem(&[
        "simplify",
        s(&spot()),
        "-o",
        s(&pattern),
        "--lods",
        "0.5,0.25,0.125",
        "--report",
        s(&report),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));

    let r = json(&report);
    let levels = r["levels"].as_array().unwrap();
    assert_eq!(levels.len(), 3);
    let mut previous = 5856;
    let mut previous_error = 0.0;
    for (i, (level, ratio)) in levels.iter().zip([0.5, 0.25, 0.125]).enumerate() {
        assert_eq!(level["lod"], i);
        assert_eq!(level["ratio"], ratio);
        let out = dir.path().join(format!("spot_{i}.obj"));
        assert_eq!(level["output"], s(&out));
        let count = read_path(&out).unwrap().mesh.triangle_count();
        assert_eq!(level["triangles_out"], count);
        assert_eq!(level["triangles_in"], 5856);
        assert!(count <= (5856.0 * ratio) as usize, "level {i}: {count}");
        assert!(count < previous, "levels nest: {count} after {previous}");
        assert_eq!(level["stop_reason"], "target_reached");
        let error = level["max_error"].as_f64().unwrap();
        assert!(
            error >= previous_error,
            "the error only grows along the chain"
        );
        previous = count;
        previous_error = error;
    }
    assert_eq!(
        std::fs::read_dir(dir.path()).unwrap().count(),
        6,
        "three levels, the report, and spot's material library and texture beside them"
    );
}

#[test]
fn first_level_equals_a_plain_run() {
    // The chain's first level is the same contraction sequence as a plain run to that
    // target, so the files are identical.
    let dir = tempfile::tempdir().unwrap();
    let o = qem(&[
        "simplify",
        s(&spot()),
        "-o",
        s(&dir.path().join("l{lod}.ply")),
        "--lods",
        "0.3,0.1",
        "-q",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let plain = dir.path().join("plain.ply");
    let o = qem(&[
        "simplify",
        s(&spot()),
        "-o",
        s(&plain),
        "--ratio",
        "0.3",
        "-q",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(std::fs::read(plain).unwrap() == std::fs::read(dir.path().join("l0.ply")).unwrap());
}

#[test]
fn lods_without_placeholder_is_a_usage_error_naming_the_fix() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.obj");
    let o = qem(&["simplify", s(&spot()), "-o", s(&out), "--lods", "0.5,0.25"]);
    assert_eq!(o.status.code(), Some(2));
    let e = stderr(&o);
    assert_eq!(e.lines().count(), 1, "{e}");
    assert!(
        e.contains("out.obj") && e.contains("must contain {lod}"),
        "{e}"
    );
    assert!(e.contains("e.g. -o out_{lod}.obj"), "{e}");
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

#[test]
fn other_lods_mistakes_are_usage_errors() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o_{lod}.obj");
    let spot = spot();
    for (args, needle) in [
        (vec!["--lods", "0.25,0.5"], "must decrease"),
        (vec!["--lods", "0.5,1.5"], "outside (0, 1]"),
        (
            vec!["--lods", "0.5", "--ratio", "0.1"],
            "cannot be used with",
        ),
        (vec![], "--lods is not given"),
    ] {
        let mut all = vec!["simplify", s(&spot), "-o", s(&out)];
        all.extend(args);
        let o = qem(&all);
        assert_eq!(o.status.code(), Some(2), "{all:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(needle), "{all:?}: {}", stderr(&o));
    }
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}
