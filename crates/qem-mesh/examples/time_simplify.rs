//! Times `simplify` at ratio 0.1 on one file: best of RUNS runs of the whole call and
//! of the loop, with the rejections of each run on stderr. MODE picks the options:
//! `default`, `legacy` (free borders, no fold-over check: what the loop did before the
//! quality controls), `exact` (exact quadrics), `noflip` (no fold-over check), `free`
//! (free borders).
//!
//! `cargo run --profile dist -p qem-mesh --features io --example time_simplify -- FILE RUNS MODE`

use qem_mesh::simplify::{simplify, BoundaryMode, QuadricMode, SimplifyOptions, Target};
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let Some(file) = args.get(1) else {
        eprintln!("usage: time_simplify FILE [RUNS] [MODE]");
        std::process::exit(2);
    };
    let mesh = match qem_mesh::io::read_path(std::path::Path::new(file)) {
        Ok(loaded) => loaded.mesh,
        Err(e) => {
            eprintln!("{e}");
            std::process::exit(1);
        }
    };
    let runs: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(5);
    let mode = args.get(3).cloned().unwrap_or_default();
    let options = SimplifyOptions::DEFAULT.with_target(Target::Ratio(0.1));
    let options = match mode.as_str() {
        "legacy" => options
            .with_boundary(BoundaryMode::Free)
            .with_max_normal_angle(180.0),
        "exact" => options.with_quadrics(QuadricMode::Exact),
        "noflip" => options.with_max_normal_angle(180.0),
        "free" => options.with_boundary(BoundaryMode::Free),
        _ => options,
    };
    let mut best = f64::INFINITY;
    let mut best_loop = f64::INFINITY;
    for _ in 0..runs {
        let t = std::time::Instant::now();
        let out = match simplify(&mesh, &options) {
            Ok(out) => out,
            Err(e) => {
                eprintln!("{e}");
                std::process::exit(1);
            }
        };
        best = best.min(t.elapsed().as_secs_f64());
        best_loop = best_loop.min(out.report.timings.contract.as_secs_f64());
        let r = &out.report;
        eprintln!("{} tris, {:.3} s, loop {:.3} s, contractions {}, rejected: degenerate {} flip {} sliver {} topology {} locked {} border {}", out.mesh.triangle_count(), t.elapsed().as_secs_f64(), r.timings.contract.as_secs_f64(), r.edge_contractions + r.virtual_contractions, r.rejected.degenerate, r.rejected.flip, r.rejected.sliver, r.rejected.topology, r.rejected.locked, r.rejected.border);
    }
    println!("{mode}: best total {best:.3} s, best loop {best_loop:.3} s");
}
