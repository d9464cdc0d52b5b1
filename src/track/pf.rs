//! Bootstrap SIR particle filter for the bistatic-delay tracker (`filters-and-planning.md` §2),
//! on the EKF's motion model (E7) and measurement model (E1, `σ_p` from E8).
//!
//! - `N` particles drawn from `𝒩(x̄₀, P(t₀))`; each is propagated by `x ← A x + w`, `w ~ 𝒩(0, Q)`.
//! - Log-weights `ℓ_j += −½ Σ_links (z − h(x_j))² / σ_p²`, normalised with log-sum-exp, so a step
//!   whose likelihoods all underflow in linear space still has weights; only non-finite
//!   log-weights are a reported outcome ([`Error::Degenerate`]), never NaN.
//! - `σ_p` from the link budget at the weighted mean of the predicted particles (as the EKF's
//!   "at the prediction"), or fixed, or at a given position ([`MeasurementNoise`]).
//! - The estimate is the weighted mean and covariance, taken before resampling.
//! - Effective sample size `1/Σ w_j² < N/2` → systematic resampling (one uniform draw), then the
//!   optional roughening `𝒩(0, c·diag(spread²)·N^(−1/5))` (spread = the particles' range per
//!   state component; off by default).
//!
//! **Regularised** ([`PfConfig::regularized`], the default; issue 26): two additions to the
//! spec's bootstrap SIR, which stays available with `regularized: false`. The filtered target —
//! the posterior of the same prior `𝒩(x̄₀, P(t₀))`, motion and likelihood — is the same; only
//! how the particles sample it changes:
//! - *First update from a Gaussian proposal.* While the cloud is still the un-updated sample of
//!   the Gaussian prior (propagated by E7: `(A x̄, A P Aᵀ + Q)`), the first update with links
//!   redraws the particles from `q = 𝒩(x̂⁺, κ P⁺)`, the EKF update of that Gaussian (S17)
//!   widened by [`PROPOSAL_INFLATION`], and weights them by importance sampling,
//!   `ℓ_j = ln p(z | x_j) + ln 𝒩(x_j; x̂⁻, P⁻) − ln q(x_j)` (normalised with log-sum-exp as
//!   above). Without it, a wide prior against mm-level delays leaves one or a few particles
//!   with weight (scenario I of spec §9.4: 105 of 192 page runs failed).
//! - *Gaussian kernel after resampling* (Musso, Oudjane & Le Gland, 2001): each resampled
//!   particle moves by `h L ε`, `ε ~ 𝒩(0, I)`, `L` the Cholesky factor of the weighted
//!   covariance (the estimate's), `h = (4 / (N (d + 2)))^(1/(d + 4))`, `d = 4`, the bandwidth
//!   that is optimal for a Gaussian density; then the optional roughening as before.
//!
//! Each filter owns its random stream, so a result depends on the seed only, whatever the thread
//! count.

use alloc::vec;
use alloc::vec::Vec;

use rand::Rng as _;

use crate::error::{Error, Result};
use crate::math::{exp, ln, sqrt, Mat4, Real, Vec2, Vec4, SPEED_OF_LIGHT};
use crate::measure::{Model, Rng};
use crate::track::doppler::RangeRates;
use crate::track::shared::{
    check_covariance, check_state, link_sigmas, predict_gaussian, rolled_back, Ldl4, NO_UPDATE,
};
use crate::track::trajectory::normal4;
use crate::track::{
    ConstantVelocity, Ekf, Filter, MeasurementNoise, PredictedDelay, UpdateSummary,
};

mod measured;

use measured::Measured;

/// Most particles of a filter.
pub const MAX_PARTICLES: usize = 1_000_000;

/// `κ`: the regularised filter's first-update proposal is the EKF posterior's covariance times
/// this (wider than the posterior, so the importance weights stay bounded where the delays are
/// not linear over the cloud; for a Gaussian target the expected ESS is then
/// `N ((2κ − 1)/κ²)^(d/2)` = 0.56 N).
pub const PROPOSAL_INFLATION: Real = 2.0;

