//! Shared machinery of `montecarlo` and `pcrlb`: the study flags (scenario, trajectories I–III of
//! spec §9.4, step, duration, q̃), the Monte Carlo configuration of §9.5, the parallel run with a
//! progress bar (rate, ETA) on stderr and Ctrl-C cancellation, and the curve values at the
//! reporting times of check 9/10.

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressStyle};
use serde::Serialize;

use scatterloc::native::{run_pcrlb_parallel, Parallel};
use scatterloc::study::{
    check_cost, CurveDoc, FilterResults, FilterStudy, McMeta, MonteCarloStudy, TrackStudy as Study,
    MAX_CPU_S,
};
use scatterloc::track::ConstantVelocity;
use scatterloc::track::{
    step_count, TrackScenario, PAPER_DURATION_S, PAPER_INTENSITY, PAPER_STEP_S,
};
use scatterloc::track::{MonteCarloConfig, MAX_STEPS};
use scatterloc::{scenario::presets, Error, Model, Scenario};

use super::flags::{at_flag, with_flag};
use super::io::read_scenario;
use crate::cli::{StudyArgs, Trajectory};
use crate::failure::CliError;

/// Times at which the summaries report the curves, s (check 9, 10).
pub const REPORT_TIMES_S: [f64; 4] = [1.0, 2.0, 5.0, 10.0];
/// Most worker threads accepted by `--threads`.
const MAX_THREADS: usize = 256;

/// Set by Ctrl-C; the Monte Carlo driver stops after its current wave.
static CANCEL: AtomicBool = AtomicBool::new(false);

/// A core error as a usage error (exit status 2) naming the flag that caused it
/// ([`super::flags::with_flag`]); Ctrl-C is [`cancelled`].
pub fn flag_error(e: Error) -> CliError {
    if matches!(e, Error::Cancelled) {
        return cancelled();
    }
    CliError::usage(with_flag(&e).unwrap_or_else(|| e.to_string()))
}

/// The Ctrl-C outcome: exit status 130, nothing written.
pub fn cancelled() -> CliError {
    CliError {
        message: "cancelled by Ctrl-C; no output files were written".into(),
        code: 130,
    }
}

/// Parses the study flags: `--preset` (default `sensors2019`) or `--scenario`, `--trajectory`
/// (`I`, `II`, `III` or `all`, the default), `--dt`, `--duration`, `--process-noise`.
pub fn parse_study(args: &StudyArgs) -> Result<Study, CliError> {
    let (layout, scenario) = load_layout(args.preset.as_deref(), args.scenario.as_deref())?;
    let trajectories = trajectories_of(args.trajectory);
    let dt = args.dt.unwrap_or(PAPER_STEP_S);
    let q = args.process_noise.unwrap_or(PAPER_INTENSITY);
    let motion = ConstantVelocity::validated(dt, q).map_err(flag_error)?;
    let duration = args.duration.unwrap_or(PAPER_DURATION_S);
    let steps = checked_steps(duration, dt)?;
    new_study(layout, scenario, trajectories, motion, steps)
}

/// The trajectories of `--trajectory` (`I`, `II`, `III`, or `all`, the default).
pub fn trajectories_of(trajectory: Option<Trajectory>) -> Vec<TrackScenario> {
    match trajectory {
        None | Some(Trajectory::All) => TrackScenario::ALL.to_vec(),
        Some(Trajectory::One) => vec![TrackScenario::I],
        Some(Trajectory::Two) => vec![TrackScenario::II],
        Some(Trajectory::Three) => vec![TrackScenario::III],
    }
}

/// The node layout of `--preset NAME` (default `sensors2019`) or `--scenario FILE` (not both):
/// its name (the preset's, or the scenario's `name`) and the validated scenario.
pub fn load_layout(
    preset: Option<&str>,
    scenario: Option<&str>,
) -> Result<(String, Scenario), CliError> {
    match (preset, scenario) {
        (Some(_), Some(_)) => Err(CliError::usage(
            "--preset / --scenario: give one of them, not both",
        )),
        (_, Some(path)) => {
            let s = read_scenario(path)?;
            Ok((s.name.clone(), s))
        }
        (p, None) => {
            let name = p.unwrap_or("sensors2019");
            let s = presets::preset(name).map_err(|e| at_flag("preset", e))?;
            Ok((name.to_string(), s))
        }
    }
}

