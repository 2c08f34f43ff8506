//! The ladder of relaxations' vocabulary: its steps, what a run reports of them, and
//! the constraints that can stop a run (the ladder itself is [`super::ladder`]). Plain
//! types, read by the settings, the report and the ladder alike.

use super::options::{BoundaryMode, SimplifyOptions};
use std::fmt;

/// A step of the ladder of relaxations, in the order they are climbed; each step keeps
/// the relaxations of the steps before it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum RelaxationStep {
    /// The fold-over rules allow any turn of a face's normal in one contraction and
    /// any sliver ([`max_normal_angle`](super::SimplifyOptions::max_normal_angle) and
    /// [`min_triangle_quality`](super::SimplifyOptions::min_triangle_quality) are
    /// off), as long as the face still points less than 90° away from the input face
    /// it descends from; a face still may not get zero area. The orientation check
    /// still asks first, and its waivers still apply.
    FoldOver,
    /// A contraction may pinch, close or remove a border loop. Not climbed with
    /// [`BoundaryMode::Locked`] or
    /// [`preserve_topology`](super::SimplifyOptions::preserve_topology).
    BorderLoops,
    /// An edge contraction may merge two faces `a x y` and `b x y`: both are removed
    /// (they would lie back to back on the same three vertices). This is how a closed
    /// part too small to keep goes away (a tetrahedron loses its last four faces in one
    /// contraction). Not climbed with
    /// [`preserve_topology`](super::SimplifyOptions::preserve_topology).
    MergedFaces,
    /// A moved face may point more than 90° away from the input face it descends from
    /// (the report's [`faces_flipped`](super::SimplifyReport::faces_flipped) can then be
    /// above 0). Last: a face turned over is the worst of the relaxed outcomes.
    FlippedFaces,
}

impl RelaxationStep {
    /// Every step, in the order they are climbed.
    pub const ALL: [RelaxationStep; 4] = [
        RelaxationStep::FoldOver,
        RelaxationStep::BorderLoops,
        RelaxationStep::MergedFaces,
        RelaxationStep::FlippedFaces,
    ];

    /// A short snake_case name, as used in JSON reports.
    pub fn as_str(self) -> &'static str {
        match self {
            RelaxationStep::FoldOver => "fold_over",
            RelaxationStep::BorderLoops => "border_loops",
            RelaxationStep::MergedFaces => "merged_faces",
            RelaxationStep::FlippedFaces => "flipped_faces",
        }
    }

    /// Whether a run with `options` may climb this step.
    pub(super) fn allowed(self, options: &SimplifyOptions) -> bool {
        match self {
            RelaxationStep::FoldOver => true,
            RelaxationStep::BorderLoops => {
                !options.preserve_topology && options.boundary != BoundaryMode::Locked
            }
            RelaxationStep::MergedFaces => !options.preserve_topology,
            RelaxationStep::FlippedFaces => true,
        }
    }
}

impl fmt::Display for RelaxationStep {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// A step of the ladder that a run climbed, and how many contractions were made while
/// it was in force (each of them passed that step's relaxed checks; most of them
/// failed the stricter ones).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Relaxation {
    /// The step.
    pub step: RelaxationStep,
    /// Contractions made while it was in force, over the run.
    pub contractions: usize,
}

/// What stopped a run short of its target when no pair was left
/// ([`StopReason::NoValidPair`](super::StopReason::NoValidPair)): the constraint that refused the most pairs on the
/// last climb of the ladder (or the ladder's absence).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Constraint {
    /// [`strict`](super::SimplifyOptions::strict): the ladder was not climbed.
    Strict,
    /// [`preserve_topology`](super::SimplifyOptions::preserve_topology).
    PreserveTopology,
    /// Locked vertices ([`locked_vertices`](super::SimplifyOptions::locked_vertices)
    /// or [`BoundaryMode::Locked`]).
    Locks,
    /// Border loops kept with [`BoundaryMode::Locked`].
    LockedBoundary,
    /// Every contraction left would give a face zero area.
    ZeroArea,
    /// The output keeps at least one triangle: a target of 0, or of fewer triangles
    /// than the last contractions remove at once.
    LastTriangles,
    /// The attribute seams: every pair left would join the two sides of a seam (a UV
    /// seam, a hard normal, a colour or material border).
    Seams,
    /// No pair was left to try (every vertex alone, or the error bound).
    NoPairs,
}

impl Constraint {
    /// A short snake_case name, as used in JSON reports.
    pub fn as_str(self) -> &'static str {
        match self {
            Constraint::Strict => "strict",
            Constraint::PreserveTopology => "preserve_topology",
            Constraint::Locks => "locks",
            Constraint::LockedBoundary => "locked_boundary",
            Constraint::ZeroArea => "zero_area",
            Constraint::LastTriangles => "last_triangles",
            Constraint::Seams => "seams",
            Constraint::NoPairs => "no_pairs",
        }
    }
}

impl fmt::Display for Constraint {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// The ladder's state over a run (kept across the levels of a chain).
#[derive(Clone, Debug, Default)]
pub(super) struct Ladder {
    /// Contractions made under each step of [`RelaxationStep::ALL`]; `None`: never
    /// climbed.
    pub contractions: [Option<usize>; RelaxationStep::ALL.len()],
    /// What stopped the last run that stopped with no pair left.
    pub stopped_by: Option<Constraint>,
    /// How many triangles below the target a contraction may take the count, beyond
    /// the 1% that always counts as reaching it (see
    /// [`Engine::run_landing`](super::engine::Engine::run_landing)): 0 until no pair
    /// lands on the level's target, then grown until a pair passes it.
    pub may_pass_by: usize,
    /// Whether an attempt was put off because it would have taken the count below
    /// the target while that was not allowed.
    pub put_off_past_target: bool,
    /// Whether a check refused a pair since the last contraction: when a run stops
    /// with pairs put off, a relaxed check may then let a pair land on the target
    /// (none may when every pair left was put off, e.g. a closed mesh one triangle
    /// above an odd target).
    pub refused_since_contraction: bool,
}

impl Ladder {
    /// The steps climbed, in order, for the report.
    pub fn relaxations(&self) -> Vec<Relaxation> {
        RelaxationStep::ALL
            .iter()
            .zip(self.contractions)
            .filter_map(|(&step, n)| n.map(|contractions| Relaxation { step, contractions }))
            .collect()
    }
}
