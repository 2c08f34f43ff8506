//! Attributes in the engine: the wedges (a vertex's distinct combinations of
//! attribute values and material), their attribute quadrics, the rule that keeps
//! seams, and the attribute values of the output.
//!
//! Every corner of a live triangle has a wedge. Two corners at one vertex share a
//! wedge when they have the same value in every channel and their faces the same
//! material; a vertex with several wedges lies on a seam (a UV seam, a hard normal, a
//! colour or material border). Each wedge keeps, per channel, the attribute quadric
//! of the triangles whose corner it is ([`AttributeQuadric`], Garland–Heckbert 98 in
//! Hoppe 99's form).
//!
//! Contracting `b` into `a`: each triangle on both ends pairs `b`'s wedge there with
//! `a`'s wedge there, and the paired wedges merge (their quadrics add). The pairing
//! must be one to one: a wedge of `b` paired with two of `a`'s, or two of `b`'s with
//! one of `a`'s, would join the two sides of a seam, and the pair is refused
//! ([`Rejection::Seam`]). `b`'s other wedges move to `a` unchanged (a vertex that
//! joins a seam keeps each side's values). So no output triangle takes a value from
//! the other side of a seam, and a seam edge contracts only along the seam.
//!
//! The cost of a pair adds, for every wedge the merged vertex would have, the error
//! left at the best values ([`AttributeQuadric::position_quadric`]), so the placement
//! weighs attributes with positions; the geometric error the report gives stays the
//! geometric quadric's. Seam edges also get the border's constraint planes, so their
//! curves keep their place as borders do.
//!
//! A wedge that never merged and whose vertex never moved keeps its input values bit
//! for bit; the others take the best values at their vertex's final place, normals
//! renormalised and colours clamped to 0–1.

use super::checks::Rejection;
use super::incidence::Incidence;
use super::options::AttributeWeights;
use super::pass_blocks::{Around, REMOVED};
use crate::attributes::{Attributes, Channel, ChannelKind, FaceLabels};
use qem_core::{AttributeQuadric, DVec3, Quadric};
use smallvec::SmallVec;
use std::collections::HashMap;

/// The engine's wedges (see the module docs).
pub(super) struct Wedges {
    /// The input's channels (values and kinds; their corners are not read).
    channels: Vec<Channel>,
    /// Per channel, its weight.
    weights: Vec<f64>,
    /// The input's labels, per cleaned-mesh triangle.
    materials: FaceLabels,
    groups: FaceLabels,
    material_libraries: Vec<Vec<u8>>,
    /// Per engine triangle, the wedge of each corner.
    corner: Vec<[u32; 3]>,
    /// Per wedge and channel (`wedge * channels + channel`): the input value index and
    /// the attribute quadric.
    input: Vec<u32>,
    quadric: Vec<AttributeQuadric>,
    /// Per wedge, whether it merged or its vertex moved (its values are then the
    /// quadric's best ones).
    touched: Vec<bool>,
}

/// `b`'s wedges paired with `a`'s by the triangles on both ends: (wedge of `b`,
/// wedge of `a`).
pub(super) type Pairing = SmallVec<[(u32, u32); 4]>;

/// Where a contraction may put the merged vertex, for the seams' sake.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Pin {
    /// Anywhere: every wedge of both ends pairs (an interior edge, or a seam edge
    /// contracted along its seam with both sides).
    Free,
    /// At `a`: `a` has a wedge the pairing leaves alone (it lies on a seam that `b`
    /// is not on), whose values would be extrapolated off its chart if `a` moved.
    A,
    /// At `b`, for the same reason.
    B,
}

