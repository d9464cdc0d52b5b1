//! The multi-target Monte Carlo study (issue 41 §2–3): people walking in a scenario's network
//! ([`simulate_people`]), tracked by the PMB tracker and the GNN baseline on the same scans, scored
//! by GOSPA per scan (its localisation, missed and false parts), label switches, the crossing
//! pair's switches and the cardinality error, beside the known-association bound: per target the
//! PCRLB (E9) with `P_D·F(r)` on its true path, summed over the targets. The sums of every run
//! add exactly ([`ExactSum`]), so a sharded run (`--shard I/N`, part kind `multi-target`, unit
//! `runs`) merges to the unsharded result.

use alloc::format;
use alloc::string::String;
use alloc::vec;
use alloc::vec::Vec;
use core::ops::Range;

use serde::{Deserialize, Serialize};
use serde_json::Value;

use crate::error::{Error, Result};
use crate::math::{sqrt, ExactSum, Mat4, Real, Vec2, Vec4};
use crate::measure::Model;
use crate::scenario::Scenario;
use crate::study::part::{differs, inconsistent, load_sums, merged_timing, PartSet};
use crate::study::{
    multi_scans, multi_tracker, simulate_people, walk_region, Driver, MultiSettings,
};
use crate::track::multi::{score_run, DelayLinks, MultiKind, RunScore, TargetEstimate};
use crate::track::{pcrlb_rmse, ConstantVelocity, GospaConfig};

/// Most runs of one study.
pub const MAX_MULTI_RUNS: usize = 100_000;

/// Every setting of a multi-target study (the `config` of its result and of its part files).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MultiStudyConfig {
    /// The network.
    pub scenario: Scenario,
    /// Walkers (1..=5).
    pub walkers: usize,
    /// Runs.
    pub runs: usize,
    /// Seed (run `i` draws from stream `i`).
    pub seed: u64,
    /// Scans per run.
    pub steps: usize,
    /// Scan interval, s.
    pub dt_s: f64,
    /// Process-noise intensity of the trackers, m²/s³.
    pub process_noise: f64,
    /// GOSPA cut-off `c`, m (`p = 2`, `α = 2`).
    pub gospa_c: f64,
    /// The scans' `P_D`, clutter and the trackers' settings (`method` is ignored: both run).
    pub settings: MultiSettings,
}

impl MultiStudyConfig {
    /// The defaults of issue 41's people scenario for `scenario`: 10 s at 10 Hz, `q = 0.5`,
    /// `c = 1 m`.
    pub fn new(scenario: Scenario, walkers: usize, runs: usize, seed: u64) -> MultiStudyConfig {
        MultiStudyConfig {
            scenario,
            walkers,
            runs,
            seed,
            steps: 100,
            dt_s: 0.1,
            process_noise: 0.5,
            gospa_c: 1.0,
            settings: MultiSettings::default(),
        }
    }

    /// Named errors for a bad setting.
    pub fn validate(&self) -> Result<()> {
        self.scenario.validate()?;
        if !(1..=MAX_MULTI_RUNS).contains(&self.runs) {
            return Err(Error::SizeLimit {
                field: "runs",
                value: self.runs,
                min: 1,
                max: MAX_MULTI_RUNS,
            });
        }
        if !(self.gospa_c.is_finite() && self.gospa_c > 0.0) {
            return Err(Error::NotPositive {
                field: "gospa_c".into(),
                value: self.gospa_c,
            });
        }
        // The rest as one run checks it.
        let model = Model::new(&self.scenario)?;
        simulate_people(
            &model,
            &walk_region(&self.scenario.area_m),
            self.walkers,
            self.steps,
            self.dt_s,
            self.process_noise,
            &self.settings,
            self.seed,
        )
        .map(|_| ())
    }
}

/// One method's sums over runs.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MethodSums {
    /// Per scan `Σ d`.
    pub gospa: Vec<ExactSum>,
    /// Per scan `Σ d²`.
    pub gospa2: Vec<ExactSum>,
    /// Per scan `Σ` localisation part.
    pub localisation: Vec<ExactSum>,
    /// Per scan `Σ` missed part.
    pub missed: Vec<ExactSum>,
    /// Per scan `Σ` false part.
    pub false_: Vec<ExactSum>,
    /// Per scan `Σ |n̂ − n|`.
    pub cardinality_error: Vec<ExactSum>,
    /// `Σ` label switches.
    pub switches: u64,
    /// Runs in which walkers 0 and 1 (the crossing pair) kept their labels.
    pub crossing_kept: u64,
}

/// The sums of a range of runs: per method (PMB, GNN) and the bound.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MultiSums {
    /// Runs summed.
    pub runs: u64,
    /// PMB, GNN.
    pub methods: Vec<MethodSums>,
    /// Per scan `Σ_runs Σ_targets tr PCRLB_position`, m².
    pub bound: Vec<ExactSum>,
}

