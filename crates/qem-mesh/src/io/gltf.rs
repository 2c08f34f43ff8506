//! glTF 2.0: `.gltf` (JSON, with its buffers in `data:` URIs or in files beside it) and
//! `.glb` (the binary container: a JSON chunk and a BIN chunk).
//!
//! # Reading
//! The JSON is parsed and validated by the `gltf` crate's document types; the GLB
//! container, the buffers and the accessors are read here, so that every size the file
//! claims is checked against the bytes that are there before anything is allocated.
//!
//! - **What is read.** Every primitive of every mesh that a node of the default scene
//!   (else the first scene; else every node without a parent; else every mesh once)
//!   places, with the node's world transform applied to positions (computed in `f64`)
//!   and its inverse transpose to normals, as one mesh. A node whose transform mirrors
//!   (negative determinant) has its triangles' winding reversed, as glTF renders them,
//!   so their orientation is kept. A mesh placed by two nodes gives two copies.
//! - **Modes.** `TRIANGLES`, `TRIANGLE_STRIP` and `TRIANGLE_FAN` (strips and fans are
//!   converted to triangles with glTF's winding); points and lines are skipped and
//!   counted in [`ReadNotes::skipped_primitives`].
//! - **Attributes.** `TEXCOORD_0` becomes the texture coordinate channel `uv`,
//!   `NORMAL` the normal channel, `COLOR_0` (vec3 or vec4) the colour channel; further
//!   sets become `uv1`, `colour1`... in the order of their numbers (a file that skips
//!   a number, which the specification forbids, has its sets named as if it did not,
//!   as the writer numbers them); application-specific attributes `_NAME` (scalar
//!   to vec4) become generic channels named `NAME`. Any component type is read, with
//!   `normalized` integers mapped to 0–1 or −1–1. `TANGENT`, `JOINTS_n` and
//!   `WEIGHTS_n` are skipped and counted in [`ReadNotes::skipped_properties`] (tangents
//!   and skin weights do not survive simplification as they are). Primitives that
//!   share their vertex accessors (within one node) share their vertices. A primitive
//!   without an attribute that others have has [`Channel::MISSING`] corners in it.
//! - **Texture coordinates** are kept in qem's (and OBJ's) convention, with the origin
//!   at the bottom left of the image; glTF puts it at the top left, so `v` is flipped
//!   (`1 - v`) on reading and on writing. Values from a glTF file survive a round trip
//!   through qem bit for bit; values below 0.5 from another format may move by up to
//!   half a unit in the last place of 1.0 (about 6e-8) on their first trip.
//! - **Labels.** Each primitive's faces get its material's name as their material
//!   label (`material N` for a material without a name, none for a primitive without
//!   a material); each mesh's faces get the mesh's name as their group (none when the
//!   mesh has no name).
//! - **Refused, with an error naming the reason:** sparse accessors; a required
//!   extension that changes the geometry (`KHR_draco_mesh_compression`,
//!   `EXT_meshopt_compression`, any unknown one; material, texture and light
//!   extensions and `KHR_mesh_quantization` are fine); node graphs that are not trees;
//!   external buffer files when reading from memory ([`super::read_bytes`] cannot
//!   resolve them; [`super::read_path`] reads them relative to the `.gltf` file, and
//!   refuses absolute paths and URLs); a buffer that holds less than its
//!   `byteLength` (a `data:` URI's length is checked before it is decoded, and a
//!   buffer file is read no further than the declared length, so a size the file only
//!   claims is never allocated); accessors, buffer views and indices that reach past
//!   what is there; a NaN or infinite value in a float accessor, naming the accessor
//!   and the element (positions, normals, texture coordinates and colours alike).
//! - **Lenient:** a `POSITION` accessor without the `min`/`max` the specification asks
//!   for is accepted (qem does not use them).
//!
//! # Writing
//! One buffer (a BIN chunk in `.glb`, a base64 `data:` URI in `.gltf`, so either is one
//! self-contained file); the mesh split at its seams
//! ([`split_at_seams`](crate::attributes::split_at_seams)) so every channel is per
//! vertex; positions as `float32` (qem's are `f64`: a coordinate is rounded to the
//! nearest `float32`, about 7 significant digits, and one beyond `float32`'s range is
//! an `InvalidInput` error); the first normal channel as `NORMAL`, texture coordinate
//! channels as `TEXCOORD_0`, `TEXCOORD_1`..., colours as `COLOR_0`... (`float32`), and
//! generic channels as `_NAME`; one glTF mesh per group (named after it) and within
//! it one primitive per material and set of channels present (faces without a value
//! in a channel get a primitive without that attribute, so they read back without
//! one), with `u32` indices; every vertex accessor is shared by all primitives. A
//! face with a value at some corners only has zeros at the others. The materials are written as glTF materials carrying only their
//! names. Names that are not UTF-8 are written with U+FFFD in place of invalid bytes.
//!
//! # What is not carried through
//! Only the geometry, the attributes above and the names of materials and meshes are
//! read: textures, images, samplers, PBR parameters, the node hierarchy (it is
//! flattened into world-space positions), cameras, lights, skins, morph targets and
//! animations are not kept, and the writer therefore cannot write them back. Writing
//! a mesh read from glTF gives a file with the same geometry, channels and material
//! names but default (white, PBR metallic-roughness) materials without textures.
//! Keeping them would need the source document inside the mesh; that is not done.

use std::collections::{BTreeMap, HashMap, HashSet};
use std::io::{self, Write};

use glam::{DMat3, DMat4, DQuat, DVec3};
use gltf::json::accessor::{ComponentType, GenericComponentType, Type};
use gltf::json::mesh::{Mode, Semantic};
use gltf::json::validation::{Checked, Validate};
use gltf::json::{self, Root};

use super::channels::per_vertex;
use super::{sniff, Format, Location, ReadError, ReadErrorKind, ReadNotes};
use crate::attributes::{Attributes, Channel, ChannelKind, FaceLabels};
use crate::{IndexedMesh, MAX_ELEMENTS};

/// Opens an external buffer for [`read`]: given its URI (percent-decoded, a relative
/// path) and the byte count the glTF declares, gives at most that many bytes (fewer
/// when the file is shorter, which [`read`] reports with the buffer's index).
pub(crate) type External<'a> = &'a dyn Fn(&str, usize) -> std::io::Result<Vec<u8>>;

/// The GLB magic, chunk types and the header sizes.
const GLB_MAGIC: &[u8; 4] = b"glTF";
const CHUNK_JSON: u32 = 0x4E4F_534A;
const CHUNK_BIN: u32 = 0x004E_4942;
const GLB_HEADER: usize = 12;
const CHUNK_HEADER: usize = 8;

/// Required extensions that change how the geometry is stored, which qem cannot decode.
const COMPRESSION: [&str; 3] = [
    "KHR_draco_mesh_compression",
    "EXT_meshopt_compression",
    "KHR_meshopt_compression",
];

/// Whether a required extension leaves the geometry as qem reads it: material,
/// texture and light extensions only add what qem does not read, and
/// `KHR_mesh_quantization` only allows integer component types, which are read.
fn harmless(extension: &str) -> bool {
    [
        "KHR_materials_",
        "KHR_texture_",
        "EXT_texture_",
        "MSFT_texture_",
    ]
    .iter()
    .any(|p| extension.starts_with(p))
        || ["KHR_lights_punctual", "KHR_mesh_quantization"].contains(&extension)
}

