//! qem with attributes against meshoptimizer's `simplifyWithUpdate` with the same
//! channels and weights, in one process (issue 29's comparison).
//!
//! Each input is read (OBJ, PLY, OFF), cleaned once by `qem_mesh::clean` with its
//! default passes, and its first texture-coordinate and first normal channel are kept
//! (the others dropped). Both tools get that mesh: qem as it is (wedges), meshopt split
//! at the seams into one vertex per distinct (position, uv, normal)
//! (`qem_mesh::attributes::split_at_seams`; meshoptimizer finds seams itself from
//! vertices that share a position), with the attributes as floats per vertex and the
//! same weights (uv 1, normal 0.5 by default: qem's defaults). Each gets the target
//! `floor(ratio × cleaned triangles)`:
//! - qem: `simplify` with `SimplifyOptions::DEFAULT`, `Target::Triangles(target)` and
//!   the weights; also without the attributes (positions only), for the geometric
//!   figures' comparison;
//! - meshopt: `meshopt::simplify_with_update` (meshoptimizer 1.x's `simplifyWithUpdate`,
//!   which moves vertices and updates their attributes) with the target index count, no
//!   options, target error `f32::MAX`; its normals are renormalised afterwards (as qem's
//!   are).
//!
//! Every output is measured against the cleaned input by `qem_mesh::measure` (mean
//! A→B and the symmetric Hausdorff distance, % of the diagonal) and
//! `measure_attributes` (95th percentile of the uv difference in uv units and of the
//! normal angle in degrees, at the output's face samples). Times are the median of
//! `--runs` runs of each call, the tools taking turns.
//!
//! ```text
//! cargo bench -p qem-bench --bench attributes -- --ratios 0.5,0.1,0.01 --runs 3 \
//!     [--input FILE]... [--uv-weight 0.3] [--normal-weight 0.15] [--endpoints]
//! ```
//! `--endpoints` places qem's merged vertex at an end or the midpoint (for both of its
//! runs) instead of the optimum. Without `--input`, the corpus's attributed meshes (`$QEM_CORPUS` or
//! `../shared/corpus`; skipped with a message when absent).

use qem_mesh::attributes::{split_at_seams, Attributes, Channel, ChannelKind};
use qem_mesh::clean::{clean, CleanOptions};
use qem_mesh::measure::{measure, measure_attributes, MeasureOptions};
use qem_mesh::simplify::{simplify, AttributeWeights, PlacementMode, SimplifyOptions, Target};
use qem_mesh::IndexedMesh;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

/// The corpus's meshes with texture coordinates (manifest `has_uv`).
const CORPUS_MESHES: &[&str] = &[
    "tm_fuze.obj",
    "asp_wuson.obj",
    "c3d_spot.obj",
    "pymeshlab_bunny10k_textured.obj",
    "c3d_beast.obj",
];

struct Args {
    inputs: Vec<PathBuf>,
    ratios: Vec<f64>,
    runs: usize,
    uv_weight: f32,
    normal_weight: f32,
    /// `--endpoints`: qem places the merged vertex at an end or the midpoint.
    endpoints: bool,
}

