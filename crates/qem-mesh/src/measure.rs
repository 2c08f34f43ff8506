//! Metro-style distance between two triangle meshes (Cignoni, Rocchini, Scopigno,
//! "Metro: measuring error on simplified surfaces", Computer Graphics Forum 17(2), 1998).
//!
//! Both surfaces are sampled — every referenced vertex, area-uniform points on the faces,
//! and points on the boundary edges — and each sample's exact distance to the *other*
//! surface is found through a bounding-volume hierarchy over its triangles. The result is
//! the symmetric Hausdorff distance and the mean and RMS distance in each direction, all as
//! fractions of the bounding-box diagonal of the first mesh (`a`, the reference).
//!
//! The sampling follows the conventions of the project's comparison harness
//! (`shared/tools/peers/peers.py`) so that the figures are comparable with it:
//! - vertices: every vertex that some triangle refers to, once;
//! - faces: `clamp(samples_per_face · triangles, min_samples, max_samples)` points, the
//!   triangle chosen with probability proportional to its area, the point uniform in it;
//! - boundary: edges (by vertex index, so an unwelded soup has every edge on its boundary)
//!   used by exactly one triangle get points at the same spacing as the face samples,
//!   `sqrt(area / face samples)`, at least one per edge, at most as many in all as face
//!   samples;
//! - the diagonal is that of the bounding box of all of `a`'s positions.
//!
//! Everything is deterministic for a given seed: samples are generated in fixed chunks,
//! each from its own seeded generator, chunks run in parallel (rayon) and their partial
//! sums are combined in chunk order, so the figures do not depend on the thread count.
//!
//! ```
//! use qem_mesh::IndexedMesh;
//! use qem_mesh::measure::{measure, MeasureOptions};
//!
//! // Two unit squares, the second lifted by 0.25 along z.
//! let square = |z: f64| IndexedMesh::new(
//!     vec![[0.0, 0.0, z], [1.0, 0.0, z], [1.0, 1.0, z], [0.0, 1.0, z]],
//!     vec![[0, 1, 2], [0, 2, 3]],
//! );
//! let options = MeasureOptions { min_samples: 1000, ..MeasureOptions::default() };
//! let m = measure(&square(0.0), &square(0.25), &options).unwrap();
//! let diagonal = 2f64.sqrt(); // of the first square's bounding box
//! assert!((m.hausdorff - 0.25 / diagonal).abs() < 1e-12);
//! assert!((m.mean_ab - 0.25 / diagonal).abs() < 1e-12);
//! assert!((m.rms_ba - 0.25 / diagonal).abs() < 1e-12);
//! assert!(m.samples_ab >= 1000);
//! ```

mod attributes;
mod bvh;
mod corner_store;
mod facing;
mod pieces;

use crate::input::{IndexedMesh, InputError};
pub use attributes::{measure_attributes, ChannelError};
pub use bvh::TriangleBvh;
use rayon::prelude::*;
use std::fmt;

/// How many samples are drawn and from which seed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeasureOptions {
    /// Area-uniform face samples per triangle of the sampled mesh (before the min/max).
    pub samples_per_face: f64,
    /// At least this many face samples per direction.
    pub min_samples: u64,
    /// At most this many face samples per direction (`None`: no cap). Boundary samples
    /// never exceed the face samples, so this also bounds the run time.
    pub max_samples: Option<u64>,
    /// Seed of the sample generators; the same seed gives bit-identical results.
    pub seed: u64,
}

impl MeasureOptions {
    /// The harness's defaults: 10 samples per face, at least one million, no cap, seed 0.
    pub const DEFAULT: MeasureOptions = MeasureOptions {
        samples_per_face: 10.0,
        min_samples: 1_000_000,
        max_samples: None,
        seed: 0,
    };

    /// The number of area-uniform face samples for a mesh with `triangles` triangles.
    pub fn face_samples(&self, triangles: usize) -> u64 {
        // `as` saturates for huge or infinite products; validation refused NaN.
        let wanted = (self.samples_per_face * triangles as f64) as u64;
        let n = wanted.max(self.min_samples);
        match self.max_samples {
            Some(cap) => n.min(cap),
            None => n,
        }
    }
}

