//! Watching a run: progress, cancellation, and (for tests and tools) each contraction.

use crate::IndexedMesh;
use qem_core::{DVec3, Frame, Quadric};

/// Progress of the contraction loop, as given to an [`Observer`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Progress {
    /// Triangles left now.
    pub triangles: usize,
    /// Triangles at the start of the loop.
    pub triangles_start: usize,
    /// The target.
    pub target: usize,
}

impl Progress {
    /// The fraction of the work done, between 0 and 1.
    pub fn fraction(&self) -> f64 {
        let total = self.triangles_start.saturating_sub(self.target);
        if total == 0 {
            return 1.0;
        }
        let done = self.triangles_start.saturating_sub(self.triangles);
        (done as f64 / total as f64).min(1.0)
    }
}

/// A stage of a run, as given to [`Observer::phase`] when it begins.
///
/// Why: on a large mesh the stages before the loop take a while (on 100M triangles,
/// about 15 s of cleaning and 40 s of setup), and a progress display that shows only
/// the loop's progress would sit at 0% through them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum Phase {
    /// Welding exact duplicates and dropping degenerate faces ([`crate::clean`]).
    Cleaning,
    /// Building the working mesh, its quadrics and, with the orientation check, the
    /// index of the input surface.
    SettingUp,
    /// The contraction loop, reported through [`Observer::progress`].
    Contracting,
    /// Building the output mesh from the working one.
    Compacting,
}

impl Phase {
    /// A lower-case name for displays: `cleaning`, `setting up`, `contracting`,
    /// `compacting`.
    ///
    /// ```
    /// use qem_mesh::simplify::Phase;
    /// assert_eq!(Phase::SettingUp.name(), "setting up");
    /// ```
    pub fn name(self) -> &'static str {
        match self {
            Phase::Cleaning => "cleaning",
            Phase::SettingUp => "setting up",
            Phase::Contracting => "contracting",
            Phase::Compacting => "compacting",
        }
    }
}

/// One contraction, as reported to [`Observer::contracted`].
///
/// Vertices are named by their index in the *cleaned* mesh given to
/// [`Observer::cleaned`]; a vertex that has absorbed others keeps the index of the
/// vertex that survived. Geometry is in the normalised [`Frame`] given there.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct Contraction {
    /// The vertex that stays (and moves to `position`).
    pub kept: u32,
    /// The vertex that was merged into `kept` and no longer exists.
    pub removed: u32,
    /// Whether no edge joined them (a virtual pair).
    pub is_virtual: bool,
    /// The quadric of the merged vertex (normalised frame): `Q_kept + Q_removed`, or
    /// their union with [`QuadricMode::Exact`](super::QuadricMode::Exact).
    pub quadric: Quadric,
    /// The new position, normalised frame.
    pub position: DVec3,
    /// The same position in model units, as the output holds it (bit for bit where
    /// the kept vertex was, when an end is locked).
    pub world: [f64; 3],
    /// How many triangles the contraction removed (those on both ends).
    pub triangles_removed: usize,
    /// `quadric` evaluated at the chosen position (clamped to be non-negative).
    pub cost: f64,
}

/// An edge flip of the run's last step, as reported to [`Observer::flipped`]: the
/// two faces on the edge `p q`, `p q r` and `q p s`, became `p s r` and `s q r`
/// (see [`SimplifyReport::faces_turned_back`](super::SimplifyReport::faces_turned_back)).
/// Vertices are named as in [`Contraction`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub struct EdgeFlip {
    /// The edge's ends `p` and `q`, in the order the first face runs it.
    pub edge: [u32; 2],
}

/// Receives progress and may cancel a run. Every method has a no-op default.
pub trait Observer {
    /// Called every few thousand contractions, and once at the end.
    fn progress(&mut self, _progress: Progress) {}
    /// Polled with [`progress`](Self::progress); returning `true` stops the run with
    /// [`StopReason::Cancelled`](super::StopReason::Cancelled) (the partial result is
    /// still a valid mesh). Also polled when the cleaning and the setup end: `true`
    /// there stops the run before the loop, with
    /// [`SimplifyError::Cancelled`](super::SimplifyError::Cancelled) (there is no
    /// partial result yet).
    fn should_stop(&mut self) -> bool {
        false
    }
    /// Called when each [`Phase`] of the run begins, in order (with levels of detail,
    /// `Contracting` and `Compacting` once per level). Vertex clustering
    /// ([`Method::Clustering`](super::Method::Clustering)) reports none: it takes a
    /// fraction of a second a million triangles, and no observer is asked.
    fn phase(&mut self, _phase: Phase) {}
    /// Called once before the loop with the cleaned mesh whose vertex indices
    /// [`Contraction`] uses, and the frame its quadrics are computed in.
    fn cleaned(&mut self, _mesh: &IndexedMesh, _frame: &Frame) {}
    /// Called after every contraction. Meant for tests and analysis tools: it is on the
    /// hot path, so keep it cheap.
    fn contracted(&mut self, _contraction: &Contraction) {}
    /// Called after every edge flip of the run's last step (faces facing away turned
    /// back; rare).
    fn flipped(&mut self, _flip: &EdgeFlip) {}
    /// Whether [`contracted`](Self::contracted) does anything. An observer that
    /// returns `false` spares the pass-based order from keeping the contractions it
    /// makes on other threads until they can be reported in order. The default is
    /// `true`, so that an observer that watches them gets every one.
    fn wants_contractions(&self) -> bool {
        true
    }
}

/// The observer that does nothing.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoObserver;

impl Observer for NoObserver {
    fn wants_contractions(&self) -> bool {
        false
    }
}