fn malformed(detail: impl Into<String>) -> ReadError {
    ReadError::new(
        ReadErrorKind::Malformed {
            detail: detail.into(),
        },
        None,
    )
}

fn too_large(what: &str, count: u64) -> ReadError {
    ReadError::new(
        ReadErrorKind::TooLarge {
            what: what.to_string(),
            count,
            limit: MAX_ELEMENTS as u64,
        },
        None,
    )
}

fn u32_at(bytes: &[u8], at: usize) -> Option<u32> {
    let b = bytes.get(at..at.checked_add(4)?)?;
    Some(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
}

/// The JSON and BIN chunks of a GLB file. Chunks of unknown types are skipped, as the
/// specification asks.
fn split_glb(bytes: &[u8]) -> Result<(&[u8], Option<&[u8]>), ReadError> {
    let at = |n: usize| Some(Location::Byte(n as u64));
    if bytes.len() < GLB_HEADER {
        return Err(ReadError::truncated(
            Location::Byte(bytes.len() as u64),
            format!("in the {GLB_HEADER}-byte GLB header"),
        ));
    }
    let version = u32_at(bytes, 4).unwrap_or(0);
    if version != 2 {
        return Err(ReadError::new(
            ReadErrorKind::Malformed {
                detail: format!("GLB version {version}; only glTF 2.0 is read"),
            },
            at(4),
        ));
    }
    let length = u32_at(bytes, 8).unwrap_or(0) as usize;
    if length < GLB_HEADER + CHUNK_HEADER {
        return Err(ReadError::new(
            ReadErrorKind::Malformed {
                detail: format!("GLB length {length} is too small for a JSON chunk"),
            },
            at(8),
        ));
    }
    if length > bytes.len() {
        return Err(ReadError::truncated(
            Location::Byte(bytes.len() as u64),
            format!(
                "after {} of the {length} bytes the GLB header declares",
                bytes.len()
            ),
        ));
    }
    let bytes = &bytes[..length];
    let mut json = None;
    let mut bin = None;
    let mut offset = GLB_HEADER;
    while offset < length {
        let (Some(size), Some(kind)) = (u32_at(bytes, offset), u32_at(bytes, offset + 4)) else {
            return Err(ReadError::truncated(
                Location::Byte(length as u64),
                format!("in the chunk header at byte {offset}"),
            ));
        };
        let start = offset + CHUNK_HEADER;
        let end = start.saturating_add(size as usize);
        let Some(data) = bytes.get(start..end) else {
            return Err(ReadError::truncated(
                Location::Byte(length as u64),
                format!("in the chunk at byte {offset}, which declares {size} bytes"),
            ));
        };
        match kind {
            CHUNK_JSON if json.is_none() => json = Some(data),
            CHUNK_BIN if bin.is_none() => bin = Some(data),
            _ => {}
        }
        if json.is_none() {
            return Err(ReadError::new(
                ReadErrorKind::Malformed {
                    detail: "the first GLB chunk is not JSON".to_string(),
                },
                at(offset),
            ));
        }
        offset = end;
    }
    // The loop ran at least once (length > GLB_HEADER) and refused a first chunk that
    // is not JSON, so `json` is set.
    Ok((json.unwrap_or_default(), bin))
}

/// Parses and validates the JSON document; refuses required extensions qem cannot
/// honour.
fn document(json_text: &[u8]) -> Result<Root, ReadError> {
    let root: Root = serde_json::from_slice(json_text).map_err(|e| {
        let detail = format!("glTF JSON: {e}");
        if e.is_eof() {
            ReadError::new(ReadErrorKind::Truncated { detail }, None)
        } else {
            malformed(detail)
        }
    })?;
    for ext in &root.extensions_required {
        if COMPRESSION.contains(&ext.as_str()) {
            return Err(malformed(format!(
                "the file requires the extension {ext} (compressed geometry), which qem \
                 cannot decode; decompress the file first"
            )));
        }
        if !harmless(ext) {
            return Err(malformed(format!(
                "the file requires the extension {ext}, which qem does not support"
            )));
        }
    }
    // The crate's validation looks up each primitive's POSITION accessor before it
    // checks that the index is in range, so a bad index would panic there.
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, prim) in mesh.primitives.iter().enumerate() {
            if let Some(i) = prim.attributes.get(&Checked::Valid(Semantic::Positions)) {
                if i.value() >= root.accessors.len() {
                    return Err(malformed(format!(
                        "meshes[{m}].primitives[{p}]: POSITION is accessor {}, but there \
                         are {} accessors",
                        i.value(),
                        root.accessors.len()
                    )));
                }
            }
        }
    }
    let mut errors = Vec::new();
    root.validate(&root, json::Path::new, &mut |path, error| {
        let path = path().to_string();
        // Lenient where the geometry is not at stake: POSITION bounds are not used,
        // and required extensions were checked above.
        let bounds =
            path.contains("[\"POSITION\"]") && (path.ends_with(".min") || path.ends_with(".max"));
        let extension = path.starts_with("extensionsRequired");
        if !bounds && !extension {
            errors.push(format!("{path}: {error}"));
        }
    });
    if let Some(first) = errors.first() {
        let more = match errors.len() {
            1 => String::new(),
            n => format!(" (and {} more problems)", n - 1),
        };
        return Err(malformed(format!("invalid glTF: {first}{more}")));
    }
    Ok(root)
}

/// Base64 text without its padding (`=` or `==` at the end).
fn unpadded(text: &[u8]) -> &[u8] {
    text.strip_suffix(b"==")
        .or(text.strip_suffix(b"="))
        .unwrap_or(text)
}

/// How many bytes [`decode_base64`] gives for `text` when it is valid, found without
/// decoding: each character carries 6 bits, and a partial byte at the end is dropped.
fn decoded_len(text: &[u8]) -> usize {
    unpadded(text).len() / 4 * 3 + unpadded(text).len() % 4 * 3 / 4
}

/// Decodes standard or URL-safe base64, with or without padding; `None` on any other
/// byte.
fn decode_base64(text: &[u8]) -> Option<Vec<u8>> {
    let text = unpadded(text);
    let mut out = Vec::with_capacity(decoded_len(text));
    let (mut acc, mut bits) = (0u32, 0u32);
    for &c in text {
        let v = match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' | b'-' => 62,
            b'/' | b'_' => 63,
            _ => return None,
        };
        acc = (acc << 6) | u32::from(v);
        bits += 6;
        if bits >= 8 {
            bits -= 8;
            out.push((acc >> bits) as u8);
            acc &= (1 << bits) - 1;
        }
    }
    Some(out)
}

