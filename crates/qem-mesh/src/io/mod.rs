//! Mesh file readers and writers: OBJ, PLY, STL, OFF and glTF 2.0 (`.gltf`, `.glb`),
//! each optionally gzipped.
//!
//! # Reading
//! [`read_path`] picks the format from the file name ([`Format::from_path`]: the
//! extension, case-insensitive, after stripping a trailing `.gz`), decompresses the
//! file as it reads it if it starts with the gzip magic bytes, and parses it as
//! [`read_bytes`] parses bytes in memory, with the same result. `read_bytes` is a pure
//! function from arbitrary bytes to a mesh or an error: it never panics and never
//! allocates more than the input can justify.
//!
//! **Streaming.** PLY (binary and ASCII), STL (binary and ASCII), OFF and OBJ are read
//! as they arrive, a chunk at a time (1 MiB): binary records whole, text a line or a
//! token at a time, so reading a file takes about the memory of the arrays it gives,
//! not the file's (or its decompressed data's) size on top (a 4M-triangle sphere: 1.04
//! times the arrays as OFF or ASCII PLY, 1.01 as ASCII STL, where it was 2.7 and 3.1
//! times; 1.21 as OBJ, where it was 8.6; figures in BENCHMARKS.md, "Loading"). A line
//! (or token) longer than a chunk is held whole while it is read, costing about its
//! length. Parsed from all their (decompressed) bytes at once: glTF; an ASCII STL whose bytes 80..84 (control
//! bytes there, not text) give a binary STL count of at most `MAX_ELEMENTS` triangles
//! and a size the data could have, since only its end says whether it is a binary
//! file; and STL text with more than 4 KiB of whitespace before `solid`. Whatever the
//! form, the result and the errors are those of reading the whole data at once: an
//! error that depends on what comes later (a cut element, a binary STL's size, an
//! ASCII PLY list longer than the rest of the file, a corrupt gzip stream) is given
//! once the rest has been read. One difference: a plain file's read error in a part
//! the reader never reaches (after an error in the content, or after a PLY file's
//! last element) is not seen, so the content's error stands, as it did for binary PLY
//! and STL (before the text formats streamed, their whole file was read first and its
//! read error won); gzip data is always read to its end.
//!
//! **Triangles as they are read.** [`stream_path`] (and [`stream_bytes`]) read as
//! [`read_path`] does but hand each triangle to a [`TriangleSink`] instead of keeping
//! a list: PLY, OFF, STL and OBJ without holding their triangles (see `io::stream`);
//! glTF is read whole first. `qem tiles split` and `--memory-budget` cut files into
//! tiles this way.
//!
//! Polygons are fan-triangulated from their first corner. Vertices are never welded
//! or removed by the PLY, STL and OFF readers (an STL facet gives three new vertices);
//! see [`obj`] for what the OBJ reader does to vertex order (numbered per `o`/`g`
//! section, as the `tobj`-based reader before it did), and
//! [`gltf`] for how glTF scenes, primitives and attributes become one mesh (and what
//! of a glTF file is not carried through).
//!
//! **What `read_*` checks.** The result is a mesh that passes
//! [`IndexedMesh::validate`]: at least one triangle, counts within
//! [`MAX_ELEMENTS`](crate::MAX_ELEMENTS), finite coordinates, indices in range. Where
//! possible these are reported during parsing with the line or byte where they occur.
//! Nothing else is checked or repaired: degenerate, duplicate and non-manifold faces
//! pass through to the cleaning stage.
//!
//! **Lenient where the geometry is not at stake.** Names, comments, unknown keywords
//! and properties may hold any bytes (Latin-1 names from CAD exports are common); a
//! UTF-8 byte order mark, `\r\n` line ends and tabs are accepted. What was passed over
//! is counted in [`LoadedMesh::notes`] ([`ReadNotes`]); OBJ names are kept byte for
//! byte ([`crate::attributes::FaceLabels`]). Numbers, counts and indices stay strict: a malformed one
//! is an error naming its line.
//!
//! **Bounded memory.** Counts above `MAX_ELEMENTS` are refused (an OBJ file may list
//! up to 2^31 - 1 `v`, `vt` and `vn` lines, about 28 bytes each while read; only the
//! elements its faces use count against `MAX_ELEMENTS`); no buffer is reserved
//! beyond what the remaining bytes could hold (for gzip data, whose size is known only
//! at its end, beyond what has arrived: the arrays grow as the data arrives); gzip
//! output is capped at [`GZIP_MAX_RATIO`] times the compressed size and at
//! [`GZIP_MAX_BYTES`]. A streamed binary PLY record, and a text line (or token), is
//! held whole before it is read: the window's buffer then grows to about that record
//! or line and one read (not to twice it: room doubles, but only what a read fills is
//! written), and never past what the rest of the data can hold, so a list that claims
//! more than the file holds costs at most the rest of the file.
//!
//! # Writing
//! [`write_to`] writes any format to a `Write`; [`write_path`] writes a file
//! atomically (a temporary file in the same directory, then a rename), gzipped when the
//! name ends in `.gz`. [`write_atomically`] is that atomic step for any content
//! ([`write_json_atomically`] for JSON), and [`remove_stale_temporaries`] removes the
//! temporary files of writers that were killed before their rename. [`OutputStamp`]
//! and [`fingerprint`] tell a complete output, made with given options, from one cut
//! short, changed or made otherwise, for jobs that skip work already done.
//!
//! OBJ and OFF are text with coordinates written in Rust's shortest round-trip form,
//! PLY is `binary_little_endian` with `double` coordinates: all three read back
//! bit-exact. Attributes go where each format has room for them (OBJ `vt`/`vn`,
//! materials and groups; PLY and OFF per-vertex normals, colours and texture
//! coordinates and face colours, PLY also generic properties); [`unwritable`] says what
//! a format leaves out. STL is binary with `float32` coordinates (the format has no
//! other choice) and facet normals computed from the triangles; a coordinate beyond
//! float32's range (about ±3.4e38) is an `InvalidInput` error rather than an infinity
//! in the file. glTF (`.gltf` with its buffer embedded, or `.glb`) also has `float32`
//! positions; its attributes, materials and groups are described in [`gltf`].
//!
//! ```
//! use qem_mesh::io::{read_bytes, write_to, Format};
//! use qem_mesh::IndexedMesh;
//!
//! let mesh = IndexedMesh::new(
//!     vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.1]],
//!     vec![[0, 1, 2]],
//! );
//! let mut bytes = Vec::new();
//! write_to(&mut bytes, &mesh, Format::Ply).unwrap();
//! let loaded = read_bytes(&bytes, Format::Ply).unwrap();
//! assert_eq!(loaded.mesh, mesh);
//! ```

