//! qem against meshoptimizer, side by side, in one process.
//!
//! Each input is loaded once and welded once (bit-identical positions become one
//! vertex; faces that repeat a vertex, have zero area or repeat another face are
//! dropped, by `qem_mesh::clean` with its default passes), so both tools get the same
//! indexed mesh and the same target triangle count, `floor(ratio x welded triangles)`.
//! Each tool then runs several times on it, the two taking turns run by run, and the
//! median wall time is reported.
//!
//! - qem: `qem_mesh::simplify::simplify` with `SimplifyOptions::DEFAULT` (t = 0,
//!   optimal placement, area weighting) and `Target::Triangles(target)`. The timed call
//!   is the whole library call: validation, cleaning, the working mesh and its quadrics,
//!   the loop, compaction.
//!   With `--fast`, `SimplifyOptions::FAST` instead (summed quadrics, no orientation
//!   check, the solve's point), reported as `qem --fast`; `--orientation-check` and
//!   `--exact` (with `--fast`) turn on the orientation check and exact quadrics.
//!   `--greedy` runs the defaults in the greedy order (`qem --order greedy`; the
//!   default order is the pass-based one);
//!   `--cluster` runs `SimplifyOptions::CLUSTER` (vertex clustering; its phases print
//!   as setup = the grid's search, contract = the clustering) against
//!   `meshopt::simplify_sloppy`, reported as `meshopt sloppy`.
//! - meshopt: `meshopt::simplify` (meshoptimizer's `meshopt_simplify`, vendored by the
//!   `meshopt` crate) on `f32` positions, with the target index count, no options and
//!   a target error of `f32::MAX`, so that it stops on the count alone. Only the call is
//!   timed; its output indexes the input vertex buffer (no compaction).
//!
//! Wall time and CPU time (all threads, from `/proc`, Linux) are both reported: on a
//! loaded machine the CPU-time ratio is the steadier one. meshopt's C++ is built
//! without asserts (`NDEBUG`, see the meshopt profile override in the root
//! `Cargo.toml`), as it ships.
//!
//! Usage (arguments after `--`; every flag optional):
//!
//! ```text
//! cargo bench -p qem-bench --bench versus -- \
//!     --input dragon --input sphere:4M --input soup \
//!     --ratios 0.1,0.01 --runs 5 --tool both
//! ```
//!
//! Inputs: `dragon` (the corpus's 871k-triangle Stanford dragon), `soup` (the corpus's
//! PrusaSlicer MK4 gantry, a 50k-triangle binary STL soup with 117 parts), `sphere:N`
//! (the procedural noisy cube-sphere of about N triangles, built here; `N` may end in
//! `k` or `M`), or a mesh file path. The corpus is `$QEM_CORPUS` or `../shared/corpus`
//! next to the workspace; corpus inputs are skipped with a message when it is absent.
//!
//! `--write-input PATH` writes the one `--input` (as loaded or built; the format
//! follows the extension, `.ply` is binary) and times nothing: the procedural sphere
//! as a file, for runs of the `qem simplify` process and of other tools on it.
//!
//! `--tool qem`, `--tool meshopt` or `--tool none` (load and weld only) run one tool,
//! for peak-memory runs under `/usr/bin/time -v` on the bench binary
//! (`cargo bench -p qem-bench --bench versus --no-run` prints its path): the tool's
//! peak is the difference between its run and the `none` run. qem uses rayon's global
//! pool; `RAYON_NUM_THREADS=1` makes it single-threaded. `--tool prep` times qem's
//! cleaning of the raw (unwelded) input and the building of its store from the cleaned
//! mesh, the two phases before the quadrics, apart.

use qem_mesh::clean::{clean, CleanOptions};
use qem_mesh::simplify::{simplify, ContractionOrder, QuadricMode, SimplifyOptions, Target};
use qem_mesh::{IndexedMesh, MeshStore};
use std::collections::HashMap;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