impl Default for MeasureOptions {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// The distances between two meshes. Distances are fractions of the diagonal of `a`'s
/// bounding box; `ab` means samples on `a`, distances to the surface of `b`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Measurement {
    /// Symmetric Hausdorff distance: the larger of the two directed maxima.
    pub hausdorff: f64,
    /// Largest distance from a sample of `a` to `b`.
    pub hausdorff_ab: f64,
    /// Largest distance from a sample of `b` to `a`.
    pub hausdorff_ba: f64,
    /// Mean distance from the samples of `a` to `b`.
    pub mean_ab: f64,
    /// Mean distance from the samples of `b` to `a`.
    pub mean_ba: f64,
    /// Root mean square distance from the samples of `a` to `b`.
    pub rms_ab: f64,
    /// Root mean square distance from the samples of `b` to `a`.
    pub rms_ba: f64,
    /// Number of samples taken on `a` (vertices + faces + boundary).
    pub samples_ab: u64,
    /// Number of samples taken on `b`.
    pub samples_ba: u64,
    /// The diagonal of `a`'s bounding box in model units (the unit of every figure).
    pub diagonal: f64,
    /// The faces of `b` facing away from `a`: the faces whose normal makes a negative
    /// dot product with the normal of `a`'s triangle nearest to the face's centroid
    /// (with any of them, when several are equally near). What Metro-style tools count
    /// as flipped faces after a simplification, and what the simplifier's orientation
    /// check refuses to make. Faces of zero area (no normal) are not counted.
    pub faces_facing_away: u64,
    /// Their share of `b`'s area (0 to 1).
    pub facing_away_area: f64,
}

/// Which of the two meshes an error is about.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Which {
    /// The first mesh (the reference).
    A,
    /// The second mesh.
    B,
}

/// Why two meshes could not be measured.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum MeasureError {
    /// One mesh failed [`IndexedMesh::validate`].
    Invalid {
        /// Which mesh.
        mesh: Which,
        /// What was wrong with it.
        error: InputError,
    },
    /// All of `a`'s positions coincide, so there is no diagonal to measure against.
    ZeroDiagonal,
    /// `samples_per_face` is negative or not finite.
    BadSamplesPerFace(f64),
}

impl fmt::Display for MeasureError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            MeasureError::Invalid { error, .. } => write!(f, "{error}"),
            MeasureError::ZeroDiagonal => write!(
                f,
                "all positions coincide: the bounding-box diagonal is 0, so no relative distance exists"
            ),
            MeasureError::BadSamplesPerFace(v) => {
                write!(f, "samples per face must be finite and ≥ 0, not {v}")
            }
        }
    }
}

impl std::error::Error for MeasureError {}

/// Measures the distance between `a` and `b` (see the [module docs](self)).
///
/// Fails when a mesh does not pass [`IndexedMesh::validate`], when `a`'s bounding box
/// is a single point, or when `samples_per_face` is not a finite number ≥ 0. Never panics.
pub fn measure(
    a: &IndexedMesh,
    b: &IndexedMesh,
    options: &MeasureOptions,
) -> Result<Measurement, MeasureError> {
    if !(options.samples_per_face.is_finite() && options.samples_per_face >= 0.0) {
        return Err(MeasureError::BadSamplesPerFace(options.samples_per_face));
    }
    let diagonal = validated_diagonal(a, b)?;
    let (index_a, index_b) = rayon::join(|| TriangleBvh::new(a), || TriangleBvh::new(b));
    // Different streams for the two directions, so the two sample sets are independent
    // even when the meshes are identical.
    let ab = directed(a, &index_b, options, stream_seed(options.seed, 0));
    let ba = directed(b, &index_a, options, stream_seed(options.seed, 1));
    let away = facing_away(b, &index_a);
    Ok(Measurement {
        hausdorff: ab.max.max(ba.max) / diagonal,
        hausdorff_ab: ab.max / diagonal,
        hausdorff_ba: ba.max / diagonal,
        mean_ab: ab.mean() / diagonal,
        mean_ba: ba.mean() / diagonal,
        rms_ab: ab.rms() / diagonal,
        rms_ba: ba.rms() / diagonal,
        samples_ab: ab.count,
        samples_ba: ba.count,
        diagonal,
        faces_facing_away: away.faces,
        facing_away_area: away.area_fraction(),
    })
}

/// The faces of one mesh facing away from another's surface, and their area.
#[derive(Clone, Copy, Debug, Default)]
struct FacingAway {
    faces: u64,
    /// Twice the area of those faces, and of all faces.
    double_area: f64,
    total_double_area: f64,
}

