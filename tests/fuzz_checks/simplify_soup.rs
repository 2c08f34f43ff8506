//! `simplify_soup`: arbitrary small soups and options through the whole simplifier.

use super::bytes::Bytes;
use crate::mesh_checks::assert_valid_output;
use qem_mesh::clean::{clean, CleanOptions};
use qem_mesh::simplify::{
    simplify, simplify_observed, ContractionOrder, Length, PlacementMode, QuadricMode,
    RelaxationStep, SimplifyError, SimplifyOptions, StopReason, StoreReplay, Target, Weighting,
};
use qem_mesh::IndexedMesh;

/// Scales applied to the integer grid: ordinary, and near the ends of f64's range where
/// squared lengths and areas underflow or overflow.
const SCALES: [f64; 8] = [1.0, 1e-3, 1e3, 1e-30, 1e30, 1e-150, 1e150, 1e300];

/// Offsets added after scaling: a large offset with a small scale makes vertices
/// coincide or differ only in the last bits.
const OFFSETS: [f64; 4] = [0.0, 1.0, 1e6, -1e12];

/// At most this many faces, so one run stays in the millisecond range.
const MAX_FACES: usize = 48;

/// In [`ContractionOrder::Passes`], one more option that [`SimplifyOptions::FAST`]
/// leaves off: topology preservation, or virtual pairs (the pass-based order once
/// refused both, so the seeds that ask for them are named `_refuses_`).
#[derive(Clone, Copy, Debug, PartialEq)]
enum PassesExtra {
    PreserveTopology,
    PairThreshold,
}

/// A soup of up to 16 vertices on a 5×5×5 grid (scaled and offset) and up to 48 faces,
/// with options, from fuzz bytes; and, in the pass-based order, the extra option asked
/// for, if any.
///
/// Layout: vertex count, target kind (and order) and value, option flags, pair
/// threshold, max error, virtual-pair cap, weld tolerance, scale, offset; then three
/// bytes per vertex (grid coordinates), then three per face (indices modulo the vertex
/// count).
///
/// The target kind is the low two bits of its byte. Bit 6 of that byte picks
/// [`ContractionOrder::Passes`] (with summed quadrics, no orientation check, no
/// virtual pairs and `SolveFirst` for the optimal placement, as in
/// [`SimplifyOptions::FAST`]); with it, bit 7 and bits 2–3 pick one more option: exact
/// quadrics (bits 2–3 = 0), the orientation check (1), topology preservation (2) or a
/// pair threshold (3). No committed seed from before the pass-based order
/// has bit 6 set, so each still decodes to the same greedy case.
fn decode(data: &[u8]) -> (IndexedMesh, SimplifyOptions, Option<PassesExtra>) {
    let mut b = Bytes::new(data);
    let n = 3 + b.below(14);
    let kind = b.byte();
    let passes = kind & 0x40 != 0;
    let asks = passes && kind & 0x80 != 0;
    let exact_quadrics = asks && (kind >> 2) & 3 == 0;
    let orientation = asks && (kind >> 2) & 3 == 1;
    let extra = asks.then_some(match (kind >> 2) & 3 {
        0 | 1 => None,
        2 => Some(PassesExtra::PreserveTopology),
        _ => Some(PassesExtra::PairThreshold),
    });
    let extra = extra.flatten();
    let target = match (kind % 4, b.byte()) {
        (0, x) => Target::Ratio(f64::from(x) / 255.0),
        (1, x) => Target::Triangles(usize::from(x)),
        (2, _) => Target::None,
        (_, _) => Target::Triangles(0),
    };
    let flags = b.byte();
    let flag = |bit: u8| flags & (1 << bit) != 0;
    let threshold = f64::from(b.byte()) / 256.0;
    let max_error = f64::from(b.byte()) / 1000.0;
    let cap = b.below(10);
    let tolerance = f64::from(b.byte() % 4) * 0.5;
    let scale = b.pick(&SCALES);
    let offset = b.pick(&OFFSETS);

    let length = |v: f64| {
        if flag(3) {
            Length::Absolute(v * scale)
        } else {
            Length::DiagonalFraction(v)
        }
    };
    let clean_options = CleanOptions::DEFAULT
        .with_weld_exact(!flag(4))
        .with_drop_zero_area(!flag(5))
        .with_drop_duplicates(!flag(6))
        .with_weld_tolerance(flag(7).then_some(tolerance * scale));
    // Greedy unless the seed says passes (the seeds from before the pass-based order
    // were greedy runs, the default then).
    let mut options = SimplifyOptions::DEFAULT
        .with_order(ContractionOrder::Greedy)
        .with_target(target)
        .with_placement(if flag(0) {
            PlacementMode::EndpointOrMidpoint
        } else {
            PlacementMode::Optimal
        })
        .with_weighting(match (flag(1), cap % 2) {
            (false, _) => Weighting::Area,
            (true, 0) => Weighting::Unweighted,
            // No flag bit is free: the blend takes an odd virtual-pair cap as its
            // switch and the pair threshold's byte as its mix (0 to 8).
            (true, _) => Weighting::Mixed(threshold * 8.0),
        })
        .with_max_error(flag(2).then_some(length(max_error)))
        .with_pair_threshold(length(threshold))
        .with_max_virtual_pairs_per_vertex(cap)
        .with_clean(clean_options);
    if passes {
        options = options
            .with_order(ContractionOrder::Passes)
            .with_quadrics(if exact_quadrics {
                QuadricMode::Exact
            } else {
                QuadricMode::Sum
            })
            .with_orientation_check(orientation);
        // FAST's own placement unless the input asked for the ends and midpoint (the
        // proptests of `passes_soups.rs` draw `Optimal` too).
        if options.placement == PlacementMode::Optimal {
            options = options.with_placement(PlacementMode::SolveFirst);
        }
        match extra {
            Some(PassesExtra::PreserveTopology) => options = options.with_preserve_topology(true),
            Some(PassesExtra::PairThreshold) => {} // as decoded, perhaps zero
            None => options = options.with_pair_threshold(Length::DiagonalFraction(0.0)),
        }
    }

    let positions = (0..n)
        .map(|_| [(); 3].map(|()| f64::from(b.byte() % 5) * scale + offset))
        .collect();
    let mut triangles = Vec::new();
    while !b.is_empty() && triangles.len() < MAX_FACES {
        triangles.push([(); 3].map(|()| b.below(n) as u32));
    }
    (IndexedMesh::new(positions, triangles), options, extra)
}

