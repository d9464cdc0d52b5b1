//! `scatterloc montecarlo`: the EKF against its posterior CRLB ([S] §5.2, spec §9.5, Fig. 3 of
//! §10), sharded (`--shard I/N`: a part file) or whole, the merge of its part files, and
//! `scatterloc pcrlb`: the bound alone, at the nominal path (check 9) or with `E[F̃]` over truth
//! trajectories (check 10).

use serde::{Deserialize, Serialize};

use scatterloc::chart::TrackingChartOptions;
use scatterloc::math::Shard;
use scatterloc::track::FilterKind;
use scatterloc::track::{
    finish, nominal_pcrlb_rmse, paper_initial_covariance, ConstantVelocity, MonteCarloConfig,
    MonteCarloResult, StudySums, TrackScenario, MAX_STEPS,
};
use scatterloc::Scenario;

use super::filters::filter_kinds;
use super::merge::{differs, inconsistent, merged_timing, sums_of, Part};
use super::report::{which, CurveDoc, Outputs};
use super::shard::{self, ShardDoc, Timing};
use super::study::{
    flag_error, parse_study, run_chunks_with_progress, run_filters_with_progress,
    run_pcrlb_with_progress, run_with_progress, threads, Study,
};
use crate::cli::{FilterName, FilterSettings, MontecarloArgs, PcrlbArgs};
use crate::failure::CliError;
use clap::ValueEnum;

/// Scalars of one Monte Carlo study, after the curves in the JSON file and in the summary.
#[derive(Serialize)]
struct McMeta {
    /// EKF runs counted (`trajectories × noise_runs − failed_runs`); with `--filters` without
    /// `ekf`, the first filter's.
    runs: usize,
    seed: u64,
    trajectory: &'static str,
    dt_s: f64,
    noise_runs: usize,
    trajectories: usize,
    failed_runs: usize,
    wall_time_s: f64,
    /// `wall · threads / (runs · steps)`: thread time per EKF step, truth simulation included
    /// (with several filters the wall time is all filters').
    ns_per_ekf_step: f64,
    /// `wall / (runs · steps)`.
    wall_ns_per_ekf_step: f64,
    threads: usize,
    steps: usize,
    process_noise: f64,
    oracle_noise: bool,
    layout: String,
    /// `--filters` other than `ekf` alone: each filter's curves, in the order asked.
    #[serde(skip_serializing_if = "Option::is_none")]
    filters: Option<FilterCurves>,
}

/// The curves of one filter of `--filters`.
#[derive(Serialize)]
struct FilterDoc {
    /// The filter's RMSE, m.
    rmse_m: Vec<f64>,
    /// Its average NEES.
    nees: Vec<f64>,
    /// Its runs counted.
    runs: usize,
    /// Its runs that failed numerically (left out of `rmse_m`).
    failed_runs: usize,
}

