//! `scatterloc calibrate` (spec §4: cluster calibration snapshots into static paths; the flags
//! over the core's [`ClusterConfig`]) and `scatterloc simulate-walk` (spec §9.6: the flags → the
//! core's [`WalkRequest`] → the synthetic measurement case's three input files), plus the
//! calibration file read by `track --calibration`. Core errors name their flag through
//! [`super::flags`].

use std::path::Path;

use scatterloc::formats::{CalibrationResult, CalibrationSnapshots, Measurements, Truth};
use scatterloc::study::{simulate_people, MultiSettings, Walkers};
use scatterloc::track::gating::{Calibration, ClusterConfig, WalkRequest, WalkSimulation};
use scatterloc::track::ConstantVelocity;
use scatterloc::Model;

use super::flags::{at_flag, in_file};
use super::io::{emit_json, model_of, one_stdin, read_json_file, read_scenario};
use super::output::{check_writable, write_json_file, Format, OutputSet};
use super::study::{checked_steps, flag_error};
use crate::cli::{CalibrateArgs, SimulateWalkArgs, WalkStart};
use crate::failure::CliError;

/// Reads `--calibration` for a model.
pub fn read_calibration(path: &str, model: &Model) -> Result<Calibration, CliError> {
    let f: CalibrationResult = read_json_file("calibration", path)?;
    f.into_calibration(model.link_count())
        .map_err(|e| in_file("calibration", path, e))
}

/// `scatterloc calibrate --scenario S --snapshots C [--gap-s G] [--min-fraction F]
/// [--sigma-floor-s S] [--out OUT.json]`.
pub fn calibrate(args: &CalibrateArgs) -> Result<(), CliError> {
    one_stdin(&[
        ("scenario", Some(&args.scenario)),
        ("snapshots", Some(&args.snapshots)),
    ])?;
    // The extension rule of every other output flag (issue 24: `--out cal.txt` wrote JSON).
    if let Some(p) = args.out.as_deref() {
        check_writable("out", p)?;
        Format::of("out", p, &[Format::Json])?;
    }
    let scenario = read_scenario(&args.scenario)?;
    let model = model_of(&scenario)?;
    let n = model.link_count();
    // The clusterer's defaults are the core's (spec §4), for the scenario's bandwidth.
    let mut cfg = ClusterConfig::for_bandwidth(scenario.radio.bandwidth_hz)
        .map_err(|e| at_flag("scenario", e))?;
    if let Some(g) = args.gap_s {
        cfg.gap_s = g;
    }
    if let Some(f) = args.min_fraction {
        cfg.min_fraction = f;
    }
    if let Some(s) = args.sigma_floor_s {
        cfg.sigma_floor_s = s;
    }
    cfg.validate().map_err(flag_error)?;
    let path = args.snapshots.as_str();
    let f: CalibrationSnapshots = read_json_file("snapshots", path)?;
    let cal = f
        .calibrate(n, &cfg)
        .map_err(|e| in_file("snapshots", path, e))?;
    let out = CalibrationResult::of(cal, &cfg, f.snapshots.len());
    match args.out.as_deref() {
        Some(p) => write_json_file("out", p, &out),
        None => emit_json(&out),
    }
}

/// The files `simulate-walk` writes into `--out-dir`, in order.
const WALK_FILES: [&str; 3] = [
    "calibration_snapshots.json",
    "measurements.json",
    "truth.json",
];

/// `--out-dir` must name a directory or a new path: not empty, not an existing file. A missing
/// directory is created here, before the work (bad input, exit status 2, when it cannot be);
/// then every file's target is checked (a link or a FIFO planted at `truth.json` is refused
/// before anything is written; issue 24). Returns whether the directory was created.
fn prepare_out_dir(dir: &str) -> Result<bool, CliError> {
    prepare_out_dir_for(dir, &WALK_FILES)
}

