//! The simplification options shared by `qem simplify` and `qem batch` (and any later
//! command that simplifies): one clap `Args` struct that each command flattens, so a
//! new option is added in one place.

use crate::failure::Failure;
use clap::{Args, ValueEnum};
use qem_mesh::attributes::ChannelKind;
use qem_mesh::simplify::{
    AttributeWeights, BoundaryMode, ContractionOrder, Length, Method, QuadricMode, SimplifyOptions,
    Target, VirtualPairs, Weighting, DEFAULT_BOUNDARY_WEIGHT, DEFAULT_MAX_NORMAL_ANGLE,
    DEFAULT_MIN_TRIANGLE_QUALITY,
};
use std::path::{Path, PathBuf};

/// The quadric a contracted pair gets (`--quadrics`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum QuadricsFlag {
    /// Garland–Heckbert's sum of the two quadrics (shared planes count twice).
    Sum,
    /// The quadric of the union of the two plane sets (every plane counts once).
    Exact,
}

/// In which order pairs are contracted (`--order`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum OrderFlag {
    /// Always the cheapest pair next, its neighbours re-costed (Garland–Heckbert's).
    Greedy,
    /// In passes: each costs every pair and contracts a batch of the cheapest, no two
    /// sharing a vertex (meshoptimizer's).
    Passes,
}

/// The default of `--weighting`, as written on the command line; a unit test checks
/// that it parses to the library's default.
pub const DEFAULT_WEIGHTING_FLAG: &str = "mixed:0.75";

/// Which unconnected vertex pairs may merge (`--virtual-pairs`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum VirtualPairsFlag {
    /// Any two close vertices that share no edge (also closes cracks inside a part).
    Any,
    /// Only vertices of different connected parts.
    BetweenParts,
}

