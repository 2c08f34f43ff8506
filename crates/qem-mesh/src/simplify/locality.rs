//! The engine's arrays in space-filling-curve order: the cleaned mesh is renumbered
//! before the engine builds its arrays, so that vertices and
//! triangles near each other in space are near each other in memory, and the output
//! is numbered back.
//!
//! Why: every contraction reads the quadrics, positions, adjacency and neighbouring
//! triangles of a small patch of the surface, all indexed by vertex and triangle
//! number. In the input's
//! own order a patch can be spread over the whole of each array, and each read is then
//! a cache miss. Meshes come in anywhere from well local (marching cubes, grids) to
//! random (some exporters, merged parts). Measured on the 871k-triangle dragon at
//! ratio 0.1 (the report's `simplify` time, one to three runs; the file itself
//! renumbered beforehand, before this module existed): with `--fast --quadrics exact
//! --orientation-check` its own order 2.78 s, this order 2.54 s, a random order 4.20 s;
//! with the greedy defaults 6.05 s, 5.73 s and 7.19 s.
//!
//! The order: vertices by the Morton code of their normalised position (21 bits per
//! axis), ties by their cleaned number; triangles by their lowest renumbered corner,
//! ties in their cleaned order (so of triangles with the same three vertices the first
//! stays first, and the engine keeps that one). Both are total orders on the input
//! alone, so the result does not depend on the threads. Each triangle keeps its corners
//! in their order.
//!
//! What callers see: nothing but the tie-breaks. Contractions of equal cost are ordered
//! by the new numbers (and the virtual pairs found in this order), so outputs differ
//! from those of the input's order, but the output mesh, the observer's
//! [`Contraction`](super::Contraction)s and every index a caller gives or gets are in
//! the cleaned mesh's numbers and order, and a run that contracts nothing gives the
//! cleaned mesh back as it was.

use crate::IndexedMesh;
use qem_core::{DVec3, Frame};
use rayon::prelude::*;

/// Bits of the Morton code per axis: 63 bits in all.
const BITS_PER_AXIS: u32 = 21;

/// A mesh renumbered in locality order, and the way back.
#[derive(Debug)]
pub(super) struct Renumbered {
    /// The mesh in locality order.
    pub mesh: IndexedMesh,
    /// For each vertex of `mesh`, its number in the mesh it came from.
    pub vertex_from: Vec<u32>,
    /// For each vertex of the mesh it came from, its number in `mesh`.
    pub vertex_to: Vec<u32>,
    /// For each triangle of `mesh`, its number in the mesh it came from.
    pub triangle_from: Vec<u32>,
}

/// `mesh` renumbered in locality order (see the module's doc); `frame` is its frame.
/// Triangles' corners must be valid indices (a validated, cleaned mesh).
pub(super) fn in_locality_order(mesh: &IndexedMesh, frame: &Frame) -> Renumbered {
    let mut order: Vec<(u64, u32)> = mesh
        .positions
        .par_iter()
        .enumerate()
        .map(|(v, p)| {
            (
                morton_code(frame.to_normalized(DVec3::from_array(*p))),
                v as u32,
            )
        })
        .collect();
    order.par_sort_unstable();
    let vertex_from: Vec<u32> = order.into_iter().map(|(_, old)| old).collect();
    let mut vertex_to = vec![0u32; vertex_from.len()];
    for (new, &old) in vertex_from.iter().enumerate() {
        vertex_to[old as usize] = new as u32;
    }
    let positions = vertex_from
        .par_iter()
        .map(|&old| mesh.positions[old as usize])
        .collect();

    let corners: Vec<[u32; 3]> = mesh
        .triangles
        .par_iter()
        .map(|t| t.map(|v| vertex_to[v as usize]))
        .collect();
    let triangle_from = by_lowest_corner(&corners, vertex_from.len());
    let triangles = triangle_from
        .par_iter()
        .map(|&old| corners[old as usize])
        .collect();
    Renumbered {
        mesh: IndexedMesh::new(positions, triangles),
        vertex_from,
        vertex_to,
        triangle_from,
    }
}

