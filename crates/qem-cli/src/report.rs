//! JSON reports, written atomically.

use qem_mesh::simplify::SimplifyReport;
use serde::Serialize;
use std::collections::BTreeMap;
use std::io::Write;
use std::path::Path;
use std::time::Duration;

/// The report of one `qem simplify` run. Field names are the documented JSON keys.
#[derive(Serialize, Debug)]
pub struct SimplifyJson {
    input: String,
    output: String,
    triangles_in: usize,
    triangles_out: usize,
    vertices_in: usize,
    vertices_out: usize,
    target_triangles: usize,
    edge_contractions: usize,
    virtual_contractions: usize,
    virtual_pairs: usize,
    virtual_pairs_capped: usize,
    /// Largest contraction error as a fraction of the bounding-box diagonal
    /// (serde_json writes a non-finite value, possible only for a mesh without extent,
    /// as null).
    max_error: f64,
    /// The same in model units.
    max_error_abs: f64,
    bbox_diagonal: f64,
    stop_reason: &'static str,
    cleanup: BTreeMap<&'static str, usize>,
    degenerate_faces_removed: usize,
    rejected_degenerate: usize,
    timings_ms: BTreeMap<&'static str, f64>,
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

impl SimplifyJson {
    /// Collects the report of a run with its file names and the CLI's own timings.
    pub fn new(
        input: &Path,
        output: &Path,
        r: &SimplifyReport,
        load: Duration,
        simplify: Duration,
        write: Duration,
    ) -> Self {
        let c = &r.cleanup;
        let cleanup = BTreeMap::from([
            ("welded_vertices", c.welded_vertices),
            ("tolerance_welded_vertices", c.tolerance_welded_vertices),
            ("repeated_index_faces", c.repeated_index_faces),
            ("zero_area_faces", c.zero_area_faces),
            ("duplicate_faces", c.duplicate_faces),
            ("unreferenced_vertices", c.unreferenced_vertices),
        ]);
        let t = &r.timings;
        let timings_ms = BTreeMap::from([
            ("load", ms(load)),
            ("simplify", ms(simplify)),
            ("write", ms(write)),
            ("clean", ms(t.clean)),
            ("build", ms(t.build)),
            ("setup", ms(t.setup)),
            ("contract", ms(t.contract)),
            ("compact", ms(t.compact)),
        ]);
        SimplifyJson {
            input: input.display().to_string(),
            output: output.display().to_string(),
            triangles_in: r.triangles_in,
            triangles_out: r.triangles_out,
            vertices_in: r.vertices_in,
            vertices_out: r.vertices_out,
            target_triangles: r.target_triangles,
            edge_contractions: r.edge_contractions,
            virtual_contractions: r.virtual_contractions,
            virtual_pairs: r.virtual_pairs,
            virtual_pairs_capped: r.virtual_pairs_capped,
            max_error: r.max_error,
            max_error_abs: r.max_error_abs,
            bbox_diagonal: r.bbox_diagonal,
            stop_reason: r.stop_reason.as_str(),
            cleanup,
            degenerate_faces_removed: r.degenerate_faces_removed,
            rejected_degenerate: r.rejected_degenerate,
            timings_ms,
        }
    }
}

/// Writes `value` as pretty JSON to `path` through a temporary file in the same
/// directory, so a failure never leaves a partial report.
pub fn write_json_atomically(path: &Path, value: &impl Serialize) -> Result<(), String> {
    let fail =
        |e: &dyn std::fmt::Display| format!("{}: cannot write the report: {e}", path.display());
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let mut tmp = tempfile::NamedTempFile::new_in(dir).map_err(|e| fail(&e))?;
    serde_json::to_writer_pretty(&mut tmp, value).map_err(|e| fail(&e))?;
    tmp.write_all(b"\n").map_err(|e| fail(&e))?;
    tmp.persist(path).map_err(|e| fail(&e.error))?;
    Ok(())
}
