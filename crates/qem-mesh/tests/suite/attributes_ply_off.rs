//! Attributes through PLY and OFF: colours (uchar, ushort, float, RGBA), normals,
//! texture coordinates under each PLY naming, face colours and generic properties
//! survive read → write → read; OBJ, PLY and OFF convert into each other with the same
//! value at every corner; hostile headers and non-finite values are clear errors.

#![allow(clippy::unwrap_used)]

use std::collections::BTreeMap;
use std::path::Path;

use qem_mesh::attributes::{Channel, ChannelKind};
use qem_mesh::io::{read_path, unwritable, Format};
use qem_mesh::IndexedMesh;

/// Each corner's value in one channel (`None`: the corner has none).
type CornerValues = Vec<Option<Vec<f32>>>;

/// Per channel name, each corner's value (`None`: the corner has none), triangle by
/// triangle: what must survive a round trip whatever the vertex numbering and the
/// channel order.
fn values_by_corner(mesh: &IndexedMesh) -> BTreeMap<String, (ChannelKind, CornerValues)> {
    mesh.attributes
        .channels
        .iter()
        .map(|c| {
            let corners = (0..mesh.triangle_count())
                .flat_map(|t| (0..3).map(move |k| (t, k)))
                .map(|(t, k)| c.at_corner(t, k).map(<[f32]>::to_vec))
                .collect();
            (c.name.clone(), (c.kind, corners))
        })
        .collect()
}

/// Each corner's position bits, triangle by triangle.
fn positions_by_corner(mesh: &IndexedMesh) -> Vec<[u64; 3]> {
    mesh.triangles
        .iter()
        .flatten()
        .map(|&i| mesh.positions[i as usize].map(f64::to_bits))
        .collect()
}

use crate::attributes_common::{encode, err, load};

/// Writes `mesh` in `format`, reads it back, checks every corner kept its position and
/// values, and that writing again gives the same bytes; returns what was read.
fn assert_round_trip(name: &str, mesh: &IndexedMesh, format: Format) -> IndexedMesh {
    let bytes = encode(mesh, format);
    let again = load(&bytes, format).mesh;
    assert_eq!(
        positions_by_corner(&again),
        positions_by_corner(mesh),
        "{name}"
    );
    assert_eq!(values_by_corner(&again), values_by_corner(mesh), "{name}");
    assert_eq!(encode(&again, format), bytes, "{name}: second write");
    again
}

/// `mesh`'s channel `name`.
fn channel<'m>(mesh: &'m IndexedMesh, name: &str) -> &'m Channel {
    let found = mesh.attributes.channels.iter().find(|c| c.name == name);
    found.unwrap_or_else(|| panic!("no channel {name:?}"))
}

/// The PLY header of `bytes` (through `end_header`), as text.
fn ply_header(bytes: &[u8]) -> String {
    let end = bytes
        .windows(11)
        .position(|w| w == b"end_header\n")
        .unwrap();
    String::from_utf8(bytes[..end].to_vec()).unwrap()
}

const ASCII: &[u8] = b"ply\nformat ascii 1.0\n\
element vertex 4\n\
property float x\nproperty float y\nproperty float z\n\
property uchar red\nproperty uchar green\nproperty uchar blue\nproperty uchar alpha\n\
property float nx\nproperty float ny\nproperty float nz\n\
property float s\nproperty float t\n\
property float quality\n\
property float w_0\nproperty float w_1\nproperty float w_2\n\
property list uchar int neighbours\n\
element face 2\n\
property list uchar int vertex_indices\n\
property uchar red\nproperty uchar green\nproperty uchar blue\n\
property int flags\n\
element camera 1\nproperty float focal\n\
end_header\n\
0 0 0 255 0 0 255 0 0 1 0 0 0.5 1 2 3 2 1 2\n\
1 0 0 0 255 0 128 0 0 1 1 0 1.5 4 5 6 1 0\n\
1 1 0 0 0 255 0 0 0.6 0.8 1 1 2.5 7 8 9 0\n\
0 1 0 10 20 30 40 0 0 1 0 1 3.5 -1 -2 -3 0\n\
3 0 1 2 200 100 50 7\n\
3 0 2 3 1 2 3 8\n\
35\n";

