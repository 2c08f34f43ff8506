//! Streaming reads: each triangle handed to a [`TriangleSink`] as it is read, so that a
//! file can be cut into pieces on disk (`qem tiles split`) without its triangle list
//! ever being held.
//!
//! The readers are the ones [`read_path`](super::read_path) uses, in a mode where the
//! triangles they make go to the sink instead of into a list ([`Triangles`]). What a
//! streaming read still holds: PLY and OFF keep their vertices (24 bytes each, the
//! faces name them by number); STL keeps only the facet being read. Attribute values
//! (per vertex, per face) are read and checked as by an ordinary read, but only the
//! record being read is kept. OBJ keeps its vertices, texture coordinates and normals
//! (and, for each, the output element it became: see `io::obj`), but no triangle once
//! the vertices it names are read, nor any per-corner or per-face value. glTF is not
//! streamed: it is read whole, as an ordinary read reads it, and its triangles handed
//! on afterwards.
//!
//! A triangle whose corners are not all known when it is read (a PLY file with its
//! faces before its vertices) waits, 16 bytes a triangle, until the end of the file.
//! So the sink sees the file's triangles in the file's order except for those, which
//! follow later; and such a file's triangles are all held while it is read.
//!
//! The sink sees triangles before the end of the file says whether the file is valid:
//! a streaming read that ends in an error has handed on some triangles, which the
//! caller must discard. A read that succeeds has checked what
//! [`IndexedMesh::validate`](crate::IndexedMesh::validate) checks of the mesh
//! [`read_path`](super::read_path) would have returned but its attributes (which
//! the PLY, OFF and STL readers check as they read them), and the sink has seen
//! exactly that mesh's triangles, as the positions of their corners. That the two
//! reads fail alike, with the same message, is tested on every fuzz input and
//! regression of the readers, truncated and in chunks (`io::input`'s tests, and the
//! fuzz targets' checks).

use super::error::{IoError, ReadError};
use super::{ReadNotes, StreamError};
use crate::input::{check_vertices, InputError};

/// Where a streaming read ([`stream_path`](super::stream_path)) sends each triangle.
pub trait TriangleSink {
    /// Takes one triangle, as its three corners' positions (in the file's corner
    /// order). An error stops the read (at the reader's next record for PLY, OFF and
    /// STL, at its next line for OBJ; glTF is read whole first): it is what the read
    /// returns.
    fn triangle(&mut self, corners: [[f64; 3]; 3]) -> Result<(), IoError>;
}

/// What a successful streaming read saw.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Streamed {
    /// The vertices of the mesh an ordinary read would have returned.
    pub vertices: usize,
    /// The triangles handed to the sink (those of that mesh).
    pub triangles: usize,
    /// What the reader passed over, as for an ordinary read.
    pub notes: ReadNotes,
    /// The names of the attributes the file had (as
    /// [`Attributes::names`](crate::attributes::Attributes::names) gives them), which a
    /// streaming read does not hand on.
    pub attributes: Vec<String>,
}

/// The triangles a reader makes: kept in a list (an ordinary read) or handed to a sink
/// (a streaming read).
pub(crate) struct Triangles<'s> {
    kept: Vec<[u32; 3]>,
    stream: Option<Stream<'s>>,
}

/// The streaming side of [`Triangles`].
struct Stream<'s> {
    sink: &'s mut dyn TriangleSink,
    /// Triangles whose corners were not all known when made: (triangle number, corners).
    waiting: Vec<(u32, [u32; 3])>,
    /// The sink's first error; nothing more is handed on after it.
    failed: Option<IoError>,
    /// Vertices already forgotten by the reader ([`Triangles::forget`]): the
    /// positions it passes start at this vertex number.
    forgotten: usize,
    /// Triangles made so far.
    made: usize,
}

impl<'s> Triangles<'s> {
    /// An ordinary read's list.
    pub(crate) fn kept() -> Self {
        Triangles {
            kept: Vec::new(),
            stream: None,
        }
    }

    /// A streaming read's: every triangle goes to `sink`.
    pub(crate) fn streamed(sink: &'s mut dyn TriangleSink) -> Self {
        Triangles {
            kept: Vec::new(),
            stream: Some(Stream {
                sink,
                waiting: Vec::new(),
                failed: None,
                forgotten: 0,
                made: 0,
            }),
        }
    }

    /// Whether the sink refused a triangle: the reader should stop
    /// ([`Triangles::stopped`]); the read's error is the sink's.
    #[inline]
    pub(crate) fn has_failed(&self) -> bool {
        self.stream.as_ref().is_some_and(|s| s.failed.is_some())
    }

