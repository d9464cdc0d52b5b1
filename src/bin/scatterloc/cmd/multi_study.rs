//! `scatterloc montecarlo --targets N` (issue 41 §2): the library's multi-target study
//! ([`scatterloc::study::MultiStudy`]: N people walking, the PMB tracker and the GNN baseline on
//! the same scans, GOSPA per scan against the known-association bound) under a progress bar,
//! with a summary table, JSON and a figure of GOSPA against time; sharded (`--shard I/N`: a part
//! file of kind `multi-target`) or whole, and the merge of its part files.

use plotters::coord::Shift;
use plotters::prelude::*;
use serde::Serialize;

use scatterloc::chart::{
    curve_chart_size, draw_curves, ChartError, CurveChartOptions, CurveSeries, LineKind, Marker,
};
use scatterloc::native::Parallel;
use scatterloc::study::{
    multi_study_doc, MultiStudy, MultiStudyConfig, MultiStudyDoc, MultiSums, PartFile, PartSet,
    ShardDoc, Timing,
};
use scatterloc::track::multi::people_layout;

use super::io::{emit, emit_summary};
use super::output::{result_outputs, Figure, FigureOut, OutputSet};
use super::parts::PartReader;
use super::shard;
use super::study::{flag_error, load_layout, run_with_bar, threads};
use crate::cli::MontecarloArgs;
use crate::failure::CliError;

/// The single-target flags `--targets` does not take: a usage error naming the first given.
fn refuse_single_target_flags(args: &MontecarloArgs) -> Result<(), CliError> {
    let given = [
        ("--trajectory", args.study.trajectory.is_some()),
        ("--noise-runs", args.noise_runs.is_some()),
        ("--oracle-noise", args.oracle_noise),
        ("--filters", args.filters.is_some()),
        ("--max-cpu-hours", args.max_cpu_hours.is_some()),
    ];
    match given.iter().find(|(_, g)| *g) {
        Some((f, _)) => Err(CliError::usage(format!(
            "{f}: not with --targets (the multi-target study runs pmb and gnn on people walking)"
        ))),
        None => Ok(()),
    }
}

/// The study of the flags (errors name the flags): `--scenario`/`--preset` (default: the people
/// layout, `sensors2019` with a second transmitter), `--targets` walkers, `--runs` (default
/// 100), `--seed`, `--dt` (0.1 s), `--duration` (10 s), `--process-noise` (0.5).
pub fn multi_config(args: &MontecarloArgs, walkers: usize) -> Result<MultiStudyConfig, CliError> {
    refuse_single_target_flags(args)?;
    let s = &args.study;
    let scenario = if s.preset.is_none() && s.scenario.is_none() {
        people_layout()
    } else {
        load_layout(s.preset.as_deref(), s.scenario.as_deref())?.1
    };
    let mut cfg = MultiStudyConfig::new(
        scenario,
        walkers,
        args.runs.unwrap_or(100),
        args.seed.unwrap_or(1),
    );
    if let Some(dt) = s.dt {
        cfg.dt_s = dt;
    }
    if let Some(q) = s.process_noise {
        cfg.process_noise = q;
    }
    let duration = s.duration.unwrap_or(10.0);
    cfg.steps = super::study::checked_steps(duration, cfg.dt_s)?;
    cfg.validate().map_err(flag_error)?;
    Ok(cfg)
}

/// Runs `range` of `cfg` on `threads` threads under the progress bar; Ctrl-C exits 130.
fn run(
    cfg: &MultiStudyConfig,
    range: std::ops::Range<usize>,
    threads: usize,
    label: &str,
) -> Result<(MultiSums, f64), CliError> {
    let (res, wall) = run_with_bar(range.len(), "runs", label, |cancel, progress| {
        MultiStudy::run_range(
            cfg,
            range.clone(),
            &mut Parallel::new(threads, cancel),
            progress,
        )
    })?;
    Ok((res.map_err(flag_error)?, wall))
}

/// `scatterloc montecarlo --targets N`.
pub fn multi_montecarlo(args: &MontecarloArgs, walkers: usize) -> Result<(), CliError> {
    let cfg = multi_config(args, walkers)?;
    let (threads, used) = threads(args.threads)?;
    if let Some(shard) = shard::resolve(&args.shard)? {
        let path = shard::part_path(args.json.as_deref(), args.out.as_deref())?;
        let range = shard.range(cfg.runs);
        let label = format!(
            "{walkers} walkers shard {}/{}",
            shard.index(),
            shard.count()
        );
        let (sums, wall) = run(&cfg, range, threads, &label)?;
        #[derive(Serialize)]
        struct Counted {
            runs: u64,
        }
        let timing = Timing {
            threads: used,
            wall_time_s: vec![wall],
        };
        let doc = ShardDoc::new(shard, "runs", cfg.runs);
        let part = PartFile::new("multi-target", &cfg, &doc, &timing, &sums);
        return shard::write_part(&path, &part, &Counted { runs: sums.runs });
    }
    let (figure, json) = result_outputs(args.out.as_deref(), args.json.as_deref())?;
    let (sums, wall) = run(&cfg, 0..cfg.runs, threads, &format!("{walkers} walkers"))?;
    write_result(&multi_study_doc(&cfg, &sums), wall, used, json, figure)
}

