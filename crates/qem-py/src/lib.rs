//! `qem._qem`, the extension module of the `qem` Python package: a thin PyO3 layer over
//! qem-mesh's public API.
//!
//! What it does and nothing more: NumPy arrays in, checked, copied once into an
//! [`IndexedMesh`]; keyword arguments mapped one by one onto the `with_*` setters of
//! [`SimplifyOptions`] (starting from [`SimplifyOptions::DEFAULT`] or
//! [`SimplifyOptions::FAST`]), so an option left out has the library's own default and a
//! change of default in the library reaches Python unchanged; the library call with the
//! GIL released; the output handed to NumPy without a copy where the dtypes allow; the
//! report as a dict with the keys of the CLI's JSON report. Every failure is a Python
//! exception: [`QemError`] (a `ValueError`) for what qem refuses, carrying its message,
//! `TypeError` for arguments of the wrong kind.
//!
//! Attributes (texture coordinates, normals, colours, generic channels, materials) come
//! and go as dicts of per-vertex arrays; the `attributes` module turns them into qem's
//! per-corner channels and back, splitting the output at its seams.
//!
//! The tile jobs of `qem tiles` (`tiles_split`, `tiles_simplify`, `tiles_merge`, the
//! `tiles` module) are the same library calls as the command's, with the GIL released;
//! `python/qem/tiles.py` and `python/qem/distributed.py` (Dask) build on them.
//!
//! The pure-Python part of the package (`python/qem/__init__.py`) re-exports these
//! functions and adds the trimesh helper; `python/qem/__init__.pyi` has the types.

use numpy::ndarray::Array2;
use numpy::prelude::*;
use numpy::{Element, PyArray2, PyUntypedArray};
use pyo3::create_exception;
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyList, PyString, PyTuple};
use qem_mesh::clean::CleanOptions;
use qem_mesh::measure::{MeasureOptions, Measurement};
use qem_mesh::simplify::{
    BoundaryMode, ContractionOrder, Length, Method, Observer, Phase, PlacementMode, Progress,
    QuadricMode, SimplifyOptions, SimplifyReport, Target, VirtualPairs, Weighting,
};
use qem_mesh::IndexedMesh;
use std::path::PathBuf;
use std::time::{Duration, Instant};

mod attributes;
mod tiles;

create_exception!(
    qem,
    QemError,
    PyValueError,
    "Raised when qem refuses its input: an invalid mesh (no triangles, a non-finite \
     coordinate, an index out of range, arrays of the wrong shape or dtype), options it \
     cannot honour, or a file it cannot read or write. The message is qem's own and names \
     the place (vertex, face, file and line). A subclass of ValueError."
);

fn qem_error(message: impl Into<String>) -> PyErr {
    QemError::new_err(message.into())
}

// ---------------------------------------------------------------------------- arrays in

/// The float dtype the vertices came in; the output vertices get the same one.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum FloatKind {
    F32,
    F64,
}

/// The integer dtype the faces came in; the output faces get the same one.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum IndexKind {
    I32,
    I64,
    U32,
    U64,
}

/// Python's way of writing a shape: `(4,)`, `(4, 3)`.
fn shape_text(shape: &[usize]) -> String {
    match shape {
        [n] => format!("({n},)"),
        _ => {
            let parts: Vec<String> = shape.iter().map(|n| n.to_string()).collect();
            format!("({})", parts.join(", "))
        }
    }
}

/// `obj` as a NumPy array: itself when it is one (no copy, whatever its dtype, which the
/// caller checks), else `numpy.asarray(obj, dtype)` so that nested lists work too (with
/// `dtype` given, a list of ints becomes float positions, as a user writing
/// `[[0, 0, 0], ...]` means).
fn as_ndarray<'py>(
    obj: &Bound<'py, PyAny>,
    dtype: Option<&str>,
) -> PyResult<Bound<'py, PyUntypedArray>> {
    if let Ok(array) = obj.cast::<PyUntypedArray>() {
        return Ok(array.clone());
    }
    let converted = obj
        .py()
        .import("numpy")?
        .call_method1("asarray", (obj, dtype))?;
    converted
        .cast_into::<PyUntypedArray>()
        .map_err(|_| PyTypeError::new_err("numpy.asarray did not return an array"))
}

/// Checks that `array` has shape (n, 3), naming it `what` in the error.
fn check_n_by_3(array: &Bound<'_, PyUntypedArray>, what: &str) -> PyResult<usize> {
    match array.shape() {
        [n, 3] => Ok(*n),
        shape => Err(qem_error(format!(
            "{what} must have shape (n, 3), not {}",
            shape_text(shape)
        ))),
    }
}

fn dtype_name(array: &Bound<'_, PyUntypedArray>) -> String {
    array
        .dtype()
        .str()
        .map(|s| s.to_string())
        .unwrap_or_else(|_| "unknown".into())
}

/// Reads (n, 3) rows of `T` in place (any strides) and maps each to `f`'s output.
fn read_rows<T, U>(
    array: &Bound<'_, PyUntypedArray>,
    mut f: impl FnMut(usize, [T; 3]) -> PyResult<U>,
) -> PyResult<Vec<U>>
where
    T: Element + Copy,
{
    let typed = array
        .cast::<PyArray2<T>>()
        .map_err(|e| PyTypeError::new_err(e.to_string()))?;
    let readonly = typed.try_readonly().map_err(|e| qem_error(e.to_string()))?;
    let view = readonly.as_array();
    let mut out = Vec::with_capacity(view.nrows());
    for (i, row) in view.outer_iter().enumerate() {
        // The shape was checked to be (n, 3), so every row has three entries.
        match row.as_slice() {
            Some(&[a, b, c]) => out.push(f(i, [a, b, c])?),
            _ => {
                let mut it = row.iter().copied();
                match (it.next(), it.next(), it.next()) {
                    (Some(a), Some(b), Some(c)) => out.push(f(i, [a, b, c])?),
                    _ => return Err(qem_error(format!("row {i} does not have 3 entries"))),
                }
            }
        }
    }
    Ok(out)
}

