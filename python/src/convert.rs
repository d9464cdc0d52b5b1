//! Python ⇄ Rust conversions shared by every function of the package: numbers and arrays in
//! (anything `numpy.asarray` takes, float64 read without a copy when it already is one; every
//! array's size checked from its shape against a cap before anything is copied or converted,
//! so a broadcast view of 10¹⁰ values is a named error, not an abort), numpy arrays out, and
//! the core's serde documents as the same Python dicts the CLI's JSON parses to (`json.loads`
//! of the same text: keys, order, `null` for unbounded values, floats bit for bit).

use numpy::{
    Element, PyArray1, PyArrayDescrMethods, PyArrayDyn, PyArrayMethods, PyUntypedArray,
    PyUntypedArrayMethods,
};
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::PyAnyMethods;

use scatterloc::error::limits;
use scatterloc::localize::MAX_GRID_CELLS;

use crate::errors::{arg_error, core_error};

/// Most values of an array argument without a tighter cap of its own (measurements, raw
/// estimates): the CLI's cap on an input file ([`limits::MAX_INPUT_BYTES`], 256 MiB) as
/// float64 values, 32 Mi.
pub const MAX_VALUES: usize = (limits::MAX_INPUT_BYTES / 8) as usize;

/// The number of values of an array of `shape` (saturating: never overflows).
pub fn count(shape: &[usize]) -> usize {
    shape.iter().fold(1usize, |a, &d| a.saturating_mul(d))
}

/// "`field`: `n` `what`, at most `max` are allowed" (a `ScatterlocError` naming `field`).
pub fn too_many(field: &str, n: usize, max: usize, what: &str) -> PyErr {
    arg_error(field, format!("{n} {what}, at most {max} are allowed"))
}

/// `obj` as a numpy array when it is one (any dtype, any strides; nothing is copied).
pub fn ndarray<'a, 'py>(obj: &'a Bound<'py, PyAny>) -> Option<&'a Bound<'py, PyUntypedArray>> {
    obj.cast::<PyUntypedArray>().ok()
}

/// numpy's name of `a`'s dtype (`float64`, `complex256`, `int8`, …).
pub fn dtype_name(a: &Bound<'_, PyUntypedArray>) -> String {
    a.dtype()
        .getattr("name")
        .and_then(|n| n.extract::<String>())
        .unwrap_or_else(|_| "unknown".into())
}

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
pub fn asarray<'py>(py: Python<'py>) -> PyResult<&'py Bound<'py, PyAny>> {
    static ASARRAY: PyOnceLock<Py<PyAny>> = PyOnceLock::new();
    ASARRAY.import(py, "numpy", "asarray")
}

/// `obj` as a float64 array (anything `numpy.asarray(obj, dtype=float)` accepts) of at most
/// `max` values; a [`crate::errors::ScatterlocError`] naming `field` when it is not numeric,
/// holds complex numbers (numpy would drop their imaginary parts with a mere warning) or has
/// more than `max` values — checked from a numpy array's shape before anything is copied.
pub fn f64_array(obj: &Bound<'_, PyAny>, field: &str, max: usize) -> PyResult<F64Array> {
    if let Some(u) = ndarray(obj) {
        let n = count(u.shape());
        if n > max {
            return Err(too_many(field, n, max, "values"));
        }
        if u.dtype().kind() == b'c' {
            return Err(arg_error(
                field,
                format!(
                    "complex values (dtype {}) where real numbers are expected",
                    dtype_name(u)
                ),
            ));
        }
    }
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
            if v.len() > max {
                return Err(too_many(field, v.len(), max, "values"));
            }
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
    let n = count(a.shape());
    if n > max {
        return Err(too_many(field, n, max, "values"));
    }
    let ro = a.readonly();
    Ok(F64Array {
        shape: ro.shape().to_vec(),
        data: ro.as_array().iter().copied().collect(),
    })
}

