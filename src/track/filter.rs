//! The trackers side by side (issues 15, 23): the one filter seam ([`Filter`]), which filter a
//! study or a track runs ([`FilterKind`]) and one value that is any of them ([`Tracker`]), so a
//! driver — a Monte Carlo chunk, the CLI's `track --filter`, the gated tracker of spec §4, the
//! page's animated track — predicts, updates and reads the estimate the same way whichever
//! filter it holds. The EKF (spec §6), the UKF and the bootstrap particle filter
//! (`filters-and-planning.md` §1–2) share the CV motion model (E7) and the delay measurement
//! model (E1, E8).

use alloc::boxed::Box;
use alloc::string::{String, ToString};
use alloc::vec::Vec;

use crate::error::{Error, Result};
use crate::math::{sqrt, Mat4, Real, Vec2, Vec4};
use crate::measure::{LinkMotion, Model, Rng};
use crate::track::shared::{rolled_back, spd_quadratic_form};
use crate::track::{ConstantVelocity, Ekf, MeasurementNoise, PredictedDelay, UpdateSummary};
use crate::track::{ParticleFilter, PfConfig, Ukf, UkfParams};
use crate::track::{PredictedRate, RangeRates, RateNoise};

/// The filter seam: what every tracker of the delay model does, on the CV motion model (E7) and
/// the delay measurement model (E1, `σ_p` from E8 or given).
///
/// - [`Filter::predict`]: the time update (E7; S16 for the EKF).
/// - [`Filter::predicted_delays`]: after a predict, each link's predicted delay `ẑ_p` and its
///   innovation σ `√S_pp` — the EKF's from its Jacobian (E3, `S = J P Jᵀ + σ²`), the UKF's from
///   its sigma points (§1, `S = Σ Wᶜ (𝒵 − ẑ)² + σ²`), the particle filter's from its weighted
///   particles (§2, `S = Σ w (h − ẑ)² + σ²`). Gating (E4) and association (spec §4) read them.
/// - [`Filter::update`]: the measurement update with delays `z` (one per link, `None` =
///   missing); on error the filter is unchanged.
/// - [`Filter::state`], [`Filter::covariance`], [`Filter::nees`]: the estimate, its covariance
///   and the NEES against a true state.
/// - [`Filter::step`]: predict then update, rolled back on error.
///
/// # Example
///
/// ```
/// use scatterloc::math::{Mat4, Vec4};
/// use scatterloc::measure::rng;
/// use scatterloc::scenario::presets;
/// use scatterloc::track::{ConstantVelocity, Filter, FilterKind, MeasurementNoise, Tracker};
/// use scatterloc::Model;
///
/// let model = Model::new(&presets::sensors2019()).unwrap();
/// let motion = ConstantVelocity::new(0.1, 0.1);
/// let x0 = Vec4::new(8.0, 3.0, 0.5, 0.0);
/// let p0 = Mat4::from_diagonal(&Vec4::new(0.01, 0.01, 0.1, 0.1));
/// let mut f = Tracker::new(FilterKind::Ekf, x0, p0, rng(1, 0)).unwrap();
/// f.predict(&motion);
/// let predicted = f.predicted_delays(&model, MeasurementNoise::AtPrediction).unwrap();
/// let z: Vec<_> = predicted.iter().map(|p| Some(p.delay_s)).collect();
/// let summary = f.update(&model, &z, MeasurementNoise::AtPrediction).unwrap();
/// assert_eq!(summary.links_used, model.link_count());
/// // A bad measurement leaves the filter as it was.
/// let before = *f.state();
/// let bad = vec![Some(-1.0); model.link_count()];
/// assert!(f.step(&motion, &model, &bad, MeasurementNoise::AtPrediction).is_err());
/// assert_eq!(*f.state(), before);
/// ```
pub trait Filter: Clone {
    /// `ekf`, `ukf` or `pf`.
    fn name(&self) -> &'static str;

    /// Predict by the CV model (E7).
    fn predict(&mut self, motion: &ConstantVelocity);

