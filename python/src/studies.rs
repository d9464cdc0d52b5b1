//! The tracking studies: `montecarlo` (the tracker(s) against the posterior CRLB, [S] Fig. 3,
//! spec §8/§9.5 — the library's `study::MonteCarloStudy` on the parallel driver, as
//! `scatterloc montecarlo`) and `pcrlb` (the bound alone, as `scatterloc pcrlb`).

use pyo3::prelude::*;
use pyo3::types::PyDict;

use scatterloc::native::{run_pcrlb_parallel, Parallel};
use scatterloc::study::{check_cost, CurveDoc, McMeta, MonteCarloStudy, RunTime, TrackStudy};
use scatterloc::track::{
    nominal_pcrlb_rmse, paper_initial_covariance, step_count, ConstantVelocity, TrackScenario,
    DEFAULT_STUDY_SEED, MAX_STEPS, PAPER_DURATION_S, PAPER_INTENSITY, PAPER_NOISE_RUNS, PAPER_RUNS,
    PAPER_STEP_S,
};
use scatterloc::Error;

use crate::convert::{array, JsonDoc};
use crate::errors::{arg_error, Core};
use crate::run::{check_threads, run_job};
use crate::scenario::scenario_arg;
use crate::tracking::{cpu_cap, settings};

// The defaults of `montecarlo` and `pcrlb` are written as numbers (so that Python's
// signatures show them); they are the CLI's, the paper's study ([S] Fig. 3):
const _: () = assert!(PAPER_STEP_S == 2.048e-3 && PAPER_DURATION_S == 10.0);
const _: () = assert!(PAPER_INTENSITY == 0.01);
const _: () = assert!(PAPER_RUNS == 5000 && PAPER_NOISE_RUNS == 50 && DEFAULT_STUDY_SEED == 1);

/// The curves of one trajectory of a study.
#[pyclass(module = "scatterloc", frozen)]
pub struct Curves {
    /// `I`, `II` or `III` (spec §9.4).
    #[pyo3(get)]
    trajectory: &'static str,
    /// `t_n = n T`, s, shape (steps + 1,).
    #[pyo3(get)]
    t: Py<PyAny>,
    /// The posterior CRLB's RMSE bound ε_PCRLB(t_n), m (E9); `inf` where singular.
    #[pyo3(get)]
    pcrlb: Py<PyAny>,
    /// Per filter (`ekf`, `ukf`, `pf`, in the order asked) its RMSE ε(t_n), m.
    #[pyo3(get)]
    rmse: Py<PyAny>,
    /// Per filter its average NEES (4 for a consistent filter).
    #[pyo3(get)]
    nees: Py<PyAny>,
    /// Per filter its runs counted.
    #[pyo3(get)]
    runs: Py<PyAny>,
    /// Per filter its runs that failed numerically (left out of its RMSE).
    #[pyo3(get)]
    failed_runs: Py<PyAny>,
    /// Per filter whose every run failed: the error (its curves are absent).
    #[pyo3(get)]
    errors: Py<PyAny>,
    /// Wall time, s.
    #[pyo3(get)]
    wall_time_s: f64,
}

#[pymethods]
impl Curves {
    fn __repr__(&self, py: Python<'_>) -> String {
        let filters: Vec<String> = self
            .runs
            .bind(py)
            .cast::<PyDict>()
            .map(|d| d.keys().iter().filter_map(|k| k.extract().ok()).collect())
            .unwrap_or_default();
        format!(
            "Curves(trajectory={:?}, filters={:?})",
            self.trajectory, filters
        )
    }
}

/// A study's result (returned by `montecarlo` and `pcrlb`): one [`Curves`] per trajectory.
#[pyclass(module = "scatterloc", frozen)]
pub struct StudyResult {
    /// The curves, one per trajectory in the order asked.
    #[pyo3(get)]
    curves: Vec<Py<Curves>>,
    doc: JsonDoc,
}

