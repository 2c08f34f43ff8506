//! Load throughput on the largest corpus meshes (the 871k-triangle Stanford dragon as
//! gzipped ascii PLY and as OBJ), and on a generated 2M-triangle grid written as binary
//! PLY and binary STL (the streamed readers). Skips the corpus with a message when it is
//! absent; set `QEM_CORPUS` to its directory.
#![allow(missing_docs)]

use std::path::{Path, PathBuf};

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use qem_mesh::io::{read_path, write_path};
use qem_mesh::IndexedMesh;

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
    let generated = tempfile::tempdir().expect("a temporary directory");
    let grid = grid(1000);
    let mut paths: Vec<(String, PathBuf)> = files
        .iter()
        .map(|name| (name.to_string(), dir.join(name)))
        .collect();
    for name in ["grid_2M.ply", "grid_2M.ply.gz", "grid_2M.stl"] {
        let path = generated.path().join(name);
        write_path(&path, &grid).expect("the grid is written");
        paths.push((format!("generated/{name}"), path));
    }
    let mut group = c.benchmark_group("load");
    group.sample_size(10);
    for (name, path) in paths {
        let Ok(loaded) = read_path(&path) else {
            eprintln!("SKIPPED load/{name}: cannot read {}", path.display());
            continue;
        };
        group.throughput(Throughput::Elements(loaded.mesh.triangle_count() as u64));
        group.bench_function(&name, |b| {
            b.iter(|| read_path(&path).map(|m| m.mesh.triangle_count()))
        });
    }
    group.finish();
}

criterion_group!(benches, load);
criterion_main!(benches);

/// `n` x `n` vertices in a plane with a little relief, two triangles per square.
fn grid(n: u32) -> IndexedMesh {
    let positions = (0..n * n)
        .map(|i| {
            let (x, y) = (f64::from(i % n), f64::from(i / n));
            [x, y, (x * 0.1).sin() * (y * 0.1).cos()]
        })
        .collect();
    let mut triangles = Vec::new();
    for y in 0..n - 1 {
        for x in 0..n - 1 {
            let a = y * n + x;
            triangles.push([a, a + 1, a + n]);
            triangles.push([a + 1, a + n + 1, a + n]);
        }
    }
    IndexedMesh::new(positions, triangles)
}
