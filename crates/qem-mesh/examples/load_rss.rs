//! Reads one mesh file and prints what its arrays take, for measuring the readers' peak
//! memory (`/usr/bin/time -f "%M KB %e s"`, BENCHMARKS.md "Loading"); or writes a UV
//! sphere of about 2·N² triangles as a mesh file (binary PLY with `double` coordinates
//! for `.ply`), to have a large input to read; `noisy-sphere` gives its vertices a
//! deterministic ±0.001 radial noise, as `scripts/make_uv_sphere.py` does (a large input
//! to simplify: BENCHMARKS.md "A hundred million triangles").
//!
//! ```sh
//! cargo run --release -p qem-mesh --features io --example load_rss -- sphere 6325 /tmp/s.ply
//! /usr/bin/time -f "%M KB %e s" target/release/examples/load_rss read /tmp/s.ply
//! ```

use std::path::Path;
use std::process::ExitCode;

use qem_mesh::IndexedMesh;

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    match args[..] {
        ["read", file] => match qem_mesh::io::read_path(Path::new(file)) {
            Ok(loaded) => {
                let mesh = &loaded.mesh;
                // What the result holds, not what its vectors reserved.
                let channels: usize = mesh
                    .attributes
                    .channels
                    .iter()
                    .map(|c| 4 * c.values.len() + 12 * c.corners.len())
                    .sum();
                let bytes = 24 * mesh.positions.len() + 12 * mesh.triangles.len() + channels;
                println!(
                    "{} vertices, {} triangles, {} channels: arrays {bytes} bytes ({:.1} MB)",
                    mesh.positions.len(),
                    mesh.triangles.len(),
                    mesh.attributes.channels.len(),
                    bytes as f64 / 1e6
                );
                ExitCode::SUCCESS
            }
            Err(e) => {
                eprintln!("{e}");
                ExitCode::FAILURE
            }
        },
        [kind @ ("sphere" | "noisy-sphere"), n, out] => {
            let Ok(n) = n.parse::<u32>() else {
                eprintln!("N must be a whole number");
                return ExitCode::FAILURE;
            };
            let noise = if kind == "noisy-sphere" { 0.001 } else { 0.0 };
            match qem_mesh::io::write_path(Path::new(out), &sphere(n.max(3), noise)) {
                Ok(()) => ExitCode::SUCCESS,
                Err(e) => {
                    eprintln!("{e}");
                    ExitCode::FAILURE
                }
            }
        }
        _ => {
            eprintln!("usage: load_rss read FILE | load_rss [noisy-]sphere N OUT");
            ExitCode::FAILURE
        }
    }
}

/// `n - 1` rings of `n` vertices between two poles, as `scripts/make_uv_sphere.py`
/// builds them; the ring vertices at radius 1 ± `noise` (a deterministic hash of the
/// vertex number, not the script's random sequence). 0 for `sphere`: the readers do not
/// care; the noise keeps a simplification's quadrics from all being alike.
fn sphere(n: u32, noise: f64) -> IndexedMesh {
    let mut positions = vec![[0.0, 0.0, 1.0]];
    for i in 1..n {
        let theta = std::f64::consts::PI * f64::from(i) / f64::from(n);
        for j in 0..n {
            let phi = 2.0 * std::f64::consts::PI * f64::from(j) / f64::from(n);
            let r = 1.0 + noise * (2.0 * unit_hash(positions.len() as u64) - 1.0);
            positions.push([
                r * theta.sin() * phi.cos(),
                r * theta.sin() * phi.sin(),
                r * theta.cos(),
            ]);
        }
    }
    positions.push([0.0, 0.0, -1.0]);
    let south = (n - 1) * n + 1;
    let at = |i: u32, j: u32| 1 + (i - 1) * n + j % n;
    let mut triangles = Vec::new();
    for j in 0..n {
        triangles.push([0, at(1, j), at(1, j + 1)]);
    }
    for i in 1..n - 1 {
        for j in 0..n {
            let (a, b, c, d) = (at(i, j), at(i, j + 1), at(i + 1, j), at(i + 1, j + 1));
            triangles.push([a, c, b]);
            triangles.push([b, c, d]);
        }
    }
    for j in 0..n {
        triangles.push([south, at(n - 1, j + 1), at(n - 1, j)]);
    }
    IndexedMesh::new(positions, triangles)
}

/// A number in [0, 1) from `x` (SplitMix64's finaliser, Steele et al. 2014).
fn unit_hash(x: u64) -> f64 {
    let mut z = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    (z >> 11) as f64 / (1u64 << 53) as f64
}
