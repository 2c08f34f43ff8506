//! glTF 2.0 (`.gltf`, `.glb`): primitives of several materials under node transforms
//! become one mesh with transformed positions and normals, per-primitive material
//! labels and channels; read → write → read keeps every corner's values and every
//! face's material; spot.obj goes through GLB with its UVs; external buffers resolve
//! beside the file; hostile files (truncated GLB, bogus counts, compression
//! extensions, sparse accessors, node cycles) are clear errors, never panics.

#![allow(clippy::unwrap_used)]

use std::path::Path;

use qem_mesh::attributes::{Channel, ChannelKind, FaceLabels};
use qem_mesh::io::{read_bytes, read_path, unwritable, write_path, Format};
use qem_mesh::IndexedMesh;
use serde_json::{json, Value};

use crate::attributes_common::{encode, err, glb, load};

fn floats(values: &[f32]) -> Vec<u8> {
    values.iter().flat_map(|v| v.to_le_bytes()).collect()
}

/// Two triangles' worth of data in one buffer: positions of a unit right triangle
/// (bytes 0..36), normals +z (36..72), UVs (72..96), u16 indices 0 1 2 (96..102).
fn bin() -> Vec<u8> {
    let mut b = floats(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0]);
    b.extend(floats(&[0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0]));
    b.extend(floats(&[0.0, 1.0, 1.0, 1.0, 0.0, 0.0]));
    b.extend([0u16, 1, 2].iter().flat_map(|i| i.to_le_bytes()));
    b
}