#[test]
fn ascii_ply_reads_colours_normals_uvs_generics_and_face_colours() {
    let loaded = load(ASCII, Format::Ply);
    let mesh = &loaded.mesh;
    let names: Vec<&str> = mesh
        .attributes
        .channels
        .iter()
        .map(|c| c.name.as_str())
        .collect();
    assert_eq!(
        names,
        ["colour", "normal", "uv", "quality", "w", "face_colour"]
    );
    // Skipped: the vertex list, the face's flags, the camera's focal length.
    assert_eq!(loaded.notes.skipped_properties, 3);
    let colour = channel(mesh, "colour");
    assert_eq!((colour.kind, colour.dimension), (ChannelKind::Color, 4));
    assert_eq!(colour.corners, mesh.triangles);
    assert_eq!(colour.value(1), &[0.0, 1.0, 0.0, 128.0 / 255.0]);
    assert_eq!(channel(mesh, "normal").value(2), &[0.0, 0.6, 0.8]);
    assert_eq!(channel(mesh, "uv").kind, ChannelKind::TexCoord);
    assert_eq!(channel(mesh, "uv").value(3), &[0.0, 1.0]);
    let quality = channel(mesh, "quality");
    assert_eq!((quality.kind, quality.dimension), (ChannelKind::Generic, 1));
    assert_eq!(quality.values, [0.5, 1.5, 2.5, 3.5]);
    let w = channel(mesh, "w");
    assert_eq!((w.kind, w.dimension), (ChannelKind::Generic, 3));
    assert_eq!(w.value(3), &[-1.0, -2.0, -3.0]);
    let face = channel(mesh, "face_colour");
    assert_eq!(face.corners, vec![[0; 3], [1; 3]]);
    assert_eq!(face.value(0), &[200.0 / 255.0, 100.0 / 255.0, 50.0 / 255.0]);

    let bytes = encode(mesh, Format::Ply);
    assert_eq!(
        ply_header(&bytes),
        "ply\nformat binary_little_endian 1.0\ncomment written by qem\n\
         element vertex 4\nproperty double x\nproperty double y\nproperty double z\n\
         property uchar red\nproperty uchar green\nproperty uchar blue\nproperty uchar alpha\n\
         property float nx\nproperty float ny\nproperty float nz\n\
         property float s\nproperty float t\nproperty float quality\n\
         property float w_0\nproperty float w_1\nproperty float w_2\n\
         element face 2\nproperty list uchar int vertex_indices\n\
         property uchar red\nproperty uchar green\nproperty uchar blue\n"
    );
    let again = assert_round_trip("ascii", mesh, Format::Ply);
    // Per-vertex data comes back with the same vertices.
    assert_eq!(again.triangles, mesh.triangles);
    assert_eq!(again.attributes.channels, mesh.attributes.channels);
}

/// A binary PLY: 3 vertices with float RGB colours (not uchar levels) and `u v`, one
/// triangle with a float RGBA face colour.
fn binary(big: bool) -> Vec<u8> {
    let format = if big {
        "binary_big_endian"
    } else {
        "binary_little_endian"
    };
    let mut data = format!(
        "ply\nformat {format} 1.0\nelement vertex 3\n\
         property float x\nproperty float y\nproperty float z\n\
         property float red\nproperty float green\nproperty float blue\n\
         property double u\nproperty double v\n\
         element face 1\nproperty float red\nproperty float green\nproperty float blue\n\
         property float alpha\nproperty list uchar uint vertex_indices\nend_header\n"
    )
    .into_bytes();
    let f32s = |data: &mut Vec<u8>, vs: &[f32]| {
        for v in vs {
            data.extend(if big {
                v.to_be_bytes()
            } else {
                v.to_le_bytes()
            });
        }
    };
    let f64s = |data: &mut Vec<u8>, vs: &[f64]| {
        for v in vs {
            data.extend(if big {
                v.to_be_bytes()
            } else {
                v.to_le_bytes()
            });
        }
    };
    for (i, p) in [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0f32]]
        .iter()
        .enumerate()
    {
        f32s(&mut data, p);
        f32s(&mut data, &[0.3, 0.1 * i as f32, 1.25]);
        f64s(&mut data, &[0.125, 0.1 + i as f64]);
    }
    f32s(&mut data, &[0.2, 0.4, 0.6, 0.5]);
    data.push(3);
    for i in [0u32, 1, 2] {
        data.extend(if big {
            i.to_be_bytes()
        } else {
            i.to_le_bytes()
        });
    }
    data
}

