//! OFF reader and writer.
//!
//! Reads the text form: a header word `OFF` optionally prefixed by `ST`, `C` and `N`
//! (`N` before `C` is accepted too), then `vertices faces [edges]` (on the header line
//! or the next one), one vertex per line, then one face per line as
//! `n i1 .. in [colour]`. `#` starts a comment. `4OFF`, `nOFF` and `OFF BINARY` are
//! refused with a clear error. Polygons are fan-triangulated.
//!
//! # Attributes
//! After a vertex's coordinates come, as the header's prefixes promise and in the
//! spec's order, a normal (`N`: 3 numbers), a colour (`C`: 3 or 4, the same in every
//! vertex) and texture coordinates (`ST`: 2); each becomes a per-vertex channel. A face
//! line with 3 or 4 numbers after its indices has a face colour (a channel whose
//! corners all use the face's value; faces without one have none); one number (an
//! index into a colour map the file does not hold) is ignored. A missing or malformed
//! number, or one that is not finite as a 32-bit float, is an error naming the vertex
//! or face and the line.
//!
//! Colours: OFF files use both 0–1 floats (Geomview's spec) and 0–255 integers (common
//! exporters). The reader decides per channel: if any component is above 1, all are
//! 0–255 levels and divided by 255; otherwise they are taken as 0–1 floats. Whether a
//! number is written as an integer decides nothing, since floats such as 1 and 0 are
//! written that way too. A component still outside 0–1 (a level above 255, a negative
//! number) is clamped to it, as the writer would: the file's colours then survive a
//! round trip.
//!
//! Comments may hold any bytes (they are counted in [`ReadNotes::non_utf8_lines`] when
//! they are not UTF-8); numbers must be numbers. Lines after the last face are skipped
//! and counted in [`ReadNotes::skipped_lines`].
//!
//! # Writing
//! `OFF`, with `ST`, `C` and `N` prefixes (`STCNOFF`) for the channels it has
//! ([`slots`]): the first normals, the first colour and the first texture coordinates,
//! per vertex after splitting the vertices at their seams (channels the reader made are
//! already per vertex and keep the vertices as they are), and the first face colour
//! after each face's indices. Numbers are written in Rust's shortest round-trip form;
//! colours are clamped to 0–1 (so none is taken for a 0–255 level when read back).
//! Generic channels, second channels of a kind, materials and groups have no place in
//! OFF ([`super::unwritable`]). A mesh without channels gives the same file as before
//! attributes existed.

use std::io::Write;

use smallvec::SmallVec;

use super::channels::{colours_on_faces, per_vertex, unit_colours};
use super::input::Input;
use super::stream::Triangles;
use super::text::{self, capacity_for, parse_f32, parse_f64, parse_i64, show, words, TextStream};
use super::{sniff_start, starts_solid, Format, Location, ReadError, ReadNotes, SNIFF_HEAD};
use crate::attributes::{Attributes, Channel, ChannelKind};
use crate::{IndexedMesh, InputError, MAX_ELEMENTS};