/// `scatterloc merge` of `multi-target` parts.
pub fn merge_multi(
    set: &PartSet,
    mut reader: PartReader,
    json: &str,
    out: Option<&str>,
) -> Result<(), CliError> {
    let (cfg, sums, wall, threads) = MultiStudy::merge(set, &mut |p| reader.load(p))
        .map_err(|e| CliError::usage(e.to_string()))?;
    let (figure, json) = result_outputs(out, Some(json))?;
    write_result(&multi_study_doc(&cfg, &sums), wall, threads, json, figure)
}

/// The `--json` document: the study's result with the run's wall time and threads.
#[derive(Serialize)]
struct Doc<'a> {
    #[serde(flatten)]
    result: &'a MultiStudyDoc,
    threads: usize,
    wall_time_s: f64,
}

struct GospaFigure<'a> {
    series: Vec<CurveSeries<'a>>,
    opts: CurveChartOptions,
}

impl Figure for GospaFigure<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), ChartError> {
        draw_curves(root, &self.series, &self.opts)
    }
}

fn write_result(
    d: &MultiStudyDoc,
    wall: f64,
    used: usize,
    json: Option<&str>,
    figure: FigureOut,
) -> Result<(), CliError> {
    let mut files = OutputSet::new();
    if let Some(p) = json {
        files.json(
            "json",
            p,
            &Doc {
                result: d,
                threads: used,
                wall_time_s: wall,
            },
        )?;
    }
    let xy: Vec<Vec<(f64, f64)>> = d
        .methods
        .iter()
        .map(|m| {
            d.t_s
                .iter()
                .copied()
                .zip(m.mean_gospa_m.iter().copied())
                .collect()
        })
        .chain(std::iter::once(
            d.t_s
                .iter()
                .zip(&d.bound_m)
                .map(|(t, b)| (*t, b.unwrap_or(f64::NAN)))
                .collect(),
        ))
        .collect();
    if let Some((p, format)) = figure {
        let labels = [
            format!(
                "PMB (BP) mean GOSPA, {:.4} m",
                d.methods[0].mean_gospa_over_run_m
            ),
            format!(
                "GNN mean GOSPA, {:.4} m",
                d.methods[1].mean_gospa_over_run_m
            ),
            "known-association bound √Σ tr PCRLB".into(),
        ];
        let styles = [
            (0, LineKind::Solid, Marker::None),
            (1, LineKind::Dashed, Marker::None),
            (2, LineKind::Dashed, Marker::Dot),
        ];
        let series = xy
            .iter()
            .zip(labels)
            .zip(styles)
            .map(|((pts, label), (colour, line, marker))| CurveSeries {
                label,
                points: pts,
                colour,
                line,
                marker,
            })
            .collect();
        // The axis shows the tracking after the first second (3× its largest value); the
        // start-up transient above it is clipped (its values are in the JSON).
        let hi = xy
            .iter()
            .flatten()
            .filter(|p| p.0 >= 1.0 || d.t_s.len() <= 10)
            .map(|p| p.1)
            .filter(|v| v.is_finite())
            .fold(1e-6, f64::max)
            * 3.0;
        let c = &d.config;
        let opts = CurveChartOptions {
            title: format!(
                "{} walkers — GOSPA against time, {} runs",
                c.walkers, d.runs
            ),
            subtitle: Some(format!(
                "{} · c = {} m, p = 2 · P_D = {} · {} clutter/link/scan · seed {}",
                c.scenario.name,
                c.gospa_c,
                c.settings.detection_probability,
                c.settings.clutter,
                c.seed
            )),
            x_desc: "time (s)".into(),
            y_desc: "GOSPA (m)".into(),
            x_range: (0.0, d.t_s.last().copied().unwrap_or(1.0).max(1e-9)),
            y_range: (0.0, hi),
            legend: SeriesLabelPosition::UpperRight,
        };
        files.figure(
            "out",
            p,
            format,
            curve_chart_size(),
            &GospaFigure { series, opts },
        )?;
    }
    let written = !files.is_empty();
    files.commit()?;
    let mut t = format!(
        "{} walkers, {} runs, {} scans of {} s; GOSPA c = {} m, p = 2\n",
        d.config.walkers, d.runs, d.config.steps, d.config.dt_s, d.config.gospa_c
    );
    t.push_str("method  mean GOSPA (m)  card. err after 1 s  loc./bound after 1 s  switches/run  crossing kept\n");
    for m in &d.methods {
        t.push_str(&format!(
            "{:<7} {:>14.5} {:>20.4} {:>21} {:>13.3} {:>14.3}\n",
            m.method,
            m.mean_gospa_over_run_m,
            m.cardinality_error_after_1s,
            m.localisation_over_bound_after_1s
                .map_or("unbounded".to_string(), |v| format!("{v:.3}")),
            m.switches_per_run,
            m.crossing_kept
        ));
    }
    t.push_str(&format!(
        "PMB mean GOSPA {:.1} % below GNN; wall {wall:.2} s on {used} threads",
        d.pmb_below_gnn_pct
    ));
    if written {
        emit_summary(&t)
    } else {
        emit(&t)
    }
}
