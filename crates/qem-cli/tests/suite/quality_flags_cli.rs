//! The quality-control flags of `qem simplify` (shared with `qem batch`): locks,
//! borders, topology, quadrics, and how they show in the report.

use crate::common;

use common::{qem, s, spot, stderr};
use qem_mesh::inspect::inspect;
use qem_mesh::io::read_path;

/// Locked vertices come out bit for bit where they were (the PLY output keeps doubles).
#[test]
fn locked_vertices_are_in_the_output_unmoved() {
    let dir = tempfile::tempdir().expect("tempdir");
    let lock = dir.path().join("lock.txt");
    let locked: Vec<usize> = (0..40).map(|i| i * 37).collect();
    let mut text = String::from("# every 37th vertex\n\n");
    for i in &locked {
        text.push_str(&format!("{i}  # a comment after the index\n"));
    }
    std::fs::write(&lock, text).expect("write lock file");
    let out = dir.path().join("out.ply");
    let report = dir.path().join("report.json");
    let o = qem(&[
        "simplify",
        s(&spot()),
        "-o",
        s(&out),
        "--ratio",
        "0.05",
        "--lock",
        s(&lock),
        "--report",
        s(&report),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));

    let input = read_path(&spot()).expect("spot loads").mesh;
    let output = read_path(&out).expect("output loads").mesh;
    for &i in &locked {
        let p = input.positions[i];
        assert!(
            output.positions.iter().any(|q| q == &p),
            "locked vertex {i} at {p:?} is not in the output"
        );
    }
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).expect("report")).expect("json");
    assert_eq!(json["locked_vertices"], locked.len());
    for reason in [
        "degenerate",
        "flip",
        "sliver",
        "topology",
        "locked",
        "border",
        "merge",
    ] {
        assert!(json["rejected"].get(reason).is_some(), "{json}");
    }
}

