//! One snapshot: the CRLB at points (`crlb`, E8, S18–S24), the CRLB map over a grid
//! (`crlb_map`, the SIMD kernel on the parallel driver, as `scatterloc crlb-map`) and the
//! weighted Levenberg–Marquardt fix (`locate`, E5–E6, as `scatterloc locate`).

use pyo3::prelude::*;

use scatterloc::formats::Sigma;
use scatterloc::localize::{crlb_at, locate as lm_locate, DelayMeasurements, Grid, LmConfig};
use scatterloc::native::crlb_map_parallel_in;
use scatterloc::present::{CrlbDoc, FixDoc};
use scatterloc::scenario::Area;
use scatterloc::Vec2;

use crate::convert::{array, f64_array, masked, point, to_python};
use crate::errors::{arg_error, Core};
use crate::run::run_job;
use crate::scenario::{scenario_arg, PyScenario};

/// The CRLB at a set of points (returned by `crlb`). Arrays have the points' leading shape
/// (`()` for one point): `sigma_x`, `sigma_y`, `rmse` in m (`inf` where the geometry is
/// singular), `bounded`, `fisher` and `covariance` (..., 2, 2), and per link (..., L) the
/// `snr_db`, the link budget's `sigma_delay` (s) and the noise-free `delay` (s).
#[pyclass(module = "scatterloc", frozen)]
pub struct Crlb {
    /// The points, m, shape (..., 2).
    #[pyo3(get)]
    points: Py<PyAny>,
    /// σx, m (S18); `inf` where unbounded.
    #[pyo3(get)]
    sigma_x: Py<PyAny>,
    /// σy, m (S19); `inf` where unbounded.
    #[pyo3(get)]
    sigma_y: Py<PyAny>,
    /// The RMSE bound √(σx² + σy²), m (S24); `inf` where unbounded.
    #[pyo3(get)]
    rmse: Py<PyAny>,
    /// Whether the Fisher matrix is invertible.
    #[pyo3(get)]
    bounded: Py<PyAny>,
    /// The Fisher matrix F(r), 1/m², shape (..., 2, 2) (E8).
    #[pyo3(get)]
    fisher: Py<PyAny>,
    /// F⁻¹, m², shape (..., 2, 2); `inf` where unbounded.
    #[pyo3(get)]
    covariance: Py<PyAny>,
    /// The echo's SNR per link, dB, shape (..., L).
    #[pyo3(get)]
    snr_db: Py<PyAny>,
    /// The link budget's delay σ per link, s, shape (..., L) (E8).
    #[pyo3(get)]
    sigma_delay: Py<PyAny>,
    /// The noise-free delay per link, s, shape (..., L) (E1).
    #[pyo3(get)]
    delay: Py<PyAny>,
    scenario: PyScenario,
    at: Vec<[f64; 2]>,
}

#[pymethods]
impl Crlb {
    /// Per point, the document `scatterloc crlb --at X,Y` prints (a list of dicts, in the
    /// points' order, flattened).
    fn to_dicts<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let docs = self
            .at
            .iter()
            .map(|&p| CrlbDoc::at(self.scenario.scenario(), self.scenario.model(), p))
            .collect::<scatterloc::Result<Vec<_>>>()
            .py()?;
        to_python(py, &docs)
    }

    /// The 1σ error ellipses `(semi_major, semi_minor, angle_deg)`, masked where unbounded.
    fn ellipses<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let model = self.scenario.model();
        let mut v = Vec::with_capacity(self.at.len() * 3);
        for p in &self.at {
            let e = crlb_at(model, Vec2::new(p[0], p[1])).ellipse();
            match e {
                Some(e) => v.extend([
                    Some(e.semi_major),
                    Some(e.semi_minor),
                    Some(e.angle_rad.to_degrees()),
                ]),
                None => v.extend([None, None, None]),
            }
        }
        let lead = self
            .points
            .bind(py)
            .getattr("shape")?
            .extract::<Vec<usize>>()?;
        let mut shape = lead[..lead.len() - 1].to_vec();
        shape.push(3);
        masked(py, &v, &shape)
    }

    fn __repr__(&self) -> String {
        format!("Crlb(points={})", self.at.len())
    }
}

