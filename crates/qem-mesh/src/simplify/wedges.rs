//! Attributes in the engine: the wedges (a vertex's distinct values of a channel),
//! their attribute quadrics, the rule that keeps seams, and the attribute values of
//! the output.
//!
//! Each channel has its own wedges, and so do the materials: two corners at one vertex
//! share a channel's wedge when they have the same value in that channel (a material
//! wedge when their faces have the same material). A vertex with several wedges of a
//! channel lies on that channel's seam (a UV seam, a hard normal, a colour border; a
//! material border for the materials); a UV seam is no normal seam, so the normals
//! stay continuous across it. Each channel wedge keeps the attribute quadric of the
//! triangles whose corner it is ([`AttributeQuadric`], Garland–Heckbert 98 in Hoppe
//! 99's form).
//!
//! Contracting `b` into `a`: in each set, each triangle on both ends pairs `b`'s wedge
//! there with `a`'s wedge there, and the paired wedges merge (their quadrics add). The
//! pairing must be one to one: a wedge of `b` paired with two of `a`'s, or two of
//! `b`'s with one of `a`'s, would join the two sides of a seam, and the pair is
//! refused ([`Rejection::Seam`]). `b`'s other wedges move to `a` unchanged. An end
//! with a wedge the pairing leaves alone (a vertex on a seam the other end is not on)
//! stays where it is ([`Pin`]): so a seam vertex moves only along its seam, and no
//! chart's values are extrapolated past its border (meshoptimizer keeps seam vertices
//! in place for the same reason). No output triangle takes a value from the other side
//! of a seam.
//!
//! The cost of a pair adds, for every channel wedge the merged vertex would have, the
//! error left at the best values ([`AttributeQuadric::position_quadric`]) times the
//! square of the channel's weight, so the placement weighs attributes with positions;
//! the geometric error the report gives stays the geometric quadric's. Seam edges also
//! get the border's constraint planes, so their curves keep their place as borders do.
//!
//! A wedge that never merged and whose vertex never moved keeps its input values bit
//! for bit; the others take the best values at their vertex's final place, normals
//! renormalised and colours clamped to 0–1.

use super::checks::Rejection;
use super::incidence::Incidence;
use super::options::AttributeWeights;
use super::pass_blocks::{Around, Positions, REMOVED};
use crate::attributes::{Attributes, Channel, ChannelKind, FaceLabels};
use qem_core::{AttributeQuadric, DVec3, Quadric};
use smallvec::SmallVec;
use std::collections::HashMap;

/// The wedges of one channel, or of the materials (no values, no quadrics).
struct WedgeSet {
    /// The channel (an index into [`Wedges::channels`]); `None` for the materials.
    channel: Option<usize>,
    /// Per engine triangle, the wedge of each corner.
    corner: Vec<[u32; 3]>,
    /// Per wedge, the input value index (channel sets; [`Channel::MISSING`] for none).
    input: Vec<u32>,
    /// Per wedge, the attribute quadric (channel sets only).
    quadric: Vec<AttributeQuadric>,
    /// Per wedge, whether it merged or its vertex moved (its values are then the
    /// quadric's best ones).
    touched: Vec<bool>,
}

impl WedgeSet {
    /// The wedge at vertex `v` of triangle `t` (whose corners are `corners`).
    fn at(&self, t: u32, corners: [u32; 3], v: u32) -> Option<u32> {
        let k = corners.iter().position(|&c| c == v)?;
        Some(self.corner[t as usize][k])
    }

    /// The pairing of contracting `b` into `a` in this set, or [`Rejection::Seam`]
    /// when it is not one to one.
    fn pairing(&self, a: u32, b: u32, around_a: &[Around]) -> Result<Pairing, Rejection> {
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

    /// Whether `v` has a wedge (at its triangles `around`) that `paired` leaves alone.
    fn left_alone(&self, around: &[Around], v: u32, paired: impl Fn(u32) -> bool) -> bool {
        around
            .iter()
            .filter_map(|x| self.at(x.triangle, x.corners, v))
            .any(|w| !paired(w))
    }
}

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
    /// One set per channel, in the channels' order, then the materials' (if any).
    sets: Vec<WedgeSet>,
}

