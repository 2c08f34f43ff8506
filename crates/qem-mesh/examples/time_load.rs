//! Temporary timing helper.
fn main() {
    for p in std::env::args().skip(1) {
        let t = std::time::Instant::now();
        let r = qem_mesh::io::read_path(std::path::Path::new(&p));
        println!(
            "{p}: {:?} in {:?}",
            r.map(|m| m.mesh.triangle_count()),
            t.elapsed()
        );
    }
}
