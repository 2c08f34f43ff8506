//! What a mesh carries besides positions: per-corner attribute channels (texture
//! coordinates, normals, colours, generic floats) and per-face labels (materials,
//! groups).
//!
//! Every channel is stored per triangle corner (a *wedge* model): a list of values and,
//! for each triangle, the index of the value at each of its three corners. A vertex
//! whose corners use different values of a channel lies on a seam of that channel (a
//! UV seam, a hard normal edge, a colour border). Per-vertex data (PLY colours, glTF
//! attributes) is the special case where each corner uses its vertex's value; the
//! wedge form keeps it exact through welding, where two vertices at one position but
//! with different values become one vertex with two wedges.
//!
//! ```
//! use qem_mesh::attributes::{Attributes, Channel, ChannelKind};
//! use qem_mesh::IndexedMesh;
//! let mut mesh = IndexedMesh::new(
//!     vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
//!     vec![[0, 1, 2]],
//! );
//! mesh.attributes.channels.push(Channel::new(
//!     ChannelKind::TexCoord,
//!     vec![0.0, 0.0, 1.0, 0.0, 0.0, 1.0],
//!     vec![[0, 1, 2]],
//! ));
//! assert!(mesh.validate().is_ok());
//! assert_eq!(mesh.attributes.channel(ChannelKind::TexCoord).unwrap().value(2), &[0.0, 1.0]);
//! ```

use std::fmt;

/// What a channel means, which fixes its dimension and how it is read, written and
/// simplified.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum ChannelKind {
    /// Texture coordinates (u, v): OBJ `vt`, PLY `s t` / `u v`, glTF `TEXCOORD_0`.
    TexCoord,
    /// Normals (x, y, z), unit length: OBJ `vn`, PLY `nx ny nz`, glTF `NORMAL`.
    /// Simplified values are renormalised.
    Normal,
    /// Colours, RGB or RGBA in 0–1: PLY `red green blue [alpha]`, glTF `COLOR_0`,
    /// OFF's COFF. Simplified values are clamped to 0–1.
    Color,
    /// Any other float data (1 to 4 per corner), named by [`Channel::name`].
    Generic,
}

impl ChannelKind {
    /// The name the reports and `--attribute-weights` use: `uv`, `normal`, `colour`,
    /// `generic`.
    pub fn as_str(self) -> &'static str {
        match self {
            ChannelKind::TexCoord => "uv",
            ChannelKind::Normal => "normal",
            ChannelKind::Color => "colour",
            ChannelKind::Generic => "generic",
        }
    }
}

impl fmt::Display for ChannelKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// One attribute channel, stored per triangle corner.
#[derive(Clone, Debug, PartialEq)]
pub struct Channel {
    /// What the values mean.
    pub kind: ChannelKind,
    /// A name: the kind's name for the first three kinds, the file's property name for
    /// generic channels. Names are unique within a mesh.
    pub name: String,
    /// Floats per value: 2 for texture coordinates, 3 for normals, 3 or 4 for colours,
    /// 1 to 4 for generic channels.
    pub dimension: usize,
    /// The values, `dimension` floats each, one after the other.
    pub values: Vec<f32>,
    /// One entry per triangle of the mesh: the index of the value at each corner, or
    /// [`Channel::MISSING`] where a corner has none (an OBJ face without `vt`).
    pub corners: Vec<[u32; 3]>,
}

impl Channel {
    /// The index of a corner that has no value in this channel.
    pub const MISSING: u32 = u32::MAX;

    /// A channel of `kind` with the kind's name and usual dimension (2 for texture
    /// coordinates, 3 for normals and colours, 1 for generic channels; RGBA colours and
    /// generic vectors set theirs with [`Channel::with_dimension`]); `values` flat,
    /// `corners` one per triangle.
    pub fn new(kind: ChannelKind, values: Vec<f32>, corners: Vec<[u32; 3]>) -> Channel {
        let dimension = match kind {
            ChannelKind::TexCoord => 2,
            ChannelKind::Normal | ChannelKind::Color => 3,
            ChannelKind::Generic => 1,
        };
        Channel {
            kind,
            name: kind.as_str().to_string(),
            dimension,
            values,
            corners,
        }
    }

    /// The channel with another dimension (RGBA colours, generic vectors).
    pub fn with_dimension(mut self, dimension: usize) -> Channel {
        self.dimension = dimension;
        self
    }

    /// The channel with another name (generic channels).
    pub fn with_name(mut self, name: impl Into<String>) -> Channel {
        self.name = name.into();
        self
    }