#[test]
fn binary_ply_float_colours_stay_float_in_both_byte_orders() {
    for big in [false, true] {
        let mesh = load(&binary(big), Format::Ply).mesh;
        let colour = channel(&mesh, "colour");
        assert_eq!(colour.value(2), &[0.3, 0.2, 1.25]);
        assert_eq!(channel(&mesh, "uv").value(1), &[0.125, 1.1]);
        let face = channel(&mesh, "face_colour");
        assert_eq!(
            (face.dimension, face.value(0)),
            (4, &[0.2, 0.4, 0.6, 0.5][..])
        );
        let header = ply_header(&encode(&mesh, Format::Ply));
        // Floats that are not k/255 are written as floats, so they come back exactly.
        assert!(header.contains("property float red\n"), "{header}");
        assert!(header.contains("property float alpha\n"), "{header}");
        assert_round_trip("binary", &mesh, Format::Ply);
    }
}

#[test]
fn every_uchar_level_comes_back_as_the_same_byte() {
    let mut ply = b"ply\nformat ascii 1.0\nelement vertex 256\nproperty float x\n\
property float y\nproperty float z\nproperty uchar red\nproperty uchar green\n\
property uchar blue\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
        .to_vec();
    for k in 0..256 {
        ply.extend(format!("{k} {} 0 {k} {} 7\n", k % 3, 255 - k).bytes());
    }
    ply.extend(b"3 0 1 2\n");
    let mesh = load(&ply, Format::Ply).mesh;
    let bytes = encode(&mesh, Format::Ply);
    assert!(ply_header(&bytes).contains("property uchar red\n"));
    // Vertices no face uses keep their colours too.
    let body = &bytes[ply_header(&bytes).len() + "end_header\n".len()..];
    for k in 0..256 {
        let record = &body[k * 27..(k + 1) * 27];
        assert_eq!(record[24..], [k as u8, 255 - k as u8, 7], "level {k}");
    }
    assert_round_trip("levels", &mesh, Format::Ply);
}

#[test]
fn every_ply_uv_naming_and_diffuse_and_ushort_colours() {
    for (u, v) in [
        ("s", "t"),
        ("u", "v"),
        ("texture_u", "texture_v"),
        ("texture_s", "texture_t"),
    ] {
        let ply = format!(
            "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
             property float z\nproperty float {u}\nproperty float {v}\n\
             property ushort diffuse_red\nproperty ushort diffuse_green\n\
             property ushort diffuse_blue\nelement face 1\n\
             property list uchar int vertex_indices\nend_header\n\
             0 0 0 0.25 0.5 65535 0 0\n1 0 0 1 0 0 65535 0\n0 1 0 0 1 0 0 13107\n3 0 1 2\n"
        );
        let loaded = load(ply.as_bytes(), Format::Ply);
        assert_eq!(loaded.notes.skipped_properties, 0, "{u} {v}");
        let mesh = loaded.mesh;
        let uv = mesh.attributes.channel(ChannelKind::TexCoord).unwrap();
        assert_eq!(uv.value(0), &[0.25, 0.5], "{u} {v}");
        let colour = mesh.attributes.channel(ChannelKind::Color).unwrap();
        assert_eq!(colour.value(2), &[0.0, 0.0, 0.2], "{u} {v}");
        assert_round_trip(u, &mesh, Format::Ply);
    }
}