/// Which tools a run times.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Tools {
    Both,
    Qem,
    Meshopt,
    /// Load and weld only: the memory baseline.
    None,
    /// qem's cleaning (of the raw input) and store building alone, timed apart.
    Prep,
}

impl Tools {
    fn qem(self) -> bool {
        matches!(self, Tools::Both | Tools::Qem)
    }
    fn meshopt(self) -> bool {
        matches!(self, Tools::Both | Tools::Meshopt)
    }
}

/// The command line.
#[derive(Debug)]
struct Args {
    inputs: Vec<String>,
    ratios: Vec<f64>,
    runs: usize,
    tools: Tools,
    /// qem runs with `SimplifyOptions::FAST` (the pass-based order) instead of
    /// `DEFAULT`.
    fast: bool,
    /// With `fast`, the orientation check on.
    orientation_check: bool,
    /// With `fast`, exact quadrics.
    exact: bool,
    /// The defaults in `ContractionOrder::Greedy` (not with `fast`).
    greedy: bool,
    /// qem's vertex clustering against `meshopt::simplify_sloppy`.
    cluster: bool,
    /// Write the one input, as loaded or built, to this file and time nothing (for
    /// runs of whole processes on the procedural sphere).
    write_input: Option<PathBuf>,
}

const USAGE: &str = "usage: versus [--input dragon|soup|sphere:N|PATH]... [--ratios R,R...] \
                     [--runs K] [--tool both|qem|meshopt|none|prep] [--fast [--orientation-check] [--exact] | --greedy | --cluster] \
                     | --input INPUT --write-input PATH";

fn parse_args() -> Result<Args, String> {
    let mut args = Args {
        inputs: Vec::new(),
        ratios: Vec::new(),
        runs: 5,
        tools: Tools::Both,
        fast: false,
        orientation_check: false,
        exact: false,
        greedy: false,
        cluster: false,
        write_input: None,
    };
    let mut it = std::env::args().skip(1);
    while let Some(flag) = it.next() {
        // `cargo bench` passes `--bench` to harness-less benches.
        if flag == "--bench" {
            continue;
        }
        let mut value = || it.next().ok_or(format!("{flag} needs a value\n{USAGE}"));
        match flag.as_str() {
            "--input" => args.inputs.push(value()?),
            "--ratios" => {
                for r in value()?.split(',') {
                    let r: f64 = r.parse().map_err(|e| format!("ratio {r:?}: {e}"))?;
                    if !(r > 0.0 && r <= 1.0) {
                        return Err(format!("ratio {r} is not in (0, 1]"));
                    }
                    args.ratios.push(r);
                }
            }
            "--runs" => {
                let v = value()?;
                args.runs = v.parse().map_err(|e| format!("runs {v:?}: {e}"))?;
                args.runs = args.runs.max(1);
            }
            "--tool" => {
                args.tools = match value()?.as_str() {
                    "both" => Tools::Both,
                    "qem" => Tools::Qem,
                    "meshopt" => Tools::Meshopt,
                    "none" => Tools::None,
                    "prep" => Tools::Prep,
                    other => return Err(format!("unknown tool {other:?}\n{USAGE}")),
                }
            }
            "--fast" => args.fast = true,
            "--orientation-check" => args.orientation_check = true,
            "--exact" => args.exact = true,
            "--greedy" => args.greedy = true,
            "--cluster" => args.cluster = true,
            "--write-input" => args.write_input = Some(PathBuf::from(value()?)),
            "-h" | "--help" => return Err(USAGE.to_string()),
            other => return Err(format!("unknown argument {other:?}\n{USAGE}")),
        }
    }
    if (args.orientation_check || args.exact) && !args.fast {
        return Err(format!(
            "--orientation-check and --exact need --fast\n{USAGE}"
        ));
    }
    if [args.greedy, args.fast, args.cluster]
        .iter()
        .filter(|&&x| x)
        .count()
        > 1
    {
        return Err(format!(
            "--greedy, --fast and --cluster exclude each other\n{USAGE}"
        ));
    }
    if args.write_input.is_some() && args.inputs.len() != 1 {
        return Err(format!("--write-input needs exactly one --input\n{USAGE}"));
    }
    if args.inputs.is_empty() {
        args.inputs = vec!["dragon".into(), "sphere:4M".into(), "soup".into()];
    }
    if args.ratios.is_empty() {
        args.ratios = vec![0.1, 0.01];
    }
    Ok(args)
}

