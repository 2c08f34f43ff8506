//! JSON reports, written atomically. Field names are the documented JSON keys.

use crate::materials::MaterialFilesJson;
use qem_mesh::attributes::Attributes;
use qem_mesh::inspect::MeshInfo;
use qem_mesh::io::{unwritable, Format, ReadNotes};
use qem_mesh::simplify::SimplifyReport;
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::Path;
use std::time::Duration;

/// The report of one `qem simplify` run (and of each file of `qem batch`).
#[derive(Serialize, Debug, Clone)]
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
    /// Contractions refused, by reason: `degenerate`, `flip`, `sliver`, `topology`,
    /// `locked`, `border`, `merge`, `orientation`, `last_triangles`, `seam`.
    rejected: BTreeMap<&'static str, usize>,
    /// The steps of the ladder of relaxations the run climbed (none unless it got
    /// stuck), in order, each with the contractions made under it.
    relaxations: Vec<RelaxationJson>,
    /// With `stop_reason` `no_valid_pair`: what stopped the run (`strict`,
    /// `preserve_topology`, `locks`, `locked_boundary`, `zero_area`, `last_triangles`,
    /// `seams`, `no_pairs`); null otherwise.
    stopped_by: Option<&'static str>,
    /// Vertices locked (by --lock or --lock-boundary).
    locked_vertices: usize,
    /// Output faces whose normal points away from their input face (0 unless the
    /// fold-over check is off).
    faces_flipped: usize,
    /// Faces facing away from the input turned back by an edge flip after the run.
    faces_turned_back: usize,
    /// What the reader passed over (issue 33): `skipped_lines`, `skipped_properties`,
    /// `skipped_primitives`, `non_utf8_lines`, `byte_order_mark`.
    read_notes: ReadNotesJson,
    /// The attribute channels and labels of the input that the output file carries,
    /// and those it does not, each with the reason.
    attributes: AttributesJson,
    /// The files the output's material libraries name, copied from beside the input
    /// (`copied`, `already_there`, `not_copied` with the reason); empty unless the
    /// output is an OBJ with material libraries written to another directory.
    material_files: MaterialFilesJson,
    /// With `--memory-budget`: the budget, how many triangles it holds in core, and
    /// the rounds of tiles that ran before the in-core finish (none when the input
    /// fitted); absent otherwise. After rounds of tiles, `max_error` and the counts
    /// other than `triangles_in` and `vertices_in` are the finish's, from the merged tiles.
    #[serde(skip_serializing_if = "Option::is_none")]
    memory_budget: Option<MemoryBudgetJson>,
    timings_ms: BTreeMap<&'static str, f64>,
}

/// A run under `--memory-budget` (see [`qem_mesh::tiles::budget`]).
#[derive(Serialize, Debug, Clone)]
pub struct MemoryBudgetJson {
    budget_bytes: u64,
    in_core_triangles: usize,
    rounds: Vec<BudgetRoundJson>,
}

/// One round of tiles of a run under `--memory-budget`.
#[derive(Serialize, Debug, Clone)]
pub struct BudgetRoundJson {
    triangles_in: usize,
    tiles: usize,
    tile_ratio: f64,
    triangles_out: usize,
    attributes_dropped: bool,
}

impl MemoryBudgetJson {
    /// The budget section of `run`'s report.
    pub fn new(run: &qem_mesh::tiles::budget::BudgetRun) -> Self {
        MemoryBudgetJson {
            budget_bytes: run.budget,
            in_core_triangles: run.room,
            rounds: run
                .rounds
                .iter()
                .map(|r| BudgetRoundJson {
                    triangles_in: r.triangles_in,
                    tiles: r.tiles,
                    tile_ratio: r.tile_ratio,
                    triangles_out: r.triangles_out,
                    attributes_dropped: r.attributes_dropped,
                })
                .collect(),
        }
    }

    /// Whether rounds of tiles ran (the input did not fit).
    pub fn tiled(&self) -> bool {
        !self.rounds.is_empty()
    }