/// Standard base64 with padding.
fn encode_base64(bytes: &[u8]) -> String {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            *chunk.get(1).unwrap_or(&0),
            *chunk.get(2).unwrap_or(&0),
        ];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(char::from(ALPHABET[((n >> (18 - 6 * k)) & 63) as usize]));
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// A URI's percent escapes decoded (`%20` is a space); a `%` not followed by two hex
/// digits is kept as it is.
fn percent_decode(uri: &str) -> Vec<u8> {
    let b = uri.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        let hex = b
            .get(i + 1..i + 3)
            .and_then(|h| std::str::from_utf8(h).ok())
            .and_then(|h| u8::from_str_radix(h, 16).ok());
        match (b[i], hex) {
            (b'%', Some(v)) => {
                out.push(v);
                i += 3;
            }
            (c, _) => {
                out.push(c);
                i += 1;
            }
        }
    }
    out
}

/// The bytes of every buffer a mesh primitive's accessor uses (`None` for the others,
/// which are never opened), each exactly its declared `byteLength` long.
fn load_buffers(
    root: &Root,
    bin: Option<&[u8]>,
    external: Option<External<'_>>,
) -> Result<Vec<Option<Vec<u8>>>, ReadError> {
    let mut used = vec![false; root.buffers.len()];
    let accessors = root
        .meshes
        .iter()
        .flat_map(|m| &m.primitives)
        .flat_map(|p| p.attributes.values().chain(p.indices.as_ref()));
    for a in accessors {
        let view = root
            .accessors
            .get(a.value())
            .and_then(|a| a.buffer_view)
            .and_then(|v| root.buffer_views.get(v.value()));
        if let Some(slot) = view.and_then(|v| used.get_mut(v.buffer.value())) {
            *slot = true;
        }
    }
    let mut out = Vec::with_capacity(root.buffers.len());
    for (i, buffer) in root.buffers.iter().enumerate() {
        if !used[i] {
            out.push(None);
            continue;
        }
        let declared = usize::try_from(buffer.byte_length.0).unwrap_or(usize::MAX);
        let short = |held: usize| {
            ReadError::new(
                ReadErrorKind::Truncated {
                    detail: format!(
                        "in buffer {i}: it holds {held} bytes, its byteLength says {declared}"
                    ),
                },
                None,
            )
        };
        let data = match buffer.uri.as_deref() {
            None => bin
                .ok_or_else(|| {
                    malformed(format!(
                        "buffer {i} has no uri, and there is no GLB BIN chunk to hold it"
                    ))
                })?
                .to_vec(),
            Some(uri) if uri.starts_with("data:") => {
                let (header, payload) = uri.split_once(',').unwrap_or((uri, ""));
                if !header.ends_with(";base64") {
                    return Err(malformed(format!(
                        "buffer {i}: a data URI that is not base64 ({header:?})"
                    )));
                }
                // Refused before decoding when the text is too short for the declared
                // length, so a short URI that claims 10^9 bytes costs nothing.
                let held = decoded_len(payload.as_bytes());
                if held < declared {
                    return Err(short(held));
                }
                decode_base64(payload.as_bytes()).ok_or_else(|| {
                    malformed(format!("buffer {i}: the data URI is not valid base64"))
                })?
            }
            Some(uri) => {
                let Some(open) = external else {
                    return Err(malformed(format!(
                        "buffer {i} is in the external file {uri:?}, which cannot be \
                         resolved from memory: read the .gltf file by its path"
                    )));
                };
                let path = String::from_utf8(percent_decode(uri))
                    .map_err(|_| malformed(format!("buffer {i}: the URI {uri:?} is not UTF-8")))?;
                // A relative reference only: a scheme (`http:`, `file:`, a drive letter)
                // or an absolute path would reach outside the asset's own files.
                let scheme = path
                    .find(':')
                    .is_some_and(|c| !path[..c].contains(['/', '\\']));
                if scheme || path.starts_with(['/', '\\']) {
                    return Err(malformed(format!(
                        "buffer {i}: the URI {uri:?} is not a relative file path"
                    )));
                }
                open(&path, declared).map_err(|e| {
                    ReadError::new(
                        ReadErrorKind::BufferFile {
                            buffer: i,
                            uri: path.clone(),
                            detail: e.to_string(),
                        },
                        None,
                    )
                })?
            }
        };
        if data.len() < declared {
            return Err(short(data.len()));
        }
        let mut data = data;
        data.truncate(declared);
        out.push(Some(data));
    }
    Ok(out)
}

/// An accessor's elements, checked to lie within its buffer view and buffer.
struct Elements<'b> {
    /// The accessor for messages: `accessor 3 (NORMAL of mesh 0 primitive 1)`.
    name: String,
    /// From the first element's first byte to the last element's last byte.
    data: &'b [u8],
    count: usize,
    stride: usize,
    components: usize,
    component: ComponentType,
    normalized: bool,
}

fn component_size(c: ComponentType) -> usize {
    match c {
        ComponentType::I8 | ComponentType::U8 => 1,
        ComponentType::I16 | ComponentType::U16 => 2,
        ComponentType::U32 | ComponentType::F32 => 4,
    }
}

/// The elements of accessor `index`, for `what` (as the error messages say it).
/// Every offset and length is checked against the bytes present, so a bogus count
/// cannot make the caller allocate more than the buffer can hold.
fn elements<'b>(
    root: &Root,
    buffers: &'b [Option<Vec<u8>>],
    index: json::Index<json::Accessor>,
    what: &str,
) -> Result<Elements<'b>, ReadError> {
    let i = index.value();
    let problem = |detail: String| malformed(format!("accessor {i} ({what}): {detail}"));
    let accessor = root
        .accessors
        .get(i)
        .ok_or_else(|| problem("no such accessor".to_string()))?;
    if accessor.sparse.is_some() {
        return Err(problem("sparse accessors are not supported".to_string()));
    }
    let components = match accessor.type_ {
        Checked::Valid(Type::Scalar) => 1,
        Checked::Valid(Type::Vec2) => 2,
        Checked::Valid(Type::Vec3) => 3,
        Checked::Valid(Type::Vec4) => 4,
        _ => {
            return Err(problem(
                "matrix accessors are not vertex data qem reads".into(),
            ))
        }
    };
    let Checked::Valid(GenericComponentType(component)) = accessor.component_type else {
        return Err(problem("unknown component type".to_string()));
    };
    let count = accessor.count.0;
    if count > MAX_ELEMENTS as u64 {
        return Err(too_large(&format!("accessor {i} ({what}) elements"), count));
    }
    let view = accessor
        .buffer_view
        .and_then(|v| root.buffer_views.get(v.value()))
        .ok_or_else(|| problem("no buffer view".to_string()))?;
    let buffer = buffers
        .get(view.buffer.value())
        .and_then(Option::as_deref)
        .ok_or_else(|| problem("its buffer was not loaded".to_string()))?;
    let element = components * component_size(component);
    let stride = view.byte_stride.map_or(element, |s| s.0);
    if stride < element {
        return Err(problem(format!(
            "byteStride {stride} is less than the {element} bytes of an element"
        )));
    }
    let view_start = view.byte_offset.map_or(0, |o| o.0);
    let view_end = view_start.checked_add(view.byte_length.0);
    if view_end.is_none_or(|e| e > buffer.len() as u64) {
        return Err(problem(format!(
            "its buffer view ends past the {} bytes of buffer {}",
            buffer.len(),
            view.buffer.value()
        )));
    }
    let start = view_start + accessor.byte_offset.map_or(0, |o| o.0);
    let span = match count {
        0 => Some(0),
        n => (n - 1)
            .checked_mul(stride as u64)
            .and_then(|s| s.checked_add(element as u64)),
    };
    let end = span.and_then(|s| s.checked_add(start));
    // Both ends are within `view_end`, itself within the buffer: the casts are exact.
    let Some(end) = end.filter(|&e| view_end.is_some_and(|v| e <= v)) else {
        return Err(problem(format!(
            "{count} elements of {stride} bytes do not fit in its buffer view"
        )));
    };
    Ok(Elements {
        name: format!("accessor {i} ({what})"),
        data: &buffer[start as usize..end as usize],
        count: count as usize,
        stride,
        components,
        component,
        normalized: accessor.normalized,
    })
}