/// [`prepare_out_dir`] for the files `names` of a command.
pub fn prepare_out_dir_for(dir: &str, names: &[&str]) -> Result<bool, CliError> {
    if dir.is_empty() {
        return Err(CliError::usage("--out-dir: the path is empty".to_string()));
    }
    match std::fs::metadata(dir) {
        Ok(meta) if !meta.is_dir() => Err(CliError::usage(format!(
            "--out-dir: '{dir}' exists and is not a directory"
        ))),
        Ok(_) => {
            for name in names {
                check_writable("out-dir", &walk_file(dir, name))?;
            }
            Ok(false)
        }
        Err(_) => std::fs::create_dir_all(dir)
            .map(|()| true)
            .map_err(|e| CliError::usage(format!("--out-dir: cannot create '{dir}': {e}"))),
    }
}

/// The path of `name` in `--out-dir`.
pub fn walk_file(dir: &str, name: &str) -> String {
    Path::new(dir).join(name).to_string_lossy().into_owned()
}

/// `scatterloc simulate-walk --scenario S --out-dir DIR [--duration S] [--dt T]
/// [--calibration-snapshots N] [--false-alarms F] [--process-noise Q] [--seed N]`: the flags
/// → the core's [`WalkRequest`] (every default and check is there) → its three files.
pub fn simulate_walk(args: &SimulateWalkArgs) -> Result<(), CliError> {
    let scenario = read_scenario(&args.scenario)?;
    let model = model_of(&scenario)?;
    let dir = args.out_dir.as_str();
    if dir.is_empty() {
        return Err(CliError::usage("--out-dir: the path is empty".to_string()));
    }
    if args.walkers.is_some() || !args.path.is_empty() {
        return simulate_walkers(args, &scenario, &model);
    }
    if args.detection_probability.is_some() {
        return Err(CliError::usage(
            "--detection-probability: only with --walkers (several people)",
        ));
    }
    let d = WalkRequest::default();
    let req = WalkRequest {
        duration_s: args.duration.unwrap_or(d.duration_s),
        dt_s: args.dt.unwrap_or(d.dt_s),
        process_noise: args.process_noise.unwrap_or(d.process_noise),
        calibration_snapshots: args
            .calibration_snapshots
            .unwrap_or(d.calibration_snapshots),
        false_alarms: args.false_alarms.unwrap_or(d.false_alarms),
        seed: args.seed.unwrap_or(d.seed),
        start_from_truth: args
            .start
            .map_or(d.start_from_truth, |s| s == WalkStart::Truth),
    };
    let bandwidth_hz = scenario.radio.bandwidth_hz;
    // Checked before the directory is made; drawn after. The duration and step count first in
    // the words `montecarlo` and `track` use for them (seconds, and the duration and dt that
    // gave the steps); the core checks them again with everything else.
    ConstantVelocity::validated(req.dt_s, req.process_noise).map_err(flag_error)?;
    checked_steps(req.duration_s, req.dt_s)?;
    req.check(&model, bandwidth_hz).map_err(flag_error)?;
    let created = prepare_out_dir(dir)?;
    let written = req
        .simulate(&model, bandwidth_hz)
        .map_err(flag_error)
        .and_then(|sim| write_walk(dir, sim));
    if written.is_err() && created {
        // Nothing new is left: the directory made above is removed again (only if empty).
        let _ = std::fs::remove_dir(dir);
    }
    let (steps, blind_zone_pairs) = written?;
    emit_json(&serde_json::json!({
        "steps": steps,
        "calibration_snapshots": req.calibration_snapshots,
        "false_alarms": req.false_alarms,
        "blind_zone_pairs": blind_zone_pairs,
        "files": WALK_FILES,
    }))
}