/// Vertex positions from an (n, 3) float32 or float64 array (or nested lists).
fn read_vertices(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<(Vec<[f64; 3]>, FloatKind)> {
    let array = as_ndarray(obj, Some("float64"))?;
    check_n_by_3(&array, what)?;
    if array.is_instance_of::<PyArray2<f64>>() {
        Ok((read_rows(&array, |_, p: [f64; 3]| Ok(p))?, FloatKind::F64))
    } else if array.is_instance_of::<PyArray2<f32>>() {
        let rows = read_rows(&array, |_, p: [f32; 3]| Ok(p.map(f64::from)))?;
        Ok((rows, FloatKind::F32))
    } else {
        Err(qem_error(format!(
            "{what} must be float32 or float64, not {}; convert with .astype(numpy.float64)",
            dtype_name(&array)
        )))
    }
}

/// Checks one face's indices against the vertex count.
fn face_indices<T: Into<i128> + Copy>(
    face: usize,
    indices: [T; 3],
    vertex_count: usize,
    what: &str,
) -> PyResult<[u32; 3]> {
    let mut out = [0u32; 3];
    for (slot, &index) in out.iter_mut().zip(indices.iter()) {
        let index: i128 = index.into();
        if index < 0 {
            return Err(qem_error(format!(
                "{what}[{face}] holds the index {index}: indices must be ≥ 0 \
                 (negative indices from the end are not accepted)"
            )));
        }
        if index >= vertex_count as i128 {
            return Err(qem_error(format!(
                "{what}[{face}] refers to vertex {index}, but there are only {vertex_count} vertices"
            )));
        }
        *slot = u32::try_from(index).map_err(|_| {
            qem_error(format!(
                "{what}[{face}] holds the index {index}, above qem's limit of {}",
                u32::MAX
            ))
        })?;
    }
    Ok(out)
}

/// Triangles from an (m, 3) int32, int64, uint32 or uint64 array (or nested lists), each
/// index checked against `vertex_count`.
fn read_faces(
    obj: &Bound<'_, PyAny>,
    vertex_count: usize,
    what: &str,
) -> PyResult<(Vec<[u32; 3]>, IndexKind)> {
    let array = as_ndarray(obj, None)?;
    check_n_by_3(&array, what)?;
    let n = vertex_count;
    if array.is_instance_of::<PyArray2<i32>>() {
        let rows = read_rows(&array, |i, t: [i32; 3]| face_indices(i, t, n, what))?;
        Ok((rows, IndexKind::I32))
    } else if array.is_instance_of::<PyArray2<i64>>() {
        let rows = read_rows(&array, |i, t: [i64; 3]| face_indices(i, t, n, what))?;
        Ok((rows, IndexKind::I64))
    } else if array.is_instance_of::<PyArray2<u32>>() {
        let rows = read_rows(&array, |i, t: [u32; 3]| face_indices(i, t, n, what))?;
        Ok((rows, IndexKind::U32))
    } else if array.is_instance_of::<PyArray2<u64>>() {
        let rows = read_rows(&array, |i, t: [u64; 3]| face_indices(i, t, n, what))?;
        Ok((rows, IndexKind::U64))
    } else {
        Err(qem_error(format!(
            "{what} must be int32, int64, uint32 or uint64, not {}; \
             convert with .astype(numpy.int64)",
            dtype_name(&array)
        )))
    }
}

/// A mesh argument: a `(vertices, faces)` pair, a `(vertices, faces, attributes)`
/// triple (as `load(path, attributes=True)` returns), or any object with `vertices`
/// and `faces` attributes (a `trimesh.Trimesh`, for one). The attributes are read
/// only `with_attributes` (by `save`; `measure` compares surfaces and leaves them).
fn read_mesh(obj: &Bound<'_, PyAny>, name: &str, with_attributes: bool) -> PyResult<IndexedMesh> {
    let (vertices, faces, attributes) = if obj.hasattr("vertices")? && obj.hasattr("faces")? {
        (obj.getattr("vertices")?, obj.getattr("faces")?, None)
    } else if let Ok((v, f, a)) =
        obj.extract::<(Bound<'_, PyAny>, Bound<'_, PyAny>, Bound<'_, PyAny>)>()
    {
        (v, f, Some(a))
    } else {
        let (v, f): (Bound<'_, PyAny>, Bound<'_, PyAny>) = obj.extract().map_err(|_| {
            PyTypeError::new_err(format!(
                "{name} must be a (vertices, faces) pair, a (vertices, faces, attributes) \
                 triple, or have .vertices and .faces, not {}",
                obj.get_type()
                    .name()
                    .map(|n| n.to_string())
                    .unwrap_or_default()
            ))
        })?;
        (v, f, None)
    };
    let (positions, _) = read_vertices(&vertices, &format!("{name} vertices"))?;
    let (triangles, _) = read_faces(&faces, positions.len(), &format!("{name} faces"))?;
    let mut attrs = None;
    if let Some(a) = attributes.filter(|a| with_attributes && !a.is_none()) {
        attrs = Some(attributes::read_attributes(&a, positions.len(), &triangles)?.for_save()?);
    }
    let mesh = IndexedMesh::new(positions, triangles);
    Ok(match attrs {
        Some(a) => mesh.with_attributes(a),
        None => mesh,
    })
}

// --------------------------------------------------------------------------- arrays out

/// An (n, 3) array from rows, handed to NumPy without a copy.
fn owned_array<'py, T: Element>(py: Python<'py>, rows: Vec<[T; 3]>) -> PyResult<Bound<'py, PyAny>> {
    let n = rows.len();
    let array = Array2::from_shape_vec((n, 3), rows.into_flattened())
        .map_err(|e| qem_error(format!("internal error, please report: {e}")))?;
    Ok(PyArray2::from_owned_array(py, array).into_any())
}