mod atomic;
mod channels;
mod error;
pub mod gltf;
mod input;
pub mod obj;
#[cfg(test)]
mod obj_legacy;
mod off;
mod ply;
mod stamp;
mod stl;
mod stream;
mod text;

use std::io::{Read, Write};
use std::path::Path;

pub use atomic::{
    directory_of, remove_stale_temporaries, remove_stale_temporaries_of, temporary_owner,
    write_atomically, write_json_atomically, write_new_atomically, STALE_AGE_WITHOUT_PROC,
    TEMP_MARKER,
};
pub use error::{IoError, Location, ReadError, ReadErrorKind};
use input::Input;
pub use stamp::{fingerprint, OutputStamp};
use stream::Triangles;
pub use stream::{Streamed, TriangleSink};

use crate::IndexedMesh;

/// The extensions [`Format::from_path`] accepts, as shown in error messages.
pub const SUPPORTED_EXTENSIONS: &str =
    ".obj, .ply, .stl, .off, .gltf, .glb (each optionally followed by .gz)";

/// Decompressed gzip data may be at most this many times the compressed size (plus
/// 64 KiB, so tiny files are never refused).
///
/// Why 64: glTF is read from the whole decompressed file (and before issue 30 OBJ was
/// too), and deflate can
/// expand up to about 1032:1, so a 1 MB "zip bomb" of whitespace would otherwise need
/// over 2 GB (measured: 2.0 GB peak RSS, see FUZZING.md). Real meshes compress far less: gzip -9
/// of the project's 49-mesh corpus gives at most 9:1 (OBJ text); 64 leaves a margin of
/// 7 times that while bounding memory at about 64 times the file size. What it refuses
/// is data made of long repeats, such as millions of copies of one face.
pub const GZIP_MAX_RATIO: u64 = 64;

/// Decompressed gzip data may be at most this many bytes (4 GiB).
pub const GZIP_MAX_BYTES: u64 = 4 << 30;

/// A mesh file format.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Format {
    /// Wavefront OBJ (text).
    Obj,
    /// Stanford PLY (ascii, binary little or big endian).
    Ply,
    /// STL (ascii or binary).
    Stl,
    /// Object File Format (text; `OFF`, `COFF`, `NOFF`, `STOFF`... headers).
    Off,
    /// glTF 2.0 JSON; buffers in `data:` URIs or in files beside it (see [`gltf`]).
    Gltf,
    /// glTF 2.0 binary container (GLB).
    Glb,
}

impl Format {
    /// All formats, in the order of [`SUPPORTED_EXTENSIONS`].
    pub const ALL: [Format; 6] = [
        Format::Obj,
        Format::Ply,
        Format::Stl,
        Format::Off,
        Format::Gltf,
        Format::Glb,
    ];