/// A document over [`bin`]: mesh 0 has primitive 0 (material "red", with normals and
/// UVs, indexed), primitive 1 (material "blue", positions only, not indexed) and a
/// LINES primitive; node 0 places it translated by (10, 0, 0) and scaled by (2, 1, 1);
/// node 1, its child, places it again rotated a quarter turn about z.
fn document() -> Value {
    let view = |offset: usize, length: usize| json!({"buffer": 0, "byteOffset": offset, "byteLength": length});
    json!({
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [
            {"mesh": 0, "translation": [10.0, 0.0, 0.0], "scale": [2.0, 1.0, 1.0], "children": [1]},
            {"mesh": 0, "rotation": [0.0, 0.0, std::f32::consts::FRAC_1_SQRT_2, std::f32::consts::FRAC_1_SQRT_2]}
        ],
        "meshes": [{"name": "tri", "primitives": [
            {"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2}, "indices": 3, "material": 0},
            {"attributes": {"POSITION": 0}, "material": 1},
            {"attributes": {"POSITION": 0}, "mode": 1}
        ]}],
        "materials": [{"name": "red"}, {"name": "blue"}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
             "min": [0.0, 0.0, 0.0], "max": [1.0, 1.0, 0.0]},
            {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC3"},
            {"bufferView": 2, "componentType": 5126, "count": 3, "type": "VEC2"},
            {"bufferView": 3, "componentType": 5123, "count": 3, "type": "SCALAR"}
        ],
        "bufferViews": [view(0, 36), view(36, 36), view(72, 24), view(96, 6)],
        "buffers": [{"byteLength": 102}]
    })
}

/// Each face as what must survive a round trip whatever the numbering: its
/// material and group names, its corners' positions and each channel's value at
/// each corner, as bits; sorted.
type Face = (
    Option<Vec<u8>>,
    Option<Vec<u8>>,
    Vec<[u64; 3]>,
    Vec<(String, Vec<Option<Vec<u32>>>)>,
);

fn faces(mesh: &IndexedMesh) -> Vec<Face> {
    let a = &mesh.attributes;
    let mut out: Vec<Face> = (0..mesh.triangle_count())
        .map(|t| {
            let positions = mesh.triangles[t]
                .iter()
                .map(|&i| mesh.positions[i as usize].map(f64::to_bits))
                .collect();
            let channels = a
                .channels
                .iter()
                .map(|c| {
                    let corners = (0..3)
                        .map(|k| {
                            c.at_corner(t, k)
                                .map(|v| v.iter().map(|x| x.to_bits()).collect())
                        })
                        .collect();
                    (format!("{}:{}", c.kind, c.name), corners)
                })
                .collect();
            (
                a.materials.of_face(t).map(<[u8]>::to_vec),
                a.groups.of_face(t).map(<[u8]>::to_vec),
                positions,
                channels,
            )
        })
        .collect();
    out.sort();
    out
}

fn assert_close(a: [f64; 3], b: [f64; 3]) {
    let d = (0..3).map(|k| (a[k] - b[k]).abs()).fold(0.0, f64::max);
    assert!(d < 1e-6, "{a:?} against {b:?}");
}

#[test]
fn primitives_of_two_materials_under_node_transforms_become_one_mesh() {
    let loaded = load(&glb(&document(), &bin()), Format::Glb);
    let mesh = &loaded.mesh;
    // Two nodes place the mesh, each with its two triangle primitives; the LINES
    // primitive is skipped at each.
    assert_eq!(loaded.notes.skipped_primitives, 2);
    assert_eq!(mesh.triangle_count(), 4);
    // Primitives 0 and 1 share their POSITION accessor, so they share vertices (and
    // the blue one's corners have no UVs): three vertices per placement.
    assert_eq!(mesh.vertex_count(), 6);
    let corner = |t: usize, k: usize| mesh.positions[mesh.triangles[t][k] as usize];
    // Node 0: x scaled by 2, then moved by 10.
    assert_close(corner(0, 1), [12.0, 0.0, 0.0]);
    assert_close(corner(0, 2), [10.0, 1.0, 0.0]);
    // Node 1 (child of node 0): rotated a quarter turn first: (1,0,0) -> (0,1,0).
    assert_close(corner(2, 1), [10.0, 1.0, 0.0]);
    assert_close(corner(2, 2), [8.0, 0.0, 0.0]);
    let names: Vec<_> = (0..4)
        .map(|t| mesh.attributes.materials.of_face(t))
        .collect();
    assert_eq!(
        names,
        [
            Some(&b"red"[..]),
            Some(b"blue"),
            Some(b"red"),
            Some(b"blue")
        ]
    );
    assert_eq!(mesh.attributes.groups.names, vec![b"tri".to_vec()]);
    let uv = mesh.attributes.channel(ChannelKind::TexCoord).unwrap();
    assert_eq!(uv.name, "uv");
    // glTF's v points down the image; qem keeps OBJ's, which points up.
    assert_eq!(uv.at_corner(0, 0), Some(&[0.0, 0.0][..]));
    assert_eq!(uv.at_corner(0, 1), Some(&[1.0, 0.0][..]));
    assert_eq!(uv.at_corner(1, 0), None, "the blue primitive has no UVs");
    // A normal of +z stays +z under these transforms.
    let n = mesh.attributes.channel(ChannelKind::Normal).unwrap();
    for t in [0, 2] {
        let v = n.at_corner(t, 0).unwrap();
        assert!(v[0].abs() < 1e-6 && v[1].abs() < 1e-6 && (v[2] - 1.0).abs() < 1e-6);
    }
    assert_eq!(n.at_corner(3, 0), None);
}

#[test]
fn normals_use_the_inverse_transpose_and_mirrors_keep_orientation() {
    let mut doc = document();
    // A shear-free non-uniform scale on a slanted normal, and a mirror in x.
    doc["nodes"] = json!([{"mesh": 0, "scale": [-4.0, 1.0, 1.0]}]);
    let mut b = bin();
    b[36..72].copy_from_slice(&floats(&[0.6, 0.0, 0.8, 0.6, 0.0, 0.8, 0.6, 0.0, 0.8]));
    let mesh = load(&glb(&doc, &b), Format::Glb).mesh;
    let n = mesh.attributes.channel(ChannelKind::Normal).unwrap();
    // Inverse transpose of diag(-4, 1, 1) is diag(-1/4, 1, 1): (-0.15, 0, 0.8), unit.
    let v = n.at_corner(0, 0).unwrap();
    let len = (0.15f64 * 0.15 + 0.64).sqrt();
    assert!((f64::from(v[0]) + 0.15 / len).abs() < 1e-6, "{v:?}");
    assert!((f64::from(v[2]) - 0.8 / len).abs() < 1e-6, "{v:?}");
    // The mirrored triangle keeps an outward (+z) winding: corners 1 and 2 swapped.
    let p = |k: usize| mesh.positions[mesh.triangles[0][k] as usize];
    let (a, b, c) = (p(0), p(1), p(2));
    let cross_z = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
    assert!(cross_z > 0.0, "{a:?} {b:?} {c:?}");
}

#[test]
fn read_write_read_keeps_every_corner_and_material_in_glb_and_gltf() {
    let mut doc = document();
    // Identity placement, so positions are float32 values already and the first
    // read is the reference; a COLOR_0 (normalized u8) and a custom attribute too.
    doc["nodes"] = json!([{"mesh": 0}]);
    let mut b = bin();
    let colour_at = b.len();
    b.extend([255u8, 0, 0, 255, 0, 255, 0, 128, 0, 0, 255, 0]);
    let custom_at = b.len();
    b.extend(floats(&[0.5, 1.5, 2.5]));
    doc["bufferViews"]
        .as_array_mut()
        .unwrap()
        .push(json!({"buffer": 0, "byteOffset": colour_at, "byteLength": 12}));
    doc["bufferViews"]
        .as_array_mut()
        .unwrap()
        .push(json!({"buffer": 0, "byteOffset": custom_at, "byteLength": 12}));
    doc["accessors"].as_array_mut().unwrap().extend([
        json!({"bufferView": 4, "componentType": 5121, "normalized": true, "count": 3, "type": "VEC4"}),
        json!({"bufferView": 5, "componentType": 5126, "count": 3, "type": "SCALAR"}),
    ]);
    doc["meshes"][0]["primitives"][0]["attributes"]["COLOR_0"] = json!(4);
    doc["meshes"][0]["primitives"][1]["attributes"]["_TEMPERATURE"] = json!(5);
    doc["buffers"][0]["byteLength"] = json!(b.len());
    let source = load(&glb(&doc, &b), Format::Glb).mesh;
    let kinds: Vec<_> = source
        .attributes
        .channels
        .iter()
        .map(|c| (c.kind, c.name.as_str(), c.dimension))
        .collect();
    assert_eq!(
        kinds,
        [
            (ChannelKind::TexCoord, "uv", 2),
            (ChannelKind::Normal, "normal", 3),
            (ChannelKind::Color, "colour", 4),
            (ChannelKind::Generic, "TEMPERATURE", 1),
        ]
    );
    let colour = source.attributes.channel(ChannelKind::Color).unwrap();
    assert_eq!(
        colour.at_corner(0, 1),
        Some(&[0.0, 1.0, 0.0, (128.0f64 / 255.0) as f32][..])
    );
    assert!(unwritable(&source.attributes, Format::Glb).is_empty());
    for format in [Format::Glb, Format::Gltf] {
        let once = load(&encode(&source, format), format).mesh;
        assert_eq!(faces(&once), faces(&source), "{format:?}");
        let twice = load(&encode(&once, format), format).mesh;
        assert_eq!(twice, once, "{format:?}: a second trip changes nothing");
    }
    // The .gltf is one self-contained JSON file.
    let text = encode(&source, Format::Gltf);
    assert!(text.starts_with(b"{"));
    assert!(std::str::from_utf8(&text)
        .unwrap()
        .contains("data:application/octet-stream;base64,"));
}

#[test]
fn groups_become_meshes_and_materials_primitives() {
    let mut mesh = IndexedMesh::new(
        vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [1.0, 1.0, 0.0],
        ],
        vec![[0, 1, 2], [1, 3, 2], [0, 2, 1], [2, 3, 1]],
    );
    mesh.attributes.materials = FaceLabels {
        names: vec![b"a".to_vec(), b"b".to_vec(), b"unused".to_vec()],
        faces: vec![0, 1, 1, FaceLabels::NONE],
    };
    mesh.attributes.groups = FaceLabels {
        names: vec![b"left".to_vec(), b"right".to_vec()],
        faces: vec![0, 1, 0, 1],
    };
    mesh.attributes.channels.push(
        Channel::new(ChannelKind::Generic, vec![1.0, 2.0], vec![[0, 0, 1]; 4]).with_name("weight"),
    );
    mesh.attributes.material_libraries.push(b"x.mtl".to_vec());
    let left = unwritable(&mesh.attributes, Format::Gltf);
    assert_eq!(left.len(), 1);
    assert_eq!(left[0].what, "material libraries");
    let back = load(&encode(&mesh, Format::Glb), Format::Glb).mesh;
    let mut without_libraries = mesh.clone();
    without_libraries.attributes.material_libraries.clear();
    assert_eq!(faces(&back), faces(&without_libraries));
    assert_eq!(back.attributes.channels[0].kind, ChannelKind::Generic);
}

