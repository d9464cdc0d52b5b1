//! Several targets (issue 41): `track_multi` (a measurements file's `raw_steps` through the PMB
//! tracker or the GNN baseline — the library's `study::track_multi`, scored by
//! `study::score_multi` against a truth, as `scatterloc track --targets auto`) and
//! `simulate_people` (the library's `study::simulate_people` in `study::walk_region`, as
//! `scatterloc simulate-walk --walkers N`). Types are converted here; every check and number is
//! the library's.

use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString};

use scatterloc::error::Cancel;
use scatterloc::formats::{CalibrationResult, Measurements};
use scatterloc::scenario::parse_json;
use scatterloc::study::{
    score_multi, simulate_people as core_simulate_people, track_multi as core_track_multi,
    walk_region, MultiSettings, MultiTrackOutput, MultiTruth, Walkers, DEFAULT_PROCESS_NOISE,
};
use scatterloc::track::gating::Calibration;
use scatterloc::track::multi::MultiKind;
use scatterloc::track::{step_count, ConstantVelocity, MAX_STEPS};

use crate::convert::{array, f64_array, path_string, to_json_text, to_python, JsonDoc};
use crate::detections::PyDetections;
use crate::errors::{arg_error, Core};
use crate::run::{run_job, run_quick};
use crate::scenario::{read_text, scenario_arg};
use crate::tracking::StaticCalibration;

/// The keywords of `track_multi` as the library's [`MultiSettings`] (the one conversion; the
/// settings not given keep the library's defaults, as the CLI's flags do).
fn multi_settings(
    method: &str,
    detection_probability: f64,
    clutter: f64,
    clutter_window_s: f64,
    birth_rate: f64,
) -> PyResult<MultiSettings> {
    Ok(MultiSettings {
        method: MultiKind::parse(method).py()?,
        detection_probability,
        clutter,
        clutter_window_s,
        birth_rate,
        ..MultiSettings::default()
    })
}

/// Whether `obj` is a document argument: a dict or a path (`str` or `os.PathLike`).
fn is_document(obj: &Bound<'_, PyAny>) -> PyResult<bool> {
    Ok(obj.cast::<PyDict>().is_ok()
        || obj.cast::<PyString>().is_ok()
        || obj.hasattr("__fspath__")?)
}

/// A document argument (`field`): a dict (as `json.load` gives it) or a path to the JSON file,
/// as text.
fn document_text(obj: &Bound<'_, PyAny>, field: &str) -> PyResult<String> {
    let text = if obj.cast::<PyDict>().is_ok() {
        to_json_text(obj, field)?
    } else if is_document(obj)? {
        read_text(&path_string(obj)?, field)?
    } else {
        return Err(arg_error(
            field,
            "expected a dict (the file's JSON document) or a path to the file",
        ));
    };
    Ok(text.trim_start_matches('\u{feff}').to_string())
}

/// The measurements of `track_multi`: a file (dict or path) or `Detections` (converted with
/// `process_noise`, as `track --detections`).
fn measurements_arg(
    obj: &Bound<'_, PyAny>,
    model: &scatterloc::Model,
    process_noise: Option<f64>,
) -> PyResult<Measurements> {
    if let Ok(d) = obj.cast::<PyDetections>() {
        let q = process_noise.unwrap_or(DEFAULT_PROCESS_NOISE);
        return d.get().d.to_measurements(model, q).py();
    }
    if process_noise.is_some() {
        return Err(arg_error(
            "process_noise",
            "only with detections (a measurements file has its own process_noise)",
        ));
    }
    if !is_document(obj)? {
        return Err(arg_error(
            "measurements",
            "expected a measurements file (a dict or a path) or Detections",
        ));
    }
    let text = document_text(obj, "measurements")?;
    Measurements::from_json(&text).py()
}

/// A calibration argument: a `StaticCalibration`, a dict (the calibration file) or a path, for
/// `links` links.
fn calibration_arg(obj: &Bound<'_, PyAny>, links: usize) -> PyResult<Calibration> {
    let text = if obj.cast::<StaticCalibration>().is_ok() {
        to_json_text(&obj.call_method0("to_dict")?, "calibration")?
    } else {
        document_text(obj, "calibration")?
    };
    CalibrationResult::from_json(&text)
        .py()?
        .into_calibration(links)
        .py()
}

