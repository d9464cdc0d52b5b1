//! Posterior CRLB for the tracker (spec §8, E9 = S34, S35):
//! `F_B(t_n) = (Q + A F_B(t_{n−1})⁻¹ Aᵀ)⁻¹ + E[F̃(x(t_n))]`, `F_B(t₀) = P(t₀)⁻¹`, with
//! `F̃ = blockdiag(F(r), 0₂ₓ₂)` (S30) and `F(r)` the snapshot Fisher matrix (E8).
//! No measurement at `t₀`. The expectation is supplied by the caller: a Monte Carlo mean over
//! truth trajectories, or `F` at the noise-free path for the deterministic "nominal" variant.

use alloc::vec::Vec;

use nalgebra::Cholesky;

use crate::error::{Error, Result};
use crate::localize::fisher;
use crate::math::{sqrt, Mat2, Mat4, Real, Vec2, Vec4};
use crate::measure::Model;
use crate::track::ConstantVelocity;

/// The Bayesian information `F_B(t_n)` carried through the recursion (E9).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PosteriorInformation {
    /// `F_B`, the inverse of the bound on the state error covariance.
    pub information: Mat4,
}

/// Inverse of a symmetric positive-definite 4×4 matrix.
fn spd_inverse(m: &Mat4) -> Option<Mat4> {
    Cholesky::new(*m).map(|c| c.inverse())
}

impl PosteriorInformation {
    /// `F_B(t₀) = P(t₀)⁻¹`.
    pub fn new(initial_covariance: &Mat4) -> Result<PosteriorInformation> {
        crate::track::check_covariance("initial_covariance", initial_covariance)?;
        let information =
            spd_inverse(initial_covariance).ok_or_else(|| Error::NotPositiveDefinite {
                field: "initial_covariance".into(),
            })?;
        Ok(PosteriorInformation { information })
    }

    /// One step of (E9) with the expected position Fisher matrix `mean_fisher` (1/m²).
    /// Fails only if the information stops being positive definite (reported, never NaN).
    pub fn step(&mut self, motion: &ConstantVelocity, mean_fisher: &Mat2) -> Result<()> {
        let bound = spd_inverse(&self.information).ok_or_else(|| Error::NotPositiveDefinite {
            field: "pcrlb.information".into(),
        })?;
        let predicted = motion.propagate_covariance(&bound);
        let mut info = spd_inverse(&predicted).ok_or_else(|| Error::NotPositiveDefinite {
            field: "pcrlb.prediction".into(),
        })?;
        let mut block = info.fixed_view_mut::<2, 2>(0, 0);
        block += mean_fisher;
        self.information = (info + info.transpose()) * 0.5;
        Ok(())
    }

    /// One step of (E9) with the expected Fisher matrix of the whole state `mean_fisher`
    /// (position and velocity: the delay and range-rate information of
    /// [`state_fisher`](crate::measure::state_fisher), D7). Fails as [`Self::step`].
    pub fn step_state(&mut self, motion: &ConstantVelocity, mean_fisher: &Mat4) -> Result<()> {
        let bound = spd_inverse(&self.information).ok_or_else(|| Error::NotPositiveDefinite {
            field: "pcrlb.information".into(),
        })?;
        let predicted = motion.propagate_covariance(&bound);
        let info = spd_inverse(&predicted).ok_or_else(|| Error::NotPositiveDefinite {
            field: "pcrlb.prediction".into(),
        })? + mean_fisher;
        self.information = (info + info.transpose()) * 0.5;
        Ok(())
    }

    /// `√([F_B⁻¹]₃₃ + [F_B⁻¹]₄₄)`, the bound on the velocity's RMS error, m/s; `None` if
    /// singular.
    pub fn velocity_rmse(&self) -> Option<Real> {
        self.bound().map(|b| sqrt(b[(2, 2)] + b[(3, 3)]))
    }

    /// The bound `F_B⁻¹` on the state error covariance; `None` if singular.
    pub fn bound(&self) -> Option<Mat4> {
        spd_inverse(&self.information)
    }

    /// `ε_PCRLB = √([F_B⁻¹]₁₁ + [F_B⁻¹]₂₂)`, m (spec §8); `None` if singular.
    pub fn position_rmse(&self) -> Option<Real> {
        self.bound().map(|b| sqrt(b[(0, 0)] + b[(1, 1)]))
    }
}

/// Runs (E9) for `mean_fishers.len()` steps after `t₀` and returns `ε_PCRLB(t_n)` for
/// `n = 0 … len` (`len + 1` values; `None` where the information became singular).
pub fn pcrlb_rmse(
    motion: &ConstantVelocity,
    initial_covariance: &Mat4,
    mean_fishers: &[Mat2],
) -> Result<Vec<Option<Real>>> {
    let mut fb = PosteriorInformation::new(initial_covariance)?;
    let mut out = Vec::with_capacity(mean_fishers.len() + 1);
    out.push(fb.position_rmse());
    for f in mean_fishers {
        match fb.step(motion, f) {
            Ok(()) => out.push(fb.position_rmse()),
            Err(_) => {
                out.resize(mean_fishers.len() + 1, None);
                break;
            }
        }
    }
    Ok(out)
}

/// The deterministic "nominal" PCRLB (spec §8, check 9): `E[F̃]` replaced by `F̃` at the
/// noise-free path `r̄ + t v̄` of the prior mean `x̄₀`, for `steps` steps.
pub fn nominal_pcrlb_rmse(
    model: &Model,
    motion: &ConstantVelocity,
    mean_state: &Vec4,
    initial_covariance: &Mat4,
    steps: usize,
) -> Result<Vec<Option<Real>>> {
    let (r0, v) = (
        Vec2::new(mean_state[0], mean_state[1]),
        Vec2::new(mean_state[2], mean_state[3]),
    );
    let fishers: Vec<Mat2> = (1..=steps)
        .map(|n| fisher(model, r0 + (n as Real * motion.dt_s) * v))
        .collect();
    pcrlb_rmse(motion, initial_covariance, &fishers)
}

/// The nominal PCRLB with the CPI's delay and, with `doppler`, range-rate information
/// (issue 42 §1): (E9) with `F̃` the [`state_fisher`](crate::measure::state_fisher) (D7) at the
/// noise-free path of the prior mean `x̄₀`, for `steps` steps. Returns per step `n = 0 … steps`
/// the position and velocity RMSE bounds (m, m/s; `None` once singular).
pub fn nominal_pcrlb_state(
    model: &Model,
    motion: &ConstantVelocity,
    mean_state: &Vec4,
    initial_covariance: &Mat4,
    cpi: &crate::measure::Cpi,
    doppler: bool,
    steps: usize,
) -> Result<Vec<Option<(Real, Real)>>> {
    let mut fb = PosteriorInformation::new(initial_covariance)?;
    let both = |fb: &PosteriorInformation| fb.position_rmse().zip(fb.velocity_rmse());
    let mut out = Vec::with_capacity(steps + 1);
    out.push(both(&fb));
    let v = Vec2::new(mean_state[2], mean_state[3]);
    for n in 1..=steps {
        let r = Vec2::new(mean_state[0], mean_state[1]) + (n as Real * motion.dt_s) * v;
        let x = Vec4::new(r.x, r.y, v.x, v.y);
        let f = crate::measure::state_fisher(model, &x, cpi, doppler);
        match fb.step_state(motion, &f) {
            Ok(()) => out.push(both(&fb)),
            Err(_) => {
                out.resize(steps + 1, None);
                break;
            }
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests;
