//! `scatterloc cir simulate|estimate|track`: the channel front end (issues 25, 36; spec
//! channel-estimation.md). Flags → the core's [`ChannelRequest`] (every default and check is
//! there) → [`scatterloc::study::estimate_recording`] and [`scatterloc::study::cir_track`]
//! (several people with `--targets auto`: `cir_multi`), the simulator
//! [`scatterloc::channel::simulate_recording`] (a scene's further walkers too) → files written
//! all or none.

use scatterloc::channel::{Recording, SimulationRequest};
use scatterloc::error::Cancel;
use scatterloc::formats::{CalibrationSnapshots, Detections, Truth};
use scatterloc::native::Parallel;
use scatterloc::present::{estimates_doc, track_doc, track_errors};
use scatterloc::study::{
    cir_track as track_recording, delays_only, estimate_recording, recording_measurements,
    uniform_step, ChannelRequest, ChannelStatics, DelayReference, FrontEndConfig,
    RecordingEstimates, StaticMode, DEFAULT_PROCESS_NOISE,
};
use scatterloc::track::ConstantVelocity;
use scatterloc::{npz, Model, Scenario};

use super::flags::{at_flag, in_file, renamed, with_flag};
use super::gating::{prepare_out_dir_for, walk_file};
use super::io::{emit_summary, model_of, one_stdin, read_json_file, read_scenario};
use super::output::{check_distinct, check_writable, Format, OutputSet};
use super::study::{catch_ctrl_c, interrupted, run_with_counter, threads};
use crate::cli::{
    Association, CirEstimateArgs, CirSimulateArgs, CirTrackArgs, CsiArgs, FrontEndArgs,
    ReferenceName, SigmaSource, StaticsName,
};
use crate::failure::CliError;

/// `cir track --targets auto` (several people, issue 41).
#[path = "cir_multi.rs"]
mod cir_multi;

/// Reads the recording `--flag PATH` (.npz, docs/recording.md, or a CSI tool's file read as
/// `csi` says), checked against `model`.
pub(super) fn read_recording(
    flag: &str,
    path: &str,
    model: &Model,
    csi: &CsiArgs,
) -> Result<Recording, CliError> {
    Ok(open_recording(flag, path, model, csi)?.recording)
}

/// [`read_recording`] with what a CSI file held (`csi: None` for a `.npz`).
fn open_recording(
    flag: &str,
    path: &str,
    model: &Model,
    csi: &CsiArgs,
) -> Result<scatterloc::csi::Opened, CliError> {
    // The reader validates what it read (`Recording::validate`); the links against the scenario.
    let opened = super::cir_convert::open(flag, path, csi)?;
    opened
        .recording
        .link_map(model)
        .map_err(|e| in_file(flag, path, e))?;
    Ok(opened)
}

/// A core error of the request, named by the flag that sets its field.
pub(super) fn flag_error(e: &scatterloc::Error) -> CliError {
    CliError::usage(with_flag(e).unwrap_or_else(|| e.to_string()))
}

/// The request of the front end's flags (and, for `cir track`, the tracker's), checked by the
/// core.
pub(super) fn request(
    fe: &FrontEndArgs,
    track: Option<&CirTrackArgs>,
) -> Result<ChannelRequest, CliError> {
    let mut r = ChannelRequest::default();
    if let Some(k) = fe.max_paths {
        r.max_paths = k;
    }
    if let Some(p) = fe.pfa {
        r.pfa = p;
    }
    if let Some(s) = fe.statics {
        r.statics = match s {
            StaticsName::Background => StaticMode::Background,
            StaticsName::Clusters => StaticMode::Clusters,
        };
    }
    if let Some(d) = fe.delay_reference {
        r.delay_reference = Some(match d {
            ReferenceName::Absolute => DelayReference::Absolute,
            ReferenceName::Los => DelayReference::Los,
        });
    }
    if let Some(t) = fe.background_time {
        r.background_time_s = t;
    }
    if let Some([a, b]) = fe.calibration_range {
        r.calibration_range_s = Some([a, b]);
    }
    r.cpi_snapshots = fe.cpi_snapshots;
    if let Some(f) = fe.range_rate_floor {
        r.range_rate_floor_mps = f;
    }
    if let Some(t) = track {
        if let Some(f) = t.filter {
            r.filter = f.name().to_string();
        }
        r.ukf_alpha = t.settings.ukf_alpha;
        r.ukf_beta = t.settings.ukf_beta;
        r.ukf_kappa = t.settings.ukf_kappa;
        r.particles = t.settings.particles;
        r.roughening = t.settings.roughening;
        r.bootstrap = t.settings.pf_bootstrap;
        r.seed = t.seed;
        if let Some(q) = t.process_noise {
            r.process_noise = q;
        }
        if let Some(s) = t.sigma {
            r.sigma = match s {
                SigmaSource::Estimator => scatterloc::study::DelaySigma::Estimator,
                SigmaSource::Budget => scatterloc::study::DelaySigma::LinkBudget,
            };
        }
        if let Some(x) = t.extent_sigma_m {
            r.extent_sigma_m = x;
        }
        if let Some(a) = t.association {
            r.association = match a {
                Association::Spec => scatterloc::track::gating::AssociationRule::Spec,
                Association::Gated => scatterloc::track::gating::AssociationRule::Gated,
            };
        }
    }
    r.check().map_err(|e| flag_error(&e))?;
    Ok(r)
}

