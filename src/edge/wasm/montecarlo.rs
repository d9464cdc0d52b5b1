//! The worker-facing Monte Carlo job: the core's study of one or more trackers
//! ([`FilterStudy`], the one the CLI runs) run a few work items per call, so a Web Worker can report progress and drop a job between calls. Chunks are
//! combined exactly ([`StudySums`]), so the result equals
//! [`run_sequential`](crate::track::run_sequential) (and the native CLI, sharded or not) for the
//! same inputs. A job can run several trackers on the same truth and measurements
//! ([`run_filter_chunk`], issue 15); the particle filter then covers only the leading chunks a
//! work budget allows (`set_filters`).

use wasm_bindgen::prelude::*;

use alloc::vec::Vec;
use serde::Deserialize;

use super::json::{to_json, FailedFilterJs, FilterCurvesJs, MonteCarloJs, StudyProgressJs};
use super::tracking::{checked_steps, page_filter, Trajectory};
use super::{err, settings};
use crate::study::{check_cost, FilterStudy, PAGE_STUDY_CPU_S};
use crate::track::{paper_initial_covariance, FilterKind, MonteCarloConfig};
use crate::{Model, Scenario};

/// [`crate::Error::TooLong`] when `study` is predicted to take more than
/// [`PAGE_STUDY_CPU_S`] (issue 24: a shared link on a 64 × 64 mesh must not start hours of work).
fn check_page_cost(model: &Model, study: &FilterStudy) -> Result<(), JsError> {
    let all = 0..study.config().chunk_count();
    check_cost(
        "runs, steps, filters (on this network's links)",
        study.predicted_cpu_s(model.link_count(), &all),
        PAGE_STUDY_CPU_S,
    )
    .map_err(err)
}

/// The settings of a [`MonteCarloJob`] (JSON: `{trajectory: {kind, x0_m, y0_m, vx_mps,
/// vy_mps}, dt_s, steps, trajectories, noise_runs, seed}`, every field required, unknown ones
/// refused).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct StudySettings {
    trajectory: Trajectory,
    /// Step `T`, s.
    dt_s: f64,
    /// Steps after t₀ (1 … [`MAX_TRACK_STEPS`](super::MAX_TRACK_STEPS)).
    steps: usize,
    /// Truth trajectories.
    trajectories: usize,
    /// Noise runs per truth trajectory.
    noise_runs: usize,
    /// The seed.
    seed: u32,
}

/// A Monte Carlo study of ε(t) of one or more trackers and ε_PCRLB(t) in progress: the core's
/// [`FilterStudy`] run a few work items per call.
#[wasm_bindgen]
pub struct MonteCarloJob {
    model: Model,
    study: FilterStudy,
}

#[wasm_bindgen]
impl MonteCarloJob {
    /// A study on scenario JSON `scenario_json` (schema v1) of `settings_json`, one object
    /// (JSON text): `{trajectory: {kind, x0_m, y0_m, vx_mps, vy_mps}, dt_s, steps,
    /// trajectories, noise_runs, seed}`: trajectory `kind` (`I`, `II`, `III`, or `custom` with
    /// prior mean start `(x0_m, y0_m)` m and velocity `(vx_mps, vy_mps)` m/s, as
    /// `App.simulate_track`), `P(t₀)`, `q̃` and EKF set-up of spec §9.5, step `dt_s` s,
    /// `steps` steps (1 … 10 000), `trajectories` × `noise_runs` EKF runs and `seed`. Throws
    /// the core's message naming the field on bad input (`settings: invalid JSON: …` for an
    /// unknown, missing or mistyped one); nothing runs yet.
    #[wasm_bindgen(constructor)]
    pub fn new(scenario_json: &str, settings_json: &str) -> Result<MonteCarloJob, JsError> {
        let model = Model::new(&Scenario::from_json(scenario_json).map_err(err)?).map_err(err)?;
        let StudySettings {
            trajectory,
            dt_s,
            steps,
            trajectories,
            noise_runs,
            seed,
        } = settings("settings", settings_json)?;
        let (mean_state, motion) = trajectory.prior_and_motion(dt_s).map_err(err)?;
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
        let study = FilterStudy::new(cfg, &[FilterKind::Ekf]).map_err(err)?;
        check_page_cost(&model, &study)?;
        Ok(MonteCarloJob { model, study })
    }

    /// The study's predicted CPU time, s (issue 24, `FilterStudy::predicted_cpu_s`, calibrated
    /// natively; the page's wasm is slower).
    pub fn predicted_cpu_s(&self) -> f64 {
        let all = 0..self.study.config().chunk_count();
        self.study.predicted_cpu_s(self.model.link_count(), &all)
    }

