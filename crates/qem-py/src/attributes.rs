//! The `attributes` dicts of the Python API: per-vertex NumPy arrays in, qem's
//! per-corner [`Channel`]s inside, per-vertex arrays out again (split at seams).
//!
//! A dict maps a key to an array with one row per vertex: `"uv"` (n, 2) texture
//! coordinates, `"normal"` (n, 3), `"colour"` or `"color"` (n, 3 or 4, 0–1), any other
//! key a generic channel of that name ((n,) or (n, k), k from 1 to 4). Two keys are per
//! face: `"material"`, an integer array with one label per face, and
//! `"material_names"`, a list of strings (label `i` is the material named
//! `material_names[i]`, -1 none), which only `load` and `save` give a meaning and
//! `simplify` passes through. Every channel comes in per vertex, so each corner takes
//! its vertex's value; qem's cleaning welds vertices at one position into one vertex
//! with several wedges, which is how a seam (a UV island's border, a hard normal edge)
//! reaches the simplifier.

use crate::{as_ndarray, dtype_name, non_negative, qem_error, shape_text, FloatKind, IndexKind};
use numpy::ndarray::Array2;
use numpy::prelude::*;
use numpy::{PyArray1, PyArray2, PyArrayDyn, PyUntypedArray};
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use qem_mesh::attributes::{Attributes, Channel, ChannelKind, FaceLabels};
use qem_mesh::simplify::AttributeWeights;
use qem_mesh::IndexedMesh;

/// The key of the per-face material labels.
const MATERIAL: &str = "material";
/// The key of the material names that `load` gives and `save` writes.
const MATERIAL_NAMES: &str = "material_names";

/// One per-vertex array of an `attributes` dict, as a channel, and how to give it back.
struct ChannelArg {
    /// The key as the caller wrote it (`"color"` stays `"color"`).
    key: String,
    /// The channel, per vertex: its corners are the mesh's triangles.
    channel: Channel,
    /// The dtype the array came in; the output array gets the same one.
    float: FloatKind,
    /// Whether a generic channel came as a 1-d (n,) array.
    flat: bool,
}

/// The `"material"` array: one integer label per face.
struct MaterialArg {
    values: Vec<i128>,
    kind: IndexKind,
}

/// An `attributes` dict, read and checked against the mesh it goes with.
pub(crate) struct AttributesArg {
    channels: Vec<ChannelArg>,
    material: Option<MaterialArg>,
    /// `"material_names"`: the object as given (simplify hands it back as it is) and
    /// its strings.
    material_names: Option<(Py<PyAny>, Vec<String>)>,
}

/// What a key means: the channel kind and the dimensions it allows, with their
/// wording for an error message.
fn kind_of(key: &str) -> (ChannelKind, &'static [usize], &'static str) {
    match key {
        "uv" => (ChannelKind::TexCoord, &[2], "(n, 2)"),
        "normal" => (ChannelKind::Normal, &[3], "(n, 3)"),
        "colour" | "color" => (ChannelKind::Color, &[3, 4], "(n, 3) or (n, 4)"),
        _ => (
            ChannelKind::Generic,
            &[1, 2, 3, 4],
            "(n,) or (n, k) with k from 1 to 4",
        ),
    }
}

/// The floats of a float32 or float64 array of any shape, in C order.
fn read_floats(array: &Bound<'_, PyUntypedArray>, what: &str) -> PyResult<(Vec<f64>, FloatKind)> {
    let readonly_error = |e: numpy::BorrowError| qem_error(format!("{what}: {e}"));
    if let Ok(a) = array.cast::<PyArrayDyn<f64>>() {
        let r = a.try_readonly().map_err(readonly_error)?;
        Ok((r.as_array().iter().copied().collect(), FloatKind::F64))
    } else if let Ok(a) = array.cast::<PyArrayDyn<f32>>() {
        let r = a.try_readonly().map_err(readonly_error)?;
        let values = r.as_array().iter().map(|&v| f64::from(v)).collect();
        Ok((values, FloatKind::F32))
    } else {
        Err(qem_error(format!(
            "{what} must be float32 or float64, not {}; convert with .astype(numpy.float32)",
            dtype_name(array)
        )))
    }
}

