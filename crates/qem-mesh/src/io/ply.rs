//! PLY reader and writer.
//!
//! Reads `ascii`, `binary_little_endian` and `binary_big_endian`. The `vertex` element
//! must have scalar `x`, `y`, `z` properties (any numeric type; `float` and `double`
//! are usual); the `face` element must have an integer list `vertex_indices` or
//! `vertex_index` (any integer count and item types). Every other element and
//! property, lists included, is skipped (and counted in
//! [`ReadNotes::skipped_properties`]). Polygons are fan-triangulated.
//!
//! Header lines are read as bytes: comments and names may hold any bytes (counted in
//! [`ReadNotes::non_utf8_lines`] when not UTF-8), and a line whose keyword the format
//! does not define (`comment`, `obj_info`, `format`, `element`, `property`,
//! `end_header`) is skipped and counted in [`ReadNotes::skipped_lines`]. Types, counts
//! and numbers stay strict: they decide where the geometry is.
//!
//! Writes `binary_little_endian` with `double` coordinates (so positions read back
//! exactly) and `list uchar int vertex_indices`.

use std::io::Write;

use super::off::fan;
use super::text::{self, capacity_for, parse_f64, parse_i64, show, Tokens};
use super::{sniff, Format, Location, ReadError, ReadNotes};
use crate::{IndexedMesh, InputError, MAX_ELEMENTS};