impl Elements<'_> {
    /// Component `c` of element `k`, raw, as an integer or float bit pattern widened.
    fn raw(&self, k: usize, c: usize) -> u32 {
        let size = component_size(self.component);
        let at = k * self.stride + c * size;
        let mut b = [0u8; 4];
        // In range by construction (`elements` checked the span); a zero is never used.
        if let Some(s) = self.data.get(at..at + size) {
            b[..size].copy_from_slice(s);
        }
        u32::from_le_bytes(b)
    }

    /// All components as floats, `normalized` integers scaled as glTF defines.
    fn floats(&self) -> Vec<f32> {
        let mut out = Vec::with_capacity(self.count * self.components);
        for k in 0..self.count {
            for c in 0..self.components {
                let r = self.raw(k, c);
                let n = self.normalized;
                out.push(match self.component {
                    ComponentType::F32 => f32::from_bits(r),
                    ComponentType::U8 if n => super::channels::from_level(f64::from(r), 255.0),
                    ComponentType::U16 if n => super::channels::from_level(f64::from(r), 65535.0),
                    ComponentType::I8 if n => (f32::from(r as u8 as i8) / 127.0).max(-1.0),
                    ComponentType::I16 if n => (f32::from(r as u16 as i16) / 32767.0).max(-1.0),
                    ComponentType::I8 => f32::from(r as u8 as i8),
                    ComponentType::I16 => f32::from(r as u16 as i16),
                    ComponentType::U8 | ComponentType::U16 | ComponentType::U32 => r as f32,
                });
            }
        }
        out
    }

    /// [`Self::floats`], refusing a value that is not finite (NaN or an infinity in a
    /// float accessor) with the accessor and the element: the mesh's validation would
    /// refuse it too, but could not say where it came from.
    fn finite_floats(&self) -> Result<Vec<f32>, ReadError> {
        let v = self.floats();
        match v.iter().position(|x| !x.is_finite()) {
            Some(k) => Err(malformed(format!(
                "{}: element {} holds {}, not a finite number",
                self.name,
                k / self.components,
                v[k]
            ))),
            None => Ok(v),
        }
    }

    /// The elements as vertex indices (unsigned integer scalars).
    fn indices(&self, what: &str) -> Result<Vec<u32>, ReadError> {
        let unsigned = matches!(
            self.component,
            ComponentType::U8 | ComponentType::U16 | ComponentType::U32
        );
        if self.components != 1 || !unsigned {
            return Err(malformed(format!(
                "{what}: indices must be unsigned integer scalars"
            )));
        }
        Ok((0..self.count).map(|k| self.raw(k, 0)).collect())
    }
}

/// Which channel a glTF attribute feeds, in the order channels are made.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
enum Key {
    TexCoord(u32),
    Normal,
    Color(u32),
    Custom(String),
}

impl Key {
    fn kind(&self) -> ChannelKind {
        match self {
            Key::TexCoord(_) => ChannelKind::TexCoord,
            Key::Normal => ChannelKind::Normal,
            Key::Color(_) => ChannelKind::Color,
            Key::Custom(_) => ChannelKind::Generic,
        }
    }

    /// The channel's name, before making it unique, for the set that is number `rank`
    /// among the file's sets of its kind (`TEXCOORD_1` alone is rank 0).
    ///
    /// Sets are named by rank rather than by their glTF number because the writer
    /// numbers them from 0 without gaps, as the specification requires: naming
    /// `TEXCOORD_1` alone `uv1` would make it `uv` after a round trip.
    fn name(&self, rank: usize) -> String {
        match self {
            Key::TexCoord(_) | Key::Color(_) if rank > 0 => {
                format!("{}{rank}", self.kind().as_str())
            }
            Key::TexCoord(_) | Key::Normal | Key::Color(_) => self.kind().as_str().to_string(),
            Key::Custom(name) => name.clone(),
        }
    }

    /// The attribute's glTF name, for messages.
    fn semantic(&self) -> String {
        match self {
            Key::TexCoord(n) => format!("TEXCOORD_{n}"),
            Key::Normal => "NORMAL".to_string(),
            Key::Color(n) => format!("COLOR_{n}"),
            Key::Custom(name) => format!("_{name}"),
        }
    }

    fn dimensions(&self) -> std::ops::RangeInclusive<usize> {
        match self {
            Key::TexCoord(_) => 2..=2,
            Key::Normal => 3..=3,
            Key::Color(_) => 3..=4,
            Key::Custom(_) => 1..=4,
        }
    }
}

/// A placed mesh: which mesh and its node's world transform.
struct Instance {
    mesh: usize,
    world: DMat4,
}

/// A node's local transform: its matrix, or its translation, rotation and scale.
fn local(node: &json::Node) -> DMat4 {
    if let Some(m) = node.matrix {
        return DMat4::from_cols_array(&m.map(f64::from));
    }
    let t = node.translation.unwrap_or([0.0; 3]).map(f64::from);
    let r = node
        .rotation
        .map_or([0.0, 0.0, 0.0, 1.0], |q| q.0)
        .map(f64::from);
    let s = node.scale.unwrap_or([1.0; 3]).map(f64::from);
    DMat4::from_scale_rotation_translation(
        DVec3::from(s),
        DQuat::from_xyzw(r[0], r[1], r[2], r[3]).normalize(),
        DVec3::from(t),
    )
}

