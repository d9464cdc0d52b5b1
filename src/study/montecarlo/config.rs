//! The configuration a Monte Carlo study's part files record ([`McConfig`], with its trackers'
//! settings [`FiltersConfig`]) and the study rebuilt from it, exactly as this build writes it
//! ([`MonteCarloStudy::config_doc`], [`MonteCarloStudy::from_config`]).

use alloc::format;
use alloc::string::{String, ToString};
use alloc::vec;
use alloc::vec::Vec;

use serde::{Deserialize, Serialize};
use serde_json::Value;

use super::{MonteCarloStudy, TrackStudy};
use crate::error::{Error, Result};
use crate::scenario::Scenario;
use crate::study::part::differs;
use crate::track::{ConstantVelocity, FilterKind, PfConfig, TrackScenario, UkfParams, MAX_STEPS};

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

impl MonteCarloStudy {
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
}
