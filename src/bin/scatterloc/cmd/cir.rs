//! `scatterloc cir simulate|estimate|track`: the channel front end (issue 25; spec
//! channel-estimation.md). Flags → the library's use cases ([`scatterloc::study::estimate_recording`],
//! [`scatterloc::study::calibrate_estimates`], [`scatterloc::study::cir_track`], the simulator
//! [`scatterloc::channel::simulate_recording`]) → files written all or none.

use scatterloc::channel::{simulate_recording, ChannelScene, Recording};
use scatterloc::error::{limits, Cancel};
use scatterloc::formats::{CalibrationSnapshots, Measurements, Truth};
use scatterloc::native::Parallel;
use scatterloc::present::{estimates_doc, track_doc, track_errors};
use scatterloc::study::{
    calibrate_estimates, cir_track as track_recording, delays_only, estimate_recording,
    CirTrackRequest, DelaySigma, FrontEndConfig, RecordingEstimates, EXTENT_SIGMA_M,
};
use scatterloc::track::gating::{AmplitudeClusterConfig, AssociationRule, Calibration};
use scatterloc::track::ConstantVelocity;
use scatterloc::{npz, Model, Scenario};

use super::filters::filter_kinds;
use super::gating::{prepare_out_dir_for, walk_file};
use super::io::{emit_summary, model_of, read_bytes, read_json_file, read_scenario};
use super::output::{check_writable, Format, OutputSet};
use super::study::{catch_ctrl_c, interrupted, run_with_counter, threads};
use crate::cli::{
    Association, CirEstimateArgs, CirSimulateArgs, CirTrackArgs, FilterName, SigmaSource,
};
use crate::failure::CliError;

/// Default process-noise intensity of `cir track`, m²/s³: a person at 1–2 m/s turning on 2–3 m
/// radii accelerates by up to v²/r ≈ 1–2 m/s².
const DEFAULT_PROCESS_NOISE: f64 = 1.0;

/// Reads the recording `--flag PATH` (.npz, docs/recording.md), checked against `model`.
fn read_recording(flag: &str, path: &str, model: &Model) -> Result<Recording, CliError> {
    let bytes = read_bytes(flag, path, limits::MAX_RECORDING_BYTES)?;
    let bad = |e: &dyn std::fmt::Display| CliError::usage(format!("--{flag} {path}: {e}"));
    // The reader validates what it read (`Recording::validate`); the links against the scenario.
    let rec = npz::read_recording(&bytes).map_err(|e| bad(&e))?;
    rec.link_map(model).map_err(|e| bad(&e))?;
    Ok(rec)
}

/// The front end's settings from the flags (the core's defaults and checks; an error names
/// its flag).
fn front_end(max_paths: Option<usize>, pfa: Option<f64>) -> Result<FrontEndConfig, CliError> {
    FrontEndConfig::with_overrides(max_paths, pfa).map_err(|e| {
        let flag = if e.to_string().contains("p_fa") {
            "--pfa"
        } else {
            "--max-paths"
        };
        CliError::usage(format!("{flag}: {e}"))
    })
}

/// Estimates `rec` on `threads` threads under a progress bar (Ctrl-C: exit 130, nothing
/// written).
fn estimate(
    flag: &str,
    scenario: &Scenario,
    model: &Model,
    rec: &Recording,
    cfg: &FrontEndConfig,
    threads: usize,
) -> Result<RecordingEstimates, CliError> {
    let total = rec.t_s.len() * rec.links.len();
    let (res, _) = run_with_counter(total, "snapshots", flag, |cancel, bar| {
        let progress = |n: usize| bar.inc(n as u64);
        estimate_recording(
            model,
            scenario.radio.bandwidth_hz,
            rec,
            cfg,
            &mut Parallel::new(threads, cancel),
            &progress,
        )
    })?;
    res.map_err(|e| CliError::usage(format!("--{flag}: {e}")))
}

/// The checked output flag `--flag PATH` of `allowed` formats.
fn output(flag: &str, path: &str, allowed: &[Format]) -> Result<Format, CliError> {
    let f = Format::of(flag, path, allowed)?;
    check_writable(flag, path)?;
    Ok(f)
}

