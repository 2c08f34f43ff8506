//! Malformed input, round trips and atomic writes of `qem_mesh::io`.
#![cfg(feature = "io")]
#![allow(clippy::unwrap_used)]

use std::io::Write;
use std::path::Path;

use proptest::prelude::*;
use qem_mesh::attributes::ChannelKind;
use qem_mesh::io::{read_bytes, read_path, write_path, write_to, Format};
use qem_mesh::IndexedMesh;

fn err(bytes: &[u8], f: Format) -> String {
    match read_bytes(bytes, f) {
        Ok(m) => panic!(
            "expected an error, loaded {} triangles",
            m.mesh.triangle_count()
        ),
        Err(e) => e.to_string(),
    }
}

fn assert_contains(msg: &str, part: &str) {
    assert!(
        msg.contains(part),
        "message {msg:?} does not contain {part:?}"
    );
}

fn quad() -> IndexedMesh {
    IndexedMesh::new(
        vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0 / 3.0, 0.0],
            [0.1, 1e-300, 12_345.678_9],
        ],
        vec![[0, 1, 2], [0, 2, 3]],
    )
}

fn encode(mesh: &IndexedMesh, f: Format) -> Vec<u8> {
    let mut out = Vec::new();
    write_to(&mut out, mesh, f).unwrap();
    out
}

fn gz(data: &[u8]) -> Vec<u8> {
    let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    e.write_all(data).unwrap();
    e.finish().unwrap()
}

#[test]
fn empty_file_for_each_format() {
    for f in Format::ALL {
        assert_eq!(err(b"", f), "the file is empty");
    }
}

#[test]
fn vertices_but_no_faces() {
    let obj = err(b"v 0 0 0\nv 1 0 0\nv 0 1 0\n", Format::Obj);
    assert_eq!(obj, "the mesh has no triangles");
    let off = err(b"OFF\n3 0 0\n0 0 0\n1 0 0\n0 1 0\n", Format::Off);
    assert_eq!(off, "the mesh has no triangles");
    let ply = b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 0 0\n";
    assert_eq!(err(ply, Format::Ply), "the mesh has no triangles");
    let stl = b"solid x\nendsolid x\n";
    assert_eq!(err(stl, Format::Stl), "the mesh has no triangles");
}

#[test]
fn truncated_binary_stl_names_where_it_ended() {
    let mut data = encode(&quad(), Format::Stl);
    data.truncate(84 + 50 + 20);
    assert_eq!(
        err(&data, Format::Stl),
        "byte 154: unexpected end of file after 1 of 2 triangles (binary STL of 184 bytes)"
    );
}

#[test]
fn truncated_binary_ply_names_where_it_ended() {
    let full = encode(&quad(), Format::Ply);
    let header_len = full.windows(11).position(|w| w == b"end_header\n").unwrap() + 11;
    // Cut inside the third vertex.
    let cut = &full[..header_len + 24 * 2 + 5];
    let msg = err(cut, Format::Ply);
    assert_contains(
        &msg,
        "unexpected end of file after 2 of 4 vertices (binary PLY)",
    );
    assert!(
        msg.starts_with(&format!("byte {}: ", header_len + 48)),
        "{msg}"
    );
    // Cut inside the faces.
    let cut = &full[..full.len() - 3];
    assert_contains(
        &err(cut, Format::Ply),
        "unexpected end of file in face 1: its list claims 3 items (12 bytes) but only 9 bytes are left",
    );
}

#[test]
fn ply_header_claiming_1e12_vertices() {
    let data = b"ply\nformat binary_little_endian 1.0\nelement vertex 1000000000000\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
    assert_eq!(
        err(data, Format::Ply),
        "line 3: PLY header claims vertices: 1000000000000, more than the limit of 268435456"
    );
}

#[test]
fn ply_face_list_count_of_4e9() {
    let mut data = b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uint int vertex_indices\nend_header\n".to_vec();
    let body = data.len();
    data.extend(std::iter::repeat_n(0u8, 36));
    data.extend(4_000_000_000u32.to_le_bytes());
    data.extend([0u8; 12]);
    let msg = err(&data, Format::Ply);
    assert_eq!(
        msg,
        format!(
            "byte {}: unexpected end of file in face 0: its list claims 4000000000 items \
             (16000000000 bytes) but only 12 bytes are left",
            body + 36
        )
    );
    let ascii = b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uint int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n4000000000 0 1 2\n";
    assert_contains(
        &err(ascii, Format::Ply),
        "line 13: unexpected end of file in face 0: its list claims 4000000000 items",
    );
}