    /// The same channel (kind, name, values) with other `corners`.
    pub fn with_corners(&self, corners: Vec<[u32; 3]>) -> Channel {
        Channel {
            kind: self.kind,
            name: self.name.clone(),
            dimension: self.dimension,
            values: self.values.clone(),
            corners,
        }
    }

    /// How many values the channel holds.
    pub fn value_count(&self) -> usize {
        self.values.len() / self.dimension.max(1)
    }

    /// Value `i` (`dimension` floats). Panics when `i` is out of range, like slice
    /// indexing; a validated mesh's corners are all in range.
    pub fn value(&self, i: u32) -> &[f32] {
        let d = self.dimension;
        &self.values[i as usize * d..(i as usize + 1) * d]
    }

    /// The value at corner `k` of triangle `t`, or `None` when it has none.
    pub fn at_corner(&self, t: usize, k: usize) -> Option<&[f32]> {
        let i = *self.corners.get(t)?.get(k)?;
        (i != Channel::MISSING).then(|| self.value(i))
    }
}

/// A name per face: which material, or which group, each triangle belongs to.
///
/// Empty (`faces` empty) when the mesh has no such labels; otherwise `faces` has one
/// entry per triangle, an index into `names`, or [`FaceLabels::NONE`] for a triangle
/// before the file's first label.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct FaceLabels {
    /// The distinct names, in order of first appearance. Kept byte for byte: OBJ does
    /// not say how names are encoded, and Latin-1 names are common in CAD exports.
    pub names: Vec<Vec<u8>>,
    /// Per triangle, an index into `names` (or [`FaceLabels::NONE`]).
    pub faces: Vec<u32>,
}

impl FaceLabels {
    /// The label of a triangle that has none.
    pub const NONE: u32 = u32::MAX;

    /// Whether the mesh has no labels of this kind.
    pub fn is_empty(&self) -> bool {
        self.faces.is_empty()
    }

    /// The name of triangle `t`'s label, if it has one.
    pub fn of_face(&self, t: usize) -> Option<&[u8]> {
        let i = *self.faces.get(t)?;
        self.names.get(i as usize).map(Vec::as_slice)
    }
}

/// Everything a mesh carries besides positions and triangles. Empty by default; a
/// positions-only mesh has `Attributes::default()`.
#[derive(Clone, Debug, Default, PartialEq)]
#[non_exhaustive]
pub struct Attributes {
    /// Per-corner channels, in the order the file gave them.
    pub channels: Vec<Channel>,
    /// Per-face materials (OBJ `usemtl`, glTF primitives' materials, PLY has none).
    pub materials: FaceLabels,
    /// Per-face groups (OBJ `o`/`g`).
    pub groups: FaceLabels,
    /// Material files the mesh refers to (OBJ `mtllib`), as written in the file.
    pub material_libraries: Vec<Vec<u8>>,
}

impl Attributes {
    /// Whether there is nothing besides positions.
    pub fn is_empty(&self) -> bool {
        self.channels.is_empty()
            && self.materials.is_empty()
            && self.groups.is_empty()
            && self.material_libraries.is_empty()
    }

    /// The names of what the mesh carries besides positions: its channels' names,
    /// then `materials`, `groups` and `material libraries` when it has them (as
    /// reports list them).
    ///
    /// ```
    /// use qem_mesh::attributes::{Attributes, Channel, ChannelKind};
    /// let mut a = Attributes::default();
    /// a.channels.push(Channel::new(ChannelKind::TexCoord, vec![0.0, 0.0], vec![[0; 3]]));
    /// assert_eq!(a.names(), vec!["uv".to_string()]);
    /// ```
    pub fn names(&self) -> Vec<String> {
        let mut names: Vec<String> = self.channels.iter().map(|c| c.name.clone()).collect();
        for (what, there) in [
            ("materials", !self.materials.is_empty()),
            ("groups", !self.groups.is_empty()),
            ("material libraries", !self.material_libraries.is_empty()),
        ] {
            if there {
                names.push(what.to_string());
            }
        }
        names
    }

    /// The first channel of `kind`, if any.
    pub fn channel(&self, kind: ChannelKind) -> Option<&Channel> {
        self.channels.iter().find(|c| c.kind == kind)
    }

