//! STL reader and writer.
//!
//! Binary or ASCII is decided by size, not by the `solid` prefix (many binary files
//! start with `solid` too): data of exactly `84 + 50·n` bytes, where `n` is the
//! little-endian count at byte 80, is binary. Otherwise data that starts with `solid`
//! is ASCII. Each facet gives three new vertices: STL has no shared vertices and the
//! reader does not weld (that is the cleaning stage's job). ASCII facets with more than
//! three vertices are fan-triangulated.
//!
//! ASCII STL's names (after `solid` and `endsolid`) may hold any bytes, a UTF-8 byte
//! order mark before `solid` is skipped, and words outside the grammar (`facet normal
//! outer loop vertex endloop endfacet` and numbers) are skipped, their lines counted in
//! [`ReadNotes::skipped_lines`]. A coordinate after `vertex` must be a number.

use std::io::Write;

use super::input::Input;
use super::stream::Triangles;
use super::text::{self, capacity_for, parse_f64, show, TextStream};
use super::{sniff, strip_bom, Format, Location, ReadError, ReadNotes, BOM, SNIFF_HEAD};
use crate::{IndexedMesh, InputError, MAX_ELEMENTS};

const HEADER: usize = 84;
const RECORD: usize = 50;

/// What the start of the data must hold for [`sniff`] and the NUL test below to see
/// what they would see in the whole data: a byte order mark and what `sniff` looks at.
const START: usize = BOM.len() + SNIFF_HEAD;

/// Reads an STL file as it arrives: binary STL whole records at a time, ASCII STL a
/// token at a time.
///
/// The triangles go to `triangles` (see [`Triangles`]; a streaming read forgets each
/// facet's vertices once its triangles are handed on); the mesh returned holds the
/// positions kept, its triangle list empty.
pub(crate) fn read(
    input: &mut Input<'_>,
    notes: &mut ReadNotes,
    triangles: &mut Triangles<'_>,
) -> Result<IndexedMesh, ReadError> {
    input.fill(START)?;
    let window = input.window();
    let (text, bom) = strip_bom(window);
    // `sniff` looks past its first `SNIFF_HEAD` bytes only to skip leading whitespace.
    let decided = input.at_end() || text::trim_start(text).len() >= 5;
    let count = window
        .get(80..84)
        .and_then(|b| b.try_into().ok())
        .map(u32::from_le_bytes);
    let looks_like = sniff(text);
    let ascii = decided && is_text(looks_like, text);
    match count {
        Some(n) if decided && !ascii => read_binary(input, n, looks_like, triangles),
        // Text is binary STL all the same if its size is that of a binary file of the
        // count at byte 80, which only the end of the data tells. Read as it arrives
        // when the data cannot be that big (`could_hold` is at least its size); a
        // count beyond `MAX_ELEMENTS` gives the same error whichever way it is read.
        Some(n)
            if ascii
                && (n as usize > MAX_ELEMENTS || expected_len(n) > input.could_hold() as u64) =>
        {
            // Only a count beyond `MAX_ELEMENTS` can leave the size in doubt here: the
            // rest is read to its end for that one case, not for every error.
            let maybe_binary =
                n as usize > MAX_ELEMENTS && expected_len(n) <= input.could_hold() as u64;
            notes.byte_order_mark = bom;
            // Unlike `skip_bom`, offsets keep counting the mark: the size compared is
            // the whole data's.
            input.consume(if bom { BOM.len() } else { 0 });
            let mut tok = TextStream::new(input, 1);
            tok.count_non_utf8();
            let read = read_ascii(&mut tok, notes, triangles);
            // Counted before `count_rest`, which skips what is left without counting
            // it (a last line without a line break went uncounted that way).
            let non_utf8 = tok.non_utf8_lines();
            if maybe_binary && tok.offset() + tok.count_rest()? == expected_len(n) {
                return Err(too_many_binary(n));
            }
            let mesh = read?;
            notes.non_utf8_lines += non_utf8;
            Ok(mesh)
        }
        _ => read_all(&input.rest()?, notes, triangles),
    }
}

/// Whether data that `looks_like` this and starts with `text` is read as ASCII STL
/// (when its size does not say it is binary).
fn is_text(looks_like: Option<&str>, text: &[u8]) -> bool {
    looks_like == Some("an ASCII STL file") && !text[..text.len().min(1024)].contains(&0)
}

