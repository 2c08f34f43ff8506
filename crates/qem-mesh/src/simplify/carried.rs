//! [`CarriedQuadrics`]: vertex quadrics carried from one run into another on the same
//! surface (the tiles of a memory budget, then the run that finishes their merged
//! mesh, [`crate::tiles::budget`]).
//!
//! Why: a mesh simplified in two runs loses the input surface between them if the
//! second run sums its quadrics from the first run's faces. On the dragon at ratio
//! 0.01, through 0.1, two runs gave a Hausdorff distance of 0.62% of the diagonal
//! against one run's 0.39%; the second run starting from the first's quadrics gave
//! 0.34% (BENCHMARKS.md, "Under a memory budget").

use crate::clean::Cleaned;
use qem_core::Quadric;

/// Each vertex's quadric in world units ([`qem_core::Frame::quadric_to_world`]), so
/// that runs in different frames add up to what one run would have summed;
/// [`NOT_CARRIED`] for a vertex whose quadric the run sums from its faces as usual.
///
/// Not `Option<Quadric>`: the run puts the carried quadrics in its vertex order in
/// place and makes them its own quadric array, so they are held once (80 bytes a
/// vertex at the setup's peak, where a separate array was measured at 70 MB more on
/// the 10M-triangle budget run).
pub(crate) type CarriedQuadrics = Vec<Quadric>;

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

/// `seed` (one per input vertex) by the cleaned mesh's vertex: the quadrics of input
/// vertices welded into one are summed; [`NOT_CARRIED`] where no input vertex has one.
pub(super) fn by_cleaned_vertex(seed: CarriedQuadrics, cleaned: &Cleaned) -> CarriedQuadrics {
    let mut summed: CarriedQuadrics = vec![NOT_CARRIED; cleaned.mesh.vertex_count()];
    for (&to, q) in cleaned.vertex_map.iter().zip(seed) {
        if let Some(sum) = summed.get_mut(to as usize).filter(|_| is_carried(&q)) {
            *sum = if is_carried(sum) { *sum + q } else { q };
        }
    }
    summed
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
    use super::super::{simplify_carrying, NoObserver, QuadricMode, SimplifyOptions, Target};
    use super::*;
    use crate::IndexedMesh;
    use qem_core::DVec3;

    /// An open, bumpy 12 x 9 grid (216 triangles), far from the origin and not unit
    /// sized, so that frames matter.
    fn bumpy_grid() -> IndexedMesh {
        let (nx, ny) = (12u32, 9u32);
        let positions = (0..=ny)
            .flat_map(|y| (0..=nx).map(move |x| (f64::from(x), f64::from(y))))
            .map(|(x, y)| {
                [
                    300.0 + 2.0 * x,
                    -40.0 + 2.0 * y,
                    7.0 + 0.4 * (x * 0.9).sin() * (y * 0.7).cos(),
                ]
            })
            .collect();
        let triangles = (0..ny)
            .flat_map(|y| (0..nx).map(move |x| y * (nx + 1) + x))
            .flat_map(|v| [[v, v + 1, v + nx + 2], [v, v + nx + 2, v + nx + 1]])
            .collect();
        IndexedMesh::new(positions, triangles)
    }

    /// `a` and `b` agree at a few points, to rounding of their size.
    fn same_quadric(a: &Quadric, b: &Quadric) -> bool {
        let points = [
            DVec3::new(300.0, -40.0, 7.0),
            DVec3::new(310.0, -30.0, 8.0),
            DVec3::new(325.0, -22.0, 6.0),
        ];
        points.iter().all(|&p| {
            let scale = (a.magnitude() + b.magnitude()) * (1.0 + p.length_squared());
            (a.evaluate(p) - b.evaluate(p)).abs() <= 1e-9 * scale
        })
    }

    /// A run that contracts nothing hands back, for each vertex, the quadric it was
    /// seeded with (through both frames and the engine's vertex order), with no
    /// border plane added on top; an unseeded vertex gets the quadric the run sums.
    #[test]
    fn a_run_hands_back_the_quadrics_it_was_seeded_with() {
        let mesh = bumpy_grid();
        let n = mesh.triangle_count();
        let options = SimplifyOptions::DEFAULT.with_target(Target::Triangles(n));
        let (_, summed) =
            simplify_carrying(mesh.clone(), &options, None, &mut NoObserver).expect("run");
        let mut seed: CarriedQuadrics = (mesh.positions.iter().enumerate())
            .map(|(i, p)| Quadric::from_point(DVec3::from_array(*p), 1.0 + i as f64))
            .collect();
        seed[5] = NOT_CARRIED;
        let (out, back) =
            simplify_carrying(mesh.clone(), &options, Some(seed.clone()), &mut NoObserver)
                .expect("run");
        assert_eq!(out.mesh.positions, mesh.positions, "nothing contracted");
        assert_eq!(back.len(), seed.len());
        for (v, (back, seed)) in back.iter().zip(&seed).enumerate() {
            let expected = if v == 5 { &summed[5] } else { seed };
            assert!(same_quadric(back, expected), "vertex {v}");
        }
    }

    /// Summed quadrics only add up: what a run hands back sums to what it started
    /// from, and a run seeded with it hands back the same sum again.
    #[test]
    fn quadrics_carried_through_two_runs_add_up_to_the_input_planes() {
        let mesh = bumpy_grid();
        let n = mesh.triangle_count();
        let sum = SimplifyOptions::DEFAULT.with_quadrics(QuadricMode::Sum);
        let total = |qs: &[Quadric]| qs.iter().copied().sum::<Quadric>();
        let (_, start) = simplify_carrying(
            mesh.clone(),
            &sum.clone().with_target(Target::Triangles(n)),
            None,
            &mut NoObserver,
        )
        .expect("run");
        let (half, first) = simplify_carrying(
            mesh,
            &sum.clone().with_target(Target::Triangles(n / 2)),
            None,
            &mut NoObserver,
        )
        .expect("run");
        assert!(half.mesh.triangle_count() <= n / 2);
        assert!(same_quadric(&total(&first), &total(&start)));
        let (quarter, second) = simplify_carrying(
            half.mesh,
            &sum.with_target(Target::Triangles(n / 4)),
            Some(first.clone()),
            &mut NoObserver,
        )
        .expect("run");
        assert!(quarter.mesh.triangle_count() <= n / 4);
        assert!(same_quadric(&total(&second), &total(&first)));
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
}
