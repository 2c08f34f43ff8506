//! The one list of what a run counts for its report (contractions, refusals by
//! reason, the largest error), accumulated by every order and by the block workers.

use super::checks::Rejection;

/// What the report counts, accumulated over the run.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Counters {
    pub edge_contractions: usize,
    pub virtual_contractions: usize,
    pub virtual_pairs: usize,
    pub virtual_pairs_capped: usize,
    /// The largest error contracted so far, normalised units.
    pub max_error: f64,
    pub rejected_degenerate: usize,
    pub rejected_flip: usize,
    pub rejected_sliver: usize,
    pub rejected_topology: usize,
    pub rejected_locked: usize,
    pub rejected_border: usize,
    pub rejected_merge: usize,
    pub rejected_orientation: usize,
    pub locked_vertices: usize,
}

impl Counters {
    /// Adds `other`'s counts of what happened to these and keeps the larger of the two
    /// largest errors (the counts of one block of a pass, see `pass_blocks`;
    /// `locked_vertices` is a property of the run, not counted there).
    pub(super) fn absorb(&mut self, other: &Counters) {
        self.edge_contractions += other.edge_contractions;
        self.virtual_contractions += other.virtual_contractions;
        self.virtual_pairs += other.virtual_pairs;
        self.virtual_pairs_capped += other.virtual_pairs_capped;
        self.max_error = self.max_error.max(other.max_error);
        self.rejected_degenerate += other.rejected_degenerate;
        self.rejected_flip += other.rejected_flip;
        self.rejected_sliver += other.rejected_sliver;
        self.rejected_topology += other.rejected_topology;
        self.rejected_locked += other.rejected_locked;
        self.rejected_border += other.rejected_border;
        self.rejected_merge += other.rejected_merge;
        self.rejected_orientation += other.rejected_orientation;
    }

    pub(super) fn reject(&mut self, why: Rejection) {
        let counter = match why {
            Rejection::Degenerate => &mut self.rejected_degenerate,
            Rejection::Flip => &mut self.rejected_flip,
            Rejection::Sliver => &mut self.rejected_sliver,
            Rejection::Topology => &mut self.rejected_topology,
            Rejection::Locked => &mut self.rejected_locked,
            Rejection::Border => &mut self.rejected_border,
            Rejection::Merge => &mut self.rejected_merge,
            Rejection::Orientation => &mut self.rejected_orientation,
        };
        *counter += 1;
    }
}