impl FacingAway {
    fn area_fraction(&self) -> f64 {
        if self.total_double_area > 0.0 {
            self.double_area / self.total_double_area
        } else {
            0.0
        }
    }
}

/// How many triangles, at most, are asked when several of `to`'s triangles are equally
/// near a centroid (a vertex where many triangles meet).
const EQUALLY_NEAR_MAX: usize = 16;

/// The faces of `from` facing away from `to` (see
/// [`Measurement::faces_facing_away`]), on the thread pool; the sums are taken in face
/// order, so the figures do not depend on the threads.
fn facing_away(from: &IndexedMesh, to: &TriangleBvh) -> FacingAway {
    let corners = |t: &[u32; 3]| t.map(|v| from.positions[v as usize]);
    let per_face: Vec<(bool, f64)> = from
        .triangles
        .par_iter()
        .map_init(Vec::new, |nearest, t| {
            let [a, b, c] = corners(t);
            let normal = cross(sub(b, a), sub(c, a));
            let double_area = length(normal);
            if double_area.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
                return (false, 0.0);
            }
            let centroid = [0, 1, 2].map(|k| (a[k] + b[k] + c[k]) / 3.0);
            to.nearest_triangles(centroid, 1.0, 0.0, EQUALLY_NEAR_MAX, nearest);
            let away = nearest.iter().any(|&i| {
                let [p, q, r] = to.corners(i);
                dot(normal, cross(sub(q, p), sub(r, p))) < 0.0
            });
            (away, double_area)
        })
        .collect();
    let mut sum = FacingAway::default();
    for (away, double_area) in per_face {
        sum.total_double_area += double_area;
        if away {
            sum.faces += 1;
            sum.double_area += double_area;
        }
    }
    sum
}

/// Checks both meshes ([`IndexedMesh::validate`]), naming the one that fails.
fn validate_both(a: &IndexedMesh, b: &IndexedMesh) -> Result<(), MeasureError> {
    for (mesh, which) in [(a, Which::A), (b, Which::B)] {
        mesh.validate()
            .map_err(|error| MeasureError::Invalid { mesh: which, error })?;
    }
    Ok(())
}

/// Checks both meshes and returns `a`'s bounding-box diagonal, refused when it is 0.
fn validated_diagonal(a: &IndexedMesh, b: &IndexedMesh) -> Result<f64, MeasureError> {
    validate_both(a, b)?;
    let diagonal = match a.bounding_box() {
        Some((lo, hi)) => length(sub(hi, lo)),
        None => 0.0,
    };
    if diagonal.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
        return Err(MeasureError::ZeroDiagonal);
    }
    Ok(diagonal)
}

/// The distance from each vertex of `b` to the surface of `a`, as a fraction of `a`'s
/// bounding-box diagonal (a vertex no triangle of `b` uses gets 0): what a heat map of
/// `b` shows. Fails as [`measure`] does.
///
/// ```
/// use qem_mesh::IndexedMesh;
/// use qem_mesh::measure::vertex_distances;
/// let square = |z: f64| IndexedMesh::new(
///     vec![[0.0, 0.0, z], [1.0, 0.0, z], [1.0, 1.0, z], [0.0, 1.0, z]],
///     vec![[0, 1, 2], [0, 2, 3]],
/// );
/// let d = vertex_distances(&square(0.0), &square(0.5)).unwrap();
/// assert!(d.iter().all(|&x| (x - 0.5 / 2f64.sqrt()).abs() < 1e-12));
/// ```
pub fn vertex_distances(a: &IndexedMesh, b: &IndexedMesh) -> Result<Vec<f64>, MeasureError> {
    let diagonal = validated_diagonal(a, b)?;
    let mut used = vec![false; b.positions.len()];
    for t in &b.triangles {
        for &i in t {
            used[i as usize] = true;
        }
    }
    let index = TriangleBvh::new(a);
    Ok(b.positions
        .par_iter()
        .zip(&used)
        .map(|(&p, &used)| {
            if used {
                index.distance(p).unwrap_or(0.0) / diagonal
            } else {
                0.0
            }
        })
        .collect())
}

// ----------------------------------------------------------------------------- geometry

type P3 = [f64; 3];

fn sub(a: P3, b: P3) -> P3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: P3, b: P3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: P3, b: P3) -> P3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn length(a: P3) -> f64 {
    dot(a, a).sqrt()
}

/// `a + s·d`.
fn along(a: P3, d: P3, s: f64) -> P3 {
    [a[0] + s * d[0], a[1] + s * d[1], a[2] + s * d[2]]
}

