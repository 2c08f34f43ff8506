//! `qem batch` run as a user would: bad files do not stop good ones, outputs keep their
//! relative paths, `-j` does not change a byte, colliding outputs are refused.

use crate::common;

use common::{bumpy_grid, json, qem, s, spot, stderr};
use qem_mesh::io::{read_path, write_path};
use std::path::{Path, PathBuf};

/// The manifest `qem batch` keeps in the output directory.
const MANIFEST: &str = ".qem-batch-manifest.jsonl";

const CORRUPT_PLY: &[u8] =
    b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nend_header\n1\n";

/// A folder with good meshes in four formats (one in a subfolder, one gzipped), a
/// corrupt PLY, an unsupported file and a material file.
fn messy_folder(root: &Path) {
    std::fs::create_dir_all(root.join("sub")).expect("set up the test files");
    std::fs::copy(spot(), root.join("spot.obj")).expect("set up the test files");
    write_path(&root.join("grid.ply"), &bumpy_grid(12, 1)).expect("set up the test files");
    write_path(&root.join("sub/grid.stl"), &bumpy_grid(10, 2)).expect("set up the test files");
    write_path(&root.join("sub/more.off.gz"), &bumpy_grid(8, 3)).expect("set up the test files");
    std::fs::write(root.join("corrupt.ply"), CORRUPT_PLY).expect("set up the test files");
    std::fs::write(root.join("scene.fbx"), b"Kaydara FBX Binary").expect("set up the test files");
    std::fs::write(root.join("spot.mtl"), b"newmtl skin\n").expect("set up the test files");
}

/// The files under `dir`, relative to it, without the batch manifest (which
/// `resume_skips_what_is_done` and the soak test check on their own).
fn files_under(dir: &Path) -> Vec<PathBuf> {
    let mut out: Vec<PathBuf> = walk(dir)
        .into_iter()
        .map(|p| p.strip_prefix(dir).expect("walk the output").to_path_buf())
        .filter(|p| p != Path::new(MANIFEST))
        .collect();
    out.sort();
    out
}

fn walk(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(dir).expect("walk the output") {
        let p = e.expect("walk the output").path();
        if p.is_dir() {
            out.extend(walk(&p));
        } else {
            out.push(p);
        }
    }
    out
}

#[test]
fn bad_files_are_reported_and_the_rest_succeed() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in");
    messy_folder(&input);
    let out = dir.path().join("out");
    let report = dir.path().join("report.json");
    // A glob names every file of the folder explicitly, so the unsupported one is an
    // input (and fails) while the subfolder is walked for meshes.
    let pattern = format!("{}/*", s(&input));
    let o = qem(&[
        "batch",
        &pattern,
        "--out-dir",
        s(&out),
        "--ratio",
        "0.5",
        "--report",
        s(&report),
        "-j",
        "2",
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));

    let r = json(&report);
    let entries = r["inputs"].as_array().unwrap();
    let names: Vec<&str> = entries
        .iter()
        .map(|e| e["input"].as_str().unwrap())
        .collect();
    let mut sorted = names.clone();
    sorted.sort();
    assert_eq!(names, sorted, "the report lists inputs in sorted order");
    assert_eq!(entries.len(), 7, "{names:?}");

    let error_of = |suffix: &str| {
        entries
            .iter()
            .find(|e| e["input"].as_str().unwrap().ends_with(suffix))
            .unwrap_or_else(|| panic!("{suffix} is in the report"))
            .get("error")
            .and_then(|v| v.as_str())
            .map(str::to_string)
    };
    let corrupt = error_of("corrupt.ply").expect("corrupt.ply failed");
    assert!(corrupt.contains("corrupt.ply: line 3:"), "{corrupt}");
    let fbx = error_of("scene.fbx").expect("scene.fbx failed");
    assert!(fbx.contains("scene.fbx: unsupported file extension \".fbx\""));
    assert!(fbx.contains(".obj, .ply"), "the fix is suggested: {fbx}");
    let mtl = error_of("spot.mtl").expect("spot.mtl failed");
    assert!(mtl.contains("unsupported file extension"), "{mtl}");
    for good in ["spot.obj", "grid.ply", "grid.stl", "more.off.gz"] {
        assert_eq!(error_of(good), None, "{good} succeeded");
    }
    assert_eq!(r["summary"]["inputs"], 7);
    assert_eq!(r["summary"]["succeeded"], 4);
    assert_eq!(r["summary"]["failed"], 3);

    // stderr: one line per failure naming the file, then the summary line.
    let e = stderr(&o);
    assert!(e
        .lines()
        .any(|l| l.starts_with("qem: error: ") && l.contains("corrupt.ply")));
    assert!(e
        .lines()
        .any(|l| l.starts_with("qem: error: ") && l.contains("scene.fbx")));

    // Outputs keep the relative path, in the input's own format, and nothing else is
    // left in the output directory (no temporary files, nothing for failed inputs)
    // but spot.obj's material library, copied beside it.
    assert_eq!(
        files_under(&out),
        [
            "grid.ply",
            "spot.mtl",
            "spot.obj",
            "sub/grid.stl",
            "sub/more.off"
        ]
        .map(PathBuf::from)
        .to_vec()
    );
    for entry in entries.iter().filter(|e| e.get("error").is_none()) {
        let output = Path::new(entry["output"].as_str().unwrap());
        let back = read_path(output).unwrap();
        assert_eq!(
            back.mesh.triangle_count() as u64,
            entry["triangles_out"].as_u64().unwrap()
        );
        assert!(
            entry["triangles_out"].as_u64().unwrap() * 2 <= entry["triangles_in"].as_u64().unwrap()
        );
    }
}