    /// `2 rounds of tiles (12, 2 tiles) within the memory budget` for the summary
    /// line, or nothing when the input fitted.
    fn summary(&self) -> Option<String> {
        if self.rounds.is_empty() {
            return None;
        }
        let tiles: Vec<String> = self.rounds.iter().map(|r| r.tiles.to_string()).collect();
        let (n, s) = (
            self.rounds.len(),
            if self.rounds.len() == 1 { "" } else { "s" },
        );
        Some(format!(
            "{n} round{s} of tiles ({} tiles) within the memory budget",
            tiles.join(", ")
        ))
    }
}

/// What became of the input's attributes (issue 29): `carried` names the channels
/// (`uv`, `normal`, `colour`, ...) and labels (`materials`, `groups`, `material
/// libraries`) the output file holds; `dropped` the others, with the reason.
#[derive(Serialize, Debug, Clone, Default)]
pub struct AttributesJson {
    carried: Vec<String>,
    dropped: Vec<DroppedJson>,
}

/// An attribute the output does not carry, and why.
#[derive(Serialize, Debug, Clone)]
pub struct DroppedJson {
    what: String,
    reason: String,
}

impl AttributesJson {
    /// What became of the input's attributes (`input`, their names as
    /// [`Attributes::names`] gives them) in the simplified mesh's `output`, written
    /// in `format`; `lost` is why one the simplification did not keep is missing (only
    /// vertex clustering and tiles keep positions alone).
    pub fn new(input: Vec<String>, output: &Attributes, format: Format, lost: &str) -> Self {
        let kept = output.names();
        let not_written = unwritable(output, format);
        let mut json = AttributesJson::default();
        for what in input {
            if !kept.contains(&what) {
                json.dropped.push(DroppedJson {
                    what,
                    reason: lost.to_string(),
                });
            } else if let Some(u) = not_written.iter().find(|u| u.what == what) {
                json.dropped.push(DroppedJson {
                    what,
                    reason: u.reason.to_string(),
                });
            } else {
                json.carried.push(what);
            }
        }
        json
    }

    /// `carried: uv, normal; dropped: colour (STL holds positions only)`, or `None`
    /// when the input had no attributes.
    pub fn summary(&self) -> Option<String> {
        if self.carried.is_empty() && self.dropped.is_empty() {
            return None;
        }
        let dropped: Vec<String> = self
            .dropped
            .iter()
            .map(|d| format!("{} ({})", d.what, d.reason))
            .collect();
        Some(format!(
            "attributes carried: {}; dropped: {}",
            if self.carried.is_empty() {
                "none".to_string()
            } else {
                self.carried.join(", ")
            },
            if dropped.is_empty() {
                "none".to_string()
            } else {
                dropped.join(", ")
            },
        ))
    }
}

/// A step of the ladder of relaxations the run climbed.
#[derive(Serialize, Debug, Clone, Copy)]
pub struct RelaxationJson {
    step: &'static str,
    contractions: usize,
}

/// [`ReadNotes`] as JSON.
#[derive(Serialize, Debug, Clone, Copy, Default)]
pub struct ReadNotesJson {
    skipped_lines: usize,
    skipped_properties: usize,
    skipped_primitives: usize,
    non_utf8_lines: usize,
    byte_order_mark: bool,
}

impl From<ReadNotes> for ReadNotesJson {
    fn from(n: ReadNotes) -> Self {
        ReadNotesJson {
            skipped_lines: n.skipped_lines,
            skipped_properties: n.skipped_properties,
            skipped_primitives: n.skipped_primitives,
            non_utf8_lines: n.non_utf8_lines,
            byte_order_mark: n.byte_order_mark,
        }
    }
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

impl SimplifyJson {
    /// Collects the report of a run with its file names, what the reader passed over
    /// and the CLI's own timings.
    pub fn new(
        input: &Path,
        output: &Path,
        r: &SimplifyReport,
        notes: ReadNotes,
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
            rejected: BTreeMap::from(r.rejected.named()),
            relaxations: r
                .relaxations
                .iter()
                .map(|x| RelaxationJson {
                    step: x.step.as_str(),
                    contractions: x.contractions,
                })
                .collect(),
            stopped_by: r.stopped_by.map(|c| c.as_str()),
            locked_vertices: r.locked_vertices,
            faces_flipped: r.faces_flipped,
            faces_turned_back: r.faces_turned_back,
            read_notes: notes.into(),
            attributes: AttributesJson::default(),
            material_files: MaterialFilesJson::default(),
            memory_budget: None,
            timings_ms,
        }
    }