/// A tracking study of `scenario` named `layout` (model errors name `--scenario`).
pub fn new_study(
    layout: String,
    scenario: Scenario,
    trajectories: Vec<TrackScenario>,
    motion: ConstantVelocity,
    steps: usize,
) -> Result<Study, CliError> {
    Study::new(layout, scenario, trajectories, motion, steps).map_err(|e| at_flag("scenario", e))
}

/// `--threads` (default 0 = all cores) and the number of threads that means.
pub fn threads(threads: Option<usize>) -> Result<(usize, usize), CliError> {
    let n = threads.unwrap_or(0);
    if n > MAX_THREADS {
        return Err(CliError::usage(format!(
            "--threads: {n} is outside the allowed range 0..={MAX_THREADS} (0 = all cores)"
        )));
    }
    let used = if n == 0 {
        rayon::current_num_threads()
    } else {
        n
    };
    Ok((n, used))
}

/// The steps after `t₀` of `--duration` at `--dt` (validated `dt`): `--duration` must be `> 0`
/// and give 1 … [`MAX_STEPS`] steps.
pub fn checked_steps(duration: f64, dt: f64) -> Result<usize, CliError> {
    if duration <= 0.0 {
        return Err(CliError::usage(format!(
            "--duration: must be > 0 s (got {duration})"
        )));
    }
    let steps = step_count(duration, dt);
    if steps == 0 || steps > MAX_STEPS {
        return Err(CliError::usage(format!(
            "--duration / --dt: {duration} s at {dt} s is {steps} steps, outside 1..={MAX_STEPS}"
        )));
    }
    Ok(steps)
}

/// The predicted CPU time of `chunks` of every trajectory of `study` (issue 24,
/// [`FilterStudy::predicted_cpu_s`]) checked against [`MAX_CPU_S`] unless `allow_long`: over it
/// is a usage error (exit status 2) with the predicted time and the flags to change. Returns a
/// note for the progress bar (` · predicted ≈ … on N threads`).
pub fn check_study_cost(
    study: &MonteCarloStudy,
    chunks: &std::ops::Range<usize>,
    threads: usize,
    max_cpu_hours: Option<f64>,
) -> Result<String, CliError> {
    let links = study.track.model.link_count();
    let mut cpu_s = 0.0;
    for k in 0..study.track.trajectories.len() {
        cpu_s += study
            .filter_study(k)
            .map_err(flag_error)?
            .predicted_cpu_s(links, chunks);
    }
    let wall = cpu_s / threads.max(1) as f64;
    cost_refused(
        "montecarlo",
        cpu_s,
        threads,
        max_cpu_hours,
        "--runs, --noise-runs, --duration (or a larger --dt), --particles, fewer --filters or a \
         scenario with fewer links, or split it with --shard",
    )?;
    Ok(format!(
        " · predicted ≈ {} on {threads} threads",
        duration_text(wall)
    ))
}

/// [`check_cost`] of `cpu_s` against `--max-cpu-hours` (default [`MAX_CPU_S`]), as a usage
/// error of command `what` with the predicted time, naming the flags `change` and
/// `--max-cpu-hours`.
pub fn cost_refused(
    what: &str,
    cpu_s: f64,
    threads: usize,
    max_cpu_hours: Option<f64>,
    change: &str,
) -> Result<(), CliError> {
    let cap = match max_cpu_hours {
        None => MAX_CPU_S,
        Some(h) if h > 0.0 && h <= 1e6 => h * 3600.0,
        Some(h) => {
            return Err(CliError::usage(format!(
                "--max-cpu-hours: {h} is outside the allowed range 0 < H <= 1e6"
            )))
        }
    };
    check_cost(what, cpu_s, cap).map_err(|_| {
        CliError::usage(format!(
            "{what}: the work is predicted to take {} of CPU time (≈ {} on {threads} threads), \
             over the cap of {} (--max-cpu-hours {}); lower {change}, or raise --max-cpu-hours \
             to run it anyway (the cost model: docs/benchmarks.md \"Cost model\")",
            duration_text(cpu_s),
            duration_text(cpu_s / threads.max(1) as f64),
            duration_text(cap),
            cap / 3600.0,
        ))
    })
}