fn vertices_out(
    py: Python<'_>,
    positions: Vec<[f64; 3]>,
    kind: FloatKind,
) -> PyResult<Bound<'_, PyAny>> {
    match kind {
        FloatKind::F64 => owned_array(py, positions),
        FloatKind::F32 => {
            let rows: Vec<[f32; 3]> = positions
                .iter()
                // The output lies within reach of float32 input: rounding, not overflow.
                .map(|p| p.map(|c| c as f32))
                .collect();
            owned_array(py, rows)
        }
    }
}

/// Converts output indices into `T`; they are below the input's vertex count, which came
/// in as `T`, so this fails only on a bug.
fn convert_indices<T: TryFrom<u32>>(triangles: &[[u32; 3]]) -> PyResult<Vec<[T; 3]>> {
    triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(T::try_from);
            match (a, b, c) {
                (Ok(a), Ok(b), Ok(c)) => Ok([a, b, c]),
                _ => Err(qem_error(format!(
                    "internal error, please report: output face {t:?} does not fit the input's dtype"
                ))),
            }
        })
        .collect()
}

fn faces_out(
    py: Python<'_>,
    triangles: Vec<[u32; 3]>,
    kind: IndexKind,
) -> PyResult<Bound<'_, PyAny>> {
    match kind {
        IndexKind::U32 => owned_array(py, triangles),
        IndexKind::I32 => owned_array(py, convert_indices::<i32>(&triangles)?),
        IndexKind::I64 => owned_array(py, convert_indices::<i64>(&triangles)?),
        IndexKind::U64 => owned_array(py, convert_indices::<u64>(&triangles)?),
    }
}

// ------------------------------------------------------------------------------ options

/// A number option: finite and ≥ 0 (NaN, negative and infinite values have no meaning
/// for any of them, and the library would quietly clamp some).
fn non_negative(name: &str, value: &Bound<'_, PyAny>) -> PyResult<f64> {
    let v: f64 = value
        .extract()
        .map_err(|_| PyTypeError::new_err(format!("{name} must be a number")))?;
    if v.is_finite() && v >= 0.0 {
        Ok(v)
    } else {
        Err(qem_error(format!(
            "{name} must be a finite number ≥ 0, not {v}"
        )))
    }
}

fn boolean(name: &str, value: &Bound<'_, PyAny>) -> PyResult<bool> {
    value
        .extract()
        .map_err(|_| PyTypeError::new_err(format!("{name} must be True or False")))
}

