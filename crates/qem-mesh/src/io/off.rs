//! OFF reader and writer.
//!
//! Reads the text form: a header word `OFF` optionally prefixed by `ST`, `C` and `N`
//! (texture coordinates, colours and normals after each vertex's coordinates, which are
//! skipped), then `vertices faces [edges]` (on the header line or the next one), one
//! vertex per line, then one face per line as `n i1 .. in [colour]`. `#` starts a
//! comment. `4OFF`, `nOFF` and `OFF BINARY` are refused with a clear error.
//!
//! Comments may hold any bytes (they are counted in [`ReadNotes::non_utf8_lines`] when
//! they are not UTF-8); numbers must be numbers. Lines after the last face are skipped
//! and counted in [`ReadNotes::skipped_lines`].

use std::io::Write;

use super::text::{self, capacity_for, parse_f64, parse_i64, show, words};
use super::{sniff, Format, Location, ReadError, ReadNotes};
use crate::{IndexedMesh, InputError, MAX_ELEMENTS};

pub(crate) fn read(bytes: &[u8], notes: &mut ReadNotes) -> Result<IndexedMesh, ReadError> {
    let mut lines = text::lines(bytes)
        .map(|(no, l)| (no, text::trim(text::strip_comment(l, b'#'))))
        .filter(|(_, l)| !l.is_empty());
    let not_off =
        |detail: &str| ReadError::not_this_format(Format::Off, sniff(bytes), detail.to_string());
    let Some((header_line, header)) = lines.next() else {
        return Err(not_off("no header (only blank lines and comments)"));
    };
    let mut header_words = words(header);
    let magic = header_words.next().unwrap_or_default();
    let Some(prefix) = magic.strip_suffix(b"OFF") else {
        return Err(not_off(&format!(
            "the first word is {}, not OFF",
            show(magic)
        )));
    };
    let at = |line| Location::Line(line);
    match prefix {
        b"" | b"C" | b"N" | b"NC" | b"CN" | b"ST" | b"STC" | b"STN" | b"STNC" | b"STCN" => {}
        _ => {
            return Err(ReadError::malformed(
                at(header_line),
                format!("unsupported OFF variant {}", show(magic)),
            ))
        }
    }
    let mut counts: Vec<&[u8]> = header_words.collect();
    if counts.first() == Some(&&b"BINARY"[..]) {
        return Err(ReadError::malformed(
            at(header_line),
            "binary OFF is not supported",
        ));
    }
    let mut counts_line = header_line;
    if counts.is_empty() {
        let Some((no, l)) = lines.next() else {
            return Err(ReadError::truncated(
                at(header_line),
                "after the header: no vertex and face counts",
            ));
        };
        counts_line = no;
        counts = words(l).collect();
    }
    if counts.len() < 2 {
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
    let nv = parse_count(counts[0], "vertex", "vertices")?;
    let nf = parse_count(counts[1], "face", "faces")?;

    let mut positions = Vec::with_capacity(capacity_for(nv, bytes.len(), 6));
    let mut last_line = counts_line;
    for v in 0..nv {
        let Some((no, l)) = lines.next() else {
            return Err(ReadError::truncated(
                at(last_line),
                format!("after {v} of {nv} vertices"),
            ));
        };
        last_line = no;
        let mut p = [0.0; 3];
        let mut w = words(l);
        for (k, c) in p.iter_mut().enumerate() {
            let tok = w.next().ok_or_else(|| {
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
    }
    let mut triangles = Vec::with_capacity(capacity_for(nf, bytes.len(), 8));
    let mut corners: Vec<u32> = Vec::new();
    for f in 0..nf {
        let Some((no, l)) = lines.next() else {
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
        fan(&corners, &mut triangles);
    }
    notes.skipped_lines += lines.count();
    notes.non_utf8_lines += text::non_utf8_lines(bytes);
    Ok(IndexedMesh::new(positions, triangles))
}

/// Appends the fan triangulation of a polygon (first corner shared) to `out`.
pub(crate) fn fan(corners: &[u32], out: &mut Vec<[u32; 3]>) {
    if let Some((&a, rest)) = corners.split_first() {
        out.extend(rest.windows(2).map(|w| [a, w[0], w[1]]));
    }
}

pub(crate) fn write(out: &mut impl Write, mesh: &IndexedMesh) -> std::io::Result<()> {
    writeln!(out, "OFF")?;
    writeln!(out, "# written by qem")?;
    writeln!(out, "{} {} 0", mesh.positions.len(), mesh.triangles.len())?;
    for [x, y, z] in &mesh.positions {
        writeln!(out, "{x} {y} {z}")?;
    }
    for [a, b, c] in &mesh.triangles {
        writeln!(out, "3 {a} {b} {c}")?;
    }
    Ok(())
}
