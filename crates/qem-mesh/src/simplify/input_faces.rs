//! [`InputFaces`]: what the run asks of each input triangle for as long as it lasts,
//! its facing (the fold-over check's reference, [`Facing`]) and its weighted face
//! plane (exact quadrics' bookkeeping, [`super::pass_exact`]).
//!
//! Two ways to give them, the same bits either way:
//! - **kept**, one [`Facing`] (4 bytes) and, with exact quadrics, one
//!   [`WeightedPlane`] (40 bytes) per triangle, computed at the setup;
//! - **read from the orientation check's index**, when the check is on: the index
//!   holds every input triangle's corners in the loop's frame (the very points the
//!   setup computed both from, bit for bit, corner order kept), so both are computed
//!   again from them when asked, and only each triangle's place in the index is kept
//!   (4 bytes a triangle).
//!
//! Why: the kept arrays were 52 of the defaults' about 293 bytes per input triangle
//! at the loop's peak, and they only repeated what the index already holds (issue 30's
//! memory budget).

use super::checks::Facing;
use crate::measure::TriangleBvh;
use qem_core::{DVec3, Quadric, WeightedPlane};
use std::sync::Arc;

/// Each input triangle's facing and weighted face plane (see the module docs), by the
/// engine's triangle number.
#[derive(Debug)]
pub(super) struct InputFaces {
    source: Source,
    /// The constant added to each face's area in its plane's weight (`None`: every
    /// plane weighs 1), as the setup weighted the planes.
    area_offset: Option<f64>,
}

#[derive(Debug)]
enum Source {
    /// Computed once and kept; `planes` is empty without exact quadrics.
    Kept {
        facing: Vec<Facing>,
        planes: Vec<WeightedPlane>,
    },
    /// Computed when asked from the corners of triangle `slot[t]` of the index.
    Indexed {
        index: Arc<TriangleBvh>,
        slot: Vec<u32>,
    },
}

impl InputFaces {
    /// The facings and planes the setup computed, kept (`planes` empty when no plane
    /// will be asked), with the planes' area weighting `area_offset`.
    pub fn kept(facing: Vec<Facing>, planes: Vec<WeightedPlane>, area_offset: Option<f64>) -> Self {
        InputFaces {
            source: Source::Kept { facing, planes },
            area_offset,
        }
    }

    /// The input faces read from `index`: triangle `t`'s from triangle `slot[t]` of
    /// it, planes weighted with `area_offset`. `index` must hold the same triangles,
    /// in the loop's frame, corners in the same order. `None` when `slot` places a
    /// triangle outside the index (an index built from a mesh gives every triangle a
    /// slot, so this is a guard, not a case the engine meets).
    pub fn from_index(
        index: Arc<TriangleBvh>,
        slot: Vec<u32>,
        area_offset: Option<f64>,
    ) -> Option<Self> {
        let placed = index.triangle_count();
        if slot.iter().any(|&s| s as usize >= placed) {
            return None;
        }
        Some(InputFaces {
            source: Source::Indexed { index, slot },
            area_offset,
        })
    }

    /// The corners of triangle `t` as the setup saw them (read from the index).
    #[inline]
    fn indexed_corners(index: &TriangleBvh, slot: &[u32], t: u32) -> [DVec3; 3] {
        index.corners(slot[t as usize]).map(DVec3::from_array)
    }

    /// Which way input triangle `t` faces.
    #[inline]
    pub fn facing(&self, t: u32) -> Facing {
        match &self.source {
            Source::Kept { facing, .. } => facing[t as usize],
            Source::Indexed { index, slot } => {
                let [a, b, c] = Self::indexed_corners(index, slot, t);
                Facing::of((b - a).cross(c - a))
            }
        }
    }

    /// Input triangle `t`'s weighted face plane (asked only with exact quadrics).
    #[inline]
    pub fn plane(&self, t: u32) -> WeightedPlane {
        match &self.source {
            Source::Kept { planes, .. } => planes[t as usize],
            Source::Indexed { index, slot } => {
                let [a, b, c] = Self::indexed_corners(index, slot, t);
                weighted_plane(a, b, c, self.area_offset)
            }
        }
    }

    /// The constant the face planes' weights add to their areas (`None`: unit
    /// weights).
    #[cfg(test)]
    pub fn area_offset(&self) -> Option<f64> {
        self.area_offset
    }

    /// Whether the faces are read from an index (rather than kept).
    #[cfg(test)]
    pub fn reads_from_index(&self) -> bool {
        matches!(self.source, Source::Indexed { .. })
    }

    /// The quadric of input triangle `t`'s face plane.
    #[inline]
    pub fn quadric(&self, t: u32) -> Quadric {
        self.plane(t).quadric()
    }
}

/// The plane of triangle `a b c` weighted by its area plus `area_offset`, or by 1
/// when there is no offset: the one weighting of face planes, at the setup and when
/// read again.
#[inline]
pub(super) fn weighted_plane(
    a: DVec3,
    b: DVec3,
    c: DVec3,
    area_offset: Option<f64>,
) -> WeightedPlane {
    match area_offset {
        Some(extra) => WeightedPlane::from_triangle_area_plus(a, b, c, extra),
        None => WeightedPlane::from_triangle_unweighted(a, b, c),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::IndexedMesh;

    /// Read from the index or kept, every facing and plane has the same bits.
    #[test]
    fn facings_and_planes_read_from_the_index_are_the_kept_ones() {
        let positions = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.1, 0.0],
            [0.2, 1.0, 0.3],
            [1.3, 1.1, -0.7],
            [0.4, 0.3, 1.9],
        ];
        let triangles = vec![[0, 1, 2], [1, 3, 2], [2, 3, 4], [4, 0, 2]];
        let mesh = IndexedMesh::new(positions.clone(), triangles.clone());
        let corners = |t: usize| triangles[t].map(|v| DVec3::from_array(positions[v as usize]));
        for area_offset in [None, Some(0.25)] {
            let facing = (0..4)
                .map(|t| {
                    let [a, b, c] = corners(t);
                    Facing::of((b - a).cross(c - a))
                })
                .collect();
            let planes = (0..4)
                .map(|t| {
                    let [a, b, c] = corners(t);
                    weighted_plane(a, b, c, area_offset)
                })
                .collect();
            let kept = InputFaces::kept(facing, planes, area_offset);
            let (index, slots) = TriangleBvh::with_slots(&mesh);
            let index = Arc::new(index);
            let outside = vec![0, 1, 2, 4];
            assert!(InputFaces::from_index(Arc::clone(&index), outside, area_offset).is_none());
            let read = InputFaces::from_index(index, slots, area_offset).expect("all placed");
            for t in 0..4 {
                assert_eq!(read.facing(t), kept.facing(t));
                assert_eq!(read.plane(t), kept.plane(t));
            }
        }
    }
}