fn corpus() -> PathBuf {
    std::env::var_os("QEM_CORPUS")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../shared/corpus"))
}

/// `"4M"` → 4,000,000; `"100k"` → 100,000.
fn parse_count(s: &str) -> Result<usize, String> {
    let (digits, scale) = match s.as_bytes().last() {
        Some(b'k' | b'K') => (&s[..s.len() - 1], 1_000.0),
        Some(b'M' | b'm') => (&s[..s.len() - 1], 1_000_000.0),
        _ => (s, 1.0),
    };
    let n: f64 = digits.parse().map_err(|e| format!("count {s:?}: {e}"))?;
    Ok((n * scale).round() as usize)
}

/// Loads (or builds) an input; `Ok(None)` when a corpus file is absent.
fn load(input: &str) -> Result<Option<IndexedMesh>, String> {
    if let Some(count) = input.strip_prefix("sphere:") {
        return Ok(Some(noisy_cube_sphere(parse_count(count)?)));
    }
    let path = match input {
        "dragon" => corpus().join("originals/stanford_dragon_vrip.ply.gz"),
        "soup" => corpus().join("originals/ps_mk4_gantry.stl.gz"),
        path => PathBuf::from(path),
    };
    if !path.exists() && matches!(input, "dragon" | "soup") {
        eprintln!("skipping {input}: {} is absent", path.display());
        return Ok(None);
    }
    qem_mesh::io::read_path(&path)
        .map(|loaded| Some(loaded.mesh))
        .map_err(|e| e.to_string())
}

/// A deterministic hash of a lattice point to `[-1, 1]` (SplitMix64's finaliser).
fn lattice_noise(p: [u32; 3]) -> f64 {
    let mut z = (u64::from(p[0]) << 42) ^ (u64::from(p[1]) << 21) ^ u64::from(p[2]);
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    (z >> 11) as f64 / (1u64 << 52) as f64 - 1.0
}

/// A closed, welded, noisy sphere of about `triangles` triangles (12·n², n ≥ 1).
///
/// The six faces of the cube `[0, n]³` are split into n×n squares of two triangles,
/// outward-facing; lattice points shared by two faces are one vertex. Each point is
/// projected to the sphere (with the area-evening "spherified cube" map) and pushed
/// radially by a smooth bump of 5% of the radius plus a per-point random offset of
/// 20% of the grid spacing, so the roughness relative to the resolution is the same
/// at every size.
fn noisy_cube_sphere(triangles: usize) -> IndexedMesh {
    let n = ((triangles as f64 / 12.0).sqrt().round() as u32).max(1);
    let spacing = std::f64::consts::FRAC_PI_2 / f64::from(n);
    let mut index: HashMap<[u32; 3], u32> = HashMap::new();
    let mut positions: Vec<[f64; 3]> = Vec::new();
    let mut vertex = |p: [u32; 3]| -> u32 {
        *index.entry(p).or_insert_with(|| {
            let c = p.map(|x| 2.0 * f64::from(x) / f64::from(n) - 1.0);
            let (x2, y2, z2) = (c[0] * c[0], c[1] * c[1], c[2] * c[2]);
            let s = [
                c[0] * (1.0 - y2 / 2.0 - z2 / 2.0 + y2 * z2 / 3.0).sqrt(),
                c[1] * (1.0 - z2 / 2.0 - x2 / 2.0 + z2 * x2 / 3.0).sqrt(),
                c[2] * (1.0 - x2 / 2.0 - y2 / 2.0 + x2 * y2 / 3.0).sqrt(),
            ];
            let bump = 0.05 * (5.0 * s[0]).sin() * (7.0 * s[1]).sin() * (3.0 * s[2]).sin();
            let r = 1.0 + bump + 0.2 * spacing * lattice_noise(p);
            positions.push(s.map(|x| r * x));
            (positions.len() - 1) as u32
        })
    };
    let mut faces = Vec::with_capacity(12 * (n as usize).pow(2));
    // Each face: the fixed axis and its value, and two in-face axes (u, v) ordered so
    // that u × v points outwards.
    for (axis, value, u, v) in [
        (0, n, 1, 2),
        (0, 0, 2, 1),
        (1, n, 2, 0),
        (1, 0, 0, 2),
        (2, n, 0, 1),
        (2, 0, 1, 0),
    ] {
        let point = |i: u32, j: u32| {
            let mut p = [0u32; 3];
            p[axis] = value;
            p[u] = i;
            p[v] = j;
            p
        };
        for j in 0..n {
            for i in 0..n {
                let a = vertex(point(i, j));
                let b = vertex(point(i + 1, j));
                let c = vertex(point(i + 1, j + 1));
                let d = vertex(point(i, j + 1));
                faces.push([a, b, c]);
                faces.push([a, c, d]);
            }
        }
    }
    IndexedMesh::new(positions, faces)
}