/// A string option, one of `choices`.
fn choice<'a>(name: &str, value: &Bound<'_, PyAny>, choices: &[&'a str]) -> PyResult<&'a str> {
    let s: String = value.extract().map_err(|_| {
        PyTypeError::new_err(format!("{name} must be one of {}", choices.join(", ")))
    })?;
    choices.iter().copied().find(|&c| c == s).ok_or_else(|| {
        qem_error(format!(
            "{name} must be one of {}, not '{s}'",
            choices.join(", ")
        ))
    })
}

/// The option names `simplify` takes besides the arrays and `progress`, in the order of
/// the fields of [`SimplifyOptions`] (`ratio`/`triangles` for its `target`).
const OPTION_NAMES: &[&str] = &[
    "fast",
    "ratio",
    "triangles",
    "max_error",
    "absolute",
    "pair_threshold",
    "max_virtual_pairs_per_vertex",
    "virtual_pairs",
    "placement",
    "weighting",
    "quadrics",
    "boundary",
    "max_normal_angle",
    "min_triangle_quality",
    "orientation_check",
    "preserve_topology",
    "locked_vertices",
    "clean",
    "order",
    "strict",
    "method",
    "attribute_weights",
];

/// The keys of the `clean` option, the fields of [`CleanOptions`].
const CLEAN_NAMES: &[&str] = &[
    "weld_exact",
    "weld_tolerance",
    "drop_repeated_index",
    "drop_zero_area",
    "drop_duplicates",
    "drop_unreferenced",
];

fn clean_options(value: &Bound<'_, PyAny>) -> PyResult<CleanOptions> {
    let dict = value.cast::<PyDict>().map_err(|_| {
        PyTypeError::new_err(format!(
            "clean must be a dict with some of the keys {}",
            CLEAN_NAMES.join(", ")
        ))
    })?;
    let mut clean = CleanOptions::DEFAULT;
    for (key, value) in dict.iter() {
        let key: String = key.extract()?;
        let name = format!("clean['{key}']");
        clean = match key.as_str() {
            "weld_exact" => clean.with_weld_exact(boolean(&name, &value)?),
            "weld_tolerance" => clean.with_weld_tolerance(if value.is_none() {
                None
            } else {
                Some(non_negative(&name, &value)?)
            }),
            "drop_repeated_index" => clean.with_drop_repeated_index(boolean(&name, &value)?),
            "drop_zero_area" => clean.with_drop_zero_area(boolean(&name, &value)?),
            "drop_duplicates" => clean.with_drop_duplicates(boolean(&name, &value)?),
            "drop_unreferenced" => clean.with_drop_unreferenced(boolean(&name, &value)?),
            _ => {
                return Err(PyTypeError::new_err(format!(
                    "clean has no key '{key}'; the keys are {}",
                    CLEAN_NAMES.join(", ")
                )))
            }
        };
    }
    Ok(clean)
}

/// The library options that the keyword arguments of `simplify` ask for.
///
/// Starts from [`SimplifyOptions::FAST`] with `fast=True`, else from
/// [`SimplifyOptions::DEFAULT`], and applies each argument given through its `with_*`
/// setter; arguments left out keep the preset's value. An unknown keyword is a
/// `TypeError` naming `function` and listing its arguments: `also` (those it takes
/// besides the options) and the options.
fn simplify_options(
    options: Option<&Bound<'_, PyDict>>,
    function: &str,
    also: &[&str],
) -> PyResult<SimplifyOptions> {
    let Some(options) = options else {
        return Ok(SimplifyOptions::DEFAULT);
    };
    let get = |name: &str| options.get_item(name);
    // `fast` chooses the preset and `absolute` the unit of two other options, so both
    // are read before the rest; every other option is independent of the order.
    let fast = match get("fast")? {
        Some(v) => boolean("fast", &v)?,
        None => false,
    };
    let absolute = match get("absolute")? {
        Some(v) => boolean("absolute", &v)?,
        None => false,
    };
    let length = |v: f64| {
        if absolute {
            Length::Absolute(v)
        } else {
            Length::DiagonalFraction(v)
        }
    };
    let mut o = if fast {
        SimplifyOptions::FAST
    } else {
        SimplifyOptions::DEFAULT
    };
    let ratio = get("ratio")?.filter(|v| !v.is_none());
    let triangles = get("triangles")?.filter(|v| !v.is_none());
    match (ratio, triangles) {
        (Some(_), Some(_)) => {
            return Err(qem_error("give ratio or triangles, not both"));
        }
        (Some(r), None) => {
            let r = non_negative("ratio", &r)?;
            if r > 1.0 {
                return Err(qem_error(format!(
                    "ratio must be between 0 and 1 (a fraction of the input's triangles), not {r}"
                )));
            }
            o = o.with_target(Target::Ratio(r));
        }
        (None, Some(n)) => {
            let n: i64 = n
                .extract()
                .map_err(|_| PyTypeError::new_err("triangles must be an int"))?;
            let n = usize::try_from(n)
                .map_err(|_| qem_error(format!("triangles must be ≥ 0, not {n}")))?;
            o = o.with_target(Target::Triangles(n));
        }
        (None, None) => {}
    }
    for (key, value) in options.iter() {
        let key: String = key.extract()?;
        let v = &value;
        o = match key.as_str() {
            "fast" | "absolute" | "ratio" | "triangles" => o,
            "max_error" => o.with_max_error(if v.is_none() {
                None
            } else {
                Some(length(non_negative("max_error", v)?))
            }),
            "pair_threshold" => o.with_pair_threshold(length(non_negative("pair_threshold", v)?)),
            "max_virtual_pairs_per_vertex" => {
                let k: usize = v.extract().map_err(|_| {
                    PyTypeError::new_err("max_virtual_pairs_per_vertex must be an int ≥ 0")
                })?;
                o.with_max_virtual_pairs_per_vertex(k)
            }
            "virtual_pairs" => o.with_virtual_pairs(
                match choice("virtual_pairs", v, &["any", "between_components"])? {
                    "any" => VirtualPairs::Any,
                    _ => VirtualPairs::BetweenComponents,
                },
            ),
            "placement" => o.with_placement(
                match choice(
                    "placement",
                    v,
                    &["optimal", "endpoint_or_midpoint", "solve_first"],
                )? {
                    "optimal" => PlacementMode::Optimal,
                    "endpoint_or_midpoint" => PlacementMode::EndpointOrMidpoint,
                    _ => PlacementMode::SolveFirst,
                },
            ),
            "weighting" => o.with_weighting(if v.is_instance_of::<PyString>() {
                match choice("weighting", v, &["area", "unweighted"])? {
                    "area" => Weighting::Area,
                    _ => Weighting::Unweighted,
                }
            } else {
                Weighting::Mixed(non_negative("weighting", v)?)
            }),
            "quadrics" => o.with_quadrics(match choice("quadrics", v, &["sum", "exact"])? {
                "sum" => QuadricMode::Sum,
                _ => QuadricMode::Exact,
            }),
            "boundary" => o.with_boundary(if v.is_instance_of::<PyString>() {
                match choice("boundary", v, &["free", "locked"])? {
                    "free" => BoundaryMode::Free,
                    _ => BoundaryMode::Locked,
                }
            } else {
                BoundaryMode::Planes(non_negative("boundary", v)?)
            }),
            "max_normal_angle" => o.with_max_normal_angle(non_negative("max_normal_angle", v)?),
            "min_triangle_quality" => {
                let q = non_negative("min_triangle_quality", v)?;
                if q > 1.0 {
                    return Err(qem_error(format!(
                        "min_triangle_quality must be between 0 and 1, not {q}"
                    )));
                }
                o.with_min_triangle_quality(q)
            }
            "orientation_check" => o.with_orientation_check(boolean("orientation_check", v)?),
            "preserve_topology" => o.with_preserve_topology(boolean("preserve_topology", v)?),
            "strict" => o.with_strict(boolean("strict", v)?),
            "method" => o.with_method(match choice("method", v, &["contraction", "clustering"])? {
                "contraction" => Method::Contraction,
                _ => Method::Clustering,
            }),
            "locked_vertices" => o.with_locked_vertices(locked_vertices(v)?),
            "clean" => o.with_clean(clean_options(v)?),
            "attribute_weights" => {
                let preset = o.attribute_weights;
                o.with_attribute_weights(attributes::attribute_weights(v, preset)?)
            }
            "order" => o.with_order(match choice("order", v, &["greedy", "passes"])? {
                "greedy" => ContractionOrder::Greedy,
                _ => ContractionOrder::Passes,
            }),
            _ => {
                return Err(PyTypeError::new_err(format!(
                    "{function} got an unexpected keyword argument '{key}'; the options are \
                     {}",
                    [also, OPTION_NAMES].concat().join(", ")
                )))
            }
        };
    }
    Ok(o)
}

/// `locked_vertices`: any sequence or 1-d array of vertex indices.
fn locked_vertices(value: &Bound<'_, PyAny>) -> PyResult<Vec<u32>> {
    let array = as_ndarray(value, None)?;
    let flat = array.call_method1("reshape", (-1,))?;
    let list: Vec<i128> = flat.call_method0("tolist")?.extract().map_err(|_| {
        PyTypeError::new_err("locked_vertices must be a sequence of vertex indices (ints)")
    })?;
    list.into_iter()
        .map(|i| {
            u32::try_from(i).map_err(|_| {
                qem_error(format!(
                    "locked_vertices holds {i}, which is not a vertex index (0 to {})",
                    u32::MAX
                ))
            })
        })
        .collect()
}

/// The options as keyword arguments: the inverse of [`simplify_options`] (without
/// `fast` and `absolute`; lengths relative to the diagonal come out as plain numbers,
/// absolute ones are refused since one `absolute` flag covers both lengths).
fn options_dict<'py>(py: Python<'py>, o: &SimplifyOptions) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    match o.target {
        Target::Ratio(r) => d.set_item("ratio", r)?,
        Target::Triangles(n) => d.set_item("triangles", n)?,
        Target::None => d.set_item("ratio", 0.0)?,
    }
    let fraction = |l: Length| match l {
        Length::DiagonalFraction(f) => Ok(f),
        Length::Absolute(_) => Err(qem_error("internal error: an absolute length in a preset")),
    };
    d.set_item("max_error", o.max_error.map(fraction).transpose()?)?;
    d.set_item("pair_threshold", fraction(o.pair_threshold)?)?;
    d.set_item(
        "max_virtual_pairs_per_vertex",
        o.max_virtual_pairs_per_vertex,
    )?;
    d.set_item(
        "virtual_pairs",
        match o.virtual_pairs {
            VirtualPairs::Any => "any",
            VirtualPairs::BetweenComponents => "between_components",
        },
    )?;
    d.set_item(
        "placement",
        match o.placement {
            PlacementMode::Optimal => "optimal",
            PlacementMode::EndpointOrMidpoint => "endpoint_or_midpoint",
            PlacementMode::SolveFirst => "solve_first",
        },
    )?;
    match o.weighting {
        Weighting::Area => d.set_item("weighting", "area")?,
        Weighting::Unweighted => d.set_item("weighting", "unweighted")?,
        Weighting::Mixed(s) => d.set_item("weighting", s)?,
    }
    d.set_item(
        "quadrics",
        match o.quadrics {
            QuadricMode::Sum => "sum",
            QuadricMode::Exact => "exact",
        },
    )?;
    match o.boundary {
        BoundaryMode::Free => d.set_item("boundary", "free")?,
        BoundaryMode::Locked => d.set_item("boundary", "locked")?,
        BoundaryMode::Planes(w) => d.set_item("boundary", w)?,
    }
    d.set_item("max_normal_angle", o.max_normal_angle)?;
    d.set_item("min_triangle_quality", o.min_triangle_quality)?;
    d.set_item("orientation_check", o.orientation_check)?;
    d.set_item("preserve_topology", o.preserve_topology)?;
    d.set_item("strict", o.strict)?;
    d.set_item("locked_vertices", o.locked_vertices.clone())?;
    let c = &o.clean;
    let clean = PyDict::new(py);
    clean.set_item("weld_exact", c.weld_exact)?;
    clean.set_item("weld_tolerance", c.weld_tolerance)?;
    clean.set_item("drop_repeated_index", c.drop_repeated_index)?;
    clean.set_item("drop_zero_area", c.drop_zero_area)?;
    clean.set_item("drop_duplicates", c.drop_duplicates)?;
    clean.set_item("drop_unreferenced", c.drop_unreferenced)?;
    d.set_item("clean", clean)?;
    d.set_item(
        "order",
        match o.order {
            ContractionOrder::Greedy => "greedy",
            ContractionOrder::Passes => "passes",
        },
    )?;
    d.set_item(
        "method",
        match o.method {
            Method::Contraction => "contraction",
            Method::Clustering => "clustering",
        },
    )?;
    // Not an option of the library but a keyword argument of simplify(), listed so the
    // dict names every keyword argument: None, the 3-tuple, as without it.
    d.set_item("attributes", py.None())?;
    d.set_item(
        "attribute_weights",
        attributes::weights_dict(py, &o.attribute_weights)?,
    )?;
    Ok(d)
}

