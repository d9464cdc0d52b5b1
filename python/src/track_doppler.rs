//! Range rates in `track` (issue 42 §5; docs/doppler.md D1, D5): the numpy arguments
//! (`range_rates`, `range_rate_sigma`) as a measurement file's [`RangeRateFields`], the caller's
//! CPI (`cpi`, `cpi_spacing_s`, `range_rate_floor`, the names of `sigma_range_rates` and
//! `doppler_map`) and `doppler` checked against the rates as `scatterloc track` checks
//! `--doppler`/`--no-doppler`, and [`TrackDoppler`], the `doppler` part of a track.

use pyo3::prelude::*;

use scatterloc::error::limits;
use scatterloc::formats::{CheckedRates, RangeRateFields, Sigma};
use scatterloc::measure::{Cpi, DEFAULT_RANGE_RATE_FLOOR_MPS};
use scatterloc::study::TrackDoppler as Doc;

use crate::convert::{array, f64_array, f64_vec, masked, to_python, Len, MAX_VALUES};
use crate::errors::{arg_error, Core};

/// The CPI's snapshots when `cpi` is not given (as `crlb --doppler`'s `--cpi`).
const DEFAULT_CPI_SNAPSHOTS: i64 = 16;
/// The CPI's spacing when `cpi_spacing_s` is not given (a 2.048 ms sounder frame), s.
const DEFAULT_CPI_SPACING_S: f64 = 2.048e-3;

/// The Doppler arguments of `track`: the rates of the numpy form and the caller's CPI.
#[derive(Clone, Copy)]
pub struct RateArgs<'a, 'py> {
    /// `range_rates`: (S, L), m/s, NaN = missing.
    pub range_rates: Option<&'a Bound<'py, PyAny>>,
    /// `range_rate_sigma`: one or per link, m/s.
    pub range_rate_sigma: Option<&'a Bound<'py, PyAny>>,
    /// `cpi`: snapshots in the CPI.
    pub cpi: Option<i64>,
    /// `cpi_spacing_s`: their spacing, s.
    pub cpi_spacing_s: Option<f64>,
    /// `range_rate_floor`: the floor on the rates' σ, m/s.
    pub range_rate_floor: Option<f64>,
    /// `doppler`: `False` ignores the rates (`--no-doppler`), `True` asks for them.
    pub doppler: Option<bool>,
}

impl RateArgs<'_, '_> {
    /// The names of the numpy-form arguments given (refused beside a file, which holds them).
    pub fn given_numpy(&self) -> [(&'static str, bool); 2] {
        [
            ("range_rates", self.range_rates.is_some()),
            ("range_rate_sigma", self.range_rate_sigma.is_some()),
        ]
    }

    /// The first CPI argument given, if any.
    fn cpi_given(&self) -> Option<&'static str> {
        [
            ("cpi", self.cpi.is_some()),
            ("cpi_spacing_s", self.cpi_spacing_s.is_some()),
            ("range_rate_floor", self.range_rate_floor.is_some()),
        ]
        .into_iter()
        .find_map(|(f, g)| g.then_some(f))
    }

    /// The numpy form's rates for `steps` steps of `links` links as a file's fields (empty
    /// without `range_rates`): `range_rates` of shape (S, L), each rate NaN (missing) or within
    /// [`limits::RANGE_RATE_M_S`]; `range_rate_sigma` one or per link, each within
    /// [`limits::RANGE_RATE_SIGMA_M_S`]. Errors name the argument (`range_rates[k][p]`, …).
    pub fn fields(&self, plain: bool, steps: usize, links: usize) -> PyResult<RangeRateFields> {
        let Some(obj) = self.range_rates else {
            if self.range_rate_sigma.is_some() {
                return Err(arg_error("range_rate_sigma", "only with range_rates"));
            }
            return Ok(RangeRateFields::default());
        };
        if !plain {
            return Err(arg_error(
                "range_rates",
                "only with delays per step (an array (S, L)), not raw estimates",
            ));
        }
        let a = f64_array(obj, "range_rates", MAX_VALUES)?;
        let ok = match a.shape.as_slice() {
            [s, l] => *s == steps && *l == links,
            [0] => steps == 0,
            _ => false,
        };
        if !ok {
            return Err(arg_error(
                "range_rates",
                format!(
                    "expected range rates of shape ({steps}, {links}) (one per step and link, \
                     NaN = missing), got {:?}",
                    a.shape
                ),
            ));
        }
        let mut rates = Vec::with_capacity(steps);
        for k in 0..steps {
            let row = &a.data[k * links..(k + 1) * links];
            let mut r = Vec::with_capacity(links);
            for (p, &v) in row.iter().enumerate() {
                if v.is_nan() {
                    r.push(None);
                } else {
                    limits::RANGE_RATE_M_S
                        .check(&format!("range_rates[{k}][{p}]"), v)
                        .py()?;
                    r.push(Some(v));
                }
            }
            rates.push(r);
        }
        let sigma = match self.range_rate_sigma {
            None => None,
            Some(s) => Some(match s.extract::<f64>() {
                Ok(v) => {
                    limits::RANGE_RATE_SIGMA_M_S
                        .check("range_rate_sigma", v)
                        .py()?;
                    Sigma::One(v)
                }
                Err(_) => {
                    let v = f64_vec(s, "range_rate_sigma", Len::AtMost(limits::MAX_LINKS))?;
                    if v.len() != links {
                        return Err(arg_error(
                            "range_rate_sigma",
                            format!(
                                "expected one value or {links} (one per link), got {}",
                                v.len()
                            ),
                        ));
                    }
                    for (p, x) in v.iter().enumerate() {
                        limits::RANGE_RATE_SIGMA_M_S
                            .check(&format!("range_rate_sigma[{p}]"), *x)
                            .py()?;
                    }
                    Sigma::PerLink(v)
                }
            }),
        };
        Ok(RangeRateFields {
            range_rates_mps: Some(rates),
            range_rate_sigma_mps: sigma,
            cpi: None,
        })
    }

