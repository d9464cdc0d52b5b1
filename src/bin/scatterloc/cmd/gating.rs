//! `scatterloc calibrate` (spec §4: cluster calibration snapshots into static paths) and
//! `scatterloc simulate-walk` (spec §9.6: the synthetic measurement case's input files), plus
//! the calibration file read by `track --calibration`.

use std::path::Path;

use scatterloc::formats::{CalibrationResult, CalibrationSnapshots, Measurements, RawStep, Truth};
use scatterloc::track::gating::{default_channel, Calibration, ClusterConfig, StaticChannel};
use scatterloc::track::gating::{LoopPath, LOOP_DURATION_S};
use scatterloc::track::paper_initial_covariance;
use scatterloc::track::ConstantVelocity;
use scatterloc::{measure, Model};

use super::io::{emit_json, model_of, one_stdin, read_json_file, read_scenario};
use super::output::{check_writable, write_json_file, Format, OutputSet};
use super::study::{checked_steps, flag_error};
use crate::cli::{CalibrateArgs, SimulateWalkArgs, WalkStart};
use crate::failure::CliError;

/// Reads `--calibration` for a model.
pub fn read_calibration(path: &str, model: &Model) -> Result<Calibration, CliError> {
    let f: CalibrationResult = read_json_file("calibration", path)?;
    f.into_calibration(model.link_count())
        .map_err(|e| CliError::usage(format!("--calibration {path}: {e}")))
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
    let mut cfg = ClusterConfig::for_bandwidth(scenario.radio.bandwidth_hz)
        .map_err(|e| CliError::usage(format!("--scenario: {e}")))?;
    if let Some(g) = args.gap_s {
        cfg.gap_s = g;
    }
    if let Some(f) = args.min_fraction {
        cfg.min_fraction = f;
    }
    if let Some(s) = args.sigma_floor_s {
        cfg.sigma_floor_s = s;
    }
    cfg.validate().map_err(|e| {
        let text = e.to_string();
        let flag = if text.contains("gap_s") {
            "--gap-s"
        } else if text.contains("min_fraction") {
            "--min-fraction"
        } else {
            "--sigma-floor-s"
        };
        CliError::usage(format!("{flag}: {e}"))
    })?;
    let path = args.snapshots.as_str();
    let f: CalibrationSnapshots = read_json_file("snapshots", path)?;
    let bad = |e: &dyn std::fmt::Display| CliError::usage(format!("--snapshots {path}: {e}"));
    let cal = f.calibrate(n, &cfg).map_err(|e| bad(&e))?;
    let out = CalibrationResult::of(cal, &cfg, f.snapshots.len());
    match args.out.as_deref() {
        Some(p) => write_json_file("out", p, &out),
        None => emit_json(&out),
    }
}

/// Largest expected number of estimates `simulate-walk` writes: at most 46 bytes each (a
/// `[delay, amplitude]` pair with a comma), so every file it writes stays below the input cap
/// of 256 MiB ([`scatterloc::error::limits::MAX_INPUT_BYTES`]) and `track` can read it.
const MAX_WALK_ESTIMATES: f64 = 5e6;

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
/// [--calibration-snapshots N] [--false-alarms F] [--process-noise Q] [--seed N]`.
pub fn simulate_walk(args: &SimulateWalkArgs) -> Result<(), CliError> {
    let scenario = read_scenario(&args.scenario)?;
    let model = model_of(&scenario)?;
    let dir = args.out_dir.as_str();
    if dir.is_empty() {
        return Err(CliError::usage("--out-dir: the path is empty".to_string()));
    }
    let dt = args.dt.unwrap_or(0.1);
    let q = args.process_noise.unwrap_or(0.1);
    ConstantVelocity::validated(dt, q).map_err(flag_error)?;
    let duration = args.duration.unwrap_or(LOOP_DURATION_S);
    let steps = checked_steps(duration, dt)?;
    let ncal = args.calibration_snapshots.unwrap_or(500);
    if ncal == 0 || ncal > 100_000 {
        return Err(CliError::usage(format!(
            "--calibration-snapshots: {ncal}, 1 … 100000 are allowed"
        )));
    }
    let fa = args.false_alarms.unwrap_or(0.5);
    let seed = args.seed.unwrap_or(1);
    let from_truth = args.start == Some(WalkStart::Truth);
    let channel = default_channel(scenario.radio.bandwidth_hz, fa);
    channel
        .validate()
        .map_err(|e| CliError::usage(format!("--false-alarms: {e}")))?;
    // The files' size: about (static paths + echo + false alarms) estimates per link and step.
    let per_step = model.link_count() as f64 * (2.0 + channel.reflectors_m.len() as f64 + fa);
    let estimates = per_step * (steps + 1) as f64 + per_step * ncal as f64;
    if estimates > MAX_WALK_ESTIMATES {
        return Err(CliError::usage(format!(
            "--duration/--dt/--false-alarms/--calibration-snapshots: about {estimates:.0} \
             estimates would be written, at most {MAX_WALK_ESTIMATES:.0} are allowed"
        )));
    }
    let created = prepare_out_dir(dir)?;
    let walk = Walk {
        model: &model,
        channel: &channel,
        clean: &default_channel(scenario.radio.bandwidth_hz, 0.0),
        ncal,
        seed,
        dt,
        q,
        steps,
        from_truth,
    };
    let written = walk.write(dir);
    if written.is_err() && created {
        // Nothing new is left: the directory made above is removed again (only if empty).
        let _ = std::fs::remove_dir(dir);
    }
    let truth = written?;
    emit_json(&serde_json::json!({
        "steps": steps,
        "calibration_snapshots": ncal,
        "false_alarms": fa,
        "blind_zone_pairs": truth.resolved.iter().flatten().filter(|r| !**r).count(),
        "files": WALK_FILES,
    }))
}

