//! The engine's oracle: an [`Observer`] that replays every contraction of a run, and
//! every edge flip of its last step ([`MeshStore::flip_edge`]), on the radial-edge
//! store ([`MeshStore`]), the library's model of non-manifold input, and
//! checks after every step that the store is valid and removed the triangles the
//! engine removed, and at the end that both hold the same triangles.
//!
//! The engine works on flat arrays and never builds the store; the store contracts by
//! its own rules (faces on both ends collapse, the other faces of the removed vertex
//! move to the kept one, faces that would coincide merge). Replaying the engine's
//! contractions, in order, on a store built from the cleaned mesh must give the
//! engine's output: any difference is a bug in one of the two. (Except one the output
//! makes after the loop: it drops the faces the engine counts as zero-area, which came
//! in so with cleaning passes off; the comparison leaves them out of the store's faces,
//! and fails if there are more of them than the cleaned mesh had.) Tests and fuzz targets
//! run it; it costs a validation of the whole store per contraction, so it is for
//! small meshes.

use super::checks::is_zero_area;
use super::observer::{Contraction, EdgeFlip, Observer};
use super::settings::Settings;
use super::SimplifyOptions;
use crate::store::{ContractLog, MeshStore, VertexKey};
use crate::IndexedMesh;
use qem_core::Frame;

/// Replays a run's contractions on a [`MeshStore`] (see the module's doc).
///
/// ```
/// use qem_mesh::simplify::{simplify_observed, SimplifyOptions, StoreReplay, Target};
/// use qem_mesh::IndexedMesh;
/// // A square pyramid without its base.
/// let mesh = IndexedMesh::new(
///     vec![[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]],
///     vec![[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 1]],
/// );
/// let mut replay = StoreReplay::default();
/// let options = SimplifyOptions::DEFAULT.with_target(Target::Triangles(2));
/// let out = simplify_observed(&mesh, &options, &mut replay)?;
/// replay.check_output(&out.mesh).map_err(|e| e.to_string())?;
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Default)]
pub struct StoreReplay {
    store: Option<MeshStore>,
    keys: Vec<VertexKey>,
    /// The first disagreement, if any.
    failure: Option<String>,
    /// The run's frame, and the cleaned mesh's faces the engine counts as zero-area
    /// (in that frame): the output drops such faces, and the loop never makes one.
    frame: Option<Frame>,
    zero_area_in: usize,
    contractions: usize,
    /// Scratch: what the store's last contraction removed.
    log: ContractLog,
}

impl StoreReplay {
    /// The store's keys of the vertices `ends` for the step `what`, unless a failure
    /// is recorded already; records one when the cleaned mesh never came or a vertex
    /// is unknown.
    fn keys_for(&mut self, what: &str, ends: [u32; 2]) -> Option<[VertexKey; 2]> {
        if self.failure.is_some() {
            return None;
        }
        let keys = ends.map(|v| self.keys.get(v as usize).copied());
        match (&self.store, keys) {
            (Some(_), [Some(x), Some(y)]) => Some([x, y]),
            (None, _) => {
                self.failure = Some(format!("{what} before the cleaned mesh"));
                None
            }
            (Some(_), _) => {
                self.failure = Some(format!("{what}: no such vertex"));
                None
            }
        }
    }

    /// The number of contractions replayed.
    pub fn contractions(&self) -> usize {
        self.contractions
    }

    /// `Ok` when every contraction replayed on a valid store, and the store's faces
    /// are `output`'s triangles (as corner positions, same orientation, in any order
    /// and rotation), leaving out those the engine counts as zero-area, which the
    /// output drops (at most as many as the cleaned mesh had); otherwise what differed
    /// first.
    pub fn check_output(&self, output: &IndexedMesh) -> Result<(), String> {
        if let Some(failure) = &self.failure {
            return Err(failure.clone());
        }
        let Some(store) = &self.store else {
            return Err("the run reported no cleaned mesh".to_string());
        };
        let zero_area = self.zero_area_test();
        let corners: Vec<[[f64; 3]; 3]> = store
            .faces()
            .map(|f| store.face_vertices(f).map(|v| store.position(v)))
            .collect();
        let dropped = corners.iter().filter(|&&c| zero_area(c)).count();
        if dropped > self.zero_area_in {
            return Err(format!(
                "the store holds {dropped} zero-area faces, the cleaned mesh had {}",
                self.zero_area_in
            ));
        }
        let mut from_store: Vec<[[u64; 3]; 3]> = corners
            .into_iter()
            .filter(|&c| !zero_area(c))
            .map(canonical)
            .collect();
        let mut from_output: Vec<[[u64; 3]; 3]> = output
            .triangles
            .iter()
            .map(|t| canonical(t.map(|i| output.positions[i as usize])))
            .collect();
        from_store.sort_unstable();
        from_output.sort_unstable();
        if from_store != from_output {
            let only_store = from_store
                .iter()
                .filter(|t| !from_output.contains(t))
                .count();
            let only_output = from_output
                .iter()
                .filter(|t| !from_store.contains(t))
                .count();
            return Err(format!(
                "the store holds {} faces and the output {} triangles; {only_store} only \
                 in the store, {only_output} only in the output",
                from_store.len(),
                from_output.len()
            ));
        }
        Ok(())
    }
}

