//! What a run did ([`SimplifyReport`]), why it stopped, and why it could not run.

use super::relaxation::{Constraint, Relaxation};
use crate::clean::CleanReport;
use crate::{IndexedMesh, InputError};
use std::fmt;
use std::time::Duration;

/// Why the loop stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StopReason {
    /// The triangle count reached the target (or was already at or below it).
    TargetReached,
    /// The next contraction would have exceeded the error bound.
    MaxErrorReached,
    /// No candidate pair was left before the target.
    NoValidPair,
    /// The observer asked to stop.
    Cancelled,
}

impl StopReason {
    /// A short snake_case name, as used in JSON reports.
    pub fn as_str(self) -> &'static str {
        match self {
            StopReason::TargetReached => "target_reached",
            StopReason::MaxErrorReached => "max_error_reached",
            StopReason::NoValidPair => "no_valid_pair",
            StopReason::Cancelled => "cancelled",
        }
    }
}

impl fmt::Display for StopReason {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// Wall time of each phase of a run.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Timings {
    /// Validation and cleaning.
    pub clean: Duration,
    /// Face and vertex quadrics, candidate pairs and the queue (in the pass-based
    /// order: its arrays and the vertex quadrics).
    pub setup: Duration,
    /// The contraction loop.
    pub contract: Duration,
    /// Compaction back to an [`IndexedMesh`].
    pub compact: Duration,
}

/// What a simplification did.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct SimplifyReport {
    /// Triangles in the input, as given.
    pub triangles_in: usize,
    /// Vertices in the input, as given.
    pub vertices_in: usize,
    /// Triangles in the output.
    pub triangles_out: usize,
    /// Vertices in the output.
    pub vertices_out: usize,
    /// The target the run aimed for, in triangles.
    pub target_triangles: usize,
    /// Contractions of pairs joined by an edge.
    pub edge_contractions: usize,
    /// Contractions of virtual pairs (no shared edge).
    pub virtual_contractions: usize,
    /// Virtual pairs found by the grid (after the per-vertex cap).
    pub virtual_pairs: usize,
    /// Virtual pairs the per-vertex cap left out.
    pub virtual_pairs_capped: usize,
    /// The largest contraction error, as a fraction of the input's bounding-box
    /// diagonal.
    ///
    /// The error of a contraction is a distance: `sqrt(cost / weight)`, the square root
    /// of the quadric cost at the new position divided by the quadric's total plane
    /// weight (its total area, with area weighting) — the RMS distance of the new vertex
    /// to the planes it has accumulated. So `0.001` means about 0.1% of the diagonal.
    pub max_error: f64,
    /// [`max_error`](Self::max_error) in model units.
    pub max_error_abs: f64,
    /// The input's bounding-box diagonal, in model units (after cleaning).
    pub bbox_diagonal: f64,
    /// Why the loop stopped.
    pub stop_reason: StopReason,
    /// What the cleaning passes removed or merged.
    pub cleanup: CleanReport,
    /// Faces of the result dropped at compaction because contraction left them with
    /// zero area.
    pub degenerate_faces_removed: usize,
    /// Contractions refused, by reason.
    pub rejected: Refusals,
    /// The steps of the ladder of relaxations the run climbed because no pair passed
    /// every check, in order, with the contractions made under each (empty when it
    /// never got stuck; see [`RelaxationStep`](super::RelaxationStep)).
    pub relaxations: Vec<Relaxation>,
    /// With [`StopReason::NoValidPair`]: the constraint that stopped the run (what
    /// refused the most pairs at the top of the ladder, or [`Constraint::Strict`]);
    /// `None` for every other stop reason.
    pub stopped_by: Option<Constraint>,
    /// Vertices of the cleaned input that were locked (by
    /// [`locked_vertices`](super::SimplifyOptions::locked_vertices) or by
    /// [`BoundaryMode::Locked`](super::BoundaryMode::Locked)).
    pub locked_vertices: usize,
    /// Output faces whose normal points more than 90° away from the normal of the input
    /// face they descend from (each output face is a moved input face). The fold-over
    /// check ([`max_normal_angle`](super::SimplifyOptions::max_normal_angle) below 180°)
    /// refuses every contraction that would make one, so this is 0 unless the check is
    /// off or the ladder of relaxations climbed
    /// [`RelaxationStep::FlippedFaces`](super::RelaxationStep::FlippedFaces); it is a
    /// cheap self-check, not a comparison with the input surface.
    pub faces_flipped: usize,
    /// Faces left facing away from the input by contractions made without the
    /// orientation check, turned back by an edge flip after the run (the count and
    /// every position stay; see [`SimplifyOptions::orientation_check`](super::SimplifyOptions::orientation_check)).
    pub faces_turned_back: usize,
    /// Wall time per phase.
    pub timings: Timings,
}