#[derive(Clone, Copy, Debug, PartialEq)]
enum Ty {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Ty {
    fn parse(name: &[u8]) -> Option<Ty> {
        Some(match name {
            b"char" | b"int8" => Ty::I8,
            b"uchar" | b"uint8" => Ty::U8,
            b"short" | b"int16" => Ty::I16,
            b"ushort" | b"uint16" => Ty::U16,
            b"int" | b"int32" => Ty::I32,
            b"uint" | b"uint32" => Ty::U32,
            b"float" | b"float32" => Ty::F32,
            b"double" | b"float64" => Ty::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Ty::I8 | Ty::U8 => 1,
            Ty::I16 | Ty::U16 => 2,
            Ty::I32 | Ty::U32 | Ty::F32 => 4,
            Ty::F64 => 8,
        }
    }

    fn is_float(self) -> bool {
        matches!(self, Ty::F32 | Ty::F64)
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Prop {
    Scalar(Ty),
    List(Ty, Ty),
}

#[derive(Debug)]
struct Element<'a> {
    name: &'a [u8],
    count: usize,
    line: usize,
    props: Vec<(&'a [u8], Prop)>,
}

#[derive(Clone, Copy, PartialEq)]
enum Encoding {
    Ascii,
    Little,
    Big,
}

struct Header<'a> {
    encoding: Encoding,
    elements: Vec<Element<'a>>,
    /// Offset of the first byte after `end_header\n`.
    body: usize,
    /// Line number of the body's first line.
    body_line: usize,
}

fn parse_header<'a>(bytes: &'a [u8], notes: &mut ReadNotes) -> Result<Header<'a>, ReadError> {
    if !(bytes.starts_with(b"ply\n") || bytes.starts_with(b"ply\r\n")) {
        return Err(ReadError::not_this_format(
            Format::Ply,
            sniff(bytes),
            "does not start with \"ply\"",
        ));
    }
    let mut encoding = None;
    let mut elements: Vec<Element> = Vec::new();
    let mut offset = 0usize;
    for (no, raw) in text::lines(bytes) {
        // `lines` strips "\r"; recompute where the next line starts from the raw bytes.
        let line_start = offset;
        offset = match bytes
            .get(line_start..)
            .and_then(|r| r.iter().position(|&b| b == b'\n'))
        {
            Some(i) => line_start + i + 1,
            None => bytes.len(),
        };
        let at = Location::Line(no);
        let mut w = text::words(raw);
        let Some(key) = w.next() else { continue };
        match key {
            b"ply" if no == 1 => {}
            b"comment" | b"obj_info" => {}
            b"format" => {
                encoding = Some(match w.next() {
                    Some(b"ascii") => Encoding::Ascii,
                    Some(b"binary_little_endian") => Encoding::Little,
                    Some(b"binary_big_endian") => Encoding::Big,
                    other => {
                        return Err(ReadError::malformed(
                            at,
                            format!("unknown PLY format {}", show(other.unwrap_or_default())),
                        ))
                    }
                });
            }
            b"element" => {
                let (Some(name), Some(count)) = (w.next(), w.next()) else {
                    return Err(ReadError::malformed(
                        at,
                        "\"element\" needs a name and a count",
                    ));
                };
                let count = text::parse_i64(count)
                    .and_then(|c| u64::try_from(c).ok())
                    .or_else(|| std::str::from_utf8(count).ok()?.parse::<u64>().ok())
                    .ok_or_else(|| {
                        ReadError::malformed(at, format!("bad element count {}", show(count)))
                    })?;
                if count > MAX_ELEMENTS as u64 {
                    let what = match name {
                        b"vertex" => "vertices".to_string(),
                        b"face" => "faces".to_string(),
                        other => format!("\"{}\" elements", String::from_utf8_lossy(other)),
                    };
                    return Err(ReadError::too_large(
                        at,
                        format!("PLY header claims {what}:"),
                        count,
                    ));
                }
                elements.push(Element {
                    name,
                    count: count as usize,
                    line: no,
                    props: Vec::new(),
                });
            }
            b"property" => {
                let Some(el) = elements.last_mut() else {
                    return Err(ReadError::malformed(
                        at,
                        "\"property\" before any \"element\"",
                    ));
                };
                let bad_type = |t: &[u8]| {
                    ReadError::malformed(at, format!("unknown property type {}", show(t)))
                };
                let t = w.next().unwrap_or_default();
                let (prop, name) = if t == b"list" {
                    let ct = w.next().unwrap_or_default();
                    let it = w.next().unwrap_or_default();
                    let ct_ty = Ty::parse(ct).ok_or_else(|| bad_type(ct))?;
                    let it_ty = Ty::parse(it).ok_or_else(|| bad_type(it))?;
                    if ct_ty.is_float() {
                        return Err(ReadError::malformed(
                            at,
                            "a list count must have an integer type",
                        ));
                    }
                    (Prop::List(ct_ty, it_ty), w.next())
                } else {
                    (
                        Prop::Scalar(Ty::parse(t).ok_or_else(|| bad_type(t))?),
                        w.next(),
                    )
                };
                let Some(name) = name else {
                    return Err(ReadError::malformed(at, "property without a name"));
                };
                el.props.push((name, prop));
            }
            b"end_header" => {
                let Some(encoding) = encoding else {
                    return Err(ReadError::malformed(
                        at,
                        "no \"format\" line in the PLY header",
                    ));
                };
                return Ok(Header {
                    encoding,
                    elements,
                    body: offset,
                    body_line: no + 1,
                });
            }
            // A keyword PLY does not define: an exporter's extension. Skipping it is
            // what other readers do; the count in the notes shows it happened.
            _ => notes.skipped_lines += 1,
        }
    }
    Err(ReadError::truncated(
        Location::Line(text::lines(bytes).count()),
        "in the PLY header (no \"end_header\")",
    ))
}

/// What the reader does with each property of an element.
#[derive(Clone, Copy)]
enum Role {
    Coord(usize),
    Indices,
    Skip,
}

fn roles(el: &Element, is_vertex: bool, is_face: bool) -> Result<Vec<Role>, ReadError> {
    let at = Location::Line(el.line);
    let mut roles = Vec::with_capacity(el.props.len());
    let mut found = [false; 3];
    let mut has_indices = false;
    for &(name, prop) in &el.props {
        let role = match (name, prop) {
            (b"x" | b"y" | b"z", Prop::Scalar(_)) if is_vertex => {
                let k = usize::from(name[0] - b'x');
                found[k] = true;
                Role::Coord(k)
            }
            (b"vertex_indices" | b"vertex_index", Prop::List(_, it)) if is_face && !has_indices => {
                if it.is_float() {
                    return Err(ReadError::malformed(
                        at,
                        format!(
                            "face property \"{}\" has a floating-point item type; \
                             vertex indices must be integers",
                            String::from_utf8_lossy(name)
                        ),
                    ));
                }
                has_indices = true;
                Role::Indices
            }
            _ => Role::Skip,
        };
        roles.push(role);
    }
    if is_vertex {
        if let Some(k) = found.iter().position(|f| !f) {
            return Err(ReadError::malformed(
                at,
                format!(
                    "the vertex element has no scalar \"{}\" property",
                    ["x", "y", "z"][k]
                ),
            ));
        }
    }
    if is_face && !has_indices {
        return Err(ReadError::malformed(
            at,
            "the face element has no \"vertex_indices\" list property",
        ));
    }
    Ok(roles)
}

/// Mesh under construction, shared by the ascii and binary paths.
struct Builder {
    positions: Vec<[f64; 3]>,
    triangles: Vec<[u32; 3]>,
    /// Vertex count once the vertex element is read, for range checks while reading
    /// faces (elements may come in any order; `validate` catches the rest).
    vertex_count: Option<usize>,
    corners: Vec<u32>,
    faces: usize,
}

impl Builder {
    fn push_vertex(&mut self, p: [f64; 3], at: Location) -> Result<(), ReadError> {
        if !p.iter().all(|c| c.is_finite()) {
            return Err(ReadError::mesh(
                Some(at),
                InputError::NonFiniteCoordinate {
                    vertex: self.positions.len(),
                },
            ));
        }
        self.positions.push(p);
        Ok(())
    }