    /// The error a reader gives up with once [`has_failed`](Self::has_failed): a
    /// stand-in, which the streaming read replaces by the sink's error.
    pub(crate) fn stopped() -> ReadError {
        ReadError::new(
            super::ReadErrorKind::Malformed {
                detail: "the read stopped: the sink refused a triangle".into(),
            },
            None,
        )
    }

    /// The sink's error, if it refused a triangle (taken).
    pub(crate) fn take_failure(&mut self) -> Option<IoError> {
        self.stream.as_mut().and_then(|s| s.failed.take())
    }

    /// Whether the triangles go to a sink (a streaming read).
    pub(crate) fn is_streamed(&self) -> bool {
        self.stream.is_some()
    }

    /// Triangles made so far.
    #[inline]
    pub(crate) fn len(&self) -> usize {
        match &self.stream {
            None => self.kept.len(),
            Some(stream) => stream.made,
        }
    }

    /// Reserves room for `n` more kept triangles (nothing when streaming).
    pub(crate) fn reserve(&mut self, n: usize) {
        if self.stream.is_none() {
            self.kept.reserve(n);
        }
    }

    /// Adds triangle `t`, whose corners index `positions` (offset by the vertices
    /// forgotten so far): kept, handed on, or set to wait when a corner is not in
    /// `positions` yet.
    #[inline]
    pub(crate) fn push(&mut self, t: [u32; 3], positions: &[[f64; 3]]) {
        let Some(stream) = &mut self.stream else {
            self.kept.push(t);
            return;
        };
        let number = stream.made as u32;
        stream.made += 1;
        if !stream.hand_on(t, positions) {
            stream.waiting.push((number, t));
        }
    }

    /// Hands on the waiting triangles whose corners are all in `positions` now, in
    /// the order they were made (a reader calls this once the vertices they wait for
    /// are read).
    pub(crate) fn settle(&mut self, positions: &[[f64; 3]]) {
        let Some(stream) = &mut self.stream else {
            return;
        };
        let mut waiting = std::mem::take(&mut stream.waiting);
        waiting.retain(|&(_, t)| !stream.hand_on(t, positions));
        stream.waiting = waiting;
    }

    /// For a reader whose triangles never name an earlier facet's vertices (STL):
    /// when streaming, the vertices in `positions` are handed on with their
    /// triangles already, so they are forgotten (`positions` is cleared; later
    /// indices count them still). Does nothing to an ordinary read.
    pub(crate) fn forget(&mut self, positions: &mut Vec<[f64; 3]>) {
        if let Some(stream) = &mut self.stream {
            stream.forgotten += positions.len();
            positions.clear();
        }
    }

    /// The number of vertex `local` of a reader's positions, counting the vertices
    /// forgotten before them (for messages and counts).
    pub(crate) fn vertex_number(&self, local: usize) -> usize {
        local + self.stream.as_ref().map_or(0, |s| s.forgotten)
    }

    /// The kept list (empty for a streaming read).
    pub(crate) fn kept_list(&self) -> &[[u32; 3]] {
        &self.kept
    }

    /// The kept list, taken (empty for a streaming read).
    pub(crate) fn into_kept(self) -> Vec<[u32; 3]> {
        self.kept
    }

    /// The end of a streaming read whose reader gave `positions` (the mesh's, with
    /// the vertices it forgot not among them): hands on what waited, then checks
    /// what [`IndexedMesh::validate`](crate::IndexedMesh::validate) checks of the
    /// mesh an ordinary read gives (but its attributes), after the sink's error.
    /// Returns the vertex count.
    pub(crate) fn finish(mut self, positions: &[[f64; 3]]) -> Result<usize, StreamError> {
        self.settle(positions);
        let Some(stream) = self.stream else {
            return Ok(positions.len());
        };
        // (The sink's error first, as wherever else it meets one of the data.)
        if let Some(e) = stream.failed {
            return Err(StreamError::Sink(e));
        }
        let mesh_error = |e| StreamError::Read(ReadError::mesh(None, e));
        check_vertices(positions, stream.forgotten, stream.made).map_err(mesh_error)?;
        let vertex_count = stream.forgotten + positions.len();
        if let Some(&(face, t)) = stream.waiting.first() {
            let index = t
                .into_iter()
                .find(|&i| i as usize >= vertex_count)
                .unwrap_or(t[0]);
            return Err(mesh_error(InputError::IndexOutOfRange {
                face: face as usize,
                index,
                vertex_count,
            }));
        }
        Ok(vertex_count)
    }
}