/// The kernel bandwidth `h = (4 / (N (d + 2)))^(1/(d + 4))` of the regularised particle filter
/// (Musso et al.: optimal for a Gaussian density), `d = 4` state components: 0.40 at N = 1000.
pub fn kernel_bandwidth(particles: usize) -> Real {
    let d = 4.0;
    libm::pow(
        4.0 / (particles.max(1) as Real * (d + 2.0)),
        1.0 / (d + 4.0),
    )
}

/// Settings of a [`ParticleFilter`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PfConfig {
    /// `N`, 1 … [`MAX_PARTICLES`].
    pub particles: usize,
    /// Roughening constant `c` (≥ 0, ≤ 10); `None` = off (the default).
    pub roughening: Option<Real>,
    /// The regularised filter (module docs; the default): the first update from a Gaussian
    /// proposal and a Gaussian kernel after each resampling. `false`: the spec's bootstrap SIR.
    pub regularized: bool,
}

impl Default for PfConfig {
    fn default() -> Self {
        PfConfig {
            particles: 1000,
            roughening: None,
            regularized: true,
        }
    }
}

impl PfConfig {
    /// The spec's plain bootstrap SIR (`filters-and-planning.md` §2) with `particles`, no
    /// roughening, not regularised.
    pub fn bootstrap(particles: usize) -> PfConfig {
        PfConfig {
            particles,
            roughening: None,
            regularized: false,
        }
    }
}

impl PfConfig {
    /// Checks the ranges (errors name `particles`, `roughening`).
    pub fn validate(&self) -> Result<()> {
        if !(1..=MAX_PARTICLES).contains(&self.particles) {
            return Err(Error::SizeLimit {
                field: "particles",
                value: self.particles,
                min: 1,
                max: MAX_PARTICLES,
            });
        }
        if let Some(c) = self.roughening {
            if !(c.is_finite() && (0.0..=10.0).contains(&c)) {
                return Err(Error::OutOfRange {
                    field: "roughening".into(),
                    value: c,
                    allowed: "0 to 10",
                });
            }
        }
        Ok(())
    }
}

/// What an update did, beyond [`UpdateSummary`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PfUpdate {
    /// Links used and the NIS of the weighted predicted measurement
    /// (`ν = z − ẑ`, `S = Σ w_j (h_j − ẑ)(h_j − ẑ)ᵀ + R`).
    pub summary: UpdateSummary,
    /// Effective sample size after the update, before resampling.
    pub ess: Real,
    /// Whether the particles were resampled.
    pub resampled: bool,
}

/// The particle filter: particles, their normalised log-weights, the estimate and the stream.
#[derive(Debug, Clone)]
pub struct ParticleFilter {
    particles: Vec<Vec4>,
    log_weights: Vec<Real>,
    /// `exp(log_weights)`, kept in step.
    weights: Vec<Real>,
    config: PfConfig,
    rng: Rng,
    /// Weighted mean, m and m/s.
    pub state: Vec4,
    /// Weighted covariance.
    pub covariance: Mat4,
    /// Scratch: the predicted ranges of every particle (`N × m`).
    ranges: Vec<Real>,
    /// The Gaussian `(mean, covariance)` the cloud is a sample of, while no update with links
    /// has happened yet (the prior, propagated by each predict); the regularised filter's first
    /// update draws from a proposal against it.
    gaussian: Option<(Vec4, Mat4)>,
}

impl ParticleFilter {
    /// `config.particles` particles drawn from `𝒩(mean, covariance)` (validated as for the EKF)
    /// with `rng`, which the filter then owns.
    pub fn new(
        mean: Vec4,
        covariance: Mat4,
        config: PfConfig,
        mut rng: Rng,
    ) -> Result<ParticleFilter> {
        check_state(&mean)?;
        check_covariance("initial_covariance", &covariance)?;
        config.validate()?;
        let l = nalgebra::Cholesky::new(covariance)
            .ok_or_else(|| Error::NotPositiveDefinite {
                field: "initial_covariance".into(),
            })?
            .l();
        let n = config.particles;
        let particles: Vec<Vec4> = (0..n).map(|_| mean + l * normal4(&mut rng)).collect();
        let mut f = ParticleFilter {
            particles,
            log_weights: vec![-ln(n as Real); n],
            weights: vec![1.0 / n as Real; n],
            config,
            rng,
            state: mean,
            covariance,
            ranges: Vec::new(),
            gaussian: Some((mean, covariance)),
        };
        f.estimate();
        Ok(f)
    }

