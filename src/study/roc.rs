//! The ROC study of the multi-target method (§8 experiments V-A, V-B, V-C of
//! `multi-target.md`) as one use case: its configuration from the few settings a run is
//! defined by ([`RocStudy::config`]), the record of every setting ([`RocConfig`], the `config`
//! of its JSON result and of its part files), the run over a range of realisations through a
//! [`Driver`], and the merge of a checked set of part files.
//!
//! ```
//! use scatterloc::mtl::experiment::Experiment;
//! use scatterloc::study::{RocStudy, Sequential};
//!
//! let cfg = RocStudy::config(Experiment::Vb, Some(2), 5, false, false, None).unwrap();
//! let tally = RocStudy::run_range(&cfg, 0..2, &mut Sequential::new(), &mut |_, _| {}).unwrap();
//! assert_eq!(tally.realisations(), 2);
//! let config = serde_json::to_value(scatterloc::study::RocConfig::of(&cfg)).unwrap();
//! assert_eq!(RocStudy::from_config(&config).unwrap().seed, 5);
//! ```

use alloc::format;
use alloc::string::String;
use alloc::vec::Vec;
use core::ops::Range;

use serde::{Deserialize, Serialize};
use serde_json::Value;

use crate::error::{Error, Result};
use crate::mtl::experiment::{
    evaluate, EmpiricalTraining, Experiment, ExperimentConfig, ExperimentResult, Tally,
    MAX_REALISATIONS,
};
use crate::mtl::sim::{LosModel, NodeLayout};
use crate::study::part::{differs, inconsistent, load_sums, merged_timing, PartSet};
use crate::study::Driver;

/// Every setting of a ROC run (the \[P\] parameters of §7 and §8 included): the `config` of its
/// JSON result and of its part files. Serialize it to read it.
#[derive(Debug, Clone, Serialize)]
pub struct RocConfig {
    experiment: &'static str,
    swept: &'static str,
    sweep: Vec<f64>,
    realisations: usize,
    seed: u64,
    /// `N_u` values (V-A).
    #[serde(skip_serializing_if = "Option::is_none")]
    n_u: Option<Vec<usize>>,
    /// Fixed `T_e` (V-B, V-C).
    #[serde(skip_serializing_if = "Option::is_none")]
    t_e: Option<f64>,
    icb_p_u: f64,
    ppp_exact: bool,
    empirical: Option<EmpiricalDoc>,
    settings: SettingsDoc,
    algorithm: AlgorithmDoc,
}

#[derive(Debug, Clone, Serialize)]
struct EmpiricalDoc {
    cells: usize,
    scenes: usize,
}

#[derive(Debug, Clone, Serialize)]
struct SettingsDoc {
    region_m: [[f64; 2]; 2],
    /// `uniform` (`n_tx`, `n_rx`) or `fixed` (`tx`, `rx`).
    nodes: NodesDoc,
    /// `discs` or `independent`.
    los: &'static str,
    #[serde(skip_serializing_if = "Option::is_none")]
    p_los: Option<f64>,
    lambda: f64,
    diameter_m: f64,
    range_sigma_m: f64,
    resolution_m: f64,
    detection_radius_m: f64,
    p_d: f64,
    targets: usize,
    clutter_mean: f64,
    r_max_m: f64,
    geometric_ips: [bool; 2],
}

#[derive(Debug, Clone, Serialize)]
#[serde(tag = "layout", rename_all = "lowercase")]
enum NodesDoc {
    Uniform {
        n_tx: usize,
        n_rx: usize,
    },
    Fixed {
        tx: Vec<[f64; 2]>,
        rx: Vec<[f64; 2]>,
    },
}

#[derive(Debug, Clone, Serialize)]
struct AlgorithmDoc {
    /// `null` = ∞.
    b_max: Option<usize>,
    n_min: usize,
    order: Option<Vec<usize>>,
    region_filter: bool,
    merge_final: bool,
    merge_shared_pairs: usize,
    merge_radius_m: Option<f64>,
    refinement_max_iterations: usize,
    refinement_step_tol_m: f64,
    late_seeds: bool,
    late_seed_catch_up: bool,
    max_candidates: usize,
}