impl Wedges {
    /// The wedges of the engine's triangles `triangles` (engine numbering, each from
    /// the cleaned triangle `triangle_from[t]`), positions `position` (normalised),
    /// with the cleaned mesh's `attributes`; `None` for a mesh without channels or
    /// materials.
    pub fn new(
        attributes: &Attributes,
        triangles: &[[u32; 3]],
        triangle_from: &[u32],
        position: &[DVec3],
        weights: &AttributeWeights,
    ) -> Option<Wedges> {
        if attributes.channels.is_empty() && attributes.materials.is_empty() {
            return None;
        }
        let width = attributes.channels.len();
        let mut ids: HashMap<SmallVec<[u32; 6]>, u32> = HashMap::new();
        let mut corner = Vec::with_capacity(triangles.len());
        let mut input = Vec::new();
        for (t, tri) in triangles.iter().enumerate() {
            let from = triangle_from[t] as usize;
            let material = attributes
                .materials
                .faces
                .get(from)
                .copied()
                .unwrap_or(FaceLabels::NONE);
            let mut wedges = [0u32; 3];
            for k in 0..3 {
                let mut key: SmallVec<[u32; 6]> = SmallVec::new();
                key.push(tri[k]);
                key.push(material);
                key.extend(attributes.channels.iter().map(|c| c.corners[from][k]));
                let next = ids.len() as u32;
                wedges[k] = *ids.entry(key).or_insert_with(|| {
                    input.extend(attributes.channels.iter().map(|c| c.corners[from][k]));
                    next
                });
            }
            corner.push(wedges);
        }
        let count = ids.len();
        let channel_weights: Vec<f64> = attributes
            .channels
            .iter()
            .map(|c| weights.of(c.kind))
            .collect();
        let mut quadric: Vec<AttributeQuadric> = (0..count)
            .flat_map(|_| {
                attributes
                    .channels
                    .iter()
                    .map(|c| AttributeQuadric::new(c.dimension))
            })
            .collect();
        // Each triangle's fields, added to the wedge of each of its corners.
        for (t, tri) in triangles.iter().enumerate() {
            let from = triangle_from[t] as usize;
            let p = tri.map(|v| position[v as usize]);
            for (j, c) in attributes.channels.iter().enumerate() {
                let idx = c.corners[from];
                if idx.contains(&Channel::MISSING) {
                    continue;
                }
                // Unweighted: the weight scales the error (by its square) where the
                // cost is formed, so a weight of 0 still gives the values.
                let scaled: [SmallVec<[f64; 4]>; 3] =
                    idx.map(|i| c.value(i).iter().map(|&x| f64::from(x)).collect());
                let mut one = AttributeQuadric::new(c.dimension);
                one.add_triangle(p, [&scaled[0], &scaled[1], &scaled[2]]);
                for &wedge in &corner[t] {
                    quadric[wedge as usize * width + j] += &one;
                }
            }
        }
        Some(Wedges {
            channels: attributes
                .channels
                .iter()
                .map(|c| Channel {
                    kind: c.kind,
                    name: c.name.clone(),
                    dimension: c.dimension,
                    values: c.values.clone(),
                    corners: Vec::new(),
                })
                .collect(),
            weights: channel_weights,
            materials: attributes.materials.clone(),
            groups: attributes.groups.clone(),
            material_libraries: attributes.material_libraries.clone(),
            corner,
            input,
            quadric,
            touched: vec![false; count],
        })
    }

    /// The wedge at vertex `v` of triangle `t` (whose corners are `corners`).
    fn at(&self, t: u32, corners: [u32; 3], v: u32) -> Option<u32> {
        let k = corners.iter().position(|&c| c == v)?;
        Some(self.corner[t as usize][k])
    }

    /// The pairing of contracting `b` into `a` (`around`: the live triangles of `a`
    /// and of `b`), or [`Rejection::Seam`] when it is not one to one.
    pub fn pairing(&self, a: u32, b: u32, around_a: &[Around]) -> Result<Pairing, Rejection> {
        let mut pairs = Pairing::new();
        for x in around_a.iter().filter(|x| x.corners.contains(&b)) {
            let (Some(wa), Some(wb)) = (
                self.at(x.triangle, x.corners, a),
                self.at(x.triangle, x.corners, b),
            ) else {
                continue;
            };
            match pairs.iter().find(|&&(pb, pa)| pb == wb || pa == wa) {
                Some(&(pb, pa)) if pb == wb && pa == wa => {}
                Some(_) => return Err(Rejection::Seam),
                None => pairs.push((wb, wa)),
            }
        }
        Ok(pairs)
    }

    /// The pairing of contracting `b` into `a` and where the merged vertex may go
    /// ([`Pin`]): a vertex with a wedge the pairing leaves alone stays where it is (so
    /// a seam vertex moves only along its seam, and no chart's values are
    /// extrapolated past its border, as meshoptimizer's seam rule keeps them); when
    /// both ends have such a wedge neither can stay for the other and the place is
    /// free. A virtual pair (no triangle on both) pairs nothing and keeps `a`'s place.
    pub fn plan(
        &self,
        a: u32,
        b: u32,
        around_a: &[Around],
        around_b: &[Around],
    ) -> Result<(Pairing, Pin), Rejection> {
        let pairs = self.pairing(a, b, around_a)?;
        if pairs.is_empty() {
            return Ok((pairs, Pin::A));
        }
        let left_alone = |around: &[Around], v: u32, paired: &dyn Fn(u32) -> bool| {
            around
                .iter()
                .filter_map(|x| self.at(x.triangle, x.corners, v))
                .any(|w| !paired(w))
        };
        let a_alone = left_alone(around_a, a, &|w| pairs.iter().any(|&(_, pa)| pa == w));
        let b_alone = left_alone(around_b, b, &|w| pairs.iter().any(|&(pb, _)| pb == w));
        let pin = match (a_alone, b_alone) {
            (false, false) => Pin::Free,
            (true, false) => Pin::A,
            (false, true) => Pin::B,
            // Both ends keep a wedge of their own (a vertex where several seams meet,
            // a face-normal solid's corner): no end can stay for both, and refusing
            // would leave such meshes stuck (per-face normals make every edge this
            // way). The one-to-one pairing still keeps each side's values apart.
            (true, true) => Pin::Free,
        };
        Ok((pairs, pin))
    }

