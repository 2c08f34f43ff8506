//! The simplification options shared by `qem simplify` and `qem batch` (and any later
//! command that simplifies): one clap `Args` struct that each command flattens, so a
//! new option is added in one place.

use clap::Args;
use qem_mesh::simplify::{Length, SimplifyOptions, Target};

/// How to simplify: target, error bound, virtual pairs.
#[derive(Args, Debug, Clone)]
pub struct SimplifyFlags {
    /// Target as a fraction of the input's triangles (as loaded), in (0, 1]
    /// [default: 0.5 when --triangles is not given].
    #[arg(long, conflicts_with = "triangles", value_parser = parse_ratio)]
    pub ratio: Option<f64>,
    /// Target as a triangle count [default: none, --ratio 0.5 applies].
    #[arg(long)]
    pub triangles: Option<usize>,
    /// Stop before the first contraction whose error would exceed this distance: a
    /// fraction of the input's bounding-box diagonal (0.001 = 0.1%), or model units
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

impl SimplifyFlags {
    fn length(&self, v: f64) -> Length {
        if self.absolute {
            Length::Absolute(v)
        } else {
            Length::DiagonalFraction(v)
        }
    }

    /// The library options these flags ask for.
    pub fn options(&self) -> SimplifyOptions {
        let target = match (self.triangles, self.ratio) {
            (Some(n), _) => Target::Triangles(n),
            (None, Some(r)) => Target::Ratio(r),
            (None, None) => Target::Ratio(0.5),
        };
        SimplifyOptions::DEFAULT
            .with_target(target)
            .with_max_error(self.max_error.map(|e| self.length(e)))
            .with_pair_threshold(self.length(self.pair_threshold))
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
}