    /// Each link's predicted delay `ẑ_p` and innovation σ `√S_pp` at the current (predicted)
    /// state, both s, with `σ_p` from `noise` at the filter's position. `Fixed` noise of the
    /// wrong length is [`Error::LengthMismatch`]; a `σ_p` not finite and `> 0` is
    /// [`Error::InvalidSigma`]; a covariance that gives no spread is
    /// [`Error::NotPositiveDefinite`].
    fn predicted_delays(
        &self,
        model: &Model,
        noise: MeasurementNoise,
    ) -> Result<Vec<PredictedDelay>>;

    /// Update with delays `z` (s, one per link, `None` = missing; no link = nothing to do). On
    /// error the filter is unchanged.
    fn update(
        &mut self,
        model: &Model,
        z: &[Option<Real>],
        noise: MeasurementNoise,
    ) -> Result<UpdateSummary>;

    /// Update with delays `z` (s) and range rates `rates` (m/s), `None` = missing, one per link
    /// (issue 42 §3; D1, D3, D5): a link may give either or both. On error the filter is
    /// unchanged; a rate or its σ out of range is named (`range_rates[p]`,
    /// `range_rate_sigma_mps[p]`).
    fn update_doppler(
        &mut self,
        model: &Model,
        z: &[Option<Real>],
        noise: MeasurementNoise,
        rates: &RangeRates,
    ) -> Result<UpdateSummary>;

    /// Each link's predicted range rate `ṙ_p(x̂⁻)` (D1) and innovation σ `√(h P hᵀ + σ_ṙ²)`,
    /// `h = [∂ṙ/∂r, ∂ṙ/∂v]` (D3) at the estimate, with `σ_ṙ` from `noise` there (`+∞` where
    /// it is: no Doppler information). Gating and association read them beside
    /// [`Filter::predicted_delays`]. `Fixed` noise of the wrong length is
    /// [`Error::LengthMismatch`].
    fn predicted_range_rates(&self, model: &Model, noise: RateNoise) -> Result<Vec<PredictedRate>> {
        if let RateNoise::Fixed(s) = noise {
            crate::error::check_len("range_rate_sigma_mps", model.link_count(), s.len())?;
        }
        let x = self.state();
        let (r, v) = (Vec2::new(x[0], x[1]), Vec2::new(x[2], x[3]));
        let p = self.covariance();
        Ok((0..model.link_count())
            .map(|link| {
                let g = LinkMotion::new(&model.network, link, r, v);
                let sigma = noise.sigma(model, link, &g);
                let h = g.rate_row();
                PredictedRate {
                    range_rate_mps: g.range_rate_mps,
                    innovation_sigma_mps: sqrt(h.dot(&(p * h)) + sigma * sigma),
                }
            })
            .collect())
    }

    /// The estimate `x̂ = [x, y, vx, vy]`, m and m/s.
    fn state(&self) -> &Vec4;

    /// Its covariance `P`.
    fn covariance(&self) -> &Mat4;

    /// Position part of the estimate, m.
    fn position(&self) -> Vec2 {
        let x = self.state();
        Vec2::new(x[0], x[1])
    }

    /// Normalised estimation error squared `(x̂ − x)ᵀ P⁻¹ (x̂ − x)` against a true state;
    /// `None` if `P` is not positive definite.
    fn nees(&self, truth: &Vec4) -> Option<Real> {
        spd_quadratic_form(self.covariance(), &(self.state() - truth))
    }

    /// Predict then update (one filter step); on error the filter is left as before the step.
    fn step(
        &mut self,
        motion: &ConstantVelocity,
        model: &Model,
        z: &[Option<Real>],
        noise: MeasurementNoise,
    ) -> Result<UpdateSummary> {
        rolled_back(self, |f| {
            f.predict(motion);
            f.update(model, z, noise)
        })
    }
}

/// Predict then update with delays and range rates ([`Filter::update_doppler`]); on error the
/// filter is left as before the step.
pub fn step_doppler<F: Filter>(
    filter: &mut F,
    motion: &ConstantVelocity,
    model: &Model,
    z: &[Option<Real>],
    noise: MeasurementNoise,
    rates: &RangeRates,
) -> Result<UpdateSummary> {
    rolled_back(filter, |f| {
        f.predict(motion);
        f.update_doppler(model, z, noise, rates)
    })
}

/// The tracker a study or a track runs: the EKF (spec §6), the UKF or the bootstrap particle
/// filter (`filters-and-planning.md` §1–2), all on the same motion and measurement models.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum FilterKind {
    /// The EKF (the studies of \[S\] Fig. 3).
    #[default]
    Ekf,
    /// The UKF with these parameters.
    Ukf(UkfParams),
    /// The particle filter with these settings.
    Pf(PfConfig),
}