impl Stream<'_> {
    /// Hands triangle `t` on when its corners are all in `positions` (offset by the
    /// vertices forgotten), and says whether they were; nothing more goes to the sink
    /// once it has refused a triangle.
    fn hand_on(&mut self, t: [u32; 3], positions: &[[f64; 3]]) -> bool {
        let corner = |i: u32| {
            (i as usize)
                .checked_sub(self.forgotten)
                .and_then(|i| positions.get(i).copied())
        };
        let [Some(a), Some(b), Some(c)] = t.map(corner) else {
            return false;
        };
        if self.failed.is_none() {
            if let Err(e) = self.sink.triangle([a, b, c]) {
                self.failed = Some(e);
            }
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::{read_bytes, stream_bytes, Format, StreamBytesError};

    /// Every triangle handed on, as its corners.
    #[derive(Default)]
    struct Collect {
        corners: Vec<[[f64; 3]; 3]>,
        /// Refuse the triangle of this number.
        refuse: Option<usize>,
    }

    impl TriangleSink for Collect {
        fn triangle(&mut self, corners: [[f64; 3]; 3]) -> Result<(), IoError> {
            if self.refuse == Some(self.corners.len()) {
                return Err(IoError::File {
                    path: "spill".into(),
                    action: "write",
                    source: std::io::Error::other("disk full"),
                });
            }
            self.corners.push(corners);
            Ok(())
        }
    }

    /// A PLY file whose faces come before its vertices: each triangle waits for its
    /// corners, and comes once the vertices are read, in order.
    #[test]
    fn triangles_before_their_vertices_wait_for_them() {
        let ply =
            b"ply\nformat ascii 1.0\nelement face 2\nproperty list uchar int vertex_indices\n\
            element vertex 4\nproperty float x\nproperty float y\nproperty float z\nend_header\n\
            3 0 1 2\n3 2 1 3\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n";
        let mut sink = Collect::default();
        let streamed = stream_bytes(ply, Format::Ply, &mut sink).unwrap();
        assert_eq!((streamed.vertices, streamed.triangles), (4, 2));
        let p = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [1.0, 1.0, 0.0],
        ];
        assert_eq!(sink.corners, vec![[p[0], p[1], p[2]], [p[2], p[1], p[3]]]);
        assert_eq!(
            read_bytes(ply, Format::Ply).unwrap().mesh.triangle_count(),
            2
        );
    }

    /// The sink's error is the read's, even when the data goes wrong after it (the
    /// reader stops at its next record), and nothing is handed on after it.
    #[test]
    fn a_sink_error_ends_the_read() {
        let off = b"OFF\n4 3 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n3 0 x 1\n";
        assert!(
            read_bytes(off, Format::Off).is_err(),
            "the third face is malformed"
        );
        for format in [Format::Off, Format::Stl, Format::Ply, Format::Obj] {
            let data = match format {
                Format::Off => off.to_vec(),
                _ => {
                    let mesh = crate::IndexedMesh::new(
                        vec![[0.0; 3], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
                        vec![[0, 1, 2], [0, 2, 3], [1, 2, 3]],
                    );
                    let mut bytes = Vec::new();
                    crate::io::write_to(&mut bytes, &mesh, format).unwrap();
                    bytes
                }
            };
            let mut sink = Collect {
                refuse: Some(1),
                ..Collect::default()
            };
            match stream_bytes(&data, format, &mut sink) {
                Err(StreamBytesError::Sink(e)) => {
                    assert_eq!(e.to_string(), "spill: cannot write: disk full")
                }
                other => panic!("{format:?}: expected the sink's error, got {other:?}"),
            }
            assert_eq!(sink.corners.len(), 1, "{format:?}");
        }
    }

    /// A streaming read of an STL soup keeps no vertex between facets, and the
    /// checks of the whole mesh still hold: no triangle is an error, as for a read.
    #[test]
    fn stl_facets_are_forgotten_and_an_empty_file_is_refused() {
        let stl = b"solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n\
            vertex 0 1 0\nendloop\nendfacet\nfacet normal 0 0 1\nouter loop\nvertex 1 0 0\n\
            vertex 1 1 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid t\n";
        let mut sink = Collect::default();
        let streamed = stream_bytes(stl, Format::Stl, &mut sink).unwrap();
        assert_eq!((streamed.vertices, streamed.triangles), (6, 2));
        assert_eq!(
            sink.corners[1],
            [[1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]]
        );
        let empty = b"solid t\nendsolid t\n";
        let read = read_bytes(empty, Format::Stl).unwrap_err().to_string();
        match stream_bytes(empty, Format::Stl, &mut Collect::default()) {
            Err(StreamBytesError::Read(e)) => assert_eq!(e.to_string(), read),
            other => panic!("expected a read error, got {other:?}"),
        }
    }
}
