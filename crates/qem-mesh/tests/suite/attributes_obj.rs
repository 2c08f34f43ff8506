//! Attributes through OBJ: texture coordinates, normals, materials, groups and
//! material libraries survive read → write → read, on made files, the repo's spot and
//! the corpus's attributed meshes; cleaning keeps each face's attributes.

#![allow(clippy::unwrap_used)]

use crate::common::corpus_dir;
use qem_mesh::attributes::{Attributes, ChannelKind};
use qem_mesh::clean::{clean, CleanOptions};
use qem_mesh::io::{read_bytes, read_path, write_to, Format};
use qem_mesh::IndexedMesh;
use std::path::Path;

/// Per channel, each corner's value (`None`: the corner has none).
type CornerValues = Vec<Vec<Option<Vec<f32>>>>;
/// Per label kind (materials, groups), each face's name.
type FaceNames = Vec<Vec<Option<Vec<u8>>>>;

/// Every corner's values, channel by channel, and every face's labels by name: what
/// must survive a round trip (value lists may be renumbered).
fn per_corner(mesh: &IndexedMesh) -> (CornerValues, FaceNames) {
    let a: &Attributes = &mesh.attributes;
    let channels = a
        .channels
        .iter()
        .map(|c| {
            (0..mesh.triangle_count())
                .flat_map(|t| (0..3).map(move |k| (t, k)))
                .map(|(t, k)| c.at_corner(t, k).map(<[f32]>::to_vec))
                .collect()
        })
        .collect();
    let labels = [&a.materials, &a.groups]
        .iter()
        .map(|l| {
            (0..l.faces.len())
                .map(|t| l.of_face(t).map(<[u8]>::to_vec))
                .collect()
        })
        .collect();
    (channels, labels)
}

fn round_trip(mesh: &IndexedMesh, format: Format) -> IndexedMesh {
    let mut bytes = Vec::new();
    write_to(&mut bytes, mesh, format).unwrap();
    read_bytes(&bytes, format)
        .unwrap_or_else(|e| panic!("{format:?} round trip: {e}"))
        .mesh
}

fn assert_round_trip(name: &str, mesh: &IndexedMesh) {
    let again = round_trip(mesh, Format::Obj);
    assert_eq!(again.triangle_count(), mesh.triangle_count(), "{name}");
    for (t, (a, b)) in mesh.triangles.iter().zip(&again.triangles).enumerate() {
        let pa = a.map(|i| mesh.positions[i as usize]);
        let pb = b.map(|i| again.positions[i as usize]);
        assert_eq!(pa, pb, "{name}: face {t}");
    }
    assert_eq!(per_corner(&again), per_corner(mesh), "{name}");
    assert_eq!(
        again.attributes.material_libraries, mesh.attributes.material_libraries,
        "{name}"
    );
}

const MADE: &[u8] = b"mtllib a.mtl b.mtl\n\
v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\n\
vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvt 0.25 0.125\n\
vn 0 0 1\nvn 0 0.6 0.8\n\
f 1 2 3\n\
g left side\nusemtl red\nf 1/1/1 2/2/1 3/3/2 4/4/2\n\
g right\nusemtl blue\nf 2/5 5/1 3/2\n\
usemtl red\nf 2//1 5//2 3//1\n";

#[test]
fn made_obj_keeps_uvs_normals_materials_groups_and_libraries() {
    let mesh = read_bytes(MADE, Format::Obj).unwrap().mesh;
    assert_eq!(mesh.triangle_count(), 5);
    let a = &mesh.attributes;
    assert_eq!(a.material_libraries, vec![b"a.mtl b.mtl".to_vec()]);
    assert_eq!(a.materials.names, vec![b"red".to_vec(), b"blue".to_vec()]);
    assert_eq!(a.materials.faces, vec![u32::MAX, 0, 0, 1, 0]);
    assert_eq!(
        a.groups.names,
        vec![b"left side".to_vec(), b"right".to_vec()]
    );
    assert_eq!(a.groups.faces, vec![u32::MAX, 0, 0, 1, 1]);
    let uv = a.channel(ChannelKind::TexCoord).unwrap();
    assert_eq!(uv.at_corner(0, 0), None);
    assert_eq!(uv.at_corner(2, 2), Some(&[0.0, 1.0][..]));
    assert_eq!(uv.at_corner(3, 0), Some(&[0.25, 0.125][..]));
    assert_eq!(uv.at_corner(4, 1), None);
    let normal = a.channel(ChannelKind::Normal).unwrap();
    assert_eq!(normal.at_corner(4, 1), Some(&[0.0, 0.6, 0.8][..]));
    assert_eq!(normal.at_corner(3, 1), None);
    assert_round_trip("made", &mesh);
}