    /// The report of a run under `--memory-budget`, with the input's counts (the
    /// finish's own report starts from the merged tiles).
    pub fn with_memory_budget(
        mut self,
        budget: MemoryBudgetJson,
        (triangles_in, vertices_in): (usize, usize),
    ) -> Self {
        self.triangles_in = triangles_in;
        self.vertices_in = vertices_in;
        self.memory_budget = Some(budget);
        self
    }

    /// The report with what became of the input's attributes.
    pub fn with_attributes(mut self, attributes: AttributesJson) -> Self {
        self.attributes = attributes;
        self
    }

    /// The report with what became of the files the output's materials name.
    pub fn with_material_files(mut self, material_files: MaterialFilesJson) -> Self {
        self.material_files = material_files;
        self
    }
}

impl SimplifyJson {
    /// Triangles as loaded.
    pub fn triangles_in(&self) -> usize {
        self.triangles_in
    }

    /// Triangles written.
    pub fn triangles_out(&self) -> usize {
        self.triangles_out
    }

    /// One line for the terminal: `in → out: 5856 → 586 triangles, max error 0.4019%
    /// of the bounding-box diagonal (target_reached)`.
    ///
    /// A run that got stuck adds the relaxations it climbed (`; relaxed: fold_over 12,
    /// merged_faces 3`), and one that stopped short with no pair left what stopped it
    /// (`(no_valid_pair: last_triangles)`). A mesh with attributes adds what was
    /// carried and dropped (`; attributes carried: uv; dropped: none`).
    pub fn summary_line(&self) -> String {
        let stop = match self.stopped_by {
            Some(by) => format!("{}: {by}", self.stop_reason),
            None => self.stop_reason.to_string(),
        };
        let relaxed = if self.relaxations.is_empty() {
            String::new()
        } else {
            let steps: Vec<String> = self
                .relaxations
                .iter()
                .map(|r| format!("{} {}", r.step, r.contractions))
                .collect();
            format!("; relaxed: {}", steps.join(", "))
        };
        let budget = self
            .memory_budget
            .as_ref()
            .and_then(MemoryBudgetJson::summary);
        let attributes: String = [
            budget,
            self.attributes.summary(),
            self.material_files.summary(),
        ]
        .into_iter()
        .flatten()
        .map(|s| format!("; {s}"))
        .collect();
        format!(
            "{} → {}: {} → {} triangles, max error {:.4}% of the bounding-box diagonal ({stop}){relaxed}{attributes}",
            self.input,
            self.output,
            self.triangles_in,
            self.triangles_out,
            self.max_error * 100.0,
        )
    }
}

/// One level of `qem simplify --lods`.
#[derive(Serialize, Debug)]
pub struct LevelJson {
    /// The level's index, what `{lod}` in the output name expands to.
    pub lod: usize,
    /// The level's target as a fraction of the input's triangles.
    pub ratio: f64,
    /// The run up to this level (counts and `max_error` are cumulative).
    #[serde(flatten)]
    pub run: SimplifyJson,
}

/// The report of `qem simplify --lods`: every level in order.
#[derive(Serialize, Debug)]
pub struct LevelsJson {
    /// The input file.
    pub input: String,
    /// One entry per level.
    pub levels: Vec<LevelJson>,
}