/// `mesh` numbered and ordered as the mesh it came from, which had `vertex_count`
/// vertices, where its vertex `i` came from vertex `vertex_from[i]` (below
/// `vertex_count`) and its triangle `k` from triangle `triangle_from[k]` (no number
/// twice in either): vertices and triangles in the order of those numbers. What the
/// loops' output goes through, so that it keeps the cleaned mesh's order.
pub(super) fn in_original_order(
    mesh: IndexedMesh,
    vertex_count: usize,
    vertex_from: &[u32],
    triangle_from: &[u32],
) -> IndexedMesh {
    // A scatter by origin, then the occupied places in order: linear, no sort. (Sized
    // by the count, not by the largest number: no number can make it grow.)
    let mut at_origin = vec![u32::MAX; vertex_count];
    for (i, &from) in vertex_from.iter().enumerate() {
        at_origin[from as usize] = i as u32;
    }
    let order: Vec<u32> = at_origin.into_iter().filter(|&i| i != u32::MAX).collect();
    let mut new_number = vec![0u32; order.len()];
    for (new, &i) in order.iter().enumerate() {
        new_number[i as usize] = new as u32;
    }
    let positions = order.iter().map(|&i| mesh.positions[i as usize]).collect();
    let mut triangles: Vec<(u32, [u32; 3])> = mesh
        .triangles
        .iter()
        .zip(triangle_from)
        .map(|(t, &from)| (from, t.map(|v| new_number[v as usize])))
        .collect();
    if mesh.attributes.is_empty() {
        triangles.par_sort_unstable_by_key(|&(from, _)| from);
        return IndexedMesh::new(positions, triangles.into_iter().map(|(_, t)| t).collect());
    }
    // With attributes, one sort of the triangles' places, which orders both them and
    // their attributes.
    let mut by_origin: Vec<u32> = (0..triangles.len() as u32).collect();
    by_origin.par_sort_unstable_by_key(|&k| triangles[k as usize].0);
    IndexedMesh::new(
        positions,
        by_origin.iter().map(|&k| triangles[k as usize].1).collect(),
    )
    .with_attributes(mesh.attributes.for_faces(&by_origin))
}

/// The numbers of `triangles` stably sorted by their lowest corner (a counting sort:
/// one pass to count, one to place), each corner below `vertex_count`.
fn by_lowest_corner(triangles: &[[u32; 3]], vertex_count: usize) -> Vec<u32> {
    let lowest = |t: &[u32; 3]| t[0].min(t[1]).min(t[2]) as usize;
    // `next[v]` is where the next triangle whose lowest corner is `v` goes.
    let mut next = vec![0u32; vertex_count + 1];
    for t in triangles {
        next[lowest(t) + 1] += 1;
    }
    for v in 0..vertex_count {
        next[v + 1] += next[v];
    }
    let mut sorted = vec![0u32; triangles.len()];
    for (i, t) in triangles.iter().enumerate() {
        let slot = &mut next[lowest(t)];
        sorted[*slot as usize] = i as u32;
        *slot += 1;
    }
    sorted
}

/// The Morton code of a normalised point (coordinates in `[-1, 1]`; anything outside,
/// or NaN, is clamped to the nearest cell).
fn morton_code(p: DVec3) -> u64 {
    let cells = (1u64 << BITS_PER_AXIS) as f64;
    let cell = |x: f64| {
        // `as` saturates and sends NaN to 0: no out-of-range cell, no panic.
        let c = ((x + 1.0) * 0.5 * cells) as u64;
        spread(c.min((1 << BITS_PER_AXIS) - 1))
    };
    cell(p.x) | cell(p.y) << 1 | cell(p.z) << 2
}

