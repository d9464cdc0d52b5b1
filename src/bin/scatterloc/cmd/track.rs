//! `scatterloc track`: flags and files of the library's [`scatterloc::study::track_measurements`]
//! (and its figure). The track: the EKF of spec §6 (S16, S17) over a measurement file — step `n` predicts
//! by `dt_s` with the CV model (E7), then updates with `steps[n−1]` (missing links skipped, none =
//! predict only), `R` fixed from `sigma_s` or from the link budget (E8) at the predicted position.
//! With `raw_steps` (every link's full list of `[delay, amplitude]` estimates) each step is first
//! gated against `--calibration` (E4) and associated (spec §4) before the update.
//! `--filter ukf|pf` runs the UKF or the particle filter instead, in either form: gating and
//! association then use that filter's predicted delays and innovation σ (its sigma points, its
//! weighted particles).
//! `--detections D.jsonl` reads the JSON lines of docs/detections.md instead
//! ([`scatterloc::formats::Detections`], converted to the raw form with `--process-noise`).
//! A file with `steps` may carry range rates (`range_rates_mps`, issue 42 §5): then every step
//! updates with delays and range rates ([`scatterloc::study::TrackRequest::track_with_rates`]),
//! their σ fixed by the file or from a CPI (the file's `cpi`, or `--doppler --cpi ...`, the
//! flags of `crlb --doppler`); `--no-doppler` ignores them.

use scatterloc::error::Cancel;
use scatterloc::formats::{Detections, Measurements, Steps};
use scatterloc::study::{
    score_multi, track_cpu_s, track_doppler_cpu_s, track_measurements_in, track_multi,
    MultiSettings, MultiTruth, TrackRequest, DEFAULT_PROCESS_NOISE,
};
use scatterloc::track::gating::AssociationRule;
use scatterloc::track::multi::MultiKind;

use super::filters::filter_kinds;
use super::flags::{in_file, with_flag};
use super::gating::read_calibration;
use super::io::{emit, model_of, one_stdin, read_input, read_json_file, read_scenario};
use super::output::{check_writable, Format};
use super::study::{cost_refused, run_with_bar};
use super::track_fig::{read_truth, write_track_figure, TrackSeries};
use super::track_people_fig::write_people_figure;
use crate::cli::{Association, FilterName, MultiMethod, TrackArgs};
use crate::failure::CliError;

