//! `read_obj`, `read_ply`, `read_stl`, `read_off`, `read_gltf`: arbitrary bytes through a
//! reader.

use qem_mesh::attributes::ChannelKind;
use qem_mesh::io::{
    read_bytes, stream_bytes, write_to, Format, IoError, StreamBytesError, TriangleSink,
};
use qem_mesh::IndexedMesh;

/// `read_obj`: see [`read_checked`].
pub fn read_obj(data: &[u8]) {
    read_checked(data, Format::Obj);
}

/// `read_ply`: see [`read_checked`].
pub fn read_ply(data: &[u8]) {
    read_checked(data, Format::Ply);
}

/// `read_stl`: see [`read_checked`].
pub fn read_stl(data: &[u8]) {
    read_checked(data, Format::Stl);
}

/// `read_off`: see [`read_checked`].
pub fn read_off(data: &[u8]) {
    read_checked(data, Format::Off);
}

/// `read_gltf`: bytes that start with the GLB magic `glTF` are read and written back as
/// `.glb`, any others as `.gltf` (JSON). The reader itself goes by the content, so the
/// choice only decides which container the round trip writes; see [`read_checked`].
pub fn read_gltf(data: &[u8]) {
    let format = if data.starts_with(b"glTF") {
        Format::Glb
    } else {
        Format::Gltf
    };
    read_checked(data, format);
}

/// Every triangle a streaming read hands on, as its corners' bits.
#[derive(Default)]
struct Collect(Vec<[[u64; 3]; 3]>);

impl TriangleSink for Collect {
    fn triangle(&mut self, corners: [[f64; 3]; 3]) -> Result<(), IoError> {
        self.0.push(corners.map(|p| p.map(f64::to_bits)));
        Ok(())
    }
}

/// A streaming read of `data` ([`stream_bytes`]) fails exactly when [`read_bytes`]
/// fails, with the same message, and otherwise hands on the mesh's triangles (in its
/// order but for triangles that waited for their vertices) and its counts.
fn streamed_as_read(data: &[u8], format: Format) {
    let mut sink = Collect::default();
    let streamed = stream_bytes(data, format, &mut sink);
    match (read_bytes(data, format), streamed) {
        (Ok(loaded), Ok(streamed)) => {
            let mesh = &loaded.mesh;
            let mut expected: Vec<[[u64; 3]; 3]> = mesh
                .triangles
                .iter()
                .map(|t| t.map(|v| mesh.positions[v as usize].map(f64::to_bits)))
                .collect();
            let mut got = sink.0;
            if got != expected {
                got.sort_unstable();
                expected.sort_unstable();
                assert!(got == expected, "streamed triangles differ");
            }
            assert_eq!(streamed.triangles, mesh.triangle_count());
            assert_eq!(streamed.vertices, mesh.vertex_count());
            assert_eq!(streamed.attributes, mesh.attributes.names());
        }
        (Err(read), Err(StreamBytesError::Read(stream))) => {
            assert_eq!(stream.to_string(), read.to_string());
        }
        (read, streamed) => panic!(
            "read {:?} but streamed {:?}",
            read.map(|l| l.mesh.triangle_count()),
            streamed.map(|s| s.triangles)
        ),
    }
}

