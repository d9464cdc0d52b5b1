//! Tracking for the page's animation: `App::simulate_track` runs the core's
//! [`simulate_track`] (truth, noisy delays, and the EKF, UKF or particle filter) and hands back a
//! [`Track`], whose `data()` is the whole run and `frame(n)` one step shaped like a snapshot
//! ([`crate::present`]).

use wasm_bindgen::prelude::*;

use serde::Deserialize;

use super::json::{to_js, EstimateJs, FrameJs, TrackDataJs};
use super::{err, settings, App};
use crate::error::Error;
use crate::math::{Real, Vec2, Vec4};
use crate::present::{track_estimate, track_frame, track_mean_state, velocity_through};
use crate::track::{paper_initial_covariance, step_count, PAPER_INTENSITY};
use crate::track::{simulate_track, TrackRun};
use crate::track::{ConstantVelocity, FilterKind, PfConfig, UkfParams};
use crate::{Model, Scenario};

/// Most steps of one simulated track or browser Monte Carlo study (keeps the JSON and the
/// worker's memory bounded; 10 s at 1 ms).
pub const MAX_TRACK_STEPS: usize = 10_000;

/// The core's range of a track's step index (the URL's `step`), which the page range-checks
/// before the core does: `{"step": [0, MAX_TRACK_STEPS]}` ([`MAX_TRACK_STEPS`]), so the page and
/// the core share one definition.
#[wasm_bindgen]
pub fn track_field_ranges() -> String {
    serde_json::json!({ "step": [0, MAX_TRACK_STEPS] }).to_string()
}

/// Most particle-steps (`steps × particles`) of one animated particle-filter track: it runs on
/// the page's main thread (about 1 s in Chromium on a 2020s laptop core).
pub const MAX_TRACK_PARTICLE_STEPS: usize = 10_000_000;

/// The tracker `name` of the page (`ekf`, `ukf` with the default α, β, κ, `pf` with
/// `particles` particles), named in errors as `field`.
pub(super) fn page_filter(field: &str, name: &str, particles: usize) -> crate::Result<FilterKind> {
    let pf = PfConfig {
        particles,
        roughening: None,
        regularized: true,
    };
    FilterKind::named(field, name, UkfParams::default(), pf)
}

/// `steps` within `1..=MAX_TRACK_STEPS`, else [`Error::SizeLimit`] naming `steps`.
pub(super) fn checked_steps(steps: usize) -> crate::Result<usize> {
    if (1..=MAX_TRACK_STEPS).contains(&steps) {
        Ok(steps)
    } else {
        Err(Error::SizeLimit {
            field: "steps",
            value: steps,
            min: 1,
            max: MAX_TRACK_STEPS,
        })
    }
}

/// The trajectory of a track or study: `kind` (`I`, `II`, `III` of spec §9.4, or `custom`), and
/// for `custom` the prior mean's start `(x0_m, y0_m)` m and velocity `(vx_mps, vy_mps)` m/s
/// (ignored for the others).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct Trajectory {
    kind: String,
    x0_m: Real,
    y0_m: Real,
    vx_mps: Real,
    vy_mps: Real,
}

impl Trajectory {
    /// Its prior mean and the CV model for step `dt_s` with the paper's intensity, both
    /// validated.
    pub(super) fn prior_and_motion(&self, dt_s: Real) -> crate::Result<(Vec4, ConstantVelocity)> {
        let start = Vec2::new(self.x0_m, self.y0_m);
        let mean = track_mean_state(&self.kind, start, Vec2::new(self.vx_mps, self.vy_mps))?;
        Ok((mean, ConstantVelocity::validated(dt_s, PAPER_INTENSITY)?))
    }
}

/// The settings of `App.simulate_track` (JSON: `{trajectory: {kind, x0_m, y0_m, vx_mps,
/// vy_mps}, dt_s, steps, seed, filter, particles}`, every field required, unknown ones refused).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TrackSettings {
    trajectory: Trajectory,
    /// Step `T`, s.
    dt_s: Real,
    /// Steps after t₀ (1 … [`MAX_TRACK_STEPS`]).
    steps: usize,
    /// The noise streams' seed.
    seed: u32,
    /// `ekf`, `ukf` or `pf`.
    filter: String,
    /// The particle filter's particles (ignored by the others).
    particles: usize,
}

/// A simulated track: the run and the scenario it was simulated on.
#[wasm_bindgen]
pub struct Track {
    scenario: Scenario,
    model: Model,
    run: TrackRun,
    kind: String,
    seed: u32,
    steps: usize,
    filter: FilterKind,
}

