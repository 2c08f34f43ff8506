//! OBJ reader and writer. The reader streams: it reads the text a line at a time out of
//! the window of the I/O layer's input (`io::input::Input`, through
//! `io::text::TextStream`, as the OFF and PLY readers do), so neither the file nor its
//! decompressed text is ever held whole.
//!
//! # What the reader keeps
//! Positions (`v`), faces (`f`), and the mesh's attributes
//! ([`crate::attributes`]): texture coordinates (`vt`) and normals (`vn`) per corner,
//! each face's group (`o`/`g`) and material (`usemtl`), and the material files
//! (`mtllib`, not opened), and vertex colours (`v x y z r g b`, read as 0–1; a file
//! with a value above 1 is read as 0–255 levels; a component still outside 0–1 is
//! clamped, since no OBJ file could hold it: written back, a value above 1 would make
//! every colour a level). A corner without a `vt` or `vn` index has none
//! ([`Channel::MISSING`]). `l` and `p` elements, points and lines written as `f` with
//! one or two corners, and smoothing groups are ignored. Polygons are fan-triangulated
//! from their first corner, each triangle with its polygon's corners' values and
//! labels. `v x y z w` divides the coordinates by `w`.
//!
//! # Vertex order
//! The reader numbers vertices as the `tobj`-based reader it replaced did, so that a
//! file loads to the same mesh as before: the file is cut into *sections* at each
//! `o`/`g` line that follows a face, and each section numbers the vertices, texture
//! coordinates and normals in the order its faces first use them. So compared with the
//! file: **vertices no face uses are dropped, vertices used by several sections appear
//! once per section** (at the same position, so an exact weld joins them again), and
//! the order follows first use. Triangle count and order are the file's. A section
//! whose first corner has no `vt` index (while the file has texture coordinates) gets
//! the file's first texture coordinate as its first value, which no corner uses
//! (likewise for normals). A face may name an element defined later in its section;
//! a vertex colour is the `n`-th colour of the file for the `n`-th vertex (a file where
//! only some `v` lines have colours therefore has them shifted, as before), and
//! colours are kept only when every section with faces had colours by its end.
//!
//! # Errors
//! Every error names the line (the first line of a continued line), except where the
//! old reader could not say where: an element named by a face and defined only after
//! the face's section (the message says which list), and checks of the whole mesh
//! ([`IndexedMesh::validate`]). Refused: bytes that are not UTF-8 on a `v`, `vt`, `vn`,
//! `f` or `l` line, `v` lines without three numbers or with a non-finite coordinate (of
//! a vertex a face uses) or a zero weight, `vt` and `vn` lines without enough numbers,
//! and every face index that is not an integer, is 0, points before the first element
//! or past the last one of its list. A texture coordinate, normal or vertex colour that
//! is not a finite 32-bit float is refused when the mesh keeps it.
//!
//! Which error is reported when a file has several is the old reader's choice, which
//! checked in two passes: first the text of the geometry lines and the face indices
//! (not 0, not before the start, not past the file's size in bytes), then, only when
//! the file could not be read, the numbers and the indices against the whole file's
//! counts; the first problem of the first pass that finds one is reported. So a bad
//! face index reported after a bad number earlier in the file is what the old reader
//! said too. To decide this without holding the file, the reader keeps, while it
//! reads, the first problem of each kind and the face indices past the end of their
//! list so far (only those that exceed every earlier one), and reads on to the end of
//! the file once it has a problem whose place depends on what follows.
//!
//! # Memory
//! While reading, the reader holds per element of the file: 24 bytes per `v` (its
//! position, f64) plus 4 bytes (where its vertex went in the current section), 12 more
//! per `v` with a colour; 8 + 4 per `vt`, 12 + 4 per `vn`; and per element of the
//! result: 4 bytes per output vertex, texture coordinate and normal (which file
//! element it is), 12 per triangle and 12 per triangle and kept channel (the corners).
//! At the end the maps are freed and the positions (and texture coordinates and
//! normals) are rearranged in place into the result's order (2 bytes per element of
//! bookkeeping), so the peak is about the result's arrays plus 8 bytes per element of
//! each list (a 4M-triangle sphere: 112 MB for 96 MB of arrays, 1.21 times with the
//! program; as `v/vt/vn` in four sections, 1.23 times; where the reader built on
//! `tobj` took 8.6 and 4.7 times: BENCHMARKS.md, "Loading"). Colours are gathered
//! into a new array (12 bytes per vertex more, only for files with colours).
//!
//! A streaming read (`io::stream`) holds the same per element of the file, but no
//! triangle (nor its corners' texture coordinates and normals) once every element its
//! section has named so far is read: the triangles are then handed on, each corner as
//! its vertex's position. Those that name an element not read yet are held until it
//! is (at the latest, their section's end); so are the triangles after them, so that
//! the sink sees the file's order.
//!
//! # Differences from the reader built on `tobj`
//! The old reader is kept for tests (`io::obj_legacy`), which check on random files,
//! the fuzz inputs and the corpus that both give the same meshes, notes and errors
//! (kind, line, message). Left different: an `l` polyline of three points or more
//! is skipped (`tobj` made it a face, so the old reader refused the file for a count
//! that did not match its own); a vertical tab (`\x0b`) is not whitespace between a
//! keyword and what follows (`tobj` split at it, the old scan did not, so they could
//! disagree about the line); `tobj`'s refusals without a line read "OBJ rejected:
//! ..." instead of "OBJ rejected by tobj: ..."; a file with more than 2^31 - 1 `v`,
//! `vt` or `vn` lines is refused as too large; and a read error of the file after a
//! problem in its content is not seen (the content's problem is reported, as for
//! the other streamed formats).
//!
//! # Lenient where the geometry is not at stake
//! Everything else may hold any bytes: comments, names and unknown lines. Names are
//! kept byte for byte ([`FaceLabels`]); skipped lines and lines that are not UTF-8 are
//! counted in [`ReadNotes`]. A UTF-8 byte order mark is skipped (by
//! [`read_bytes`](super::read_bytes)); `\r\n` line ends and tabs are whitespace. Line
//! continuations (`\\` at the end of a line) join the next line (the backslash and the
//! line break read as spaces). Unknown keywords and free text are skipped: a text file
//! with no `v`/`f` lines is "no triangles", not "not an OBJ file".
//!
//! The writer writes all of it: `mtllib`, `v` (with its colour; a vertex with colour
//! seams once per colour, which an exact weld joins again), `vt`, `vn`, then the faces as
//! `v/vt/vn` corners with a `g` or `usemtl` line wherever the group or material
//! changes (the first channel of each kind: OBJ has one slot each). Names are written
//! byte for byte, except that a line feed becomes a space and a name ending in a
//! backslash is followed by a space (which the reader trims), so that it does not
//! continue its line.

use std::io::Write;
use std::ops::Range;

use rustc_hash::FxHashMap;

use super::input::Input;
use super::stream::Triangles;
use super::text::{self, parse_f64, parse_i64, show, words, TextStream};
use super::{Format, Location, ReadError, ReadErrorKind, ReadNotes, SNIFF_HEAD};
use crate::attributes::{Attributes, Channel, ChannelKind, FaceLabels};
use crate::input::check_vertices;
use crate::{IndexedMesh, InputError, MAX_ELEMENTS};

/// No output element (in the maps from file elements to output elements).
const NONE: u32 = u32::MAX;
/// Marks an output element that copies an earlier output element (a file element used
/// by several sections) rather than a file element.
const DUP: u32 = 1 << 31;

/// The most `v`, `vt` or `vn` lines a file may have: their numbers must stay below
/// [`DUP`]. (Only the vertices the faces use count against [`MAX_ELEMENTS`].)
const FILE_LIST_LIMIT: usize = (DUP - 1) as usize;

/// Counts of `v`, `vt` and `vn` lines so far.
#[derive(Clone, Copy, Default)]
struct Counts {
    v: usize,
    vt: usize,
    vn: usize,
}

impl Counts {
    fn of(&self, kind: usize) -> usize {
        [self.v, self.vt, self.vn][kind]
    }
}

/// Names of the three index slots of a face corner, singular and plural.
const LISTS: [(&str, &str); 3] = [
    ("vertex", "vertices"),
    ("texture coordinate", "texture coordinates"),
    ("normal", "normals"),
];

/// The place of a problem in the file: line, then corner and slot in the line, so
/// that problems compare in the order the old reader's scans met them.
type Key = (usize, u32, u8);

/// A face index past the end of its list when it was read.
#[derive(Clone, Copy)]
struct Far {
    key: Key,
    face: usize,
    kind: usize,
    index: u64,
}

/// Face indices past their list's end, each larger than every one before it: the first
/// index in file order that exceeds any bound is among them.
///
/// A deque: as a list grows, the records its new length covers are dropped from the
/// front at each section's end ([`Records::drop_within`]), so a file of many sections
/// costs each record once (a `retain` over all of them at every section was quadratic:
/// 320,000 sections of one face each with growing `vt` indices and no `vt` line took
/// 21-29 s to read; found in review).
#[derive(Default)]
struct Records(std::collections::VecDeque<Far>);

impl Records {
    fn note(&mut self, far: Far) {
        if self.0.back().is_none_or(|r| far.index > r.index) {
            self.0.push_back(far);
        }
    }

    fn first_above(&self, bound: u64) -> Option<Far> {
        self.0.iter().find(|r| r.index > bound).copied()
    }

    /// Drops the records of indices at most `count` (now within their list): they are
    /// the first ones, the indices increasing.
    fn drop_within(&mut self, count: u64) {
        while self.0.front().is_some_and(|r| r.index <= count) {
            self.0.pop_front();
        }
    }
}

/// One of the file's lists (`v`, `vt` or `vn`) and the output elements made from it.
struct List<T> {
    /// Values in file order (`stride` numbers each for the flat lists).
    file: Vec<T>,
    /// Number of file elements.
    len: usize,
    /// File element -> its latest output element (current in the section when at or
    /// past `base`), or [`NONE`].
    map: Vec<u32>,
    /// Output elements of this section made for file elements not read yet.
    forward: FxHashMap<u32, u32>,
    /// Output element -> file element, or [`DUP`] | an earlier output element.
    src: Vec<u32>,
    /// Output elements before this section.
    base: u32,
    /// Largest file element given an output element in this section.
    max_new: u32,
}

impl<T> List<T> {
    fn new() -> Self {
        Self {
            file: Vec::new(),
            len: 0,
            map: Vec::new(),
            forward: FxHashMap::default(),
            src: Vec::new(),
            base: 0,
            max_new: 0,
        }
    }

    /// Notes that file element `len` was read (its values already pushed).
    #[inline]
    fn added(&mut self) {
        let i = self.len as u32;
        self.len += 1;
        let out = if self.forward.is_empty() {
            NONE
        } else {
            self.forward.remove(&i).unwrap_or(NONE)
        };
        self.map.push(out);
    }

