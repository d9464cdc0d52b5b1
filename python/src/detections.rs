//! Detections, JSON lines (issue 40 §3, docs/detections.md): `Detections` (the library's
//! `formats::Detections`), `read_detections`, `write_detections` and `Paths.to_detections()`
//! (`estimate_recording`'s paths as `cir estimate --detections-out` writes them);
//! `track(scenario, detections)` is `track --detections` (in `tracking`). The format — its
//! parser, its checks and errors, its writer, the frames' conversion — is the core's; this
//! file only converts types.

use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::PyString;

use scatterloc::formats::Detections;

use crate::convert::{array, masked, path_string, to_json_text};
use crate::errors::Core;
use crate::scenario::read_text;

/// Detections, one line per frame and link (docs/detections.md). Made by `read_detections`,
/// `Detections(lines)` or `Paths.to_detections()`; `track` takes it. The arrays are in long
/// format, one row per detection, in the file's order; delays and σ are in seconds whatever
/// the line's `unit`.
#[pyclass(module = "scatterloc", name = "Detections", frozen)]
pub struct PyDetections {
    pub(crate) d: Detections,
}

/// The rows of the long format.
struct Rows {
    frame: Vec<i64>,
    tx: Vec<i64>,
    rx: Vec<i64>,
    delay: Vec<f64>,
    snr: Vec<Option<f64>>,
    sigma: Vec<Option<f64>>,
    doppler: Vec<Option<f64>>,
}

impl PyDetections {
    fn rows(&self) -> Rows {
        let mut r = Rows {
            frame: Vec::new(),
            tx: Vec::new(),
            rx: Vec::new(),
            delay: Vec::new(),
            snr: Vec::new(),
            sigma: Vec::new(),
            doppler: Vec::new(),
        };
        for (k, f) in self.d.frames.iter().enumerate() {
            for l in &f.lines {
                for (i, &d) in l.delay.iter().enumerate() {
                    r.frame.push(k as i64);
                    r.tx.push(l.link.tx as i64);
                    r.rx.push(l.link.rx as i64);
                    r.delay.push(l.unit.to_seconds(d));
                    r.snr.push(l.snr_db.as_ref().and_then(|s| s[i]));
                    r.sigma.push(
                        l.sigma
                            .as_ref()
                            .and_then(|s| s[i])
                            .map(|s| l.unit.to_seconds(s)),
                    );
                    r.doppler.push(l.doppler_hz.as_ref().map(|s| s[i]));
                }
            }
        }
        r
    }

    fn count(&self) -> usize {
        self.d
            .frames
            .iter()
            .flat_map(|f| &f.lines)
            .map(|l| l.delay.len())
            .sum()
    }
}

/// The detections of `text` (the core's parser: errors name the line and the field).
fn parse(text: &str) -> PyResult<PyDetections> {
    Detections::from_text(text.trim_start_matches('\u{feff}'))
        .map(|d| PyDetections { d })
        .py()
}

#[pymethods]
impl PyDetections {
    /// Detections from `lines`: an iterable of dicts, each one line of the file
    /// (`{"timestamp": t, "tx": k, "rx": l, "delay": [...], ...}`, docs/detections.md), read by
    /// the library's parser as the file of those lines (errors name `line N`, 1-based).
    #[new]
    fn new(lines: &Bound<'_, PyAny>) -> PyResult<PyDetections> {
        let mut text = String::new();
        for (i, l) in lines
            .try_iter()
            .map_err(|_| crate::errors::arg_error("lines", "expected an iterable of dicts"))?
            .enumerate()
        {
            let l = l?;
            let field = format!("lines[{i}]");
            if l.cast::<pyo3::types::PyDict>().is_err() {
                return Err(crate::errors::arg_error(
                    &field,
                    "expected a dict (one line)",
                ));
            }
            text.push_str(&to_json_text(&l, &field)?);
            text.push('\n');
        }
        parse(&text)
    }