    /// The particles.
    pub fn particles(&self) -> &[Vec4] {
        &self.particles
    }

    /// Their normalised log-weights.
    pub fn log_weights(&self) -> &[Real] {
        &self.log_weights
    }

    /// Update with delays `z` (s, one per link, `None` = missing): weights, estimate, and
    /// resampling when the effective sample size falls below `N/2`. No link: nothing to do. On
    /// error the filter is unchanged.
    pub fn update(
        &mut self,
        model: &Model,
        z: &[Option<Real>],
        noise: MeasurementNoise,
    ) -> Result<PfUpdate> {
        self.update_with(model, z, noise, None)
    }

    /// Update with delays `z` and range rates `rates` (issue 42 §3): the likelihood of each
    /// particle is the product over the delay rows (E1) and the range-rate rows (D1, `σ_ṙ` from
    /// `rates.noise` at the weighted mean of the predicted particles); the regularised filter's
    /// first proposal is the EKF's delay-and-Doppler update. Otherwise as [`Self::update`].
    pub fn update_doppler(
        &mut self,
        model: &Model,
        z: &[Option<Real>],
        noise: MeasurementNoise,
        rates: &RangeRates,
    ) -> Result<PfUpdate> {
        self.update_with(model, z, noise, Some(rates))
    }

    /// [`Self::update`] (`rates` `None`) or [`Self::update_doppler`].
    fn update_with(
        &mut self,
        model: &Model,
        z: &[Option<Real>],
        noise: MeasurementNoise,
        rates: Option<&RangeRates>,
    ) -> Result<PfUpdate> {
        let measured = Measured::new(model, z, noise, rates, &self.state)?;
        let (zc, info) = (&measured.z[..], &measured.info[..]);
        let m = zc.len();
        let n = self.particles.len();
        if m == 0 {
            return Ok(PfUpdate {
                summary: NO_UPDATE,
                ess: ess(&self.weights),
                resampled: false,
            });
        }
        let mut q = vec![0.0; n];
        measured.pass(model, &self.particles, &mut self.ranges, &mut q);
        // The NIS of the predicted particles, before any redraw.
        let nis = self.nis(zc, info, m);
        let proposal = match self.gaussian {
            Some(g) if self.config.regularized => self.first_proposal(model, z, noise, rates, g),
            _ => None,
        };
        let mut log_w = self.log_weights.clone();
        if let Some((particles, extra, _)) = &proposal {
            measured.pass(model, particles, &mut self.ranges, &mut q);
            // The cloud was unweighted: ln p(z|x) + ln prior(x) − ln q(x) (constants cancel).
            for ((l, qj), e) in log_w.iter_mut().zip(&q).zip(extra) {
                *l = -0.5 * qj + e;
            }
        } else {
            for (l, qj) in log_w.iter_mut().zip(&q) {
                *l -= 0.5 * qj;
            }
        }
        let max = log_w.iter().copied().fold(Real::NEG_INFINITY, Real::max);
        if !max.is_finite() {
            return Err(Error::Degenerate {
                field: "pf.weights".into(),
            });
        }
        let sum: Real = log_w.iter().map(|l| exp(l - max)).sum();
        let norm = max + ln(sum);
        for l in log_w.iter_mut() {
            *l -= norm;
        }
        if log_w.iter().any(|l| l.is_nan()) {
            return Err(Error::Degenerate {
                field: "pf.weights".into(),
            });
        }
        if let Some((particles, _, rng)) = proposal {
            self.particles = particles;
            self.rng = rng;
        }
        self.gaussian = None;
        self.weights = log_w.iter().map(|l| exp(*l)).collect();
        self.log_weights = log_w;
        self.estimate();
        let e = ess(&self.weights);
        let resampled = e < 0.5 * n as Real;
        if resampled {
            self.resample();
        }
        Ok(PfUpdate {
            summary: UpdateSummary {
                nis,
                links_used: measured.links,
            },
            ess: e,
            resampled,
        })
    }