    /// Runs the trackers `names` (comma-separated `ekf`, `ukf`, `pf`, each at most once, in
    /// the order given; the default is `ekf`) instead, on the same truth and measurements. The
    /// UKF takes the default α, β, κ; the particle filter `particles` particles and only the
    /// leading chunks whose `runs × steps × particles` fit `particle_budget` (at least one
    /// chunk of 16 trajectories). Throws on an unknown or repeated name, a particle count
    /// outside 1 … 10⁶, or once a chunk has run.
    pub fn set_filters(
        &mut self,
        names: &str,
        particles: usize,
        particle_budget: usize,
    ) -> Result<(), JsError> {
        if self.study.items_done() > 0 {
            return Err(JsError::new(
                "set_filters: the study has started (set the filters before the first chunk)",
            ));
        }
        let mut kinds: Vec<FilterKind> = Vec::new();
        for (i, name) in names.split(',').map(str::trim).enumerate() {
            let field = alloc::format!("filters[{i}]");
            let kind = page_filter(&field, name, particles).map_err(err)?;
            if kinds.iter().any(|k| k.name() == kind.name()) {
                return Err(JsError::new(&alloc::format!(
                    "{field}: filter \"{name}\" is already in the list"
                )));
            }
            kinds.push(kind);
        }
        let study =
            FilterStudy::with_particle_budget(*self.study.config(), &kinds, particle_budget)
                .map_err(err)?;
        check_page_cost(&self.model, &study)?;
        self.study = study;
        Ok(())
    }

    /// Number of work items: chunks (16 trajectories each) summed over the filters.
    pub fn chunk_count(&self) -> usize {
        self.study.item_count()
    }

    /// Work items run so far.
    pub fn chunks_done(&self) -> usize {
        self.study.items_done()
    }

    /// Total runs of the study per filter (`trajectories × noise_runs`; the particle filter may
    /// run fewer, see `result_json`).
    pub fn runs(&self) -> usize {
        self.study.config().runs()
    }

    /// True once every work item has run.
    pub fn is_done(&self) -> bool {
        self.study.is_done()
    }

    /// Runs up to `n` more work items in order; returns whether the study is complete.
    pub fn run_chunks(&mut self, n: usize) -> Result<bool, JsError> {
        self.study.run_items(&self.model, n).map_err(err)
    }

    /// The curves from the work run so far (all of it once done), as JSON text: `{t_s,
    /// rmse_ekf_m, rmse_pcrlb_m (null where the information is singular), nees, runs,
    /// failed_runs, seed, trajectories, noise_runs, trajectories_done, steps, dt_s, chunks_done,
    /// chunk_count, done, filters: {name: {rmse_m, nees, runs, failed_runs, chunks_done,
    /// chunk_count, runs_planned}, ..}, particles, particle_budget}` (`runs_planned`: the runs the
    /// filter will have made when done). The top-level curves and counts are the
    /// EKF's when it runs, else the first filter's (`rmse_ekf_m` then holds that filter's RMSE);
    /// `ε_PCRLB` comes from the filter with the most trajectories done; `particles` and
    /// `particle_budget` are null without the particle filter. Throws before any run has been
    /// counted.
    pub fn result_json(&self) -> Result<String, JsError> {
        let results = self.study.results().map_err(err)?;
        let (cfg, filters) = (self.study.config(), self.study.filters());
        let top = results.top();
        let lead = &filters[results.curves[results.lead].0];
        let per_filter: Vec<FilterCurvesJs> = results
            .curves
            .iter()
            .map(|(i, r)| {
                let f = &filters[*i];
                FilterCurvesJs {
                    name: f.kind.name(),
                    rmse_m: &r.rmse_m,
                    nees: &r.nees,
                    runs: r.runs,
                    failed_runs: r.failed_runs,
                    chunks_done: f.chunks_done,
                    chunk_count: f.chunks,
                    runs_planned: f.runs_planned(cfg),
                }
            })
            .collect();
        let failed = results
            .failed
            .iter()
            .map(|(i, e)| FailedFilterJs {
                name: filters[*i].kind.name(),
                failed_runs: filters[*i].sums.failed_runs,
                error: alloc::string::ToString::to_string(e),
            })
            .collect();
        to_json(&MonteCarloJs::new(
            &top,
            cfg,
            StudyProgressJs {
                trajectories_done: lead.sums.trajectories,
                chunks_done: self.study.items_done(),
                chunk_count: self.study.item_count(),
                filters: per_filter,
                particles: self.study.particles(),
                particle_budget: self.study.particle_budget(),
                failed_filters: failed,
            },
        ))
    }
}