/// The meshes the scene places, in depth-first order from its root nodes.
fn instances(root: &Root) -> Result<Vec<Instance>, ReadError> {
    let n = root.nodes.len();
    // Each node has at most one parent and scene roots have none (glTF's rule that
    // nodes form disjoint trees): then a walk from the roots visits each node once,
    // and a cycle, which needs a second parent somewhere, cannot be reached.
    let mut parent: Vec<Option<usize>> = vec![None; n];
    for (p, node) in root.nodes.iter().enumerate() {
        for c in node.children.iter().flatten().map(|c| c.value()) {
            match parent.get(c) {
                Some(Some(q)) => {
                    return Err(malformed(format!(
                        "node {c} is a child of both node {q} and node {p}: glTF nodes \
                         form trees"
                    )))
                }
                Some(None) => parent[c] = Some(p),
                None => return Err(malformed(format!("node {p}: no child node {c}"))),
            }
        }
    }
    let scene = root
        .scene
        .and_then(|s| root.scenes.get(s.value()))
        .or(root.scenes.first());
    let roots: Vec<usize> = match scene {
        Some(scene) => scene.nodes.iter().map(|r| r.value()).collect(),
        None if n > 0 => (0..n).filter(|&i| parent[i].is_none()).collect(),
        None => {
            return Ok((0..root.meshes.len())
                .map(|mesh| Instance {
                    mesh,
                    world: DMat4::IDENTITY,
                })
                .collect())
        }
    };
    let mut seen = vec![false; n];
    let mut out = Vec::new();
    let mut stack = Vec::new();
    for &r in roots.iter().rev() {
        match (seen.get(r), parent.get(r)) {
            (None, _) => return Err(malformed(format!("the scene has no node {r}"))),
            (Some(true), _) => return Err(malformed(format!("node {r} is a scene root twice"))),
            (_, Some(Some(p))) => {
                return Err(malformed(format!(
                    "scene root node {r} is also a child of node {p}"
                )))
            }
            _ => seen[r] = true,
        }
        stack.push((r, DMat4::IDENTITY));
    }
    // Roots were pushed in reverse, so they are visited in the scene's order.
    while let Some((i, above)) = stack.pop() {
        let node = &root.nodes[i];
        let world = above * local(node);
        if let Some(mesh) = node.mesh {
            out.push(Instance {
                mesh: mesh.value(),
                world,
            });
        }
        for c in node.children.iter().flatten().rev() {
            stack.push((c.value(), world));
        }
    }
    Ok(out)
}

/// One attribute of a block's vertices.
struct Values {
    /// The accessor it was read from.
    accessor: usize,
    dimension: usize,
    values: Vec<f32>,
}

/// Vertices as one primitive (or several sharing accessors) gave them.
struct Block {
    positions: Vec<[f64; 3]>,
    values: BTreeMap<Key, Values>,
}

/// Triangles of one primitive, indices local to a block.
struct Run {
    block: usize,
    /// The attributes the primitive has; its corners are missing in the others.
    keys: Vec<Key>,
    triangles: Vec<[u32; 3]>,
    material: u32,
    group: u32,
}

/// Label numbers by name, in order of first use.
#[derive(Default)]
struct Labels {
    names: Vec<Vec<u8>>,
    by_name: HashMap<Vec<u8>, u32>,
}

impl Labels {
    fn label(&mut self, name: Vec<u8>) -> u32 {
        let next = self.names.len() as u32;
        *self.by_name.entry(name.clone()).or_insert_with(|| {
            self.names.push(name);
            next
        })
    }

    fn into_face_labels(self, faces: Vec<u32>) -> FaceLabels {
        if faces.iter().all(|&f| f == FaceLabels::NONE) {
            return FaceLabels::default();
        }
        FaceLabels {
            names: self.names,
            faces,
        }
    }
}

/// Converts a primitive's index list to triangles as its mode defines them.
fn triangles(mode: Mode, idx: &[u32], what: &str) -> Result<Vec<[u32; 3]>, ReadError> {
    let n = idx.len();
    Ok(match mode {
        Mode::TriangleStrip => (0..n.saturating_sub(2))
            .map(|i| match i % 2 {
                0 => [idx[i], idx[i + 1], idx[i + 2]],
                _ => [idx[i], idx[i + 2], idx[i + 1]],
            })
            .collect(),
        Mode::TriangleFan => (1..n.saturating_sub(1))
            .map(|i| [idx[i], idx[i + 1], idx[0]])
            .collect(),
        _ if n % 3 != 0 => {
            return Err(malformed(format!(
                "{what}: {n} indices are not a whole number of triangles"
            )))
        }
        _ => idx.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect(),
    })
}

/// Reads glTF or GLB data (`format` only names what was claimed, in errors; the
/// content decides which container it is). `external` opens buffer files.
pub(crate) fn read(
    bytes: &[u8],
    format: Format,
    external: Option<External<'_>>,
    notes: &mut ReadNotes,
) -> Result<IndexedMesh, ReadError> {
    let (json_text, bin) = if bytes.starts_with(GLB_MAGIC) {
        split_glb(bytes)?
    } else if bytes.iter().find(|b| !b.is_ascii_whitespace()) == Some(&b'{') {
        (bytes, None)
    } else {
        return Err(ReadError::not_this_format(
            format,
            sniff(bytes),
            "neither glTF JSON (\"{...\") nor binary glTF (\"glTF\" magic bytes)",
        ));
    };
    let root = document(json_text)?;
    let buffers = load_buffers(&root, bin, external)?;

    let mut blocks: Vec<Block> = Vec::new();
    // The blocks of each placement and POSITION accessor, which primitives share.
    let mut by_position: HashMap<(usize, usize), Vec<usize>> = HashMap::new();
    let mut runs: Vec<Run> = Vec::new();
    let mut materials = Labels::default();
    let mut groups = Labels::default();
    let (mut vertex_total, mut triangle_total) = (0u64, 0u64);
    for (instance, placed) in instances(&root)?.into_iter().enumerate() {
        let Some(mesh) = root.meshes.get(placed.mesh) else {
            return Err(malformed(format!(
                "a node places mesh {}, which does not exist",
                placed.mesh
            )));
        };
        let linear = DMat3::from_mat4(placed.world);
        let det = linear.determinant();
        // A singular transform flattens the mesh; its normals are then left as they are.
        let normal_matrix = if det != 0.0 && det.is_finite() {
            linear.inverse().transpose()
        } else {
            DMat3::IDENTITY
        };
        let group = match &mesh.name {
            Some(name) => groups.label(name.as_bytes().to_vec()),
            None => FaceLabels::NONE,
        };
        for (p, prim) in mesh.primitives.iter().enumerate() {
            let what = format!("mesh {} primitive {p}", placed.mesh);
            let mode = match prim.mode {
                Checked::Valid(m @ (Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan)) => {
                    m
                }
                _ => {
                    notes.skipped_primitives += 1;
                    continue;
                }
            };
            let Some(&position) = prim.attributes.get(&Checked::Valid(Semantic::Positions)) else {
                notes.skipped_primitives += 1;
                continue;
            };
            let mut keys = Vec::new();
            for (semantic, &accessor) in &prim.attributes {
                let key = match semantic {
                    Checked::Valid(Semantic::Normals) => Key::Normal,
                    Checked::Valid(Semantic::TexCoords(n)) => Key::TexCoord(*n),
                    Checked::Valid(Semantic::Colors(n)) => Key::Color(*n),
                    Checked::Valid(Semantic::Extras(name)) => Key::Custom(name.clone()),
                    Checked::Valid(Semantic::Positions) => continue,
                    _ => {
                        notes.skipped_properties += 1;
                        continue;
                    }
                };
                keys.push((key, accessor));
            }
            // A block of this placement and POSITION accessor whose attributes come
            // from the same accessors as this primitive's (it may lack some, which
            // are then added): primitives that share accessors share vertices.
            let candidates = by_position.entry((instance, position.value())).or_default();
            let compatible = candidates.iter().copied().find(|&b| {
                keys.iter().all(|(k, a)| {
                    blocks[b]
                        .values
                        .get(k)
                        .is_none_or(|v| v.accessor == a.value())
                })
            });
            let block = match compatible {
                Some(b) => b,
                None => {
                    let positions = read_positions(&root, &buffers, position, &placed, &what)?;
                    vertex_total += positions.len() as u64;
                    if vertex_total > MAX_ELEMENTS as u64 {
                        return Err(too_large("vertices", vertex_total));
                    }
                    blocks.push(Block {
                        positions,
                        values: BTreeMap::new(),
                    });
                    candidates.push(blocks.len() - 1);
                    blocks.len() - 1
                }
            };
            let vertices = blocks[block].positions.len();
            let mut run_keys = Vec::with_capacity(keys.len());
            for (key, accessor) in keys {
                if !blocks[block].values.contains_key(&key) {
                    let Some(values) =
                        read_attribute(&root, &buffers, &key, accessor, normal_matrix, &what)?
                    else {
                        notes.skipped_properties += 1;
                        continue;
                    };
                    if values.values.len() != vertices * values.dimension {
                        return Err(malformed(format!(
                            "{what}: {} has {} elements, POSITION has {vertices}",
                            key.semantic(),
                            values.values.len() / values.dimension
                        )));
                    }
                    blocks[block].values.insert(key.clone(), values);
                }
                run_keys.push(key);
            }
            let indices = match prim.indices {
                Some(i) => {
                    elements(&root, &buffers, i, &format!("indices of {what}"))?.indices(&what)?
                }
                None => (0..vertices as u32).collect(),
            };
            if let Some(&bad) = indices.iter().find(|&&i| i as usize >= vertices) {
                return Err(malformed(format!(
                    "{what}: index {bad}, but POSITION has {vertices} elements"
                )));
            }
            let mut tris = triangles(mode, &indices, &what)?;
            if det < 0.0 {
                for t in &mut tris {
                    t.swap(1, 2);
                }
            }
            triangle_total += tris.len() as u64;
            if triangle_total > MAX_ELEMENTS as u64 {
                return Err(too_large("triangles", triangle_total));
            }
            let material = match prim.material {
                Some(m) => {
                    let name = root.materials.get(m.value()).and_then(|m| m.name.clone());
                    materials.label(
                        name.unwrap_or_else(|| format!("material {}", m.value()))
                            .into_bytes(),
                    )
                }
                None => FaceLabels::NONE,
            };
            runs.push(Run {
                block,
                keys: run_keys,
                triangles: tris,
                material,
                group,
            });
        }
    }
    Ok(assemble(blocks, runs, materials, groups))
}

