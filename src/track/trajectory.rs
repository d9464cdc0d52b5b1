//! Tracking scenarios of \[S\] Fig. 2b (spec §9.4), the Monte Carlo prior of §9.5, and sampling
//! of truth trajectories with process noise (E7).

use nalgebra::Cholesky;

use crate::error::{Error, Result};
use crate::math::{Mat4, Real, Vec2, Vec4};
use crate::measure::{standard_normal, Rng};
use crate::track::ConstantVelocity;

/// Process-noise intensity of \[S\] §5.2 (σ_q² = 0.01 m²/s³).
pub const PAPER_INTENSITY: Real = 0.01;
/// Duration of the \[S\] scenarios, s.
pub const PAPER_DURATION_S: Real = 10.0;
/// Time step `T_g` of \[S\] Table 1, s.
pub const PAPER_STEP_S: Real = 2.048e-3;
/// Trajectories of the paper-scale Monte Carlo study (\[S\] §5.2; spec §8): the default of
/// `scatterloc montecarlo`/`pcrlb --runs` and Python's `runs`.
pub const PAPER_RUNS: usize = 5000;
/// Measurement-noise realisations per trajectory of the paper-scale study (`--noise-runs`).
pub const PAPER_NOISE_RUNS: usize = 50;
/// The seed of every study when none is given (the CLI's `--seed`, Python's `seed`).
pub const DEFAULT_STUDY_SEED: u64 = 1;

/// The three scenarios of \[S\] Fig. 2b on layout L4 (spec §9.4 \[choice\]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TrackScenario {
    /// Start (4, 1), heading 10°: main beam, far from baselines.
    I,
    /// Start (−4.5, −2), heading −30°: crosses the Tx–Rx3 baseline at 1.7 s.
    II,
    /// Start (−4.5, −8.5), heading 45°: along Tx–Rx3, crosses Tx–Rx4 at 7.2 s.
    III,
}

impl TrackScenario {
    /// All three, in order.
    pub const ALL: [TrackScenario; 3] = [TrackScenario::I, TrackScenario::II, TrackScenario::III];

    /// Parses `I`, `II` or `III` (case-insensitive).
    pub fn parse(s: &str) -> Result<TrackScenario> {
        match s.to_ascii_uppercase().as_str() {
            "I" | "1" => Ok(TrackScenario::I),
            "II" | "2" => Ok(TrackScenario::II),
            "III" | "3" => Ok(TrackScenario::III),
            _ => Err(Error::UnknownTrajectory {
                field: "trajectory".into(),
                name: s.into(),
                known: "I, II, III",
            }),
        }
    }

    /// `I`, `II` or `III`.
    pub fn name(self) -> &'static str {
        match self {
            TrackScenario::I => "I",
            TrackScenario::II => "II",
            TrackScenario::III => "III",
        }
    }

    /// Mean start `r̄`, m.
    pub fn start(self) -> Vec2 {
        match self {
            TrackScenario::I => Vec2::new(4.0, 1.0),
            TrackScenario::II => Vec2::new(-4.5, -2.0),
            TrackScenario::III => Vec2::new(-4.5, -8.5),
        }
    }

    /// Mean velocity `v̄`, m/s (|v| ≈ 1.41 m/s), exactly as printed in the §9.4 table (the
    /// check-9 values were computed from these 4-decimal numbers, not from cos/sin of the heading).
    #[allow(clippy::approx_constant)]
    pub fn velocity(self) -> Vec2 {
        match self {
            TrackScenario::I => Vec2::new(1.3927, 0.2456),
            TrackScenario::II => Vec2::new(1.2247, -0.7071),
            TrackScenario::III => Vec2::new(1.0, 1.0),
        }
    }

    /// Prior mean `x̄₀ = [r̄; v̄]`.
    pub fn mean_state(self) -> Vec4 {
        let (r, v) = (self.start(), self.velocity());
        Vec4::new(r.x, r.y, v.x, v.y)
    }
}

/// `P(t₀) = diag(0.1, 0.1, 0.01, 0.01)` (m², m²/s²) of \[S\] §5.2 / spec §9.5.
pub fn paper_initial_covariance() -> Mat4 {
    Mat4::from_diagonal(&Vec4::new(0.1, 0.1, 0.01, 0.01))
}

/// Number of steps covering `duration_s` at `dt_s`: `⌈duration/T⌉` (4883 for 10 s at 2.048 ms).
pub fn step_count(duration_s: Real, dt_s: Real) -> usize {
    let n = duration_s / dt_s;
    // Guard against 100.00000000000001 → 101 from rounding of decimal steps.
    let r = libm::round(n);
    if (n - r).abs() < 1e-9 * r.max(1.0) {
        r as usize
    } else {
        libm::ceil(n) as usize
    }
}

/// Samples truth trajectories: `x(t₀) ~ 𝒩(x̄₀, P₀)`, then `x_n = A x_{n−1} + n_n`, `n ~ 𝒩(0, Q)`.
#[derive(Debug, Clone)]
pub struct TruthSampler {
    motion: ConstantVelocity,
    mean: Vec4,
    initial_factor: Mat4,
    noise_factor: Mat4,
}

impl TruthSampler {
    /// A sampler for the prior `𝒩(mean, initial_covariance)` and the motion model.
    pub fn new(
        motion: ConstantVelocity,
        mean: Vec4,
        initial_covariance: &Mat4,
    ) -> Result<TruthSampler> {
        crate::track::check_covariance("initial_covariance", initial_covariance)?;
        let initial_factor = Cholesky::new(*initial_covariance)
            .ok_or_else(|| Error::NotPositiveDefinite {
                field: "initial_covariance".into(),
            })?
            .l();
        Ok(TruthSampler {
            motion,
            mean,
            initial_factor,
            noise_factor: motion.process_noise_factor(),
        })
    }

    /// Writes `steps + 1` states `x(t₀) … x(t_steps)` into `out` (cleared first).
    pub fn sample(&self, steps: usize, rng: &mut Rng, out: &mut alloc::vec::Vec<Vec4>) {
        out.clear();
        let mut x = self.mean + self.initial_factor * normal4(rng);
        out.push(x);
        for _ in 0..steps {
            x = self.motion.propagate(&x) + self.noise_factor * normal4(rng);
            out.push(x);
        }
    }
}

/// Four independent standard normals (a state-sized draw).
pub(crate) fn normal4(rng: &mut Rng) -> Vec4 {
    Vec4::new(
        standard_normal(rng),
        standard_normal(rng),
        standard_normal(rng),
        standard_normal(rng),
    )
}

#[cfg(test)]
mod tests;
