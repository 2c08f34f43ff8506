//! Hostile input through the `qem` binary: every file is either refused with exit code
//! 1 and one line on stderr that names the file and the problem (and no output file,
//! not even a temporary one), or simplified into a valid output. Never a panic.
//!
//! Each case builds its file in a fresh temporary directory. The expected messages are
//! exact, so a change in wording is a deliberate change of this test.

use std::path::PathBuf;
use std::process::{Command, Output};

use qem_mesh::io::read_path;

/// Three vertices of a unit right triangle, as OBJ lines.
const TRIANGLE_VERTICES: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";

/// Runs `qem simplify INPUT -o OUTPUT` on `bytes` written as `name` in a fresh directory.
struct Run {
    dir: tempfile::TempDir,
    input: PathBuf,
    output: PathBuf,
    result: Output,
}

fn simplify(name: &str, bytes: &[u8]) -> Run {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let input = dir.path().join(name);
    std::fs::write(&input, bytes).expect("the input is written");
    let output = dir.path().join("out.ply");
    let result = Command::new(env!("CARGO_BIN_EXE_qem"))
        .arg("simplify")
        .arg(&input)
        .arg("-o")
        .arg(&output)
        // No summary line: a success must then leave stderr empty.
        .arg("--quiet")
        .output()
        .expect("qem runs");
    Run {
        dir,
        input,
        output,
        result,
    }
}

impl Run {
    fn stderr(&self) -> String {
        String::from_utf8_lossy(&self.result.stderr).into_owned()
    }

    /// The names in the directory besides the input: the output and any temporary file.
    fn leftovers(&self) -> Vec<String> {
        let input = self.input.file_name().expect("the input has a name");
        let mut names: Vec<String> = std::fs::read_dir(self.dir.path())
            .expect("the directory is readable")
            .filter_map(|e| e.ok().map(|e| e.file_name()))
            .filter(|n| n != input)
            .map(|n| n.to_string_lossy().into_owned())
            .collect();
        names.sort();
        names
    }
}

/// `name` with content `bytes` is refused with exactly
/// `qem: error: PATH: CAUSE` on one line, exit code 1, and nothing written.
fn assert_refused(name: &str, bytes: &[u8], cause: &str) {
    let run = simplify(name, bytes);
    let stderr = run.stderr();
    assert!(!stderr.contains("panicked"), "{name}: panic: {stderr}");
    assert_eq!(
        run.result.status.code(),
        Some(1),
        "{name}: exit status, stderr {stderr}"
    );
    assert_eq!(
        stderr,
        format!("qem: error: {}: {cause}\n", run.input.display()),
        "{name}: message"
    );
    assert!(run.result.stdout.is_empty(), "{name}: stdout");
    assert!(!run.output.exists(), "{name}: an output file was written");
    assert_eq!(
        run.leftovers(),
        Vec::<String>::new(),
        "{name}: files left behind"
    );
}