    /// The frames' times, s, shape (F,).
    #[getter]
    fn t<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let t: Vec<f64> = self.d.frames.iter().map(|f| f.timestamp_s).collect();
        let n = t.len();
        array(py, t, &[n])
    }

    /// The frame of each detection (index into `t`), shape (D,).
    #[getter]
    fn frame<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let r = self.rows();
        let n = r.frame.len();
        array(py, r.frame, &[n])
    }

    /// The link of each detection as (tx, rx) scenario indices, shape (D, 2).
    #[getter]
    fn links<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let r = self.rows();
        let n = r.tx.len();
        let v: Vec<i64> = r.tx.iter().zip(&r.rx).flat_map(|(&a, &b)| [a, b]).collect();
        array(py, v, &[n, 2])
    }

    /// Each detection's delay, s (a bistatic range in metres divided by c), shape (D,).
    #[getter]
    fn delay<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let r = self.rows();
        let n = r.delay.len();
        array(py, r.delay, &[n])
    }

    /// Each detection's SNR, dB, shape (D,), masked where unknown.
    #[getter]
    fn snr_db<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let r = self.rows();
        masked(py, &r.snr, &[r.snr.len()])
    }

    /// Each detection's σ, s, shape (D,), masked where unknown.
    #[getter]
    fn sigma<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let r = self.rows();
        masked(py, &r.sigma, &[r.sigma.len()])
    }

    /// Each detection's Doppler shift, Hz, shape (D,), masked where not given.
    #[getter]
    fn doppler<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let r = self.rows();
        masked(py, &r.doppler, &[r.doppler.len()])
    }

    /// The file's text, as `write_detections` writes it and `cir estimate --detections-out`
    /// would (the library's writer: one line per frame and link, numbers in their shortest
    /// round-trip form).
    fn to_text(&self) -> String {
        self.d.to_text()
    }

    /// The lines as dicts (`json.loads` of each line of `to_text()`).
    fn lines<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        static LOADS: PyOnceLock<Py<PyAny>> = PyOnceLock::new();
        let text = self.d.to_text();
        let list = format!("[{}]", text.lines().collect::<Vec<_>>().join(","));
        LOADS.import(py, "json", "loads")?.call1((list,))
    }

    fn __len__(&self) -> usize {
        self.count()
    }

    fn __eq__(&self, other: &Bound<'_, PyAny>) -> bool {
        other
            .cast::<PyDetections>()
            .is_ok_and(|o| o.get().d.to_text() == self.d.to_text())
    }

    fn __repr__(&self) -> String {
        let lines: usize = self.d.frames.iter().map(|f| f.lines.len()).sum();
        format!(
            "Detections(frames={}, lines={lines}, detections={})",
            self.d.frames.len(),
            self.count()
        )
    }
}

/// Reads detections (docs/detections.md; `scatterloc track --detections` reads the same):
/// `source` is a path (`str` or `os.PathLike`) or the text itself (a `str` holding a newline
/// or starting with `{` or `#`). Errors (`ScatterlocError`) name the line and the field, as
/// the CLI's.
#[pyfunction]
pub fn read_detections(source: &Bound<'_, PyAny>) -> PyResult<PyDetections> {
    if let Ok(s) = source.cast::<PyString>() {
        let s = s.to_cow()?;
        let t = s.trim_start_matches('\u{feff}').trim_start();
        if s.contains('\n') || t.starts_with('{') || t.starts_with('#') || t.is_empty() {
            return parse(&s);
        }
    }
    let p = path_string(source)?;
    parse(&read_text(&p, "source")?)
}

/// Writes `detections` to `path` (the library's writer, `Detections.to_text()`), atomically as
/// the CLI writes its outputs (`crate::output`).
#[pyfunction]
pub fn write_detections(
    py: Python<'_>,
    path: &Bound<'_, PyAny>,
    detections: &PyDetections,
) -> PyResult<()> {
    let p = std::path::PathBuf::from(path_string(path)?);
    crate::output::write_file(py, "path", &p, detections.d.to_text().as_bytes())
}
