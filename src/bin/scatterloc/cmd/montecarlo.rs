//! `scatterloc montecarlo`: the tracker(s) against the posterior CRLB ([S] §5.2, spec §9.5,
//! Fig. 3 of §10), sharded (`--shard I/N`: a part file) or whole, the merge of its part files,
//! and `scatterloc pcrlb`: the bound alone, at the nominal path (check 9) or with `E[F̃]` over
//! truth trajectories (check 10). The study itself is the library's
//! [`scatterloc::study::MonteCarloStudy`]; this file parses flags, runs it under a progress bar
//! and writes its documents.

use serde::Serialize;

use scatterloc::chart::TrackingChartOptions;
use scatterloc::math::Shard;
use scatterloc::study::{
    FilterStudy, MonteCarloStudy, PartFile, PartSet, RunTime, ShardDoc, Timing, TrackStudy,
};
use scatterloc::track::{
    nominal_pcrlb_rmse, paper_initial_covariance, DEFAULT_STUDY_SEED, PAPER_NOISE_RUNS, PAPER_RUNS,
};

use super::filters::filter_kinds;
use super::parts::PartReader;
use super::report::Outputs;
use super::shard;
use super::study::{
    check_study_cost, flag_error, parse_study, report_failures, run_filters_with_progress,
    run_pcrlb_with_progress, threads,
};
use crate::cli::{FilterName, MontecarloArgs, PcrlbArgs};
use crate::failure::CliError;

/// The figure's title and subtitle.
fn chart_options(study: &MonteCarloStudy) -> TrackingChartOptions {
    let names: Vec<String> = study
        .filters
        .iter()
        .map(|k| k.name().to_uppercase())
        .collect();
    let track = &study.track;
    TrackingChartOptions {
        title: format!("{} vs posterior CRLB — {}", names.join(", "), track.which()),
        subtitle: Some(format!(
            "{} trajectories × {} noise runs · step T = {} · σq² = {} m²/s³ · seed {}",
            study.runs,
            study.noise_runs,
            track.step_label(),
            track.motion.intensity,
            study.seed
        )),
    }
}

/// The study of `montecarlo`'s flags, checked (errors name the flags).
fn study_of(args: &MontecarloArgs) -> Result<MonteCarloStudy, CliError> {
    let track = parse_study(&args.study)?;
    let runs = args.runs.unwrap_or(PAPER_RUNS);
    let noise_runs = args.noise_runs.unwrap_or(PAPER_NOISE_RUNS);
    let names = match &args.filters {
        Some(list) => list.0.clone(),
        None => vec![FilterName::Ekf],
    };
    let kinds = filter_kinds(&names, &args.settings, "--filters")?;
    let seed = args.seed.unwrap_or(DEFAULT_STUDY_SEED);
    MonteCarloStudy::new(track, runs, noise_runs, seed, args.oracle_noise, &kinds)
        .map_err(flag_error)
}

/// What each of `shards` shards of `args` (on `threads` threads each) checks before its run,
/// without running it (`slurm submit`, issue 37): the study's flags, and the predicted CPU time
/// of the costliest shard against `--max-cpu-hours`.
pub fn check_shards(args: &MontecarloArgs, shards: usize, threads: usize) -> Result<(), CliError> {
    if let Some(walkers) = args.targets {
        // The multi-target study: its configuration as each shard checks it.
        return super::multi_study::multi_config(args, walkers).map(drop);
    }
    let study = study_of(args)?;
    let links = study.track.model.link_count();
    let runs = (0..study.track.trajectories.len())
        .map(|k| study.filter_study(k))
        .collect::<Result<Vec<_>, _>>()
        .map_err(flag_error)?;
    let cost = |chunks: &std::ops::Range<usize>| -> f64 {
        runs.iter().map(|r| r.predicted_cpu_s(links, chunks)).sum()
    };
    let costliest = (0..shards)
        .filter_map(|i| Shard::new(i, shards))
        .map(|s| s.range(study.chunk_count()))
        .max_by(|a, b| cost(a).total_cmp(&cost(b)));
    match costliest {
        Some(chunks) => check_study_cost(&study, &chunks, threads, args.max_cpu_hours).map(drop),
        None => Ok(()),
    }
}

