//! `qem measure A B`: Metro-style distance between two mesh files, and the error of
//! the attribute channels they share.

use crate::failure::print_stdout;
use clap::Args;
use qem_mesh::attributes::{Channel, ChannelKind};
use qem_mesh::io::{read_path, write_path_commented, Format};
use qem_mesh::measure::{
    measure, measure_attributes, vertex_distances, ChannelError, MeasureError, MeasureOptions,
    Measurement, Which,
};
use qem_mesh::IndexedMesh;
use serde::Serialize;
use std::path::{Path, PathBuf};

/// Arguments of `qem measure`.
#[derive(Args, Debug)]
pub struct MeasureArgs {
    /// The reference mesh (distances are fractions of its bounding-box diagonal).
    pub a: PathBuf,
    /// The mesh compared with it (e.g. the simplified one).
    pub b: PathBuf,
    /// Print the figures as one JSON object on stdout (fractions of the diagonal).
    #[arg(long)]
    pub json: bool,
    /// Area-uniform face samples per triangle of the sampled mesh.
    #[arg(long, default_value_t = MeasureOptions::DEFAULT.samples_per_face, value_parser = parse_samples_per_face)]
    pub samples_per_face: f64,
    /// At least this many face samples in each direction.
    #[arg(long, default_value_t = MeasureOptions::DEFAULT.min_samples)]
    pub min_samples: u64,
    /// At most this many face samples in each direction [default: no cap].
    #[arg(long)]
    pub max_samples: Option<u64>,
    /// Seed of the sampling; the same seed gives the same figures to the bit.
    #[arg(long, default_value_t = MeasureOptions::DEFAULT.seed)]
    pub seed: u64,
    /// Also write B coloured by each vertex's distance to A (blue: 0, red: the largest),
    /// with the scale in the file's comments and on stderr; the format follows the
    /// extension (.ply or .off hold vertex colours).
    #[arg(long, value_name = "OUT")]
    pub heatmap: Option<PathBuf>,
}

/// A colour for `t` in 0..=1: blue, cyan, green, yellow, red (four linear steps).
fn heat(t: f64) -> [f32; 3] {
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        1.0
    };
    let stops = [
        [0.0, 0.0, 1.0],
        [0.0, 1.0, 1.0],
        [0.0, 1.0, 0.0],
        [1.0, 1.0, 0.0],
        [1.0, 0.0, 0.0],
    ];
    let x = t * 4.0;
    let i = (x.floor() as usize).min(3);
    let f = x - i as f64;
    // On the 0–255 levels, so that PLY holds them as `uchar` (what every viewer reads).
    std::array::from_fn(|k| {
        let c = stops[i][k] * (1.0 - f) + stops[i + 1][k] * f;
        ((c * 255.0).round() / 255.0) as f32
    })
}

/// Writes the heat map of `b` against `a` to `out` (see [`MeasureArgs::heatmap`]).
fn write_heatmap(
    args: &MeasureArgs,
    a: &IndexedMesh,
    b: &IndexedMesh,
    out: &Path,
) -> Result<(), String> {
    let format = Format::from_path(out).map_err(|e| format!("{}: {e}", out.display()))?;
    if !matches!(format, Format::Ply | Format::Off) {
        return Err(format!(
            "{}: a heat map needs a format with vertex colours: use .ply or .off",
            out.display()
        ));
    }
    let distances = vertex_distances(a, b).map_err(|e| e.to_string())?;
    let largest = distances.iter().copied().fold(0.0, f64::max);
    let values = distances
        .iter()
        .flat_map(|&d| heat(if largest > 0.0 { d / largest } else { 0.0 }))
        .collect();
    let mut map = IndexedMesh::new(b.positions.clone(), b.triangles.clone());
    map.attributes.channels.push(Channel::new(
        ChannelKind::Color,
        values,
        b.triangles.clone(),
    ));
    let diagonal = a.bounding_box().map_or(0.0, |(lo, hi)| {
        (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt()
    });
    let scale = format!(
        "heat map of {} against {}: vertex colour = distance to A, blue 0 to red {:.6}% of \
         A's bounding-box diagonal ({} model units)",
        args.b.display(),
        args.a.display(),
        100.0 * largest,
        largest * diagonal
    );
    write_path_commented(out, &map, std::slice::from_ref(&scale)).map_err(|e| e.to_string())?;
    eprintln!("{}: {scale}", out.display());
    Ok(())
}

fn parse_samples_per_face(s: &str) -> Result<f64, String> {
    let v: f64 = s.parse().map_err(|_| format!("`{s}` is not a number"))?;
    if v >= 0.0 && v.is_finite() {
        Ok(v)
    } else {
        Err(format!("{v} must be a finite number ≥ 0"))
    }
}

/// The JSON object `qem measure --json` prints.
#[derive(Serialize)]
struct MeasureJson<'a> {
    a: &'a Path,
    b: &'a Path,
    /// What every distance below is a fraction of.
    units: &'static str,
    hausdorff: f64,
    hausdorff_ab: f64,
    hausdorff_ba: f64,
    mean_ab: f64,
    mean_ba: f64,
    rms_ab: f64,
    rms_ba: f64,
    samples_ab: u64,
    samples_ba: u64,
    /// A's bounding-box diagonal in model units.
    diagonal: f64,
    triangles_a: usize,
    triangles_b: usize,
    /// B's faces facing away from A's nearest triangle, and their share of B's area.
    faces_facing_away: u64,
    facing_away_area: f64,
    seed: u64,
    /// Per channel both meshes carry (by name): the difference between B's value and
    /// A's at the closest point, at B's face samples (UV units; degrees for normals).
    attributes: Vec<ChannelJson>,
}