    /// Predict then update (one filter step, as [`Filter::step`] with the particle filter's
    /// own outcome); on error the filter is left as before the step.
    pub fn step(
        &mut self,
        motion: &ConstantVelocity,
        model: &Model,
        z: &[Option<Real>],
        noise: MeasurementNoise,
    ) -> Result<PfUpdate> {
        rolled_back(self, |f| {
            f.predict(motion);
            f.update(model, z, noise)
        })
    }

    /// The regularised filter's first-update proposal (module docs): `N` particles drawn from
    /// `𝒩(x̂⁺, κ P⁺)` (the EKF update of the cloud's Gaussian `(x̂⁻, P⁻)` with `z`, S17) with a
    /// clone of the filter's stream, and each particle's `ln 𝒩(x; x̂⁻, P⁻) − ln q(x)` up to a
    /// common constant; the stream after the draws. `None` (the bootstrap update instead) when
    /// that update fails or a covariance is not positive definite.
    fn first_proposal(
        &self,
        model: &Model,
        z: &[Option<Real>],
        noise: MeasurementNoise,
        rates: Option<&RangeRates>,
        (mean, covariance): (Vec4, Mat4),
    ) -> Option<(Vec<Vec4>, Vec<Real>, Rng)> {
        let mut ekf = Ekf {
            state: mean,
            covariance,
        };
        match rates {
            None => ekf.update(model, z, noise, None).ok()?,
            Some(rates) => ekf.update_doppler(model, z, noise, rates).ok()?,
        };
        let pq = (ekf.covariance + ekf.covariance.transpose()) * (0.5 * PROPOSAL_INFLATION);
        let l = nalgebra::Cholesky::new(pq)?.l();
        let prior = Ldl4::new(&covariance)?;
        let proposal = Ldl4::new(&pq)?;
        let mut rng = self.rng.clone();
        let n = self.particles.len();
        let mut particles = Vec::with_capacity(n);
        let mut extra = Vec::with_capacity(n);
        for _ in 0..n {
            let e = l * normal4(&mut rng);
            let x = ekf.state + e;
            extra.push(0.5 * (proposal.quadratic_form(&e) - prior.quadratic_form(&(x - mean))));
            particles.push(x);
        }
        if extra.iter().all(|v| v.is_finite()) {
            Some((particles, extra, rng))
        } else {
            None
        }
    }

    /// NIS of the weighted predicted measurement, from the ranges just computed and the
    /// weights before this update.
    fn nis(&self, zc: &[Real], info: &[Real], m: usize) -> Real {
        let w = &self.weights;
        let mut zhat = vec![0.0; m];
        for (wj, h) in w.iter().zip(self.ranges.chunks_exact(m)) {
            for (z, hk) in zhat.iter_mut().zip(h) {
                *z += wj * hk;
            }
        }
        let mut sm = vec![0.0; m * m];
        for (j, wj) in w.iter().enumerate() {
            let h = &self.ranges[j * m..(j + 1) * m];
            for a in 0..m {
                let da = wj * (h[a] - zhat[a]);
                for b in 0..=a {
                    sm[a * m + b] += da * (h[b] - zhat[b]);
                }
            }
        }
        let mut s = nalgebra::DMatrix::<Real>::zeros(m, m);
        for a in 0..m {
            for b in 0..=a {
                s[(a, b)] = sm[a * m + b];
                s[(b, a)] = sm[a * m + b];
            }
            s[(a, a)] += 1.0 / info[a];
        }
        let nu = nalgebra::DVector::from_iterator(m, (0..m).map(|k| zc[k] - zhat[k]));
        match nalgebra::Cholesky::new(s) {
            Some(c) => nu.dot(&c.solve(&nu)),
            None => Real::INFINITY,
        }
    }