/// A multi-target track (returned by `track_multi`). The reported targets in long format, one
/// row per scan and target (scans in order, labels ascending within a scan):
/// `states[label == l]` is target `l`'s track at times `t[scan[label == l]]`.
#[pyclass(module = "scatterloc", frozen)]
pub struct MultiTrack {
    /// Scan times `t_k = k T`, s, shape (S,).
    #[pyo3(get)]
    t: Py<PyAny>,
    /// The scan of each reported target, shape (K,).
    #[pyo3(get)]
    scan: Py<PyAny>,
    /// The label of each reported target, shape (K,).
    #[pyo3(get)]
    label: Py<PyAny>,
    /// States [x, y, vx, vy] (m, m/s), shape (K, 4).
    #[pyo3(get)]
    states: Py<PyAny>,
    /// Covariances, shape (K, 4, 4).
    #[pyo3(get)]
    covariances: Py<PyAny>,
    /// Existence probabilities (1 for the GNN's confirmed tracks), shape (K,).
    #[pyo3(get)]
    existence: Py<PyAny>,
    /// Targets reported per scan, shape (S,).
    #[pyo3(get)]
    count: Py<PyAny>,
    /// Every label reported, ascending, shape (N,).
    #[pyo3(get)]
    labels: Py<PyAny>,
    /// Per label its life (`label`, `first_scan`, `last_scan`, `scans`, `start`, `end`), a list
    /// of dicts in label order.
    #[pyo3(get)]
    tracks: Py<PyAny>,
    /// Estimates removed as static by the calibration per scan (all links), shape (S,).
    #[pyo3(get)]
    static_removed: Py<PyAny>,
    /// With `truth`: the score (GOSPA per scan and its parts, label switches, mean cardinality
    /// error), a dict; else None.
    #[pyo3(get)]
    score: Py<PyAny>,
    /// `pmb` or `gnn`.
    #[pyo3(get)]
    method: String,
    doc: JsonDoc,
    scans: usize,
    reported: usize,
}

#[pymethods]
impl MultiTrack {
    /// The document `scatterloc track --targets auto` prints for the same input (with `score`
    /// when a truth was given).
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.doc.to_python(py)
    }

    fn __repr__(&self) -> String {
        format!(
            "MultiTrack(method='{}', scans={}, reported={})",
            self.method, self.scans, self.reported
        )
    }

    fn __len__(&self) -> usize {
        self.scans
    }
}

/// The Python object of a multi-target track and its document (`score` added as the CLI adds
/// it).
fn multi_object(
    py: Python<'_>,
    out: &MultiTrackOutput,
    score: Option<serde_json::Value>,
) -> PyResult<MultiTrack> {
    let encoding = |e: serde_json::Error| {
        pyo3::exceptions::PyRuntimeError::new_err(format!("encoding JSON: {e}"))
    };
    let mut value = serde_json::to_value(out).map_err(encoding)?;
    let score_obj = match score {
        Some(s) => {
            value["score"] = s.clone();
            to_python(py, &s)?.unbind()
        }
        None => py.None(),
    };
    let rows: Vec<(usize, &scatterloc::study::TargetDoc)> = out
        .targets
        .iter()
        .enumerate()
        .flat_map(|(k, scan)| scan.iter().map(move |t| (k, t)))
        .collect();
    let k = rows.len();
    let s = out.t_s.len();
    Ok(MultiTrack {
        t: array(py, out.t_s.clone(), &[s])?.unbind(),
        scan: array(py, rows.iter().map(|(k, _)| *k as i64).collect(), &[k])?.unbind(),
        label: array(py, rows.iter().map(|(_, t)| t.label as i64).collect(), &[k])?.unbind(),
        states: array(
            py,
            rows.iter().flat_map(|(_, t)| t.state).collect(),
            &[k, 4],
        )?
        .unbind(),
        covariances: array(
            py,
            rows.iter()
                .flat_map(|(_, t)| t.covariance.iter().flatten().copied())
                .collect(),
            &[k, 4, 4],
        )?
        .unbind(),
        existence: array(py, rows.iter().map(|(_, t)| t.existence).collect(), &[k])?.unbind(),
        count: array(
            py,
            out.targets.iter().map(|s| s.len() as i64).collect(),
            &[s],
        )?
        .unbind(),
        labels: array(
            py,
            out.tracks.iter().map(|t| t.label as i64).collect(),
            &[out.tracks.len()],
        )?
        .unbind(),
        tracks: to_python(py, &out.tracks)?.unbind(),
        static_removed: array(
            py,
            out.static_removed.iter().map(|&n| n as i64).collect(),
            &[out.static_removed.len()],
        )?
        .unbind(),
        score: score_obj,
        method: out.method.clone(),
        doc: JsonDoc::of(&value)?,
        scans: s,
        reported: k,
    })
}

