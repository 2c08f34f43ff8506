//! Hostile attribute files (issue 29), read from disk through `read_path`: each is
//! refused with one line that starts with the file's path and names the place (the
//! line for OBJ and ASCII PLY, the byte for binary PLY and GLB containers, the
//! vertex or face, the glTF buffer, accessor or primitive). Never a panic, and never
//! an allocation in proportion to a size the file only claims.
//!
//! The expected messages are exact, so a change of wording is a deliberate change of
//! this test.

use qem_mesh::io::read_path;

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