    /// The output element of file element `i` in this section, made on first use.
    #[inline]
    fn output(&mut self, i: u32) -> u32 {
        let current = match self.map.get(i as usize) {
            Some(&m) => m,
            None => self.forward.get(&i).copied().unwrap_or(NONE),
        };
        if current != NONE && current >= self.base {
            return current;
        }
        let out = self.src.len() as u32;
        self.src
            .push(if current == NONE { i } else { DUP | current });
        match self.map.get_mut(i as usize) {
            Some(m) => *m = out,
            None => {
                self.forward.insert(i, out);
            }
        }
        self.max_new = self.max_new.max(i);
        out
    }

    /// The file element of output element `o`.
    fn file_element(&self, mut o: u32) -> u32 {
        while let Some(&s) = self.src.get(o as usize) {
            if s & DUP == 0 {
                return s;
            }
            o = s & !DUP;
        }
        NONE
    }

    /// Ends a section: every element it named is in the file.
    fn commit(&mut self) {
        self.base = self.src.len() as u32;
        self.max_new = 0;
    }

    /// Ends a section whose elements are dropped (no element of the list was in the
    /// file by its end, so none was kept).
    fn discard(&mut self) {
        self.src.truncate(self.base as usize);
        self.forward.clear();
        self.max_new = 0;
    }
}

/// Rearranges `data` (elements of `stride` values) into the output order of `src`:
/// element `j` becomes file element `src[j]`, or a copy of output element `i < j` for
/// `src[j] == DUP | i`; the result has `src.len()` elements. In place: the file
/// elements given an output element first move along the paths and cycles of the
/// map `j -> src[j]` (one to one), the copies come last.
fn gather<T: Copy + Default>(data: &mut Vec<T>, stride: usize, src: &[u32]) {
    let m = src.len();
    if src.iter().enumerate().all(|(j, &s)| s as usize == j) {
        data.truncate(m * stride);
        return;
    }
    let n = data.len() / stride;
    let size = n.max(m);
    data.resize(size * stride, T::default());
    let moves =
        |j: usize| -> Option<usize> { src.get(j).filter(|&&s| s & DUP == 0).map(|&s| s as usize) };
    let mut targeted = vec![false; size];
    for j in 0..m {
        if let Some(t) = moves(j).and_then(|k| targeted.get_mut(k)) {
            *t = true;
        }
    }
    let mut done = vec![false; size];
    let step = |data: &mut Vec<T>, from: usize, to: usize| {
        data.copy_within(from * stride..(from + 1) * stride, to * stride);
    };
    // Paths: from an element nobody reads, each takes the value of the next.
    for (j, &read) in targeted.iter().enumerate().take(m) {
        if read || moves(j).is_none() {
            continue;
        }
        let mut cur = j;
        while let Some(k) = moves(cur) {
            step(data, k, cur);
            done[cur] = true;
            cur = k;
        }
    }
    // Cycles: the first value is kept aside for the last.
    let mut first = vec![T::default(); stride];
    for j in 0..m {
        if done[j] || moves(j).is_none() {
            continue;
        }
        first.copy_from_slice(&data[j * stride..(j + 1) * stride]);
        let mut cur = j;
        loop {
            done[cur] = true;
            match moves(cur) {
                Some(k) if k != j => {
                    step(data, k, cur);
                    cur = k;
                }
                _ => {
                    data[cur * stride..(cur + 1) * stride].copy_from_slice(&first);
                    break;
                }
            }
        }
    }
    drop((targeted, done));
    for (j, &s) in src.iter().enumerate() {
        if s & DUP != 0 {
            step(data, (s & !DUP) as usize, j);
        }
    }
    data.truncate(m * stride);
}

/// Distinct names in order of first appearance (the maps answer "seen, and where?").
#[derive(Default)]
pub(super) struct Names {
    pub(super) groups: Vec<Vec<u8>>,
    pub(super) materials: Vec<Vec<u8>>,
    pub(super) libraries: Vec<Vec<u8>>,
    seen: [FxHashMap<Vec<u8>, u32>; 3],
}

impl Names {
    /// Adds a name of kind `which` (0 groups, 1 materials, 2 libraries) and returns
    /// its index, or [`FaceLabels::NONE`] for an empty name.
    pub(super) fn add(&mut self, which: usize, name: &[u8]) -> u32 {
        if name.is_empty() {
            return FaceLabels::NONE;
        }
        if let Some(&i) = self.seen[which].get(name) {
            return i;
        }
        let list = match which {
            0 => &mut self.groups,
            1 => &mut self.materials,
            _ => &mut self.libraries,
        };
        let i = list.len() as u32;
        self.seen[which].insert(name.to_vec(), i);
        list.push(name.to_vec());
        i
    }
}

/// Where the group or material changes: from triangle `first` on (in file order),
/// the faces have `label`.
#[derive(Clone, Copy)]
pub(super) struct LabelRun {
    pub(super) first: usize,
    pub(super) label: u32,
}

/// Adds `run`; a run starting where the last one starts replaces it (the last one
/// labels no face), so label lines without faces between them cost nothing (a file of
/// 20 MB of `g` lines held 8 bytes a byte of runs; found in review).
fn push_run(runs: &mut Vec<LabelRun>, run: LabelRun) {
    match runs.last_mut() {
        Some(last) if last.first == run.first => *last = run,
        _ => runs.push(run),
    }
}

/// Per-face labels from their runs, for `triangles` triangles; empty when there was
/// no label line.
pub(super) fn expand_runs(runs: &[LabelRun], triangles: usize) -> Vec<u32> {
    if runs.is_empty() {
        return Vec::new();
    }
    let mut faces = vec![FaceLabels::NONE; triangles];
    for (i, run) in runs.iter().enumerate() {
        let end = runs
            .get(i + 1)
            .map_or(triangles, |r| r.first)
            .min(triangles);
        if let Some(span) = faces.get_mut(run.first.min(end)..end) {
            span.fill(run.label);
        }
    }
    faces
}

/// Corners of a texture-coordinate or normal channel, made when the first corner has
/// a value (a file without `vt` holds no corners for them), for the triangles the
/// reader holds (all of them in an ordinary read; see [`Reader::held_from`]).
#[derive(Default)]
struct Corners {
    corners: Vec<[u32; 3]>,
    active: bool,
    /// Whether a corner of the current section has a value.
    section_values: bool,
    /// Whether a section kept so far had a corner with a value: the mesh has the
    /// channel.
    kept_values: bool,
}

impl Corners {
    /// Adds the corners of held triangle `t` (counted from the first held one).
    fn push(&mut self, t: usize, c: [u32; 3]) {
        if !self.active {
            if c == [Channel::MISSING; 3] {
                return;
            }
            self.active = true;
            self.corners.resize(t, [Channel::MISSING; 3]);
        }
        self.section_values |= c != [Channel::MISSING; 3];
        self.corners.push(c);
    }

    /// Ends a section: its values are the mesh's (`kept`), or marked missing from held
    /// triangle `from` on.
    fn end_section(&mut self, kept: bool, from: usize) {
        if kept {
            self.kept_values |= self.section_values;
        } else if let Some(span) = self.corners.get_mut(from..) {
            span.fill([Channel::MISSING; 3]);
        }
        self.section_values = false;
    }
}

/// A face corner's indices as written (0: slot empty).
type Corner = [i64; 3];

/// Where a streaming read handed on the current section's first triangles (see
/// [`Reader::flush`]): what [`Reader::first_out_of_bounds`] needs to know of them.
#[derive(Clone, Copy)]
struct Flushed {
    /// The number of output elements of each list made by then (the next new one).
    next: [u32; 3],
    /// The largest file vertex given an output vertex in the section by then.
    max_vertex: u32,
}

/// Everything the reader keeps between lines.
struct Reader<'a, 's> {
    v: List<[f64; 3]>,
    vt: List<f32>,
    vn: List<f32>,
    /// `v x y z r g b` colours, three numbers per `v` line that has them (an
    /// unparsable one ends its line's: as `tobj` did).
    colours: Vec<f32>,
    /// The triangles held, from triangle number `held_from` on, as output vertices:
    /// every triangle in an ordinary read; in a streaming read, those not handed on
    /// yet (see [`Reader::flush`]).
    triangles: Vec<[u32; 3]>,
    /// The number of the first triangle held (0 in an ordinary read).
    held_from: usize,
    /// Where a streaming read's triangles go (an ordinary read keeps its own list,
    /// which its corners' attributes index, and leaves this empty).
    out: &'a mut Triangles<'s>,
    /// In a streaming read, whether the current section's first triangles were handed
    /// on, and what was known then.
    flushed: Option<Flushed>,
    /// Whether the current section's texture coordinates (normals) start with the
    /// file's first as a stand-in, which no corner uses (see the module docs).
    stand_in: [bool; 2],
    uv: Corners,
    normal: Corners,
    /// Lines counted by keyword (the old reader's scan counted these).
    count: Counts,
    /// `f` lines so far.
    faces: usize,
    /// Triangles the faces make (also once building stopped).
    triangle_count: usize,
    /// Where the current section's triangles start.
    section_start: usize,
    /// Sections with vertices, with colours by their end and without.
    coloured: (usize, usize),
    names: Names,
    group_runs: Vec<LabelRun>,
    material_runs: Vec<LabelRun>,
    notes: ReadNotes,
    /// Building the mesh (no problem met yet that stops it).
    building: bool,
    /// Why the mesh cannot be built, when nothing located explains it better.
    failure: Option<ReadError>,
    /// First problem of the old reader's first pass (text of geometry lines, face
    /// indices).
    first_a: Option<(Key, ReadError)>,
    /// First problem of its second pass (numbers).
    first_d: Option<(Key, ReadError)>,
    /// Face indices past the end of their list so far, per list (past the file's
    /// count is a problem of the second pass).
    far: [Records; 3],
    /// Same, among faces the first pass checked in full: an index past the file's
    /// size in bytes is a problem of the first pass.
    far_bytes: Records,
    /// Scratch: the corners of the face being read.
    corners: Vec<Corner>,
}

/// What the old reader said when `tobj` refused the file and its own checks could not
/// say where: `what` is `tobj`'s reason.
fn unlocated(what: &str) -> ReadError {
    ReadError::new(
        ReadErrorKind::Malformed {
            detail: format!("OBJ rejected: {what} (line not located)"),
        },
        None,
    )
}

/// [`unlocated`] for an element named by a face and missing at its section's end.
fn section_error(what: &str) -> ReadError {
    unlocated(&format!("face {what} index out of bounds"))
}

const POSITION: &str = "position parse error";
const COLOUR: &str = "color parse error (too many or too few components)";