/// `name` with content `bytes` is simplified (exit code 0, nothing on stderr) into a
/// valid mesh; returns it.
fn assert_simplified(name: &str, bytes: &[u8]) -> qem_mesh::IndexedMesh {
    let run = simplify(name, bytes);
    let stderr = run.stderr();
    assert!(
        run.result.status.success(),
        "{name}: exit {:?}, stderr {stderr}",
        run.result.status
    );
    assert_eq!(stderr, "", "{name}: stderr");
    assert_eq!(
        run.leftovers(),
        vec!["out.ply".to_string()],
        "{name}: files"
    );
    let mesh = read_path(&run.output)
        .unwrap_or_else(|e| panic!("{name}: the output cannot be read back: {e}"))
        .mesh;
    for (f, t) in mesh.triangles.iter().enumerate() {
        assert!(
            t[0] != t[1] && t[1] != t[2] && t[0] != t[2],
            "{name}: face {f} {t:?} repeats a vertex"
        );
        let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
        let (u, v) = (sub(b, a), sub(c, a));
        let cross = [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ];
        assert!(cross != [0.0; 3], "{name}: face {f} {t:?} has zero area");
    }
    mesh
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// A binary STL facet record (normal, three corners, attribute bytes).
fn stl_facet(corners: [[f32; 3]; 3]) -> Vec<u8> {
    let mut rec: Vec<u8> = [0.0f32, 0.0, 1.0]
        .iter()
        .chain(corners.iter().flatten())
        .flat_map(|c| c.to_le_bytes())
        .collect();
    rec.extend_from_slice(&[0, 0]);
    rec
}

/// A binary STL whose header claims `claimed` triangles, followed by `facets` copies of
/// one facet.
fn binary_stl(claimed: u32, facets: usize) -> Vec<u8> {
    let mut bytes = vec![b' '; 80];
    bytes.extend_from_slice(&claimed.to_le_bytes());
    let facet = stl_facet([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
    for _ in 0..facets {
        bytes.extend_from_slice(&facet);
    }
    bytes
}

/// A binary little-endian PLY header with three float coordinates per vertex and a face
/// list of the given count type.
fn ply_header(vertices: u64, faces: u64, count_type: &str) -> Vec<u8> {
    format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex {vertices}\n\
         property float x\nproperty float y\nproperty float z\nelement face {faces}\n\
         property list {count_type} int vertex_indices\nend_header\n"
    )
    .into_bytes()
}

/// The three vertices of a unit triangle as binary PLY float records.
fn ply_triangle_vertices() -> Vec<u8> {
    [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0]
        .iter()
        .flat_map(|c| c.to_le_bytes())
        .collect()
}

/// Deterministic pseudo-random bytes (xorshift), so "binary garbage" is reproducible.
fn garbage(len: usize) -> Vec<u8> {
    let mut x: u64 = 0x9e37_79b9_7f4a_7c15;
    (0..len)
        .map(|_| {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x >> 24) as u8
        })
        .collect()
}

#[test]
fn empty_files_are_refused() {
    for ext in ["obj", "ply", "stl", "off"] {
        assert_refused(&format!("empty.{ext}"), b"", "the file is empty");
    }
}

#[test]
fn non_finite_coordinates_are_refused_with_their_line() {
    assert_refused(
        "nan.obj",
        b"v 0 nan 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
        "line 1: vertex 0 has a non-finite coordinate",
    );
    assert_refused(
        "inf.off",
        b"OFF\n3 1 0\n0 0 0\ninf 0 0\n0 1 0\n3 0 1 2\n",
        "line 4: vertex 1 has a non-finite coordinate",
    );
    // 1e400 is beyond f64: it parses to infinity.
    assert_refused(
        "overflow.obj",
        b"v 0 0 0\nv 1e400 0 0\nv 0 1 0\nf 1 2 3\n",
        "line 2: vertex 1 has a non-finite coordinate",
    );
    let mut ply = ply_header(3, 1, "uchar");
    ply.extend(
        [0.0f32, 0.0, 0.0, f32::NAN, 0.0, 0.0, 0.0, 1.0, 0.0]
            .iter()
            .flat_map(|c| c.to_le_bytes()),
    );
    ply.push(3);
    ply.extend([0i32, 1, 2].iter().flat_map(|i| i.to_le_bytes()));
    // The place is the start of the vertex's record.
    let at = ply_header(3, 1, "uchar").len() + 12;
    assert_refused(
        "nan.ply",
        &ply,
        &format!("byte {at}: vertex 1 has a non-finite coordinate"),
    );
}

#[test]
fn bad_indices_are_refused_with_their_line() {
    let obj = |face: &str| format!("{TRIANGLE_VERTICES}{face}\n").into_bytes();
    assert_refused(
        "out_of_range.obj",
        &obj("f 1 2 9"),
        "line 4: face 0 refers to vertex 9, but there are only 3 vertices",
    );
    assert_refused(
        "zero.obj",
        &obj("f 0 1 2"),
        "line 4: face 0: vertex index 0 is invalid (OBJ indices start at 1)",
    );
    assert_refused(
        "negative_past_start.obj",
        &obj("f -5 1 2"),
        "line 4: face 0: relative vertex index -5 points before the first one (3 vertices so far)",
    );
    assert_refused(
        "out_of_range.off",
        b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n",
        "line 6: face 0 refers to vertex 7, but there are only 3 vertices",
    );
    assert_refused(
        "negative.off",
        b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n",
        "line 6: face 0 refers to vertex -1, but there are only 3 vertices",
    );
}

#[test]
fn bad_indices_in_ply_and_stl_nan_are_refused_with_their_place() {
    let mut ply = ply_header(3, 1, "uchar");
    let face = ply.len() + 36;
    ply.extend(ply_triangle_vertices());
    let mut negative = ply.clone();
    negative.push(3);
    negative.extend([0i32, -1, 2].iter().flat_map(|i| i.to_le_bytes()));
    assert_refused(
        "negative.ply",
        &negative,
        &format!(
            "byte {}: face 0 refers to vertex -1, but there are only 3 vertices",
            face + 5
        ),
    );
    ply.push(3);
    ply.extend([0i32, 1, 3].iter().flat_map(|i| i.to_le_bytes()));
    assert_refused(
        "out_of_range.ply",
        &ply,
        &format!(
            "byte {}: face 0 refers to vertex 3, but there are only 3 vertices",
            face + 9
        ),
    );
    assert_refused(
        "nan.stl",
        b"solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex nan 0 0\n\
          vertex 0 1 0\nendloop\nendfacet\nendsolid x\n",
        "line 5: vertex 1 has a non-finite coordinate",
    );
}

#[test]
fn vertices_without_faces_are_refused() {
    assert_refused(
        "no_faces.obj",
        TRIANGLE_VERTICES.as_bytes(),
        "the mesh has no triangles",
    );
    assert_refused(
        "no_faces.off",
        b"OFF\n3 0 0\n0 0 0\n1 0 0\n0 1 0\n",
        "the mesh has no triangles",
    );
    let mut ply = ply_header(3, 0, "uchar");
    ply.extend(ply_triangle_vertices());
    assert_refused("no_faces.ply", &ply, "the mesh has no triangles");
}

#[test]
fn truncated_binary_files_are_refused() {
    let stl = binary_stl(2, 2);
    assert_refused(
        "truncated.stl",
        &stl[..stl.len() - 30],
        "byte 154: unexpected end of file after 1 of 2 triangles (binary STL of 184 bytes)",
    );
    let mut ply = ply_header(3, 1, "uchar");
    let header = ply.len();
    ply.extend(ply_triangle_vertices());
    ply.push(3);
    ply.extend([0i32, 1, 2].iter().flat_map(|i| i.to_le_bytes()));
    ply.truncate(ply.len() - 7);
    assert_refused(
        "truncated.ply",
        &ply,
        &format!(
            "byte {}: unexpected end of file in face 0: its list claims 3 items (12 bytes) \
             but only 5 bytes are left",
            header + 36
        ),
    );
    let mut vertices_cut = ply_header(3, 1, "uchar");
    vertices_cut.extend(&ply_triangle_vertices()[..20]);
    assert_refused(
        "vertices_cut.ply",
        &vertices_cut,
        &format!(
            "byte {}: unexpected end of file after 1 of 3 vertices (binary PLY)",
            header + 12
        ),
    );
}

#[test]
fn absurd_header_counts_are_refused_before_allocating() {
    let limit = qem_mesh::MAX_ELEMENTS;
    assert_refused(
        "absurd.stl",
        &binary_stl(4_000_000_000, 1),
        &format!(
            "byte 80: binary STL header claims triangles: 4000000000, more than the limit of {limit}"
        ),
    );
    let mut ply = ply_header(4_000_000_000, 1, "uchar");
    ply.extend(ply_triangle_vertices());
    assert_refused(
        "absurd.ply",
        &ply,
        &format!("line 3: PLY header claims vertices: 4000000000, more than the limit of {limit}"),
    );
    assert_refused(
        "absurd.off",
        b"OFF\n4000000000 4000000000 0\n0 0 0\n",
        &format!("line 2: OFF header claims vertices: 4000000000, more than the limit of {limit}"),
    );
    assert_refused(
        "absurd_faces.off",
        b"OFF\n3 4000000000 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
        &format!("line 2: OFF header claims faces: 4000000000, more than the limit of {limit}"),
    );
}

#[test]
fn list_lengths_of_four_billion_are_refused() {
    let mut ply = ply_header(3, 1, "uint");
    let header = ply.len();
    ply.extend(ply_triangle_vertices());
    ply.extend(4_000_000_000u32.to_le_bytes());
    ply.extend([0u8; 12]);
    assert_refused(
        "list_length.ply",
        &ply,
        &format!(
            "byte {}: unexpected end of file in face 0: its list claims 4000000000 items \
             (16000000000 bytes) but only 12 bytes are left",
            header + 36
        ),
    );
    let ascii = b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                  property float z\nelement face 1\nproperty list uint int vertex_indices\n\
                  end_header\n0 0 0\n1 0 0\n0 1 0\n4000000000 0 1 2\n";
    assert_refused(
        "list_length_ascii.ply",
        ascii,
        "line 13: unexpected end of file in face 0: its list claims 4000000000 items, \
         more than the rest of the file can hold",
    );
}

#[test]
fn binary_garbage_with_a_mesh_extension_is_refused() {
    let bytes = garbage(3000);
    assert_refused(
        "garbage.obj",
        &bytes,
        "not an OBJ file: the content is not OBJ text (it looks like binary data)",
    );
    assert_refused(
        "garbage.ply",
        &bytes,
        "not a PLY file: does not start with \"ply\" (it looks like binary data)",
    );
    let count = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]);
    assert_refused(
        "garbage.stl",
        &bytes,
        &format!(
            "byte 80: binary STL header claims triangles: {count}, more than the limit of {}",
            qem_mesh::MAX_ELEMENTS
        ),
    );
    let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
    png.extend(&bytes[..200]);
    assert_refused(
        "image.obj",
        &png,
        "not an OBJ file: the content is not OBJ text (it looks like a PNG image)",
    );
    let mut gz = vec![0x1f, 0x8b, 8, 0, 0, 0, 0, 0, 0, 3];
    gz.extend(&bytes[..100]);
    let run = simplify("corrupt.obj.gz", &gz);
    let stderr = run.stderr();
    assert_eq!(run.result.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.starts_with(&format!(
            "qem: error: {}: gzip: corrupt data after ",
            run.input.display()
        )) && stderr.lines().count() == 1,
        "{stderr}"
    );
    assert_eq!(run.leftovers(), Vec::<String>::new());
}