/// `scatterloc track --scenario S (--measurements M | --detections D) [--calibration C]
/// [--association R]`.
pub fn track(args: &TrackArgs) -> Result<(), CliError> {
    // The input: a measurements file, or detections (JSON lines, turned into one).
    let (flag, mpath) = match (&args.measurements, &args.detections) {
        (Some(m), None) => ("measurements", m.as_str()),
        (None, Some(d)) => ("detections", d.as_str()),
        (Some(_), Some(_)) => {
            return Err(CliError::usage(
                "--measurements/--detections: give one of them, not both",
            ))
        }
        (None, None) => {
            return Err(CliError::usage(
                "--measurements/--detections: give one of them (the delays to track)",
            ))
        }
    };
    if args.process_noise.is_some() && args.detections.is_none() {
        return Err(CliError::usage(
            "--process-noise: only with --detections (a measurements file has its own \
             process_noise)",
        ));
    }
    one_stdin(&[
        ("scenario", Some(&args.scenario)),
        (flag, Some(mpath)),
        ("calibration", args.calibration.as_deref()),
        ("truth", args.truth.as_deref()),
    ])?;
    let figure = match args.out.as_deref() {
        Some(p) => {
            let f = Format::of("out", p, &[Format::Svg, Format::Png])?;
            check_writable("out", p)?;
            Some((p, f))
        }
        None if args.truth.is_some() && args.targets.is_none() => {
            return Err(CliError::usage(
                "--truth: only used with --out (the figure)",
            ))
        }
        None => None,
    };
    multi_flags_need_targets(args)?;
    let name = args.filter.unwrap_or(FilterName::Ekf);
    let kind = filter_kinds(&[name], &args.settings, "--filter")?[0];
    if args.seed.is_some() && name != FilterName::Pf {
        return Err(CliError::usage(
            "--seed: only for the pf filter (--filter is not pf)",
        ));
    }
    let scenario = read_scenario(&args.scenario)?;
    let bad = |e: &dyn std::fmt::Display| in_file(flag, mpath, e);
    let model = model_of(&scenario)?;
    let (m, fields) = match &args.detections {
        None => {
            let text = read_input("measurements", mpath)?;
            Measurements::from_json_with_rates(&text).map_err(|e| parse_error(mpath, &e))?
        }
        Some(_) => (
            {
                let q = args.process_noise.unwrap_or(DEFAULT_PROCESS_NOISE);
                Detections::from_text(&read_input(flag, mpath)?)
                    .and_then(|d| d.to_measurements(&model, q))
                    .map_err(|e| match with_flag(&e) {
                        Some(text) => CliError::usage(text),
                        None => bad(&e),
                    })?
            },
            Default::default(),
        ),
    };
    let n = model.link_count();
    // The range rates of the file, checked, and their σ (issue 42 §5).
    let rates = fields.check(&m, n, model.carrier_hz).map_err(|e| bad(&e))?;
    let file_sigma = rates.as_ref().and_then(|r| r.sigma.fixed());
    doppler_flags(args, rates.is_some(), file_sigma.is_some())?;
    let flags_cpi = super::scenario::cpi_of(&args.doppler, &scenario)?;
    // The rates' σ: the file's fixed σ, else the flags' CPI with --doppler, else the file's
    // CPI, else the flags' default CPI (one rule with Python's `track`).
    let caller_cpi = args.doppler.on.then_some(flags_cpi);
    let rule = match args.association {
        None | Some(Association::Spec) => AssociationRule::Spec,
        Some(Association::Gated) => AssociationRule::Gated,
    };
    let calibration = match args.calibration.as_deref() {
        Some(path) => Some(read_calibration(path, &model)?),
        None => None,
    };
    if args.targets.is_some() {
        return track_several(args, &scenario, &model, &m, calibration.as_ref(), bad);
    }
    if matches!(m.steps(), Ok(Steps::Plain(_)))
        && (args.calibration.is_some() || args.association.is_some())
    {
        return Err(CliError::usage(
            "--calibration/--association: apply to raw_steps only (this file has steps)",
        ));
    }
    let steps = match m.steps() {
        Ok(Steps::Plain(s)) => s.len(),
        Ok(Steps::Raw(r)) => r.len(),
        Err(_) => 0, // reported by the track itself
    };
    // With range rates used, the step of the delay-and-Doppler update.
    let cost = if rates.is_some() && !args.no_doppler {
        track_doppler_cpu_s(kind, n, steps)
    } else {
        track_cpu_s(kind, n, steps)
    };
    cost_refused(
        "track",
        cost,
        1,
        args.max_cpu_hours,
        &format!(
            "the steps of --{flag}, --particles, or use --filter ekf or a scenario with fewer \
             links"
        ),
    )?;
    let req = TrackRequest {
        model: &model,
        area: &scenario.area_m,
        measurements: &m,
        calibration: calibration.as_ref(),
        rule,
        filter: kind,
        // The particle filter draws its particles from stream 0 of `--seed`.
        seed: args.seed.unwrap_or(1),
    };
    // Ctrl-C stops the track within milliseconds (issue 24): exit status 130, nothing written.
    let (res, _) = run_with_bar(steps, "steps", "track", |cancel, _| {
        let stop = || cancel.load(std::sync::atomic::Ordering::Relaxed);
        match &rates {
            Some(r) => req.track_with_rates(
                r.rates_mps,
                r.sigma.noise(caller_cpi, flags_cpi),
                !args.no_doppler,
                Cancel::when(&stop),
            ),
            None => track_measurements_in(&req, Cancel::when(&stop)),
        }
    })?;
    let out = res.map_err(|e| bad(&e))?;
    if let Some((path, format)) = figure {
        let truth = match args.truth.as_deref() {
            Some(t) => Some(read_truth(t, &out.t_s)?),
            None => None,
        };
        let series = TrackSeries {
            t_s: &out.t_s,
            states: &out.states,
            covariances: &out.covariances,
            links_used: &out.links_used,
            link_count: n,
        };
        let how = if out.choices.is_some() {
            format!(
                "raw estimates gated (E4), association {}",
                args.association.unwrap_or(Association::Spec).name()
            )
        } else if out.doppler.as_ref().is_some_and(|d| d.used) {
            "delays and range rates as given".to_string()
        } else {
            "delays as given".to_string()
        };
        let subtitle = format!(
            "{} · {} steps of {} s · {how}",
            scenario.name,
            out.t_s.len(),
            m.dt_s
        );
        write_track_figure(path, format, &series, truth.as_ref(), subtitle)?;
    }
    let text =
        serde_json::to_string(&out).map_err(|e| CliError::output(format!("encoding JSON: {e}")))?;
    emit(&text)
}

/// A measurements file's parse error as every JSON file's (`--measurements PATH: field: …`,
/// as `read_json_file` words it).
fn parse_error(path: &str, e: &scatterloc::Error) -> CliError {
    CliError::usage(format!(
        "--measurements {path}: {}",
        e.to_string().replace(
            "data did not match any variant of untagged enum Sigma",
            "expected a number or a list of numbers (one per link)",
        )
    ))
}