#[test]
fn polygon_face_colours_apply_to_each_of_its_triangles() {
    let ply = b"ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\nproperty float y\n\
property float z\nelement face 2\nproperty list uchar int vertex_indices\n\
property uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n\
0 0 0\n1 0 0\n1 1 0\n0 1 0\n2 0 0\n4 0 1 2 3 255 0 0\n3 1 4 2 0 0 255\n";
    let mesh = load(ply, Format::Ply).mesh;
    assert_eq!(mesh.triangle_count(), 3);
    let colour = channel(&mesh, "colour");
    assert_eq!(colour.corners, vec![[0; 3], [0; 3], [1; 3]]);
    assert_eq!(colour.at_corner(1, 2), Some(&[1.0, 0.0, 0.0][..]));
    let again = assert_round_trip("face colours", &mesh, Format::Ply);
    // Written on the faces, not by splitting vertices.
    assert_eq!(again.vertex_count(), 5);
    let off = assert_round_trip("face colours", &mesh, Format::Off);
    assert_eq!(off.vertex_count(), 5);
}

#[test]
fn off_reads_coff_noff_stoff_and_their_combinations() {
    // COFF with 0-255 integers and alpha, and face colours.
    let coff = b"COFF\n3 1 0\n0 0 0 255 0 0 255\n1 0 0 0 255 0 128\n0 1 0 0 0 51 0\n\
3 0 1 2 0 0 255\n";
    let mesh = load(coff, Format::Off).mesh;
    let colour = channel(&mesh, "colour");
    assert_eq!(
        (colour.dimension, colour.value(2)),
        (4, &[0.0, 0.0, 0.2, 0.0][..])
    );
    assert_eq!(channel(&mesh, "face_colour").value(0), &[0.0, 0.0, 1.0]);
    let bytes = encode(&mesh, Format::Off);
    assert!(bytes.starts_with(b"COFF\n"));
    assert_round_trip("coff", &mesh, Format::Off);
    assert_round_trip("coff", &mesh, Format::Ply);

    // 0-1 floats stay as they are.
    let coff = b"COFF\n3 1 0\n0 0 0 1 0 0\n1 0 0 0 1 0\n0 1 0 0.5 0.25 0.125\n3 0 1 2\n";
    let mesh = load(coff, Format::Off).mesh;
    assert_eq!(channel(&mesh, "colour").value(2), &[0.5, 0.25, 0.125]);
    assert_round_trip("coff floats", &mesh, Format::Off);

    let noff = b"NOFF\n3 1 0\n0 0 0 0 0 1\n1 0 0 0 0.6 0.8\n0 1 0 0 0 -1\n3 0 1 2\n";
    let mesh = load(noff, Format::Off).mesh;
    assert_eq!(channel(&mesh, "normal").value(1), &[0.0, 0.6, 0.8]);
    assert!(encode(&mesh, Format::Off).starts_with(b"NOFF\n"));
    assert_round_trip("noff", &mesh, Format::Off);

    let stoff = b"STOFF\n3 1 0\n0 0 0 0.1 0.2\n1 0 0 0.3 0.4\n0 1 0 0.5 0.6\n3 0 1 2\n";
    let mesh = load(stoff, Format::Off).mesh;
    assert_eq!(channel(&mesh, "uv").value(2), &[0.5, 0.6]);
    assert!(encode(&mesh, Format::Off).starts_with(b"STOFF\n"));
    assert_round_trip("stoff", &mesh, Format::Off);

    // All three: normal, colour, texture coordinates after the coordinates, in that
    // order (the spec's), whatever the order of the header's letters.
    for header in ["STCNOFF", "STNCOFF"] {
        let off = format!(
            "{header}\n3 1 0\n0 0 0 0 0 1 1 0 0 0.1 0.2\n1 0 0 0 1 0 0 1 0 0.3 0.4\n\
             0 1 0 1 0 0 0 0 1 0.5 0.6\n4 0 1 2 0\n"
        );
        let mesh = load(off.as_bytes(), Format::Off).mesh;
        assert_eq!(channel(&mesh, "normal").value(0), &[0.0, 0.0, 1.0]);
        assert_eq!(channel(&mesh, "colour").value(1), &[0.0, 1.0, 0.0]);
        assert_eq!(channel(&mesh, "uv").value(2), &[0.5, 0.6]);
        let bytes = encode(&mesh, Format::Off);
        assert!(bytes.starts_with(b"STCNOFF\n"), "{header}");
        assert_round_trip(header, &mesh, Format::Off);
        assert_round_trip(header, &mesh, Format::Ply);
    }
}