    /// Weighted mean and covariance of the particles (plain arithmetic on the 10 unique entries:
    /// the hot loop of the filter).
    fn estimate(&mut self) {
        let w = &self.weights;
        let total: Real = w.iter().sum();
        let mut mean = [0.0; 4];
        for (x, wj) in self.particles.iter().zip(w) {
            for (m, xi) in mean.iter_mut().zip(x.iter()) {
                *m += wj * xi;
            }
        }
        for m in mean.iter_mut() {
            *m /= total;
        }
        let mut c = [0.0; 10];
        for (x, wj) in self.particles.iter().zip(w) {
            let d = [
                x[0] - mean[0],
                x[1] - mean[1],
                x[2] - mean[2],
                x[3] - mean[3],
            ];
            let mut k = 0;
            for a in 0..4 {
                for b in a..4 {
                    c[k] += wj * d[a] * d[b];
                    k += 1;
                }
            }
        }
        let mut cov = Mat4::zeros();
        let mut k = 0;
        for a in 0..4 {
            for b in a..4 {
                cov[(a, b)] = c[k] / total;
                cov[(b, a)] = c[k] / total;
                k += 1;
            }
        }
        self.state = Vec4::new(mean[0], mean[1], mean[2], mean[3]);
        self.covariance = cov;
    }

    /// Systematic resampling (one uniform draw), then the regularised filter's kernel and the
    /// optional roughening.
    fn resample(&mut self) {
        let n = self.particles.len();
        let step = 1.0 / n as Real;
        let mut u = self.rng.random::<Real>() * step;
        let mut cumulative = 0.0;
        let mut out = Vec::with_capacity(n);
        let mut j = 0;
        for (i, w) in self.weights.iter().enumerate() {
            cumulative += w;
            while j < n && u < cumulative {
                out.push(self.particles[i]);
                u += step;
                j += 1;
            }
        }
        // Rounding can leave the last slots unfilled: they take the last particle.
        while out.len() < n {
            out.push(self.particles[n - 1]);
        }
        self.particles = out;
        self.log_weights.fill(-ln(n as Real));
        self.weights.fill(step);
        if self.config.regularized {
            // The kernel `h L ε` of the weighted covariance (the estimate, before resampling);
            // none if it is not positive definite (the weights collapsed onto one particle).
            if let Some(c) = nalgebra::Cholesky::new(self.covariance) {
                let hl = c.l() * kernel_bandwidth(n);
                for x in self.particles.iter_mut() {
                    *x += hl * normal4(&mut self.rng);
                }
            }
        }
        if let Some(c) = self.config.roughening {
            let mut lo = Vec4::repeat(Real::INFINITY);
            let mut hi = Vec4::repeat(Real::NEG_INFINITY);
            for x in &self.particles {
                lo = lo.inf(x);
                hi = hi.sup(x);
            }
            let scale = sqrt(c * libm::pow(n as Real, -0.2));
            let sd = (hi - lo) * scale;
            for x in self.particles.iter_mut() {
                let z = normal4(&mut self.rng);
                *x += sd.component_mul(&z);
            }
        }
    }
}

/// `1/Σ w_j²` of normalised weights.
fn ess(weights: &[Real]) -> Real {
    1.0 / weights.iter().map(|w| w * w).sum::<Real>()
}