/// The integers of a 1-d int32, int64, uint32 or uint64 array.
fn read_labels(array: &Bound<'_, PyUntypedArray>, what: &str) -> PyResult<MaterialArg> {
    fn read<T: numpy::Element + Copy + Into<i128>>(
        array: &Bound<'_, PyUntypedArray>,
        what: &str,
    ) -> PyResult<Option<Vec<i128>>> {
        let Ok(a) = array.cast::<PyArray1<T>>() else {
            return Ok(None);
        };
        let r = a
            .try_readonly()
            .map_err(|e| qem_error(format!("{what}: {e}")))?;
        Ok(Some(r.as_array().iter().map(|&v| v.into()).collect()))
    }
    let found = if let Some(v) = read::<i32>(array, what)? {
        Some((v, IndexKind::I32))
    } else if let Some(v) = read::<i64>(array, what)? {
        Some((v, IndexKind::I64))
    } else if let Some(v) = read::<u32>(array, what)? {
        Some((v, IndexKind::U32))
    } else {
        read::<u64>(array, what)?.map(|v| (v, IndexKind::U64))
    };
    match found {
        Some((values, kind)) => Ok(MaterialArg { values, kind }),
        None => Err(qem_error(format!(
            "{what} must be int32, int64, uint32 or uint64, not {}",
            dtype_name(array)
        ))),
    }
}

/// `obj` as an array, a failure of `numpy.asarray` named after the key.
fn array_of<'py>(
    obj: &Bound<'py, PyAny>,
    dtype: Option<&str>,
    what: &str,
) -> PyResult<Bound<'py, PyUntypedArray>> {
    as_ndarray(obj, dtype).map_err(|e| qem_error(format!("{what} is not an array: {e}")))
}

/// One per-vertex channel: `attributes[key]` for a mesh of `vertex_count` vertices
/// and `triangles`.
fn read_channel(
    key: &str,
    value: &Bound<'_, PyAny>,
    vertex_count: usize,
    triangles: &[[u32; 3]],
) -> PyResult<ChannelArg> {
    let what = format!("attributes['{key}']");
    let (kind, dimensions, expected) = kind_of(key);
    let array = array_of(value, Some("float64"), &what)?;
    let n = vertex_count;
    let (dimension, flat) = match array.shape() {
        [rows, k] if *rows == n && dimensions.contains(k) => (*k, false),
        [rows] if *rows == n && kind == ChannelKind::Generic => (1, true),
        shape => {
            return Err(qem_error(format!(
                "{what} must have shape {expected}, one row per vertex (n = {n}), not {}",
                shape_text(shape)
            )))
        }
    };
    let (floats, float) = read_floats(&array, &what)?;
    let mut values = Vec::with_capacity(floats.len());
    for (i, &v) in floats.iter().enumerate() {
        let single = v as f32;
        if !single.is_finite() {
            return Err(qem_error(format!(
                "{what}[{}] holds {v}: values must be finite (and within float32's range)",
                i / dimension
            )));
        }
        if kind == ChannelKind::Color && !(0.0..=1.0).contains(&v) {
            return Err(qem_error(format!(
                "{what}[{}] holds {v}: colours are floats from 0 to 1 \
                 (divide 8-bit colours by 255)",
                i / dimension
            )));
        }
        values.push(single);
    }
    let name = match kind {
        ChannelKind::Generic => key.to_string(),
        other => other.as_str().to_string(),
    };
    let channel = Channel::new(kind, values, triangles.to_vec())
        .with_dimension(dimension)
        .with_name(name);
    Ok(ChannelArg {
        key: key.to_string(),
        channel,
        float,
        flat,
    })
}

/// Reads and checks an `attributes` dict for a mesh of `vertex_count` vertices and
/// `triangles`: a [`qem_error`] (a `ValueError`) naming the key and the shape it
/// expects for a wrong array, a `TypeError` for a dict that is not one.
pub(crate) fn read_attributes(
    obj: &Bound<'_, PyAny>,
    vertex_count: usize,
    triangles: &[[u32; 3]],
) -> PyResult<AttributesArg> {
    let dict = obj.cast::<PyDict>().map_err(|_| {
        PyTypeError::new_err(
            "attributes must be a dict of per-vertex arrays (uv, normal, colour, ...) \
             and per-face material labels",
        )
    })?;
    let mut arg = AttributesArg {
        channels: Vec::new(),
        material: None,
        material_names: None,
    };
    for (key, value) in dict.iter() {
        let key: String = key
            .extract()
            .map_err(|_| PyTypeError::new_err("the keys of attributes must be strings"))?;
        match key.as_str() {
            MATERIAL => {
                let what = "attributes['material']";
                let array = array_of(&value, Some("int64"), what)?;
                let m = triangles.len();
                if array.shape() != [m] {
                    return Err(qem_error(format!(
                        "{what} must have shape (m,), one label per face (m = {m}), not {}",
                        shape_text(array.shape())
                    )));
                }
                arg.material = Some(read_labels(&array, what)?);
            }
            MATERIAL_NAMES => {
                let names: Vec<String> = value.extract().map_err(|_| {
                    qem_error("attributes['material_names'] must be a list of strings")
                })?;
                arg.material_names = Some((value.clone().unbind(), names));
            }
            _ => {
                let channel = read_channel(&key, &value, vertex_count, triangles)?;
                if let Some(other) = arg
                    .channels
                    .iter()
                    .find(|c| c.channel.name == channel.channel.name)
                {
                    return Err(qem_error(format!(
                        "attributes has both '{}' and '{key}': give one of them",
                        other.key
                    )));
                }
                arg.channels.push(channel);
            }
        }
    }
    Ok(arg)
}