/// A duration in words: `12 s`, `3.4 min`, `5.6 h`, `7.8 days`.
pub fn duration_text(s: f64) -> String {
    if s < 60.0 {
        format!("{s:.0} s")
    } else if s < 3600.0 {
        format!("{:.1} min", s / 60.0)
    } else if s < 86_400.0 * 2.0 {
        format!("{:.1} h", s / 3600.0)
    } else {
        format!("{:.1} days", s / 86_400.0)
    }
}

/// Issue 24: a filter whose every run failed is reported on its own — a warning on stderr
/// naming its flag and first failure (the study's other filters keep their results and the exit
/// status stays 0), and the flag in place of the core field in the document's `error`.
pub fn report_failures(label: &str, results: &FilterResults, doc: &mut CurveDoc<McMeta>) {
    for (_, e) in &results.failed {
        let text = with_flag(e).unwrap_or_else(|| e.to_string());
        eprintln!("warning: {label}: {text}; its curve is left out");
        if let (Some(field), Some(filters)) = (e.field(), doc.meta.filters.as_mut()) {
            for (_, f) in filters.0.iter_mut() {
                if let (Some(msg), Some(flag)) = (f.error.as_mut(), super::flags::flag_of(field)) {
                    *msg = msg.replacen(field, flag, 1);
                }
            }
        }
    }
}

/// Installs the Ctrl-C handler (once) that sets the flag every long run asks: from then on
/// Ctrl-C cancels the command (exit status 130, nothing written) instead of killing it. Long
/// runs install it themselves; a command that reads large inputs first (a recording) calls it
/// at its start. A second Ctrl-C leaves at once (nothing has been written yet either way).
pub fn catch_ctrl_c() {
    static HANDLER: std::sync::Once = std::sync::Once::new();
    HANDLER.call_once(|| {
        let _ = ctrlc::set_handler(|| {
            if CANCEL.swap(true, Ordering::SeqCst) {
                std::process::exit(130);
            }
        });
    });
}

/// Whether Ctrl-C was pressed (after a run of [`run_with_bar`], e.g. while a figure is drawn).
pub fn interrupted() -> bool {
    CANCEL.load(Ordering::SeqCst)
}

/// Runs the chunks `chunks` of every filter of `study` ([`FilterStudy::run_range`]) on
/// `threads` threads under one progress bar labelled `label` counting the runs of every
/// filter (drawn only when stderr is a terminal). Ctrl-C stops it: exit status 130. Returns
/// the wall time, s.
pub fn run_filters_with_progress(
    model: &Model,
    study: &mut FilterStudy,
    chunks: std::ops::Range<usize>,
    threads: usize,
    label: &str,
) -> Result<f64, CliError> {
    let runs = study.runs_in(&chunks);
    let ((), wall) = with_progress(runs, "runs", label, |cancel, progress| {
        study.run_range(model, chunks, &mut Parallel::new(threads, cancel), progress)
    })?;
    Ok(wall)
}

/// The Monte Carlo PCRLB alone (truth trajectories only, no EKF) with the same progress bar
/// (counting trajectories) and Ctrl-C handling as [`run_with_progress`].
pub fn run_pcrlb_with_progress(
    model: &Model,
    cfg: &MonteCarloConfig,
    threads: usize,
    label: &str,
) -> Result<(Vec<Option<f64>>, f64), CliError> {
    with_progress(
        cfg.trajectories,
        "trajectories",
        label,
        |cancel, progress| run_pcrlb_parallel(model, cfg, threads, cancel, progress),
    )
}

