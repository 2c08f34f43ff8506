//! Which contractions are allowed: fold-over (degenerate, flipped and sliver faces),
//! topology (the link condition) and locks. Cheapest first; none allocates.

use super::engine::{Engine, Settings};
use crate::clean::cross_underflows;
use crate::store::{slot_index, EdgeClass, EdgeKey, FaceKey, VertexClass, VertexKey};
use qem_core::{DVec3, Frame};

/// Why a contraction was refused (each has a counter in the report).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Rejection {
    /// A surviving face would have (numerically) zero area.
    Degenerate,
    /// A surviving face's normal would turn past the allowed angle.
    Flip,
    /// A surviving face would become a sliver below the quality threshold.
    Sliver,
    /// The contraction would change the topology (or cannot be shown not to).
    Topology,
    /// Both ends are locked, or a locked vertex would lose its last face.
    Locked,
    /// The contraction would pinch, close or remove a border loop.
    Border,
    /// An edge contraction would merge two faces `a x y` and `b x y` into one.
    Merge,
    /// A moved face would face away from the input surface nearest to it.
    Orientation,
}

/// `4√3·area / (l₀² + l₁² + l₂²)` from twice the area (`double_area`): 1 for an
/// equilateral triangle, 0 for a degenerate one.
fn quality(p0: DVec3, p1: DVec3, p2: DVec3, double_area: f64) -> f64 {
    let sum = p0.distance_squared(p1) + p1.distance_squared(p2) + p2.distance_squared(p0);
    if sum > 0.0 {
        2.0 * 3f64.sqrt() * double_area / sum
    } else {
        0.0
    }
}

/// Whether the normal turned from `old` to `new` by more than the angle whose cosine is
/// `min_cos`: `old·new < min_cos·|old|·|new|`, compared in squares (`new_squared` is
/// `|new|²`) so that no square root is taken.
#[inline]
fn turned_past(old: DVec3, new: DVec3, new_squared: f64, min_cos: f64) -> bool {
    let dot = old.dot(new);
    let bound = min_cos * min_cos * old.length_squared() * new_squared;
    if min_cos >= 0.0 {
        dot < 0.0 || dot * dot < bound
    } else {
        dot < 0.0 && dot * dot > bound
    }
}

/// [`Engine::is_zero_area`], from the parts of a run it reads (the pass-based order
/// uses it too).
pub(super) fn is_zero_area(
    frame: &Frame,
    settings: &Settings,
    world_corners: [[f64; 3]; 3],
) -> bool {
    let [p0, p1, p2] = world_corners.map(|c| frame.to_normalized(DVec3::from_array(c)));
    let squared = (p1 - p0).cross(p2 - p0).length_squared();
    squared.is_nan()
        || squared <= settings.min_double_area_squared
        || (settings.world_may_underflow && cross_underflows(world_corners))
}

/// The fold-over rules for one surviving face whose corners move from `old` to `new`
/// (normalised frame), shared by both contraction orders: zero area (or NaN, only from
/// overflow), a normal turned past the allowed angle or against the input face's
/// (`input_normal`, asked only when the angle check is on), a sliver worse than before.
/// `world_underflows` is asked only for a model so small that its cross products can
/// underflow in world units (see `Settings::world_may_underflow`). Squared lengths
/// throughout: no square root unless the sliver test runs.
#[inline]
pub(super) fn moved_face_verdict(
    settings: &Settings,
    old: [DVec3; 3],
    new: [DVec3; 3],
    input_normal: impl FnOnce() -> DVec3,
    world_underflows: impl FnOnce() -> bool,
) -> Result<(), Rejection> {
    let new_normal = (new[1] - new[0]).cross(new[2] - new[0]);
    let new_squared = new_normal.length_squared();
    if new_squared.is_nan()
        || new_squared <= settings.min_double_area_squared
        || (settings.world_may_underflow && world_underflows())
    {
        return Err(Rejection::Degenerate);
    }
    let old_normal = (old[1] - old[0]).cross(old[2] - old[0]);
    if let Some(min_cos) = settings.min_normal_cos {
        // The second test stops a face from turning away from the input face it
        // descends from in several small steps.
        if turned_past(old_normal, new_normal, new_squared, min_cos)
            || input_normal().dot(new_normal) < 0.0
        {
            return Err(Rejection::Flip);
        }
    }
    if let Some(min_quality) = settings.min_quality {
        let q_new = quality(new[0], new[1], new[2], new_squared.sqrt());
        if q_new < min_quality && q_new < quality(old[0], old[1], old[2], old_normal.length()) {
            return Err(Rejection::Sliver);
        }
    }
    Ok(())
}