/// The low 21 bits of `x` spread to every third bit (bit `i` to bit `3i`).
fn spread(x: u64) -> u64 {
    let mut x = x & 0x1f_ffff;
    x = (x | x << 32) & 0x001f_0000_0000_ffff;
    x = (x | x << 16) & 0x001f_0000_ff00_00ff;
    x = (x | x << 8) & 0x100f_00f0_0f00_f00f;
    x = (x | x << 4) & 0x10c3_0c30_c30c_30c3;
    x = (x | x << 2) & 0x1249_2492_4924_9249;
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spread_puts_bit_i_at_bit_3i() {
        for i in 0..BITS_PER_AXIS {
            assert_eq!(spread(1 << i), 1 << (3 * i), "bit {i}");
        }
        assert_eq!(spread(u64::MAX), 0x1249_2492_4924_9249);
    }

    #[test]
    fn morton_codes_interleave_the_axes_and_clamp() {
        assert_eq!(morton_code(DVec3::splat(-1.0)), 0);
        assert_eq!(morton_code(DVec3::splat(1.0)), (1 << 63) - 1);
        assert_eq!(morton_code(DVec3::splat(5.0)), (1 << 63) - 1);
        assert_eq!(morton_code(DVec3::splat(f64::NAN)), 0);
        // Just past the middle on one axis: that axis's top bit alone.
        let half = 1.0 / (1u64 << BITS_PER_AXIS) as f64;
        let top = 3 * (BITS_PER_AXIS as u64 - 1);
        assert_eq!(morton_code(DVec3::new(half, -1.0, -1.0)), 1 << top);
        assert_eq!(morton_code(DVec3::new(-1.0, half, -1.0)), 1 << (top + 1));
        assert_eq!(morton_code(DVec3::new(-1.0, -1.0, half)), 1 << (top + 2));
    }

    /// A strip of triangles along x whose vertices and triangles are numbered
    /// backwards, and a vertex no triangle uses.
    fn backwards_strip(quads: u32) -> IndexedMesh {
        let columns = quads + 1;
        let mut positions = Vec::new();
        for i in (0..columns).rev() {
            positions.push([i as f64, 0.0, 0.0]);
            positions.push([i as f64, 1.0, 0.0]);
        }
        positions.push([100.0, 100.0, 100.0]);
        let at = |i: u32, top: u32| 2 * (columns - 1 - i) + top;
        let mut triangles = Vec::new();
        for i in (0..quads).rev() {
            triangles.push([at(i, 0), at(i + 1, 0), at(i + 1, 1)]);
            triangles.push([at(i, 0), at(i + 1, 1), at(i, 1)]);
        }
        IndexedMesh::new(positions, triangles)
    }

    #[test]
    fn the_renumbered_mesh_is_the_same_surface_in_space_order() {
        let input = backwards_strip(50);
        let frame = Frame::from_points(input.positions.iter().map(|p| DVec3::from_array(*p)));
        let r = in_locality_order(&input, &frame);
        assert_ne!(r.mesh, input, "the backwards strip is reordered");

        // Each triangle is its source triangle, corner for corner, in positions.
        let corners = |m: &IndexedMesh, t: [u32; 3]| t.map(|v| m.positions[v as usize]);
        for (t, &from) in r.mesh.triangles.iter().zip(&r.triangle_from) {
            assert_eq!(
                corners(&r.mesh, *t),
                corners(&input, input.triangles[from as usize])
            );
        }
        let mut seen = r.triangle_from.clone();
        seen.sort_unstable();
        assert!(seen.iter().copied().eq(0..input.triangles.len() as u32));

        // The vertex maps are inverse permutations.
        for (new, &old) in r.vertex_from.iter().enumerate() {
            assert_eq!(r.vertex_to[old as usize], new as u32);
            assert_eq!(r.mesh.positions[new], input.positions[old as usize]);
        }

        // Vertices by Morton code, triangles by lowest corner.
        let codes: Vec<u64> = r
            .mesh
            .positions
            .iter()
            .map(|p| morton_code(frame.to_normalized(DVec3::from_array(*p))))
            .collect();
        assert!(codes.windows(2).all(|w| w[0] <= w[1]));
        let lowest: Vec<u32> = r
            .mesh
            .triangles
            .iter()
            .map(|t| t[0].min(t[1]).min(t[2]))
            .collect();
        assert!(lowest.windows(2).all(|w| w[0] <= w[1]));
    }

    #[test]
    fn numbering_back_restores_the_input() {
        let input = backwards_strip(20);
        let frame = Frame::from_points(input.positions.iter().map(|p| DVec3::from_array(*p)));
        let r = in_locality_order(&input, &frame);
        assert_eq!(
            in_original_order(
                r.mesh,
                input.positions.len(),
                &r.vertex_from,
                &r.triangle_from
            ),
            input
        );

        // A subset: vertices 1, 2 and 3 of four, and two triangles of eight.
        let part = IndexedMesh::new(
            vec![[3.0; 3], [1.0; 3], [2.0; 3]],
            vec![[0, 1, 2], [2, 1, 0]],
        );
        let back = in_original_order(part, 4, &[3, 1, 2], &[7, 4]);
        assert_eq!(back.positions, [[1.0; 3], [2.0; 3], [3.0; 3]]);
        assert_eq!(back.triangles, [[1, 0, 2], [2, 0, 1]]);
    }

    #[test]
    fn counting_sort_is_stable() {
        let sorted = by_lowest_corner(&[[2, 3, 4], [1, 5, 6], [4, 2, 7], [6, 1, 0]], 8);
        assert_eq!(sorted, [3, 1, 0, 2]);
    }
}