#[test]
fn ply_float_index_list_is_an_error() {
    let data = b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar float vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    assert_contains(
        &err(data, Format::Ply),
        "line 7: face property \"vertex_indices\" has a floating-point item type",
    );
}

#[test]
fn ply_skips_unknown_elements_and_list_properties_and_reads_big_endian() {
    let mut data = b"ply\nformat binary_big_endian 1.0\nelement material 2\nproperty list uchar float weights\nelement vertex 3\nproperty uchar red\nproperty double x\nproperty double y\nproperty double z\nelement face 1\nproperty list uchar uint texcoord\nproperty list ushort short vertex_index\nproperty int flags\nend_header\n".to_vec();
    data.extend([1, 0, 0, 0, 0]); // material 0: one float
    data.extend([0]); // material 1: empty list
    for p in [[0.0f64, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.5]] {
        data.push(255);
        for c in p {
            data.extend(c.to_be_bytes());
        }
    }
    data.extend([1, 0, 0, 0, 7]); // texcoord list, one uint
    data.extend(3u16.to_be_bytes());
    for i in [0i16, 1, 2] {
        data.extend(i.to_be_bytes());
    }
    data.extend(9i32.to_be_bytes());
    let m = read_bytes(&data, Format::Ply).unwrap().mesh;
    assert_eq!(m.triangles, vec![[0, 1, 2]]);
    assert_eq!(m.positions[2], [0.0, 1.0, 0.5]);
}

#[test]
fn index_out_of_range_names_the_face() {
    let off = b"OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 1 120\n";
    assert_eq!(
        err(off, Format::Off),
        "line 7: face 1 refers to vertex 120, but there are only 3 vertices"
    );
    let obj = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 120\n";
    assert_eq!(
        err(obj, Format::Obj),
        "line 5: face 1 refers to vertex 120, but there are only 3 vertices"
    );
    let ply = b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n";
    assert_eq!(
        err(ply, Format::Ply),
        "line 13: face 0 refers to vertex 3, but there are only 3 vertices"
    );
}

#[test]
fn obj_negative_index_past_the_start_and_index_zero() {
    let obj = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n";
    assert_eq!(
        err(obj, Format::Obj),
        "line 4: face 0: relative vertex index -4 points before the first one (3 vertices so far)"
    );
    // In a texture-coordinate slot this would overflow inside tobj (a debug panic).
    let obj = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/-5 2/-5 3/-5\n";
    assert_contains(
        &err(obj, Format::Obj),
        "line 5: face 0: relative texture coordinate index -5",
    );
    let obj = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/4611686018427387904 2/1 3/1\n";
    assert_contains(
        &err(obj, Format::Obj),
        "line 5: face 0 refers to texture coordinate 4611686018427387904",
    );
    let obj = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n";
    assert_eq!(
        err(obj, Format::Obj),
        "line 4: face 0: vertex index 0 is invalid (OBJ indices start at 1)"
    );
    let obj = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/0 2/1 3/1\n";
    assert_contains(
        &err(obj, Format::Obj),
        "texture coordinate index 0 is invalid",
    );
}

#[test]
fn obj_keeps_texcoords_normals_and_fans_polygons() {
    let obj = b"v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\nusemtl\nf 1/1/1 2/2/1 3/3/1 \\\n 4/4/1\n";
    let loaded = read_bytes(obj, Format::Obj).unwrap();
    assert_eq!(loaded.mesh.triangles.len(), 2);
    let a = &loaded.mesh.attributes;
    let uvs = a.channel(ChannelKind::TexCoord).unwrap();
    let normals = a.channel(ChannelKind::Normal).unwrap();
    assert_eq!(uvs.value_count(), 4);
    assert_eq!(normals.values, vec![0.0, 0.0, 1.0]);
    assert_eq!(uvs.corners.len(), 2);
    let p = &loaded.mesh.positions;
    let uv = |t: usize, k: usize| uvs.at_corner(t, k).unwrap().to_vec();
    // Fan from the first corner, and each corner keeps its own texture coordinate.
    assert_eq!(p[loaded.mesh.triangles[1][2] as usize], [0.0, 1.0, 0.0]);
    assert_eq!(uv(1, 2), [0.0, 1.0]);
    // A bare `usemtl` names nothing: the faces have no material.
    assert!(a.materials.names.is_empty());
}

