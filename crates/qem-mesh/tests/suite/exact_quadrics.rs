//! Exact quadrics (`QuadricMode::Exact`) against brute force: every contraction's
//! quadric must be the sum of the planes whose support meets the union of the two
//! vertex groups, each plane once, and its cost the brute-force sum of squared plane
//! distances at the chosen point — through whole simplifications, virtual pairs
//! included, in both contraction orders (the pass-based one keeps its planes
//! differently, see `simplify/pass_exact.rs`).
//!
//! The observer rebuilds the plane set from the cleaned mesh the engine reports, in the
//! frame it reports: one plane per face (support: its three corners) and, with border
//! planes on, one per border edge (support: its two ends), and follows the groups from
//! the `(kept, removed)` indices of each contraction.
//!
//! Tolerance: 1e-9 relative to the quadric's scale — its largest coefficient for the
//! coefficients, and that times `1 + |p|²` for the cost (the size of the terms that
//! cancel when a quadric is evaluated at `p`; the cost itself can be ~0 on flat parts,
//! where no relative test on the cost alone is meaningful).

use crate::common;

use common::{concat, grid};
use proptest::prelude::*;
use qem_core::{DVec3, Frame, Quadric};
use qem_mesh::simplify::{
    simplify_observed, BoundaryMode, Contraction, ContractionOrder, Length, Observer, QuadricMode,
    SimplifyOptions, Target, Weighting,
};
use qem_mesh::IndexedMesh;
use std::collections::HashMap;

const TOLERANCE: f64 = 1e-9;

/// A plane and the cleaned-mesh vertices it belongs to.
struct Plane {
    support: Vec<u32>,
    quadric: Quadric,
}

/// Tracks explicit plane sets and checks every contraction against them.
struct BruteForce {
    boundary_weight: Option<f64>,
    weighting: Weighting,
    planes: Vec<Plane>,
    /// Plane indices per cleaned vertex.
    incident: Vec<Vec<usize>>,
    /// The original vertices each current vertex stands for.
    groups: Vec<Vec<u32>>,
    /// Per plane: the contraction at which it was last counted (dedup without a set).
    seen: Vec<usize>,
    contractions: usize,
    virtual_contractions: usize,
    worst: f64,
    failures: Vec<String>,
}

impl BruteForce {
    fn new(options: &SimplifyOptions) -> Self {
        BruteForce {
            boundary_weight: match options.boundary {
                BoundaryMode::Planes(w) => Some(w),
                _ => None,
            },
            weighting: options.weighting,
            planes: Vec::new(),
            incident: Vec::new(),
            groups: Vec::new(),
            seen: Vec::new(),
            contractions: 0,
            virtual_contractions: 0,
            worst: 0.0,
            failures: Vec::new(),
        }
    }

    fn add(&mut self, support: Vec<u32>, quadric: Quadric) {
        for &v in &support {
            self.incident[v as usize].push(self.planes.len());
        }
        self.planes.push(Plane { support, quadric });
    }
}

impl Observer for BruteForce {
    fn cleaned(&mut self, mesh: &IndexedMesh, frame: &Frame) {
        let p = |i: u32| frame.to_normalized(DVec3::from_array(mesh.positions[i as usize]));
        self.incident = vec![Vec::new(); mesh.vertex_count()];
        self.groups = (0..mesh.vertex_count() as u32).map(|i| vec![i]).collect();
        let mut edge_faces: HashMap<(u32, u32), Vec<usize>> = HashMap::new();
        // Weighting::Mixed(s) adds s times the mean face area to every face's weight
        // (and to the border planes' |edge|²).
        let area = |t: &[u32; 3]| {
            let (a, b, c) = (p(t[0]), p(t[1]), p(t[2]));
            0.5 * (b - a).cross(c - a).length()
        };
        let mean_area =
            mesh.triangles.iter().map(area).sum::<f64>() / mesh.triangles.len().max(1) as f64;
        let offset = match self.weighting {
            Weighting::Mixed(s) => s * mean_area,
            _ => 0.0,
        };
        for (f, t) in mesh.triangles.iter().enumerate() {
            let (a, b, c) = (p(t[0]), p(t[1]), p(t[2]));
            let q = match self.weighting {
                Weighting::Area => Quadric::from_triangle(a, b, c),
                Weighting::Unweighted => Quadric::from_triangle_unweighted(a, b, c),
                Weighting::Mixed(_) => {
                    let unit = Quadric::from_triangle_unweighted(a, b, c);
                    unit * (area(t) + offset)
                }
            };
            self.add(t.to_vec(), q);
            for i in 0..3 {
                let (x, y) = (t[i], t[(i + 1) % 3]);
                edge_faces.entry((x.min(y), x.max(y))).or_default().push(f);
            }
        }
        if let Some(w) = self.boundary_weight {
            let mut borders: Vec<_> = edge_faces
                .into_iter()
                .filter(|(_, f)| f.len() == 1)
                .collect();
            borders.sort();
            for ((x, y), faces) in borders {
                let t = mesh.triangles[faces[0]];
                let (a, b, c) = (p(t[0]), p(t[1]), p(t[2]));
                let normal = (b - a).cross(c - a).normalize_or_zero();
                let weight = match self.weighting {
                    Weighting::Area => w * p(x).distance_squared(p(y)),
                    Weighting::Unweighted => w,
                    Weighting::Mixed(_) => w * (p(x).distance_squared(p(y)) + offset),
                };
                self.add(
                    vec![x, y],
                    Quadric::boundary_constraint(p(x), p(y), normal, weight),
                );
            }
        }
        self.seen = vec![usize::MAX; self.planes.len()];
    }