/// `scatterloc cir estimate --scenario S --cir REC.npz --out EST.json [--snapshots F]
/// [--measurements F]`.
pub fn cir_estimate(args: &CirEstimateArgs) -> Result<(), CliError> {
    catch_ctrl_c();
    output("out", &args.out, &[Format::Json])?;
    for (flag, p) in [
        ("snapshots", &args.snapshots),
        ("measurements", &args.measurements),
    ] {
        if let Some(p) = p {
            output(flag, p, &[Format::Json])?;
        }
    }
    let q = args.process_noise.unwrap_or(DEFAULT_PROCESS_NOISE);
    if args.process_noise.is_some() && args.measurements.is_none() {
        return Err(CliError::usage(
            "--process-noise: only written to --measurements (not given)",
        ));
    }
    let cfg = front_end(args.front_end.max_paths, args.front_end.pfa)?;
    let (threads, _) = threads(args.front_end.threads)?;
    let scenario = read_scenario(&args.scenario)?;
    let model = model_of(&scenario)?;
    let rec = read_recording("cir", &args.cir, &model)?;
    let measurements = match &args.measurements {
        Some(_) => Some(uniform_dt(&rec.t_s, q)?),
        None => None,
    };
    let est = estimate("cir", &scenario, &model, &rec, &cfg, threads)?;
    let mut files = OutputSet::new();
    files.json("out", &args.out, &estimates_doc(&model, &est, &cfg))?;
    let snaps = est.snapshots();
    if let Some(p) = &args.snapshots {
        let doc = CalibrationSnapshots {
            snapshots: snaps.iter().map(|s| delays_only(s)).collect(),
        };
        files.json("snapshots", p, &doc)?;
    }
    if let (Some(p), Some((dt, q))) = (&args.measurements, measurements) {
        let doc = Measurements {
            dt_s: dt,
            process_noise: q,
            initial_state: None,
            initial_covariance: None,
            initial_snapshot: Some(Measurements::raw_step(&snaps[0])),
            sigma_s: None,
            steps: None,
            raw_steps: Some(
                snaps[1..]
                    .iter()
                    .map(|s| Measurements::raw_step(s))
                    .collect(),
            ),
        };
        files.json("measurements", p, &doc)?;
    }
    files.commit()?;
    let paths: usize = est.paths.iter().flatten().map(Vec::len).sum();
    emit_summary(
        &serde_json::json!({
            "out": args.out,
            "snapshots": est.len(),
            "links": rec.links.len(),
            "paths": paths,
        })
        .to_string(),
    )
}

/// The uniform step of `t_s` (within 1e-6 relative), checked as a CV model with `q`, for
/// `--measurements` (a measurements file has one `dt_s`).
fn uniform_dt(t_s: &[f64], q: f64) -> Result<(f64, f64), CliError> {
    if t_s.len() < 2 {
        return Err(CliError::usage(
            "--measurements: the recording has fewer than 2 snapshots",
        ));
    }
    let dt = (t_s[t_s.len() - 1] - t_s[0]) / (t_s.len() - 1) as f64;
    if let Some(k) = (1..t_s.len()).find(|&k| ((t_s[k] - t_s[k - 1]) - dt).abs() > 1e-6 * dt) {
        return Err(CliError::usage(format!(
            "--measurements: the recording's snapshots are not uniform in time (t_s[{k}] − \
             t_s[{}] = {} s, the mean step is {dt} s); a measurements file has one dt_s",
            k - 1,
            t_s[k] - t_s[k - 1]
        )));
    }
    ConstantVelocity::validated(dt, q)
        .map_err(|e| CliError::usage(format!("--process-noise: {e}")))?;
    Ok((dt, q))
}

