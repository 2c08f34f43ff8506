//! Throughput of the whole simplification (clean, build, quadrics, loop, compact) on
//! the 871k-triangle Stanford dragon from the corpus, single thread, ratio 0.1.
//! Skips with a message when the corpus is absent.
//!
//! `cargo bench -p qem-mesh --features io --bench simplify`
//! Input triangles per second = 871,414 / the reported time.
#![allow(missing_docs)] // criterion_group! generates undocumented items

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use qem_mesh::simplify::{simplify, SimplifyOptions, Target};
use std::path::PathBuf;

fn corpus() -> PathBuf {
    std::env::var_os("QEM_CORPUS")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/corpus"))
}

fn bench(c: &mut Criterion) {
    let path = corpus().join("originals/stanford_dragon_vrip.ply.gz");
    let Ok(loaded) = qem_mesh::io::read_path(&path) else {
        eprintln!("skipping the simplify bench: {} is absent", path.display());
        return;
    };
    let mesh = loaded.mesh;
    let options = SimplifyOptions::DEFAULT.with_target(Target::Ratio(0.1));
    let mut group = c.benchmark_group("simplify");
    group.sample_size(10);
    group.throughput(Throughput::Elements(mesh.triangle_count() as u64));
    group.bench_function("dragon_871k_ratio_0.1", |b| {
        b.iter(|| simplify(&mesh, &options).expect("the dragon simplifies"))
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