/// The recording of the empty area: `--calibration CAL.npz`, or the snapshots of the recording
/// in `--calibration-range` (`None`: neither, a recursive background;
/// [`ChannelRequest::empty_area`]).
fn empty_area(
    path: Option<&str>,
    req: &ChannelRequest,
    rec: &Recording,
    model: &Model,
    csi: &CsiArgs,
) -> Result<Option<Recording>, CliError> {
    let file = match path {
        Some(p) => Some(read_recording("calibration", p, model, csi)?),
        None => None,
    };
    req.empty_area(file.as_ref(), rec)
        .map(|c| c.map(std::borrow::Cow::into_owned))
        .map_err(|e| flag_error(&e))
}

/// Statics and estimates of `rec` on `threads` threads under a progress bar (Ctrl-C: exit 130,
/// nothing written). An error names the file it comes from (`files`: the `--cir` path and the
/// `--calibration` path, if any): `--cir PATH: …`, `--calibration PATH: …` (issue 37 item 8:
/// the flag alone, and `--calibration: calibration: …` twice).
fn estimate(
    scenario: &Scenario,
    model: &Model,
    rec: &Recording,
    empty: Option<&Recording>,
    cfg: &FrontEndConfig,
    threads: usize,
    files: (&str, Option<&str>),
) -> Result<(ChannelStatics, RecordingEstimates), CliError> {
    let total = rec.t_s.len() * rec.links.len();
    let (res, _) = run_with_counter(total, "snapshots", "cir", |cancel, bar| {
        let progress = |n: usize| bar.inc(n as u64);
        estimate_recording(
            model,
            scenario.radio.bandwidth_hz,
            rec,
            empty,
            cfg,
            &mut Parallel::new(threads, cancel),
            &progress,
        )
    })?;
    res.map_err(|e| {
        if let Some(text) = with_flag(&e) {
            return CliError::usage(text);
        }
        // The empty area's problems name `calibration…` (the core's field): its file's.
        let calibration = match files.1 {
            Some(path) => format!("--calibration {path}"),
            None => "--calibration".to_string(),
        };
        if let Some(text) = renamed(&e, "calibration", &calibration) {
            return CliError::usage(text);
        }
        // The estimator's input `response` is the recording's array.
        let text = renamed(&e, "response", rec.layout.array()).unwrap_or_else(|| e.to_string());
        in_file("cir", files.0, text)
    })
}

/// The checked output flag `--flag PATH` of `allowed` formats.
fn output(flag: &str, path: &str, allowed: &[Format]) -> Result<Format, CliError> {
    let f = Format::of(flag, path, allowed)?;
    check_writable(flag, path)?;
    Ok(f)
}

