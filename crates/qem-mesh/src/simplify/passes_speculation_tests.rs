//! Tests that speculating a round (`Engine::speculate`) gives the sequential
//! order's output, bit for bit: a thin lens, with counts of reused and re-asked
//! verdicts; then adversarial inputs, with every option the pass-based order takes
//! and the orientation check on, through the same setup as `simplify_levels`
//! (cleaning, locked vertices renumbered, the frame of the cleaned mesh), on 1, 2
//! and 4 threads.

use super::*;
use crate::clean::{clean, CleanOptions, Cleaned};
use crate::simplify::observer::NoObserver;
use crate::simplify::{Length, PlacementMode, Weighting};
use proptest::prelude::*;

/// A UV sphere squashed to a thin lens (height 0.04 of its width) with a
/// deterministic wobble: at ratio 0.05 the rim's faces come near input faces of the
/// other side, so the orientation check refuses pairs.
/// `--fast --quadrics exact --orientation-check`: every default quality option in
/// the pass-based order.
pub(super) fn fast_with_every_quality_option() -> SimplifyOptions {
    SimplifyOptions::FAST
        .with_quadrics(QuadricMode::Exact)
        .with_orientation_check(true)
}

pub(super) fn thin_lens(rings: u32, segments: u32) -> IndexedMesh {
    let mut positions = vec![[0.0, 0.0, 0.02]];
    for i in 1..rings {
        let theta = std::f64::consts::PI * f64::from(i) / f64::from(rings);
        for j in 0..segments {
            let phi = 2.0 * std::f64::consts::PI * f64::from(j) / f64::from(segments);
            let wobble = 1.0 + 0.03 * (f64::from(i * segments + j) * 1.618).sin();
            positions.push([
                wobble * theta.sin() * phi.cos(),
                wobble * theta.sin() * phi.sin(),
                0.02 * wobble * theta.cos(),
            ]);
        }
    }
    positions.push([0.0, 0.0, -0.02]);
    let south = positions.len() as u32 - 1;
    let ring = |i: u32, j: u32| 1 + (i - 1) * segments + j % segments;
    let mut triangles = Vec::new();
    for j in 0..segments {
        triangles.push([0, ring(1, j), ring(1, j + 1)]);
        triangles.push([south, ring(rings - 1, j + 1), ring(rings - 1, j)]);
    }
    for i in 1..rings - 1 {
        for j in 0..segments {
            let (a, b, c, d) = (
                ring(i, j),
                ring(i, j + 1),
                ring(i + 1, j),
                ring(i + 1, j + 1),
            );
            triangles.push([a, c, d]);
            triangles.push([a, d, b]);
        }
    }
    IndexedMesh::new(positions, triangles)
}

/// The speculated attempts give the sequential order's output bit for bit, on a
/// mesh where the orientation check refuses pairs, verdicts are reused, and others
/// are asked again because a neighbour moved after the speculation. (Checked to
/// fail when every known verdict is reused regardless of moved corners.)
#[test]
fn speculation_gives_the_sequential_output() {
    let mesh = thin_lens(60, 120);
    let options = fast_with_every_quality_option();
    let seen = assert_same(&mesh, &options, &[mesh.triangle_count() / 20]);
    assert!(seen.refused > 0, "the check refuses some pairs");
    assert!(seen.reused > 0 && seen.asked_again > 0, "{seen:?}");
}

/// What a run gives that must not depend on speculation: per level, the stop
/// reason, the output's bits, the counters (max error by its bits) and the flipped
/// faces.
pub(super) type Levels = Vec<(StopReason, Vec<[u64; 3]>, Vec<[u32; 3]>, String, usize)>;

