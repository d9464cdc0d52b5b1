//! `scatterloc montecarlo`: the EKF against its posterior CRLB ([S] §5.2, spec §9.5, Fig. 3 of
//! §10), and `scatterloc pcrlb`: the bound alone, at the nominal path (check 9) or with `E[F̃]`
//! over truth trajectories (check 10).

use serde::Serialize;

use scatterloc::chart::TrackingChartOptions;
use scatterloc::track::nominal_pcrlb_rmse;
use scatterloc::track::paper_initial_covariance;

use super::report::{which, CurveDoc, Outputs};
use super::study::{flag_error, parse_study, run_pcrlb_with_progress, run_with_progress, threads};
use crate::cli::{MontecarloArgs, PcrlbArgs};
use crate::CliError;

/// Scalars of one Monte Carlo study, after the curves in the JSON file and in the summary.
#[derive(Serialize)]
struct McMeta {
    /// EKF runs counted (`trajectories × noise_runs − failed_runs`).
    runs: usize,
    seed: u64,
    trajectory: &'static str,
    dt_s: f64,
    noise_runs: usize,
    trajectories: usize,
    failed_runs: usize,
    wall_time_s: f64,
    /// `wall · threads / (runs · steps)`: thread time per EKF step, truth simulation included.
    ns_per_ekf_step: f64,
    /// `wall / (runs · steps)`.
    wall_ns_per_ekf_step: f64,
    threads: usize,
    steps: usize,
    process_noise: f64,
    oracle_noise: bool,
    layout: String,
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
    let outputs = Outputs::parse(args.out.as_deref(), args.json.as_deref())?;

    let mut docs = Vec::new();
    for (t, cfg) in study.trajectories.iter().zip(&configs) {
        let label = format!("scenario {:>3}", t.name());
        let (r, wall) = run_with_progress(&study.model, cfg, threads, &label)?;
        let per_step = 1e9 * wall / (cfg.runs() as f64 * cfg.steps as f64);
        let meta = McMeta {
            runs: r.runs,
            seed,
            trajectory: t.name(),
            dt_s: cfg.motion.dt_s,
            noise_runs,
            trajectories: runs,
            failed_runs: r.failed_runs,
            wall_time_s: wall,
            ns_per_ekf_step: per_step * used as f64,
            wall_ns_per_ekf_step: per_step,
            threads: used,
            steps: cfg.steps,
            process_noise: cfg.motion.intensity,
            oracle_noise: oracle,
            layout: study.layout.clone(),
        };
        docs.push(CurveDoc {
            t_s: r.t_s,
            rmse_ekf_m: Some(r.rmse_ekf_m),
            rmse_pcrlb_m: r.rmse_pcrlb_m,
            nees: Some(r.nees),
            caption_note: Some(failed_note(r.failed_runs, r.runs + r.failed_runs)),
            meta,
        });
    }
    let opts = TrackingChartOptions {
        title: format!("EKF vs posterior CRLB — {}", which(&study)),
        subtitle: Some(format!(
            "{runs} trajectories × {noise_runs} noise runs · step T = {} · σq² = {} m²/s³ · seed {seed}",
            study.step_label(),
            study.motion.intensity
        )),
    };
    outputs.finish(&study, &docs, &opts)
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