/// Median of a non-empty list of seconds.
fn median(times: &mut [f64]) -> f64 {
    times.sort_by(f64::total_cmp);
    let m = times.len() / 2;
    if times.len() % 2 == 1 {
        times[m]
    } else {
        (times[m - 1] + times[m]) / 2.0
    }
}

/// Median seconds (wall and CPU) and output triangle count of one tool.
struct Measured {
    seconds: f64,
    /// CPU time of the process (all threads), when the platform tells it.
    cpu_seconds: Option<f64>,
    triangles_out: usize,
}

/// CPU time consumed so far by all threads of this process, in seconds, from
/// `/proc/self/task/*/schedstat` (nanoseconds on the CPU; Linux only).
///
/// Why CPU time next to wall time: on a shared machine the wall time of a
/// single-threaded run grows with the load while its CPU time barely does, so the
/// CPU-time ratio of two tools stays meaningful when the wall-time ratio is noisy.
fn process_cpu_seconds() -> Option<f64> {
    let mut total_ns = 0u64;
    for task in std::fs::read_dir("/proc/self/task").ok()? {
        let stat = std::fs::read_to_string(task.ok()?.path().join("schedstat")).ok()?;
        total_ns += stat.split_whitespace().next()?.parse::<u64>().ok()?;
    }
    Some(total_ns as f64 * 1e-9)
}

/// Times `f` in wall and CPU seconds.
fn timed<T>(f: impl FnOnce() -> T) -> (T, f64, Option<f64>) {
    let cpu = process_cpu_seconds();
    let clock = Instant::now();
    let out = f();
    let wall = clock.elapsed().as_secs_f64();
    let cpu = process_cpu_seconds()
        .zip(cpu)
        .map(|(after, before)| after - before);
    (out, wall, cpu)
}

/// One tool's runs: wall and CPU seconds, and the output's triangle count.
#[derive(Default)]
struct Samples {
    wall: Vec<f64>,
    cpu: Vec<Option<f64>>,
    triangles_out: usize,
}

impl Samples {
    /// Adds one run's output triangle count, wall and CPU seconds.
    fn push(&mut self, (triangles_out, wall, cpu): (usize, f64, Option<f64>)) {
        self.wall.push(wall);
        self.cpu.push(cpu);
        self.triangles_out = triangles_out;
    }

