//! The result documents of the tracking studies, one per trajectory: [`CurveDoc`] with the
//! Monte Carlo study's scalars [`McMeta`] ([`MonteCarloStudy::doc`]: the EKF's curves and
//! counts at the top level when it runs, else the first filter's, and, for any list other than
//! `[ekf]`, every filter's curves under `filters`) or the posterior CRLB's [`PcrlbMeta`]
//! ([`TrackStudy::pcrlb_doc`]); the figures' legend labels and failed-run note.

use alloc::format;
use alloc::string::{String, ToString};
use alloc::vec::Vec;

use serde::Serialize;

use super::{MonteCarloStudy, TrackStudy};
use crate::study::FilterResults;
use crate::track::{FilterKind, MonteCarloConfig, MonteCarloResult, TrackScenario};

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

impl MonteCarloStudy {
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
}
