//! `scatterloc mtl roc`: the §8 experiments (V-A, V-B, V-C) under a progress bar, with a summary
//! table, JSON and a figure; sharded (`--shard I/N`: a part file of the tally of its
//! realisations) or whole, and the merge of its part files.

use super::super::output::{result_outputs, FigureOut};
use super::*;

/// Runs the realisations `range` of `cfg` on `threads` threads under the shared progress bar
/// ([`run_with_bar`]) labelled `label`; Ctrl-C stops it with exit status 130. Returns the tally
/// and the wall time, s.
fn run_with_progress(
    cfg: &ExperimentConfig,
    range: std::ops::Range<usize>,
    threads: usize,
    label: &str,
) -> Result<(Tally, f64), CliError> {
    let (res, wall) = run_with_bar(range.len(), "realisations", label, |cancel, progress| {
        run_experiment_range(cfg, range.clone(), threads, cancel, progress)
    })?;
    Ok((res.map_err(|e| core_error(&e, "mtl roc"))?, wall))
}

#[derive(Serialize)]
struct PointDoc {
    threshold: f64,
    p_d: f64,
    p_fa: f64,
    detections: u64,
    false_alarms: u64,
    estimates: u64,
}

#[derive(Serialize)]
struct CurveDoc {
    method: &'static str,
    #[serde(skip_serializing_if = "Option::is_none")]
    n_u: Option<usize>,
    label: String,
    points: Vec<PointDoc>,
}

/// The `--json` file of `mtl roc`.
#[derive(Serialize)]
struct RocDoc {
    config: RocConfig,
    realisations: usize,
    targets: u64,
    disagreements: u64,
    threads: usize,
    wall_time_s: f64,
    curves: Vec<CurveDoc>,
}

/// The figure of one experiment.
struct RocFigure<'a> {
    series: Vec<CurveSeries<'a>>,
    opts: CurveChartOptions,
}

impl Figure for RocFigure<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), ChartError> {
        draw_curves(root, &self.series, &self.opts)
    }
}

/// The series and axes of the figure of `r`; `xy[c]` holds the points of curve `c`.
fn figure_of<'a>(
    r: &ExperimentResult,
    cfg: &ExperimentConfig,
    xy: &'a [Vec<(f64, f64)>],
) -> RocFigure<'a> {
    let mut series = Vec::new();
    let n_u_colour = |n| cfg.n_u.iter().position(|&x| x == n).unwrap_or(0);
    for (c, pts) in r.curves.iter().zip(xy) {
        let (colour, line, marker) = match (c.spec.method, c.spec.n_u) {
            (Method::SizeRule, n) => (n_u_colour(n.unwrap_or(0)), LineKind::Solid, Marker::Dot),
            (Method::Icb, Some(n)) => (n_u_colour(n), LineKind::None, Marker::Ring),
            (Method::Ppp, _) => (0, LineKind::Solid, Marker::Dot),
            (Method::Icb, None) => (1, LineKind::Solid, Marker::Triangle),
            (Method::Empirical, _) => (2, LineKind::Solid, Marker::Square),
            (Method::Genie, _) => (1, LineKind::Dashed, Marker::Cross),
        };
        series.push(CurveSeries {
            label: c.label.clone(),
            points: pts,
            colour,
            line,
            marker,
        });
    }
    let what = match cfg.experiment {
        Experiment::Va => "Fig. 3 (V-A): ROC over T_e, size rule vs Bayesian MTL (i.c.b)",
        Experiment::Vb => "Fig. 4 (V-B): ROC over T_b, PPP vs i.c.b",
        Experiment::Vc => "Fig. 5 (V-C): missed detection vs T_b, Bayesian MTL vs genie",
    };
    let title = format!(
        "Experiment {} — {} realisations",
        cfg.experiment.name().to_uppercase(),
        r.realisations
    );
    let sweep = match cfg.experiment {
        Experiment::Va => "T_e = 0.5 … 5".to_string(),
        _ => format!("T_e = {}, T_b swept", cfg.t_e),
    };
    let subtitle = Some(format!(
        "{what} · {} targets · {sweep} · seed {}",
        r.targets, cfg.seed
    ));
    let opts = match cfg.experiment {
        Experiment::Vc => {
            let hi = cfg.sweep.last().copied().unwrap_or(1.0).max(1e-9);
            CurveChartOptions {
                title,
                subtitle,
                x_desc: "blocking threshold T_b (nats)".into(),
                y_desc: "missed-detection probability 1 − P_D".into(),
                x_range: (cfg.sweep.first().copied().unwrap_or(0.0).min(hi - 1e-9), hi),
                y_range: (0.0, 1.0),
                legend: SeriesLabelPosition::UpperRight,
            }
        }
        _ => CurveChartOptions::roc(title, subtitle),
    };
    RocFigure { series, opts }
}