#[test]
fn a_second_normal_channel_is_reported_as_left_out() {
    let mut mesh = IndexedMesh::new(
        vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        vec![[0, 1, 2]],
    );
    for name in ["normal", "smooth"] {
        mesh.attributes.channels.push(
            Channel::new(ChannelKind::Normal, vec![0.0, 0.0, 1.0], vec![[0, 0, 0]]).with_name(name),
        );
    }
    let left = unwritable(&mesh.attributes, Format::Glb);
    assert_eq!(left.len(), 1);
    assert_eq!(left[0].what, "smooth");
    let back = load(&encode(&mesh, Format::Glb), Format::Glb).mesh;
    assert_eq!(back.attributes.channels.len(), 1);
}

#[test]
fn spot_goes_obj_to_glb_and_back_with_its_uvs() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/spot.obj");
    let spot = read_path(&path).unwrap().mesh;
    let uv = spot.attributes.channel(ChannelKind::TexCoord).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("spot.glb");
    write_path(&out, &spot).unwrap();
    let back = read_path(&out).unwrap().mesh;
    assert_eq!(back.triangle_count(), spot.triangle_count());
    let back_uv = back.attributes.channel(ChannelKind::TexCoord).unwrap();
    // No materials or groups: the faces keep their order.
    for t in 0..spot.triangle_count() {
        for k in 0..3 {
            let (a, b) = (
                spot.positions[spot.triangles[t][k] as usize],
                back.positions[back.triangles[t][k] as usize],
            );
            for c in 0..3 {
                assert!((a[c] - b[c]).abs() <= a[c].abs() * 1e-7, "{a:?} {b:?}");
            }
            let (a, b) = (
                uv.at_corner(t, k).unwrap(),
                back_uv.at_corner(t, k).unwrap(),
            );
            // The v flip may round a value below 0.5 by half an ulp of 1.0.
            assert!((a[0] - b[0]).abs() <= 6e-8 && (a[1] - b[1]).abs() <= 6e-8);
        }
    }
    // What GLB wrote, a .gltf writes too, in one file.
    let gltf = dir.path().join("spot.gltf");
    write_path(&gltf, &back).unwrap();
    assert_eq!(faces(&read_path(&gltf).unwrap().mesh), faces(&back));
}

