//! Python ⇄ Rust conversions shared by every function of the package: numbers and arrays in
//! (anything `numpy.asarray` takes, float64 read without a copy when it already is one), numpy
//! arrays out, and the core's serde documents as the same Python dicts the CLI's JSON parses to
//! (`json.loads` of the same text: keys, order, `null` for unbounded values, floats bit for bit).

use numpy::{Element, PyArray1, PyArrayDyn, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::PyAnyMethods;

use scatterloc::error::limits;

use crate::errors::{arg_error, core_error};

/// An n-dimensional float64 array read from Python: its shape and its values (C order).
pub struct F64Array {
    /// The shape.
    pub shape: Vec<usize>,
    /// The values, row-major.
    pub data: Vec<f64>,
}

/// The values of `a` in C (row-major) order: a C-contiguous array copied at once, any other
/// (Fortran order, strided views) element by element through a checked borrow. (`to_vec` alone
/// copies the memory of a Fortran-ordered array in its own order: a transposed input would be
/// read scrambled.)
pub fn logical_order<T: numpy::Element + Copy>(a: &Bound<'_, PyArrayDyn<T>>) -> Vec<T> {
    if a.is_c_contiguous() {
        if let Ok(v) = a.to_vec() {
            return v;
        }
    }
    a.readonly().as_array().iter().copied().collect()
}

/// `numpy.asarray`.
fn asarray<'py>(py: Python<'py>) -> PyResult<&'py Bound<'py, PyAny>> {
    static ASARRAY: PyOnceLock<Py<PyAny>> = PyOnceLock::new();
    ASARRAY.import(py, "numpy", "asarray")
}

/// `obj` as a float64 array (anything `numpy.asarray(obj, dtype=float)` accepts); a
/// [`crate::errors::ScatterlocError`] naming `field` when it is not numeric.
pub fn f64_array(obj: &Bound<'_, PyAny>, field: &str) -> PyResult<F64Array> {
    if let Ok(a) = obj.cast::<PyArrayDyn<f64>>() {
        let shape = a.shape().to_vec();
        return Ok(F64Array {
            shape,
            data: logical_order(a),
        });
    }
    // A flat list or tuple of numbers (the common small argument) without numpy.
    if obj.cast::<pyo3::types::PyList>().is_ok() || obj.cast::<pyo3::types::PyTuple>().is_ok() {
        if let Ok(v) = obj.extract::<Vec<f64>>() {
            return Ok(F64Array {
                shape: vec![v.len()],
                data: v,
            });
        }
    }
    let py = obj.py();
    let kwargs = pyo3::types::PyDict::new(py);
    kwargs.set_item("dtype", "float64")?;
    let converted = asarray(py)?
        .call((obj,), Some(&kwargs))
        .map_err(|e| arg_error(field, format!("not an array of numbers ({e})")))?;
    let a = converted
        .cast::<PyArrayDyn<f64>>()
        .map_err(|_| arg_error(field, "not an array of numbers"))?;
    let ro = a.readonly();
    Ok(F64Array {
        shape: ro.shape().to_vec(),
        data: ro.as_array().iter().copied().collect(),
    })
}

/// A 1-D float64 vector (`field` names it in errors); `len`, when given, is its required length.
pub fn f64_vec(obj: &Bound<'_, PyAny>, field: &str, len: Option<usize>) -> PyResult<Vec<f64>> {
    let a = f64_array(obj, field)?;
    if a.shape.len() != 1 {
        return Err(arg_error(
            field,
            format!("expected a 1-D array, got shape {:?}", a.shape),
        ));
    }
    if let Some(n) = len {
        if a.data.len() != n {
            return Err(arg_error(
                field,
                format!("expected {n} values, got {}", a.data.len()),
            ));
        }
    }
    Ok(a.data)
}

/// Points `(..., 2)` in metres: the points and the leading shape (`()` for one point given as
/// `(2,)`). Every coordinate is checked against the core's coordinate range (a NaN or a point
/// 10⁸ m away is a named error, never a NaN out).
pub fn points(obj: &Bound<'_, PyAny>, field: &str) -> PyResult<(Vec<[f64; 2]>, Vec<usize>)> {
    let a = f64_array(obj, field)?;
    match a.shape.split_last() {
        Some((2, lead)) => {
            let one = lead.is_empty();
            for (i, v) in a.data.iter().enumerate() {
                let at = || match one {
                    true => format!("{field}[{i}]"),
                    false => format!("{field}[{}][{}]", i / 2, i % 2),
                };
                if !limits::COORDINATE_M.contains(*v) {
                    return Err(core_error(
                        limits::COORDINATE_M
                            .check(&at(), *v)
                            .err()
                            .unwrap_or(scatterloc::Error::NonFinite { field: at() }),
                    ));
                }
            }
            Ok((
                a.data.chunks_exact(2).map(|p| [p[0], p[1]]).collect(),
                lead.to_vec(),
            ))
        }
        _ => Err(arg_error(
            field,
            format!(
                "expected points of shape (2,) or (..., 2), got shape {:?}",
                a.shape
            ),
        )),
    }
}