    /// The usual extension, lower case, without the dot.
    pub fn extension(self) -> &'static str {
        match self {
            Format::Obj => "obj",
            Format::Ply => "ply",
            Format::Stl => "stl",
            Format::Off => "off",
            Format::Gltf => "gltf",
            Format::Glb => "glb",
        }
    }

    /// The format's name with an article, for messages: "an OBJ", "a PLY".
    fn article_name(self) -> &'static str {
        match self {
            Format::Obj => "an OBJ",
            Format::Ply => "a PLY",
            Format::Stl => "an STL",
            Format::Off => "an OFF",
            Format::Gltf => "a glTF",
            Format::Glb => "a binary glTF",
        }
    }

    /// The format for an extension (without the dot, case-insensitive).
    pub fn from_extension(ext: &str) -> Option<Format> {
        Format::ALL
            .into_iter()
            .find(|f| f.extension().eq_ignore_ascii_case(ext))
    }

    /// The format named by a path's extension, after stripping a trailing `.gz`
    /// (case-insensitive). An unknown or missing extension is an error that lists the
    /// supported ones.
    ///
    /// ```
    /// use qem_mesh::io::Format;
    /// use std::path::Path;
    /// assert_eq!(Format::from_path(Path::new("bunny.PLY.gz")).unwrap(), Format::Ply);
    /// let err = Format::from_path(Path::new("bunny.js")).unwrap_err();
    /// assert!(err.to_string().starts_with("unsupported file extension \".js\""));
    /// ```
    pub fn from_path(path: &Path) -> Result<Format, ReadError> {
        let name = path
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        let stem = strip_gz(&name).unwrap_or(&name);
        let ext = Path::new(stem)
            .extension()
            .map(|e| e.to_string_lossy().into_owned())
            .unwrap_or_default();
        Format::from_extension(&ext).ok_or_else(|| {
            ReadError::new(ReadErrorKind::UnsupportedExtension { extension: ext }, None)
        })
    }
}

/// `name` without a trailing `.gz` (any case), or `None` if it has none.
fn strip_gz(name: &str) -> Option<&str> {
    let cut = name.len().checked_sub(3)?;
    let (stem, tail) = (name.get(..cut)?, name.get(cut..)?);
    tail.eq_ignore_ascii_case(".gz").then_some(stem)
}

/// A mesh as read from a file, with what the file held beside it.
#[derive(Clone, Debug, Default, PartialEq)]
#[non_exhaustive]
pub struct LoadedMesh {
    /// The triangles, positions and attributes (texture coordinates, normals,
    /// colours, materials, groups: what the format and the file carry); passes
    /// [`IndexedMesh::validate`].
    pub mesh: IndexedMesh,
    /// What the reader passed over without using it.
    pub notes: ReadNotes,
}

/// What a reader passed over: parts of the file that carry nothing qem uses.
///
/// The readers are lenient where a format gives bytes no meaning for the geometry
/// (names, comments, unknown keywords and properties) and strict where it does (a
/// malformed number is an error naming its line). These counts say how much was passed
/// over, so a report can show it; none of it changes the mesh.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[non_exhaustive]
pub struct ReadNotes {
    /// Lines skipped as unknown or unused: OBJ lines other than `v`, `vt`, `vn`, `f`,
    /// `o`, `g`, `usemtl`, `mtllib`, comments and blank lines (so `l`, `p`, `s`, `vp`,
    /// curve and surface statements, and unknown keywords); PLY header lines with a
    /// keyword the format does not define; ASCII STL lines holding a word outside STL's
    /// grammar; OFF lines after the last face. Default 0.
    pub skipped_lines: usize,
    /// PLY properties the reader does not use, counted once per declaration in the
    /// header: list properties other than the face element's indices, face properties
    /// other than its colour, all properties of other elements, and vertex properties
    /// that are not kept as channels (a lone member of a colour, normal or texture
    /// coordinate set such as `red` without `green`, a name another channel has, those
    /// past the channel limit). Scalar vertex properties are otherwise kept as
    /// channels ([`crate::attributes`]). glTF vertex attributes that are not read
    /// (`TANGENT`, `JOINTS_n`, `WEIGHTS_n`, matrix-typed `_NAME` ones), counted once per
    /// primitive and node, are counted here too. Default 0.
    pub skipped_properties: usize,
    /// glTF mesh primitives not read: points and lines (`POINTS`, `LINES`,
    /// `LINE_LOOP`, `LINE_STRIP`) and primitives without positions, counted once per
    /// node that places them. Default 0.
    pub skipped_primitives: usize,
    /// Text lines holding bytes that are not UTF-8 (in names and comments; Latin-1
    /// material names are common), read as bytes. Default 0.
    pub non_utf8_lines: usize,
    /// Whether the data began with a UTF-8 byte order mark (`EF BB BF`), which was
    /// skipped. Default `false`.
    pub byte_order_mark: bool,
}