/// The positions of accessor `index`, placed by `placed`'s transform.
fn read_positions(
    root: &Root,
    buffers: &[Option<Vec<u8>>],
    index: json::Index<json::Accessor>,
    placed: &Instance,
    what: &str,
) -> Result<Vec<[f64; 3]>, ReadError> {
    let pos = elements(root, buffers, index, &format!("POSITION of {what}"))?;
    if pos.components != 3 {
        return Err(malformed(format!("{what}: POSITION must be VEC3")));
    }
    let mut positions = Vec::with_capacity(pos.count);
    // Untransformed positions are kept as they are: the identity's arithmetic turns
    // -0.0 into 0.0, and a round trip through glTF would then not be bit for bit.
    let identity = placed.world == DMat4::IDENTITY;
    for (v, c) in pos.finite_floats()?.chunks_exact(3).enumerate() {
        let c = DVec3::new(c[0].into(), c[1].into(), c[2].into());
        let p = if identity {
            c
        } else {
            placed.world.transform_point3(c)
        };
        if !p.is_finite() {
            return Err(malformed(format!(
                "{what}: vertex {v} is not finite after its node's transform"
            )));
        }
        positions.push(p.to_array());
    }
    Ok(positions)
}

/// The values of attribute `key` from accessor `index`: texture coordinates with `v`
/// flipped, normals transformed by `normal_matrix`. `None` for an application-specific
/// attribute of a type no channel holds (a matrix), which is skipped.
fn read_attribute(
    root: &Root,
    buffers: &[Option<Vec<u8>>],
    key: &Key,
    index: json::Index<json::Accessor>,
    normal_matrix: DMat3,
    what: &str,
) -> Result<Option<Values>, ReadError> {
    let name = key.semantic();
    let matrix = root.accessors.get(index.value()).is_some_and(|a| {
        !matches!(
            a.type_,
            Checked::Valid(Type::Scalar | Type::Vec2 | Type::Vec3 | Type::Vec4)
        )
    });
    if matrix && matches!(key, Key::Custom(_)) {
        return Ok(None);
    }
    let e = elements(root, buffers, index, &format!("{name} of {what}"))?;
    if !key.dimensions().contains(&e.components) {
        return Err(malformed(format!(
            "{what}: {name} has {} components",
            e.components
        )));
    }
    let mut v = e.finite_floats()?;
    match key {
        Key::TexCoord(_) => {
            for uv in v.chunks_exact_mut(2) {
                uv[1] = flip_v(uv[1]);
            }
        }
        // Untransformed normals are kept bit for bit, so a round trip through glTF
        // does not renormalise them.
        Key::Normal if normal_matrix != DMat3::IDENTITY => {
            for (k, n) in v.chunks_exact_mut(3).enumerate() {
                let m = normal_matrix * DVec3::new(n[0].into(), n[1].into(), n[2].into());
                // A normal too long to normalise (its squared length overflows) stays
                // as it is, and may then be beyond float32.
                let m = m.try_normalize().unwrap_or(m).as_vec3();
                if !m.is_finite() {
                    return Err(malformed(format!(
                        "{what}: NORMAL element {k} is not finite after its node's transform"
                    )));
                }
                n.copy_from_slice(&m.to_array());
            }
        }
        _ => {}
    }
    Ok(Some(Values {
        accessor: index.value(),
        dimension: e.components,
        values: v,
    }))
}

/// glTF's `v` (origin at the top of the image) to qem's (origin at the bottom), and
/// back: the same flip.
fn flip_v(v: f32) -> f32 {
    (1.0 - f64::from(v)) as f32
}