/// The CRLB (E8, S18–S24) of `scenario` at `points` (shape (2,) or (..., 2), m): σx, σy, the
/// RMSE bound, the Fisher matrix and covariance, and per link the SNR, the delay σ and the delay.
/// The same numbers as `scatterloc crlb --at X,Y` per point (`to_dicts()` gives its documents).
/// Singular geometry is unbounded: `inf`, never NaN.
#[pyfunction]
pub fn crlb<'py>(
    py: Python<'py>,
    scenario: &Bound<'py, PyAny>,
    points: &Bound<'py, PyAny>,
) -> PyResult<Crlb> {
    let sc = scenario_arg(scenario)?;
    let model = sc.model();
    let l = model.link_count();
    let (at, lead) = crate::convert::eval_points(points, "points", l)?;
    let n = at.len();
    let (mut sx, mut sy, mut rmse) = (
        Vec::with_capacity(n),
        Vec::with_capacity(n),
        Vec::with_capacity(n),
    );
    let mut bounded = Vec::with_capacity(n);
    let (mut fim, mut cov) = (Vec::with_capacity(4 * n), Vec::with_capacity(4 * n));
    let (mut snr, mut sig, mut del) = (
        Vec::with_capacity(n * l),
        Vec::with_capacity(n * l),
        Vec::with_capacity(n * l),
    );
    for p in &at {
        let r = Vec2::new(p[0], p[1]);
        let pt = crlb_at(model, r);
        let f = &pt.fisher_per_m2;
        fim.extend([f[(0, 0)], f[(0, 1)], f[(0, 1)], f[(1, 1)]]);
        match pt.bound {
            Some(b) => {
                sx.push(b.sigma_x_m);
                sy.push(b.sigma_y_m);
                rmse.push(b.rmse_m);
                bounded.push(true);
                let c = &b.covariance_m2;
                cov.extend([c[(0, 0)], c[(0, 1)], c[(0, 1)], c[(1, 1)]]);
            }
            None => {
                sx.push(f64::INFINITY);
                sy.push(f64::INFINITY);
                rmse.push(f64::INFINITY);
                bounded.push(false);
                cov.extend([f64::INFINITY; 4]);
            }
        }
        for k in 0..l {
            snr.push(10.0 * scatterloc::math::log10(model.snr(k, r)));
            sig.push(model.sigma_delay(k, r));
            del.push(model.network.delay(k, r));
        }
    }
    let with = |extra: &[usize]| {
        let mut s = lead.clone();
        s.extend_from_slice(extra);
        s
    };
    let pts: Vec<f64> = at.iter().flatten().copied().collect();
    Ok(Crlb {
        points: array(py, pts, &with(&[2]))?.unbind(),
        sigma_x: shaped(py, sx, &lead)?,
        sigma_y: shaped(py, sy, &lead)?,
        rmse: shaped(py, rmse, &lead)?,
        bounded: if lead.is_empty() {
            pyo3::types::PyBool::new(py, bounded[0])
                .to_owned()
                .into_any()
                .unbind()
        } else {
            array(py, bounded, &lead)?.unbind()
        },
        fisher: array(py, fim, &with(&[2, 2]))?.unbind(),
        covariance: array(py, cov, &with(&[2, 2]))?.unbind(),
        snr_db: array(py, snr, &with(&[l]))?.unbind(),
        sigma_delay: array(py, sig, &with(&[l]))?.unbind(),
        delay: array(py, del, &with(&[l]))?.unbind(),
        scenario: sc,
        at,
    })
}

/// `values` with the leading shape `lead`: a float for one point, else an array.
fn shaped(py: Python<'_>, values: Vec<f64>, lead: &[usize]) -> PyResult<Py<PyAny>> {
    if lead.is_empty() {
        return Ok(pyo3::types::PyFloat::new(py, values[0]).into_any().unbind());
    }
    Ok(array(py, values, lead)?.unbind())
}