/// Runs the pass-based order on `mesh` to each of `targets` in turn, speculating or
/// not, on `threads` threads; the levels and what the run did.
pub(super) fn run_levels(
    mesh: &IndexedMesh,
    options: &SimplifyOptions,
    targets: &[usize],
    setup: Setup,
    threads: usize,
) -> (Levels, Seen) {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| {
        let cleaned = clean(mesh, &options.clean);
        let locked: Vec<u32> = options
            .locked_vertices
            .iter()
            .filter(|&&i| (i as usize) < mesh.vertex_count())
            .map(|&i| cleaned.vertex_map[i as usize])
            .filter(|&i| i != Cleaned::REMOVED)
            .collect();
        if cleaned.mesh.triangles.is_empty() {
            return (Vec::new(), Seen::default());
        }
        let frame =
            Frame::from_points(cleaned.mesh.positions.iter().map(|p| DVec3::from_array(*p)));
        let mut engine = Engine::new(&cleaned.mesh, frame, &locked, options, None);
        engine.probes.speculate_chunks = setup.speculation;
        if let Some(block_vertices) = setup.block_vertices {
            engine.set_block_vertices(block_vertices);
        }
        engine.probes.blocks_in_order = setup.blocks_in_order;
        let mut levels = Vec::new();
        for &target in targets {
            let reason = engine.run_passes(target, &mut NoObserver);
            let out = engine.to_mesh();
            let mut counters = engine.counters;
            let max_error = counters.max_error.to_bits();
            counters.max_error = 0.0;
            levels.push((
                reason,
                out.positions.iter().map(|p| p.map(f64::to_bits)).collect(),
                out.triangles,
                format!("{counters:?} max_error bits {max_error:x}"),
                engine.flipped_faces(),
            ));
            if reason != StopReason::TargetReached {
                break;
            }
        }
        let seen = Seen {
            reused: engine.probes.verdicts_reused,
            asked_again: engine.probes.verdicts_asked_again,
            refused: engine.counters.rejected.orientation,
            block_contractions: engine.probes.block_contractions,
            block_deferrals: engine.probes.block_deferrals,
        };
        (levels, seen)
    })
}

/// How a test run sets the engine up: whether it speculates, the vertices per block of
/// `pass_blocks` (`None`: the engine's own), and whether the blocks' order is run
/// sequentially instead.
#[derive(Clone, Copy, Debug)]
pub(super) struct Setup {
    pub speculation: bool,
    pub block_vertices: Option<u32>,
    /// Instead of the blocks, their order run by the sequential attempts (see
    /// `Engine::interior_first`).
    pub blocks_in_order: bool,
}

/// What a run did: orientation verdicts taken from a speculation and asked again,
/// pairs the orientation check refused, and pairs contracted by the blocks of
/// `pass_blocks` or left by them to the sequential attempts.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Seen {
    pub reused: usize,
    pub asked_again: usize,
    pub refused: usize,
    pub block_contractions: usize,
    pub block_deferrals: usize,
}

/// Asserts that speculating gives the sequential levels, on one, two and four
/// threads; returns what the two-thread speculated run did.
fn assert_same(mesh: &IndexedMesh, options: &SimplifyOptions, targets: &[usize]) -> Seen {
    let plain_setup = Setup {
        speculation: false,
        block_vertices: None,
        blocks_in_order: false,
    };
    let (sequential, plain) = run_levels(mesh, options, targets, plain_setup, 2);
    assert_eq!(plain.reused + plain.asked_again, 0);
    let mut on_two = plain;
    for threads in [1, 2, 4] {
        let setup = Setup {
            speculation: true,
            ..plain_setup
        };
        let (speculated, seen) = run_levels(mesh, options, targets, setup, threads);
        if threads == 2 {
            on_two = seen;
        }
        assert_eq!(speculated.len(), sequential.len());
        for (level, (s, q)) in speculated.iter().zip(&sequential).enumerate() {
            assert_eq!(s.0, q.0, "stop reason, level {level}, {threads} threads");
            assert_eq!(s.3, q.3, "counters, level {level}, {threads} threads");
            assert_eq!(s.4, q.4, "flipped faces, level {level}, {threads} threads");
            assert!(s.1 == q.1, "positions, level {level}, {threads} threads");
            assert!(s.2 == q.2, "triangles, level {level}, {threads} threads");
        }
    }
    on_two
}

/// A deterministic value in [0, 1) from `i` (a hash, not a stream).
pub(super) fn noise(i: u64) -> f64 {
    let mut x = i.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ 0xD1B5_4A32_D192_ED03;
    x ^= x >> 31;
    x = x.wrapping_mul(0xBF58_476D_1CE4_E5B9);
    x ^= x >> 29;
    (x >> 11) as f64 / (1u64 << 53) as f64
}

/// An `nx` × `ny` grid in x y with heights `z(x, y)`, its vertices from `first`.
pub(super) fn grid(
    nx: u32,
    ny: u32,
    first: u32,
    z: impl Fn(u32, u32) -> [f64; 3],
) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    let positions = (0..=ny)
        .flat_map(|y| (0..=nx).map(move |x| (x, y)))
        .map(|(x, y)| z(x, y))
        .collect();
    let id = |x: u32, y: u32| first + y * (nx + 1) + x;
    let mut triangles = Vec::new();
    for y in 0..ny {
        for x in 0..nx {
            triangles.push([id(x, y), id(x + 1, y), id(x + 1, y + 1)]);
            triangles.push([id(x, y), id(x + 1, y + 1), id(x, y + 1)]);
        }
    }
    (positions, triangles)
}

