//! The readers are lenient where a format gives bytes no meaning for the geometry
//! (names, comments, unknown keywords and properties, byte order marks, CRLF, tabs) and
//! strict where it does (numbers). Issue 33.
#![cfg(feature = "io")]
#![allow(clippy::unwrap_used)]

use std::path::Path;

use qem_mesh::io::{read_bytes, read_path, Format, LoadedMesh, ReadNotes};
use qem_mesh::IndexedMesh;

fn fixture(name: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures")
        .join(name)
}

fn load(bytes: &[u8], f: Format) -> LoadedMesh {
    read_bytes(bytes, f).unwrap_or_else(|e| panic!("refused: {e}"))
}

fn err(bytes: &[u8], f: Format) -> String {
    match read_bytes(bytes, f) {
        Ok(m) => panic!(
            "expected an error, loaded {} triangles",
            m.mesh.triangle_count()
        ),
        Err(e) => e.to_string(),
    }
}

/// Every triangle as its three corner positions: compares meshes whose vertex
/// numbering differs (tobj numbers vertices per `o`/`g` section).
fn corners(m: &IndexedMesh) -> Vec<[[u64; 3]; 3]> {
    m.triangles
        .iter()
        .map(|t| t.map(|i| m.positions[i as usize].map(f64::to_bits)))
        .collect()
}

fn notes(skipped_lines: usize, skipped_properties: usize, non_utf8: usize, bom: bool) -> ReadNotes {
    let mut n = ReadNotes::default();
    n.skipped_lines = skipped_lines;
    n.skipped_properties = skipped_properties;
    n.non_utf8_lines = non_utf8;
    n.byte_order_mark = bom;
    n
}

/// The fixture of issue 33: an OBJ as a European CAD program writes it, a terrace
/// (`Terraind\xe6k`, "terrace deck" in Danish with a Latin-1 æ) under a pyramid roof,
/// with a UTF-8 byte order mark, CRLF line ends, a Latin-1 comment, `mtllib`, `g` and
/// `usemtl` names in Latin-1, a tab before a material name, `s off`, an unknown
/// `cstype` line and a face continued with `\`.
#[test]
fn latin1_names_bom_and_crlf_load_and_keep_their_names() {
    let path = fixture("latin1_bom_crlf.obj");
    let bytes = std::fs::read(&path).unwrap();
    assert!(bytes.starts_with(b"\xef\xbb\xbf") && bytes.windows(2).any(|w| w == b"\r\n"));
    let loaded = read_path(&path).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(loaded.mesh.triangle_count(), 6);
    // The same geometry as the plain file below: the names and the rest change nothing.
    let plain = b"v 0 0 0\nv 4 0 0\nv 4 3 0\nv 0 3 0\nv 2 1.5 2\n\
                  f 1 3 2\nf 1 4 3\nf 1 2 5\nf 2 3 5\nf 3 4 5\nf 4 1 5\n";
    assert_eq!(
        corners(&loaded.mesh),
        corners(&load(plain, Format::Obj).mesh)
    );

    let obj = &loaded.mesh.attributes;
    assert_eq!(
        obj.groups.names,
        vec![
            b"Bygning".to_vec(),
            b"Terraind\xe6k".to_vec(),
            b"Tag".to_vec()
        ]
    );
    assert_eq!(
        obj.materials.names,
        vec![b"Terraind\xe6k".to_vec(), b"Tagpap_gr\xe5".to_vec()]
    );
    assert_eq!(obj.material_libraries, vec![b"terr\xe6n.mtl".to_vec()]);
    // Which face has which: `o Bygning` holds no face; the tab-separated `usemtl`
    // (which tobj refuses) still names the last four faces' material.
    assert_eq!(obj.groups.faces, vec![1, 1, 2, 2, 2, 2]);
    assert_eq!(obj.materials.faces, vec![0, 0, 1, 1, 1, 1]);
    // Skipped: `s off` and `cstype`. Not UTF-8: the comment, mtllib, g, 2 usemtl.
    assert_eq!(loaded.notes, notes(2, 0, 5, true));
}

#[test]
fn geometry_stays_strict_and_names_its_line() {
    // The fixture's first lines, then a vertex with a Latin-1 byte: line 9 of the file
    // (the BOM and CRLF do not shift the count).
    let mut bad = b"\xef\xbb\xbf# caf\xe9\r\nusemtl Terraind\xe6k\r\n".to_vec();
    bad.extend(b"v 0 0 0\r\nv 1 0 0\r\nv 0 1 0\r\ng \xe6\r\ns 1\r\nf 1 2 3\r\nv 1 \xe6 0\r\n");
    assert_eq!(
        err(&bad, Format::Obj),
        "line 9: not valid UTF-8 text (byte 5 of the line)"
    );
    // A malformed number is an error naming the line, whatever the names around it.
    let bad = b"g Terraind\xe6k\r\nv 0 0 0\r\nv 1 0 0\r\nv 0 1x 0\r\nf 1 2 3\r\n";
    assert_eq!(err(bad, Format::Obj), "line 4: vertex 2: bad number \"1x\"");
    // A face index that is not one, next to a Latin-1 material.
    let bad = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl \xe6\nf 1 2 3a\n";
    assert_eq!(
        err(bad, Format::Obj),
        "line 5: face 0: bad vertex index \"3a\""
    );
}