    fn contracted(&mut self, c: &Contraction) {
        self.contractions += 1;
        if c.is_virtual {
            self.virtual_contractions += 1;
        }
        let removed = std::mem::take(&mut self.groups[c.removed as usize]);
        self.groups[c.kept as usize].extend(removed);
        // Brute force over the union: each plane meeting the group, once.
        let mut quadric = Quadric::ZERO;
        let mut cost = 0.0;
        let mut count = 0;
        for &v in &self.groups[c.kept as usize] {
            for &i in &self.incident[v as usize] {
                if self.seen[i] != self.contractions {
                    self.seen[i] = self.contractions;
                    quadric += self.planes[i].quadric;
                    cost += self.planes[i].quadric.evaluate(c.position).max(0.0);
                    count += 1;
                }
            }
        }
        let scale = quadric.magnitude().max(f64::MIN_POSITIVE);
        let coefficient_error = quadric
            .entries()
            .iter()
            .zip(c.quadric.entries())
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max)
            / scale;
        let cost_error = (cost - c.cost).abs() / (scale * (1.0 + c.position.length_squared()));
        self.worst = self.worst.max(coefficient_error).max(cost_error);
        if (coefficient_error > TOLERANCE || cost_error > TOLERANCE) && self.failures.len() < 5 {
            self.failures.push(format!(
                "contraction {} ({} <- {}, virtual {}, {count} planes, supports of the first: \
                 {:?}): coefficient error {coefficient_error:e}, cost error {cost_error:e} \
                 (cost {} vs brute force {cost})",
                self.contractions,
                c.kept,
                c.removed,
                c.is_virtual,
                self.planes.first().map(|p| &p.support),
                c.cost,
            ));
        }
    }
}

fn run(mesh: &IndexedMesh, options: &SimplifyOptions) -> BruteForce {
    let mut brute = BruteForce::new(options);
    // Errors (an all-degenerate soup) are fine: nothing was contracted.
    let _ = simplify_observed(mesh, options, &mut brute);
    brute
}

/// Strict: the faces the ladder of relaxations merges away drop out of the exact
/// bookkeeping (see `pass_exact`'s doc), which the brute force rightly flags.
fn exact(target: f64) -> SimplifyOptions {
    SimplifyOptions::DEFAULT
        .with_quadrics(QuadricMode::Exact)
        .with_target(Target::Ratio(target))
        .with_strict(true)
}

#[test]
fn bumpy_grid_with_borders_matches_brute_force_to_the_end() {
    let mesh = grid(12, 9, 0.4);
    let brute = run(&mesh, &exact(0.0));
    assert!(brute.failures.is_empty(), "{:#?}", brute.failures);
    // 216 faces down to the last ones: nearly every vertex was merged.
    assert!(
        brute.contractions > 100,
        "{} contractions",
        brute.contractions
    );
}

/// [`SimplifyOptions::FAST`] with exact quadrics down to `target`.
fn exact_passes(target: f64) -> SimplifyOptions {
    SimplifyOptions::FAST
        .with_quadrics(QuadricMode::Exact)
        .with_target(Target::Ratio(target))
        .with_strict(true)
}

#[test]
fn bumpy_grid_with_borders_matches_brute_force_to_the_end_in_passes() {
    let mesh = grid(12, 9, 0.4);
    let brute = run(&mesh, &exact_passes(0.0));
    assert!(brute.failures.is_empty(), "{:#?}", brute.failures);
    assert!(
        brute.contractions > 100,
        "{} contractions",
        brute.contractions
    );
}

/// 151 × 121 = 18,271 vertices: more than one block of `simplify/pass_blocks.rs`
/// (16,384 vertex numbers), so most pairs of each round are contracted block by block,
/// with their changes to the planes made after the blocks; every contraction must still
/// match the brute-force union, with the orientation check on as well.
#[test]
fn a_grid_of_several_blocks_matches_brute_force_in_passes() {
    let mesh = grid(150, 120, 0.4);
    for check in [false, true] {
        let options = exact_passes(0.1).with_orientation_check(check);
        let brute = run(&mesh, &options);
        assert!(
            brute.failures.is_empty(),
            "{:#?}",
            &brute.failures[..5.min(brute.failures.len())]
        );
        assert!(
            brute.contractions > 14_000,
            "{} contractions",
            brute.contractions
        );
    }
}

