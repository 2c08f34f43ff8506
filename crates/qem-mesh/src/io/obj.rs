//! OBJ reader (on top of `tobj`) and writer.
//!
//! # What the reader keeps and what `tobj` changes
//! Only `v`, `vt`, `vn` and `f` matter; `l` and `p` elements, points and lines written
//! as `f` with one or two corners, materials, groups and smoothing groups are ignored.
//! Polygons are fan-triangulated from their first corner (as `tobj` does with
//! `triangulate`).
//!
//! `tobj` splits the file into one model per `o`/`g`/`usemtl` section and numbers each
//! model's vertices in the order its faces first use them. The reader concatenates the
//! models, so compared with the file: **vertices no face uses are dropped, vertices used
//! by several sections appear once per section** (at the same position, so an exact weld
//! joins them again), and the order follows first use. Triangle count and order are
//! the file's.
//!
//! # Checks before `tobj`
//! `tobj` reports errors without a line, and some inputs make it misbehave (an index
//! past the start of a texture-coordinate or normal list overflows an index computation,
//! which panics in debug builds; index `0` in a `vt`/`vn` slot is silently treated as
//! "absent"). So the reader first scans the bytes itself and reports, with the line:
//! bytes that are not UTF-8 on a `v`, `vt`, `vn`, `f` or `l` line, `v` lines without
//! three numbers or with a non-finite coordinate or a zero `w`, `vt` and `vn` lines
//! without enough numbers, and every face index that is not an integer, is 0, points
//! before the first element or past the last one of its list. Whatever `tobj` still
//! refuses is reported with its own message and no line.
//!
//! # Lenient where the geometry is not at stake
//! Everything else may hold any bytes: comments, names and unknown lines. `tobj` reads
//! only UTF-8, so before it sees the text the reader blanks (overwrites with spaces, in
//! a copy, keeping every offset) comments and `usemtl`/`mtllib`/unknown lines that are
//! not UTF-8, the name of an `o`/`g` line that is not (the keyword stays: `tobj` starts
//! a new model there), `usemtl` lines `tobj` refuses (bare, or with a tab before the
//! name) and unknown lines with non-ASCII bytes (where `tobj`'s Unicode whitespace and
//! the scan's ASCII whitespace could disagree about the keyword). Names are kept byte
//! for byte in [`ObjAttributes`]; skipped lines and lines that are not UTF-8 are
//! counted in [`ReadNotes`]. A UTF-8 byte order mark is skipped (by
//! [`read_bytes`](super::read_bytes)); `\r\n` line ends and tabs are whitespace.
//!
//! Line continuations (`\\` at the end of a line) are joined before both.
//!
//! `tobj` accepts (and the reader therefore accepts) unknown keywords and free text on
//! lines it does not understand: a text file with no `v`/`f` lines is "no triangles",
//! not "not an OBJ file".

use std::io::Write;

use super::text::{self, parse_f64, parse_i64, show, words};
use std::collections::HashSet;

use super::{sniff, Format, Location, ReadError, ReadNotes};
use crate::{IndexedMesh, InputError};

/// Texture coordinates and normals of an OBJ file, indexed per triangle corner, and the
/// names it carries.
///
/// `texcoord_indices` and `normal_indices` are either empty (the file has none) or hold
/// one entry per triangle of [`LoadedMesh::mesh`](super::LoadedMesh::mesh), in the
/// same order; a corner without a texture coordinate or normal holds
/// [`ObjAttributes::MISSING`].
///
/// Names are kept byte for byte (OBJ does not say how names are encoded, and Latin-1
/// names are common in CAD exports): each is the rest of its line after the keyword,
/// without the ASCII whitespace around it, listed once, in order of first appearance.
/// Which faces a name applies to is not kept (yet).
#[derive(Clone, Debug, Default, PartialEq)]
#[non_exhaustive]
pub struct ObjAttributes {
    /// `vt` values (u, v) that faces use.
    pub texcoords: Vec<[f64; 2]>,
    /// `vn` values that faces use.
    pub normals: Vec<[f64; 3]>,
    /// Per triangle corner, an index into `texcoords`.
    pub texcoord_indices: Vec<[u32; 3]>,
    /// Per triangle corner, an index into `normals`.
    pub normal_indices: Vec<[u32; 3]>,
    /// Names of `o` and `g` lines.
    pub groups: Vec<Vec<u8>>,
    /// Names of `usemtl` lines.
    pub materials: Vec<Vec<u8>>,
    /// File names of `mtllib` lines (not opened).
    pub material_libraries: Vec<Vec<u8>>,
}

