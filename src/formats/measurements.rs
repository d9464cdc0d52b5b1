//! The measurements file of `track` (spec §6, §4): the CV model's step and intensity (E7), the
//! start, an optional fixed delay σ and per step either one delay per link (`steps`, E1) or
//! every link's `[delay, amplitude]` estimates (`raw_steps`, gated by E4 and associated by
//! spec §4). With `steps`, a file may also give per step one range rate per link
//! (`range_rates_mps`, issue 42 §5; docs/doppler.md D1) and their σ: fixed
//! (`range_rate_sigma_mps`) or from a CPI (`cpi`, D5) ([`RangeRateFields`]).

use alloc::format;
use alloc::string::{String, ToString};
use alloc::vec;
use alloc::vec::Vec;

use serde::{Deserialize, Serialize};

use crate::channel::{DelayEstimate, Snapshot};
use crate::error::{limits, Error, Result};
use crate::math::{Mat4, Real, Vec4};
use crate::measure::{Cpi, DEFAULT_RANGE_RATE_FLOOR_MPS};
use crate::scenario::parse_json;
use crate::track::{ConstantVelocity, RateNoise, MAX_STEPS};

/// One raw estimate of a measurements file: `[delay_s, amplitude]`, or `[delay_s, amplitude,
/// sigma_s]` when the estimator gives the delay's standard deviation (`cir estimate` does, C5);
/// the tracker then weights that delay with it unless the file fixes `sigma_s`.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, Serialize)]
#[serde(untagged)]
pub enum RawEstimate {
    /// `[delay_s, amplitude]`.
    Pair([f64; 2]),
    /// `[delay_s, amplitude, sigma_s]`.
    WithSigma([f64; 3]),
}

/// One raw step: per link, every estimate.
pub type RawStep = Vec<Vec<RawEstimate>>;

/// `sigma_s` of a measurements file: one delay standard deviation for all links or one per
/// link, s.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(untagged)]
pub enum Sigma {
    /// The same σ for every link.
    One(f64),
    /// One σ per link in scenario link order.
    PerLink(Vec<f64>),
}

impl Sigma {
    /// One σ per link for `n` links, each a finite number > 0 (errors name `sigma_s`, or the
    /// link of a bad per-link σ).
    pub fn per_link(self, n: usize) -> Result<Vec<f64>> {
        let v = match self {
            Sigma::One(v) => {
                if !(v.is_finite() && v > 0.0) {
                    return Err(Error::NotPositive {
                        field: "sigma_s".into(),
                        value: v,
                    });
                }
                vec![v; n]
            }
            Sigma::PerLink(v) if v.len() != n => {
                return Err(Error::LengthMismatch {
                    field: "sigma_s",
                    expected: n,
                    found: v.len(),
                })
            }
            Sigma::PerLink(v) => v,
        };
        match v.iter().position(|s| !(s.is_finite() && *s > 0.0)) {
            Some(link) => Err(Error::InvalidSigma {
                link,
                value: v[link],
            }),
            None => Ok(v),
        }
    }
}

/// The measurements file (`track --measurements`; `simulate-walk` writes the `raw_steps`
/// form). Absent optional fields are not written.
///
/// # Example
///
/// ```
/// use scatterloc::formats::{Measurements, Start, Steps};
///
/// let m = Measurements::from_json(
///     r#"{"dt_s": 0.1, "process_noise": 0.1,
///         "initial_state": [1, 2, 0, 0],
///         "initial_covariance": [[0.1,0,0,0],[0,0.1,0,0],[0,0,0.01,0],[0,0,0,0.01]],
///         "steps": [[3.0e-8, null]]}"#,
/// )
/// .unwrap();
/// assert!(matches!(m.start().unwrap(), Start::Given(..)));
/// let Steps::Plain(steps) = m.steps().unwrap() else { panic!("plain form") };
/// Measurements::check_plain_step(0, &steps[0], 2).unwrap();
/// // A step with the wrong number of delays is named.
/// let e = Measurements::check_plain_step(0, &steps[0], 3).unwrap_err();
/// assert_eq!(e.to_string(), "steps[0]: expected 3 delays (one per link, null = missing), found 2");
/// ```
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Measurements {
    /// Step `T`, s.
    pub dt_s: f64,
    /// Process-noise intensity `q̃`, m²/s³.
    pub process_noise: f64,
    /// `x̂(t₀) = [x, y, vx, vy]`, m and m/s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub initial_state: Option<[f64; 4]>,
    /// `P(t₀)`, row-major.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub initial_covariance: Option<[[f64; 4]; 4]>,
    /// No track yet (raw form only): the snapshot at t₀, `[[delay_s, amplitude], ..]` per link;
    /// the filter starts from its LM fix.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub initial_snapshot: Option<RawStep>,
    /// Fixed delay σ (one or per link), s; absent: the link budget at the prediction (E8).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sigma_s: Option<Sigma>,
    /// Per step, one delay per link in scenario link order (`null` = missing), s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub steps: Option<Vec<Vec<Option<f64>>>>,
    /// Per step, per link, every `[delay_s, amplitude]` estimate (gated and associated).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub raw_steps: Option<Vec<RawStep>>,
}

