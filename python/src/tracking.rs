//! Tracking: `track` (a delay sequence, or raw estimates gated and associated, through the
//! EKF, UKF or particle filter — the library's `study::track_measurements`, as `scatterloc
//! track`) and `calibrate` (the static paths of the empty area, spec §4, as `scatterloc
//! calibrate`), plus the filter settings shared with the studies. Range rates (issue 42 §5) in
//! `track`: `track_doppler`.

use pyo3::prelude::*;

use scatterloc::error::Cancel;
use scatterloc::formats::{
    CalibrationResult, CalibrationSnapshots, Measurements, RawEstimate, RawStep, Sigma,
};
use scatterloc::study::{
    track_cpu_s, track_doppler_cpu_s, track_measurements_in, TrackOutput, TrackRequest,
    DEFAULT_PROCESS_NOISE, MAX_CPU_S,
};
use scatterloc::track::gating::{AssociationRule, Calibration, ClusterConfig};
use scatterloc::track::{FilterKind, FilterSettings};

use crate::convert::{array, f64_array, masked, matrix, to_json_text, to_python};
use crate::detections::PyDetections;
use crate::errors::{arg_error, Core};
use crate::run::run_sized;
use crate::scenario::{read_text, scenario_arg};
use crate::track_doppler::{doppler_object, RateArgs, TrackDoppler};

/// The filter settings of `track`, `cir_track` and `montecarlo` as given (None = not given):
/// the library's [`FilterSettings`], which refuses a setting of a filter that is not run.
pub fn settings(
    ukf: [Option<f64>; 3],
    particles: Option<usize>,
    roughening: Option<f64>,
    bootstrap: Option<bool>,
) -> FilterSettings {
    FilterSettings {
        ukf_alpha: ukf[0],
        ukf_beta: ukf[1],
        ukf_kappa: ukf[2],
        particles,
        roughening,
        bootstrap: bootstrap.unwrap_or(false),
    }
}

/// The one filter `name` of `track` and `cir_track` (the argument `filter`), and its `seed`
/// checked (the particle filter's only).
pub fn one_filter(s: &FilterSettings, name: &str, seed: Option<u64>) -> PyResult<FilterKind> {
    let kind = s.kinds(&[name], "filter", |_| "filter".into()).py()?[0];
    if seed.is_some() && name != "pf" {
        return Err(arg_error(
            "seed",
            "only for the pf filter (filter is not pf)",
        ));
    }
    Ok(kind)
}

/// The CPU cap in seconds from `max_cpu_hours` (default 24 h, at most 10⁶ h).
pub fn cpu_cap(max_cpu_hours: Option<f64>) -> PyResult<f64> {
    match max_cpu_hours {
        None => Ok(MAX_CPU_S),
        Some(h) if h > 0.0 && h <= 1e6 => Ok(h * 3600.0),
        Some(h) => Err(arg_error(
            "max_cpu_hours",
            format!("{h} is outside the allowed range 0 < H <= 1e6"),
        )),
    }
}

/// A static-path calibration (returned by `calibrate`; `track(..., calibration=c)` takes it).
#[pyclass(module = "scatterloc", frozen)]
pub struct StaticCalibration {
    file: CalibrationResult,
}

#[pymethods]
impl StaticCalibration {
    /// The calibration file `scatterloc calibrate` writes (`track --calibration` reads it).
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_python(py, &self.file)
    }

    /// Per link, the static clusters as an array (K, 2) of (mean delay, σ̄), s.
    #[getter]
    fn clusters<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyAny>>> {
        self.file
            .links
            .iter()
            .map(|l| {
                let v: Vec<f64> = l
                    .clusters
                    .iter()
                    .flat_map(|c| [c.mean_s, c.sigma_s])
                    .collect();
                array(py, v, &[l.clusters.len(), 2])
            })
            .collect()
    }

    fn __repr__(&self) -> String {
        let n: usize = self.file.links.iter().map(|l| l.clusters.len()).sum();
        format!(
            "StaticCalibration(links={}, clusters={n})",
            self.file.links.len()
        )
    }
}

