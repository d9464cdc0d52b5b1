//! Delay and Doppler (issue 42 §1, docs/doppler.md, D1–D7): `crlb_doppler`, the bound on
//! position and velocity over one CPI from delays and range rates (the library's `DopplerDoc`,
//! as `scatterloc crlb --doppler` prints it under `doppler`); `doppler_map`, that bound over a
//! grid (`localize::doppler_map`, as `scatterloc crlb-map --doppler`); `range_rates`, the links'
//! range rates and their gradients (D1, D3); `sigma_range_rates`, a CPI's σ of them (D5).

use numpy::PyUntypedArrayMethods;
use pyo3::prelude::*;

use scatterloc::error::limits;
use scatterloc::localize::{doppler_map as localize_doppler_map, MapQuantity, MAX_GRID_CELLS};
use scatterloc::measure::{range_rate, range_rate_gradient, Cpi};
use scatterloc::present::DopplerDoc;
use scatterloc::Vec2;

use crate::convert::{
    array, count, eval_points, f64_array, f64_vec, ndarray, point, to_python, too_many, Len,
};
use crate::errors::{arg_error, Core};
use crate::scenario::{scenario_arg, PyScenario};
use crate::snapshot::grid_arg;

/// The bound at `point` (m) for a target moving at `velocity` (m/s) over a CPI of `cpi`
/// snapshots `cpi_spacing_s` apart, with the floor `range_rate_floor` (m/s) on each range
/// rate's σ (default 0.1 m/s: `measure::DEFAULT_RANGE_RATE_FLOOR_MPS`): a dict `{cpi, velocity_mps, position_rmse_m, velocity_rmse_mps,
/// delay_only_position_rmse_m, fim, links}` (`None` where unbounded), equal to the `doppler`
/// of `scatterloc crlb --at X,Y --doppler`. Bad CPI settings raise `ValueError` naming them.
#[pyfunction]
#[pyo3(signature = (scenario, point_m, velocity_mps = None, *, cpi = 16, cpi_spacing_s = 2.048e-3,
                    range_rate_floor = 0.1))]
pub fn crlb_doppler<'py>(
    py: Python<'py>,
    scenario: &Bound<'py, PyAny>,
    point_m: &Bound<'py, PyAny>,
    velocity_mps: Option<&Bound<'py, PyAny>>,
    cpi: usize,
    cpi_spacing_s: f64,
    range_rate_floor: f64,
) -> PyResult<Bound<'py, PyAny>> {
    let sc = scenario_arg(scenario)?;
    let at = point(point_m, "point_m")?;
    let v = match velocity_mps {
        Some(v) => point(v, "velocity_mps")?,
        None => [0.0, 0.0],
    };
    let c = Cpi::new(
        sc.scenario().radio.carrier_hz,
        cpi,
        cpi_spacing_s,
        range_rate_floor,
    )
    .py()?;
    to_python(py, &DopplerDoc::at(sc.model(), at, v, &c))
}

/// A count argument taken as a Python `int` (a negative one is a named error, not PyO3's
/// `OverflowError`), named `field` as the core names it.
fn count_arg(v: i64, field: &str) -> PyResult<usize> {
    usize::try_from(v).map_err(|_| arg_error(field, format!("{v} is negative")))
}

/// The CPI of `scenario`'s carrier: `cpi` snapshots `spacing_s` apart, the floor `floor` (m/s)
/// on the range rate's σ; the core's named errors (`cpi.snapshots`, `cpi.spacing_s`,
/// `cpi.floor_mps`).
fn cpi_arg(sc: &PyScenario, cpi: i64, spacing_s: f64, floor: f64) -> PyResult<Cpi> {
    let n = count_arg(cpi, "cpi.snapshots")?;
    Cpi::new(sc.scenario().radio.carrier_hz, n, spacing_s, floor).py()
}

