//! The generator of the §9.6 measurement case (spec §9.6 **[choice]**, the CLI's
//! `simulate-walk`): a [`WalkRequest`] (its settings, each with its default) drawn through the
//! stand-in's [`LoopPath`] and [`default_channel`] into a [`WalkSimulation`]: the calibration
//! snapshots of the empty area, the raw steps with their estimates, and the truth (states and
//! which links resolve the echo from every static path).

use alloc::format;
use alloc::vec::Vec;

use crate::error::{check_positive, limits, Error, Result};
use crate::math::{Real, Vec2, Vec4};
use crate::measure::{self, Model};
use crate::track::gating::{default_channel, DelayEstimate, LoopPath, LOOP_DURATION_S};
use crate::track::{paper_initial_covariance, step_count, ConstantVelocity, MAX_STEPS};

/// One snapshot of the simulated estimator: per link its delay estimates.
pub type WalkSnapshot = Vec<Vec<DelayEstimate>>;

/// The settings of one walk: the fields a front end sets (`simulate-walk`'s flags), each with
/// its default ([`WalkRequest::default`]); [`WalkRequest::simulate`] checks them, naming the
/// field.
#[derive(Debug, Clone, PartialEq)]
pub struct WalkRequest {
    /// Length of the walk, s (default [`LOOP_DURATION_S`], one loop).
    pub duration_s: Real,
    /// Step `T` between snapshots, s (default 0.1; [`limits::DT_S`]).
    pub dt_s: Real,
    /// Process-noise intensity `q` written with the steps, m²/s³ (default 0.1;
    /// [`limits::PROCESS_NOISE`]).
    pub process_noise: Real,
    /// Calibration snapshots of the empty area (default 500; 1 …
    /// [`limits::MAX_WALK_CALIBRATION_SNAPSHOTS`]).
    pub calibration_snapshots: usize,
    /// Mean number of false alarms per link and snapshot (default 0.5; 0 …
    /// [`crate::track::gating::MAX_FALSE_ALARMS`]).
    pub false_alarms: Real,
    /// Random seed (default 1).
    pub seed: u64,
    /// Start the filter from the true state at `t₀` and the paper's `P₀` (default `false`:
    /// from the snapshot at `t₀`).
    pub start_from_truth: bool,
}

impl Default for WalkRequest {
    fn default() -> Self {
        WalkRequest {
            duration_s: LOOP_DURATION_S,
            dt_s: 0.1,
            process_noise: 0.1,
            calibration_snapshots: 500,
            false_alarms: 0.5,
            seed: 1,
            start_from_truth: false,
        }
    }
}

/// A drawn walk: what the three files of `simulate-walk` hold.
#[derive(Debug, Clone, PartialEq)]
pub struct WalkSimulation {
    /// The calibration snapshots of the empty area (no false alarms): per snapshot and link
    /// the delays, s.
    pub calibration: Vec<Vec<Vec<Real>>>,
    /// The step `T`, s.
    pub dt_s: Real,
    /// The process-noise intensity `q`, m²/s³.
    pub process_noise: Real,
    /// The true state at `t₀` (with [`WalkRequest::start_from_truth`]).
    pub initial_state: Option<Vec4>,
    /// The paper's `P₀`, row-major (with [`WalkRequest::start_from_truth`]).
    pub initial_covariance: Option<[[Real; 4]; 4]>,
    /// The snapshot at `t₀` (without [`WalkRequest::start_from_truth`]).
    pub initial_snapshot: Option<WalkSnapshot>,
    /// The snapshots at `T, 2T, …`.
    pub raw_steps: Vec<WalkSnapshot>,
    /// The update times `T, 2T, …`, s.
    pub t_s: Vec<Real>,
    /// The true states `[x, y, vx, vy]` at those times.
    pub states: Vec<Vec4>,
    /// Per step and link: whether the echo is resolved from every static path.
    pub resolved: Vec<Vec<bool>>,
}

impl WalkSimulation {
    /// The steps where a link's echo falls in a static path's blind zone, summed over links.
    pub fn blind_zone_pairs(&self) -> usize {
        self.resolved.iter().flatten().filter(|r| !**r).count()
    }
}