#[test]
fn off_attribute_errors_name_the_vertex_and_line() {
    assert_eq!(
        err(
            b"NOFF\n3 1 0\n0 0 0 0 0 1\n1 0 0 0 1\n0 1 0 1 0 0\n3 0 1 2\n",
            Format::Off
        ),
        "line 4: vertex 1: expected 3 normal components after the coordinates, found 2 numbers"
    );
    assert_eq!(
        err(
            b"COFF\n3 1 0\n0 0 0 1 0 0\n1 0 0 0 1 0 1\n0 1 0 1 0 0\n3 0 1 2\n",
            Format::Off
        ),
        "line 4: vertex 1 has 4 colour components, vertex 0 has 3"
    );
    assert_eq!(
        err(
            b"COFF\n3 1 0\n0 0 0 1 0 0\n1 0 0 0 nan 0\n0 1 0 1 0 0\n3 0 1 2\n",
            Format::Off
        ),
        "line 4: vertex 1: colour component \"nan\" is not a finite 32-bit float"
    );
    assert_eq!(
        err(
            b"STOFF\n3 1 0\n0 0 0 0 0\n1 0 0 0 x\n0 1 0 1 0\n3 0 1 2\n",
            Format::Off
        ),
        "line 4: vertex 1: bad texture coordinate \"x\""
    );
    assert_eq!(
        err(
            b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2 1 inf 0\n",
            Format::Off
        ),
        "line 6: face 0: colour component \"inf\" is not a finite 32-bit float"
    );
}

#[test]
fn ply_non_finite_values_are_errors_naming_the_element_and_property() {
    let ascii = String::from_utf8_lossy(ASCII).replace(
        "1 0 0 0 255 0 128 0 0 1 1 0 1.5",
        "1 0 0 0 255 0 128 0 nan 1 1 0 1.5",
    );
    assert_eq!(
        err(ascii.as_bytes(), Format::Ply),
        "line 31: vertex 1: property \"ny\" is \"nan\", not a finite 32-bit float"
    );
    // A double beyond f32's range is not finite as a float either.
    let mut data = binary(false);
    let header = data.windows(11).position(|w| w == b"end_header\n").unwrap() + 11;
    let u = header + 12 + 12;
    data[u..u + 8].copy_from_slice(&1e300f64.to_le_bytes());
    assert_eq!(
        err(&data, Format::Ply),
        format!("byte {u}: vertex 0: property \"u\" is 1e300, not a finite 32-bit float")
    );
    let mut data = binary(true);
    let red = data.windows(11).position(|w| w == b"end_header\n").unwrap() + 11 + 12;
    data[red..red + 4].copy_from_slice(&f32::INFINITY.to_be_bytes());
    assert_eq!(
        err(&data, Format::Ply),
        format!("byte {red}: vertex 0: property \"red\" is inf, not a finite 32-bit float")
    );
}