/// The validated settings of one `simulate-walk`.
struct Walk<'a> {
    model: &'a Model,
    /// The channel of the walk (with false alarms).
    channel: &'a StaticChannel,
    /// Calibration of the empty area without false alarms (see the calibration module).
    clean: &'a StaticChannel,
    ncal: usize,
    seed: u64,
    dt: f64,
    q: f64,
    steps: usize,
    from_truth: bool,
}

impl Walk<'_> {
    /// Draws the walk and writes its three files into `dir`, all or none; returns the truth.
    fn write(&self, dir: &str) -> Result<Truth, CliError> {
        let Walk {
            model,
            channel,
            clean,
            ncal,
            seed,
            dt,
            q,
            steps,
            from_truth,
        } = *self;
        let path = LoopPath::default();
        let mut rng = measure::rng(seed, 0);
        let cal_snaps = clean.calibration_snapshots(model, ncal, &mut rng);
        let states = path.states(dt, steps);
        let raw = |snap: Vec<Vec<scatterloc::track::gating::DelayEstimate>>| -> RawStep {
            Measurements::raw_step(&snap)
        };
        // The snapshot at t₀ (drawn either way, so the later ones do not depend on --start).
        let s0 = path.state_at(0.0);
        let first =
            raw(channel.snapshot(model, Some(scatterloc::Vec2::new(s0[0], s0[1])), &mut rng));
        let mut raw_steps = Vec::with_capacity(steps);
        let mut resolved = Vec::with_capacity(steps);
        for s in &states {
            let r = scatterloc::Vec2::new(s[0], s[1]);
            raw_steps.push(raw(channel.snapshot(model, Some(r), &mut rng)));
            resolved.push(
                (0..model.link_count())
                    .map(|p| channel.resolved(model, p, model.network.delay(p, r)))
                    .collect(),
            );
        }
        let p0 = paper_initial_covariance();
        let measurements = Measurements {
            dt_s: dt,
            process_noise: q,
            initial_state: from_truth.then(|| s0.into()),
            initial_covariance: from_truth
                .then(|| std::array::from_fn(|i| std::array::from_fn(|j| p0[(i, j)]))),
            initial_snapshot: (!from_truth).then_some(first),
            sigma_s: None,
            steps: None,
            raw_steps: Some(raw_steps),
        };
        let truth = Truth {
            t_s: (1..=steps).map(|k| k as f64 * dt).collect(),
            states: states.iter().map(|s| (*s).into()).collect(),
            resolved,
        };
        // All three files or none (issue 24).
        let [cal_file, meas_file, truth_file] = WALK_FILES.map(|name| walk_file(dir, name));
        let mut files = OutputSet::new();
        files.json(
            "out-dir",
            &cal_file,
            &CalibrationSnapshots {
                snapshots: cal_snaps,
            },
        )?;
        files.json("out-dir", &meas_file, &measurements)?;
        files.json("out-dir", &truth_file, &truth)?;
        files.commit()?;
        Ok(truth)
    }
}