impl WalkRequest {
    /// Checks the settings for `model` at bandwidth `bandwidth_hz` and returns the number of
    /// steps: `dt_s` and `process_noise` in their ranges, `duration_s > 0` giving 1 …
    /// [`MAX_STEPS`] steps, `calibration_snapshots` and `false_alarms` in theirs, and at most
    /// [`limits::MAX_WALK_ESTIMATES`] expected estimates in the files (field `walk_estimates`).
    pub fn check(&self, model: &Model, bandwidth_hz: Real) -> Result<usize> {
        ConstantVelocity::validated(self.dt_s, self.process_noise)?;
        check_positive("duration_s", self.duration_s)?;
        let steps = step_count(self.duration_s, self.dt_s);
        if steps == 0 || steps > MAX_STEPS {
            return Err(Error::SizeLimit {
                field: "steps",
                value: steps,
                min: 1,
                max: MAX_STEPS,
            });
        }
        let ncal = self.calibration_snapshots;
        if ncal == 0 || ncal > limits::MAX_WALK_CALIBRATION_SNAPSHOTS {
            return Err(Error::SizeLimit {
                field: "calibration_snapshots",
                value: ncal,
                min: 1,
                max: limits::MAX_WALK_CALIBRATION_SNAPSHOTS,
            });
        }
        let channel = default_channel(bandwidth_hz, self.false_alarms);
        channel.validate()?;
        // The files' size: about (static paths + echo + false alarms) estimates per link and
        // step.
        let per_step = model.link_count() as Real
            * (2.0 + channel.reflectors_m.len() as Real + self.false_alarms);
        let estimates = per_step * (steps + 1) as Real + per_step * ncal as Real;
        if estimates > limits::MAX_WALK_ESTIMATES {
            return Err(Error::InvalidFile {
                field: "walk_estimates".into(),
                reason: format!(
                    "about {estimates:.0} estimates would be written, at most {:.0} are allowed",
                    limits::MAX_WALK_ESTIMATES
                ),
            });
        }
        Ok(steps)
    }

    /// Draws the walk ([`LoopPath::default`] through [`default_channel`] of `bandwidth_hz`) on
    /// `model`: first the calibration snapshots of the empty area without false alarms, then the
    /// snapshot at `t₀` (drawn either way, so the later ones do not depend on
    /// [`WalkRequest::start_from_truth`]), then one snapshot per step. Errors: those of
    /// [`WalkRequest::check`].
    pub fn simulate(&self, model: &Model, bandwidth_hz: Real) -> Result<WalkSimulation> {
        let steps = self.check(model, bandwidth_hz)?;
        let (dt, from_truth) = (self.dt_s, self.start_from_truth);
        let channel = default_channel(bandwidth_hz, self.false_alarms);
        let clean = default_channel(bandwidth_hz, 0.0);
        let path = LoopPath::default();
        let mut rng = measure::rng(self.seed, 0);
        let calibration = clean.calibration_snapshots(model, self.calibration_snapshots, &mut rng);
        let states = path.states(dt, steps);
        let s0 = path.state_at(0.0);
        let first = channel.snapshot(model, Some(Vec2::new(s0[0], s0[1])), &mut rng);
        let mut raw_steps = Vec::with_capacity(steps);
        let mut resolved = Vec::with_capacity(steps);
        for s in &states {
            let r = Vec2::new(s[0], s[1]);
            raw_steps.push(channel.snapshot(model, Some(r), &mut rng));
            resolved.push(
                (0..model.link_count())
                    .map(|p| channel.resolved(model, p, model.network.delay(p, r)))
                    .collect(),
            );
        }
        let p0 = paper_initial_covariance();
        Ok(WalkSimulation {
            calibration,
            dt_s: dt,
            process_noise: self.process_noise,
            initial_state: from_truth.then_some(s0),
            initial_covariance: from_truth
                .then(|| core::array::from_fn(|i| core::array::from_fn(|j| p0[(i, j)]))),
            initial_snapshot: (!from_truth).then_some(first),
            raw_steps,
            t_s: (1..=steps).map(|k| k as Real * dt).collect(),
            states,
            resolved,
        })
    }
}

#[cfg(test)]
mod tests;