/// Reads an OFF file a line at a time as it arrives.
///
/// The triangles go to `triangles` (see [`Triangles`]); the mesh returned holds the
/// positions and the attributes, its triangle list empty.
pub(crate) fn read(
    input: &mut Input<'_>,
    notes: &mut ReadNotes,
    triangles: &mut Triangles<'_>,
) -> Result<IndexedMesh, ReadError> {
    // What `sniff` needs to say what data that is not OFF looks like: its start, and
    // whether its first line with content starts with "solid" (`next_content` notes it).
    input.fill(SNIFF_HEAD)?;
    let window = input.window();
    let head = window[..window.len().min(SNIFF_HEAD)].to_vec();
    let mut solid = None;
    let mut lines = TextStream::new(input, 1);
    lines.count_non_utf8();
    let not_off = |detail: &str, solid: Option<bool>| {
        ReadError::not_this_format(
            Format::Off,
            sniff_start(&head, solid == Some(true)),
            detail.to_string(),
        )
    };
    let Some((header_line, header)) = next_content(&mut lines, &mut solid)? else {
        return Err(not_off("no header (only blank lines and comments)", solid));
    };
    let mut header_words = words(header);
    let magic = header_words.next().unwrap_or_default();
    let Some(prefix) = magic.strip_suffix(b"OFF") else {
        return Err(not_off(
            &format!("the first word is {}, not OFF", show(magic)),
            solid,
        ));
    };
    let at = |line| Location::Line(line);
    // The spec's order is ST, C, N; N before C is accepted too (some writers use it).
    let (has_uv, has_colour, has_normal) = match prefix {
        b"" => (false, false, false),
        b"C" => (false, true, false),
        b"N" => (false, false, true),
        b"NC" | b"CN" => (false, true, true),
        b"ST" => (true, false, false),
        b"STC" => (true, true, false),
        b"STN" => (true, false, true),
        b"STNC" | b"STCN" => (true, true, true),
        _ => {
            return Err(ReadError::malformed(
                at(header_line),
                format!("unsupported OFF variant {}", show(magic)),
            ))
        }
    };
    // The counts are copied, so the header's line can be let go.
    let mut counts: SmallVec<[Vec<u8>; 2]> =
        header_words.by_ref().take(2).map(<[u8]>::to_vec).collect();
    let mut count_words = counts.len() + header_words.count();
    if counts.first().is_some_and(|w| w == b"BINARY") {
        return Err(ReadError::malformed(
            at(header_line),
            "binary OFF is not supported",
        ));
    }
    let mut counts_line = header_line;
    if count_words == 0 {
        let Some((no, l)) = next_content(&mut lines, &mut solid)? else {
            return Err(ReadError::truncated(
                at(header_line),
                "after the header: no vertex and face counts",
            ));
        };
        counts_line = no;
        counts = words(l).take(2).map(<[u8]>::to_vec).collect();
        count_words = words(l).count();
    }
    if count_words < 2 {
        return Err(ReadError::malformed(
            at(counts_line),
            "expected vertex, face and edge counts",
        ));
    }
    let parse_count = |tok: &[u8], what: &str, plural: &str| -> Result<usize, ReadError> {
        let n = text::parse_i64(tok).filter(|&n| n >= 0).ok_or_else(|| {
            ReadError::malformed(at(counts_line), format!("bad {what} count {}", show(tok)))
        })?;
        if n as u64 > MAX_ELEMENTS as u64 {
            return Err(ReadError::too_large(
                at(counts_line),
                format!("OFF header claims {plural}:"),
                n as u64,
            ));
        }
        Ok(n as usize)
    };
    let nv = parse_count(&counts[0], "vertex", "vertices")?;
    let nf = parse_count(&counts[1], "face", "faces")?;

    let mut positions = Vec::with_capacity(capacity_for(nv, lines.could_hold(), 6));
    let mut normals = Vec::new();
    let mut colours = Vec::new();
    let mut uvs = Vec::new();
    // What the header promises after each vertex's coordinates, for messages.
    let promised = [
        (has_normal, "3 normal components"),
        (has_colour, "3 or 4 colour components"),
        (has_uv, "2 texture coordinates"),
    ]
    .iter()
    .filter(|p| p.0)
    .map(|p| p.1)
    .collect::<Vec<_>>()
    .join(", ");
    let fixed = 3 * usize::from(has_normal) + 2 * usize::from(has_uv);
    let mut colour_dimension = None;
    let mut last_line = counts_line;
    for v in 0..nv {
        let Some((no, l)) = next_content(&mut lines, &mut solid)? else {
            return Err(ReadError::truncated(
                at(last_line),
                format!("after {v} of {nv} vertices"),
            ));
        };
        last_line = no;
        let w: SmallVec<[&[u8]; 16]> = words(l).collect();
        let mut p = [0.0; 3];
        for (k, c) in p.iter_mut().enumerate() {
            let tok = w.get(k).ok_or_else(|| {
                ReadError::malformed(
                    at(no),
                    format!("vertex {v}: expected 3 coordinates, found {k}"),
                )
            })?;
            *c = parse_f64(tok).ok_or_else(|| {
                ReadError::malformed(at(no), format!("vertex {v}: bad coordinate {}", show(tok)))
            })?;
        }
        if !p.iter().all(|c| c.is_finite()) {
            return Err(ReadError::mesh(
                Some(at(no)),
                InputError::NonFiniteCoordinate { vertex: v },
            ));
        }
        positions.push(p);
        if promised.is_empty() {
            continue;
        }
        // Normal, colour, texture coordinates, in that order (the spec's): the colour's
        // length (3 or 4) is what the others leave.
        let rest = &w[3..];
        let colour = if has_colour {
            rest.len()
                .checked_sub(fixed)
                .filter(|n| (3..=4).contains(n))
        } else {
            Some(0).filter(|_| rest.len() >= fixed)
        };
        let Some(colour) = colour else {
            return Err(ReadError::malformed(
                at(no),
                format!(
                    "vertex {v}: expected {promised} after the coordinates, found {} numbers",
                    rest.len()
                ),
            ));
        };
        if has_colour && *colour_dimension.get_or_insert(colour) != colour {
            return Err(ReadError::malformed(
                at(no),
                format!(
                    "vertex {v} has {colour} colour components, vertex 0 has {}",
                    colour_dimension.unwrap_or(colour)
                ),
            ));
        }
        let normal_end = 3 * usize::from(has_normal);
        let parts = [
            (&rest[..normal_end], &mut normals, "normal component"),
            (
                &rest[normal_end..normal_end + colour],
                &mut colours,
                "colour component",
            ),
            (
                &rest[normal_end + colour..fixed + colour],
                &mut uvs,
                "texture coordinate",
            ),
        ];
        for (toks, out, what) in parts {
            for tok in toks {
                out.push(attribute(tok, &format!("vertex {v}"), what, at(no))?);
            }
        }
    }
    triangles.reserve(capacity_for(nf, lines.could_hold(), 8));
    let mut corners: Vec<u32> = Vec::new();
    let mut face_colours: Vec<f32> = Vec::new();
    let mut face_dimension = None;
    // Per triangle, its face colour's index (filled from the first coloured face on).
    let mut triangle_colours: Vec<u32> = Vec::new();
    for f in 0..nf {
        if triangles.has_failed() {
            return Err(Triangles::stopped());
        }
        let Some((no, l)) = next_content(&mut lines, &mut solid)? else {
            return Err(ReadError::truncated(
                at(last_line),
                format!("after {f} of {nf} faces"),
            ));
        };
        last_line = no;
        let mut w = words(l);
        let n_tok = w.next().unwrap_or_default();
        let n = parse_i64(n_tok).filter(|&n| n >= 0).ok_or_else(|| {
            ReadError::malformed(
                at(no),
                format!("face {f}: bad corner count {}", show(n_tok)),
            )
        })?;
        corners.clear();
        for k in 0..n {
            let Some(tok) = w.next() else {
                return Err(ReadError::malformed(
                    at(no),
                    format!("face {f}: expected {n} vertex indices, found {k}"),
                ));
            };
            let i = parse_i64(tok).ok_or_else(|| {
                ReadError::malformed(at(no), format!("face {f}: bad vertex index {}", show(tok)))
            })?;
            if i < 0 || i as u64 >= nv as u64 {
                return Err(ReadError::malformed(
                    at(no),
                    format!("face {f} refers to vertex {i}, but there are only {nv} vertices"),
                ));
            }
            corners.push(i as u32);
        }
        if corners.len() < 3 {
            return Err(ReadError::malformed(
                at(no),
                format!(
                    "face {f} has {} corners; a face needs at least 3",
                    corners.len()
                ),
            ));
        }
        let first_triangle = triangles.len();
        fan(&corners, triangles, &positions);
        // A face colour is 3 or 4 numbers after the indices; one number (a colour map
        // index, meaningless without the map) or none leaves the face without one.
        let rest: SmallVec<[&[u8]; 4]> = w.take(5).collect();
        if (3..=4).contains(&rest.len()) {
            if *face_dimension.get_or_insert(rest.len()) != rest.len() {
                return Err(ReadError::malformed(
                    at(no),
                    format!(
                        "face {f} has {} colour components, the first coloured face has {}",
                        rest.len(),
                        face_dimension.unwrap_or(rest.len())
                    ),
                ));
            }
            let index = (face_colours.len() / rest.len()) as u32;
            for tok in &rest {
                let value = attribute(tok, &format!("face {f}"), "colour component", at(no))?;
                // (A streaming read checks the values but keeps no per-face data.)
                if !triangles.is_streamed() {
                    face_colours.push(value);
                }
            }
            if !triangles.is_streamed() {
                triangle_colours.resize(first_triangle, Channel::MISSING);
                triangle_colours.resize(triangles.len(), index);
            }
        }
    }
    while next_content(&mut lines, &mut solid)?.is_some() {
        notes.skipped_lines += 1;
    }
    notes.non_utf8_lines += lines.non_utf8_lines();
    let mut channels = Vec::new();
    let per_vertex = |kind, values| Channel::new(kind, values, triangles.kept_list().to_vec());
    if has_normal {
        channels.push(per_vertex(ChannelKind::Normal, normals));
    }
    if let Some(d) = colour_dimension {
        channels.push(per_vertex(ChannelKind::Color, levels(colours)).with_dimension(d));
    }
    if has_uv {
        channels.push(per_vertex(ChannelKind::TexCoord, uvs));
    }
    if let Some(d) = face_dimension {
        triangle_colours.resize(triangles.kept_list().len(), Channel::MISSING);
        let name = if colour_dimension.is_some() {
            "face_colour"
        } else {
            "colour"
        };
        let corners = triangle_colours.iter().map(|&i| [i; 3]).collect();
        channels.push(
            Channel::new(ChannelKind::Color, levels(face_colours), corners)
                .with_dimension(d)
                .with_name(name),
        );
    }
    Ok(
        IndexedMesh::new(positions, Vec::new()).with_attributes(Attributes {
            channels,
            ..Attributes::default()
        }),
    )
}

