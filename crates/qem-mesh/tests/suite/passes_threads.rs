//! The pass-based order ([`SimplifyOptions::FAST`]) gives the same output, bit for bit,
//! on rayon pools of 1, 2 and 3 threads.
//!
//! Its parallel parts: the input's normalisation and face planes in the setup (and,
//! with the orientation check, the input's index, built meanwhile); in each pass, the
//! costing of every edge (a parallel map, collected in order), the segments of exact
//! quadrics listed beside the edges, with the orientation check, the speculated
//! chunks of each round (placements and quick tests, a parallel map collected in
//! order; `simplify/passes_speculation_tests.rs` compares them with no speculation at
//! all on 1, 2 and 4 threads), and the rounds' contractions block by block (the
//! grid's 53,361 vertices are four blocks of `simplify/pass_blocks.rs`;
//! `simplify/passes_blocks_tests.rs` cuts small meshes into small blocks). The input
//! has 157,410 edges, so in the first passes each thread of a larger pool costs tens of
//! thousands of them: the split is real, not a formality of a tiny input.

use crate::passes_common;

use passes_common::bits;
use qem_mesh::simplify::{simplify, ContractionOrder, SimplifyOptions, StopReason, Target};
use qem_mesh::IndexedMesh;
use rayon::ThreadPoolBuilder;

/// Runs `f` on a rayon pool of `threads` threads.
fn on_threads<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("a thread pool")
        .install(f)
}

/// A 230 × 230 grid with a deterministic pseudo-random height added at each vertex (so
/// the order is decided by the costs, not only by the tie-break) and a 20 × 30 hole
/// cut out of it: 104,600 triangles, 157,410 edges.
fn noisy_grid() -> IndexedMesh {
    let n = 230u32;
    let mut positions = Vec::new();
    for y in 0..=n {
        for x in 0..=n {
            // A 32-bit integer hash of the vertex, as a height in [0, 0.5).
            let mut h = (y * (n + 1) + x).wrapping_mul(0x9E37_79B9);
            h ^= h >> 15;
            h = h.wrapping_mul(0x85EB_CA6B);
            h ^= h >> 13;
            let noise = f64::from(h) / f64::from(u32::MAX) * 0.5;
            let (fx, fy) = (f64::from(x), f64::from(y));
            positions.push([fx, fy, 4.0 * (fx * 0.05).sin() * (fy * 0.07).cos() + noise]);
        }
    }
    let id = |x: u32, y: u32| y * (n + 1) + x;
    let in_hole = |x: u32, y: u32| (100..120).contains(&x) && (60..90).contains(&y);
    let mut triangles = Vec::new();
    for y in 0..n {
        for x in 0..n {
            if in_hole(x, y) {
                continue;
            }
            triangles.push([id(x, y), id(x + 1, y), id(x + 1, y + 1)]);
            triangles.push([id(x, y), id(x + 1, y + 1), id(x, y + 1)]);
        }
    }
    IndexedMesh::new(positions, triangles)
}

#[test]
fn fast_simplification_is_the_same_on_1_2_and_3_threads() {
    same_on_1_2_and_3_threads(&SimplifyOptions::FAST.with_target(Target::Ratio(0.05)));
}

/// The defaults in the pass-based order: exact quadrics, and the orientation check,
/// whose index is built on the other core while the quadrics are summed.
#[test]
fn defaults_in_passes_are_the_same_on_1_2_and_3_threads() {
    same_on_1_2_and_3_threads(
        &SimplifyOptions::DEFAULT
            .with_order(ContractionOrder::Passes)
            .with_target(Target::Ratio(0.05)),
    );
}

fn same_on_1_2_and_3_threads(options: &SimplifyOptions) {
    let grid = noisy_grid();
    let edges = passes_common::edge_valences(&grid).len();
    assert!(edges >= 100_000, "{edges} edges");
    let one = on_threads(1, || simplify(&grid, options)).expect("simplifies");
    assert_eq!(one.report.stop_reason, StopReason::TargetReached);
    assert!(one.report.edge_contractions > 40_000);
    for threads in [2, 3] {
        let many = on_threads(threads, || simplify(&grid, options)).expect("simplifies");
        assert_eq!(bits(&many.mesh), bits(&one.mesh), "{threads} threads");
        let mut report = many.report.clone();
        report.timings = one.report.timings;
        assert_eq!(report, one.report, "{threads} threads");
    }
}
