//! `store_ops`: random contraction sequences on the store against the brute-force model.

use super::bytes::Bytes;
use crate::store_model::{run, Op};
use qem_mesh::IndexedMesh;

/// At most this many operations: the model check after each one is O(n²) queries.
const MAX_OPS: usize = 16;

/// A mesh over 3..=12 vertex ids with 1..=14 faces (any indices, so repeated vertices,
/// duplicates in any orientation and non-manifold fans all occur), then operations.
///
/// Layout: vertex count, face count, three bytes per face, then two bytes per
/// operation: an even first byte contracts the edge picked by the second (the bit 1
/// flips which end is kept); an odd one contracts the arbitrary pair (second byte,
/// first byte / 4), which may be equal, dead or unconnected.
fn decode(data: &[u8]) -> (IndexedMesh, Vec<Op>) {
    let mut b = Bytes::new(data);
    let n = 3 + b.below(10);
    let faces = 1 + b.below(14);
    let triangles = (0..faces)
        .map(|_| [(); 3].map(|()| b.below(n) as u32))
        .collect();
    // Distinct positions, so the model's placement bookkeeping is easy to follow.
    let positions = (0..n)
        .map(|i| [i as f64, (i % 3) as f64, (i / 3) as f64])
        .collect();
    let mut ops = Vec::new();
    while !b.is_empty() && ops.len() < MAX_OPS {
        let (kind, value) = (b.byte(), usize::from(b.byte()));
        ops.push(if kind % 2 == 0 {
            Op::Edge {
                pick: value,
                flip: kind & 2 != 0,
            }
        } else {
            Op::Pair {
                a: value,
                b: usize::from(kind / 4),
            }
        });
    }
    (IndexedMesh::new(positions, triangles), ops)
}

/// `store_ops`: after every contraction, every query of the store equals the model's
/// brute-force answer (see [`crate::store_model`]), and the same operations twice give
/// the same keys and output.
pub fn store_ops(data: &[u8]) {
    let (mesh, ops) = decode(data);
    let first = run(&mesh, &ops);
    let second = run(&mesh, &ops);
    assert_eq!(first, second, "two runs disagree");
}