#[test]
fn hostile_ply_headers_stay_bounded() {
    // A vertex count near the limit with a tiny body: an error, not a reservation of
    // 2^28 colours.
    let ascii = b"ply\nformat ascii 1.0\nelement vertex 268435455\nproperty float x\n\
property float y\nproperty float z\nproperty uchar red\nproperty uchar green\n\
property uchar blue\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n\
0 0 0 1 2 3\n";
    assert_eq!(
        err(ascii, Format::Ply),
        "line 13: unexpected end of file after 1 of 268435455 vertices"
    );
    let binary = String::from_utf8_lossy(ascii).replace("ascii", "binary_little_endian");
    // The body (12 bytes) holds no whole 15-byte record: the error is at its start.
    let body = binary.len() - 12;
    assert_eq!(
        err(binary.as_bytes(), Format::Ply),
        format!("byte {body}: unexpected end of file after 0 of 268435455 vertices (binary PLY)")
    );
    // Many one-byte properties: at most 16 channels are read (each holds 3 indices per
    // triangle), the rest are skipped and counted.
    let mut ply = b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n\
property float y\nproperty float z\n"
        .to_vec();
    for i in 0..1000 {
        ply.extend(format!("property uchar p{i}\n").bytes());
    }
    ply.extend(b"element face 1\nproperty list uchar uchar vertex_indices\nend_header\n");
    for p in [[0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] {
        for c in p {
            ply.extend(c.to_le_bytes());
        }
        ply.extend([7u8; 1000]);
    }
    ply.extend([3, 0, 1, 2]);
    let loaded = load(&ply, Format::Ply);
    assert_eq!(loaded.mesh.attributes.channels.len(), 16);
    assert_eq!(loaded.mesh.attributes.channels[15].name, "p15");
    assert_eq!(loaded.notes.skipped_properties, 1000 - 16);
}

/// Two quads sharing an edge, every corner with a `vt` and a `vn`, with a UV seam
/// along the shared edge and a hard normal at one corner.
const OBJ: &[u8] = b"v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nv 2 1 0\n\
vt 0 0\nvt 0.5 0\nvt 0.5 1\nvt 0 1\nvt 0.6 0\nvt 1 0\nvt 1 1\nvt 0.6 1\n\
vn 0 0 1\nvn 0 0.6 0.8\n\
f 1/1/1 2/2/1 3/3/1 4/4/1\nf 2/5/1 5/6/2 6/7/1 3/8/1\n";

#[test]
fn obj_uvs_and_normals_convert_to_ply_and_off_corner_by_corner() {
    let mesh = load(OBJ, Format::Obj).mesh;
    assert_eq!(mesh.vertex_count(), 6);
    for format in [Format::Ply, Format::Off] {
        let bytes = encode(&mesh, format);
        let again = load(&bytes, format).mesh;
        // Split at the seam: vertices 2 and 3 (1-based) get a second copy each.
        assert_eq!(again.vertex_count(), 8, "{format:?}");
        assert_eq!(
            positions_by_corner(&again),
            positions_by_corner(&mesh),
            "{format:?}"
        );
        assert_eq!(
            values_by_corner(&again),
            values_by_corner(&mesh),
            "{format:?}"
        );
        // Back to OBJ: the same corners again.
        let obj = load(&encode(&again, Format::Obj), Format::Obj).mesh;
        assert_eq!(
            values_by_corner(&obj),
            values_by_corner(&mesh),
            "{format:?}"
        );
    }
}

#[test]
fn spot_goes_obj_to_ply_to_off_and_back_with_its_uvs() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/spot.obj");
    let spot = read_path(&path).unwrap().mesh;
    assert!(spot.attributes.channel(ChannelKind::TexCoord).is_some());
    let ply = load(&encode(&spot, Format::Ply), Format::Ply).mesh;
    assert_eq!(values_by_corner(&ply), values_by_corner(&spot));
    assert_eq!(positions_by_corner(&ply), positions_by_corner(&spot));
    // Already per vertex: PLY to OFF and back keeps the vertices themselves.
    let off = assert_round_trip("spot", &ply, Format::Off);
    assert_eq!(off.triangles, ply.triangles);
    assert_eq!(off.attributes.channels, ply.attributes.channels);
    assert_eq!(values_by_corner(&off), values_by_corner(&spot));
}