impl FilterKind {
    /// `ekf`, `ukf` or `pf`.
    pub fn name(&self) -> &'static str {
        match self {
            FilterKind::Ekf => "ekf",
            FilterKind::Ukf(_) => "ukf",
            FilterKind::Pf(_) => "pf",
        }
    }

    /// The filter named `name` (`ekf`, `ukf` with `ukf`'s parameters, `pf` with `pf`'s
    /// settings), its settings validated; an unknown name is [`Error::UnknownFilter`] naming
    /// `field`.
    pub fn named(field: &str, name: &str, ukf: UkfParams, pf: PfConfig) -> Result<FilterKind> {
        let kind = match name {
            "ekf" => FilterKind::Ekf,
            "ukf" => FilterKind::Ukf(ukf),
            "pf" => FilterKind::Pf(pf),
            _ => {
                return Err(Error::UnknownFilter {
                    field: field.to_string(),
                    name: name.to_string(),
                })
            }
        };
        kind.validate()?;
        Ok(kind)
    }

    /// Checks the filter's settings ([`UkfParams::validate`], [`PfConfig::validate`]).
    pub fn validate(&self) -> Result<()> {
        match self {
            FilterKind::Ekf => Ok(()),
            FilterKind::Ukf(p) => p.validate(),
            FilterKind::Pf(c) => c.validate(),
        }
    }
}

/// A front end's tracker settings as its user gave them (`None` / `false`: not given): the UKF's
/// parameters and the particle filter's. [`FilterSettings::kinds`] turns a list of filter names
/// into [`FilterKind`]s with them, the defaults where not given, and refuses a setting of a
/// filter that is not run — the one rule of the CLI's `--filter(s)` flags and the Python
/// package's `filter(s)` arguments.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct FilterSettings {
    /// UKF α.
    pub ukf_alpha: Option<Real>,
    /// UKF β.
    pub ukf_beta: Option<Real>,
    /// UKF κ.
    pub ukf_kappa: Option<Real>,
    /// Particles of the particle filter.
    pub particles: Option<usize>,
    /// Its roughening constant.
    pub roughening: Option<Real>,
    /// Run it as the plain bootstrap filter.
    pub bootstrap: bool,
}

impl FilterSettings {
    /// The filters `names` (`ekf`, `ukf`, `pf`, in order) with these settings, each validated.
    /// A UKF setting without `ukf` in `names`, or a particle-filter setting without `pf`, is
    /// [`Error::UnusedSetting`] naming the setting and `list` (the front end's name of the list);
    /// an unknown name is [`Error::UnknownFilter`] naming `field_of(i)`.
    pub fn kinds(
        &self,
        names: &[&str],
        list: &str,
        field_of: impl Fn(usize) -> String,
    ) -> Result<Vec<FilterKind>> {
        let given: [(&str, &'static str, bool); 6] = [
            ("ukf_alpha", "ukf", self.ukf_alpha.is_some()),
            ("ukf_beta", "ukf", self.ukf_beta.is_some()),
            ("ukf_kappa", "ukf", self.ukf_kappa.is_some()),
            ("particles", "pf", self.particles.is_some()),
            ("roughening", "pf", self.roughening.is_some()),
            ("bootstrap", "pf", self.bootstrap),
        ];
        if let Some((field, filter, _)) = given
            .iter()
            .find(|(_, filter, g)| *g && !names.contains(filter))
        {
            return Err(Error::UnusedSetting {
                field: field.to_string(),
                filter,
                list: list.to_string(),
            });
        }
        let d = UkfParams::default();
        let ukf = UkfParams {
            alpha: self.ukf_alpha.unwrap_or(d.alpha),
            beta: self.ukf_beta.unwrap_or(d.beta),
            kappa: self.ukf_kappa.unwrap_or(d.kappa),
        };
        let pf = PfConfig {
            particles: self.particles.unwrap_or(PfConfig::default().particles),
            roughening: self.roughening,
            regularized: !self.bootstrap,
        };
        names
            .iter()
            .enumerate()
            .map(|(i, n)| FilterKind::named(&field_of(i), n, ukf, pf))
            .collect()
    }
}

/// One running filter of any [`FilterKind`].
#[derive(Debug, Clone)]
pub enum Tracker {
    /// The EKF.
    Ekf(Ekf),
    /// The UKF.
    Ukf(Ukf),
    /// The particle filter (boxed: it owns its particles).
    Pf(Box<ParticleFilter>),
}

impl Tracker {
    /// A `kind` filter started at `state` with covariance `covariance` (validated as for the
    /// EKF). `rng` is the particle filter's own stream (its particles are drawn from it); the
    /// other filters ignore it.
    pub fn new(kind: FilterKind, state: Vec4, covariance: Mat4, rng: Rng) -> Result<Tracker> {
        Ok(match kind {
            FilterKind::Ekf => Tracker::Ekf(Ekf::new(state, covariance)?),
            FilterKind::Ukf(p) => Tracker::Ukf(Ukf::new(state, covariance, p)?),
            FilterKind::Pf(c) => {
                Tracker::Pf(Box::new(ParticleFilter::new(state, covariance, c, rng)?))
            }
        })
    }
}

/// Every filter behind one value: each method delegates to the filter held (the EKF's own
/// `step` is a copy and the particle filter's a clone, as the default).
impl Filter for Tracker {
    fn name(&self) -> &'static str {
        match self {
            Tracker::Ekf(f) => f.name(),
            Tracker::Ukf(f) => f.name(),
            Tracker::Pf(f) => f.name(),
        }
    }