#[test]
fn one_format_under_another_extension_is_refused() {
    let obj = format!("{TRIANGLE_VERTICES}f 1 2 3\n").into_bytes();
    let mut ply = ply_header(3, 1, "uchar");
    ply.extend(ply_triangle_vertices());
    ply.push(3);
    ply.extend([0i32, 1, 2].iter().flat_map(|i| i.to_le_bytes()));
    assert_refused(
        "a_ply.obj",
        &ply,
        "not an OBJ file: the content is not OBJ text (it looks like a PLY file)",
    );
    assert_refused(
        "an_obj.stl",
        &obj,
        "not an STL file: neither ASCII (\"solid ...\") nor binary (84 + 50 bytes per \
         triangle) (it looks like an OBJ file)",
    );
    assert_refused(
        "an_obj.off",
        &obj,
        "not an OFF file: the first word is \"v\", not OFF (it looks like an OBJ file)",
    );
    assert_refused(
        "an_stl.ply",
        &binary_stl(1, 1),
        "not a PLY file: does not start with \"ply\" (it looks like binary data)",
    );
}

#[test]
fn non_utf8_bytes_are_refused_with_their_line() {
    assert_refused(
        "latin1.obj",
        b"v 0 0 0\nv 1 \xff\xfe 0\nv 0 1 0\nf 1 2 3\n",
        "line 2: not valid UTF-8 text (byte 5 of the line)",
    );
    assert_refused(
        "latin1.off",
        b"OFF\n3 1 0\n0 0 0\n1 \xff 0\n0 1 0\n3 0 1 2\n",
        "line 4: vertex 1: bad coordinate \"\u{fffd}\"",
    );
}