/// One channel's error in `qem measure --json`.
#[derive(Serialize)]
struct ChannelJson {
    channel: String,
    /// `uv units`, `degrees` or `value units`.
    units: &'static str,
    samples: u64,
    rms: f64,
    mean: f64,
    p95: f64,
    max: f64,
}

/// The unit of a channel kind's differences.
fn unit(kind: ChannelKind) -> &'static str {
    match kind {
        ChannelKind::TexCoord => "uv units",
        ChannelKind::Normal => "degrees",
        ChannelKind::Color | ChannelKind::Generic => "value units",
    }
}

/// Runs `qem measure`; the error is the one-line message for stderr.
pub fn run(args: &MeasureArgs) -> Result<(), String> {
    let a = read_path(&args.a).map_err(|e| e.to_string())?.mesh;
    let b = read_path(&args.b).map_err(|e| e.to_string())?.mesh;
    let options = MeasureOptions {
        samples_per_face: args.samples_per_face,
        min_samples: args.min_samples,
        max_samples: args.max_samples,
        seed: args.seed,
    };
    let m = measure(&a, &b, &options).map_err(|e| match &e {
        MeasureError::Invalid { mesh: Which::B, .. } => format!("{}: {e}", args.b.display()),
        _ => format!("{}: {e}", args.a.display()),
    })?;
    // Both meshes passed validation above, so only the options could be refused.
    let channels = measure_attributes(&a, &b, &options).map_err(|e| e.to_string())?;
    if let Some(out) = &args.heatmap {
        write_heatmap(args, &a, &b, out)?;
    }
    if args.json {
        let json = MeasureJson {
            a: &args.a,
            b: &args.b,
            units: "fraction of A's bounding-box diagonal",
            hausdorff: m.hausdorff,
            hausdorff_ab: m.hausdorff_ab,
            hausdorff_ba: m.hausdorff_ba,
            mean_ab: m.mean_ab,
            mean_ba: m.mean_ba,
            rms_ab: m.rms_ab,
            rms_ba: m.rms_ba,
            samples_ab: m.samples_ab,
            samples_ba: m.samples_ba,
            diagonal: m.diagonal,
            triangles_a: a.triangle_count(),
            triangles_b: b.triangle_count(),
            faces_facing_away: m.faces_facing_away,
            facing_away_area: m.facing_away_area,
            seed: args.seed,
            attributes: channels
                .iter()
                .map(|c| ChannelJson {
                    channel: c.channel.clone(),
                    units: unit(c.kind),
                    samples: c.samples,
                    rms: c.rms,
                    mean: c.mean,
                    p95: c.p95,
                    max: c.max,
                })
                .collect(),
        };
        let text = serde_json::to_string_pretty(&json).map_err(|e| format!("JSON: {e}"))?;
        print_stdout(&format!("{text}\n"))
    } else {
        print_stdout(&human(
            args,
            &m,
            a.triangle_count(),
            b.triangle_count(),
            &channels,
        ))
    }
}

/// One line per figure, distances in % of A's diagonal.
fn human(
    args: &MeasureArgs,
    m: &Measurement,
    tris_a: usize,
    tris_b: usize,
    channels: &[ChannelError],
) -> String {
    let pct = |v: f64| format!("{:.6} % of diagonal", 100.0 * v);
    let mut s = String::new();
    s += &format!("A: {} ({tris_a} triangles)\n", args.a.display());
    s += &format!("B: {} ({tris_b} triangles)\n", args.b.display());
    s += &format!("diagonal of A:  {} (model units)\n", m.diagonal);
    s += &format!("Hausdorff:      {}\n", pct(m.hausdorff));
    s += &format!("Hausdorff A→B:  {}\n", pct(m.hausdorff_ab));
    s += &format!("Hausdorff B→A:  {}\n", pct(m.hausdorff_ba));
    s += &format!("mean A→B:       {}\n", pct(m.mean_ab));
    s += &format!("mean B→A:       {}\n", pct(m.mean_ba));
    s += &format!("RMS A→B:        {}\n", pct(m.rms_ab));
    s += &format!("RMS B→A:        {}\n", pct(m.rms_ba));
    s += &format!(
        "facing away:    {} faces of B ({:.4} % of its area)\n",
        m.faces_facing_away,
        100.0 * m.facing_away_area
    );
    s += &format!(
        "samples:        {} on A, {} on B (seed {})\n",
        m.samples_ab, m.samples_ba, args.seed
    );
    for c in channels {
        s += &format!(
            "{}: p95 {:.6}, mean {:.6}, RMS {:.6}, max {:.6} ({}; {} samples on B)\n",
            c.channel,
            c.p95,
            c.mean,
            c.rms,
            c.max,
            unit(c.kind),
            c.samples
        );
    }
    s
}