#[pymethods]
impl StudyResult {
    /// The JSON document the CLI writes with `--json` for the same study (`{"scenarios":
    /// [...]}` for several trajectories, one object for one).
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.doc.to_python(py)
    }

    /// The curves of trajectory `key` (`"I"`, `"II"`, `"III"`) or of index `key`.
    fn __getitem__(&self, py: Python<'_>, key: &Bound<'_, PyAny>) -> PyResult<Py<Curves>> {
        if let Ok(i) = key.extract::<isize>() {
            let n = self.curves.len() as isize;
            let j = if i < 0 { i + n } else { i };
            return self
                .curves
                .get(j as usize)
                .filter(|_| (0..n).contains(&j))
                .map(|c| c.clone_ref(py))
                .ok_or_else(|| pyo3::exceptions::PyIndexError::new_err(format!("{i}")));
        }
        let name: String = key.extract()?;
        self.curves
            .iter()
            .find(|c| c.get().trajectory.eq_ignore_ascii_case(&name))
            .map(|c| c.clone_ref(py))
            .ok_or_else(|| pyo3::exceptions::PyKeyError::new_err(name))
    }

    fn __len__(&self) -> usize {
        self.curves.len()
    }

    fn __repr__(&self) -> String {
        format!("StudyResult(trajectories={})", self.curves.len())
    }
}

/// `(curves, pcrlb)` with `None` as `inf`.
fn bound_array<'py>(py: Python<'py>, v: &[Option<f64>]) -> PyResult<Bound<'py, PyAny>> {
    array(
        py,
        v.iter().map(|x| x.unwrap_or(f64::INFINITY)).collect(),
        &[v.len()],
    )
}

/// The Python curves of one Monte Carlo document.
fn mc_curves(py: Python<'_>, doc: &CurveDoc<McMeta>) -> PyResult<Curves> {
    let (rmse, nees, runs, failed, errors) = (
        PyDict::new(py),
        PyDict::new(py),
        PyDict::new(py),
        PyDict::new(py),
        PyDict::new(py),
    );
    match &doc.meta.filters {
        None => {
            // The EKF alone: the top-level curves are its.
            let n = doc.t_s.len();
            if let Some(r) = &doc.rmse_ekf_m {
                rmse.set_item("ekf", array(py, r.clone(), &[n])?)?;
            }
            if let Some(v) = &doc.nees {
                nees.set_item("ekf", array(py, v.clone(), &[n])?)?;
            }
            runs.set_item("ekf", doc.meta.runs)?;
            failed.set_item("ekf", doc.meta.failed_runs)?;
        }
        Some(f) => {
            for (name, d) in &f.0 {
                if !d.rmse_m.is_empty() {
                    rmse.set_item(*name, array(py, d.rmse_m.clone(), &[d.rmse_m.len()])?)?;
                    nees.set_item(*name, array(py, d.nees.clone(), &[d.nees.len()])?)?;
                }
                runs.set_item(*name, d.runs)?;
                failed.set_item(*name, d.failed_runs)?;
                if let Some(e) = &d.error {
                    errors.set_item(*name, e)?;
                }
            }
        }
    }
    Ok(Curves {
        trajectory: doc.meta.trajectory,
        t: array(py, doc.t_s.clone(), &[doc.t_s.len()])?.unbind(),
        pcrlb: bound_array(py, &doc.rmse_pcrlb_m)?.unbind(),
        rmse: rmse.into_any().unbind(),
        nees: nees.into_any().unbind(),
        runs: runs.into_any().unbind(),
        failed_runs: failed.into_any().unbind(),
        errors: errors.into_any().unbind(),
        wall_time_s: doc.meta.wall_time_s,
    })
}

/// The CLI's `--json` body: one document, or `{"scenarios": [...]}` for several.
fn body<T: serde::Serialize>(docs: &[T]) -> PyResult<JsonDoc> {
    #[derive(serde::Serialize)]
    struct Scenarios<'a, T> {
        scenarios: &'a [T],
    }
    match docs {
        [one] => JsonDoc::of(one),
        _ => JsonDoc::of(&Scenarios { scenarios: docs }),
    }
}

