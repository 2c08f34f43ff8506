//! PLY reader and writer.
//!
//! Reads `ascii`, `binary_little_endian` and `binary_big_endian`. The `vertex` element
//! must have scalar `x`, `y`, `z` properties (any numeric type; `float` and `double`
//! are usual); the `face` element must have an integer list `vertex_indices` or
//! `vertex_index` (any integer count and item types). Polygons are fan-triangulated.
//!
//! # Attributes
//! Scalar vertex properties become per-vertex channels (stored per corner: a corner's
//! value is its vertex's):
//! - colours `red green blue [alpha]`, or `diffuse_red diffuse_green diffuse_blue
//!   [diffuse_alpha]`: a [`ChannelKind::Color`] of 3 or 4 floats. `uchar` (and any
//!   integer type but `ushort`) is divided by 255, `ushort` by 65535, `float` and
//!   `double` are taken as they are;
//! - normals `nx ny nz`;
//! - texture coordinates `s t`, `u v`, `texture_u texture_v` or `texture_s texture_t`;
//! - every other scalar: a [`ChannelKind::Generic`] channel named after the property,
//!   and `<name>_0`, `<name>_1`... (2 to 4 in a row) as one vector channel `<name>`.
//!   Integers become floats (exact up to 2^24). A name that no PLY file could hold
//!   (empty, or with a space or control byte) is skipped, as the writer leaves it out.
//!
//! Only the first complete set of each kind is read; a property named like a member of
//! a set (`red`, `u`, ...) outside a complete set is skipped. The face element's
//! colour (the same two sets) becomes a channel whose corners all use their face's
//! value (each triangle of a polygon gets the polygon's), named `colour`, or
//! `face_colour` when the vertices have one. Channel names are unique: a property
//! whose name is taken is skipped. At most [`MAX_CHANNELS`] channels are read.
//! A value that is not finite as a 32-bit float (`nan`, or a `double` beyond
//! `f32`) is an error naming the element, its index and the property.
//!
//! What is skipped and counted in [`ReadNotes::skipped_properties`]: list properties
//! other than the face's indices, face properties other than its colour, every
//! property of other elements, and the vertex properties described above.
//!
//! Header lines are read as bytes: comments and names may hold any bytes (counted in
//! [`ReadNotes::non_utf8_lines`] when not UTF-8; names become channel names with
//! invalid bytes replaced), and a line whose keyword the format does not define
//! (`comment`, `obj_info`, `format`, `element`, `property`, `end_header`) is skipped
//! and counted in [`ReadNotes::skipped_lines`]. Types, counts and numbers stay strict:
//! they decide where the geometry is.
//!
//! # Writing
//! Writes `binary_little_endian` with `double` coordinates (so positions read back
//! exactly) and `list uchar int vertex_indices`. Channels ([`placements`]) follow the
//! coordinates, per vertex after splitting the vertices at their seams
//! ([`split_at_seams`](crate::attributes::split_at_seams); channels the reader made are
//! already per vertex and keep the vertices as they are): the first normals as
//! `float nx ny nz`, the first texture coordinates as `float s t`, the first colour as
//! `red green blue [alpha]`, generic channels as `float <name>` (vectors
//! `<name>_0`...). A colour with one value per triangle (a face colour) is written on
//! the faces instead. Colours are `uchar` when every component is exactly a level
//! `k/255` (what `uchar` colours read as, so they come back bit-exact), `float`
//! otherwise (so 0.3 is not rounded to 77/255). A corner without a value is written as
//! zeros. A mesh without channels gives the same file as before attributes existed.

use std::io::Write;

use super::channels::{all_levels, colours_on_faces, from_level, per_vertex, to_level};
use super::input::Input;
use super::off::fan;
use super::stream::Triangles;
use super::text::{self, capacity_for, parse_f32, parse_f64, parse_i64, show, TextStream};
use super::{sniff, sniff_input, Format, Location, ReadError, ReadErrorKind, ReadNotes};
use crate::attributes::{Attributes, Channel, ChannelKind};
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

/// Whether `bytes` start with PLY's magic line (`ply` and a line break).
pub(crate) fn starts_ply(bytes: &[u8]) -> bool {
    bytes.starts_with(b"ply\n") || bytes.starts_with(b"ply\r\n")
}

