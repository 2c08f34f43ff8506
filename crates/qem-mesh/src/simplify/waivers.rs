//! The orientation waivers: pairs refused by the orientation check, ranked at a
//! penalty ([`ORIENTATION_PENALTY`] times their cost) and then tried without the
//! check.
//!
//! The greedy order queues such a pair again at the penalty; the pass-based order
//! costs it at the penalty in later passes. Either way its next attempt skips the
//! check. A waiver ends when either end moves (the pair is then costed and checked
//! afresh), or when an attempt of the pair gets past the other checks and the error
//! bound, so reaches the point where the check would run; a waived pair that another
//! check refuses keeps its waiver and its penalty.
//!
//! A contraction made without the check may leave a face facing away; the vertices
//! such contractions kept are recorded, and after the run their faces are asked again
//! (`turn_back`).
//!
//! Why a flag per vertex beside the map: every edge of every pass asks whether it is
//! waived, and once a pair has been refused the map is never empty again; the flags,
//! one byte per vertex, answer no without hashing for almost every edge. The map is
//! only looked up and changed, never iterated, so its order cannot reach an output.

use qem_core::Quadric;
use smallvec::SmallVec;
use std::collections::HashMap;

/// The factor on the cost of a pair refused by the orientation check when it is queued
/// again. Why not refuse for good: at extreme ratios (1% of the triangles and below)
/// most remaining pairs fail the check, and refusing them all forced contractions ten
/// times costlier elsewhere (cgal_mannequin_devil at 0.01: Hausdorff 2.0% → 21% of the
/// diagonal, and the run stopped short of its target). At a penalty, a pair that turns
/// a face against the input is taken only once every alternative costs more.
///
/// Measured (qem measure, and a brute-force count of faces against the nearest input
/// face) on the 5 clean corpus scans that had such faces at ratio 0.1, plus 4 runs at
/// 0.01: with 8, cgal_mannequin_devil keeps one such face at 0.1 (0.04%); with 32 and
/// 128 none is left at 0.1; at 0.01 the mannequin's Hausdorff is 4.1% (32) and 3.9%
/// (128) against 2.0% with the check off, the other 0.01 runs within a few percent of
/// each other. 32 is the smallest factor tried that leaves none at 0.1.
pub(super) const ORIENTATION_PENALTY: f64 = 32.0;

/// The least cost a penalised pair is queued at, as a distance (normalised units, where
/// the model's diagonal is at most 2√3): `weight · d²` for the pair's quadric. Why: on a
/// flat region a pair costs exactly 0, and 32 × 0 would queue it right back at the
/// front, where it would pop again at once with the check waived; with the floor it
/// waits behind every pair that moves the surface by less than this.
pub(super) const PENALTY_FLOOR_DISTANCE: f64 = 1e-6;

/// The waived pairs of a pass-based run, by vertex index.
#[derive(Debug, Default)]
pub(super) struct Waivers {
    /// Whether each vertex may be in a waived pair (set when it is, cleared when its
    /// waivers end; a cleared flag is always right, a set one only asks the map).
    flagged: Vec<bool>,
    /// Each vertex's waived partners, both ways round.
    partners: HashMap<u32, SmallVec<[u32; 4]>>,
    /// The vertices kept by contractions made without the check (a waiver taken):
    /// only their faces can face away from the input (see `turn_back`).
    kept_unchecked: Vec<u32>,
}

impl Waivers {
    /// No waived pair among `vertex_count` vertices.
    pub fn new(vertex_count: usize) -> Self {
        Waivers {
            flagged: vec![false; vertex_count],
            partners: HashMap::new(),
            kept_unchecked: Vec::new(),
        }
    }

    /// Whether `v` is an end of a waived pair.
    #[inline]
    pub fn involves(&self, v: u32) -> bool {
        self.flagged[v as usize]
    }

    /// Whether no pair is waived.
    pub fn is_empty(&self) -> bool {
        self.partners.is_empty()
    }

    /// Whether the pair `a`, `b` is waived.
    #[inline]
    pub fn contains(&self, a: u32, b: u32) -> bool {
        self.flagged[a as usize]
            && self.flagged[b as usize]
            && self.partners.get(&a).is_some_and(|p| p.contains(&b))
    }

    /// Waives the pair `a`, `b` (refused by the orientation check).
    pub fn waive(&mut self, a: u32, b: u32) {
        if self.contains(a, b) {
            return;
        }
        for (v, w) in [(a, b), (b, a)] {
            self.flagged[v as usize] = true;
            self.partners.entry(v).or_default().push(w);
        }
    }

    /// Ends the waiver of the pair `a`, `b`, contracted without the check (`b` into
    /// `a`); whether it was waived.
    pub fn take(&mut self, a: u32, b: u32) -> bool {
        if !self.contains(a, b) {
            return false;
        }
        self.kept_unchecked.push(a);
        for (v, w) in [(a, b), (b, a)] {
            self.drop_partner(v, w);
        }
        true
    }

    /// The vertices kept by contractions made without the check since the last call,
    /// in increasing order, each once.
    pub fn take_kept_unchecked(&mut self) -> Vec<u32> {
        let mut kept = std::mem::take(&mut self.kept_unchecked);
        kept.sort_unstable();
        kept.dedup();
        kept
    }

    /// Ends every waiver of `v` (it moved or was removed).
    pub fn forget(&mut self, v: u32) {
        if !self.flagged[v as usize] {
            return;
        }
        self.flagged[v as usize] = false;
        if let Some(partners) = self.partners.remove(&v) {
            for w in partners {
                self.drop_partner(w, v);
            }
        }
    }

    /// Takes `w` off the partners of `v`, clearing `v`'s flag when none is left.
    fn drop_partner(&mut self, v: u32, w: u32) {
        if let Some(list) = self.partners.get_mut(&v) {
            list.retain(|x| *x != w);
            if list.is_empty() {
                self.partners.remove(&v);
                self.flagged[v as usize] = false;
            }
        }
    }
}

/// The cost a waived pair is ranked at: [`ORIENTATION_PENALTY`] times its cost `cost`
/// (at least the floor of [`PENALTY_FLOOR_DISTANCE`] for its merged quadric `q`).
pub(super) fn penalised(cost: f64, q: &Quadric) -> f64 {
    let floor = q.weight() * PENALTY_FLOOR_DISTANCE * PENALTY_FLOOR_DISTANCE;
    cost.max(floor) * ORIENTATION_PENALTY
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn waivers_end_when_taken_or_when_an_end_moves() {
        let mut w = Waivers::new(6);
        assert!(!w.contains(0, 1));
        w.waive(0, 1);
        w.waive(1, 2);
        w.waive(3, 4);
        assert!(w.contains(1, 0) && w.contains(2, 1) && w.contains(4, 3));
        assert!(!w.contains(0, 2), "both flagged, not partners");
        assert!(w.take(1, 0));
        assert!(!w.take(0, 1), "taken once");
        assert!(!w.flagged[0], "no waiver of 0 is left");
        w.forget(2);
        assert!(!w.contains(1, 2));
        assert!(!w.flagged[1] && !w.flagged[2]);
        assert!(w.contains(3, 4), "other pairs keep theirs");
        w.forget(5);
        assert!(w.contains(3, 4));
    }

    #[test]
    fn a_zero_cost_is_penalised_from_the_floor() {
        let q = Quadric::from_plane(qem_core::DVec3::Z, 0.0);
        let floor = q.weight() * 1e-12;
        assert_eq!(penalised(0.0, &q), floor * ORIENTATION_PENALTY);
        assert_eq!(penalised(1.0, &q), ORIENTATION_PENALTY);
    }
}