/// The tracking study (the CLI's `parse_study`): the layout (a scenario, default the preset
/// `sensors2019`), the trajectories (`"I"`, `"II"`, `"III"` or `"all"`, or a list), step,
/// duration and process noise.
fn track_study(
    scenario: Option<&Bound<'_, PyAny>>,
    trajectory: &Bound<'_, PyAny>,
    dt: f64,
    duration: f64,
    process_noise: f64,
) -> PyResult<TrackStudy> {
    let (layout, s) = match scenario {
        None => (
            "sensors2019".to_string(),
            scatterloc::scenario::presets::sensors2019(),
        ),
        Some(obj) => {
            // A preset name keeps the preset's name as the layout (as `--preset`).
            let sc = scenario_arg(obj)?;
            let name = match obj.extract::<String>() {
                Ok(n) if scatterloc::scenario::presets::PRESET_NAMES.contains(&n.as_str()) => n,
                _ => sc.scenario().name.clone(),
            };
            (name, sc.scenario().clone())
        }
    };
    let names: Vec<String> = match trajectory.extract::<String>() {
        Ok(one) => vec![one],
        Err(_) => trajectory
            .extract()
            .map_err(|_| arg_error("trajectory", "expected 'I', 'II', 'III', 'all' or a list"))?,
    };
    let mut trajectories = Vec::new();
    for (i, n) in names.iter().enumerate() {
        if n.eq_ignore_ascii_case("all") && names.len() == 1 {
            trajectories.extend(TrackScenario::ALL);
        } else {
            trajectories.push(TrackScenario::parse(n).map_err(|e| match e {
                Error::UnknownTrajectory { name, known, .. } => {
                    crate::errors::core_error(Error::UnknownTrajectory {
                        field: if names.len() == 1 {
                            "trajectory".into()
                        } else {
                            format!("trajectory[{i}]")
                        },
                        name,
                        known,
                    })
                }
                e => crate::errors::core_error(e),
            })?);
        }
    }
    if trajectories.is_empty() {
        return Err(arg_error("trajectory", "no trajectory given"));
    }
    let motion = ConstantVelocity::validated(dt, process_noise).py()?;
    if duration.is_nan() || duration <= 0.0 {
        return Err(arg_error(
            "duration",
            format!("must be > 0 s (got {duration})"),
        ));
    }
    let steps = step_count(duration, dt);
    if steps == 0 || steps > MAX_STEPS {
        return Err(crate::errors::core_error(Error::SizeLimit {
            field: "steps",
            value: steps,
            min: 1,
            max: MAX_STEPS,
        }));
    }
    TrackStudy::new(layout, s, trajectories, motion, steps).py()
}