/// Reads an STL file from all its bytes.
fn read_all(
    bytes: &[u8],
    notes: &mut ReadNotes,
    triangles: &mut Triangles<'_>,
) -> Result<IndexedMesh, ReadError> {
    let count = bytes
        .get(80..84)
        .and_then(|b| b.try_into().ok())
        .map(u32::from_le_bytes);
    let (text, bom) = strip_bom(bytes);
    let looks_like = sniff(text);
    match count {
        Some(n) if expected_len(n) == bytes.len() as u64 || !is_text(looks_like, text) => {
            read_binary(&mut Input::plain(bytes), n, looks_like, triangles)
        }
        _ if is_text(looks_like, text) => {
            notes.byte_order_mark = bom;
            let mut input = Input::plain(text);
            let mut tok = TextStream::new(&mut input, 1);
            tok.count_non_utf8();
            let mesh = read_ascii(&mut tok, notes, triangles)?;
            notes.non_utf8_lines += tok.non_utf8_lines();
            Ok(mesh)
        }
        _ => Err(not_stl(looks_like)),
    }
}

/// The error for a binary STL header's count `n` beyond [`MAX_ELEMENTS`].
fn too_many_binary(n: u32) -> ReadError {
    ReadError::too_large(
        Location::Byte(80),
        "binary STL header claims triangles:",
        n as u64,
    )
}

/// The size of a binary STL file of `n` triangles.
fn expected_len(n: u32) -> u64 {
    u64::from(n) * RECORD as u64 + HEADER as u64
}

/// The error for data that is neither ASCII nor binary STL.
fn not_stl(looks_like: Option<&'static str>) -> ReadError {
    ReadError::not_this_format(
        Format::Stl,
        looks_like,
        "neither ASCII (\"solid ...\") nor binary (84 + 50 bytes per triangle)",
    )
}

/// Reads data that is binary STL if its size is `84 + 50·n` bytes, `n` being the count
/// at byte 80, and otherwise an error (`looks_like` is what its start looks like).
/// Facets are read as they arrive; the size is known at the end of the data, and
/// decides whether what was read is the result.
fn read_binary(
    input: &mut Input<'_>,
    n: u32,
    looks_like: Option<&'static str>,
    triangles: &mut Triangles<'_>,
) -> Result<IndexedMesh, ReadError> {
    let too_large = n as usize > MAX_ELEMENTS;
    let count = if too_large { 0 } else { n as usize };
    input.consume(HEADER);
    let room = capacity_for(count, input.could_hold(), RECORD);
    // (A streaming read holds one window's facets at a time.)
    let mut positions = Vec::with_capacity(if triangles.is_streamed() { 0 } else { 3 * room });
    triangles.reserve(room);
    // The first facet with a coordinate that is not finite: reported only once the
    // size says the data is binary STL.
    let mut bad = None;
    let mut t = 0;
    while t < count {
        if triangles.has_failed() {
            return Err(Triangles::stopped());
        }
        input.fill(RECORD)?;
        let window = input.window();
        let k = (window.len() / RECORD).min(count - t);
        if k == 0 {
            break;
        }
        if bad.is_none() {
            let at = input.offset();
            bad = read_facets(&window[..k * RECORD], at, &mut positions, triangles);
            triangles.forget(&mut positions);
        }
        input.consume(k * RECORD);
        t += k;
    }
    let len = input.offset() + input.skip(u64::MAX)?;
    if len == expected_len(n) && !too_large {
        return match bad {
            Some(e) => Err(e),
            None => Ok(IndexedMesh::new(positions, Vec::new())),
        };
    }
    let binary_error = matches!(
        looks_like,
        None | Some("an ASCII STL file") | Some("binary data")
    );
    if too_large && (binary_error || len == expected_len(n)) {
        return Err(too_many_binary(n));
    }
    if !binary_error {
        return Err(not_stl(looks_like));
    }
    // Not ASCII: a binary STL whose size disagrees with its count.
    let expected = expected_len(n);
    if len < expected {
        let done = (len - HEADER as u64) / RECORD as u64;
        Err(ReadError::truncated(
            Location::Byte(len),
            format!("after {done} of {n} triangles (binary STL of {expected} bytes)"),
        ))
    } else {
        Err(ReadError::not_this_format(
            Format::Stl,
            looks_like.filter(|&l| l != "binary data"),
            format!(
                "binary STL header claims {n} triangles ({expected} bytes) \
                 but there are {len} bytes"
            ),
        ))
    }
}