fn parse_header<'a>(bytes: &'a [u8], notes: &mut ReadNotes) -> Result<Header<'a>, ReadError> {
    if !starts_ply(bytes) {
        return Err(not_ply(sniff(bytes)));
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

/// At most this many attribute channels are read from one file; the properties of
/// further ones are skipped and counted. Every channel holds three indices per
/// triangle, so without a cap a header of many one-byte properties would make memory
/// grow with properties times triangles, far beyond the file's size: 16 channels take
/// 192 bytes per triangle, 48 times the smallest binary face record (4 bytes), and are
/// more than scanners and exporters write (normal, colour, texture coordinates and a
/// few scalars such as quality or intensity).
pub(crate) const MAX_CHANNELS: usize = 16;

/// Vertex properties read together as one channel, in the order the reader looks for
/// them: the first complete set of each kind is read. A colour set's last name (alpha)
/// is optional.
const VERTEX_SETS: [(ChannelKind, &[&[u8]]); 7] = [
    (ChannelKind::Color, &[b"red", b"green", b"blue", b"alpha"]),
    (
        ChannelKind::Color,
        &[
            b"diffuse_red",
            b"diffuse_green",
            b"diffuse_blue",
            b"diffuse_alpha",
        ],
    ),
    (ChannelKind::Normal, &[b"nx", b"ny", b"nz"]),
    (ChannelKind::TexCoord, &[b"s", b"t"]),
    (ChannelKind::TexCoord, &[b"u", b"v"]),
    (ChannelKind::TexCoord, &[b"texture_u", b"texture_v"]),
    (ChannelKind::TexCoord, &[b"texture_s", b"texture_t"]),
];

/// Whether the reader gives a vertex property's name a meaning (a coordinate or a
/// member of [`VERTEX_SETS`]). Such a property outside a complete set is skipped rather
/// than read as a generic channel, because written back under its name it would mean
/// something else; the writer refuses generic channels with these names for the same
/// reason.
fn is_reserved(name: &[u8]) -> bool {
    matches!(name, b"x" | b"y" | b"z") || VERTEX_SETS.iter().any(|(_, set)| set.contains(&name))
}

/// The PLY property names of a generic channel: its name, or `<name>_0`, `<name>_1`...
/// for a vector. The writer writes them; the reader skips a channel whose names an
/// earlier one has, which the writer could not write.
fn generic_property_names(name: &str, dimension: usize) -> Vec<String> {
    if dimension == 1 {
        vec![name.to_string()]
    } else {
        (0..dimension).map(|k| format!("{name}_{k}")).collect()
    }
}

/// Whether a generic channel's name can be a PLY property name: not empty, and without
/// spaces or control bytes (which PLY readers take for a separator or choke on). The
/// writer leaves other channels out; the reader skips such properties (a fuzzed
/// header had `diff&use\0\x0b_red`), so that what it reads it can write back.
fn is_writable_name(name: &[u8]) -> bool {
    !name.is_empty() && !name.iter().any(|&b| b <= b' ' || b == 0x7f)
}

/// How a property's number becomes a channel's float.
#[derive(Clone, Copy, Debug)]
enum Convert {
    /// A float property: its value, rounded to `f32`.
    Float,
    /// An integer property: its value divided by this (255 for `uchar` colours,
    /// 65535 for `ushort` ones, 1 for everything else).
    Level(f64),
}

impl Convert {
    fn of(kind: ChannelKind, ty: Ty) -> Convert {
        match (kind, ty) {
            (_, Ty::F32 | Ty::F64) => Convert::Float,
            (ChannelKind::Color, Ty::U16) => Convert::Level(65535.0),
            // Integer colours of any other type follow the 0-255 convention of uchar.
            (ChannelKind::Color, _) => Convert::Level(255.0),
            _ => Convert::Level(1.0),
        }
    }
}

/// What the reader does with each property of an element.
#[derive(Clone, Copy, Debug)]
enum Role {
    Coord(usize),
    Indices,
    /// Component `component` of the element's channel `channel`.
    Value {
        channel: usize,
        component: usize,
        convert: Convert,
    },
    Skip,
}

/// Which element an element is for the reader: the first `vertex`, the first `face`,
/// or another.
#[derive(Clone, Copy, PartialEq)]
enum Side {
    Vertex,
    Face,
    Other,
}

/// A channel the reader fills from an element's properties.
struct Planned {
    kind: ChannelKind,
    name: String,
    dimension: usize,
}

/// How the reader reads one element.
struct Plan {
    roles: Vec<Role>,
    /// The channels filled from the element, in the order of their first property.
    channels: Vec<Planned>,
}

/// A channel's properties: (property index, component) pairs.
type Members = Vec<(usize, usize)>;

/// The plan for `el`; `names` holds the names of the channels planned so far (which
/// must stay unique) and receives the new ones.
fn plan(el: &Element, side: Side, names: &mut Vec<String>) -> Result<Plan, ReadError> {
    let at = Location::Line(el.line);
    let is_vertex = side == Side::Vertex;
    let is_face = side == Side::Face;
    let mut roles = vec![Role::Skip; el.props.len()];
    let mut found = [false; 3];
    let mut has_indices = false;
    for (role, &(name, prop)) in roles.iter_mut().zip(&el.props) {
        match (name, prop) {
            (b"x" | b"y" | b"z", Prop::Scalar(_)) if is_vertex => {
                let k = usize::from(name[0] - b'x');
                found[k] = true;
                *role = Role::Coord(k);
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
                *role = Role::Indices;
            }
            _ => {}
        }
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

    // Candidate channels: kind, name and members, sets first.
    let mut candidates: Vec<(ChannelKind, String, Members)> = Vec::new();
    let scalar = |i: usize| matches!(el.props[i].1, Prop::Scalar(_));
    let sets: &[(ChannelKind, &[&[u8]])] = match side {
        Side::Vertex => &VERTEX_SETS,
        // Faces carry colours only (the two colour sets).
        Side::Face => &VERTEX_SETS[..2],
        Side::Other => &[],
    };
    let mut member = vec![false; el.props.len()];
    for &(kind, set) in sets {
        if candidates.iter().any(|c| c.0 == kind) {
            continue;
        }
        let required = if kind == ChannelKind::Color {
            3
        } else {
            set.len()
        };
        let at: Vec<Option<usize>> = set
            .iter()
            .map(|n| (0..el.props.len()).find(|&i| el.props[i].0 == *n && scalar(i)))
            .collect();
        if at[..required].iter().any(Option::is_none) {
            continue;
        }
        let members: Members = at
            .iter()
            .enumerate()
            .filter_map(|(k, i)| i.map(|i| (i, k)))
            .collect();
        for &(i, _) in &members {
            member[i] = true;
        }
        let name = if is_face && names.iter().any(|n| n == "colour") {
            "face_colour".to_string()
        } else {
            kind.as_str().to_string()
        };
        candidates.push((kind, name, members));
    }
    if is_vertex {
        // Every other scalar: a generic channel; `<base>_0`, `<base>_1`... (2 to 4 in a
        // row) together, as the writer writes a generic vector.
        let free = |i: usize| {
            let name = el.props[i].0;
            scalar(i)
                && !member[i]
                && !is_reserved(name)
                && is_writable_name(name)
                && matches!(roles[i], Role::Skip)
        };
        let mut i = 0;
        while i < el.props.len() {
            if !free(i) {
                i += 1;
                continue;
            }
            let name = el.props[i].0;
            let mut len = 1;
            if let Some(base) = name.strip_suffix(b"_0") {
                while len < 4
                    && i + len < el.props.len()
                    && free(i + len)
                    && el.props[i + len].0.strip_prefix(base) == Some(format!("_{len}").as_bytes())
                {
                    len += 1;
                }
            }
            let shown = if len > 1 {
                &name[..name.len() - 2]
            } else {
                name
            };
            // `_0`, `_1`: a vector without a name.
            if !is_writable_name(shown) {
                i += len;
                continue;
            }
            candidates.push((
                ChannelKind::Generic,
                String::from_utf8_lossy(shown).into_owned(),
                (i..i + len).enumerate().map(|(k, p)| (p, k)).collect(),
            ));
            i += len;
        }
    }

    // Accepted in priority order (sets, then generics), kept in property order.
    let mut accepted = Vec::new();
    // The property names of the generic channels accepted, as the writer names them.
    let mut written: Vec<String> = Vec::new();
    for (kind, name, members) in candidates {
        if names.len() >= MAX_CHANNELS || names.contains(&name) {
            continue;
        }
        if kind == ChannelKind::Generic {
            // A channel whose property names another has could not be written back
            // (`a_0 a_1` and a second `a_0`; or two names that differ only in bytes
            // that are not UTF-8, which both become U+FFFD), so it is skipped.
            let props = generic_property_names(&name, members.len());
            if props.iter().any(|p| written.contains(p)) {
                continue;
            }
            written.extend(props);
        }
        names.push(name.clone());
        accepted.push((kind, name, members));
    }
    accepted.sort_by_key(|(_, _, members)| members.iter().map(|m| m.0).min());
    let mut channels = Vec::with_capacity(accepted.len());
    for (c, (kind, name, members)) in accepted.into_iter().enumerate() {
        for &(i, component) in &members {
            if let Prop::Scalar(ty) = el.props[i].1 {
                roles[i] = Role::Value {
                    channel: c,
                    component,
                    convert: Convert::of(kind, ty),
                };
            }
        }
        channels.push(Planned {
            kind,
            name,
            dimension: members.len(),
        });
    }
    Ok(Plan { roles, channels })
}

/// One channel's values as they are read.
struct Values {
    dimension: usize,
    data: Vec<f32>,
}

/// Mesh under construction, shared by the ascii and binary paths.
struct Builder<'t, 's> {
    positions: Vec<[f64; 3]>,
    triangles: &'t mut Triangles<'s>,
    /// Vertex count once the vertex element is read, for range checks while reading
    /// faces (elements may come in any order; `validate` catches the rest).
    vertex_count: Option<usize>,
    corners: Vec<u32>,
    faces: usize,
    /// The vertex element's channels, one value per vertex record.
    vertex_values: Vec<Values>,
    /// The face element's channels (a colour), one value per face record.
    face_values: Vec<Values>,
    /// For each triangle, the face record it comes from (kept only when the face
    /// element has channels: a polygon's triangles share its values).
    triangle_faces: Vec<u32>,
}

impl Builder<'_, '_> {
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
        fan(&self.corners, self.triangles, &self.positions);
        // (A streaming read keeps no per-face data.)
        if !self.face_values.is_empty() && !self.triangles.is_streamed() {
            // faces < MAX_ELEMENTS (the header's count is checked), so it fits a u32.
            self.triangle_faces.extend(std::iter::repeat_n(
                self.faces as u32,
                self.corners.len() - 2,
            ));
        }
        self.corners.clear();
        self.faces += 1;
        Ok(())
    }

    fn values(&mut self, side: Side) -> &mut [Values] {
        match side {
            Side::Vertex => &mut self.vertex_values,
            Side::Face => &mut self.face_values,
            Side::Other => &mut [],
        }
    }

    /// Starts a record of `side`'s element: a zero value in each of its channels, for
    /// [`Builder::store`] to fill.
    fn start_record(&mut self, side: Side) {
        // A streaming read checks every value but keeps only the record being read.
        let streamed = self.triangles.is_streamed();
        for v in self.values(side) {
            if streamed {
                v.data.clear();
            }
            v.data.extend(std::iter::repeat_n(0.0, v.dimension));
        }
    }

    /// Stores component `component` of channel `channel` in the current record of
    /// `side`'s element; a value that is not finite is an error naming record `r` of
    /// `el` and the property (`shown`: the number as the file has it).
    fn store(
        &mut self,
        side: Side,
        (channel, component): (usize, usize),
        value: f32,
        (el, r, name): (&[u8], usize, &[u8]),
        shown: impl FnOnce() -> String,
        at: Location,
    ) -> Result<(), ReadError> {
        if !value.is_finite() {
            return Err(ReadError::malformed(
                at,
                format!(
                    "{} {r}: property \"{}\" is {}, not a finite 32-bit float",
                    el.escape_ascii(),
                    name.escape_ascii(),
                    shown()
                ),
            ));
        }
        if let Some(v) = self.values(side).get_mut(channel) {
            let i = v.data.len() - v.dimension + component;
            v.data[i] = value;
        }
        Ok(())
    }
}

/// Header bytes looked at first for `end_header`; a longer header is read in doubling
/// steps.
pub(crate) const HEADER_PREFIX: usize = 1 << 16;

/// Reads a PLY file as it arrives: the header whole, then a binary body whole records
/// at a time, an ASCII one a token at a time.
///
/// The triangles go to `triangles` (see [`Triangles`]); the mesh returned holds the
/// positions and the attributes, its triangle list empty.
pub(crate) fn read(
    input: &mut Input<'_>,
    notes: &mut ReadNotes,
    triangles: &mut Triangles<'_>,
) -> Result<IndexedMesh, ReadError> {
    input.fill(b"ply\r\n".len())?;
    if !starts_ply(input.window()) {
        return Err(not_ply(sniff_input(input)?));
    }
    let mut want = HEADER_PREFIX;
    loop {
        input.fill(want)?;
        let window = input.window();
        let end = input.at_end();
        // The window's lines are whole up to its last line break, or all of it at the
        // end of the data: a header found in them is the whole data's header, and an
        // error in them is the whole data's first error.
        let cut = if end {
            Some(window.len())
        } else {
            window.iter().rposition(|&b| b == b'\n').map(|i| i + 1)
        };
        let tried = cut.map(|cut| {
            let mut trial = *notes;
            parse_header(&window[..cut], &mut trial).map(|h| (h.encoding, h.body))
        });
        // Only "no end_header" says the header may go on past the window.
        let goes_on = !end
            && match &tried {
                None => true,
                Some(Err(e)) => matches!(e.kind(), ReadErrorKind::Truncated { .. }),
                Some(Ok(_)) => false,
            };
        match tried {
            Some(Ok((encoding, body))) => {
                let head = window[..body].to_vec();
                input.consume(body);
                let header = parse_header(&head, notes)?;
                let body = match encoding {
                    Encoding::Ascii => Body::Ascii(TextStream::new(input, header.body_line)),
                    Encoding::Little | Encoding::Big => Body::Binary(input),
                };
                return read_body(&head, &header, body, notes, triangles);
            }
            Some(Err(e)) if !goes_on => return Err(e),
            _ => want = window.len().saturating_mul(2),
        }
    }
}

/// The error for data that does not start with a PLY header's first line.
fn not_ply(looks_like: Option<&'static str>) -> ReadError {
    ReadError::not_this_format(Format::Ply, looks_like, "does not start with \"ply\"")
}

/// Where the elements' records come from.
enum Body<'i, 'a> {
    Ascii(TextStream<'i, 'a>),
    Binary(&'i mut Input<'a>),
}

/// Reads the elements `header` declares from `body`; `head` is the header's bytes.
fn read_body(
    head: &[u8],
    header: &Header,
    mut body: Body,
    notes: &mut ReadNotes,
    triangles: &mut Triangles<'_>,
) -> Result<IndexedMesh, ReadError> {
    notes.non_utf8_lines += text::non_utf8_lines(head);
    // Which element is which, and the plans: the vertex element's first, so a face
    // colour knows whether "colour" is taken whatever order the elements come in.
    let mut sides = Vec::with_capacity(header.elements.len());
    let (mut seen_vertex, mut seen_face) = (false, false);
    for el in &header.elements {
        let side = if el.name == b"vertex" && !seen_vertex {
            seen_vertex = true;
            Side::Vertex
        } else if el.name == b"face" && !seen_face {
            seen_face = true;
            Side::Face
        } else {
            Side::Other
        };
        sides.push(side);
    }
    let mut names = Vec::new();
    let mut plans: Vec<Option<Plan>> = header.elements.iter().map(|_| None).collect();
    for wanted in [Side::Vertex, Side::Face, Side::Other] {
        for ((el, &side), slot) in header.elements.iter().zip(&sides).zip(&mut plans) {
            if side == wanted {
                *slot = Some(plan(el, side, &mut names)?);
            }
        }
    }
    let plans: Vec<Plan> = plans.into_iter().flatten().collect();
    let channels_of = |side: Side| -> Vec<Values> {
        sides
            .iter()
            .zip(&plans)
            .filter(|(&s, _)| s == side)
            .flat_map(|(_, p)| &p.channels)
            .map(|c| Values {
                dimension: c.dimension,
                data: Vec::new(),
            })
            .collect()
    };
    let mut b = Builder {
        positions: Vec::new(),
        triangles,
        vertex_count: None,
        corners: Vec::new(),
        faces: 0,
        vertex_values: channels_of(Side::Vertex),
        face_values: channels_of(Side::Face),
        triangle_faces: Vec::new(),
    };
    let big = header.encoding == Encoding::Big;
    for ((el, &side), plan) in header.elements.iter().zip(&sides).zip(&plans) {
        notes.skipped_properties += skipped(&plan.roles);
        let element = Reading {
            el,
            roles: &plan.roles,
            side,
        };
        match &mut body {
            Body::Ascii(tok) => read_ascii_element(tok, &element, &mut b)?,
            Body::Binary(input) => read_binary_element(input, &element, big, &mut b)?,
        }
        if side == Side::Vertex {
            b.vertex_count = Some(b.positions.len());
        }
    }
    let mut channels = Vec::new();
    for (side, values) in [(Side::Vertex, b.vertex_values), (Side::Face, b.face_values)] {
        let planned = sides
            .iter()
            .zip(&plans)
            .filter(|(&s, _)| s == side)
            .flat_map(|(_, p)| &p.channels);
        for (c, v) in planned.zip(values) {
            // A vertex channel's value i is vertex i's; a face channel's is face i's.
            let corners = match side {
                Side::Vertex => b.triangles.kept_list().to_vec(),
                _ => b.triangle_faces.iter().map(|&f| [f; 3]).collect(),
            };
            channels.push(Channel {
                kind: c.kind,
                name: c.name.clone(),
                dimension: c.dimension,
                values: v.data,
                corners,
            });
        }
    }
    Ok(
        IndexedMesh::new(b.positions, Vec::new()).with_attributes(Attributes {
            channels,
            ..Attributes::default()
        }),
    )
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

/// An element being read: its declaration, its plan's roles, and which it is.
struct Reading<'e, 'a> {
    el: &'e Element<'a>,
    roles: &'e [Role],
    side: Side,
}

fn read_ascii_element(
    tok: &mut TextStream<'_, '_>,
    reading: &Reading,
    b: &mut Builder<'_, '_>,
) -> Result<(), ReadError> {
    let Reading { el, roles, side } = *reading;
    let is_vertex = roles.iter().any(|r| matches!(r, Role::Coord(_)));
    let is_face = roles.iter().any(|r| matches!(r, Role::Indices));
    if is_vertex {
        b.positions
            .reserve(capacity_for(el.count, tok.could_hold(), 6));
    }
    if is_face {
        b.triangles
            .reserve(capacity_for(el.count, tok.could_hold(), 8));
    }
    let what = plural(el.name);
    for r in 0..el.count {
        if b.triangles.has_failed() {
            return Err(Triangles::stopped());
        }
        b.start_record(side);
        let mut p = [0.0; 3];
        for (&(name, prop), &role) in el.props.iter().zip(roles) {
            match (prop, role) {
                (Prop::Scalar(_), Role::Coord(k)) => {
                    let (t, line) = next_token(tok, r, el.count, &what)?;
                    p[k] = parse_f64(t).ok_or_else(|| {
                        ReadError::malformed(
                            Location::Line(line),
                            format!("vertex {r}: bad coordinate {}", show(t)),
                        )
                    })?;
                }
                (
                    Prop::Scalar(_),
                    Role::Value {
                        channel,
                        component,
                        convert,
                    },
                ) => {
                    let (t, line) = next_token(tok, r, el.count, &what)?;
                    let at = Location::Line(line);
                    let value = match convert {
                        Convert::Float => parse_f32(t),
                        Convert::Level(max) => parse_f64(t).map(|v| from_level(v, max)),
                    }
                    .ok_or_else(|| {
                        ReadError::malformed(
                            at,
                            format!(
                                "{} {r}: bad value {} for property \"{}\"",
                                el.name.escape_ascii(),
                                show(t),
                                name.escape_ascii()
                            ),
                        )
                    })?;
                    b.store(
                        side,
                        (channel, component),
                        value,
                        (el.name, r, name),
                        || show(t),
                        at,
                    )?;
                }
                (Prop::Scalar(_), _) => {
                    next_token(tok, r, el.count, &what)?;
                }
                (Prop::List(..), role) => {
                    let (t, line) = next_token(tok, r, el.count, &what)?;
                    let line = Location::Line(line);
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
                    let start = tok.offset();
                    let items = (0..n).try_for_each(|_| {
                        let (t, line) = next_token(tok, r, el.count, &what)?;
                        if let Role::Indices = role {
                            let at = Location::Line(line);
                            let i = parse_i64(t).ok_or_else(|| {
                                ReadError::malformed(
                                    at,
                                    format!("face {}: bad vertex index {}", b.faces, show(t)),
                                )
                            })?;
                            b.push_index(i, at)?;
                        }
                        Ok(())
                    });
                    if let Err(e) = items {
                        // A list that claims more items than the rest of the data can
                        // hold (each needs at least two bytes, "0 ") is that error
                        // rather than one of its items'. Its items are read as they
                        // arrive, so the rest is measured only when one fails: a list
                        // whose items all are there cannot claim too many.
                        let rest = tok.offset() + tok.count_rest()? - start;
                        if n as u64 > rest.div_ceil(2) {
                            return Err(ReadError::truncated(
                                line,
                                format!(
                                    "in {} {r}: its list claims {n} items, more than the rest \
                                     of the file can hold",
                                    el.name.escape_ascii()
                                ),
                            ));
                        }
                        return Err(e);
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

/// The next ascii token and its line, or a truncation error naming how many records
/// were complete.
fn next_token<'t>(
    tok: &'t mut TextStream<'_, '_>,
    done: usize,
    count: usize,
    what: &str,
) -> Result<(&'t [u8], usize), ReadError> {
    let line = tok.line();
    tok.next_token()?.ok_or_else(|| {
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
    input: &mut Input<'_>,
    reading: &Reading,
    big: bool,
    b: &mut Builder<'_, '_>,
) -> Result<(), ReadError> {
    let fixed: Option<usize> = reading
        .el
        .props
        .iter()
        .try_fold(0usize, |acc, (_, p)| match p {
            Prop::Scalar(t) => Some(acc + t.size()),
            Prop::List(..) => None,
        });
    match fixed {
        Some(stride) => read_fixed(input, reading, stride, big, b),
        None => read_variable(input, reading, big, b),
    }
}

/// Reads an element whose records all take `stride` bytes, a window of whole records
/// at a time.
///
/// The whole element must be in the data before any of its records is reported on (an
/// element that does not fit is an error that names how many of its records do): a
/// record's error is given only once the rest of the element is found to be there.
fn read_fixed(
    input: &mut Input<'_>,
    reading: &Reading,
    stride: usize,
    big: bool,
    b: &mut Builder<'_, '_>,
) -> Result<(), ReadError> {
    let Reading { el, roles, side } = *reading;
    let start = input.offset();
    let total = stride as u64 * el.count as u64;
    let short = |end: u64| {
        let fits = (end - start) / stride.max(1) as u64;
        ReadError::truncated(
            Location::Byte(start + fits * stride as u64),
            format!(
                "after {fits} of {} {} (binary PLY)",
                el.count,
                plural(el.name)
            ),
        )
    };
    if roles.iter().all(|r| matches!(r, Role::Skip)) {
        let there = input.skip(total)?;
        return if there < total {
            Err(short(start + there))
        } else {
            Ok(())
        };
    }
    // Each value takes at least a byte of its record.
    let room = capacity_for(el.count, input.could_hold(), stride);
    if roles.iter().any(|r| matches!(r, Role::Coord(_))) {
        b.positions.reserve(room);
    }
    if !b.triangles.is_streamed() {
        for v in b.values(side) {
            v.data.reserve(room * v.dimension);
        }
    }
    let mut r = 0;
    while r < el.count {
        if b.triangles.has_failed() {
            return Err(Triangles::stopped());
        }
        input.fill(stride)?;
        let window = input.window();
        let n = (window.len() / stride).min(el.count - r);
        if n == 0 {
            // The data ends inside record r.
            return Err(short(start + (r * stride) as u64));
        }
        let mut cur = Cursor {
            data: &window[..n * stride],
            pos: 0,
            base: input.offset(),
            big,
        };
        if let Err(e) = (r..r + n).try_for_each(|i| read_record(&mut cur, reading, i, b)) {
            let rest = start + total - input.offset();
            let there = input.skip(rest)?;
            return Err(if there < rest {
                short(input.offset())
            } else {
                e
            });
        }
        input.consume(n * stride);
        r += n;
    }
    Ok(())
}

/// Reads an element with list properties, a window of whole records at a time; at the
/// end of the data, the window is all that is left, and reading an incomplete record
/// from it gives the error that says what is missing.
fn read_variable(
    input: &mut Input<'_>,
    reading: &Reading,
    big: bool,
    b: &mut Builder<'_, '_>,
) -> Result<(), ReadError> {
    let el = reading.el;
    if reading.roles.iter().any(|r| matches!(r, Role::Indices)) {
        // At least 1 + 3 bytes per face: never reserve past the data.
        b.triangles
            .reserve(capacity_for(el.count, input.could_hold(), 4));
    }
    let mut r = 0;
    while r < el.count {
        if b.triangles.has_failed() {
            return Err(Triangles::stopped());
        }
        let window = input.window();
        let (mut n, mut len) = whole_records(window, &el.props, big, el.count - r);
        if n == 0 {
            if !input.at_end() {
                let want = window.len() + 1;
                input.fill(want)?;
                continue;
            }
            (n, len) = (1, window.len());
        }
        let mut cur = Cursor {
            data: &window[..len],
            pos: 0,
            base: input.offset(),
            big,
        };
        (r..r + n).try_for_each(|i| read_record(&mut cur, reading, i, b))?;
        input.consume(len);
        r += n;
    }
    Ok(())
}

/// How many whole records of an element with `props` start `data` (at most `max`),
/// and how many bytes they take. A record with a negative list length counts as whole
/// up to that length, where its reading stops with an error.
fn whole_records(data: &[u8], props: &[(&[u8], Prop)], big: bool, max: usize) -> (usize, usize) {
    let (mut n, mut len) = (0, 0);
    while n < max {
        let mut cur = Cursor {
            data,
            pos: len,
            base: 0,
            big,
        };
        for &(_, prop) in props {
            match prop {
                Prop::Scalar(ty) => cur.pos += ty.size(),
                Prop::List(ct, it) => {
                    let Some(count) = cur.int(ct) else {
                        return (n, len);
                    };
                    let Ok(count) = usize::try_from(count) else {
                        return (n + 1, cur.pos);
                    };
                    cur.pos = cur.pos.saturating_add(count.saturating_mul(it.size()));
                }
            }
            if cur.pos > data.len() {
                return (n, len);
            }
        }
        (n, len) = (n + 1, cur.pos);
    }
    (n, len)
}

/// Reads record `r` of an element from `cur`, which holds it whole unless the data
/// ends inside it.
fn read_record(
    cur: &mut Cursor,
    reading: &Reading,
    r: usize,
    b: &mut Builder<'_, '_>,
) -> Result<(), ReadError> {
    let Reading { el, roles, side } = *reading;
    let truncated = |cur: &Cursor| {
        ReadError::truncated(
            cur.at(),
            format!("after {r} of {} {} (binary PLY)", el.count, plural(el.name)),
        )
    };
    let record_at = cur.at();
    b.start_record(side);
    let mut p = [0.0; 3];
    let mut is_vertex = false;
    for (&(name, prop), &role) in el.props.iter().zip(roles) {
        match (prop, role) {
            (Prop::Scalar(ty), Role::Coord(k)) => {
                p[k] = cur.scalar(ty).ok_or_else(|| truncated(cur))?;
                is_vertex = true;
            }
            (
                Prop::Scalar(ty),
                Role::Value {
                    channel,
                    component,
                    convert,
                },
            ) => {
                let at = cur.at();
                let raw = cur.scalar(ty).ok_or_else(|| truncated(cur))?;
                let value = match convert {
                    Convert::Float => raw as f32,
                    Convert::Level(max) => from_level(raw, max),
                };
                b.store(
                    side,
                    (channel, component),
                    value,
                    (el.name, r, name),
                    || format!("{raw:e}"),
                    at,
                )?;
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
    Ok(())
}

/// Where the writer puts a channel.
pub(crate) enum Placement {
    /// On the vertex element (per vertex, after splitting at seams), as these
    /// properties.
    Vertex(Vec<String>),
    /// On the face element (a face colour), as these properties.
    Face(Vec<String>),
    /// Left out, and why.
    Left(&'static str),
}

/// Where [`write()`] puts each of `channels`: the first texture coordinates as `s t`, the
/// first normals as `nx ny nz`, the first colour with one value per triangle as the
/// faces' `red green blue [alpha]` and the first other colour as the vertices' (of two
/// colours that both have one value per triangle, the first goes on the vertices:
/// `channels::colours_on_faces`), generic channels under their names (`<name>_0`, `<name>_1`... for vectors), at most
/// [`MAX_CHANNELS`] in all (what the reader reads back).
pub(crate) fn placements(channels: &[Channel]) -> Vec<Placement> {
    let mut used: Vec<String> = Vec::new();
    let mut kinds: Vec<(ChannelKind, bool)> = Vec::new();
    let mut count = 0;
    let colour = |dimension: usize| -> Vec<String> {
        ["red", "green", "blue", "alpha"][..dimension.min(4)]
            .iter()
            .map(|s| s.to_string())
            .collect()
    };
    channels
        .iter()
        .zip(colours_on_faces(channels))
        .map(|(c, on_face)| {
            let taken = kinds.contains(&(c.kind, on_face));
            let placement = match c.kind {
                _ if count >= MAX_CHANNELS => {
                    Placement::Left("qem reads at most 16 channels from a PLY file")
                }
                ChannelKind::TexCoord | ChannelKind::Normal if taken => {
                    Placement::Left("PLY holds one texture coordinate and one normal per vertex")
                }
                ChannelKind::Color if taken => {
                    Placement::Left("PLY holds one vertex colour and one face colour")
                }
                ChannelKind::TexCoord => Placement::Vertex(vec!["s".into(), "t".into()]),
                ChannelKind::Normal => {
                    Placement::Vertex(vec!["nx".into(), "ny".into(), "nz".into()])
                }
                ChannelKind::Color if on_face => Placement::Face(colour(c.dimension)),
                ChannelKind::Color => Placement::Vertex(colour(c.dimension)),
                ChannelKind::Generic => {
                    let names = generic_property_names(&c.name, c.dimension);
                    if !is_writable_name(c.name.as_bytes()) {
                        Placement::Left("a PLY property name cannot be empty or hold spaces")
                    } else if names.iter().any(|n| is_reserved(n.as_bytes())) {
                        Placement::Left("PLY readers give this property name another meaning")
                    } else if names.iter().any(|n| used.contains(n)) {
                        Placement::Left("another channel has the same PLY property names")
                    } else {
                        used.extend(names.iter().cloned());
                        Placement::Vertex(names)
                    }
                }
            };
            if !matches!(placement, Placement::Left(_)) {
                count += 1;
                kinds.push((c.kind, on_face));
            }
            placement
        })
        .collect()
}

/// A property type the writer uses for a channel.
fn property_type(c: &Channel) -> (&'static str, usize) {
    if c.kind == ChannelKind::Color && all_levels(&c.values) {
        ("uchar", 1)
    } else {
        ("float", 4)
    }
}

/// Appends one value of `c` (`None`: zeros) in the writer's type.
fn push_value(out: &mut Vec<u8>, c: &Channel, value: Option<&[f32]>) {
    let uchar = property_type(c).1 == 1;
    for k in 0..c.dimension {
        let v = value.map_or(0.0, |v| v[k]);
        if uchar {
            out.push(to_level(v));
        } else {
            out.extend_from_slice(&v.to_le_bytes());
        }
    }
}

pub(crate) fn write(
    out: &mut impl Write,
    mesh: &IndexedMesh,
    comments: &[String],
) -> std::io::Result<()> {
    let placements = placements(&mesh.attributes.channels);
    let mut vertex_names = Vec::new();
    let mut vertex_channels = Vec::new();
    let mut face = None;
    for (c, p) in mesh.attributes.channels.iter().zip(&placements) {
        match p {
            Placement::Vertex(names) => {
                vertex_names.push(names);
                vertex_channels.push(c.clone());
            }
            Placement::Face(names) => face = Some((c, names)),
            Placement::Left(_) => {}
        }
    }
    let split = per_vertex(mesh, vertex_channels);
    let vertex = &split.channels;
    let mut header = "ply\nformat binary_little_endian 1.0\ncomment written by qem\n".to_string();
    for c in comments {
        header += &format!("comment {}\n", super::one_line(c));
    }
    header += &format!(
        "element vertex {}\nproperty double x\nproperty double y\nproperty double z\n",
        split.positions.len()
    );
    for (c, names) in vertex.iter().zip(&vertex_names) {
        for name in names.iter() {
            header += &format!("property {} {name}\n", property_type(c).0);
        }
    }
    header += &format!(
        "element face {}\nproperty list uchar int vertex_indices\n",
        split.triangles.len()
    );
    if let Some((c, names)) = face {
        for name in names {
            header += &format!("property {} {name}\n", property_type(c).0);
        }
    }
    header += "end_header\n";
    out.write_all(header.as_bytes())?;
    let mut rec = Vec::new();
    for (v, p) in split.positions.iter().enumerate() {
        rec.clear();
        for c in p {
            rec.extend_from_slice(&c.to_le_bytes());
        }
        for c in vertex {
            // Per vertex after the split: value v is vertex v's.
            push_value(&mut rec, c, Some(c.value(v as u32)));
        }
        out.write_all(&rec)?;
    }
    for (t, tri) in split.triangles.iter().enumerate() {
        rec.clear();
        rec.push(3);
        for &i in tri {
            // Indices are < 2^31 in any mesh qem accepts (MAX_ELEMENTS = 2^28).
            rec.extend_from_slice(&i.to_le_bytes());
        }
        if let Some((c, _)) = face {
            // The split keeps triangle order, so triangle t is the mesh's triangle t.
            push_value(&mut rec, c, c.at_corner(t, 0));
        }
        out.write_all(&rec)?;
    }
    Ok(())
}