impl Engine {
    /// Every check of contracting `b` into `a` at `world` (`ab` is their edge, if any);
    /// the orientation check only when `orientation` is true (it is waived for a pair
    /// queued again at a penalty).
    pub(super) fn check(
        &mut self,
        a: VertexKey,
        b: VertexKey,
        ab: Option<EdgeKey>,
        world: DVec3,
        orientation: bool,
    ) -> Result<(), Rejection> {
        // The faces around both ends, gathered once for every check that walks them.
        let mut around = std::mem::take(&mut self.around_scratch);
        self.store.faces_of_vertex(a, &mut around[0]);
        self.store.faces_of_vertex(b, &mut around[1]);
        let verdict = self.check_around(a, b, ab, world, orientation, &around);
        self.around_scratch = around;
        verdict
    }

    /// [`check`](Self::check) with `around` = the faces of `a` and of `b`.
    fn check_around(
        &mut self,
        a: VertexKey,
        b: VertexKey,
        ab: Option<EdgeKey>,
        world: DVec3,
        orientation: bool,
        around: &[Vec<FaceKey>; 2],
    ) -> Result<(), Rejection> {
        self.fold_over(a, b, world, around)?;
        // In topology mode the link condition below refuses these merges too (its edge
        // half is the same test), so it is not run twice.
        if ab.is_some()
            && !self.settings.preserve_topology
            && self.would_merge_faces(a, b, &around[0])
        {
            return Err(Rejection::Merge);
        }
        if self.settings.keep_border_loops {
            if let Some(ab) = ab {
                if !self.keeps_border_loops(a, b, ab) {
                    return Err(Rejection::Border);
                }
            }
        }
        if self.settings.preserve_topology && !self.keeps_topology(a, b, ab) {
            return Err(Rejection::Topology);
        }
        if self.settings.any_locked && self.locked_vertex_would_vanish(a, b) {
            return Err(Rejection::Locked);
        }
        // Last: the only check that searches outside the neighbourhood.
        if orientation
            && self.input_surface.is_some()
            && !self.faces_agree_with_input(a, b, world, around)
        {
            return Err(Rejection::Orientation);
        }
        Ok(())
    }

    /// Whether a triangle with these world corners is (numerically) zero-area for the
    /// loop: its double area in the normalised frame is at most the loop's bound (or
    /// NaN), or its cross product underflows in world units. The same test decides which
    /// contractions are refused and which faces are dropped at output, so a face the
    /// loop kept is never dropped afterwards (the output's own frame can be larger than
    /// the input's when a placement leaves the input's box, making a relative test there
    /// stricter: a `simplify_soup` fuzz finding emptied the output that way).
    pub(super) fn is_zero_area(&self, world_corners: [[f64; 3]; 3]) -> bool {
        is_zero_area(&self.frame, &self.settings, world_corners)
    }

    /// Whether moving `a` and `b` to `world` would leave a surviving face of either
    /// with (numerically) zero area, turn its normal past the threshold, or make it a
    /// sliver worse than it was.
    ///
    /// Zero area is always refused: such a face would be dropped at output, and if it
    /// were the last one the output would be empty. Why the sliver test also asks for
    /// "worse than before": an input full of slivers (CAD exports) would otherwise
    /// block every contraction near them, even those that improve them.
    fn fold_over(
        &self,
        a: VertexKey,
        b: VertexKey,
        world: DVec3,
        around: &[Vec<FaceKey>; 2],
    ) -> Result<(), Rejection> {
        let moved = self.frame.to_normalized(world);
        for faces in around {
            for &f in faces {
                let corners = self.store.face_vertices(f);
                if corners.contains(&a) && corners.contains(&b) {
                    continue; // collapses with the pair
                }
                let old = corners.map(|c| self.normalized_position(c));
                let new = std::array::from_fn::<_, 3, _>(|i| {
                    if corners[i] == a || corners[i] == b {
                        moved
                    } else {
                        old[i]
                    }
                });
                moved_face_verdict(
                    &self.settings,
                    old,
                    new,
                    || *self.original_normals.get(f),
                    || {
                        cross_underflows(corners.map(|c| {
                            if c == a || c == b {
                                world.to_array()
                            } else {
                                self.store.position(c)
                            }
                        }))
                    },
                )?;
            }
        }
        Ok(())
    }