/// The tracker(s) against the posterior CRLB ([S] §5.2, spec §8/§9.5, [S] Fig. 3): `runs`
/// truth trajectories drawn from the prior P(t₀) = diag(0.1, 0.1, 0.01, 0.01), each with
/// `noise_runs` measurement-noise sequences, every filter of `filters` (`"ekf"`, `"ukf"`,
/// `"pf"`) on the same data, the PCRLB (E9) with E[F̃] over the same truths. The defaults are
/// the CLI's: paper scale (5000 × 50 runs, T = 2.048 ms, 10 s, all three trajectories: minutes
/// on a laptop). Runs on `threads` workers (0 = all cores) without the GIL; the result depends
/// on `seed` only. Ctrl-C stops it (`KeyboardInterrupt`); `progress(done, total)` is called
/// with the runs done. The same numbers as `scatterloc montecarlo --json` (`to_dict()`).
#[pyfunction]
#[pyo3(signature = (
    scenario = None, *, trajectory = None, runs = 5000, noise_runs = 50, dt = 2.048e-3,
    duration = 10.0, process_noise = 0.01, seed = 1, threads = 0,
    oracle_noise = false, filters = None, particles = None, roughening = None, bootstrap = None,
    ukf_alpha = None, ukf_beta = None, ukf_kappa = None, max_cpu_hours = None, progress = None
))]
#[allow(clippy::too_many_arguments)]
pub fn montecarlo(
    py: Python<'_>,
    scenario: Option<&Bound<'_, PyAny>>,
    trajectory: Option<&Bound<'_, PyAny>>,
    runs: usize,
    noise_runs: usize,
    dt: f64,
    duration: f64,
    process_noise: f64,
    seed: u64,
    threads: usize,
    oracle_noise: bool,
    filters: Option<&Bound<'_, PyAny>>,
    particles: Option<usize>,
    roughening: Option<f64>,
    bootstrap: Option<bool>,
    ukf_alpha: Option<f64>,
    ukf_beta: Option<f64>,
    ukf_kappa: Option<f64>,
    max_cpu_hours: Option<f64>,
    progress: Option<&Bound<'_, PyAny>>,
) -> PyResult<StudyResult> {
    let all = pyo3::types::PyString::new(py, "all");
    let track = track_study(
        scenario,
        trajectory.unwrap_or(all.as_any()),
        dt,
        duration,
        process_noise,
    )?;
    check_threads(threads)?;
    let names: Vec<String> = match filters {
        None => vec!["ekf".into()],
        Some(f) => match f.extract::<String>() {
            Ok(s) => s.split(',').map(|x| x.trim().to_string()).collect(),
            Err(_) => f
                .extract()
                .map_err(|_| arg_error("filters", "expected a list of 'ekf', 'ukf', 'pf'"))?,
        },
    };
    let names: Vec<&str> = names.iter().map(String::as_str).collect();
    let kinds = settings(
        [ukf_alpha, ukf_beta, ukf_kappa],
        particles,
        roughening,
        bootstrap,
    )
    .kinds(&names, "filters", |i| format!("filters[{i}]"))
    .py()?;
    let study = MonteCarloStudy::new(track, runs, noise_runs, seed, oracle_noise, &kinds).py()?;
    let used = if threads == 0 {
        rayon::current_num_threads()
    } else {
        threads
    };
    let links = study.track.model.link_count();
    let all_chunks = 0..study.chunk_count();
    let mut cpu_s = 0.0;
    let mut total = 0;
    for k in 0..study.track.trajectories.len() {
        let f = study.filter_study(k).py()?;
        cpu_s += f.predicted_cpu_s(links, &all_chunks);
        total += f.runs_in(&all_chunks);
    }
    check_cost("montecarlo", cpu_s, cpu_cap(max_cpu_hours)?).py()?;
    let docs = run_job(py, total, progress, |job| {
        let mut docs = Vec::new();
        let mut before = 0;
        for k in 0..study.track.trajectories.len() {
            let mut runs = study.filter_study(k)?;
            let t0 = std::time::Instant::now();
            let this = runs.runs_in(&all_chunks);
            runs.run_range(
                &study.track.model,
                all_chunks.clone(),
                &mut Parallel::new(threads, &job.cancel),
                &mut |done, _| job.set_done(before + done),
            )?;
            before += this;
            let wall = t0.elapsed().as_secs_f64();
            let time = RunTime {
                wall_s: wall,
                thread_s: wall * used as f64,
                threads: used,
            };
            let results = runs.results()?;
            docs.push((study.doc(k, &results, time), results.failed));
        }
        Ok(docs)
    })?;
    let mut curves = Vec::new();
    for (doc, failed) in &docs {
        for (_, e) in failed {
            let category = py.get_type::<pyo3::exceptions::PyUserWarning>();
            let text = std::ffi::CString::new(format!(
                "scatterloc.montecarlo: trajectory {}: {e}; its curve is left out",
                doc.meta.trajectory
            ))
            .unwrap_or_default();
            PyErr::warn(py, &category, &text, 1)?;
        }
        curves.push(Py::new(py, mc_curves(py, doc)?)?);
    }
    let only: Vec<&CurveDoc<McMeta>> = docs.iter().map(|(d, _)| d).collect();
    Ok(StudyResult {
        curves,
        doc: body(&only)?,
    })
}