/// How to simplify: target, error bound, virtual pairs, quality controls.
#[derive(Args, Debug, Clone)]
pub struct SimplifyFlags {
    /// Target as a fraction of the input's triangles (as loaded), in (0, 1], rounded to
    /// the nearest count and at least 1 [default: 0.5 when --triangles is not given].
    #[arg(long, conflicts_with = "triangles", value_parser = parse_ratio)]
    pub ratio: Option<f64>,
    /// Target as a triangle count [default: none, --ratio 0.5 applies].
    #[arg(long)]
    pub triangles: Option<usize>,
    /// Stop before the first contraction whose error would exceed this distance (with
    /// --fast: never contract a pair over it, stop when a pass finds only such pairs):
    /// a fraction of the input's bounding-box diagonal (0.001 = 0.1%), or model units
    /// with --absolute [default: no bound].
    #[arg(long, value_parser = parse_non_negative)]
    pub max_error: Option<f64>,
    /// Unconnected vertex pairs closer than this may merge (virtual pairs): a fraction
    /// of the bounding-box diagonal, or model units with --absolute; 0 = edges only.
    #[arg(long, default_value_t = 0.0, value_parser = parse_non_negative)]
    pub pair_threshold: f64,
    /// Read --max-error and --pair-threshold in model units instead of fractions of the
    /// bounding-box diagonal [default: off].
    #[arg(long)]
    pub absolute: bool,
    /// Which close unconnected pairs may merge when --pair-threshold is above 0.
    #[arg(long, value_enum, default_value_t = VirtualPairsFlag::Any)]
    pub virtual_pairs: VirtualPairsFlag,
    /// Weight of the constraint planes through border edges (perpendicular to the
    /// border's face), relative to the faces' own planes; 0 lets borders move freely,
    /// turns the loop rule off and drops the seams' planes (above 0, border loops are
    /// never pinched or closed unless the run is stuck: see --strict; seams keep
    /// planes of weight 1).
    #[arg(long, default_value_t = DEFAULT_BOUNDARY_WEIGHT, value_parser = parse_non_negative,
          conflicts_with = "lock_boundary")]
    pub boundary_weight: f64,
    /// Border vertices never move and are never removed: borders come out exactly as
    /// they went in [default: off].
    #[arg(long)]
    pub lock_boundary: bool,
    /// Refuse a contraction that turns a surviving face's normal by more than this many
    /// degrees (or leaves it more than 90° from the input face it descends from); 180
    /// turns the check off.
    #[arg(long, default_value_t = DEFAULT_MAX_NORMAL_ANGLE, value_parser = parse_non_negative)]
    pub max_normal_angle: f64,
    /// Refuse a contraction that leaves a face with a quality (4√3·area / sum of
    /// squared edge lengths: 1 equilateral, 0 degenerate) below this and below its
    /// quality before; 0 turns the check off.
    #[arg(long, default_value_t = DEFAULT_MIN_TRIANGLE_QUALITY, value_parser = parse_unit_interval)]
    pub min_quality: f64,
    /// Turn off the orientation check, which refuses a contraction that leaves a face
    /// facing away from the input surface nearest to its centroid (faster; on by
    /// default).
    #[arg(long)]
    pub no_orientation_check: bool,
    /// With --fast, keep the orientation check (which --fast turns off for speed):
    /// about 1.9 times as long, and at ratio 0.1 almost no face left facing away from
    /// the input.
    #[arg(long, requires = "fast", conflicts_with = "no_orientation_check")]
    pub orientation_check: bool,
    /// Keep the topology: only contractions that pass the link condition, none at
    /// non-manifold vertices or edges, no virtual pairs; Euler characteristic, parts and
    /// border loops are kept [default: off].
    #[arg(long)]
    pub preserve_topology: bool,
    /// Stop when no pair passes every check instead of relaxing them: without it, a
    /// run that gets stuck relaxes the fold-over rules, then the border-loop rule, then
    /// lets edge contractions merge faces, then lets faces turn away from their input
    /// faces, each only when the stricter rules have nothing left (the report's
    /// `relaxations`); what you asked for (--preserve-topology,
    /// --lock, --lock-boundary, --max-error) is never relaxed [default: off].
    #[arg(long)]
    pub strict: bool,
    /// Trade some accuracy for speed (about 2.5 times as fast as the defaults): summed
    /// quadrics (unless --quadrics exact), no orientation check (unless
    /// --orientation-check), and the 3x3 solve's point without comparing it with the
    /// segment's. Every other option works with it [default: off].
    #[arg(long)]
    pub fast: bool,
    /// Vertex clustering instead of pair contraction: one vertex per cell of a grid,
    /// at the cell's quadric optimum, the grid chosen to reach the target. Many times
    /// faster and never stuck on any input, but topology is not kept (parts merge,
    /// holes close) and the error is larger; only the target options apply
    /// [default: off].
    #[arg(long, conflicts_with_all = ["fast", "preserve_topology", "lock", "lock_boundary", "max_error", "order", "strict"])]
    pub cluster: bool,
    /// Quadric of a contracted pair [default: exact, or sum with --fast].
    #[arg(long, value_enum)]
    pub quadrics: Option<QuadricsFlag>,
    /// In which order pairs are contracted; every other option works in both
    /// (`--order greedy` takes about 2.5 times as long for the same accuracy on the
    /// corpus) [default: passes].
    #[arg(long, value_enum)]
    pub order: Option<OrderFlag>,
    /// How face planes are weighted in the quadrics: `area` (by triangle area),
    /// `unweighted` (weight 1 each) or `mixed:S` (area + S × the mean face area; S = 0
    /// is `area`, large S tends to `unweighted`).
    #[arg(long, value_name = "area|unweighted|mixed:S", value_parser = parse_weighting,
          default_value = DEFAULT_WEIGHTING_FLAG)]
    pub weighting: Weighting,
    /// A text file of vertex indices that must come out unmoved and present: one per
    /// line, 0-based, `#` starts a comment. Indices follow the vertex order as loaded:
    /// the file's order for PLY and OFF, three per facet for STL, and for OBJ the order
    /// in which faces first use them [default: none].
    #[arg(long, value_name = "FILE")]
    pub lock: Option<PathBuf>,
    /// How much texture coordinates, normals, colours and other channels weigh against
    /// positions, as `kind=weight` pairs separated by commas (kinds: uv, normal,
    /// colour, generic; the others keep their defaults); 0 leaves a channel out of the
    /// cost (its values still follow the vertices) [default: uv=0.3,normal=0.15,
    /// colour=1,generic=1].
    #[arg(long, value_name = "KIND=W,...", value_parser = parse_attribute_weights)]
    pub attribute_weights: Option<AttributeWeights>,
}

/// Parses `--attribute-weights`: `uv=1,normal=0.5`.
pub fn parse_attribute_weights(s: &str) -> Result<AttributeWeights, String> {
    let mut weights = AttributeWeights::DEFAULT;
    for part in s.split(',').map(str::trim).filter(|p| !p.is_empty()) {
        let (kind, value) = part
            .split_once('=')
            .ok_or_else(|| format!("`{part}` is not kind=weight (e.g. uv=0.5)"))?;
        let kind = match kind.trim() {
            "uv" => ChannelKind::TexCoord,
            "normal" => ChannelKind::Normal,
            "colour" | "color" => ChannelKind::Color,
            "generic" => ChannelKind::Generic,
            other => {
                return Err(format!(
                    "`{other}` is not a channel kind: use uv, normal, colour or generic"
                ))
            }
        };
        weights = weights.with(kind, parse_non_negative(value.trim())?);
    }
    Ok(weights)
}

