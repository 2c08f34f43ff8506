//! Criterion bench of the quadric hot operations: construct, add, evaluate, solve.
//! Criterion reports time per iteration; each iteration is one operation, so the
//! figures read directly as ns per op.

#![allow(missing_docs)] // criterion_group! generates undocumented items

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use qem_core::{optimal_placement, DVec3, Quadric};

fn bench(c: &mut Criterion) {
    let (p0, p1, p2) = (
        DVec3::new(0.1, 0.2, 0.3),
        DVec3::new(1.0, 0.1, -0.2),
        DVec3::new(0.2, 0.9, 0.4),
    );
    let qa = Quadric::from_triangle(p0, p1, p2);
    let qb = Quadric::from_triangle(p1, p0, DVec3::new(0.5, -0.5, 1.0))
        + Quadric::from_triangle(p2, p1, DVec3::new(-0.3, 0.4, -0.9));
    c.bench_function("construct from_triangle", |b| {
        b.iter(|| Quadric::from_triangle(black_box(p0), black_box(p1), black_box(p2)))
    });
    c.bench_function("add", |b| b.iter(|| black_box(qa) + black_box(qb)));
    c.bench_function("evaluate", |b| {
        b.iter(|| black_box(qa).evaluate(black_box(p1)))
    });
    let q = qa + qb;
    c.bench_function("solve optimal_placement", |b| {
        b.iter(|| optimal_placement(black_box(&q), black_box(p0), black_box(p1)))
    });
    let flat = Quadric::from_plane(DVec3::Z, 0.0);
    c.bench_function("solve fallback (singular)", |b| {
        b.iter(|| optimal_placement(black_box(&flat), black_box(p0), black_box(p1)))
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
