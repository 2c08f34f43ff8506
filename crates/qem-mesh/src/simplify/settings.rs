//! The one place where options become settings: what the engine reads, in the form
//! it reads it (normalised units, cosines, flags).

use super::options::{BoundaryMode, PlacementMode, SimplifyOptions};
use super::relaxation::RelaxationStep;
use crate::clean::min_double_area;
use qem_core::Frame;

/// Bounding-box diagonals (model units) below which world-unit cross products may
/// underflow f64; see [`Settings::world_may_underflow`].
const WORLD_UNDERFLOW_DIAGONAL: f64 = 1e-140;

/// The options the loop reads, in the form it reads them.
#[derive(Clone, Copy, Debug)]
pub(super) struct Settings {
    pub placement: PlacementMode,
    /// The error bound in normalised units (infinite when there is none).
    pub max_error_bound: f64,
    /// The square of twice the area at or below which a face counts as zero-area
    /// (normalised units), to compare with a cross product's squared length.
    pub min_double_area_squared: f64,
    /// Whether world coordinates are so small that a proper triangle's cross product
    /// can underflow to zero in model units (see `clean::cross_underflows`); only then
    /// does the fold-over check also test faces in world units.
    pub world_may_underflow: bool,
    /// Cosine of the largest allowed normal turn; `None` when the check is off.
    pub min_normal_cos: Option<f64>,
    /// Whether a moved face must not point more than 90° away from the input face it
    /// descends from (with the fold-over check on).
    pub face_input: bool,
    /// The sliver threshold; `None` when the check is off.
    pub min_quality: Option<f64>,
    pub preserve_topology: bool,
    /// The virtual pairs' distance threshold in normalised units (0: none). None with
    /// topology preservation: joining parts changes the topology.
    pub virtual_pair_threshold: f64,
    /// Refuse contractions that pinch, close or remove a border loop (any
    /// [`BoundaryMode`] but `Free`).
    pub keep_border_loops: bool,
    /// Whether any vertex is locked (skips the lock checks entirely when not).
    pub any_locked: bool,
    /// Whether an edge contraction may merge two faces `a x y` and `b x y` (both are
    /// then removed): only on the ladder's [`RelaxationStep::MergedFaces`].
    pub allow_merges: bool,
}

impl Settings {
    /// The settings of `options` for a run in `frame`.
    pub(super) fn new(options: &SimplifyOptions, frame: &Frame) -> Settings {
        let max_error_bound = options
            .max_error
            .map_or(f64::INFINITY, |e| e.normalized(frame));
        let angle = options.max_normal_angle.clamp(0.0, 180.0);
        Settings {
            placement: options.placement,
            max_error_bound,
            min_double_area_squared: min_double_area(frame.normalized_diagonal()).powi(2),
            // A cross product of edges of length L is about L²; f64 underflows below
            // ~1e-308, so only a model smaller than ~1e-150 can be affected.
            world_may_underflow: frame.world_diagonal() < WORLD_UNDERFLOW_DIAGONAL,
            min_normal_cos: (angle < 180.0).then(|| angle.to_radians().cos()),
            face_input: angle < 180.0,
            min_quality: (options.min_triangle_quality > 0.0)
                .then_some(options.min_triangle_quality),
            preserve_topology: options.preserve_topology,
            virtual_pair_threshold: if options.preserve_topology {
                0.0
            } else {
                options.pair_threshold.normalized(frame)
            },
            keep_border_loops: options.boundary != BoundaryMode::Free,
            any_locked: false,
            allow_merges: false,
        }
    }

    /// These settings with the relaxations of the ladder's `steps` (see
    /// [`super::ladder`]: the steps a run may climb, up to the one it is on).
    pub(super) fn relaxed(&self, steps: &[RelaxationStep]) -> Settings {
        let mut relaxed = *self;
        for &s in steps {
            match s {
                RelaxationStep::FoldOver => {
                    relaxed.min_normal_cos = None;
                    relaxed.min_quality = None;
                }
                RelaxationStep::BorderLoops => relaxed.keep_border_loops = false,
                RelaxationStep::MergedFaces => relaxed.allow_merges = true,
                RelaxationStep::FlippedFaces => relaxed.face_input = false,
            }
        }
        relaxed
    }
}