/// Runs `run` under a progress bar on stderr (`unit` per step, `label` as prefix, rate and ETA)
/// with Ctrl-C cancellation through `run`'s flag: a cancelled run is exit status 130 with no
/// output written. Returns the core result and the wall time, s. Shared by every long CLI
/// study (Monte Carlo, PCRLB, multi-target ROC sweeps).
pub fn run_with_bar<T>(
    total: usize,
    unit: &str,
    label: &str,
    run: impl FnOnce(&AtomicBool, &mut dyn FnMut(usize, usize)) -> scatterloc::Result<T>,
) -> Result<(scatterloc::Result<T>, f64), CliError> {
    run_with_counter(total, unit, label, |cancel, bar| {
        run(cancel, &mut |done, _| bar.set_position(done as u64))
    })
}

/// [`run_with_bar`] whose work advances the bar itself, from any thread (`bar.inc(n)`): for
/// work whose units finish inside the driver's jobs (the snapshots of a recording's links).
pub fn run_with_counter<T>(
    total: usize,
    unit: &str,
    label: &str,
    run: impl FnOnce(&AtomicBool, &ProgressBar) -> scatterloc::Result<T>,
) -> Result<(scatterloc::Result<T>, f64), CliError> {
    catch_ctrl_c();
    let bar = ProgressBar::new(total as u64);
    let style = ProgressStyle::with_template(&format!(
        "{{prefix}} {{elapsed_precise}} [{{wide_bar}}] {{human_pos}}/{{human_len}} {unit} · {{per_sec}} · ETA {{eta}}"
    ))
    .map(|s| s.progress_chars("=> "));
    if let Ok(style) = style {
        bar.set_style(style);
    }
    bar.set_prefix(label.to_string());
    bar.enable_steady_tick(Duration::from_millis(250));
    let t0 = Instant::now();
    let res = run(&CANCEL, &bar);
    let wall = t0.elapsed().as_secs_f64();
    bar.finish_and_clear();
    if CANCEL.load(Ordering::SeqCst) {
        return Err(cancelled());
    }
    Ok((res, wall))
}

/// [`run_with_bar`] with core errors mapped to the study flags ([`flag_error`]).
fn with_progress<T>(
    total: usize,
    unit: &str,
    label: &str,
    run: impl FnOnce(&AtomicBool, &mut dyn FnMut(usize, usize)) -> scatterloc::Result<T>,
) -> Result<(T, f64), CliError> {
    let (res, wall) = run_with_bar(total, unit, label, run)?;
    Ok((res.map_err(flag_error)?, wall))
}

/// The curves at one reporting time.
#[derive(Serialize)]
pub struct AtTime {
    /// `t_n` nearest to the reporting time (step `round(t/T)`), s.
    pub t_s: f64,
    /// `ε_EKF`, m (absent for a bound alone).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rmse_ekf_m: Option<f64>,
    /// `ε_PCRLB`, m (`null` if singular).
    pub rmse_pcrlb_m: Option<f64>,
    /// Average NEES (absent for a bound alone).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub nees: Option<f64>,
}

/// The values at [`REPORT_TIMES_S`] within the run (step `round(t/T)`, as check 9).
pub fn at_report_times(
    t_s: &[f64],
    pcrlb: &[Option<f64>],
    ekf: Option<(&[f64], &[f64])>,
) -> Vec<AtTime> {
    let dt = t_s.get(1).copied().unwrap_or(1.0);
    REPORT_TIMES_S
        .iter()
        .map(|t| (t / dt).round() as usize)
        .filter(|&n| n < t_s.len())
        .map(|n| AtTime {
            t_s: t_s[n],
            rmse_ekf_m: ekf.map(|(e, _)| e[n]),
            rmse_pcrlb_m: pcrlb[n],
            nees: ekf.map(|(_, v)| v[n]),
        })
        .collect()
}