#[test]
fn lines_of_megabytes_are_handled() {
    // An 8 MB comment line is skipped; an 8 MB number overflows to infinity.
    let mut long_comment = b"# ".to_vec();
    long_comment.resize(8 << 20, b'x');
    long_comment.extend(format!("\n{TRIANGLE_VERTICES}f 1 2 3\n").as_bytes());
    let mesh = assert_simplified("long_comment.obj", &long_comment);
    assert_eq!(mesh.triangle_count(), 1);

    let mut long_number = b"v 0 0 ".to_vec();
    long_number.resize(8 << 20, b'1');
    long_number.extend(format!("\n{TRIANGLE_VERTICES}f 1 2 3\n").as_bytes());
    assert_refused(
        "long_number.obj",
        &long_number,
        "line 1: vertex 0 has a non-finite coordinate",
    );
}

#[test]
fn all_coincident_vertices_are_refused_as_degenerate() {
    assert_refused(
        "coincident.obj",
        b"v 1 1 1\nv 1 1 1\nv 1 1 1\nf 1 2 3\nf 1 2 3\n",
        "all 2 triangles are degenerate (repeated vertex or zero area): nothing is left to simplify",
    );
}

#[test]
fn extreme_but_finite_coordinates_give_valid_output() {
    for (name, scale) in [
        ("huge.obj", "1e300"),
        ("big.obj", "1e30"),
        ("small.obj", "1e-30"),
    ] {
        let obj = format!(
            "v 0 0 0\nv {scale} 0 0\nv 0 {scale} 0\nv {scale} {scale} {scale}\nf 1 2 3\nf 2 4 3\n"
        );
        let mesh = assert_simplified(name, obj.as_bytes());
        assert_eq!(mesh.triangle_count(), 1, "{name}");
    }
    // The bounding-box diagonal overflows f64 here.
    let mesh = assert_simplified(
        "near_max.obj",
        b"v -1.7e308 0 0\nv 1.7e308 0 0\nv 0 1.7e308 0\nv 0 0 1.7e308\nf 1 2 3\nf 1 2 4\n",
    );
    assert_eq!(mesh.triangle_count(), 1);
}

