//! The Monte Carlo study of [S] §5.2 (spec §8, §9.5, Fig. 3 of §10) as one use case: a layout,
//! the trajectories of §9.4, the step and duration, the run counts and seed, and the list of
//! trackers ([`MonteCarloStudy`]); its persistent configuration, the `config` of its part
//! files ([`McConfig`]); and its result documents, one per trajectory ([`CurveDoc`] with
//! [`McMeta`]), the EKF's curves and counts at the top level when it runs (else the first
//! filter's) and, for any list other than `[ekf]`, every filter's curves under `filters`.
//!
//! ```
//! use scatterloc::scenario::presets;
//! use scatterloc::study::{MonteCarloStudy, RunTime, Sequential, TrackStudy};
//! use scatterloc::track::{ConstantVelocity, FilterKind, TrackScenario};
//!
//! let scenario = presets::preset("sensors2019").unwrap();
//! let motion = ConstantVelocity::validated(0.1, 1.0).unwrap();
//! let track = TrackStudy::new("sensors2019".into(), scenario, vec![TrackScenario::II], motion, 20).unwrap();
//! let study = MonteCarloStudy::new(track, 32, 2, 7, false, &[FilterKind::Ekf]).unwrap();
//! let mut runs = study.filter_study(0).unwrap();
//! runs.run_range(&study.track.model, 0..study.chunk_count(), &mut Sequential::new(), &mut |_, _| {}).unwrap();
//! let time = RunTime { wall_s: 1.0, thread_s: 1.0, threads: 1 };
//! let doc = study.doc(0, &runs.results().unwrap(), time);
//! assert_eq!(doc.meta.runs, 64);
//! assert_eq!(doc.t_s.len(), 21);
//! // The configuration a part file records rebuilds the same study.
//! let config = serde_json::to_value(study.config_doc().unwrap()).unwrap();
//! let again = MonteCarloStudy::from_config(&config).unwrap();
//! assert_eq!(again.configs, study.configs);
//! ```

use alloc::format;
use alloc::string::{String, ToString};
use alloc::vec;
use alloc::vec::Vec;

use serde::{Deserialize, Serialize};
use serde_json::Value;

use crate::error::{Error, Result};
use crate::measure::Model;
use crate::scenario::Scenario;
use crate::study::part::{differs, load_sums, merged_timing, PartSet};
use crate::study::sums::check_sums;
use crate::study::{inconsistent, FilterResults, FilterStudy};
use crate::track::{
    paper_initial_covariance, ConstantVelocity, FilterKind, MonteCarloConfig, MonteCarloResult,
    PfConfig, StudySums, TrackScenario, UkfParams, MAX_STEPS,
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

/// The scalars of one posterior-CRLB curve (`scatterloc pcrlb`, `scatterloc.pcrlb` in Python).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PcrlbMeta {
    /// `I`, `II` or `III`.
    pub trajectory: &'static str,
    /// Step `T`, s.
    pub dt_s: f64,
    /// At the noise-free path (spec check 9) rather than `E[F̃]` over truth trajectories.
    pub nominal: bool,
    /// Steps after `t₀`.
    pub steps: usize,
    /// `q̃`, m²/s³.
    pub process_noise: f64,
    /// The layout's name.
    pub layout: String,
    /// Truth trajectories of `E[F̃]` (Monte Carlo only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub trajectories: Option<usize>,
    /// The seed (Monte Carlo only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub seed: Option<u64>,
    /// Wall time, s.
    pub wall_time_s: f64,
}