/// A CRLB map (returned by `crlb_map`): the RMSE bound over a grid of cell centres.
#[pyclass(module = "scatterloc", frozen)]
pub struct CrlbMap {
    /// Cell-centre x, m, shape (nx,).
    #[pyo3(get)]
    x: Py<PyAny>,
    /// Cell-centre y, m, shape (ny,).
    #[pyo3(get)]
    y: Py<PyAny>,
    /// The RMSE bound per cell, m, shape (ny, nx), row j = y[j] (ascending y); `inf` where
    /// unbounded.
    #[pyo3(get)]
    rmse: Py<PyAny>,
    /// σx per cell, m, shape (ny, nx) (only with `components=True`, else None).
    #[pyo3(get)]
    sigma_x: Py<PyAny>,
    /// σy per cell, m, shape (ny, nx) (only with `components=True`, else None).
    #[pyo3(get)]
    sigma_y: Py<PyAny>,
    /// The window `(x_min, x_max, y_min, y_max)`, m: `imshow(m.rmse, origin="lower",
    /// extent=m.extent)` draws the map.
    #[pyo3(get)]
    extent: (f64, f64, f64, f64),
    /// Wall time of the map kernel, s.
    #[pyo3(get)]
    compute_s: f64,
}

#[pymethods]
impl CrlbMap {
    /// The map as `scatterloc crlb-map --out map.json` writes it: `{"x_m", "y_m",
    /// "rmse_bound_m"}` (rows of nx values, `None` where unbounded).
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        #[derive(serde::Serialize)]
        struct MapDoc {
            x_m: Vec<f64>,
            y_m: Vec<f64>,
            rmse_bound_m: Vec<Vec<f64>>,
        }
        let x: Vec<f64> = self.x.bind(py).extract()?;
        let y: Vec<f64> = self.y.bind(py).extract()?;
        let rows: Vec<Vec<f64>> = self.rmse.bind(py).call_method0("tolist")?.extract()?;
        to_python(
            py,
            &MapDoc {
                x_m: x,
                y_m: y,
                rmse_bound_m: rows,
            },
        )
    }

    fn __repr__(&self) -> String {
        format!(
            "CrlbMap(extent={:?}, compute_s={:.6})",
            self.extent, self.compute_s
        )
    }
}

