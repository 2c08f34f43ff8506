//! Load throughput on the largest corpus meshes (the 871k-triangle Stanford dragon as
//! gzipped ascii PLY and as OBJ). Skips with a message when the corpus is absent; set
//! `QEM_CORPUS` to its directory.
#![allow(missing_docs)]

use std::path::{Path, PathBuf};

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use qem_mesh::io::read_path;

fn corpus() -> PathBuf {
    match std::env::var_os("QEM_CORPUS") {
        Some(d) => PathBuf::from(d),
        None => Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/corpus"),
    }
}

fn load(c: &mut Criterion) {
    let dir = corpus();
    let files = [
        "originals/stanford_dragon_vrip.ply.gz",
        "stanford_dragon_vrip.obj",
        "originals/ps_mk4_gantry.stl.gz",
        "originals/cgal_mannequin_devil.off.gz",
    ];
    let mut group = c.benchmark_group("load");
    group.sample_size(10);
    for name in files {
        let path = dir.join(name);
        let Ok(loaded) = read_path(&path) else {
            eprintln!("SKIPPED load/{name}: cannot read {}", path.display());
            continue;
        };
        group.throughput(Throughput::Elements(loaded.mesh.triangle_count() as u64));
        group.bench_function(name, |b| {
            b.iter(|| read_path(&path).map(|m| m.mesh.triangle_count()))
        });
    }
    group.finish();
}

criterion_group!(benches, load);
criterion_main!(benches);
