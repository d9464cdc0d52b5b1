//! One target's Gaussian belief and its Bernoulli (existence `r`, label): the EKF's scalar
//! Joseph-form update (S17, one measurement component at a time, so a 2-D position with diagonal
//! `R` and a delay share it), its predictive likelihood, and the moment match of a mixture of
//! such beliefs (the track-oriented PMB update, Williams, IEEE TAES 51(3), 2015, §IV).

use alloc::vec::Vec;

use crate::math::{ln, Mat4, Real, Vec4, PI};
use crate::track::multi::sensors::Observation;

/// A Bernoulli component of the multi-target density: the target exists with probability
/// `existence`; if it does, its state `[x, y, vx, vy]` is Gaussian.
#[derive(Debug, Clone, PartialEq)]
pub struct Bernoulli {
    /// Stable label (unique within a run, given at birth).
    pub label: u64,
    /// Probability of existence `r`.
    pub existence: Real,
    /// Mean, m and m/s.
    pub state: Vec4,
    /// Covariance.
    pub covariance: Mat4,
    /// The scan this component was born at.
    pub born: usize,
}

/// A Gaussian belief updated by one measurement: its moments and the log predictive likelihood
/// `ln 𝒩(z; ẑ, S)` of that measurement.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Updated {
    /// Posterior mean.
    pub state: Vec4,
    /// Posterior covariance (Joseph form).
    pub covariance: Mat4,
    /// `ln 𝒩(z; ẑ, S)` (the sum over the components of a 2-D measurement).
    pub log_likelihood: Real,
    /// The Mahalanobis distance `νᵀ S⁻¹ ν` (summed over the components).
    pub distance2: Real,
}

/// The EKF update of `(x, P)` by measurement `z` (its first `obs.dim` components) with the
/// observation `obs` linearised at `x`; each component's noise variance `obs.noise[k]`. The
/// components are applied one after the other (exact for a diagonal `R`: the chain rule makes
/// the product of the scalar predictive likelihoods the joint one). `None` if an innovation
/// variance is not positive and finite.
#[allow(clippy::needless_range_loop)] // k walks four parallel arrays of `obs` and `z`
pub fn kalman_update(x: &Vec4, p: &Mat4, obs: &Observation, z: &[Real; 2]) -> Option<Updated> {
    let (mut x1, mut p1) = (*x, *p);
    let (mut ll, mut d2) = (0.0, 0.0);
    for k in 0..obs.dim {
        let h = Vec4::from(obs.jacobian[k]);
        let r = obs.noise[k];
        // The prediction at the current (partially updated) state, linearised at `x` (E3).
        let z_hat = obs.value[k] + h.dot(&(x1 - x));
        let ph = p1 * h;
        let s = h.dot(&ph) + r;
        if !(s.is_finite() && s > 0.0) {
            return None;
        }
        let nu = z[k] - z_hat;
        let gain = ph / s;
        x1 += gain * nu;
        // Joseph form: (I − K hᵀ) P (I − K hᵀ)ᵀ + K r Kᵀ.
        let a = Mat4::identity() - gain * h.transpose();
        p1 = a * p1 * a.transpose() + gain * gain.transpose() * r;
        p1 = (p1 + p1.transpose()) * 0.5;
        ll += -0.5 * (nu * nu / s + ln(2.0 * PI * s));
        d2 += nu * nu / s;
    }
    Some(Updated {
        state: x1,
        covariance: p1,
        log_likelihood: ll,
        distance2: d2,
    })
}

/// The moment match of the mixture `Σ w_k 𝒩(x_k, P_k)` (weights ≥ 0, not all 0): its mean and
/// covariance `Σ w_k (P_k + (x_k − x̄)(x_k − x̄)ᵀ) / Σ w_k`.
pub fn moment_match(parts: &[(Real, Vec4, Mat4)]) -> (Vec4, Mat4) {
    let total: Real = parts.iter().map(|(w, _, _)| *w).sum();
    let mean = parts
        .iter()
        .fold(Vec4::zeros(), |acc, (w, x, _)| acc + x * (*w / total));
    let cov = parts.iter().fold(Mat4::zeros(), |acc, (w, x, p)| {
        let d = x - mean;
        acc + (p + d * d.transpose()) * (*w / total)
    });
    (mean, (cov + cov.transpose()) * 0.5)
}

/// `Σ w_k` and the indices of the components, largest weight first (ties by index): used to cap
/// a list of components deterministically.
pub fn by_weight_desc(weights: &[Real]) -> Vec<usize> {
    let mut idx: Vec<usize> = (0..weights.len()).collect();
    idx.sort_by(|&a, &b| weights[b].total_cmp(&weights[a]).then(a.cmp(&b)));
    idx
}