/// The steps of a [`Measurements`] file, in one of its two forms.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Steps<'a> {
    /// One delay (or `None`) per link and step.
    Plain(&'a [Vec<Option<f64>>]),
    /// Every estimate per link and step.
    Raw(&'a [RawStep]),
}

impl Steps<'_> {
    /// The number of steps.
    pub fn len(&self) -> usize {
        match self {
            Steps::Plain(s) => s.len(),
            Steps::Raw(s) => s.len(),
        }
    }

    /// Whether there is no step.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// How a [`Measurements`] file starts the filter.
#[derive(Debug, Clone, PartialEq)]
pub enum Start<'a> {
    /// `x̂(t₀)` and `P(t₀)` as given (validated by the filter).
    Given(Vec4, Mat4),
    /// The LM fix of this snapshot (raw form only).
    Snapshot(&'a RawStep),
}

/// An [`Error::InvalidFile`] of `field`.
fn invalid(field: impl Into<String>, reason: String) -> Error {
    Error::InvalidFile {
        field: field.into(),
        reason,
    }
}

/// `Err` naming `field` unless it holds one list per link (`len == n`): [`Error::InvalidFile`].
pub fn one_list_per_link(field: &str, len: usize, n: usize) -> Result<()> {
    if len == n {
        Ok(())
    } else {
        Err(invalid(
            field,
            format!("expected {n} lists (one per link), found {len}"),
        ))
    }
}

impl Measurements {
    /// Parses a measurements file (errors name the field: [`Error::Parse`]).
    pub fn from_json(text: &str) -> Result<Measurements> {
        parse_json(text)
    }

    /// The CV motion model (E7) of `dt_s` and `process_noise`, validated.
    pub fn motion(&self) -> Result<ConstantVelocity> {
        ConstantVelocity::validated(self.dt_s, self.process_noise)
    }

    /// The fixed σ per link of `links` links (`None`: from the link budget), validated as
    /// [`Sigma::per_link`].
    pub fn sigmas(&self, links: usize) -> Result<Option<Vec<Real>>> {
        self.sigma_s.clone().map(|s| s.per_link(links)).transpose()
    }

    /// The steps: exactly one of `steps` and `raw_steps`, at most [`MAX_STEPS`] of them
    /// ([`Error::InvalidFile`] of `steps` otherwise).
    pub fn steps(&self) -> Result<Steps<'_>> {
        let steps = match (&self.steps, &self.raw_steps) {
            (Some(s), None) => Steps::Plain(s),
            (None, Some(r)) => Steps::Raw(r),
            _ => {
                return Err(invalid(
                    "steps",
                    "give exactly one of steps and raw_steps".into(),
                ))
            }
        };
        let len = steps.len();
        if len > MAX_STEPS {
            return Err(invalid(
                "steps",
                format!("{len} steps, at most {MAX_STEPS} are allowed"),
            ));
        }
        Ok(steps)
    }

    /// The start: `initial_state` with `initial_covariance`, or (with `raw_steps`) an
    /// `initial_snapshot` ([`Error::InvalidFile`] of `initial_state` otherwise).
    pub fn start(&self) -> Result<Start<'_>> {
        match (
            self.initial_state,
            self.initial_covariance,
            &self.initial_snapshot,
        ) {
            (Some(x0), Some(p0), None) => {
                Ok(Start::Given(Vec4::from(x0), Mat4::from_fn(|i, j| p0[i][j])))
            }
            (None, None, Some(snap)) if self.raw_steps.is_some() => Ok(Start::Snapshot(snap)),
            _ => Err(invalid(
                "initial_state",
                "give initial_state and initial_covariance, or (with raw_steps) initial_snapshot"
                    .into(),
            )),
        }
    }

    /// Checks plain step `k`: one delay (or `null`) per each of `links` links.
    pub fn check_plain_step(k: usize, z: &[Option<f64>], links: usize) -> Result<()> {
        if z.len() == links {
            Ok(())
        } else {
            Err(invalid(
                format!("steps[{k}]"),
                format!(
                    "expected {links} delays (one per link, null = missing), found {}",
                    z.len()
                ),
            ))
        }
    }

    /// One raw step (or the initial snapshot) as the core's estimates, after checking it holds
    /// one list per each of `links` links and every given σ is finite and `> 0` (errors name
    /// `field`, and `field[p][i]` for a bad σ).
    pub fn estimates(field: &str, step: &RawStep, links: usize) -> Result<Snapshot> {
        one_list_per_link(field, step.len(), links)?;
        step.iter()
            .enumerate()
            .map(|(p, l)| {
                l.iter()
                    .enumerate()
                    .map(|(i, e)| match *e {
                        RawEstimate::Pair([delay_s, amplitude]) => Ok(DelayEstimate {
                            delay_s,
                            amplitude,
                            sigma_s: None,
                        }),
                        RawEstimate::WithSigma([delay_s, amplitude, sigma_s]) => {
                            if !(sigma_s.is_finite() && sigma_s > 0.0) {
                                return Err(Error::NotPositive {
                                    field: format!("{field}[{p}][{i}] sigma_s"),
                                    value: sigma_s,
                                });
                            }
                            Ok(DelayEstimate {
                                delay_s,
                                amplitude,
                                sigma_s: Some(sigma_s),
                            })
                        }
                    })
                    .collect()
            })
            .collect()
    }

    /// The raw form of estimates (the inverse of [`Measurements::estimates`]): pairs, or
    /// triples where an estimate has a σ.
    pub fn raw_step(estimates: &[Vec<DelayEstimate>]) -> RawStep {
        estimates
            .iter()
            .map(|l| {
                l.iter()
                    .map(|e| match e.sigma_s {
                        None => RawEstimate::Pair([e.delay_s, e.amplitude]),
                        Some(s) => RawEstimate::WithSigma([e.delay_s, e.amplitude, s]),
                    })
                    .collect()
            })
            .collect()
    }
}