impl MultiSums {
    fn new(steps: usize) -> MultiSums {
        let m = || MethodSums {
            gospa: vec![ExactSum::default(); steps],
            gospa2: vec![ExactSum::default(); steps],
            localisation: vec![ExactSum::default(); steps],
            missed: vec![ExactSum::default(); steps],
            false_: vec![ExactSum::default(); steps],
            cardinality_error: vec![ExactSum::default(); steps],
            switches: 0,
            crossing_kept: 0,
        };
        MultiSums {
            runs: 0,
            methods: vec![m(), m()],
            bound: vec![ExactSum::default(); steps],
        }
    }

    fn add_run(&mut self, scores: &[RunScore; 2], bound: &[Real]) {
        self.runs += 1;
        for (m, s) in self.methods.iter_mut().zip(scores) {
            for (k, st) in s.steps.iter().enumerate() {
                m.gospa[k].add(st.gospa);
                m.gospa2[k].add(st.gospa * st.gospa);
                m.localisation[k].add(st.localisation);
                m.missed[k].add(st.missed);
                m.false_[k].add(st.false_);
                m.cardinality_error[k].add(st.cardinality_error as Real);
            }
            m.switches += s.total_switches() as u64;
            let crossing =
                s.switches.get(&0).copied().unwrap_or(0) + s.switches.get(&1).copied().unwrap_or(0);
            m.crossing_kept += u64::from(crossing == 0);
        }
        for (b, v) in self.bound.iter_mut().zip(bound) {
            b.add(*v);
        }
    }

    /// Adds `other` (disjoint runs) exactly.
    pub fn merge(&mut self, other: &MultiSums) {
        self.runs += other.runs;
        for (a, b) in self.methods.iter_mut().zip(&other.methods) {
            for (x, y) in [
                (&mut a.gospa, &b.gospa),
                (&mut a.gospa2, &b.gospa2),
                (&mut a.localisation, &b.localisation),
                (&mut a.missed, &b.missed),
                (&mut a.false_, &b.false_),
                (&mut a.cardinality_error, &b.cardinality_error),
            ] {
                for (u, v) in x.iter_mut().zip(y) {
                    u.merge(v);
                }
            }
            a.switches += b.switches;
            a.crossing_kept += b.crossing_kept;
        }
        for (u, v) in self.bound.iter_mut().zip(&other.bound) {
            u.merge(v);
        }
    }

    /// Checks a part's sums: `runs` runs of `steps` scans (the error names the field).
    pub fn check(&self, runs: usize, steps: usize) -> core::result::Result<(), String> {
        if self.runs != runs as u64 {
            return Err(format!(
                "runs: {} summed, not the shard's {runs}",
                self.runs
            ));
        }
        if self.methods.len() != 2 {
            return Err(format!("methods: {} entries, not 2", self.methods.len()));
        }
        if self.bound.len() != steps {
            return Err(format!("bound: {} entries, not {steps}", self.bound.len()));
        }
        for (i, m) in self.methods.iter().enumerate() {
            for (name, v) in [
                ("gospa", &m.gospa),
                ("gospa2", &m.gospa2),
                ("localisation", &m.localisation),
                ("missed", &m.missed),
                ("false_", &m.false_),
                ("cardinality_error", &m.cardinality_error),
            ] {
                if v.len() != steps {
                    return Err(format!(
                        "methods[{i}].{name}: {} entries, not {steps}",
                        v.len()
                    ));
                }
                if let Some(k) = v.iter().position(|x| x.value().is_nan() || x.value() < 0.0) {
                    return Err(format!(
                        "methods[{i}].{name}[{k}] is negative or not finite"
                    ));
                }
            }
            if m.crossing_kept > self.runs {
                return Err(format!("methods[{i}].crossing_kept exceeds the runs"));
            }
        }
        Ok(())
    }
}

/// The per-target known-association bound of one run's truth, summed over the targets (m²,
/// per scan): the PCRLB (E9) from a prior of 0.1 m per axis and 1 m/s, with `P_D·F(r)` (E8).
pub fn known_association_bound(
    model: &Model,
    truth: &crate::track::multi::Truth,
    motion: &ConstantVelocity,
    detection: Real,
) -> Result<Vec<Real>> {
    let p0 = Mat4::from_diagonal(&Vec4::new(0.01, 0.01, 1.0, 1.0));
    let steps = truth.steps.len();
    let mut bound = vec![0.0; steps];
    let labels: Vec<u64> = truth
        .steps
        .first()
        .map_or(Vec::new(), |s| s.iter().map(|(l, _)| *l).collect());
    for label in labels {
        let fishers: Vec<_> = truth
            .steps
            .iter()
            .skip(1)
            .filter_map(|s| s.iter().find(|(l, _)| *l == label))
            .map(|(_, x)| crate::localize::fisher(model, Vec2::new(x[0], x[1])) * detection)
            .collect();
        let b = pcrlb_rmse(motion, &p0, &fishers)?;
        for (k, v) in b.iter().enumerate().take(steps) {
            // An unbounded step stays unbounded (∞, reported as null).
            bound[k] += v.map_or(Real::INFINITY, |v| v * v);
        }
    }
    Ok(bound)
}

