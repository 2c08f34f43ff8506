//! Runs the built `qem` binary as a user would.

use crate::common;

use common::{qem, spot, stderr};
use std::process::Command;

#[test]
fn simplify_writes_mesh_and_report() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("spot-10.ply");
    let report = dir.path().join("report.json");
    let o = qem(&[
        "simplify",
        spot().to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--ratio",
        "0.1",
        "--report",
        report.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    for key in [
        "input",
        "output",
        "triangles_in",
        "triangles_out",
        "vertices_in",
        "vertices_out",
        "edge_contractions",
        "virtual_contractions",
        "max_error",
        "max_error_abs",
        "stop_reason",
        "cleanup",
        "timings_ms",
    ] {
        assert!(json.get(key).is_some(), "report lacks {key}: {json}");
    }
    for key in ["load", "simplify", "write"] {
        assert!(json["timings_ms"].get(key).is_some());
    }
    assert_eq!(json["triangles_in"], 5856);
    assert_eq!(json["target_triangles"], 586); // the count nearest 10% of 5,856
    assert!(json["triangles_out"].as_u64().unwrap() <= 586);
    assert_eq!(json["stop_reason"], "target_reached");
    let back = qem_mesh::io::read_path(&out).unwrap();
    assert_eq!(
        back.mesh.triangle_count() as u64,
        json["triangles_out"].as_u64().unwrap()
    );
}

#[test]
fn missing_input_fails_with_one_line_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o.obj");
    let o = qem(&["simplify", "no/such/file.obj", "-o", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1));
    let e = stderr(&o);
    assert_eq!(e.lines().count(), 1, "{e}");
    assert!(e.starts_with("qem: error: no/such/file.obj: "), "{e}");
    assert!(!out.exists());
}

#[test]
fn corrupt_input_leaves_no_output() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.ply");
    std::fs::write(
        &bad,
        b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nend_header\n1\n",
    )
    .unwrap();
    let out = dir.path().join("o.obj");
    let o = qem(&[
        "simplify",
        bad.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("bad.ply"), "{}", stderr(&o));
    assert!(!out.exists());
    assert_eq!(
        std::fs::read_dir(dir.path()).unwrap().count(),
        1,
        "no stray files"
    );
}

#[test]
fn unknown_output_extension_fails_before_writing() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o.xyz");
    let o = qem(&[
        "simplify",
        spot().to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("o.xyz"), "{}", stderr(&o));
    assert!(!out.exists());
}

#[test]
fn usage_errors_exit_2() {
    let o = qem(&["simplify", "a.obj", "-o", "b.obj", "--ratio", "1.5"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("outside (0, 1]"), "{}", stderr(&o));
    let o = qem(&["simplify", "a.obj"]);
    assert_eq!(o.status.code(), Some(2));
}

#[test]
fn missing_output_directory_fails_first_with_the_fix() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("not/there/o.obj");
    let o = qem(&[
        "simplify",
        spot().to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1));
    let e = stderr(&o);
    assert_eq!(e.lines().count(), 1, "{e}");
    assert!(e.contains("o.obj: the directory"), "{e}");
    assert!(e.contains("create it first"), "{e}");
}

/// Ctrl-C (SIGINT) during the contraction loop: exit 130, no output, no temporary file.
#[cfg(unix)]
#[test]
fn ctrl_c_leaves_no_output() {
    use std::process::Stdio;
    use std::time::Duration;
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("big.ply");
    qem_mesh::io::write_path(&input, &common::bumpy_grid(400, 1)).unwrap();
    let out = dir.path().join("small.ply");
    let child = Command::new(env!("CARGO_BIN_EXE_qem"))
        .args([
            "simplify",
            input.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--ratio",
            "0.001",
        ])
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_millis(700));
    let killed = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(killed.success());
    let o = child.wait_with_output().unwrap();
    assert_eq!(o.status.code(), Some(130), "{}", stderr(&o));
    assert!(!out.exists());
    assert_eq!(
        std::fs::read_dir(dir.path()).unwrap().count(),
        1,
        "only the input is left"
    );
}