impl TrackStudy {
    /// The document of a posterior-CRLB curve `rmse` (spec §8, E9) of trajectory `t` computed
    /// with `cfg` (`nominal`: at the noise-free path; else `E[F̃]` over `cfg.trajectories`
    /// truths of `cfg.seed`) in `wall_s` seconds.
    pub fn pcrlb_doc(
        &self,
        t: TrackScenario,
        cfg: &MonteCarloConfig,
        nominal: bool,
        rmse: Vec<Option<f64>>,
        wall_s: f64,
    ) -> CurveDoc<PcrlbMeta> {
        CurveDoc {
            t_s: (0..=cfg.steps)
                .map(|n| n as f64 * cfg.motion.dt_s)
                .collect(),
            rmse_ekf_m: None,
            rmse_pcrlb_m: rmse,
            nees: None,
            caption_note: None,
            figure_curves: Vec::new(),
            figure_note: None,
            meta: PcrlbMeta {
                trajectory: t.name(),
                dt_s: cfg.motion.dt_s,
                nominal,
                steps: cfg.steps,
                process_noise: cfg.motion.intensity,
                layout: self.layout.clone(),
                trajectories: (!nominal).then_some(cfg.trajectories),
                seed: (!nominal).then_some(cfg.seed),
                wall_time_s: wall_s,
            },
        }
    }
}

/// Everything a Monte Carlo study's result depends on: the `config` of its part files.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct McConfig {
    /// The layout's name (preset or scenario file's `name`).
    pub layout: String,
    /// The scenario document (schema v1) as read and validated.
    pub scenario: Value,
    /// Trajectories of spec §9.4, in order.
    pub trajectories: Vec<String>,
    /// Step `T`, s.
    pub dt_s: f64,
    /// Steps after `t₀`.
    pub steps: usize,
    /// `q̃`, m²/s³.
    pub process_noise: f64,
    /// Truth trajectories per trajectory (`--runs`).
    pub runs: usize,
    /// Noise runs per truth trajectory.
    pub noise_runs: usize,
    /// The seed.
    pub seed: u64,
    /// The EKF's `R` at the truth.
    pub oracle_noise: bool,
    /// Filters other than the EKF alone: the filters and their settings (absent: the EKF).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub filters: Option<FiltersConfig>,
}

/// The trackers of a study with several (`--filters`), as its part files record them.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct FiltersConfig {
    /// `ekf`, `ukf`, `pf`, in the order run.
    pub names: Vec<String>,
    /// UKF `alpha`, `beta`, `kappa` (when `ukf` runs).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ukf: Option<[f64; 3]>,
    /// Particles (when `pf` runs).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub particles: Option<usize>,
    /// Roughening constant (when `pf` runs with it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub roughening: Option<f64>,
    /// `true` when `pf` runs as the spec's plain bootstrap SIR (`--pf-bootstrap`); absent (not
    /// written) for the regularised particle filter, the default.
    #[serde(default, skip_serializing_if = "core::ops::Not::not")]
    pub bootstrap: bool,
}

impl FiltersConfig {
    /// The record of `kinds`; `None` for the EKF alone.
    pub fn of(kinds: &[FilterKind]) -> Option<FiltersConfig> {
        if kinds == [FilterKind::Ekf] {
            return None;
        }
        let mut c = FiltersConfig {
            names: kinds.iter().map(|k| k.name().to_string()).collect(),
            ukf: None,
            particles: None,
            roughening: None,
            bootstrap: false,
        };
        for k in kinds {
            match k {
                FilterKind::Ekf => {}
                FilterKind::Ukf(p) => c.ukf = Some([p.alpha, p.beta, p.kappa]),
                FilterKind::Pf(p) => {
                    c.particles = Some(p.particles);
                    c.roughening = p.roughening;
                    c.bootstrap = !p.regularized;
                }
            }
        }
        Some(c)
    }

    /// The filters again, validated (errors name `names[i]` or the setting).
    pub fn kinds(&self) -> Result<Vec<FilterKind>> {
        let d = UkfParams::default();
        let ukf = match self.ukf {
            Some([alpha, beta, kappa]) => UkfParams { alpha, beta, kappa },
            None => d,
        };
        let pf = PfConfig {
            particles: self.particles.unwrap_or(PfConfig::default().particles),
            roughening: self.roughening,
            regularized: !self.bootstrap,
        };
        self.names
            .iter()
            .enumerate()
            .map(|(i, n)| FilterKind::named(&format!("names[{i}]"), n, ukf, pf))
            .collect()
    }
}