/// The posterior CRLB alone (spec §8, E9): at the noise-free path (`nominal=True`, spec check 9,
/// deterministic) or with E[F̃] over `runs` truth trajectories of `seed` (spec check 10) on
/// `threads` workers. Study arguments as `montecarlo`. The same numbers as `scatterloc pcrlb
/// --json` (`to_dict()`).
#[pyfunction]
#[pyo3(signature = (
    scenario = None, *, nominal = false, trajectory = None, runs = None, dt = 2.048e-3,
    duration = 10.0, process_noise = 0.01, seed = None, threads = None,
    progress = None
))]
#[allow(clippy::too_many_arguments)]
pub fn pcrlb(
    py: Python<'_>,
    scenario: Option<&Bound<'_, PyAny>>,
    nominal: bool,
    trajectory: Option<&Bound<'_, PyAny>>,
    runs: Option<usize>,
    dt: f64,
    duration: f64,
    process_noise: f64,
    seed: Option<u64>,
    threads: Option<usize>,
    progress: Option<&Bound<'_, PyAny>>,
) -> PyResult<StudyResult> {
    let all = pyo3::types::PyString::new(py, "all");
    let study = track_study(
        scenario,
        trajectory.unwrap_or(all.as_any()),
        dt,
        duration,
        process_noise,
    )?;
    if nominal {
        for (f, given) in [
            ("runs", runs.is_some()),
            ("seed", seed.is_some()),
            ("threads", threads.is_some()),
        ] {
            if given {
                return Err(arg_error(
                    f,
                    "only for the Monte Carlo bound (nominal=False)",
                ));
            }
        }
    }
    let (runs, seed, threads) = (
        runs.unwrap_or(PAPER_RUNS),
        seed.unwrap_or(DEFAULT_STUDY_SEED),
        threads.unwrap_or(0),
    );
    check_threads(threads)?;
    let configs = study
        .trajectories
        .iter()
        .map(|t| study.config(*t, runs, 1, seed, false))
        .collect::<scatterloc::Result<Vec<_>>>()
        .py()?;
    let total = if nominal {
        configs.len()
    } else {
        runs * configs.len()
    };
    let docs = run_job(py, total, progress, |job| {
        let mut docs = Vec::new();
        for (k, (t, cfg)) in study.trajectories.iter().zip(&configs).enumerate() {
            let start = std::time::Instant::now();
            let rmse = if nominal {
                let (p0, mean) = (paper_initial_covariance(), t.mean_state());
                let r = nominal_pcrlb_rmse(&study.model, &cfg.motion, &mean, &p0, cfg.steps)?;
                job.set_done(k + 1);
                r
            } else {
                run_pcrlb_parallel(&study.model, cfg, threads, &job.cancel, |done, _| {
                    job.set_done(k * runs + done)
                })?
            };
            docs.push(study.pcrlb_doc(*t, cfg, nominal, rmse, start.elapsed().as_secs_f64()));
        }
        Ok(docs)
    })?;
    let mut curves = Vec::new();
    for d in &docs {
        let empty = PyDict::new(py);
        curves.push(Py::new(
            py,
            Curves {
                trajectory: d.meta.trajectory,
                t: array(py, d.t_s.clone(), &[d.t_s.len()])?.unbind(),
                pcrlb: bound_array(py, &d.rmse_pcrlb_m)?.unbind(),
                rmse: empty.clone().into_any().unbind(),
                nees: empty.clone().into_any().unbind(),
                runs: empty.clone().into_any().unbind(),
                failed_runs: empty.clone().into_any().unbind(),
                errors: empty.into_any().unbind(),
                wall_time_s: d.meta.wall_time_s,
            },
        )?);
    }
    Ok(StudyResult {
        curves,
        doc: body(&docs)?,
    })
}
