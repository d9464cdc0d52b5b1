//! The trackers side by side (issue 15): which one a study or a track runs ([`FilterKind`]) and
//! one value that is any of them ([`Tracker`]), so a driver — a Monte Carlo chunk, the CLI's
//! `track --filter`, the page's animated track — predicts, updates and reads the estimate the
//! same way whichever filter it holds. The EKF (spec §6), the UKF and the bootstrap particle
//! filter (`filters-and-planning.md` §1–2) share the CV motion model (E7) and the delay
//! measurement model (E1, E8).

use alloc::boxed::Box;

use alloc::string::ToString;

use crate::error::{Error, Result};
use crate::math::{Mat4, Real, Vec2, Vec4};
use crate::measure::{Model, Rng};
use crate::track::{ConstantVelocity, Ekf, MeasurementNoise, UpdateSummary};
use crate::track::{ParticleFilter, PfConfig, Ukf, UkfParams};

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

    /// `ekf`, `ukf` or `pf`.
    pub fn name(&self) -> &'static str {
        match self {
            Tracker::Ekf(_) => "ekf",
            Tracker::Ukf(_) => "ukf",
            Tracker::Pf(_) => "pf",
        }
    }

    /// Predict by the CV model (E7).
    pub fn predict(&mut self, motion: &ConstantVelocity) {
        match self {
            Tracker::Ekf(f) => f.predict(motion),
            Tracker::Ukf(f) => f.predict(motion),
            Tracker::Pf(f) => f.predict(motion),
        }
    }

    /// Update with delays `z` (s, one per link, `None` = missing): the filter's own update
    /// (the EKF without innovations, the particle filter's summary). On error the filter is
    /// unchanged.
    pub fn update(
        &mut self,
        model: &Model,
        z: &[Option<Real>],
        noise: MeasurementNoise,
    ) -> Result<UpdateSummary> {
        match self {
            Tracker::Ekf(f) => f.update(model, z, noise, None),
            Tracker::Ukf(f) => f.update(model, z, noise),
            Tracker::Pf(f) => f.update(model, z, noise).map(|u| u.summary),
        }
    }

    /// Predict then update (one filter step); on error the filter is left as before the step.
    pub fn step(
        &mut self,
        motion: &ConstantVelocity,
        model: &Model,
        z: &[Option<Real>],
        noise: MeasurementNoise,
    ) -> Result<UpdateSummary> {
        match self {
            Tracker::Ekf(f) => f.step(motion, model, z, noise),
            Tracker::Ukf(f) => f.step(motion, model, z, noise),
            Tracker::Pf(f) => f.step(motion, model, z, noise).map(|u| u.summary),
        }
    }

    /// The estimate `x̂`, m and m/s (the particle filter's weighted mean).
    pub fn state(&self) -> &Vec4 {
        match self {
            Tracker::Ekf(f) => &f.state,
            Tracker::Ukf(f) => &f.state,
            Tracker::Pf(f) => &f.state,
        }
    }

    /// Its covariance `P` (the particle filter's weighted covariance).
    pub fn covariance(&self) -> &Mat4 {
        match self {
            Tracker::Ekf(f) => &f.covariance,
            Tracker::Ukf(f) => &f.covariance,
            Tracker::Pf(f) => &f.covariance,
        }
    }

    /// Position part of the estimate, m.
    pub fn position(&self) -> Vec2 {
        let x = self.state();
        Vec2::new(x[0], x[1])
    }
}
