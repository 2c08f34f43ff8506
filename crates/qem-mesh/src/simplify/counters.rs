//! The one list of what a run counts for its report (contractions, refusals by
//! reason, the largest error), accumulated by every order and by the block workers.

use super::checks::Rejection;
use super::report::Refusals;

/// What the report counts, accumulated over the run.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Counters {
    pub edge_contractions: usize,
    pub virtual_contractions: usize,
    pub virtual_pairs: usize,
    pub virtual_pairs_capped: usize,
    /// The largest error contracted so far, normalised units.
    pub max_error: f64,
    pub rejected: Refusals,
    pub locked_vertices: usize,
    /// Faces facing away turned back by an edge flip after the run (`turn_back`).
    pub faces_turned_back: usize,
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
        self.rejected.add(&other.rejected);
    }

    /// Contractions so far, of edges and of virtual pairs.
    pub(super) fn contractions(&self) -> usize {
        self.edge_contractions + self.virtual_contractions
    }

    /// Counts one refusal for `why`.
    pub(super) fn reject(&mut self, why: Rejection) {
        let counter = match why {
            Rejection::Degenerate => &mut self.rejected.degenerate,
            Rejection::Flip => &mut self.rejected.flip,
            Rejection::Sliver => &mut self.rejected.sliver,
            Rejection::Topology => &mut self.rejected.topology,
            Rejection::Locked => &mut self.rejected.locked,
            Rejection::Border => &mut self.rejected.border,
            Rejection::Merge => &mut self.rejected.merge,
            Rejection::Orientation => &mut self.rejected.orientation,
            Rejection::LastTriangles => &mut self.rejected.last_triangles,
            Rejection::Seam => &mut self.rejected.seam,
        };
        *counter += 1;
    }
}