/// The static paths of the empty area (spec §4): per link the delays of `snapshots` (a list of
/// snapshots, each a list per link of delays, s) sorted and split where neighbours differ by
/// more than `gap` (default 1/B), the clusters seen in at least `min_fraction` of the snapshots
/// kept, σ̄ floored at `sigma_floor` (default 0.01/B). The result of `scatterloc calibrate`.
#[pyfunction]
#[pyo3(signature = (scenario, snapshots, *, gap = None, min_fraction = None, sigma_floor = None))]
pub fn calibrate(
    scenario: &Bound<'_, PyAny>,
    snapshots: &Bound<'_, PyAny>,
    gap: Option<f64>,
    min_fraction: Option<f64>,
    sigma_floor: Option<f64>,
) -> PyResult<StaticCalibration> {
    let sc = scenario_arg(scenario)?;
    let n = sc.model().link_count();
    let mut cfg = ClusterConfig::for_bandwidth(sc.scenario().radio.bandwidth_hz).py()?;
    if let Some(g) = gap {
        cfg.gap_s = g;
    }
    if let Some(f) = min_fraction {
        cfg.min_fraction = f;
    }
    if let Some(s) = sigma_floor {
        cfg.sigma_floor_s = s;
    }
    cfg.validate().py()?;
    let snaps: Vec<Vec<Vec<f64>>> = snapshots.extract().map_err(|_| {
        arg_error(
            "snapshots",
            "expected a list of snapshots, each a list per link of delays (s)",
        )
    })?;
    let f = CalibrationSnapshots { snapshots: snaps };
    let cal = f.calibrate(n, &cfg).py()?;
    Ok(StaticCalibration {
        file: CalibrationResult::of(cal, &cfg, f.snapshots.len()),
    })
}

/// A calibration argument: a [`StaticCalibration`], a dict (the calibration file) or a path.
fn calibration_arg(obj: &Bound<'_, PyAny>, links: usize) -> PyResult<Calibration> {
    let file = if let Ok(c) = obj.cast::<StaticCalibration>() {
        c.get().file.clone()
    } else if obj.cast::<pyo3::types::PyDict>().is_ok() {
        CalibrationResult::from_json(&to_json_text(obj, "calibration")?).py()?
    } else {
        let p = crate::convert::path_string(obj)?;
        CalibrationResult::from_json(&read_text(&p, "calibration")?).py()?
    };
    file.into_calibration(links).py()
}

/// One raw step from Python: per link an array (K, 2) of (delay, amplitude) or (K, 3) of
/// (delay, amplitude, σ).
fn raw_step(obj: &Bound<'_, PyAny>, field: &str, links: usize) -> PyResult<RawStep> {
    let per_link: Vec<Bound<'_, PyAny>> = obj.extract().map_err(|_| {
        arg_error(
            field,
            "expected a list with one array of estimates per link",
        )
    })?;
    if per_link.len() != links {
        return Err(arg_error(
            field,
            format!("expected {links} links, got {}", per_link.len()),
        ));
    }
    per_link
        .iter()
        .enumerate()
        .map(|(p, l)| {
            let f = format!("{field}[{p}]");
            let a = f64_array(l, &f, crate::convert::MAX_VALUES)?;
            match a.shape.as_slice() {
                [0] | [0, _] => Ok(Vec::new()),
                [_, 2] => Ok(a
                    .data
                    .chunks_exact(2)
                    .map(|e| RawEstimate::Pair([e[0], e[1]]))
                    .collect()),
                [_, 3] => Ok(a
                    .data
                    .chunks_exact(3)
                    .map(|e| RawEstimate::WithSigma([e[0], e[1], e[2]]))
                    .collect()),
                s => Err(arg_error(
                    &f,
                    format!("expected estimates of shape (K, 2) or (K, 3), got {s:?}"),
                )),
            }
        })
        .collect()
}