impl ReadNotes {
    /// Whether the reader passed over anything at all.
    pub fn is_empty(&self) -> bool {
        *self == ReadNotes::default()
    }
}

/// The UTF-8 byte order mark some Windows tools put before text.
const BOM: &[u8] = b"\xEF\xBB\xBF";

/// `bytes` without a leading UTF-8 byte order mark, and whether there was one.
pub(crate) fn strip_bom(bytes: &[u8]) -> (&[u8], bool) {
    match bytes.strip_prefix(BOM) {
        Some(rest) => (rest, true),
        None => (bytes, false),
    }
}

/// Reads mesh data in `format` from memory. Gzip data (magic bytes `1f 8b`) is
/// decompressed first, whatever the format.
///
/// Never panics; the result passes [`IndexedMesh::validate`] (see the
/// [module docs](self) for what that covers).
///
/// ```
/// use qem_mesh::io::{read_bytes, Format};
/// let off = b"OFF\n4 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n";
/// let loaded = read_bytes(off, Format::Off).unwrap();
/// assert_eq!(loaded.mesh.triangles, vec![[0, 1, 2], [0, 2, 3]]);
///
/// let err = read_bytes(b"OFF\n3 1 0\n0 0 0\n1 0 0\n", Format::Off).unwrap_err();
/// assert_eq!(err.to_string(), "line 4: unexpected end of file after 2 of 3 vertices");
/// ```
pub fn read_bytes(bytes: &[u8], format: Format) -> Result<LoadedMesh, ReadError> {
    read_input(&mut Input::detect(bytes), format, None)
}

/// Reads `input` in `format`; a `.gltf`'s external buffers are opened with `external`.
fn read_input(
    input: &mut Input<'_>,
    format: Format,
    external: Option<gltf::External<'_>>,
) -> Result<LoadedMesh, ReadError> {
    let read = read_plain(input, format, external);
    // A gzip error anywhere in the stream wins over what the reader found.
    input.finish()?;
    read
}

fn read_plain(
    input: &mut Input<'_>,
    format: Format,
    external: Option<gltf::External<'_>>,
) -> Result<LoadedMesh, ReadError> {
    let mut triangles = Triangles::kept();
    let Parsed {
        mut mesh, notes, ..
    } = parse(input, format, external, &mut triangles)?;
    if hands_on_triangles(format, false) {
        mesh.triangles = triangles.into_kept();
    }
    let loaded = LoadedMesh { mesh, notes };
    // The parsers report most problems with a place; this is the safety net that makes
    // the documented guarantee hold whatever they missed.
    loaded
        .mesh
        .validate()
        .map_err(|e| ReadError::mesh(None, e))?;
    Ok(loaded)
}

/// What a streaming read ends with: the reader's result, or the error to give (the
/// sink's, or one of the data, which the caller names the file in).
pub(crate) enum StreamError {
    Read(ReadError),
    Sink(IoError),
}

impl From<ReadError> for StreamError {
    fn from(e: ReadError) -> Self {
        StreamError::Read(e)
    }
}

/// [`read_input`]'s streaming counterpart (see [`stream_path`]).
pub(crate) fn stream_input(
    input: &mut Input<'_>,
    format: Format,
    external: Option<gltf::External<'_>>,
    sink: &mut dyn TriangleSink,
) -> Result<Streamed, StreamError> {
    let read = stream_plain(input, format, external, sink);
    // The sink's error (the disk full, say) is the caller's to hear, whatever the
    // rest of the data holds; otherwise a gzip error wins, as for an ordinary read.
    if matches!(read, Err(StreamError::Sink(_))) {
        return read;
    }
    input.finish()?;
    read
}

fn stream_plain(
    input: &mut Input<'_>,
    format: Format,
    external: Option<gltf::External<'_>>,
    sink: &mut dyn TriangleSink,
) -> Result<Streamed, StreamError> {
    let mut triangles = Triangles::streamed(sink);
    let parsed = match parse(input, format, external, &mut triangles) {
        Ok(parsed) => parsed,
        // A reader that stopped for the sink's error gives that error.
        Err(e) => {
            return Err(match triangles.take_failure() {
                Some(sink) => StreamError::Sink(sink),
                None => StreamError::Read(e),
            })
        }
    };
    let Parsed { mesh, notes, names } = parsed;
    if !hands_on_triangles(format, true) {
        // Read whole: checked as an ordinary read is, then handed on.
        mesh.validate().map_err(|e| ReadError::mesh(None, e))?;
        for &t in &mesh.triangles {
            triangles.push(t, &mesh.positions);
        }
    }
    let triangle_count = triangles.len();
    let vertices = triangles.finish(&mesh.positions)?;
    Ok(Streamed {
        vertices,
        triangles: triangle_count,
        notes,
        attributes: names.unwrap_or_else(|| mesh.attributes.names()),
    })
}

