//! `quadric_solve`: placement of arbitrary quadrics.

use qem_core::{endpoint_placement, optimal_placement, DVec3, Quadric};

/// Largest magnitude accepted from fuzz bytes: beyond it, `evaluate` (degree 2 in the
/// coordinates times the entries) can overflow f64, and the property "finite in,
/// finite out" is about placement, not about overflow of the cost.
const FUZZ_VALUE_LIMIT: f64 = 1e30;

/// Reads f64 values, 8 little-endian bytes each, keeping those that are finite and
/// within [`FUZZ_VALUE_LIMIT`] (others become 0).
fn values(data: &[u8]) -> impl Iterator<Item = f64> + '_ {
    data.chunks_exact(8).map(|c| {
        let mut b = [0u8; 8];
        b.copy_from_slice(c);
        let v = f64::from_le_bytes(b);
        if v.is_finite() && v.abs() <= FUZZ_VALUE_LIMIT {
            v
        } else {
            0.0
        }
    })
}

/// `quadric_solve`: for finite inputs, placement gives a finite point and a
/// non-negative cost that is never above the cost of the ends and the midpoint.
///
/// The first byte chooses how the quadric is built: from raw entries (any symmetric
/// matrix, even indefinite) or as a sum of planes (the positive semi-definite case the
/// simplifier produces). The rest are f64 values: the two ends, then the quadric.
pub fn quadric_solve(data: &[u8]) {
    let Some((&mode, rest)) = data.split_first() else {
        return;
    };
    let v: Vec<f64> = values(rest).collect();
    if v.len() < 6 {
        return;
    }
    let a = DVec3::new(v[0], v[1], v[2]);
    let b = DVec3::new(v[3], v[4], v[5]);
    let q = if mode % 2 == 0 {
        let mut e = [0.0; 10];
        for (slot, x) in e.iter_mut().zip(&v[6..]) {
            *slot = *x;
        }
        Quadric::from_entries(e)
    } else {
        v[6..]
            .chunks_exact(4)
            .filter_map(|p| {
                let n = DVec3::new(p[0], p[1], p[2]).try_normalize()?;
                Some(Quadric::from_plane(n, p[3]))
            })
            .sum()
    };
    let placed = optimal_placement(&q, a, b);
    assert!(
        placed.position.is_finite(),
        "non-finite placement {placed:?}"
    );
    assert!(placed.cost >= 0.0, "negative cost {placed:?}");
    let fallback = endpoint_placement(&q, a, b);
    // The ends' rule picks the least cost that is a number (an overflowing one, NaN,
    // never wins), clamped at 0.
    let mid = a * 0.5 + b * 0.5;
    let least = [q.evaluate(mid), q.evaluate(a), q.evaluate(b)]
        .into_iter()
        .filter(|c| !c.is_nan())
        .reduce(f64::min);
    if let Some(least) = least {
        assert_eq!(
            fallback.cost,
            least.max(0.0),
            "the ends' rule did not pick the least cost: {fallback:?}"
        );
    }
    // When the cost overflows, comparisons mean nothing; the point must still be finite.
    if fallback.cost.is_finite() {
        assert!(
            placed.cost <= fallback.cost,
            "placement {placed:?} costs more than the ends/midpoint {fallback:?}"
        );
    }
}