/// The keys of a measurements file that [`RangeRateFields`] reads.
pub const RANGE_RATE_KEYS: [&str; 3] = ["range_rates_mps", "range_rate_sigma_mps", "cpi"];

/// The optional range rates of a measurements file with `steps` (issue 42 §5; docs/doppler.md
/// D1, D5): per step one range rate per link, and where their σ comes from — fixed
/// (`range_rate_sigma_mps`, one or per link), or a CPI (`cpi`; absent: the caller's, e.g. the
/// flags of `track`). Read beside the file's [`Measurements`] by
/// [`Measurements::from_json_with_rates`]; checked against it by [`RangeRateFields::check`].
#[derive(Debug, Clone, Default, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct RangeRateFields {
    /// Per step, one range rate per link in scenario link order (`null` = missing), m/s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub range_rates_mps: Option<Vec<Vec<Option<f64>>>>,
    /// Fixed range-rate σ, one for all links or one per link, m/s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub range_rate_sigma_mps: Option<Sigma>,
    /// The CPI the rates were measured over: their σ from it at the prediction (D5).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cpi: Option<CpiFields>,
}

/// The `cpi` of a measurements file (D4, D5); the wavelength is the scenario's.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct CpiFields {
    /// Snapshots `N` in the CPI.
    pub snapshots: usize,
    /// Their spacing `T`, s.
    pub spacing_s: f64,
    /// The floor on the range rate's σ, m/s [default: 0.1].
    #[serde(default = "default_floor")]
    pub floor_mps: f64,
}

/// [`DEFAULT_RANGE_RATE_FLOOR_MPS`].
fn default_floor() -> f64 {
    DEFAULT_RANGE_RATE_FLOOR_MPS
}

/// The σ of a file's range rates.
#[derive(Debug, Clone, PartialEq)]
pub enum RateSigma {
    /// Fixed, one per link, m/s (`range_rate_sigma_mps`).
    Fixed(Vec<f64>),
    /// From the file's `cpi`.
    Cpi(Cpi),
    /// Neither given: the caller's CPI.
    Unstated,
}

/// A file's range rates after [`RangeRateFields::check`].
#[derive(Debug, Clone, PartialEq)]
pub struct CheckedRates<'a> {
    /// Per step, one range rate per link (`None` = missing), m/s.
    pub rates_mps: &'a [Vec<Option<f64>>],
    /// Their σ.
    pub sigma: RateSigma,
}

impl RateSigma {
    /// The fixed σ per link, m/s, if the file gives them.
    pub fn fixed(&self) -> Option<&[f64]> {
        match self {
            RateSigma::Fixed(s) => Some(s),
            _ => None,
        }
    }

