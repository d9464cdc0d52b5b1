//! One simulated tracking run for display and examples: a truth trajectory from the prior
//! (E7), noisy delays with `σ_p` from the link budget at the truth (E2, E8), and the track of
//! any [`FilterKind`] — the EKF (§6), the UKF or the particle filter — with its covariance and
//! NIS at every step.

use alloc::vec::Vec;

use crate::error::Result;
use crate::math::{Mat4, Real, Vec2, Vec4};
use crate::measure::Model;
use crate::measure::{rng, standard_normal};
use crate::track::ConstantVelocity;
use crate::track::TruthSampler;
use crate::track::{Filter, FilterKind, MeasurementNoise, Tracker};

/// A simulated run, `steps + 1` entries per series (`t₀ … t_steps`; no measurement at `t₀`).
#[derive(Debug, Clone, PartialEq)]
pub struct TrackRun {
    /// Time of each entry, s.
    pub t_s: Vec<Real>,
    /// True states.
    pub truth: Vec<Vec4>,
    /// Measured delays per step, s (empty at `t₀`).
    pub delays_s: Vec<Vec<Real>>,
    /// `σ_p` at the truth per step, s (empty at `t₀`).
    pub sigmas_s: Vec<Vec<Real>>,
    /// The filter's estimates.
    pub estimates: Vec<Vec4>,
    /// The filter's covariances.
    pub covariances: Vec<Mat4>,
    /// NIS per step (0 at `t₀`).
    pub nis: Vec<Real>,
    /// Step at which the filter failed numerically, if it did (the series stop there).
    pub failed_at: Option<usize>,
}

/// Simulates one run of `filter`. Truth `x(t₀) ~ 𝒩(mean, P₀)` (stream `rng(seed, 0)`),
/// measurement noise from stream `rng(seed, 1)`, so every filter sees the same truth and
/// delays for one seed; a particle filter draws its particles from `rng(seed, 2)`. The filter
/// starts at `mean`, `P₀` and uses `R` at the predicted position (spec §6, §9.5).
pub fn simulate_track(
    model: &Model,
    motion: &ConstantVelocity,
    mean: &Vec4,
    initial_covariance: &Mat4,
    steps: usize,
    seed: u64,
    filter: FilterKind,
) -> Result<TrackRun> {
    let sampler = TruthSampler::new(*motion, *mean, initial_covariance)?;
    let mut truth = Vec::with_capacity(steps + 1);
    sampler.sample(steps, &mut rng(seed, 0), &mut truth);
    let mut noise = rng(seed, 1);
    let mut tracker = Tracker::new(filter, *mean, *initial_covariance, rng(seed, 2))?;
    let links = model.link_count();
    let mut run = TrackRun {
        t_s: Vec::with_capacity(steps + 1),
        truth: Vec::with_capacity(steps + 1),
        delays_s: Vec::with_capacity(steps + 1),
        sigmas_s: Vec::with_capacity(steps + 1),
        estimates: Vec::with_capacity(steps + 1),
        covariances: Vec::with_capacity(steps + 1),
        nis: Vec::with_capacity(steps + 1),
        failed_at: None,
    };
    let mut z: Vec<Option<Real>> = Vec::with_capacity(links);
    for (n, x) in truth.iter().enumerate() {
        let r = Vec2::new(x[0], x[1]);
        let (mut delays, mut sigmas, mut nis) = (Vec::new(), Vec::new(), 0.0);
        if n > 0 {
            sigmas = model.sigma_delays(r);
            delays = (0..links)
                .map(|p| model.network.delay(p, r) + sigmas[p] * standard_normal(&mut noise))
                .collect();
            z.clear();
            z.extend(delays.iter().map(|d| Some(*d)));
            tracker.predict(motion);
            match tracker.update(model, &z, MeasurementNoise::AtPrediction) {
                Ok(s) => nis = s.nis,
                Err(_) => {
                    run.failed_at = Some(n);
                    break;
                }
            }
        }
        run.t_s.push(n as Real * motion.dt_s);
        run.truth.push(*x);
        run.delays_s.push(delays);
        run.sigmas_s.push(sigmas);
        run.estimates.push(*tracker.state());
        run.covariances.push(*tracker.covariance());
        run.nis.push(nis);
    }
    Ok(run)
}

#[cfg(test)]
mod tests;