/// `scatterloc cir estimate --scenario S --cir REC.npz --out EST.json [--calibration CAL.npz]
/// [--snapshots F] [--measurements F] [--detections-out D.jsonl]`.
pub fn cir_estimate(args: &CirEstimateArgs) -> Result<(), CliError> {
    catch_ctrl_c();
    one_stdin(&[
        ("scenario", Some(&args.scenario)),
        ("cir", Some(&args.cir)),
        ("calibration", args.calibration.as_deref()),
    ])?;
    output("out", &args.out, &[Format::Json])?;
    let mut outputs = vec![("out", args.out.as_str())];
    for (flag, p) in [
        ("snapshots", &args.snapshots),
        ("measurements", &args.measurements),
    ] {
        if let Some(p) = p {
            output(flag, p, &[Format::Json])?;
            outputs.push((flag, p));
        }
    }
    if let Some(p) = &args.detections_out {
        // JSON lines: any name (`.jsonl` by convention).
        check_writable("detections-out", p)?;
        outputs.push(("detections-out", p));
    }
    check_distinct(&outputs)?;
    let q = args.process_noise.unwrap_or(DEFAULT_PROCESS_NOISE);
    if args.process_noise.is_some() && args.measurements.is_none() {
        return Err(CliError::usage(
            "--process-noise: only written to --measurements (not given)",
        ));
    }
    let req = request(&args.front_end, None)?;
    let (threads, _) = threads(args.front_end.threads)?;
    let scenario = read_scenario(&args.scenario)?;
    let model = model_of(&scenario)?;
    let opened = open_recording("cir", &args.cir, &model, &args.front_end.csi)?;
    let rec = opened.recording;
    let empty = empty_area(
        args.calibration.as_deref(),
        &req,
        &rec,
        &model,
        &args.front_end.csi,
    )?;
    // A CSI file: what it held and its direct path per link (C10; issue 40).
    let csi_doc = match &opened.csi {
        Some(summary) => {
            let direct = scatterloc::study::direct_paths(
                &rec,
                scenario.radio.bandwidth_hz,
                Cancel::when(&interrupted),
            )
            .map_err(|e| match e {
                scatterloc::Error::Cancelled => super::study::cancelled(),
                e => in_file("cir", &args.cir, e),
            })?;
            Some((summary.to_json(&rec), direct))
        }
        None => None,
    };
    let measurements = match &args.measurements {
        Some(_) => Some(uniform_dt(&rec.t_s, q)?),
        None => None,
    };
    let cfg = req.front_end(rec.synchronized);
    let (statics, est) = estimate(
        &scenario,
        &model,
        &rec,
        empty.as_ref(),
        &cfg,
        threads,
        (&args.cir, args.calibration.as_deref()),
    )?;
    let mut files = OutputSet::new();
    files.json(
        "out",
        &args.out,
        &estimates_doc(&model, &est, &cfg, &statics),
    )?;
    let snaps = est.snapshots();
    if let Some(p) = &args.snapshots {
        let doc = CalibrationSnapshots {
            snapshots: snaps.iter().map(|s| delays_only(s)).collect(),
        };
        files.json("snapshots", p, &doc)?;
    }
    if let (Some(p), Some((dt, q))) = (&args.measurements, measurements) {
        files.json("measurements", p, &recording_measurements(&snaps, dt, q))?;
    }
    if let Some(p) = &args.detections_out {
        let d = Detections::from_paths(&model.network.links, &est.t_s, &est.recorded, &est.paths);
        files.bytes("detections-out", p, d.to_text().as_bytes())?;
    }
    files.commit()?;
    let paths: usize = est.paths.iter().flatten().map(Vec::len).sum();
    let mut summary = serde_json::json!({
        "out": args.out,
        "snapshots": est.len(),
        "links": rec.links.len(),
        "paths": paths,
        "statics": cfg.statics.name(),
        "delay_reference": cfg.delay_reference.name(),
        "bounds": est.bounds(),
    });
    if let Some((csi, direct)) = csi_doc {
        summary["csi"] = csi;
        summary["direct_path"] = serde_json::to_value(&direct)
            .map_err(|e| CliError::output(format!("encoding JSON: {e}")))?;
    }
    emit_summary(&summary.to_string())
}

/// The uniform step of `t_s` (within 1e-6 relative), checked as a CV model with `q`, for
/// `--measurements` (a measurements file has one `dt_s`).
fn uniform_dt(t_s: &[f64], q: f64) -> Result<(f64, f64), CliError> {
    let dt = uniform_step(t_s)
        .map_err(|e| at_flag("measurements", format_args!("the recording's {e}")))?;
    // `q` is the flag's; the step is the recording's.
    ConstantVelocity::validated(dt, q).map_err(|e| match e.field() {
        Some("dt_s") => at_flag(
            "measurements",
            format_args!("the recording's mean step {e}"),
        ),
        _ => flag_error(&e),
    })?;
    Ok((dt, q))
}

