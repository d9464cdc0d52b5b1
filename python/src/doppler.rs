//! `crlb_doppler`: the bound on position and velocity over one CPI from delays and range rates
//! (issue 42 §1, docs/doppler.md): the library's `DopplerDoc`, as `scatterloc crlb --doppler`
//! prints it under `doppler`.

use pyo3::prelude::*;

use scatterloc::measure::Cpi;
use scatterloc::present::DopplerDoc;

use crate::convert::{point, to_python};
use crate::errors::Core;
use crate::scenario::scenario_arg;

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