/// Appends the facets of whole records `data`, which start at byte `at` of the data;
/// stops at the first vertex with a coordinate that is not finite, and gives its
/// error.
fn read_facets(
    data: &[u8],
    at: u64,
    positions: &mut Vec<[f64; 3]>,
    triangles: &mut Triangles<'_>,
) -> Option<ReadError> {
    for (r, rec) in data.chunks_exact(RECORD).enumerate() {
        for k in 0..3 {
            let mut p = [0.0f64; 3];
            for (c, slot) in p.iter_mut().enumerate() {
                let o = 12 + 12 * k + 4 * c;
                let raw = rec
                    .get(o..o + 4)
                    .and_then(|b| b.try_into().ok())
                    .map(f32::from_le_bytes)
                    .unwrap_or(f32::NAN);
                *slot = f64::from(raw);
            }
            if !p.iter().all(|c| c.is_finite()) {
                return Some(ReadError::mesh(
                    Some(Location::Byte(at + (r * RECORD + 12 + 12 * k) as u64)),
                    InputError::NonFiniteCoordinate {
                        vertex: triangles.vertex_number(positions.len()),
                    },
                ));
            }
            positions.push(p);
        }
        // Fewer than 2^28 triangles (MAX_ELEMENTS), so 3t + 2 fits a u32.
        let b = triangles.vertex_number(positions.len() - 3) as u32;
        triangles.push([b, b + 1, b + 2], positions);
    }
    None
}

/// The words of ASCII STL's grammar, and the others.
#[derive(Clone, Copy, PartialEq)]
enum Word {
    /// `solid` or `endsolid`, followed by a free-form name.
    Solid,
    Facet,
    Vertex,
    EndFacet,
    /// `normal`, `outer`, `loop`, `endloop` and numbers: nothing the reader keeps.
    Passed,
    /// Not STL: an exporter's extension or junk.
    Other,
}

impl Word {
    fn of(word: &[u8]) -> Word {
        let is = |kw: &[u8]| word.eq_ignore_ascii_case(kw);
        if is(b"solid") || is(b"endsolid") {
            Word::Solid
        } else if is(b"facet") {
            Word::Facet
        } else if is(b"vertex") {
            Word::Vertex
        } else if is(b"endfacet") {
            Word::EndFacet
        } else if is(b"normal")
            || is(b"outer")
            || is(b"loop")
            || is(b"endloop")
            || parse_f64(word).is_some()
        {
            Word::Passed
        } else {
            Word::Other
        }
    }
}

