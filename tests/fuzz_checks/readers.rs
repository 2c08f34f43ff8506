//! `read_obj`, `read_ply`, `read_stl`, `read_off`: arbitrary bytes through a reader.

use qem_mesh::io::{read_bytes, write_to, Format};
use qem_mesh::IndexedMesh;

/// `read_obj`: see [`read_checked`].
pub fn read_obj(data: &[u8]) {
    read_checked(data, Format::Obj);
}

/// `read_ply`: see [`read_checked`].
pub fn read_ply(data: &[u8]) {
    read_checked(data, Format::Ply);
}

/// `read_stl`: see [`read_checked`].
pub fn read_stl(data: &[u8]) {
    read_checked(data, Format::Stl);
}

/// `read_off`: see [`read_checked`].
pub fn read_off(data: &[u8]) {
    read_checked(data, Format::Off);
}

/// Arbitrary bytes give a mesh that passes validation or an error whose message is one
/// non-empty line; never a panic. (Memory: libFuzzer's `-rss_limit_mb` and
/// `-malloc_limit_mb` turn an allocation blow-up into a crash, see FUZZING.md.)
///
/// A mesh that was read is written back in the same format (STL refuses coordinates
/// beyond float32, the one accepted write error) and read again, and must
/// come back as the same triangles: for OBJ, PLY and OFF the same indices and the same
/// position bits; for STL, which has no shared vertices and `float32` coordinates, the
/// same corner positions rounded to f32, triangle by triangle (an ASCII facet with more
/// than three vertices is fanned into triangles that share them, and comes back as
/// separate triangles).
pub fn read_checked(data: &[u8], format: Format) {
    let loaded = match read_bytes(data, format) {
        Ok(loaded) => loaded,
        Err(e) => {
            let message = e.to_string();
            assert!(!message.is_empty(), "empty error message");
            assert!(!message.contains('\n'), "multi-line message: {message:?}");
            return;
        }
    };
    let mesh = loaded.mesh;
    if let Err(e) = mesh.validate() {
        panic!("read an invalid mesh: {e}");
    }
    let mut written = Vec::new();
    if let Err(e) = write_to(&mut written, &mesh, format) {
        // The one documented refusal: STL cannot hold coordinates beyond float32.
        let beyond_f32 = mesh
            .positions
            .iter()
            .flatten()
            .any(|&c| (c as f32).is_infinite());
        assert!(
            format == Format::Stl && beyond_f32,
            "a valid mesh cannot be written: {e}"
        );
        return;
    }
    let again = match read_bytes(&written, format) {
        Ok(again) => again.mesh,
        Err(e) => panic!("cannot read back what was written: {e}"),
    };
    if format == Format::Stl {
        let f32_bits = |c: f64| f64::from(c as f32).to_bits();
        assert_eq!(
            corner_bits(&again, f64::to_bits),
            corner_bits(&mesh, f32_bits),
            "round trip changed triangles"
        );
    } else {
        assert_eq!(again.triangles, mesh.triangles, "round trip changed faces");
        let bits = |m: &IndexedMesh| -> Vec<[u64; 3]> {
            m.positions.iter().map(|p| p.map(f64::to_bits)).collect()
        };
        assert_eq!(bits(&again), bits(&mesh), "round trip changed positions");
    }
}

/// The bits of every corner position, triangle by triangle, through `bits`.
fn corner_bits(mesh: &IndexedMesh, bits: impl Fn(f64) -> u64) -> Vec<[u64; 3]> {
    mesh.triangles
        .iter()
        .flatten()
        .map(|&i| mesh.positions[i as usize].map(&bits))
        .collect()
}
