//! `simplify_soup`: arbitrary small soups and options through the whole simplifier.

use super::bytes::Bytes;
use crate::mesh_checks::assert_valid_output;
use qem_mesh::clean::{clean, CleanOptions};
use qem_mesh::simplify::{
    simplify, Length, PlacementMode, SimplifyError, SimplifyOptions, StopReason, Target, Weighting,
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

/// A soup of up to 16 vertices on a 5×5×5 grid (scaled and offset) and up to 48 faces,
/// with options, from fuzz bytes.
///
/// Layout: vertex count, target kind and value, option flags, pair threshold, max
/// error, virtual-pair cap, weld tolerance, scale, offset; then three bytes per vertex
/// (grid coordinates), then three per face (indices modulo the vertex count).
fn decode(data: &[u8]) -> (IndexedMesh, SimplifyOptions) {
    let mut b = Bytes::new(data);
    let n = 3 + b.below(14);
    let target = match (b.below(4), b.byte()) {
        (0, x) => Target::Ratio(f64::from(x) / 255.0),
        (1, x) => Target::Triangles(usize::from(x)),
        (2, _) => Target::None,
        (_, _) => Target::Ratio(0.0),
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
    let options = SimplifyOptions::DEFAULT
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
        .with_clean(clean_options)
        .with_validate_each_contraction(true);

    let positions = (0..n)
        .map(|_| [(); 3].map(|()| f64::from(b.byte() % 5) * scale + offset))
        .collect();
    let mut triangles = Vec::new();
    while !b.is_empty() && triangles.len() < MAX_FACES {
        triangles.push([(); 3].map(|()| b.below(n) as u32));
    }
    (IndexedMesh::new(positions, triangles), options)
}

/// `simplify_soup`: whatever the soup and options, `simplify` gives a valid mesh with a
/// consistent report, or the documented error for an invalid or fully degenerate input;
/// the store's invariants hold after every contraction; and a second run gives the same
/// result bit for bit.
pub fn simplify_soup(data: &[u8]) {
    let (mesh, options) = decode(data);
    let first = simplify(&mesh, &options);
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
            if options.pair_threshold == Length::DiagonalFraction(0.0) {
                assert_eq!(r.virtual_contractions, 0);
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