/// `scatterloc cir track --scenario S --calibration CAL.npz --cir REC.npz --out TRACK.json`.
pub fn cir_track(args: &CirTrackArgs) -> Result<(), CliError> {
    catch_ctrl_c();
    output("out", &args.out, &[Format::Json])?;
    let figure = match &args.figure {
        Some(p) => Some((
            p.as_str(),
            output("figure", p, &[Format::Svg, Format::Png])?,
        )),
        None => None,
    };
    let delays_figure = match &args.delays_figure {
        Some(p) => Some((
            p.as_str(),
            output("delays-figure", p, &[Format::Svg, Format::Png])?,
        )),
        None => None,
    };
    let name = args.filter.unwrap_or(FilterName::Ekf);
    let kind = filter_kinds(&[name], &args.settings, "--filter")?[0];
    if args.seed.is_some() && name != FilterName::Pf {
        return Err(CliError::usage(
            "--seed: only for the pf filter (--filter is not pf)",
        ));
    }
    let q = args.process_noise.unwrap_or(DEFAULT_PROCESS_NOISE);
    ConstantVelocity::validated(1.0, q)
        .map_err(|e| CliError::usage(format!("--process-noise: {e}")))?;
    let cfg = front_end(args.front_end.max_paths, args.front_end.pfa)?;
    let (threads, _) = threads(args.front_end.threads)?;
    let scenario = read_scenario(&args.scenario)?;
    let model = model_of(&scenario)?;
    let cal_rec = read_recording("calibration", &args.calibration, &model)?;
    let rec = read_recording("cir", &args.cir, &model)?;
    let truth = match &args.truth {
        Some(p) => {
            let t: Truth = read_json_file("truth", p)?;
            t.check_times(&rec.t_s)
                .map_err(|e| CliError::usage(format!("--truth {p}: {e}")))?;
            Some(t)
        }
        None => None,
    };
    let empty = estimate("calibration", &scenario, &model, &cal_rec, &cfg, threads)?;
    let ccfg = AmplitudeClusterConfig::for_bandwidth(scenario.radio.bandwidth_hz)
        .map_err(|e| CliError::usage(format!("--scenario: {e}")))?;
    let calibration: Calibration = calibrate_estimates(&model, &empty, &ccfg)
        .map_err(|e| CliError::usage(format!("--calibration {}: {e}", args.calibration)))?;
    let est = estimate("cir", &scenario, &model, &rec, &cfg, threads)?;
    let sigma = match args.sigma {
        None | Some(SigmaSource::Estimator) => DelaySigma::Estimator,
        Some(SigmaSource::Budget) => DelaySigma::LinkBudget,
    };
    let req = CirTrackRequest {
        model: &model,
        area: &scenario.area_m,
        calibration: &calibration,
        estimates: &est,
        filter: kind,
        process_noise: q,
        rule: match args.association {
            Some(Association::Spec) => AssociationRule::Spec,
            None | Some(Association::Gated) => AssociationRule::Gated,
        },
        sigma,
        extent_sigma_m: args.extent_sigma_m.unwrap_or(EXTENT_SIGMA_M),
        seed: args.seed.unwrap_or(1),
    };
    let (res, _) = run_with_counter(est.len(), "snapshots", "track", |cancel, _| {
        let stop = || cancel.load(std::sync::atomic::Ordering::Relaxed);
        track_recording(&req, Cancel::when(&stop))
    })?;
    let track = res.map_err(|e| CliError::usage(format!("--cir {}: {e}", args.cir)))?;
    // The error view (per snapshot, its statistics and CDF) once, for TRACK.json and --figure.
    let truth_states: Vec<Option<[f64; 4]>> = truth
        .as_ref()
        .map(|t| t.states.iter().map(|s| Some(*s)).collect())
        .unwrap_or_default();
    let view = track_errors(&track.t_s, &track.states, &truth_states)
        .map_err(|e| CliError::usage(format!("--truth: {e}")))?;
    let error = truth.as_ref().and(view.stats);
    let doc = track_doc(
        &track,
        name.name(),
        q,
        sigma,
        &calibration,
        empty.len(),
        error,
    );
    let mut files = OutputSet::new();
    files.json("out", &args.out, &doc)?;
    if let Some((p, f)) = delays_figure {
        super::cir_fig::stage_delays_figure(
            &mut files,
            p,
            f,
            &scenario,
            &model,
            &rec,
            &est,
            &calibration,
            truth.as_ref(),
        )?;
    }
    if let Some((p, f)) = figure {
        super::cir_fig::stage_track_figure(&mut files, p, f, &scenario, &track, view, name.name())?;
    }
    files.commit()?;
    emit_summary(
        &serde_json::json!({
            "out": args.out,
            "snapshots": track.t_s.len(),
            "start": track.start.as_ref().map(|s| s.t_s),
            "error": doc.error,
        })
        .to_string(),
    )
}

/// The files of `cir simulate`.
const SIM_FILES: [&str; 4] = [
    "recording.npz",
    "calibration.npz",
    "truth.json",
    "scene.json",
];