/// Why a simplification could not run. Stopping short of the target is not an error
/// (see [`StopReason`]).
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum SimplifyError {
    /// The input failed validation.
    Input(InputError),
    /// Every triangle was degenerate or a duplicate: nothing is left to simplify.
    /// (With [`CleanOptions::drop_zero_area`](crate::clean::CleanOptions::drop_zero_area)
    /// turned off, zero-area faces enter the loop; if only such faces are left at the
    /// end, this is the error too, since the output never has a zero-area face.)
    NothingLeftAfterCleaning {
        /// How many triangles the input had.
        triangles_in: usize,
    },
    /// A locked vertex index is not a vertex of the input.
    LockedVertexOutOfRange {
        /// The offending index.
        index: u32,
        /// How many vertices the input has.
        vertex_count: usize,
    },
    /// [`Method::Clustering`](super::Method::Clustering) was asked together with an
    /// option it cannot honour.
    NotWithClustering {
        /// The option, as the library names it (`preserve_topology`,
        /// `locked_vertices`, `boundary: Locked`, `max_error`, `target: None`).
        option: &'static str,
    },
    /// The observer asked to stop ([`Observer::should_stop`](super::Observer::should_stop))
    /// before the contraction loop began: there is no partial result yet. (Asked
    /// during the loop, the run ends with [`StopReason::Cancelled`] and a valid mesh.)
    Cancelled {
        /// The phase that had just ended.
        after: super::Phase,
    },
}

impl fmt::Display for SimplifyError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SimplifyError::Input(e) => e.fmt(f),
            SimplifyError::NothingLeftAfterCleaning { triangles_in } => write!(
                f,
                "all {triangles_in} triangles are degenerate (repeated vertex or zero area): \
                 nothing is left to simplify"
            ),
            SimplifyError::LockedVertexOutOfRange {
                index,
                vertex_count,
            } => write!(
                f,
                "locked vertex {index} is out of range: the input has {vertex_count} \
                 vertices (indices start at 0)"
            ),
            SimplifyError::NotWithClustering { option } => write!(
                f,
                "vertex clustering cannot honour {option}: it places one vertex per grid \
                 cell and reaches a triangle count, nothing else"
            ),
            SimplifyError::Cancelled { after } => {
                write!(
                    f,
                    "cancelled after {}, before any contraction",
                    after.name()
                )
            }
        }
    }
}

impl std::error::Error for SimplifyError {}

impl From<InputError> for SimplifyError {
    fn from(e: InputError) -> Self {
        SimplifyError::Input(e)
    }
}

