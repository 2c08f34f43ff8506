//! The OBJ reader as it was before it streamed (commit 3c4017a): the text read whole,
//! scanned, and handed to `tobj`. Kept for tests only, to check that the streaming
//! reader ([`super`]) gives the same meshes, notes and errors.
#![allow(dead_code)]

use super::text::{self, parse_f64, parse_i64, show, words};

use super::obj::{expand_runs, keyword, plain_positive_corners, LabelRun, Names};
use super::{sniff, Format, Location, ReadError, ReadNotes};
use crate::attributes::{Channel, ChannelKind, FaceLabels};
use crate::{IndexedMesh, InputError};

/// Counts of `v`, `vt` and `vn` lines in the file.
#[derive(Clone, Copy, Default)]
struct Counts {
    v: usize,
    vt: usize,
    vn: usize,
}

/// What the first scan found besides errors: the lines to blank before `tobj` sees
/// the text, the names, and the notes.
#[derive(Default)]
struct Scan {
    /// Byte ranges to overwrite with spaces in the copy given to `tobj`.
    blank: Vec<std::ops::Range<usize>>,
    names: Names,
    /// Where the group and the material change, in triangles of the file's order.
    group_runs: Vec<LabelRun>,
    material_runs: Vec<LabelRun>,
    /// Triangles the file's faces make (fan triangulation: a face of n corners makes
    /// n - 2, a face of fewer than 3 none, as in `tobj`).
    triangles: usize,
    /// Which triangle corners have no `vt` or `vn` index ([`Slots`]).
    slots: Slots,
    notes: ReadNotes,
}

/// Which corners of the file's triangles name a texture coordinate and a normal.
///
/// Why: `tobj` fills a corner without a `vt` (or `vn`) index with its neighbour's, or
/// with the file's first value, when other faces of its section have one; the reader
/// marks those corners [`Channel::MISSING`] instead. Kept as runs of triangles whose
/// corners all agree (a file is nearly always one run), plus the corners of the rare
/// faces that mix.
#[derive(Default)]
struct Slots {
    /// From triangle `.0` on: whether every corner has a `vt` (`.1`) and a `vn` (`.2`).
    runs: Vec<(usize, bool, bool)>,
    /// Corners of faces that mix: (triangle, corner, has `vt`, has `vn`).
    mixed: Vec<(usize, usize, bool, bool)>,
}

impl Slots {
    /// Notes the face line `rest`, whose first triangle is `first`.
    fn add_face(&mut self, rest: &[u8], first: usize) {
        let mut all = (true, true);
        let mut none = (true, true);
        for corner in words(rest) {
            let has = corner_slots(corner);
            all = (all.0 && has.0, all.1 && has.1);
            none = (none.0 && !has.0, none.1 && !has.1);
        }
        let uniform = (all.0 || none.0) && (all.1 || none.1);
        if uniform {
            if self.runs.last().is_none_or(|r| (r.1, r.2) != all) {
                self.runs.push((first, all.0, all.1));
            }
            return;
        }
        // A mixed face lies in a run where every corner has both, and only its own
        // corners without one are marked. The run must start at this face: the run
        // before it (say, faces without `vn`) would otherwise cover it and mark its
        // corners that have one as missing too.
        if self.runs.last().is_none_or(|r| (r.1, r.2) != (true, true)) {
            self.runs.push((first, true, true));
        }
        // Fan triangulation: triangle j of the face has corners 0, j + 1, j + 2.
        let corners: Vec<(bool, bool)> = words(rest).map(corner_slots).collect();
        for j in 0..corners.len().saturating_sub(2) {
            for (k, c) in [0, j + 1, j + 2].into_iter().enumerate() {
                self.mixed.push((first + j, k, corners[c].0, corners[c].1));
            }
        }
    }

    /// Marks the corners without an index as missing in `uv` and `normal`.
    fn apply(&self, uv: Option<&mut Channel>, normal: Option<&mut Channel>, triangles: usize) {
        for (which, channel) in [(0, uv), (1, normal)] {
            let Some(channel) = channel else { continue };
            for (i, &(first, has_uv, has_normal)) in self.runs.iter().enumerate() {
                let has = if which == 0 { has_uv } else { has_normal };
                let end = self
                    .runs
                    .get(i + 1)
                    .map_or(triangles, |r| r.0)
                    .min(triangles);
                if !has {
                    if let Some(span) = channel.corners.get_mut(first.min(end)..end) {
                        span.fill([Channel::MISSING; 3]);
                    }
                }
            }
            for &(t, k, has_uv, has_normal) in &self.mixed {
                let has = if which == 0 { has_uv } else { has_normal };
                if let Some(c) = channel.corners.get_mut(t).filter(|_| !has) {
                    c[k] = Channel::MISSING;
                }
            }
        }
    }
}

