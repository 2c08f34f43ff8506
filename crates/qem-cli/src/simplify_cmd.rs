//! `qem simplify`: one file in, one simplified file (or a chain of levels of detail)
//! out, an optional JSON report.

use crate::failure::Failure;
use crate::materials::{copy_beside, MaterialFilesJson};
use crate::options::{parse_ratio, SimplifyFlags};
use crate::progress::{bars_wanted, interrupted, simplify_bar, BarObserver};
use crate::report::{
    write_json_atomically, AttributesJson, LevelJson, LevelsJson, MemoryBudgetJson, SimplifyJson,
};
use crate::tiles_cmd::refused;
use clap::Args;
use qem_mesh::io::{read_path, write_path, Format, ReadNotes};
use qem_mesh::simplify::{
    simplify_levels_owned, simplify_owned, Observer, Simplified, SimplifyError, SimplifyOptions,
    StopReason, Target,
};
use qem_mesh::tiles::budget::{simplify_file_within, BudgetError};
use qem_mesh::tiles::jobs::TilesError;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// The placeholder in `-o` that `--lods` replaces with the level's index.
pub const LOD_PLACEHOLDER: &str = "{lod}";

/// Arguments of `qem simplify`.
#[derive(Args, Debug)]
pub struct SimplifyArgs {
    /// Input mesh (.obj .ply .stl .off .gltf .glb, optionally .gz).
    pub input: PathBuf,
    /// Output mesh; the format follows the extension (.obj .ply .stl .off .gltf .glb,
    /// optionally .gz). With --lods it must contain {lod}, which becomes the level's index
    /// (0, 1, 2, ... in the order of --lods).
    #[arg(short, long)]
    pub output: PathBuf,
    #[command(flatten)]
    pub flags: SimplifyFlags,
    /// Levels of detail from one run, as fractions of the input's triangles, largest
    /// first, comma-separated (e.g. 0.5,0.25,0.125). Each level continues from the
    /// previous one, so level i+1 is a simplification of level i [default: off].
    #[arg(
        long,
        value_delimiter = ',',
        value_parser = parse_ratio,
        conflicts_with_all = ["ratio", "triangles"],
    )]
    pub lods: Vec<f64>,
    /// Write a JSON report of the run here (with --lods: one entry per level)
    /// [default: no report].
    #[arg(long, value_name = "REPORT.json")]
    pub report: Option<PathBuf>,
    /// Hold about this much memory at most: an input whose in-core run would need more
    /// is cut into tiles in a temporary directory, each simplified with its border
    /// locked, the tiles merged and the merged mesh finished in one piece (attributes
    /// are then dropped). A size in bytes, or with K, M, G or T (powers of 1024), e.g.
    /// 500M, 4G [default: no budget].
    #[arg(long, value_name = "SIZE", value_parser = parse_size, conflicts_with = "lods")]
    pub memory_budget: Option<u64>,
    /// Where --memory-budget makes its temporary directory of tiles (removed at the
    /// end) [default: the output's directory].
    #[arg(long, value_name = "DIR", requires = "memory_budget")]
    pub scratch: Option<PathBuf>,
    /// No progress bar and no summary line; errors are still printed [default: off].
    #[arg(short, long)]
    pub quiet: bool,
}

/// A memory budget for `qem simplify` and where its tiles go.
#[derive(Clone, Debug)]
pub struct MemoryBudget {
    /// The budget in bytes.
    pub bytes: u64,
    /// The directory the temporary tile directory is made in.
    pub scratch: PathBuf,
}

/// Parses a size: a whole number of bytes, or a number with K, M, G or T (powers of
/// 1024; a trailing B or iB is allowed: 4G, 4GB and 4GiB are the same).
pub fn parse_size(s: &str) -> Result<u64, String> {
    let t = s.trim();
    let t = t
        .strip_suffix("iB")
        .or_else(|| t.strip_suffix('B'))
        .unwrap_or(t);
    let (number, scale) = match t.char_indices().last() {
        Some((i, c)) if c.is_ascii_alphabetic() => {
            let power = match c.to_ascii_uppercase() {
                'K' => 1,
                'M' => 2,
                'G' => 3,
                'T' => 4,
                _ => return Err(format!("{s}: the unit must be K, M, G or T")),
            };
            (&t[..i], 1024f64.powi(power))
        }
        _ => (t, 1.0),
    };
    let value: f64 = number
        .trim()
        .parse()
        .map_err(|_| format!("{s}: not a size (e.g. 500M, 4G, or a number of bytes)"))?;
    let bytes = value * scale;
    if bytes >= 2f64.powi(63) {
        return Err(format!("{s}: too large (at most 8 EiB)"));
    }
    if bytes.is_nan() || bytes < 1.0 {
        return Err(format!("{s}: a size must be at least one byte"));
    }
    Ok(bytes as u64)
}

