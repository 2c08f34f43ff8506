//! Simplification with attributes: values follow the vertices (a linear field is
//! reproduced exactly), seams keep their sides apart, materials stay with their faces
//! and their borders, and positions-only input is not affected.

#![allow(clippy::unwrap_used)]

use qem_mesh::attributes::{Attributes, Channel, ChannelKind, FaceLabels};
use qem_mesh::simplify::{simplify, SimplifyOptions, Target};
use qem_mesh::IndexedMesh;

/// An `n` by `n` grid of squares over [0, 1]², gently curved (so the simplifier has
/// work to do), two triangles a square.
fn grid(n: u32) -> IndexedMesh {
    grid_with_height(n, 0.1)
}

/// [`grid`] with bumps of `height` (0: flat).
fn grid_with_height(n: u32, height: f64) -> IndexedMesh {
    let mut positions = Vec::new();
    for y in 0..=n {
        for x in 0..=n {
            let (fx, fy) = (f64::from(x) / f64::from(n), f64::from(y) / f64::from(n));
            positions.push([fx, fy, height * (3.0 * fx).sin() * (2.0 * fy).cos()]);
        }
    }
    let mut triangles = Vec::new();
    for y in 0..n {
        for x in 0..n {
            let v = y * (n + 1) + x;
            triangles.push([v, v + 1, v + n + 1]);
            triangles.push([v + 1, v + n + 2, v + n + 1]);
        }
    }
    IndexedMesh::new(positions, triangles)
}

/// Per-vertex values `f(position)` as a channel of `kind` (corners = triangles).
fn per_vertex(mesh: &IndexedMesh, kind: ChannelKind, f: impl Fn([f64; 3]) -> Vec<f32>) -> Channel {
    let values: Vec<f32> = mesh.positions.iter().flat_map(|&p| f(p)).collect();
    let dimension = values.len() / mesh.vertex_count();
    Channel::new(kind, values, mesh.triangles.clone()).with_dimension(dimension)
}

#[test]
fn a_linear_uv_field_comes_out_exact_at_every_vertex() {
    // Flat: on a curved surface a moved vertex leaves every input triangle's plane,
    // where the triangles' in-plane fields no longer agree with u = x exactly.
    let mut mesh = grid_with_height(24, 0.0);
    let uv = per_vertex(&mesh, ChannelKind::TexCoord, |p| {
        vec![p[0] as f32, (2.0 * p[1]) as f32]
    });
    mesh.attributes.channels.push(uv);
    let out = simplify(
        &mesh,
        &SimplifyOptions::DEFAULT.with_target(Target::Ratio(0.1)),
    )
    .unwrap();
    let m = &out.mesh;
    assert_eq!(m.validate(), Ok(()));
    assert!(m.triangle_count() <= 115, "{}", m.triangle_count());
    let uv = m
        .attributes
        .channel(ChannelKind::TexCoord)
        .expect("the uv channel is kept");
    let mut moved = 0;
    for (t, tri) in m.triangles.iter().enumerate() {
        for (k, &corner) in tri.iter().enumerate() {
            let p = m.positions[corner as usize];
            let value = uv.at_corner(t, k).expect("every corner keeps a uv");
            // u = x and v = 2y on every input triangle (a plane's projection): the
            // quadric's best values at a moved vertex are the same field there.
            assert!(
                (f64::from(value[0]) - p[0]).abs() < 1e-6,
                "u {value:?} at {p:?}"
            );
            assert!(
                (f64::from(value[1]) - 2.0 * p[1]).abs() < 2e-6,
                "v {value:?} at {p:?}"
            );
            moved += usize::from(mesh.positions.iter().all(|q| *q != p));
        }
    }
    assert!(moved > 0, "some vertices moved off the input's");
}

