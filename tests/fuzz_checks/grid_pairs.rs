//! `grid_pairs`: the virtual-pair grid against the brute-force rule.

use super::bytes::Bytes;
use crate::pair_model::brute_force_pairs;
use qem_mesh::pairs::{virtual_pairs, GridOptions};

/// Scales of the integer-grid points (and of the threshold with them).
const SCALES: [f64; 7] = [1.0, 0.1, 1e-30, 1e30, 1e-300, 1e300, 3.0e-5];

/// Thresholds for raw-f64 points, including the ones that mean "no pairs".
const RAW_THRESHOLDS: [f64; 11] = [
    0.0,
    -1.0,
    f64::NAN,
    f64::INFINITY,
    1e-300,
    1e-30,
    0.5,
    1.0,
    1e30,
    1e300,
    f64::MAX,
];

/// At most this many points: the reference is O(n² log n).
const MAX_POINTS: usize = 64;

/// `grid_pairs`: `virtual_pairs` equals [`brute_force_pairs`] for any finite points,
/// threshold, cap and filter.
///
/// Layout: mode (bit 0: raw f64 points instead of grid points), threshold byte, cap
/// byte, filter byte, scale byte; then points, three bytes each on a 5×5×5 grid (many
/// exact ties at distance t), or 24 bytes each as raw f64 (non-finite ones become 0).
pub fn grid_pairs(data: &[u8]) {
    let mut b = Bytes::new(data);
    let raw = b.byte() % 2 == 1;
    let t_byte = b.byte();
    let k = match b.below(6) {
        5 => usize::MAX,
        k => k,
    };
    let filter = b.below(4);
    let scale = b.pick(&SCALES);
    let (t, points) = if raw {
        let t = RAW_THRESHOLDS[usize::from(t_byte) % RAW_THRESHOLDS.len()];
        let mut points = Vec::new();
        while !b.is_empty() && points.len() < MAX_POINTS {
            points.push([(); 3].map(|()| Some(b.f64()).filter(|x| x.is_finite()).unwrap_or(0.0)));
        }
        (t, points)
    } else {
        let t = f64::from(t_byte % 12) * 0.5 * scale;
        let mut points = Vec::new();
        while !b.is_empty() && points.len() < MAX_POINTS {
            points.push([(); 3].map(|()| f64::from(b.byte() % 5) * scale));
        }
        (t, points)
    };
    let allowed = |i: u32, j: u32| match filter {
        0 => true,
        1 => (i + j) % 3 != 0,
        2 => i % 2 == j % 2,
        _ => j - i > 1,
    };
    let options = GridOptions::new(t).with_max_per_vertex(k);
    let got = virtual_pairs(&points, &options, allowed);
    let want = brute_force_pairs(&points, t, k, allowed);
    assert_eq!(
        got, want,
        "t = {t}, k = {k}, filter {filter}, points {points:?}"
    );
}