#[test]
fn non_finite_coordinates_name_the_vertex() {
    for bad in ["nan", "inf", "1e999", "-infinity"] {
        let obj = format!("v 0 0 0\nv 1 {bad} 0\nv 0 1 0\nf 1 2 3\n");
        assert_eq!(
            err(obj.as_bytes(), Format::Obj),
            "line 2: vertex 1 has a non-finite coordinate"
        );
        let off = format!("OFF\n3 1 0\n0 0 0\n1 {bad} 0\n0 1 0\n3 0 1 2\n");
        assert_eq!(
            err(off.as_bytes(), Format::Off),
            "line 4: vertex 1 has a non-finite coordinate"
        );
        let stl = format!("solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 {bad} 0\nendloop\nendfacet\nendsolid\n");
        assert_eq!(
            err(stl.as_bytes(), Format::Stl),
            "line 6: vertex 2 has a non-finite coordinate"
        );
    }
    let mut m = quad();
    m.positions[2][0] = f64::INFINITY;
    let ply = encode(&m, Format::Ply);
    assert_contains(
        &err(&ply, Format::Ply),
        "vertex 2 has a non-finite coordinate",
    );
}

#[test]
fn garbage_and_wrong_content_are_clear_errors() {
    let png = b"\x89PNG\r\n\x1a\n\0\0\0\rIHDR\0\0\x01\0\0\0\x01\0\x08\x06\0\0\0";
    assert_eq!(
        err(png, Format::Ply),
        "not a PLY file: does not start with \"ply\" (it looks like a PNG image)"
    );
    assert_contains(&err(png, Format::Stl), "not an STL file");
    assert_contains(&err(png, Format::Off), "not an OFF file");
    assert_contains(&err(png, Format::Obj), "not an OBJ file");
    let garbage: Vec<u8> = (0..500u32)
        .map(|i| (i.wrapping_mul(2_654_435_761) >> 13) as u8)
        .collect();
    for f in Format::ALL {
        let msg = err(&garbage, f);
        assert!(!msg.is_empty());
    }
    let obj = b"# an OBJ\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    assert_eq!(
        err(obj, Format::Stl),
        "not an STL file: neither ASCII (\"solid ...\") nor binary (84 + 50 bytes per triangle) (it looks like an OBJ file)"
    );
}

#[test]
fn unknown_extension_lists_supported_ones() {
    let e = read_path(Path::new("/nonexistent/bunny.js")).unwrap_err();
    assert_eq!(
        e.to_string(),
        "/nonexistent/bunny.js: unsupported file extension \".js\"; supported: .obj, .ply, .stl, .off, .gltf, .glb (each optionally followed by .gz)"
    );
    assert_eq!(
        Format::from_path(Path::new("a.OBJ.GZ")).unwrap(),
        Format::Obj
    );
    assert!(Format::from_path(Path::new("a.gz")).is_err());
}

#[test]
fn a_line_of_several_megabytes() {
    let mut obj = b"v 0 0 0\nv 1 0 0\nv 0 1 0\n# ".to_vec();
    obj.extend(std::iter::repeat_n(b'x', 5 << 20));
    obj.extend(b"\nf 1 2 3\n");
    assert_eq!(
        read_bytes(&obj, Format::Obj).unwrap().mesh.triangles.len(),
        1
    );
    // A face with a million corners is a fan of 999998 triangles.
    let n = 1_000_000usize;
    let mut off = format!("OFF\n{n} 1 0\n").into_bytes();
    for i in 0..n {
        off.extend(format!("{i} 0 {}\n", i % 7).as_bytes());
    }
    off.extend(format!("{n}").as_bytes());
    for i in 0..n {
        off.extend(format!(" {i}").as_bytes());
    }
    off.push(b'\n');
    assert_eq!(
        read_bytes(&off, Format::Off).unwrap().mesh.triangles.len(),
        n - 2
    );
    let mut stl = b"solid ".to_vec();
    stl.extend(std::iter::repeat_n(b'n', 3 << 20));
    stl.extend(b"\nendsolid\n");
    assert_eq!(err(&stl, Format::Stl), "the mesh has no triangles");
}

#[test]
fn non_utf8_bytes() {
    let obj = b"v 0 0 0\nv 1 \xff 0\nv 0 1 0\nf 1 2 3\n";
    assert_eq!(
        err(obj, Format::Obj),
        "line 2: not valid UTF-8 text (byte 5 of the line)"
    );
    // Outside data lines, non-UTF-8 is harmless.
    let obj = b"# caf\xe9\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    assert_eq!(
        read_bytes(obj, Format::Obj).unwrap().mesh.triangles.len(),
        1
    );
    let off = b"OFF\n3 1 0\n0 0 0\n1 \xff 0\n0 1 0\n3 0 1 2\n";
    assert_eq!(
        err(off, Format::Off),
        "line 4: vertex 1: bad coordinate \"\u{fffd}\""
    );
}

