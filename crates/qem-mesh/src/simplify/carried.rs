//! [`CarriedQuadrics`]: vertex quadrics carried from one run into another on the same
//! surface (the tiles of a memory budget, then the run that finishes their merged
//! mesh, `tiles::budget`, feature `io`).
//!
//! Why: a mesh simplified in two runs loses the input surface between them if the
//! second run sums its quadrics from the first run's faces. On the dragon at ratio
//! 0.01, through 0.1, two runs gave a Hausdorff distance of 0.62% of the diagonal
//! against one run's 0.39%; the second run starting from the first's quadrics gave
//! 0.34% (BENCHMARKS.md, "Under a memory budget").

use qem_core::{DVec3, Quadric};

/// Vertex quadrics in world units about `origin` ([`qem_core::Frame::quadric_to_world`]),
/// so that runs in different frames add up to what one run would have summed.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct CarriedQuadrics {
    /// The point the quadrics are about, in world units: near the mesh, so that they
    /// keep their precision whatever its coordinates (the tiles of a split use the
    /// centre of their centroids' box, `tiles::jobs::Manifest::quadric_origin`).
    pub origin: DVec3,
    /// One per vertex; [`NOT_CARRIED`] for a vertex whose quadric the run sums from
    /// its faces as usual.
    ///
    /// Quadrics rather than `Option`s: the run puts them in its vertex order in place
    /// and makes them its own quadric array, so the engine never holds them twice (a
    /// separate array was measured at 70 MB more at the setup's peak on the 10M
    /// budget run).
    pub quadrics: Vec<Quadric>,
}

/// The entry of a vertex with no carried quadric: NaN entries, which no quadric of
/// finite planes has.
pub(crate) const NOT_CARRIED: Quadric = Quadric {
    xx: f64::NAN,
    xy: f64::NAN,
    xz: f64::NAN,
    yy: f64::NAN,
    yz: f64::NAN,
    zz: f64::NAN,
    x: f64::NAN,
    y: f64::NAN,
    z: f64::NAN,
    c: f64::NAN,
};

/// Whether `q` is a carried quadric (not [`NOT_CARRIED`]).
#[inline]
pub(crate) fn is_carried(q: &Quadric) -> bool {
    !q.c.is_nan()
}

/// `seed` (one per vertex of a mesh) by the vertex of its cleaned mesh, of `n`
/// vertices, where `map` ([`Cleaned::vertex_map`](crate::clean::Cleaned::vertex_map)) takes each vertex: the quadrics of
/// vertices welded into one are summed, those of vertices the cleaning removed
/// ([`Cleaned::REMOVED`](crate::clean::Cleaned::REMOVED)) dropped; a cleaned vertex is [`NOT_CARRIED`] when any of its
/// vertices is not (its faces' planes would be lost in the carried ones' quadric: the
/// run sums its quadric from its faces instead). When the cleaning merged and dropped
/// nothing, the seed is returned as it is, not copied. (Both ways: a run's input
/// vertices into its cleaned mesh, and its output's before the output's cleaning.)
pub(super) fn by_cleaned_vertex(seed: CarriedQuadrics, map: &[u32], n: usize) -> CarriedQuadrics {
    if map.len() == n && map.iter().enumerate().all(|(i, &to)| to as usize == i) {
        return seed;
    }
    let mut summed = vec![Quadric::ZERO; n];
    for (&to, q) in map.iter().zip(seed.quadrics) {
        if let Some(sum) = summed.get_mut(to as usize) {
            *sum = if is_carried(&q) {
                *sum + q
            } else {
                NOT_CARRIED
            };
        }
    }
    CarriedQuadrics {
        origin: seed.origin,
        quadrics: summed,
    }
}