#[wasm_bindgen]
impl App {
    /// Simulates one track ([`simulate_track`]) of `settings_json`, one object (JSON text):
    /// `{trajectory: {kind, x0_m, y0_m, vx_mps, vy_mps}, dt_s, steps, seed, filter,
    /// particles}`: trajectory `kind` = `"I"`, `"II"`, `"III"` (spec §9.4; `x0_m … vy_mps`
    /// ignored) or `"custom"` (prior mean start `(x0_m, y0_m)` m, velocity `(vx_mps, vy_mps)`
    /// m/s), `P(t₀)` and `q̃` of §9.5, step `dt_s` s, `steps` steps (1 … 10 000), noise
    /// streams from `seed`, tracked by `filter` (`ekf`, `ukf`, or `pf` with `particles`
    /// particles; `steps × particles` at most [`MAX_TRACK_PARTICLE_STEPS`]). Every filter sees
    /// the same truth and delays for one seed. The filter starts at the prior mean. Throws on
    /// bad input, naming the field (`settings: invalid JSON: …` for an unknown, missing or
    /// mistyped one).
    pub fn simulate_track(&self, settings_json: &str) -> Result<Track, JsError> {
        let TrackSettings {
            trajectory,
            dt_s,
            steps,
            seed,
            filter,
            particles,
        } = settings("settings", settings_json)?;
        let (mean, motion) = trajectory.prior_and_motion(dt_s).map_err(err)?;
        let steps = checked_steps(steps).map_err(err)?;
        let tracker = page_filter("filter", &filter, particles).map_err(err)?;
        if matches!(tracker, FilterKind::Pf(_))
            && steps.saturating_mul(particles) > MAX_TRACK_PARTICLE_STEPS
        {
            return Err(err(Error::WorkLimit {
                field: "particles × steps".into(),
                limit: MAX_TRACK_PARTICLE_STEPS,
            }));
        }
        let session = self.session();
        // Issue 24: the track runs on the page's main thread; refuse one predicted to freeze it
        // (a UKF or PF on a 64 × 64 mesh took over 90 s) with the predicted time.
        let links = session.model().link_count();
        crate::study::check_cost(
            "filter, particles, steps (on this network's links)",
            crate::study::track_cpu_s(tracker, links, steps),
            crate::study::PAGE_TRACK_CPU_S,
        )
        .map_err(err)?;
        let p0 = paper_initial_covariance();
        let run = simulate_track(
            session.model(),
            &motion,
            &mean,
            &p0,
            steps,
            seed.into(),
            tracker,
        )
        .map_err(err)?;
        Ok(Track {
            scenario: session.scenario().clone(),
            model: session.model().clone(),
            run,
            kind: trajectory.kind,
            seed,
            steps,
            filter: tracker,
        })
    }
}

impl Track {
    /// The scenario, its model, the run and the filter (for the figure export, `export.rs`).
    pub(super) fn parts(&self) -> (&Scenario, &Model, &TrackRun, FilterKind) {
        (&self.scenario, &self.model, &self.run, self.filter)
    }
}

#[wasm_bindgen]
impl Track {
    /// Number of entries (`steps + 1`, fewer if the filter failed: see `failed_at`).
    pub fn entries(&self) -> usize {
        self.run.truth.len()
    }

    /// The whole run: `{kind, filter ("ekf" | "ukf" | "pf"), particles (null but for the
    /// particle filter), seed, steps, dt_s, failed_at, t_s: [..], truth: [[x, y], ..],
    /// estimates: [[x, y, vx, vy], ..], ellipses: [1σ position ellipse of P | null, ..],
    /// sigma_m: [√(Pxx+Pyy), ..], error_m: [..], nis: [..], measurements: [[iso-delay ellipse
    /// per link | null], ..] (empty at t₀)}`.
    pub fn data(&self) -> Result<JsValue, JsError> {
        let run = &self.run;
        let est: Vec<_> = (0..run.estimates.len())
            .map(|n| track_estimate(run, n))
            .collect::<crate::Result<_>>()
            .map_err(err)?;
        to_js(&TrackDataJs::new(
            &self.kind,
            self.filter,
            self.seed,
            self.steps,
            run,
            &est,
            &self.model,
        ))
    }

    /// Step `n` shaped like `App.simulate_fix`'s snapshot (`fix` is the filter's estimate: `{x, y,
    /// vx, vy, ellipse, error_m, error_label, sigma_m, sigma_label, nis}`), plus `step`, `t_s`
    /// and the truth's velocity. Throws for a step past the end.
    pub fn frame(&self, n: usize) -> Result<JsValue, JsError> {
        let f = track_frame(&self.model, &self.run, n).map_err(err)?;
        to_js(&FrameJs::new(&f, &self.scenario))
    }

    /// One estimate: as `frame(n).fix`, without the measurement geometry.
    pub fn estimate(&self, n: usize) -> Result<JsValue, JsError> {
        to_js(&EstimateJs::new(
            &track_estimate(&self.run, n).map_err(err)?,
        ))
    }
}

/// The velocity of a trajectory drawn from `(x0, y0)` to `(x1, y1)` over `duration_s`:
/// `[vx, vy]`, m/s.
#[wasm_bindgen]
pub fn drag_velocity(
    x0: f64,
    y0: f64,
    x1: f64,
    y1: f64,
    duration_s: f64,
) -> Result<Vec<f64>, JsError> {
    let v = velocity_through(Vec2::new(x0, y0), Vec2::new(x1, y1), duration_s).map_err(err)?;
    Ok(vec![v.x, v.y])
}

/// Steps covering `duration_s` at `dt_s` (`⌈duration/T⌉`, spec §9.5), validated against the
/// cap of 10 000.
#[wasm_bindgen]
pub fn track_steps(duration_s: f64, dt_s: f64) -> Result<usize, JsError> {
    ConstantVelocity::validated(dt_s, PAPER_INTENSITY).map_err(err)?;
    if !(duration_s.is_finite() && duration_s > 0.0) {
        return Err(err(Error::NotPositive {
            field: "duration_s".into(),
            value: duration_s,
        }));
    }
    let n = step_count(duration_s, dt_s);
    checked_steps(n).map_err(err)
}