    fn predict(&mut self, motion: &ConstantVelocity) {
        match self {
            Tracker::Ekf(f) => Filter::predict(f, motion),
            Tracker::Ukf(f) => Filter::predict(f, motion),
            Tracker::Pf(f) => Filter::predict(f.as_mut(), motion),
        }
    }

    fn predicted_delays(
        &self,
        model: &Model,
        noise: MeasurementNoise,
    ) -> Result<Vec<PredictedDelay>> {
        match self {
            Tracker::Ekf(f) => Filter::predicted_delays(f, model, noise),
            Tracker::Ukf(f) => Filter::predicted_delays(f, model, noise),
            Tracker::Pf(f) => Filter::predicted_delays(f.as_ref(), model, noise),
        }
    }

    fn update(
        &mut self,
        model: &Model,
        z: &[Option<Real>],
        noise: MeasurementNoise,
    ) -> Result<UpdateSummary> {
        match self {
            Tracker::Ekf(f) => Filter::update(f, model, z, noise),
            Tracker::Ukf(f) => Filter::update(f, model, z, noise),
            Tracker::Pf(f) => Filter::update(f.as_mut(), model, z, noise),
        }
    }

    fn update_doppler(
        &mut self,
        model: &Model,
        z: &[Option<Real>],
        noise: MeasurementNoise,
        rates: &RangeRates,
    ) -> Result<UpdateSummary> {
        match self {
            Tracker::Ekf(f) => f.update_doppler(model, z, noise, rates),
            Tracker::Ukf(f) => f.update_doppler(model, z, noise, rates),
            Tracker::Pf(f) => f.update_doppler(model, z, noise, rates).map(|u| u.summary),
        }
    }

    fn state(&self) -> &Vec4 {
        match self {
            Tracker::Ekf(f) => Filter::state(f),
            Tracker::Ukf(f) => Filter::state(f),
            Tracker::Pf(f) => Filter::state(f.as_ref()),
        }
    }

    fn covariance(&self) -> &Mat4 {
        match self {
            Tracker::Ekf(f) => Filter::covariance(f),
            Tracker::Ukf(f) => Filter::covariance(f),
            Tracker::Pf(f) => Filter::covariance(f.as_ref()),
        }
    }

    /// The held filter's step, so that the rollback copies only that filter.
    fn step(
        &mut self,
        motion: &ConstantVelocity,
        model: &Model,
        z: &[Option<Real>],
        noise: MeasurementNoise,
    ) -> Result<UpdateSummary> {
        match self {
            Tracker::Ekf(f) => Filter::step(f, motion, model, z, noise),
            Tracker::Ukf(f) => Filter::step(f, motion, model, z, noise),
            Tracker::Pf(f) => Filter::step(f.as_mut(), motion, model, z, noise),
        }
    }
}
