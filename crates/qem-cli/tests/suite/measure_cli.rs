//! Runs the built `qem measure` as a user would.

use crate::common;

use common::{qem, spot, stderr, stdout};
use std::path::Path;

/// Few samples keep the test quick; the figures stay meaningful at this size.
const FEW: [&str; 4] = ["--samples-per-face", "2", "--min-samples", "20000"];

fn measure_json(a: &Path, b: &Path, extra: &[&str]) -> serde_json::Value {
    let mut args = vec![
        "measure",
        a.to_str().expect("UTF-8 path"),
        b.to_str().expect("UTF-8 path"),
        "--json",
    ];
    args.extend_from_slice(&FEW);
    args.extend_from_slice(extra);
    let o = qem(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    serde_json::from_str(&stdout(&o)).expect("stdout is JSON")
}

#[test]
fn a_mesh_against_itself_measures_zero_and_against_its_simplification_more() {
    let same = measure_json(&spot(), &spot(), &[]);
    for key in ["hausdorff", "mean_ab", "mean_ba", "rms_ab", "rms_ba"] {
        let v = same[key].as_f64().unwrap();
        assert!((0.0..1e-12).contains(&v), "{key} = {v}");
    }
    assert!(same["samples_ab"].as_u64().unwrap() >= 20_000);
    assert_eq!(same["faces_facing_away"], 0);
    assert_eq!(same["facing_away_area"], 0.0);

    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("spot-10.obj");
    let o = qem(&[
        "simplify",
        spot().to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--ratio",
        "0.1",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let m = measure_json(&spot(), &out, &[]);
    let f = |k: &str| m[k].as_f64().unwrap();
    // A 10% simplification of Spot deviates by a fraction of a percent of the diagonal:
    // clearly above zero, clearly below 5%.
    for key in ["mean_ab", "mean_ba", "rms_ab", "rms_ba", "hausdorff"] {
        assert!(f(key) > 1e-5 && f(key) < 0.05, "{key} = {}", f(key));
    }
    assert!(f("mean_ab") <= f("rms_ab") && f("rms_ab") <= f("hausdorff"));
    assert_eq!(f("hausdorff"), f("hausdorff_ab").max(f("hausdorff_ba")));
    assert_eq!(m["triangles_a"], 5856);

    // The same seed gives the same figures; another seed other ones.
    assert_eq!(measure_json(&spot(), &out, &[]), m);
    let other = measure_json(&spot(), &out, &["--seed", "9"]);
    assert_ne!(other["mean_ab"], m["mean_ab"]);
}

#[test]
fn human_output_has_one_line_per_figure_in_percent_of_the_diagonal() {
    let spot = spot();
    let mut args = vec!["measure", spot.to_str().unwrap(), spot.to_str().unwrap()];
    args.extend_from_slice(&FEW);
    let o = qem(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = stdout(&o);
    for label in [
        "Hausdorff:",
        "Hausdorff A→B:",
        "Hausdorff B→A:",
        "mean A→B:",
        "mean B→A:",
        "RMS A→B:",
        "RMS B→A:",
    ] {
        let line = text
            .lines()
            .find(|l| l.starts_with(label))
            .unwrap_or_else(|| panic!("no {label} line in {text}"));
        assert!(line.ends_with("% of diagonal"), "{line}");
    }
}

#[test]
fn a_missing_file_fails_with_one_line_naming_it() {
    let spot = spot();
    let o = qem(&["measure", spot.to_str().unwrap(), "no/such/b.obj"]);
    assert_eq!(o.status.code(), Some(1));
    let e = stderr(&o);
    assert_eq!(e.lines().count(), 1, "{e}");
    assert!(e.starts_with("qem: error: no/such/b.obj: "), "{e}");
    assert!(o.stdout.is_empty());
}

#[test]
fn a_mesh_whose_positions_all_coincide_is_refused_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    let point = dir.path().join("point.obj");
    std::fs::write(&point, "v 1 1 1\nv 1 1 1\nv 1 1 1\nf 1 2 3\n").unwrap();
    let spot = spot();
    let o = qem(&["measure", point.to_str().unwrap(), spot.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let e = stderr(&o);
    assert_eq!(e.lines().count(), 1, "{e}");
    assert!(
        e.starts_with(&format!("qem: error: {}: ", point.display())),
        "{e}"
    );
}

#[test]
fn usage_errors_exit_with_2() {
    assert_eq!(qem(&["measure"]).status.code(), Some(2));
    assert_eq!(
        qem(&["measure", "a.obj"]).status.code(),
        Some(2),
        "B is required"
    );
    let o = qem(&["measure", "a.obj", "b.obj", "--samples-per-face", "-1"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
}

#[test]
fn attribute_error_and_heat_map() {
    let dir = tempfile::tempdir().expect("tempdir");
    let simplified = dir.path().join("s.obj");
    let o = common::simplify_spot(&simplified, "0.05", &["--quiet"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let heat = dir.path().join("heat.ply");
    let json = measure_json(
        &spot(),
        &simplified,
        &["--heatmap", heat.to_str().expect("UTF-8 path")],
    );
    let uv = &json["attributes"][0];
    assert_eq!(uv["channel"], "uv");
    assert_eq!(uv["units"], "uv units");
    let (p95, max) = (uv["p95"].as_f64().unwrap(), uv["max"].as_f64().unwrap());
    assert!(0.0 < p95 && p95 <= max, "{uv}");
    // The heat map: the simplified mesh, coloured per vertex from blue to red.
    let map = qem_mesh::io::read_path(&heat)
        .expect("the heat map loads")
        .mesh;
    let back = qem_mesh::io::read_path(&simplified).expect("loads").mesh;
    assert_eq!(map.triangle_count(), back.triangle_count());
    let colours = map
        .attributes
        .channel(qem_mesh::attributes::ChannelKind::Color)
        .expect("vertex colours");
    let reddest = colours
        .values
        .chunks_exact(3)
        .map(|c| c[0])
        .fold(0.0, f32::max);
    let bluest = colours
        .values
        .chunks_exact(3)
        .map(|c| c[2])
        .fold(0.0, f32::max);
    assert!(
        reddest == 1.0 && bluest == 1.0,
        "red {reddest}, blue {bluest}"
    );
    let text = std::fs::read(&heat).expect("read");
    let header = String::from_utf8_lossy(&text[..text.len().min(600)]).into_owned();
    assert!(header.contains("comment heat map of"), "{header}");
    assert!(stderr(&qem(&[
        "measure",
        spot().to_str().unwrap(),
        simplified.to_str().unwrap(),
        "--heatmap",
        dir.path().join("h.stl").to_str().unwrap(),
    ]))
    .contains("use .ply or .off"));
}

/// A reader that closes the pipe before `qem measure` prints (`qem measure ... | head
/// -c 0`) ends the output quietly: `print!` used to panic on the broken pipe, with a
/// backtrace on stderr.
#[test]
fn a_closed_pipe_on_stdout_is_no_panic() {
    use std::process::{Command, Stdio};
    let spot = spot();
    let mut child = Command::new(env!("CARGO_BIN_EXE_qem"))
        .args(["measure", common::s(&spot), common::s(&spot), "--json"])
        .args(FEW)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("qem starts");
    // Closed at once: loading and sampling spot take far longer than this.
    drop(child.stdout.take());
    let o = child.wait_with_output().expect("qem ends");
    let err = stderr(&o);
    assert!(!err.contains("panicked"), "{err}");
    assert!(o.status.success(), "{err}");
}