/// A velocity `(vx, vy)` (m/s; default 0, 0), each component within the trackers' range
/// ([`limits::VELOCITY_M_S`]).
fn velocity_arg(obj: Option<&Bound<'_, PyAny>>, field: &str) -> PyResult<Vec2> {
    let Some(obj) = obj else {
        return Ok(Vec2::zeros());
    };
    let v = f64_vec(obj, field, Len::Exactly(2))?;
    for (i, c) in v.iter().enumerate() {
        limits::VELOCITY_M_S
            .check(&format!("{field}[{i}]"), *c)
            .py()?;
    }
    Ok(Vec2::new(v[0], v[1]))
}

/// The bound with Doppler over a grid (issue 42 §1, D7): per cell of an `nx × ny` grid of cell
/// centres over `window` (`(x_min, x_max, y_min, y_max)`, m; default the scenario's area), the
/// position (`quantity="position"`, m) or velocity (`quantity="velocity"`, m/s) RMSE bound from
/// every link's delay and range rate over one CPI (`cpi` snapshots `cpi_spacing_s` apart, the
/// floor `range_rate_floor` m/s on each range rate's σ) for a target moving at `velocity_mps`
/// (default 0, 0): a float64 array (ny, nx), row j at ascending y as `crlb_map`'s `rmse`, `inf`
/// where the information is singular (never NaN). The numbers of `scatterloc crlb-map
/// --doppler --quantity …` bit for bit (its JSON's `rmse_bound_m` or `velocity_rmse_bound_mps`,
/// `null` there where `inf` here). Runs on one core with the GIL released.
#[pyfunction]
#[pyo3(signature = (scenario, nx = 256, ny = 256, window = None, *, velocity_mps = None, cpi = 16,
                    cpi_spacing_s = 2.048e-3, range_rate_floor = 0.1, quantity = "position"))]
#[allow(clippy::too_many_arguments)]
pub fn doppler_map<'py>(
    py: Python<'py>,
    scenario: &Bound<'py, PyAny>,
    nx: i64,
    ny: i64,
    window: Option<(f64, f64, f64, f64)>,
    velocity_mps: Option<&Bound<'py, PyAny>>,
    cpi: i64,
    cpi_spacing_s: f64,
    range_rate_floor: f64,
    quantity: &str,
) -> PyResult<Bound<'py, PyAny>> {
    let sc = scenario_arg(scenario)?;
    let (grid, _) = grid_arg(&sc, count_arg(nx, "nx")?, count_arg(ny, "ny")?, window)?;
    let quantity = match quantity {
        "position" => MapQuantity::Position,
        "velocity" => MapQuantity::Velocity,
        other => {
            return Err(arg_error(
                "quantity",
                format!("{other:?} is not \"position\" or \"velocity\""),
            ))
        }
    };
    let v = velocity_arg(velocity_mps, "velocity_mps")?;
    let c = cpi_arg(&sc, cpi, cpi_spacing_s, range_rate_floor)?;
    let model = sc.model();
    let values = crate::run::run_quick(py, || {
        let mut out = vec![0.0; grid.len()];
        localize_doppler_map(model, &grid, &c, v, quantity, &mut out)?;
        Ok(out)
    })?;
    array(py, values, &[grid.ny, grid.nx])
}

/// States `(..., 4)` `[x, y, vx, vy]`: the states and their leading shape (`()` for one state
/// `(4,)`); positions within the core's coordinate range, velocities within the trackers'
/// ([`limits::VELOCITY_M_S`]); at most `max` states (checked from a numpy array's shape first).
fn states_arg(obj: &Bound<'_, PyAny>, max: usize) -> PyResult<(Vec<[f64; 4]>, Vec<usize>)> {
    const FIELD: &str = "states";
    if let Some(u) = ndarray(obj) {
        if let Some((4, lead)) = u.shape().split_last() {
            let n = count(lead);
            if n > max {
                return Err(too_many(FIELD, n, max, "states"));
            }
        }
    }
    let a = f64_array(obj, FIELD, max.saturating_mul(4))?;
    let Some((4, lead)) = a.shape.split_last() else {
        return Err(arg_error(
            FIELD,
            format!(
                "expected states [x, y, vx, vy] of shape (4,) or (..., 4), got shape {:?}",
                a.shape
            ),
        ));
    };
    let one = lead.is_empty();
    for (i, v) in a.data.iter().enumerate() {
        let at = match one {
            true => format!("{FIELD}[{i}]"),
            false => format!("{FIELD}[{}][{}]", i / 4, i % 4),
        };
        let range = if i % 4 < 2 {
            limits::COORDINATE_M
        } else {
            limits::VELOCITY_M_S
        };
        range.check(&at, *v).py()?;
    }
    Ok((
        a.data
            .chunks_exact(4)
            .map(|s| [s[0], s[1], s[2], s[3]])
            .collect(),
        lead.to_vec(),
    ))
}

