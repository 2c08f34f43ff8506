//! `qem batch`: many files, in parallel, into one output directory, with one report.
//!
//! Every file is simplified on its own (the library call is deterministic), so the
//! outputs do not depend on `-j`; the report lists the inputs sorted by path. One bad
//! file never stops the others: it is reported with its cause and the run goes on.
//!
//! Each completed file is recorded in a manifest beside the outputs ([`crate::manifest`])
//! as soon as its output is in place, so `--resume` after a crash, a kill or a full
//! disk skips what is done and runs the rest; the report covers every input either
//! way. Temporary files that killed runs left in the output directories are removed
//! first ([`qem_mesh::io::remove_stale_temporaries`]).

use crate::failure::Failure;
use crate::inputs::{expand, output_path, Input};
use crate::manifest::{fingerprint, InputStamp, Manifest, Record};
use crate::options::SimplifyFlags;
use crate::progress::{bars_wanted, batch_bar, interrupted, CtrlCObserver};
use crate::report::{write_json_atomically, BatchEntry, BatchJson, BatchSummary, SimplifyJson};
use crate::simplify_cmd::{parse_size, simplify_file, MemoryBudget};
use clap::{Args, ValueEnum};
use qem_mesh::io::Format;
use qem_mesh::simplify::SimplifyOptions;
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

/// Output formats for `--format`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum FormatArg {
    /// Wavefront OBJ (text, coordinates round-trip exactly).
    Obj,
    /// PLY, binary little-endian with double coordinates.
    Ply,
    /// STL, binary (float32 coordinates).
    Stl,
    /// OFF (text).
    Off,
    /// glTF 2.0 JSON with its buffer embedded (float32 coordinates).
    Gltf,
    /// glTF 2.0 binary (GLB, float32 coordinates).
    Glb,
}

impl From<FormatArg> for Format {
    fn from(f: FormatArg) -> Format {
        match f {
            FormatArg::Obj => Format::Obj,
            FormatArg::Ply => Format::Ply,
            FormatArg::Stl => Format::Stl,
            FormatArg::Off => Format::Off,
            FormatArg::Gltf => Format::Gltf,
            FormatArg::Glb => Format::Glb,
        }
    }
}

/// Arguments of `qem batch`.
#[derive(Args, Debug)]
pub struct BatchArgs {
    /// Input files, directories (walked recursively for .obj .ply .stl .off .gltf .glb,
    /// optionally .gz) or glob patterns such as 'scans/**/*.ply' (quote them so qem expands them).
    #[arg(required = true, value_name = "INPUT")]
    pub inputs: Vec<PathBuf>,
    /// Output directory (created if missing). Each output keeps its input's path
    /// relative to the directory or pattern it was found in (a file named directly:
    /// its file name), with the extension of the output format.
    #[arg(long, value_name = "DIR")]
    pub out_dir: PathBuf,
    #[command(flatten)]
    pub flags: SimplifyFlags,
    /// Files simplified at the same time, one per thread [default: the number of
    /// cores].
    #[arg(short = 'j', long = "jobs", value_name = "N",
          value_parser = clap::value_parser!(u16).range(1..))]
    pub jobs: Option<u16>,
    /// Output format [default: each input's own format; a .gz input is written
    /// uncompressed].
    #[arg(long, value_enum)]
    pub format: Option<FormatArg>,
    /// Write a JSON report here: one entry per input (the `qem simplify` report, or
    /// `input`, `output` and `error`), the ignored files, and a summary [default: no
    /// report].
    #[arg(long, value_name = "REPORT.json")]
    pub report: Option<PathBuf>,
    /// Skip inputs that an earlier run with the same options completed: their output
    /// exists and matches the manifest in the output directory (size and CRC-32), and
    /// the input's size and modification time are unchanged. The rest run; the report
    /// covers every input [default: off, every input runs].
    #[arg(long)]
    pub resume: bool,
    /// Each file's run holds about this much memory at most, as with `qem simplify
    /// --memory-budget` (a file whose in-core run would need more goes through tiles
    /// in a temporary directory). Per file, so that the outputs do not depend on -j:
    /// the whole batch holds up to -j times as much. A size in bytes, or with K, M, G
    /// or T (powers of 1024), e.g. 500M, 4G [default: no budget].
    #[arg(long, value_name = "SIZE", value_parser = parse_size)]
    pub memory_budget: Option<u64>,
    /// Where --memory-budget makes each file's temporary directory of tiles (removed
    /// at the end of the file) [default: the output directory].
    #[arg(long, value_name = "DIR", requires = "memory_budget")]
    pub scratch: Option<PathBuf>,
    /// No progress bar and no summary line; failures are still printed [default: off].
    #[arg(short, long)]
    pub quiet: bool,
}

