//! The orientation check: a face the loop moves must still face the same way as the
//! input surface nearest to it.
//!
//! Why the fold-over check is not enough: it compares a face with itself before the
//! move and with the input face it descends from. A large face that spans a crease or
//! a thin part can pass both and still lie, at its centroid, closest to input faces that
//! face the other way: a face of the opposite side of a thin fin, or the far wall of a
//! fold. Metro-style tools count such a face as flipped (the side-by-side harness does:
//! output normal · normal of the input face nearest to the output face's centroid < 0),
//! and rightly: it shades inside out and its centroid sits on the wrong side of the
//! surface. Seen before this check: 0.03-0.35% of the output faces on 5 of the 9 clean
//! corpus scans at ratio 0.1.
//!
//! The test: for each face a contraction would move, find the input triangles nearest
//! to the face's new centroid (up to [`NEAR_COUNT`] within [`NEAR_FACTOR`] of the
//! nearest distance, so a centroid over a crease hears from both sides) and refuse if
//! any of them faces away (normal dot product ≤ 0).

use crate::measure::TriangleBvh;
use crate::IndexedMesh;
use qem_core::{DVec3, Frame};
use std::sync::Arc;

/// Input triangles up to this factor farther than the nearest one count as "nearest".
/// Why not 1: a centroid over a shared edge or vertex is equally near to several
/// triangles (ties), and a nearest-face search elsewhere (the harness looks among the 8
/// triangles with the nearest centroids) may settle on a slightly farther one.
const NEAR_FACTOR: f64 = 1.5;

/// At most this many of them are asked, the nearest first. Why a cap: above a finely
/// cut region (CAD fillets, fans of slivers) the ball holds hundreds of triangles and
/// the search cost grew with them: a CAD soup (ps_mk4_gantry, 50k triangles) took 31 s
/// instead of 0.4 s without the check. Why 8: the side-by-side harness asks the 8
/// triangles with the nearest centroids; and 8 covers the fan around a vertex of
/// ordinary valence, the commonest tie.
const NEAR_COUNT: usize = 8;

/// An absolute margin (normalised units, where the model's diagonal is about 1) so that
/// a centroid lying on the input surface (distance 0) still gathers every triangle
/// through that point.
const NEAR_MARGIN: f64 = 1e-9;

/// Widening of the quick test's radius, far above the rounding of the distances it is
/// built from, so that it never looks at less than the full test would.
const QUICK_RADIUS_FACTOR: f64 = 1.0 + 1e-9;

/// A face without a hint in [`InputSurface`]'s table.
const NO_HINT: u32 = u32::MAX;

/// What the quick tests of [`InputSurface::agrees`] found (also the answer of
/// [`InputSurface::agrees_quickly`]).
pub(super) enum Quick {
    /// The face agrees; `settled` is the triangle to become its hint, if any.
    Agrees { settled: Option<u32> },
    /// Only the full test can tell; `known2` bounds the nearest squared distance.
    Undecided { known2: Option<f64> },
}

/// A face's centroid and (unnormalised) normal.
fn centroid_and_normal(corners: [DVec3; 3]) -> (DVec3, DVec3) {
    let normal = (corners[1] - corners[0]).cross(corners[2] - corners[0]);
    ((corners[0] + corners[1] + corners[2]) / 3.0, normal)
}

/// The input surface, indexed for nearest-triangle queries, in normalised units.
#[derive(Debug)]
pub(super) struct InputSurface {
    /// Shared with [`super::input_faces::InputFaces`], which reads the input
    /// triangles' facings and planes from it.
    bvh: Arc<TriangleBvh>,
    /// Reused query result.
    near: Vec<u32>,
    /// Per face, an input triangle near it: at first the face's own input triangle,
    /// then the nearest one at the face's last full test, or the previous face's
    /// triangle when a quick test with it passed (in the pass-based order, also as a
    /// speculation found it, given with [`set_hint`](Self::set_hint)); [`NO_HINT`]
    /// when there is none yet. Its distance to the face's new centroid bounds the
    /// nearest distance from above, which is what the quick test needs (and lets the
    /// full test prune from its first node). Any triangle would give the same answers;
    /// a nearer one gives them sooner.
    ///
    /// Indexed by a face number the caller chooses: the slot index of a store face in
    /// the greedy order, the triangle's index in the pass-based one.
    hints: Vec<u32>,
}