/// Runs `qem simplify`.
pub fn run(args: &SimplifyArgs) -> Result<(), Failure> {
    if args.lods.is_empty() {
        run_single(args)
    } else {
        run_levels(args)
    }
}

fn run_single(args: &SimplifyArgs) -> Result<(), Failure> {
    if lossy(&args.output).contains(LOD_PLACEHOLDER) {
        return Err(Failure::Usage(format!(
            "{}: the output name contains {LOD_PLACEHOLDER} but --lods is not given; \
             add e.g. --lods 0.5,0.25 or remove {LOD_PLACEHOLDER}",
            args.output.display()
        )));
    }
    check_output_name(&args.output)?;
    remove_stale_beside(&args.output);
    let bar = simplify_bar(bars_wanted(args.quiet), &file_name(&args.input));
    let budget = args.memory_budget.map(|bytes| MemoryBudget {
        bytes,
        scratch: args
            .scratch
            .clone()
            .unwrap_or_else(|| directory_of(&args.output)),
    });
    let result = simplify_file(
        &args.input,
        &args.output,
        &args.flags.options()?,
        &mut BarObserver::new(&bar),
        false,
        budget.as_ref(),
    );
    bar.finish_and_clear();
    let json = result?;
    if !args.quiet {
        eprintln!("{}", json.summary_line());
    }
    if let Some(path) = &args.report {
        write_json_atomically(path, &json).map_err(Failure::Failed)?;
    }
    Ok(())
}

/// What the report says of the input as read.
struct InputRead {
    /// Its attributes' names.
    attributes: Vec<String>,
    /// Its triangles and vertices.
    counts: (usize, usize),
    notes: ReadNotes,
    /// The time reading it took.
    load: Duration,
}

/// The directory a file is in (`.` for a bare name).
fn directory_of(path: &Path) -> PathBuf {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// Loads `input`, simplifies it (within `budget`, when given) and writes `output`
/// atomically; the report names both. Nothing is written (and with `create_dirs`, no
/// missing directory of `output` is created) when loading or simplifying fails or
/// Ctrl-C stops the run.
pub fn simplify_file(
    input: &Path,
    output: &Path,
    options: &SimplifyOptions,
    observer: &mut dyn Observer,
    create_dirs: bool,
    budget: Option<&MemoryBudget>,
) -> Result<SimplifyJson, Failure> {
    let clock = Instant::now();
    let (result, budget_json, read) = match budget {
        None => {
            let (mesh, notes, load) = load(input)?;
            let read = InputRead {
                attributes: mesh.attributes.names(),
                counts: (mesh.triangle_count(), mesh.vertex_count()),
                notes,
                load,
            };
            // Handed over: the engine drops it once cleaned (see `simplify_owned`).
            let result =
                simplify_owned(mesh, options, observer).map_err(|e| simplify_failure(input, e))?;
            (result, None, read)
        }
        Some(budget) => {
            // Read by the budgeted run itself, so that a file too large to fit is
            // streamed into tiles rather than held.
            let run = simplify_file_within(input, options, budget.bytes, &budget.scratch, observer)
                .map_err(|e| budget_failure(input, e))?;
            let json = MemoryBudgetJson::new(&run.run);
            let read = InputRead {
                attributes: run.attributes,
                counts: (run.triangles_in, run.vertices_in),
                notes: run.notes,
                load: run.load,
            };
            (run.run.result, Some(json), read)
        }
    };
    let InputRead {
        attributes: input_attributes,
        counts: counts_in,
        notes,
        load,
    } = read;
    let simplify_time = clock.elapsed().saturating_sub(load);
    if result.report.stop_reason == StopReason::Cancelled || interrupted() {
        return Err(Failure::Interrupted);
    }
    if create_dirs {
        if let Some(dir) = output.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).map_err(|e| {
                Failure::Failed(format!(
                    "{}: cannot create the directory {}: {e}",
                    output.display(),
                    dir.display()
                ))
            })?;
        }
    }
    let write = write(output, &result)?;
    let json = SimplifyJson::new(
        input,
        output,
        &result.report,
        notes,
        load,
        simplify_time,
        write,
    )
    .with_attributes(attributes_of(
        input_attributes,
        &result,
        output,
        if budget_json.as_ref().is_some_and(MemoryBudgetJson::tiled) {
            "the tiles of --memory-budget keep positions only"
        } else {
            CLUSTERING_KEEPS_POSITIONS
        },
    ))
    .with_material_files(material_files_of(input, output, &result));
    Ok(match budget_json {
        Some(b) => json.with_memory_budget(b, counts_in),
        None => json,
    })
}