/// Closest point to `p` on the segment `a`–`b` (a point when `a == b`).
fn closest_on_segment(p: P3, a: P3, b: P3) -> P3 {
    let d = sub(b, a);
    let len2 = dot(d, d);
    if len2 <= 0.0 {
        return a;
    }
    let t = (dot(sub(p, a), d) / len2).clamp(0.0, 1.0);
    along(a, d, t)
}

/// The point of triangle `abc` closest to `p`.
///
/// Ericson, *Real-Time Collision Detection* (2005), §5.1.5 "Closest point on triangle to
/// point": the Voronoi regions of the three vertices, then of the three edges, are tested
/// with dot products; otherwise the point projects inside the face. A degenerate
/// triangle — two equal corners (an edge test would divide by zero) or collinear corners
/// (the face case would) — is handled exactly as the union of its three edges.
pub fn closest_point_on_triangle(p: [f64; 3], a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> [f64; 3] {
    if a == b || b == c || c == a {
        return closest_on_edges(p, a, b, c);
    }
    let ab = sub(b, a);
    let ac = sub(c, a);
    let ap = sub(p, a);
    let d1 = dot(ab, ap);
    let d2 = dot(ac, ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return a; // vertex region of a
    }
    let bp = sub(p, b);
    let d3 = dot(ab, bp);
    let d4 = dot(ac, bp);
    if d3 >= 0.0 && d4 <= d3 {
        return b; // vertex region of b
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return along(a, ab, d1 / (d1 - d3)); // edge region of ab
    }
    let cp = sub(p, c);
    let d5 = dot(ab, cp);
    let d6 = dot(ac, cp);
    if d6 >= 0.0 && d5 <= d6 {
        return c; // vertex region of c
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return along(a, ac, d2 / (d2 - d6)); // edge region of ac
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let t = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return along(b, sub(c, b), t); // edge region of bc
    }
    let denom = va + vb + vc;
    if denom.is_nan() || denom <= 0.0 || denom.is_infinite() {
        return closest_on_edges(p, a, b, c); // collinear corners
    }
    let v = vb / denom;
    let w = vc / denom;
    along(along(a, ab, v), ac, w) // inside the face
}

/// Closest point to `p` on the three edges of `abc` (the first of equally near ones).
fn closest_on_edges(p: P3, a: P3, b: P3, c: P3) -> P3 {
    let candidates = [
        closest_on_segment(p, a, b),
        closest_on_segment(p, b, c),
        closest_on_segment(p, c, a),
    ];
    let mut best = candidates[0];
    for q in &candidates[1..] {
        if dot(sub(*q, p), sub(*q, p)) < dot(sub(best, p), sub(best, p)) {
            best = *q;
        }
    }
    best
}

/// Squared distance from `p` to triangle `abc`.
fn triangle_distance2(p: P3, a: P3, b: P3, c: P3) -> f64 {
    let q = closest_point_on_triangle(p, a, b, c);
    let d = sub(p, q);
    dot(d, d)
}

/// The exact distance from `p` to the nearest triangle of `mesh`, by testing every
/// triangle: the reference [`TriangleBvh::distance`] is checked against. `None` when the
/// mesh has no triangle with valid indices.
pub fn brute_force_distance(mesh: &IndexedMesh, p: [f64; 3]) -> Option<f64> {
    let mut best: Option<f64> = None;
    for t in &mesh.triangles {
        let corner = |i: u32| mesh.positions.get(i as usize).copied();
        if let (Some(a), Some(b), Some(c)) = (corner(t[0]), corner(t[1]), corner(t[2])) {
            let d = triangle_distance2(p, a, b, c);
            best = Some(best.map_or(d, |x: f64| x.min(d)));
        }
    }
    best.map(f64::sqrt)
}

// ----------------------------------------------------------------------------- sampling

/// SplitMix64 (Steele, Lea, Flood, "Fast splittable pseudorandom number generators",
/// OOPSLA 2014; constants as in Vigna's public-domain reference). Written here rather
/// than taken from `rand` so the sample stream is fixed by this file and cannot change
/// with a dependency's version; its statistical quality is ample for Monte Carlo sampling.
struct SplitMix64(u64);

impl SplitMix64 {
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1) with 53 random bits.
    fn next_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
}

/// A seed for one independent stream, derived from the user's seed and a stream label.
fn stream_seed(seed: u64, stream: u64) -> u64 {
    let mut g = SplitMix64(seed ^ stream.wrapping_mul(0xD1B5_4A32_D192_ED03));
    g.next_u64()
}