impl InputSurface {
    /// Indexes the cleaned mesh's triangles in the loop's frame; also returns where
    /// each went (`slots[i]`: the index's number for the cleaned mesh's triangle `i`),
    /// for [`seed_hints`](Self::seed_hints).
    pub fn new(cleaned: &IndexedMesh, frame: &Frame) -> (InputSurface, Vec<u32>) {
        // The corners in the loop's frame, mapped as the index gathers them (a
        // normalised copy of the mesh first would cost its size again at the peak).
        let (bvh, slots) = TriangleBvh::from_triangles(cleaned, |p| {
            frame.to_normalized(DVec3::from_array(p)).to_array()
        });
        let surface = InputSurface {
            bvh: Arc::new(bvh),
            near: Vec::new(),
            hints: Vec::new(),
        };
        (surface, slots)
    }

    /// Gives each face its own input triangle as its first hint: `hints` pairs each
    /// face's number (see `hints`) with the index slot of its input triangle (the
    /// loops take those from what [`new`](Self::new) returned, through their own
    /// numbering).
    ///
    /// Why seed the hints: without one, a face's first test is a full nearest search
    /// (on the dragon at ratio 0.1, about 9 in 10 of the full searches). Any triangle
    /// would do for correctness (a hint only bounds the nearest distance from above);
    /// the face's own input triangle is the nearest one.
    pub fn seed_hints(&mut self, hints: impl Iterator<Item = (usize, u32)> + Clone) {
        // Sized from the numbers rather than grown (growing by doubling would hold up
        // to twice the memory).
        let len = hints.clone().map(|(f, _)| f + 1).max().unwrap_or(0);
        self.hints = vec![NO_HINT; len];
        for (face, slot) in hints {
            self.hints[face] = slot;
        }
    }

    /// How many faces have a slot in the hints (every face once seeded).
    pub fn hint_count(&self) -> usize {
        self.hints.len()
    }

    /// The hint of `face`, if it has one.
    #[inline]
    fn hint(&self, face: usize) -> Option<u32> {
        self.hints.get(face).copied().filter(|&h| h != NO_HINT)
    }

    /// Whether face `face`, moved to these corners (normalised units), faces the same
    /// way as every input triangle nearest to its centroid.
    ///
    /// Two ways to the same answer. The quick test: if the face's hint triangle (see
    /// `hints`) is at distance `u` from the new centroid, the nearest
    /// distance `d` is at most `u`, so every triangle the full test would ask lies
    /// within `NEAR_FACTOR·u + NEAR_MARGIN`; if no triangle in that ball faces away
    /// (a search that skips whole subtrees whose normals all agree), the answer is yes.
    /// Otherwise the full test: find the nearest triangles and ask each of them.
    #[inline]
    pub fn agrees(
        &mut self,
        face: usize,
        corners: [DVec3; 3],
        neighbour_hint: &mut Option<u32>,
    ) -> bool {
        if self.hints.len() <= face {
            self.hints.resize(face + 1, NO_HINT);
        }
        let InputSurface { bvh, near, hints } = self;
        Nearest { bvh }.agrees(&mut hints[face], near, corners, neighbour_hint)
    }

    /// The quick tests of [`agrees`](Self::agrees) alone, without touching the hints
    /// (so many faces can be asked at once on several cores). When they show that the
    /// face agrees, the answer holds the triangle that should become its hint, if any:
    /// the caller may give it with [`set_hint`](Self::set_hint), or not (hints change
    /// the work, never the answers).
    #[inline]
    pub fn agrees_quickly(
        &self,
        face: usize,
        corners: [DVec3; 3],
        neighbour_hint: &mut Option<u32>,
    ) -> Quick {
        let (centroid, normal) = centroid_and_normal(corners);
        let nearest = Nearest { bvh: &self.bvh };
        nearest.quick_verdict(self.hint(face), centroid, normal, neighbour_hint)
    }

    /// The index, for asking [`Nearest::agrees`] with hints held elsewhere, and the
    /// hints, one per face (for the blocks of `pass_blocks`, each with its faces'
    /// share of the hints).
    pub fn parts(&mut self) -> (Nearest<'_>, &mut [u32]) {
        (Nearest { bvh: &self.bvh }, &mut self.hints)
    }

    /// The index of the input triangles, to share.
    pub fn index(&self) -> Arc<TriangleBvh> {
        Arc::clone(&self.bvh)
    }