/// Tracks several targets in `measurements` on `scenario` (issue 41), as `scatterloc track
/// --targets auto` does with the same file: every scan (the `initial_snapshot`, if any, then
/// each of the `raw_steps`: every link's unlabelled delays) goes through the PMB tracker
/// (`method="pmb"`, belief-propagation association) or the GNN baseline (`"gnn"`), which start
/// targets from a birth grid over the scenario's area and end them on their own; static paths
/// are first removed by `calibration` (a `StaticCalibration`, a dict or a path; E4).
///
/// `measurements` is a measurements file with `raw_steps` (a dict as `json.load` gives it, or a
/// path; `simulate_people` makes one) or `Detections` (`track --detections --targets auto`;
/// `process_noise`, default 1 m²/s³, is then its only other argument). The tracker's
/// settings: `detection_probability` per link (0 < P_D < 1), `clutter` (mean false delays per
/// link and scan) spread over `clutter_window_s`, `birth_rate` (expected new targets per scan).
/// `truth` (a dict as `simulate_people`'s or the CLI's `truth.json`, or a path) adds `score`:
/// GOSPA (cut-off `gospa_c`, default 1 m, p = 2) per scan with its parts, label switches and
/// the mean cardinality error. Runs without the GIL; Ctrl-C stops it.
#[pyfunction]
#[pyo3(signature = (
    scenario, measurements, *, calibration = None, method = "pmb", detection_probability = 0.9,
    clutter = 5.0, clutter_window_s = 60e-9, birth_rate = 0.01, truth = None, gospa_c = None,
    process_noise = None
))]
#[allow(clippy::too_many_arguments)]
pub fn track_multi(
    py: Python<'_>,
    scenario: &Bound<'_, PyAny>,
    measurements: &Bound<'_, PyAny>,
    calibration: Option<&Bound<'_, PyAny>>,
    method: &str,
    detection_probability: f64,
    clutter: f64,
    clutter_window_s: f64,
    birth_rate: f64,
    truth: Option<&Bound<'_, PyAny>>,
    gospa_c: Option<f64>,
    process_noise: Option<f64>,
) -> PyResult<MultiTrack> {
    let sc = scenario_arg(scenario)?;
    let model = sc.model();
    let settings = multi_settings(
        method,
        detection_probability,
        clutter,
        clutter_window_s,
        birth_rate,
    )?;
    if truth.is_none() && gospa_c.is_some() {
        return Err(arg_error("gospa_c", "only with truth (the score)"));
    }
    let m = measurements_arg(measurements, model, process_noise)?;
    let cal = calibration
        .map(|c| calibration_arg(c, model.link_count()))
        .transpose()?;
    let truth: Option<MultiTruth> = truth
        .map(|t| parse_json(&document_text(t, "truth")?).py())
        .transpose()?;
    let area = sc.scenario().area_m;
    let scans = m.raw_steps.as_ref().map_or(0, Vec::len) + 1;
    let out = run_job(py, scans, None, |job| {
        let stop = || job.cancelled();
        core_track_multi(
            model,
            &area,
            &m,
            cal.as_ref(),
            &settings,
            Cancel::when(&stop),
        )
    })?;
    let score = match &truth {
        Some(t) => {
            let s = run_quick(py, || score_multi(&out, t, gospa_c.unwrap_or(1.0)))?;
            Some(serde_json::to_value(&s).map_err(|e| {
                pyo3::exceptions::PyRuntimeError::new_err(format!("encoding JSON: {e}"))
            })?)
        }
        None => None,
    };
    multi_object(py, &out, score)
}