// ------------------------------------------------------------------------------ reports

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

/// The report as a dict, with the keys of `qem simplify --report` (without its file
/// names; `timings_ms.simplify` is the library call as timed here, as the CLI times it).
fn report_dict<'py>(
    py: Python<'py>,
    r: &SimplifyReport,
    simplify: Duration,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("triangles_in", r.triangles_in)?;
    d.set_item("triangles_out", r.triangles_out)?;
    d.set_item("vertices_in", r.vertices_in)?;
    d.set_item("vertices_out", r.vertices_out)?;
    d.set_item("target_triangles", r.target_triangles)?;
    d.set_item("edge_contractions", r.edge_contractions)?;
    d.set_item("virtual_contractions", r.virtual_contractions)?;
    d.set_item("virtual_pairs", r.virtual_pairs)?;
    d.set_item("virtual_pairs_capped", r.virtual_pairs_capped)?;
    d.set_item("max_error", r.max_error)?;
    d.set_item("max_error_abs", r.max_error_abs)?;
    d.set_item("bbox_diagonal", r.bbox_diagonal)?;
    d.set_item("stop_reason", r.stop_reason.as_str())?;
    let c = &r.cleanup;
    let cleanup = PyDict::new(py);
    cleanup.set_item("welded_vertices", c.welded_vertices)?;
    cleanup.set_item("tolerance_welded_vertices", c.tolerance_welded_vertices)?;
    cleanup.set_item("repeated_index_faces", c.repeated_index_faces)?;
    cleanup.set_item("zero_area_faces", c.zero_area_faces)?;
    cleanup.set_item("duplicate_faces", c.duplicate_faces)?;
    cleanup.set_item("unreferenced_vertices", c.unreferenced_vertices)?;
    d.set_item("cleanup", cleanup)?;
    d.set_item("degenerate_faces_removed", r.degenerate_faces_removed)?;
    let rejected = PyDict::new(py);
    for (name, count) in r.rejected.named() {
        rejected.set_item(name, count)?;
    }
    d.set_item("rejected", rejected)?;
    let relaxations = PyList::empty(py);
    for x in &r.relaxations {
        let step = PyDict::new(py);
        step.set_item("step", x.step.as_str())?;
        step.set_item("contractions", x.contractions)?;
        relaxations.append(step)?;
    }
    d.set_item("relaxations", relaxations)?;
    d.set_item("stopped_by", r.stopped_by.map(|c| c.as_str()))?;
    d.set_item("locked_vertices", r.locked_vertices)?;
    d.set_item("faces_flipped", r.faces_flipped)?;
    d.set_item("faces_turned_back", r.faces_turned_back)?;
    let t = &r.timings;
    let timings = PyDict::new(py);
    timings.set_item("simplify", ms(simplify))?;
    timings.set_item("clean", ms(t.clean))?;
    timings.set_item("setup", ms(t.setup))?;
    timings.set_item("contract", ms(t.contract))?;
    timings.set_item("compact", ms(t.compact))?;
    d.set_item("timings_ms", timings)?;
    Ok(d)
}