    /// Whether every face that contracting `b` into `a` at `world` moves faces the same
    /// way as the input surface nearest to its new centroid (see
    /// [`super::orientation`]). Faces on both `a` and `b` collapse and are not asked.
    fn faces_agree_with_input(
        &mut self,
        a: VertexKey,
        b: VertexKey,
        world: DVec3,
        around: &[Vec<FaceKey>; 2],
    ) -> bool {
        let Some(mut surface) = self.input_surface.take() else {
            return true;
        };
        let moved = self.frame.to_normalized(world);
        let mut agree = true;
        // A face seen for the first time borrows the hint of the face checked before it.
        let mut neighbour_hint = None;
        'vertices: for faces in around {
            for &f in faces {
                let corners = self.store.face_vertices(f);
                if corners.contains(&a) && corners.contains(&b) {
                    continue;
                }
                let new = corners.map(|c| {
                    if c == a || c == b {
                        moved
                    } else {
                        self.normalized_position(c)
                    }
                });
                if !surface.agrees(slot_index(f), new, &mut neighbour_hint) {
                    agree = false;
                    break 'vertices;
                }
            }
        }
        self.input_surface = Some(surface);
        agree
    }

    /// Whether contracting the edge `ab` would merge a face `a x y` with a face `b x y`
    /// (the edge half of the link condition). The merged pair leaves one face where two
    /// were, so the edges `x–y` that had two faces get one: a closed surface opens a
    /// hole, or two sheets that met along `x y` are glued into one. Seen on the corpus
    /// before this check: c3d_nefertiti (closed) came out of a 50% run with 9 holes.
    /// Virtual pairs are not asked: joining parts is what they are for.
    ///
    /// Cost: for each face of `a` not on `ab`, a search of one fan at `b`; faces on `ab`
    /// are skipped since they collapse.
    fn would_merge_faces(&self, a: VertexKey, b: VertexKey, faces_of_a: &[FaceKey]) -> bool {
        faces_of_a.iter().any(|&f| {
            let corners = self.store.face_vertices(f);
            if corners.contains(&b) {
                return false;
            }
            let mut others = corners.iter().copied().filter(|&c| c != a);
            match (others.next(), others.next()) {
                (Some(x), Some(y)) => self.store.find_face(b, x, y).is_some(),
                _ => false,
            }
        })
    }

    /// Whether contracting the edge `ab` keeps every border loop: when both ends are on
    /// a border (an edge with one face), `ab` must be a border edge (otherwise two points
    /// of the border, perhaps of two loops, are pinched together), and no third vertex
    /// may be joined to both by border edges (that would close a loop of three edges,
    /// or remove a lone triangle with its loop). Cheap when either end is interior: one
    /// pass over each star.
    fn keeps_border_loops(&self, a: VertexKey, b: VertexKey, ab: EdgeKey) -> bool {
        let on_border = |v| {
            self.store
                .star(v)
                .iter()
                .any(|&e| self.store.fan(e).len() == 1)
        };
        if !on_border(a) || !on_border(b) {
            return true;
        }
        if self.store.fan(ab).len() != 1 {
            return false;
        }
        !self.store.star(a).iter().any(|&e| {
            self.store.fan(e).len() == 1
                && self.store.other_vertex(e, a).is_some_and(|x| {
                    x != b
                        && self
                            .store
                            .find_edge(b, x)
                            .is_some_and(|bx| self.store.fan(bx).len() == 1)
                })
        })
    }

    /// The link condition of Dey, Edelsbrunner, Guha and Nekhayev ("Topology preserving
    /// edge contraction", 1999) on a 2-manifold with border, and a refusal elsewhere.
    ///
    /// For a border, their extension cones the border off with a dummy vertex ω (a
    /// face `x y ω` for every border edge `x–y`) and asks the link condition of the
    /// closed result. In terms of the real mesh, besides `Lk a ∩ Lk b = Lk ab`:
    /// - ω is a common neighbour when `a` and `b` are both on a border, so `a–b` must be
    ///   a border edge itself (otherwise the contraction pinches the border);
    /// - `x ω` is a common link edge when `a–x` and `b–x` are both border edges, which
    ///   would close a border loop of three edges (or collapse a lone triangle).
    fn keeps_topology(&self, a: VertexKey, b: VertexKey, ab: Option<EdgeKey>) -> bool {
        let Some(ab) = ab else {
            return false; // a virtual pair joins parts or closes a gap
        };
        let border_edge = match self.store.classify_edge(ab) {
            EdgeClass::Boundary => true,
            EdgeClass::Manifold => false,
            EdgeClass::Wire | EdgeClass::NonManifold => return false,
        };
        let on_border = |v| match self.store.classify_vertex(v) {
            VertexClass::Interior => Some(false),
            VertexClass::Boundary => Some(true),
            VertexClass::Isolated | VertexClass::NonManifold => None,
        };
        let (Some(a_border), Some(b_border)) = (on_border(a), on_border(b)) else {
            return false;
        };
        if a_border && b_border && !border_edge {
            return false;
        }
        if !self.store.link_condition(a, b) {
            return false;
        }
        if a_border && b_border {
            for &e in self.store.star(a) {
                if self.store.fan(e).len() != 1 {
                    continue;
                }
                let Some(x) = self.store.other_vertex(e, a) else {
                    continue;
                };
                if x != b
                    && self
                        .store
                        .find_edge(b, x)
                        .is_some_and(|bx| self.store.fan(bx).len() == 1)
                {
                    return false;
                }
            }
        }
        true
    }

    /// Whether contracting `b` into `a` would leave a locked vertex without a face (it
    /// would then be missing from the output): `a` itself, or a locked common neighbour
    /// whose faces all collapse or merge.
    fn locked_vertex_would_vanish(&mut self, a: VertexKey, b: VertexKey) -> bool {
        let mut faces = std::mem::take(&mut self.face_scratch);
        let mut vanish = false;
        if self.state[a].locked {
            // The merged vertex keeps every face of a or b that does not hold both. A
            // face b x y that merges into a x y leaves a x y, so a has a face as soon
            // as one of the two has a face without the other.
            let mut left = 0usize;
            for v in [a, b] {
                self.store.faces_of_vertex(v, &mut faces);
                let other = if v == a { b } else { a };
                left += faces
                    .iter()
                    .filter(|&&f| !self.store.face_vertices(f).contains(&other))
                    .count();
            }
            vanish = left == 0;
        }
        if !vanish {
            for i in 0..self.store.star(a).len() {
                let e = self.store.star(a)[i];
                let Some(w) = self.store.other_vertex(e, a) else {
                    continue;
                };
                if w == b || !self.state[w].locked || self.store.find_edge(b, w).is_none() {
                    continue;
                }
                // w's faces on both a and b collapse; w b z merges when w a z exists.
                self.store.faces_of_vertex(w, &mut faces);
                let left = faces
                    .iter()
                    .filter(|&&f| {
                        let c = self.store.face_vertices(f);
                        let (has_a, has_b) = (c.contains(&a), c.contains(&b));
                        if has_a && has_b {
                            return false;
                        }
                        if has_b {
                            let z = c.into_iter().find(|&v| v != w && v != b);
                            return z.is_none_or(|z| self.store.find_face(w, a, z).is_none());
                        }
                        true
                    })
                    .count();
                if left == 0 {
                    vanish = true;
                    break;
                }
            }
        }
        self.face_scratch = faces;
        vanish
    }
}

#[cfg(test)]
mod tests {
    use super::turned_past;
    use qem_core::DVec3;

    /// `turned_past` against the angle computed with `acos`.
    #[test]
    fn turned_past_matches_the_angle() {
        let old = DVec3::new(0.0, 0.0, 2.0);
        for degrees in [0.0f64, 30.0, 59.0, 61.0, 89.0, 91.0, 120.0, 179.0] {
            let t = degrees.to_radians();
            let new = DVec3::new(3.0 * t.sin(), 0.0, 3.0 * t.cos());
            for limit in [45.0f64, 60.0, 90.0, 135.0] {
                let expected = degrees > limit;
                let got = turned_past(old, new, new.length_squared(), limit.to_radians().cos());
                assert_eq!(got, expected, "{degrees}° against {limit}°");
            }
        }
    }
}