/// Samples per parallel chunk: large enough to amortise scheduling, small enough to
/// balance two cores and keep memory flat.
const CHUNK: u64 = 1 << 14;

/// Running sums of one set of distances.
#[derive(Clone, Copy, Debug, Default)]
struct Stats {
    count: u64,
    sum: f64,
    sum2: f64,
    max: f64,
}

impl Stats {
    fn add(&mut self, d: f64) {
        self.count += 1;
        self.sum += d;
        self.sum2 += d * d;
        self.max = self.max.max(d);
    }

    fn combine(mut self, other: Stats) -> Stats {
        self.count += other.count;
        self.sum += other.sum;
        self.sum2 += other.sum2;
        self.max = self.max.max(other.max);
        self
    }

    fn mean(&self) -> f64 {
        if self.count == 0 {
            0.0
        } else {
            self.sum / self.count as f64
        }
    }

    fn rms(&self) -> f64 {
        if self.count == 0 {
            0.0
        } else {
            (self.sum2 / self.count as f64).sqrt()
        }
    }
}

/// What one mesh contributes as sample points: its referenced vertices, its triangles by
/// cumulative area, and its boundary edges by cumulative sample count.
struct SampleSet<'m> {
    mesh: &'m IndexedMesh,
    vertices: Vec<u32>,
    /// Running sum of triangle areas (for picking a triangle by area).
    cumulative_area: Vec<f64>,
    face_samples: u64,
    boundary_edges: Vec<[u32; 2]>,
    /// Running sum of samples per boundary edge.
    cumulative_edge_samples: Vec<u64>,
}

