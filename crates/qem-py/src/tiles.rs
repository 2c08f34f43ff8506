//! The tile jobs (`qem_mesh::tiles::jobs`) for the `qem.tiles` module: split a mesh
//! file into a directory of tiles, simplify one tile or every tile not yet done, merge.
//! The same library calls as `qem tiles`, so the same files, byte for byte.
//!
//! Each call releases the GIL while the library reads, simplifies and writes (so tile
//! jobs in threads, such as Dask's, run in parallel). What the library returns (the
//! manifest, a tile's status, the merge report) comes back as a dict with the keys of
//! its JSON file; errors are `QemError`s naming the file, their remedy worded as the
//! Python call to make.

use crate::{qem_error, simplify_options, PyObserver};
use pyo3::exceptions::PyUserWarning;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use qem_mesh::simplify::{Observer, SimplifyOptions};
use qem_mesh::tiles::jobs::{
    merge, split, RefusedOption, Remedy, TileCount, TileDir, TileOptions, TileStatus, TileWork,
    TilesError, ATTRIBUTES_DROPPED,
};
use std::path::{Path, PathBuf};

/// Asks Python whether Ctrl-C was pressed each time the library asks whether to stop
/// (before each tile of a split or a merge); the `KeyboardInterrupt` is kept and
/// raised once the library has returned.
struct Interrupts {
    error: Option<PyErr>,
}

impl Observer for Interrupts {
    fn should_stop(&mut self) -> bool {
        if self.error.is_none() {
            self.error = Python::attach(|py| py.check_signals().err());
        }
        self.error.is_some()
    }

    fn wants_contractions(&self) -> bool {
        false
    }
}

/// `value` (one of the library's serialisable results) as a Python object with the
/// keys of its JSON file: through `json.loads`, so the dict is exactly the file's.
fn to_python<'py>(py: Python<'py>, value: &impl serde::Serialize) -> PyResult<Bound<'py, PyAny>> {
    let text = serde_json::to_string(value)
        .map_err(|e| qem_error(format!("internal error, please report: {e}")))?;
    py.import("json")?.call_method1("loads", (text,))
}

/// A `UserWarning` pointing at the caller of the `qem.tiles` function (stack level 2:
/// past the wrapper in qem/tiles.py).
fn warn(py: Python<'_>, message: String) -> PyResult<()> {
    // A message with a NUL (from a path) is not worth failing the job for.
    match std::ffi::CString::new(message) {
        Ok(message) => PyErr::warn(py, &py.get_type::<PyUserWarning>(), &message, 2),
        Err(_) => Ok(()),
    }
}

/// The error for an option the tiles do not take, named as the keyword argument.
fn refused(option: RefusedOption) -> PyErr {
    let name = match option {
        RefusedOption::TriangleTarget => "triangles",
        RefusedOption::LockedVertices => "locked_vertices",
        RefusedOption::Clustering => "method='clustering'",
        RefusedOption::VirtualPairs => "pair_threshold above 0",
        _ => "one of these options",
    };
    qem_error(format!(
        "qem.tiles.simplify does not take {name}: {}",
        option.reason()
    ))
}

/// `error` as a Python exception, its remedy worded as the call to make on `directory`;
/// `interrupt` (a `KeyboardInterrupt` noticed meanwhile) comes first.
fn tiles_error(error: TilesError, directory: &Path, interrupt: Option<PyErr>) -> PyErr {
    if let Some(e) = interrupt {
        return e;
    }
    let remedy = match error.remedy() {
        Some(Remedy::Split) => {
            format!("; split a mesh into it first: qem.tiles.split(input, {directory:?})")
        }
        Some(Remedy::SimplifyTile(k)) => {
            format!("; run qem.tiles.simplify({directory:?}, tile={k}, ...)")
        }
        _ => String::new(),
    };
    match error {
        TilesError::Refused(option) => refused(option),
        e => qem_error(format!("{e}{remedy}")),
    }
}

/// A positive whole number argument.
fn positive(name: &str, value: Option<i64>) -> PyResult<Option<usize>> {
    match value {
        None => Ok(None),
        Some(n) if n >= 1 => Ok(usize::try_from(n).ok()),
        Some(n) => Err(qem_error(format!(
            "{name} must be a whole number above 0, not {n}"
        ))),
    }
}