    fn push_index(&mut self, i: i64, at: Location) -> Result<(), ReadError> {
        let f = self.faces;
        let in_range = match self.vertex_count {
            Some(n) => i >= 0 && (i as u64) < n as u64,
            None => (0..=i64::from(u32::MAX)).contains(&i),
        };
        if !in_range {
            let n = self
                .vertex_count
                .map_or("no".to_string(), |n| n.to_string());
            return Err(ReadError::malformed(
                at,
                format!("face {f} refers to vertex {i}, but there are only {n} vertices"),
            ));
        }
        self.corners.push(i as u32);
        Ok(())
    }

    fn end_face(&mut self, at: Location) -> Result<(), ReadError> {
        if self.corners.len() < 3 {
            return Err(ReadError::malformed(
                at,
                format!(
                    "face {} has {} corners; a face needs at least 3",
                    self.faces,
                    self.corners.len()
                ),
            ));
        }
        if self.triangles.len() + self.corners.len() - 2 > MAX_ELEMENTS {
            return Err(ReadError::too_large(
                at,
                "PLY triangles:",
                self.triangles.len() as u64,
            ));
        }
        fan(&self.corners, &mut self.triangles);
        self.corners.clear();
        self.faces += 1;
        Ok(())
    }
}

pub(crate) fn read(bytes: &[u8], notes: &mut ReadNotes) -> Result<IndexedMesh, ReadError> {
    let header = parse_header(bytes, notes)?;
    notes.non_utf8_lines += text::non_utf8_lines(bytes.get(..header.body).unwrap_or_default());
    let body = bytes.get(header.body..).unwrap_or_default();
    let mut b = Builder {
        positions: Vec::new(),
        triangles: Vec::new(),
        vertex_count: None,
        corners: Vec::new(),
        faces: 0,
    };
    let mut seen_vertex = false;
    let mut seen_face = false;
    match header.encoding {
        Encoding::Ascii => {
            let mut tok = Tokens::new(body, header.body_line);
            for el in &header.elements {
                let is_vertex = el.name == b"vertex" && !seen_vertex;
                let is_face = el.name == b"face" && !seen_face;
                seen_vertex |= is_vertex;
                seen_face |= is_face;
                let roles = roles(el, is_vertex, is_face)?;
                notes.skipped_properties += skipped(&roles);
                read_ascii_element(&mut tok, el, &roles, &mut b)?;
                if is_vertex {
                    b.vertex_count = Some(b.positions.len());
                }
            }
        }
        Encoding::Little | Encoding::Big => {
            let mut cur = Cursor {
                data: body,
                pos: 0,
                base: header.body as u64,
                big: header.encoding == Encoding::Big,
            };
            for el in &header.elements {
                let is_vertex = el.name == b"vertex" && !seen_vertex;
                let is_face = el.name == b"face" && !seen_face;
                seen_vertex |= is_vertex;
                seen_face |= is_face;
                let roles = roles(el, is_vertex, is_face)?;
                notes.skipped_properties += skipped(&roles);
                read_binary_element(&mut cur, el, &roles, &mut b)?;
                if is_vertex {
                    b.vertex_count = Some(b.positions.len());
                }
            }
        }
    }
    Ok(IndexedMesh::new(b.positions, b.triangles))
}

/// How many properties of an element the reader skips.
fn skipped(roles: &[Role]) -> usize {
    roles.iter().filter(|r| matches!(r, Role::Skip)).count()
}

fn plural(name: &[u8]) -> String {
    match name {
        b"vertex" => "vertices".into(),
        b"face" => "faces".into(),
        other => format!("\"{}\" elements", String::from_utf8_lossy(other)),
    }
}

fn read_ascii_element<'a>(
    tok: &mut Tokens<'a>,
    el: &Element,
    roles: &[Role],
    b: &mut Builder,
) -> Result<(), ReadError> {
    let is_vertex = roles.iter().any(|r| matches!(r, Role::Coord(_)));
    let is_face = roles.iter().any(|r| matches!(r, Role::Indices));
    if is_vertex {
        b.positions
            .reserve(capacity_for(el.count, tok.remaining(), 6));
    }
    if is_face {
        b.triangles
            .reserve(capacity_for(el.count, tok.remaining(), 8));
    }
    let what = plural(el.name);
    for r in 0..el.count {
        let mut p = [0.0; 3];
        for (&(name, prop), &role) in el.props.iter().zip(roles) {
            match (prop, role) {
                (Prop::Scalar(_), Role::Coord(k)) => {
                    let t = next_token(tok, r, el.count, &what)?;
                    p[k] = parse_f64(t).ok_or_else(|| {
                        ReadError::malformed(
                            Location::Line(tok.line()),
                            format!("vertex {r}: bad coordinate {}", show(t)),
                        )
                    })?;
                }
                (Prop::Scalar(_), _) => {
                    next_token(tok, r, el.count, &what)?;
                }
                (Prop::List(..), role) => {
                    let t = next_token(tok, r, el.count, &what)?;
                    let line = Location::Line(tok.line());
                    let n = parse_i64(t).filter(|&n| n >= 0).ok_or_else(|| {
                        ReadError::malformed(
                            line,
                            format!(
                                "{} {r}: bad list length {} for \"{}\"",
                                el.name.escape_ascii(),
                                show(t),
                                name.escape_ascii()
                            ),
                        )
                    })?;
                    // Every item needs at least two bytes ("0 ").
                    if n as u64 > (tok.remaining() as u64).div_ceil(2) {
                        return Err(ReadError::truncated(
                            line,
                            format!(
                                "in {} {r}: its list claims {n} items, more than the rest \
                                 of the file can hold",
                                el.name.escape_ascii()
                            ),
                        ));
                    }
                    for _ in 0..n {
                        let t = next_token(tok, r, el.count, &what)?;
                        if let Role::Indices = role {
                            let at = Location::Line(tok.line());
                            let i = parse_i64(t).ok_or_else(|| {
                                ReadError::malformed(
                                    at,
                                    format!("face {}: bad vertex index {}", b.faces, show(t)),
                                )
                            })?;
                            b.push_index(i, at)?;
                        }
                    }
                    if let Role::Indices = role {
                        b.end_face(line)?;
                    }
                }
            }
        }
        if is_vertex {
            b.push_vertex(p, Location::Line(tok.line()))?;
        }
    }
    Ok(())
}