#[test]
fn obj_unknown_lines_with_any_bytes_are_skipped_and_counted() {
    // A line `tobj` would split at the no-break space into "v 1 2 3": both must skip it
    // (the scan does not know the keyword), or the vertex numbering would differ.
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv\u{a0}9 9 9\nx-custom \u{e6}\u{f8}\nf 1 2 3\n";
    let loaded = load(obj.as_bytes(), Format::Obj);
    assert_eq!(
        loaded.mesh.positions,
        vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]
    );
    assert_eq!(loaded.notes, notes(2, 0, 0, false));
    // Bytes that are not text at all on an unknown line, and a bare usemtl.
    let obj = b"v 0 0 0\nv 1 0 0\nv 0 1 0\n\xfe\xff junk \x80\nusemtl\nf 1 2 3\n";
    let loaded = load(obj, Format::Obj);
    assert_eq!(loaded.mesh.triangle_count(), 1);
    assert_eq!(loaded.notes, notes(1, 0, 1, false));
    assert!(loaded.mesh.attributes.materials.names.is_empty());
}

#[test]
fn ply_header_with_latin1_bom_unknown_keywords_and_properties() {
    let mut ply = b"\xef\xbb\xbfply\r\nformat ascii 1.0\r\ncomment Terraind\xe6k\r\n".to_vec();
    ply.extend(b"element vertex 3\r\nproperty float x\r\nproperty float y\r\n");
    ply.extend(b"property float z\r\nproperty uchar r\xe6d\r\nx_exporter_note v2\r\n");
    ply.extend(b"element face 1\r\nproperty list uchar int vertex_indices\r\n");
    ply.extend(b"element m\xe6rke 1\r\nproperty float w\r\nend_header\r\n");
    ply.extend(b"0 0 0 1\r\n1 0 0 2\r\n0\t1 0 3\r\n3 0 1 2\r\n7\r\n");
    let loaded = load(&ply, Format::Ply);
    assert_eq!(loaded.mesh.triangles, vec![[0, 1, 2]]);
    assert_eq!(loaded.mesh.positions[2], [0.0, 1.0, 0.0]);
    // Skipped: the exporter's line; property w (of another element: r\xe6d is a
    // generic vertex channel); 3 header lines not UTF-8.
    assert_eq!(loaded.notes, notes(1, 1, 3, true));
    let kept = &loaded.mesh.attributes.channels[0];
    assert_eq!(
        (kept.name.as_str(), &kept.values[..]),
        ("r\u{fffd}d", &[1.0, 2.0, 3.0][..])
    );
    // Numbers stay strict.
    let bad = String::from_utf8_lossy(&ply).replace("0\t1 0 3", "0\t1x 0 3");
    assert_eq!(
        err(bad.as_bytes(), Format::Ply),
        "line 17: vertex 2: bad coordinate \"1x\""
    );
}

#[test]
fn off_with_bom_latin1_comments_and_trailing_lines() {
    let off = b"\xef\xbb\xbfOFF\r\n# Terraind\xe6k\r\n3 1 0\r\n0 0 0\r\n1\t0 0\r\n0 1 0\r\n\
                3 0 1 2\r\n# slut \xe6\r\nextra lines\r\n";
    let loaded = load(off, Format::Off);
    assert_eq!(loaded.mesh.triangles, vec![[0, 1, 2]]);
    assert_eq!(loaded.notes, notes(1, 0, 2, true));
}

#[test]
fn ascii_stl_with_bom_latin1_names_and_unknown_words() {
    let stl = b"\xef\xbb\xbfsolid Terraind\xe6k\r\nfacet normal 0 0 1\r\n outer loop\r\n\
                vertex 0 0 0\r\n vertex 1 0 0\r\n vertex 0 1 0\r\n endloop\r\n\
                color 255 0 0\r\nendfacet\r\nendsolid Terraind\xe6k\r\n";
    let loaded = load(stl, Format::Stl);
    assert_eq!(loaded.mesh.triangle_count(), 1);
    assert_eq!(loaded.notes, notes(1, 0, 2, true));
    let bad = String::from_utf8_lossy(stl).replace("vertex 1 0 0", "vertex 1 0x 0");
    assert_eq!(
        err(bad.as_bytes(), Format::Stl),
        "line 5: facet 0, vertex 1: coordinate 1 is \"0x\", not a number"
    );
}

#[test]
fn binary_stl_header_may_start_like_a_byte_order_mark() {
    // 80 header bytes starting with EF BB BF, one triangle: still binary, no BOM noted.
    let mut stl = b"\xef\xbb\xbfsolid binary".to_vec();
    stl.resize(80, b' ');
    stl.extend(1u32.to_le_bytes());
    for v in [[0f32, 0., 1.], [0., 0., 0.], [1., 0., 0.], [0., 1., 0.]] {
        for c in v {
            stl.extend(c.to_le_bytes());
        }
    }
    stl.extend([0, 0]);
    let loaded = load(&stl, Format::Stl);
    assert_eq!(loaded.mesh.triangle_count(), 1);
    assert!(loaded.notes.is_empty());
}

#[test]
fn clean_files_note_nothing() {
    let obj = b"# plain\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\nf 1 2 3\n";
    assert!(load(obj, Format::Obj).notes.is_empty());
    let off = b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    assert!(load(off, Format::Off).notes.is_empty());
}