/// `scatterloc montecarlo`.
pub fn montecarlo(args: &MontecarloArgs) -> Result<(), CliError> {
    if args.doppler.on {
        return super::doppler_study::doppler_montecarlo(args);
    }
    if let Some(walkers) = args.targets {
        return super::multi_study::multi_montecarlo(args, walkers);
    }
    let study = study_of(args)?;
    let (threads, used) = threads(args.threads)?;
    let shard = shard::resolve(&args.shard)?;
    let chunks = match shard {
        Some(s) => s.range(study.chunk_count()),
        None => 0..study.chunk_count(),
    };
    let predicted = check_study_cost(&study, &chunks, used, args.max_cpu_hours)?;
    if let Some(shard) = shard {
        let path = shard::part_path(args.json.as_deref(), args.out.as_deref())?;
        return run_shard(&study, shard, (threads, used), &path);
    }
    let outputs = Outputs::parse(args.out.as_deref(), args.json.as_deref())?;

    let mut docs = Vec::new();
    for (k, t) in study.track.trajectories.iter().enumerate() {
        let label = format!("scenario {:>3}{}", t.name(), predicted);
        let mut runs = study.filter_study(k).map_err(flag_error)?;
        let all = 0..study.chunk_count();
        let wall = run_filters_with_progress(&study.track.model, &mut runs, all, threads, &label)?;
        let time = RunTime {
            wall_s: wall,
            thread_s: wall * used as f64,
            threads: used,
        };
        let results = runs.results().map_err(flag_error)?;
        let mut doc = study.doc(k, &results, time);
        report_failures(&format!("scenario {}", t.name()), &results, &mut doc);
        docs.push(doc);
    }
    outputs.finish(&study.track, &docs, &chart_options(&study))
}

/// Runs shard `shard` (its chunks of every trajectory) and writes its part file `path`.
fn run_shard(
    study: &MonteCarloStudy,
    shard: Shard,
    (threads, used): (usize, usize),
    path: &str,
) -> Result<(), CliError> {
    let total = study.chunk_count();
    let chunks = shard.range(total);
    let mut runs: Vec<FilterStudy> = Vec::new();
    let mut walls = Vec::new();
    for (k, t) in study.track.trajectories.iter().enumerate() {
        let label = format!(
            "scenario {:>3} shard {}/{}",
            t.name(),
            shard.index(),
            shard.count()
        );
        let mut run = study.filter_study(k).map_err(flag_error)?;
        let wall = run_filters_with_progress(
            &study.track.model,
            &mut run,
            chunks.clone(),
            threads,
            &label,
        )?;
        runs.push(run);
        walls.push(wall);
    }
    let sums = MonteCarloStudy::part_sums(&runs);
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
    let config = study
        .config_doc()
        .map_err(|e| CliError::output(e.to_string()))?;
    let part = PartFile::new("montecarlo", &config, &doc, &timing, &sums);
    shard::write_part(path, &part, &counted)
}

/// `scatterloc merge` of Monte Carlo parts (checked as a set by `merge`): the sums of every
/// shard added exactly ([`MonteCarloStudy::merge`]), then the outputs of the unsharded run.
pub fn merge_parts(
    set: &PartSet,
    mut reader: PartReader,
    json: &str,
    out: Option<&str>,
) -> Result<(), CliError> {
    let (study, runs, times) =
        MonteCarloStudy::merge(set, &mut |p| reader.load(p)).map_err(flag_error)?;
    let outputs = Outputs::parse(out, Some(json))?;
    let mut docs = Vec::new();
    for (k, (run, time)) in runs.iter().zip(times).enumerate() {
        let results = run.results().map_err(flag_error)?;
        let mut doc = study.doc(k, &results, time);
        let name = study.track.trajectories[k].name();
        report_failures(&format!("scenario {name}"), &results, &mut doc);
        docs.push(doc);
    }
    outputs.finish(&study.track, &docs, &chart_options(&study))
}

/// `scatterloc pcrlb`.
pub fn pcrlb(args: &PcrlbArgs) -> Result<(), CliError> {
    let study: TrackStudy = parse_study(&args.study)?;
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
    let runs = args.runs.unwrap_or(PAPER_RUNS);
    let (seed, (threads, _)) = (
        args.seed.unwrap_or(DEFAULT_STUDY_SEED),
        threads(args.threads)?,
    );
    let configs = study
        .trajectories
        .iter()
        .map(|t| study.config(*t, runs, 1, seed, false))
        .collect::<Result<Vec<_>, _>>()
        .map_err(flag_error)?;
    let outputs = Outputs::parse(args.out.as_deref(), args.json.as_deref())?;

    let mut docs = Vec::new();
    for (t, cfg) in study.trajectories.iter().zip(&configs) {
        let start = std::time::Instant::now();
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
        docs.push(study.pcrlb_doc(*t, cfg, nominal, rmse, wall));
    }
    let kind = if nominal {
        "nominal path".to_string()
    } else {
        format!("E[F̃] over {runs} trajectories, seed {seed}")
    };
    let opts = TrackingChartOptions {
        title: format!("Posterior CRLB — {}", study.which()),
        subtitle: Some(format!("{kind} · step T = {}", study.step_label())),
    };
    outputs.finish(&study, &docs, &opts)
}