/// How one task ended.
enum Outcome {
    /// Simplified and written by this run.
    Done(Box<SimplifyJson>),
    /// Completed by an earlier run (`--resume`): its report.
    Resumed(serde_json::Value),
    /// Failed: the one-line message.
    Failed(String),
}

/// One input with where its output goes, or why it cannot be run.
struct Task {
    input: String,
    path: Option<PathBuf>,
    output: Option<PathBuf>,
    refused: Option<String>,
}

impl Task {
    /// Bytes on disk (compressed size for .gz), 0 when unknown: the scheduling key.
    fn file_size(&self) -> u64 {
        self.path
            .as_ref()
            .and_then(|p| std::fs::metadata(p).ok())
            .map_or(0, |m| m.len())
    }
}

/// Runs `qem batch`.
pub fn run(args: &BatchArgs) -> Result<(), Failure> {
    let jobs = args.jobs.map_or_else(
        || std::thread::available_parallelism().map_or(1, |n| n.get()),
        usize::from,
    );
    let found = expand(&args.inputs, &args.out_dir);
    let tasks = plan(
        &found.inputs,
        &found.failures,
        &args.out_dir,
        args.format.map(Format::from),
    );
    std::fs::create_dir_all(&args.out_dir).map_err(|e| {
        Failure::Failed(format!(
            "{}: cannot create the output directory: {e}",
            args.out_dir.display()
        ))
    })?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(jobs)
        .build()
        .map_err(|e| Failure::Failed(format!("cannot start {jobs} worker threads: {e}")))?;

    let options = args.flags.options()?;
    let format = args.format.map(Format::from);
    let budget = args.memory_budget.map(|bytes| MemoryBudget {
        bytes,
        scratch: args.scratch.clone().unwrap_or_else(|| args.out_dir.clone()),
    });
    // A budget can change an output (a file that does not fit is tiled): a run with
    // another budget is not the work done. Without one, the fingerprints of earlier
    // runs stay valid.
    let fingerprint = match &budget {
        None => fingerprint(&options, &format),
        Some(budget) => fingerprint(&(&options, budget.bytes), &format),
    };
    let stale = remove_stale(&args.out_dir, &tasks);
    // No manifest when nothing can run (every input refused): the output directory is
    // then left as it was.
    let manifest = match tasks.iter().any(|t| t.refused.is_none()) {
        true => Some(Manifest::open(&args.out_dir, args.resume).map_err(Failure::Failed)?),
        false => None,
    };
    // One warning for the whole run: every later append would fail the same way.
    let manifest_warning: std::sync::Mutex<Option<String>> = std::sync::Mutex::new(None);
    let bar = batch_bar(bars_wanted(args.quiet), tasks.len());
    let failed_so_far = AtomicUsize::new(0);
    let clock = Instant::now();
    // Largest files first (longest-processing-time-first scheduling), so one big mesh
    // does not start last and run alone. Every worker takes the next file of that list
    // from a shared counter (a slice split in halves would start the second worker in
    // the middle of the list instead). Results go back to sorted order below, and each
    // file's output does not depend on when or where it ran.
    let mut order: Vec<usize> = (0..tasks.len()).collect();
    let sizes: Vec<u64> = tasks.iter().map(Task::file_size).collect();
    order.sort_by(|&a, &b| sizes[b].cmp(&sizes[a]).then(a.cmp(&b)));
    let next = AtomicUsize::new(0);
    let per_worker: Vec<Vec<(usize, Outcome)>> = pool.broadcast(|_| {
        let mut done = Vec::new();
        while let Some(&i) = order.get(next.fetch_add(1, Ordering::Relaxed)) {
            let task = &tasks[i];
            let (outcome, warning) = run_recorded(
                task,
                &options,
                budget.as_ref(),
                &fingerprint,
                args.resume,
                manifest.as_ref(),
            );
            if let Some(warning) = warning {
                let mut slot = manifest_warning.lock().unwrap_or_else(|p| p.into_inner());
                slot.get_or_insert(warning);
            }
            if let Outcome::Failed(_) = outcome {
                let n = failed_so_far.fetch_add(1, Ordering::Relaxed) + 1;
                bar.set_message(format!("{n} failed"));
            }
            bar.inc(1);
            done.push((i, outcome));
        }
        done
    });
    let mut results: Vec<Option<Outcome>> = (0..tasks.len()).map(|_| None).collect();
    for (i, outcome) in per_worker.into_iter().flatten() {
        results[i] = Some(outcome);
    }
    let wall = clock.elapsed();
    bar.finish_and_clear();

    let stopped = interrupted();
    let mut entries = Vec::with_capacity(tasks.len());
    let mut failures = Vec::new();
    let (mut triangles_in, mut triangles_out, mut resumed, mut simplified_in) = (0, 0, 0, 0);
    for (task, result) in tasks.iter().zip(results) {
        let result = result
            .unwrap_or_else(|| Outcome::Failed(format!("{}: was not run (a bug)", task.input)));
        match result {
            Outcome::Done(json) => {
                triangles_in += json.triangles_in();
                simplified_in += json.triangles_in();
                triangles_out += json.triangles_out();
                entries.push(BatchEntry::Done(json));
            }
            Outcome::Resumed(mut json) => {
                let count = |key: &str| json[key].as_u64().unwrap_or(0) as usize;
                triangles_in += count("triangles_in");
                triangles_out += count("triangles_out");
                resumed += 1;
                if let Some(map) = json.as_object_mut() {
                    map.insert("resumed".into(), serde_json::Value::Bool(true));
                }
                entries.push(BatchEntry::Resumed(json));
            }
            Outcome::Failed(error) => {
                failures.push(error.clone());
                entries.push(BatchEntry::Failed {
                    input: task.input.clone(),
                    output: task.output.as_ref().map(|o| o.display().to_string()),
                    error,
                });
            }
        }
    }
    let succeeded = tasks.len() - failures.len();
    let seconds = wall.as_secs_f64();
    let summary = BatchSummary {
        inputs: tasks.len(),
        succeeded,
        resumed,
        failed: failures.len(),
        interrupted: stopped,
        jobs,
        stale_temporaries_removed: stale,
        triangles_in,
        triangles_out,
        wall_ms: seconds * 1e3,
        input_triangles_per_second: if seconds > 0.0 {
            simplified_in as f64 / seconds
        } else {
            0.0
        },
    };
    for line in &failures {
        eprintln!("qem: error: {line}");
    }
    let manifest_warning = manifest_warning
        .into_inner()
        .unwrap_or_else(|p| p.into_inner());
    if let Some(warning) = &manifest_warning {
        eprintln!("qem: warning: {warning}");
    }
    if !args.quiet {
        if stale > 0 {
            eprintln!(
                "qem: removed {stale} temporary {} left by killed runs",
                if stale == 1 { "file" } else { "files" }
            );
        }
        let earlier = if resumed > 0 {
            format!(" ({resumed} of them by an earlier run)")
        } else {
            String::new()
        };
        eprintln!(
            "qem: {succeeded} of {} files simplified into {}{earlier}, {} failed; \
             {triangles_in} → {triangles_out} triangles in {seconds:.2} s ({:.0} input \
             triangles/s, {jobs} jobs)",
            tasks.len(),
            args.out_dir.display(),
            failures.len(),
            summary.input_triangles_per_second,
        );
        if !found.ignored.is_empty() {
            let n = found.ignored.len();
            eprintln!(
                "qem: ignored {n} {} not a mesh format (listed in the report)",
                if n == 1 {
                    "file that is"
                } else {
                    "files that are"
                }
            );
        }
    }
    if let Some(path) = &args.report {
        let json = BatchJson {
            inputs: entries,
            ignored: found
                .ignored
                .iter()
                .map(|p| p.display().to_string())
                .collect(),
            summary,
        };
        write_json_atomically(path, &json).map_err(Failure::Failed)?;
    }
    if stopped {
        Err(Failure::Interrupted)
    } else if failures.is_empty() {
        Ok(())
    } else {
        Err(Failure::Reported)
    }
}