#[test]
fn spot_round_trips_through_obj() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/spot.obj");
    let mesh = read_path(&path).unwrap().mesh;
    let uv = mesh.attributes.channel(ChannelKind::TexCoord).unwrap();
    assert_eq!(uv.corners.len(), mesh.triangle_count());
    assert!(uv.corners.iter().flatten().all(|&i| i != u32::MAX));
    assert_round_trip("spot", &mesh);
}

#[test]
fn corpus_attributed_meshes_round_trip_through_obj() {
    let Some(dir) = corpus_dir() else { return };
    for name in [
        "tm_fuze.obj",
        "asp_wuson.obj",
        "c3d_spot.obj",
        "pymeshlab_bunny10k_textured.obj",
        "c3d_beast.obj",
    ] {
        let Some(path) = [dir.join(name), dir.join("public").join(name)]
            .into_iter()
            .find(|p| p.is_file())
        else {
            eprintln!("SKIPPED: {name} is not in {}", dir.display());
            continue;
        };
        let mesh = read_path(&path).unwrap().mesh;
        assert!(
            mesh.attributes.channel(ChannelKind::TexCoord).is_some(),
            "{name} has texture coordinates"
        );
        assert_round_trip(name, &mesh);
    }
}

#[test]
fn cleaning_keeps_each_kept_face_with_its_attributes() {
    // Face 0 has a repeated vertex, face 2 repeats face 1: both go; the survivors keep
    // their own corners' values and labels.
    let obj = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nvt 1 1\n\
usemtl a\nf 1/1 1/2 2/3\nf 1/1 2/2 3/3\nusemtl b\nf 2/4 3/4 1/4\nf 2/2 4/4 3/3\n";
    let mesh = read_bytes(obj, Format::Obj).unwrap().mesh;
    let cleaned = clean(&mesh, &CleanOptions::DEFAULT);
    assert_eq!(cleaned.report.repeated_index_faces, 1);
    assert_eq!(cleaned.report.duplicate_faces, 1);
    let kept = &cleaned.mesh;
    assert_eq!(kept.triangle_count(), 2);
    assert_eq!(kept.attributes.materials.faces, vec![0, 1]);
    let uv = kept.attributes.channel(ChannelKind::TexCoord).unwrap();
    assert_eq!(uv.at_corner(0, 2), Some(&[0.0, 1.0][..]));
    assert_eq!(uv.at_corner(1, 1), Some(&[1.0, 1.0][..]));
    assert_eq!(kept.validate(), Ok(()));
}

#[test]
fn vertex_colours_on_v_lines_round_trip_and_survive_a_seam() {
    let obj = b"v 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 1 1 0 0 0 1\nv 0 1 0 0.5 0.5 0.5\n\
vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n";
    let mesh = read_bytes(obj, Format::Obj).unwrap().mesh;
    let colour = mesh.attributes.channel(ChannelKind::Color).unwrap();
    assert_eq!(colour.dimension, 3);
    assert_eq!(colour.at_corner(1, 2), Some(&[0.5, 0.5, 0.5][..]));
    assert_round_trip("coloured", &mesh);
    // A colour seam (vertex 0 red on one face, blue on the other): written as two
    // `v` lines at one position, read back with each face's own colour.
    let mut seam = mesh.clone();
    let c = &mut seam.attributes.channels[1];
    c.values.extend([0.0, 0.0, 1.0]);
    c.corners[1][0] = 4;
    assert_eq!(seam.validate(), Ok(()));
    assert_round_trip("colour seam", &seam);
    // 0–255 levels (some scanners' OBJ) read as 0–1.
    let levels = b"v 0 0 0 255 0 0\nv 1 0 0 0 255 0\nv 0 1 0 0 0 51\nf 1 2 3\n";
    let mesh = read_bytes(levels, Format::Obj).unwrap().mesh;
    let colour = mesh.attributes.channel(ChannelKind::Color).unwrap();
    assert_eq!(colour.at_corner(0, 2), Some(&[0.0, 0.0, 0.2][..]));
}