/// The next line with content once its comment is cut off, trimmed, with its number.
/// Notes in `solid`, at the first line with anything but whitespace (comments
/// included), whether it starts with "solid" (what [`sniff`](super::sniff) looks for
/// past the data's start).
fn next_content<'s>(
    lines: &'s mut TextStream<'_, '_>,
    solid: &mut Option<bool>,
) -> Result<Option<(usize, &'s [u8])>, ReadError> {
    loop {
        let Some((no, span)) = lines.next_line_span()? else {
            return Ok(None);
        };
        let raw = lines.span(span.clone());
        if solid.is_none() && !text::trim(raw).is_empty() {
            *solid = Some(starts_solid(text::trim_start(raw)));
        }
        let content = text::trimmed(text::strip_comment(raw, b'#'));
        if !content.is_empty() {
            let at = span.start;
            return Ok(Some((no, lines.span(at + content.start..at + content.end))));
        }
    }
}

/// One attribute number of an OFF line (`what` of `item`), as the nearest `f32`.
fn attribute(tok: &[u8], item: &str, what: &str, at: Location) -> Result<f32, ReadError> {
    let v = parse_f32(tok)
        .ok_or_else(|| ReadError::malformed(at, format!("{item}: bad {what} {}", show(tok))))?;
    if !v.is_finite() {
        return Err(ReadError::malformed(
            at,
            format!("{item}: {what} {} is not a finite 32-bit float", show(tok)),
        ));
    }
    Ok(v)
}