/// `{"ekf": {..}, "ukf": {..}, ..}` in the order of `--filters`.
struct FilterCurves(Vec<(&'static str, FilterDoc)>);

impl Serialize for FilterCurves {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        let mut map = s.serialize_map(Some(self.0.len()))?;
        for (name, doc) in &self.0 {
            map.serialize_entry(name, doc)?;
        }
        map.end()
    }
}

/// The document of several filters' results `rs` (in the order of `kinds`): the PCRLB and
/// times once, the EKF's curves and counts at the top level when it ran (else the first
/// filter's counts), and every filter's curves under `filters`.
fn multi_doc(
    study: &Study,
    t: TrackScenario,
    cfg: &MonteCarloConfig,
    kinds: &[FilterKind],
    rs: Vec<MonteCarloResult>,
    time: RunTime,
) -> CurveDoc<McMeta> {
    let main = kinds.iter().position(|k| *k == FilterKind::Ekf);
    let lead = &rs[main.unwrap_or(0)];
    let mut doc = mc_doc(
        study,
        t,
        cfg,
        MonteCarloResult {
            t_s: lead.t_s.clone(),
            rmse_ekf_m: lead.rmse_ekf_m.clone(),
            rmse_pcrlb_m: lead.rmse_pcrlb_m.clone(),
            nees: lead.nees.clone(),
            runs: lead.runs,
            failed_runs: lead.failed_runs,
            seed: lead.seed,
        },
        time,
    );
    if main.is_none() {
        doc.rmse_ekf_m = None;
        doc.nees = None;
    }
    let notes: Vec<String> = kinds
        .iter()
        .zip(&rs)
        .map(|(k, r)| {
            format!(
                "{}: {} of {} failed",
                k.name(),
                r.failed_runs,
                r.runs + r.failed_runs
            )
        })
        .collect();
    doc.caption_note = Some(notes.join(", "));
    doc.figure_curves = Some(
        kinds
            .iter()
            .zip(&rs)
            .map(|(k, r)| {
                let label = format!("{} RMSE", k.name().to_uppercase());
                (label, r.rmse_ekf_m.clone())
            })
            .collect(),
    );
    doc.meta.filters = Some(FilterCurves(
        kinds
            .iter()
            .zip(rs)
            .map(|(k, r)| {
                (
                    k.name(),
                    FilterDoc {
                        rmse_m: r.rmse_ekf_m,
                        nees: r.nees,
                        runs: r.runs,
                        failed_runs: r.failed_runs,
                    },
                )
            })
            .collect(),
    ));
    doc
}

/// The run time of one trajectory's study: wall time, thread time (`Σ wall · threads`) and
/// threads.
struct RunTime {
    wall_s: f64,
    thread_s: f64,
    threads: usize,
}

/// The JSON document (and figure panel) of trajectory `t`'s result.
fn mc_doc(
    study: &Study,
    t: TrackScenario,
    cfg: &MonteCarloConfig,
    r: MonteCarloResult,
    time: RunTime,
) -> CurveDoc<McMeta> {
    let steps_run = cfg.runs() as f64 * cfg.steps as f64;
    let meta = McMeta {
        runs: r.runs,
        seed: cfg.seed,
        trajectory: t.name(),
        dt_s: cfg.motion.dt_s,
        noise_runs: cfg.noise_runs,
        trajectories: cfg.trajectories,
        failed_runs: r.failed_runs,
        wall_time_s: time.wall_s,
        ns_per_ekf_step: 1e9 * time.thread_s / steps_run,
        wall_ns_per_ekf_step: 1e9 * time.wall_s / steps_run,
        threads: time.threads,
        steps: cfg.steps,
        process_noise: cfg.motion.intensity,
        oracle_noise: cfg.oracle_noise,
        layout: study.layout.clone(),
        filters: None,
    };
    CurveDoc {
        t_s: r.t_s,
        rmse_ekf_m: Some(r.rmse_ekf_m),
        rmse_pcrlb_m: r.rmse_pcrlb_m,
        nees: Some(r.nees),
        caption_note: Some(failed_note(r.failed_runs, r.runs + r.failed_runs)),
        figure_curves: None,
        meta,
    }
}

/// The figure's title and subtitle.
fn chart_options(study: &Study, c: &McConfig, kinds: &[FilterKind]) -> TrackingChartOptions {
    let names: Vec<String> = kinds.iter().map(|k| k.name().to_uppercase()).collect();
    TrackingChartOptions {
        title: format!("{} vs posterior CRLB — {}", names.join(", "), which(study)),
        subtitle: Some(format!(
            "{} trajectories × {} noise runs · step T = {} · σq² = {} m²/s³ · seed {}",
            c.runs,
            c.noise_runs,
            study.step_label(),
            study.motion.intensity,
            c.seed
        )),
    }
}

/// Everything a Monte Carlo study's result depends on: the `config` of its part files.
#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct McConfig {
    /// The layout's name (preset or scenario file's `name`).
    layout: String,
    /// The scenario document (schema v1) as read and validated.
    scenario: serde_json::Value,
    /// Trajectories of spec §9.4, in order.
    trajectories: Vec<String>,
    dt_s: f64,
    steps: usize,
    process_noise: f64,
    /// Truth trajectories per trajectory (`--runs`).
    runs: usize,
    noise_runs: usize,
    seed: u64,
    oracle_noise: bool,
    /// `--filters` other than `ekf` alone: the filters and their settings (absent: the EKF).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    filters: Option<FiltersConfig>,
}