/// A sheet folded like an accordion (folds far steeper than wide, so faces near a
/// fold lie close to faces of the next pleat facing the other way), with noise.
pub(super) fn accordion(nx: u32, ny: u32, pleats: u32) -> IndexedMesh {
    let (p, t) = grid(nx, ny, 0, |x, y| {
        let u = f64::from(x) / f64::from(nx);
        let phase = (u * f64::from(pleats)).fract();
        let tri = 1.0 - (2.0 * phase - 1.0).abs();
        let n = noise(u64::from(y * (nx + 1) + x));
        [
            u + 0.002 * n,
            f64::from(y) / f64::from(ny),
            0.3 * tri + 0.004 * (n - 0.5),
        ]
    });
    IndexedMesh::new(p, t)
}

/// Two noisy sheets `gap` apart facing opposite ways, sharing nothing: every pair
/// near where they come closest is refused by the orientation check.
fn two_sided_sheet(n: u32, gap: f64) -> IndexedMesh {
    let wave = |x: u32, y: u32, k: u64| {
        let (u, v) = (f64::from(x) / f64::from(n), f64::from(y) / f64::from(n));
        [
            u,
            v,
            0.05 * (7.0 * u).sin() * (5.0 * v).cos() + 0.01 * noise(k),
        ]
    };
    let (mut p, mut t) = grid(n, n, 0, |x, y| wave(x, y, u64::from(y * (n + 1) + x)));
    let first = p.len() as u32;
    let (q, s) = grid(n, n, first, |x, y| {
        let mut c = wave(x, y, u64::from(y * (n + 1) + x) + 1_000_000);
        c[2] += gap;
        c
    });
    p.extend(q);
    t.extend(s.into_iter().map(|[a, b, c]| [a, c, b]));
    IndexedMesh::new(p, t)
}

/// `pages` sheets (`n` × `n` each) sharing their first row, the spine, so every
/// spine edge has `pages` triangles; pages at close angles, every third one wound
/// the other way.
pub(super) fn book(pages: u32, n: u32) -> IndexedMesh {
    let spine: Vec<[f64; 3]> = (0..=n)
        .map(|x| [f64::from(x) / f64::from(n), 0.0, 0.0])
        .collect();
    let mut positions = spine.clone();
    let mut triangles = Vec::new();
    for page in 0..pages {
        let angle = 0.3 * f64::from(page) / f64::from(pages.max(1)) + 0.01;
        let first = positions.len() as u32;
        // Rows 1..=n of this page; row 0 is the spine.
        for y in 1..=n {
            for x in 0..=n {
                let r = f64::from(y) / f64::from(n);
                let k = u64::from(page * 10_000 + y * (n + 1) + x);
                positions.push([
                    f64::from(x) / f64::from(n),
                    r * angle.cos(),
                    r * angle.sin() + 0.003 * noise(k),
                ]);
            }
        }
        let id = |x: u32, y: u32| {
            if y == 0 {
                x
            } else {
                first + (y - 1) * (n + 1) + x
            }
        };
        for y in 0..n {
            for x in 0..n {
                let mut t0 = [id(x, y), id(x + 1, y), id(x + 1, y + 1)];
                let mut t1 = [id(x, y), id(x + 1, y + 1), id(x, y + 1)];
                if page % 3 == 1 {
                    t0.swap(1, 2);
                    t1.swap(1, 2);
                }
                triangles.push(t0);
                triangles.push(t1);
            }
        }
    }
    IndexedMesh::new(positions, triangles)
}

/// A bumpy grid whose every triangle has its own three vertices (an unwelded
/// export): with exact welding off, coincident vertices stay apart.
pub(super) fn unwelded(n: u32) -> IndexedMesh {
    let (p, t) = grid(n, n, 0, |x, y| {
        let k = u64::from(y * (n + 1) + x);
        [f64::from(x), f64::from(y), (4.0 * noise(k)).floor() * 0.25]
    });
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for (i, tri) in t.iter().enumerate() {
        let first = positions.len() as u32;
        positions.extend(tri.map(|c| p[c as usize]));
        // Every third triangle keeps the welded corners, so parts connect.
        if i % 3 == 0 {
            triangles.push(*tri);
        } else {
            triangles.push([first, first + 1, first + 2]);
        }
    }
    // The welded corners refer to `p`'s indices: put `p` after, shifted.
    let shift = positions.len() as u32;
    for (i, tri) in triangles.iter_mut().enumerate() {
        if i % 3 == 0 {
            *tri = tri.map(|c| c + shift);
        }
    }
    positions.extend(p);
    IndexedMesh::new(positions, triangles)
}