/// One mesh from the blocks and runs: positions and triangles concatenated, a
/// channel per attribute key any block has (missing where a block lacks it).
fn assemble(blocks: Vec<Block>, runs: Vec<Run>, materials: Labels, groups: Labels) -> IndexedMesh {
    // Only attributes some triangle uses make channels, with the dimension of those
    // uses: a primitive without triangles (a strip of two indices) would otherwise
    // give a channel no corner has, which the writer cannot write back as such (it
    // would shift the numbering of the sets that are used, or widen vec3 colours).
    let used: HashSet<(usize, &Key)> = runs
        .iter()
        .filter(|r| !r.triangles.is_empty())
        .flat_map(|r| r.keys.iter().map(|k| (r.block, k)))
        .collect();
    let mut dims: BTreeMap<Key, usize> = BTreeMap::new();
    for &(b, key) in &used {
        if let Some(v) = blocks[b].values.get(key) {
            let e = dims.entry(key.clone()).or_insert(v.dimension);
            *e = (*e).max(v.dimension);
        }
    }
    let mut position_base = Vec::with_capacity(blocks.len());
    let mut positions = Vec::new();
    for b in &blocks {
        position_base.push(positions.len() as u32);
        positions.extend_from_slice(&b.positions);
    }
    let mut names: Vec<String> = Vec::new();
    let mut channels: Vec<Channel> = Vec::new();
    for (key, dim) in dims {
        // The keys come sorted, so a set's rank is the number of channels of its kind
        // before it.
        let rank = channels.iter().filter(|c| c.kind == key.kind()).count();
        // Unique names: a `_NAME` attribute may be called like a standard channel.
        let base = key.name(rank);
        let mut name = base.clone();
        let mut k = 1;
        while names.contains(&name) {
            name = format!("{base}_{k}");
            k += 1;
        }
        names.push(name.clone());
        let mut values = Vec::new();
        let mut base = Vec::with_capacity(blocks.len());
        for (bi, b) in blocks.iter().enumerate() {
            match b.values.get(&key).filter(|_| used.contains(&(bi, &key))) {
                Some(v) => {
                    base.push(Some((values.len() / dim) as u32));
                    let d = v.dimension;
                    for value in v.values.chunks_exact(d) {
                        values.extend_from_slice(value);
                        // A vec3 colour among vec4 ones is opaque; other shorter
                        // generic values are padded with zeros.
                        let pad = if key.kind() == ChannelKind::Color {
                            1.0
                        } else {
                            0.0
                        };
                        values.extend(std::iter::repeat_n(pad, dim - d));
                    }
                }
                None => base.push(None),
            }
        }
        let corners = runs
            .iter()
            .flat_map(|r| {
                let base = base[r.block].filter(|_| r.keys.contains(&key));
                r.triangles
                    .iter()
                    .map(move |t| t.map(|i| base.map_or(Channel::MISSING, |b| b + i)))
            })
            .collect();
        channels.push(
            Channel::new(key.kind(), values, corners)
                .with_dimension(dim)
                .with_name(name),
        );
    }
    let triangles = runs
        .iter()
        .flat_map(|r| {
            let base = position_base[r.block];
            r.triangles.iter().map(move |t| t.map(|i| base + i))
        })
        .collect();
    let per_face = |label: fn(&Run) -> u32| -> Vec<u32> {
        runs.iter()
            .flat_map(|r| std::iter::repeat_n(label(r), r.triangles.len()))
            .collect()
    };
    let attributes = Attributes {
        channels,
        materials: materials.into_face_labels(per_face(|r| r.material)),
        groups: groups.into_face_labels(per_face(|r| r.group)),
        ..Attributes::default()
    };
    IndexedMesh::new(positions, triangles).with_attributes(attributes)
}

/// Where each channel goes in a glTF file: the attribute semantic, or why it is left
/// out. The writer and [`super::unwritable`] both use it.
pub(crate) fn semantics(channels: &[Channel]) -> Vec<Result<String, &'static str>> {
    let (mut uv, mut colour, mut normal) = (0, 0, false);
    channels
        .iter()
        .map(|c| match c.kind {
            ChannelKind::TexCoord => {
                uv += 1;
                Ok(format!("TEXCOORD_{}", uv - 1))
            }
            ChannelKind::Color => {
                colour += 1;
                Ok(format!("COLOR_{}", colour - 1))
            }
            ChannelKind::Normal if !normal => {
                normal = true;
                Ok("NORMAL".to_string())
            }
            ChannelKind::Normal => Err("glTF holds one NORMAL per vertex"),
            ChannelKind::Generic => Ok(format!("_{}", c.name)),
        })
        .collect()
}

/// The binary buffer and the JSON accessors and buffer views that describe it.
#[derive(Default)]
struct Builder {
    bin: Vec<u8>,
    views: Vec<serde_json::Value>,
    accessors: Vec<serde_json::Value>,
}

impl Builder {
    /// Appends one tightly packed accessor of `count` elements of `kind` ("VEC3"...)
    /// with `component` (5126 float, 5125 unsigned int); gives its index.
    fn add(
        &mut self,
        words: impl IntoIterator<Item = [u8; 4]>,
        count: usize,
        kind: &str,
        component: u32,
        target: u32,
        bounds: Option<([f32; 3], [f32; 3])>,
    ) -> usize {
        let start = self.bin.len();
        for w in words {
            self.bin.extend_from_slice(&w);
        }
        self.views.push(serde_json::json!({
            "buffer": 0,
            "byteOffset": start,
            "byteLength": self.bin.len() - start,
            "target": target,
        }));
        let mut accessor = serde_json::json!({
            "bufferView": self.views.len() - 1,
            "componentType": component,
            "count": count,
            "type": kind,
        });
        if let Some((min, max)) = bounds {
            accessor["min"] = serde_json::json!(min);
            accessor["max"] = serde_json::json!(max);
        }
        self.accessors.push(accessor);
        self.accessors.len() - 1
    }
}

fn invalid(message: String) -> io::Error {
    io::Error::new(io::ErrorKind::InvalidInput, message)
}

/// A primitive to write: its material label, which written channels it has, and its
/// faces.
type Primitive = (u32, Vec<bool>, Vec<usize>);