/// The trackers of a study with several (`--filters`), as its part files record them.
#[derive(Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
struct FiltersConfig {
    /// `ekf`, `ukf`, `pf`, in the order run.
    names: Vec<String>,
    /// UKF `alpha`, `beta`, `kappa` (when `ukf` runs).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    ukf: Option<[f64; 3]>,
    /// Particles (when `pf` runs).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    particles: Option<usize>,
    /// Roughening constant (when `pf` runs with it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    roughening: Option<f64>,
}

impl FiltersConfig {
    /// `None` for the EKF alone.
    fn of(kinds: &[FilterKind]) -> Option<FiltersConfig> {
        if kinds == [FilterKind::Ekf] {
            return None;
        }
        let mut c = FiltersConfig {
            names: kinds.iter().map(|k| k.name().to_string()).collect(),
            ukf: None,
            particles: None,
            roughening: None,
        };
        for k in kinds {
            match k {
                FilterKind::Ekf => {}
                FilterKind::Ukf(p) => c.ukf = Some([p.alpha, p.beta, p.kappa]),
                FilterKind::Pf(p) => {
                    c.particles = Some(p.particles);
                    c.roughening = p.roughening;
                }
            }
        }
        Some(c)
    }

    /// The filters again (validated).
    fn kinds(&self) -> Result<Vec<FilterKind>, String> {
        let names = self
            .names
            .iter()
            .map(|n| FilterName::from_str(n, false).map_err(|_| format!("unknown filter '{n}'")))
            .collect::<Result<Vec<_>, _>>()?;
        let settings = FilterSettings {
            particles: self.particles,
            roughening: self.roughening,
            ukf_alpha: self.ukf.map(|u| u[0]),
            ukf_beta: self.ukf.map(|u| u[1]),
            ukf_kappa: self.ukf.map(|u| u[2]),
        };
        filter_kinds(&names, &settings, "--filters").map_err(|e| e.message)
    }
}

impl McConfig {
    fn of(
        study: &Study,
        runs: usize,
        noise_runs: usize,
        seed: u64,
        oracle_noise: bool,
        kinds: &[FilterKind],
    ) -> Result<McConfig, CliError> {
        Ok(McConfig {
            layout: study.layout.clone(),
            scenario: serde_json::to_value(&study.scenario)
                .map_err(|e| CliError::output(format!("encoding the scenario: {e}")))?,
            trajectories: study
                .trajectories
                .iter()
                .map(|t| t.name().to_string())
                .collect(),
            dt_s: study.motion.dt_s,
            steps: study.steps,
            process_noise: study.motion.intensity,
            runs,
            noise_runs,
            seed,
            oracle_noise,
            filters: FiltersConfig::of(kinds),
        })
    }

    /// The study and its configurations (one per trajectory) again, as the unsharded run built
    /// them; errors say what is wrong.
    fn study(&self) -> Result<(Study, Vec<MonteCarloConfig>), String> {
        let scenario = Scenario::from_json(&self.scenario.to_string())
            .map_err(|e| format!("config.scenario: {e}"))?;
        let trajectories = self
            .trajectories
            .iter()
            .map(|t| TrackScenario::parse(t).map_err(|e| format!("config.trajectories: {e}")))
            .collect::<Result<Vec<_>, _>>()?;
        let motion = ConstantVelocity::validated(self.dt_s, self.process_noise)
            .map_err(|e| format!("config: {e}"))?;
        if !(1..=MAX_STEPS).contains(&self.steps) || trajectories.is_empty() {
            return Err("config: no steps or no trajectories".into());
        }
        let study = Study::new(
            self.layout.clone(),
            scenario,
            trajectories,
            motion,
            self.steps,
        )
        .map_err(|e| e.message)?;
        let configs = study
            .trajectories
            .iter()
            .map(|t| study.config(*t, self.runs, self.noise_runs, self.seed, self.oracle_noise))
            .collect::<Result<Vec<_>, _>>()
            .map_err(|e| format!("config: {}", e.message))?;
        Ok((study, configs))
    }
}

