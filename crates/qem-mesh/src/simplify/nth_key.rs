//! The `rank`-th smallest of a list of distinct keys, on the thread pool: what bounds
//! each pass's batch ([`crate::simplify::engine`]'s pass-based order).
//!
//! Why not `select_nth_unstable` on a copy of the keys: on the 6M edges of the first
//! pass over a 4M-triangle mesh that was 83 ms on one core, with 96 MB of keys written
//! first. Here a sorted sample of the keys (every [`SAMPLE_EVERY`]-th) brackets the
//! wanted key; one pass over the list on both cores counts the keys below the bracket
//! and collects the few inside it; the selection runs among those. The bracket is
//! only a guess, and when it misses (which needs keys ordered against the sample) the
//! selection runs on a copy of every key, as before. Either way the answer is the same
//! key: the keys are distinct and totally ordered, so the `rank`-th is one key.

use rayon::prelude::*;
use std::cmp::Ordering;

/// Every how many keys the sample takes one.
const SAMPLE_EVERY: usize = 64;

/// Below this many keys, the sample is not worth it.
const MIN_SAMPLED: usize = 1 << 16;

/// The `rank`-th smallest (from 0) of `key(0..len)` under `cmp`, a total order under
/// which no two of the keys are equal. `scratch` holds the copy of every key when the
/// sample's bracket misses (or the list is short). `rank` must be below `len`.
pub(super) fn nth_key<K: Copy + Send + Sync>(
    len: usize,
    rank: usize,
    key: impl Fn(usize) -> K + Sync,
    cmp: impl Fn(&K, &K) -> Ordering + Sync,
    scratch: &mut Vec<K>,
) -> K {
    assert!(rank < len, "rank {rank} of {len} keys");
    if len >= MIN_SAMPLED {
        if let Some(found) = nth_in_bracket(len, rank, &key, &cmp) {
            return found;
        }
    }
    scratch.clear();
    scratch.extend((0..len).map(&key));
    *scratch.select_nth_unstable_by(rank, &cmp).1
}

/// The `rank`-th key found among those between two keys of a sorted sample, or `None`
/// when it lies outside them.
fn nth_in_bracket<K: Copy + Send + Sync>(
    len: usize,
    rank: usize,
    key: &(impl Fn(usize) -> K + Sync),
    cmp: &(impl Fn(&K, &K) -> Ordering + Sync),
) -> Option<K> {
    let mut sample: Vec<K> = (0..len).step_by(SAMPLE_EVERY).map(key).collect();
    sample.sort_unstable_by(cmp);
    let samples = sample.len();
    // Where the wanted key would fall among the samples, were they a fair draw, and a
    // margin of several times the spread of a fair draw's count (at most √n / 2).
    let at = rank * samples / len;
    let margin = 4 * samples.isqrt() + 4;
    let low = at.checked_sub(margin).map(|k| sample[k]);
    let high = sample.get(at + margin).copied();
    let is_below = |k: &K| low.is_some_and(|low| cmp(k, &low).is_lt());
    let is_above = |k: &K| high.is_some_and(|high| cmp(k, &high).is_gt());
    let (below, mut inside) = (0..len)
        .into_par_iter()
        .fold(
            || (0usize, Vec::new()),
            |(below, mut inside), i| {
                let k = key(i);
                if is_below(&k) {
                    return (below + 1, inside);
                }
                if !is_above(&k) {
                    inside.push(k);
                }
                (below, inside)
            },
        )
        .reduce(
            || (0, Vec::new()),
            |(below, mut inside), (more_below, more_inside)| {
                inside.extend(more_inside);
                (below + more_below, inside)
            },
        );
    let within = rank.checked_sub(below).filter(|&r| r < inside.len())?;
    Some(*inside.select_nth_unstable_by(within, cmp).1)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A scatter of `0..len`, `len` a power of two (a multiplication by an odd
    /// constant modulo a power of two is a bijection), so the keys are distinct and in
    /// no order.
    fn scattered(len: usize) -> Vec<u64> {
        assert!(len.is_power_of_two());
        (0..len as u64)
            .map(|i| i.wrapping_mul(0x9E37_79B9_7F4A_7C15) & (len as u64 - 1))
            .collect()
    }

    fn brute(keys: &[u64], rank: usize) -> u64 {
        let mut sorted = keys.to_vec();
        sorted.sort_unstable();
        sorted[rank]
    }

    #[test]
    fn finds_the_rank_th_key_in_scattered_sorted_and_reversed_lists() {
        let len = 3 * MIN_SAMPLED + 17;
        let scattered_keys: Vec<u64> = scattered(1 << 18).into_iter().take(len).collect();
        let ascending: Vec<u64> = (0..len as u64).collect();
        let descending: Vec<u64> = (0..len as u64).rev().collect();
        for keys in [&scattered_keys, &ascending, &descending] {
            for rank in [0, 1, len / 3, len / 2, len - 2, len - 1] {
                let found = nth_key(len, rank, |i| keys[i], u64::cmp, &mut Vec::new());
                assert_eq!(found, brute(keys, rank), "rank {rank}");
            }
        }
    }

    /// Keys ordered against the sample (every sampled key is the largest around it):
    /// the bracket misses, and the copy of every key gives the answer.
    #[test]
    fn a_sample_that_misses_falls_back_to_every_key() {
        let len = 2 * MIN_SAMPLED;
        let keys: Vec<u64> = (0..len as u64)
            .map(|i| {
                if i as usize % SAMPLE_EVERY == 0 {
                    len as u64 + i
                } else {
                    i
                }
            })
            .collect();
        let rank = len / 2;
        assert!(nth_in_bracket(len, rank, &|i| keys[i], &u64::cmp).is_none());
        let mut scratch = Vec::new();
        assert_eq!(
            nth_key(len, rank, |i| keys[i], u64::cmp, &mut scratch),
            brute(&keys, rank)
        );
        assert_eq!(scratch.len(), len, "the copy of every key was made");
    }

    #[test]
    fn short_lists_select_directly() {
        let keys = [5u64, 1, 4, 2, 3];
        for rank in 0..5 {
            assert_eq!(
                nth_key(5, rank, |i| keys[i], u64::cmp, &mut Vec::new()),
                rank as u64 + 1
            );
        }
    }
}