/// The CRLB map (spec §7, S24) of `scenario` on an `nx × ny` grid of cell centres over `window`
/// (`(x_min, x_max, y_min, y_max)`, m; default the scenario's area): the same SIMD kernel and
/// row split over `threads` workers (0 = all cores) as `scatterloc crlb-map`, bit for bit, with
/// the GIL released (Ctrl-C stops a large map). `components=True` adds the σx and σy maps
/// (evaluated per cell by the point bound, ≈ 10× the map's time). At most 4096 cells a side
/// and 2048² cells.
#[pyfunction]
#[pyo3(signature = (scenario, nx = 256, ny = 256, window = None, *, threads = 0, components = false))]
pub fn crlb_map(
    py: Python<'_>,
    scenario: &Bound<'_, PyAny>,
    nx: usize,
    ny: usize,
    window: Option<(f64, f64, f64, f64)>,
    threads: usize,
    components: bool,
) -> PyResult<CrlbMap> {
    let sc = scenario_arg(scenario)?;
    let (grid, area) = grid_arg(&sc, nx, ny, window)?;
    crate::run::check_threads(threads)?;
    let model = sc.model();
    let cells = grid.len();
    // Small maps (a few ms) run on this thread with the GIL released; large ones on a worker
    // that Ctrl-C can stop.
    let big = cells.saturating_mul(model.link_count()) > 1 << 26;
    let run = |cancel: &std::sync::atomic::AtomicBool| {
        let t0 = std::time::Instant::now();
        let mut values = vec![0.0; cells];
        crlb_map_parallel_in(model, &grid, &mut values, threads, cancel)?;
        let secs = t0.elapsed().as_secs_f64();
        let comps = if components {
            let mut sx = Vec::with_capacity(cells);
            let mut sy = Vec::with_capacity(cells);
            for j in 0..grid.ny {
                if cancel.load(std::sync::atomic::Ordering::Relaxed) {
                    return Err(scatterloc::Error::Cancelled);
                }
                for i in 0..grid.nx {
                    let b = crlb_at(model, Vec2::new(grid.x(i), grid.y(j))).bound;
                    sx.push(b.map_or(f64::INFINITY, |b| b.sigma_x_m));
                    sy.push(b.map_or(f64::INFINITY, |b| b.sigma_y_m));
                }
            }
            Some((sx, sy))
        } else {
            None
        };
        Ok((values, comps, secs))
    };
    let (values, comps, secs) = if big {
        run_job(py, cells, None, |job| run(&job.cancel))?
    } else {
        let never = std::sync::atomic::AtomicBool::new(false);
        crate::run::run_quick(py, || run(&never))?
    };
    let xs: Vec<f64> = (0..grid.nx).map(|i| grid.x(i)).collect();
    let ys: Vec<f64> = (0..grid.ny).map(|j| grid.y(j)).collect();
    let shape = [grid.ny, grid.nx];
    let (sigma_x, sigma_y) = match comps {
        Some((sx, sy)) => (
            array(py, sx, &shape)?.unbind(),
            array(py, sy, &shape)?.unbind(),
        ),
        None => (py.None(), py.None()),
    };
    Ok(CrlbMap {
        x: array(py, xs, &[grid.nx])?.unbind(),
        y: array(py, ys, &[grid.ny])?.unbind(),
        rmse: array(py, values, &shape)?.unbind(),
        sigma_x,
        sigma_y,
        extent: (area.x[0], area.x[1], area.y[0], area.y[1]),
        compute_s: secs,
    })
}

/// The `nx × ny` grid of cell centres over `window` (`(x_min, x_max, y_min, y_max)`, m; default
/// the scenario's area) and its area, checked as `scatterloc crlb-map` checks them (`crlb_map`,
/// `doppler_map`).
pub fn grid_arg(
    sc: &PyScenario,
    nx: usize,
    ny: usize,
    window: Option<(f64, f64, f64, f64)>,
) -> PyResult<(Grid, Area)> {
    let area = match window {
        Some((x0, x1, y0, y1)) => {
            let a = Area {
                x: [x0, x1],
                y: [y0, y1],
            };
            a.validate().py()?;
            a
        }
        None => sc.scenario().area_m,
    };
    Ok((Grid::new(area, nx, ny).py()?, area))
}

/// A Levenberg–Marquardt fix (returned by `locate`).
#[pyclass(module = "scatterloc", frozen)]
pub struct Fix {
    doc: FixDoc,
}

#[pymethods]
impl Fix {
    /// The fix r̂, m, shape (2,).
    #[getter]
    fn position<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        array(py, self.doc.position_m.to_vec(), &[2])
    }

    /// (JᵀR⁻¹J)⁻¹ at r̂, m², shape (2, 2); None when singular.
    #[getter]
    fn covariance<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.doc
            .covariance_m2
            .map(|c| array(py, c.iter().flatten().copied().collect(), &[2, 2]))
            .transpose()
    }

    /// The cost 𝓛(r̂) (E5).
    #[getter]
    fn cost(&self) -> f64 {
        self.doc.cost
    }

    /// Iterations (Jacobian evaluations).
    #[getter]
    fn iterations(&self) -> usize {
        self.doc.iterations
    }

    /// Why it stopped: `step_tolerance`, `cost_tolerance`, `exact_fit`, `max_iterations`,
    /// `no_improvement` or `numerical_failure`.
    #[getter]
    fn termination(&self) -> &'static str {
        self.doc.termination
    }

    /// Whether the termination means a converged fix (the first three).
    #[getter]
    fn converged(&self) -> bool {
        self.doc.converged
    }

    /// Links that carried a measurement.
    #[getter]
    fn links_used(&self) -> usize {
        self.doc.links_used
    }

    /// Where the kept iteration started, m, shape (2,).
    #[getter]
    fn start<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        array(py, self.doc.start_m.to_vec(), &[2])
    }

    /// The document `scatterloc locate` prints for the same input.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_python(py, &self.doc)
    }

    fn __repr__(&self) -> String {
        format!(
            "Fix(position=[{}, {}], termination={:?}, links_used={})",
            self.doc.position_m[0],
            self.doc.position_m[1],
            self.doc.termination,
            self.doc.links_used
        )
    }
}

