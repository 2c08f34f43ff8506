//! `read_path` reads binary PLY and STL as they arrive, a chunk at a time: it gives
//! what reading the whole file at once gave (and what `read_bytes` gives), the same
//! mesh and the same errors, in the same order of precedence.
#![cfg(feature = "io")]
#![allow(clippy::unwrap_used)]

use std::io::Write;

use crate::common::grid;
use qem_mesh::io::{read_bytes, read_path, write_to, Format, LoadedMesh};
use qem_mesh::IndexedMesh;

/// `data` read from memory, from a file `name` and from a gzipped file `name.gz`: the
/// three must agree; errors without the file name in front.
fn read_three_ways(data: &[u8], name: &str) -> Result<LoadedMesh, String> {
    let format = Format::from_path(std::path::Path::new(name)).unwrap();
    let from_memory = read_bytes(data, format).map_err(|e| e.to_string());
    let dir = tempfile::tempdir().unwrap();
    for (file, bytes) in [
        (name.to_string(), data.to_vec()),
        (format!("{name}.gz"), gz(data)),
    ] {
        let path = dir.path().join(&file);
        std::fs::write(&path, bytes).unwrap();
        let prefix = format!("{}: ", path.display());
        let from_file = read_path(&path).map_err(|e| {
            let message = e.to_string();
            message
                .strip_prefix(&prefix)
                .unwrap_or(&message)
                .to_string()
        });
        assert_eq!(from_file, from_memory, "{file}");
    }
    from_memory
}

fn gz(data: &[u8]) -> Vec<u8> {
    let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    e.write_all(data).unwrap();
    e.finish().unwrap()
}

fn encode(mesh: &IndexedMesh, f: Format) -> Vec<u8> {
    let mut out = Vec::new();
    write_to(&mut out, mesh, f).unwrap();
    out
}

fn quad() -> IndexedMesh {
    IndexedMesh::new(
        vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ],
        vec![[0, 1, 2], [0, 2, 3]],
    )
}

/// `data` with the first `old` replaced by `new`.
fn replaced(data: &[u8], old: &[u8], new: &[u8]) -> Vec<u8> {
    let at = data.windows(old.len()).position(|w| w == old).unwrap();
    [&data[..at], new, &data[at + old.len()..]].concat()
}

/// Where the body of a PLY file starts.
fn body(ply: &[u8]) -> usize {
    ply.windows(11).position(|w| w == b"end_header\n").unwrap() + 11
}

#[test]
fn files_of_several_chunks_read_back_exactly() {
    // 400 x 400 vertices: large enough that records straddle the 1 MiB chunks.
    let mesh = grid(399, 399, 0.3);
    for (name, format) in [("grid.ply", Format::Ply), ("grid.stl", Format::Stl)] {
        let data = encode(&mesh, format);
        assert!(data.len() > 3 << 20, "{name} spans several chunks");
        let loaded = read_three_ways(&data, name).unwrap();
        if format == Format::Ply {
            assert_eq!(loaded.mesh, mesh);
        } else {
            assert_eq!(loaded.mesh.triangles.len(), mesh.triangles.len());
        }
    }
}

/// Before streaming, a fixed-size element was checked to fit in the file before any
/// record was read: a bad record in an element that is cut short is reported as the
/// cut.
#[test]
fn a_cut_element_is_reported_before_a_bad_record_in_it() {
    let mut ply = encode(&quad(), Format::Ply);
    let at = body(&ply);
    ply[at + 24 + 8..at + 24 + 16].copy_from_slice(&f64::NAN.to_le_bytes());
    assert_eq!(
        read_three_ways(&ply, "nan.ply").unwrap_err(),
        format!("byte {}: vertex 1 has a non-finite coordinate", at + 24)
    );
    let cut = &ply[..at + 3 * 24 + 5];
    assert_eq!(
        read_three_ways(cut, "nan.ply").unwrap_err(),
        format!(
            "byte {}: unexpected end of file after 3 of 4 vertices (binary PLY)",
            at + 3 * 24
        )
    );
}

#[test]
fn a_list_longer_than_the_rest_of_the_file() {
    let mut ply = encode(&quad(), Format::Ply);
    let first_face = body(&ply) + 4 * 24;
    ply[first_face] = 255;
    assert_eq!(
        read_three_ways(&ply, "list.ply").unwrap_err(),
        format!(
            "byte {first_face}: unexpected end of file in face 0: its list claims 255 items \
             (1020 bytes) but only 25 bytes are left"
        )
    );
}

/// Counts up to the largest accepted, in files that hold a few records: the reader
/// reserves what the file could hold, not what the header claims.
#[test]
fn huge_counts_in_small_files() {
    let ply = encode(&quad(), Format::Ply);
    let claims = replaced(&ply, b"element vertex 4", b"element vertex 268435456");
    assert_eq!(
        read_three_ways(&claims, "huge.ply").unwrap_err(),
        format!(
            "byte {}: unexpected end of file after 5 of 268435456 vertices (binary PLY)",
            // The faces' 26 bytes are read as vertices.
            body(&claims) + 5 * 24
        )
    );
    let mut stl = encode(&quad(), Format::Stl);
    stl[80..84].copy_from_slice(&(1u32 << 28).to_le_bytes());
    assert_eq!(
        read_three_ways(&stl, "huge.stl").unwrap_err(),
        "byte 184: unexpected end of file after 2 of 268435456 triangles \
         (binary STL of 13421772884 bytes)"
    );
}

/// Binary STL is binary by its size, known at the end of the data: a facet that is
/// not finite is reported only when the size says binary.
#[test]
fn an_stl_size_wins_over_a_bad_facet() {
    let mut stl = encode(&quad(), Format::Stl);
    stl[84 + 50 + 16..84 + 50 + 20].copy_from_slice(&f32::NAN.to_le_bytes());
    assert_eq!(
        read_three_ways(&stl, "nan.stl").unwrap_err(),
        "byte 146: vertex 3 has a non-finite coordinate"
    );
    let longer = [&stl[..], b"x"].concat();
    assert_eq!(
        read_three_ways(&longer, "nan.stl").unwrap_err(),
        "not an STL file: binary STL header claims 2 triangles (184 bytes) but there are \
         185 bytes"
    );
}

/// Gzip data was decompressed whole before parsing: a stream that is corrupt after
/// the mesh's last byte is still refused.
#[test]
fn a_gzip_error_after_the_mesh_is_still_an_error() {
    let ply = encode(&quad(), Format::Ply);
    let mut data = gz(&ply);
    let n = data.len();
    data[n - 1] ^= 0xff; // the uncompressed size in the trailer
    for format in [Format::Ply, Format::Obj] {
        let e = read_bytes(&data, format).unwrap_err().to_string();
        assert!(e.starts_with("gzip: corrupt data after "), "{e}");
    }
}

/// A header longer than the part first looked at for `end_header` (64 KiB).
#[test]
fn a_long_header() {
    let ply = encode(&quad(), Format::Ply);
    let comments = "comment a long comment line\n".repeat(5000);
    let long = replaced(&ply, b"comment ", format!("{comments}comment ").as_bytes());
    assert!(body(&long) > 1 << 17);
    assert_eq!(read_three_ways(&long, "long.ply").unwrap().mesh, quad());
}