/// Pairs every input with its output, refusing inputs whose outputs would collide, and
/// merges in the arguments that failed to expand; sorted by input path.
fn plan(
    inputs: &[Input],
    failures: &[(String, String)],
    out_dir: &Path,
    format: Option<Format>,
) -> Vec<Task> {
    let outputs: Vec<Option<PathBuf>> = inputs
        .iter()
        .map(|i| output_path(i, out_dir, format))
        .collect();
    // Output path → the inputs that would write it (BTreeMap: no hash order).
    let mut writers: BTreeMap<&Path, Vec<&Path>> = BTreeMap::new();
    for (input, output) in inputs.iter().zip(&outputs) {
        if let Some(o) = output {
            writers.entry(o.as_path()).or_default().push(&input.path);
        }
    }
    let mut tasks: Vec<Task> = inputs
        .iter()
        .zip(&outputs)
        .map(|(input, output)| {
            let overwrites_input = output.as_deref().is_some_and(|o| {
                o.canonicalize()
                    .ok()
                    .is_some_and(|c| input.path.canonicalize().ok() == Some(c))
            });
            let refused = output.as_deref().and_then(|o| {
                if overwrites_input {
                    return Some(format!(
                        "{}: its output would overwrite it; choose another --out-dir",
                        input.path.display()
                    ));
                }
                let others: Vec<String> = writers[o]
                    .iter()
                    .filter(|p| **p != input.path)
                    .map(|p| p.display().to_string())
                    .collect();
                (!others.is_empty()).then(|| {
                    format!(
                        "{}: its output {} would also be written from {}; nothing was written \
                         for either, rename one of them or run them separately",
                        input.path.display(),
                        o.display(),
                        others.join(", ")
                    )
                })
            });
            Task {
                input: input.path.display().to_string(),
                path: Some(input.path.clone()),
                output: output.clone(),
                refused,
            }
        })
        .collect();
    tasks.extend(failures.iter().map(|(input, cause)| Task {
        input: input.clone(),
        path: None,
        output: None,
        refused: Some(format!("{input}: {cause}")),
    }));
    tasks.sort_by(|a, b| a.input.cmp(&b.input));
    tasks
}