/// A track (returned by `track`): per step (after its update) the time, the state and its
/// covariance, the NIS and the links used; with raw estimates also the delays used, how each
/// link was chosen and the static estimates removed; with range rates how they were used
/// (`doppler`).
#[pyclass(module = "scatterloc", frozen)]
pub struct Track {
    /// `t_k = (k + 1) T`, s, shape (S,).
    #[pyo3(get)]
    t: Py<PyAny>,
    /// States [x, y, vx, vy] (m, m/s), shape (S, 4).
    #[pyo3(get)]
    states: Py<PyAny>,
    /// Covariances, shape (S, 4, 4).
    #[pyo3(get)]
    covariances: Py<PyAny>,
    /// NIS νᵀS⁻¹ν per step, shape (S,), masked where no link was used.
    #[pyo3(get)]
    nis: Py<PyAny>,
    /// Links used per step, shape (S,).
    #[pyo3(get)]
    links_used: Py<PyAny>,
    /// Raw estimates only: the delay taken per step and link, s, shape (S, L), masked where
    /// absent; else None.
    #[pyo3(get)]
    delays_used: Py<PyAny>,
    /// Raw estimates only: how each link was chosen (`absent`, `single`, `nearest`,
    /// `strongest`), a list per step; else None.
    #[pyo3(get)]
    choices: Py<PyAny>,
    /// Raw estimates only: estimates removed as static (E4) per step and link, shape (S, L);
    /// else None.
    #[pyo3(get)]
    static_removed: Py<PyAny>,
    /// `initial_snapshot` only: the LM fix that started the filter (a dict); else None.
    #[pyo3(get)]
    start: Py<PyAny>,
    /// With range rates only: how they were used (`TrackDoppler`: the predicted range rates,
    /// their innovations, the σ); else None.
    #[pyo3(get)]
    doppler: Option<Py<TrackDoppler>>,
    out: TrackOutput,
}

#[pymethods]
impl Track {
    /// The document `scatterloc track` prints for the same input.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_python(py, &self.out)
    }

    fn __repr__(&self) -> String {
        format!("Track(steps={})", self.out.t_s.len())
    }

    fn __len__(&self) -> usize {
        self.out.t_s.len()
    }
}

/// The Python object of a track of `n` links.
pub fn track_object(py: Python<'_>, out: TrackOutput, n: usize) -> PyResult<Track> {
    let s = out.t_s.len();
    let states: Vec<f64> = out.states.iter().flatten().copied().collect();
    let covs: Vec<f64> = out
        .covariances
        .iter()
        .flatten()
        .flatten()
        .copied()
        .collect();
    let links = out
        .delays_used_s
        .as_ref()
        .and_then(|d| d.first())
        .map_or(0, Vec::len);
    let delays_used = match &out.delays_used_s {
        Some(d) => {
            let flat: Vec<Option<f64>> = d.iter().flatten().copied().collect();
            masked(py, &flat, &[s, links])?.unbind()
        }
        None => py.None(),
    };
    let static_removed = match &out.static_removed {
        Some(r) => array(
            py,
            r.iter().flatten().map(|&n| n as i64).collect(),
            &[s, links],
        )?
        .unbind(),
        None => py.None(),
    };
    let choices = match &out.choices {
        Some(c) => c.clone().into_pyobject(py)?.into_any().unbind(),
        None => py.None(),
    };
    let start = match &out.start {
        Some(st) => to_python(py, st)?.unbind(),
        None => py.None(),
    };
    let doppler = match &out.doppler {
        Some(d) => Some(Py::new(py, doppler_object(py, d, n)?)?),
        None => None,
    };
    Ok(Track {
        t: array(py, out.t_s.clone(), &[s])?.unbind(),
        states: array(py, states, &[s, 4])?.unbind(),
        covariances: array(py, covs, &[s, 4, 4])?.unbind(),
        nis: masked(py, &out.nis, &[s])?.unbind(),
        links_used: array(py, out.links_used.iter().map(|&n| n as i64).collect(), &[s])?.unbind(),
        delays_used,
        choices,
        static_removed,
        start,
        doppler,
        out,
    })
}