/// `b`'s wedges of one set paired with `a`'s by the triangles on both ends: (wedge of
/// `b`, wedge of `a`).
pub(super) type Pairing = SmallVec<[(u32, u32); 4]>;

/// A contraction's pairings, one per set, and where the merged vertex may go.
pub(super) struct Plan {
    pairs: SmallVec<[Pairing; 3]>,
    /// Where the merged vertex may go.
    pub pin: Pin,
}

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
    /// the cleaned triangle `triangle_from[t]`), vertex positions from `positions`,
    /// with the cleaned mesh's `attributes`; `None` for a mesh without channels or
    /// materials.
    pub fn new(
        attributes: &Attributes,
        triangles: &[[u32; 3]],
        triangle_from: &[u32],
        positions: &Positions,
        weights: &AttributeWeights,
    ) -> Option<Wedges> {
        if attributes.channels.is_empty() && attributes.materials.is_empty() {
            return None;
        }
        let mut sets: Vec<WedgeSet> = (0..attributes.channels.len())
            .map(Some)
            .chain((!attributes.materials.is_empty()).then_some(None))
            .map(|channel| {
                // The value a corner has in this set: the channel's value index, or
                // its face's material.
                let key = |from: usize, k: usize| match channel {
                    Some(j) => attributes.channels[j].corners[from][k],
                    None => attributes.materials.faces[from],
                };
                let mut ids: HashMap<(u32, u32), u32> = HashMap::new();
                let mut corner = Vec::with_capacity(triangles.len());
                let mut input = Vec::new();
                for (t, tri) in triangles.iter().enumerate() {
                    let from = triangle_from[t] as usize;
                    let mut wedges = [0u32; 3];
                    for k in 0..3 {
                        let value = key(from, k);
                        let next = ids.len() as u32;
                        wedges[k] = *ids.entry((tri[k], value)).or_insert_with(|| {
                            input.push(value);
                            next
                        });
                    }
                    corner.push(wedges);
                }
                let count = input.len();
                let quadric = match channel {
                    Some(j) => {
                        vec![AttributeQuadric::new(attributes.channels[j].dimension); count]
                    }
                    None => Vec::new(),
                };
                WedgeSet {
                    channel,
                    corner,
                    input,
                    quadric,
                    touched: vec![false; count],
                }
            })
            .collect();
        // Each triangle's field, added to the wedge of each of its corners. Unweighted:
        // the weight scales the error (by its square) where the cost is formed, so a
        // weight of 0 still gives the values.
        for set in &mut sets {
            let Some(j) = set.channel else { continue };
            let c = &attributes.channels[j];
            for (t, tri) in triangles.iter().enumerate() {
                let idx = c.corners[triangle_from[t] as usize];
                if idx.contains(&Channel::MISSING) {
                    continue;
                }
                let values: [SmallVec<[f64; 4]>; 3] =
                    idx.map(|i| c.value(i).iter().map(|&x| f64::from(x)).collect());
                let mut one = AttributeQuadric::new(c.dimension);
                one.add_triangle(
                    tri.map(|v| positions.position(v)),
                    [&values[0], &values[1], &values[2]],
                );
                for &wedge in &set.corner[t] {
                    set.quadric[wedge as usize] += &one;
                }
            }
        }
        Some(Wedges {
            channels: attributes
                .channels
                .iter()
                .map(|c| c.with_corners(Vec::new()))
                .collect(),
            weights: attributes
                .channels
                .iter()
                .map(|c| weights.of(c.kind))
                .collect(),
            materials: attributes.materials.clone(),
            groups: attributes.groups.clone(),
            material_libraries: attributes.material_libraries.clone(),
            sets,
        })
    }

    /// The plan of contracting `b` into `a` (`around_a`, `around_b`: their live
    /// triangles): each set's pairing, and where the merged vertex may go ([`Pin`]).
    /// An end with a wedge that a pairing leaves alone stays where it is; when both
    /// ends have one, neither can stay for the other and the place is free (a vertex
    /// where several seams meet; per-face normals make every edge so, and refusing
    /// would leave such meshes stuck). A virtual pair (no triangle on both) pairs
    /// nothing and keeps `a`'s place. [`Rejection::Seam`] when a pairing is not one
    /// to one.
    pub fn plan(
        &self,
        a: u32,
        b: u32,
        around_a: &[Around],
        around_b: &[Around],
    ) -> Result<Plan, Rejection> {
        let mut pairs = SmallVec::new();
        for set in &self.sets {
            pairs.push(set.pairing(a, b, around_a)?);
        }
        if !around_a.iter().any(|x| x.corners.contains(&b)) {
            return Ok(Plan { pairs, pin: Pin::A });
        }
        let (mut a_alone, mut b_alone) = (false, false);
        for (set, p) in self.sets.iter().zip(&pairs) {
            a_alone |= set.left_alone(around_a, a, |w| p.iter().any(|&(_, pa)| pa == w));
            b_alone |= set.left_alone(around_b, b, |w| p.iter().any(|&(pb, _)| pb == w));
        }
        let pin = match (a_alone, b_alone) {
            (true, false) => Pin::A,
            (false, true) => Pin::B,
            _ => Pin::Free,
        };
        Ok(Plan { pairs, pin })
    }

    /// The attribute error of contracting `b` into `a`, as a quadric in the merged
    /// vertex's position (for each channel wedge the merged vertex would have, the
    /// error left at its best values, times the channel's weight squared), and where
    /// the vertex may go. `None` when the pair is refused ([`Wedges::plan`]).
    pub fn merged_error(
        &self,
        incidence: &Incidence,
        triangles: &[[u32; 3]],
        a: u32,
        b: u32,
    ) -> Option<(Quadric, Pin)> {
        let around_a: SmallVec<[Around; 16]> = live_around(incidence, triangles, a).collect();
        let around_b: SmallVec<[Around; 16]> = live_around(incidence, triangles, b).collect();
        let plan = self.plan(a, b, &around_a, &around_b).ok()?;
        let mut q = Quadric::ZERO;
        for (set, pairs) in self.sets.iter().zip(&plan.pairs) {
            let Some(j) = set.channel else { continue };
            let w2 = self.weights[j] * self.weights[j];
            let mut seen: SmallVec<[u32; 8]> = SmallVec::new();
            let mut add = |wedge: u32, partner: Option<u32>| {
                if seen.contains(&wedge) {
                    return;
                }
                seen.push(wedge);
                let mut sum = set.quadric[wedge as usize].clone();
                if let Some(p) = partner {
                    seen.push(p);
                    sum += &set.quadric[p as usize];
                }
                q += sum.position_quadric() * w2;
            };
            for x in &around_a {
                if let Some(wa) = set.at(x.triangle, x.corners, a) {
                    let partner = pairs.iter().find(|&&(_, pa)| pa == wa).map(|&(pb, _)| pb);
                    add(wa, partner);
                }
            }
            for x in &around_b {
                if let Some(wb) = set.at(x.triangle, x.corners, b) {
                    add(wb, None);
                }
            }
        }
        Some((q, plan.pin))
    }

    /// Records the contraction of `b` into `a` by `plan`, with `around` the live
    /// triangles of `a` and of `b` before it: paired wedges merge into `a`'s, `b`'s
    /// surviving triangles take the merged wedges, and every wedge at either end is
    /// touched.
    pub fn contract(&mut self, a: u32, b: u32, around: &[Vec<Around>; 2], plan: &Plan) {
        for (set, pairs) in self.sets.iter_mut().zip(&plan.pairs) {
            if set.channel.is_some() {
                for &(wb, wa) in pairs {
                    let from = set.quadric[wb as usize].clone();
                    set.quadric[wa as usize] += &from;
                }
            }
            for x in around.iter().flatten() {
                for (k, &c) in x.corners.iter().enumerate() {
                    if c != a && c != b {
                        continue;
                    }
                    let w = &mut set.corner[x.triangle as usize][k];
                    if c == b {
                        if let Some(&(_, wa)) = pairs.iter().find(|&&(pb, _)| pb == *w) {
                            *w = wa;
                        }
                    }
                    set.touched[*w as usize] = true;
                }
            }
        }
    }

    /// The attributes of the output: for the engine's `live` triangles (each from the
    /// cleaned triangle `triangle_from[t]`), with the position of each vertex from
    /// `positions`. Each channel's values are listed once per wedge used, in order of first
    /// use.
    pub fn output(
        &self,
        live: &[u32],
        triangles: &[[u32; 3]],
        triangle_from: &[u32],
        positions: &Positions,
    ) -> Attributes {
        let channels = self
            .sets
            .iter()
            .filter_map(|set| {
                let j = set.channel?;
                let c = &self.channels[j];
                let mut number: HashMap<u32, u32> = HashMap::new();
                let mut out = Channel {
                    kind: c.kind,
                    name: c.name.clone(),
                    dimension: c.dimension,
                    values: Vec::new(),
                    corners: Vec::with_capacity(live.len()),
                };
                for &t in live {
                    let tri = triangles[t as usize];
                    let corners = std::array::from_fn(|k| {
                        let wedge = set.corner[t as usize][k];
                        if set.input[wedge as usize] == Channel::MISSING {
                            return Channel::MISSING;
                        }
                        let next = (out.values.len() / c.dimension) as u32;
                        *number.entry(wedge).or_insert_with(|| {
                            out.values
                                .extend(self.value(set, wedge, positions.position(tri[k])));
                            next
                        })
                    });
                    out.corners.push(corners);
                }
                Some(out)
            })
            .collect();
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

    /// The values of `set`'s channel at `wedge` (which has a value), whose vertex is
    /// at `p`: the input's when untouched (or when its quadric has no area), else the
    /// best ones at `p`.
    fn value(&self, set: &WedgeSet, wedge: u32, p: DVec3) -> SmallVec<[f32; 4]> {
        let Some(j) = set.channel else {
            return SmallVec::new();
        };
        let channel = &self.channels[j];
        let input = || {
            channel
                .value(set.input[wedge as usize])
                .iter()
                .copied()
                .collect()
        };
        let q = &set.quadric[wedge as usize];
        if !set.touched[wedge as usize] || q.area().is_nan() || q.area() <= 0.0 {
            return input();
        }
        let mut v: SmallVec<[f64; 4]> = q.values_at(p);
        match channel.kind {
            ChannelKind::Normal => {
                let n = DVec3::new(v[0], v[1], v[2]).normalize_or_zero();
                if n == DVec3::ZERO {
                    return input();
                }
                v = SmallVec::from_slice(&n.to_array());
            }
            ChannelKind::Color => v.iter_mut().for_each(|x| *x = x.clamp(0.0, 1.0)),
            ChannelKind::TexCoord | ChannelKind::Generic => {}
        }
        if v.iter().any(|x| !x.is_finite()) {
            return input();
        }
        v.iter().map(|&x| x as f32).collect()
    }

    /// The seam edges: (smaller end, larger end, triangle) for each live triangle on
    /// an edge whose triangles do not all have the same wedges at its ends, in some
    /// set.
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
                    let on_edge = || around.iter().filter(|y| y.corners.contains(&c));
                    let differs = self.sets.iter().any(|set| {
                        let wedges = |y: &Around| {
                            (
                                set.at(y.triangle, y.corners, v),
                                set.at(y.triangle, y.corners, c),
                            )
                        };
                        let mine = wedges(x);
                        on_edge().any(|y| wedges(y) != mine)
                    });
                    if differs && on_edge().count() > 1 {
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