#[test]
fn a_bad_lock_file_names_the_file_and_line() {
    let dir = tempfile::tempdir().expect("tempdir");
    let lock = dir.path().join("lock.txt");
    std::fs::write(&lock, "3\nseven\n").expect("write lock file");
    let out = dir.path().join("out.obj");
    let o = qem(&["simplify", s(&spot()), "-o", s(&out), "--lock", s(&lock)]);
    assert_eq!(o.status.code(), Some(1));
    let err = stderr(&o);
    assert!(err.contains("lock.txt:2:"), "{err}");
    assert!(err.contains("`seven` is not a vertex index"), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(!out.exists());
}

#[test]
fn a_lock_index_past_the_end_is_an_error() {
    let dir = tempfile::tempdir().expect("tempdir");
    let lock = dir.path().join("lock.txt");
    std::fs::write(&lock, "999999\n").expect("write lock file");
    let out = dir.path().join("out.obj");
    let o = qem(&["simplify", s(&spot()), "-o", s(&out), "--lock", s(&lock)]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("999999"), "{}", stderr(&o));
    assert!(!out.exists());
}

/// The cow is a closed genus-0 surface: with --preserve-topology it stays one closed
/// 2-manifold part with Euler characteristic 2 (V − E + F with E = 3F/2).
#[test]
fn preserve_topology_keeps_the_cow_a_sphere() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("out.ply");
    for quadrics in ["sum", "exact"] {
        let o = qem(&[
            "simplify",
            s(&spot()),
            "-o",
            s(&out),
            "--ratio",
            "0.02",
            "--preserve-topology",
            "--quadrics",
            quadrics,
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        let mesh = read_path(&out).expect("output loads").mesh;
        let info = inspect(&mesh).expect("valid output");
        assert_eq!(info.components, 1);
        assert_eq!(info.boundary_edges, 0);
        assert_eq!(info.nonmanifold_edges, 0);
        assert_eq!(info.nonmanifold_vertices, 0);
        // The PLY holds spot's texture coordinates per vertex, so vertices on a seam
        // are written once per side: count positions (the welded vertices).
        let positions = info.vertices - info.welded_vertices;
        assert_eq!(
            2 * positions as i64 - info.triangles as i64,
            4,
            "Euler characteristic changed: {info:?}"
        );
    }
}

#[test]
fn lock_boundary_and_a_boundary_weight_conflict() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("out.obj");
    let o = qem(&[
        "simplify",
        s(&spot()),
        "-o",
        s(&out),
        "--lock-boundary",
        "--boundary-weight",
        "2",
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
}

#[test]
fn help_lists_the_quality_flags_with_defaults() {
    let o = qem(&["simplify", "--help"]);
    assert!(o.status.success());
    let help = String::from_utf8_lossy(&o.stdout);
    for flag in [
        "--boundary-weight",
        "--lock-boundary",
        "--max-normal-angle",
        "--min-quality",
        "--preserve-topology",
        "--quadrics",
        "--lock <FILE>",
        "--virtual-pairs",
        "--weighting",
    ] {
        assert!(help.contains(flag), "--help lacks {flag}");
    }
    assert!(help.contains("[default: 90]"), "{help}");
}

/// 30 separate tetrahedra as an OBJ: stuck without the ladder of relaxations.
fn tetrahedra_obj(path: &std::path::Path) {
    let mut text = String::new();
    for i in 0..30 {
        let (x, e) = (3.0 * f64::from(i), 1.0 + 0.01 * f64::from(i));
        text += &format!("v {x} 0 0\nv {} 0 0\nv {x} {e} 0\nv {x} 0 {e}\n", x + e);
        let v = 4 * i + 1;
        let (a, b, c, d) = (v, v + 1, v + 2, v + 3);
        text += &format!("f {a} {c} {b}\nf {a} {b} {d}\nf {a} {d} {c}\nf {b} {c} {d}\n");
    }
    std::fs::write(path, text).expect("writes");
}

/// A stuck run climbs the ladder and says so in its report and its summary line;
/// `--strict` stops where the checks do and names itself as what stopped the run.
#[test]
fn strict_and_the_ladder_show_in_the_report() {
    let dir = tempfile::tempdir().expect("tempdir");
    let (input, out, report) = (
        dir.path().join("tets.obj"),
        dir.path().join("out.obj"),
        dir.path().join("r.json"),
    );
    tetrahedra_obj(&input);
    let run = |extra: &[&str]| {
        let mut args = vec!["simplify", s(&input), "-o", s(&out), "--ratio", "0.1"];
        args.extend_from_slice(&["--report", s(&report)]);
        args.extend_from_slice(extra);
        let o = qem(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        (common::json(&report), stderr(&o))
    };
    let (j, line) = run(&[]);
    assert_eq!(j["stop_reason"], "target_reached");
    assert_eq!(j["triangles_out"], 12);
    assert!(j["stopped_by"].is_null());
    let steps: Vec<&str> = j["relaxations"]
        .as_array()
        .expect("a list")
        .iter()
        .map(|r| r["step"].as_str().expect("a name"))
        .collect();
    assert_eq!(steps, ["fold_over", "border_loops", "merged_faces"]);
    assert_eq!(j["relaxations"][2]["contractions"], 27);
    assert!(
        line.contains("relaxed: fold_over 0, border_loops 0, merged_faces 27"),
        "{line}"
    );
    let (j, line) = run(&["--strict"]);
    assert_eq!(j["stop_reason"], "no_valid_pair");
    assert_eq!(j["stopped_by"], "strict");
    assert_eq!(j["triangles_out"], 120);
    assert_eq!(j["relaxations"].as_array().map(Vec::len), Some(0));
    assert!(line.contains("(no_valid_pair: strict)"), "{line}");
}

/// `--cluster` clusters (the report says no contraction was made, the count is near
/// the target and the output is a valid mesh), `--order` picks the order, and the
/// contraction-only flags are usage errors with `--cluster`.
#[test]
fn cluster_and_order_flags() {
    let dir = tempfile::tempdir().expect("tempdir");
    let (out, report) = (dir.path().join("out.obj"), dir.path().join("r.json"));
    let input = spot();
    let run = |extra: &[&str]| {
        let mut args = vec!["simplify", s(&input), "-o", s(&out), "--ratio", "0.1"];
        args.extend_from_slice(&["--report", s(&report), "-q"]);
        args.extend_from_slice(extra);
        qem(&args)
    };
    let o = run(&["--cluster"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let j = common::json(&report);
    assert_eq!(j["edge_contractions"], 0);
    let (got, target) = (
        j["triangles_out"].as_u64().expect("a count"),
        j["target_triangles"].as_u64().expect("a count"),
    );
    assert!(got.abs_diff(target) * 20 <= target, "{got} for {target}");
    let mesh = read_path(&out).expect("the output reads back").mesh;
    assert_eq!(mesh.triangle_count() as u64, got);
    assert!(mesh.validate().is_ok());

    for flag in [
        "--preserve-topology",
        "--fast",
        "--lock-boundary",
        "--strict",
    ] {
        let o = run(&["--cluster", flag]);
        assert_eq!(o.status.code(), Some(2), "{flag}: {}", stderr(&o));
    }
    let o = run(&["--cluster", "--max-error", "0.01"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));

    for order in ["greedy", "passes"] {
        let o = run(&["--order", order]);
        assert!(o.status.success(), "{order}: {}", stderr(&o));
        assert_eq!(common::json(&report)["stop_reason"], "target_reached");
    }
    let o = run(&["--order", "sideways"]);
    assert_eq!(o.status.code(), Some(2));
}