#[test]
fn external_buffers_resolve_beside_the_file_but_not_from_memory() {
    let dir = tempfile::tempdir().unwrap();
    let mut doc = document();
    doc["buffers"][0]["uri"] = json!("data%20file.bin");
    std::fs::write(dir.path().join("data file.bin"), bin()).unwrap();
    let text = serde_json::to_vec(&doc).unwrap();
    let path = dir.path().join("scene.gltf");
    std::fs::write(&path, &text).unwrap();
    assert_eq!(read_path(&path).unwrap().mesh.triangle_count(), 4);
    let e = err(&text, Format::Gltf);
    assert!(e.contains("external file \"data%20file.bin\""), "{e}");
    assert!(e.contains("read the .gltf file by its path"), "{e}");
    // A missing file and a short one are errors naming the file.
    std::fs::write(dir.path().join("data file.bin"), &bin()[..50]).unwrap();
    let e = read_path(&path).unwrap_err().to_string();
    assert!(
        e.contains("in buffer 0: it holds 50 bytes, its byteLength says 102"),
        "{e}"
    );
    std::fs::remove_file(dir.path().join("data file.bin")).unwrap();
    let e = read_path(&path).unwrap_err().to_string();
    assert!(
        e.contains("buffer 0: cannot read its file \"data file.bin\""),
        "{e}"
    );
    // Absolute paths and URLs are refused.
    for uri in [
        "/etc/passwd",
        "https://example.invalid/a.bin",
        "file:///a.bin",
    ] {
        doc["buffers"][0]["uri"] = json!(uri);
        std::fs::write(&path, serde_json::to_vec(&doc).unwrap()).unwrap();
        let e = read_path(&path).unwrap_err().to_string();
        assert!(e.contains("is not a relative file path"), "{e}");
    }
}

#[test]
fn strips_and_fans_are_converted() {
    let mut doc = document();
    doc["nodes"] = json!([{"mesh": 0}]);
    doc["meshes"][0]["primitives"] = json!([
        {"attributes": {"POSITION": 0}, "mode": 5},
        {"attributes": {"POSITION": 0}, "mode": 6, "indices": 3}
    ]);
    let mesh = load(&glb(&doc, &bin()), Format::Glb).mesh;
    assert_eq!(mesh.triangles, vec![[0, 1, 2], [1, 2, 0]]);
}

#[test]
fn every_truncation_of_a_glb_is_an_error() {
    let data = glb(&document(), &bin());
    for n in 0..data.len() {
        assert!(read_bytes(&data[..n], Format::Glb).is_err(), "{n} bytes");
    }
    assert!(err(&data[..30], Format::Glb).contains("unexpected end of file"));
    assert!(err(&data[..8], Format::Glb).contains("12-byte GLB header"));
    // A header claiming fewer bytes than its own header.
    let mut small = data.clone();
    small[8..12].copy_from_slice(&4u32.to_le_bytes());
    assert!(err(&small, Format::Glb).contains("too small"));
    let mut v1 = data.clone();
    v1[4] = 1;
    assert!(err(&v1, Format::Glb).contains("GLB version 1"));
}

