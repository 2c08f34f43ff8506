//! Hostile attribute files (issue 29), read from disk through `read_path`: each is
//! refused with one line that starts with the file's path and names the place (the
//! line for OBJ and ASCII PLY, the byte for binary PLY and GLB containers, the
//! vertex or face, the glTF buffer, accessor or primitive). Never a panic, and never
//! an allocation in proportion to a size the file only claims.
//!
//! The expected messages are exact, so a change of wording is a deliberate change of
//! this test.

use std::path::Path;

use qem_mesh::attributes::{Channel, ChannelKind};
use qem_mesh::io::{read_path, Format};
use qem_mesh::IndexedMesh;
use serde_json::{json, Value};

use crate::attributes_common::{encode, glb};

/// Writes `files` (name, content) into a fresh directory, reads the first through
/// `read_path`, and checks that it is refused with exactly `PATH: CAUSE` on one line.
fn assert_refused_among(files: &[(&str, &[u8])], cause: &str) {
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("a temporary directory: {e}"));
    for (name, bytes) in files {
        std::fs::write(dir.path().join(name), bytes)
            .unwrap_or_else(|e| panic!("{name} is written: {e}"));
    }
    let path = dir.path().join(files[0].0);
    let message = match read_path(&path) {
        Ok(loaded) => panic!(
            "{}: loaded {} triangles",
            files[0].0,
            loaded.mesh.triangle_count()
        ),
        Err(e) => e.to_string(),
    };
    assert!(!message.contains('\n'), "more than one line: {message:?}");
    assert_eq!(message, format!("{}: {cause}", path.display()));
}

/// [`assert_refused_among`] with the one file `name`.
fn assert_refused(name: &str, bytes: &[u8], cause: &str) {
    assert_refused_among(&[(name, bytes)], cause);
}

const TRIANGLE: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";

#[test]
fn obj_texture_coordinates_normals_and_colours_beyond_float32_name_their_line() {
    let obj = |lines: &str| format!("{TRIANGLE}{lines}").into_bytes();
    assert_refused(
        "nan_vt.obj",
        &obj("vt 0 0\nvt nan 0.5\nvt 1 1\nf 1/1 2/2 3/3\n"),
        "line 5: texture coordinate 1: \"nan\" is not a finite 32-bit float",
    );
    // Finite as f64, but texture coordinates are kept as f32.
    assert_refused(
        "huge_vt.obj",
        &obj("vt 0 1e39\nf 1/1 2/1 3/1\n"),
        "line 4: texture coordinate 0: \"1e39\" is not a finite 32-bit float",
    );
    assert_refused(
        "inf_vn.obj",
        &obj("vn 0 0 1\nvn 0 -inf 1\nf 1//1 2//2 3//1\n"),
        "line 5: normal 1: \"-inf\" is not a finite 32-bit float",
    );
    assert_refused(
        "nan_colour.obj",
        b"v 0 0 0 1 0 0\nv 1 0 0 0 NaN 0\nv 0 1 0 0 0 1\nf 1 2 3\n",
        "line 2: vertex 1: colour: \"NaN\" is not a finite 32-bit float",
    );
    // Beyond float32 even as a 0–255 level: not clamped to 1, but refused.
    assert_refused(
        "huge_colour.obj",
        b"v 0 0 0 255 0 0\nv 1 0 0 0 1e39 0\nv 0 1 0 0 0 255\nf 1 2 3\n",
        "line 2: vertex 1: colour: \"1e39\" is not a finite 32-bit float",
    );
}

#[test]
fn obj_texture_coordinate_and_normal_indices_out_of_range_name_their_line() {
    let obj = |face: &str| format!("{TRIANGLE}vt 0 0\nvn 0 0 1\n{face}\n").into_bytes();
    assert_refused(
        "vt_out_of_range.obj",
        &obj("f 1/1/1 2/7/1 3/1/1"),
        "line 6: face 0 refers to texture coordinate 7, but there are only 1 texture \
         coordinates",
    );
    assert_refused(
        "vn_out_of_range.obj",
        &obj("f 1/1/1 2/1/1 3/1/5"),
        "line 6: face 0 refers to normal 5, but there are only 1 normals",
    );
    assert_refused(
        "vt_before_start.obj",
        &obj("f 1/-2 2/1 3/1"),
        "line 6: face 0: relative texture coordinate index -2 points before the first one \
         (1 texture coordinates so far)",
    );
}

/// A binary little-endian PLY header for `vertices` vertices with float `x y z` and
/// the float vertex properties `extra`, and `faces` triangles.
fn ply_header(vertices: usize, extra: &[&str], faces: usize) -> Vec<u8> {
    let mut h = format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex {vertices}\n\
         property float x\nproperty float y\nproperty float z\n"
    );
    for p in extra {
        h.push_str(&format!("property float {p}\n"));
    }
    h.push_str(&format!(
        "element face {faces}\nproperty list uchar int vertex_indices\nend_header\n"
    ));
    h.into_bytes()
}