/// Tracks `measurements` on `scenario` (spec §6; §4 for raw estimates) with the EKF, the UKF or
/// the particle filter (`filter`), as `scatterloc track` does with the same file.
///
/// `measurements` is one of:
/// - an array (S, L) of delays, s, one per step and link (NaN = missing): the `steps` form,
///   with `dt` (s), `process_noise` (q̃, m²/s³), `initial_state` [x, y, vx, vy] and
///   `initial_covariance` (4, 4), and `sigma` (s, one or per link; default the link budget at
///   the prediction, E8);
/// - a list of S raw steps, each a list per link of an array (K, 2) of (delay, amplitude) or
///   (K, 3) with the estimator's σ: the `raw_steps` form, gated against `calibration` (E4) and
///   associated (`association`: `"spec"` or `"gated"`); start from `initial_state` and
///   `initial_covariance`, or from the LM fix of `initial_snapshot` (one raw step at t₀);
/// - a dict (a measurement file, as `json.load` gives it) or a path to one; the other
///   measurement arguments must then be absent (a file with `range_rates_mps` is tracked with
///   them, as `scatterloc track`);
/// - `Detections` (docs/detections.md; `scatterloc track --detections`): the first frame
///   starts the track (`initial_snapshot`), the others are its raw steps, `dt` their mean
///   spacing; `process_noise` (default 1 m²/s³) is the only other measurement argument.
///
/// Range rates (issue 42 §5, docs/doppler.md D1, D5), with delays per step only: `range_rates`
/// an array (S, L), m/s (NaN = missing), their σ fixed by `range_rate_sigma` (m/s, one or per
/// link) or from a CPI at the prediction: `cpi` snapshots `cpi_spacing_s` apart with the floor
/// `range_rate_floor` (m/s) (the names of `sigma_range_rates`; any of them given makes the
/// CPI, the others at 16, 2.048e-3 s and 0.1 m/s; it overrides a file's `cpi` as `track
/// --doppler --cpi ...`); neither: the file's `cpi`, else that default CPI. Every step then
/// updates with delays and range rates; `doppler=False` ignores them (the delay-only track, as
/// `--no-doppler`). The track's `doppler` says how they were used. `doppler` or a CPI argument
/// without range rates, or a CPI beside a fixed σ, is an error naming the argument.
///
/// `filter` settings (`ukf_alpha`, `ukf_beta`, `ukf_kappa`; `particles`, `roughening`,
/// `bootstrap`, `seed`) apply to their filter only (an error otherwise, as the CLI's flags).
/// A track predicted to take more than `max_cpu_hours` (24) is refused. Runs without the GIL;
/// Ctrl-C stops it.
#[pyfunction]
#[pyo3(signature = (
    scenario, measurements, *, dt = None, process_noise = None, initial_state = None,
    initial_covariance = None, initial_snapshot = None, sigma = None, filter = "ekf",
    particles = None, roughening = None, bootstrap = None, seed = None, ukf_alpha = None,
    ukf_beta = None, ukf_kappa = None, calibration = None, association = None,
    max_cpu_hours = None, range_rates = None, range_rate_sigma = None, cpi = None,
    cpi_spacing_s = None, range_rate_floor = None, doppler = None
))]
#[allow(clippy::too_many_arguments)]
pub fn track(
    py: Python<'_>,
    scenario: &Bound<'_, PyAny>,
    measurements: &Bound<'_, PyAny>,
    dt: Option<f64>,
    process_noise: Option<f64>,
    initial_state: Option<&Bound<'_, PyAny>>,
    initial_covariance: Option<&Bound<'_, PyAny>>,
    initial_snapshot: Option<&Bound<'_, PyAny>>,
    sigma: Option<&Bound<'_, PyAny>>,
    filter: &str,
    particles: Option<usize>,
    roughening: Option<f64>,
    bootstrap: Option<bool>,
    seed: Option<u64>,
    ukf_alpha: Option<f64>,
    ukf_beta: Option<f64>,
    ukf_kappa: Option<f64>,
    calibration: Option<&Bound<'_, PyAny>>,
    association: Option<&str>,
    max_cpu_hours: Option<f64>,
    range_rates: Option<&Bound<'_, PyAny>>,
    range_rate_sigma: Option<&Bound<'_, PyAny>>,
    cpi: Option<i64>,
    cpi_spacing_s: Option<f64>,
    range_rate_floor: Option<f64>,
    doppler: Option<bool>,
) -> PyResult<Track> {
    let rate_args = RateArgs {
        range_rates,
        range_rate_sigma,
        cpi,
        cpi_spacing_s,
        range_rate_floor,
        doppler,
    };
    let sc = scenario_arg(scenario)?;
    let model = sc.model();
    let n = model.link_count();
    let kind = one_filter(
        &settings(
            [ukf_alpha, ukf_beta, ukf_kappa],
            particles,
            roughening,
            bootstrap,
        ),
        filter,
        seed,
    )?;
    let detections = measurements.cast::<PyDetections>().ok();
    let is_file = detections.is_some()
        || measurements.cast::<pyo3::types::PyDict>().is_ok()
        || measurements.cast::<pyo3::types::PyString>().is_ok()
        || measurements.hasattr("__fspath__")?;
    let (m, fields) = if is_file {
        let numpy_rates = rate_args.given_numpy();
        let given = [
            ("dt", dt.is_some()),
            // Detections take the process noise (`track --detections --process-noise`).
            (
                "process_noise",
                process_noise.is_some() && detections.is_none(),
            ),
            ("initial_state", initial_state.is_some()),
            ("initial_covariance", initial_covariance.is_some()),
            ("initial_snapshot", initial_snapshot.is_some()),
            ("sigma", sigma.is_some()),
            numpy_rates[0],
            numpy_rates[1],
        ];
        if let Some((f, _)) = given.iter().find(|(_, g)| *g) {
            return Err(arg_error(
                f,
                if detections.is_some() {
                    "not with detections: the frames give it (their spacing, the first frame)"
                } else {
                    "given twice: the measurement file (dict or path) holds it"
                },
            ));
        }
        if let Some(d) = detections {
            let q = process_noise.unwrap_or(DEFAULT_PROCESS_NOISE);
            (
                d.get().d.to_measurements(model, q).py()?,
                Default::default(),
            )
        } else {
            let text = if measurements.cast::<pyo3::types::PyDict>().is_ok() {
                to_json_text(measurements, "measurements")?
            } else {
                read_text(&crate::convert::path_string(measurements)?, "measurements")?
            };
            Measurements::from_json_with_rates(text.trim_start_matches('\u{feff}')).py()?
        }
    } else {
        let dt = dt.ok_or_else(|| arg_error("dt", "required with delays or raw estimates"))?;
        let q = process_noise
            .ok_or_else(|| arg_error("process_noise", "required with delays or raw estimates"))?;
        let initial_state = initial_state
            .map(|s| crate::convert::f64_vec(s, "initial_state", crate::convert::Len::Exactly(4)))
            .transpose()?
            .map(|v| [v[0], v[1], v[2], v[3]]);
        let initial_covariance = initial_covariance
            .map(|c| matrix::<4>(c, "initial_covariance"))
            .transpose()?;
        let sigma_s = match sigma {
            None => None,
            Some(s) => Some(match s.extract::<f64>() {
                Ok(v) => Sigma::One(v),
                Err(_) => Sigma::PerLink(crate::convert::f64_vec(
                    s,
                    "sigma",
                    crate::convert::Len::AtMost(scatterloc::error::limits::MAX_LINKS),
                )?),
            }),
        };
        let is_array = measurements.cast::<numpy::PyUntypedArray>().is_ok();
        let plain = if is_array {
            true
        } else {
            // A list: plain when its first step is a flat list of numbers.
            let steps: Vec<Bound<'_, PyAny>> = measurements.extract().map_err(|_| {
                arg_error(
                    "measurements",
                    "expected an array (S, L), a list of raw steps, a dict or a path",
                )
            })?;
            steps
                .first()
                .is_none_or(|s| s.extract::<Vec<f64>>().is_ok())
        };
        let (steps, raw_steps) = if plain {
            let a = f64_array(measurements, "measurements", crate::convert::MAX_VALUES)?;
            let rows = match a.shape.as_slice() {
                [_, l] if *l == n => a.data.chunks_exact(n).count(),
                [0] => 0,
                s => {
                    return Err(arg_error(
                        "measurements",
                        format!("expected delays of shape (S, {n}), got {s:?}"),
                    ))
                }
            };
            let steps: Vec<Vec<Option<f64>>> = (0..rows)
                .map(|k| {
                    a.data[k * n..(k + 1) * n]
                        .iter()
                        .map(|&v| if v.is_nan() { None } else { Some(v) })
                        .collect()
                })
                .collect();
            (Some(steps), None)
        } else {
            let list: Vec<Bound<'_, PyAny>> = measurements.extract()?;
            let raw = list
                .iter()
                .enumerate()
                .map(|(k, s)| raw_step(s, &format!("measurements[{k}]"), n))
                .collect::<PyResult<Vec<_>>>()?;
            (None, Some(raw))
        };
        let initial_snapshot = initial_snapshot
            .map(|s| raw_step(s, "initial_snapshot", n))
            .transpose()?;
        let rows = steps.as_ref().map_or(0, Vec::len);
        let fields = rate_args.fields(steps.is_some(), rows, n)?;
        let m = Measurements {
            dt_s: dt,
            process_noise: q,
            initial_state,
            initial_covariance,
            initial_snapshot,
            sigma_s,
            steps,
            raw_steps,
        };
        (m, fields)
    };
    // The range rates (the file's, or the arguments'), checked, and the CPIs of their σ.
    let carrier_hz = sc.scenario().radio.carrier_hz;
    let rates = fields.check(&m, n, carrier_hz).py()?;
    let (caller_cpi, default_cpi) = rate_args.cpis(rates.as_ref(), carrier_hz)?;
    let raw = m.raw_steps.is_some();
    if !raw && (calibration.is_some() || association.is_some()) {
        return Err(arg_error(
            if calibration.is_some() {
                "calibration"
            } else {
                "association"
            },
            "applies to raw estimates only (these are delays per step)",
        ));
    }
    let rule = match association {
        None | Some("spec") => AssociationRule::Spec,
        Some("gated") => AssociationRule::Gated,
        Some(other) => {
            return Err(arg_error(
                "association",
                format!("'{other}' is not 'spec' or 'gated'"),
            ))
        }
    };
    let cal = calibration.map(|c| calibration_arg(c, n)).transpose()?;
    let steps = m.steps.as_ref().map_or(0, Vec::len) + m.raw_steps.as_ref().map_or(0, Vec::len);
    let use_rates = doppler != Some(false);
    // With range rates used, the step of the delay-and-Doppler update.
    let predicted_s = if rates.is_some() && use_rates {
        track_doppler_cpu_s(kind, n, steps)
    } else {
        track_cpu_s(kind, n, steps)
    };
    scatterloc::study::check_cost("track", predicted_s, cpu_cap(max_cpu_hours)?).py()?;
    let area = sc.scenario().area_m;
    let req = TrackRequest {
        model,
        area: &area,
        measurements: &m,
        calibration: cal.as_ref(),
        rule,
        filter: kind,
        seed: seed.unwrap_or(1),
    };
    // A short track (the usual call in a loop) runs on this thread: no worker to start.
    let out = run_sized(py, predicted_s, steps, None, |job| {
        let stop = || job.cancelled();
        match &rates {
            Some(r) => req.track_with_rates(
                r.rates_mps,
                r.sigma.noise(caller_cpi, default_cpi),
                use_rates,
                Cancel::when(&stop),
            ),
            None => track_measurements_in(&req, Cancel::when(&stop)),
        }
    })?;
    track_object(py, out, n)
}