impl StoreReplay {
    /// The output's zero-area test in the run's frame (`checks::is_zero_area`, whose
    /// settings depend on the frame alone).
    fn zero_area_test(&self) -> impl Fn([[f64; 3]; 3]) -> bool + '_ {
        let settings = self
            .frame
            .map(|frame| (frame, Settings::new(&SimplifyOptions::DEFAULT, &frame)));
        move |corners| {
            settings
                .as_ref()
                .is_some_and(|(frame, settings)| is_zero_area(frame, settings, corners))
        }
    }
}

/// A triangle as the bits of its corners, rotated so that the smallest comes first
/// (orientation kept).
fn canonical(corners: [[f64; 3]; 3]) -> [[u64; 3]; 3] {
    let bits = corners.map(|c| c.map(f64::to_bits));
    let first = (0..3).min_by_key(|&i| bits[i]).unwrap_or(0);
    [bits[first], bits[(first + 1) % 3], bits[(first + 2) % 3]]
}

impl Observer for StoreReplay {
    fn cleaned(&mut self, mesh: &IndexedMesh, frame: &Frame) {
        self.frame = Some(*frame);
        let zero_area_in = {
            let zero_area = self.zero_area_test();
            (mesh.triangles.iter())
                .filter(|t| zero_area(t.map(|i| mesh.positions[i as usize])))
                .count()
        };
        self.zero_area_in = zero_area_in;
        match MeshStore::from_mesh(mesh) {
            Ok((store, keys)) => {
                self.store = Some(store);
                self.keys = keys;
            }
            Err(e) => self.failure = Some(format!("the store refused the cleaned mesh: {e}")),
        }
    }

    fn flipped(&mut self, flip: &EdgeFlip) {
        let [p, q] = flip.edge;
        let what = format!("flip of {p} {q}");
        let (Some([kp, kq]), Some(store)) = (self.keys_for(&what, flip.edge), self.store.as_mut())
        else {
            return;
        };
        let failure = match store.flip_edge(kp, kq) {
            Err(e) => Some(format!("{what}: the store refused it: {e}")),
            Ok(()) => (store.validate().err())
                .map(|e| format!("{what}: the store is invalid after it: {e}")),
        };
        self.failure = failure;
    }

    fn contracted(&mut self, c: &Contraction) {
        let what = format!("contraction {}", self.contractions);
        let (Some([a, b]), Some(store)) = (
            self.keys_for(&what, [c.kept, c.removed]),
            self.store.as_mut(),
        ) else {
            return;
        };
        let step = self.contractions;
        self.contractions += 1;
        let faces_before = store.face_count();
        if let Err(e) = store.contract_logged(a, b, c.world, &mut self.log) {
            self.failure = Some(format!(
                "contraction {step} ({} into {}): the store refused it: {e}",
                c.removed, c.kept
            ));
            return;
        }
        let (collapsed, merged) = (self.log.faces_collapsed.len(), self.log.faces_merged.len());
        // The store keeps the kept vertex's face of each merged pair; the engine keeps
        // it too, or (the ladder's merged faces) removes both.
        if c.triangles_removed == collapsed + 2 * merged && merged > 0 {
            for &(_, kept) in &self.log.faces_merged {
                store.remove_face_and_bare_edges(kept);
            }
        } else if c.triangles_removed != collapsed + merged {
            self.failure = Some(format!(
                "contraction {step} ({} into {}): the engine removed {} triangles, \
                 the store {} faces ({collapsed} collapsed, {merged} merged; {faces_before} before)",
                c.removed,
                c.kept,
                c.triangles_removed,
                collapsed + merged,
            ));
            return;
        }
        if let Err(e) = store.validate() {
            self.failure = Some(format!("contraction {step}: the store broke: {e}"));
        }
    }
}