fn le_floats(values: &[f32]) -> Vec<u8> {
    values.iter().flat_map(|v| v.to_le_bytes()).collect()
}

#[test]
fn ply_nan_normals_and_colours_name_the_element_and_property() {
    let ascii = b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n\
        property float y\nproperty float z\nproperty float nx\nproperty float ny\n\
        property float nz\nelement face 1\nproperty list uchar int vertex_indices\n\
        end_header\n0 0 0 0 0 1\n1 0 0 nan 0 1\n0 1 0 0 0 1\n3 0 1 2\n";
    assert_refused(
        "nan_normal.ply",
        ascii,
        "line 14: vertex 1: property \"nx\" is \"nan\", not a finite 32-bit float",
    );
    // Float colours, the second vertex's green NaN: the place is the value's first byte
    // (after 24 bytes of vertex 0, and x, y, z and red of vertex 1).
    let mut binary = ply_header(3, &["red", "green", "blue"], 1);
    let green_1 = binary.len() + 24 + 16;
    binary.extend(le_floats(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0]));
    binary.extend(le_floats(&[1.0, 0.0, 0.0, 0.0, f32::NAN, 0.0]));
    binary.extend(le_floats(&[0.0, 1.0, 0.0, 0.0, 0.0, 1.0]));
    binary.push(3);
    binary.extend([0i32, 1, 2].iter().flat_map(|i| i.to_le_bytes()));
    assert_refused(
        "nan_colour.ply",
        &binary,
        &format!("byte {green_1}: vertex 1: property \"green\" is NaN, not a finite 32-bit float"),
    );
    let face_colour = b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n\
        property float y\nproperty float z\nelement face 1\n\
        property list uchar int vertex_indices\nproperty float red\nproperty float green\n\
        property float blue\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2 1 inf 0\n";
    assert_refused(
        "inf_face_colour.ply",
        face_colour,
        "line 16: face 0: property \"green\" is \"inf\", not a finite 32-bit float",
    );
}

/// A triangle with texture coordinates and normals as the glTF writer writes it, as
/// its JSON document and its binary buffer: accessor 0 is POSITION (bytes 0..36),
/// 1 TEXCOORD_0 (36..60), 2 NORMAL (60..96), 3 the indices (96..108).
fn triangle_gltf() -> (Value, Vec<u8>) {
    let triangles = vec![[0, 1, 2]];
    let uv = Channel::new(
        ChannelKind::TexCoord,
        vec![0.0, 0.0, 1.0, 0.0, 0.0, 1.0],
        triangles.clone(),
    );
    let normal = Channel::new(
        ChannelKind::Normal,
        vec![0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0],
        triangles.clone(),
    );
    let mut mesh = IndexedMesh::new(
        vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        triangles,
    );
    mesh.attributes.channels = vec![uv, normal];
    let file = encode(&mesh, Format::Glb);
    let u32_at =
        |at: usize| u32::from_le_bytes([file[at], file[at + 1], file[at + 2], file[at + 3]]);
    let json_len = u32_at(12) as usize;
    let doc = serde_json::from_slice(&file[20..20 + json_len])
        .unwrap_or_else(|e| panic!("the writer's JSON: {e}"));
    let bin_len = u32_at(20 + json_len) as usize;
    let bin = file[28 + json_len..28 + json_len + bin_len].to_vec();
    assert_eq!(bin.len(), 108, "the layout this test's offsets assume");
    (doc, bin)
}

/// `doc` as `.gltf` text.
fn text(doc: &Value) -> Vec<u8> {
    serde_json::to_vec(doc).unwrap_or_else(|e| panic!("JSON: {e}"))
}

#[test]
fn gltf_external_buffer_missing_or_short_names_the_buffer_and_accessor() {
    let (mut doc, bin) = triangle_gltf();
    doc["buffers"][0]["uri"] = json!("tri.bin");
    assert_refused(
        "missing_buffer.gltf",
        &text(&doc),
        "buffer 0: cannot read its file \"tri.bin\": No such file or directory (os error 2)",
    );
    assert_refused_among(
        &[("short_buffer.gltf", &text(&doc)), ("tri.bin", &bin[..50])],
        "unexpected end of file in buffer 0: it holds 50 bytes, its byteLength says 108",
    );
    // The file holds all the buffer declares, but the buffer is too short for what its
    // views and accessors claim (accessors 1 and 2 end past byte 50; the attributes are
    // read in glTF's order of semantics, NORMAL first).
    doc["buffers"][0]["byteLength"] = json!(50);
    assert_refused_among(
        &[("short_view.gltf", &text(&doc)), ("tri.bin", &bin[..50])],
        "accessor 2 (NORMAL of mesh 0 primitive 0): its buffer view ends past the 50 bytes \
         of buffer 0",
    );
    let (mut doc, _) = triangle_gltf();
    doc["accessors"][0]["count"] = json!(4);
    doc["buffers"][0]["uri"] = json!("tri.bin");
    assert_refused_among(
        &[("long_accessor.gltf", &text(&doc)), ("tri.bin", &bin)],
        "accessor 0 (POSITION of mesh 0 primitive 0): 4 elements of 12 bytes do not fit in \
         its buffer view",
    );
}