fn checked(options: SimplifyOptions) -> SimplifyOptions {
    options
        .with_orientation_check(true)
        .with_quadrics(QuadricMode::Exact)
}

/// Targets at several ratios of `mesh`'s triangles, largest first.
pub(super) fn ratios(mesh: &IndexedMesh, ratios: &[f64]) -> Vec<usize> {
    ratios
        .iter()
        .map(|r| (r * mesh.triangle_count() as f64) as usize)
        .collect()
}

#[test]
fn speculation_is_sequential_on_an_accordion() {
    let mesh = accordion(160, 60, 9);
    for options in [
        checked(SimplifyOptions::FAST),
        checked(SimplifyOptions::FAST).with_quadrics(QuadricMode::Sum),
        checked(SimplifyOptions::FAST).with_boundary(BoundaryMode::Locked),
        checked(SimplifyOptions::FAST).with_placement(PlacementMode::EndpointOrMidpoint),
    ] {
        let seen = assert_same(&mesh, &options, &ratios(&mesh, &[0.3, 0.05, 0.0]));
        assert!(seen.reused > 0 && seen.asked_again > 0, "{seen:?}");
    }
}

#[test]
fn speculation_is_sequential_on_a_two_sided_sheet() {
    for gap in [1e-3, 0.0] {
        let mesh = two_sided_sheet(45, gap);
        let options = checked(SimplifyOptions::FAST).with_boundary(BoundaryMode::Free);
        assert_same(&mesh, &options, &ratios(&mesh, &[0.2, 0.01]));
        assert_same(
            &mesh,
            &options
                .with_max_normal_angle(180.0)
                .with_boundary(BoundaryMode::Locked),
            &ratios(&mesh, &[0.1]),
        );
    }
}

#[test]
fn speculation_is_sequential_on_non_manifold_books() {
    for pages in [3, 5, 12] {
        let mesh = book(pages, 24);
        for options in [
            checked(SimplifyOptions::FAST),
            checked(SimplifyOptions::FAST).with_boundary(BoundaryMode::Locked),
            checked(SimplifyOptions::FAST)
                .with_boundary(BoundaryMode::Free)
                .with_max_normal_angle(180.0),
        ] {
            assert_same(&mesh, &options, &ratios(&mesh, &[0.25, 0.02]));
        }
    }
}

#[test]
fn speculation_is_sequential_with_locked_vertices_and_an_error_bound() {
    let mesh = accordion(120, 40, 7);
    let locked: Vec<u32> = (0..mesh.vertex_count() as u32)
        .filter(|&v| noise(u64::from(v) + 77) < 0.2)
        .collect();
    let options = checked(SimplifyOptions::FAST).with_locked_vertices(locked);
    assert_same(&mesh, &options, &ratios(&mesh, &[0.2, 0.0]));
    let bounded = SimplifyOptions {
        max_error: Some(Length::DiagonalFraction(0.002)),
        ..options
    };
    assert_same(&mesh, &bounded, &ratios(&mesh, &[0.0]));
}

#[test]
fn speculation_is_sequential_on_unwelded_and_uncleaned_input() {
    let mesh = unwelded(40);
    for clean_options in [
        CleanOptions::DEFAULT,
        CleanOptions::DEFAULT.with_weld_exact(false),
        CleanOptions::DEFAULT
            .with_weld_exact(false)
            .with_drop_duplicates(false)
            .with_drop_zero_area(false)
            .with_drop_repeated_index(false),
    ] {
        let options = SimplifyOptions {
            clean: clean_options,
            ..checked(SimplifyOptions::FAST)
        };
        assert_same(&mesh, &options, &ratios(&mesh, &[0.3, 0.0]));
    }
}

#[test]
fn speculation_is_sequential_on_tiny_meshes() {
    let tetra = IndexedMesh::new(
        vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
        ],
        vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]],
    );
    let pair = IndexedMesh::new(
        vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]],
        vec![[0, 1, 2], [1, 3, 2]],
    );
    for mesh in [tetra, pair] {
        for boundary in [BoundaryMode::Free, BoundaryMode::Locked] {
            let options = checked(SimplifyOptions::FAST).with_boundary(boundary);
            assert_same(&mesh, &options, &[1, 0]);
        }
    }
}