/// One input of `qem batch`: the `qem simplify` report, or why it failed.
#[derive(Serialize, Debug)]
#[serde(untagged)]
pub enum BatchEntry {
    /// The file was simplified and written.
    Done(Box<SimplifyJson>),
    /// An earlier run simplified and wrote it (`--resume`): that run's report, with
    /// `"resumed": true` added.
    Resumed(serde_json::Value),
    /// The file failed; nothing was written for it.
    Failed {
        /// The input file.
        input: String,
        /// Where its output would have gone, when that was decided.
        output: Option<String>,
        /// The one-line cause.
        error: String,
    },
}

/// Totals of a `qem batch` run.
#[derive(Serialize, Debug)]
pub struct BatchSummary {
    /// Inputs found (files named, matched by globs, found in directories).
    pub inputs: usize,
    /// Inputs simplified and written, by this run or (with `--resume`) an earlier one.
    pub succeeded: usize,
    /// Of `succeeded`, the inputs an earlier run completed (`--resume`).
    pub resumed: usize,
    /// Inputs that failed (or were not started because of Ctrl-C).
    pub failed: usize,
    /// Whether Ctrl-C stopped the run.
    pub interrupted: bool,
    /// Worker threads.
    pub jobs: usize,
    /// Temporary files of killed runs removed from the output directories.
    pub stale_temporaries_removed: usize,
    /// Triangles of the succeeded inputs, as loaded.
    pub triangles_in: usize,
    /// Triangles written.
    pub triangles_out: usize,
    /// Wall time of the whole run, from the first load to the last write.
    pub wall_ms: f64,
    /// Input triangles simplified by this run (not the resumed ones) per second of
    /// `wall_ms`.
    pub input_triangles_per_second: f64,
}

/// The report of `qem batch`.
#[derive(Serialize, Debug)]
pub struct BatchJson {
    /// One entry per input, sorted by input path.
    pub inputs: Vec<BatchEntry>,
    /// Files in the given directories that were skipped because their extension is not
    /// a mesh format qem reads (materials, textures, notes...), sorted.
    pub ignored: Vec<String>,
    /// Totals.
    pub summary: BatchSummary,
}

/// The JSON of `qem info --json`.
#[derive(Serialize, Debug)]
pub struct InfoJson {
    input: String,
    vertices: usize,
    triangles: usize,
    welded_vertices: usize,
    unreferenced_vertices: usize,
    components: usize,
    boundary_edges: usize,
    boundary_loops: usize,
    nonmanifold_edges: usize,
    nonmanifold_vertices: usize,
    duplicate_faces: usize,
    degenerate_faces: usize,
    bbox_min: [f64; 3],
    bbox_max: [f64; 3],
    bbox_diagonal: f64,
}

impl InfoJson {
    /// The counts of `info` for the file `input`.
    pub fn new(input: &Path, info: &MeshInfo) -> Self {
        InfoJson {
            input: input.display().to_string(),
            vertices: info.vertices,
            triangles: info.triangles,
            welded_vertices: info.welded_vertices,
            unreferenced_vertices: info.unreferenced_vertices,
            components: info.components,
            boundary_edges: info.boundary_edges,
            boundary_loops: info.boundary_loops,
            nonmanifold_edges: info.nonmanifold_edges,
            nonmanifold_vertices: info.nonmanifold_vertices,
            duplicate_faces: info.duplicate_faces,
            degenerate_faces: info.degenerate_faces,
            bbox_min: info.bbox_min,
            bbox_max: info.bbox_max,
            bbox_diagonal: info.bbox_diagonal,
        }
    }
}

/// Writes `value` as pretty JSON to `path` through a temporary file in the same
/// directory (qem's own, so a killed run's is cleaned up by the next), so a failure
/// never leaves a partial report: `qem_mesh::io::write_json_atomically`, its error as
/// the message to print.
pub fn write_json_atomically(path: &Path, value: &impl Serialize) -> Result<(), String> {
    qem_mesh::io::write_json_atomically(path, value).map_err(|e| e.to_string())
}