/// Arbitrary bytes give a mesh that passes validation or an error whose message is one
/// non-empty line; never a panic. (Memory: libFuzzer's `-rss_limit_mb` and
/// `-malloc_limit_mb` turn an allocation blow-up into a crash, see FUZZING.md.)
///
/// A mesh that was read is written back in the same format (STL and glTF refuse
/// coordinates beyond float32, the one accepted write error) and read again, and must
/// come back as the same triangles with the same attributes (`Face`):
/// - OBJ, PLY and OFF: the same indices and position bits, and face by face the same
///   channel values at each corner, material and group; OBJ also the same material
///   libraries;
/// - STL, which has no shared vertices and `float32` coordinates: the same corner
///   positions rounded to f32, triangle by triangle (an ASCII facet with more than
///   three vertices is fanned into triangles that share them, and comes back as
///   separate triangles);
/// - glTF, which writes `float32` positions, splits vertices at seams and orders the
///   faces by group and material: the same faces (corner positions rounded to f32,
///   channel values, material and group) as a multiset.
pub fn read_checked(data: &[u8], format: Format) {
    streamed_as_read(data, format);
    let loaded = match read_bytes(data, format) {
        Ok(loaded) => loaded,
        Err(e) => {
            let message = e.to_string();
            assert!(!message.is_empty(), "empty error message");
            assert!(!message.contains('\n'), "multi-line message: {message:?}");
            return;
        }
    };
    let mesh = loaded.mesh;
    if let Err(e) = mesh.validate() {
        panic!("read an invalid mesh: {e}");
    }
    let float32 = matches!(format, Format::Stl | Format::Gltf | Format::Glb);
    let mut written = Vec::new();
    if let Err(e) = write_to(&mut written, &mesh, format) {
        // The one documented refusal: STL and glTF cannot hold coordinates beyond
        // float32.
        let beyond_f32 = mesh
            .positions
            .iter()
            .flatten()
            .any(|&c| (c as f32).is_infinite());
        assert!(float32 && beyond_f32, "a valid mesh cannot be written: {e}");
        return;
    }
    let again = match read_bytes(&written, format) {
        Ok(again) => again.mesh,
        Err(e) => panic!("cannot read back what was written: {e}"),
    };
    let f32_bits = |c: f64| f64::from(c as f32).to_bits();
    match format {
        Format::Stl => assert_eq!(
            faces(&again, f64::to_bits),
            faces(&mesh, f32_bits),
            "round trip changed triangles"
        ),
        Format::Gltf | Format::Glb => {
            let mut before = faces(&mesh, f32_bits);
            let mut after = faces(&again, f64::to_bits);
            before.sort();
            after.sort();
            assert_eq!(after, before, "round trip changed faces or attributes");
        }
        Format::Obj | Format::Ply | Format::Off => {
            assert_eq!(again.triangles, mesh.triangles, "round trip changed faces");
            let bits = |m: &IndexedMesh| -> Vec<[u64; 3]> {
                m.positions.iter().map(|p| p.map(f64::to_bits)).collect()
            };
            assert_eq!(bits(&again), bits(&mesh), "round trip changed positions");
            assert_eq!(
                faces(&again, f64::to_bits),
                faces(&mesh, f64::to_bits),
                "round trip changed attributes"
            );
            assert_eq!(
                again.attributes.material_libraries, mesh.attributes.material_libraries,
                "round trip changed material libraries"
            );
        }
    }
}

/// What a round trip must keep of one triangle, whatever the numbering of vertices and
/// values: its corners' positions (as bits), its material and group names, and each
/// channel that has a value at one of its corners.
///
/// Channels are compared by what a corner holds, not by their value lists: writers
/// split vertices at seams and readers number values in their own order (`tobj` by
/// first use), and a channel no corner uses is no channel.
#[derive(Debug, PartialEq, Eq, PartialOrd, Ord)]
struct Face {
    positions: [[u64; 3]; 3],
    material: Option<Vec<u8>>,
    group: Option<Vec<u8>>,
    /// Sorted by name (names are unique within a mesh).
    channels: Vec<CornerValues>,
}

/// A channel at one triangle: its name, its kind and the bits of its value at each
/// corner (`None` where a corner has none).
type CornerValues = (String, ChannelKind, [Option<Vec<u32>>; 3]);

/// Every triangle of `mesh` as a [`Face`], in order, positions through `bits`.
fn faces(mesh: &IndexedMesh, bits: impl Fn(f64) -> u64) -> Vec<Face> {
    let a = &mesh.attributes;
    (0..mesh.triangles.len())
        .map(|t| {
            let mut channels: Vec<_> = a
                .channels
                .iter()
                .filter_map(|c| {
                    let at = |k| {
                        c.at_corner(t, k)
                            .map(|v| v.iter().map(|x| x.to_bits()).collect())
                    };
                    let corners = [at(0), at(1), at(2)];
                    corners
                        .iter()
                        .any(Option::is_some)
                        .then(|| (c.name.clone(), c.kind, corners))
                })
                .collect();
            channels.sort();
            Face {
                positions: mesh.triangles[t].map(|i| mesh.positions[i as usize].map(&bits)),
                material: a.materials.of_face(t).map(<[u8]>::to_vec),
                group: a.groups.of_face(t).map(<[u8]>::to_vec),
                channels,
            }
        })
        .collect()
}