/// The next ascii token, or a truncation error naming how many records were complete.
fn next_token<'a>(
    tok: &mut Tokens<'a>,
    done: usize,
    count: usize,
    what: &str,
) -> Result<&'a [u8], ReadError> {
    let line = tok.line();
    tok.next_token().ok_or_else(|| {
        ReadError::truncated(
            Location::Line(line),
            format!("after {done} of {count} {what}"),
        )
    })
}

struct Cursor<'a> {
    data: &'a [u8],
    pos: usize,
    /// Offset of `data[0]` in the file, for error locations.
    base: u64,
    big: bool,
}

impl Cursor<'_> {
    fn at(&self) -> Location {
        Location::Byte(self.base + self.pos as u64)
    }

    fn remaining(&self) -> usize {
        self.data.len().saturating_sub(self.pos)
    }

    fn take<const N: usize>(&mut self) -> Option<[u8; N]> {
        let b: [u8; N] = self
            .data
            .get(self.pos..self.pos.checked_add(N)?)?
            .try_into()
            .ok()?;
        self.pos += N;
        Some(if self.big {
            let mut r = b;
            r.reverse();
            r
        } else {
            b
        })
    }

    /// Reads one scalar of type `ty` as f64 (exact for every PLY type).
    fn scalar(&mut self, ty: Ty) -> Option<f64> {
        Some(match ty {
            Ty::I8 => f64::from(i8::from_le_bytes(self.take()?)),
            Ty::U8 => f64::from(u8::from_le_bytes(self.take()?)),
            Ty::I16 => f64::from(i16::from_le_bytes(self.take()?)),
            Ty::U16 => f64::from(u16::from_le_bytes(self.take()?)),
            Ty::I32 => f64::from(i32::from_le_bytes(self.take()?)),
            Ty::U32 => f64::from(u32::from_le_bytes(self.take()?)),
            Ty::F32 => f64::from(f32::from_le_bytes(self.take()?)),
            Ty::F64 => f64::from_le_bytes(self.take()?),
        })
    }

    /// Reads one integer scalar (`ty` is never a float type here).
    fn int(&mut self, ty: Ty) -> Option<i64> {
        Some(match ty {
            Ty::I8 => i64::from(i8::from_le_bytes(self.take()?)),
            Ty::U8 => i64::from(u8::from_le_bytes(self.take()?)),
            Ty::I16 => i64::from(i16::from_le_bytes(self.take()?)),
            Ty::U16 => i64::from(u16::from_le_bytes(self.take()?)),
            Ty::I32 => i64::from(i32::from_le_bytes(self.take()?)),
            Ty::U32 => i64::from(u32::from_le_bytes(self.take()?)),
            // A float where an integer is required: read it so the caller can refuse it.
            Ty::F32 | Ty::F64 => return None,
        })
    }
}