/// Parses a ratio in (0, 1].
pub fn parse_ratio(s: &str) -> Result<f64, String> {
    let r: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("`{s}` is not a number"))?;
    if r > 0.0 && r <= 1.0 {
        Ok(r)
    } else {
        Err(format!(
            "{r} is outside (0, 1]; use e.g. 0.1 for 10% of the triangles"
        ))
    }
}

fn parse_non_negative(s: &str) -> Result<f64, String> {
    let v: f64 = s.parse().map_err(|_| format!("`{s}` is not a number"))?;
    if v >= 0.0 && v.is_finite() {
        Ok(v)
    } else {
        Err(format!("{v} must be a finite number ≥ 0"))
    }
}

/// The largest S of `--weighting mixed:S`. A face's weight is area + S·(mean area), so
/// above this the area changes a weight by at most (faces / S), under 1e-6 for a
/// million faces: `unweighted` is then the same ordering, without the risk of weights
/// that overflow once summed.
const MAX_WEIGHTING_MIX: f64 = 1e12;

/// Parses `--weighting`: `area`, `unweighted` or `mixed:S` with S a finite number in
/// [0, 1e12].
pub fn parse_weighting(s: &str) -> Result<Weighting, String> {
    match s.trim() {
        "area" => Ok(Weighting::Area),
        "unweighted" => Ok(Weighting::Unweighted),
        other => match other.strip_prefix("mixed:") {
            Some(mix) => {
                let mix = parse_non_negative(mix.trim())?;
                if mix > MAX_WEIGHTING_MIX {
                    // Face weights of s × the mean area would overflow f64 once summed.
                    return Err(format!(
                        "mixed:{mix} is too large: S must be at most {MAX_WEIGHTING_MIX:e} \
                         (use `unweighted` for unit weights)"
                    ));
                }
                Ok(Weighting::Mixed(mix))
            }
            None => Err(format!(
                "`{s}` is not a weighting: use area, unweighted or mixed:S (e.g. mixed:1)"
            )),
        },
    }
}

fn parse_unit_interval(s: &str) -> Result<f64, String> {
    let v = parse_non_negative(s)?;
    if v <= 1.0 {
        Ok(v)
    } else {
        Err(format!("{v} is outside [0, 1]"))
    }
}

/// Reads a lock file: one vertex index per line; blank lines and `#` comments are
/// skipped. Errors name the file and the line.
pub fn read_lock_file(path: &Path) -> Result<Vec<u32>, String> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| format!("{}: cannot read the lock file: {e}", path.display()))?;
    let mut indices = Vec::new();
    for (number, line) in text.lines().enumerate() {
        let content = line.split('#').next().unwrap_or("").trim();
        if content.is_empty() {
            continue;
        }
        let index: u32 = content.parse().map_err(|_| {
            format!(
                "{}:{}: `{content}` is not a vertex index (a whole number from 0 to {})",
                path.display(),
                number + 1,
                u32::MAX
            )
        })?;
        indices.push(index);
    }
    Ok(indices)
}

impl SimplifyFlags {
    fn length(&self, v: f64) -> Length {
        if self.absolute {
            Length::Absolute(v)
        } else {
            Length::DiagonalFraction(v)
        }
    }

