//! `cir track --targets auto`: several people in a recording (issue 41 §2). The front end of
//! `cir track` (the same flags, statics and estimates) → [`scatterloc::study::cir_track_multi`]
//! with the recording's multi-target settings ([`scatterloc::study::recording_multi_settings`]
//! and the flags) → TRACK.json, with the score against `cir simulate`'s truth (its `others`).

use scatterloc::error::Cancel;
use scatterloc::formats::Truth;
use scatterloc::study::{
    cir_track_multi, recording_multi_settings, score_multi, walkers_truth, MultiTruth,
    RECORDING_EXTENT_SIGMA_M,
};
use scatterloc::track::multi::MultiKind;

use super::super::flags::{in_file, with_flag};
use super::super::io::{emit_summary, model_of, one_stdin, read_json_file, read_scenario};
use super::super::output::{Format, OutputSet};
use super::super::study::{catch_ctrl_c, run_with_counter, threads};
use super::{empty_area, estimate, output, read_recording, request};
use crate::cli::{CirTrackArgs, MultiMethod};
use crate::failure::CliError;

/// The single-target flags given with `--targets auto`: a usage error naming the first.
fn single_flags(args: &CirTrackArgs) -> Result<(), CliError> {
    let s = &args.settings;
    let given = [
        ("--filter", args.filter.is_some()),
        ("--association", args.association.is_some()),
        ("--seed", args.seed.is_some()),
        ("--sigma", args.sigma.is_some()),
        ("--figure", args.figure.is_some()),
        ("--delays-figure", args.delays_figure.is_some()),
        ("--particles", s.particles.is_some()),
        ("--roughening", s.roughening.is_some()),
        ("--pf-bootstrap", s.pf_bootstrap),
        ("--ukf-alpha", s.ukf_alpha.is_some()),
        ("--ukf-beta", s.ukf_beta.is_some()),
        ("--ukf-kappa", s.ukf_kappa.is_some()),
    ];
    match given.iter().find(|(_, g)| *g) {
        Some((f, _)) => Err(CliError::usage(format!(
            "{f}: not with --targets auto (the multi-target tracker has its own settings: \
             --method, --detection-probability, --clutter, --clutter-window-ns, --birth-rate)"
        ))),
        None => Ok(()),
    }
}

/// The multi-target flags given without `--targets auto`: a usage error naming the first.
pub(super) fn multi_flags_need_targets(args: &CirTrackArgs) -> Result<(), CliError> {
    let given = [
        ("--method", args.method.is_some()),
        (
            "--detection-probability",
            args.detection_probability.is_some(),
        ),
        ("--clutter", args.clutter.is_some()),
        ("--clutter-window-ns", args.clutter_window_ns.is_some()),
        ("--birth-rate", args.birth_rate.is_some()),
        ("--gospa-c", args.gospa_c.is_some()),
    ];
    match given.iter().find(|(_, g)| *g) {
        Some((f, _)) => Err(CliError::usage(format!(
            "{f}: only with --targets auto (several people)"
        ))),
        None => Ok(()),
    }
}

/// `cir simulate`'s truth file (`--truth`) as the walkers' truth, checked against the
/// recording's snapshot times.
fn read_truth(path: &str, t_s: &[f64]) -> Result<MultiTruth, CliError> {
    let doc: serde_json::Value = read_json_file("truth", path)?;
    let bad = |e: &dyn std::fmt::Display| CliError::usage(format!("--truth {path}: {e}"));
    let t: Truth = serde_json::from_value(doc.clone()).map_err(|e| bad(&e))?;
    t.check_times(t_s).map_err(|e| in_file("truth", path, e))?;
    let others: Vec<Vec<[f64; 4]>> = match doc.get("others") {
        Some(o) => serde_json::from_value(o.clone()).map_err(|e| bad(&format!("others: {e}")))?,
        None => Vec::new(),
    };
    walkers_truth(&t.t_s, &t.states, &others).map_err(|e| in_file("truth", path, e))
}