/// `scatterloc montecarlo`.
pub fn montecarlo(args: &MontecarloArgs) -> Result<(), CliError> {
    let study = parse_study(&args.study)?;
    let runs = args.runs.unwrap_or(5000);
    let noise_runs = args.noise_runs.unwrap_or(50);
    let (seed, (threads, used)) = (args.seed.unwrap_or(1), threads(args.threads)?);
    let oracle = args.oracle_noise;
    let configs = study
        .trajectories
        .iter()
        .map(|t| study.config(*t, runs, noise_runs, seed, oracle))
        .collect::<Result<Vec<_>, _>>()?;
    let names = match &args.filters {
        Some(list) => list.0.clone(),
        None => vec![FilterName::Ekf],
    };
    let kinds = filter_kinds(&names, &args.settings, "--filters")?;
    let ekf_only = kinds == [FilterKind::Ekf];
    let config = McConfig::of(&study, runs, noise_runs, seed, oracle, &kinds)?;
    if let Some(shard) = shard::resolve(&args.shard)? {
        let path = shard::part_path(args.json.as_deref(), args.out.as_deref())?;
        return run_shard(
            &study,
            &configs,
            &config,
            &kinds,
            shard,
            (threads, used),
            &path,
        );
    }
    let outputs = Outputs::parse(args.out.as_deref(), args.json.as_deref())?;

    let mut docs = Vec::new();
    for (t, cfg) in study.trajectories.iter().zip(&configs) {
        let label = format!("scenario {:>3}", t.name());
        if ekf_only {
            let (r, wall) = run_with_progress(&study.model, cfg, threads, &label)?;
            let time = RunTime {
                wall_s: wall,
                thread_s: wall * used as f64,
                threads: used,
            };
            docs.push(mc_doc(&study, *t, cfg, r, time));
        } else {
            let all = 0..cfg.chunk_count();
            let (sums, wall) =
                run_filters_with_progress(&study.model, cfg, &kinds, all, threads, &label)?;
            let rs = sums
                .iter()
                .map(|s| finish(cfg, s))
                .collect::<Result<Vec<_>, _>>()
                .map_err(flag_error)?;
            let time = RunTime {
                wall_s: wall,
                thread_s: wall * used as f64,
                threads: used,
            };
            docs.push(multi_doc(&study, *t, cfg, &kinds, rs, time));
        }
    }
    outputs.finish(&study, &docs, &chart_options(&study, &config, &kinds))
}

/// Runs shard `shard` (its chunks of every trajectory) and writes its part file `path`.
fn run_shard(
    study: &Study,
    configs: &[MonteCarloConfig],
    config: &McConfig,
    kinds: &[FilterKind],
    shard: Shard,
    (threads, used): (usize, usize),
    path: &str,
) -> Result<(), CliError> {
    let total = configs[0].chunk_count();
    let chunks = shard.range(total);
    let mut sums = Vec::new();
    let mut walls = Vec::new();
    for (t, cfg) in study.trajectories.iter().zip(configs) {
        let label = format!(
            "scenario {:>3} shard {}/{}",
            t.name(),
            shard.index(),
            shard.count()
        );
        if kinds == [FilterKind::Ekf] {
            let (s, wall) =
                run_chunks_with_progress(&study.model, cfg, chunks.clone(), threads, &label)?;
            sums.push(s);
            walls.push(wall);
        } else {
            // Per trajectory, one entry per filter in order.
            let (s, wall) = run_filters_with_progress(
                &study.model,
                cfg,
                kinds,
                chunks.clone(),
                threads,
                &label,
            )?;
            sums.extend(s);
            walls.push(wall);
        }
    }
    #[derive(Serialize)]
    struct Counted {
        runs: usize,
        failed_runs: usize,
    }
    let counted = Counted {
        runs: sums.iter().map(|s| s.runs).sum(),
        failed_runs: sums.iter().map(|s| s.failed_runs).sum(),
    };
    let timing = Timing {
        threads: used,
        wall_time_s: walls,
    };
    let doc = ShardDoc::new(shard, "chunks", total);
    shard::write_part(path, "montecarlo", config, &doc, &timing, &sums, &counted)
}

