//! `qem tiles split | simplify | merge` through the binary: the merged mesh is valid
//! and closed where the input was (no cracks along tile borders), every step rerun
//! gives the same bytes, a killed job's leftovers are redone rather than taken for
//! done, and bad directories are clear errors naming the file.

use crate::common::{qem, s, spot, stderr};
use qem_mesh::inspect::{inspect, MeshInfo};
use qem_mesh::io::{read_path, write_path};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Output;

/// Runs `qem` and checks it succeeded.
fn ok(args: &[&str]) -> Output {
    let out = qem(args);
    assert!(out.status.success(), "qem {args:?}: {}", stderr(&out));
    out
}

/// Runs `qem`, checks it failed with exit code 1 and one `qem: error:` line naming
/// `names` (and no panic), and gives that line.
fn fails_naming(args: &[&str], names: &str) -> String {
    let out = qem(args);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "qem {args:?}: {err}");
    assert!(!err.contains("panicked"), "{err}");
    assert!(err.starts_with("qem: error: "), "{err}");
    assert!(
        err.contains(names),
        "qem {args:?}: expected {names} in: {err}"
    );
    err
}

/// Every file of `dir` (name → bytes).
fn files(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    std::fs::read_dir(dir)
        .expect("list the directory")
        .map(|e| {
            let e = e.expect("an entry");
            (
                e.file_name().to_string_lossy().into_owned(),
                std::fs::read(e.path()).expect("read"),
            )
        })
        .collect()
}

fn info(path: &Path) -> MeshInfo {
    inspect(&read_path(path).expect("the merged mesh reads").mesh).expect("valid")
}

/// The cow split into 5 tiles in `dir` (closed, 5,856 triangles).
fn split_spot(dir: &Path) {
    ok(&["tiles", "split", s(&spot()), s(dir), "--tiles", "5", "-q"]);
}

#[test]
fn split_simplify_merge_gives_a_closed_mesh_without_cracks() {
    let tmp = tempfile::tempdir().expect("a temporary directory");
    let dir = tmp.path().join("tiles");
    split_spot(&dir);
    ok(&["tiles", "simplify", s(&dir), "--ratio", "0.2", "-q"]);
    let out = tmp.path().join("merged.ply");
    ok(&["tiles", "merge", s(&dir), "-o", s(&out), "-q"]);
    let merged = info(&out);
    // A crack along a tile border would show as border edges (the cow is closed).
    assert_eq!(merged.boundary_edges, 0, "{merged:?}");
    assert_eq!(merged.nonmanifold_edges, 0, "{merged:?}");
    assert_eq!(merged.components, 1, "{merged:?}");
    assert_eq!(merged.welded_vertices, 0, "every border vertex was welded");
    assert_eq!(merged.degenerate_faces, 0, "{merged:?}");
    assert!(
        merged.triangles <= 5856 / 4,
        "about 20% of the triangles, the borders locked: {}",
        merged.triangles
    );
}

#[test]
fn an_stl_soup_has_its_borders_found_by_position() {
    let tmp = tempfile::tempdir().expect("a temporary directory");
    let stl = tmp.path().join("spot.stl");
    let mesh = read_path(&spot()).expect("the cow").mesh;
    write_path(
        &stl,
        &qem_mesh::IndexedMesh::new(mesh.positions, mesh.triangles),
    )
    .expect("write STL");
    let dir = tmp.path().join("tiles");
    ok(&[
        "tiles",
        "split",
        s(&stl),
        s(&dir),
        "--tile-triangles",
        "1000",
    ]);
    ok(&["tiles", "simplify", s(&dir), "--ratio", "0.3", "-q"]);
    let out = tmp.path().join("merged.obj");
    ok(&["tiles", "merge", s(&dir), "-o", s(&out), "-q"]);
    let merged = info(&out);
    assert_eq!(merged.boundary_edges, 0, "{merged:?}");
    assert_eq!(merged.welded_vertices, 0, "{merged:?}");
}