#[test]
fn faces_whose_area_underflows_are_refused_as_degenerate() {
    // Edges of 1e-300: every cross product underflows to zero in f64.
    assert_refused(
        "tiny.obj",
        b"v 0 0 0\nv 1e-300 0 0\nv 0 1e-300 0\nv 1e-300 1e-300 1e-300\nf 1 2 3\nf 2 4 3\n",
        "all 2 triangles are degenerate (repeated vertex or zero area): nothing is left to simplify",
    );
}

#[test]
fn many_coincident_faces_clean_to_one() {
    // 200 000 copies of one triangle, half of them reversed: cleaning keeps one.
    let mut obj = TRIANGLE_VERTICES.to_string();
    for i in 0..200_000 {
        obj.push_str(if i % 2 == 0 { "f 1 2 3\n" } else { "f 3 2 1\n" });
    }
    let mesh = assert_simplified("coincident_faces.obj", obj.as_bytes());
    assert_eq!(mesh.triangles, vec![[0, 1, 2]]);
    let mesh = assert_simplified("coincident_faces.stl", &binary_stl(100_000, 100_000));
    assert_eq!(mesh.triangle_count(), 1);
}

#[test]
fn gzip_that_expands_too_much_is_refused() {
    // A million copies of one face compress about 680:1 as OBJ text; the reader refuses
    // more than 64:1 rather than hold the whole expansion in memory.
    let dir = tempfile::tempdir().expect("a temporary directory");
    let source = dir.path().join("coincident.obj.gz");
    let mesh = qem_mesh::IndexedMesh::new(
        vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        vec![[0, 1, 2]; 1_000_000],
    );
    qem_mesh::io::write_path(&source, &mesh).expect("the gzip file is written");
    let bytes = std::fs::read(&source).expect("readable");
    let limit = bytes.len() as u64 * qem_mesh::io::GZIP_MAX_RATIO + (1 << 16);
    assert_refused(
        "coincident.obj.gz",
        &bytes,
        &format!(
            "gzip: decompresses to more than {limit} bytes ({}x the compressed size, at most {})",
            qem_mesh::io::GZIP_MAX_RATIO,
            qem_mesh::io::GZIP_MAX_BYTES
        ),
    );
}