/// `scatterloc merge` of Monte Carlo parts (checked as a set by `merge`): the sums of every
/// shard added exactly, then the outputs of the unsharded run.
pub fn merge_parts(parts: &[Part], json: &str, out: Option<&str>) -> Result<(), CliError> {
    let first = &parts[0];
    let config = McConfig::deserialize(&first.config)
        .map_err(|e| inconsistent(&first.path, format!("config: {e}")))?;
    let (study, configs) = config.study().map_err(|e| inconsistent(&first.path, e))?;
    // The configuration must be the one this build writes for that study.
    let kinds = match &config.filters {
        Some(f) => f
            .kinds()
            .map_err(|e| inconsistent(&first.path, format!("config.filters: {e}")))?,
        None => vec![FilterKind::Ekf],
    };
    let again = McConfig::of(
        &study,
        config.runs,
        config.noise_runs,
        config.seed,
        config.oracle_noise,
        &kinds,
    )?;
    let again = serde_json::to_value(&again)
        .map_err(|e| CliError::output(format!("encoding JSON: {e}")))?;
    if let Some(d) = differs(&again, &first.config) {
        return Err(inconsistent(
            &first.path,
            format!("config is not as this scatterloc writes it ({d})"),
        ));
    }
    let total = configs[0].chunk_count();
    if first.shard.total != total {
        return Err(inconsistent(
            &first.path,
            format!(
                "shard.total {} is not the study's {total} chunks",
                first.shard.total
            ),
        ));
    }
    let outputs = Outputs::parse(out, Some(json))?;

    // Per trajectory, one entry per filter in order.
    let per = kinds.len();
    let mut merged: Vec<StudySums> = configs
        .iter()
        .flat_map(|c| std::iter::repeat_n(c.steps, per))
        .map(StudySums::new)
        .collect();
    for part in parts {
        let sums: Vec<StudySums> = sums_of(part)?;
        let chunks = part.shard.range[0]..part.shard.range[1];
        if sums.len() != configs.len() * per {
            return Err(inconsistent(
                &part.path,
                format!(
                    "{} sums for {} trajectories × {per} filters",
                    sums.len(),
                    configs.len()
                ),
            ));
        }
        let cfg_of = configs.iter().flat_map(|c| std::iter::repeat_n(c, per));
        for ((m, s), cfg) in merged.iter_mut().zip(&sums).zip(cfg_of) {
            let trajectories = cfg.trajectories_in(&chunks);
            if !s.has_steps(cfg.steps)
                || s.trajectories != trajectories
                || s.runs + s.failed_runs != trajectories * cfg.noise_runs
            {
                return Err(inconsistent(
                    &part.path,
                    format!(
                        "sums do not match chunks [{}, {}) of the study ({} steps, {trajectories} trajectories × {} noise runs)",
                        chunks.start, chunks.end, cfg.steps, cfg.noise_runs
                    ),
                ));
            }
            m.merge(s);
        }
    }
    let (timing, thread_s) = merged_timing(parts, configs.len())?;
    let mut docs = Vec::new();
    for (k, ((t, cfg), sums)) in study
        .trajectories
        .iter()
        .zip(&configs)
        .zip(merged.chunks(per))
        .enumerate()
    {
        let mut rs = sums
            .iter()
            .map(|s| finish(cfg, s))
            .collect::<Result<Vec<_>, _>>()
            .map_err(flag_error)?;
        let time = RunTime {
            wall_s: timing.wall_time_s[k],
            thread_s: thread_s[k],
            threads: timing.threads,
        };
        if config.filters.is_none() {
            docs.push(mc_doc(&study, *t, cfg, rs.remove(0), time));
        } else {
            docs.push(multi_doc(&study, *t, cfg, &kinds, rs, time));
        }
    }
    outputs.finish(&study, &docs, &chart_options(&study, &config, &kinds))
}