fn measurement_dict<'py>(py: Python<'py>, m: &Measurement) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("hausdorff", m.hausdorff)?;
    d.set_item("hausdorff_ab", m.hausdorff_ab)?;
    d.set_item("hausdorff_ba", m.hausdorff_ba)?;
    d.set_item("mean_ab", m.mean_ab)?;
    d.set_item("mean_ba", m.mean_ba)?;
    d.set_item("faces_facing_away", m.faces_facing_away)?;
    d.set_item("facing_away_area", m.facing_away_area)?;
    d.set_item("rms_ab", m.rms_ab)?;
    d.set_item("rms_ba", m.rms_ba)?;
    d.set_item("samples_ab", m.samples_ab)?;
    d.set_item("samples_ba", m.samples_ba)?;
    d.set_item("diagonal", m.diagonal)?;
    Ok(d)
}

// ----------------------------------------------------------------------------- progress

/// Passes the loop's progress to a Python callable, with the GIL taken back for the call.
///
/// A callback that returns `False` cancels the run (the partial result is returned, its
/// `stop_reason` "cancelled"); one that raises cancels it too, and the exception is
/// raised from `simplify` once the library has returned. Ctrl-C is noticed the same way
/// (the signal check runs at every poll, callback or not), so a long run can be
/// interrupted from an interactive session.
struct PyObserver {
    callback: Option<Py<PyAny>>,
    cancelled: bool,
    error: Option<PyErr>,
}

impl Observer for PyObserver {
    fn progress(&mut self, progress: Progress) {
        if self.cancelled || self.error.is_some() {
            return;
        }
        Python::attach(|py| {
            if let Err(e) = py.check_signals() {
                self.error = Some(e);
                return;
            }
            let Some(callback) = &self.callback else {
                return;
            };
            match callback.call1(py, (progress.fraction(),)) {
                Ok(answer) => {
                    let answer = answer.bind(py);
                    if answer.is_instance_of::<PyBool>() && !answer.is_truthy().unwrap_or(true) {
                        self.cancelled = true;
                    }
                }
                Err(e) => self.error = Some(e),
            }
        });
    }

    fn should_stop(&mut self) -> bool {
        self.cancelled || self.error.is_some()
    }

    /// Ctrl-C is checked as each stage begins too: the cleaning and the setup of a large
    /// mesh take a while before the loop's first poll, and the run stops at their end.
    fn phase(&mut self, _phase: Phase) {
        if self.error.is_none() {
            Python::attach(|py| {
                if let Err(e) = py.check_signals() {
                    self.error = Some(e);
                }
            });
        }
    }

    fn wants_contractions(&self) -> bool {
        // Only progress is passed on; this spares the pass-based order the bookkeeping.
        false
    }
}

// ---------------------------------------------------------------------------- functions