/// The run time of one trajectory's study: wall time, thread time (`Σ wall · threads`) and
/// threads.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RunTime {
    /// Wall time, s.
    pub wall_s: f64,
    /// Thread time, s.
    pub thread_s: f64,
    /// Worker threads.
    pub threads: usize,
}

/// The curves of one trajectory and its scalars `M` (flattened after the curves).
#[derive(Debug, Clone, Serialize)]
pub struct CurveDoc<M: Serialize> {
    /// `t_n`, s.
    pub t_s: Vec<f64>,
    /// The lead filter's RMSE `ε(t_n)`, m (studies with a filter only; the key keeps the name
    /// of the EKF's curve).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rmse_ekf_m: Option<Vec<f64>>,
    /// `ε_PCRLB(t_n)`, m (`null` where singular).
    pub rmse_pcrlb_m: Vec<Option<f64>>,
    /// Average NEES (studies with a filter only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub nees: Option<Vec<f64>>,
    /// Everything else.
    #[serde(flatten)]
    pub meta: M,
    /// Added to the panel caption of the figure (the failed runs, which `ε` leaves out); not
    /// part of the JSON.
    #[serde(skip)]
    pub caption_note: Option<String>,
    /// The figure's labelled RMSE curves, one per filter (legend labels: [`curve_label`]); not
    /// part of the JSON.
    #[serde(skip)]
    pub figure_curves: Vec<(String, Vec<f64>)>,
    /// The figure's last legend row (what a failed run is, [`FAILED_NOTE`], when the legend
    /// gives the failed counts); not part of the JSON.
    #[serde(skip)]
    pub figure_note: Option<&'static str>,
}

/// The legend label of a filter's RMSE curve in the tracking figures (the one home of these
/// labels): `EKF RMSE  ε_EKF` for the EKF alone (\[S\] Fig. 3), else `EKF RMSE`, `UKF RMSE`,
/// `PF RMSE`.
pub fn curve_label(filter: &str, alone: bool) -> String {
    match (filter, alone) {
        ("ekf", true) => "EKF RMSE  ε_EKF".to_string(),
        _ => format!("{} RMSE", filter.to_uppercase()),
    }
}

/// What a failed run is, as the tracking figures' legends say it (the one home of this text):
/// the run's filter broke down numerically — its covariance stopped being positive definite
/// (a particle filter whose weights collapsed onto one particle, so it has no NEES), or an
/// update failed ([`crate::track::run_filter_chunk`]); such runs are left out of the curves.
pub const FAILED_NOTE: &str =
    "failed = filter broke down (covariance not positive definite), left out of its RMSE";

/// The legend label of a filter's RMSE curve with its failed runs: `PF RMSE (3/192 failed)`.
pub fn failed_label(filter: &str, failed: usize, runs: usize) -> String {
    format!("{} ({failed}/{runs} failed)", curve_label(filter, false))
}

/// Scalars of one Monte Carlo study, after the curves in the JSON file and in the summary.
#[derive(Debug, Clone, Serialize)]
pub struct McMeta {
    /// Runs counted (`trajectories × noise_runs − failed_runs`) of the lead filter.
    pub runs: usize,
    /// The seed.
    pub seed: u64,
    /// `I`, `II` or `III`.
    pub trajectory: &'static str,
    /// Step `T`, s.
    pub dt_s: f64,
    /// Noise runs per trajectory.
    pub noise_runs: usize,
    /// Truth trajectories.
    pub trajectories: usize,
    /// The lead filter's failed runs.
    pub failed_runs: usize,
    /// Wall time, s.
    pub wall_time_s: f64,
    /// `thread time / (runs · steps)`: thread time per filter step, truth simulation included
    /// (with several filters the wall time is all filters').
    pub ns_per_ekf_step: f64,
    /// `wall / (runs · steps)`.
    pub wall_ns_per_ekf_step: f64,
    /// Worker threads.
    pub threads: usize,
    /// Steps after `t₀`.
    pub steps: usize,
    /// `q̃`, m²/s³.
    pub process_noise: f64,
    /// The EKF's `R` at the truth.
    pub oracle_noise: bool,
    /// The layout's name.
    pub layout: String,
    /// Filters other than the EKF alone: each filter's curves, in the order asked.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub filters: Option<FilterCurves>,
}