/// Whether a face corner `v/vt/vn` names a texture coordinate and a normal.
fn corner_slots(corner: &[u8]) -> (bool, bool) {
    let mut parts = corner.split(|&b| b == b'/').skip(1);
    let vt = parts.next().is_some_and(|p| !p.is_empty());
    let vn = parts.next().is_some_and(|p| !p.is_empty());
    (vt, vn)
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
                    (0, _) => {}
                    (3, _) => check_f32(words(rest).skip(3), at, || format!("vertex {v}: colour"))?,
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
                let index = so_far.vt;
                numbers(2, "texture coordinate", index)?;
                check_f32(words(rest).take(2), at, || {
                    format!("texture coordinate {index}")
                })?;
                so_far.vt += 1;
            }
            b"vn" => {
                let index = so_far.vn;
                numbers(3, "normal", index)?;
                check_f32(words(rest).take(3), at, || format!("normal {index}"))?;
                so_far.vn += 1;
            }
            b"f" | b"l" => {
                // Nearly every face passes the quick check; the rest get the full one.
                let quick = !detailed && plain_positive_corners(rest);
                for corner in words(rest).filter(|_| !quick) {
                    check_corner(corner, faces, so_far, total, at)?;
                }
                faces += usize::from(key == b"f");
                if key == b"f" {
                    scan.slots.add_face(rest, scan.triangles);
                    scan.triangles += words(rest).count().saturating_sub(2);
                }
                // Lines and points are read (their indices guard tobj) but not kept.
                scan.notes.skipped_lines += usize::from(key == b"l");
            }
            b"o" | b"g" => {
                let label = scan.names.add(0, text::trim(rest));
                scan.group_runs.push(LabelRun {
                    first: scan.triangles,
                    label,
                });
                // `tobj` starts a new model at every `o`/`g` line, which decides the
                // vertex order: keep the keyword, hide a name it cannot take as text.
                if utf8_error.is_some() {
                    scan.blank.push(start + line.len() - rest.len()..whole.end);
                }
            }
            b"usemtl" => {
                let label = scan.names.add(1, text::trim(rest));
                scan.material_runs.push(LabelRun {
                    first: scan.triangles,
                    label,
                });
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

/// Refuses the first of `tokens` (numbers, already checked) that is not a finite
/// `f32`: texture coordinates, normals and colours are kept as `f32`, so a NaN, an
/// infinity or a value beyond float32 (`1e39`) would be refused by the mesh's
/// validation, which cannot name the line. `what` names the element for the message.
fn check_f32<'a>(
    tokens: impl Iterator<Item = &'a [u8]>,
    at: Location,
    what: impl Fn() -> String,
) -> Result<(), ReadError> {
    for tok in tokens {
        if parse_f64(tok).is_some_and(|x| !(x as f32).is_finite()) {
            return Err(ReadError::malformed(
                at,
                format!("{}: {} is not a finite 32-bit float", what(), show(tok)),
            ));
        }
    }
    Ok(())
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

pub(crate) fn read(bytes: &[u8], notes: &mut ReadNotes) -> Result<IndexedMesh, ReadError> {
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
    let mut mesh = assemble(&models);
    let Scan {
        names,
        group_runs,
        material_runs,
        triangles,
        slots,
        notes: n,
        ..
    } = scan;
    if triangles != mesh.triangles.len() {
        // The scan and tobj disagree about the faces, so the labels cannot be placed:
        // say so rather than guess (no file seen so far does this).
        return Err(ReadError::malformed(
            Location::Line(0),
            format!(
                "the faces make {triangles} triangles by fan triangulation, but tobj made {}",
                mesh.triangles.len()
            ),
        ));
    }
    {
        let mut uv = None;
        let mut normal = None;
        for c in &mut mesh.attributes.channels {
            match c.kind {
                ChannelKind::TexCoord => uv = Some(c),
                ChannelKind::Normal => normal = Some(c),
                _ => {}
            }
        }
        slots.apply(uv, normal, triangles);
    }
    // A list no corner uses (values without any face naming them) is no channel.
    mesh.attributes
        .channels
        .retain(|c| c.corners.iter().flatten().any(|&i| i != Channel::MISSING));
    mesh.attributes.groups = FaceLabels {
        names: names.groups,
        faces: expand_runs(&group_runs, triangles),
    };
    mesh.attributes.materials = FaceLabels {
        names: names.materials,
        faces: expand_runs(&material_runs, triangles),
    };
    mesh.attributes.material_libraries = names.libraries;
    if let Err(e) = mesh.validate() {
        // Say where, when the detailed scan can (e.g. a non-finite coordinate).
        prescan(source, true).map_err(located)?;
        return Err(ReadError::mesh(None, e));
    }
    notes.skipped_lines += n.skipped_lines;
    notes.non_utf8_lines += n.non_utf8_lines;
    Ok(mesh)
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

/// Concatenates tobj's models into one mesh, with its texture coordinates and
/// normals as channels (corners without one hold [`Channel::MISSING`]).
fn assemble(models: &[tobj::Model]) -> IndexedMesh {
    let mut mesh = IndexedMesh::default();
    let any_tex = models.iter().any(|m| !m.mesh.texcoord_indices.is_empty());
    let any_norm = models.iter().any(|m| !m.mesh.normal_indices.is_empty());
    let tri_total: usize = models.iter().map(|m| m.mesh.indices.len() / 3).sum();
    mesh.triangles.reserve(tri_total);
    let mut uv = Channel::new(ChannelKind::TexCoord, Vec::new(), Vec::new());
    let mut normal = Channel::new(ChannelKind::Normal, Vec::new(), Vec::new());
    // `v x y z r g b` colours (tobj refuses a file where only some `v` lines have
    // them), one per vertex as tobj numbers them.
    let colours = models
        .iter()
        .any(|m| !m.mesh.vertex_color.is_empty())
        .then(|| {
            models
                .iter()
                .all(|m| m.mesh.vertex_color.len() == m.mesh.positions.len())
        })
        == Some(true);
    let mut colour = Vec::new();
    for m in models {
        let m = &m.mesh;
        if colours {
            colour.extend(m.vertex_color.iter().map(|&x| x as f32));
        }
        let base = mesh.positions.len() as u32;
        mesh.positions
            .extend(m.positions.chunks_exact(3).map(|c| [c[0], c[1], c[2]]));
        let tris = m.indices.chunks_exact(3);
        mesh.triangles
            .extend(tris.map(|t| [base + t[0], base + t[1], base + t[2]]));
        let ntri = m.indices.len() / 3;
        if any_tex {
            let tbase = uv.value_count() as u32;
            // f32: what every consumer of texture coordinates (GPUs, glTF) holds.
            uv.values.extend(m.texcoords.iter().map(|&x| x as f32));
            push_corners(&mut uv.corners, &m.texcoord_indices, tbase, ntri);
        }
        if any_norm {
            let nbase = normal.value_count() as u32;
            normal.values.extend(m.normals.iter().map(|&x| x as f32));
            push_corners(&mut normal.corners, &m.normal_indices, nbase, ntri);
        }
    }
    if any_tex {
        mesh.attributes.channels.push(uv);
    }
    if any_norm {
        mesh.attributes.channels.push(normal);
    }
    if colours {
        // Some exporters write 0–255 levels: a value above 1 says so.
        super::channels::unit_colours(&mut colour);
        let corners = mesh.triangles.clone();
        mesh.attributes
            .channels
            .push(Channel::new(ChannelKind::Color, colour, corners));
    }
    mesh
}

/// Appends `ntri` corner triples from `src` offset by `base`, or MISSING when `src`
/// does not cover them.
fn push_corners(dst: &mut Vec<[u32; 3]>, src: &[u32], base: u32, ntri: usize) {
    let miss = Channel::MISSING;
    for t in 0..ntri {
        let corner = |k: usize| src.get(3 * t + k).map_or(miss, |&i| base + i);
        dst.push([corner(0), corner(1), corner(2)]);
    }
}