impl ObjAttributes {
    /// The index of a corner that has no texture coordinate or normal.
    pub const MISSING: u32 = u32::MAX;
}

/// Counts of `v`, `vt` and `vn` lines in the file.
#[derive(Clone, Copy, Default)]
struct Counts {
    v: usize,
    vt: usize,
    vn: usize,
}

fn keyword(line: &[u8]) -> (&[u8], &[u8]) {
    let line = text::trim_start(line);
    let end = line
        .iter()
        .position(|b| b.is_ascii_whitespace())
        .unwrap_or(line.len());
    (&line[..end], &line[end..])
}

/// What the first scan found besides errors: the lines to blank before `tobj` sees
/// the text, the names, and the notes.
#[derive(Default)]
struct Scan {
    /// Byte ranges to overwrite with spaces in the copy given to `tobj`.
    blank: Vec<std::ops::Range<usize>>,
    names: Names,
    notes: ReadNotes,
}

/// Distinct names in order of first appearance (the set only answers "seen?").
#[derive(Default)]
struct Names {
    groups: Vec<Vec<u8>>,
    materials: Vec<Vec<u8>>,
    libraries: Vec<Vec<u8>>,
    seen: [HashSet<Vec<u8>>; 3],
}

impl Names {
    fn add(&mut self, which: usize, name: &[u8]) {
        if name.is_empty() || self.seen[which].contains(name) {
            return;
        }
        self.seen[which].insert(name.to_vec());
        let list = match which {
            0 => &mut self.groups,
            1 => &mut self.materials,
            _ => &mut self.libraries,
        };
        list.push(name.to_vec());
    }
}

/// Whether `tobj` refuses this `usemtl` line: it takes the name after the first space
/// (not tab) and refuses an empty one. Materials are never loaded, so for `tobj` every
/// `usemtl` line is a no-op and blanking one changes nothing else.
fn tobj_refuses_usemtl(line: &[u8]) -> bool {
    match std::str::from_utf8(line) {
        Ok(l) => l
            .split_once(' ')
            .is_none_or(|(_, name)| name.trim().is_empty()),
        Err(_) => true,
    }
}