/// The failure of a run under a memory budget: as [`simplify_failure`], the tiles'
/// errors naming their file, the others the input.
fn budget_failure(input: &Path, e: BudgetError) -> Failure {
    match e {
        BudgetError::Simplify(e) => simplify_failure(input, e),
        BudgetError::Tiles(TilesError::Cancelled) => Failure::Interrupted,
        BudgetError::Tiles(TilesError::Refused(o)) => refused("qem simplify --memory-budget", o),
        e @ (BudgetError::Tiles(_) | BudgetError::Io(_)) => Failure::Failed(e.to_string()),
        e => Failure::Failed(format!("{}: {e}", input.display())),
    }
}

/// The files `result`'s material libraries name, copied beside `output` when it is an
/// OBJ (the only format that names them).
fn material_files_of(input: &Path, output: &Path, result: &Simplified) -> MaterialFilesJson {
    if Format::from_path(output).ok() != Some(Format::Obj) {
        return MaterialFilesJson::default();
    }
    copy_beside(input, output, &result.mesh.attributes.material_libraries)
}

/// Why an attribute the simplification did not keep is missing, without tiles.
const CLUSTERING_KEEPS_POSITIONS: &str = "vertex clustering keeps positions only";

/// What became of the input's attributes (`input`, as [`Attributes::names`](qem_mesh::attributes::Attributes::names) gives
/// them) in `result`, written to `output`; `lost` is why one the simplification did
/// not keep is missing.
fn attributes_of(
    input: Vec<String>,
    result: &Simplified,
    output: &Path,
    lost: &str,
) -> AttributesJson {
    // The output's name was checked before it was written, so it has a format.
    let format = Format::from_path(output).unwrap_or(Format::Obj);
    AttributesJson::new(input, &result.mesh.attributes, format, lost)
}

/// The failure of simplifying `input`: Ctrl-C pressed before the loop began is an
/// interruption (see `Observer::should_stop`), anything else an error naming the file.
fn simplify_failure(input: &Path, e: SimplifyError) -> Failure {
    match e {
        SimplifyError::Cancelled { .. } => Failure::Interrupted,
        e => Failure::Failed(format!("{}: {e}", input.display())),
    }
}

fn load(input: &Path) -> Result<(qem_mesh::IndexedMesh, ReadNotes, Duration), Failure> {
    let clock = Instant::now();
    let loaded = read_path(input).map_err(|e| Failure::Failed(e.to_string()))?;
    if interrupted() {
        return Err(Failure::Interrupted);
    }
    Ok((loaded.mesh, loaded.notes, clock.elapsed()))
}

fn write(output: &Path, result: &Simplified) -> Result<Duration, Failure> {
    let clock = Instant::now();
    write_path(output, &result.mesh).map_err(|e| Failure::Failed(e.to_string()))?;
    Ok(clock.elapsed())
}

fn run_levels(args: &SimplifyArgs) -> Result<(), Failure> {
    if let Some(w) = args.lods.windows(2).find(|w| w[1] >= w[0]) {
        return Err(Failure::Usage(format!(
            "--lods must decrease, but {} follows {}; list the levels largest first, \
             e.g. --lods 0.5,0.25,0.125",
            w[1], w[0]
        )));
    }
    let pattern = lossy(&args.output);
    if !pattern.contains(LOD_PLACEHOLDER) {
        return Err(Failure::Usage(format!(
            "{}: --lods writes one file per level, so the output name must contain \
             {LOD_PLACEHOLDER} (it becomes 0, 1, 2, ...); e.g. -o out_{LOD_PLACEHOLDER}.obj",
            args.output.display()
        )));
    }
    let outputs: Vec<PathBuf> = (0..args.lods.len())
        .map(|i| PathBuf::from(pattern.replace(LOD_PLACEHOLDER, &i.to_string())))
        .collect();
    for o in &outputs {
        check_output_name(o)?;
    }
    // `{lod}` may be in a directory name: each level's directory is cleaned.
    for o in &outputs {
        remove_stale_beside(o);
    }

    let bar = simplify_bar(bars_wanted(args.quiet), &file_name(&args.input));
    let result = (|| {
        let (mesh, notes, load) = load(&args.input)?;
        let input_attributes = mesh.attributes.names();
        let targets: Vec<Target> = args.lods.iter().map(|&r| Target::Ratio(r)).collect();
        let clock = Instant::now();
        let levels = simplify_levels_owned(
            mesh,
            &args.flags.options()?,
            &targets,
            &mut BarObserver::new(&bar),
        )
        .map_err(|e| simplify_failure(&args.input, e))?;
        Ok((input_attributes, levels, notes, load, clock.elapsed()))
    })();
    bar.finish_and_clear();
    let (input_attributes, levels, notes, load, simplify_time) = result?;
    if interrupted()
        || levels
            .iter()
            .any(|l| l.report.stop_reason == StopReason::Cancelled)
    {
        return Err(Failure::Interrupted);
    }

    let mut entries = Vec::with_capacity(levels.len());
    for (lod, ((level, output), &ratio)) in levels.iter().zip(&outputs).zip(&args.lods).enumerate()
    {
        if interrupted() {
            return Err(Failure::Interrupted);
        }
        let write = write(output, level)?;
        let run = SimplifyJson::new(
            &args.input,
            output,
            &level.report,
            notes,
            load,
            simplify_time,
            write,
        )
        .with_attributes(attributes_of(
            input_attributes.clone(),
            level,
            output,
            CLUSTERING_KEEPS_POSITIONS,
        ))
        .with_material_files(material_files_of(&args.input, output, level));
        if !args.quiet {
            eprintln!("level {lod} (ratio {ratio}): {}", run.summary_line());
        }
        entries.push(LevelJson { lod, ratio, run });
    }
    if let Some(path) = &args.report {
        let json = LevelsJson {
            input: args.input.display().to_string(),
            levels: entries,
        };
        write_json_atomically(path, &json).map_err(Failure::Failed)?;
    }
    Ok(())
}