impl<'a, 's> Reader<'a, 's> {
    fn new(out: &'a mut Triangles<'s>) -> Self {
        Self {
            v: List::new(),
            vt: List::new(),
            vn: List::new(),
            colours: Vec::new(),
            triangles: Vec::new(),
            held_from: 0,
            out,
            flushed: None,
            stand_in: [false; 2],
            uv: Corners::default(),
            normal: Corners::default(),
            count: Counts::default(),
            faces: 0,
            triangle_count: 0,
            section_start: 0,
            coloured: (0, 0),
            names: Names::default(),
            group_runs: Vec::new(),
            material_runs: Vec::new(),
            notes: ReadNotes::default(),
            building: true,
            failure: None,
            first_a: None,
            first_d: None,
            far: Default::default(),
            far_bytes: Records::default(),
            corners: Vec::new(),
        }
    }

    /// Stops building: the mesh cannot be read, for `why` unless a located problem
    /// explains it.
    fn fail(&mut self, why: ReadError) {
        if self.building {
            self.building = false;
            self.failure = Some(why);
        }
    }

    fn problem_a(&mut self, key: Key, e: ReadError) {
        if self.first_a.is_none() {
            self.first_a = Some((key, e));
            self.building = false;
        }
    }

    fn problem_d(&mut self, key: Key, e: ReadError) {
        if self.first_d.is_none() {
            self.first_d = Some((key, e));
        }
    }

    /// One line (continuations joined); `seen` is how many bytes of the data were read
    /// up to its end.
    fn line(&mut self, no: usize, line: &[u8], seen: u64) {
        let ascii = line.is_ascii();
        let utf8_error = if ascii {
            None
        } else {
            std::str::from_utf8(line).err()
        };
        self.notes.non_utf8_lines += usize::from(utf8_error.is_some());
        let (key, rest) = keyword(line);
        if key.first() == Some(&b'#') {
            return;
        }
        let at = Location::Line(no);
        if let Some(e) = utf8_error.filter(|_| matches!(key, b"v" | b"vt" | b"vn" | b"f" | b"l")) {
            // Geometry stays strict: a byte that is not text cannot be a number.
            let detail = format!(
                "not valid UTF-8 text (byte {} of the line)",
                e.valid_up_to() + 1
            );
            self.problem_a((no, 0, 0), ReadError::malformed(at, detail));
            return;
        }
        match key {
            b"v" => self.vertex(no, rest, ascii),
            b"vt" => self.value(no, rest, ascii, 1),
            b"vn" => self.value(no, rest, ascii, 2),
            b"f" | b"l" => self.face(no, rest, key == b"f", seen),
            b"o" | b"g" => {
                // A new section starts here when the current one has faces.
                if self.triangle_count > self.section_start {
                    self.end_section();
                }
                self.section_start = self.triangle_count;
                let label = self.names.add(0, text::trim(rest));
                push_run(
                    &mut self.group_runs,
                    LabelRun {
                        first: self.triangle_count,
                        label,
                    },
                );
            }
            b"usemtl" => {
                let label = self.names.add(1, text::trim(rest));
                push_run(
                    &mut self.material_runs,
                    LabelRun {
                        first: self.triangle_count,
                        label,
                    },
                );
            }
            b"mtllib" => {
                self.names.add(2, text::trim(rest));
            }
            b"" => {}
            _ => self.notes.skipped_lines += 1,
        }
    }

    /// A `v` line.
    fn vertex(&mut self, no: usize, rest: &[u8], ascii: bool) {
        let v = self.count.v;
        self.count.v += 1;
        let at = Location::Line(no);
        let mut toks: [&[u8]; 8] = [&[]; 8];
        // The values as the old reader took them (`tobj`: split at Unicode whitespace)
        // and as its check of the numbers took them (ASCII whitespace).
        let n = split_values(rest, ascii, &mut toks);
        let mut vals = [None; 8];
        for (val, tok) in vals.iter_mut().zip(&toks).take(n.min(8)) {
            *val = parse_f64(tok);
        }
        if self.building {
            match (n, vals) {
                (3..=7, [Some(x), Some(y), Some(z), ..]) if n != 5 => {
                    let mut p = [x, y, z];
                    match n {
                        4 => match vals[3] {
                            Some(w) if w != 0.0 => p = p.map(|c| c / w),
                            Some(_) => self.fail(unlocated("scaling (w) by zero")),
                            None => self.fail(unlocated(POSITION)),
                        },
                        6 => {
                            for c in vals[3..6].iter().map_while(|c| *c) {
                                self.colours.push(c as f32);
                            }
                        }
                        7 => self.fail(unlocated(COLOUR)),
                        _ => {}
                    }
                    if self.building {
                        if self.v.len >= FILE_LIST_LIMIT {
                            self.fail(ReadError::mesh(
                                None,
                                InputError::TooLarge {
                                    what: "vertices",
                                    count: self.v.len + 1,
                                    limit: FILE_LIST_LIMIT,
                                },
                            ));
                        } else {
                            self.v.file.push(p);
                            self.v.added();
                        }
                    }
                }
                (3.., [Some(_), Some(_), Some(_), ..]) => self.fail(unlocated(COLOUR)),
                _ => self.fail(unlocated(POSITION)),
            }
        }
        if self.first_d.is_some() {
            return;
        }
        // The check of the numbers, on words split at ASCII whitespace.
        let (dn, dvals) = ascii_numbers(rest, ascii, (n, vals), &mut toks, 8);
        let key = (no, 0, 0);
        for k in 0..dn.min(3) {
            if dvals[k].is_none() {
                let detail = format!("vertex {v}: bad number {}", show(toks[k]));
                return self.problem_d(key, ReadError::malformed(at, detail));
            }
        }
        if dn < 3 {
            let detail = format!("vertex {v}: expected 3 numbers, found {dn}");
            return self.problem_d(key, ReadError::malformed(at, detail));
        }
        if !dvals[..3].iter().all(|c| c.is_some_and(f64::is_finite)) {
            let e = ReadError::mesh(Some(at), InputError::NonFiniteCoordinate { vertex: v });
            return self.problem_d(key, e);
        }
        match dn - 3 {
            0 => {}
            3 => {
                for k in 3..6 {
                    if dvals[k].is_some_and(|x| !(x as f32).is_finite()) {
                        let detail = format!(
                            "vertex {v}: colour: {} is not a finite 32-bit float",
                            show(toks[k])
                        );
                        return self.problem_d(key, ReadError::malformed(at, detail));
                    }
                }
            }
            1 => {
                if dvals[3].is_none_or(|w| w == 0.0 || !w.is_finite()) {
                    let detail = format!("vertex {v}: bad homogeneous weight {}", show(toks[3]));
                    self.problem_d(key, ReadError::malformed(at, detail));
                }
            }
            extra => {
                let detail = format!(
                    "vertex {v}: expected 3 coordinates, optionally followed by a weight or 3 \
                     colour values; found {} numbers",
                    3 + extra
                );
                self.problem_d(key, ReadError::malformed(at, detail));
            }
        }
    }

    /// A `vt` (`kind` 1) or `vn` (2) line.
    fn value(&mut self, no: usize, rest: &[u8], ascii: bool, kind: usize) {
        let (what, dim) = if kind == 1 {
            ("texture coordinate", 2)
        } else {
            ("normal", 3)
        };
        let index = self.count.of(kind);
        if kind == 1 {
            self.count.vt += 1;
        } else {
            self.count.vn += 1;
        }
        let at = Location::Line(no);
        let mut toks: [&[u8]; 8] = [&[]; 8];
        let n = split_values(rest, ascii, &mut toks);
        let mut vals = [None; 3];
        for (val, tok) in vals.iter_mut().zip(&toks).take(n.min(dim)) {
            *val = parse_f64(tok);
        }
        if self.building {
            let list = if kind == 1 {
                &mut self.vt
            } else {
                &mut self.vn
            };
            if n >= dim && vals[..dim].iter().all(Option::is_some) {
                if list.len >= FILE_LIST_LIMIT {
                    let what = if kind == 1 {
                        "texture coordinates"
                    } else {
                        "normals"
                    };
                    let count = list.len + 1;
                    self.fail(ReadError::mesh(
                        None,
                        InputError::TooLarge {
                            what,
                            count,
                            limit: FILE_LIST_LIMIT,
                        },
                    ));
                } else {
                    list.file
                        .extend(vals[..dim].iter().map(|x| x.unwrap_or(0.0) as f32));
                    list.added();
                }
            } else {
                let why = if kind == 1 {
                    "texcoord parse error"
                } else {
                    "normal parse error"
                };
                self.fail(unlocated(why));
            }
        }
        if self.first_d.is_some() {
            return;
        }
        let (dn, dvals) = ascii_numbers(rest, ascii, (n, vals), &mut toks, dim);
        let key = (no, 0, 0);
        for k in 0..dn.min(dim) {
            if dvals[k].is_none() {
                let detail = format!("{what} {index}: bad number {}", show(toks[k]));
                return self.problem_d(key, ReadError::malformed(at, detail));
            }
        }
        if dn < dim {
            let detail = format!("{what} {index}: expected {dim} numbers, found {dn}");
            return self.problem_d(key, ReadError::malformed(at, detail));
        }
        for k in 0..dim {
            if dvals[k].is_some_and(|x| !(x as f32).is_finite()) {
                let detail = format!(
                    "{what} {index}: {} is not a finite 32-bit float",
                    show(toks[k])
                );
                return self.problem_d(key, ReadError::malformed(at, detail));
            }
        }
    }

    /// An `f` (or `l`) line.
    fn face(&mut self, no: usize, rest: &[u8], is_face: bool, seen: u64) {
        let face = self.faces;
        self.faces += usize::from(is_face);
        if !is_face {
            // Lines and points are checked but not kept.
            self.notes.skipped_lines += 1;
        }
        let mut corners = std::mem::take(&mut self.corners);
        corners.clear();
        let ok = if plain_positive_corners(rest) {
            self.quick_corners(no, rest, face, &mut corners)
        } else {
            self.checked_corners(no, rest, face, seen, &mut corners)
        };
        if ok && is_face && corners.len() >= 3 {
            let made = corners.len() - 2;
            self.triangle_count += made;
            if self.building {
                self.build_face(&corners);
            }
        }
        self.corners = corners;
    }

    /// Notes index `i` (positive) of slot `kind` at `key`, past the end of its list so
    /// far: a problem if the file never gets that far.
    fn far_index(&mut self, key: Key, face: usize, kind: usize, i: u64, full: bool, seen: u64) {
        let far = Far {
            key,
            face,
            kind,
            index: i,
        };
        if self.first_d.is_none() {
            self.far[kind].note(far);
        }
        if full && i > seen && self.first_a.is_none() {
            self.far_bytes.note(far);
        }
    }