/// Reorders `values` in place so that place `v` holds what place `from[v]` held, when
/// `from` is a permutation of the places (else leaves them and returns `false`). One
/// flag a place besides.
pub(super) fn gather_in_place<T: Copy>(values: &mut [T], from: &[u32]) -> bool {
    let n = values.len();
    if from.len() != n {
        return false;
    }
    let mut seen = vec![false; n];
    for &f in from {
        match seen.get_mut(f as usize) {
            Some(s) if !*s => *s = true,
            _ => return false,
        }
    }
    // Each cycle of the permutation in turn: place j takes from[j]'s value, the first
    // place's value saved to close the cycle.
    let mut done = seen;
    done.fill(false);
    for start in 0..n {
        if done[start] {
            continue;
        }
        let first = values[start];
        let mut j = start;
        loop {
            done[j] = true;
            let k = from[j] as usize;
            if k == start {
                values[j] = first;
                break;
            }
            values[j] = values[k];
            j = k;
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::super::{
        simplify_carrying, NoObserver, QuadricMode, SimplifyOptions, Target, Weighting,
    };
    use super::*;
    use crate::IndexedMesh;

    /// An open, bumpy `nx` x `ny` grid of squares 2 units wide from `corner`, so that
    /// frames matter.
    fn bumpy_grid(nx: u32, ny: u32, corner: DVec3) -> IndexedMesh {
        let positions = (0..=ny)
            .flat_map(|y| (0..=nx).map(move |x| (f64::from(x), f64::from(y))))
            .map(|(x, y)| {
                let p =
                    corner + DVec3::new(2.0 * x, 2.0 * y, 0.4 * (x * 0.9).sin() * (y * 0.7).cos());
                p.to_array()
            })
            .collect();
        let triangles = (0..ny)
            .flat_map(|y| (0..nx).map(move |x| y * (nx + 1) + x))
            .flat_map(|v| [[v, v + 1, v + nx + 2], [v, v + nx + 2, v + nx + 1]])
            .collect();
        IndexedMesh::new(positions, triangles)
    }

    const CORNER: DVec3 = DVec3::new(300.0, -40.0, 7.0);

    /// `a` and `b` (about the same origin, at the grid's corner) agree at a few points
    /// of the grid, to rounding of what they measure there.
    fn same_quadric(a: &Quadric, b: &Quadric) -> bool {
        let points = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(10.0, 10.0, 1.0),
            DVec3::new(25.0, 18.0, -1.0),
        ];
        points.iter().all(|&p| {
            let scale = (a.magnitude() + b.magnitude()) * (1.0 + p.length_squared());
            (a.evaluate(p) - b.evaluate(p)).abs() <= 1e-9 * scale
        })
    }

    /// Runs `mesh` to `target` triangles, seeded with `seed`, handing back about the
    /// grid's corner.
    fn run(
        mesh: &IndexedMesh,
        options: &SimplifyOptions,
        target: usize,
        seed: Option<CarriedQuadrics>,
        corner: DVec3,
    ) -> (IndexedMesh, CarriedQuadrics) {
        let options = options.clone().with_target(Target::Triangles(target));
        let (out, back) = simplify_carrying(mesh.clone(), &options, seed, corner, &mut NoObserver)
            .expect("simplifies");
        (out.mesh, back)
    }

    #[test]
    fn gathering_in_place_is_indexing_by_the_permutation() {
        let values: Vec<u32> = (100..110).collect();
        let from = [3, 0, 9, 1, 2, 5, 4, 8, 7, 6];
        let mut gathered = values.clone();
        assert!(gather_in_place(&mut gathered, &from));
        let indexed: Vec<u32> = from.iter().map(|&f| values[f as usize]).collect();
        assert_eq!(gathered, indexed);
        // Not a permutation: a repeat, a place out of range, another length.
        for bad in [&[0, 0, 1][..], &[0, 1, 3], &[0, 1]] {
            let mut three = vec![1, 2, 3];
            assert!(!gather_in_place(&mut three, bad));
            assert_eq!(three, vec![1, 2, 3]);
        }
    }

    /// The cleaning's weld sums the carried quadrics of the input vertices it merges,
    /// and a vertex merged with one that carries none carries none (the run then sums
    /// its quadric from its faces, which the uncarried vertex's planes are among).
    #[test]
    fn welded_vertices_sum_their_quadrics_and_an_uncarried_one_wins() {
        use crate::clean::{clean, CleanOptions, Cleaned};
        // Two triangles of a soup sharing an edge: inputs 1 and 4, and 2 and 3, are
        // the same points.
        let soup = IndexedMesh::new(
            vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [0.0, 1.0, 0.0],
                [1.0, 0.0, 0.0],
                [1.0, 1.0, 0.0],
            ],
            vec![[0, 1, 2], [3, 4, 5]],
        );
        let cleaned = clean(&soup, &CleanOptions::DEFAULT);
        assert_eq!(cleaned.mesh.vertex_count(), 4);
        let map = &cleaned.vertex_map;
        assert_eq!((map[1], map[2]), (map[4], map[3]));
        let point = |i: usize| Quadric::from_point(DVec3::from_array(soup.positions[i]), 1.0);
        let mut quadrics: Vec<Quadric> = (0..6).map(point).collect();
        quadrics[3] = NOT_CARRIED;
        let seed = CarriedQuadrics {
            origin: DVec3::ZERO,
            quadrics,
        };
        let by_cleaned = by_cleaned_vertex(seed.clone(), map, cleaned.mesh.vertex_count());
        assert_eq!(by_cleaned.quadrics.len(), 4);
        assert_eq!(by_cleaned.quadrics[map[1] as usize], point(1) + point(4));
        assert!(!is_carried(&by_cleaned.quadrics[map[2] as usize]));
        assert_eq!(by_cleaned.quadrics[map[0] as usize], point(0));
        // Nothing merged: the seed as it is.
        let welded = cleaned.mesh.clone();
        let again = clean(&welded, &CleanOptions::DEFAULT);
        let seed = CarriedQuadrics {
            origin: DVec3::ZERO,
            quadrics: (0..4).map(point).collect(),
        };
        assert_eq!(
            by_cleaned_vertex(seed.clone(), &again.vertex_map, again.mesh.vertex_count()),
            seed
        );
        // A vertex the cleaning removed is dropped.
        let removed = [0, Cleaned::REMOVED, 1];
        let seed = CarriedQuadrics {
            origin: DVec3::ZERO,
            quadrics: (0..3).map(point).collect(),
        };
        let kept = by_cleaned_vertex(seed, &removed, 2).quadrics;
        assert_eq!(kept, vec![point(0), point(2)]);
    }

    /// A run that contracts nothing hands back, for each vertex, the quadric it was
    /// seeded with (through both frames and the engine's vertex order), with no
    /// border plane added on top; an unseeded vertex gets the quadric the run sums
    /// (with area weights: a mixed weighting's offset is the mean area of the faces
    /// summed, here those around vertex 5 only).
    #[test]
    fn a_run_hands_back_the_quadrics_it_was_seeded_with() {
        let mesh = bumpy_grid(12, 9, CORNER);
        let n = mesh.triangle_count();
        let options = SimplifyOptions::DEFAULT.with_weighting(Weighting::Area);
        let (_, summed) = run(&mesh, &options, n, None, CORNER);
        let mut seed = CarriedQuadrics {
            origin: CORNER,
            quadrics: (mesh.positions.iter().enumerate())
                .map(|(i, p)| Quadric::from_point(DVec3::from_array(*p) - CORNER, 1.0 + i as f64))
                .collect(),
        };
        seed.quadrics[5] = NOT_CARRIED;
        let (out, back) = run(&mesh, &options, n, Some(seed.clone()), CORNER);
        assert_eq!(out.positions, mesh.positions, "nothing contracted");
        assert_eq!(back.quadrics.len(), seed.quadrics.len());
        for (v, (back, seed)) in back.quadrics.iter().zip(&seed.quadrics).enumerate() {
            let expected = if v == 5 { &summed.quadrics[5] } else { seed };
            assert!(same_quadric(back, expected), "vertex {v}");
        }
    }

    /// Summed quadrics only add up: what a run hands back sums to what it started
    /// from, and a run seeded with it hands back the same sum again.
    #[test]
    fn quadrics_carried_through_two_runs_add_up_to_the_input_planes() {
        let mesh = bumpy_grid(12, 9, CORNER);
        let n = mesh.triangle_count();
        let sum = SimplifyOptions::DEFAULT.with_quadrics(QuadricMode::Sum);
        let total = |c: &CarriedQuadrics| c.quadrics.iter().copied().sum::<Quadric>();
        let (_, start) = run(&mesh, &sum, n, None, CORNER);
        let (half, first) = run(&mesh, &sum, n / 2, None, CORNER);
        assert!(half.triangle_count() <= n / 2);
        assert!(same_quadric(&total(&first), &total(&start)));
        let (quarter, second) = run(&half, &sum, n / 4, Some(first.clone()), CORNER);
        assert!(quarter.triangle_count() <= n / 4);
        assert!(same_quadric(&total(&second), &total(&first)));
    }

    /// Far from zero (a scan in georeferenced coordinates), a run seeded with the
    /// quadrics it would sum itself makes the same contractions as without the seed:
    /// the quadrics about an origin near the mesh keep their precision.
    #[test]
    fn far_from_zero_a_run_seeded_with_its_own_quadrics_is_the_same_run() {
        let corner = DVec3::new(3.0e6, -5.0e6, 1.0e5);
        let mesh = bumpy_grid(12, 9, corner);
        let n = mesh.triangle_count();
        let sum = SimplifyOptions::DEFAULT.with_quadrics(QuadricMode::Sum);
        let (_, own) = run(&mesh, &sum, n, None, corner);
        let (plain, _) = run(&mesh, &sum, n / 3, None, corner);
        let (seeded, _) = run(&mesh, &sum, n / 3, Some(own), corner);
        assert_eq!(seeded.triangles, plain.triangles);
        for (a, b) in seeded.positions.iter().zip(&plain.positions) {
            let d = DVec3::from_array(*a).distance(DVec3::from_array(*b));
            assert!(d <= 1e-6, "{a:?} against {b:?}");
        }
    }

    /// A vertex inside a part of a mesh gets the quadric it has in the whole mesh,
    /// though the part's run has another frame: with area weights (which scale with
    /// the frame) and with unit weights (which do not).
    #[test]
    fn an_inner_vertex_of_a_part_carries_its_quadric_in_the_whole() {
        let whole = bumpy_grid(24, 18, CORNER);
        let part = bumpy_grid(12, 9, CORNER);
        // Vertex (6, 4): inside both, away from every border.
        let (in_whole, in_part) = (4 * 25 + 6, 4 * 13 + 6);
        assert_eq!(whole.positions[in_whole], part.positions[in_part]);
        for weighting in [Weighting::Area, Weighting::Unweighted] {
            let options = SimplifyOptions::DEFAULT.with_weighting(weighting);
            let (_, w) = run(&whole, &options, whole.triangle_count(), None, CORNER);
            let (_, p) = run(&part, &options, part.triangle_count(), None, CORNER);
            assert!(
                same_quadric(&w.quadrics[in_whole], &p.quadrics[in_part]),
                "{weighting:?}"
            );
        }
    }
}