#[test]
fn the_sum_mode_double_counts_in_passes_too() {
    let mesh = grid(6, 6, 0.4);
    let brute = run(&mesh, &exact_passes(0.5).with_quadrics(QuadricMode::Sum));
    assert!(!brute.failures.is_empty());
}

#[test]
fn two_sheets_merging_through_virtual_pairs_match_brute_force() {
    // Two bumpy sheets 0.05 apart, one above the other: virtual pairs join them.
    let lower = grid(6, 6, 0.1);
    let mut upper = grid(6, 6, 0.1);
    for p in &mut upper.positions {
        p[2] += 0.05;
        p[0] += 0.3;
    }
    let mesh = concat(&[lower, upper]);
    let options = exact(0.05).with_pair_threshold(Length::DiagonalFraction(0.05));
    let brute = run(&mesh, &options);
    assert!(brute.failures.is_empty(), "{:#?}", brute.failures);
    assert!(
        brute.virtual_contractions > 0,
        "no virtual pair was contracted"
    );
}

#[test]
fn the_sum_mode_double_counts_and_the_brute_force_notices() {
    // The checker must be able to fail: Garland–Heckbert's sum counts the two faces of
    // the first contracted interior edge twice.
    let mesh = grid(6, 6, 0.4);
    let options = exact(0.5).with_quadrics(QuadricMode::Sum);
    let brute = run(&mesh, &options);
    assert!(!brute.failures.is_empty());
}

fn soup(max_vertices: usize) -> impl Strategy<Value = IndexedMesh> {
    (3..max_vertices).prop_flat_map(|n| {
        let positions = prop::collection::vec(prop::array::uniform3(0..4i32), n);
        let triangles = prop::collection::vec(prop::array::uniform3(0..n as u32), 1..40);
        (positions, triangles).prop_map(|(p, t)| {
            IndexedMesh::new(p.into_iter().map(|c| c.map(f64::from)).collect(), t)
        })
    })
}

fn bumpy_parts() -> impl Strategy<Value = IndexedMesh> {
    (
        prop::collection::vec((1..6u32, 1..6u32, -0.5..0.5f64, -1.0..1.0f64), 1..4),
        prop::collection::vec(-0.3..0.3f64, 0..60),
    )
        .prop_map(|(parts, jitter)| {
            let meshes: Vec<IndexedMesh> = parts
                .iter()
                .map(|&(nx, ny, h, dz)| {
                    let mut g = grid(nx, ny, h);
                    for (i, p) in g.positions.iter_mut().enumerate() {
                        p[2] += dz + jitter.get(i).copied().unwrap_or(0.0);
                    }
                    g
                })
                .collect();
            concat(&meshes)
        })
}

fn options() -> impl Strategy<Value = SimplifyOptions> {
    (
        0.0..0.8f64,
        prop_oneof![Just(0.0), 0.0..0.4f64],
        prop_oneof![
            Just(BoundaryMode::Free),
            (0.1..100.0f64).prop_map(BoundaryMode::Planes)
        ],
        prop_oneof![
            Just(Weighting::Area),
            Just(Weighting::Unweighted),
            (0.0..10.0f64).prop_map(Weighting::Mixed)
        ],
        any::<bool>(),
    )
        .prop_map(|(r, t, boundary, weighting, topology)| {
            exact(r)
                .with_pair_threshold(Length::DiagonalFraction(t))
                .with_boundary(boundary)
                .with_weighting(weighting)
                .with_preserve_topology(topology)
        })
}

/// [`options`], but in the pass-based order (no virtual pairs, no topology
/// preservation: it refuses both), with its own placement.
fn passes_options() -> impl Strategy<Value = SimplifyOptions> {
    (options(), any::<bool>()).prop_map(|(o, orientation)| {
        o.with_order(ContractionOrder::Passes)
            .with_pair_threshold(Length::DiagonalFraction(0.0))
            .with_preserve_topology(false)
            .with_placement(SimplifyOptions::FAST.placement)
            .with_orientation_check(orientation)
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// The same in the pass-based order: collapsed triangles and border planes kept as
    /// segments, followed through later contractions.
    #[test]
    fn every_contraction_in_passes_matches_the_brute_force_union(
        mesh in prop_oneof![soup(30), bumpy_parts()], o in passes_options()
    ) {
        let brute = run(&mesh, &o);
        prop_assert!(brute.failures.is_empty(), "{:#?}", brute.failures);
        prop_assert!(brute.worst <= TOLERANCE);
    }

    /// Messy soups (fins, merged duplicate faces and edges, wire edges) and stacked
    /// bumpy sheets (borders, virtual pairs): every contraction matches brute force.
    #[test]
    fn every_contraction_matches_the_brute_force_union(
        mesh in prop_oneof![soup(30), bumpy_parts()], o in options()
    ) {
        let brute = run(&mesh, &o);
        prop_assert!(brute.failures.is_empty(), "{:#?}", brute.failures);
        prop_assert!(brute.worst <= TOLERANCE);
    }
}