#[test]
fn seams_keep_their_sides_apart_and_their_place() {
    // The left half (x < 0.5) maps to u in [0, 0.4], the right half to u in [0.6, 1]:
    // the column x = 0.5 is a seam, its vertices with one uv on each side.
    let mut mesh = grid(24);
    let n = mesh.vertex_count() as u32;
    let mut values = Vec::new();
    for p in &mesh.positions {
        values.extend([(0.8 * p[0]) as f32, p[1] as f32]);
    }
    for p in &mesh.positions {
        values.extend([(0.2 + 0.8 * p[0]) as f32, p[1] as f32]);
    }
    let corners = mesh
        .triangles
        .iter()
        .map(|t| {
            let right = t
                .iter()
                .map(|&v| mesh.positions[v as usize][0])
                .sum::<f64>()
                / 3.0
                > 0.5;
            t.map(|v| if right { v + n } else { v })
        })
        .collect();
    mesh.attributes
        .channels
        .push(Channel::new(ChannelKind::TexCoord, values, corners));
    let out = simplify(
        &mesh,
        &SimplifyOptions::DEFAULT.with_target(Target::Ratio(0.1)),
    )
    .unwrap();
    let m = &out.mesh;
    let uv = m.attributes.channel(ChannelKind::TexCoord).unwrap();
    let mut seam_corners = 0;
    for (t, tri) in m.triangles.iter().enumerate() {
        let us: Vec<f32> = (0..3).map(|k| uv.at_corner(t, k).unwrap()[0]).collect();
        let left = us.iter().all(|&u| u < 0.5);
        let right = us.iter().all(|&u| u > 0.5);
        assert!(
            left ^ right,
            "triangle {t} takes uvs from both sides: {us:?}"
        );
        // Each side stays on its side of the seam (its planes hold it as a border's
        // hold a border: to within a small fraction of a grid square, 1/24).
        for &v in tri {
            let x = m.positions[v as usize][0];
            assert!(
                if left {
                    x <= 0.5 + 1e-3
                } else {
                    x >= 0.5 - 1e-3
                },
                "x {x}"
            );
            seam_corners += usize::from((x - 0.5).abs() < 1e-3);
        }
    }
    assert!(seam_corners > 0, "the seam is still there");
    assert!(m.triangle_count() <= 115, "{}", m.triangle_count());
}

#[test]
fn materials_stay_with_their_faces_and_their_border() {
    let mut mesh = grid(20);
    let faces = mesh
        .triangles
        .iter()
        .map(|t| {
            u32::from(
                t.iter()
                    .map(|&v| mesh.positions[v as usize][1])
                    .sum::<f64>()
                    / 3.0
                    > 0.5,
            )
        })
        .collect();
    mesh.attributes.materials = FaceLabels {
        names: vec![b"below".to_vec(), b"above".to_vec()],
        faces,
    };
    let out = simplify(
        &mesh,
        &SimplifyOptions::DEFAULT.with_target(Target::Ratio(0.1)),
    )
    .unwrap();
    let m = &out.mesh;
    assert_eq!(
        m.attributes.materials.names,
        mesh.attributes.materials.names
    );
    assert_eq!(m.attributes.materials.faces.len(), m.triangle_count());
    for (t, tri) in m.triangles.iter().enumerate() {
        let above = m.attributes.materials.faces[t] == 1;
        for &v in tri {
            let y = m.positions[v as usize][1];
            assert!(
                if above {
                    y >= 0.5 - 1e-3
                } else {
                    y <= 0.5 + 1e-3
                },
                "face {t}: y {y}"
            );
        }
    }
    assert!(m.triangle_count() <= 80, "{}", m.triangle_count());
}

#[test]
fn normals_stay_unit_colours_in_range_and_runs_repeat_bit_for_bit() {
    let mut mesh = grid(16);
    let normal = per_vertex(&mesh, ChannelKind::Normal, |p| {
        let n = [-0.3 * (3.0 * p[0]).cos(), 0.2 * (2.0 * p[1]).sin(), 1.0];
        let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        n.iter().map(|c| (c / l) as f32).collect()
    });
    let colour = per_vertex(&mesh, ChannelKind::Color, |p| {
        vec![p[0] as f32, (1.0 - p[1]) as f32, 0.5, 1.0]
    });
    mesh.attributes.channels.extend([normal, colour]);
    let options = SimplifyOptions::DEFAULT.with_target(Target::Ratio(0.15));
    let out = simplify(&mesh, &options).unwrap();
    let again = simplify(&mesh, &options).unwrap();
    assert_eq!(out.mesh, again.mesh);
    let a: &Attributes = &out.mesh.attributes;
    let normals = a.channel(ChannelKind::Normal).unwrap();
    for n in normals.values.chunks_exact(3) {
        let l = n.iter().map(|c| c * c).sum::<f32>().sqrt();
        assert!((l - 1.0).abs() < 1e-5, "{n:?}");
    }
    let colours = a.channel(ChannelKind::Color).unwrap();
    assert_eq!(colours.dimension, 4);
    assert!(colours.values.iter().all(|c| (0.0..=1.0).contains(c)));
    assert_eq!(out.mesh.validate(), Ok(()));
}