    /// Makes `t` the hint of `face`.
    pub fn set_hint(&mut self, face: usize, t: u32) {
        if self.hints.len() <= face {
            self.hints.resize(face + 1, NO_HINT);
        }
        self.hints[face] = t;
    }
}

/// The input surface's index, asked with a face's hint held by the caller (one slot of
/// [`InputSurface`]'s hints, or of a block's share of them).
#[derive(Clone, Copy)]
pub(super) struct Nearest<'a> {
    bvh: &'a TriangleBvh,
}

impl Nearest<'_> {
    /// [`InputSurface::agrees`] for a face whose hint is `hint` ([`NO_HINT`] when it
    /// has none; updated as there), with `near` as scratch.
    #[inline]
    pub fn agrees(
        &self,
        hint: &mut u32,
        near: &mut Vec<u32>,
        corners: [DVec3; 3],
        neighbour_hint: &mut Option<u32>,
    ) -> bool {
        let (centroid, normal) = centroid_and_normal(corners);
        let own_hint = (*hint != NO_HINT).then_some(*hint);
        let known2 = match self.quick_verdict(own_hint, centroid, normal, neighbour_hint) {
            Quick::Agrees { settled } => {
                if let Some(t) = settled {
                    *hint = t;
                }
                return true;
            }
            Quick::Undecided { known2 } => known2,
        };
        let nearest = self.bvh.nearest_triangles_within(
            centroid.to_array(),
            known2.unwrap_or(f64::INFINITY),
            NEAR_FACTOR,
            NEAR_MARGIN,
            NEAR_COUNT,
            near,
        );
        if let Some(t) = nearest {
            *hint = t;
            *neighbour_hint = Some(t);
        }
        // A zero-area input triangle (cleaning drops exact ones) has no say.
        // (Normals computed here rather than kept: 24 bytes per input triangle saved,
        // and this full test is rare once every face has a hint.)
        near.iter().all(|&i| {
            let [a, b, c] = self.bvh.corners(i).map(DVec3::from_array);
            let n = (b - a).cross(c - a);
            n.dot(normal) > 0.0 || n == DVec3::ZERO
        })
    }

    /// The quick tests of [`agrees`](Self::agrees): with the face's own hint, then with
    /// the neighbour's when it is nearer.
    #[inline]
    fn quick_verdict(
        &self,
        own_hint: Option<u32>,
        centroid: DVec3,
        normal: DVec3,
        neighbour_hint: &mut Option<u32>,
    ) -> Quick {
        let previous = *neighbour_hint;
        let hint = own_hint.or(previous);
        *neighbour_hint = hint;
        let mut known2 = hint.and_then(|h| self.bvh.distance_squared_to(centroid.to_array(), h));
        if self.quick_test(centroid, normal, known2) {
            return Quick::Agrees { settled: None };
        }
        // Before the full test, the quick test once more with the triangle the face
        // checked before this one settled on, when it is nearer than this face's own
        // hint. Why: a contraction can move a face far from the input triangle it
        // remembers (a fan's centre merging into its rim moves every fan face across
        // the cap), so its own hint's ball reaches faces at right angles and the quick
        // test fails; the neighbour's nearest triangle, found a moment ago next to
        // the same moved vertex, is usually close. Either ball gives the same answer
        // (see above); only the work differs.
        if let Some(p) = previous.filter(|&p| Some(p) != hint) {
            let p2 = self.bvh.distance_squared_to(centroid.to_array(), p);
            if p2.is_some_and(|p2| known2.is_none_or(|u2| p2 < u2)) {
                known2 = p2;
                if self.quick_test(centroid, normal, known2) {
                    *neighbour_hint = Some(p);
                    return Quick::Agrees { settled: Some(p) };
                }
            }
        }
        Quick::Undecided { known2 }
    }

    /// The quick test of [`agrees`](Self::agrees): with `known2` a squared distance
    /// from `centroid` to some input triangle, whether no triangle within the ball it
    /// bounds faces away from `normal` (false also when there is no such bound).
    #[inline]
    fn quick_test(&self, centroid: DVec3, normal: DVec3, known2: Option<f64>) -> bool {
        let Some(u2) = known2 else {
            return false;
        };
        let radius = (u2.sqrt() * NEAR_FACTOR + NEAR_MARGIN) * QUICK_RADIUS_FACTOR;
        radius.is_finite()
            && !self
                .bvh
                .any_facing_away(centroid.to_array(), radius, normal.to_array())
    }
}
