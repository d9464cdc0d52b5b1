//! `gospa`: the GOSPA metric (α = 2, issue 41) of the core's `track::gospa` on numpy points.

use pyo3::prelude::*;

use scatterloc::track::{gospa as core_gospa, GospaConfig, MAX_GOSPA_POINTS};
use scatterloc::Vec2;

use crate::convert::{points, to_python};
use crate::errors::Core;

/// GOSPA (α = 2) between true positions `truth` and `estimates`, each `(n, 2)` in metres, with
/// cut-off `c` (m) and order `p` (≥ 1): a dict with `distance` (m), its parts `localisation`,
/// `missed` and `false` as p-th powers (Stone Soup's `GOSPAMetric` convention), the assigned
/// `pairs` `[truth, estimate]` closer than `c`, `missed_count` and `false_count`.
#[pyfunction]
#[pyo3(signature = (truth, estimates, *, c, p = 2.0))]
pub fn gospa<'py>(
    py: Python<'py>,
    truth: &Bound<'py, PyAny>,
    estimates: &Bound<'py, PyAny>,
    c: f64,
    p: f64,
) -> PyResult<Bound<'py, PyAny>> {
    let as_vec = |obj: &Bound<'py, PyAny>, field: &str| -> PyResult<Vec<Vec2>> {
        let (pts, _) = points(obj, field, MAX_GOSPA_POINTS)?;
        Ok(pts.into_iter().map(|q| Vec2::new(q[0], q[1])).collect())
    };
    let (x, y) = (as_vec(truth, "truth")?, as_vec(estimates, "estimates")?);
    let g = core_gospa(&x, &y, &GospaConfig { c, p }).py()?;
    to_python(py, &g)
}