/// Parses `--walk "x,y x,y ..."` (at least two points).
fn parse_walk(text: &str) -> Result<Vec<[f64; 2]>, CliError> {
    let bad = |why: String| CliError::usage(format!("--walk: {why}"));
    let pts = text
        .split_whitespace()
        .enumerate()
        .map(|(i, p)| {
            let (x, y) = p
                .split_once(',')
                .ok_or_else(|| bad(format!("point {i} '{p}' is not x,y")))?;
            let num = |v: &str| {
                v.trim()
                    .parse::<f64>()
                    .ok()
                    .filter(|v| v.is_finite())
                    .ok_or_else(|| bad(format!("point {i} '{p}': '{v}' is not a finite number")))
            };
            Ok([num(x)?, num(y)?])
        })
        .collect::<Result<Vec<_>, CliError>>()?;
    if pts.len() < 2 {
        return Err(bad(format!("{} points, at least 2 are needed", pts.len())));
    }
    Ok(pts)
}

/// `scatterloc cir simulate --scenario S --out-dir DIR [--scene F] [--walk P] [--speed V]
/// [--duration S] [--dt T] [--calibration-duration S] [--seed N]`.
pub fn cir_simulate(args: &CirSimulateArgs) -> Result<(), CliError> {
    catch_ctrl_c();
    let scenario = read_scenario(&args.scenario)?;
    let model = model_of(&scenario)?;
    let mut scene: ChannelScene = match &args.scene {
        Some(p) => read_json_file("scene", p)?,
        None => ChannelScene::hangar(),
    };
    if let Some(w) = &args.walk {
        scene.walk.waypoints_m = parse_walk(w)?;
    }
    if let Some(v) = args.speed {
        scene.walk.speed_mps = v;
    }
    if let Some(d) = args.duration {
        scene.duration_s = Some(d);
    }
    if let Some(dt) = args.dt {
        scene.dt_s = dt;
    }
    let flag_of = |e: &scatterloc::Error| {
        let t = e.to_string();
        if t.contains("walk.waypoints") {
            "--walk"
        } else if t.contains("speed") {
            "--speed"
        } else if t.contains("duration") {
            "--duration"
        } else if t.contains("dt_s") {
            "--dt"
        } else {
            "--scene"
        }
    };
    scene
        .validate()
        .map_err(|e| CliError::usage(format!("{}: {e}", flag_of(&e))))?;
    let mut empty = scene.clone();
    empty.duration_s = Some(args.calibration_duration.unwrap_or(1.0));
    empty
        .validate()
        .map_err(|e| CliError::usage(format!("--calibration-duration: {e}")))?;
    let seed = args.seed.unwrap_or(1);
    let dir = args.out_dir.as_str();
    let created = prepare_out_dir_for(dir, &SIM_FILES)?;
    let written = (|| {
        let fail = |e: scatterloc::Error| CliError::usage(format!("{}: {e}", flag_of(&e)));
        let (rec, truth) =
            simulate_recording(&scenario, &model, &scene, true, seed).map_err(fail)?;
        let (cal, _) = simulate_recording(&scenario, &model, &empty, false, seed).map_err(fail)?;
        let enc = |r: &Recording| {
            npz::write_recording(r).map_err(|e| CliError::output(format!("--out-dir: {e}")))
        };
        if interrupted() {
            return Err(super::study::cancelled());
        }
        let mut files = OutputSet::new();
        let [rec_f, cal_f, truth_f, scene_f] = SIM_FILES.map(|n| walk_file(dir, n));
        files.bytes("out-dir", &rec_f, &enc(&rec)?)?;
        files.bytes("out-dir", &cal_f, &enc(&cal)?)?;
        files.json("out-dir", &truth_f, &truth)?;
        files.json("out-dir", &scene_f, &scene)?;
        files.commit()?;
        Ok::<_, CliError>((rec.t_s.len(), cal.t_s.len()))
    })();
    if written.is_err() && created {
        let _ = std::fs::remove_dir(dir);
    }
    let (snapshots, cal_snapshots) = written?;
    emit_summary(
        &serde_json::json!({
            "snapshots": snapshots,
            "calibration_snapshots": cal_snapshots,
            "links": model.link_count(),
            "subcarriers": scene.subcarriers,
            "files": SIM_FILES,
        })
        .to_string(),
    )
}