    /// The file's CPI, if it gives one.
    pub fn cpi(&self) -> Option<Cpi> {
        match self {
            RateSigma::Cpi(c) => Some(*c),
            _ => None,
        }
    }

    /// Where the tracker takes the rates' σ from (`track`'s one rule, CLI and Python): the
    /// file's fixed σ as given; else the `caller`'s CPI if given (`track --doppler --cpi …`),
    /// else the file's `cpi`, else `default` (the CPI of the flags' defaults). A caller's CPI
    /// beside a fixed σ is refused by the caller (the CLI and Python name it).
    ///
    /// # Example
    ///
    /// ```
    /// use scatterloc::formats::RateSigma;
    /// use scatterloc::measure::Cpi;
    /// use scatterloc::track::RateNoise;
    ///
    /// let file = Cpi::new(5.8e9, 8, 1e-3, 0.1).unwrap();
    /// let caller = Cpi::new(5.8e9, 32, 2e-3, 0.2).unwrap();
    /// let default = Cpi::new(5.8e9, 16, 2.048e-3, 0.1).unwrap();
    /// let fixed = RateSigma::Fixed(vec![0.3, 0.4]);
    /// assert_eq!(fixed.noise(None, default), RateNoise::Fixed(&[0.3, 0.4]));
    /// assert_eq!(fixed.noise(Some(caller), default), RateNoise::Fixed(&[0.3, 0.4]));
    /// assert_eq!(RateSigma::Cpi(file).noise(None, default), RateNoise::Cpi(file));
    /// assert_eq!(RateSigma::Cpi(file).noise(Some(caller), default), RateNoise::Cpi(caller));
    /// assert_eq!(RateSigma::Unstated.noise(None, default), RateNoise::Cpi(default));
    /// assert_eq!(RateSigma::Unstated.noise(Some(caller), default), RateNoise::Cpi(caller));
    /// ```
    pub fn noise(&self, caller: Option<Cpi>, default: Cpi) -> RateNoise<'_> {
        match (self, caller) {
            (RateSigma::Fixed(s), _) => RateNoise::Fixed(s),
            (_, Some(c)) => RateNoise::Cpi(c),
            (RateSigma::Cpi(file), None) => RateNoise::Cpi(*file),
            (RateSigma::Unstated, None) => RateNoise::Cpi(default),
        }
    }
}

impl RangeRateFields {
    /// Whether the file gives none of the fields.
    pub fn is_empty(&self) -> bool {
        self == &RangeRateFields::default()
    }

    /// Checks the fields against `m` for `links` links on a carrier of `carrier_hz`: `None`
    /// without `range_rates_mps`. Errors name the field: `range_rate_sigma_mps` or `cpi`
    /// without `range_rates_mps`, or both given; `range_rates_mps` with `raw_steps`, of another
    /// step count than `steps`, or a step of another link count (`range_rates_mps[k]`); a rate
    /// not finite or outside [`limits::RANGE_RATE_M_S`] (`range_rates_mps[k][p]`); a σ outside
    /// [`limits::RANGE_RATE_SIGMA_M_S`] (`range_rate_sigma_mps[p]`; a list of another length:
    /// [`Error::LengthMismatch`]); a bad CPI as [`Cpi::new`] names it (`cpi.snapshots`, …).
    pub fn check(
        &self,
        m: &Measurements,
        links: usize,
        carrier_hz: f64,
    ) -> Result<Option<CheckedRates<'_>>> {
        let Some(rates) = &self.range_rates_mps else {
            for (given, field) in [
                (self.range_rate_sigma_mps.is_some(), "range_rate_sigma_mps"),
                (self.cpi.is_some(), "cpi"),
            ] {
                if given {
                    return Err(invalid(field, "only with range_rates_mps".into()));
                }
            }
            return Ok(None);
        };
        let Some(steps) = &m.steps else {
            return Err(invalid(
                "range_rates_mps",
                "only with steps (not raw_steps)".into(),
            ));
        };
        if rates.len() != steps.len() {
            return Err(invalid(
                "range_rates_mps",
                format!(
                    "expected {} lists (one per step of steps), found {}",
                    steps.len(),
                    rates.len()
                ),
            ));
        }
        for (k, step) in rates.iter().enumerate() {
            if step.len() != links {
                return Err(invalid(
                    format!("range_rates_mps[{k}]"),
                    format!(
                        "expected {links} range rates (one per link, null = missing), found {}",
                        step.len()
                    ),
                ));
            }
            for (p, rate) in step.iter().enumerate() {
                if let Some(v) = *rate {
                    if !limits::RANGE_RATE_M_S.contains(v) {
                        limits::RANGE_RATE_M_S.check(&format!("range_rates_mps[{k}][{p}]"), v)?;
                    }
                }
            }
        }
        let sigma = match (&self.range_rate_sigma_mps, &self.cpi) {
            (Some(_), Some(_)) => {
                return Err(invalid(
                    "cpi",
                    "give at most one of range_rate_sigma_mps and cpi".into(),
                ))
            }
            (Some(s), None) => RateSigma::Fixed(rate_sigmas(s, links)?),
            (None, Some(c)) => {
                RateSigma::Cpi(Cpi::new(carrier_hz, c.snapshots, c.spacing_s, c.floor_mps)?)
            }
            (None, None) => RateSigma::Unstated,
        };
        Ok(Some(CheckedRates {
            rates_mps: rates,
            sigma,
        }))
    }
}