#[test]
fn corrupt_gzip() {
    let mut data = gz(&encode(&quad(), Format::Obj));
    let n = data.len();
    data[n / 2] ^= 0xff;
    data[n / 2 + 1] ^= 0x55;
    assert_contains(&err(&data, Format::Obj), "gzip: corrupt data after");
    let truncated = &gz(&encode(&quad(), Format::Off))[..20];
    assert_contains(&err(truncated, Format::Off), "gzip: corrupt data");
}

#[test]
fn round_trips_every_format_plain_and_gzipped() {
    let m = quad();
    for f in Format::ALL {
        let bytes = encode(&m, f);
        for data in [bytes.clone(), gz(&bytes)] {
            let back = read_bytes(&data, f).unwrap().mesh;
            if f == Format::Stl {
                assert_eq!(back.triangles, vec![[0, 1, 2], [3, 4, 5]]);
                for (t, tri) in m.triangles.iter().enumerate() {
                    for (k, &i) in tri.iter().enumerate() {
                        let want = m.positions[i as usize].map(|c| f64::from(c as f32));
                        assert_eq!(back.positions[3 * t + k], want);
                    }
                }
            } else if matches!(f, Format::Gltf | Format::Glb) {
                // float32 positions, the vertex order kept.
                assert_eq!(back.triangles, m.triangles, "{f:?}");
                let want: Vec<_> = m
                    .positions
                    .iter()
                    .map(|p| p.map(|c| f64::from(c as f32)))
                    .collect();
                assert_eq!(back.positions, want, "{f:?}");
            } else {
                assert_eq!(back, m, "{f:?}");
            }
        }
    }
}

#[test]
fn write_path_is_atomic_and_leaves_no_temp_files() {
    let dir = tempfile::tempdir().unwrap();
    for name in ["m.obj", "m.ply", "m.stl", "m.off", "m.ply.gz"] {
        let path = dir.path().join(name);
        write_path(&path, &quad()).unwrap();
        write_path(&path, &quad()).unwrap(); // replaces
        assert_eq!(read_path(&path).unwrap().mesh.triangle_count(), 2);
    }
    let names: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    assert_eq!(names.len(), 5, "{names:?}");
}

#[test]
fn failed_write_leaves_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("no/such/dir/m.obj");
    let e = write_path(&missing, &quad()).unwrap_err();
    assert_contains(
        &e.to_string(),
        "m.obj: cannot write (its directory does not exist)",
    );
    let mut bad = quad();
    bad.triangles.push([0, 1, 99]);
    let path = dir.path().join("bad.ply");
    let e = write_path(&path, &bad).unwrap_err();
    assert_contains(
        &e.to_string(),
        "bad.ply: cannot write: face 2 refers to vertex 99",
    );
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

fn mutate(mut data: Vec<u8>, edits: &[(usize, u8)], cut: Option<usize>) -> Vec<u8> {
    for &(i, b) in edits {
        if !data.is_empty() {
            let n = data.len();
            data[i % n] = b;
        }
    }
    if let Some(c) = cut {
        data.truncate(c % (data.len() + 1));
    }
    data
}

proptest! {
    #[test]
    fn read_bytes_never_panics_on_arbitrary_bytes(data in proptest::collection::vec(any::<u8>(), 0..600)) {
        for f in Format::ALL {
            let _ = read_bytes(&data, f);
        }
    }

    #[test]
    fn read_bytes_never_panics_on_mutated_files(
        edits in proptest::collection::vec((any::<usize>(), any::<u8>()), 0..6),
        cut in proptest::option::of(any::<usize>()),
    ) {
        let m = quad();
        for f in Format::ALL {
            let data = mutate(encode(&m, f), &edits, cut);
            let _ = read_bytes(&data, f);
        }
        let ply_ascii = b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n".to_vec();
        let _ = read_bytes(&mutate(ply_ascii, &edits, cut), Format::Ply);
        let obj = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\nf 1/1/1 2/1/1 3/1/1\nf -1 -2 -3\n".to_vec();
        let _ = read_bytes(&mutate(obj, &edits, cut), Format::Obj);
        let stl = b"solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid\n".to_vec();
        let _ = read_bytes(&mutate(stl, &edits, cut), Format::Stl);
    }
}