    /// The attribute error of contracting `b` into `a`, as a quadric in the merged
    /// vertex's position (for each wedge the merged vertex would have, the error left
    /// at its best values), and where the vertex may go. `None` when the pair is
    /// refused ([`Wedges::plan`]).
    pub fn merged_error(
        &self,
        incidence: &Incidence,
        triangles: &[[u32; 3]],
        a: u32,
        b: u32,
    ) -> Option<(Quadric, Pin)> {
        let around_a: SmallVec<[Around; 16]> = live_around(incidence, triangles, a).collect();
        let around_b: SmallVec<[Around; 16]> = live_around(incidence, triangles, b).collect();
        let (pairs, pin) = self.plan(a, b, &around_a, &around_b).ok()?;
        let width = self.channels.len();
        let mut seen: SmallVec<[u32; 8]> = SmallVec::new();
        let mut q = Quadric::ZERO;
        let mut add = |wedge: u32, partner: Option<u32>, seen: &mut SmallVec<[u32; 8]>| {
            if seen.contains(&wedge) {
                return;
            }
            seen.push(wedge);
            if let Some(p) = partner {
                seen.push(p);
            }
            for j in 0..width {
                let mut sum = self.quadric[wedge as usize * width + j].clone();
                if let Some(p) = partner {
                    sum += &self.quadric[p as usize * width + j];
                }
                let w = self.weights[j];
                q += sum.position_quadric() * (w * w);
            }
        };
        for x in &around_a {
            if let Some(wa) = self.at(x.triangle, x.corners, a) {
                let partner = pairs.iter().find(|&&(_, pa)| pa == wa).map(|&(pb, _)| pb);
                add(wa, partner, &mut seen);
            }
        }
        for x in &around_b {
            if let Some(wb) = self.at(x.triangle, x.corners, b) {
                add(wb, None, &mut seen);
            }
        }
        Some((q, pin))
    }

    /// Records the contraction of `b` into `a`, with `around` the live triangles of
    /// `a` and of `b` before it: paired wedges merge into `a`'s, `b`'s surviving
    /// triangles take the merged wedges, and every wedge at either end is touched.
    pub fn contract(&mut self, a: u32, b: u32, around: &[Vec<Around>; 2]) {
        let Ok(pairs) = self.pairing(a, b, &around[0]) else {
            debug_assert!(false, "a refused pairing reached the contraction");
            return;
        };
        let width = self.channels.len();
        for &(wb, wa) in &pairs {
            for j in 0..width {
                let from = self.quadric[wb as usize * width + j].clone();
                self.quadric[wa as usize * width + j] += &from;
            }
        }
        for x in around.iter().flatten() {
            for (k, &c) in x.corners.iter().enumerate() {
                if c != a && c != b {
                    continue;
                }
                let w = &mut self.corner[x.triangle as usize][k];
                if c == b {
                    if let Some(&(_, wa)) = pairs.iter().find(|&&(pb, _)| pb == *w) {
                        *w = wa;
                    }
                }
                self.touched[*w as usize] = true;
            }
        }
    }