#[test]
fn hostile_documents_are_clear_errors() {
    let read = |doc: &Value| err(&glb(doc, &bin()), Format::Glb);
    // Bogus counts: nothing is allocated for them.
    for count in [4u64, 1 << 27, 1 << 40, u64::MAX / 2] {
        let mut doc = document();
        doc["accessors"][0]["count"] = json!(count);
        let e = read(&doc);
        assert!(
            e.contains("do not fit in its buffer view") || e.contains("more than the limit"),
            "{count}: {e}"
        );
    }
    let mut doc = document();
    doc["bufferViews"][0]["byteLength"] = json!(1u64 << 50);
    assert!(read(&doc).contains("ends past the"));
    let mut doc = document();
    doc["bufferViews"][0]["byteOffset"] = json!(u64::MAX - 3);
    assert!(read(&doc).contains("ends past the"));
    let mut doc = document();
    doc["buffers"][0]["byteLength"] = json!(1000);
    assert!(read(&doc).contains("it holds 104 bytes, its byteLength says 1000"));
    let mut doc = document();
    doc["bufferViews"][0]["byteStride"] = json!(8);
    assert!(read(&doc).contains("byteStride 8 is less than the 12 bytes"));
    // Compression and unknown required extensions are named.
    for ext in [
        "KHR_draco_mesh_compression",
        "EXT_meshopt_compression",
        "EXT_made_up_compression",
    ] {
        let mut doc = document();
        doc["extensionsUsed"] = json!([ext]);
        doc["extensionsRequired"] = json!([ext]);
        let e = read(&doc);
        assert!(e.contains(&format!("requires the extension {ext}")), "{e}");
    }
    // Extensions that leave the geometry alone are accepted.
    let mut doc = document();
    doc["extensionsUsed"] = json!(["KHR_materials_unlit"]);
    doc["extensionsRequired"] = json!(["KHR_materials_unlit"]);
    assert_eq!(
        load(&glb(&doc, &bin()), Format::Glb).mesh.triangle_count(),
        4
    );
    let mut doc = document();
    doc["accessors"][0]["sparse"] = json!({
        "count": 1,
        "indices": {"bufferView": 3, "componentType": 5123},
        "values": {"bufferView": 0}
    });
    assert!(read(&doc).contains("sparse accessors are not supported"));
    // Out-of-range indices, including the one the gltf crate's validation would index
    // with before checking it.
    let mut doc = document();
    doc["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = json!(99);
    assert!(read(&doc).contains("POSITION is accessor 99, but there are 4 accessors"));
    let mut doc = document();
    doc["meshes"][0]["primitives"][0]["material"] = json!(7);
    assert!(read(&doc).contains("invalid glTF: meshes[0].primitives[0].material"));
    // Vertex indices past the vertices.
    let mut b = bin();
    b[100] = 9;
    let e = err(&glb(&document(), &b), Format::Glb);
    assert!(e.contains("index 9, but POSITION has 3 elements"), "{e}");
    // Node graphs that are not trees.
    let mut doc = document();
    doc["nodes"][1]["children"] = json!([0]);
    assert!(read(&doc).contains("is also a child of node 1"));
    let mut doc = document();
    doc["scenes"] = json!([{"nodes": [1]}]);
    doc["nodes"][0].as_object_mut().unwrap().remove("children");
    doc["nodes"][1]["children"] = json!([1]);
    assert!(read(&doc).contains("scene root node 1 is also a child of node 1"));
    let mut doc = document();
    doc["nodes"]
        .as_array_mut()
        .unwrap()
        .push(json!({"children": [1]}));
    assert!(read(&doc).contains("node 1 is a child of both node 0 and node 2"));
    // Not glTF at all, and malformed JSON.
    assert!(err(b"solid x\n", Format::Gltf).starts_with("not a glTF file"));
    assert!(err(b"{\"asset\": ", Format::Gltf).starts_with("unexpected end of file"));
    assert!(err(b"{\"meshes\": []}", Format::Gltf).contains("missing field `asset`"));
    assert_eq!(
        err(b"{\"asset\": {\"version\": \"2.0\"}}", Format::Gltf),
        "the mesh has no triangles"
    );
}