/// The scan described in the module docs.
///
/// With `detailed == false` only what guards `tobj` is checked (text of geometry lines,
/// face indices: not 0, not before the start, not absurdly large); the detailed scan
/// also checks the numbers of `v`/`vt`/`vn` lines and indices against the file's
/// totals, and runs only when `tobj` or validation has refused the data, to say where.
fn prescan(bytes: &[u8], detailed: bool) -> Result<Scan, ReadError> {
    if let Some(other) = sniff(bytes).filter(|&s| s != "an OBJ file") {
        return Err(ReadError::not_this_format(
            Format::Obj,
            Some(other),
            "the content is not OBJ text",
        ));
    }
    // No list can have more elements than the file has lines.
    let mut total = Counts {
        v: bytes.len(),
        vt: bytes.len(),
        vn: bytes.len(),
    };
    if detailed {
        total = Counts::default();
    }
    for (_, line) in text::lines(bytes).filter(|_| detailed) {
        match keyword(line).0 {
            b"v" => total.v += 1,
            b"vt" => total.vt += 1,
            b"vn" => total.vn += 1,
            _ => {}
        }
    }
    let mut so_far = Counts::default();
    let mut faces = 0usize;
    let mut scan = Scan::default();
    // One check of the whole text is much cheaper than one per line.
    let all_utf8 = std::str::from_utf8(bytes).is_ok();
    for (no, line) in text::lines(bytes) {
        let at = Location::Line(no);
        let (key, rest) = keyword(line);
        // Offset of the line in `bytes` (both are views of the same buffer).
        let start = line.as_ptr() as usize - bytes.as_ptr() as usize;
        let whole = start..start + line.len();
        let utf8_error = (!all_utf8)
            .then(|| std::str::from_utf8(line).err())
            .flatten();
        scan.notes.non_utf8_lines += usize::from(utf8_error.is_some());
        if key.first() == Some(&b'#') {
            if utf8_error.is_some() {
                scan.blank.push(whole);
            }
            continue;
        }
        let is_geometry = matches!(key, b"v" | b"vt" | b"vn" | b"f" | b"l");
        if let Some(e) = utf8_error.filter(|_| is_geometry) {
            // Geometry stays strict: a byte that is not text cannot be a number.
            return Err(ReadError::malformed(
                at,
                format!(
                    "not valid UTF-8 text (byte {} of the line)",
                    e.valid_up_to() + 1
                ),
            ));
        }
        let numbers = |n: usize, what: &str, index: usize| -> Result<[f64; 3], ReadError> {
            let mut vals = [0.0; 3];
            let mut found = 0;
            for (slot, tok) in vals.iter_mut().zip(words(rest)).take(n) {
                *slot = parse_f64(tok).ok_or_else(|| {
                    ReadError::malformed(at, format!("{what} {index}: bad number {}", show(tok)))
                })?;
                found += 1;
            }
            if found < n {
                return Err(ReadError::malformed(
                    at,
                    format!("{what} {index}: expected {n} numbers, found {found}"),
                ));
            }
            Ok(vals)
        };
        match key {
            b"v" | b"vt" | b"vn" if !detailed => match key {
                b"v" => so_far.v += 1,
                b"vt" => so_far.vt += 1,
                _ => so_far.vn += 1,
            },
            b"v" => {
                let v = so_far.v;
                let p = numbers(3, "vertex", v)?;
                if !p.iter().all(|c| c.is_finite()) {
                    return Err(ReadError::mesh(
                        Some(at),
                        InputError::NonFiniteCoordinate { vertex: v },
                    ));
                }
                let mut extra = words(rest).skip(3);
                let first = extra.next();
                let n_extra = usize::from(first.is_some()) + extra.count();
                match (n_extra, first) {
                    (0 | 3, _) => {}
                    (_, Some(w)) if n_extra == 1 => {
                        if parse_f64(w).is_none_or(|w| w == 0.0 || !w.is_finite()) {
                            return Err(ReadError::malformed(
                                at,
                                format!("vertex {v}: bad homogeneous weight {}", show(w)),
                            ));
                        }
                    }
                    _ => {
                        return Err(ReadError::malformed(
                            at,
                            format!(
                                "vertex {v}: expected 3 coordinates, optionally followed by \
                                 a weight or 3 colour values; found {} numbers",
                                3 + n_extra
                            ),
                        ))
                    }
                }
                so_far.v += 1;
            }
            b"vt" => {
                numbers(2, "texture coordinate", so_far.vt)?;
                so_far.vt += 1;
            }
            b"vn" => {
                numbers(3, "normal", so_far.vn)?;
                so_far.vn += 1;
            }
            b"f" | b"l" => {
                // Nearly every face passes the quick check; the rest get the full one.
                let quick = !detailed && plain_positive_corners(rest);
                for corner in words(rest).filter(|_| !quick) {
                    check_corner(corner, faces, so_far, total, at)?;
                }
                faces += usize::from(key == b"f");
                // Lines and points are read (their indices guard tobj) but not kept.
                scan.notes.skipped_lines += usize::from(key == b"l");
            }
            b"o" | b"g" => {
                scan.names.add(0, text::trim(rest));
                // `tobj` starts a new model at every `o`/`g` line, which decides the
                // vertex order: keep the keyword, hide a name it cannot take as text.
                if utf8_error.is_some() {
                    scan.blank.push(start + line.len() - rest.len()..whole.end);
                }
            }
            b"usemtl" => {
                scan.names.add(1, text::trim(rest));
                if utf8_error.is_some() || tobj_refuses_usemtl(line) {
                    scan.blank.push(whole);
                }
            }
            b"mtllib" => {
                scan.names.add(2, text::trim(rest));
                if utf8_error.is_some() {
                    scan.blank.push(whole);
                }
            }
            b"" => {}
            _ => {
                scan.notes.skipped_lines += 1;
                // `tobj` splits words at Unicode whitespace and this scan at ASCII
                // whitespace; a line the scan does not know is hidden from `tobj` when
                // they could disagree (e.g. "v\u{a0}1 2 3"), so both skip it.
                if utf8_error.is_some() || !line.is_ascii() {
                    scan.blank.push(whole);
                }
            }
        }
    }
    Ok(scan)
}