/// The Doppler flags against the file: `--doppler` and `--no-doppler` need range rates in the
/// file and exclude each other; `--doppler` (a CPI) is refused when the file fixes the rates'
/// σ; `--velocity` is not for `track` (the filter estimates the velocity).
fn doppler_flags(args: &TrackArgs, has_rates: bool, fixed_sigma: bool) -> Result<(), CliError> {
    let d = &args.doppler;
    if args.no_doppler && d.on {
        return Err(CliError::usage(
            "--no-doppler: not with --doppler (use the range rates or ignore them)",
        ));
    }
    if d.on && d.velocity != [0.0, 0.0] {
        return Err(CliError::usage(
            "--velocity: not for track (the filter estimates the velocity)",
        ));
    }
    for (flag, given) in [("--doppler", d.on), ("--no-doppler", args.no_doppler)] {
        if given && !has_rates {
            return Err(CliError::usage(format!(
                "{flag}: only for a measurements file with range_rates_mps (this one has none)"
            )));
        }
    }
    if d.on && fixed_sigma {
        return Err(CliError::usage(
            "--doppler: the file fixes range_rate_sigma_mps (the rates' sigma); drop one of them",
        ));
    }
    Ok(())
}

/// The flags of `--targets auto` given without it: a usage error naming them.
fn multi_flags_need_targets(args: &TrackArgs) -> Result<(), CliError> {
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
        ("--figure", args.figure.is_some()),
    ];
    if args.targets.is_some() {
        // The single-target flags do not apply.
        let single = [
            ("--filter", args.filter.is_some()),
            ("--association", args.association.is_some()),
            ("--out", args.out.is_some()),
            ("--seed", args.seed.is_some()),
        ];
        if let Some((f, _)) = single.iter().find(|(_, g)| *g) {
            return Err(CliError::usage(format!(
                "{f}: not with --targets auto (the multi-target tracker has its own settings: \
                 --method, --detection-probability, --clutter, --clutter-window-ns, --birth-rate)"
            )));
        }
        return Ok(());
    }
    match given.iter().find(|(_, g)| *g) {
        Some((f, _)) => Err(CliError::usage(format!(
            "{f}: only with --targets auto (several targets)"
        ))),
        None => Ok(()),
    }
}

/// `track --targets auto`: the library's [`track_multi`] on the file's raw_steps.
fn track_several(
    args: &TrackArgs,
    scenario: &scatterloc::Scenario,
    model: &scatterloc::Model,
    m: &Measurements,
    calibration: Option<&scatterloc::track::gating::Calibration>,
    bad: impl Fn(&dyn std::fmt::Display) -> CliError,
) -> Result<(), CliError> {
    multi_flags_need_targets(args)?;
    let figure = match args.figure.as_deref() {
        Some(p) => {
            let f = Format::of("figure", p, &[Format::Svg, Format::Png])?;
            check_writable("figure", p)?;
            Some((p, f))
        }
        None => None,
    };
    let mut settings = MultiSettings::default();
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
    let scans = m.raw_steps.as_ref().map_or(0, |r| r.len()) + 1;
    let (res, _) = run_with_bar(scans, "scans", "track", |cancel, _| {
        let stop = || cancel.load(std::sync::atomic::Ordering::Relaxed);
        track_multi(
            model,
            &scenario.area_m,
            m,
            calibration,
            &settings,
            Cancel::when(&stop),
        )
    })?;
    let out = res.map_err(|e| match with_flag(&e) {
        Some(text) => CliError::usage(text),
        None => bad(&e),
    })?;
    let mut doc =
        serde_json::to_value(&out).map_err(|e| CliError::output(format!("encoding JSON: {e}")))?;
    let mut truth_read: Option<MultiTruth> = None;
    if let Some(path) = args.truth.as_deref() {
        let truth: &MultiTruth = truth_read.insert(read_json_file("truth", path)?);
        let c = args.gospa_c.unwrap_or(1.0);
        let score = score_multi(&out, truth, c).map_err(|e| match with_flag(&e) {
            Some(text) => CliError::usage(text),
            None => in_file("truth", path, e),
        })?;
        doc["score"] = serde_json::to_value(&score)
            .map_err(|e| CliError::output(format!("encoding JSON: {e}")))?;
    } else if args.gospa_c.is_some() {
        return Err(CliError::usage("--gospa-c: only with --truth (the score)"));
    }
    if let Some((path, format)) = figure {
        write_people_figure(path, format, scenario, &out, truth_read.as_ref())?;
    }
    let text =
        serde_json::to_string(&doc).map_err(|e| CliError::output(format!("encoding JSON: {e}")))?;
    emit(&text)
}