/// Whether the reader of `format` gives its triangles to a [`Triangles`] as it reads
/// them, in a streaming read or an ordinary one: PLY, STL and OFF in both; OBJ only
/// when streaming (an ordinary read keeps its own list, which the corners of its
/// attributes follow); glTF in neither (read whole, then handed on).
fn hands_on_triangles(format: Format, streaming: bool) -> bool {
    match format {
        Format::Ply | Format::Stl | Format::Off => true,
        Format::Obj => streaming,
        Format::Gltf | Format::Glb => false,
    }
}

/// What [`parse`] read.
struct Parsed {
    /// The mesh, with or without its triangles ([`hands_on_triangles`]).
    mesh: IndexedMesh,
    /// What was passed over.
    notes: ReadNotes,
    /// The names of what the file carries besides positions, when the mesh cannot
    /// show them ([`Attributes::names`](crate::attributes::Attributes::names) of the
    /// mesh otherwise): a streamed OBJ drops its per-face labels.
    names: Option<Vec<String>>,
}

/// Parses `input` in `format`: the mesh and what was passed over, its triangles given
/// to `triangles` or in the mesh's list ([`hands_on_triangles`]).
fn parse(
    input: &mut Input<'_>,
    format: Format,
    external: Option<gltf::External<'_>>,
    triangles: &mut Triangles<'_>,
) -> Result<Parsed, ReadError> {
    input.fill(1)?;
    if input.window().is_empty() {
        return Err(ReadError::new(ReadErrorKind::Empty, None));
    }
    let mut notes = ReadNotes::default();
    // A byte order mark is text's; binary STL's 80-byte header may start with any
    // bytes, so the STL reader decides for itself once it knows which form it reads.
    if format != Format::Stl {
        notes.byte_order_mark = input.skip_bom()?;
    }
    // PLY, STL, OFF and OBJ are read as they arrive; glTF (JSON, and buffers anywhere in
    // it) from all its bytes.
    let (mesh, names) = match format {
        Format::Obj => obj::read(input, &mut notes, triangles)?,
        Format::Ply => (ply::read(input, &mut notes, triangles)?, None),
        Format::Stl => (stl::read(input, &mut notes, triangles)?, None),
        Format::Off => (off::read(input, &mut notes, triangles)?, None),
        Format::Gltf | Format::Glb => (
            gltf::read(&input.rest()?, format, external, &mut notes)?,
            None,
        ),
    };
    Ok(Parsed { mesh, notes, names })
}

/// Reads a mesh file; the format comes from the name ([`Format::from_path`]),
/// gzip is detected by content. Errors name the file. A `.gltf` file's external
/// buffers are read from paths relative to its directory.
///
/// ```
/// # fn main() -> Result<(), Box<dyn std::error::Error>> {
/// use qem_mesh::io::{read_path, write_path};
/// use qem_mesh::IndexedMesh;
/// let dir = tempfile::tempdir()?;
/// let path = dir.path().join("tri.stl.gz");
/// let mesh = IndexedMesh::new(vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], vec![[0, 1, 2]]);
/// write_path(&path, &mesh)?;
/// assert_eq!(read_path(&path)?.mesh, mesh);
///
/// let err = read_path(&dir.path().join("missing.obj")).unwrap_err();
/// assert!(err.to_string().contains("missing.obj: cannot read: "));
/// # Ok(()) }
/// ```
pub fn read_path(path: &Path) -> Result<LoadedMesh, IoError> {
    from_file(path, |input, format, external| {
        read_input(input, format, external).map_err(StreamError::Read)
    })
}

/// Runs `read` on the file at `path`, in the format its name gives, with a `.gltf`'s
/// external buffers read from beside it. Errors name the file; the system's error
/// reading the file wins over a problem of its content.
fn from_file<T>(
    path: &Path,
    read: impl FnOnce(&mut Input<'_>, Format, Option<gltf::External<'_>>) -> Result<T, StreamError>,
) -> Result<T, IoError> {
    let read_err = |source| IoError::Read {
        path: path.to_path_buf(),
        source,
    };
    let format = Format::from_path(path).map_err(read_err)?;
    let file_err = |source| IoError::File {
        path: path.to_path_buf(),
        action: "read",
        source,
    };
    let mut input = std::fs::File::open(path)
        .and_then(Input::file)
        .map_err(file_err)?;
    let dir = directory_of(path);
    let open = |uri: &str, len: usize| read_buffer_file(&dir.join(uri), len);
    let read = read(&mut input, format, Some(&open));
    // The system's error reading the file, not a problem of its content.
    if let Some(source) = input.take_file_error() {
        return Err(file_err(source));
    }
    match read {
        Ok(t) => Ok(t),
        Err(StreamError::Read(e)) => Err(read_err(e)),
        Err(StreamError::Sink(e)) => Err(e),
    }
}

