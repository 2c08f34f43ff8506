//! The attribute error between two meshes: at area-uniform samples of the second mesh
//! (`b`, the simplified one), the difference between its attributes interpolated there
//! and the first mesh's (`a`, the reference) interpolated at the closest point of `a`.
//!
//! Channels are matched by name; each is compared in its own units: texture
//! coordinates as the distance in UV units, normals as the angle in degrees between
//! the two (normalised) vectors, colours and generic channels as the distance between
//! the two vectors. A sample whose triangle (on either mesh) has a corner without a
//! value in the channel is not counted for it.
//!
//! The 95th percentile is the figure to read: a sample on one side of a seam whose
//! closest point on `a` lands on the other side compares values of two different
//! charts, and the few such samples dominate the mean square and the maximum.

use super::{
    closest_point_on_triangle, stream_seed, validate_both, MeasureError, MeasureOptions, SampleSet,
    SplitMix64, TriangleBvh, CHUNK,
};
use crate::attributes::{Channel, ChannelKind};
use crate::IndexedMesh;
use rayon::prelude::*;

/// The error of one channel.
#[derive(Clone, Debug, PartialEq)]
pub struct ChannelError {
    /// The channel's name (the same in both meshes).
    pub channel: String,
    /// Its kind, which sets the unit: UV units, degrees, or the values' own units.
    pub kind: ChannelKind,
    /// Samples that counted (both triangles had values at every corner).
    pub samples: u64,
    /// Root mean square of the differences.
    pub rms: f64,
    /// Mean difference.
    pub mean: f64,
    /// 95th percentile of the differences.
    pub p95: f64,
    /// Largest difference.
    pub max: f64,
}

/// The attribute error of `b` against `a`, one entry per channel the two share (by
/// name, in `b`'s order); empty when they share none. Deterministic for a seed, like
/// [`super::measure`]; it draws `options.face_samples(b's triangles)` samples.
///
/// ```
/// use qem_mesh::attributes::{Channel, ChannelKind};
/// use qem_mesh::measure::{measure_attributes, MeasureOptions};
/// use qem_mesh::IndexedMesh;
/// let square = |u_right: f32| {
///     let mut m = IndexedMesh::new(
///         vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
///         vec![[0, 1, 2], [0, 2, 3]],
///     );
///     let uv = vec![0.0, 0.0, u_right, 0.0, u_right, 1.0, 0.0, 1.0];
///     m.attributes.channels.push(Channel::new(ChannelKind::TexCoord, uv, m.triangles.clone()));
///     m
/// };
/// let options = MeasureOptions { min_samples: 1000, ..MeasureOptions::DEFAULT };
/// let same = measure_attributes(&square(1.0), &square(1.0), &options).unwrap();
/// assert!(same[0].max < 1e-6);
/// // u stretched by half on the right: the difference is x / 2, at most 0.5.
/// let off = measure_attributes(&square(1.0), &square(1.5), &options).unwrap();
/// assert!(off[0].max <= 0.5 + 1e-6 && off[0].mean > 0.2);
/// ```
pub fn measure_attributes(
    a: &IndexedMesh,
    b: &IndexedMesh,
    options: &MeasureOptions,
) -> Result<Vec<ChannelError>, MeasureError> {
    if !(options.samples_per_face.is_finite() && options.samples_per_face >= 0.0) {
        return Err(MeasureError::BadSamplesPerFace(options.samples_per_face));
    }
    validate_both(a, b)?;
    let shared: Vec<(&Channel, &Channel)> = b
        .attributes
        .channels
        .iter()
        .filter_map(|cb| {
            let ca = a.attributes.channels.iter().find(|c| c.name == cb.name)?;
            (ca.dimension == cb.dimension).then_some((ca, cb))
        })
        .collect();
    if shared.is_empty() {
        return Ok(Vec::new());
    }
    let (index, slots) = TriangleBvh::with_slots(a);
    // Index slot → a's triangle.
    let mut triangle_of_slot = vec![0u32; index.triangle_count()];
    for (t, &slot) in slots.iter().enumerate() {
        if let Some(x) = triangle_of_slot.get_mut(slot as usize) {
            *x = t as u32;
        }
    }
    let set = SampleSet::new(b, options);
    let count = set.face_samples;
    let seed = stream_seed(options.seed, 2);
    let chunks = count.div_ceil(CHUNK);
    // Per chunk, per channel, the differences in sample order; concatenated in chunk
    // order, so the figures do not depend on the thread count.
    let per_chunk: Vec<Vec<Vec<f64>>> = (0..chunks)
        .into_par_iter()
        .map(|i| {
            let mut rng = SplitMix64(stream_seed(seed, i));
            let mut out = vec![Vec::new(); shared.len()];
            let mut near = Vec::new();
            let end = ((i + 1) * CHUNK).min(count);
            for _ in i * CHUNK..end {
                let (tb, weights) = set.face_sample(&mut rng);
                let p = set.point(tb, weights);
                let Some(slot) = index.nearest_triangles(p, 1.0, 0.0, 1, &mut near) else {
                    continue;
                };
                let ta = triangle_of_slot[slot as usize] as usize;
                let corners = a.triangles[ta].map(|v| a.positions[v as usize]);
                let q = closest_point_on_triangle(p, corners[0], corners[1], corners[2]);
                let weights_a = barycentric(q, corners);
                for (j, (ca, cb)) in shared.iter().enumerate() {
                    let (Some(va), Some(vb)) =
                        (interpolate(ca, ta, weights_a), interpolate(cb, tb, weights))
                    else {
                        continue;
                    };
                    out[j].push(difference(cb.kind, &va, &vb));
                }
            }
            out
        })
        .collect();
    Ok(shared
        .iter()
        .enumerate()
        .map(|(j, (_, cb))| {
            let mut all: Vec<f64> = per_chunk
                .iter()
                .flat_map(|c| c[j].iter().copied())
                .collect();
            let n = all.len();
            let sum: f64 = all.iter().sum();
            let sum2: f64 = all.iter().map(|d| d * d).sum();
            all.sort_unstable_by(f64::total_cmp);
            let at = |q: f64| {
                all.get(((q * n as f64).ceil() as usize).saturating_sub(1))
                    .copied()
            };
            ChannelError {
                channel: cb.name.clone(),
                kind: cb.kind,
                samples: n as u64,
                rms: if n > 0 { (sum2 / n as f64).sqrt() } else { 0.0 },
                mean: if n > 0 { sum / n as f64 } else { 0.0 },
                p95: at(0.95).unwrap_or(0.0),
                max: all.last().copied().unwrap_or(0.0),
            }
        })
        .collect())
}