impl AttributesArg {
    /// The attributes for `simplify`: the channels, and the material labels with
    /// their values written out as names (the simplifier only compares them).
    pub(crate) fn for_simplify(&self) -> Attributes {
        let mut attributes = Attributes::default();
        attributes.channels = self.channels.iter().map(|c| c.channel.clone()).collect();
        if let Some(material) = &self.material {
            attributes.materials = decimal_labels(&material.values);
        }
        attributes
    }

    /// The attributes for `save`: the channels, and the materials named by
    /// `material_names` when given (label -1 is none), else by their values.
    pub(crate) fn for_save(&self) -> PyResult<Attributes> {
        let mut attributes = self.for_simplify();
        if let (Some(material), Some((_, names))) = (&self.material, &self.material_names) {
            let faces = material
                .values
                .iter()
                .enumerate()
                .map(|(face, &v)| match v {
                    -1 => Ok(FaceLabels::NONE),
                    v if (0..names.len() as i128).contains(&v) => Ok(v as u32),
                    v => Err(qem_error(format!(
                        "attributes['material'][{face}] is {v}: with material_names each \
                         label is -1 (no material) or an index into them (0 to {})",
                        names.len() as i128 - 1
                    ))),
                })
                .collect::<PyResult<Vec<u32>>>()?;
            attributes.materials = FaceLabels {
                names: names.iter().map(|n| n.as_bytes().to_vec()).collect(),
                faces,
            };
        }
        Ok(attributes)
    }

    /// Whether the dict carries anything for the simplifier to keep.
    pub(crate) fn is_empty(&self) -> bool {
        self.channels.is_empty() && self.material.is_none()
    }

    /// The output dict of `simplify`: the same keys, each array for `split` (the
    /// simplified mesh split at its seams), with the dtypes and shapes they came in.
    pub(crate) fn output<'py>(
        &self,
        py: Python<'py>,
        split: &IndexedMesh,
    ) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        let n = split.vertex_count();
        for arg in &self.channels {
            let channel = split
                .attributes
                .channels
                .iter()
                .find(|c| c.name == arg.channel.name)
                .ok_or_else(|| {
                    qem_error(format!(
                        "internal error, please report: the output lost the channel '{}'",
                        arg.key
                    ))
                })?;
            d.set_item(
                &arg.key,
                float_array(
                    py,
                    &channel.values,
                    n,
                    channel.dimension,
                    arg.flat,
                    arg.float,
                )?,
            )?;
        }
        if let Some(material) = &self.material {
            let labels = &split.attributes.materials;
            let values = labels
                .faces
                .iter()
                .map(|&i| {
                    labels
                        .names
                        .get(i as usize)
                        .and_then(|name| std::str::from_utf8(name).ok()?.parse::<i128>().ok())
                        .ok_or_else(|| {
                            qem_error(
                                "internal error, please report: an output face lost its material",
                            )
                        })
                })
                .collect::<PyResult<Vec<i128>>>()?;
            d.set_item(MATERIAL, label_array(py, &values, material.kind)?)?;
        }
        if let Some((names, _)) = &self.material_names {
            d.set_item(MATERIAL_NAMES, names.bind(py))?;
        }
        Ok(d)
    }
}

/// Labels named by their values, one name per distinct value in order of first use.
fn decimal_labels(values: &[i128]) -> FaceLabels {
    let mut index = std::collections::HashMap::new();
    let mut labels = FaceLabels::default();
    for &v in values {
        let i = *index.entry(v).or_insert_with(|| {
            labels.names.push(v.to_string().into_bytes());
            (labels.names.len() - 1) as u32
        });
        labels.faces.push(i);
    }
    labels
}

/// An (n, k) array (or (n,) with `flat`) of `values` in the dtype `kind`.
fn float_array<'py>(
    py: Python<'py>,
    values: &[f32],
    n: usize,
    k: usize,
    flat: bool,
    kind: FloatKind,
) -> PyResult<Bound<'py, PyAny>> {
    fn build<'py, T: numpy::Element>(
        py: Python<'py>,
        values: Vec<T>,
        n: usize,
        k: usize,
        flat: bool,
    ) -> PyResult<Bound<'py, PyAny>> {
        if flat {
            return Ok(PyArray1::from_vec(py, values).into_any());
        }
        let array = Array2::from_shape_vec((n, k), values)
            .map_err(|e| qem_error(format!("internal error, please report: {e}")))?;
        Ok(PyArray2::from_owned_array(py, array).into_any())
    }
    match kind {
        FloatKind::F32 => build(py, values.to_vec(), n, k, flat),
        FloatKind::F64 => build(
            py,
            values.iter().map(|&v| f64::from(v)).collect(),
            n,
            k,
            flat,
        ),
    }
}