/// `simplify_soup`: whatever the soup and options, `simplify` gives a valid mesh with a
/// consistent report, or the documented error for an invalid or fully degenerate input;
/// replayed on the store ([`StoreReplay`]), every contraction keeps the store valid and
/// the store ends as the output; in the pass-based order no output face is flipped;
/// and a second run gives the same result bit for bit.
pub fn simplify_soup(data: &[u8]) {
    let (mesh, options, _) = decode(data);
    let passes = options.order == ContractionOrder::Passes;
    let mut replay = StoreReplay::default();
    let first = simplify_observed(&mesh, &options, &mut replay);
    if let Ok(out) = &first {
        if let Err(e) = replay.check_output(&out.mesh) {
            panic!("the store disagrees with the engine: {e}");
        }
    }
    match &first {
        Err(SimplifyError::Input(e)) => {
            assert_eq!(mesh.validate(), Err(e.clone()), "refused a valid input");
        }
        Err(SimplifyError::NothingLeftAfterCleaning { triangles_in }) => {
            assert_eq!(*triangles_in, mesh.triangle_count());
            // With the zero-area pass off, zero-area faces enter the loop and may be all
            // that is left at the end (documented on the error).
            assert!(
                clean(&mesh, &options.clean).mesh.triangles.is_empty()
                    || !options.clean.drop_zero_area,
                "refused an input with triangles left after cleaning"
            );
        }
        Err(e) => panic!("unexpected error: {e}"),
        Ok(out) => {
            assert_valid_output(&out.mesh, mesh.triangle_count());
            let r = &out.report;
            assert_eq!(r.triangles_in, mesh.triangle_count());
            assert_eq!(r.vertices_in, mesh.vertex_count());
            assert_eq!(r.triangles_out, out.mesh.triangle_count());
            assert_eq!(r.vertices_out, out.mesh.vertex_count());
            assert!(
                r.max_error >= 0.0 && r.max_error.is_finite(),
                "max_error {}",
                r.max_error
            );
            assert!(r.max_error_abs >= 0.0, "max_error_abs {}", r.max_error_abs);
            if r.stop_reason == StopReason::TargetReached {
                assert!(r.triangles_out <= r.target_triangles, "{r:?}");
            }
            if options.pair_threshold == Length::DiagonalFraction(0.0) || options.preserve_topology
            {
                assert_eq!(r.virtual_contractions, 0);
            }
            // The fold-over check's default 90° limit also refuses a face turned more
            // than 90° from the input face it descends from, unless a stuck run took
            // the ladder of relaxations' last step.
            let flips_allowed = r
                .relaxations
                .iter()
                .any(|x| x.step == RelaxationStep::FlippedFaces && x.contractions > 0);
            if passes && !flips_allowed {
                assert_eq!(r.faces_flipped, 0, "{r:?}");
            }
        }
    }
    let second = simplify(&mesh, &options);
    match (first, second) {
        (Ok(a), Ok(b)) => {
            assert_eq!(a.mesh.triangles, b.mesh.triangles, "triangles differ");
            let bits = |m: &IndexedMesh| -> Vec<[u64; 3]> {
                m.positions.iter().map(|p| p.map(f64::to_bits)).collect()
            };
            assert_eq!(bits(&a.mesh), bits(&b.mesh), "positions differ");
            let (mut ra, mut rb) = (a.report, b.report);
            ra.timings = Default::default();
            rb.timings = Default::default();
            assert_eq!(ra.max_error.to_bits(), rb.max_error.to_bits());
            assert_eq!(format!("{ra:?}"), format!("{rb:?}"), "reports differ");
        }
        (Err(a), Err(b)) => assert_eq!(a, b),
        (a, b) => panic!("two runs disagree: {a:?} then {b:?}"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    /// The committed seeds, by file name.
    fn seeds() -> Vec<(String, Vec<u8>)> {
        let mut seeds = Vec::new();
        for kind in ["corpus", "regressions"] {
            let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("../fuzz")
                .join(kind)
                .join("simplify_soup");
            for entry in std::fs::read_dir(&dir).expect("the committed seeds") {
                let path = entry.expect("a directory entry").path();
                let name = path.file_name().expect("a file").to_string_lossy().into();
                seeds.push((name, std::fs::read(&path).expect("a readable seed")));
            }
        }
        seeds.sort();
        seeds
    }

    /// The seeds from before the pass-based order still decode to greedy runs (the
    /// format stayed compatible); those named `_passes` run in passes (with the
    /// orientation check when named `_orientation_check`, with exact quadrics when
    /// named `_exact_quadrics`), and those named `_refuses_` ask for the option they
    /// name (which that order once refused).
    #[test]
    fn seeds_decode_to_the_order_their_name_says() {
        let seeds = seeds();
        assert!(seeds.iter().filter(|(n, _)| n.contains("_passes")).count() >= 6);
        for (name, data) in seeds {
            let (_, options, extra) = decode(&data);
            let want = if name.contains("_passes") {
                ContractionOrder::Passes
            } else {
                ContractionOrder::Greedy
            };
            assert_eq!(options.order, want, "{name}");
            assert_eq!(
                options.orientation_check,
                want == ContractionOrder::Greedy || name.contains("_orientation_check"),
                "{name}"
            );
            if want == ContractionOrder::Passes {
                let exact = options.quadrics == QuadricMode::Exact;
                assert_eq!(exact, name.contains("_exact_quadrics"), "{name}");
            }
            if let Some((_, what)) = name.split_once("_refuses_") {
                let asked = match what {
                    "preserve_topology" => PassesExtra::PreserveTopology,
                    "pair_threshold" => PassesExtra::PairThreshold,
                    _ => panic!("{name}: refuses what?"),
                };
                assert_eq!(extra, Some(asked), "{name}");
            }
        }
    }
}
