//! Measures the quality controls on meshes given on the command line: for each mesh
//! and each configuration, the output count, the stop reason, the error, the faces
//! flipped against the face they descend from, the border loops before and after, the
//! rejections by reason and the loop time. Used to choose the defaults of
//! `SimplifyOptions` (see the commit messages of the quality branch).
//!
//! `cargo run --profile dist -p qem-mesh --features io --example quality_sweep -- RATIO FILE...`

use qem_mesh::clean::{clean, CleanOptions};
use qem_mesh::simplify::{simplify, BoundaryMode, QuadricMode, SimplifyOptions, Target};
use qem_mesh::store::{EdgeClass, MeshStore};
use qem_mesh::IndexedMesh;
use std::path::Path;

/// Border loops: connected groups of border edges, as `qem info` counts them.
fn border_loops(mesh: &IndexedMesh) -> usize {
    qem_mesh::inspect::inspect(mesh).map_or(0, |info| info.boundary_loops)
}

/// Total length of the border edges and total area.
fn border_length_and_area(mesh: &IndexedMesh) -> (f64, f64) {
    let Ok((store, _)) = MeshStore::from_mesh(mesh) else {
        return (0.0, 0.0);
    };
    let p = |v| glam::DVec3::from_array(store.position(v));
    let length = store
        .edges()
        .filter(|&e| store.classify_edge(e) == EdgeClass::Boundary)
        .map(|e| {
            let [a, b] = store.edge_vertices(e);
            p(a).distance(p(b))
        })
        .sum();
    let area = store
        .faces()
        .map(|f| {
            let [a, b, c] = store.face_vertices(f).map(p);
            0.5 * (b - a).cross(c - a).length()
        })
        .sum();
    (length, area)
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some((ratio, files)) = args.split_first() else {
        eprintln!("usage: quality_sweep RATIO FILE...");
        std::process::exit(2);
    };
    let ratio: f64 = ratio.parse().unwrap_or(0.1);
    let base = SimplifyOptions::DEFAULT.with_target(Target::Ratio(ratio));
    let configs: Vec<(String, SimplifyOptions)> = vec![
        (
            "legacy(free,180,sum)".into(),
            base.clone()
                .with_boundary(BoundaryMode::Free)
                .with_max_normal_angle(180.0),
        ),
        ("default".into(), base.clone()),
        (
            "free".into(),
            base.clone().with_boundary(BoundaryMode::Free),
        ),
        (
            "planes0.1".into(),
            base.clone().with_boundary(BoundaryMode::Planes(0.1)),
        ),
        (
            "planes10".into(),
            base.clone().with_boundary(BoundaryMode::Planes(10.0)),
        ),
        (
            "planes100".into(),
            base.clone().with_boundary(BoundaryMode::Planes(100.0)),
        ),
        (
            "locked".into(),
            base.clone().with_boundary(BoundaryMode::Locked),
        ),
        ("angle180".into(), base.clone().with_max_normal_angle(180.0)),
        ("angle60".into(), base.clone().with_max_normal_angle(60.0)),
        ("angle45".into(), base.clone().with_max_normal_angle(45.0)),
        (
            "quality0.1".into(),
            base.clone().with_min_triangle_quality(0.1),
        ),
        (
            "quality0.2".into(),
            base.clone().with_min_triangle_quality(0.2),
        ),
        (
            "angle60+q0.1".into(),
            base.clone()
                .with_max_normal_angle(60.0)
                .with_min_triangle_quality(0.1),
        ),
        (
            "angle90+q0.1".into(),
            base.clone()
                .with_max_normal_angle(90.0)
                .with_min_triangle_quality(0.1),
        ),
        (
            "planes0.5".into(),
            base.clone().with_boundary(BoundaryMode::Planes(0.5)),
        ),
        (
            "planes2".into(),
            base.clone().with_boundary(BoundaryMode::Planes(2.0)),
        ),
        (
            "exact".into(),
            base.clone().with_quadrics(QuadricMode::Exact),
        ),
        ("topology".into(), base.clone().with_preserve_topology(true)),
    ];
    println!(
        "mesh\tconfig\ttris_in\ttris_out\tstop\tmax_error\tflipped%\tloops_in\tloops_out\t\
         rej_degenerate\trej_flip\trej_sliver\trej_topology\trej_locked\trej_border\tloop_ms\t\
         border_len_ratio\tarea_ratio"
    );
    for file in files {
        let name = Path::new(file)
            .file_name()
            .map_or(file.clone(), |n| n.to_string_lossy().into_owned());
        let mesh = match qem_mesh::io::read_path(Path::new(file)) {
            Ok(loaded) => loaded.mesh,
            Err(e) => {
                eprintln!("{name}: {e}");
                continue;
            }
        };
        let cleaned = clean(&mesh, &CleanOptions::DEFAULT).mesh;
        let loops_in = border_loops(&cleaned);
        let (length_in, area_in) = border_length_and_area(&cleaned);
        for (label, options) in &configs {
            match simplify(&mesh, options) {
                Ok(out) => {
                    let r = &out.report;
                    let (length, area) = border_length_and_area(&out.mesh);
                    println!(
                        "{name}\t{label}\t{}\t{}\t{}\t{:.3e}\t{:.2}\t{loops_in}\t{}\t{}\t{}\t{}\t{}\t{}\t{}\t{:.1}\t{:.4}\t{:.4}",
                        r.triangles_in,
                        r.triangles_out,
                        r.stop_reason,
                        r.max_error,
                        100.0 * r.faces_flipped as f64 / r.triangles_out.max(1) as f64,
                        border_loops(&out.mesh),
                        r.rejected.degenerate,
                        r.rejected.flip,
                        r.rejected.sliver,
                        r.rejected.topology,
                        r.rejected.locked,
                        r.rejected.border,
                        r.timings.contract.as_secs_f64() * 1e3,
                        length / length_in.max(f64::MIN_POSITIVE),
                        area / area_in.max(f64::MIN_POSITIVE),
                    );
                }
                Err(e) => println!("{name}\t{label}\terror: {e}"),
            }
        }
    }
}