#[test]
fn every_step_rerun_gives_the_same_bytes() {
    let tmp = tempfile::tempdir().expect("a temporary directory");
    let (a, b) = (tmp.path().join("a"), tmp.path().join("b"));
    split_spot(&a);
    let split = files(&a);
    // Again into the same directory, and into another one.
    split_spot(&a);
    split_spot(&b);
    assert_eq!(files(&a), split);
    assert_eq!(files(&b), split);

    ok(&["tiles", "simplify", s(&a), "--ratio", "0.3", "-q"]);
    let simplified = files(&a);
    // Done tiles are skipped, and say so.
    let again = ok(&["tiles", "simplify", s(&a), "--ratio", "0.3"]);
    assert_eq!(stderr(&again).matches("done already").count(), 5);
    assert_eq!(files(&a), simplified);
    // One tile at a time (as an array job runs them), in another order: the same.
    for k in ["4", "2", "0", "3", "1"] {
        ok(&[
            "tiles",
            "simplify",
            s(&b),
            "--ratio",
            "0.3",
            "--tile",
            k,
            "-q",
        ]);
    }
    assert_eq!(files(&b), simplified);
    // Other options are not the work done: every tile runs again.
    let other = ok(&["tiles", "simplify", s(&b), "--ratio", "0.25"]);
    assert!(
        !stderr(&other).contains("done already"),
        "{}",
        stderr(&other)
    );

    let (m1, m2) = (tmp.path().join("m1.ply"), tmp.path().join("m2.ply"));
    ok(&["tiles", "merge", s(&a), "-o", s(&m1), "-q"]);
    ok(&["tiles", "merge", s(&a), "-o", s(&m2), "-q"]);
    assert_eq!(std::fs::read(&m1).ok(), std::fs::read(&m2).ok());
}

#[test]
fn a_killed_job_is_redone_not_taken_for_done() {
    let tmp = tempfile::tempdir().expect("a temporary directory");
    let dir = tmp.path().join("tiles");
    split_spot(&dir);
    ok(&["tiles", "simplify", s(&dir), "--ratio", "0.3", "-q"]);
    let whole = files(&dir);
    let path = |name: &str| dir.join(name);

    // A simplified tile cut short (its status still there).
    let good = std::fs::read(path("tile-00001.simplified.ply")).expect("tile 1");
    std::fs::write(path("tile-00001.simplified.ply"), &good[..good.len() / 2]).expect("cut");
    fails_naming(
        &[
            "tiles",
            "merge",
            s(&dir),
            "-o",
            s(&tmp.path().join("m.ply")),
        ],
        "tile-00001.simplified.ply",
    );
    // A job killed after writing its tile but before its status.
    std::fs::remove_file(path("tile-00003.done.json")).expect("remove a status");
    let err = fails_naming(
        &[
            "tiles",
            "merge",
            s(&dir),
            "-o",
            s(&tmp.path().join("m.ply")),
        ],
        "tile-00003.done.json",
    );
    assert!(err.contains("--tile 3"), "{err}");
    // A job killed before it wrote anything: no status and a half-written output
    // under the final name (as a writer without atomic renames would leave).
    std::fs::remove_file(path("tile-00004.done.json")).expect("remove a status");
    std::fs::write(path("tile-00004.simplified.ply"), b"ply\nformat binary").expect("write");

    let rerun = ok(&["tiles", "simplify", s(&dir), "--ratio", "0.3"]);
    let err = stderr(&rerun);
    for k in [1, 3, 4] {
        assert!(!err.contains(&format!("tile {k}: done already")), "{err}");
    }
    assert_eq!(err.matches("done already").count(), 2, "{err}");
    assert_eq!(files(&dir), whole);
    ok(&[
        "tiles",
        "merge",
        s(&dir),
        "-o",
        s(&tmp.path().join("m.ply")),
        "-q",
    ]);
}