/// Reads a mesh file as [`read_path`] does, but hands each triangle to `sink` as it is
/// read instead of keeping a list of them (see [`TriangleSink`] for what is held
/// meanwhile: for PLY, OFF, STL and OBJ, the vertices at most; glTF is read whole,
/// then handed on). It fails exactly when [`read_path`] fails, with the same
/// error, or when the sink fails, with the sink's; either way the sink may have been
/// given triangles first, which the caller must discard. On success the sink has seen
/// every triangle of the mesh [`read_path`] gives, as the positions of its corners,
/// in the file's order (a triangle that names a vertex not read yet comes once it is).
///
/// ```
/// # fn main() -> Result<(), Box<dyn std::error::Error>> {
/// use qem_mesh::io::{stream_path, write_path, IoError, TriangleSink};
/// use qem_mesh::IndexedMesh;
/// struct Count(usize);
/// impl TriangleSink for Count {
///     fn triangle(&mut self, _corners: [[f64; 3]; 3]) -> Result<(), IoError> {
///         self.0 += 1;
///         Ok(())
///     }
/// }
/// let dir = tempfile::tempdir()?;
/// let path = dir.path().join("two.ply");
/// let mesh = IndexedMesh::new(
///     vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]],
///     vec![[0, 1, 2], [1, 3, 2]],
/// );
/// write_path(&path, &mesh)?;
/// let mut count = Count(0);
/// let streamed = stream_path(&path, &mut count)?;
/// assert_eq!((count.0, streamed.triangles, streamed.vertices), (2, 2, 4));
/// # Ok(()) }
/// ```
pub fn stream_path(path: &Path, sink: &mut dyn TriangleSink) -> Result<Streamed, IoError> {
    from_file(path, |input, format, external| {
        stream_input(input, format, external, sink)
    })
}

/// [`stream_path`] for data in memory in `format` (gzip data decompressed first), as
/// [`read_bytes`] reads it: the same errors, the sink's aside.
pub fn stream_bytes(
    bytes: &[u8],
    format: Format,
    sink: &mut dyn TriangleSink,
) -> Result<Streamed, StreamBytesError> {
    match stream_input(&mut Input::detect(bytes), format, None, sink) {
        Ok(streamed) => Ok(streamed),
        Err(StreamError::Read(e)) => Err(StreamBytesError::Read(e)),
        Err(StreamError::Sink(e)) => Err(StreamBytesError::Sink(e)),
    }
}

/// Why [`stream_bytes`] failed.
#[derive(Debug)]
pub enum StreamBytesError {
    /// The data was refused, as [`read_bytes`] refuses it.
    Read(ReadError),
    /// The sink refused a triangle.
    Sink(IoError),
}

/// The first `len` bytes of a glTF buffer file; fewer when the file is shorter, which
/// the caller reports (it also names the buffer in errors). Reading stops at `len`, so
/// a large file is not read whole, and nothing is reserved for `len` up front, so a
/// buffer that declares more than its file holds costs only what the file holds.
fn read_buffer_file(path: &Path, len: usize) -> std::io::Result<Vec<u8>> {
    let mut data = Vec::new();
    std::fs::File::open(path)?
        .take(len as u64)
        .read_to_end(&mut data)?;
    Ok(data)
}

/// Something a mesh carries that a format cannot hold, and why: what a writer leaves
/// out, for the caller's report (see [`unwritable`]).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Unwritable {
    /// What is left out: a channel's name, `materials`, `groups` or `material
    /// libraries`.
    pub what: String,
    /// Why, in a few words.
    pub reason: &'static str,
}