/// Contractions refused, by the check that refused them (each attempt of a pair that
/// a check refuses counts once).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Refusals {
    /// Contractions refused because they would have left a surviving face with zero
    /// area.
    pub degenerate: usize,
    /// Contractions refused because a surviving face's normal would have turned by more
    /// than [`max_normal_angle`](super::SimplifyOptions::max_normal_angle).
    pub flip: usize,
    /// Contractions refused because a surviving face would have become a sliver (below
    /// [`min_triangle_quality`](super::SimplifyOptions::min_triangle_quality)).
    pub sliver: usize,
    /// Contractions refused by [`preserve_topology`](super::SimplifyOptions::preserve_topology):
    /// link condition failed, or a non-manifold vertex or edge.
    pub topology: usize,
    /// Contractions refused because both vertices were locked, or because a locked
    /// vertex would have lost its last face.
    pub locked: usize,
    /// Contractions refused because they would have pinched, closed or removed a border
    /// loop (with any [`BoundaryMode`](super::BoundaryMode) but `Free`).
    pub border: usize,
    /// Contractions refused because two faces `a x y` and `b x y` would have merged
    /// into one, which opens a hole in a closed surface (virtual pairs may merge faces:
    /// joining parts is their purpose). With
    /// [`preserve_topology`](super::SimplifyOptions::preserve_topology) the link condition
    /// refuses these first, and they count in [`topology`](Self::topology).
    pub merge: usize,
    /// Contractions refused by the orientation check
    /// ([`orientation_check`](super::SimplifyOptions::orientation_check)): a moved face
    /// would have faced away from the input surface nearest to it. Such a pair is
    /// queued again at a penalty and may be contracted later, when everything else
    /// costs more; each refusal is counted.
    pub orientation: usize,
    /// Contractions refused because they would have removed the last triangles: the
    /// output keeps at least one.
    pub last_triangles: usize,
    /// Contractions refused because they would have joined the two sides of an
    /// attribute seam (a UV seam, a hard normal, a colour or material border); only on
    /// meshes with attributes.
    pub seam: usize,
}

impl Refusals {
    /// Every refusal, whatever the reason.
    pub fn total(&self) -> usize {
        let Refusals {
            degenerate,
            flip,
            sliver,
            topology,
            locked,
            border,
            merge,
            orientation,
            last_triangles,
            seam,
        } = *self;
        degenerate
            + flip
            + sliver
            + topology
            + locked
            + border
            + merge
            + orientation
            + last_triangles
            + seam
    }

    /// Every count with its snake_case name, as used in JSON reports (the CLI's and
    /// the Python package's `rejected`).
    pub fn named(&self) -> [(&'static str, usize); 10] {
        [
            ("degenerate", self.degenerate),
            ("flip", self.flip),
            ("sliver", self.sliver),
            ("topology", self.topology),
            ("locked", self.locked),
            ("border", self.border),
            ("merge", self.merge),
            ("orientation", self.orientation),
            ("last_triangles", self.last_triangles),
            ("seam", self.seam),
        ]
    }

    /// Adds `other`'s counts to these.
    pub(crate) fn add(&mut self, other: &Refusals) {
        self.degenerate += other.degenerate;
        self.flip += other.flip;
        self.sliver += other.sliver;
        self.topology += other.topology;
        self.locked += other.locked;
        self.border += other.border;
        self.merge += other.merge;
        self.orientation += other.orientation;
        self.last_triangles += other.last_triangles;
        self.seam += other.seam;
    }

    /// These counts less `earlier`'s (an earlier copy of the same counters).
    pub(crate) fn minus(&self, earlier: &Refusals) -> Refusals {
        Refusals {
            degenerate: self.degenerate - earlier.degenerate,
            flip: self.flip - earlier.flip,
            sliver: self.sliver - earlier.sliver,
            topology: self.topology - earlier.topology,
            locked: self.locked - earlier.locked,
            border: self.border - earlier.border,
            merge: self.merge - earlier.merge,
            orientation: self.orientation - earlier.orientation,
            last_triangles: self.last_triangles - earlier.last_triangles,
            seam: self.seam - earlier.seam,
        }
    }
}

/// The result of a simplification.
#[derive(Clone, Debug, PartialEq)]
pub struct Simplified {
    /// The simplified mesh.
    pub mesh: IndexedMesh,
    /// What happened.
    pub report: SimplifyReport,
}
