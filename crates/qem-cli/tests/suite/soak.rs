//! Soak test of `qem batch --resume` (issue 33): a batch over many files, some corrupt,
//! is killed with SIGKILL at random (seeded) moments several times and rerun with
//! `--resume` until it finishes. Then every good input has exactly one complete output,
//! identical bit for bit to a clean single run's, every bad input is reported once, the
//! report covers every input as the clean run's does, and no temporary file is left.
//!
//! `cargo test` runs a small size (30 generated files, 4 kills; a few seconds). The
//! large run is `#[ignore]`d and sized by the environment (FUZZING.md records it):
//!
//! ```sh
//! QEM_SOAK_FILES=500 QEM_SOAK_KILLS=10 cargo test -p qem-cli --test suite -- --ignored --nocapture soak::
//! ```
//!
//! It derives its files from the shared corpus (`$QEM_CORPUS` or `../shared/corpus`,
//! copied into a temporary directory, never into the repository) and skips with a
//! message when the corpus is absent. `QEM_SOAK_SEED` changes the kill moments and
//! which files are corrupted.

use crate::common;

use common::{bumpy_grid, corpus_dir, json, s};
use qem_mesh::io::{read_path, write_path};
use std::os::unix::process::ExitStatusExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

const MANIFEST: &str = ".qem-batch-manifest.jsonl";

/// SplitMix64: a few lines of seeded, reproducible randomness (no dependency).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `[lo, hi)`.
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
}

fn env_usize(name: &str, default: usize) -> usize {
    std::env::var(name)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

/// Every file under `dir`, relative to it, sorted.
fn files_under(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).expect("list a directory") {
            let p = e.expect("a directory entry").path();
            if p.is_dir() {
                stack.push(p);
            } else {
                out.push(p.strip_prefix(dir).expect("under dir").to_path_buf());
            }
        }
    }
    out.sort();
    out
}

/// Makes a mesh file corrupt for sure: an OBJ (which a cut at a line end could leave
/// valid) becomes a vertex with two coordinates; any other format is cut at a seeded
/// point in its first half, past its first bytes (their headers promise more).
fn corrupt(path: &Path, rng: &mut Rng) {
    let bytes = std::fs::read(path).expect("read back");
    let bad = if path.extension().is_some_and(|e| e == "obj") {
        b"v 1 2\nf 1 1 1\n".to_vec()
    } else {
        let cut = 16 + (rng.next() as usize) % (bytes.len() / 2);
        bytes[..cut].to_vec()
    };
    std::fs::write(path, bad).expect("write a corrupt input");
}

/// `n` small generated meshes in four formats (some gzipped, some in a subfolder);
/// every sixth is corrupt. Returns the corrupt ones' paths, sorted.
fn generated_inputs(dir: &Path, n: usize, rng: &mut Rng) -> Vec<String> {
    let mut bad = Vec::new();
    for i in 0..n {
        let broken = i % 6 == 5;
        let ext = match ["ply", "obj", "off", "stl", "obj.gz"][i % 5] {
            "obj.gz" if broken => "obj",
            ext => ext,
        };
        let sub = if i % 3 == 0 { "sub/" } else { "" };
        let path = dir.join(format!("{sub}m{i:03}.{ext}"));
        std::fs::create_dir_all(path.parent().expect("a parent")).expect("mkdir");
        write_path(&path, &bumpy_grid(8 + (i as u32 * 7) % 17, i as u32)).expect("write an input");
        if broken {
            corrupt(&path, rng);
            bad.push(path.display().to_string());
        }
    }
    bad.sort();
    bad
}

/// `n` files derived from the corpus's meshes of at most `max_triangles` triangles
/// (cycled, renamed, in four formats); every tenth is corrupt. `None` without a corpus.
fn corpus_inputs(dir: &Path, n: usize, rng: &mut Rng) -> Option<Vec<String>> {
    let corpus = corpus_dir()?;
    let manifest = std::fs::read_to_string(corpus.join("manifest.tsv")).expect("manifest");
    let max_triangles = env_usize("QEM_SOAK_MAX_TRIANGLES", 60_000);
    let mut meshes = Vec::new();
    for line in manifest.lines().skip(1) {
        let cols: Vec<&str> = line.split('\t').collect();
        let (Some(file), Some(tris)) = (cols.first(), cols.get(4)) else {
            continue;
        };
        let name = Path::new(file).file_name().expect("a file name");
        if tris.parse::<usize>().is_ok_and(|t| t <= max_triangles) {
            let loaded = read_path(&corpus.join(name)).expect("a corpus mesh reads");
            meshes.push((name.to_string_lossy().into_owned(), loaded.mesh));
        }
    }
    assert!(
        !meshes.is_empty(),
        "no corpus mesh under {max_triangles} triangles"
    );
    let mut bad = Vec::new();
    for i in 0..n {
        let (name, mesh) = &meshes[i % meshes.len()];
        let stem = name.trim_end_matches(".obj");
        let ext = ["obj", "ply", "off", "stl"][(i / meshes.len()) % 4];
        let path = dir.join(format!("{}/{i:03}_{stem}.{ext}", i % 7));
        std::fs::create_dir_all(path.parent().expect("a parent")).expect("mkdir");
        write_path(&path, mesh).expect("write an input");
        if i % 10 == 9 {
            corrupt(&path, rng);
            bad.push(path.display().to_string());
        }
    }
    bad.sort();
    Some(bad)
}

fn batch(input: &Path, out: &Path, report: &Path, resume: bool) -> Command {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_qem"));
    cmd.args([
        "batch",
        s(input),
        "--out-dir",
        s(out),
        "--report",
        s(report),
    ])
    .args(["--ratio", "0.3", "-j", "2", "-q"])
    .stdout(Stdio::null())
    .stderr(Stdio::null());
    if resume {
        cmd.arg("--resume");
    }
    cmd
}