/// What writing `attributes` in `format` leaves out, in the order of the channels and
/// then the labels; empty when the format keeps everything.
///
/// ```
/// use qem_mesh::attributes::{Attributes, Channel, ChannelKind};
/// use qem_mesh::io::{unwritable, Format};
/// let mut attributes = Attributes::default();
/// attributes.channels.push(Channel::new(ChannelKind::TexCoord, vec![0.0, 0.0], vec![[0; 3]]));
/// assert!(unwritable(&attributes, Format::Obj).is_empty());
/// assert_eq!(unwritable(&attributes, Format::Stl)[0].what, "uv");
/// ```
pub fn unwritable(attributes: &crate::attributes::Attributes, format: Format) -> Vec<Unwritable> {
    use crate::attributes::ChannelKind;
    let channels = &attributes.channels;
    let reasons: Vec<Option<&'static str>> = match format {
        Format::Stl => vec![Some("STL holds positions only"); channels.len()],
        Format::Obj => {
            let mut seen = Vec::new();
            channels
                .iter()
                .map(|c| {
                    let first_of_kind = !seen.contains(&c.kind);
                    seen.push(c.kind);
                    match c.kind {
                        ChannelKind::TexCoord | ChannelKind::Normal if first_of_kind => None,
                        ChannelKind::TexCoord | ChannelKind::Normal => {
                            Some("OBJ holds one texture coordinate and one normal per corner")
                        }
                        ChannelKind::Color if first_of_kind && c.dimension == 3 => None,
                        ChannelKind::Color if first_of_kind => {
                            Some("OBJ vertex colours are RGB (no alpha)")
                        }
                        ChannelKind::Color => Some("OBJ holds one colour per vertex"),
                        ChannelKind::Generic => Some("OBJ holds no other channels"),
                    }
                })
                .collect()
        }
        // The writers' own plans, so the report and the file cannot disagree.
        Format::Ply => ply::placements(channels)
            .into_iter()
            .map(|p| match p {
                ply::Placement::Left(reason) => Some(reason),
                ply::Placement::Vertex(_) | ply::Placement::Face(_) => None,
            })
            .collect(),
        Format::Off => off::slots(channels)
            .into_iter()
            .map(|s| match s {
                off::Slot::Left(reason) => Some(reason),
                off::Slot::Vertex | off::Slot::Face => None,
            })
            .collect(),
        Format::Gltf | Format::Glb => gltf::semantics(channels)
            .into_iter()
            .map(Result::err)
            .collect(),
    };
    let mut out: Vec<Unwritable> = channels
        .iter()
        .zip(reasons)
        .filter_map(|(c, reason)| {
            reason.map(|reason| Unwritable {
                what: c.name.clone(),
                reason,
            })
        })
        .collect();
    let labels = [
        ("materials", !attributes.materials.is_empty()),
        ("groups", !attributes.groups.is_empty()),
        (
            "material libraries",
            !attributes.material_libraries.is_empty(),
        ),
    ];
    for (what, present) in labels {
        let reason = match format {
            Format::Obj => None,
            Format::Stl => Some("STL holds positions only"),
            Format::Ply => Some("PLY has no materials, groups or material libraries"),
            Format::Off => Some("OFF has no materials, groups or material libraries"),
            // Materials and groups become glTF materials and meshes.
            Format::Gltf | Format::Glb => {
                Some("glTF has no material libraries").filter(|_| what == "material libraries")
            }
        };
        if let Some(reason) = reason.filter(|_| present) {
            out.push(Unwritable {
                what: what.to_string(),
                reason,
            });
        }
    }
    out
}

/// Writes `mesh` in `format` to `out` (uncompressed). See the [module docs](self) for
/// the exact encodings and [`unwritable`] for what a format leaves out. A triangle
/// index out of range, malformed attributes (what [`IndexedMesh::validate`] refuses in
/// them), or an STL coordinate beyond float32, is an `InvalidInput` error; nothing else
/// about the mesh is checked.
pub fn write_to<W: Write>(out: W, mesh: &IndexedMesh, format: Format) -> std::io::Result<()> {
    write_commented(out, mesh, format, &[])
}

/// [`write_to`] with `comments` in the file's header (one line each; a line break in
/// one becomes a space): PLY `comment` lines, OBJ and OFF `#` lines. STL and glTF get
/// none (STL has no place for them; glTF's would be JSON `extras`, not written yet).
pub fn write_commented<W: Write>(
    out: W,
    mesh: &IndexedMesh,
    format: Format,
    comments: &[String],
) -> std::io::Result<()> {
    // The writers index channels by triangle and corner: checked here, so a malformed
    // channel is an error rather than a panic.
    if let Err(e) = mesh.attributes.validate(mesh.triangles.len()) {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            e.to_string(),
        ));
    }
    let n = mesh.positions.len();
    if let Some((face, &index)) = mesh
        .triangles
        .iter()
        .enumerate()
        .find_map(|(f, t)| t.iter().find(|&&i| i as usize >= n).map(|i| (f, i)))
    {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            format!("face {face} refers to vertex {index}, but there are only {n} vertices"),
        ));
    }
    let mut out = std::io::BufWriter::with_capacity(1 << 16, out);
    match format {
        Format::Obj => obj::write(&mut out, mesh, comments)?,
        Format::Ply => ply::write(&mut out, mesh, comments)?,
        Format::Stl => stl::write(&mut out, mesh)?,
        Format::Off => off::write(&mut out, mesh, comments)?,
        Format::Gltf | Format::Glb => gltf::write(&mut out, mesh, format)?,
    }
    out.flush()
}