/// The curves of one filter of a study of several.
#[derive(Debug, Clone, Serialize)]
pub struct FilterDoc {
    /// The filter's RMSE, m (absent when every run failed).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub rmse_m: Vec<f64>,
    /// Its average NEES (absent when every run failed).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub nees: Vec<f64>,
    /// Its runs counted.
    pub runs: usize,
    /// Its runs that failed numerically (left out of `rmse_m`).
    pub failed_runs: usize,
    /// Only when every run failed (issue 24): the error naming the setting to change and the
    /// first failure ([`crate::Error::AllRunsFailed`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
}

/// `{"ekf": {..}, "ukf": {..}, ..}` in the order of the filter list.
#[derive(Debug, Clone)]
pub struct FilterCurves(pub Vec<(&'static str, FilterDoc)>);

impl Serialize for FilterCurves {
    fn serialize<S: serde::Serializer>(&self, s: S) -> core::result::Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        let mut map = s.serialize_map(Some(self.0.len()))?;
        for (name, doc) in &self.0 {
            map.serialize_entry(name, doc)?;
        }
        map.end()
    }
}

/// A Monte Carlo study of one or more trackers over one or more trajectories.
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

    /// The configuration its part files record.
    pub fn config_doc(&self) -> Result<McConfig> {
        let t = &self.track;
        Ok(McConfig {
            layout: t.layout.clone(),
            scenario: serde_json::to_value(&t.scenario).map_err(|e| Error::Parse {
                message: format!("encoding the scenario: {e}"),
            })?,
            trajectories: t
                .trajectories
                .iter()
                .map(|t| t.name().to_string())
                .collect(),
            dt_s: t.motion.dt_s,
            steps: t.steps,
            process_noise: t.motion.intensity,
            runs: self.runs,
            noise_runs: self.noise_runs,
            seed: self.seed,
            oracle_noise: self.oracle_noise,
            filters: FiltersConfig::of(&self.filters),
        })
    }

    /// The study a part file's `config` records, rebuilt as the unsharded run built it. The
    /// configuration must be exactly the one this build writes for that study. Errors
    /// ([`Error::Parse`]) say what is wrong, with the field.
    pub fn from_config(config: &Value) -> Result<MonteCarloStudy> {
        let bad = |message: String| Error::Parse { message };
        let c = McConfig::deserialize(config).map_err(|e| bad(format!("config: {e}")))?;
        let scenario = Scenario::from_json(&c.scenario.to_string())
            .map_err(|e| bad(format!("config.scenario: {e}")))?;
        let trajectories = c
            .trajectories
            .iter()
            .map(|t| TrackScenario::parse(t).map_err(|e| bad(format!("config.trajectories: {e}"))))
            .collect::<Result<Vec<_>>>()?;
        let motion = ConstantVelocity::validated(c.dt_s, c.process_noise)
            .map_err(|e| bad(format!("config: {e}")))?;
        if !(1..=MAX_STEPS).contains(&c.steps) || trajectories.is_empty() {
            return Err(bad("config: no steps or no trajectories".into()));
        }
        let track = TrackStudy::new(c.layout.clone(), scenario, trajectories, motion, c.steps)
            .map_err(|e| bad(format!("config.scenario: {e}")))?;
        let filters = match &c.filters {
            Some(f) => f.kinds().map_err(|e| bad(format!("config.filters: {e}")))?,
            None => vec![FilterKind::Ekf],
        };
        let study = MonteCarloStudy::new(
            track,
            c.runs,
            c.noise_runs,
            c.seed,
            c.oracle_noise,
            &filters,
        )
        .map_err(|e| bad(format!("config: {e}")))?;
        let again = serde_json::to_value(study.config_doc()?).map_err(|e| Error::Parse {
            message: format!("encoding JSON: {e}"),
        })?;
        if let Some(d) = differs(&again, config) {
            return Err(bad(format!(
                "config is not as this scatterloc writes it ({d})"
            )));
        }
        Ok(study)
    }

    /// The document (and figure panel) of trajectory `k`'s results. The curves and counts at
    /// the top level are the lead filter's ([`FilterResults::top`]); a study of any list other
    /// than `[ekf]` adds every filter's curves under `filters` and drops the top-level curves
    /// when the EKF does not run.
    pub fn doc(&self, k: usize, results: &FilterResults, time: RunTime) -> CurveDoc<McMeta> {
        let cfg = &self.configs[k];
        let t = self.track.trajectories[k];
        let top = results.top();
        let steps_run = cfg.runs() as f64 * cfg.steps as f64;
        let name = |i: usize| self.filters[i].name();
        let note = |r: &MonteCarloResult| {
            format!("{} of {} failed", r.failed_runs, r.runs + r.failed_runs)
        };
        let mut doc = CurveDoc {
            t_s: top.t_s.clone(),
            rmse_ekf_m: Some(top.rmse_m.clone()),
            rmse_pcrlb_m: top.rmse_pcrlb_m.clone(),
            nees: Some(top.nees.clone()),
            caption_note: Some(format!(
                "{} of {} runs failed",
                top.failed_runs,
                top.runs + top.failed_runs
            )),
            figure_curves: results
                .curves
                .iter()
                .map(|(i, r)| {
                    let label = if self.ekf_only() {
                        curve_label(name(*i), true)
                    } else {
                        failed_label(name(*i), r.failed_runs, r.runs + r.failed_runs)
                    };
                    (label, r.rmse_m.clone())
                })
                .collect(),
            figure_note: None,
            meta: McMeta {
                runs: top.runs,
                seed: cfg.seed,
                trajectory: t.name(),
                dt_s: cfg.motion.dt_s,
                noise_runs: cfg.noise_runs,
                trajectories: cfg.trajectories,
                failed_runs: top.failed_runs,
                wall_time_s: time.wall_s,
                ns_per_ekf_step: 1e9 * time.thread_s / steps_run,
                wall_ns_per_ekf_step: 1e9 * time.wall_s / steps_run,
                threads: time.threads,
                steps: cfg.steps,
                process_noise: cfg.motion.intensity,
                oracle_noise: cfg.oracle_noise,
                layout: self.track.layout.clone(),
                filters: None,
            },
        };
        if self.ekf_only() {
            return doc;
        }
        doc.figure_note = Some(FAILED_NOTE);
        let ekf_counted = results
            .curves
            .iter()
            .any(|(i, _)| self.filters[*i] == FilterKind::Ekf);
        if !ekf_counted {
            doc.rmse_ekf_m = None;
            doc.nees = None;
        }
        // Every filter in list order: its curves, or its failure (issue 24).
        let mut entries: Vec<(usize, String, FilterDoc)> = results
            .curves
            .iter()
            .map(|(i, r)| {
                let doc = FilterDoc {
                    rmse_m: r.rmse_m.clone(),
                    nees: r.nees.clone(),
                    runs: r.runs,
                    failed_runs: r.failed_runs,
                    error: None,
                };
                (*i, note(r), doc)
            })
            .collect();
        for (i, e) in &results.failed {
            let runs = match e {
                crate::Error::AllRunsFailed { runs, .. } => *runs,
                _ => 0,
            };
            let doc = FilterDoc {
                rmse_m: Vec::new(),
                nees: Vec::new(),
                runs: 0,
                failed_runs: runs,
                error: Some(e.to_string()),
            };
            (entries).push((*i, format!("all {runs} runs failed"), doc));
        }
        entries.sort_by_key(|(i, _, _)| *i);
        let notes: Vec<String> = entries
            .iter()
            .map(|(i, n, _)| format!("{}: {n}", name(*i)))
            .collect();
        doc.caption_note = Some(notes.join(", "));
        doc.meta.filters = Some(FilterCurves(
            entries.into_iter().map(|(i, _, d)| (name(i), d)).collect(),
        ));
        doc
    }

    /// The sums a shard's part file records: per trajectory, one entry per filter in order.
    pub fn part_sums(runs: &[FilterStudy]) -> Vec<StudySums> {
        runs.iter().flat_map(FilterStudy::sums).collect()
    }

    /// The merge of a checked set of part files ([`PartSet::read`]): the study of its
    /// configuration ([`MonteCarloStudy::from_config`]), every trajectory's runs with the sums
    /// of every shard added exactly, and each trajectory's run time (the wall times added, the
    /// most threads of any part, the thread time `Σ wall · threads`). Each part's sums are
    /// read again through `load`, one part at a time, and checked against their digest and the
    /// study ([`crate::study::Part::read_sums`], `check_sums`; the invariants are listed in
    /// [`crate::study::PartSet`]'s module). A part whose sums or timing do not fit the study
    /// is [`Error::InconsistentPart`], naming the part and the field.
    pub fn merge(
        set: &PartSet,
        load: &mut dyn FnMut(&str) -> Result<String>,
    ) -> Result<(MonteCarloStudy, Vec<FilterStudy>, Vec<RunTime>)> {
        let parts = &set.parts;
        let first = parts.first().ok_or(Error::PartSet {
            what: "merge: no part files given".into(),
        })?;
        let study = MonteCarloStudy::from_config(&set.config).map_err(|e| match e {
            Error::Parse { message } => inconsistent(&first.path, message),
            e => inconsistent(&first.path, e),
        })?;
        let total = study.chunk_count();
        if first.shard.total != total {
            return Err(inconsistent(
                &first.path,
                format!(
                    "shard.total {} is not the study's {total} chunks",
                    first.shard.total
                ),
            ));
        }
        // Timing first (no sums read for a part whose header does not fit).
        let (timing, thread_s) = merged_timing(parts, study.configs.len())?;
        let per = study.filters.len();
        let entries = study.configs.len() * per;
        let steps = study.track.steps;
        // The longest array of a part's sums: the per-step lists, the entries, the partials of
        // an exact sum (at most ~40).
        let max_len = (steps + 1).max(entries).max(64);
        let mut runs = (0..study.configs.len())
            .map(|k| study.filter_study(k))
            .collect::<Result<Vec<_>>>()?;
        for part in parts {
            let sums: Vec<StudySums> = load_sums(part, max_len, load)?;
            let chunks = part.shard.range[0]..part.shard.range[1];
            if sums.len() != entries {
                return Err(inconsistent(
                    &part.path,
                    format!(
                        "sums: {} entries, not {} trajectories × {per} filters",
                        sums.len(),
                        study.configs.len()
                    ),
                ));
            }
            for (k, (cfg, run)) in study.configs.iter().zip(runs.iter_mut()).enumerate() {
                let of_trajectory = &sums[k * per..(k + 1) * per];
                check_sums(cfg, &chunks, k * per, of_trajectory)
                    .map_err(|what| inconsistent(&part.path, what))?;
                for (f, s) in of_trajectory.iter().enumerate() {
                    run.add_sums(f, s, chunks.len());
                }
            }
        }
        let times = timing
            .wall_time_s
            .iter()
            .zip(&thread_s)
            .map(|(&wall_s, &thread_s)| RunTime {
                wall_s,
                thread_s,
                threads: timing.threads,
            })
            .collect();
        Ok((study, runs, times))
    }
}
