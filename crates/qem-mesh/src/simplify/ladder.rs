//! What the engine does when no pair passes every check before the target: it climbs a
//! ladder of relaxations instead of stopping.
//!
//! The order (greedy or passes) runs with every check. When it finds no pair it can
//! contract, the engine takes the first [`RelaxationStep`] and runs the order again
//! with that step's checks relaxed (each step relaxes what the steps before it relaxed,
//! and one thing more). When that run is stuck too, the engine goes back to every
//! check, since the relaxed contractions may have freed pairs that pass them, and
//! climbs again from the bottom; a step that allowed nothing sends it one step higher.
//! The run stops short only when the top step allowed nothing, and the report then
//! names what stopped it ([`Constraint`]).
//!
//! Never relaxed: what the user asked for ([`preserve_topology`], locked vertices,
//! [`BoundaryMode::Locked`], [`max_error`]), the output's guarantees (no zero-area
//! face, at least one triangle), and nothing at all with [`strict`].
//!
//! [`preserve_topology`]: super::SimplifyOptions::preserve_topology
//! [`max_error`]: super::SimplifyOptions::max_error
//! [`strict`]: super::SimplifyOptions::strict

use super::engine::Engine;
use super::observer::Observer;
use super::options::{BoundaryMode, ContractionOrder, SimplifyOptions};
use super::report::{Refusals, StopReason};
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
    fn allowed(self, options: &SimplifyOptions) -> bool {
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
/// ([`StopReason::NoValidPair`]): the constraint that refused the most pairs on the
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
            Constraint::NoPairs => "no_pairs",
        }
    }

    /// The constraint behind the most of `refused`, the refusals of a run at the top
    /// of the ladder, where only constraints that are never relaxed refuse for good
    /// (the orientation check's refusals are waived, not final).
    fn behind(refused: &Refusals, options: &SimplifyOptions) -> Constraint {
        let locked_boundary = options.boundary == BoundaryMode::Locked;
        let by_border = if options.preserve_topology {
            Constraint::PreserveTopology
        } else if locked_boundary {
            Constraint::LockedBoundary
        } else {
            Constraint::NoPairs
        };
        let candidates = [
            (
                refused.topology + refused.merge,
                Constraint::PreserveTopology,
            ),
            (refused.locked, Constraint::Locks),
            (refused.border, by_border),
            (refused.degenerate, Constraint::ZeroArea),
            (refused.last_triangles, Constraint::LastTriangles),
        ];
        // The first of the largest, so the order above breaks ties.
        let (count, constraint) =
            candidates
                .into_iter()
                .fold((0, Constraint::NoPairs), |best, c| {
                    if c.0 > best.0 {
                        c
                    } else {
                        best
                    }
                });
        if count == 0 {
            Constraint::NoPairs
        } else {
            constraint
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

impl Engine {
    /// Runs `order` down to `target`, climbing the ladder (see the module's doc) when
    /// it finds no pair.
    pub(crate) fn run_order_with_ladder(
        &mut self,
        options: &SimplifyOptions,
        target: usize,
        observer: &mut dyn Observer,
    ) -> StopReason {
        let every_check = self.settings;
        self.ladder.stopped_by = None;
        let steps: Vec<(usize, RelaxationStep)> = RelaxationStep::ALL
            .into_iter()
            .enumerate()
            .filter(|(_, step)| !options.strict && step.allowed(options))
            .collect();
        let climbable: Vec<RelaxationStep> = steps.iter().map(|&(_, step)| step).collect();
        let mut reason = self.run_order(options.order, target, observer);
        let mut climb = 0;
        while reason == StopReason::NoValidPair {
            let Some(&(slot, _)) = steps.get(climb) else {
                break;
            };
            // This step and the allowed ones below it, never one the options forbid.
            self.settings = every_check.relaxed(&climbable[..=climb]);
            self.ladder.contractions[slot].get_or_insert(0);
            self.retry(options.order);
            let (before, refused_before) = (self.counters.contractions(), self.counters.rejected);
            reason = self.run_order(options.order, target, observer);
            let made = self.counters.contractions() - before;
            *self.ladder.contractions[slot].get_or_insert(0) += made;
            self.settings = every_check;
            if reason != StopReason::NoValidPair {
                break;
            }
            if made == 0 {
                if climb + 1 == steps.len() {
                    let refused = self.counters.rejected.minus(&refused_before);
                    self.ladder.stopped_by = Some(Constraint::behind(&refused, options));
                }
                climb += 1;
                continue;
            }
            // Back to every check: the relaxed contractions may have freed pairs that
            // pass them.
            climb = 0;
            self.retry(options.order);
            reason = self.run_order(options.order, target, observer);
        }
        if reason == StopReason::NoValidPair && options.strict {
            self.ladder.stopped_by = Some(Constraint::Strict);
        }
        reason
    }

    /// One run of `order`.
    fn run_order(
        &mut self,
        order: ContractionOrder,
        target: usize,
        observer: &mut dyn Observer,
    ) -> StopReason {
        match order {
            ContractionOrder::Greedy => self.run_greedy(target, observer),
            ContractionOrder::Passes => self.run_passes(target, observer),
        }
    }

    /// Before the order runs again under other checks: the greedy order queues again
    /// every pair it dropped when a check refused it (the pass-based order asks every
    /// pair at each pass anyway).
    fn retry(&mut self, order: ContractionOrder) {
        if order == ContractionOrder::Greedy {
            self.requeue_every_pair();
        }
    }
}