fn read_binary_element(
    cur: &mut Cursor,
    el: &Element,
    roles: &[Role],
    b: &mut Builder,
) -> Result<(), ReadError> {
    let what = plural(el.name);
    let fixed: Option<usize> = el.props.iter().try_fold(0usize, |acc, (_, p)| match p {
        Prop::Scalar(t) => Some(acc + t.size()),
        Prop::List(..) => None,
    });
    if let Some(stride) = fixed {
        // Fixed-size records: the whole element must fit in what is left.
        let fits = cur.remaining() / stride.max(1);
        if stride > 0 && fits < el.count {
            let at = Location::Byte(cur.base + (cur.pos + fits * stride) as u64);
            return Err(ReadError::truncated(
                at,
                format!("after {fits} of {} {what} (binary PLY)", el.count),
            ));
        }
        if !roles.iter().any(|r| matches!(r, Role::Coord(_))) {
            cur.pos += stride * el.count;
            return Ok(());
        }
        b.positions.reserve(el.count);
    }
    let mut has_faces = false;
    for r in 0..el.count {
        let truncated = |cur: &Cursor| {
            ReadError::truncated(
                cur.at(),
                format!("after {r} of {} {what} (binary PLY)", el.count),
            )
        };
        let record_at = cur.at();
        let mut p = [0.0; 3];
        let mut is_vertex = false;
        for (&(_, prop), &role) in el.props.iter().zip(roles) {
            match (prop, role) {
                (Prop::Scalar(ty), Role::Coord(k)) => {
                    p[k] = cur.scalar(ty).ok_or_else(|| truncated(cur))?;
                    is_vertex = true;
                }
                (Prop::Scalar(ty), _) => {
                    if cur.remaining() < ty.size() {
                        return Err(truncated(cur));
                    }
                    cur.pos += ty.size();
                }
                (Prop::List(ct, it), role) => {
                    let list_at = cur.at();
                    let n = cur.int(ct).ok_or_else(|| truncated(cur))?;
                    let n = u64::try_from(n).map_err(|_| {
                        ReadError::malformed(
                            list_at,
                            format!("{} {r}: negative list length {n}", el.name.escape_ascii()),
                        )
                    })?;
                    let bytes = n.saturating_mul(it.size() as u64);
                    if bytes > cur.remaining() as u64 {
                        return Err(ReadError::truncated(
                            list_at,
                            format!(
                                "in {} {r}: its list claims {n} items ({bytes} bytes) but \
                                 only {} bytes are left",
                                el.name.escape_ascii(),
                                cur.remaining()
                            ),
                        ));
                    }
                    if let Role::Indices = role {
                        if !has_faces {
                            // At least 1 + 3 bytes per face: never reserve past the data.
                            b.triangles
                                .reserve(capacity_for(el.count, cur.remaining(), 4));
                            has_faces = true;
                        }
                        for _ in 0..n {
                            let at = cur.at();
                            let i = cur.int(it).ok_or_else(|| truncated(cur))?;
                            b.push_index(i, at)?;
                        }
                        b.end_face(record_at)?;
                    } else {
                        cur.pos += bytes as usize;
                    }
                }
            }
        }
        if is_vertex {
            b.push_vertex(p, record_at)?;
        }
    }
    Ok(())
}

pub(crate) fn write(out: &mut impl Write, mesh: &IndexedMesh) -> std::io::Result<()> {
    write!(
        out,
        "ply\nformat binary_little_endian 1.0\ncomment written by qem\n\
         element vertex {}\nproperty double x\nproperty double y\nproperty double z\n\
         element face {}\nproperty list uchar int vertex_indices\nend_header\n",
        mesh.positions.len(),
        mesh.triangles.len()
    )?;
    let mut buf = [0u8; 24];
    for p in &mesh.positions {
        for (k, c) in p.iter().enumerate() {
            buf[8 * k..8 * k + 8].copy_from_slice(&c.to_le_bytes());
        }
        out.write_all(&buf)?;
    }
    let mut rec = [0u8; 13];
    rec[0] = 3;
    for t in &mesh.triangles {
        for (k, &i) in t.iter().enumerate() {
            // Indices are < 2^31 in any mesh qem accepts (MAX_ELEMENTS = 2^28).
            rec[1 + 4 * k..5 + 4 * k].copy_from_slice(&i.to_le_bytes());
        }
        out.write_all(&rec)?;
    }
    Ok(())
}