/// The report's entries without what differs between runs.
fn entries(report: &Path, out_dir: &Path) -> Vec<serde_json::Value> {
    let mut entries = json(report)["inputs"]
        .as_array()
        .expect("the report lists inputs")
        .clone();
    for e in &mut entries {
        let e = e.as_object_mut().expect("an entry is an object");
        e.remove("timings_ms");
        e.remove("resumed");
        if let Some(o) = e.get_mut("output") {
            // The clean run wrote into another directory.
            let rel = o.as_str().map(|o| o.replace(s(out_dir), "OUT"));
            *o = rel.into();
        }
    }
    entries
}

/// The soak itself: a clean reference run, `kills` killed runs, a final run.
fn soak(input: &Path, work: &Path, bad: &[String], kills: usize, rng: &mut Rng) {
    let reference = work.join("reference");
    let ref_report = work.join("reference.json");
    let clock = Instant::now();
    let status = batch(input, &reference, &ref_report, false)
        .status()
        .expect("qem runs");
    let clean = clock.elapsed();
    assert_eq!(status.code(), Some(if bad.is_empty() { 0 } else { 1 }));

    let out = work.join("out");
    let report = work.join("out.json");
    let mut landed = 0;
    let good = files_under(input).len() - bad.len();
    for k in 0..kills {
        // A random moment within the first half of the time the work left should take
        // (the clean run's time scaled by the share of good inputs not yet in the
        // manifest), so that later kills land too instead of after a run that had
        // little left to do. (Up to 90% of it, the large run's kills landed 3 times in
        // 10: files differ in cost, so the estimate runs long.)
        let done = std::fs::read_to_string(out.join(MANIFEST))
            .map_or(0, |m| m.matches('\n').count().saturating_sub(1));
        let left = 1.0 - (done.min(good) as f64 / good.max(1) as f64);
        let delay =
            clean.mul_f64(left.max(0.02) * rng.uniform(0.05, 0.5)) + Duration::from_millis(5);
        let mut child = batch(input, &out, &report, true)
            .spawn()
            .expect("qem starts");
        std::thread::sleep(delay);
        // `Child::kill` is SIGKILL on Unix: no handler runs, nothing is cleaned up.
        child.kill().expect("send SIGKILL");
        let status = child.wait().expect("reap the child");
        let killed = status.signal() == Some(9);
        landed += usize::from(killed);
        eprintln!(
            "soak: kill {k} after {:.0} ms: {}",
            delay.as_secs_f64() * 1e3,
            if killed { "killed" } else { "had finished" }
        );
    }
    assert!(
        landed > 0,
        "no kill landed during a run; the soak tested nothing"
    );
    let clock = Instant::now();
    let status = batch(input, &out, &report, true)
        .status()
        .expect("qem runs");
    eprintln!(
        "soak: clean run {:.2} s, final resumed run {:.2} s, {landed} of {kills} kills landed",
        clean.as_secs_f64(),
        clock.elapsed().as_secs_f64()
    );
    assert_eq!(status.code(), Some(if bad.is_empty() { 0 } else { 1 }));

    // Exactly the clean run's files (so one output per good input, no temporary
    // file), each identical bit for bit.
    let files = files_under(&out);
    let leftovers: Vec<_> = files
        .iter()
        .filter(|f| f.to_string_lossy().contains(".qem-tmp-"))
        .collect();
    assert!(leftovers.is_empty(), "temporary files left: {leftovers:?}");
    assert_eq!(files, files_under(&reference));
    for f in &files {
        if f != Path::new(MANIFEST) {
            let same = std::fs::read(out.join(f)).ok() == std::fs::read(reference.join(f)).ok();
            assert!(same, "{} differs from the clean run's", f.display());
        }
    }
    // Every input once, bad ones with their error, the rest as in the clean run.
    let r = json(&report);
    let failed: Vec<String> = r["inputs"]
        .as_array()
        .expect("inputs")
        .iter()
        .filter(|e| e.get("error").is_some())
        .map(|e| e["input"].as_str().expect("a name").to_string())
        .collect();
    assert_eq!(failed, bad);
    assert_eq!(entries(&report, &out), entries(&ref_report, &reference));
    assert_eq!(r["summary"]["failed"].as_u64(), Some(bad.len() as u64));
}

#[test]
fn killed_batches_resume_to_the_clean_result() {
    let work = tempfile::tempdir().expect("a scratch directory");
    let input = work.path().join("in");
    let mut rng = Rng(env_usize("QEM_SOAK_SEED", 33) as u64);
    let bad = generated_inputs(&input, 30, &mut rng);
    assert_eq!(bad.len(), 5);
    soak(&input, work.path(), &bad, 4, &mut rng);
}

/// The large run (see the module docs): corpus-derived files, sized by
/// `QEM_SOAK_FILES` (default 500) and `QEM_SOAK_KILLS` (default 10).
#[test]
#[ignore = "minutes; run with --ignored, see the module docs"]
fn killed_batches_resume_to_the_clean_result_at_scale() {
    let work = tempfile::tempdir().expect("a scratch directory");
    let input = work.path().join("in");
    let mut rng = Rng(env_usize("QEM_SOAK_SEED", 33) as u64);
    let n = env_usize("QEM_SOAK_FILES", 500);
    let Some(bad) = corpus_inputs(&input, n, &mut rng) else {
        return;
    };
    soak(
        &input,
        work.path(),
        &bad,
        env_usize("QEM_SOAK_KILLS", 10),
        &mut rng,
    );
}