    /// Corners all `a[/[b][/c]]` with positive indices of at most 15 digits (see
    /// [`plain_positive_corners`]): no check can fail but an index past the end.
    fn quick_corners(
        &mut self,
        no: usize,
        rest: &[u8],
        face: usize,
        out: &mut Vec<Corner>,
    ) -> bool {
        let mut corner = [0i64; 3];
        let mut slot = 0;
        let mut value = 0i64;
        let mut digits = false;
        let finish = |corner: &mut [i64; 3], slot: usize, value: i64, digits: bool| {
            if digits {
                corner[slot] = value;
            }
        };
        for &b in rest.iter().chain(std::iter::once(&b' ')) {
            match b {
                b'0'..=b'9' => {
                    value = value * 10 + i64::from(b - b'0');
                    digits = true;
                }
                b'/' => {
                    finish(&mut corner, slot, value, digits);
                    slot += 1;
                    (value, digits) = (0, false);
                }
                _ => {
                    finish(&mut corner, slot, value, digits);
                    if digits || slot > 0 {
                        out.push(corner);
                    }
                    corner = [0; 3];
                    slot = 0;
                    (value, digits) = (0, false);
                }
            }
        }
        for (c, corner) in out.iter().enumerate() {
            for (kind, &i) in corner.iter().enumerate() {
                if i as usize > self.count.of(kind) {
                    let key = (no, c as u32, kind as u8);
                    if self.first_d.is_none() {
                        self.far[kind].note(Far {
                            key,
                            face,
                            kind,
                            index: i as u64,
                        });
                    }
                }
            }
        }
        true
    }

    /// Corners checked one by one as the old reader's first pass did.
    fn checked_corners(
        &mut self,
        no: usize,
        rest: &[u8],
        face: usize,
        seen: u64,
        out: &mut Vec<Corner>,
    ) -> bool {
        let at = Location::Line(no);
        for (c, word) in words(rest).enumerate() {
            let key = (no, c as u32, 0);
            if word.iter().filter(|&&b| b == b'/').count() > 2 || word.first() == Some(&b'/') {
                let detail = format!("face {face}: bad corner {}", show(word));
                self.problem_a(key, ReadError::malformed(at, detail));
                return false;
            }
            let mut corner = [0i64; 3];
            for (kind, part) in word.split(|&b| b == b'/').enumerate() {
                if part.is_empty() {
                    continue;
                }
                let (what, whats) = LISTS[kind];
                let key = (no, c as u32, kind as u8);
                let Some(i) = parse_i64(part) else {
                    let detail = format!("face {face}: bad {what} index {}", show(part));
                    self.problem_a(key, ReadError::malformed(at, detail));
                    return false;
                };
                let before = self.count.of(kind);
                if i == 0 {
                    let detail =
                        format!("face {face}: {what} index 0 is invalid (OBJ indices start at 1)");
                    self.problem_a(key, ReadError::malformed(at, detail));
                    return false;
                }
                if i < 0 && i.unsigned_abs() > before as u64 {
                    let detail = format!(
                        "face {face}: relative {what} index {i} points before the first one \
                         ({before} {whats} so far)"
                    );
                    self.problem_a(key, ReadError::malformed(at, detail));
                    return false;
                }
                if i > 0 && i as u64 > before as u64 {
                    self.far_index(key, face, kind, i as u64, true, seen);
                }
                corner[kind] = i;
            }
            out.push(corner);
        }
        true
    }

    /// Adds the fan triangles of a face whose corners passed the checks.
    fn build_face(&mut self, corners: &[Corner]) {
        let resolve = |i: i64, count: usize| -> Option<u32> {
            let file = if i < 0 { count as i64 + i } else { i - 1 };
            u32::try_from(file).ok().filter(|&f| f < DUP)
        };
        let first_in_section = self.made() == self.section_start;
        let mut out = [[0u32; 3]; 0].to_vec();
        out.reserve(corners.len());
        for (c, corner) in corners.iter().enumerate() {
            let Some(v) = resolve(corner[0], self.v.len) else {
                return self.fail(section_error("vertex"));
            };
            let pos = self.v.output(v);
            let mut slots = [pos, Channel::MISSING, Channel::MISSING];
            for kind in [1, 2] {
                let list = if kind == 1 {
                    &mut self.vt
                } else {
                    &mut self.vn
                };
                if corner[kind] != 0 {
                    let Some(i) = resolve(corner[kind], list.len) else {
                        return self.fail(section_error(["vertex", "texcoord", "normal"][kind]));
                    };
                    slots[kind] = list.output(i);
                } else if c == 0 && first_in_section {
                    // The section's first value is the file's first (no corner uses it).
                    list.output(0);
                    self.stand_in[kind - 1] = true;
                }
            }
            out.push(slots);
        }
        if self.v.src.len() > MAX_ELEMENTS {
            let count = self.v.src.len();
            return self.fail(ReadError::mesh(
                None,
                InputError::TooLarge {
                    what: "vertices",
                    count,
                    limit: MAX_ELEMENTS,
                },
            ));
        }
        let a = out[0];
        for pair in out[1..].windows(2) {
            let (b, c) = (pair[0], pair[1]);
            let t = self.made();
            if t >= MAX_ELEMENTS {
                return self.fail(ReadError::mesh(
                    None,
                    InputError::TooLarge {
                        what: "triangles",
                        count: t + 1,
                        limit: MAX_ELEMENTS,
                    },
                ));
            }
            let held = self.triangles.len();
            self.triangles.push([a[0], b[0], c[0]]);
            self.uv.push(held, [a[1], b[1], c[1]]);
            self.normal.push(held, [a[2], b[2], c[2]]);
        }
        if self.out.is_streamed() && self.all_read() {
            self.flush();
        }
    }

    /// Whether every element the section's corners named so far is read: then
    /// nothing held can matter to the section's error any more but through
    /// [`Flushed`]. (The stand-in first value of a section without texture coordinates
    /// or normals may be missing: it is never the one an error names, see
    /// [`first_out_of_bounds`](Self::first_out_of_bounds), which starts after it.)
    fn all_read(&self) -> bool {
        let only_stand_in = |list: &List<f32>, stand_in: bool| {
            list.forward.is_empty()
                || (stand_in && list.forward.len() == 1 && list.forward.contains_key(&0))
        };
        self.v.forward.is_empty()
            && only_stand_in(&self.vt, self.stand_in[0])
            && only_stand_in(&self.vn, self.stand_in[1])
    }

    /// Triangles made so far (while building).
    fn made(&self) -> usize {
        self.held_from + self.triangles.len()
    }

    /// Hands the held triangles on (a streaming read), each vertex as its file
    /// element's position, once every vertex they name is read, and notes what
    /// [`first_out_of_bounds`](Self::first_out_of_bounds) needs to know of those of the
    /// current section.
    ///
    /// Why a streaming read may let them go: the section's error, if its end finds an
    /// element missing, is decided by the first new element in its corners whose file
    /// element is missing (or, for a vertex, its colour). Those handed on named only
    /// elements already read, so of them only a missing colour can decide it, which
    /// the largest vertex among them tells.
    fn flush(&mut self) {
        if self.triangles.is_empty() {
            return;
        }
        for &t in &self.triangles {
            let file = t.map(|o| self.v.file_element(o));
            self.out.push(file, &self.v.file);
        }
        self.held_from += self.triangles.len();
        self.triangles.clear();
        self.uv.corners.clear();
        self.normal.corners.clear();
        self.flushed = Some(Flushed {
            next: [&self.v.src, &self.vt.src, &self.vn.src].map(|src| src.len() as u32),
            max_vertex: self.v.max_new,
        });
    }

    /// Ends the current section: every element its faces named must be in the file by
    /// now (as `tobj` required), its colours decided.
    fn end_section(&mut self) {
        if !self.building {
            return;
        }
        let vertices = self.v.src.len() > self.v.base as usize;
        let colours_short = !self.colours.is_empty()
            && vertices
            && 3 * self.v.max_new as usize + 2 >= self.colours.len();
        let bad = !self.v.forward.is_empty()
            || colours_short
            || (self.vt.len > 0 && !self.vt.forward.is_empty())
            || (self.vn.len > 0 && !self.vn.forward.is_empty());
        if bad {
            let what = self.first_out_of_bounds();
            return self.fail(section_error(what));
        }
        if vertices {
            if self.colours.is_empty() {
                self.coloured.1 += 1;
            } else {
                self.coloured.0 += 1;
            }
        }
        self.v.commit();
        let section_held = self.section_start.saturating_sub(self.held_from);
        for (list, corners) in [
            (&mut self.vt, &mut self.uv),
            (&mut self.vn, &mut self.normal),
        ] {
            let kept = list.len > 0;
            if kept {
                list.commit();
            } else {
                list.discard();
            }
            corners.end_section(kept, section_held);
        }
        // Indices within their list by now can never be past the file's end.
        for (kind, far) in self.far.iter_mut().enumerate() {
            far.drop_within(self.count.of(kind) as u64);
        }
        if self.out.is_streamed() {
            self.flush();
        }
        self.flushed = None;
        self.stand_in = [false; 2];
        self.section_start = self.made();
    }