impl<'m> SampleSet<'m> {
    fn new(mesh: &'m IndexedMesh, options: &MeasureOptions) -> SampleSet<'m> {
        let p = |i: u32| mesh.positions[i as usize];
        let mut used = vec![false; mesh.positions.len()];
        for t in &mesh.triangles {
            for &i in t {
                used[i as usize] = true;
            }
        }
        let vertices = (0..mesh.positions.len() as u32)
            .filter(|&i| used[i as usize])
            .collect();
        let mut total = 0.0;
        let cumulative_area: Vec<f64> = mesh
            .triangles
            .iter()
            .map(|t| {
                total += 0.5 * length(cross(sub(p(t[1]), p(t[0])), sub(p(t[2]), p(t[0]))));
                total
            })
            .collect();
        let face_samples = if total > 0.0 {
            options.face_samples(mesh.triangles.len())
        } else {
            0
        };
        // Boundary edges by index: an undirected edge used by exactly one triangle. A
        // sorted list of (min, max) keys gives the counts in a deterministic order.
        let mut keys: Vec<[u32; 2]> = mesh
            .triangles
            .iter()
            .flat_map(|t| [[t[0], t[1]], [t[1], t[2]], [t[2], t[0]]])
            .map(|[x, y]| [x.min(y), x.max(y)])
            .collect();
        keys.sort_unstable();
        let mut boundary_edges = Vec::new();
        let mut i = 0;
        while i < keys.len() {
            let mut j = i + 1;
            while j < keys.len() && keys[j] == keys[i] {
                j += 1;
            }
            if j - i == 1 {
                boundary_edges.push(keys[i]);
            }
            i = j;
        }
        let lengths: Vec<f64> = boundary_edges
            .iter()
            .map(|e| length(sub(p(e[1]), p(e[0]))))
            .collect();
        let boundary_length: f64 = lengths.iter().sum();
        let mut cumulative_edge_samples = Vec::with_capacity(boundary_edges.len());
        if boundary_length > 0.0 && face_samples > 0 {
            // The face samples' spacing, as if they were on a grid.
            let spacing = (total / face_samples as f64).sqrt();
            let wanted = (boundary_length / spacing).ceil().min(face_samples as f64);
            let edge_spacing = boundary_length / wanted.max(1.0);
            let mut running = 0u64;
            for len in &lengths {
                running += ((len / edge_spacing).ceil() as u64).max(1);
                cumulative_edge_samples.push(running);
            }
        } else {
            boundary_edges.clear();
        }
        SampleSet {
            mesh,
            vertices,
            cumulative_area,
            face_samples,
            boundary_edges,
            cumulative_edge_samples,
        }
    }

    fn boundary_samples(&self) -> u64 {
        self.cumulative_edge_samples.last().copied().unwrap_or(0)
    }

    fn position(&self, i: u32) -> P3 {
        self.mesh.positions[i as usize]
    }

    /// One area-uniform face sample, drawn from `rng`.
    fn face_point(&self, rng: &mut SplitMix64) -> P3 {
        let (t, weights) = self.face_sample(rng);
        self.point(t, weights)
    }

    /// One area-uniform face sample, drawn from `rng`, as its triangle and barycentric
    /// weights.
    fn face_sample(&self, rng: &mut SplitMix64) -> (usize, [f64; 3]) {
        let total = self.cumulative_area.last().copied().unwrap_or(0.0);
        let r = rng.next_f64() * total;
        let f = self
            .cumulative_area
            .partition_point(|&c| c <= r)
            .min(self.cumulative_area.len() - 1);
        // Uniform in the triangle: Osada et al., "Shape distributions" (2002), eq. 1.
        let s1 = rng.next_f64().sqrt();
        let r2 = rng.next_f64();
        let (u, v) = (1.0 - s1, s1 * (1.0 - r2));
        let w = 1.0 - u - v;
        (f, [u, v, w])
    }

    /// The point of triangle `t` with barycentric `weights`.
    fn point(&self, t: usize, [u, v, w]: [f64; 3]) -> P3 {
        let t = self.mesh.triangles[t];
        let (a, b, c) = (
            self.position(t[0]),
            self.position(t[1]),
            self.position(t[2]),
        );
        [
            u * a[0] + v * b[0] + w * c[0],
            u * a[1] + v * b[1] + w * c[1],
            u * a[2] + v * b[2] + w * c[2],
        ]
    }

    /// Boundary sample number `k`'s point: uniform on the edge it falls to.
    fn boundary_point(&self, k: u64, rng: &mut SplitMix64) -> P3 {
        let e = self
            .cumulative_edge_samples
            .partition_point(|&c| c <= k)
            .min(self.boundary_edges.len() - 1);
        let [x, y] = self.boundary_edges[e];
        let (a, b) = (self.position(x), self.position(y));
        along(a, sub(b, a), rng.next_f64())
    }
}

/// Which kind of sample a chunk holds.
#[derive(Clone, Copy)]
enum Kind {
    Vertices,
    Faces,
    Boundary,
}

/// Chunks handed to rayon at a time: their partial sums are all that is kept in memory,
/// however many samples were asked for.
const CHUNKS_PER_ROUND: u64 = 256;

/// Samples `from` and measures each sample's distance to the surface in `to`.
fn directed(from: &IndexedMesh, to: &TriangleBvh, options: &MeasureOptions, seed: u64) -> Stats {
    let set = SampleSet::new(from, options);
    // Samples `start..end` of one kind, chunk number `index` of that kind.
    let run_chunk = |kind: Kind, index: u64, start: u64, end: u64| {
        let mut stats = Stats::default();
        let mut add = |p: P3| {
            if let Some(d) = to.distance(p) {
                stats.add(d);
            }
        };
        match kind {
            Kind::Vertices => {
                for k in start..end {
                    add(set.position(set.vertices[k as usize]));
                }
            }
            Kind::Faces => {
                let mut rng = SplitMix64(stream_seed(seed, index.wrapping_mul(2)));
                for _ in start..end {
                    add(set.face_point(&mut rng));
                }
            }
            Kind::Boundary => {
                let mut rng = SplitMix64(stream_seed(seed, index.wrapping_mul(2) | 1));
                for k in start..end {
                    add(set.boundary_point(k, &mut rng));
                }
            }
        }
        stats
    };
    let mut total = Stats::default();
    for (kind, count) in [
        (Kind::Vertices, set.vertices.len() as u64),
        (Kind::Faces, set.face_samples),
        (Kind::Boundary, set.boundary_samples()),
    ] {
        let chunks = count.div_ceil(CHUNK);
        let mut first = 0;
        while first < chunks {
            let last = first.saturating_add(CHUNKS_PER_ROUND).min(chunks);
            let partial: Vec<Stats> = (first..last)
                .into_par_iter()
                .map(|i| {
                    let start = i * CHUNK;
                    run_chunk(kind, i, start, start.saturating_add(CHUNK).min(count))
                })
                .collect();
            // Combined in chunk order: the same sums whatever the thread count.
            total = partial.into_iter().fold(total, Stats::combine);
            first = last;
        }
    }
    total
}
