//! The worker-facing Monte Carlo job: the core's chunked study ([`crate::track`]) run a few
//! chunks per call, so a Web Worker can report progress and drop a job between calls. Chunks are
//! combined exactly ([`StudySums`]), so the result equals
//! [`run_sequential`](crate::track::run_sequential) (and the native CLI, sharded or not) for the
//! same inputs.

use wasm_bindgen::prelude::*;

use super::err;
use super::json::{to_json, MonteCarloJs};
use super::tracking::{checked_steps, prior_and_motion};
use crate::track::paper_initial_covariance;
use crate::track::{finish, run_chunk, MonteCarloConfig, StudySums};
use crate::{Model, Scenario};

/// A Monte Carlo study of ε_EKF(t) and ε_PCRLB(t) in progress.
#[wasm_bindgen]
pub struct MonteCarloJob {
    model: Model,
    cfg: MonteCarloConfig,
    sums: StudySums,
    chunks_done: usize,
}

#[wasm_bindgen]
impl MonteCarloJob {
    /// A study on scenario JSON `scenario_json` (schema v1) for trajectory `kind` (`I`, `II`,
    /// `III`, or `custom` with prior mean `(x0, y0, vx, vy)`), `P(t₀)`, `q̃` and EKF set-up of
    /// spec §9.5, step `dt_s`, `steps` steps (1 … 10 000), `trajectories` × `noise_runs` EKF
    /// runs and `seed`. Throws the core's message on bad input; nothing runs yet.
    #[wasm_bindgen(constructor)]
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        scenario_json: &str,
        kind: &str,
        x0: f64,
        y0: f64,
        vx: f64,
        vy: f64,
        dt_s: f64,
        steps: usize,
        trajectories: usize,
        noise_runs: usize,
        seed: u32,
    ) -> Result<MonteCarloJob, JsError> {
        let model = Model::new(&Scenario::from_json(scenario_json).map_err(err)?).map_err(err)?;
        let (mean_state, motion) = prior_and_motion(kind, [x0, y0, vx, vy], dt_s).map_err(err)?;
        let cfg = MonteCarloConfig {
            motion,
            steps,
            mean_state,
            initial_covariance: paper_initial_covariance(),
            trajectories,
            noise_runs,
            seed: seed.into(),
            oracle_noise: false,
        };
        checked_steps(steps).map_err(err)?;
        cfg.validate().map_err(err)?;
        Ok(MonteCarloJob {
            model,
            sums: StudySums::new(steps),
            cfg,
            chunks_done: 0,
        })
    }

    /// Number of chunks (16 trajectories each).
    pub fn chunk_count(&self) -> usize {
        self.cfg.chunk_count()
    }

    /// Chunks run so far.
    pub fn chunks_done(&self) -> usize {
        self.chunks_done
    }

    /// Total EKF runs of the study (`trajectories × noise_runs`).
    pub fn runs(&self) -> usize {
        self.cfg.runs()
    }

    /// True once every chunk has run.
    pub fn is_done(&self) -> bool {
        self.chunks_done >= self.cfg.chunk_count()
    }

    /// Runs up to `n` more chunks in order; returns whether the study is complete.
    pub fn run_chunks(&mut self, n: usize) -> Result<bool, JsError> {
        for _ in 0..n {
            if self.is_done() {
                break;
            }
            let part = run_chunk(&self.model, &self.cfg, self.chunks_done).map_err(err)?;
            self.sums.add(&part);
            self.chunks_done += 1;
        }
        Ok(self.is_done())
    }

    /// The curves from the chunks run so far (all of them once done), as JSON text: `{t_s,
    /// rmse_ekf_m, rmse_pcrlb_m (null where the information is singular), nees, runs,
    /// failed_runs, seed, trajectories, noise_runs, trajectories_done, steps, dt_s, chunks_done,
    /// chunk_count, done}`. Throws before the first chunk has run (no run counted yet).
    pub fn result_json(&self) -> Result<String, JsError> {
        let r = finish(&self.cfg, &self.sums).map_err(err)?;
        to_json(&MonteCarloJs::new(
            &r,
            &self.cfg,
            self.sums.trajectories,
            self.chunks_done,
        ))
    }
}