/// Whether a face line's corners are all `a[/[b][/c]]` with positive indices of at
/// most 15 digits (which cannot overflow anything), in one pass over the bytes.
fn plain_positive_corners(rest: &[u8]) -> bool {
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

/// Checks one `v[/vt[/vn]]` face corner.
fn check_corner(
    corner: &[u8],
    face: usize,
    so_far: Counts,
    total: Counts,
    at: Location,
) -> Result<(), ReadError> {
    let bad_corner =
        || ReadError::malformed(at, format!("face {face}: bad corner {}", show(corner)));
    if corner.iter().filter(|&&b| b == b'/').count() > 2 || corner.first() == Some(&b'/') {
        return Err(bad_corner());
    }
    let parts = corner.split(|&b| b == b'/');
    let lists = [
        ("vertex", "vertices", so_far.v, total.v),
        (
            "texture coordinate",
            "texture coordinates",
            so_far.vt,
            total.vt,
        ),
        ("normal", "normals", so_far.vn, total.vn),
    ];
    for (part, (what, whats, before, all)) in parts.zip(lists) {
        if part.is_empty() {
            continue;
        }
        let i = parse_i64(part).ok_or_else(|| {
            ReadError::malformed(at, format!("face {face}: bad {what} index {}", show(part)))
        })?;
        if i == 0 {
            return Err(ReadError::malformed(
                at,
                format!("face {face}: {what} index 0 is invalid (OBJ indices start at 1)"),
            ));
        }
        if i < 0 && i.unsigned_abs() > before as u64 {
            return Err(ReadError::malformed(
                at,
                format!(
                    "face {face}: relative {what} index {i} points before the first one \
                     ({before} {whats} so far)"
                ),
            ));
        }
        if i > 0 && i as u64 > all as u64 {
            return Err(ReadError::malformed(
                at,
                format!("face {face} refers to {what} {i}, but there are only {all} {whats}"),
            ));
        }
    }
    Ok(())
}

pub(crate) fn read(
    bytes: &[u8],
    notes: &mut ReadNotes,
) -> Result<(IndexedMesh, ObjAttributes), ReadError> {
    // tobj does not know line continuations ("\\" at the end of a line, used for
    // long faces); join them first, keeping byte offsets, and remember where.
    let (joined, joins) = join_continuations(bytes);
    let source: &[u8] = joined.as_deref().unwrap_or(bytes);
    let located = |e| physical_line(e, source, &joins);
    let scan = prescan(source, false).map_err(located)?;
    let owned;
    let text: &[u8] = if scan.blank.is_empty() {
        source
    } else {
        let mut copy = source.to_vec();
        for r in &scan.blank {
            if let Some(line) = copy.get_mut(r.clone()) {
                line.fill(b' ');
            }
        }
        owned = copy;
        &owned
    };
    // `..Default::default()` covers fields that tobj's optional features add.
    #[allow(clippy::needless_update)]
    let options = tobj::LoadOptions {
        single_index: false,
        triangulate: true,
        ignore_points: true,
        ignore_lines: true,
        ..Default::default()
    };
    let mut reader = text;
    let (models, _materials) =
        match tobj::load_obj_buf(&mut reader, &options, |_| Ok(Default::default())) {
            Ok(r) => r,
            Err(e) => {
                prescan(source, true).map_err(located)?;
                return Err(ReadError::new(
                    super::ReadErrorKind::Malformed {
                        detail: format!("OBJ rejected by tobj: {e} (line not located)"),
                    },
                    None,
                ));
            }
        };
    let (mesh, mut attrs) = assemble(&models);
    if let Err(e) = mesh.validate() {
        // Say where, when the detailed scan can (e.g. a non-finite coordinate).
        prescan(source, true).map_err(located)?;
        return Err(ReadError::mesh(None, e));
    }
    let Scan {
        names, notes: n, ..
    } = scan;
    attrs.groups = names.groups;
    attrs.materials = names.materials;
    attrs.material_libraries = names.libraries;
    notes.skipped_lines += n.skipped_lines;
    notes.non_utf8_lines += n.non_utf8_lines;
    Ok((mesh, attrs))
}

/// Replaces every `\\` that ends a line, and the line break after it, by spaces.
/// Returns the new text (`None` when there was nothing to join) and the offsets of
/// the removed line breaks.
fn join_continuations(bytes: &[u8]) -> (Option<Vec<u8>>, Vec<usize>) {
    let mut copy: Option<Vec<u8>> = None;
    let mut joins = Vec::new();
    let mut i = 0;
    while let Some(k) = bytes
        .get(i..)
        .and_then(|r| r.iter().position(|&b| b == b'\\'))
    {
        let at = i + k;
        let nl = match (bytes.get(at + 1), bytes.get(at + 2)) {
            (Some(b'\r'), Some(b'\n')) => Some(2),
            (Some(b'\n'), _) => Some(1),
            _ => None,
        };
        if let Some(len) = nl {
            let c = copy.get_or_insert_with(|| bytes.to_vec());
            if let Some(span) = c.get_mut(at..=at + len) {
                span.fill(b' ');
            }
            joins.push(at + len);
        }
        i = at + 1;
    }
    (copy, joins)
}

/// Converts a line number in the joined text to the file's line number.
fn physical_line(e: ReadError, joined: &[u8], joins: &[usize]) -> ReadError {
    match e.location() {
        Some(Location::Line(n)) if !joins.is_empty() => {
            let start = text::lines(joined)
                .nth(n.saturating_sub(1))
                .map_or(joined.len(), |(_, l)| {
                    l.as_ptr() as usize - joined.as_ptr() as usize
                });
            let before = joins.iter().take_while(|&&j| j < start).count();
            ReadError::new(e.kind().clone(), Some(Location::Line(n + before)))
        }
        _ => e,
    }
}

/// Concatenates tobj's models into one mesh with attributes.
fn assemble(models: &[tobj::Model]) -> (IndexedMesh, ObjAttributes) {
    let mut mesh = IndexedMesh::default();
    let mut attrs = ObjAttributes::default();
    let any_tex = models.iter().any(|m| !m.mesh.texcoord_indices.is_empty());
    let any_norm = models.iter().any(|m| !m.mesh.normal_indices.is_empty());
    let tri_total: usize = models.iter().map(|m| m.mesh.indices.len() / 3).sum();
    mesh.triangles.reserve(tri_total);
    for m in models {
        let m = &m.mesh;
        let base = mesh.positions.len() as u32;
        mesh.positions
            .extend(m.positions.chunks_exact(3).map(|c| [c[0], c[1], c[2]]));
        let tris = m.indices.chunks_exact(3);
        mesh.triangles
            .extend(tris.map(|t| [base + t[0], base + t[1], base + t[2]]));
        let ntri = m.indices.len() / 3;
        if any_tex {
            let tbase = attrs.texcoords.len() as u32;
            attrs
                .texcoords
                .extend(m.texcoords.chunks_exact(2).map(|c| [c[0], c[1]]));
            push_corners(
                &mut attrs.texcoord_indices,
                &m.texcoord_indices,
                tbase,
                ntri,
            );
        }
        if any_norm {
            let nbase = attrs.normals.len() as u32;
            attrs
                .normals
                .extend(m.normals.chunks_exact(3).map(|c| [c[0], c[1], c[2]]));
            push_corners(&mut attrs.normal_indices, &m.normal_indices, nbase, ntri);
        }
    }
    (mesh, attrs)
}

/// Appends `ntri` corner triples from `src` offset by `base`, or MISSING when `src`
/// does not cover them.
fn push_corners(dst: &mut Vec<[u32; 3]>, src: &[u32], base: u32, ntri: usize) {
    let miss = ObjAttributes::MISSING;
    for t in 0..ntri {
        let corner = |k: usize| src.get(3 * t + k).map_or(miss, |&i| base + i);
        dst.push([corner(0), corner(1), corner(2)]);
    }
}

pub(crate) fn write(out: &mut impl Write, mesh: &IndexedMesh) -> std::io::Result<()> {
    writeln!(out, "# written by qem")?;
    writeln!(
        out,
        "# {} vertices, {} triangles",
        mesh.positions.len(),
        mesh.triangles.len()
    )?;
    for [x, y, z] in &mesh.positions {
        writeln!(out, "v {x} {y} {z}")?;
    }
    for [a, b, c] in &mesh.triangles {
        writeln!(out, "f {} {} {}", a + 1, b + 1, c + 1)?;
    }
    Ok(())
}