#[test]
fn directories_are_walked_for_meshes_only() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in");
    messy_folder(&input);
    let out = dir.path().join("out");
    let report = dir.path().join("r.json");
    let o = qem(&[
        "batch",
        s(&input),
        "--out-dir",
        s(&out),
        "--format",
        "obj",
        "--report",
        s(&report),
        "-q",
    ]);
    // The corrupt PLY is a mesh by its name, so it is an input and fails.
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let r = json(&report);
    let ignored: Vec<&str> = r["ignored"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_str().unwrap())
        .collect();
    assert_eq!(ignored.len(), 2, "{ignored:?}");
    assert!(ignored[0].ends_with("scene.fbx") && ignored[1].ends_with("spot.mtl"));
    assert_eq!(r["summary"]["succeeded"], 4);
    assert_eq!(r["summary"]["failed"], 1);
    assert_eq!(
        files_under(&out),
        [
            "grid.obj",
            "spot.mtl",
            "spot.obj",
            "sub/grid.obj",
            "sub/more.obj"
        ]
        .map(PathBuf::from)
        .to_vec()
    );
    // --quiet: only the failure line.
    let e = stderr(&o);
    assert_eq!(e.lines().count(), 1, "{e}");
    assert!(e.contains("corrupt.ply"));

    // A second run over the same tree with the output inside it does not take the
    // first run's outputs as inputs.
    let inner = input.join("lod");
    let o = qem(&["batch", s(&input), "--out-dir", s(&inner), "-q"]);
    assert_eq!(o.status.code(), Some(1));
    let o = qem(&["batch", s(&input), "--out-dir", s(&inner), "-q"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(!inner.join("lod").exists());
}

#[test]
fn all_good_exits_zero() {
    let dir = tempfile::tempdir().unwrap();
    let a = dir.path().join("a.ply");
    write_path(&a, &bumpy_grid(6, 0)).unwrap();
    let out = dir.path().join("out");
    let o = qem(&[
        "batch",
        s(&a),
        s(&spot()),
        "--out-dir",
        s(&out),
        "--triangles",
        "20",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    // With spot.obj, its material library and texture.
    assert_eq!(
        files_under(&out),
        ["a.ply", "spot.mtl", "spot.obj", "spot_checker.png"]
            .map(PathBuf::from)
            .to_vec()
    );
    assert!(
        read_path(&out.join("spot.obj"))
            .unwrap()
            .mesh
            .triangle_count()
            <= 20
    );
    assert!(
        stderr(&o).contains("2 of 2 files simplified"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn jobs_do_not_change_a_byte() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in");
    std::fs::create_dir_all(&input).unwrap();
    std::fs::copy(spot(), input.join("spot.obj")).unwrap();
    for seed in 0..5 {
        let ext = ["ply", "obj", "off", "stl", "ply"][seed as usize];
        write_path(
            &input.join(format!("grid{seed}.{ext}")),
            &bumpy_grid(14 + seed, seed),
        )
        .unwrap();
    }
    let mut trees = Vec::new();
    for jobs in ["1", "2"] {
        let out = dir.path().join(format!("out{jobs}"));
        let report = dir.path().join(format!("r{jobs}.json"));
        let o = qem(&[
            "batch",
            s(&input),
            "--out-dir",
            s(&out),
            "--ratio",
            "0.2",
            "--pair-threshold",
            "0.01",
            "-j",
            jobs,
            "--report",
            s(&report),
        ]);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        assert_eq!(
            json(&report)["summary"]["jobs"],
            jobs.parse::<u64>().unwrap()
        );
        let files = files_under(&out);
        let bytes: Vec<Vec<u8>> = files
            .iter()
            .map(|f| std::fs::read(out.join(f)).unwrap())
            .collect();
        // The report's per-file content, without timings and output directory.
        let mut entries = json(&report)["inputs"].clone();
        for e in entries.as_array_mut().unwrap() {
            let e = e.as_object_mut().unwrap();
            e.remove("timings_ms");
            e.remove("output");
        }
        trees.push((files, bytes, entries));
    }
    assert_eq!(trees[0].0.len(), 6);
    assert_eq!(trees[0].0, trees[1].0);
    for (i, f) in trees[0].0.iter().enumerate() {
        assert!(trees[0].1[i] == trees[1].1[i], "{} differs", f.display());
    }
    assert_eq!(trees[0].2, trees[1].2);
}

#[test]
fn colliding_outputs_are_refused_not_overwritten() {
    let dir = tempfile::tempdir().unwrap();
    write_path(&dir.path().join("a.obj"), &bumpy_grid(5, 0)).unwrap();
    write_path(&dir.path().join("a.ply"), &bumpy_grid(5, 1)).unwrap();
    write_path(&dir.path().join("b.ply"), &bumpy_grid(5, 2)).unwrap();
    let out = dir.path().join("out");
    let report = dir.path().join("r.json");
    let pattern = format!("{}/*.*", s(dir.path()));
    let o = qem(&[
        "batch",
        &pattern,
        "--out-dir",
        s(&out),
        "--format",
        "obj",
        "--report",
        s(&report),
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let r = json(&report);
    let entries = r["inputs"].as_array().unwrap();
    assert_eq!(entries.len(), 3);
    for e in &entries[..2] {
        let error = e["error"].as_str().unwrap();
        assert!(error.contains("would also be written from"), "{error}");
    }
    assert!(entries[2].get("error").is_none());
    assert_eq!(files_under(&out), vec![PathBuf::from("b.obj")]);
}

#[test]
fn missing_inputs_and_empty_patterns_are_failures_of_their_own() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let report = dir.path().join("r.json");
    let missing = dir.path().join("no/such.obj");
    let nothing = format!("{}/*.stl", s(dir.path()));
    let o = qem(&[
        "batch",
        s(&spot()),
        s(&missing),
        &nothing,
        "--out-dir",
        s(&out),
        "--report",
        s(&report),
    ]);
    assert_eq!(o.status.code(), Some(1));
    let r = json(&report);
    let errors: Vec<&str> = r["inputs"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|e| e["error"].as_str())
        .collect();
    assert_eq!(errors.len(), 2, "{errors:?}");
    assert!(errors
        .iter()
        .any(|e| e.contains("such.obj: no such file or directory")));
    assert!(errors.iter().any(|e| e.contains("matches no file")));
    assert!(out.join("spot.obj").is_file());
}

#[test]
fn usage_errors_exit_2() {
    let o = qem(&["batch", "x.obj"]);
    assert_eq!(o.status.code(), Some(2), "--out-dir is required");
    let o = qem(&["batch", "x.obj", "--out-dir", "o", "-j", "0"]);
    assert_eq!(o.status.code(), Some(2));
    let o = qem(&["batch", "x.obj", "--out-dir", "o", "--format", "fbx"]);
    assert_eq!(o.status.code(), Some(2));
}

/// Ctrl-C (SIGINT) stops the run: exit 130 and every file in the output directory is a
/// complete mesh (no temporary or half-written file).
#[cfg(unix)]
#[test]
fn ctrl_c_stops_cleanly() {
    use std::process::{Command, Stdio};
    use std::time::{Duration, Instant};
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in");
    std::fs::create_dir_all(&input).unwrap();
    // Enough work that the run is still going when the signal comes.
    for seed in 0..6 {
        write_path(&input.join(format!("g{seed}.ply")), &bumpy_grid(260, seed)).unwrap();
    }
    let out = dir.path().join("out");
    let report = dir.path().join("r.json");
    let child = Command::new(env!("CARGO_BIN_EXE_qem"))
        .args([
            "batch",
            s(&input),
            "--out-dir",
            s(&out),
            "--ratio",
            "0.01",
            "-j",
            "1",
            "--report",
            s(&report),
        ])
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Wait until the first file is being worked on (the output directory exists).
    let start = Instant::now();
    while !out.exists() && start.elapsed() < Duration::from_secs(30) {
        std::thread::sleep(Duration::from_millis(20));
    }
    std::thread::sleep(Duration::from_millis(200));
    let killed = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(killed.success());
    let o = child.wait_with_output().unwrap();
    assert_eq!(o.status.code(), Some(130), "{}", stderr(&o));
    assert!(stderr(&o).contains("interrupted"), "{}", stderr(&o));
    let r = json(&report);
    assert_eq!(r["summary"]["interrupted"], true);
    assert!(r["summary"]["succeeded"].as_u64().unwrap() < 6);
    for f in files_under(&out) {
        let back = read_path(&out.join(&f));
        assert!(back.is_ok(), "{} is a complete mesh", f.display());
    }
    let done = r["summary"]["succeeded"].as_u64().unwrap() as usize;
    assert_eq!(
        files_under(&out).len(),
        done,
        "only finished files are written"
    );
}

#[test]
fn failed_files_leave_no_directories_and_empty_folders_fail() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in");
    std::fs::create_dir_all(input.join("deep/er")).unwrap();
    std::fs::write(input.join("deep/er/corrupt.ply"), CORRUPT_PLY).unwrap();
    write_path(&input.join("good.ply"), &bumpy_grid(4, 0)).unwrap();
    let empty = dir.path().join("empty");
    std::fs::create_dir_all(empty.join("only/notes")).unwrap();
    std::fs::write(empty.join("only/notes/readme.txt"), b"no meshes here").unwrap();
    let out = dir.path().join("out");
    let report = dir.path().join("r.json");
    let o = qem(&[
        "batch",
        s(&input),
        s(&empty),
        "--out-dir",
        s(&out),
        "--report",
        s(&report),
    ]);
    assert_eq!(o.status.code(), Some(1));
    assert_eq!(files_under(&out), vec![PathBuf::from("good.ply")]);
    assert!(!out.join("deep").exists(), "no directory for a failed file");
    let r = json(&report);
    let errors: Vec<&str> = r["inputs"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|e| e["error"].as_str())
        .collect();
    assert_eq!(errors.len(), 2, "{errors:?}");
    // Sorted by input: .../empty before .../in/deep/er/corrupt.ply.
    assert!(
        errors[0].contains("empty: no mesh file in this directory"),
        "{errors:?}"
    );
    assert!(errors[1].contains("corrupt.ply: line 3"), "{errors:?}");
}

#[test]
fn inputs_are_never_overwritten() {
    let dir = tempfile::tempdir().unwrap();
    let a = dir.path().join("a.ply");
    write_path(&a, &bumpy_grid(6, 0)).unwrap();
    let before = std::fs::read(&a).unwrap();
    // The folder as its own output directory, and the file into its own folder.
    let o = qem(&["batch", s(dir.path()), "--out-dir", s(dir.path())]);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains("is the output directory"),
        "{}",
        stderr(&o)
    );
    let o = qem(&["batch", s(&a), "--out-dir", s(dir.path())]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("would overwrite it"), "{}", stderr(&o));
    assert!(std::fs::read(&a).unwrap() == before);
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
}

/// The report's entries without what differs between runs (timings, `resumed`).
fn entries_without_timings(report: &Path) -> Vec<serde_json::Value> {
    let mut entries = json(report)["inputs"]
        .as_array()
        .expect("the report lists inputs")
        .clone();
    for e in &mut entries {
        let e = e.as_object_mut().expect("an entry is an object");
        e.remove("timings_ms");
        e.remove("resumed");
    }
    entries
}

fn modified(p: &Path) -> std::time::SystemTime {
    std::fs::metadata(p)
        .and_then(|m| m.modified())
        .expect("a modification time")
}

#[test]
fn resume_skips_what_is_done_and_reports_every_input() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in");
    messy_folder(&input);
    let out = dir.path().join("out");
    let report = |n: u32| dir.path().join(format!("r{n}.json"));
    let run = |n: u32, extra: &[&str]| {
        let r = report(n);
        let mut args = vec!["batch", s(&input), "--out-dir", s(&out), "--report", s(&r)];
        args.extend_from_slice(extra);
        let o = qem(&args);
        // corrupt.ply fails in every run.
        assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
        (json(&r)["summary"].clone(), stderr(&o))
    };
    let (first, _) = run(1, &[]);
    assert_eq!(
        (first["succeeded"].as_u64(), first["resumed"].as_u64()),
        (Some(4), Some(0))
    );
    assert!(out.join(MANIFEST).is_file());
    let outputs = files_under(&out);
    let times: Vec<_> = outputs.iter().map(|f| modified(&out.join(f))).collect();

    // Temporary files of killed runs (no process 99999999 exists: Linux PIDs stay
    // below 2^22) are removed; one of a live process (this test) is kept.
    let own = format!(".grid.ply.qem-tmp-{}-0", std::process::id());
    for stale in [
        ".spot.obj.qem-tmp-99999999-0",
        "sub/.grid.stl.qem-tmp-99999999-1",
        &own,
    ] {
        std::fs::write(out.join(stale), b"half a mesh").unwrap();
    }
    let (second, err) = run(2, &["--resume"]);
    assert_eq!(second["resumed"].as_u64(), Some(4), "{err}");
    assert_eq!(second["succeeded"].as_u64(), Some(4));
    assert_eq!(second["failed"].as_u64(), Some(1));
    assert_eq!(second["triangles_in"], first["triangles_in"]);
    assert_eq!(second["triangles_out"], first["triangles_out"]);
    assert_eq!(second["stale_temporaries_removed"].as_u64(), Some(2));
    assert!(err.contains("(4 of them by an earlier run)"), "{err}");
    assert!(
        err.contains("removed 2 temporary files left by killed runs"),
        "{err}"
    );
    assert!(!out.join(".spot.obj.qem-tmp-99999999-0").exists());
    assert!(out.join(&own).exists());
    std::fs::remove_file(out.join(&own)).unwrap();
    // Nothing was rewritten, and the report covers every input as the first one did.
    assert_eq!(files_under(&out), outputs);
    let again: Vec<_> = outputs.iter().map(|f| modified(&out.join(f))).collect();
    assert_eq!(again, times);
    assert_eq!(
        entries_without_timings(&report(2)),
        entries_without_timings(&report(1))
    );
    let resumed = json(&report(2))["inputs"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|e| e["resumed"] == true)
        .count();
    assert_eq!(resumed, 4);

    // A changed input and a missing output run again; the rest is still done.
    write_path(&input.join("grid.ply"), &bumpy_grid(12, 7)).unwrap();
    std::fs::remove_file(out.join("spot.obj")).unwrap();
    let (third, _) = run(3, &["--resume"]);
    assert_eq!(third["resumed"].as_u64(), Some(2));
    assert_eq!(third["succeeded"].as_u64(), Some(4));
    assert!(out.join("spot.obj").is_file());
    // An output changed behind qem's back runs again too.
    std::fs::write(out.join("sub/grid.stl"), b"not what qem wrote").unwrap();
    let (fourth, _) = run(4, &["--resume"]);
    assert_eq!(fourth["resumed"].as_u64(), Some(3));
    assert!(read_path(&out.join("sub/grid.stl")).is_ok());
    // Other options: nothing counts as done.
    let (fifth, _) = run(5, &["--resume", "--ratio", "0.3"]);
    assert_eq!(fifth["resumed"].as_u64(), Some(0));
    // Without --resume everything runs.
    let (sixth, _) = run(6, &[]);
    assert_eq!(sixth["resumed"].as_u64(), Some(0));
    assert_eq!(sixth["succeeded"].as_u64(), Some(4));
}

/// Runs `qem` so that directory permissions apply to it. Root ignores them, so when
/// this test runs as root (a container) the child runs as `nobody` instead.
#[cfg(unix)]
fn qem_where_permissions_apply(args: &[&str]) -> std::process::Output {
    use std::os::unix::fs::PermissionsExt;
    use std::os::unix::process::CommandExt;
    let scratch = tempfile::tempdir().expect("a scratch directory");
    let probe = scratch.path().join("probe");
    std::fs::create_dir(&probe).expect("a probe directory");
    std::fs::set_permissions(&probe, std::fs::Permissions::from_mode(0o555))
        .expect("a read-only probe directory");
    let privileged = std::fs::write(probe.join("x"), b"").is_ok();
    let mut cmd = std::process::Command::new(env!("CARGO_BIN_EXE_qem"));
    cmd.args(args);
    if privileged {
        cmd.uid(65534).gid(65534);
    }
    cmd.output().expect("qem runs")
}

/// A read-only output directory is found before any work (one line, nothing written);
/// a read-only or blocked subdirectory fails its own inputs, one line each, and the
/// batch goes on with the rest.
#[cfg(unix)]
#[test]
fn unwritable_output_directories_fail_with_one_line_each() {
    use std::os::unix::fs::PermissionsExt;
    let mode = |p: &Path, m: u32| {
        std::fs::set_permissions(p, std::fs::Permissions::from_mode(m)).unwrap();
    };
    let dir = tempfile::tempdir().unwrap();
    mode(dir.path(), 0o777);
    let input = dir.path().join("in");
    std::fs::create_dir_all(input.join("locked")).unwrap();
    std::fs::create_dir_all(input.join("blocked")).unwrap();
    write_path(&input.join("a.ply"), &bumpy_grid(6, 0)).unwrap();
    write_path(&input.join("locked/b.ply"), &bumpy_grid(6, 1)).unwrap();
    write_path(&input.join("blocked/c.ply"), &bumpy_grid(6, 2)).unwrap();
    for d in [&input, &input.join("locked"), &input.join("blocked")] {
        mode(d, 0o755);
    }

    // The whole output directory is read-only.
    let out = dir.path().join("read-only");
    std::fs::create_dir(&out).unwrap();
    mode(&out, 0o555);
    let o = qem_where_permissions_apply(&["batch", s(&input), "--out-dir", s(&out)]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert_eq!(
        stderr(&o),
        format!(
            "qem: error: {}: cannot write (its directory is not writable): Permission denied \
             (os error 13); nothing was simplified\n",
            out.join(MANIFEST).display()
        )
    );
    assert_eq!(std::fs::read_dir(&out).unwrap().count(), 0);

    // A read-only subdirectory, and a file where a subdirectory should be (the output
    // path's directory cannot exist).
    let out = dir.path().join("out");
    std::fs::create_dir_all(out.join("locked")).unwrap();
    mode(&out, 0o777);
    mode(&out.join("locked"), 0o555);
    std::fs::write(out.join("blocked"), b"a file, not a directory").unwrap();
    let o = qem_where_permissions_apply(&["batch", s(&input), "--out-dir", s(&out), "-j", "1"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let err = stderr(&o);
    let lines: Vec<&str> = err.lines().collect();
    assert_eq!(lines.len(), 3, "{err}");
    assert!(
        lines[0].starts_with(&format!(
            "qem: error: {}: cannot create the directory {}: ",
            out.join("blocked/c.ply").display(),
            out.join("blocked").display()
        )),
        "{err}"
    );
    assert_eq!(
        lines[1],
        format!(
            "qem: error: {}: cannot write (its directory is not writable): Permission denied \
             (os error 13)",
            out.join("locked/b.ply").display()
        )
    );
    assert!(lines[2].contains("1 of 3 files simplified"), "{err}");
    assert_eq!(
        files_under(&out),
        vec![PathBuf::from("a.ply"), PathBuf::from("blocked")]
    );
    assert_eq!(std::fs::read_dir(out.join("locked")).unwrap().count(), 0);
}

/// `--memory-budget` applies to each file as `qem simplify --memory-budget` does (the
/// same bytes), tiles only the file that does not fit, leaves no tiles behind, and
/// counts in `--resume`'s fingerprint.
#[test]
fn a_memory_budget_applies_to_each_file_as_in_qem_simplify() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in");
    std::fs::create_dir_all(&input).unwrap();
    // 80,000 triangles, which 8 MB over the fixed 32 MiB do not hold in core, and 288.
    write_path(&input.join("big.ply"), &bumpy_grid(200, 1)).unwrap();
    write_path(&input.join("small.ply"), &bumpy_grid(12, 2)).unwrap();
    let budget = format!("{}", (32 << 20) + 8_000_000);
    let out = dir.path().join("out");
    let report = |n: u32| dir.path().join(format!("r{n}.json"));
    let batch = |n: u32, extra: &[&str]| {
        let r = report(n);
        let mut args = vec![
            "batch",
            s(&input),
            "--out-dir",
            s(&out),
            "--ratio",
            "0.02",
            "-j",
            "2",
            "--report",
            s(&r),
        ];
        args.extend_from_slice(extra);
        let o = qem(&args);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        json(&r)
    };
    let first = batch(1, &["--memory-budget", &budget]);
    let entries = first["inputs"].as_array().unwrap();
    let rounds = |name: &str| {
        let entry = entries
            .iter()
            .find(|e| e["input"].as_str().unwrap().ends_with(name))
            .unwrap();
        entry["memory_budget"]["rounds"].as_array().unwrap().len()
    };
    assert_eq!((rounds("big.ply"), rounds("small.ply")), (1, 0), "{first}");
    // No tiles left in the output directory (the default scratch).
    assert_eq!(
        files_under(&out),
        vec![PathBuf::from("big.ply"), PathBuf::from("small.ply")]
    );
    for name in ["big.ply", "small.ply"] {
        let alone = dir.path().join(format!("alone-{name}"));
        let o = qem(&[
            "simplify",
            s(&input.join(name)),
            "-o",
            s(&alone),
            "--ratio",
            "0.02",
            "--memory-budget",
            &budget,
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        assert!(
            std::fs::read(&alone).unwrap() == std::fs::read(out.join(name)).unwrap(),
            "{name} differs from qem simplify's"
        );
    }
    let same = batch(2, &["--memory-budget", &budget, "--resume"]);
    assert_eq!(same["summary"]["resumed"], 2);
    let other = batch(3, &["--memory-budget", "4G", "--resume"]);
    assert_eq!(other["summary"]["resumed"], 0);
    let none = batch(4, &["--resume"]);
    assert_eq!(none["summary"]["resumed"], 0);
}