fn parse_args() -> Result<Args, String> {
    let mut args = Args {
        inputs: Vec::new(),
        ratios: vec![0.5, 0.1, 0.01],
        runs: 3,
        uv_weight: AttributeWeights::DEFAULT.uv as f32,
        normal_weight: AttributeWeights::DEFAULT.normal as f32,
        endpoints: false,
    };
    let mut it = std::env::args().skip(1);
    while let Some(a) = it.next() {
        let mut value = || it.next().ok_or(format!("{a} needs a value"));
        match a.as_str() {
            "--input" => args.inputs.push(PathBuf::from(value()?)),
            "--ratios" => {
                args.ratios = value()?
                    .split(',')
                    .map(|r| r.parse().map_err(|_| format!("bad ratio {r}")))
                    .collect::<Result<_, _>>()?
            }
            "--runs" => args.runs = value()?.parse().map_err(|_| "bad --runs".to_string())?,
            "--uv-weight" => args.uv_weight = value()?.parse().map_err(|_| "bad weight")?,
            "--normal-weight" => args.normal_weight = value()?.parse().map_err(|_| "bad weight")?,
            "--endpoints" => args.endpoints = true,
            "--bench" => {}
            other => return Err(format!("unknown argument {other}")),
        }
    }
    if args.inputs.is_empty() {
        let dir = std::env::var_os("QEM_CORPUS").map_or_else(
            || PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../shared/corpus"),
            PathBuf::from,
        );
        for name in CORPUS_MESHES {
            match [dir.join(name), dir.join("public").join(name)]
                .into_iter()
                .find(|p| p.is_file())
            {
                Some(p) => args.inputs.push(p),
                None => eprintln!("SKIPPED: {name} is not in {}", dir.display()),
            }
        }
    }
    Ok(args)
}