/// The figure's note on the EKF runs that failed numerically (left out of `ε_EKF`), shown
/// even when there are none.
fn failed_note(failed: usize, total: usize) -> String {
    format!("{failed} of {total} runs failed")
}

/// Scalars of one bound curve (`pcrlb`).
#[derive(Serialize)]
struct PcrlbMeta {
    trajectory: &'static str,
    dt_s: f64,
    nominal: bool,
    steps: usize,
    process_noise: f64,
    layout: String,
    /// Truth trajectories of `E[F̃]` (Monte Carlo only).
    #[serde(skip_serializing_if = "Option::is_none")]
    trajectories: Option<usize>,
    #[serde(skip_serializing_if = "Option::is_none")]
    seed: Option<u64>,
    wall_time_s: f64,
}

/// `scatterloc pcrlb`.
pub fn pcrlb(args: &PcrlbArgs) -> Result<(), CliError> {
    let study = parse_study(&args.study)?;
    let nominal = args.nominal;
    let mc_only = [
        ("runs", args.runs.is_some()),
        ("seed", args.seed.is_some()),
        ("threads", args.threads.is_some()),
    ];
    if let Some((f, _)) = mc_only.iter().find(|(_, given)| nominal && *given) {
        return Err(CliError::usage(format!(
            "--{f}: only for the Monte Carlo bound (drop --nominal)"
        )));
    }
    let runs = args.runs.unwrap_or(5000);
    let (seed, (threads, _)) = (args.seed.unwrap_or(1), threads(args.threads)?);
    let configs = study
        .trajectories
        .iter()
        .map(|t| study.config(*t, runs, 1, seed, false))
        .collect::<Result<Vec<_>, _>>()?;
    let outputs = Outputs::parse(args.out.as_deref(), args.json.as_deref())?;

    let mut docs = Vec::new();
    for (t, cfg) in study.trajectories.iter().zip(&configs) {
        let start = std::time::Instant::now();
        let t_s = (0..=cfg.steps)
            .map(|n| n as f64 * cfg.motion.dt_s)
            .collect();
        let (rmse, wall) = if nominal {
            let (p0, mean) = (paper_initial_covariance(), t.mean_state());
            let rmse = nominal_pcrlb_rmse(&study.model, &cfg.motion, &mean, &p0, cfg.steps)
                .map_err(flag_error)?;
            (rmse, start.elapsed().as_secs_f64())
        } else {
            // E[F̃] over `runs` truth trajectories (no EKF runs).
            let label = format!("scenario {:>3} (PCRLB)", t.name());
            run_pcrlb_with_progress(&study.model, cfg, threads, &label)?
        };
        let meta = PcrlbMeta {
            trajectory: t.name(),
            dt_s: cfg.motion.dt_s,
            nominal,
            steps: cfg.steps,
            process_noise: cfg.motion.intensity,
            layout: study.layout.clone(),
            trajectories: (!nominal).then_some(runs),
            seed: (!nominal).then_some(seed),
            wall_time_s: wall,
        };
        docs.push(CurveDoc {
            t_s,
            rmse_ekf_m: None,
            rmse_pcrlb_m: rmse,
            nees: None,
            caption_note: None,
            figure_curves: None,
            meta,
        });
    }
    let kind = if nominal {
        "nominal path".to_string()
    } else {
        format!("E[F̃] over {runs} trajectories, seed {seed}")
    };
    let opts = TrackingChartOptions {
        title: format!("Posterior CRLB — {}", which(&study)),
        subtitle: Some(format!("{kind} · step T = {}", study.step_label())),
    };
    outputs.finish(&study, &docs, &opts)
}