    /// Which list the first corner of the section that names an element missing at
    /// its end belongs to, in the order `tobj` met them: corner by corner, a new
    /// vertex (and its colour), then its texture coordinate, then its normal.
    fn first_out_of_bounds(&self) -> &'static str {
        let mut next = [self.v.base, self.vt.base, self.vn.base];
        if let Some(flushed) = self.flushed {
            // The section's first triangles were handed on (see `flush`).
            if !self.colours.is_empty() && 3 * flushed.max_vertex as usize + 2 >= self.colours.len()
            {
                return "vertex color";
            }
            next = flushed.next;
        } else {
            // A section whose first corner has no `vt` (`vn`) made the file's first
            // value its first, before any corner's.
            for (kind, corners, list) in [(1, &self.uv, &self.vt), (2, &self.normal, &self.vn)] {
                let first = corners
                    .corners
                    .get(self.section_start - self.held_from)
                    .map_or(Channel::MISSING, |c| c[0]);
                if first == Channel::MISSING && list.src.len() > list.base as usize {
                    next[kind] += 1;
                }
            }
        }
        for t in self.section_start.max(self.held_from) - self.held_from..self.triangles.len() {
            for k in 0..3 {
                let corner = [
                    Some(self.triangles[t][k]),
                    self.uv.corners.get(t).map(|c| c[k]),
                    self.normal.corners.get(t).map(|c| c[k]),
                ];
                for kind in 0..3 {
                    let Some(o) = corner[kind].filter(|&o| o != Channel::MISSING) else {
                        continue;
                    };
                    if o != next[kind] {
                        continue;
                    }
                    next[kind] += 1;
                    let (len, file) = match kind {
                        0 => (self.v.len, self.v.file_element(o)),
                        1 => (self.vt.len, self.vt.file_element(o)),
                        _ => (self.vn.len, self.vn.file_element(o)),
                    };
                    if kind > 0 && len == 0 {
                        continue;
                    }
                    if file as usize >= len {
                        return ["vertex", "texcoord", "normal"][kind];
                    }
                    if kind == 0
                        && !self.colours.is_empty()
                        && 3 * file as usize + 2 >= self.colours.len()
                    {
                        return "vertex color";
                    }
                }
            }
        }
        "vertex"
    }

    /// The old reader's first pass's first problem, once the data's size `len` is known:
    /// the text of a geometry line, a face index that is not one, is 0, points before
    /// the start or (checked only on faces that are not plain) past `len`.
    fn first_pass(&mut self, len: u64) -> Option<ReadError> {
        let bytes = self.far_bytes.first_above(len).map(|far| {
            let (what, whats) = LISTS[far.kind];
            let detail = format!(
                "face {} refers to {what} {}, but there are only {len} {whats}",
                far.face, far.index
            );
            (
                far.key,
                ReadError::malformed(Location::Line(far.key.0), detail),
            )
        });
        [self.first_a.take(), bytes]
            .into_iter()
            .flatten()
            .min_by_key(|(key, _)| *key)
            .map(|(_, e)| e)
    }

    /// The error for a file the old reader could not read (`failure`, the reason
    /// without a place): its second pass's first problem, when there is one.
    fn second_pass(&mut self, failure: ReadError) -> ReadError {
        let totals = self.count;
        let far = (0..3).filter_map(|kind| {
            let total = totals.of(kind);
            self.far[kind].first_above(total as u64).map(|far| {
                let (what, whats) = LISTS[kind];
                let detail = format!(
                    "face {} refers to {what} {}, but there are only {total} {whats}",
                    far.face, far.index
                );
                (
                    far.key,
                    ReadError::malformed(Location::Line(far.key.0), detail),
                )
            })
        });
        far.chain(self.first_d.take())
            .min_by_key(|(key, _)| *key)
            .map_or(failure, |(_, e)| e)
    }

    /// What [`Attributes::names`](crate::attributes::Attributes::names) says of the
    /// mesh [`finish`](Self::finish) makes in an ordinary read (before it).
    fn attribute_names(&self) -> Vec<String> {
        let mut kept = Attributes::default();
        let coloured = self.coloured.0 > 0 && self.coloured.1 == 0;
        for (kind, there) in [
            (ChannelKind::TexCoord, self.uv.kept_values),
            (ChannelKind::Normal, self.normal.kept_values),
            (ChannelKind::Color, coloured),
        ] {
            if there {
                kept.channels
                    .push(Channel::new(kind, Vec::new(), Vec::new()));
            }
        }
        // Each kind of label has one face at least (a mesh has a triangle) when it has
        // a run.
        let one = |runs: &[LabelRun]| expand_runs(runs, 1);
        kept.groups.faces = one(&self.group_runs);
        kept.materials.faces = one(&self.material_runs);
        kept.material_libraries = self.names.libraries.clone();
        kept.names()
    }

    /// The mesh, once every line is read and nothing stopped building. A streaming
    /// read's has no triangles (they were handed on), so neither per-corner nor
    /// per-face values.
    fn finish(&mut self) -> IndexedMesh {
        let triangles = std::mem::take(&mut self.triangles);
        let t = triangles.len();
        let mut mesh = IndexedMesh::default();
        let colours = (self.coloured.0 > 0 && self.coloured.1 == 0).then(|| {
            let mut out: Vec<f32> = Vec::with_capacity(3 * self.v.src.len());
            for &s in &self.v.src {
                let from = if s & DUP != 0 {
                    out.get(3 * (s & !DUP) as usize..).unwrap_or_default()
                } else {
                    self.colours.get(3 * s as usize..).unwrap_or_default()
                };
                let mut c = [0.0f32; 3];
                for (c, &x) in c.iter_mut().zip(from) {
                    *c = x;
                }
                out.extend_from_slice(&c);
            }
            out
        });
        self.colours = Vec::new();
        let mut positions = std::mem::take(&mut self.v.file);
        self.v.map = Vec::new();
        gather(&mut positions, 1, &self.v.src);
        self.v.src = Vec::new();
        mesh.positions = positions;
        for (mut list, corners, kind, dim) in [
            (
                std::mem::replace(&mut self.vt, List::new()),
                std::mem::take(&mut self.uv),
                ChannelKind::TexCoord,
                2,
            ),
            (
                std::mem::replace(&mut self.vn, List::new()),
                std::mem::take(&mut self.normal),
                ChannelKind::Normal,
                3,
            ),
        ] {
            if !corners.kept_values {
                continue;
            }
            let mut corners = corners.corners;
            corners.resize(t, [Channel::MISSING; 3]);
            list.map = Vec::new();
            let mut values = std::mem::take(&mut list.file);
            gather(&mut values, dim, &list.src);
            mesh.attributes
                .channels
                .push(Channel::new(kind, values, corners));
        }
        if let Some(mut colour) = colours {
            // Some exporters write 0–255 levels: a value above 1 says so.
            super::channels::unit_colours(&mut colour);
            mesh.attributes.channels.push(Channel::new(
                ChannelKind::Color,
                colour,
                triangles.clone(),
            ));
        }
        mesh.triangles = triangles;
        let names = std::mem::take(&mut self.names);
        mesh.attributes.groups = FaceLabels {
            names: names.groups,
            faces: expand_runs(&self.group_runs, t),
        };
        mesh.attributes.materials = FaceLabels {
            names: names.materials,
            faces: expand_runs(&self.material_runs, t),
        };
        mesh.attributes.material_libraries = names.libraries;
        mesh
    }
}

/// The words of `rest` split at ASCII whitespace (into `toks`) and the first `take` of
/// them (at most `N`) read as numbers, with their count: `split`, the count and numbers
/// of the split already made, when that split was the same (an ASCII line without a
/// vertical tab). The numbers are checked on these words, as the reader before
/// streaming split them.
fn ascii_numbers<'a, const N: usize>(
    rest: &'a [u8],
    ascii: bool,
    split: (usize, [Option<f64>; N]),
    toks: &mut [&'a [u8]; 8],
    take: usize,
) -> (usize, [Option<f64>; N]) {
    if ascii && !rest.contains(&0x0b) {
        return split;
    }
    *toks = [&[]; 8];
    let n = split_ascii(rest, toks);
    let mut vals = [None; N];
    for (val, tok) in vals.iter_mut().zip(toks.iter()).take(n.min(take)) {
        *val = parse_f64(tok);
    }
    (n, vals)
}

/// The line's keyword (its first word) and what follows it.
pub(super) fn keyword(line: &[u8]) -> (&[u8], &[u8]) {
    let line = text::trim_start(line);
    let end = line
        .iter()
        .position(|b| b.is_ascii_whitespace())
        .unwrap_or(line.len());
    (&line[..end], &line[end..])
}

/// Splits `rest` at ASCII whitespace into the first words of `out`; returns how many
/// words there are (all of them, also past `out`'s length).
fn split_ascii<'a>(rest: &'a [u8], out: &mut [&'a [u8]; 8]) -> usize {
    let mut n = 0;
    for w in words(rest) {
        if let Some(slot) = out.get_mut(n) {
            *slot = w;
        }
        n += 1;
    }
    n
}

/// Splits the numbers of a `v`, `vt` or `vn` line as the old reader took them: at
/// Unicode whitespace (`tobj` used `split_whitespace`), which for ASCII text is ASCII
/// whitespace and the vertical tab.
fn split_values<'a>(rest: &'a [u8], ascii: bool, out: &mut [&'a [u8]; 8]) -> usize {
    let mut n = 0;
    let mut put = |w: &'a [u8]| {
        if let Some(slot) = out.get_mut(n) {
            *slot = w;
        }
        n += 1;
    };
    if ascii {
        rest.split(|&b| b.is_ascii_whitespace() || b == 0x0b)
            .filter(|w| !w.is_empty())
            .for_each(&mut put);
    } else if let Ok(s) = std::str::from_utf8(rest) {
        s.split_whitespace().map(str::as_bytes).for_each(&mut put);
    }
    n
}

/// Whether a face line's corners are all `a[/[b][/c]]` with positive indices of at
/// most 15 digits (which cannot overflow anything), in one pass over the bytes.
pub(super) fn plain_positive_corners(rest: &[u8]) -> bool {
    let (mut digits, mut nonzero, mut slashes) = (0u32, false, 0u32);
    for &b in rest {
        match b {
            b'0'..=b'9' => {
                digits += 1;
                nonzero |= b != b'0';
                if digits > 15 {
                    return false;
                }
            }
            b'/' => {
                // A corner cannot start with "/", an index cannot be 0, at most 2 "/".
                if (slashes == 0 && digits == 0) || (digits > 0 && !nonzero) || slashes == 2 {
                    return false;
                }
                slashes += 1;
                (digits, nonzero) = (0, false);
            }
            b' ' | b'\t' | b'\r' => {
                if digits > 0 && !nonzero {
                    return false;
                }
                (digits, nonzero, slashes) = (0, false, 0);
            }
            _ => return false,
        }
    }
    digits == 0 || nonzero
}

/// A line's number, and where its bytes are: a range of the stream's window, or `None`
/// for [`Logical::joined`].
type LineAt = (usize, Option<Range<usize>>);

/// Lines with their continuations joined: a line ending in `\` (before its line
/// break) goes on with the next, the backslash and the line break read as spaces.
struct Logical {
    joined: Vec<u8>,
}

impl Logical {
    /// How the line `span` continues: `None` when it does not, else the length of its
    /// line break (1 or 2).
    fn continues(stream: &TextStream<'_, '_>, span: &Range<usize>) -> Option<usize> {
        if !stream.span(span.clone()).ends_with(b"\\") {
            return None;
        }
        match (
            stream.span(span.end..span.end + 1),
            stream.span(span.end + 1..span.end + 2),
        ) {
            (b"\n", _) => Some(1),
            (b"\r", b"\n") => Some(2),
            _ => None,
        }
    }

    /// The next line: its number, and where it is (in the stream's window, or in
    /// `joined` when it was continued).
    fn next(&mut self, stream: &mut TextStream<'_, '_>) -> Result<Option<LineAt>, ReadError> {
        let Some((no, mut span)) = stream.next_line_span()? else {
            return Ok(None);
        };
        if Self::continues(stream, &span).is_none() {
            return Ok(Some((no, Some(span))));
        }
        self.joined.clear();
        loop {
            let bytes = stream.span(span.clone());
            match Self::continues(stream, &span) {
                None => {
                    self.joined.extend_from_slice(bytes);
                    break;
                }
                Some(breaks) => {
                    self.joined
                        .extend_from_slice(bytes.get(..bytes.len() - 1).unwrap_or_default());
                    self.joined.extend(std::iter::repeat_n(b' ', 1 + breaks));
                }
            }
            match stream.next_line_span()? {
                Some((_, next)) => span = next,
                None => break,
            }
        }
        Ok(Some((no, None)))
    }
}

/// Replaces continuations (`\` and the line break after it) by spaces in a copy of
/// the data's start, as the old reader did before it looked at the text.
fn join_in(bytes: &mut [u8]) {
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'\\' {
            let len = match (bytes.get(i + 1), bytes.get(i + 2)) {
                (Some(b'\r'), Some(b'\n')) => 2,
                (Some(b'\n'), _) => 1,
                _ => 0,
            };
            if len > 0 {
                bytes[i..=i + len].fill(b' ');
            }
        }
        i += 1;
    }
}

