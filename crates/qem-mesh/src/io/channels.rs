//! What the PLY and OFF readers and writers share about attribute channels: which
//! channels are per face, and integer colour levels as floats.

use std::borrow::Cow;

use crate::attributes::{split_at_seams, Attributes, Channel, ChannelKind};
use crate::IndexedMesh;

/// A mesh as a writer writes it: positions, triangles and the channels it writes per
/// vertex, with one value per vertex (value `v` is vertex `v`'s).
pub(crate) struct PerVertex<'m> {
    pub(crate) positions: Cow<'m, [[f64; 3]]>,
    pub(crate) triangles: Cow<'m, [[u32; 3]]>,
    pub(crate) channels: Vec<Channel>,
}

/// `mesh` with `channels` (those a writer writes per vertex) one value per vertex.
/// Channels the writer leaves out or writes per face are not passed, so they do not
/// split vertices. Channels already per vertex (what the PLY and OFF readers make) are
/// kept as they are, so vertices no triangle uses keep their values; otherwise the
/// mesh is split at the channels' seams ([`split_at_seams`]), which keeps the
/// triangles' order.
pub(crate) fn per_vertex(mesh: &IndexedMesh, channels: Vec<Channel>) -> PerVertex<'_> {
    let n = mesh.positions.len();
    if channels
        .iter()
        .all(|c| c.corners == mesh.triangles && c.value_count() == n)
    {
        return PerVertex {
            positions: Cow::Borrowed(&mesh.positions),
            triangles: Cow::Borrowed(&mesh.triangles),
            channels,
        };
    }
    let only = IndexedMesh::new(mesh.positions.clone(), mesh.triangles.clone()).with_attributes(
        Attributes {
            channels,
            ..Attributes::default()
        },
    );
    let split = split_at_seams(&only);
    PerVertex {
        positions: Cow::Owned(split.positions),
        triangles: Cow::Owned(split.triangles),
        channels: split.attributes.channels,
    }
}

/// Whether `c` is a colour with one value per triangle (all three corners of every
/// triangle use the same value, or none): PLY and OFF write it on the face element
/// rather than splitting every vertex per face. Reading a file's face colours gives
/// such a channel back, so it survives the round trip without new vertices.
pub(crate) fn is_face_colour(c: &Channel) -> bool {
    c.kind == ChannelKind::Color && c.corners.iter().all(|&[a, b, d]| a == b && b == d)
}

/// Which of `channels` PLY and OFF write on the faces: the colours with one value per
/// triangle ([`is_face_colour`]), except that when every colour has one value per
/// triangle and there are two or more, the first goes on the vertices.
///
/// Why: a vertex colour also has one value per triangle when every triangle repeats one
/// vertex (a file of degenerate faces `3 0 0 0`), and then the file's vertex and face
/// colours looked alike; the first took the face slot and the second was left out (a
/// read_off finding). The readers put the vertex colour first, so each goes back where
/// it came from; and in any mesh a second such colour is written (per vertex) rather
/// than left out.
pub(crate) fn colours_on_faces(channels: &[Channel]) -> Vec<bool> {
    let mut on_face: Vec<bool> = channels.iter().map(is_face_colour).collect();
    let colours: Vec<usize> = (0..channels.len())
        .filter(|&i| channels[i].kind == ChannelKind::Color)
        .collect();
    if colours.len() >= 2 && colours.iter().all(|&i| on_face[i]) {
        on_face[colours[0]] = false;
    }
    on_face
}

/// An integer colour level `level` out of `max` (255 for `uchar`) as a float in 0–1.
/// The writers use the same function to check that a float is exactly a level, so
/// `uchar` colours read back bit-exact.
pub(crate) fn from_level(level: f64, max: f64) -> f32 {
    (level / max) as f32
}

/// A file's colours in 0–1, for the formats that do not say whether they hold 0–1
/// floats or 0–255 levels (OBJ's `v x y z r g b`, OFF): levels when any component is
/// above 1, since 0–1 colours never are, and floats otherwise; a file's colours either
/// all are levels or none is, so one dark colour cannot be read differently from the
/// others. Then every finite component is clamped to 0–1: one still outside (a level
/// above 255, a negative value) could not be written back in these formats, where a
/// value above 1 makes every colour of the file a level when it is read again. NaN and
/// infinities (`1e39` is one in `f32`) are left for the reader to refuse, with the
/// line, as it refuses them in coordinates.
pub(crate) fn unit_colours(colours: &mut [f32]) {
    let levels = colours.iter().any(|&c| c > 1.0);
    for c in colours.iter_mut() {
        if levels {
            *c = from_level(f64::from(*c), 255.0);
        }
        if c.is_finite() {
            *c = c.clamp(0.0, 1.0);
        }
    }
}

/// The `uchar` level of a colour component: `round(v * 255)`, clamped to 0–255.
pub(crate) fn to_level(v: f32) -> u8 {
    // The cast saturates (NaN gives 0), so out-of-range values are clamped.
    (f64::from(v) * 255.0).round() as u8
}

/// Whether every component of `values` is exactly a `uchar` level (`k / 255` as
/// [`from_level`] makes it): then `uchar` is lossless, otherwise floats must be written.
pub(crate) fn all_levels(values: &[f32]) -> bool {
    values
        .iter()
        .all(|&v| from_level(f64::from(to_level(v)), 255.0).to_bits() == v.to_bits())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_uchar_level_survives_the_float_form() {
        for k in 0..=255u8 {
            let v = from_level(f64::from(k), 255.0);
            assert_eq!(to_level(v), k);
            assert!(all_levels(&[v]));
        }
        assert!(!all_levels(&[0.3]));
        assert!(!all_levels(&[1.5]));
        assert!(!all_levels(&[-0.0]));
        assert_eq!(to_level(2.0), 255);
        assert_eq!(to_level(-1.0), 0);
    }

    #[test]
    fn colours_are_levels_when_one_is_above_1_and_end_in_0_to_1() {
        let mut floats = [0.5, -0.25, 1.0];
        unit_colours(&mut floats);
        assert_eq!(floats, [0.5, 0.0, 1.0]);
        let mut levels = [255.0, 300.0, -3.0, 51.0];
        unit_colours(&mut levels);
        assert_eq!(levels, [1.0, 1.0, 0.0, from_level(51.0, 255.0)]);
        let mut non_finite = [f32::NAN, f32::INFINITY, 0.5];
        unit_colours(&mut non_finite);
        assert!(non_finite[0].is_nan());
        assert_eq!(non_finite[1..], [f32::INFINITY, from_level(0.5, 255.0)]);
    }
}
