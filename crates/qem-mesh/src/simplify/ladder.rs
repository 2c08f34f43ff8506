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
use super::relaxation::{Constraint, RelaxationStep};
use super::report::{Refusals, StopReason};

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
        // The greedy order dropped the pairs the last level put off (a level that
        // landed on its target never asked them again): queued again for this one.
        if self.ladder.put_off_past_target {
            self.retry(options.order);
        }
        self.ladder.may_pass_target = false;
        self.ladder.put_off_past_target = false;
        let mut reason = self.run_landing(options.order, target, observer);
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
            reason = self.run_landing(options.order, target, observer);
            let made = self.counters.contractions() - before;
            *self.ladder.contractions[slot].get_or_insert(0) += made;
            self.settings = every_check;
            if reason != StopReason::NoValidPair {
                break;
            }
            if made == 0 {
                if climb + 1 == steps.len() {
                    let refused = self.counters.rejected.minus(&refused_before);
                    self.ladder.stopped_by = Some(constraint_behind(&refused, options));
                }
                climb += 1;
                continue;
            }
            // Back to every check: the relaxed contractions may have freed pairs that
            // pass them.
            climb = 0;
            self.retry(options.order);
            reason = self.run_landing(options.order, target, observer);
        }
        if reason == StopReason::NoValidPair && options.strict {
            self.ladder.stopped_by = Some(Constraint::Strict);
        }
        reason
    }

    /// One run of `order` that lands on `target` when it can: a contraction that would
    /// take the count more than 1% below the target (`misses_target` in the attempt)
    /// is put off while another may land on it (a border edge removes one triangle
    /// where an inner edge removes two); when no pair is left but those (or the others
    /// are over the error bound), they may pass it, and the order runs once more.
    ///
    /// Why: a run asked for 28 triangles ended at 27, 9 at 8 (the corpus's small
    /// meshes at ratio 0.01, where one triangle is more than 1%). Far from the target
    /// nothing is put off, so it costs nothing there; near it, at most one more pass
    /// or queue.
    pub(super) fn run_landing(
        &mut self,
        order: ContractionOrder,
        target: usize,
        observer: &mut dyn Observer,
    ) -> StopReason {
        let reason = self.run_order(order, target, observer);
        // Also after an error bound: the pairs put off were cheaper than the one over
        // it, and may be within it.
        let short = matches!(
            reason,
            StopReason::NoValidPair | StopReason::MaxErrorReached
        );
        if !short || !self.ladder.put_off_past_target || self.ladder.may_pass_target {
            return reason;
        }
        self.ladder.may_pass_target = true;
        self.retry(order);
        self.run_order(order, target, observer)
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

/// The constraint behind the most of `refused`, the refusals of a run at the top
/// of the ladder, where only constraints that are never relaxed refuse for good
/// (the orientation check's refusals are waived, not final).
fn constraint_behind(refused: &Refusals, options: &SimplifyOptions) -> Constraint {
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
        (refused.seam, Constraint::Seams),
    ];
    // The first of the largest, so the order above breaks ties; none refused: no pairs.
    let none = (0, Constraint::NoPairs);
    let (_, constraint) = candidates
        .into_iter()
        .fold(none, |best, c| if c.0 > best.0 { c } else { best });
    constraint
}