/// The summary table: one row per threshold (every point for up to 21 thresholds, else about
/// 21 evenly spaced ones), per curve `P_D` and `P_FA` (V-C: `1 − P_D` and `P_FA`).
fn summary_table(r: &ExperimentResult, cfg: &ExperimentConfig, wall: f64, used: usize) -> String {
    let vc = cfg.experiment == Experiment::Vc;
    let mut t = String::new();
    t.push_str(&format!(
        "experiment {}: {} realisations, {} targets, seed {}, {} thread(s), wall {:.2} s\n",
        cfg.experiment.name(),
        r.realisations,
        r.targets,
        cfg.seed,
        used,
        wall
    ));
    for (i, c) in r.curves.iter().enumerate() {
        t.push_str(&format!("  [{}] {}\n", i + 1, c.label));
    }
    let pd = if vc { "1-P_D" } else { "P_D" };
    t.push_str(&format!("{:>7}", cfg.experiment.swept()));
    for i in 0..r.curves.len() {
        t.push_str(&format!(
            " {:>8} {:>8}",
            format!("{pd}[{}]", i + 1),
            format!("P_FA[{}]", i + 1)
        ));
    }
    t.push('\n');
    let n = cfg.sweep.len();
    let step = n.div_ceil(21).max(1);
    for k in (0..n).filter(|k| k % step == 0 || *k == n - 1) {
        t.push_str(&format!("{:>7.2}", cfg.sweep[k]));
        for c in &r.curves {
            let p = &c.points[k];
            let d = if vc { 1.0 - p.p_d } else { p.p_d };
            t.push_str(&format!(" {d:>8.3} {:>8.3}", p.p_fa));
        }
        t.push('\n');
    }
    if cfg.experiment == Experiment::Va {
        t.push_str(&format!(
            "disagreements between the size rule and Bayesian i.c.b (spec check 6): {}",
            r.disagreements
        ));
    } else {
        t.pop();
    }
    t
}

/// The flags that define an experiment (and its part files' `config`).
struct RocFlags {
    experiment: Experiment,
    realisations: Option<usize>,
    seed: u64,
    exact: bool,
    empirical: bool,
    max_candidates: Option<usize>,
}

/// The validated configuration of `f` (errors name the flags).
fn roc_config(f: &RocFlags) -> Result<ExperimentConfig, CliError> {
    if let Some(n) = f
        .realisations
        .filter(|n| !(1..=MAX_REALISATIONS).contains(n))
    {
        return Err(CliError::usage(format!(
            "--realizations: {n} is outside the allowed range 1..={MAX_REALISATIONS}"
        )));
    }
    if f.experiment == Experiment::Va {
        let only = [("empirical", f.empirical), ("exact", f.exact)];
        if let Some((flag, _)) = only.iter().find(|(_, given)| *given) {
            return Err(CliError::usage(format!(
                "--{flag}: not used with --experiment va (i.c.b only)"
            )));
        }
    }
    RocStudy::config(
        f.experiment,
        f.realisations,
        f.seed,
        f.exact,
        f.empirical,
        f.max_candidates,
    )
    .map_err(|e| core_error(&e, "mtl roc"))
}

/// The validated experiment of `mtl roc`'s flags (errors name the flags); `slurm submit`
/// checks a study with it before submitting (issue 37).
pub fn roc_config_of(args: &RocArgs) -> Result<ExperimentConfig, CliError> {
    let experiment = match args.experiment {
        RocExperiment::Va => Experiment::Va,
        RocExperiment::Vb => Experiment::Vb,
        RocExperiment::Vc => Experiment::Vc,
    };
    roc_config(&RocFlags {
        experiment,
        realisations: args.realizations,
        seed: args.seed.unwrap_or(1),
        exact: args.exact,
        empirical: args.empirical,
        max_candidates: args.max_candidates,
    })
}