/// One point `(2,)`, checked as [`points`] checks.
pub fn point(obj: &Bound<'_, PyAny>, field: &str) -> PyResult<[f64; 2]> {
    let (p, shape) = points(obj, field)?;
    if !shape.is_empty() {
        return Err(arg_error(
            field,
            format!("expected one point (x, y), got {} points", p.len()),
        ));
    }
    Ok(p[0])
}

/// A square `n × n` matrix, row-major rows.
pub fn matrix<const N: usize>(obj: &Bound<'_, PyAny>, field: &str) -> PyResult<[[f64; N]; N]> {
    let a = f64_array(obj, field)?;
    if a.shape != [N, N] {
        return Err(arg_error(
            field,
            format!("expected shape ({N}, {N}), got {:?}", a.shape),
        ));
    }
    let mut m = [[0.0; N]; N];
    for (i, row) in m.iter_mut().enumerate() {
        row.copy_from_slice(&a.data[i * N..(i + 1) * N]);
    }
    Ok(m)
}

/// An array of `shape` from row-major `data` (float64, int64, bool or complex128: numpy's dtype
/// of `T`).
pub fn array<'py, T: Element>(
    py: Python<'py>,
    data: Vec<T>,
    shape: &[usize],
) -> PyResult<Bound<'py, PyAny>> {
    let a = PyArray1::from_vec(py, data);
    if shape.len() == 1 {
        return Ok(a.into_any());
    }
    Ok(a.reshape(shape.to_vec())?.into_any())
}

/// A masked float64 array (`numpy.ma.MaskedArray`) of `shape`: `None` entries are masked
/// (their data 0), so no output ever holds NaN for "no value".
pub fn masked<'py>(
    py: Python<'py>,
    data: &[Option<f64>],
    shape: &[usize],
) -> PyResult<Bound<'py, PyAny>> {
    static MASKED_ARRAY: PyOnceLock<Py<PyAny>> = PyOnceLock::new();
    let values = array(py, data.iter().map(|v| v.unwrap_or(0.0)).collect(), shape)?;
    let mask = array(py, data.iter().map(Option::is_none).collect(), shape)?;
    let kwargs = pyo3::types::PyDict::new(py);
    kwargs.set_item("mask", mask)?;
    MASKED_ARRAY
        .import(py, "numpy.ma", "MaskedArray")?
        .call((values,), Some(&kwargs))
}

/// The serde document `doc` as the Python object its JSON parses to (`json.loads`): exactly what
/// a caller of the CLI reads from the same command's output.
pub fn to_python<'py, T: serde::Serialize>(
    py: Python<'py>,
    doc: &T,
) -> PyResult<Bound<'py, PyAny>> {
    JsonDoc::of(doc)?.to_python(py)
}

/// A serde document kept as its JSON text: the keys in its structs' order, as the CLI prints
/// them (a `serde_json::Value` would sort them).
pub struct JsonDoc(String);

impl JsonDoc {
    /// The JSON text of `doc`.
    pub fn of<T: serde::Serialize>(doc: &T) -> PyResult<JsonDoc> {
        serde_json::to_string(doc)
            .map(JsonDoc)
            .map_err(|e| pyo3::exceptions::PyRuntimeError::new_err(format!("encoding JSON: {e}")))
    }

    /// The document as the Python object its JSON parses to (`json.loads`).
    pub fn to_python<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        static LOADS: PyOnceLock<Py<PyAny>> = PyOnceLock::new();
        LOADS.import(py, "json", "loads")?.call1((self.0.as_str(),))
    }
}

/// A Python object (a dict from `json.load`, a list) as JSON text (`json.dumps`), for the core's
/// parsers, whose errors name the offending field.
pub fn to_json_text(obj: &Bound<'_, PyAny>, field: &str) -> PyResult<String> {
    static DUMPS: PyOnceLock<Py<PyAny>> = PyOnceLock::new();
    let py = obj.py();
    let kwargs = pyo3::types::PyDict::new(py);
    // NaN and ±inf are not JSON: refuse them here rather than write invalid JSON.
    kwargs.set_item("allow_nan", false)?;
    let text = DUMPS
        .import(py, "json", "dumps")?
        .call((obj,), Some(&kwargs))
        .map_err(|e| arg_error(field, format!("not a JSON document ({e})")))?;
    text.extract::<String>()
}

/// A path-like argument (`str` or `os.PathLike`) as a `String`.
pub fn path_string(obj: &Bound<'_, PyAny>) -> PyResult<String> {
    static FSPATH: PyOnceLock<Py<PyAny>> = PyOnceLock::new();
    let py = obj.py();
    let p = FSPATH.import(py, "os", "fspath")?.call1((obj,))?;
    p.extract::<String>()
}