#[test]
fn positions_only_input_is_simplified_as_before() {
    // The same mesh with and without an (empty) attribute set: the same output.
    let mesh = grid(16);
    let options = SimplifyOptions::DEFAULT.with_target(Target::Ratio(0.2));
    let plain = simplify(&mesh, &options).unwrap();
    assert!(plain.mesh.attributes.is_empty());
    // A material that every face shares changes no geometry either: no seam anywhere.
    let mut labelled = mesh.clone();
    labelled.attributes.materials = FaceLabels {
        names: vec![b"only".to_vec()],
        faces: vec![0; mesh.triangle_count()],
    };
    let out = simplify(&labelled, &options).unwrap();
    assert_eq!(out.mesh.positions, plain.mesh.positions);
    assert_eq!(out.mesh.triangles, plain.mesh.triangles);
}

/// A UV sphere of radius 1 with `rings` × `segments` quads (the poles as fans).
fn sphere(rings: u32, segments: u32) -> IndexedMesh {
    let mut positions = vec![[0.0, 0.0, 1.0]];
    for r in 1..rings {
        let theta = std::f64::consts::PI * f64::from(r) / f64::from(rings);
        for s in 0..segments {
            let phi = 2.0 * std::f64::consts::PI * f64::from(s) / f64::from(segments);
            positions.push([
                theta.sin() * phi.cos(),
                theta.sin() * phi.sin(),
                theta.cos(),
            ]);
        }
    }
    positions.push([0.0, 0.0, -1.0]);
    let last = positions.len() as u32 - 1;
    let at = |r: u32, s: u32| 1 + (r - 1) * segments + s % segments;
    let mut triangles = Vec::new();
    for s in 0..segments {
        triangles.push([0, at(1, s), at(1, s + 1)]);
        triangles.push([last, at(rings - 1, s + 1), at(rings - 1, s)]);
    }
    for r in 1..rings - 1 {
        for s in 0..segments {
            let (a, b, c, d) = (at(r, s), at(r, s + 1), at(r + 1, s), at(r + 1, s + 1));
            triangles.push([a, c, d]);
            triangles.push([a, d, b]);
        }
    }
    IndexedMesh::new(positions, triangles)
}

#[test]
fn smooth_normals_on_a_sphere_follow_the_surface_and_cost_little_geometry() {
    // On a sphere the exact normal is the position: a field the quadric holds well.
    let mut mesh = sphere(40, 80);
    let normal = per_vertex(&mesh, ChannelKind::Normal, |p| {
        p.iter().map(|&c| c as f32).collect()
    });
    mesh.attributes.channels.push(normal);
    let options = SimplifyOptions::DEFAULT.with_target(Target::Ratio(0.1));
    let out = simplify(&mesh, &options).unwrap();
    let plain = simplify(
        &IndexedMesh::new(mesh.positions.clone(), mesh.triangles.clone()),
        &options,
    )
    .unwrap();
    let m = &out.mesh;
    let normals = m.attributes.channel(ChannelKind::Normal).unwrap();
    let mut worst: f64 = 0.0;
    for (t, tri) in m.triangles.iter().enumerate() {
        for (k, &v) in tri.iter().enumerate() {
            let p = m.positions[v as usize];
            let l = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
            let n = normals.at_corner(t, k).unwrap();
            let dot: f64 = (0..3).map(|i| f64::from(n[i]) * p[i] / l).sum();
            worst = worst.max(dot.clamp(-1.0, 1.0).acos().to_degrees());
        }
    }
    assert!(
        worst < 2.0,
        "a normal is {worst}° off its position's direction"
    );
    let measure = |x: &IndexedMesh| {
        qem_mesh::measure::measure(
            &mesh,
            x,
            &qem_mesh::measure::MeasureOptions {
                min_samples: 100_000,
                ..qem_mesh::measure::MeasureOptions::DEFAULT
            },
        )
        .unwrap()
    };
    let (with, without) = (measure(m), measure(&plain.mesh));
    assert!(
        with.mean_ab < 1.1 * without.mean_ab,
        "mean {} with normals, {} without",
        with.mean_ab,
        without.mean_ab
    );
}