/// Simplifies a triangle mesh by Garland–Heckbert pair contraction.
///
/// vertices: (n, 3) float32 or float64 array; faces: (m, 3) int32, int64, uint32 or
/// uint64 array of indices into vertices (nested lists work too). Any triangle soup is
/// accepted: non-manifold, open, unwelded, several parts, degenerate or duplicate faces.
///
/// Returns (vertices, faces, report): new arrays with the input's dtypes, and the report
/// as a dict (the keys of `qem simplify --report`: triangles_out, max_error as a
/// fraction of the bounding-box diagonal, stop_reason, rejected, timings_ms, ...).
///
/// attributes: a dict of per-vertex arrays, "uv" (n, 2), "normal" (n, 3), "colour" or
/// "color" (n, 3 or 4, floats 0 to 1), any other key a generic channel ((n,) or (n, k),
/// k ≤ 4), float32 or float64; "material": one integer label per face. With it the
/// result is (vertices, faces, attributes, report): the attributes carried through the
/// simplification (seams kept), as a dict with the same keys, dtypes and shapes, and
/// the output split at its seams, so a vertex on a seam comes out once per side (the
/// returned vertex count can exceed report["vertices_out"], which counts it once).
///
/// Options (keyword only; each left out has the library's default, see
/// qem.default_options()): ratio or triangles (the target; default ratio=0.5), fast
/// (start from SimplifyOptions::FAST), max_error, absolute, pair_threshold,
/// max_virtual_pairs_per_vertex, virtual_pairs, placement, weighting, quadrics,
/// boundary, max_normal_angle, min_triangle_quality, orientation_check,
/// preserve_topology, locked_vertices, clean, order, strict, method,
/// attribute_weights. The stub file (qem/__init__.pyi) documents each.
///
/// progress: called as progress(fraction) every few thousand contractions, fraction in
/// [0, 1]; returning False cancels the run (the partial, valid result is returned with
/// stop_reason "cancelled"); an exception it raises cancels the run and is re-raised.
///
/// The GIL is released during the work. Raises QemError (a ValueError) with qem's
/// message when the input or the options are refused.
#[pyfunction]
#[pyo3(signature = (vertices, faces, *, progress=None, attributes=None, **options))]
fn simplify<'py>(
    py: Python<'py>,
    vertices: &Bound<'py, PyAny>,
    faces: &Bound<'py, PyAny>,
    progress: Option<Py<PyAny>>,
    attributes: Option<&Bound<'py, PyAny>>,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyTuple>> {
    let options = simplify_options(options, "simplify()", &["progress", "attributes"])?;
    let (positions, float_kind) = read_vertices(vertices, "vertices")?;
    let (triangles, index_kind) = read_faces(faces, positions.len(), "faces")?;
    let attributes = attributes
        .filter(|a| !a.is_none())
        .map(|a| attributes::read_attributes(a, positions.len(), &triangles))
        .transpose()?;
    if let Some(callback) = &progress {
        if !callback.bind(py).is_callable() {
            return Err(PyTypeError::new_err("progress must be callable"));
        }
    }
    if options.method == Method::Clustering && attributes.as_ref().is_some_and(|a| !a.is_empty()) {
        return Err(qem_error(
            "method='clustering' keeps positions only and cannot carry attributes: \
             use method='contraction', or leave attributes out",
        ));
    }
    let mut mesh = IndexedMesh::new(positions, triangles);
    if let Some(a) = &attributes {
        mesh = mesh.with_attributes(a.for_simplify());
    }
    let mut observer = PyObserver {
        callback: progress,
        cancelled: false,
        error: None,
    };
    let (result, elapsed) = py.detach(|| {
        let clock = Instant::now();
        // Handed over: dropped once cleaned, before the setup and the loop.
        let result = qem_mesh::simplify::simplify_owned(mesh, &options, &mut observer);
        (result, clock.elapsed())
    });
    if let Some(error) = observer.error.take() {
        return Err(error);
    }
    let out = result.map_err(|e| qem_error(e.to_string()))?;
    let report = report_dict(py, &out.report, elapsed)?;
    let Some(attributes) = attributes else {
        let vertices = vertices_out(py, out.mesh.positions, float_kind)?;
        let faces = faces_out(py, out.mesh.triangles, index_kind)?;
        return PyTuple::new(py, [vertices, faces, report.into_any()]);
    };
    let split = py.detach(|| qem_mesh::attributes::split_at_seams(&out.mesh));
    drop(out);
    let attributes = attributes.output(py, &split)?;
    let vertices = vertices_out(py, split.positions, float_kind)?;
    let faces = faces_out(py, split.triangles, index_kind)?;
    PyTuple::new(
        py,
        [vertices, faces, attributes.into_any(), report.into_any()],
    )
}