    /// The same attributes for the triangles `kept` (indices into this mesh's
    /// triangles, in the order the new mesh has them): face-indexed arrays are picked,
    /// value lists are kept whole.
    pub fn for_faces(&self, kept: &[u32]) -> Attributes {
        let pick = |faces: &FaceLabels| FaceLabels {
            names: faces.names.clone(),
            faces: if faces.faces.is_empty() {
                Vec::new()
            } else {
                kept.iter().map(|&t| faces.faces[t as usize]).collect()
            },
        };
        Attributes {
            channels: self
                .channels
                .iter()
                .map(|c| c.with_corners(kept.iter().map(|&t| c.corners[t as usize]).collect()))
                .collect(),
            materials: pick(&self.materials),
            groups: pick(&self.groups),
            material_libraries: self.material_libraries.clone(),
        }
    }

    /// Checks the attributes of a mesh with `triangle_count` triangles: what
    /// [`crate::IndexedMesh::validate`] checks beyond positions.
    pub(crate) fn validate(&self, triangle_count: usize) -> Result<(), AttributeError> {
        let mut names = std::collections::HashSet::new();
        for c in &self.channels {
            let problem = |problem| AttributeError::Channel {
                channel: c.name.clone(),
                problem,
            };
            if !names.insert(c.name.as_str()) {
                return Err(problem(ChannelProblem::DuplicateName));
            }
            let allowed = match c.kind {
                ChannelKind::TexCoord => 2..=2,
                ChannelKind::Normal => 3..=3,
                ChannelKind::Color => 3..=4,
                ChannelKind::Generic => 1..=4,
            };
            if !allowed.contains(&c.dimension) {
                return Err(problem(ChannelProblem::Dimension {
                    dimension: c.dimension,
                }));
            }
            if c.values.len() % c.dimension != 0 {
                return Err(problem(ChannelProblem::RaggedValues {
                    floats: c.values.len(),
                }));
            }
            if c.corners.len() != triangle_count {
                return Err(problem(ChannelProblem::CornerCount {
                    found: c.corners.len(),
                    triangles: triangle_count,
                }));
            }
            if let Some(i) = c.values.iter().position(|v| !v.is_finite()) {
                return Err(problem(ChannelProblem::NonFinite {
                    value: i / c.dimension,
                }));
            }
            let count = c.value_count();
            for (face, corners) in c.corners.iter().enumerate() {
                if let Some(&index) = corners
                    .iter()
                    .find(|&&i| i != Channel::MISSING && i as usize >= count)
                {
                    return Err(problem(ChannelProblem::IndexOutOfRange {
                        face,
                        index,
                        values: count,
                    }));
                }
            }
        }
        for (what, labels) in [("materials", &self.materials), ("groups", &self.groups)] {
            if labels.faces.is_empty() {
                continue;
            }
            if labels.faces.len() != triangle_count {
                return Err(AttributeError::LabelCount {
                    what,
                    found: labels.faces.len(),
                    triangles: triangle_count,
                });
            }
            if let Some(face) = labels
                .faces
                .iter()
                .position(|&i| i != FaceLabels::NONE && i as usize >= labels.names.len())
            {
                return Err(AttributeError::LabelOutOfRange {
                    what,
                    face,
                    index: labels.faces[face],
                    names: labels.names.len(),
                });
            }
        }
        Ok(())
    }
}