/// `scatterloc mtl roc`.
pub fn mtl_roc(args: &RocArgs) -> Result<(), CliError> {
    let cfg = roc_config_of(args)?;
    let experiment = cfg.experiment;
    let (threads, used) = threads(args.threads)?;
    if let Some(shard) = shard::resolve(&args.shard)? {
        let path = shard::part_path(args.json.as_deref(), args.out.as_deref())?;
        let range = shard.range(cfg.realisations);
        let label = format!(
            "experiment {} shard {}/{}",
            experiment.name(),
            shard.index(),
            shard.count()
        );
        let (tally, wall) = run_with_progress(&cfg, range, threads, &label)?;
        #[derive(Serialize)]
        struct Counted {
            realisations: usize,
        }
        let timing = Timing {
            threads: used,
            wall_time_s: vec![wall],
        };
        let doc = ShardDoc::new(shard, "realisations", cfg.realisations);
        let counted = Counted {
            realisations: tally.realisations(),
        };
        let config = RocConfig::of(&cfg);
        let part = PartFile::new("mtl-roc", &config, &doc, &timing, &tally);
        return shard::write_part(&path, &part, &counted);
    }
    let (figure, json) = result_outputs(args.out.as_deref(), args.json.as_deref())?;
    let label = format!("experiment {}", experiment.name());
    let (tally, wall) = run_with_progress(&cfg, 0..cfg.realisations, threads, &label)?;
    write_result(&cfg, &tally.finish(&cfg), wall, used, json, figure)
}

/// `scatterloc merge` of `mtl roc` parts (checked as a set by `merge`): the tallies of every
/// shard added exactly ([`RocStudy::merge`]), then the outputs of the unsharded run.
pub fn merge_roc(
    set: &PartSet,
    mut reader: PartReader,
    json: &str,
    out: Option<&str>,
) -> Result<(), CliError> {
    let (cfg, r, wall, threads) = RocStudy::merge(set, &mut |p| reader.load(p))
        .map_err(|e| CliError::usage(e.to_string()))?;
    let (figure, json) = result_outputs(out, Some(json))?;
    write_result(&cfg, &r, wall, threads, json, figure)
}

/// Writes the outputs of a result: the JSON file, the figure and the summary table on stdout.
fn write_result(
    cfg: &ExperimentConfig,
    r: &ExperimentResult,
    wall: f64,
    used: usize,
    json: Option<&str>,
    figure: FigureOut,
) -> Result<(), CliError> {
    let experiment = cfg.experiment;
    // The JSON and the figure are renamed into place together, or neither (issue 24).
    let mut files = OutputSet::new();
    if let Some(p) = json {
        let doc = RocDoc {
            config: RocConfig::of(cfg),
            realisations: r.realisations,
            targets: r.targets,
            disagreements: r.disagreements,
            threads: used,
            wall_time_s: wall,
            curves: r
                .curves
                .iter()
                .map(|c| CurveDoc {
                    method: c.spec.method.name(),
                    n_u: c.spec.n_u,
                    label: c.label.clone(),
                    points: c
                        .points
                        .iter()
                        .map(|p| PointDoc {
                            threshold: p.threshold,
                            p_d: p.p_d,
                            p_fa: p.p_fa,
                            detections: p.detections,
                            false_alarms: p.false_alarms,
                            estimates: p.estimates,
                        })
                        .collect(),
                })
                .collect(),
        };
        files.json("json", p, &doc)?;
    }
    if let Some((p, format)) = figure {
        let xy: Vec<Vec<(f64, f64)>> = r
            .curves
            .iter()
            .map(|c| {
                c.points
                    .iter()
                    .map(|p| match experiment {
                        Experiment::Vc => (p.threshold, 1.0 - p.p_d),
                        _ => (p.p_fa, p.p_d),
                    })
                    .collect()
            })
            .collect();
        let fig = figure_of(r, cfg, &xy);
        files.figure("out", p, format, curve_chart_size(), &fig)?;
    }
    let files_written = !files.is_empty();
    files.commit()?;
    let table = summary_table(r, cfg, wall, used);
    if files_written {
        emit_summary(&table)
    } else {
        emit(&table)
    }
}