/// Writes the walk's three files into `dir`, all or none; returns its steps and blind-zone
/// pairs.
fn write_walk(dir: &str, sim: WalkSimulation) -> Result<(usize, usize), CliError> {
    let summary = (sim.raw_steps.len(), sim.blind_zone_pairs());
    let measurements = Measurements {
        dt_s: sim.dt_s,
        process_noise: sim.process_noise,
        initial_state: sim.initial_state.map(Into::into),
        initial_covariance: sim.initial_covariance,
        initial_snapshot: sim.initial_snapshot.as_deref().map(Measurements::raw_step),
        sigma_s: None,
        steps: None,
        raw_steps: Some(
            sim.raw_steps
                .iter()
                .map(|s| Measurements::raw_step(s))
                .collect(),
        ),
    };
    let truth = Truth {
        t_s: sim.t_s,
        states: sim.states.iter().map(|s| (*s).into()).collect(),
        resolved: sim.resolved,
    };
    let [cal_file, meas_file, truth_file] = WALK_FILES.map(|name| walk_file(dir, name));
    let mut files = OutputSet::new();
    files.json(
        "out-dir",
        &cal_file,
        &CalibrationSnapshots {
            snapshots: sim.calibration,
        },
    )?;
    files.json("out-dir", &meas_file, &measurements)?;
    files.json("out-dir", &truth_file, &truth)?;
    files.commit()?;
    Ok(summary)
}

/// `simulate-walk --walkers N` or `--path x0,y0,x1,y1 …`: the library's [`simulate_people`]
/// (the planned walkers, or one per drawn path) → measurements.json (raw scans) and truth.json
/// (several labelled targets).
fn simulate_walkers(
    args: &SimulateWalkArgs,
    scenario: &scatterloc::Scenario,
    model: &scatterloc::Model,
) -> Result<(), CliError> {
    let walkers = match (args.walkers, args.path.len()) {
        (Some(n), 0) => Walkers::Count(n),
        (Some(n), k) if n != k => {
            return Err(CliError::usage(format!(
                "--walkers {n}: {k} --path given (--path implies --walkers {k}; leave --walkers out)"
            )));
        }
        _ => Walkers::Drawn(
            args.path
                .iter()
                .map(|p| ([p[0], p[1]], [p[2], p[3]]))
                .collect(),
        ),
    };
    let count = walkers.count();
    if args.calibration_snapshots.is_some() || args.start.is_some() {
        return Err(CliError::usage(
            "--calibration-snapshots/--start: not with --walkers (no static paths are simulated; \
             the multi-target tracker starts its own tracks)",
        ));
    }
    let dt = args.dt.unwrap_or(0.1);
    let duration = args.duration.unwrap_or(10.0);
    let q = args.process_noise.unwrap_or(0.5);
    ConstantVelocity::validated(dt, q).map_err(flag_error)?;
    let steps = checked_steps(duration, dt)? + 1;
    let settings = MultiSettings {
        detection_probability: args.detection_probability.unwrap_or(0.9),
        clutter: args.false_alarms.unwrap_or(5.0),
        ..MultiSettings::default()
    };
    let region = scatterloc::study::walk_region(&scenario.area_m);
    let (m, truth) = simulate_people(
        model,
        &region,
        walkers,
        steps,
        dt,
        q,
        &settings,
        args.seed.unwrap_or(1),
    )
    .map_err(|e| match e.field() {
        // The drawn paths' errors name `paths[i].x0` …: shown after the flag that gave them.
        Some(f) if f.starts_with("paths") => at_flag("path", e),
        _ => flag_error(e),
    })?;
    let dir = args.out_dir.as_str();
    let created = prepare_out_dir(dir)?;
    let mut files = OutputSet::new();
    let written = files
        .json("out-dir", &walk_file(dir, "measurements.json"), &m)
        .and_then(|_| files.json("out-dir", &walk_file(dir, "truth.json"), &truth))
        .and_then(|_| files.commit());
    if written.is_err() && created {
        let _ = std::fs::remove_dir(dir);
    }
    written?;
    emit_json(&serde_json::json!({
        "steps": steps,
        "walkers": count,
        "region_m": {"x": region.x, "y": region.y},
        "detection_probability": settings.detection_probability,
        "clutter_per_link": settings.clutter,
        "clutter_window_s": settings.clutter_window_s,
        "files": ["measurements.json", "truth.json"],
    }))
}
