//! What the three filters share (issue 23 §2): the measurement-noise option and the outcome
//! types of an update, the checks of a user-supplied start, the update preamble (the lengths of
//! `z` and of `Fixed` noise, the links present), the first bad input of an update, the
//! information of a delay σ or an SNR (E8), the node geometry of the EKF's pass 1
//! ([`geometry`]) and the `LDLᵀ` test and NEES form of a 4 × 4 covariance ([`nees`]).
//!
//! The EKF (spec §6, S16–S17), the UKF and the particle filter (`filters-and-planning.md`
//! §1–2) use these; the EKF's lane-batched update (`ekf::batch`) is written against them with
//! `#[inline(always)]`, so it compiles as before.

use nalgebra::Cholesky;

use crate::error::{check_len, limits, Error, Result};
use crate::math::{Mat4, Real, Vec2, Vec4, PI, SPEED_OF_LIGHT};
use crate::measure::Model;
use crate::track::ConstantVelocity;

mod geometry;
mod nees;

pub(crate) use geometry::{NodeView, NodeViews};
pub(crate) use nees::{spd_quadratic_form, Ldl4};

/// Where the measurement noise `R = diag(σ_p²)` comes from (spec §6 \[choice\]).
#[derive(Debug, Clone, Copy)]
pub enum MeasurementNoise<'a> {
    /// Fixed `σ_p` per link, s (e.g. the parameter estimator's variances).
    Fixed(&'a [Real]),
    /// `σ_p` from the link budget (E8) at the predicted position — the simulation default.
    AtPrediction,
    /// `σ_p` from the link budget at a given position (the "oracle" option: the truth).
    At(Vec2),
}

impl MeasurementNoise<'_> {
    /// `Fixed` noise must give one σ per link (`LengthMismatch` of `sigma_s` otherwise).
    pub fn check_links(&self, n: usize) -> Result<()> {
        match self {
            MeasurementNoise::Fixed(s) if s.len() != n => Err(Error::LengthMismatch {
                field: "sigma_s",
                expected: n,
                found: s.len(),
            }),
            _ => Ok(()),
        }
    }

    /// `σ_p` of link `link`, s, for a filter whose predicted position is `r_pred`.
    pub fn sigma(&self, model: &Model, link: usize, r_pred: Vec2) -> Real {
        match *self {
            MeasurementNoise::Fixed(s) => s[link],
            MeasurementNoise::AtPrediction => model.sigma_delay(link, r_pred),
            MeasurementNoise::At(r) => model.sigma_delay(link, r),
        }
    }
}

/// The filter's predicted measurement of one link: `h_p(r̂⁻)` (E1) and the innovation standard
/// deviation `√S_pp`, `S_pp = J_p P_rr J_pᵀ + σ_p²` (E3, spec §6), both in seconds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PredictedDelay {
    /// `h_p(r̂⁻)`, s.
    pub delay_s: Real,
    /// `√S_pp`, s.
    pub innovation_sigma_s: Real,
}

impl PredictedDelay {
    /// `|τ − h_p(r̂⁻)| / √S_pp`: the normalised innovation of a candidate delay.
    pub fn normalized_innovation(&self, delay_s: Real) -> Real {
        (delay_s - self.delay_s).abs() / self.innovation_sigma_s
    }
}

/// Outcome of one update.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UpdateSummary {
    /// Normalised innovation squared `νᵀ S⁻¹ ν` (0 when no link was used).
    pub nis: Real,
    /// Links whose measurement was used.
    pub links_used: usize,
}

/// `8π²β²/c²`: turns an SNR into the range-domain information `1/(cσ_p)²`, 1/m² (E8).
#[inline(always)]
pub(crate) fn range_information_per_snr(model: &Model) -> Real {
    8.0 * PI * PI * model.beta2 / (SPEED_OF_LIGHT * SPEED_OF_LIGHT)
}

/// `1/(cσ)²` for a delay standard deviation `σ`, 1/m² (checked by the caller).
#[inline(always)]
pub(crate) fn information_from_sigma(sigma: Real) -> Real {
    let r = SPEED_OF_LIGHT * sigma;
    1.0 / (r * r)
}

/// Checks a user-supplied state: finite, position within [`limits::COORDINATE_M`], velocity
/// within [`limits::VELOCITY_M_S`] (errors name `initial_state[i]`).
pub(crate) fn check_state(state: &Vec4) -> Result<()> {
    if state.iter().any(|v| !v.is_finite()) {
        return Err(Error::NonFinite {
            field: "initial_state".into(),
        });
    }
    for (i, range) in [
        limits::COORDINATE_M,
        limits::COORDINATE_M,
        limits::VELOCITY_M_S,
        limits::VELOCITY_M_S,
    ]
    .iter()
    .enumerate()
    {
        range.check(&alloc::format!("initial_state[{i}]"), state[i])?;
    }
    Ok(())
}