/// The length a 1-D argument must have ([`f64_vec`]).
#[derive(Clone, Copy)]
pub enum Len {
    /// Exactly this many values.
    Exactly(usize),
    /// At most this many values (a cap of the library's, `src/error/limits.rs`).
    AtMost(usize),
}

/// A 1-D float64 vector (`field` names it in errors) of the length `len` requires (a numpy
/// array's length checked from its shape, before any copy).
pub fn f64_vec(obj: &Bound<'_, PyAny>, field: &str, len: Len) -> PyResult<Vec<f64>> {
    let wrong = |n: usize, got: usize| arg_error(field, format!("expected {n} values, got {got}"));
    let a = match len {
        Len::AtMost(max) => f64_array(obj, field, max)?,
        Len::Exactly(n) => {
            if let Some(got) = ndarray(obj).map(|u| count(u.shape())) {
                if got > n {
                    return Err(wrong(n, got));
                }
            }
            f64_array(obj, field, MAX_VALUES)?
        }
    };
    if a.shape.len() != 1 {
        return Err(arg_error(
            field,
            format!("expected a 1-D array, got shape {:?}", a.shape),
        ));
    }
    if let Len::Exactly(n) = len {
        if a.data.len() != n {
            return Err(wrong(n, a.data.len()));
        }
    }
    Ok(a.data)
}

/// Points `(..., 2)` in metres: the points and the leading shape (`()` for one point given as
/// `(2,)`). Every coordinate is checked against the core's coordinate range (a NaN or a point
/// 10⁸ m away is a named error, never a NaN out).
///
/// At most `max` points: a numpy array's count is checked from its shape, before any copy.
pub fn points(
    obj: &Bound<'_, PyAny>,
    field: &str,
    max: usize,
) -> PyResult<(Vec<[f64; 2]>, Vec<usize>)> {
    if let Some(u) = ndarray(obj) {
        if let Some((2, lead)) = u.shape().split_last() {
            let n = count(lead);
            if n > max {
                return Err(too_many(field, n, max, "points"));
            }
        }
    }
    let a = f64_array(obj, field, max.saturating_mul(2))?;
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

/// Points at which a function evaluates the scenario link by link (`crlb`, `Scenario.delays`,
/// `Scenario.snr_db`, …), as [`points`]: at most crlb-map's cell cap
/// ([`scatterloc::localize::MAX_GRID_CELLS`], 2048²) point-links, i.e. that many points over
/// the scenario's `links` links, so no per-link output has more values than the CLI's largest
/// map.
pub fn eval_points(
    obj: &Bound<'_, PyAny>,
    field: &str,
    links: usize,
) -> PyResult<(Vec<[f64; 2]>, Vec<usize>)> {
    points(obj, field, MAX_GRID_CELLS / links.max(1))
}

/// One point `(2,)`, checked as [`points`] checks.
pub fn point(obj: &Bound<'_, PyAny>, field: &str) -> PyResult<[f64; 2]> {
    let several = |n: usize| arg_error(field, format!("expected one point (x, y), got {n} points"));
    if let Some(u) = ndarray(obj) {
        if let Some((2, lead)) = u.shape().split_last() {
            if !lead.is_empty() {
                return Err(several(count(lead)));
            }
        }
    }
    let (p, shape) = points(obj, field, MAX_VALUES / 2)?;
    if !shape.is_empty() {
        return Err(several(p.len()));
    }
    Ok(p[0])
}

/// A square `n × n` matrix, row-major rows.
pub fn matrix<const N: usize>(obj: &Bound<'_, PyAny>, field: &str) -> PyResult<[[f64; N]; N]> {
    let wrong =
        |shape: &[usize]| arg_error(field, format!("expected shape ({N}, {N}), got {shape:?}"));
    if let Some(u) = ndarray(obj) {
        if u.shape() != [N, N] {
            return Err(wrong(u.shape()));
        }
    }
    let a = f64_array(obj, field, MAX_VALUES)?;
    if a.shape != [N, N] {
        return Err(wrong(&a.shape));
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
