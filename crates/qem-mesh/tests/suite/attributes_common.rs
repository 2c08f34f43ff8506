//! Helpers of the attribute I/O tests (PLY, OFF, glTF): load, encode, expect an error,
//! build a GLB.

use qem_mesh::io::{read_bytes, write_to, Format, LoadedMesh};
use qem_mesh::IndexedMesh;

/// `bytes` read in `format`; panics with the reader's message when refused.
pub fn load(bytes: &[u8], format: Format) -> LoadedMesh {
    read_bytes(bytes, format).unwrap_or_else(|e| panic!("{format:?} refused: {e}"))
}

/// `mesh` written in `format`.
pub fn encode(mesh: &IndexedMesh, format: Format) -> Vec<u8> {
    let mut out = Vec::new();
    write_to(&mut out, mesh, format).unwrap_or_else(|e| panic!("{format:?} not written: {e}"));
    out
}

/// The reader's message for `bytes`, which must be refused.
pub fn err(bytes: &[u8], format: Format) -> String {
    match read_bytes(bytes, format) {
        Ok(m) => panic!(
            "expected an error, loaded {} triangles",
            m.mesh.triangle_count()
        ),
        Err(e) => e.to_string(),
    }
}

/// A GLB file from a JSON document and a BIN chunk (both padded to four bytes).
pub fn glb(doc: &serde_json::Value, bin: &[u8]) -> Vec<u8> {
    let mut json_text = serde_json::to_vec(doc).unwrap_or_else(|e| panic!("JSON: {e}"));
    json_text.resize(json_text.len().next_multiple_of(4), b' ');
    let mut bin = bin.to_vec();
    bin.resize(bin.len().next_multiple_of(4), 0);
    let total = 12 + 8 + json_text.len() + 8 + bin.len();
    let mut out = Vec::new();
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(json_text.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&json_text);
    out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&bin);
    out
}