/// The cleaned mesh with only its first uv and first normal channel.
fn prepared(path: &Path) -> Result<IndexedMesh, String> {
    let raw = qem_mesh::io::read_path(path)
        .map_err(|e| e.to_string())?
        .mesh;
    let mut mesh = clean(&raw, &CleanOptions::DEFAULT).mesh;
    let mut kept = Vec::new();
    for kind in [ChannelKind::TexCoord, ChannelKind::Normal] {
        if let Some(c) = mesh.attributes.channel(kind) {
            kept.push(c.clone());
        }
    }
    // Corners without a value cannot be given to meshopt (it needs one per vertex).
    kept.retain(|c| c.corners.iter().flatten().all(|&i| i != Channel::MISSING));
    mesh.attributes = Attributes::default();
    mesh.attributes.channels = kept;
    Ok(mesh)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// meshopt's run on the split mesh: the output as a mesh with per-vertex channels.
fn meshopt_run(split: &IndexedMesh, weights: &[f32], target: usize) -> (IndexedMesh, f64) {
    let channels = &split.attributes.channels;
    let stride: usize = channels.iter().map(|c| c.dimension).sum();
    let mut positions: Vec<[f32; 3]> = split
        .positions
        .iter()
        .map(|p| p.map(|x| x as f32))
        .collect();
    let mut attrs = Vec::with_capacity(positions.len() * stride);
    for v in 0..positions.len() as u32 {
        for c in channels {
            attrs.extend_from_slice(c.value(v));
        }
    }
    let mut indices: Vec<u32> = split.triangles.iter().flatten().copied().collect();
    let clock = Instant::now();
    let count = meshopt::simplify_with_update(
        &mut indices,
        &mut positions,
        &mut attrs,
        weights,
        stride * 4,
        None,
        target * 3,
        f32::MAX,
        meshopt::SimplifyOptions::None,
        None,
    );
    let time = clock.elapsed().as_secs_f64();
    indices.truncate(count);
    let triangles: Vec<[u32; 3]> = indices
        .chunks_exact(3)
        .map(|t| [t[0], t[1], t[2]])
        .collect();
    let mut out_channels = Vec::new();
    let mut offset = 0;
    for c in channels {
        let mut values = Vec::with_capacity(positions.len() * c.dimension);
        for v in 0..positions.len() {
            let x = &attrs[v * stride + offset..v * stride + offset + c.dimension];
            if c.kind == ChannelKind::Normal {
                let l = x
                    .iter()
                    .map(|a| a * a)
                    .sum::<f32>()
                    .sqrt()
                    .max(f32::MIN_POSITIVE);
                values.extend(x.iter().map(|a| a / l));
            } else {
                values.extend_from_slice(x);
            }
        }
        offset += c.dimension;
        out_channels
            .push(Channel::new(c.kind, values, triangles.clone()).with_dimension(c.dimension));
    }
    let mut mesh = IndexedMesh::new(
        positions.iter().map(|p| p.map(f64::from)).collect(),
        triangles,
    );
    mesh.attributes.channels = out_channels;
    (mesh, time)
}

/// `mean_ab` and Hausdorff (% of the diagonal), and the p95 of uv and normal.
fn figures(reference: &IndexedMesh, out: &IndexedMesh) -> Result<String, String> {
    let options = MeasureOptions::DEFAULT;
    let m = measure(reference, out, &options).map_err(|e| e.to_string())?;
    let attrs = measure_attributes(reference, out, &options).map_err(|e| e.to_string())?;
    let p95 = |kind: ChannelKind| {
        attrs
            .iter()
            .find(|c| c.kind == kind)
            .map_or("-".to_string(), |c| format!("{:.4}", c.p95))
    };
    Ok(format!(
        "{:>8.4} {:>8.4} {:>8} {:>8}",
        100.0 * m.mean_ab,
        100.0 * m.hausdorff,
        p95(ChannelKind::TexCoord),
        p95(ChannelKind::Normal)
    ))
}

fn run() -> Result<(), String> {
    let args = parse_args()?;
    let weights_qem = AttributeWeights::DEFAULT
        .with(ChannelKind::TexCoord, f64::from(args.uv_weight))
        .with(ChannelKind::Normal, f64::from(args.normal_weight));
    println!(
        "{:<34} {:>5} {:>7} {:<12} {:>7} {:>9} {:>8} {:>8} {:>8} {:>8}",
        "mesh", "ratio", "target", "tool", "tris", "ms", "mean%", "haus%", "uv p95", "nrm p95"
    );
    for path in &args.inputs {
        let name = path
            .file_name()
            .map_or(String::new(), |n| n.to_string_lossy().into_owned());
        let mesh = prepared(path)?;
        let split = split_at_seams(&mesh);
        let weights: Vec<f32> = split
            .attributes
            .channels
            .iter()
            .flat_map(|c| {
                let w = if c.kind == ChannelKind::Normal {
                    args.normal_weight
                } else {
                    args.uv_weight
                };
                std::iter::repeat_n(w, c.dimension)
            })
            .collect();
        let positions_only = IndexedMesh::new(mesh.positions.clone(), mesh.triangles.clone());
        for &ratio in &args.ratios {
            let target = (ratio * mesh.triangle_count() as f64).floor() as usize;
            let mut options = SimplifyOptions::DEFAULT
                .with_target(Target::Triangles(target))
                .with_attribute_weights(weights_qem);
            if args.endpoints {
                options = options.with_placement(PlacementMode::EndpointOrMidpoint);
            }
            let (mut t_qem, mut t_plain, mut t_meshopt) = (Vec::new(), Vec::new(), Vec::new());
            let (mut qem_out, mut plain_out, mut meshopt_out) = (None, None, None);
            for _ in 0..args.runs.max(1) {
                let clock = Instant::now();
                let out = simplify(&mesh, &options).map_err(|e| e.to_string())?;
                t_qem.push(clock.elapsed().as_secs_f64());
                qem_out = Some(out.mesh);
                let clock = Instant::now();
                let out = simplify(&positions_only, &options).map_err(|e| e.to_string())?;
                t_plain.push(clock.elapsed().as_secs_f64());
                plain_out = Some(out.mesh);
                let (out, time) = meshopt_run(&split, &weights, target);
                t_meshopt.push(time);
                meshopt_out = Some(out);
            }
            for (tool, out, times) in [
                ("qem", qem_out, t_qem),
                ("qem no-attr", plain_out, t_plain),
                ("meshopt upd", meshopt_out, t_meshopt),
            ] {
                let Some(out) = out else { continue };
                println!(
                    "{:<34} {:>5} {:>7} {:<12} {:>7} {:>9.2} {}",
                    name,
                    ratio,
                    target,
                    tool,
                    out.triangle_count(),
                    1e3 * median(times),
                    figures(&mesh, &out)?
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
            eprintln!("attributes bench: {e}");
            ExitCode::FAILURE
        }
    }
}
