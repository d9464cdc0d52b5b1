//! Native timings for the package's benchmark (`python/bench/bench.py`, docs/benchmarks.md):
//! the same kernels timed inside Rust, in the same process and run as the Python calls they are
//! compared with, so "Python overhead" is measured, not guessed; and `panic`, the tests' probe of
//! the binding's panic guard ([`crate::run::guarded`]). Not part of the public API.

use std::time::Instant;

use pyo3::prelude::*;

use scatterloc::localize::{locate, DelayMeasurements, Grid, LmConfig};
use scatterloc::native::crlb_map_parallel;
use scatterloc::Vec2;

use crate::errors::Core;
use crate::scenario::PyScenario;

/// Seconds per call of the CRLB map kernel (`crlb_map_parallel` on `threads` workers) on the
/// scenario's area at `nx × ny`, the best of `repeat` batches of `inner` calls each.
#[pyfunction]
#[pyo3(signature = (scenario, nx, ny, threads, repeat = 7, inner = 20))]
fn crlb_map_seconds(
    py: Python<'_>,
    scenario: &PyScenario,
    nx: usize,
    ny: usize,
    threads: usize,
    repeat: usize,
    inner: usize,
) -> PyResult<f64> {
    let model = scenario.model();
    let grid = Grid::new(scenario.scenario().area_m, nx, ny).py()?;
    py.detach(|| {
        let mut out = vec![0.0; grid.len()];
        let mut best = f64::INFINITY;
        for _ in 0..repeat.max(1) {
            let t0 = Instant::now();
            for _ in 0..inner.max(1) {
                crlb_map_parallel(model, &grid, &mut out, threads)?;
            }
            best = best.min(t0.elapsed().as_secs_f64() / inner.max(1) as f64);
        }
        Ok(best)
    })
    .py()
}

/// Seconds per Levenberg–Marquardt fix of `delays` (σ `sigma` on every link) from `initial`,
/// the best of `repeat` batches of `inner` fixes.
#[pyfunction]
#[pyo3(signature = (scenario, delays, sigma, initial, repeat = 7, inner = 10000))]
fn locate_seconds(
    scenario: &PyScenario,
    delays: Vec<f64>,
    sigma: f64,
    initial: [f64; 2],
    repeat: usize,
    inner: usize,
) -> PyResult<f64> {
    let model = scenario.model();
    let d: Vec<Option<f64>> = delays.iter().map(|&v| Some(v)).collect();
    let s = vec![sigma; d.len()];
    let m = DelayMeasurements {
        delays_s: &d,
        sigmas_s: &s,
    };
    let area = &scenario.scenario().area_m;
    let start = Some(Vec2::new(initial[0], initial[1]));
    let mut best = f64::INFINITY;
    let mut sink = 0.0;
    for _ in 0..repeat.max(1) {
        let t0 = Instant::now();
        for _ in 0..inner.max(1) {
            let r = locate(&model.network, &m, &LmConfig::default(), start, area).py()?;
            sink += r.position.x;
        }
        best = best.min(t0.elapsed().as_secs_f64() / inner.max(1) as f64);
    }
    // Keep the fixes observable (no dead-code elimination of the loop).
    if sink.is_nan() {
        return Err(pyo3::exceptions::PyRuntimeError::new_err("NaN fix"));
    }
    Ok(best)
}

/// Panics with `message` inside core work run as every call runs it: on a worker thread
/// (`worker=True`, [`crate::run::run_job`]) or on the calling thread
/// ([`crate::run::run_quick`]). The tests check that it raises `ScatterlocError` (kind
/// `"Panic"`), not `PanicException`.
#[pyfunction]
#[pyo3(signature = (message, worker = false))]
fn panic(py: Python<'_>, message: &str, worker: bool) -> PyResult<()> {
    let work = || -> scatterloc::Result<()> { panic!("{message}") };
    if worker {
        crate::run::run_job(py, 1, None, |_| work())
    } else {
        crate::run::run_quick(py, work)
    }
}

/// Registers the timings (and the panic probe) in `m` (`scatterloc._scatterloc._bench`).
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(panic, m)?)?;
    m.add_function(wrap_pyfunction!(crlb_map_seconds, m)?)?;
    m.add_function(wrap_pyfunction!(locate_seconds, m)?)?;
    Ok(())
}