    /// The attributes of the output: for the engine's `live` triangles (each from the
    /// cleaned triangle `triangle_from[t]`), with `position` (normalised) of each
    /// vertex. Values are listed once per wedge used, in order of first use.
    pub fn output(
        &self,
        live: &[u32],
        triangles: &[[u32; 3]],
        triangle_from: &[u32],
        position: &[DVec3],
    ) -> Attributes {
        let mut number: HashMap<u32, u32> = HashMap::new();
        let mut channels: Vec<Channel> = self
            .channels
            .iter()
            .map(|c| Channel {
                kind: c.kind,
                name: c.name.clone(),
                dimension: c.dimension,
                values: Vec::new(),
                corners: Vec::with_capacity(live.len()),
            })
            .collect();
        // Per output value (one per wedge used), whether each channel has one.
        let mut present: Vec<SmallVec<[bool; 4]>> = Vec::new();
        for &t in live {
            let tri = triangles[t as usize];
            let mut out = [0u32; 3];
            for k in 0..3 {
                let wedge = self.corner[t as usize][k];
                let next = number.len() as u32;
                out[k] = *number.entry(wedge).or_insert_with(|| {
                    let p = position[tri[k] as usize];
                    let mut has = SmallVec::new();
                    for (j, ch) in channels.iter_mut().enumerate() {
                        let v = self.value(wedge, j, p);
                        has.push(v.is_some());
                        ch.values.extend(v.unwrap_or_else(|| {
                            SmallVec::from_elem(0.0, self.channels[j].dimension)
                        }));
                    }
                    present.push(has);
                    next
                });
            }
            for (j, ch) in channels.iter_mut().enumerate() {
                ch.corners.push(out.map(|i| {
                    if present[i as usize][j] {
                        i
                    } else {
                        Channel::MISSING
                    }
                }));
            }
        }
        let pick = |labels: &FaceLabels| FaceLabels {
            names: labels.names.clone(),
            faces: if labels.faces.is_empty() {
                Vec::new()
            } else {
                live.iter()
                    .map(|&t| labels.faces[triangle_from[t as usize] as usize])
                    .collect()
            },
        };
        Attributes {
            channels,
            materials: pick(&self.materials),
            groups: pick(&self.groups),
            material_libraries: self.material_libraries.clone(),
        }
    }

    /// The values of channel `j` at `wedge`, whose vertex is at `p`: the input's when
    /// untouched (or when its quadric has no area), else the best ones at `p`; `None`
    /// when the wedge has no value in that channel.
    fn value(&self, wedge: u32, j: usize, p: DVec3) -> Option<SmallVec<[f32; 4]>> {
        let width = self.channels.len();
        let i = self.input[wedge as usize * width + j];
        if i == Channel::MISSING {
            return None;
        }
        let channel = &self.channels[j];
        let q = &self.quadric[wedge as usize * width + j];
        if !self.touched[wedge as usize] || q.area().is_nan() || q.area() <= 0.0 {
            return Some(channel.value(i).iter().copied().collect());
        }
        let mut v: SmallVec<[f64; 4]> = q.values_at(p);
        match channel.kind {
            ChannelKind::Normal => {
                let n = DVec3::new(v[0], v[1], v[2]).normalize_or_zero();
                if n == DVec3::ZERO {
                    return Some(channel.value(i).iter().copied().collect());
                }
                v = SmallVec::from_slice(&n.to_array());
            }
            ChannelKind::Color => v.iter_mut().for_each(|x| *x = x.clamp(0.0, 1.0)),
            ChannelKind::TexCoord | ChannelKind::Generic => {}
        }
        if v.iter().any(|x| !x.is_finite()) {
            return Some(channel.value(i).iter().copied().collect());
        }
        Some(v.iter().map(|&x| x as f32).collect())
    }

    /// The seam edges: (smaller end, larger end, triangle) for each live triangle on
    /// an edge whose triangles do not all have the same wedges at its ends.
    pub fn seam_edges(
        &self,
        incidence: &Incidence,
        triangles: &[[u32; 3]],
        vertex_count: usize,
    ) -> Vec<(u32, u32, u32)> {
        let mut out = Vec::new();
        for v in 0..vertex_count as u32 {
            let around: Vec<Around> = live_around(incidence, triangles, v).collect();
            for x in &around {
                for &c in &x.corners {
                    if c <= v {
                        continue;
                    }
                    let wedges = |y: &Around| {
                        (
                            self.at(y.triangle, y.corners, v),
                            self.at(y.triangle, y.corners, c),
                        )
                    };
                    let mine = wedges(x);
                    let on_edge = around.iter().filter(|y| y.corners.contains(&c));
                    let differs = on_edge.clone().any(|y| wedges(y) != mine);
                    if differs && on_edge.count() > 1 {
                        out.push((v, c, x.triangle));
                    }
                }
            }
        }
        out
    }
}

/// The live triangles around `v`.
fn live_around<'a>(
    incidence: &'a Incidence,
    triangles: &'a [[u32; 3]],
    v: u32,
) -> impl Iterator<Item = Around> + 'a {
    incidence.of(v).iter().filter_map(move |&t| {
        let corners = triangles[t as usize];
        (corners[0] != REMOVED).then_some(Around {
            triangle: t,
            corners,
        })
    })
}