/// `mesh` with every channel per vertex, as PLY, OFF and glTF store them: each corner's
/// channels come from its vertex (`corners == triangles` in every channel, one value
/// per vertex).
///
/// A vertex whose corners use different values (a seam) becomes one vertex per
/// distinct combination of values: the first combination (in triangle order) keeps
/// the vertex's number, the others are appended in order of first use. So a mesh that
/// already is per vertex comes back with its vertex order unchanged. A vertex no
/// corner uses, and a corner without a value ([`Channel::MISSING`]), get zeros.
/// Face labels are kept as they are.
///
/// ```
/// use qem_mesh::attributes::{split_at_seams, Channel, ChannelKind};
/// use qem_mesh::IndexedMesh;
/// // Two triangles sharing the edge 1-2, with different UVs on each side of it.
/// let mut mesh = IndexedMesh::new(
///     vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]],
///     vec![[0, 1, 2], [1, 3, 2]],
/// );
/// mesh.attributes.channels.push(Channel::new(
///     ChannelKind::TexCoord,
///     vec![0.0, 0.0, 0.5, 0.0, 0.0, 0.5, 0.6, 0.0, 1.0, 1.0, 0.6, 1.0],
///     vec![[0, 1, 2], [3, 4, 5]],
/// ));
/// let split = split_at_seams(&mesh);
/// assert_eq!(split.vertex_count(), 6); // vertices 1 and 2 are each split in two
/// assert_eq!(split.triangles, vec![[0, 1, 2], [4, 3, 5]]);
/// assert_eq!(split.attributes.channels[0].corners, split.triangles);
/// ```
pub fn split_at_seams(mesh: &crate::IndexedMesh) -> crate::IndexedMesh {
    let channels = &mesh.attributes.channels;
    let n = mesh.positions.len();
    let width = channels.len();
    if width == 0 {
        return mesh.clone();
    }
    // The combination of value indices at a corner, and the vertex that got each
    // vertex's first combination (`first`) or a later one (`later`).
    let combination = |t: usize, k: usize| -> smallvec::SmallVec<[u32; 4]> {
        channels.iter().map(|c| c.corners[t][k]).collect()
    };
    let mut first: Vec<u32> = vec![Channel::MISSING; n * width];
    let mut assigned = vec![false; n];
    let mut later: std::collections::HashMap<(u32, smallvec::SmallVec<[u32; 4]>), u32> =
        std::collections::HashMap::new();
    let mut positions = mesh.positions.clone();
    let mut triangles = Vec::with_capacity(mesh.triangles.len());
    for (t, tri) in mesh.triangles.iter().enumerate() {
        let mut out = [0u32; 3];
        for k in 0..3 {
            let v = tri[k] as usize;
            let combo = combination(t, k);
            let slot = &mut first[v * width..(v + 1) * width];
            out[k] = if !assigned[v] {
                assigned[v] = true;
                slot.copy_from_slice(&combo);
                v as u32
            } else if slot == combo.as_slice() {
                v as u32
            } else {
                *later.entry((v as u32, combo)).or_insert_with(|| {
                    positions.push(mesh.positions[v]);
                    (positions.len() - 1) as u32
                })
            };
        }
        triangles.push(out);
    }
    // The value indices of every output vertex, then the values themselves.
    let mut combos: Vec<u32> = first;
    combos.resize(positions.len() * width, Channel::MISSING);
    for ((_, combo), &new) in &later {
        combos[new as usize * width..(new as usize + 1) * width].copy_from_slice(combo);
    }
    let split_channels = channels
        .iter()
        .enumerate()
        .map(|(j, c)| {
            let mut values = Vec::with_capacity(positions.len() * c.dimension);
            for v in 0..positions.len() {
                let i = combos[v * width + j];
                if i == Channel::MISSING {
                    values.extend(std::iter::repeat_n(0.0, c.dimension));
                } else {
                    values.extend_from_slice(c.value(i));
                }
            }
            Channel {
                kind: c.kind,
                name: c.name.clone(),
                dimension: c.dimension,
                values,
                corners: triangles.clone(),
            }
        })
        .collect();
    crate::IndexedMesh::new(positions, triangles).with_attributes(Attributes {
        channels: split_channels,
        ..mesh.attributes.clone()
    })
}

/// What is wrong with one channel.
#[derive(Clone, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum ChannelProblem {
    /// Another channel has the same name.
    DuplicateName,
    /// The dimension is not one the kind allows.
    Dimension {
        /// The channel's dimension.
        dimension: usize,
    },
    /// The number of floats is not a multiple of the dimension.
    RaggedValues {
        /// How many floats there are.
        floats: usize,
    },
    /// `corners` does not have one entry per triangle.
    CornerCount {
        /// Entries in `corners`.
        found: usize,
        /// Triangles in the mesh.
        triangles: usize,
    },
    /// A value is NaN or infinite.
    NonFinite {
        /// The value's index.
        value: usize,
    },
    /// A corner refers to a value that does not exist.
    IndexOutOfRange {
        /// The triangle.
        face: usize,
        /// The index it holds.
        index: u32,
        /// How many values there are.
        values: usize,
    },
}

/// Why the attributes of a mesh were refused.
#[derive(Clone, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum AttributeError {
    /// A channel is malformed.
    Channel {
        /// The channel's name.
        channel: String,
        /// What is wrong.
        problem: ChannelProblem,
    },
    /// Face labels do not have one entry per triangle.
    LabelCount {
        /// `"materials"` or `"groups"`.
        what: &'static str,
        /// Entries.
        found: usize,
        /// Triangles in the mesh.
        triangles: usize,
    },
    /// A face label refers to a name that does not exist.
    LabelOutOfRange {
        /// `"materials"` or `"groups"`.
        what: &'static str,
        /// The triangle.
        face: usize,
        /// The index it holds.
        index: u32,
        /// How many names there are.
        names: usize,
    },
}