    /// The library options these flags ask for; fails (naming the file and line) when
    /// the lock file cannot be read.
    pub fn options(&self) -> Result<SimplifyOptions, Failure> {
        let target = match (self.triangles, self.ratio) {
            (Some(n), _) => Target::Triangles(n),
            (None, Some(r)) => Target::Ratio(r),
            (None, None) => Target::Ratio(0.5),
        };
        // The preset first (FAST's order, quadrics, check and placement are the
        // library's, not rebuilt here), then what the flags say.
        let preset = if self.fast {
            SimplifyOptions::FAST
        } else {
            SimplifyOptions::DEFAULT
        };
        let orientation_check = if self.fast {
            self.orientation_check
        } else {
            !self.no_orientation_check
        };
        let options = preset
            .clone()
            .with_target(target)
            .with_max_error(self.max_error.map(|e| self.length(e)))
            .with_pair_threshold(self.length(self.pair_threshold))
            .with_virtual_pairs(match self.virtual_pairs {
                VirtualPairsFlag::Any => VirtualPairs::Any,
                VirtualPairsFlag::BetweenParts => VirtualPairs::BetweenComponents,
            })
            .with_boundary(if self.lock_boundary {
                BoundaryMode::Locked
            } else if self.boundary_weight > 0.0 {
                BoundaryMode::Planes(self.boundary_weight)
            } else {
                BoundaryMode::Free
            })
            .with_max_normal_angle(self.max_normal_angle)
            .with_min_triangle_quality(self.min_quality)
            .with_orientation_check(orientation_check)
            .with_preserve_topology(self.preserve_topology)
            .with_strict(self.strict)
            .with_weighting(self.weighting)
            .with_quadrics(match self.quadrics {
                Some(QuadricsFlag::Sum) => QuadricMode::Sum,
                Some(QuadricsFlag::Exact) => QuadricMode::Exact,
                None => preset.quadrics,
            })
            .with_method(if self.cluster {
                Method::Clustering
            } else {
                Method::Contraction
            })
            .with_order(match self.order {
                Some(OrderFlag::Greedy) => ContractionOrder::Greedy,
                Some(OrderFlag::Passes) => ContractionOrder::Passes,
                None => preset.order,
            })
            .with_attribute_weights(self.attribute_weights.unwrap_or(preset.attribute_weights));
        Ok(match &self.lock {
            Some(path) => {
                options.with_locked_vertices(read_lock_file(path).map_err(Failure::Failed)?)
            }
            None => options,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ratio_bounds() {
        assert_eq!(parse_ratio("1"), Ok(1.0));
        assert_eq!(parse_ratio(" 0.25"), Ok(0.25));
        assert!(parse_ratio("0").is_err());
        assert!(parse_ratio("1.01").is_err());
        assert!(parse_ratio("NaN").is_err());
        assert!(parse_ratio("x")
            .unwrap_err()
            .contains("`x` is not a number"));
    }

    #[test]
    fn weighting_values() {
        assert_eq!(parse_weighting("area"), Ok(Weighting::Area));
        assert_eq!(parse_weighting("unweighted"), Ok(Weighting::Unweighted));
        assert_eq!(parse_weighting("mixed:0.5"), Ok(Weighting::Mixed(0.5)));
        assert_eq!(parse_weighting(" mixed: 2 "), Ok(Weighting::Mixed(2.0)));
        assert!(parse_weighting("mixed:-1").is_err());
        assert!(parse_weighting("mixed:inf").is_err());
        assert!(parse_weighting("mixed:1e300")
            .unwrap_err()
            .contains("too large"));
        assert_eq!(parse_weighting("mixed:1e12"), Ok(Weighting::Mixed(1e12)));
        assert!(parse_weighting("mixed").unwrap_err().contains("mixed:S"));
        assert!(parse_weighting("Area").is_err());
    }

    #[test]
    fn default_weighting_flag_is_the_library_default() {
        assert_eq!(
            parse_weighting(DEFAULT_WEIGHTING_FLAG),
            Ok(SimplifyOptions::DEFAULT.weighting)
        );
        assert_eq!(
            parse_weighting(DEFAULT_WEIGHTING_FLAG),
            Ok(Weighting::Mixed(qem_mesh::simplify::DEFAULT_WEIGHTING_MIX))
        );
    }

    #[test]
    fn default_flags_give_the_library_defaults() {
        use clap::Parser;
        #[derive(Parser)]
        struct Cli {
            #[command(flatten)]
            flags: SimplifyFlags,
        }
        let options = Cli::parse_from(["qem"])
            .flags
            .options()
            .expect("no lock file");
        assert_eq!(options, SimplifyOptions::DEFAULT);
    }

    #[test]
    fn fast_gives_the_fast_preset_and_takes_every_other_option() {
        use clap::Parser;
        #[derive(Parser)]
        struct Cli {
            #[command(flatten)]
            flags: SimplifyFlags,
        }
        let options = Cli::parse_from(["qem", "--fast"])
            .flags
            .options()
            .expect("no lock file");
        assert_eq!(options, SimplifyOptions::FAST);
        let options = Cli::parse_from(["qem", "--fast", "--preserve-topology"])
            .flags
            .options()
            .expect("no lock file");
        assert_eq!(options, SimplifyOptions::FAST.with_preserve_topology(true));
        // --quadrics exact gives exact quadrics in passes; sum is FAST's own.
        for (flag, quadrics) in [("exact", QuadricMode::Exact), ("sum", QuadricMode::Sum)] {
            let options = Cli::parse_from(["qem", "--fast", "--quadrics", flag])
                .flags
                .options()
                .expect("no lock file");
            assert_eq!(options, SimplifyOptions::FAST.with_quadrics(quadrics));
        }
        // --orientation-check keeps the check with --fast, and means nothing without it.
        let options = Cli::parse_from(["qem", "--fast", "--orientation-check"])
            .flags
            .options()
            .expect("no lock file");
        assert_eq!(options, SimplifyOptions::FAST.with_orientation_check(true));
        assert!(Cli::try_parse_from(["qem", "--orientation-check"]).is_err());
        assert!(Cli::try_parse_from([
            "qem",
            "--fast",
            "--orientation-check",
            "--no-orientation-check"
        ])
        .is_err());
    }
}