/// The particle filter behind the filter seam: predict (E7), predicted delays from its weighted
/// particles and the SIR update (spec §2).
impl Filter for ParticleFilter {
    fn name(&self) -> &'static str {
        "pf"
    }

    /// Predict: every particle `x ← A x + w`, `w ~ 𝒩(0, Q)` (E7); the estimate follows.
    fn predict(&mut self, motion: &ConstantVelocity) {
        // `Q`'s Cholesky factor is block-diagonal per axis: [[l11, 0], [l21, l22]] on (x, vx)
        // and on (y, vy).
        let lq = motion.process_noise_factor();
        let (l11, l21, l22) = (lq[(0, 0)], lq[(2, 0)], lq[(2, 2)]);
        let t = motion.dt_s;
        for x in self.particles.iter_mut() {
            let w = normal4(&mut self.rng);
            let (px, py, vx, vy) = (x[0], x[1], x[2], x[3]);
            *x = Vec4::new(
                px + t * vx + l11 * w[0],
                py + t * vy + l11 * w[1],
                vx + l21 * w[0] + l22 * w[2],
                vy + l21 * w[1] + l22 * w[3],
            );
        }
        if let Some((m, p)) = self.gaussian.as_mut() {
            predict_gaussian(m, p, motion);
        }
        self.estimate();
    }

    /// The predicted measurement of every link from the weighted particles (spec §2):
    /// `ẑ_p = Σ w_j h_p(x_j)` and `√S_pp`, `S_pp = Σ w_j (h_p(x_j) − ẑ_p)² + σ_p²` (weights
    /// normalised), both s, with `σ_p` from `noise` at the weighted mean (as the update's). Two
    /// passes over the particles (mean, then spread); no state change.
    fn predicted_delays(
        &self,
        model: &Model,
        noise: MeasurementNoise,
    ) -> Result<Vec<PredictedDelay>> {
        let sigmas = link_sigmas(model, noise, self.position())?;
        let net = &model.network;
        let links = sigmas.len();
        let ntx = net.transmitters.len();
        let mut d = vec![0.0; ntx + net.receivers.len()];
        // The particle's range on every link (E1: the sum of its two node distances), m.
        let mut ranges = |x: &Vec4, out: &mut [Real]| {
            net.node_distances_into(Vec2::new(x[0], x[1]), &mut d);
            for (o, l) in out.iter_mut().zip(&net.links) {
                *o = d[l.tx] + d[ntx + l.rx];
            }
        };
        let total: Real = self.weights.iter().sum();
        let mut h = vec![0.0; links];
        let mut mean = vec![0.0; links];
        for (x, w) in self.particles.iter().zip(&self.weights) {
            ranges(x, &mut h);
            for (m, hk) in mean.iter_mut().zip(&h) {
                *m += w * hk;
            }
        }
        mean.iter_mut().for_each(|m| *m /= total);
        let mut var = vec![0.0; links];
        for (x, w) in self.particles.iter().zip(&self.weights) {
            ranges(x, &mut h);
            for ((v, hk), m) in var.iter_mut().zip(&h).zip(&mean) {
                *v += w * (hk - m) * (hk - m);
            }
        }
        mean.iter()
            .zip(&var)
            .zip(&sigmas)
            .map(|((m, v), sigma)| {
                let s = v / (total * SPEED_OF_LIGHT * SPEED_OF_LIGHT) + sigma * sigma;
                if !(s > 0.0 && s.is_finite() && m.is_finite()) {
                    return Err(Error::Degenerate {
                        field: "pf.predicted_delays".into(),
                    });
                }
                Ok(PredictedDelay {
                    delay_s: m / SPEED_OF_LIGHT,
                    innovation_sigma_s: sqrt(s),
                })
            })
            .collect()
    }

    fn update(
        &mut self,
        model: &Model,
        z: &[Option<Real>],
        noise: MeasurementNoise,
    ) -> Result<UpdateSummary> {
        ParticleFilter::update(self, model, z, noise).map(|u| u.summary)
    }

    fn update_doppler(
        &mut self,
        model: &Model,
        z: &[Option<Real>],
        noise: MeasurementNoise,
        rates: &RangeRates,
    ) -> Result<UpdateSummary> {
        ParticleFilter::update_doppler(self, model, z, noise, rates).map(|u| u.summary)
    }

    fn state(&self) -> &Vec4 {
        &self.state
    }

    fn covariance(&self) -> &Mat4 {
        &self.covariance
    }
}