/// The range rate of every link (D1, m/s) for `states` `[x, y, vx, vy]` (shape (4,) or
/// (..., 4); m and m/s) and its Jacobian with respect to the state (D3): a tuple
/// `(rates, jacobian)` of shapes (..., L) and (..., L, 4), the Jacobian's columns
/// `[∂ṙ/∂x, ∂ṙ/∂y, ∂ṙ/∂vx, ∂ṙ/∂vy]` (1/s, 1/s, 1, 1), links in the scenario's link order. At most
/// `crlb_map`'s cell cap (2048²) state-links.
#[pyfunction]
pub fn range_rates<'py>(
    py: Python<'py>,
    scenario: &Bound<'py, PyAny>,
    states: &Bound<'py, PyAny>,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
    let sc = scenario_arg(scenario)?;
    let net = &sc.model().network;
    let l = net.link_count();
    let (xs, lead) = states_arg(states, MAX_GRID_CELLS / l.max(1))?;
    let mut rates = Vec::with_capacity(xs.len() * l);
    let mut jac = Vec::with_capacity(xs.len() * l * 4);
    for x in &xs {
        let r = Vec2::new(x[0], x[1]);
        let v = Vec2::new(x[2], x[3]);
        for p in 0..l {
            rates.push(range_rate(net, p, r, v));
            let (dr, dv) = range_rate_gradient(net, p, r, v);
            jac.extend([dr.x, dr.y, dv.x, dv.y]);
        }
    }
    let mut shape = lead;
    shape.push(l);
    let rates = array(py, rates, &shape)?;
    shape.push(4);
    Ok((rates, array(py, jac, &shape)?))
}

/// The range rate's σ per link (D5, m/s) at `points` (shape (2,) or (..., 2), m) over a CPI of
/// `cpi` snapshots `cpi_spacing_s` apart with the floor `range_rate_floor` (m/s):
/// `√(λ²/F_ff + σ_floor²)` at each link's SNR (E8) there; shape (..., L); `inf` where the CPI
/// holds no Doppler information (one snapshot). The `sigma_range_rate_mps` of `crlb_doppler`'s
/// links.
#[pyfunction]
#[pyo3(signature = (scenario, points, *, cpi = 16, cpi_spacing_s = 2.048e-3, range_rate_floor = 0.1))]
pub fn sigma_range_rates<'py>(
    py: Python<'py>,
    scenario: &Bound<'py, PyAny>,
    points: &Bound<'py, PyAny>,
    cpi: i64,
    cpi_spacing_s: f64,
    range_rate_floor: f64,
) -> PyResult<Bound<'py, PyAny>> {
    let sc = scenario_arg(scenario)?;
    let model = sc.model();
    let l = model.link_count();
    let (pts, mut shape) = eval_points(points, "points", l)?;
    let c = cpi_arg(&sc, cpi, cpi_spacing_s, range_rate_floor)?;
    let mut out = Vec::with_capacity(pts.len() * l);
    for p in &pts {
        let r = Vec2::new(p[0], p[1]);
        out.extend((0..l).map(|k| c.sigma_range_rate(model.snr(k, r))));
    }
    shape.push(l);
    array(py, out, &shape)
}