/// A channel's colours in 0–1 ([`unit_colours`]). OFF does not say whether colours
/// are 0–255 integers (common in practice) or 0–1 floats (Geomview's spec).
fn levels(mut colours: Vec<f32>) -> Vec<f32> {
    unit_colours(&mut colours);
    colours
}

/// Adds the fan triangulation of a polygon (first corner shared) to `out`, its
/// corners indexing `positions`.
pub(crate) fn fan(corners: &[u32], out: &mut Triangles<'_>, positions: &[[f64; 3]]) {
    if let Some((&a, rest)) = corners.split_first() {
        for w in rest.windows(2) {
            out.push([a, w[0], w[1]], positions);
        }
    }
}

/// Where the OFF writer puts a channel.
pub(crate) enum Slot {
    /// After each vertex's coordinates (per vertex, after splitting at seams).
    Vertex,
    /// After each face's indices (a face colour).
    Face,
    /// Left out, and why.
    Left(&'static str),
}

/// Where [`write()`] puts each of `channels`: the first normals, the first colour that
/// is not per face and the first texture coordinates on the vertices (NOFF, COFF,
/// STOFF), the first colour with one value per triangle on the faces (see
/// [`colours_on_faces`] for two of them); nothing else has a place in OFF.
pub(crate) fn slots(channels: &[Channel]) -> Vec<Slot> {
    let mut taken: Vec<(ChannelKind, bool)> = Vec::new();
    channels
        .iter()
        .zip(colours_on_faces(channels))
        .map(|(c, on_face)| match c.kind {
            ChannelKind::Generic => Slot::Left("OFF holds no generic channels"),
            _ if !taken.contains(&(c.kind, on_face)) => {
                taken.push((c.kind, on_face));
                if on_face {
                    Slot::Face
                } else {
                    Slot::Vertex
                }
            }
            ChannelKind::Color => Slot::Left("OFF holds one vertex colour and one face colour"),
            _ => Slot::Left("OFF holds one texture coordinate and one normal per vertex"),
        })
        .collect()
}

/// Writes `values` after a space each; colours clamped to 0–1, so that the reader does
/// not take them for 0–255 levels.
fn write_values(out: &mut impl Write, values: &[f32], clamp: bool) -> std::io::Result<()> {
    for &v in values {
        let v = if clamp { v.clamp(0.0, 1.0) } else { v };
        write!(out, " {v}")?;
    }
    Ok(())
}

pub(crate) fn write(
    out: &mut impl Write,
    mesh: &IndexedMesh,
    comments: &[String],
) -> std::io::Result<()> {
    let slots = slots(&mesh.attributes.channels);
    let mut vertex = Vec::new();
    let mut face = None;
    for (c, slot) in mesh.attributes.channels.iter().zip(&slots) {
        match slot {
            Slot::Vertex => vertex.push(c.clone()),
            Slot::Face => face = Some(c),
            Slot::Left(_) => {}
        }
    }
    let split = per_vertex(mesh, vertex);
    let of = |kind| split.channels.iter().find(|c| c.kind == kind);
    let (normal, colour, uv) = (
        of(ChannelKind::Normal),
        of(ChannelKind::Color),
        of(ChannelKind::TexCoord),
    );
    let st = if uv.is_some() { "ST" } else { "" };
    let c = if colour.is_some() { "C" } else { "" };
    let n = if normal.is_some() { "N" } else { "" };
    writeln!(out, "{st}{c}{n}OFF")?;
    writeln!(out, "# written by qem")?;
    for c in comments {
        writeln!(out, "# {}", super::one_line(c))?;
    }
    writeln!(out, "{} {} 0", split.positions.len(), split.triangles.len())?;
    for (v, [x, y, z]) in split.positions.iter().enumerate() {
        write!(out, "{x} {y} {z}")?;
        // Per vertex after the split: value v is vertex v's.
        for (channel, clamp) in [(normal, false), (colour, true), (uv, false)] {
            if let Some(channel) = channel {
                write_values(out, channel.value(v as u32), clamp)?;
            }
        }
        writeln!(out)?;
    }
    for (t, [a, b, c]) in split.triangles.iter().enumerate() {
        write!(out, "3 {a} {b} {c}")?;
        // The split keeps triangle order, so triangle t is the mesh's triangle t.
        if let Some(colour) = face.and_then(|f| f.at_corner(t, 0)) {
            write_values(out, colour, true)?;
        }
        writeln!(out)?;
    }
    Ok(())
}