/// A 1-d array of labels in the dtype they came in (they came from it: no overflow).
fn label_array<'py>(
    py: Python<'py>,
    values: &[i128],
    kind: IndexKind,
) -> PyResult<Bound<'py, PyAny>> {
    fn build<'py, T: numpy::Element + TryFrom<i128>>(
        py: Python<'py>,
        values: &[i128],
    ) -> PyResult<Bound<'py, PyAny>> {
        let converted = values
            .iter()
            .map(|&v| {
                T::try_from(v).map_err(|_| {
                    qem_error(format!(
                        "internal error, please report: label {v} does not fit its dtype"
                    ))
                })
            })
            .collect::<PyResult<Vec<T>>>()?;
        Ok(PyArray1::from_vec(py, converted).into_any())
    }
    match kind {
        IndexKind::I32 => build::<i32>(py, values),
        IndexKind::I64 => build::<i64>(py, values),
        IndexKind::U32 => build::<u32>(py, values),
        IndexKind::U64 => build::<u64>(py, values),
    }
}

/// The attributes of a loaded (and split) mesh as a dict: each channel under its name
/// as a float32 (n, k) array, the materials as `"material"` (int32 per face, -1 for
/// none) and `"material_names"` (decoded as UTF-8, invalid bytes replaced).
pub(crate) fn loaded_dict<'py>(
    py: Python<'py>,
    split: &IndexedMesh,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let n = split.vertex_count();
    for c in &split.attributes.channels {
        d.set_item(
            &c.name,
            float_array(py, &c.values, n, c.dimension, false, FloatKind::F32)?,
        )?;
    }
    let materials = &split.attributes.materials;
    if !materials.is_empty() {
        let labels: Vec<i128> = materials
            .faces
            .iter()
            .map(|&i| {
                if i == FaceLabels::NONE {
                    -1
                } else {
                    i128::from(i)
                }
            })
            .collect();
        d.set_item(MATERIAL, label_array(py, &labels, IndexKind::I32)?)?;
        let names = PyList::empty(py);
        for name in &materials.names {
            names.append(String::from_utf8_lossy(name))?;
        }
        d.set_item(MATERIAL_NAMES, names)?;
    }
    Ok(d)
}

/// The kinds' names as `attribute_weights` takes them.
const WEIGHT_NAMES: &[&str] = &["uv", "normal", "colour", "generic"];

/// `attribute_weights`: a dict of some of uv, normal, colour (or color) and generic to
/// a weight ≥ 0; the kinds left out keep `preset`'s weights.
pub(crate) fn attribute_weights(
    value: &Bound<'_, PyAny>,
    preset: AttributeWeights,
) -> PyResult<AttributeWeights> {
    if value.is_none() {
        return Ok(preset);
    }
    let dict = value.cast::<PyDict>().map_err(|_| {
        PyTypeError::new_err(format!(
            "attribute_weights must be a dict with some of the keys {}",
            WEIGHT_NAMES.join(", ")
        ))
    })?;
    let mut weights = preset;
    for (key, value) in dict.iter() {
        let key: String = key
            .extract()
            .map_err(|_| PyTypeError::new_err("the keys of attribute_weights must be strings"))?;
        let kind = match key.as_str() {
            "uv" => ChannelKind::TexCoord,
            "normal" => ChannelKind::Normal,
            "colour" | "color" => ChannelKind::Color,
            "generic" => ChannelKind::Generic,
            _ => {
                return Err(qem_error(format!(
                    "attribute_weights has no key '{key}'; the keys are {} (or color)",
                    WEIGHT_NAMES.join(", ")
                )))
            }
        };
        let name = format!("attribute_weights['{key}']");
        weights = weights.with(kind, non_negative(&name, &value)?);
    }
    Ok(weights)
}

/// `attribute_weights` as [`attribute_weights`] reads it back.
pub(crate) fn weights_dict<'py>(
    py: Python<'py>,
    w: &AttributeWeights,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for (name, kind) in WEIGHT_NAMES.iter().zip([
        ChannelKind::TexCoord,
        ChannelKind::Normal,
        ChannelKind::Color,
        ChannelKind::Generic,
    ]) {
        d.set_item(name, w.of(kind))?;
    }
    Ok(d)
}
