//! The worker-facing Monte Carlo job: the core's chunked study ([`crate::track`]) run a few
//! chunks per call, so a Web Worker can report progress and drop a job between calls. Chunks are
//! combined exactly ([`StudySums`]), so the result equals
//! [`run_sequential`](crate::track::run_sequential) (and the native CLI, sharded or not) for the
//! same inputs. A job can run several trackers on the same truth and measurements
//! ([`run_filter_chunk`], issue 15); the particle filter then covers only the leading chunks a
//! work budget allows (`set_filters`).

use wasm_bindgen::prelude::*;

use super::err;
use alloc::vec;
use alloc::vec::Vec;

use super::json::{to_json, FilterCurvesJs, MonteCarloJs};
use super::tracking::{checked_steps, page_filter, prior_and_motion};
use crate::error::Error;
use crate::track::{finish, run_filter_chunk, MonteCarloConfig, StudySums};
use crate::track::{paper_initial_covariance, FilterKind};
use crate::track::{CHUNK_TRAJECTORIES, MAX_PARTICLES};
use crate::{Model, Scenario};

/// One tracker of a job: its kind, how many leading chunks it runs, and its sums so far.
struct FilterStudy {
    kind: FilterKind,
    chunks: usize,
    sums: StudySums,
    chunks_done: usize,
}

/// A Monte Carlo study of ε(t) of one or more trackers and ε_PCRLB(t) in progress.
#[wasm_bindgen]
pub struct MonteCarloJob {
    model: Model,
    cfg: MonteCarloConfig,
    filters: Vec<FilterStudy>,
    /// Work items run (one chunk of one filter each), in the order of `order`.
    items_done: usize,
    /// Particle-steps the particle filter may use (`set_filters`), for the result.
    particle_budget: Option<usize>,
}

/// The study's work items in run order: chunk by chunk, each chunk's filters in the order given
/// (a filter drops out after its last chunk), as `(filter index, chunk)`.
fn work_items(filters: &[FilterStudy]) -> impl Iterator<Item = (usize, usize)> + '_ {
    let chunks = filters.iter().map(|f| f.chunks).max().unwrap_or(0);
    (0..chunks).flat_map(move |c| {
        filters
            .iter()
            .enumerate()
            .filter(move |(_, f)| c < f.chunks)
            .map(move |(i, _)| (i, c))
    })
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
            filters: vec![FilterStudy {
                kind: FilterKind::Ekf,
                chunks: cfg.chunk_count(),
                sums: StudySums::new(steps),
                chunks_done: 0,
            }],
            cfg,
            items_done: 0,
            particle_budget: None,
        })
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
        if self.items_done > 0 {
            return Err(JsError::new(
                "set_filters: the study has started (set the filters before the first chunk)",
            ));
        }
        let mut filters: Vec<FilterStudy> = Vec::new();
        for (i, name) in names.split(',').map(str::trim).enumerate() {
            let field = alloc::format!("filters[{i}]");
            let kind = page_filter(&field, name, particles).map_err(err)?;
            if filters.iter().any(|f| f.kind.name() == kind.name()) {
                return Err(JsError::new(&alloc::format!(
                    "{field}: filter \"{name}\" is already in the list"
                )));
            }
            let chunks = match kind {
                FilterKind::Pf(_) => pf_chunks(&self.cfg, particles, particle_budget),
                _ => self.cfg.chunk_count(),
            };
            filters.push(FilterStudy {
                kind,
                chunks,
                sums: StudySums::new(self.cfg.steps),
                chunks_done: 0,
            });
        }
        self.particle_budget = filters
            .iter()
            .any(|f| matches!(f.kind, FilterKind::Pf(_)))
            .then_some(particle_budget);
        self.filters = filters;
        Ok(())
    }

    /// Number of work items: chunks (16 trajectories each) summed over the filters.
    pub fn chunk_count(&self) -> usize {
        self.filters.iter().map(|f| f.chunks).sum()
    }

    /// Work items run so far.
    pub fn chunks_done(&self) -> usize {
        self.items_done
    }

    /// Total runs of the study per filter (`trajectories × noise_runs`; the particle filter may
    /// run fewer, see `result_json`).
    pub fn runs(&self) -> usize {
        self.cfg.runs()
    }

    /// True once every work item has run.
    pub fn is_done(&self) -> bool {
        self.items_done >= self.chunk_count()
    }

    /// Runs up to `n` more work items in order; returns whether the study is complete.
    pub fn run_chunks(&mut self, n: usize) -> Result<bool, JsError> {
        let next: Vec<(usize, usize)> = work_items(&self.filters)
            .skip(self.items_done)
            .take(n)
            .collect();
        for (i, chunk) in next {
            let f = &mut self.filters[i];
            let part = run_filter_chunk(&self.model, &self.cfg, f.kind, chunk).map_err(err)?;
            f.sums.add(&part);
            f.chunks_done += 1;
            self.items_done += 1;
        }
        Ok(self.is_done())
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
        let mut curves = Vec::new();
        for f in &self.filters {
            if f.chunks_done > 0 {
                curves.push((f, finish(&self.cfg, &f.sums).map_err(err)?));
            }
        }
        let lead = curves
            .iter()
            .position(|(f, _)| f.kind == FilterKind::Ekf)
            .unwrap_or(0);
        let widest = curves
            .iter()
            .enumerate()
            .max_by_key(|(i, (f, _))| (f.sums.trajectories, core::cmp::Reverse(*i)))
            .map(|(i, _)| i);
        let (Some((lead_f, lead_r)), Some(widest)) = (curves.get(lead), widest) else {
            return Err(err(Error::SizeLimit {
                field: "runs (successful)",
                value: 0,
                min: 1,
                max: crate::track::MAX_RUNS,
            }));
        };
        let mut top = lead_r.clone();
        top.rmse_pcrlb_m = curves[widest].1.rmse_pcrlb_m.clone();
        let per_filter: Vec<FilterCurvesJs> = curves
            .iter()
            .map(|(f, r)| FilterCurvesJs {
                name: f.kind.name(),
                rmse_m: &r.rmse_ekf_m,
                nees: &r.nees,
                runs: r.runs,
                failed_runs: r.failed_runs,
                chunks_done: f.chunks_done,
                chunk_count: f.chunks,
                runs_planned: (f.chunks * CHUNK_TRAJECTORIES).min(self.cfg.trajectories)
                    * self.cfg.noise_runs,
            })
            .collect();
        let particles = self.filters.iter().find_map(|f| match f.kind {
            FilterKind::Pf(c) => Some(c.particles),
            _ => None,
        });
        to_json(&MonteCarloJs::new(
            &top,
            &self.cfg,
            lead_f.sums.trajectories,
            self.items_done,
            self.chunk_count(),
            per_filter,
            particles,
            self.particle_budget,
        ))
    }
}

/// The chunks of `cfg` the particle filter with `particles` particles runs within
/// `particle_budget` particle-steps: the most leading chunks whose runs fit, at least one, at
/// most all.
fn pf_chunks(cfg: &MonteCarloConfig, particles: usize, particle_budget: usize) -> usize {
    let per_run = (cfg.steps as u128) * (particles.clamp(1, MAX_PARTICLES) as u128);
    let runs = (particle_budget as u128 / per_run.max(1)) as usize;
    let per_chunk = CHUNK_TRAJECTORIES * cfg.noise_runs;
    (runs / per_chunk).clamp(1, cfg.chunk_count())
}