/// Channel `c`'s value at the point of triangle `t` with barycentric `weights`, or
/// `None` when a corner has no value.
fn interpolate(c: &Channel, t: usize, weights: [f64; 3]) -> Option<Vec<f64>> {
    let corners = c.corners.get(t)?;
    if corners.contains(&Channel::MISSING) {
        return None;
    }
    let mut v = vec![0.0; c.dimension];
    for (k, &i) in corners.iter().enumerate() {
        for (x, &y) in v.iter_mut().zip(c.value(i)) {
            *x += weights[k] * f64::from(y);
        }
    }
    Some(v)
}

/// The difference between two values of a channel of `kind`: the angle in degrees for
/// normals, the distance otherwise.
fn difference(kind: ChannelKind, a: &[f64], b: &[f64]) -> f64 {
    if kind == ChannelKind::Normal {
        let dot: f64 = a.iter().zip(b).map(|(x, y)| x * y).sum();
        let la = a.iter().map(|x| x * x).sum::<f64>().sqrt();
        let lb = b.iter().map(|x| x * x).sum::<f64>().sqrt();
        if la > 0.0 && lb > 0.0 {
            return (dot / (la * lb)).clamp(-1.0, 1.0).acos().to_degrees();
        }
        return 180.0;
    }
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y) * (x - y))
        .sum::<f64>()
        .sqrt()
}

/// The barycentric weights of `q` (a point of the triangle) in `corners`; a degenerate
/// triangle's nearest corner takes all the weight.
fn barycentric(q: [f64; 3], [a, b, c]: [[f64; 3]; 3]) -> [f64; 3] {
    let sub = |x: [f64; 3], y: [f64; 3]| [x[0] - y[0], x[1] - y[1], x[2] - y[2]];
    let dot = |x: [f64; 3], y: [f64; 3]| x[0] * y[0] + x[1] * y[1] + x[2] * y[2];
    let (e0, e1, d) = (sub(b, a), sub(c, a), sub(q, a));
    let (d00, d01, d11) = (dot(e0, e0), dot(e0, e1), dot(e1, e1));
    let (d20, d21) = (dot(d, e0), dot(d, e1));
    let den = d00 * d11 - d01 * d01;
    if den.is_finite() && den > 1e-300 * (d00 * d11).max(1e-300) {
        let v = (d11 * d20 - d01 * d21) / den;
        let w = (d00 * d21 - d01 * d20) / den;
        return [1.0 - v - w, v, w];
    }
    let dist = [a, b, c].map(|p| dot(sub(q, p), sub(q, p)));
    let k = (0..3)
        .min_by(|&i, &j| dist[i].total_cmp(&dist[j]))
        .unwrap_or(0);
    let mut weights = [0.0; 3];
    weights[k] = 1.0;
    weights
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn barycentric_weights_rebuild_the_point() {
        let corners = [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 1.0, 1.0]];
        let w = barycentric([0.5, 0.25, 0.25], corners);
        for axis in 0..3 {
            let x: f64 = (0..3).map(|k| w[k] * corners[k][axis]).sum();
            assert!((x - [0.5, 0.25, 0.25][axis]).abs() < 1e-12);
        }
        let flat = barycentric(
            [1.0, 0.0, 0.0],
            [[0.0; 3], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]],
        );
        assert_eq!(flat, [0.0, 1.0, 0.0]);
    }

    #[test]
    fn normals_differ_by_their_angle() {
        let d = difference(ChannelKind::Normal, &[0.0, 0.0, 1.0], &[0.0, 1.0, 1.0]);
        assert!((d - 45.0).abs() < 1e-9);
        let d = difference(ChannelKind::TexCoord, &[0.0, 0.0], &[0.3, 0.4]);
        assert!((d - 0.5).abs() < 1e-12);
    }
}