#[test]
fn unwritable_says_what_ply_and_off_leave_out() {
    let mut obj = OBJ.to_vec();
    obj.extend(b"g side\nusemtl red\nf 1/1/1 2/2/1 4/4/1\n");
    let mut mesh = load(&obj, Format::Obj).mesh;
    let n = mesh.triangle_count();
    let per_face = |name: &str| {
        Channel::new(
            ChannelKind::Color,
            vec![0.5; 3 * n],
            (0..n as u32).map(|t| [t; 3]).collect(),
        )
        .with_name(name)
    };
    let generic = |name: &str, dimension: usize| {
        Channel::new(ChannelKind::Generic, vec![1.0; dimension], vec![[0; 3]; n])
            .with_dimension(dimension)
            .with_name(name)
    };
    let second_uv =
        Channel::new(ChannelKind::TexCoord, vec![0.0; 2], vec![[0; 3]; n]).with_name("uv2");
    let vertex_colour = Channel::new(
        ChannelKind::Color,
        vec![1.0; 3 * mesh.vertex_count()],
        mesh.triangles.clone(),
    );
    mesh.attributes.channels.extend([
        second_uv,
        per_face("face"),
        per_face("face2"),
        vertex_colour.clone().with_name("c1"),
        vertex_colour.with_name("c2"),
        generic("speed", 2),
        generic("red", 1),
        generic("speed_1", 1),
        generic("two words", 1),
    ]);
    assert_eq!(mesh.validate(), Ok(()));
    let left = |format| -> Vec<(String, &'static str)> {
        unwritable(&mesh.attributes, format)
            .into_iter()
            .map(|u| (u.what, u.reason))
            .collect()
    };
    let s = |what: &str, reason| (what.to_string(), reason);
    let one_uv = "PLY holds one texture coordinate and one normal per vertex";
    let colours = "PLY holds one vertex colour and one face colour";
    let labels = "PLY has no materials, groups or material libraries";
    assert_eq!(
        left(Format::Ply),
        [
            s("uv2", one_uv),
            s("face2", colours),
            s("c2", colours),
            s("red", "PLY readers give this property name another meaning"),
            s("speed_1", "another channel has the same PLY property names"),
            s(
                "two words",
                "a PLY property name cannot be empty or hold spaces"
            ),
            s("materials", labels),
            s("groups", labels),
        ]
    );
    let one_uv = "OFF holds one texture coordinate and one normal per vertex";
    let colours = "OFF holds one vertex colour and one face colour";
    let generic = "OFF holds no generic channels";
    let labels = "OFF has no materials, groups or material libraries";
    assert_eq!(
        left(Format::Off),
        [
            s("uv2", one_uv),
            s("face2", colours),
            s("c2", colours),
            s("speed", generic),
            s("red", generic),
            s("speed_1", generic),
            s("two words", generic),
            s("materials", labels),
            s("groups", labels),
        ]
    );
    // What is written comes back; what is reported left out does not.
    for format in [Format::Ply, Format::Off] {
        let again = load(&encode(&mesh, format), format).mesh;
        let kept: Vec<String> = values_by_corner(&again).into_keys().collect();
        let want = if format == Format::Ply {
            vec!["colour", "face_colour", "normal", "speed", "uv"]
        } else {
            vec!["colour", "face_colour", "normal", "uv"]
        };
        assert_eq!(kept, want, "{format:?}");
        let by = values_by_corner(&mesh);
        let got = values_by_corner(&again);
        assert_eq!(got["uv"], by["uv"], "{format:?}");
        assert_eq!(got["normal"], by["normal"], "{format:?}");
        assert_eq!(got["colour"].1, by["c1"].1, "{format:?}");
        assert_eq!(got["face_colour"].1, by["face"].1, "{format:?}");
        if format == Format::Ply {
            assert_eq!(got["speed"], by["speed"]);
        }
    }
}

#[test]
fn positions_only_files_are_written_as_before() {
    let mesh = IndexedMesh::new(
        vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.5]],
        vec![[0, 1, 2]],
    );
    let ply = encode(&mesh, Format::Ply);
    let header = "ply\nformat binary_little_endian 1.0\ncomment written by qem\n\
element vertex 3\nproperty double x\nproperty double y\nproperty double z\n\
element face 1\nproperty list uchar int vertex_indices\nend_header\n";
    assert!(ply.starts_with(header.as_bytes()));
    assert_eq!(ply.len(), header.len() + 3 * 24 + 13);
    assert_eq!(
        encode(&mesh, Format::Off),
        b"OFF\n# written by qem\n3 1 0\n0 0 0\n1 0 0\n0 1 0.5\n3 0 1 2\n"
    );
}