    /// The medians, or `None` without runs.
    fn measured(mut self) -> Option<Measured> {
        if self.wall.is_empty() {
            return None;
        }
        let mut cpu: Option<Vec<f64>> = self.cpu.iter().copied().collect();
        Some(Measured {
            seconds: median(&mut self.wall),
            cpu_seconds: cpu.as_deref_mut().map(median),
            triangles_out: self.triangles_out,
        })
    }
}

/// qem's options for a run of the bench to `target` triangles.
fn qem_options(args: &Args, target: usize) -> SimplifyOptions {
    let base = if args.fast {
        SimplifyOptions::FAST
            .with_orientation_check(args.orientation_check)
            .with_quadrics(if args.exact {
                QuadricMode::Exact
            } else {
                QuadricMode::Sum
            })
    } else if args.cluster {
        SimplifyOptions::CLUSTER
    } else if args.greedy {
        SimplifyOptions::DEFAULT.with_order(ContractionOrder::Greedy)
    } else {
        SimplifyOptions::DEFAULT
    };
    base.with_target(Target::Triangles(target))
}

/// One timed qem run (number `run`, for the phase timings it prints): output triangle
/// count, wall and CPU seconds.
fn qem_once(
    mesh: &IndexedMesh,
    options: &SimplifyOptions,
    run: usize,
) -> Result<(usize, f64, Option<f64>), String> {
    let (out, wall, cpu) = timed(|| simplify(mesh, options));
    let out = out.map_err(|e| format!("qem: {e}"))?;
    let t = out.report.timings;
    eprintln!(
        "  qem run {run}: clean {:.3} s, setup {:.3} s, contract {:.3} s, \
         compact {:.3} s",
        t.clean.as_secs_f64(),
        t.setup.as_secs_f64(),
        t.contract.as_secs_f64(),
        t.compact.as_secs_f64()
    );
    let triangles_out = out.mesh.triangle_count();
    std::hint::black_box(out);
    Ok((triangles_out, wall, cpu))
}

/// One timed meshopt run: output triangle count, wall and CPU seconds.
fn meshopt_once(
    adapter: &meshopt::VertexDataAdapter,
    indices: &[u32],
    target: usize,
    sloppy: bool,
) -> (usize, f64, Option<f64>) {
    if sloppy {
        let (out, wall, cpu) =
            timed(|| meshopt::simplify_sloppy(indices, adapter, target * 3, f32::MAX, None));
        let triangles_out = out.len() / 3;
        std::hint::black_box(out);
        return (triangles_out, wall, cpu);
    }
    let (out, wall, cpu) = timed(|| {
        meshopt::simplify(
            indices,
            adapter,
            target * 3,
            f32::MAX,
            meshopt::SimplifyOptions::None,
            None,
        )
    });
    let triangles_out = out.len() / 3;
    std::hint::black_box(out);
    (triangles_out, wall, cpu)
}

/// Times `clean` on the raw input and `MeshStore::from_mesh` on its result.
fn time_prep(input: &str, raw: &IndexedMesh, runs: usize) -> Result<(), String> {
    let (mut clean_s, mut build_s) = (Vec::new(), Vec::new());
    for _ in 0..runs {
        let clock = Instant::now();
        let cleaned = clean(raw, &CleanOptions::DEFAULT);
        clean_s.push(clock.elapsed().as_secs_f64());
        let clock = Instant::now();
        let store = MeshStore::from_mesh(&cleaned.mesh).map_err(|e| e.to_string())?;
        build_s.push(clock.elapsed().as_secs_f64());
        std::hint::black_box((cleaned, store));
    }
    println!(
        "{input}: clean {:.3} s, build {:.3} s (medians of {runs})",
        median(&mut clean_s),
        median(&mut build_s)
    );
    Ok(())
}

