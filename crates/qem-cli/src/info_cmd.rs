//! `qem info`: what is messy about a mesh, as text or JSON. The counting is
//! `qem_mesh::inspect`; this module only loads and prints.

use crate::failure::{print_stdout, Failure};
use crate::report::InfoJson;
use clap::Args;
use qem_mesh::inspect::{inspect, MeshInfo};
use qem_mesh::io::read_path;
use std::path::PathBuf;

/// The definitions printed by `qem info --help`; the same as `qem_mesh::inspect`'s.
pub const DEFINITIONS: &str = "\
Counts are taken after merging vertices with bit-identical positions (as the simplifier \
does first), so an STL soup or an OBJ split into groups is not all open edges. Faces that \
then use a vertex twice have no edges and are left out of the topology; zero-area and \
duplicate faces are kept in it.

  vertices, triangles     as loaded (the OBJ reader drops vertices no face uses)
  welded_vertices         vertices merged into an earlier one with the same position
  unreferenced_vertices   vertices (after merging) that no face uses
  components              groups of faces connected through shared vertices
  boundary_edges          edges (vertex pairs) used by exactly one face
  boundary_loops          groups of boundary edges connected through shared vertices
  nonmanifold_edges       edges used by three or more faces (each copy of a duplicate \
face counts)
  nonmanifold_vertices    vertices whose faces form more than one fan (faces at v are in \
one fan when they connect through edges at v): bow-ties, umbrellas; vertices on \
non-manifold edges are not counted unless they are also pinched
  duplicate_faces         faces with the same three vertices as an earlier face, in any \
order
  degenerate_faces        faces with a repeated vertex (after merging) or an area at most \
1e-14 x the squared bounding-box diagonal
  bbox, bbox_diagonal     axis-aligned box of the vertices faces use, in model units";

/// Arguments of `qem info`.
#[derive(Args, Debug)]
pub struct InfoArgs {
    /// Input mesh (.obj .ply .stl .off .gltf .glb, optionally .gz).
    pub input: PathBuf,
    /// Print one JSON object (keys as listed below, plus input, bbox_min, bbox_max)
    /// instead of text [default: text].
    #[arg(long)]
    pub json: bool,
}

/// Runs `qem info`.
pub fn run(args: &InfoArgs) -> Result<(), Failure> {
    let loaded = read_path(&args.input).map_err(|e| Failure::Failed(e.to_string()))?;
    let info = inspect(&loaded.mesh)
        .map_err(|e| Failure::Failed(format!("{}: {e}", args.input.display())))?;
    if args.json {
        let json = serde_json::to_string_pretty(&InfoJson::new(&args.input, &info))
            .map_err(|e| Failure::Failed(format!("cannot format the JSON: {e}")))?;
        print_stdout(&format!("{json}\n")).map_err(Failure::Failed)
    } else {
        print_stdout(&text(&args.input.display().to_string(), &info)).map_err(Failure::Failed)
    }
}

fn text(name: &str, i: &MeshInfo) -> String {
    let [x0, y0, z0] = i.bbox_min;
    let [x1, y1, z1] = i.bbox_max;
    let rows = [
        ("file", name.to_string()),
        ("vertices", i.vertices.to_string()),
        ("triangles", i.triangles.to_string()),
        ("welded vertices", i.welded_vertices.to_string()),
        ("unreferenced vertices", i.unreferenced_vertices.to_string()),
        ("components", i.components.to_string()),
        ("boundary edges", i.boundary_edges.to_string()),
        ("boundary loops", i.boundary_loops.to_string()),
        ("non-manifold edges", i.nonmanifold_edges.to_string()),
        ("non-manifold vertices", i.nonmanifold_vertices.to_string()),
        ("duplicate faces", i.duplicate_faces.to_string()),
        ("degenerate faces", i.degenerate_faces.to_string()),
        ("bbox min", format!("{x0} {y0} {z0}")),
        ("bbox max", format!("{x1} {y1} {z1}")),
        ("bbox diagonal", i.bbox_diagonal.to_string()),
    ];
    rows.iter().map(|(k, v)| format!("{k:<23}{v}\n")).collect()
}