/// `scatterloc cir track --scenario S --cir REC.npz --out TRACK.json [--calibration CAL.npz]`.
pub fn cir_track(args: &CirTrackArgs) -> Result<(), CliError> {
    catch_ctrl_c();
    // Both required by the flags without --follow (`cir_follow::cir_track_follow`).
    let (cir, out) = match (args.cir.as_deref(), args.out.as_deref()) {
        (Some(c), Some(o)) => (c, o),
        _ => {
            return Err(CliError::usage(
                "--cir and --out are required (or --follow)",
            ))
        }
    };
    if args.targets.is_some() {
        return cir_multi::cir_track_several(args, cir, out);
    }
    cir_multi::multi_flags_need_targets(args)?;
    one_stdin(&[
        ("scenario", Some(&args.scenario)),
        ("cir", Some(cir)),
        ("calibration", args.calibration.as_deref()),
        ("truth", args.truth.as_deref()),
    ])?;
    output("out", out, &[Format::Json])?;
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
    let figures = [("figure", figure), ("delays-figure", delays_figure)];
    let outputs: Vec<(&str, &str)> = std::iter::once(("out", out))
        .chain(figures.iter().filter_map(|(f, o)| o.map(|(p, _)| (*f, p))))
        .collect();
    check_distinct(&outputs)?;
    let req = request(&args.front_end, Some(args))?;
    let (threads, _) = threads(args.front_end.threads)?;
    let scenario = read_scenario(&args.scenario)?;
    let model = model_of(&scenario)?;
    let rec = read_recording("cir", cir, &model, &args.front_end.csi)?;
    let empty = empty_area(
        args.calibration.as_deref(),
        &req,
        &rec,
        &model,
        &args.front_end.csi,
    )?;
    let truth = match &args.truth {
        Some(p) => {
            let t: Truth = read_json_file("truth", p)?;
            t.check_times(&rec.t_s)
                .map_err(|e| in_file("truth", p, e))?;
            Some(t)
        }
        None => None,
    };
    let cfg = req.front_end(rec.synchronized);
    let (statics, est) = estimate(
        &scenario,
        &model,
        &rec,
        empty.as_ref(),
        &cfg,
        threads,
        (cir, args.calibration.as_deref()),
    )?;
    let (res, _) = run_with_counter(est.len(), "snapshots", "track", |cancel, _| {
        let stop = || cancel.load(std::sync::atomic::Ordering::Relaxed);
        track_recording(
            &req,
            &model,
            &scenario.area_m,
            &statics.calibration,
            &est,
            Cancel::when(&stop),
        )
    })?;
    let track = res.map_err(|e| in_file("cir", cir, e))?;
    // The error view (per snapshot, its statistics and CDF) once, for TRACK.json and --figure.
    let truth_states: Vec<Option<[f64; 4]>> = truth
        .as_ref()
        .map(|t| t.states.iter().map(|s| Some(*s)).collect())
        .unwrap_or_default();
    let view = track_errors(&track.t_s, &track.states, &truth_states)
        .map_err(|e| at_flag("truth", e))?
        .with_segments(&track)
        .map_err(|e| in_file("cir", cir, e))?;
    let error = truth.as_ref().and(view.stats);
    let doc = track_doc(&track, &req, &cfg, &statics, &est, error).map_err(|e| flag_error(&e))?;
    let mut files = OutputSet::new();
    files.json("out", out, &doc)?;
    if let Some((p, f)) = delays_figure {
        super::cir_fig::stage_delays_figure(
            &mut files,
            p,
            f,
            &scenario,
            &model,
            &rec,
            &est,
            &statics.calibration,
            truth.as_ref(),
        )?;
    }
    if let Some((p, f)) = figure {
        super::cir_fig::stage_track_figure(&mut files, p, f, &scenario, &track, view, doc.filter)?;
    }
    files.commit()?;
    emit_summary(
        &serde_json::json!({
            "out": out,
            "snapshots": track.t_s.len(),
            "start": track.start.as_ref().map(|s| s.t_s),
            "segments": track.segments.len(),
            "statics": cfg.statics.name(),
            "delay_reference": cfg.delay_reference.name(),
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
    let bad = |why: String| at_flag("walk", why);
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
    one_stdin(&[
        ("scenario", Some(&args.scenario)),
        ("scene", args.scene.as_deref()),
    ])?;
    let scenario = read_scenario(&args.scenario)?;
    let model = model_of(&scenario)?;
    let mut req = SimulationRequest {
        scene: match &args.scene {
            Some(p) => Some(read_json_file("scene", p)?),
            None => None,
        },
        walk: args.walk.as_deref().map(parse_walk).transpose()?,
        speed_mps: args.speed,
        duration_s: args.duration,
        dt_s: args.dt,
        ..SimulationRequest::default()
    };
    if let Some(d) = args.calibration_duration {
        req.calibration_duration_s = d;
    }
    if let Some(seed) = args.seed {
        req.seed = seed;
    }
    // A core error names the request's field; the scene's own fields are --scene's.
    let fail =
        |e: scatterloc::Error| with_flag(&e).map_or_else(|| at_flag("scene", e), CliError::usage);
    let (scene, _) = req.scenes().map_err(fail)?;
    let dir = args.out_dir.as_str();
    let created = prepare_out_dir_for(dir, &SIM_FILES)?;
    let written = (|| {
        // Ctrl-C is asked once per snapshot (issue 37 item 13: it took effect only after the
        // whole simulation).
        let stop = interrupted;
        let sim = req
            .run(&scenario, &model, Cancel::when(&stop))
            .map_err(|e| match e {
                scatterloc::Error::Cancelled => super::study::cancelled(),
                e => fail(e),
            })?;
        let truth = sim.truth_file();
        let (rec, cal) = (sim.recording, sim.calibration);
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