/// The weighted Levenberg–Marquardt fix (spec §5, E5–E6) from one snapshot of `delays` (one per
/// link in the scenario's link order, s; NaN = no measurement on that link; at least 3) with
/// delay σ `sigma` (one number or one per link, s). `initial` (m) starts the iteration; without
/// it the best node of a 0.5 m grid over the area starts it. A χ²-implausible fix is retried
/// from the grid (as `scatterloc locate`). The same result as `scatterloc locate` for the same
/// delays file.
#[pyfunction]
#[pyo3(signature = (scenario, delays, sigma, *, initial = None))]
pub fn locate(
    py: Python<'_>,
    scenario: &Bound<'_, PyAny>,
    delays: &Bound<'_, PyAny>,
    sigma: &Bound<'_, PyAny>,
    initial: Option<&Bound<'_, PyAny>>,
) -> PyResult<Fix> {
    let sc_ref;
    let owned;
    let sc: &PyScenario = match scenario.cast::<PyScenario>() {
        Ok(s) => {
            sc_ref = s.borrow();
            &sc_ref
        }
        Err(_) => {
            owned = scenario_arg(scenario)?;
            &owned
        }
    };
    let model = sc.model();
    let n = model.link_count();
    let d = f64_array(delays, "delays", scatterloc::error::limits::MAX_LINKS)?;
    if d.shape.len() != 1 || d.data.len() != n {
        return Err(arg_error(
            "delays",
            format!(
                "expected {n} delays (one per link), got shape {:?}",
                d.shape
            ),
        ));
    }
    let delays_s: Vec<Option<f64>> = d
        .data
        .iter()
        .map(|&v| if v.is_nan() { None } else { Some(v) })
        .collect();
    let sigmas = sigma_arg(sigma, n)?;
    let initial = match initial {
        Some(p) => {
            let p = point(p, "initial")?;
            Some(Vec2::new(p[0], p[1]))
        }
        None => None,
    };
    let m = DelayMeasurements {
        delays_s: &delays_s,
        sigmas_s: &sigmas,
    };
    let area = &sc.scenario().area_m;
    let rep = if initial.is_some() {
        // A few µs: on this thread with the GIL, through the panic guard all core calls take.
        crate::run::guarded(|| lm_locate(&model.network, &m, &LmConfig::default(), initial, area))
            .map_err(PyErr::from)?
    } else {
        // The grid-search start costs ~0.1 ms: without the GIL.
        crate::run::run_quick(py, || {
            lm_locate(&model.network, &m, &LmConfig::default(), None, area)
        })?
    };
    Ok(Fix {
        doc: FixDoc::from(&rep),
    })
}

/// A delay σ argument: one number or one per link (s), checked as the CLI's `sigma_s`.
pub fn sigma_arg(sigma: &Bound<'_, PyAny>, links: usize) -> PyResult<Vec<f64>> {
    let s = if let Ok(v) = sigma.extract::<f64>() {
        Sigma::One(v)
    } else {
        Sigma::PerLink(crate::convert::f64_vec(
            sigma,
            "sigma",
            crate::convert::Len::AtMost(scatterloc::error::limits::MAX_LINKS),
        )?)
    };
    s.per_link(links).py()
}