/// One run: its two scores and the bound.
fn run_one(
    cfg: &MultiStudyConfig,
    model: &Model,
    run: usize,
) -> Result<([RunScore; 2], Vec<Real>)> {
    let region = walk_region(&cfg.scenario.area_m);
    // Run `run` draws its own seed from stream `run` of the study's seed.
    let mut r = crate::measure::rng(cfg.seed, run as u64);
    let run_seed = rand::RngCore::next_u64(&mut r);
    let (m, truth) = simulate_people(
        model,
        &region,
        cfg.walkers,
        cfg.steps,
        cfg.dt_s,
        cfg.process_noise,
        &cfg.settings,
        run_seed,
    )?;
    let truth = truth.to_truth();
    let motion = m.motion()?;
    let sensors = DelayLinks::new(
        model,
        cfg.settings.detection_probability,
        cfg.settings.clutter,
        cfg.settings.clutter_window_s,
        None,
    )?;
    let (scans, _) = multi_scans(&m, model.link_count(), None)?;
    let g = GospaConfig {
        c: cfg.gospa_c,
        p: 2.0,
    };
    let mut scores = Vec::with_capacity(2);
    for kind in [MultiKind::Pmb, MultiKind::Gnn] {
        let settings = MultiSettings {
            method: kind,
            ..cfg.settings
        };
        let mut t = multi_tracker(model, &cfg.scenario.area_m, motion, &settings, None)?;
        let mut est: Vec<Vec<TargetEstimate>> = Vec::with_capacity(scans.len());
        for s in &scans {
            t.step(&sensors, s)?;
            est.push(t.estimates());
        }
        scores.push(score_run(&truth, &est, &g)?);
    }
    let bound =
        known_association_bound(model, &truth, &motion, cfg.settings.detection_probability)?;
    let gnn = scores.pop().ok_or(Error::Cancelled)?;
    let pmb = scores.pop().ok_or(Error::Cancelled)?;
    Ok(([pmb, gnn], bound))
}

/// The study's entry points.
pub struct MultiStudy;

impl MultiStudy {
    /// The sums of runs `runs` of `cfg` through `driver`; `progress(done, total)`.
    pub fn run_range(
        cfg: &MultiStudyConfig,
        runs: Range<usize>,
        driver: &mut impl Driver,
        progress: &mut dyn FnMut(usize, usize),
    ) -> Result<MultiSums> {
        cfg.validate()?;
        if runs.end > cfg.runs || runs.start > runs.end {
            return Err(Error::IndexOutOfRange {
                field: "runs",
                index: runs.end.max(runs.start),
                len: cfg.runs,
            });
        }
        let model = Model::new(&cfg.scenario)?;
        let (first, total) = (runs.start, runs.len());
        let mut sums = MultiSums::new(cfg.steps);
        driver.run(
            total,
            4,
            &|i, _| run_one(cfg, &model, first + i),
            &mut |(scores, bound)| sums.add_run(&scores, &bound),
            &mut |done| progress(done, total),
        )?;
        Ok(sums)
    }

    /// The configuration a part file's `config` records (must be what this build writes).
    pub fn from_config(config: &Value) -> Result<MultiStudyConfig> {
        let cfg = MultiStudyConfig::deserialize(config).map_err(|e| Error::Parse {
            message: format!("config: {e}"),
        })?;
        cfg.validate().map_err(|e| Error::Parse {
            message: format!("config: {e}"),
        })?;
        let again = serde_json::to_value(&cfg).map_err(|e| Error::Parse {
            message: format!("encoding JSON: {e}"),
        })?;
        if let Some(d) = differs(&again, config) {
            return Err(Error::Parse {
                message: format!("config is not as this scatterloc writes it ({d})"),
            });
        }
        Ok(cfg)
    }