/// People walking through `scenario`'s network and their delay scans (issue 41), as `scatterloc
/// simulate-walk --walkers N` writes them: `walkers` (1 … 5) people in the people region of
/// issue 41 (the central half of the area when the area does not hold it) for `duration_s` at
/// `dt_s` (one scan at t₀ and one per step), each link detecting each person with
/// `detection_probability` plus `clutter` false delays per scan, the measurements' process noise
/// `process_noise` (m²/s³); seeded by `seed`. `paths` (a numpy `(n, 4)` array or a list of
/// `(x0, y0, x1, y1)`, m; 1 … 5 rows) replaces the planned walkers by one walker per drawn path,
/// walking the straight line at constant velocity over the run (`simulate-walk --path`);
/// `walkers` may then be left out, else it must equal the rows. Returns `(measurements,
/// truth)`: the dicts of the CLI's `measurements.json` (`initial_snapshot` and `raw_steps`;
/// `track_multi` takes it) and `truth.json` (per scan the labelled targets present).
#[pyfunction]
#[pyo3(signature = (
    scenario, walkers = None, *, paths = None, duration_s = 10.0, dt_s = 0.1,
    process_noise = 0.5, detection_probability = 0.9, clutter = 5.0, seed = 1
))]
#[allow(clippy::too_many_arguments)]
pub fn simulate_people<'py>(
    py: Python<'py>,
    scenario: &Bound<'py, PyAny>,
    walkers: Option<usize>,
    paths: Option<&Bound<'py, PyAny>>,
    duration_s: f64,
    dt_s: f64,
    process_noise: f64,
    detection_probability: f64,
    clutter: f64,
    seed: u64,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
    let walkers = walkers_arg(walkers, paths)?;
    let sc = scenario_arg(scenario)?;
    ConstantVelocity::validated(dt_s, process_noise).py()?;
    // The scans: one at t₀ and one per step of the duration (the CLI's rule).
    if duration_s.is_nan() || duration_s <= 0.0 {
        return Err(arg_error(
            "duration_s",
            format!("must be > 0 s (got {duration_s})"),
        ));
    }
    let steps = step_count(duration_s, dt_s);
    if steps == 0 || steps > MAX_STEPS {
        return Err(scatterloc::Error::SizeLimit {
            field: "steps",
            value: steps,
            min: 1,
            max: MAX_STEPS,
        })
        .py();
    }
    let settings = MultiSettings {
        detection_probability,
        clutter,
        ..MultiSettings::default()
    };
    let region = walk_region(&sc.scenario().area_m);
    let model = sc.model();
    let (m, truth) = run_quick(py, || {
        core_simulate_people(
            model,
            &region,
            walkers.clone(),
            steps + 1,
            dt_s,
            process_noise,
            &settings,
            seed,
        )
    })?;
    Ok((to_python(py, &m)?, to_python(py, &truth)?))
}

/// The walkers of `simulate_people`: the drawn `paths` (rows `x0, y0, x1, y1`; `walkers`, if
/// given, their count) or the `walkers` count. The library checks the count and the paths.
fn walkers_arg(walkers: Option<usize>, paths: Option<&Bound<'_, PyAny>>) -> PyResult<Walkers> {
    let Some(p) = paths.filter(|p| !p.is_none()) else {
        return walkers
            .map(Walkers::Count)
            .ok_or_else(|| arg_error("walkers", "missing: give walkers (1 … 5) or paths"));
    };
    // Room for more rows than the library allows, so that it names the count.
    let a = f64_array(p, "paths", 4 * 64)?;
    let rows = match a.shape.as_slice() {
        [0] => 0,
        [n, 4] => *n,
        s => {
            return Err(arg_error(
                "paths",
                format!("shape {s:?}: expected (n, 4) rows x0, y0, x1, y1"),
            ))
        }
    };
    if let Some(n) = walkers.filter(|&n| n != rows) {
        return Err(arg_error(
            "walkers",
            format!("{n} walkers but {rows} paths (leave walkers out)"),
        ));
    }
    Ok(Walkers::Drawn(
        a.data
            .chunks_exact(4)
            .map(|q| ([q[0], q[1]], [q[2], q[3]]))
            .collect(),
    ))
}