/// The options simplify() uses when none is given (or, with fast=True, its fast=True
/// preset), as a dict of its keyword arguments: passing it back as **options changes
/// nothing. Read from the library, so it is always the library's current defaults.
#[pyfunction]
#[pyo3(signature = (fast=false))]
fn default_options(py: Python<'_>, fast: bool) -> PyResult<Bound<'_, PyDict>> {
    let preset = if fast {
        SimplifyOptions::FAST
    } else {
        SimplifyOptions::DEFAULT
    };
    options_dict(py, &preset)
}

/// How far two meshes are apart, Metro-style (qem measure): samples both surfaces
/// (every vertex, area-uniform points on the faces, points along border edges) and finds
/// each sample's exact distance to the other surface.
///
/// a, b: (vertices, faces) pairs, or objects with .vertices and .faces (a trimesh.Trimesh).
/// Returns a dict: hausdorff (symmetric), hausdorff_ab, hausdorff_ba, mean_ab, mean_ba,
/// rms_ab, rms_ba as fractions of a's bounding-box diagonal ("ab": samples on a,
/// distances to b), samples_ab, samples_ba, diagonal (a's, model units), and
/// faces_facing_away and facing_away_area (b's faces whose normal points away from a's
/// triangle nearest to their centroid, and their share of b's area). The same
/// seed gives the same figures to the bit whatever the number of cores. The GIL is
/// released during the work.
#[pyfunction]
#[pyo3(
    signature = (a, b, *, samples_per_face=None, min_samples=None, max_samples=None, seed=None),
    // The defaults are MeasureOptions::DEFAULT's, applied when an argument is None.
    text_signature = "(a, b, *, samples_per_face=10.0, min_samples=1000000, max_samples=None, seed=0)"
)]
fn measure<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
    samples_per_face: Option<&Bound<'py, PyAny>>,
    min_samples: Option<u64>,
    max_samples: Option<u64>,
    seed: Option<u64>,
) -> PyResult<Bound<'py, PyDict>> {
    let defaults = MeasureOptions::DEFAULT;
    let options = MeasureOptions {
        samples_per_face: match samples_per_face {
            Some(v) => non_negative("samples_per_face", v)?,
            None => defaults.samples_per_face,
        },
        min_samples: min_samples.unwrap_or(defaults.min_samples),
        max_samples: max_samples.or(defaults.max_samples),
        seed: seed.unwrap_or(defaults.seed),
    };
    let a = read_mesh(a, "a", false)?;
    let b = read_mesh(b, "b", false)?;
    let m = py
        .detach(|| qem_mesh::measure::measure(&a, &b, &options))
        .map_err(|e| qem_error(e.to_string()))?;
    measurement_dict(py, &m)
}

/// Reads a mesh file: .obj .ply .stl .off, each optionally gzipped (.gz). Returns
/// (vertices, faces): a float64 (n, 3) array and a uint32 (m, 3) array, polygons split
/// into triangles. With attributes=True returns (vertices, faces, attributes): the
/// mesh split at its seams so that every channel is per vertex (a vertex with two
/// texture coordinates comes out twice), attributes a dict of float32 (n, k) arrays
/// under the channels' names ("uv", "normal", "colour", a PLY property's name) and,
/// when the file has materials, "material" (int32 per face, -1 for none) and
/// "material_names". Raises QemError naming the file and the place (line, byte,
/// vertex or face) when the file cannot be read or is malformed.
#[pyfunction]
#[pyo3(signature = (path, *, attributes=false))]
fn load(py: Python<'_>, path: PathBuf, attributes: bool) -> PyResult<Bound<'_, PyTuple>> {
    let loaded = py
        .detach(|| qem_mesh::io::read_path(&path))
        .map_err(|e| qem_error(e.to_string()))?;
    let mesh = loaded.mesh;
    if !attributes {
        return PyTuple::new(
            py,
            [
                owned_array(py, mesh.positions)?,
                owned_array(py, mesh.triangles)?,
            ],
        );
    }
    let split = py.detach(|| qem_mesh::attributes::split_at_seams(&mesh));
    drop(mesh);
    let dict = attributes::loaded_dict(py, &split)?;
    PyTuple::new(
        py,
        [
            owned_array(py, split.positions)?,
            owned_array(py, split.triangles)?,
            dict.into_any(),
        ],
    )
}

/// Writes a mesh, in the format the name gives (.obj .ply .stl .off, gzipped when it
/// ends in .gz); mesh is a (vertices, faces) pair, a (vertices, faces, attributes)
/// triple (the dict simplify() takes, or load(path, attributes=True) gives), or has
/// .vertices and .faces. The file is written atomically: on any error it keeps its old
/// content (or does not appear). PLY is written binary little-endian with double
/// coordinates, STL binary. An attribute the format cannot hold (colours in OBJ,
/// anything in STL) is left out with a UserWarning saying which and why.
#[pyfunction]
fn save(py: Python<'_>, path: PathBuf, mesh: &Bound<'_, PyAny>) -> PyResult<()> {
    let mesh = read_mesh(mesh, "mesh", true)?;
    if let Ok(format) = qem_mesh::io::Format::from_path(&path) {
        let left: Vec<String> = qem_mesh::io::unwritable(&mesh.attributes, format)
            .into_iter()
            .map(|u| format!("{} ({})", u.what, u.reason))
            .collect();
        if !left.is_empty() {
            let message = format!(
                "qem.save: left out of {}: {}",
                path.display(),
                left.join(", ")
            );
            // A message with a NUL (from a path) is not worth failing the write for.
            if let Ok(message) = std::ffi::CString::new(message) {
                let category = py.get_type::<pyo3::exceptions::PyUserWarning>();
                PyErr::warn(py, &category, &message, 1)?;
            }
        }
    }
    py.detach(|| qem_mesh::io::write_path(&path, &mesh))
        .map_err(|e| qem_error(e.to_string()))
}

/// The extension module; `qem/__init__.py` re-exports everything in it but the
/// `tiles_*` functions, which `qem/tiles.py` wraps.
#[pymodule]
fn _qem(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("QemError", m.py().get_type::<QemError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_function(wrap_pyfunction!(simplify, m)?)?;
    m.add_function(wrap_pyfunction!(default_options, m)?)?;
    m.add_function(wrap_pyfunction!(measure, m)?)?;
    m.add_function(wrap_pyfunction!(load, m)?)?;
    m.add_function(wrap_pyfunction!(save, m)?)?;
    m.add_function(wrap_pyfunction!(tiles::tiles_split, m)?)?;
    m.add_function(wrap_pyfunction!(tiles::tiles_simplify, m)?)?;
    m.add_function(wrap_pyfunction!(tiles::tiles_merge, m)?)?;
    m.add_function(wrap_pyfunction!(tiles::tiles_fingerprint, m)?)?;
    Ok(())
}