#[test]
fn missing_files_and_directories_are_refused() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let folder = dir.path().join("folder.obj");
    std::fs::create_dir(&folder).expect("a directory");
    let output = dir.path().join("out.ply");
    for input in [dir.path().join("missing.obj"), folder] {
        let o = Command::new(env!("CARGO_BIN_EXE_qem"))
            .arg("simplify")
            .arg(&input)
            .arg("-o")
            .arg(&output)
            .output()
            .expect("qem runs");
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{stderr}");
        // The rest is the operating system's wording (e.g. "Is a directory (os error 21)").
        let prefix = format!("qem: error: {}: cannot read: ", input.display());
        assert!(stderr.starts_with(&prefix), "{stderr}");
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
        assert!(!output.exists());
    }
}

#[test]
fn stl_output_beyond_float32_is_refused_without_a_file() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let input = dir.path().join("huge.obj");
    std::fs::write(&input, "v 0 0 0\nv 1e39 0 0\nv 0 1e39 0\nf 1 2 3\n").expect("written");
    let output = dir.path().join("out.stl");
    let o = Command::new(env!("CARGO_BIN_EXE_qem"))
        .arg("simplify")
        .arg(&input)
        .arg("-o")
        .arg(&output)
        .output()
        .expect("qem runs");
    assert_eq!(o.status.code(), Some(1));
    assert_eq!(
        String::from_utf8_lossy(&o.stderr),
        format!(
            "qem: error: {}: cannot write: vertex 1 has coordinate 1e39, beyond the range of \
             STL's float32 (about ±3.4e38); write PLY, OBJ or OFF instead\n",
            output.display()
        )
    );
    let names: Vec<_> = std::fs::read_dir(dir.path())
        .expect("readable")
        .filter_map(|e| e.ok().map(|e| e.file_name()))
        .collect();
    assert_eq!(names, vec![std::ffi::OsString::from("huge.obj")]);
}

/// A `.gltf` triangle whose one buffer is `buffer` (its `uri` and `byteLength`).
fn gltf_triangle(buffer: &str) -> Vec<u8> {
    format!(
        "{{\"asset\":{{\"version\":\"2.0\"}},\
         \"meshes\":[{{\"primitives\":[{{\"attributes\":{{\"POSITION\":0}}}}]}}],\
         \"accessors\":[{{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}}],\
         \"bufferViews\":[{{\"buffer\":0,\"byteLength\":36}}],\
         \"buffers\":[{buffer}]}}"
    )
    .into_bytes()
}

/// Issue 29: hostile attribute files are refused like hostile geometry, with the place.
#[test]
fn hostile_attribute_files_are_refused_with_their_place() {
    assert_refused(
        "nan_vt.obj",
        format!("{TRIANGLE_VERTICES}vt 0 0\nvt nan 0\nf 1/1 2/2 3/1\n").as_bytes(),
        "line 5: texture coordinate 1: \"nan\" is not a finite 32-bit float",
    );
    assert_refused(
        "vt_out_of_range.obj",
        format!("{TRIANGLE_VERTICES}vt 0 0\nf 1/1 2/2 3/1\n").as_bytes(),
        "line 5: face 0 refers to texture coordinate 2, but there are only 1 texture \
         coordinates",
    );
    // The buffer file is not in the directory: nothing but the input is.
    assert_refused(
        "missing_buffer.gltf",
        &gltf_triangle("{\"uri\":\"tri.bin\",\"byteLength\":36}"),
        "buffer 0: cannot read its file \"tri.bin\": No such file or directory (os error 2)",
    );
    assert_refused(
        "billion.gltf",
        &gltf_triangle(
            "{\"uri\":\"data:application/octet-stream;base64,AAAA\",\"byteLength\":1000000000}",
        ),
        "unexpected end of file in buffer 0: it holds 3 bytes, its byteLength says 1000000000",
    );
}