/// Up to `max_vertices` vertices on a 5×5×5 integer grid, scaled to the extremes
/// of `f64` or not, and up to 300 faces with any indices: coincident vertices,
/// zero-area, duplicate and non-manifold faces.
pub(super) fn soup(max_vertices: usize) -> impl Strategy<Value = IndexedMesh> {
    (3..max_vertices).prop_flat_map(|n| {
        let positions = prop::collection::vec(prop::array::uniform3(0..5i32), n);
        let triangles = prop::collection::vec(prop::array::uniform3(0..n as u32), 1..300);
        let scale = prop_oneof![4 => Just(1.0), 1 => Just(3e307), 1 => Just(1e-310)];
        (positions, triangles, scale).prop_map(|(p, t, scale)| {
            let positions = p
                .into_iter()
                .map(|c| c.map(|x| f64::from(x) * scale))
                .collect();
            IndexedMesh::new(positions, t)
        })
    })
}

pub(super) fn soup_options() -> impl Strategy<Value = SimplifyOptions> {
    (
        prop_oneof![
            Just(BoundaryMode::Free),
            Just(BoundaryMode::Planes(1.0)),
            Just(BoundaryMode::Locked)
        ],
        prop_oneof![
            Just(PlacementMode::SolveFirst),
            Just(PlacementMode::Optimal),
            Just(PlacementMode::EndpointOrMidpoint)
        ],
        prop_oneof![Just(Weighting::Area), Just(SimplifyOptions::FAST.weighting)],
        prop_oneof![Just(90.0), Just(180.0)],
        prop::collection::vec(0..120u32, 0..6),
        any::<bool>(),
        any::<bool>(),
    )
        .prop_map(
            |(boundary, placement, weighting, angle, locked, exact, weld)| SimplifyOptions {
                clean: CleanOptions::DEFAULT
                    .with_weld_exact(weld)
                    .with_drop_duplicates(weld)
                    .with_drop_repeated_index(weld),
                ..SimplifyOptions::FAST
                    .with_boundary(boundary)
                    .with_placement(placement)
                    .with_weighting(weighting)
                    .with_max_normal_angle(angle)
                    .with_locked_vertices(locked)
                    .with_orientation_check(true)
                    .with_quadrics(if exact {
                        QuadricMode::Exact
                    } else {
                        QuadricMode::Sum
                    })
            },
        )
}

/// An `nx` × `ny` grid (20 to 59 each way, so rounds of more than a chunk's pairs)
/// with random coarse heights times `amplitude` (steep creases and spikes when
/// large), each triangle dropped with a chance of `drop` and wound the other way
/// with a chance of `flip`.
pub(super) fn rough_grid() -> impl Strategy<Value = IndexedMesh> {
    (20..60u32, 20..60u32, 0.01..4.0f64, 0.0..0.3f64, 0.0..0.3f64).prop_flat_map(
        |(nx, ny, amplitude, drop, flip)| {
            let vertices = ((nx + 1) * (ny + 1)) as usize;
            let faces = (2 * nx * ny) as usize;
            (
                prop::collection::vec(-3..4i32, vertices),
                prop::collection::vec((0.0..1.0f64, 0.0..1.0f64), faces),
            )
                .prop_map(move |(heights, fates)| {
                    let (positions, triangles) = grid(nx, ny, 0, |x, y| {
                        let h = heights[(y * (nx + 1) + x) as usize];
                        [
                            f64::from(x) / f64::from(nx),
                            f64::from(y) / f64::from(ny),
                            amplitude * f64::from(h) / f64::from(nx),
                        ]
                    });
                    let triangles = triangles
                        .into_iter()
                        .zip(&fates)
                        .filter(|(_, (d, _))| *d >= drop)
                        .map(|(t, &(_, f))| if f < flip { [t[0], t[2], t[1]] } else { t })
                        .collect();
                    IndexedMesh::new(positions, triangles)
                })
        },
    )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]
    #[test]
    fn speculation_is_sequential_on_soups(
        mesh in soup(120),
        options in soup_options(),
        ratio in 0.0..0.6f64,
    ) {
        let target = (ratio * mesh.triangle_count() as f64) as usize;
        assert_same(&mesh, &options, &[target, target / 3]);
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]
    #[test]
    fn speculation_is_sequential_on_rough_grids(
        mesh in rough_grid(),
        options in soup_options(),
        ratio in 0.0..0.5f64,
    ) {
        let target = (ratio * mesh.triangle_count() as f64) as usize;
        assert_same(&mesh, &options, &[target, target / 4]);
    }
}