/// Issue 33's OBJ from European CAD software (the fixture: Latin-1 `usemtl` and `g`
/// names, a byte order mark, CRLF) is simplified, and the report says what the reader
/// passed over.
#[test]
fn latin1_cad_obj_is_simplified_and_its_notes_reported() {
    let dir = tempfile::tempdir().unwrap();
    let input = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../qem-mesh/tests/fixtures/latin1_bom_crlf.obj");
    let out = dir.path().join("out.obj");
    let report = dir.path().join("report.json");
    let o = qem(&[
        "simplify",
        common::s(&input),
        "-o",
        common::s(&out),
        "--triangles",
        "4",
        "--report",
        common::s(&report),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let r = common::json(&report);
    assert_eq!(r["triangles_in"], 6);
    assert_eq!(
        r["read_notes"],
        serde_json::json!({
            "skipped_lines": 2,
            "skipped_properties": 0,
            "skipped_primitives": 0,
            "non_utf8_lines": 5,
            "byte_order_mark": true
        })
    );
}

/// A temporary file a killed run left beside the output is removed by the next run
/// writing there; one of a live process (this test) is kept.
#[cfg(target_os = "linux")]
#[test]
fn simplify_removes_stale_temporaries_beside_its_output() {
    let dir = tempfile::tempdir().unwrap();
    // No process 99999999 exists: Linux PIDs stay below 2^22.
    let stale = dir.path().join(".out.obj.qem-tmp-99999999-0");
    let live = dir
        .path()
        .join(format!(".out.obj.qem-tmp-{}-0", std::process::id()));
    std::fs::write(&stale, b"half a mesh").unwrap();
    std::fs::write(&live, b"being written").unwrap();
    let out = dir.path().join("out.obj");
    let o = qem(&["simplify", common::s(&spot()), "-o", common::s(&out), "-q"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(!stale.exists() && live.exists() && out.exists());
}

/// `--memory-budget` below what the in-core run needs: the run goes through tiles, the
/// report says how, the scratch directory is left empty; a budget too small for the
/// tiles is an error naming the input, with no output written.
#[test]
fn a_memory_budget_tiles_a_mesh_that_does_not_fit() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("grid.obj");
    // 80,000 triangles with texture coordinates; 8 MB over the fixed 32 MiB hold
    // about 30,000 in core.
    let mut grid = common::bumpy_grid(200, 1);
    let uv: Vec<f32> = grid
        .positions
        .iter()
        .flat_map(|p| [p[0] as f32, p[1] as f32])
        .collect();
    let uv = qem_mesh::attributes::Channel::new(
        qem_mesh::attributes::ChannelKind::TexCoord,
        uv,
        grid.triangles.clone(),
    );
    grid.attributes.channels.push(uv);
    qem_mesh::io::write_path(&input, &grid).unwrap();
    let scratch = dir.path().join("scratch");
    std::fs::create_dir(&scratch).unwrap();
    let out = dir.path().join("out.ply");
    let report = dir.path().join("report.json");
    let budget = format!("{}", (32 << 20) + 8_000_000);
    let o = qem(&[
        "simplify",
        common::s(&input),
        "-o",
        common::s(&out),
        "--ratio",
        "0.02",
        "--memory-budget",
        &budget,
        "--scratch",
        common::s(&scratch),
        "--report",
        common::s(&report),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("1 round of tiles"), "{}", stderr(&o));
    let json = common::json(&report);
    assert_eq!(json["triangles_in"], 80_000);
    // The tiles keep positions only, and the report says so, and why.
    assert_eq!(
        json["attributes"]["dropped"],
        serde_json::json!([{"what": "uv", "reason": "the tiles of --memory-budget keep positions only"}])
    );
    assert_eq!(json["triangles_out"], 1_600);
    let rounds = json["memory_budget"]["rounds"].as_array().unwrap();
    assert_eq!(rounds.len(), 1);
    assert!(rounds[0]["tiles"].as_u64().unwrap() >= 3, "{json}");
    assert_eq!(std::fs::read_dir(&scratch).unwrap().count(), 0);
    assert_eq!(
        qem_mesh::io::read_path(&out).unwrap().mesh.triangle_count(),
        1_600
    );

    let small = dir.path().join("small.ply");
    let o = qem(&[
        "simplify",
        common::s(&input),
        "-o",
        common::s(&small),
        "--memory-budget",
        "33M",
    ]);
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("grid.obj: a memory budget of 35 MB is too small"),
        "{}",
        stderr(&o)
    );
    assert!(!small.exists());

    let o = qem(&[
        "simplify",
        common::s(&input),
        "-o",
        common::s(&small),
        "--memory-budget",
        "4X",
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("the unit must be K, M, G or T"),
        "{}",
        stderr(&o)
    );

    // An option the tiles cannot keep is a usage error naming its flag.
    let o = qem(&[
        "simplify",
        common::s(&input),
        "-o",
        common::s(&small),
        "--ratio",
        "0.02",
        "--memory-budget",
        &budget,
        "--pair-threshold",
        "0.01",
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("qem simplify --memory-budget does not take --pair-threshold"),
        "{}",
        stderr(&o)
    );
    assert!(!small.exists());
}