/// Reads ASCII STL from `tok` (at the start of the text, after a byte order mark).
fn read_ascii(
    tok: &mut TextStream<'_, '_>,
    notes: &mut ReadNotes,
    triangles: &mut Triangles<'_>,
) -> Result<IndexedMesh, ReadError> {
    // The last line counted in `notes.skipped_lines`, so a line is counted once.
    let mut skipped_line = 0usize;
    let mut positions: Vec<[f64; 3]> = Vec::new();
    // Index in `positions` of the current facet's first vertex, while inside a facet.
    let mut facet_start: Option<usize> = None;
    let mut facets = 0usize;
    while let Some((word, line)) = tok.next_token()? {
        let at = Location::Line(line);
        let word = Word::of(word);
        if word == Word::Solid {
            // The rest of the line is a free-form name.
            tok.skip_line()?;
        } else if word == Word::Facet {
            if facet_start.is_some() {
                return Err(ReadError::malformed(
                    at,
                    format!("facet {facets}: \"facet\" before \"endfacet\" of the previous one"),
                ));
            }
            facet_start = Some(positions.len());
        } else if word == Word::Vertex {
            let Some(start) = facet_start else {
                return Err(ReadError::malformed(
                    at,
                    format!("\"vertex\" outside a facet (after facet {facets})"),
                ));
            };
            let mut p = [0.0; 3];
            for (k, c) in p.iter_mut().enumerate() {
                let (t, line) = match tok.next_token()? {
                    Some(token) => token,
                    None => (&[][..], tok.line()),
                };
                *c = parse_f64(t).ok_or_else(|| {
                    ReadError::malformed(
                        Location::Line(line),
                        format!(
                            "facet {facets}, vertex {}: coordinate {k} is {}, not a number",
                            positions.len() - start,
                            show(t)
                        ),
                    )
                })?;
            }
            if !p.iter().all(|c| c.is_finite()) {
                return Err(ReadError::mesh(
                    Some(at),
                    InputError::NonFiniteCoordinate {
                        vertex: triangles.vertex_number(positions.len()),
                    },
                ));
            }
            let vertices = triangles.vertex_number(positions.len());
            if vertices >= 3 * MAX_ELEMENTS {
                return Err(ReadError::too_large(at, "STL vertices:", vertices as u64));
            }
            positions.push(p);
        } else if word == Word::EndFacet {
            let Some(start) = facet_start.take() else {
                return Err(ReadError::malformed(at, "\"endfacet\" without \"facet\""));
            };
            let n = positions.len() - start;
            if n < 3 {
                return Err(ReadError::malformed(
                    at,
                    format!("facet {facets} has {n} vertices; a facet needs at least 3"),
                ));
            }
            // (Vertex numbers fit a u32: fewer than 3 · 2^28 vertices, checked above.)
            let forgotten = triangles.vertex_number(0);
            let number = |k: usize| (forgotten + k) as u32;
            let a = number(start);
            for k in start + 1..positions.len() - 1 {
                let t = [a, number(k), number(k) + 1];
                triangles.push(t, &positions);
            }
            triangles.forget(&mut positions);
            if triangles.has_failed() {
                return Err(Triangles::stopped());
            }
            facets += 1;
        } else if word == Word::Other && skipped_line != line {
            // An exporter's extension or junk: it has no say in the geometry.
            notes.skipped_lines += 1;
            skipped_line = line;
        }
        // "normal", its three numbers, "outer", "loop" and "endloop" carry nothing we keep.
    }
    if facet_start.is_some() {
        return Err(ReadError::truncated(
            Location::Line(tok.line()),
            format!("inside facet {facets}"),
        ));
    }
    Ok(IndexedMesh::new(positions, Vec::new()))
}

pub(crate) fn write(out: &mut impl Write, mesh: &IndexedMesh) -> std::io::Result<()> {
    // float32 cannot hold coordinates beyond ±3.4e38: they would be written as infinity,
    // a file no reader accepts. Refuse before writing anything.
    if let Some((v, c)) = mesh
        .triangles
        .iter()
        .flatten()
        .filter_map(|&i| Some((i, mesh.positions.get(i as usize)?)))
        .find_map(|(i, p)| {
            p.iter()
                .find(|c| (**c as f32).is_infinite())
                .map(|c| (i, c))
        })
    {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            format!(
                "vertex {v} has coordinate {c:e}, beyond the range of STL's float32 \
                 (about ±3.4e38); write PLY, OBJ or OFF instead"
            ),
        ));
    }
    let mut header = [b' '; 80];
    let tag = b"binary STL written by qem";
    header[..tag.len()].copy_from_slice(tag);
    out.write_all(&header)?;
    let n = u32::try_from(mesh.triangles.len()).map_err(|_| {
        std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            "more than 2^32 triangles do not fit in binary STL",
        )
    })?;
    out.write_all(&n.to_le_bytes())?;
    let mut rec = [0u8; RECORD];
    for tri in &mesh.triangles {
        // write_to checked the indices; a miss here would be a bug, written as origin.
        let p = tri.map(|i| mesh.positions.get(i as usize).copied().unwrap_or_default());
        let normal = facet_normal(p);
        let values = normal.iter().chain(p.iter().flatten());
        for (k, v) in values.enumerate() {
            rec[4 * k..4 * k + 4].copy_from_slice(&(*v as f32).to_le_bytes());
        }
        out.write_all(&rec)?;
    }
    Ok(())
}

/// Unit normal of a triangle (counter-clockwise), or zero when it is degenerate.
fn facet_normal([a, b, c]: [[f64; 3]; 3]) -> [f64; 3] {
    let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
    let n = [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ];
    let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    if len > 0.0 && len.is_finite() {
        n.map(|x| x / len)
    } else {
        [0.0; 3]
    }
}