fn run() -> Result<(), String> {
    let args = parse_args()?;
    if let Some(path) = &args.write_input {
        let input = &args.inputs[0];
        let mesh = load(input)?.ok_or(format!("{input} is absent"))?;
        qem_mesh::io::write_path(path, &mesh).map_err(|e| e.to_string())?;
        eprintln!(
            "{input}: {} triangles, {} vertices written to {}",
            mesh.triangle_count(),
            mesh.vertex_count(),
            path.display()
        );
        return Ok(());
    }
    let threads = std::env::var("RAYON_NUM_THREADS").unwrap_or_else(|_| "default".into());
    println!(
        "runs per figure: {} (median), RAYON_NUM_THREADS={threads}",
        args.runs
    );
    println!();
    println!(
        "| input | tris in (welded) | ratio | target | tool | median s | M input tris/s \
         | tris out | qem/meshopt | median CPU s | qem/meshopt (CPU) |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|");
    for input in &args.inputs {
        let clock = Instant::now();
        let Some(raw) = load(input)? else { continue };
        if args.tools == Tools::Prep {
            time_prep(input, &raw, args.runs)?;
            continue;
        }
        let welded = clean(&raw, &CleanOptions::DEFAULT).mesh;
        drop(raw);
        let positions: Vec<f32> = welded
            .positions
            .iter()
            .flat_map(|p| p.map(|c| c as f32))
            .collect();
        let indices: Vec<u32> = welded.triangles.iter().flatten().copied().collect();
        let bytes = meshopt::typed_to_bytes(&positions);
        let adapter = meshopt::VertexDataAdapter::new(bytes, 12, 0).map_err(|e| e.to_string())?;
        let n = welded.triangle_count();
        eprintln!(
            "{input}: {n} triangles, {} vertices after welding; loaded in {:.2} s",
            welded.vertex_count(),
            clock.elapsed().as_secs_f64()
        );
        for &ratio in &args.ratios {
            let target = (ratio * n as f64).floor() as usize;
            // The tools take turns, run by run, so that a drift in the machine's speed
            // (this one's wanders by 10% over minutes) falls on both.
            let options = qem_options(&args, target);
            let (mut qem, mut meshopt) = (Samples::default(), Samples::default());
            for run in 0..args.runs {
                if args.tools.qem() {
                    qem.push(qem_once(&welded, &options, run)?);
                }
                if args.tools.meshopt() {
                    meshopt.push(meshopt_once(&adapter, &indices, target, args.cluster));
                }
            }
            let (qem, meshopt) = (qem.measured(), meshopt.measured());
            let qem_name = match (args.fast, args.orientation_check, args.exact) {
                (false, ..) if args.cluster => "qem --cluster",
                (false, ..) if args.greedy => "qem --order greedy",
                (false, ..) => "qem",
                (true, false, false) => "qem --fast",
                (true, true, false) => "qem --fast --orientation-check",
                (true, false, true) => "qem --fast --exact",
                (true, true, true) => "qem --fast --exact --orientation-check",
            };
            let meshopt_name = if args.cluster {
                "meshopt sloppy"
            } else {
                "meshopt"
            };
            for (tool, m) in [(qem_name, &qem), (meshopt_name, &meshopt)] {
                let Some(m) = m else { continue };
                let (versus, versus_cpu) = match (tool, &meshopt) {
                    (name, Some(o)) if name == qem_name => (
                        format!("{:.2}", m.seconds / o.seconds),
                        m.cpu_seconds
                            .zip(o.cpu_seconds)
                            .map_or(String::new(), |(q, o)| format!("{:.2}", q / o)),
                    ),
                    _ => (String::new(), String::new()),
                };
                let cpu = m.cpu_seconds.map_or(String::new(), |c| format!("{c:.3}"));
                println!(
                    "| {input} | {n} | {ratio} | {target} | {tool} | {:.3} | {:.2} | {} | {versus} \
                     | {cpu} | {versus_cpu} |",
                    m.seconds,
                    n as f64 / m.seconds / 1e6,
                    m.triangles_out,
                );
            }
        }
    }
    Ok(())
}

fn main() -> ExitCode {
    match run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("versus: {e}");
            ExitCode::FAILURE
        }
    }
}