#[test]
fn bad_directories_are_clear_errors_naming_the_file() {
    let tmp = tempfile::tempdir().expect("a temporary directory");
    let missing = tmp.path().join("no-such-dir");
    fails_naming(
        &["tiles", "simplify", s(&missing), "--ratio", "0.5"],
        "no-such-dir",
    );
    let out = tmp.path().join("m.ply");
    fails_naming(
        &["tiles", "merge", s(&missing), "-o", s(&out)],
        "no-such-dir",
    );

    // A directory without a manifest (or whose split did not finish).
    let empty = tmp.path().join("empty");
    std::fs::create_dir(&empty).expect("mkdir");
    fails_naming(&["tiles", "simplify", s(&empty)], "tiles.json");

    let dir = tmp.path().join("tiles");
    split_spot(&dir);
    let manifest = dir.join("tiles.json");
    let text = std::fs::read_to_string(&manifest).expect("the manifest");
    let other_version = text.replace("\"qem_tiles\": 2", "\"qem_tiles\": 99");
    assert_ne!(other_version, text, "the manifest names its version, 2");
    for corrupt in [
        "{ not json".to_string(),
        other_version,
        text.replace("tile-00002.ply", "../../etc/passwd"),
        String::new(),
    ] {
        std::fs::write(&manifest, &corrupt).expect("write");
        fails_naming(&["tiles", "simplify", s(&dir), "--tile", "0"], "tiles.json");
        fails_naming(&["tiles", "merge", s(&dir), "-o", s(&out)], "tiles.json");
    }
    std::fs::write(&manifest, &text).expect("restore");

    // A tile of another split (a grid of another mesh cut into as many tiles).
    let other = tmp.path().join("other");
    let grid = tmp.path().join("grid.ply");
    write_path(&grid, &crate::common::bumpy_grid(30, 1)).expect("a grid");
    ok(&["tiles", "split", s(&grid), s(&other), "--tiles", "5", "-q"]);
    std::fs::copy(other.join("tile-00002.ply"), dir.join("tile-00002.ply")).expect("copy");
    let err = fails_naming(
        &[
            "tiles",
            "simplify",
            s(&dir),
            "--tile",
            "2",
            "--ratio",
            "0.5",
        ],
        "tile-00002.ply",
    );
    assert!(err.contains("another split"), "{err}");
    split_spot(&dir);

    // A status of another split.
    ok(&["tiles", "simplify", s(&dir), "--ratio", "0.5", "-q"]);
    ok(&["tiles", "simplify", s(&other), "--ratio", "0.5", "-q"]);
    std::fs::copy(
        other.join("tile-00001.done.json"),
        dir.join("tile-00001.done.json"),
    )
    .expect("copy");
    let err = fails_naming(
        &["tiles", "merge", s(&dir), "-o", s(&out)],
        "tile-00001.done.json",
    );
    assert!(err.contains("another split"), "{err}");
    // A status that is not one.
    std::fs::write(dir.join("tile-00001.done.json"), b"\0\0").expect("write");
    fails_naming(
        &["tiles", "merge", s(&dir), "-o", s(&out)],
        "tile-00001.done.json",
    );
    // Tiles simplified with different options.
    ok(&[
        "tiles",
        "simplify",
        s(&dir),
        "--ratio",
        "0.4",
        "--tile",
        "1",
        "-q",
    ]);
    let err = fails_naming(
        &["tiles", "merge", s(&dir), "-o", s(&out)],
        "tile-00001.done.json",
    );
    assert!(err.contains("other options"), "{err}");

    // A tile number past the last, an input that is not a mesh, an output format qem
    // cannot write.
    fails_naming(&["tiles", "simplify", s(&dir), "--tile", "5"], "no tile 5");
    let junk = tmp.path().join("junk.ply");
    std::fs::write(&junk, b"not a mesh").expect("write");
    fails_naming(
        &["tiles", "split", s(&junk), s(&tmp.path().join("j"))],
        "junk.ply",
    );
    fails_naming(
        &[
            "tiles",
            "merge",
            s(&dir),
            "-o",
            s(&tmp.path().join("m.xyz")),
        ],
        "m.xyz",
    );
    assert!(!out.exists(), "nothing was merged");
}

#[test]
fn options_the_tiles_cannot_keep_are_usage_errors() {
    let tmp = tempfile::tempdir().expect("a temporary directory");
    let dir: PathBuf = tmp.path().join("tiles");
    split_spot(&dir);
    for flag in [
        &["--triangles", "100"][..],
        &["--cluster"],
        &["--lock", "x.txt"],
    ] {
        let mut args = vec!["tiles", "simplify", s(&dir)];
        args.extend_from_slice(flag);
        let out = qem(&args);
        assert_eq!(out.status.code(), Some(2), "{flag:?}: {}", stderr(&out));
        assert!(stderr(&out).contains(flag[0]), "{}", stderr(&out));
    }
}

#[test]
fn a_target_below_twice_the_locked_vertices_is_warned_of() {
    let tmp = tempfile::tempdir().expect("a temporary directory");
    let dir = tmp.path().join("tiles");
    split_spot(&dir);
    // 1,171 triangles a tile: at 0.5, 585 triangles for under 200 locked vertices.
    let fine = ok(&[
        "tiles",
        "simplify",
        s(&dir),
        "--ratio",
        "0.5",
        "--tile",
        "0",
    ]);
    assert!(!stderr(&fine).contains("warning"), "{}", stderr(&fine));
    // At 0.05, 58 triangles.
    let crowded = ok(&[
        "tiles",
        "simplify",
        s(&dir),
        "--ratio",
        "0.05",
        "--tile",
        "0",
    ]);
    let err = stderr(&crowded);
    assert!(err.contains("qem: warning: tile 0: its "), "{err}");
    assert!(err.contains("locked vertices (its border"), "{err}");
}

