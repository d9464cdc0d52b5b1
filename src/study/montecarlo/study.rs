//! The study itself: the scenario, trajectories and time grid of a tracking study
//! ([`TrackStudy`], also the posterior CRLB's) and the Monte Carlo study of a list of trackers
//! on it ([`MonteCarloStudy`]: one validated configuration per trajectory, its chunks, the runs
//! of one trajectory).

use alloc::format;
use alloc::string::String;
use alloc::vec::Vec;

use crate::error::{Error, Result};
use crate::measure::Model;
use crate::scenario::Scenario;
use crate::study::FilterStudy;
use crate::track::{
    paper_initial_covariance, ConstantVelocity, FilterKind, MonteCarloConfig, TrackScenario,
};

/// The scenario, trajectories and time grid of a tracking study (`montecarlo`, `pcrlb`).
#[derive(Debug, Clone)]
pub struct TrackStudy {
    /// Name of the node layout (preset or scenario file's `name`).
    pub layout: String,
    /// The scenario (validated).
    pub scenario: Scenario,
    /// The measurement model.
    pub model: Model,
    /// Trajectories to evaluate, in order.
    pub trajectories: Vec<TrackScenario>,
    /// CV model (E7).
    pub motion: ConstantVelocity,
    /// Steps after `t₀`.
    pub steps: usize,
}

impl TrackStudy {
    /// A study of `scenario` (validated) named `layout`; errors are the model's.
    pub fn new(
        layout: String,
        scenario: Scenario,
        trajectories: Vec<TrackScenario>,
        motion: ConstantVelocity,
        steps: usize,
    ) -> Result<TrackStudy> {
        Ok(TrackStudy {
            layout,
            model: Model::new(&scenario)?,
            scenario,
            trajectories,
            motion,
            steps,
        })
    }

    /// The Monte Carlo configuration of spec §9.5 for trajectory `t`: prior mean `x̄₀` of §9.4,
    /// `P(t₀) = diag(0.1, 0.1, 0.01, 0.01)`, validated ([`MonteCarloConfig::validate`]).
    pub fn config(
        &self,
        t: TrackScenario,
        runs: usize,
        noise_runs: usize,
        seed: u64,
        oracle_noise: bool,
    ) -> Result<MonteCarloConfig> {
        let cfg = MonteCarloConfig {
            motion: self.motion,
            steps: self.steps,
            mean_state: t.mean_state(),
            initial_covariance: paper_initial_covariance(),
            trajectories: runs,
            noise_runs,
            seed,
            oracle_noise,
        };
        cfg.validate()?;
        Ok(cfg)
    }

    /// `T = …` for titles: milliseconds below 0.1 s, trailing zeros dropped.
    pub fn step_label(&self) -> String {
        let dt = self.motion.dt_s;
        let (v, unit) = if dt < 0.1 {
            (dt * 1e3, "ms")
        } else {
            (dt, "s")
        };
        let text = format!("{v:.6}");
        format!(
            "{} {unit}",
            text.trim_end_matches('0').trim_end_matches('.')
        )
    }

    /// `{layout}, scenario II` or `{layout}, scenarios I, II, III` (figure titles).
    pub fn which(&self) -> String {
        let names: Vec<&str> = self.trajectories.iter().map(|t| t.name()).collect();
        let plural = if names.len() > 1 { "s" } else { "" };
        format!("{}, scenario{plural} {}", self.layout, names.join(", "))
    }
}

/// A Monte Carlo study of one or more trackers over one or more trajectories.
///
///
/// ```
/// use scatterloc::scenario::presets;
/// use scatterloc::study::{MonteCarloStudy, RunTime, Sequential, TrackStudy};
/// use scatterloc::track::{ConstantVelocity, FilterKind, TrackScenario};
///
/// let scenario = presets::preset("sensors2019").unwrap();
/// let motion = ConstantVelocity::validated(0.1, 1.0).unwrap();
/// let track = TrackStudy::new("sensors2019".into(), scenario, vec![TrackScenario::II], motion, 20).unwrap();
/// let study = MonteCarloStudy::new(track, 32, 2, 7, false, &[FilterKind::Ekf]).unwrap();
/// let mut runs = study.filter_study(0).unwrap();
/// runs.run_range(&study.track.model, 0..study.chunk_count(), &mut Sequential::new(), &mut |_, _| {}).unwrap();
/// let time = RunTime { wall_s: 1.0, thread_s: 1.0, threads: 1 };
/// let doc = study.doc(0, &runs.results().unwrap(), time);
/// assert_eq!(doc.meta.runs, 64);
/// assert_eq!(doc.t_s.len(), 21);
/// // The configuration a part file records rebuilds the same study.
/// let config = serde_json::to_value(study.config_doc().unwrap()).unwrap();
/// let again = MonteCarloStudy::from_config(&config).unwrap();
/// assert_eq!(again.configs, study.configs);
/// ```
#[derive(Debug, Clone)]
pub struct MonteCarloStudy {
    /// Layout, trajectories, motion, steps.
    pub track: TrackStudy,
    /// Truth trajectories per trajectory.
    pub runs: usize,
    /// Noise runs per truth trajectory.
    pub noise_runs: usize,
    /// The seed.
    pub seed: u64,
    /// The EKF's `R` at the truth.
    pub oracle_noise: bool,
    /// The trackers, in order (`[ekf]` for the EKF alone).
    pub filters: Vec<FilterKind>,
    /// One configuration per trajectory, in order.
    pub configs: Vec<MonteCarloConfig>,
}

impl MonteCarloStudy {
    /// The study of `filters` on `track` with `runs × noise_runs` runs per trajectory and
    /// `seed`; every configuration and filter validated (errors name `runs`, `noise_runs`,
    /// `steps`, the filter settings, …).
    pub fn new(
        track: TrackStudy,
        runs: usize,
        noise_runs: usize,
        seed: u64,
        oracle_noise: bool,
        filters: &[FilterKind],
    ) -> Result<MonteCarloStudy> {
        let configs = track
            .trajectories
            .iter()
            .map(|t| track.config(*t, runs, noise_runs, seed, oracle_noise))
            .collect::<Result<Vec<_>>>()?;
        let study = MonteCarloStudy {
            track,
            runs,
            noise_runs,
            seed,
            oracle_noise,
            filters: filters.to_vec(),
            configs,
        };
        // The filter list's own checks (empty, repeated, settings).
        if let Some(cfg) = study.configs.first() {
            FilterStudy::new(*cfg, filters)?;
        }
        Ok(study)
    }

    /// Whether the study runs the EKF alone (its documents then have no `filters` key).
    pub fn ekf_only(&self) -> bool {
        self.filters == [FilterKind::Ekf]
    }

    /// Chunks of every trajectory's study (the unit of shards).
    pub fn chunk_count(&self) -> usize {
        self.configs
            .first()
            .map_or(0, MonteCarloConfig::chunk_count)
    }

    /// The runs of trajectory `k` (index into the trajectories): every filter over every chunk.
    pub fn filter_study(&self, k: usize) -> Result<FilterStudy> {
        let cfg = self.configs.get(k).ok_or(Error::IndexOutOfRange {
            field: "trajectories",
            index: k,
            len: self.configs.len(),
        })?;
        FilterStudy::new(*cfg, &self.filters)
    }
}