/// Writes `mesh` to `path` atomically, in the format its name gives (gzipped when it
/// ends in `.gz`).
///
/// The data goes to a new temporary file in the same directory, which is flushed to
/// disk and then renamed over `path`; on any error the temporary file is removed, so
/// `path` either keeps its old content or gets the complete new one
/// ([`write_atomically`]).
pub fn write_path(path: &Path, mesh: &IndexedMesh) -> Result<(), IoError> {
    write_path_commented(path, mesh, &[])
}

/// A comment as one line: line breaks become spaces.
pub(crate) fn one_line(comment: &str) -> String {
    comment.replace(['\r', '\n'], " ")
}

/// [`write_path`] with `comments` in the file's header (see [`write_commented`]).
pub fn write_path_commented(
    path: &Path,
    mesh: &IndexedMesh,
    comments: &[String],
) -> Result<(), IoError> {
    let format = Format::from_path(path).map_err(|source| IoError::Read {
        path: path.to_path_buf(),
        source,
    })?;
    let gz = path
        .file_name()
        .and_then(|n| n.to_str())
        .is_some_and(|n| strip_gz(n).is_some());
    write_atomically(path, |file| {
        if gz {
            let mut enc = flate2::write::GzEncoder::new(file, flate2::Compression::default());
            write_commented(&mut enc, mesh, format, comments)?;
            enc.finish()?;
            Ok(())
        } else {
            write_commented(file, mesh, format, comments)
        }
    })
}

/// Bytes of the data's start that [`sniff`] looks at (and, past them, only leading
/// whitespace).
pub(crate) const SNIFF_HEAD: usize = 4096;

/// What `bytes` look like, for error messages when they are not the claimed format.
pub(crate) fn sniff(bytes: &[u8]) -> Option<&'static str> {
    sniff_start(
        &bytes[..bytes.len().min(SNIFF_HEAD)],
        starts_solid(text::trim_start(bytes)),
    )
}

/// Whether text starts with `solid` (any case), as ASCII STL does.
pub(crate) fn starts_solid(text: &[u8]) -> bool {
    text.get(..5)
        .is_some_and(|w| w.eq_ignore_ascii_case(b"solid"))
}

/// [`sniff`] of the data `input` has not consumed yet, for an error found at its
/// start: whitespace past [`SNIFF_HEAD`] bytes is consumed rather than held.
pub(crate) fn sniff_input(input: &mut Input<'_>) -> Result<Option<&'static str>, ReadError> {
    input.fill(SNIFF_HEAD + 5)?;
    let window = input.window();
    let head = window[..window.len().min(SNIFF_HEAD)].to_vec();
    loop {
        let window = input.window();
        let text = text::trim_start(window);
        if text.len() >= 5 || input.at_end() {
            return Ok(sniff_start(&head, starts_solid(text)));
        }
        let (len, blank) = (window.len(), text.is_empty());
        if blank {
            input.consume(len);
        }
        input.fill(if blank { 5 } else { len + 1 })?;
    }
}

/// [`sniff`] from what it needs of the data: its first [`SNIFF_HEAD`] bytes (all of
/// it when shorter), and whether it starts with `solid` after leading whitespace.
pub(crate) fn sniff_start(head: &[u8], solid: bool) -> Option<&'static str> {
    const MAGIC: [(&[u8], &str); 7] = [
        (b"\x89PNG", "a PNG image"),
        (b"\xff\xd8\xff", "a JPEG image"),
        (b"GIF8", "a GIF image"),
        (b"%PDF", "a PDF document"),
        (b"PK\x03\x04", "a ZIP archive"),
        (b"\x1f\x8b", "gzip data"),
        (b"glTF", "a binary glTF file"),
    ];
    if let Some((_, what)) = MAGIC.iter().find(|(m, _)| head.starts_with(m)) {
        return Some(what);
    }
    if ply::starts_ply(head) {
        return Some("a PLY file");
    }
    let head = &head[..head.len().min(SNIFF_HEAD)];
    let first = text::first_content_line(head, b'#');
    let word = first.split(|b| b.is_ascii_whitespace()).next()?;
    if word.len() >= 3 && word.ends_with(b"OFF") && word.iter().all(u8::is_ascii_alphanumeric) {
        return Some("an OFF file");
    }
    if solid {
        return Some("an ASCII STL file");
    }
    if head.iter().all(|&b| b >= 0x20 || b.is_ascii_whitespace())
        && [
            &b"v"[..],
            b"vt",
            b"vn",
            b"f",
            b"o",
            b"g",
            b"mtllib",
            b"usemtl",
            b"s",
        ]
        .contains(&word)
    {
        return Some("an OBJ file");
    }
    if head.contains(&0) {
        return Some("binary data");
    }
    None
}