/// `scatterloc cir track --targets auto --scenario S --cir REC.npz --out TRACK.json
/// [--calibration CAL.npz] [--truth TRUTH.json] [--method pmb|gnn] …`.
pub(super) fn cir_track_several(args: &CirTrackArgs, cir: &str, out: &str) -> Result<(), CliError> {
    catch_ctrl_c();
    single_flags(args)?;
    one_stdin(&[
        ("scenario", Some(&args.scenario)),
        ("cir", Some(cir)),
        ("calibration", args.calibration.as_deref()),
        ("truth", args.truth.as_deref()),
    ])?;
    output("out", out, &[Format::Json])?;
    if args.gospa_c.is_some() && args.truth.is_none() {
        return Err(CliError::usage("--gospa-c: only with --truth (the score)"));
    }
    let req = request(&args.front_end, Some(args))?;
    let extent = args.extent_sigma_m.unwrap_or(RECORDING_EXTENT_SIGMA_M);
    let (threads, _) = threads(args.front_end.threads)?;
    let scenario = read_scenario(&args.scenario)?;
    let model = model_of(&scenario)?;
    let mut settings = recording_multi_settings(model.link_count());
    if let Some(k) = args.method {
        settings.method = match k {
            MultiMethod::Pmb => MultiKind::Pmb,
            MultiMethod::Gnn => MultiKind::Gnn,
        };
    }
    if let Some(p) = args.detection_probability {
        settings.detection_probability = p;
    }
    if let Some(c) = args.clutter {
        settings.clutter = c;
    }
    if let Some(w) = args.clutter_window_ns {
        settings.clutter_window_s = w * 1e-9;
    }
    if let Some(r) = args.birth_rate {
        settings.birth_rate = r;
    }
    let rec = read_recording("cir", cir, &model, &args.front_end.csi)?;
    let empty = empty_area(
        args.calibration.as_deref(),
        &req,
        &rec,
        &model,
        &args.front_end.csi,
    )?;
    let truth = match &args.truth {
        Some(p) => Some((p.as_str(), read_truth(p, &rec.t_s)?)),
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
        cir_track_multi(
            &model,
            &scenario.area_m,
            &statics.calibration,
            &est,
            &settings,
            req.process_noise,
            extent,
            Cancel::when(&stop),
        )
    })?;
    let track = res.map_err(|e| match with_flag(&e) {
        Some(text) => CliError::usage(text),
        None => in_file("cir", cir, e),
    })?;
    let mut doc = json(&track)?;
    doc["extent_sigma_m"] = serde_json::json!(extent);
    doc["statics"] = serde_json::json!(cfg.statics.name());
    doc["delay_reference"] = serde_json::json!(cfg.delay_reference.name());
    let mut score_summary = serde_json::Value::Null;
    if let Some((path, t)) = &truth {
        let c = args.gospa_c.unwrap_or(1.0);
        let score = score_multi(&track, t, c).map_err(|e| match with_flag(&e) {
            Some(text) => CliError::usage(text),
            None => in_file("truth", path, e),
        })?;
        score_summary = serde_json::json!({
            "mean_gospa_m": score.mean_gospa_m,
            "switches": score.switches,
            "mean_cardinality_error": score.mean_cardinality_error,
        });
        doc["score"] = json(&score)?;
    }
    let mut files = OutputSet::new();
    files.json("out", out, &doc)?;
    files.commit()?;
    emit_summary(
        &serde_json::json!({
            "out": out,
            "snapshots": track.t_s.len(),
            "method": track.method,
            "labels": track.tracks.len(),
            "statics": cfg.statics.name(),
            "delay_reference": cfg.delay_reference.name(),
            "score": score_summary,
        })
        .to_string(),
    )
}

/// `v` as a JSON value; an encoding failure is an output error.
fn json<T: serde::Serialize>(v: &T) -> Result<serde_json::Value, CliError> {
    serde_json::to_value(v).map_err(|e| CliError::output(format!("encoding JSON: {e}")))
}