/// Writes `mesh` as glTF JSON with an embedded buffer, or as GLB.
pub(crate) fn write<W: Write>(out: &mut W, mesh: &IndexedMesh, format: Format) -> io::Result<()> {
    let plan = semantics(&mesh.attributes.channels);
    let (written, names): (Vec<&Channel>, Vec<String>) = mesh
        .attributes
        .channels
        .iter()
        .zip(plan)
        .filter_map(|(c, s)| Some((c, s.ok()?)))
        .unzip();
    let mut doc = serde_json::json!({
        "asset": { "version": "2.0", "generator": "qem" },
    });
    let mut b = Builder::default();
    if !mesh.triangles.is_empty() {
        let pv = per_vertex(mesh, written.iter().map(|&c| c.clone()).collect());
        let mut positions = Vec::with_capacity(pv.positions.len());
        for (v, p) in pv.positions.iter().enumerate() {
            let q = p.map(|c| c as f32);
            if let Some(c) = q.iter().position(|c| !c.is_finite()) {
                return Err(invalid(format!(
                    "vertex {v} has coordinate {:e}, beyond the range of glTF's float32 \
                     (about ±3.4e38); write PLY, OBJ or OFF instead",
                    p[c]
                )));
            }
            positions.push(q);
        }
        let mut min = [f32::INFINITY; 3];
        let mut max = [f32::NEG_INFINITY; 3];
        for p in &positions {
            for k in 0..3 {
                min[k] = min[k].min(p[k]);
                max[k] = max[k].max(p[k]);
            }
        }
        const ARRAY_BUFFER: u32 = 34962;
        const ELEMENT_ARRAY_BUFFER: u32 = 34963;
        const FLOAT: u32 = 5126;
        const UNSIGNED_INT: u32 = 5125;
        let floats = |v: Vec<f32>| v.into_iter().map(f32::to_le_bytes).collect::<Vec<_>>();
        let position = b.add(
            floats(positions.iter().flatten().copied().collect()),
            positions.len(),
            "VEC3",
            FLOAT,
            ARRAY_BUFFER,
            Some((min, max)),
        );
        let mut attributes = Vec::with_capacity(names.len());
        for (c, semantic) in pv.channels.iter().zip(&names) {
            let mut values = c.values.clone();
            if c.kind == ChannelKind::TexCoord {
                for uv in values.chunks_exact_mut(2) {
                    uv[1] = flip_v(uv[1]);
                }
            }
            let kind = ["SCALAR", "VEC2", "VEC3", "VEC4"][c.dimension.clamp(1, 4) - 1];
            let count = c.value_count();
            let a = b.add(floats(values), count, kind, FLOAT, ARRAY_BUFFER, None);
            attributes.push((semantic, a));
        }
        // Faces by group (one glTF mesh each) and within a group by material and by
        // the channels they have (one primitive each), all in order of first
        // appearance. A glTF attribute belongs to a whole primitive: faces with a
        // channel and faces without it (two primitives of one material in the file
        // read) need primitives of their own, or the second would read back with the
        // zeros the shared accessor holds for them rather than with no value.
        let label = |l: &FaceLabels, t: usize| l.faces.get(t).copied().unwrap_or(FaceLabels::NONE);
        let (materials, groups) = (&mesh.attributes.materials, &mesh.attributes.groups);
        let mut meshes: Vec<(u32, Vec<Primitive>)> = Vec::new();
        let mut mesh_of: HashMap<u32, usize> = HashMap::new();
        let mut primitive_of: HashMap<(u32, u32, Vec<bool>), usize> = HashMap::new();
        for t in 0..pv.triangles.len() {
            let (g, m) = (label(groups, t), label(materials, t));
            let has: Vec<bool> = written
                .iter()
                .map(|c| c.corners[t].iter().any(|&i| i != Channel::MISSING))
                .collect();
            let gi = *mesh_of.entry(g).or_insert_with(|| {
                meshes.push((g, Vec::new()));
                meshes.len() - 1
            });
            let prims = &mut meshes[gi].1;
            let pi = *primitive_of.entry((g, m, has.clone())).or_insert_with(|| {
                prims.push((m, has, Vec::new()));
                prims.len() - 1
            });
            prims[pi].2.push(t);
        }
        let mut json_meshes = Vec::new();
        for (g, prims) in &meshes {
            let mut primitives = Vec::new();
            for (m, has, faces) in prims {
                let indices = faces
                    .iter()
                    .flat_map(|&t| pv.triangles[t])
                    .map(u32::to_le_bytes)
                    .collect::<Vec<_>>();
                let count = indices.len();
                let i = b.add(
                    indices,
                    count,
                    "SCALAR",
                    UNSIGNED_INT,
                    ELEMENT_ARRAY_BUFFER,
                    None,
                );
                // A channel none of the primitive's corners has is left out of it, so
                // reading gives those corners no value again (rather than zeros).
                let mut used = serde_json::Map::new();
                used.insert("POSITION".into(), position.into());
                for ((semantic, a), _) in attributes.iter().zip(has).filter(|(_, &h)| h) {
                    used.insert(semantic.to_string(), (*a).into());
                }
                let mut p = serde_json::json!({
                    "attributes": used,
                    "indices": i,
                    "mode": 4,
                });
                if (*m as usize) < materials.names.len() {
                    p["material"] = (*m).into();
                }
                primitives.push(p);
            }
            let mut m = serde_json::json!({ "primitives": primitives });
            if let Some(name) = groups.names.get(*g as usize) {
                m["name"] = String::from_utf8_lossy(name).into();
            }
            json_meshes.push(m);
        }
        doc["scene"] = 0.into();
        doc["scenes"] = serde_json::json!([{ "nodes": (0..meshes.len()).collect::<Vec<_>>() }]);
        doc["nodes"] = (0..meshes.len())
            .map(|i| serde_json::json!({ "mesh": i }))
            .collect();
        doc["meshes"] = json_meshes.into();
        if !materials.names.is_empty() {
            doc["materials"] = materials
                .names
                .iter()
                .map(|n| serde_json::json!({ "name": String::from_utf8_lossy(n) }))
                .collect();
        }
        let mut buffer = serde_json::json!({ "byteLength": b.bin.len() });
        if format == Format::Gltf {
            buffer["uri"] = format!(
                "data:application/octet-stream;base64,{}",
                encode_base64(&b.bin)
            )
            .into();
        }
        doc["buffers"] = serde_json::json!([buffer]);
        doc["bufferViews"] = std::mem::take(&mut b.views).into();
        doc["accessors"] = std::mem::take(&mut b.accessors).into();
    }
    let mut json_text = serde_json::to_vec(&doc).map_err(io::Error::other)?;
    if format == Format::Gltf {
        json_text.push(b'\n');
        return out.write_all(&json_text);
    }
    // GLB: chunks padded to four bytes, JSON with spaces and BIN with zeros.
    json_text.resize(json_text.len().next_multiple_of(4), b' ');
    let mut bin = b.bin;
    bin.resize(bin.len().next_multiple_of(4), 0);
    let mut total = GLB_HEADER + CHUNK_HEADER + json_text.len();
    if !bin.is_empty() {
        total += CHUNK_HEADER + bin.len();
    }
    let total = u32::try_from(total)
        .map_err(|_| invalid("the mesh needs more than the 4 GiB a GLB file can hold".into()))?;
    out.write_all(GLB_MAGIC)?;
    out.write_all(&2u32.to_le_bytes())?;
    out.write_all(&total.to_le_bytes())?;
    out.write_all(&(json_text.len() as u32).to_le_bytes())?;
    out.write_all(&CHUNK_JSON.to_le_bytes())?;
    out.write_all(&json_text)?;
    if !bin.is_empty() {
        out.write_all(&(bin.len() as u32).to_le_bytes())?;
        out.write_all(&CHUNK_BIN.to_le_bytes())?;
        out.write_all(&bin)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_round_trips_every_length() {
        for n in 0..10u8 {
            let data: Vec<u8> = (0..n).map(|i| i.wrapping_mul(97)).collect();
            let text = encode_base64(&data);
            assert_eq!(text.len() % 4, 0);
            assert_eq!(decode_base64(text.as_bytes()), Some(data));
        }
        assert_eq!(encode_base64(b"Man"), "TWFu");
        assert_eq!(decode_base64(b"TWE"), Some(b"Ma".to_vec()));
        assert_eq!(decode_base64(b"TW!u"), None);
        for text in [
            "", "T", "TW", "TWE", "TWFu", "TWFuTQ", "TWFuTQ==", "TWFuTWE=",
        ] {
            let decoded = decode_base64(text.as_bytes()).unwrap();
            assert_eq!(decoded_len(text.as_bytes()), decoded.len(), "{text}");
        }
    }

    #[test]
    fn percent_escapes_are_decoded() {
        assert_eq!(percent_decode("a%20b%2Fc%zz%"), b"a b/c%zz%");
    }

    #[test]
    fn strips_and_fans_become_triangles_with_gltf_winding() {
        let strip = triangles(Mode::TriangleStrip, &[0, 1, 2, 3], "p").unwrap();
        assert_eq!(strip, vec![[0, 1, 2], [1, 3, 2]]);
        let fan = triangles(Mode::TriangleFan, &[0, 1, 2, 3], "p").unwrap();
        assert_eq!(fan, vec![[1, 2, 0], [2, 3, 0]]);
        assert!(triangles(Mode::Triangles, &[0, 1], "p").is_err());
        assert!(triangles(Mode::TriangleStrip, &[0, 1], "p")
            .unwrap()
            .is_empty());
    }
}
