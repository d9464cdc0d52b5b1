//! Network planning: `plan` moves nodes (and turns beams) to optimise a CRLB objective over a
//! region (`filters-and-planning.md` §3) — the library's `present::run_plan`, the function the
//! CLI's `scatterloc plan` and the page's Plan panel call.

use pyo3::prelude::*;

use scatterloc::native::crlb_map_exact;
use scatterloc::present::{run_plan_with, PlanJson, PlanRequest, DEFAULT_PLAN_BUDGET};
use scatterloc::Error;

use crate::convert::{array, to_python};
use crate::errors::{arg_error, Core};
use crate::run::run_job;
use crate::scenario::{scenario_arg, PyScenario};
use scatterloc::present::Session;

// `plan`'s default budget is the library's (written as a number for Python).
const _: () = assert!(DEFAULT_PLAN_BUDGET == 10_000);

/// A plan (returned by `plan`).
#[pyclass(module = "scatterloc", frozen)]
pub struct Plan {
    /// The optimised scenario.
    #[pyo3(get)]
    scenario: Py<PyScenario>,
    /// The objective over the ROI on the requested grid before (the base scenario), m or a
    /// fraction for coverage; `inf` when unbounded.
    #[pyo3(get)]
    before: f64,
    /// The same after.
    #[pyo3(get)]
    after: f64,
    /// Every improvement of the best feasible layout: (evaluations, objective on the search
    /// grid), shape (K, 2); `inf` when unbounded.
    #[pyo3(get)]
    history: Py<PyAny>,
    /// Each moved node's path, base → each improvement → result: `{name: array (P, 2)}`.
    #[pyo3(get)]
    paths: Py<PyAny>,
    /// Evaluations made.
    #[pyo3(get)]
    evaluations: usize,
    /// `budget` or `converged`.
    #[pyo3(get)]
    termination: String,
    /// The moved nodes' names.
    #[pyo3(get)]
    moved: Vec<String>,
    doc: PlanJson,
}

#[pymethods]
impl Plan {
    /// `plan.json` as `scatterloc plan --out plan.json` writes it for the same arguments.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_python(py, &self.doc)
    }

    fn __repr__(&self) -> String {
        format!(
            "Plan(objective={:?}, before={}, after={}, evaluations={})",
            self.doc.objective.label, self.before, self.after, self.evaluations
        )
    }
}

/// Moves nodes of `scenario` to optimise `objective` — `"mean"`, `"p90"` (90th percentile),
/// `"max"` of the RMSE bound over the cells of `roi` (`(x0, x1, y0, y1)`, m), minimised, or
/// `"coverage:T"`, the fraction of cells whose bound is at most T m, maximised. `move` is
/// `"rx"`, `"tx"`, `"all"`, `"tx-boresight"` (transmitters move and parabolic beams turn) or
/// comma-separated node names. Moved nodes stay inside `bounds` (default the area) and, when
/// given, inside one of the `allowed` polygons (lists of (x, y) vertices), every pair of nodes
/// at least `min_spacing` apart. CMA-ES with restarts, `budget` evaluations on a coarser grid,
/// finalists on the `grid × grid` ROI grid; deterministic per `seed`. The same plan as
/// `scatterloc plan` (`to_dict()` is its `plan.json`), without the GIL; Ctrl-C stops it;
/// `progress(evaluations, budget)`.
#[pyfunction]
#[pyo3(signature = (
    scenario, *, r#move, objective, roi, bounds = None, allowed = None, min_spacing = 0.0,
    grid = 64, budget = 10000, seed = 1, progress = None
))]
#[allow(clippy::too_many_arguments)]
pub fn plan(
    py: Python<'_>,
    scenario: &Bound<'_, PyAny>,
    r#move: &str,
    objective: &str,
    roi: (f64, f64, f64, f64),
    bounds: Option<(f64, f64, f64, f64)>,
    allowed: Option<&Bound<'_, PyAny>>,
    min_spacing: f64,
    grid: usize,
    budget: usize,
    seed: u64,
    progress: Option<&Bound<'_, PyAny>>,
) -> PyResult<Plan> {
    let sc = scenario_arg(scenario)?;
    if !(scatterloc::plan::MIN_PLAN_GRID..=scatterloc::plan::MAX_PLAN_GRID).contains(&grid) {
        return Err(crate::errors::core_error(Error::SizeLimit {
            field: "grid",
            value: grid,
            min: scatterloc::plan::MIN_PLAN_GRID,
            max: scatterloc::plan::MAX_PLAN_GRID,
        }));
    }
    let allowed: Vec<Vec<[f64; 2]>> = match allowed {
        None => Vec::new(),
        Some(a) => {
            let polys: Vec<Bound<'_, PyAny>> = a
                .extract()
                .map_err(|_| arg_error("allowed", "expected a list of polygons"))?;
            polys
                .iter()
                .enumerate()
                .map(|(i, p)| {
                    let field = format!("allowed[{i}]");
                    crate::convert::points(p, &field, scatterloc::plan::MAX_POLYGON_VERTICES)
                        .map(|v| v.0)
                })
                .collect::<PyResult<_>>()?
        }
    };
    let request = PlanRequest {
        movable: r#move.to_string(),
        objective: objective.to_string(),
        roi: [roi.0, roi.1, roi.2, roi.3],
        bounds: bounds.map(|b| [b.0, b.1, b.2, b.3]),
        allowed,
        min_spacing_m: min_spacing,
        grid: Some(grid),
        budget: Some(budget),
        seed: Some(seed),
    };
    request.config().map_err(|e| match e {
        // The core's parse error carries no value; say which text was not understood (as the
        // CLI does).
        Error::OutOfRange { field, value, .. } if field == "objective" && value.is_nan() => {
            arg_error(
                "objective",
                format!("'{objective}' is not mean, p90, max or coverage:T (T > 0 m)"),
            )
        }
        e => crate::errors::core_error(e),
    })?;
    let base = sc.scenario().clone();
    let doc = run_job(py, budget, progress, |job| {
        run_plan_with(&base, &request, crlb_map_exact, |p| {
            job.set_done(p.evaluations.min(p.budget));
            !job.cancelled()
        })
    })?;
    let inf = |v: Option<f64>| v.unwrap_or(f64::INFINITY);
    let hist: Vec<f64> = doc
        .history
        .iter()
        .flat_map(|h| [h.evaluations as f64, inf(h.best)])
        .collect();
    let paths = pyo3::types::PyDict::new(py);
    for p in &doc.paths {
        let pts: Vec<f64> = p.points.iter().flatten().copied().collect();
        paths.set_item(&p.name, array(py, pts, &[p.points.len(), 2])?)?;
    }
    let planned = PyScenario {
        session: Session::new(doc.scenario.clone()).py()?,
    };
    Ok(Plan {
        scenario: Py::new(py, planned)?,
        before: inf(doc.objective.before),
        after: inf(doc.objective.after),
        history: array(py, hist, &[doc.history.len(), 2])?.unbind(),
        paths: paths.into_any().unbind(),
        evaluations: doc.evaluations,
        termination: doc.termination.clone(),
        moved: doc.moved.clone(),
        doc,
    })
}