/// Several jobs on one directory at once (a scheduler may start a tile's job twice, or
/// a whole run beside an array job) finish with the files of one job alone.
#[test]
fn jobs_running_at_once_leave_the_files_of_one_job() {
    let tmp = tempfile::tempdir().expect("a temporary directory");
    let (alone, shared) = (tmp.path().join("alone"), tmp.path().join("shared"));
    split_spot(&alone);
    split_spot(&shared);
    ok(&["tiles", "simplify", s(&alone), "--ratio", "0.3", "-q"]);
    let jobs: Vec<std::process::Child> = [
        &[][..],
        &["--tile", "2"],
        &[],
        &["--tile", "4"],
        &["--tile", "2"],
    ]
    .iter()
    .map(|extra| {
        std::process::Command::new(env!("CARGO_BIN_EXE_qem"))
            .args(["tiles", "simplify", s(&shared), "--ratio", "0.3", "-q"])
            .args(*extra)
            .stderr(std::process::Stdio::piped())
            .spawn()
            .expect("qem starts")
    })
    .collect();
    for job in jobs {
        let out = job.wait_with_output().expect("qem runs");
        assert!(out.status.success(), "{}", stderr(&out));
    }
    assert_eq!(files(&shared), files(&alone));
}

/// Issue 31's "killed at random points": `qem tiles split` and `qem tiles simplify`
/// processes killed (SIGKILL) after delays spread over their run, then run again to
/// the end, leave the same tile directory and merged mesh as one uninterrupted run.
/// The delays are drawn from a fixed seed; whatever point each kill lands on, the
/// outcome must be the same, so the test cannot depend on the machine's speed.
#[test]
fn jobs_killed_at_random_points_then_rerun_give_the_uninterrupted_output() {
    let tmp = tempfile::tempdir().expect("a temporary directory");
    let input = tmp.path().join("grid.ply");
    // 45,000 triangles: long enough a run to be killed in the middle.
    write_path(&input, &crate::common::bumpy_grid(150, 2)).expect("write the input");
    fn run<'a>(input: &'a Path, dir: &'a Path) -> Vec<Vec<&'a str>> {
        vec![
            vec!["tiles", "split", s(input), s(dir), "--tiles", "6", "-q"],
            vec!["tiles", "simplify", s(dir), "--ratio", "0.1", "-q"],
        ]
    }
    let clean_dir = tmp.path().join("uninterrupted");
    // How long each step takes uninterrupted: the kills land within that.
    let mut durations = Vec::new();
    for args in run(&input, &clean_dir) {
        let clock = std::time::Instant::now();
        ok(&args);
        durations.push(clock.elapsed());
    }
    let merged = |dir: &Path, name: &str| {
        let out = tmp.path().join(name);
        ok(&["tiles", "merge", s(dir), "-o", s(&out), "-q"]);
        std::fs::read(out).expect("the merged mesh")
    };
    let expected = merged(&clean_dir, "uninterrupted.ply");

    let dir = tmp.path().join("killed");
    let mut state = 0x9e37_79b9_7f4a_7c15_u64;
    let mut killed = 0;
    for (args, duration) in run(&input, &dir).into_iter().zip(durations) {
        for _ in 0..6 {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let delay = duration.mul_f64((state % 1000) as f64 / 1000.0);
            let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_qem"))
                .args(&args)
                .stderr(std::process::Stdio::null())
                .spawn()
                .expect("qem starts");
            std::thread::sleep(delay);
            if child.try_wait().expect("qem's status").is_none() {
                killed += 1;
            }
            let _ = child.kill(); // SIGKILL; it may have finished meanwhile
            let _ = child.wait();
        }
        ok(&args);
    }
    // Some kills land in a run (later runs are shorter: they skip the tiles done), so
    // the reruns had leftovers to deal with.
    eprintln!("{killed} of 12 kills landed in a run");
    assert!(killed >= 3, "only {killed} of 12 kills landed in a run");
    let leftovers: Vec<String> = files(&dir)
        .into_keys()
        .filter(|name| !files(&clean_dir).contains_key(name))
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
    assert_eq!(files(&dir), files(&clean_dir));
    assert_eq!(merged(&dir, "killed.ply"), expected);
}