/// Refuses an output name whose format qem cannot write, or whose directory does not
/// exist, before any work is done.
fn check_output_name(output: &Path) -> Result<(), Failure> {
    Format::from_path(output).map_err(|e| Failure::Failed(format!("{}: {e}", output.display())))?;
    match output.parent() {
        Some(dir) if !dir.as_os_str().is_empty() && !dir.is_dir() => Err(Failure::Failed(format!(
            "{}: the directory {} does not exist; create it first (e.g. mkdir -p {})",
            output.display(),
            dir.display(),
            dir.display()
        ))),
        _ => Ok(()),
    }
}

/// Removes the temporary files killed runs left beside `output` (see
/// [`qem_mesh::io::remove_stale_temporaries`]). Best effort: a directory that cannot be
/// listed will fail the write with a clearer message.
fn remove_stale_beside(output: &Path) {
    let dir = match output.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let _ = qem_mesh::io::remove_stale_temporaries(dir);
}

fn lossy(p: &Path) -> String {
    p.as_os_str().to_string_lossy().into_owned()
}

fn file_name(p: &Path) -> String {
    p.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| p.display().to_string())
}

#[cfg(test)]
mod tests {
    use super::*;
    use qem_mesh::simplify::Phase;

    #[test]
    fn sizes_parse_in_bytes_and_powers_of_1024() {
        assert_eq!(parse_size("1000"), Ok(1000));
        assert_eq!(parse_size("500M"), Ok(500 << 20));
        assert_eq!(parse_size("4G"), Ok(4 << 30));
        assert_eq!(parse_size("4GB"), Ok(4 << 30));
        assert_eq!(parse_size("4GiB"), Ok(4 << 30));
        assert_eq!(parse_size("1.5k"), Ok(1536));
        assert_eq!(parse_size(" 2T "), Ok(2 << 40));
        for bad in ["", "M", "4X", "-1G", "0", "NaN", "0.5"] {
            assert!(parse_size(bad).is_err(), "{bad}");
        }
        assert!(parse_size("1e30T").unwrap_err().contains("too large"));
    }

    /// Asks to stop as soon as the cleaning ends, as Ctrl-C pressed then would.
    struct StopAfterCleaning(bool);

    impl Observer for StopAfterCleaning {
        fn phase(&mut self, phase: Phase) {
            self.0 |= phase == Phase::Cleaning;
        }
        fn should_stop(&mut self) -> bool {
            self.0
        }
    }

    /// A stop before the loop is an interruption (exit 130), not an error naming the
    /// file, and no output is written.
    #[test]
    fn a_stop_before_the_loop_is_an_interruption_and_writes_nothing() {
        let dir = tempfile::tempdir().expect("a temporary directory");
        let input = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/spot.obj");
        let output = dir.path().join("out.ply");
        let result = simplify_file(
            &input,
            &output,
            &SimplifyOptions::DEFAULT,
            &mut StopAfterCleaning(false),
            false,
            None,
        );
        assert!(matches!(result, Err(Failure::Interrupted)), "{result:?}");
        assert!(!output.exists());
    }
}