    /// The caller's CPI (`Some` when any CPI argument is given, the others at their defaults)
    /// and the default CPI, both on `carrier_hz`, after checking the arguments against the
    /// `rates` (as `track` checks `--doppler`, `--no-doppler`): `doppler` or a CPI argument
    /// without range rates, a CPI argument beside a fixed σ or beside `doppler=False` are
    /// named errors; a bad CPI as the core names it (`cpi.snapshots`, …).
    pub fn cpis(
        &self,
        rates: Option<&CheckedRates<'_>>,
        carrier_hz: f64,
    ) -> PyResult<(Option<Cpi>, Cpi)> {
        let cpi_arg = self.cpi_given();
        let Some(rates) = rates else {
            if self.doppler.is_some() {
                return Err(arg_error(
                    "doppler",
                    "only with range rates (range_rates, or a file's range_rates_mps)",
                ));
            }
            if let Some(f) = cpi_arg {
                return Err(arg_error(
                    f,
                    "only with range rates (range_rates, or a file's range_rates_mps)",
                ));
            }
            return Ok((None, default_cpi(carrier_hz)?));
        };
        if let Some(f) = cpi_arg {
            if self.doppler == Some(false) {
                return Err(arg_error(
                    f,
                    "not with doppler=False (use the range rates or ignore them)",
                ));
            }
            if rates.sigma.fixed().is_some() {
                return Err(arg_error(
                    f,
                    "the rates' sigma is fixed (range_rate_sigma, or a file's \
                     range_rate_sigma_mps); drop one of them",
                ));
            }
        }
        let default = default_cpi(carrier_hz)?;
        let caller = match cpi_arg {
            None => None,
            Some(_) => {
                let n = self.cpi.unwrap_or(DEFAULT_CPI_SNAPSHOTS);
                let n = usize::try_from(n)
                    .map_err(|_| arg_error("cpi.snapshots", format!("{n} is negative")))?;
                Some(
                    Cpi::new(
                        carrier_hz,
                        n,
                        self.cpi_spacing_s.unwrap_or(DEFAULT_CPI_SPACING_S),
                        self.range_rate_floor
                            .unwrap_or(DEFAULT_RANGE_RATE_FLOOR_MPS),
                    )
                    .py()?,
                )
            }
        };
        Ok((caller, default))
    }
}

/// The CPI of the defaults (16 snapshots 2.048 ms apart, the 0.1 m/s floor) on `carrier_hz`.
fn default_cpi(carrier_hz: f64) -> PyResult<Cpi> {
    Cpi::new(
        carrier_hz,
        DEFAULT_CPI_SNAPSHOTS as usize,
        DEFAULT_CPI_SPACING_S,
        DEFAULT_RANGE_RATE_FLOOR_MPS,
    )
    .py()
}

/// How a track used its range rates (a track's `doppler`, issue 42 §5): whether the updates
/// used them, where their σ came from, and per step the predicted range rates and their
/// innovations.
#[pyclass(module = "scatterloc", frozen)]
pub struct TrackDoppler {
    /// Whether the updates used the range rates (False: ignored, the delay-only track).
    #[pyo3(get)]
    used: bool,
    /// Where their σ came from: `"fixed"` (per link) or `"cpi"` (D5 at the prediction).
    #[pyo3(get)]
    sigma: String,
    /// The CPI of a `"cpi"` σ (a dict `{snapshots, spacing_s, wavelength_m, floor_mps}` as the
    /// CLI prints it); else None.
    #[pyo3(get)]
    cpi: Py<PyAny>,
    /// When used: each link's predicted range rate after the predict (D1), m/s, shape (S, L);
    /// else None.
    #[pyo3(get)]
    predicted_range_rates: Py<PyAny>,
    /// When used: each link's innovation `ṙ − ṙ(x̂⁻)`, m/s, shape (S, L), masked where the
    /// step has no rate; else None.
    #[pyo3(get)]
    range_rate_innovations: Py<PyAny>,
    doc: Doc,
}

#[pymethods]
impl TrackDoppler {
    /// The `doppler` of the document `scatterloc track` prints.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_python(py, &self.doc)
    }

    fn __repr__(&self) -> String {
        format!("TrackDoppler(used={}, sigma={:?})", self.used, self.sigma)
    }
}

/// The Python object of a track's `doppler` for `links` links.
pub fn doppler_object(py: Python<'_>, doc: &Doc, links: usize) -> PyResult<TrackDoppler> {
    let predicted = match &doc.predicted_range_rates_mps {
        Some(p) => array(py, p.iter().flatten().copied().collect(), &[p.len(), links])?.unbind(),
        None => py.None(),
    };
    let innovations = match &doc.range_rate_innovations_mps {
        Some(i) => {
            let flat: Vec<Option<f64>> = i.iter().flatten().copied().collect();
            masked(py, &flat, &[i.len(), links])?.unbind()
        }
        None => py.None(),
    };
    let cpi = match &doc.cpi {
        Some(c) => to_python(py, c)?.unbind(),
        None => py.None(),
    };
    Ok(TrackDoppler {
        used: doc.used,
        sigma: doc.sigma.to_string(),
        cpi,
        predicted_range_rates: predicted,
        range_rate_innovations: innovations,
        doc: doc.clone(),
    })
}