impl RocConfig {
    /// The record of `cfg`.
    pub fn of(cfg: &ExperimentConfig) -> RocConfig {
        let s = &cfg.settings;
        let m = &cfg.mtl;
        let va = cfg.experiment == Experiment::Va;
        let xy = |v: &crate::math::Vec2| [v.x, v.y];
        RocConfig {
            experiment: cfg.experiment.name(),
            swept: cfg.experiment.swept(),
            sweep: cfg.sweep.clone(),
            realisations: cfg.realisations,
            seed: cfg.seed,
            n_u: va.then(|| cfg.n_u.clone()),
            t_e: (!va).then_some(cfg.t_e),
            icb_p_u: cfg.icb_p_u,
            ppp_exact: cfg.ppp_exact,
            empirical: cfg.empirical.map(|e| EmpiricalDoc {
                cells: e.cells,
                scenes: e.scenes,
            }),
            settings: SettingsDoc {
                region_m: [xy(&s.region.min), xy(&s.region.max)],
                nodes: match &s.nodes {
                    NodeLayout::Uniform { n_tx, n_rx } => NodesDoc::Uniform {
                        n_tx: *n_tx,
                        n_rx: *n_rx,
                    },
                    NodeLayout::Fixed { tx, rx } => NodesDoc::Fixed {
                        tx: tx.iter().map(xy).collect(),
                        rx: rx.iter().map(xy).collect(),
                    },
                },
                los: match s.los {
                    LosModel::Discs => "discs",
                    LosModel::Independent { .. } => "independent",
                },
                p_los: match s.los {
                    LosModel::Independent { p_los } => Some(p_los),
                    LosModel::Discs => None,
                },
                lambda: s.lambda,
                diameter_m: s.diameter,
                range_sigma_m: s.range_sigma,
                resolution_m: s.resolution,
                detection_radius_m: s.detection_radius,
                p_d: s.p_d,
                targets: s.targets,
                clutter_mean: s.clutter_mean,
                r_max_m: s.r_max,
                geometric_ips: [s.geometric_ips.kind1, s.geometric_ips.kind2],
            },
            algorithm: AlgorithmDoc {
                b_max: (m.b_max != usize::MAX).then_some(m.b_max),
                n_min: m.n_min,
                order: m.order.clone(),
                region_filter: m.region.is_some(),
                merge_final: m.merge_final,
                merge_shared_pairs: m.merge_shared_pairs,
                merge_radius_m: m.merge_radius_m.is_finite().then_some(m.merge_radius_m),
                refinement_max_iterations: m.refinement.max_iterations,
                refinement_step_tol_m: m.refinement.step_tol_m,
                late_seeds: m.late_seeds,
                late_seed_catch_up: m.late_seed_catch_up,
                max_candidates: m.max_candidates,
            },
        }
    }
}

/// What a part's `config` says about the settings (the rest is checked against
/// [`RocConfig::of`]).
#[derive(Deserialize)]
struct RocKey {
    experiment: String,
    realisations: usize,
    seed: u64,
    ppp_exact: bool,
    empirical: Option<serde::de::IgnoredAny>,
    algorithm: AlgorithmKey,
}

#[derive(Deserialize)]
struct AlgorithmKey {
    max_candidates: usize,
}

/// The ROC study's entry points (a namespace: the study is its [`ExperimentConfig`]).
pub struct RocStudy;

impl RocStudy {
    /// The validated configuration of `experiment` with `realisations` (default: the
    /// experiment's), `seed`, the exact PPP (`exact`), empirical node patterns (`empirical`)
    /// and `max_candidates` (default: the method's). Errors name the field (`realisations`,
    /// …); V-A takes neither `exact` nor `empirical` ([`Error::OutOfRange`]).
    pub fn config(
        experiment: Experiment,
        realisations: Option<usize>,
        seed: u64,
        exact: bool,
        empirical: bool,
        max_candidates: Option<usize>,
    ) -> Result<ExperimentConfig> {
        let mut cfg = ExperimentConfig::new(experiment);
        let n = realisations.unwrap_or(cfg.realisations);
        if !(1..=MAX_REALISATIONS).contains(&n) {
            return Err(Error::SizeLimit {
                field: "realisations",
                value: n,
                min: 1,
                max: MAX_REALISATIONS,
            });
        }
        cfg.realisations = n;
        cfg.seed = seed;
        if experiment == Experiment::Va && (exact || empirical) {
            return Err(Error::OutOfRange {
                field: (if empirical { "empirical" } else { "exact" }).into(),
                value: 1.0,
                allowed: "not used with experiment va (i.c.b only)",
            });
        }
        cfg.ppp_exact = exact;
        if let Some(n) = max_candidates {
            cfg.mtl.max_candidates = n;
        }
        if empirical {
            cfg.empirical = Some(EmpiricalTraining::default());
        }
        cfg.validate()?;
        Ok(cfg)
    }