    /// The merge of a checked set of part files: the sums of every shard added exactly, the
    /// wall time added, the most threads of any part.
    pub fn merge(
        set: &PartSet,
        load: &mut dyn FnMut(&str) -> Result<String>,
    ) -> Result<(MultiStudyConfig, MultiSums, f64, usize)> {
        let parts = &set.parts;
        let first = parts.first().ok_or(Error::PartSet {
            what: "merge: no part files given".into(),
        })?;
        let cfg = MultiStudy::from_config(&set.config).map_err(|e| match e {
            Error::Parse { message } => inconsistent(&first.path, message),
            e => inconsistent(&first.path, e),
        })?;
        if first.shard.total != cfg.runs {
            return Err(inconsistent(
                &first.path,
                format!(
                    "shard.total {} is not the study's {} runs",
                    first.shard.total, cfg.runs
                ),
            ));
        }
        let (timing, _) = merged_timing(parts, 1)?;
        let mut merged = MultiSums::new(cfg.steps);
        for part in parts {
            let sums: MultiSums = load_sums(part, cfg.steps.max(64), load)?;
            let len = part.shard.range[1] - part.shard.range[0];
            sums.check(len, cfg.steps)
                .map_err(|what| inconsistent(&part.path, format!("sums.{what}")))?;
            merged.merge(&sums);
        }
        Ok((cfg, merged, timing.wall_time_s[0], timing.threads))
    }
}

/// One method's result.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MethodDoc {
    /// `pmb` or `gnn`.
    pub method: &'static str,
    /// Mean GOSPA per scan, m.
    pub mean_gospa_m: Vec<f64>,
    /// RMS GOSPA per scan, m.
    pub rms_gospa_m: Vec<f64>,
    /// Mean localisation part per scan, m².
    pub localisation_m2: Vec<f64>,
    /// Mean missed part per scan, m².
    pub missed_m2: Vec<f64>,
    /// Mean false part per scan, m².
    pub false_m2: Vec<f64>,
    /// Mean cardinality error per scan.
    pub cardinality_error: Vec<f64>,
    /// Mean GOSPA over scans and runs, m.
    pub mean_gospa_over_run_m: f64,
    /// Mean cardinality error after the first second.
    pub cardinality_error_after_1s: f64,
    /// Mean localisation part after the first second over the bound there (the ratio of sums).
    pub localisation_over_bound_after_1s: Option<f64>,
    /// Label switches per run.
    pub switches_per_run: f64,
    /// Fraction of runs in which the crossing pair kept its labels.
    pub crossing_kept: f64,
}

/// The result of a study.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MultiStudyDoc {
    /// The configuration.
    pub config: MultiStudyConfig,
    /// Runs.
    pub runs: u64,
    /// Scan times, s.
    pub t_s: Vec<f64>,
    /// Per method.
    pub methods: Vec<MethodDoc>,
    /// Known-association bound per scan: `√(mean Σ_targets tr PCRLB)`, m (`null` = unbounded).
    pub bound_m: Vec<Option<f64>>,
    /// Mean GOSPA of PMB below GNN, %.
    pub pmb_below_gnn_pct: f64,
}

/// The document of summed runs.
pub fn multi_study_doc(cfg: &MultiStudyConfig, s: &MultiSums) -> MultiStudyDoc {
    let n = (s.runs.max(1)) as f64;
    let mean = |v: &[ExactSum]| v.iter().map(|x| x.value() / n).collect::<Vec<f64>>();
    let first = (crate::math::round(1.0 / cfg.dt_s) as usize).min(cfg.steps);
    let bound_after: f64 = s.bound[first..].iter().map(|b| b.value()).sum();
    let methods: Vec<MethodDoc> = s
        .methods
        .iter()
        .zip(["pmb", "gnn"])
        .map(|(m, name)| {
            let g = mean(&m.gospa);
            let loc_after: f64 = m.localisation[first..].iter().map(|b| b.value()).sum();
            let card = mean(&m.cardinality_error);
            let after = (cfg.steps - first).max(1) as f64;
            MethodDoc {
                method: name,
                mean_gospa_over_run_m: g.iter().sum::<f64>() / g.len().max(1) as f64,
                rms_gospa_m: m.gospa2.iter().map(|x| sqrt(x.value() / n)).collect(),
                localisation_m2: mean(&m.localisation),
                missed_m2: mean(&m.missed),
                false_m2: mean(&m.false_),
                cardinality_error_after_1s: card[first..].iter().sum::<f64>() / after,
                cardinality_error: card,
                localisation_over_bound_after_1s: (bound_after.is_finite() && bound_after > 0.0)
                    .then(|| loc_after / bound_after),
                switches_per_run: m.switches as f64 / n,
                crossing_kept: m.crossing_kept as f64 / n,
                mean_gospa_m: g,
            }
        })
        .collect();
    let pct = 100.0 * (1.0 - methods[0].mean_gospa_over_run_m / methods[1].mean_gospa_over_run_m);
    MultiStudyDoc {
        config: cfg.clone(),
        runs: s.runs,
        t_s: (0..cfg.steps).map(|k| k as f64 * cfg.dt_s).collect(),
        bound_m: s
            .bound
            .iter()
            .map(|b| {
                let v = b.value() / n;
                v.is_finite().then(|| sqrt(v))
            })
            .collect(),
        methods,
        pmb_below_gnn_pct: if pct.is_finite() { pct } else { 0.0 },
    }
}