/// Removes the temporary files of killed runs from the output directory and every
/// existing directory an output goes to; returns how many. A directory that cannot be
/// listed is left alone: writing there will say what is wrong.
fn remove_stale(out_dir: &Path, tasks: &[Task]) -> usize {
    let mut dirs: BTreeSet<&Path> = BTreeSet::from([out_dir]);
    dirs.extend(tasks.iter().filter_map(|t| t.output.as_deref()?.parent()));
    dirs.iter()
        .filter_map(|d| qem_mesh::io::remove_stale_temporaries(d).ok())
        .map(|removed| removed.len())
        .sum()
}

/// Runs one task unless `--resume` finds it complete, and records a success in the
/// manifest; with the outcome, the warning when recording it failed.
fn run_recorded(
    task: &Task,
    options: &SimplifyOptions,
    budget: Option<&MemoryBudget>,
    fingerprint: &str,
    resume: bool,
    manifest: Option<&Manifest>,
) -> (Outcome, Option<String>) {
    // The stamp is taken before the input is read: an input changed while it is being
    // simplified then no longer matches its record, and a later resume runs it again.
    let stamp = task.path.as_deref().and_then(InputStamp::of);
    if let (true, Some(output), Some(m)) =
        (resume && task.refused.is_none(), &task.output, manifest)
    {
        if let Some(record) = m.completed(&task.input, stamp, output, fingerprint) {
            return (Outcome::Resumed(record.report.clone()), None);
        }
    }
    let json = match run_task(task, options, budget) {
        Ok(json) => json,
        Err(e) => return (Outcome::Failed(e), None),
    };
    let (Some(stamp), Some(output), Some(manifest)) = (stamp, &task.output, manifest) else {
        return (Outcome::Done(Box::new(json)), None);
    };
    let report = serde_json::to_value(&json).unwrap_or_default();
    let recorded = Record::new(task.input.clone(), stamp, output, fingerprint, report)
        .ok_or_else(|| format!("{}: cannot read back to record it", output.display()))
        .and_then(|record| manifest.append(&record));
    (Outcome::Done(Box::new(json)), recorded.err())
}