    /// The configuration a part file's `config` records, rebuilt as the unsharded run built
    /// it; it must be exactly the one this build writes. Errors ([`Error::Parse`]) say what is
    /// wrong.
    pub fn from_config(config: &Value) -> Result<ExperimentConfig> {
        let bad = |message: String| Error::Parse { message };
        let key = RocKey::deserialize(config).map_err(|e| bad(format!("config: {e}")))?;
        let experiment = Experiment::parse(&key.experiment)
            .ok_or_else(|| bad(format!("config.experiment: {:?}", key.experiment)))?;
        let cfg = RocStudy::config(
            experiment,
            Some(key.realisations),
            key.seed,
            key.ppp_exact,
            key.empirical.is_some(),
            Some(key.algorithm.max_candidates),
        )
        .map_err(|e| bad(format!("config: {e}")))?;
        let again = serde_json::to_value(RocConfig::of(&cfg)).map_err(|e| Error::Parse {
            message: format!("encoding JSON: {e}"),
        })?;
        if let Some(d) = differs(&again, config) {
            return Err(bad(format!(
                "config is not as this scatterloc writes it ({d})"
            )));
        }
        Ok(cfg)
    }

    /// The tally of the realisations `realisations` of `cfg` (the whole run, or a shard's
    /// [`crate::math::Shard::range`]) through `driver`; `progress(done, total)` counts these
    /// realisations. Tallies of disjoint ranges merged with [`Tally::merge`] equal the tally
    /// of their union exactly. [`Error::IndexOutOfRange`] (`realisations`) past the last.
    pub fn run_range(
        cfg: &ExperimentConfig,
        realisations: Range<usize>,
        driver: &mut impl Driver,
        progress: &mut dyn FnMut(usize, usize),
    ) -> Result<Tally> {
        cfg.validate()?;
        if realisations.end > cfg.realisations || realisations.start > realisations.end {
            return Err(Error::IndexOutOfRange {
                field: "realisations",
                index: realisations.end.max(realisations.start),
                len: cfg.realisations,
            });
        }
        let (first, total) = (realisations.start, realisations.len());
        let mut tally = Tally::new(cfg.curves().len(), cfg.sweep.len());
        driver.run(
            total,
            8,
            &|i, _| evaluate(cfg, (first + i) as u64),
            &mut |part| tally.add(&part),
            &mut |done| progress(done, total),
        )?;
        Ok(tally)
    }

    /// The merge of a checked set of part files ([`PartSet::read`]): the configuration, the
    /// result of every shard's tally added exactly, the wall time added and the most threads of
    /// any part. Each part's tally is read again through `load`, one part at a time, and
    /// checked against its digest ([`crate::study::Part::read_sums`]) and the experiment
    /// ([`Tally::check`]). A part that does not fit is [`Error::InconsistentPart`], naming the
    /// part and the field.
    pub fn merge(
        set: &PartSet,
        load: &mut dyn FnMut(&str) -> Result<String>,
    ) -> Result<(ExperimentConfig, ExperimentResult, f64, usize)> {
        let parts = &set.parts;
        let first = parts.first().ok_or(Error::PartSet {
            what: "merge: no part files given".into(),
        })?;
        let cfg = RocStudy::from_config(&set.config).map_err(|e| match e {
            Error::Parse { message } => inconsistent(&first.path, message),
            e => inconsistent(&first.path, e),
        })?;
        if first.shard.total != cfg.realisations {
            return Err(inconsistent(
                &first.path,
                format!(
                    "shard.total {} is not the study's {} realisations",
                    first.shard.total, cfg.realisations
                ),
            ));
        }
        let (timing, _) = merged_timing(parts, 1)?;
        let (curves, points) = (cfg.curves().len(), cfg.sweep.len());
        // The longest array of a tally: curves, points, the partials of an exact sum (~40).
        let max_len = curves.max(points).max(64);
        let mut merged = Tally::new(curves, points);
        for part in parts {
            let tally: Tally = load_sums(part, max_len, load)?;
            let len = part.shard.range[1] - part.shard.range[0];
            tally
                .check(len, curves, points)
                .map_err(|what| inconsistent(&part.path, format!("sums.{what}")))?;
            merged.merge(&tally);
        }
        let r = merged.finish(&cfg);
        Ok((cfg, r, timing.wall_time_s[0], timing.threads))
    }
}