/// Refuses data that is plainly another format (the old reader's check of the text's
/// start). Returns whether the text starts with whitespace too long to tell yet
/// whether `solid` (ASCII STL) follows: then the first line with content tells.
fn sniff(input: &mut Input<'_>) -> Result<bool, ReadError> {
    input.fill(SNIFF_HEAD + 8)?;
    let window = input.window();
    let mut head = window[..window.len().min(SNIFF_HEAD + 8)].to_vec();
    let whole = input.at_end() && head.len() == window.len();
    join_in(&mut head);
    let text = text::trim_start(&head);
    let pending = text.len() < 5 && !whole;
    let solid = super::starts_solid(text);
    let found = super::sniff_start(&head[..head.len().min(SNIFF_HEAD)], solid);
    if let Some(other) = found.filter(|&s| s != "an OBJ file") {
        return Err(not_obj(other));
    }
    Ok(pending)
}

fn not_obj(other: &'static str) -> ReadError {
    ReadError::not_this_format(Format::Obj, Some(other), "the content is not OBJ text")
}

/// Reads an OBJ file. An ordinary read (`triangles` keeping its list) returns the
/// whole mesh and leaves `triangles` empty. A streaming read hands each triangle to
/// `triangles` once the vertices it names are read, and returns the mesh without
/// triangles, with the names of what the file carries besides positions (which the
/// mesh, without its per-face labels, cannot show).
pub(crate) fn read(
    input: &mut Input<'_>,
    notes: &mut ReadNotes,
    triangles: &mut Triangles<'_>,
) -> Result<(IndexedMesh, Option<Vec<String>>), ReadError> {
    let mut solid_pending = sniff(input)?;
    let mut stream = TextStream::new(input, 1);
    let mut lines = Logical { joined: Vec::new() };
    let mut r = Reader::new(triangles);
    while let Some((no, span)) = lines.next(&mut stream)? {
        if r.out.has_failed() {
            return Err(Triangles::stopped());
        }
        let seen = stream.offset();
        let line = match &span {
            Some(span) => stream.span(span.clone()),
            None => &lines.joined[..],
        };
        if solid_pending && !text::trim_start(line).is_empty() {
            if super::starts_solid(text::trim_start(line)) {
                return Err(not_obj("an ASCII STL file"));
            }
            solid_pending = false;
        }
        r.line(no, line, seen);
        if r.first_a.is_some() {
            break;
        }
    }
    let seen = stream.offset();
    if r.first_a.is_some() {
        // An index past the end seen before this problem might be past the file's
        // size in bytes, which only its end tells.
        let len = if r.far_bytes.0.iter().any(|far| far.index > seen) {
            seen + stream.count_rest().unwrap_or(0)
        } else {
            seen
        };
        return Err(r.first_pass(len).unwrap_or_else(rejected));
    }
    r.end_section();
    if let Some(e) = r.first_pass(seen) {
        return Err(e);
    }
    if !r.building {
        let failure = r.failure.take().unwrap_or_else(rejected);
        return Err(r.second_pass(failure));
    }
    if r.out.has_failed() {
        return Err(Triangles::stopped());
    }
    let streamed = r.out.is_streamed();
    let names = streamed.then(|| r.attribute_names());
    let mesh = r.finish();
    let checked = if streamed {
        // `validate`'s checks in its order, on the mesh without its triangles (the
        // corners, handed on, named vertices in range by construction).
        check_vertices(&mesh.positions, 0, r.out.len())
            .and_then(|()| mesh.attributes.validate(0).map_err(InputError::Attributes))
    } else {
        mesh.validate()
    };
    if let Err(e) = checked {
        // Say where, when the check of the numbers can (e.g. a non-finite coordinate).
        return Err(r.second_pass(ReadError::mesh(None, e)));
    }
    notes.skipped_lines += r.notes.skipped_lines;
    notes.non_utf8_lines += r.notes.non_utf8_lines;
    Ok((mesh, names))
}

/// A refusal with nothing more to say (not reached: every path that stops reading
/// keeps its reason).
fn rejected() -> ReadError {
    ReadError::new(
        ReadErrorKind::Malformed {
            detail: "OBJ rejected".into(),
        },
        None,
    )
}

/// Writes a name (group, material, material library) as the reader will read it back,
/// byte for byte where OBJ can hold it: a line feed (a glTF name may have one) becomes
/// a space, and a name that ends in a backslash (or a carriage return) gets a space
/// after it, which the reader trims, since a backslash before the line break would
/// continue the line (a fuzzed `g seg \\` took the next `f` line into the name).
fn write_name(out: &mut impl Write, name: &[u8]) -> std::io::Result<()> {
    for (k, line) in name.split(|&b| b == b'\n').enumerate() {
        if k > 0 {
            out.write_all(b" ")?;
        }
        out.write_all(line)?;
    }
    if name.ends_with(b"\\") || name.ends_with(b"\r") {
        out.write_all(b" ")?;
    }
    Ok(())
}