/// Simplifies one input (within `budget`, when given); the error is the one-line
/// message.
fn run_task(
    task: &Task,
    options: &SimplifyOptions,
    budget: Option<&MemoryBudget>,
) -> Result<SimplifyJson, String> {
    if let Some(refused) = &task.refused {
        return Err(refused.clone());
    }
    let Some(path) = &task.path else {
        return Err(format!("{}: nothing to read", task.input));
    };
    if interrupted() {
        return Err(format!(
            "{}: not started, the run was interrupted (Ctrl-C)",
            task.input
        ));
    }
    // No output name means the input's extension names no format qem reads.
    let output = match (&task.output, Format::from_path(path)) {
        (Some(o), _) => o.clone(),
        (None, Err(e)) => return Err(format!("{}: {e}", task.input)),
        (None, Ok(_)) => return Err(format!("{}: no output name", task.input)),
    };
    simplify_file(path, &output, options, &mut CtrlCObserver, true, budget).map_err(|f| match f {
        Failure::Failed(m) | Failure::Usage(m) => m,
        Failure::Interrupted => format!(
            "{}: interrupted (Ctrl-C); nothing was written for it",
            task.input
        ),
        Failure::Reported => format!("{}: failed", task.input),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn input(path: &str, relative: &str) -> Input {
        Input {
            path: PathBuf::from(path),
            relative: PathBuf::from(relative),
        }
    }

    #[test]
    fn colliding_outputs_are_refused_for_every_writer() {
        let inputs = [
            input("d/a.obj", "a.obj"),
            input("d/a.ply", "a.ply"),
            input("d/b.ply", "b.ply"),
        ];
        let tasks = plan(&inputs, &[], Path::new("out"), Some(Format::Obj));
        assert_eq!(tasks.len(), 3);
        assert!(tasks[0].refused.as_deref().unwrap().contains("d/a.ply"));
        assert!(tasks[1].refused.as_deref().unwrap().contains("d/a.obj"));
        assert!(tasks[2].refused.is_none());
        // Without --format each keeps its own extension: no collision.
        let tasks = plan(&inputs, &[], Path::new("out"), None);
        assert!(tasks.iter().all(|t| t.refused.is_none()));
    }

    #[test]
    fn expansion_failures_are_sorted_in() {
        let inputs = [input("b.obj", "b.obj")];
        let failures = [("a.obj".to_string(), "no such file".to_string())];
        let tasks = plan(&inputs, &failures, Path::new("out"), None);
        assert_eq!(tasks[0].input, "a.obj");
        assert_eq!(tasks[0].refused.as_deref(), Some("a.obj: no such file"));
        assert_eq!(tasks[1].input, "b.obj");
    }
}