#[test]
fn gltf_data_uri_declaring_1e9_bytes_is_refused_before_it_is_decoded() {
    let (mut doc, _) = triangle_gltf();
    let billion = 1_000_000_000u64;
    // The writer's own short URI, with a byteLength of 10^9.
    let uri = |payload: &str| format!("data:application/octet-stream;base64,{payload}");
    doc["buffers"][0]["uri"] = json!(uri("AAAA"));
    doc["buffers"][0]["byteLength"] = json!(billion);
    assert_refused(
        "short_uri.gltf",
        &text(&doc),
        "unexpected end of file in buffer 0: it holds 3 bytes, its byteLength says \
         1000000000",
    );
    // A genuinely long URI (16 MiB of base64, 12 MiB of zeros): its length is checked
    // against the declared one without decoding it, and nothing of 10^9 bytes is
    // reserved (libFuzzer's -malloc_limit_mb would catch that in the read_gltf seed
    // `data_uri_declares_1e9_bytes_gltf`).
    doc["buffers"][0]["uri"] = json!(uri(&"A".repeat(1 << 24)));
    assert_refused(
        "long_uri.gltf",
        &text(&doc),
        "unexpected end of file in buffer 0: it holds 12582912 bytes, its byteLength says \
         1000000000",
    );
}

#[test]
fn glb_chunks_longer_than_the_file_name_the_byte() {
    let (doc, bin) = triangle_gltf();
    let file = glb(&doc, &bin);
    let json_len = u32::from_le_bytes([file[12], file[13], file[14], file[15]]) as usize;
    let bin_chunk = 20 + json_len;
    let mut long_chunk = file.clone();
    long_chunk[bin_chunk..bin_chunk + 4].copy_from_slice(&0x7fff_ff00u32.to_le_bytes());
    assert_refused(
        "long_chunk.glb",
        &long_chunk,
        &format!(
            "byte {}: unexpected end of file in the chunk at byte {bin_chunk}, which \
             declares 2147483392 bytes",
            file.len()
        ),
    );
    let mut long_file = file.clone();
    long_file[8..12].copy_from_slice(&u32::MAX.to_le_bytes());
    assert_refused(
        "long_header.glb",
        &long_file,
        &format!(
            "byte {0}: unexpected end of file after {0} of the 4294967295 bytes the GLB \
             header declares",
            file.len()
        ),
    );
}

#[test]
fn gltf_non_finite_attributes_and_bad_indices_name_the_accessor_or_primitive() {
    let (doc, bin) = triangle_gltf();
    let with = |at: usize, value: f32| {
        let mut b = bin.clone();
        b[at..at + 4].copy_from_slice(&value.to_le_bytes());
        glb(&doc, &b)
    };
    // The second corner's v.
    assert_refused(
        "nan_uv.glb",
        &with(36 + 12, f32::NAN),
        "accessor 1 (TEXCOORD_0 of mesh 0 primitive 0): element 1 holds NaN, not a finite \
         number",
    );
    assert_refused(
        "inf_normal.glb",
        &with(60 + 24 + 4, f32::INFINITY),
        "accessor 2 (NORMAL of mesh 0 primitive 0): element 2 holds inf, not a finite number",
    );
    assert_refused(
        "nan_position.glb",
        &with(12, f32::NAN),
        "accessor 0 (POSITION of mesh 0 primitive 0): element 1 holds NaN, not a finite \
         number",
    );
    let mut b = bin.clone();
    b[104..108].copy_from_slice(&9u32.to_le_bytes());
    assert_refused(
        "index_out_of_range.glb",
        &glb(&doc, &b),
        "mesh 0 primitive 0: index 9, but POSITION has 3 elements",
    );
}

/// The texture coordinates of a `.gltf` read from disk come from the buffer file beside
/// it: the hostile cases above differ from this one only where they say.
#[test]
fn the_unaltered_triangle_reads() {
    let (mut doc, bin) = triangle_gltf();
    doc["buffers"][0]["uri"] = json!("tri.bin");
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("a temporary directory: {e}"));
    let path = dir.path().join("tri.gltf");
    std::fs::write(&path, text(&doc)).unwrap_or_else(|e| panic!("written: {e}"));
    std::fs::write(dir.path().join("tri.bin"), &bin).unwrap_or_else(|e| panic!("written: {e}"));
    let mesh = read_path(Path::new(&path))
        .unwrap_or_else(|e| panic!("the triangle reads: {e}"))
        .mesh;
    let uv = mesh.attributes.channel(ChannelKind::TexCoord);
    assert_eq!(uv.and_then(|c| c.at_corner(0, 1)), Some(&[1.0, 0.0][..]));
}