/// Relative asymmetry tolerated in a user-supplied covariance.
const SYMMETRY_TOLERANCE: Real = 1e-9;

/// Checks that `p` is finite, symmetric (to 1e-9 relative) and positive definite.
pub fn check_covariance(field: &str, p: &Mat4) -> Result<()> {
    if p.iter().any(|v| !v.is_finite()) {
        return Err(Error::NonFinite {
            field: field.into(),
        });
    }
    let scale = p.abs().max();
    if (p - p.transpose()).abs().max() > SYMMETRY_TOLERANCE * scale || Cholesky::new(*p).is_none() {
        return Err(Error::NotPositiveDefinite {
            field: field.into(),
        });
    }
    Ok(())
}

/// `x > 0` and finite, as two float compares (`is_finite` becomes an integer classification
/// sequence in the hot loop).
#[inline(always)]
pub(crate) fn positive_finite(x: Real) -> bool {
    x > 0.0 && finite_probe(x) == 0.0
}

/// `x − x`: `0` for a finite `x`, NaN otherwise (a sum of probes is `0` iff all are finite).
#[inline(always)]
#[allow(clippy::eq_op)]
pub(crate) fn finite_probe(x: Real) -> Real {
    x - x
}

/// The update preamble of every filter: `z` has one entry per link (`LengthMismatch` of
/// `measurement`), `Fixed` noise one σ per link (`LengthMismatch` of `sigma_s`); the number of
/// links present.
#[inline(always)]
pub(crate) fn check_update(
    model: &Model,
    z: &[Option<Real>],
    noise: MeasurementNoise,
) -> Result<usize> {
    let n = model.link_count();
    check_len("measurement", n, z.len())?;
    noise.check_links(n)?;
    Ok(z.iter().filter(|v| v.is_some()).count())
}

/// The summary of an update without links.
pub(crate) const NO_UPDATE: UpdateSummary = UpdateSummary {
    nis: 0.0,
    links_used: 0,
};

/// `σ_p` of every link for a filter at `r` (after [`check_update`]-style length checks):
/// [`Error::InvalidSigma`] for one that is not finite and `> 0`. The noise of the predicted
/// delays of every filter.
pub(crate) fn link_sigmas(
    model: &Model,
    noise: MeasurementNoise,
    r: Vec2,
) -> Result<alloc::vec::Vec<Real>> {
    let n = model.link_count();
    noise.check_links(n)?;
    (0..n)
        .map(|link| {
            let sigma = noise.sigma(model, link, r);
            if positive_finite(sigma) {
                Ok(sigma)
            } else {
                Err(Error::InvalidSigma { link, value: sigma })
            }
        })
        .collect()
}

/// The Gaussian filters' predict (the EKF's S16 and the UKF's exact unscented transform of the
/// linear CV model): `x̂⁻ = A x̂`, `P⁻ = A P Aᵀ + Q` (E7).
#[inline(always)]
pub(crate) fn predict_gaussian(state: &mut Vec4, covariance: &mut Mat4, motion: &ConstantVelocity) {
    *state = motion.propagate(state);
    *covariance = motion.propagate_covariance(covariance);
}

/// Runs `op` on `filter`; on error `filter` is put back as it was (the rollback of a step).
#[inline(always)]
pub(crate) fn rolled_back<F: Clone, T>(
    filter: &mut F,
    op: impl FnOnce(&mut F) -> Result<T>,
) -> Result<T> {
    let before = filter.clone();
    op(filter).inspect_err(|_| *filter = before)
}

/// The first bad input of an update in link order (slow path, after the accumulated checks
/// failed): a delay outside [`limits::DELAY_S`], a given (`Fixed`) `σ_p` outside
/// [`limits::DELAY_SIGMA_S`], or a `σ_p` that is not finite and positive (or so small that
/// `1/(cσ_p)²` overflows). `None` if all are fine.
#[cold]
pub(crate) fn first_input_error(
    model: &Model,
    z: &[Option<Real>],
    noise: MeasurementNoise,
    r_pred: Vec2,
) -> Option<Error> {
    for (link, zi) in z.iter().enumerate() {
        let Some(zi) = *zi else { continue };
        if !limits::DELAY_S.contains(zi) {
            return Some(Error::InvalidDelay { link, value: zi });
        }
        let sigma = noise.sigma(model, link, r_pred);
        let given = matches!(noise, MeasurementNoise::Fixed(_));
        if given && !limits::DELAY_SIGMA_S.contains(sigma) {
            return Some(Error::InvalidSigma { link, value: sigma });
        }
        if !(positive_finite(sigma) && information_from_sigma(sigma).is_finite()) {
            return Some(Error::InvalidSigma { link, value: sigma });
        }
    }
    None
}