/// The tile options that keyword arguments ask for: those of `qem.simplify` (a ratio,
/// no triangle count, no locked vertices, no clustering, no virtual pairs).
fn tile_options(options: Option<&Bound<'_, PyDict>>, function: &str) -> PyResult<TileOptions> {
    let options: SimplifyOptions = simplify_options(options, function, &[])?;
    TileOptions::new(options).map_err(refused)
}

/// Cuts a mesh file into spatial tiles in a directory; returns the manifest as a dict.
/// See qem/tiles.py.
#[pyfunction]
#[pyo3(signature = (input, directory, *, tile_triangles=None, tiles=None))]
pub fn tiles_split(
    py: Python<'_>,
    input: PathBuf,
    directory: PathBuf,
    tile_triangles: Option<i64>,
    tiles: Option<i64>,
) -> PyResult<Bound<'_, PyAny>> {
    let count = match (
        positive("tile_triangles", tile_triangles)?,
        positive("tiles", tiles)?,
    ) {
        (Some(_), Some(_)) => return Err(qem_error("give tile_triangles or tiles, not both")),
        (Some(k), None) => TileCount::MaxTriangles(k),
        (None, Some(n)) => TileCount::Tiles(n),
        (None, None) => TileCount::default(),
    };
    let mut observer = Interrupts { error: None };
    let manifest = py
        .detach(|| split(&input, &directory, count, &mut observer))
        .map_err(|e| tiles_error(e, &directory, observer.error.take()))?;
    if manifest.input.attributes_dropped {
        warn(py, format!("{}: {ATTRIBUTES_DROPPED}", input.display()))?;
    }
    to_python(py, &manifest)
}

/// A tile's status as a dict, with `already_done`.
fn status_dict<'py>(
    py: Python<'py>,
    status: &TileStatus,
    already_done: bool,
) -> PyResult<Bound<'py, PyAny>> {
    let dict = to_python(py, status)?;
    dict.set_item("already_done", already_done)?;
    Ok(dict)
}

/// Simplifies tile `tile` of a split, or every tile not yet done; returns its status
/// (or the list of every tile's). See qem/tiles.py.
#[pyfunction]
#[pyo3(signature = (directory, tile=None, **options))]
pub fn tiles_simplify<'py>(
    py: Python<'py>,
    directory: PathBuf,
    tile: Option<i64>,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyAny>> {
    let options = tile_options(options, "qem.tiles.simplify()")?;
    let tile = tile
        .map(|k| usize::try_from(k).map_err(|_| qem_error(format!("tile must be ≥ 0, not {k}"))))
        .transpose()?;
    let error = |e| tiles_error(e, &directory, None);
    let tiles = py.detach(|| TileDir::open(&directory)).map_err(error)?;
    let statuses = PyList::empty(py);
    for k in tiles.select(tile).map_err(error)? {
        py.check_signals()?;
        let status = match py.detach(|| tiles.prepare(k, &options)).map_err(error)? {
            TileWork::Done(status) => status_dict(py, &status, true)?,
            TileWork::ToDo(pending) => {
                if let Some(crowding) = pending.crowding() {
                    warn(py, format!("qem.tiles.simplify: {crowding}"))?;
                }
                // No callback: the observer passes Ctrl-C on as a stop.
                let mut observer = PyObserver {
                    callback: None,
                    cancelled: false,
                    error: None,
                };
                let status = py
                    .detach(|| pending.run(&mut observer))
                    .map_err(|e| tiles_error(e, &directory, observer.error.take()))?;
                status_dict(py, &status, false)?
            }
        };
        statuses.append(status)?;
    }
    match tile {
        Some(_) => statuses.get_item(0),
        None => Ok(statuses.into_any()),
    }
}

/// Joins the simplified tiles into one mesh file; returns the merge report. See
/// qem/tiles.py.
#[pyfunction]
pub fn tiles_merge(
    py: Python<'_>,
    directory: PathBuf,
    output: PathBuf,
) -> PyResult<Bound<'_, PyAny>> {
    let mut observer = Interrupts { error: None };
    let report = py
        .detach(|| merge(&directory, &output, &mut observer))
        .map_err(|e| tiles_error(e, &directory, observer.error.take()))?;
    to_python(py, &report)
}

/// The fingerprint a tile's status records for these options; raises for options the
/// tiles do not take. See qem/tiles.py.
#[pyfunction]
#[pyo3(signature = (**options))]
pub fn tiles_fingerprint(options: Option<&Bound<'_, PyDict>>) -> PyResult<String> {
    Ok(tile_options(options, "qem.tiles.fingerprint()")?
        .fingerprint()
        .to_string())
}