impl fmt::Display for AttributeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            AttributeError::Channel { channel, problem } => {
                write!(f, "attribute channel {channel:?}: ")?;
                match problem {
                    ChannelProblem::DuplicateName => write!(f, "another channel has this name"),
                    ChannelProblem::Dimension { dimension } => {
                        write!(f, "{dimension} floats per value is not allowed")
                    }
                    ChannelProblem::RaggedValues { floats } => {
                        write!(f, "{floats} floats are not a whole number of values")
                    }
                    ChannelProblem::CornerCount { found, triangles } => {
                        write!(f, "{found} corner triples for {triangles} triangles")
                    }
                    ChannelProblem::NonFinite { value } => {
                        write!(f, "value {value} is not finite")
                    }
                    ChannelProblem::IndexOutOfRange {
                        face,
                        index,
                        values,
                    } => write!(
                        f,
                        "face {face} refers to value {index}, but there are only {values} values"
                    ),
                }
            }
            AttributeError::LabelCount {
                what,
                found,
                triangles,
            } => write!(f, "{found} {what} labels for {triangles} triangles"),
            AttributeError::LabelOutOfRange {
                what,
                face,
                index,
                names,
            } => write!(
                f,
                "face {face} has {what} label {index}, but there are only {names} names"
            ),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn uv(corners: Vec<[u32; 3]>) -> Channel {
        Channel::new(
            ChannelKind::TexCoord,
            vec![0.0, 0.0, 1.0, 0.0, 0.0, 1.0],
            corners,
        )
    }

    #[test]
    fn a_valid_channel_passes_and_is_read_per_corner() {
        let attrs = Attributes {
            channels: vec![uv(vec![[0, 1, 2], [2, Channel::MISSING, 0]])],
            ..Attributes::default()
        };
        assert_eq!(attrs.validate(2), Ok(()));
        let c = &attrs.channels[0];
        assert_eq!(c.at_corner(1, 0), Some(&[0.0, 1.0][..]));
        assert_eq!(c.at_corner(1, 1), None);
        assert_eq!(c.value_count(), 3);
    }

    #[test]
    fn problems_name_the_channel_and_where() {
        let short = Attributes {
            channels: vec![uv(vec![[0, 1, 2]])],
            ..Attributes::default()
        };
        assert_eq!(
            short.validate(2).unwrap_err().to_string(),
            "attribute channel \"uv\": 1 corner triples for 2 triangles"
        );
        let out_of_range = Attributes {
            channels: vec![uv(vec![[0, 1, 3]])],
            ..Attributes::default()
        };
        assert_eq!(
            out_of_range.validate(1).unwrap_err().to_string(),
            "attribute channel \"uv\": face 0 refers to value 3, but there are only 3 values"
        );
        let mut nan = uv(vec![[0, 1, 2]]);
        nan.values[3] = f32::NAN;
        let nan = Attributes {
            channels: vec![nan],
            ..Attributes::default()
        };
        assert_eq!(
            nan.validate(1).unwrap_err().to_string(),
            "attribute channel \"uv\": value 1 is not finite"
        );
        let twice = Attributes {
            channels: vec![uv(vec![[0, 1, 2]]), uv(vec![[0, 1, 2]])],
            ..Attributes::default()
        };
        assert!(twice.validate(1).is_err());
        let five = Attributes {
            channels: vec![
                Channel::new(ChannelKind::Generic, vec![0.0; 5], vec![[0; 3]]).with_dimension(5),
            ],
            ..Attributes::default()
        };
        assert!(five.validate(1).is_err());
    }

    #[test]
    fn labels_are_checked_and_picked_with_their_faces() {
        let attrs = Attributes {
            channels: vec![uv(vec![[0, 1, 2], [2, 1, 0], [1, 1, 1]])],
            materials: FaceLabels {
                names: vec![b"red".to_vec(), b"blue".to_vec()],
                faces: vec![0, 1, FaceLabels::NONE],
            },
            ..Attributes::default()
        };
        assert_eq!(attrs.validate(3), Ok(()));
        let picked = attrs.for_faces(&[2, 0]);
        assert_eq!(picked.materials.faces, vec![FaceLabels::NONE, 0]);
        assert_eq!(picked.channels[0].corners, vec![[1, 1, 1], [0, 1, 2]]);
        assert_eq!(picked.materials.of_face(1), Some(&b"red"[..]));
        let mut bad = attrs.clone();
        bad.materials.faces[1] = 2;
        assert_eq!(
            bad.validate(3).unwrap_err().to_string(),
            "face 1 has materials label 2, but there are only 2 names"
        );
    }
}