/// `range_rate_sigma_mps` as one σ per link of `links`, each within
/// [`limits::RANGE_RATE_SIGMA_M_S`].
fn rate_sigmas(s: &Sigma, links: usize) -> Result<Vec<f64>> {
    match s {
        Sigma::One(v) => {
            limits::RANGE_RATE_SIGMA_M_S.check("range_rate_sigma_mps", *v)?;
            Ok(vec![*v; links])
        }
        Sigma::PerLink(v) if v.len() != links => Err(Error::LengthMismatch {
            field: "range_rate_sigma_mps",
            expected: links,
            found: v.len(),
        }),
        Sigma::PerLink(v) => {
            for (p, s) in v.iter().enumerate() {
                limits::RANGE_RATE_SIGMA_M_S.check(&format!("range_rate_sigma_mps[{p}]"), *s)?;
            }
            Ok(v.clone())
        }
    }
}

impl Measurements {
    /// Parses a measurements file that may carry range rates ([`RANGE_RATE_KEYS`]). A file
    /// without them reads exactly as [`Measurements::from_json`] (the same value, the same
    /// errors); with them, those keys are read as [`RangeRateFields`] and the rest as
    /// [`Measurements`] (errors name the field: [`Error::Parse`]).
    ///
    /// # Example
    ///
    /// ```
    /// use scatterloc::formats::Measurements;
    ///
    /// let base = r#""dt_s": 0.1, "process_noise": 0.1, "initial_state": [1, 2, 0, 0],
    ///     "initial_covariance": [[0.1,0,0,0],[0,0.1,0,0],[0,0,0.01,0],[0,0,0,0.01]],
    ///     "steps": [[3.0e-8, null]]"#;
    /// // Without range rates: exactly `from_json`.
    /// let (m, rates) = Measurements::from_json_with_rates(&format!("{{{base}}}")).unwrap();
    /// assert_eq!(m, Measurements::from_json(&format!("{{{base}}}")).unwrap());
    /// assert!(rates.is_empty() && rates.check(&m, 2, 5.8e9).unwrap().is_none());
    /// // With them, checked against the steps: one list per step, one rate per link.
    /// let text = format!(r#"{{{base}, "range_rates_mps": [[0.5, null]], "range_rate_sigma_mps": 0.2}}"#);
    /// let (m, rates) = Measurements::from_json_with_rates(&text).unwrap();
    /// let checked = rates.check(&m, 2, 5.8e9).unwrap().unwrap();
    /// assert_eq!(checked.rates_mps, &[vec![Some(0.5), None]]);
    /// assert_eq!(checked.sigma.fixed(), Some(&[0.2, 0.2][..]));
    /// let e = rates.check(&m, 3, 5.8e9).unwrap_err();
    /// assert!(e.to_string().starts_with("range_rates_mps[0]: expected 3 range rates"));
    /// ```
    pub fn from_json_with_rates(text: &str) -> Result<(Measurements, RangeRateFields)> {
        let first = match Measurements::from_json(text) {
            Ok(m) => return Ok((m, RangeRateFields::default())),
            Err(e) => e,
        };
        let Ok(serde_json::Value::Object(mut rest)) = serde_json::from_str(text) else {
            return Err(first);
        };
        if !RANGE_RATE_KEYS.iter().any(|k| rest.contains_key(*k)) {
            return Err(first);
        }
        let mut rates = serde_json::Map::new();
        for k in RANGE_RATE_KEYS {
            if let Some(v) = rest.remove(k) {
                rates.insert(k.into(), v);
            }
        }
        // Numbers round-trip exactly (serde_json's float_roundtrip and shortest printing).
        let fields: RangeRateFields = parse_json(&serde_json::Value::Object(rates).to_string())?;
        let m = Measurements::from_json(&serde_json::Value::Object(rest).to_string())?;
        Ok((m, fields))
    }
}