pub(crate) fn write(
    out: &mut impl Write,
    mesh: &IndexedMesh,
    comments: &[String],
) -> std::io::Result<()> {
    let attrs = &mesh.attributes;
    // Colours go on `v` lines, one per vertex: with colour seams (a vertex whose
    // corners have different colours) its position is written once per colour, which
    // an exact weld joins again on reading. Texture coordinates and normals are per
    // corner, so the split leaves them alone.
    let colour = attrs
        .channel(ChannelKind::Color)
        .filter(|c| c.dimension == 3);
    let split = colour.map(|c| {
        let only = IndexedMesh::new(mesh.positions.clone(), mesh.triangles.clone())
            .with_attributes(crate::attributes::Attributes {
                channels: vec![c.clone()],
                ..Default::default()
            });
        crate::attributes::split_at_seams(&only)
    });
    let (positions, triangles) = match &split {
        Some(s) => (&s.positions, &s.triangles),
        None => (&mesh.positions, &mesh.triangles),
    };
    writeln!(out, "# written by qem")?;
    for c in comments {
        writeln!(out, "# {}", super::one_line(c))?;
    }
    writeln!(
        out,
        "# {} vertices, {} triangles",
        positions.len(),
        triangles.len()
    )?;
    for library in &attrs.material_libraries {
        out.write_all(b"mtllib ")?;
        write_name(out, library)?;
        out.write_all(b"\n")?;
    }
    for (v, [x, y, z]) in positions.iter().enumerate() {
        match &split {
            Some(s) => {
                let c = s.attributes.channels[0].value(v as u32);
                writeln!(out, "v {x} {y} {z} {} {} {}", c[0], c[1], c[2])?;
            }
            None => writeln!(out, "v {x} {y} {z}")?,
        }
    }
    // OBJ has one slot for texture coordinates and one for normals: the first channel
    // of each kind. (Other channels cannot be written in OBJ; the caller's report says
    // which were dropped: [`super::unwritable`].)
    let uv = attrs.channel(ChannelKind::TexCoord);
    let normal = attrs.channel(ChannelKind::Normal);
    if let Some(uv) = uv {
        for v in uv.values.chunks_exact(2) {
            writeln!(out, "vt {} {}", v[0], v[1])?;
        }
    }
    if let Some(normal) = normal {
        for v in normal.values.chunks_exact(3) {
            writeln!(out, "vn {} {} {}", v[0], v[1], v[2])?;
        }
    }
    let (mut group, mut material) = (FaceLabels::NONE, FaceLabels::NONE);
    for (t, corners) in triangles.iter().enumerate() {
        for (labels, current, keyword) in [
            (&attrs.groups, &mut group, &b"g"[..]),
            (&attrs.materials, &mut material, &b"usemtl"[..]),
        ] {
            let Some(&label) = labels.faces.get(t) else {
                continue;
            };
            if label != *current {
                *current = label;
                out.write_all(keyword)?;
                if let Some(name) = labels.names.get(label as usize) {
                    out.write_all(b" ")?;
                    write_name(out, name)?;
                }
                out.write_all(b"\n")?;
            }
        }
        out.write_all(b"f")?;
        for (k, &vertex) in corners.iter().enumerate() {
            let index = |c: Option<&Channel>| {
                // MISSING (u32::MAX) has no 1-based number: the slot stays empty.
                c.and_then(|c| c.corners[t][k].checked_add(1))
            };
            write!(out, " {}", vertex + 1)?;
            match (index(uv), index(normal)) {
                (None, None) => {}
                (Some(vt), None) => write!(out, "/{vt}")?,
                (None, Some(vn)) => write!(out, "//{vn}")?,
                (Some(vt), Some(vn)) => write!(out, "/{vt}/{vn}")?,
            }
        }
        out.write_all(b"\n")?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use std::io::Read;

    use super::super::input::Input;
    use super::super::{
        obj_legacy, read_bytes, read_input, strip_bom, Format, LoadedMesh, ReadError,
        ReadErrorKind, ReadNotes,
    };
    use super::*;

    /// Records come off the front as their list grows past them, and only those.
    #[test]
    fn records_within_a_grown_list_are_dropped_from_the_front() {
        let far = |index| Far {
            key: (0, 0, 0),
            face: 0,
            kind: 1,
            index,
        };
        let mut r = Records::default();
        for index in [5, 3, 9, 12, 12, 40] {
            r.note(far(index));
        }
        let indices = |r: &Records| r.0.iter().map(|f| f.index).collect::<Vec<_>>();
        assert_eq!(indices(&r), [5, 9, 12, 40]);
        r.drop_within(9);
        assert_eq!(indices(&r), [12, 40]);
        assert_eq!(r.first_above(12).map(|f| f.index), Some(40));
        r.drop_within(100);
        assert!(r.0.is_empty());
    }

    /// Many sections, each with a face naming a texture coordinate past the end of a
    /// file that has none (the input that made the records' scan quadratic): the same
    /// result as the old reader.
    #[test]
    fn many_sections_with_growing_missing_indices_read_as_before() {
        let mut text = String::from("v 0 0 0\nv 1 0 0\nv 0 1 0\n");
        for k in 1..=2000 {
            text.push_str(&format!("g\nf 1/{k} 2/{k} 3/{k}\n"));
        }
        let data = text.into_bytes();
        let new = read_bytes(&data, Format::Obj);
        if let Some(why) = differ(&new, &old(&data)) {
            panic!("{why}");
        }
    }

    /// What the reader before streaming (`tobj` given the whole text) gave.
    fn old(data: &[u8]) -> Result<LoadedMesh, ReadError> {
        if data.is_empty() {
            return Err(ReadError::new(ReadErrorKind::Empty, None));
        }
        let (rest, bom) = strip_bom(data);
        let mut notes = ReadNotes {
            byte_order_mark: bom,
            ..ReadNotes::default()
        };
        let mesh = obj_legacy::read(rest, &mut notes)?;
        mesh.validate().map_err(|e| ReadError::mesh(None, e))?;
        Ok(LoadedMesh { mesh, notes })
    }

    /// Whether two results are the same: equal meshes and notes, or errors of the same
    /// kind at the same place, with the same message unless the old one was `tobj`'s
    /// (which the new reader words without naming `tobj`).
    fn differ(
        new: &Result<LoadedMesh, ReadError>,
        old: &Result<LoadedMesh, ReadError>,
    ) -> Option<String> {
        match (new, old) {
            (Ok(a), Ok(b)) if a == b => None,
            (Err(a), Err(b)) => {
                let same_kind =
                    std::mem::discriminant(a.kind()) == std::mem::discriminant(b.kind());
                let old_msg = b.to_string();
                let same_msg = old_msg.contains("tobj") || a.to_string() == old_msg;
                (!(same_kind && a.location() == b.location() && same_msg))
                    .then(|| format!("new: {a}\nold: {b}"))
            }
            (a, b) => Some(format!(
                "new: {:?}\nold: {:?}",
                a.as_ref().map(|m| &m.mesh),
                b.as_ref().map(|m| &m.mesh)
            )),
        }
    }

    fn assert_same(data: &[u8], what: &str) {
        let new = read_bytes(data, Format::Obj);
        if let Some(d) = differ(&new, &old(data)) {
            panic!("{what}: {d}\ninput: {:?}", String::from_utf8_lossy(data));
        }
    }

    /// A reader that gives at most `step` bytes per read.
    struct Trickle<'a> {
        data: &'a [u8],
        step: usize,
    }

    impl Read for Trickle<'_> {
        fn read(&mut self, out: &mut [u8]) -> std::io::Result<usize> {
            let n = out.len().min(self.step).min(self.data.len());
            out[..n].copy_from_slice(&self.data[..n]);
            self.data = &self.data[n..];
            Ok(n)
        }
    }

    fn gzip(data: &[u8]) -> Vec<u8> {
        use std::io::Write;
        let mut enc = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
        enc.write_all(data).expect("memory writes");
        enc.finish().expect("memory writes")
    }

    /// `data` read through a reader that gives `step` bytes at a time, the input asking
    /// `chunk` bytes at a time.
    fn trickled(data: &[u8], step: usize, chunk: usize) -> Result<LoadedMesh, ReadError> {
        let reader = Trickle { data, step };
        let mut input =
            Input::reader(Box::new(reader), data.len() as u64, chunk).expect("memory reads");
        read_input(&mut input, Format::Obj, None)
    }

    /// A small deterministic generator (xorshift).
    struct Rng(u64);

    impl Rng {
        fn next(&mut self) -> u64 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            self.0
        }
        fn below(&mut self, n: u64) -> u64 {
            self.next() % n
        }
        fn pick<'a>(&mut self, xs: &[&'a str]) -> &'a str {
            xs[self.below(xs.len() as u64) as usize]
        }
    }

    /// A random OBJ-like text: mostly valid lines, with now and then (one in `rare`,
    /// or never when `rare` is 0) a bad number, a bad index, an odd byte; and
    /// continuations, CRLF, tabs, names, comments.
    fn random_obj(rng: &mut Rng, lines: usize) -> Vec<u8> {
        let rare = [0, 0, 0, 30, 200][rng.below(5) as usize];
        let odd = |rng: &mut Rng| rare > 0 && rng.below(rare) == 0;
        let mut out = Vec::new();
        let numbers = [
            "0", "1", "-1", "0.5", "2", "1e3", "3.25", "-0", "+4", ".5", "7.",
        ];
        let odd_numbers = [
            "x",
            "inf",
            "nan",
            "1e39",
            "1e400",
            "0x1",
            "1.5.2",
            "-infinity",
        ];
        let mut count = [0u64; 3];
        for _ in 0..lines {
            let number = |rng: &mut Rng| -> String {
                if odd(rng) {
                    rng.pick(&odd_numbers).to_string()
                } else {
                    rng.pick(&numbers).to_string()
                }
            };
            let line = match rng.below(24) {
                0..=5 => {
                    count[0] += 1;
                    let extra = match rng.below(14) {
                        0 if odd(rng) => format!(" {}", number(rng)),
                        1 => format!(" {} {} {}", number(rng), number(rng), number(rng)),
                        2 => format!(" 255 {} 0", rng.below(300)),
                        3 if odd(rng) => " 1 2".to_string(),
                        4 => " 2".to_string(),
                        _ => String::new(),
                    };
                    format!("v {} {} {}{extra}", number(rng), number(rng), number(rng))
                }
                6 | 7 => {
                    count[1] += 1;
                    if odd(rng) {
                        format!("vt {}", number(rng))
                    } else {
                        format!(
                            "vt {} {} {}",
                            number(rng),
                            number(rng),
                            rng.pick(&["", "0"])
                        )
                    }
                }
                8 | 9 => {
                    count[2] += 1;
                    format!("vn {} {} {}", number(rng), number(rng), number(rng))
                }
                10..=16 => {
                    let corners = match rng.below(12) {
                        0 => 1,
                        1 => 2,
                        2 | 3 => 4,
                        4 => 5 + rng.below(3),
                        _ => 3,
                    };
                    let form = rng.below(5);
                    let mut f = String::from(rng.pick(&["f", "f", "f", "f", "l"]));
                    if f == "l" {
                        f = "l 1 2".into();
                    }
                    for _ in 0..corners.min(if f == "f" { 99 } else { 0 }) {
                        let index = |rng: &mut Rng, kind: usize| -> String {
                            let n = count[kind].max(1);
                            if odd(rng) {
                                rng.pick(&["0", "-99", "400", "99999999999999999", "a", "+1"])
                                    .to_string()
                            } else {
                                match rng.below(12) {
                                    0 => format!("-{}", 1 + rng.below(n)),
                                    1 if rare > 0 => format!("{}", 1 + n + rng.below(3)),
                                    _ => format!("{}", 1 + rng.below(n)),
                                }
                            }
                        };
                        let c = match form {
                            0 => format!("{}/{}", index(rng, 0), index(rng, 1)),
                            1 => format!("{}//{}", index(rng, 0), index(rng, 2)),
                            2 => format!("{}/{}/{}", index(rng, 0), index(rng, 1), index(rng, 2)),
                            3 if rng.below(8) == 0 => format!("{}/", index(rng, 0)),
                            _ => index(rng, 0),
                        };
                        f.push_str(if rng.below(10) == 0 { "\t" } else { " " });
                        f.push_str(&c);
                    }
                    f
                }
                17 => format!(
                    "{} {}",
                    rng.pick(&["g", "o"]),
                    rng.pick(&["a", "b", "", "c d"])
                ),
                18 => format!("usemtl {}", rng.pick(&["m1", "m2", "", "caf\u{e9}"])),
                19 => "mtllib x.mtl".into(),
                20 => rng
                    .pick(&["# comment", "s 1", "", "  ", "p 1", "vp 1", "usemtl\tm"])
                    .into(),
                21 => "g caf\u{e9}".into(),
                _ => String::new(),
            };
            let mut bytes = line.into_bytes();
            match rng.below(30) {
                0 if odd(rng) => bytes.push(0xff),
                1 => bytes.splice(0..0, [0xe9u8]).for_each(drop),
                2 => bytes.extend(b" \\"),
                3 => bytes.push(b'\r'),
                4 => bytes.push(b'\t'),
                5 if odd(rng) => bytes.extend("\u{a0}1".as_bytes()),
                _ => {}
            }
            out.extend(bytes);
            out.push(b'\n');
        }
        if rng.below(4) == 0 {
            out.pop();
        }
        out
    }

    /// The old and the new reader agree on many random files with every kind of line
    /// and problem (and so on which problem a file with several is reported for).
    #[test]
    fn random_files_read_as_before() {
        let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
        let mut kinds = std::collections::BTreeMap::new();
        for case in 0..20_000 {
            let lines = 1 + rng.below(40) as usize;
            let data = random_obj(&mut rng, lines);
            let old = old(&data);
            let key = match &old {
                Ok(_) => "ok".to_string(),
                Err(e) => e.to_string().split(':').next().unwrap_or("").to_string(),
            };
            *kinds
                .entry(key.chars().take(12).collect::<String>())
                .or_insert(0) += 1;
            let new = read_bytes(&data, Format::Obj);
            if let Some(d) = differ(&new, &old) {
                panic!(
                    "case {case}: {d}\ninput: {:?}",
                    String::from_utf8_lossy(&data)
                );
            }
        }
        // Both outcomes are well represented.
        assert!(kinds.get("ok").copied().unwrap_or(0) > 2_000, "{kinds:?}");
        assert!(kinds.len() > 10, "{kinds:?}");
    }

    /// A streaming read fails as the ordinary read does, with the same message, or
    /// hands on its triangles, on random files (sections, elements named before they
    /// are read, every kind of problem) and on files where a section's first triangles
    /// were handed on before its end found an element missing.
    #[test]
    fn random_files_stream_as_they_read() {
        use crate::io::input::tests::check;
        let mut rng = Rng(0x51ed_270b_2f6c_11a3);
        for case in 0..3_000 {
            let lines = 1 + rng.below(40) as usize;
            let data = random_obj(&mut rng, lines);
            for chunk in [3, 4096] {
                check(&data, Format::Obj, chunk, true, &format!("case {case}"));
            }
        }
        let tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
        let cases = [
            // Handed on, then a later face of the section names a vertex never read.
            format!("{tri}f 1 2 3\nf 1 2 9\n"),
            // ... a texture coordinate never read (the file has some).
            format!("vt 0 0\n{tri}f 1/1 2/1 3/1\nf 1/1 2/1 3/7\n"),
            // ... a colour missing for a vertex handed on, the colours read later.
            format!("{tri}f 1 2 3\nv 0 0 1 1 0 0\nf 1 2 4\n"),
            // ... or for a vertex named after the hand-on only.
            "v 0 0 0 1 0 0\nv 1 0 0 1 0 0\nv 0 1 0 1 0 0\nf 1 2 3\nv 1 1 1\nf 1 2 4\n".to_string(),
            // A face before its vertices waits for them; then one that never comes.
            format!("f 1 2 3\n{tri}f 1 2 3\ng b\nf 4 5 6\n{tri}"),
            format!("f 1 2 3\n{tri}g b\nf 1 2 3\nf 1 2 3/1\n"),
            // Sections, labels, texture coordinates and normals, all read.
            format!("mtllib m.mtl\nvt 0 0\nvn 0 0 1\n{tri}usemtl a\nf 1/1/1 2/1/1 3/1/1\ng x\nf 3//1 2//1 1//1\n"),
        ];
        for data in &cases {
            for chunk in [1, 4096] {
                check(data.as_bytes(), Format::Obj, chunk, true, data);
            }
        }
    }

    /// A streaming read hands a triangle on as soon as the vertices it names are read,
    /// not at its section's end: before a later line turns out bad, the sink has it
    /// (with texture coordinates, normals and groups in the file or not). A triangle
    /// that names a vertex not read yet waits for it, and the ones after it too (until
    /// a face is read after it).
    #[test]
    fn triangles_are_handed_on_once_their_vertices_are_read() {
        #[derive(Default)]
        struct Count(usize);
        impl crate::io::TriangleSink for Count {
            fn triangle(&mut self, _: [[f64; 3]; 3]) -> Result<(), crate::io::IoError> {
                self.0 += 1;
                Ok(())
            }
        }
        let tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
        let bad = "f 1 2 x\n";
        for (data, handed_on) in [
            (format!("{tri}f 1 2 3\nf 3 2 1\n{bad}"), 2),
            (format!("g a\n{tri}f 1 2 3\ng b\nf 3 2 1\n{bad}"), 2),
            (
                format!("vt 0 0\nvn 0 0 1\n{tri}f 1/1/1 2/1/1 3//1\n{bad}"),
                1,
            ),
            (format!("vt 0 0\n{tri}f 1 2 3\nf 1/1 2/1 3/1\n{bad}"), 2),
            (format!("{tri}f 1 2 3\nf 1 2 4\nf 3 2 1\n{bad}"), 1),
            (
                format!("{tri}f 1 2 3\nf 1 2 4\nf 3 2 1\nv 1 1 0\nf 1 2 3\n{bad}"),
                4,
            ),
        ] {
            let mut sink = Count::default();
            let streamed = crate::io::stream_bytes(data.as_bytes(), Format::Obj, &mut sink);
            assert!(streamed.is_err(), "{data:?}");
            assert_eq!(sink.0, handed_on, "{data:?}");
        }
    }

    /// Problems whose report depends on more than their line, each as the old reader
    /// reported it (kind, line and message; `tobj`'s own refusals had no line).
    #[test]
    fn hand_picked_problems_read_as_before() {
        let tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
        let cases: Vec<(String, &str)> = vec![
            // A bad number, then a bad face index: the index is reported (the old
            // reader's first pass checked indices, not numbers).
            (format!("{tri}v 1 x 0\nf 1 2 0\n"), "line 5: face 0: vertex index 0 is invalid (OBJ indices start at 1)"),
            // A face naming a vertex defined later in its section: read.
            (format!("f 1 2 3\n{tri}"), "ok"),
            // ... in a later section: refused, without a line.
            (format!("f 1 2 3\ng b\n{tri}"), "OBJ rejected: face vertex index out of bounds (line not located)"),
            // ... and past the file's count: the face's line.
            (format!("{tri}f 1 2 4\n"), "line 4: face 0 refers to vertex 4, but there are only 3 vertices"),
            // An unused vertex with an infinite coordinate is dropped, not refused...
            (format!("{tri}v inf 0 0\nf 1 2 3\n"), "ok"),
            // ... but named when something else fails (a used NaN after it).
            ("v 0 0 0\nv inf 0 0\nv 1 0 0\nv 0 nan 0\nf 1 3 4\n".to_string(), "line 2: vertex 1 has a non-finite coordinate"),
            // An index past the file's size in bytes on a face the first pass checked
            // in full, after a later problem of the second pass.
            (format!("{tri}f 1 2 -1 99999999999999999\nvt x\n"), "line 4: face 0 refers to vertex 99999999999999999, but there are only"),
            // Colours on some `v` lines only: shifted as before when in range...
            ("v 5 5 5\nv 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 0 1 0 0 0 1\nf 1 2 3\n".to_string(), "ok"),
            // ... refused when not.
            ("v 0 0 0\nv 1 0 0 1 0 0\nv 0 1 0\nf 1 2 3\n".to_string(), "OBJ rejected: face vertex color index out of bounds (line not located)"),
            // Seven numbers on a `v` line split at a no-break space (`tobj` split there).
            ("v 0 0 0 1 0 0\u{a0}1\nv 1 0 0\nv 0 1 0\nf 1 2 3\n".to_string(), "OBJ rejected: color parse error (too many or too few components) (line not located)"),
            // A continued line is located at its first line.
            (format!("{tri}f 1 \\\n2 \\\r\n0\n"), "line 4: face 0: vertex index 0 is invalid (OBJ indices start at 1)"),
            // A section whose first corner has no `vt` gets the file's first value.
            ("vt 0.5 0.5\nvt 1 1\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2/2 3/2\ng b\nf 1/1 2/1 3\n".to_string(), "ok"),
        ];
        for (data, expected) in &cases {
            assert_same(data.as_bytes(), data);
            let got = match read_bytes(data.as_bytes(), Format::Obj) {
                Ok(_) => "ok".to_string(),
                Err(e) => e.to_string(),
            };
            assert!(got.starts_with(expected), "{data:?}: {got}");
        }
        // The one difference: a polyline (`l`) of three points or more is skipped,
        // where the old reader (`tobj` made it a triangle) refused the file.
        let data = format!("{tri}f 1 2 3\nl 1 2 3\n");
        let new = read_bytes(data.as_bytes(), Format::Obj).expect("a polyline is skipped");
        assert_eq!(new.mesh.triangles.len(), 1);
        assert_eq!(new.notes.skipped_lines, 1);
        assert!(old(data.as_bytes()).is_err());
    }

    /// Every OBJ of the shared corpus loads as before (mesh, attributes, labels, notes);
    /// skipped when the corpus is absent.
    #[test]
    fn corpus_objs_read_as_before() {
        let dir = std::path::Path::new("/work/shared/corpus");
        let Ok(entries) = std::fs::read_dir(dir) else {
            eprintln!("no corpus at {}: skipped", dir.display());
            return;
        };
        let mut paths: Vec<_> = entries
            .filter_map(|e| Some(e.ok()?.path()))
            .filter(|p| p.extension().is_some_and(|e| e == "obj"))
            .collect();
        paths.sort();
        for path in &paths {
            let data = std::fs::read(path).expect("a readable corpus file");
            let new = read_bytes(&data, Format::Obj);
            let old = old(&data);
            assert!(old.is_ok(), "{}: {:?}", path.display(), old.err());
            if let Some(d) = differ(&new, &old) {
                panic!("{}: {d}", path.display());
            }
        }
        eprintln!("{} corpus OBJ files read as before", paths.len());
    }

    /// The files named in `QEM_OBJ_COMPARE` (separated by `:`) read as before: for
    /// files too large to keep in the repository (the 4M-triangle spheres of
    /// BENCHMARKS.md, "Loading"). `QEM_OBJ_COMPARE=/tmp/sphere4m_tex.obj cargo test -p
    /// qem-mesh --features io --lib -- --ignored obj::tests::named`
    #[test]
    #[ignore = "reads the files named in QEM_OBJ_COMPARE"]
    fn named_files_read_as_before() {
        let names = std::env::var("QEM_OBJ_COMPARE").unwrap_or_default();
        for name in names.split(':').filter(|n| !n.is_empty()) {
            let data = std::fs::read(name).expect("a readable file");
            let new = read_bytes(&data, Format::Obj);
            let old = old(&data);
            if let Some(d) = differ(&new, &old) {
                panic!("{name}: {d}");
            }
            eprintln!("{name}: same");
        }
    }

    /// The fuzz target's seeds and regressions read as before.
    #[test]
    fn fuzz_inputs_read_as_before() {
        let fuzz = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fuzz");
        let mut seen = 0;
        for kind in ["corpus", "regressions"] {
            let Ok(entries) = std::fs::read_dir(fuzz.join(kind).join("read_obj")) else {
                continue;
            };
            for path in entries.filter_map(|e| Some(e.ok()?.path())) {
                let data = std::fs::read(&path).expect("a readable fuzz input");
                assert_same(&data, &path.display().to_string());
                seen += 1;
            }
        }
        assert!(seen > 0, "no fuzz inputs under {}", fuzz.display());
    }

    /// Text read through readers that give 1, 7 or 4096 bytes at a time (plain and
    /// gzipped, the input asking for a few bytes or a chunk at a time) reads as it does
    /// from memory: a chunk boundary anywhere (in a number, a `\r\n`, a continuation, a
    /// character) changes nothing.
    #[test]
    fn chunk_boundaries_change_nothing() {
        let mut rng = Rng(0x2545_f491_4f6c_dd1d);
        let mut cases: Vec<Vec<u8>> = (0..150)
            .map(|_| {
                let lines = 1 + rng.below(30) as usize;
                random_obj(&mut rng, lines)
            })
            .collect();
        cases.push(b"v 0 0 0\r\nv 1 0 0\r\nv 0 1 0\r\nvt 0 0\r\nf 1/1 2/1 \\\r\n3/1\r\n".to_vec());
        cases.push(b"\xEF\xBB\xBFv 0 0 0\nv 1 0 0\nv 0 1 0\ng caf\xe9\nf 1 2 3".to_vec());
        // The reader looks at the first 4 KiB at once (to tell other formats): a long
        // first line puts the rest past it, where reads come in pieces.
        let long = format!("# {}\n", "x".repeat(5000));
        let cases: Vec<Vec<u8>> = cases
            .into_iter()
            .flat_map(|data| [[long.as_bytes(), &data].concat(), data])
            .collect();
        for (n, data) in cases.iter().enumerate() {
            let whole = read_bytes(data, Format::Obj);
            for step in [1, 7, 4096] {
                for chunk in [3, 64, 1 << 20] {
                    for data in [data.clone(), gzip(data)] {
                        let parts = trickled(&data, step, chunk);
                        assert_eq!(
                            parts.as_ref().map_err(ToString::to_string),
                            whole.as_ref().map_err(ToString::to_string),
                            "case {n}, step {step}, chunk {chunk}"
                        );
                    }
                }
            }
        }
    }

    /// Rearranging in place gives what a copy gives: paths, cycles, dropped and
    /// repeated elements.
    #[test]
    fn gather_in_place_is_a_gather() {
        let mut rng = Rng(77);
        for _ in 0..2_000 {
            let n = rng.below(12) as usize;
            let data: Vec<u32> = (0..2 * n as u32).collect();
            // A section structure: each file element first used once, then repeats.
            let mut src = Vec::new();
            let mut first: Vec<Option<u32>> = vec![None; n];
            for _ in 0..rng.below(16) {
                if n == 0 {
                    break;
                }
                let f = rng.below(n as u64) as usize;
                match first[f] {
                    Some(o) if rng.below(2) == 0 => src.push(DUP | o),
                    Some(_) => {}
                    None => {
                        first[f] = Some(src.len() as u32);
                        src.push(f as u32);
                    }
                }
            }
            let expected: Vec<u32> = {
                let mut out: Vec<u32> = Vec::new();
                for &s in &src {
                    let from = if s & DUP != 0 {
                        out[2 * (s & !DUP) as usize..][..2].to_vec()
                    } else {
                        data[2 * s as usize..][..2].to_vec()
                    };
                    out.extend(from);
                }
                out
            };
            let mut got = data.clone();
            gather(&mut got, 2, &src);
            assert_eq!(got, expected, "src {src:?}");
        }
    }
}
