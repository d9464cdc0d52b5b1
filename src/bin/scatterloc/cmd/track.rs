//! `scatterloc track`: the EKF of spec §6 (S16, S17) over a measurement file — step `n` predicts
//! by `dt_s` with the CV model (E7), then updates with `steps[n−1]` (missing links skipped, none =
//! predict only), `R` fixed from `sigma_s` or from the link budget (E8) at the predicted position.
//! With `raw_steps` (every link's full list of `[delay, amplitude]` estimates) each step is first
//! gated against `--calibration` (E4) and associated (spec §4) before the update.
//! `--filter ukf|pf` runs the UKF or the particle filter instead, in either form: gating and
//! association then use that filter's predicted delays and innovation σ (its sigma points, its
//! weighted particles).

use serde::Serialize;

use scatterloc::formats::{Measurements, RawStep, Start, Steps};
use scatterloc::math::{Mat4, Vec4};
use scatterloc::measure::rng;
use scatterloc::scenario::Area;
use scatterloc::track::gating::Calibration;
use scatterloc::track::gating::{start_from_snapshot, GatedTracker, START_SPEED_SIGMA_MPS};
use scatterloc::track::gating::{AssociationRule, Choice};
use scatterloc::track::ConstantVelocity;
use scatterloc::track::{Ekf, Filter, MeasurementNoise, Tracker, UpdateSummary};
use scatterloc::{Error, Model};

use super::filters::filter_kinds;
use super::gating::read_calibration;
use super::io::{emit, model_of, read_json_file, read_scenario};
use super::output::{check_writable, Format};
use super::track_fig::{read_truth, write_track_figure, TrackSeries};
use crate::cli::{Association, FilterName, TrackArgs};
use crate::failure::CliError;

/// Output of `track`: one entry per step (after its update).
#[derive(Serialize)]
struct TrackOut {
    t_s: Vec<f64>,
    states: Vec<[f64; 4]>,
    covariances: Vec<[[f64; 4]; 4]>,
    /// NIS `νᵀS⁻¹ν` of the step; `null` when no link was used.
    nis: Vec<Option<f64>>,
    links_used: Vec<usize>,
    /// `raw_steps` only: per step the delay taken per link (`null` = absent), s.
    #[serde(skip_serializing_if = "Option::is_none")]
    delays_used_s: Option<Vec<Vec<Option<f64>>>>,
    /// `raw_steps` only: per step how each link was chosen (absent/single/nearest/strongest).
    #[serde(skip_serializing_if = "Option::is_none")]
    choices: Option<Vec<Vec<&'static str>>>,
    /// `raw_steps` only: per step per link the estimates discarded as static (E4).
    #[serde(skip_serializing_if = "Option::is_none")]
    static_removed: Option<Vec<Vec<usize>>>,
    /// `initial_snapshot` only: the LM fix that started the filter.
    #[serde(skip_serializing_if = "Option::is_none")]
    start: Option<StartOut>,
}

/// The start of a track from `initial_snapshot`.
#[derive(Serialize)]
struct StartOut {
    position_m: [f64; 2],
    covariance_m2: [[f64; 2]; 2],
    termination: &'static str,
    links_used: usize,
    delays_used_s: Vec<Option<f64>>,
    choices: Vec<&'static str>,
}

/// `scatterloc track --scenario S --measurements M [--calibration C] [--association R]`.
pub fn track(args: &TrackArgs) -> Result<(), CliError> {
    let mpath = args.measurements.as_str();
    let figure = match args.out.as_deref() {
        Some(p) => {
            let f = Format::of("out", p, &[Format::Svg, Format::Png])?;
            check_writable("out", p)?;
            Some((p, f))
        }
        None if args.truth.is_some() => {
            return Err(CliError::usage(
                "--truth: only used with --out (the figure)",
            ))
        }
        None => None,
    };
    let name = args.filter.unwrap_or(FilterName::Ekf);
    let kind = filter_kinds(&[name], &args.settings, "--filter")?[0];
    if args.seed.is_some() && name != FilterName::Pf {
        return Err(CliError::usage(
            "--seed: only for the pf filter (--filter is not pf)",
        ));
    }
    let scenario = read_scenario(&args.scenario)?;
    let m: Measurements = read_json_file("measurements", mpath)?;
    let bad = |e: &dyn std::fmt::Display| CliError::usage(format!("--measurements {mpath}: {e}"));
    let model = model_of(&scenario)?;
    let n = model.link_count();
    let motion = m.motion().map_err(|e| bad(&e))?;
    let sigmas = m.sigmas(n).map_err(|e| bad(&e))?;
    let noise = match &sigmas {
        Some(s) => MeasurementNoise::Fixed(s),
        None => MeasurementNoise::AtPrediction,
    };
    let rule = match args.association {
        None | Some(Association::Spec) => AssociationRule::Spec,
        Some(Association::Gated) => AssociationRule::Gated,
    };
    let calibration = match args.calibration.as_deref() {
        Some(path) => Some(read_calibration(path, &model)?),
        None => None,
    };
    let cal = calibration.unwrap_or_else(|| Calibration {
        // No calibration: nothing is static (every estimate is a candidate).
        links: vec![Default::default(); n],
    });
    let (ekf, start) = initial_filter(&m, &model, &cal, &scenario.area_m, &bad)?;
    let steps = m.steps().map_err(|e| bad(&e))?;
    let len = steps.len();
    if matches!(steps, Steps::Plain(_))
        && (args.calibration.is_some() || args.association.is_some())
    {
        return Err(CliError::usage(
            "--calibration/--association: apply to raw_steps only (this file has steps)",
        ));
    }
    let mut out = TrackOut {
        t_s: Vec::with_capacity(len),
        states: Vec::with_capacity(len),
        covariances: Vec::with_capacity(len),
        nis: Vec::with_capacity(len),
        links_used: Vec::with_capacity(len),
        delays_used_s: None,
        choices: None,
        static_removed: None,
        start,
    };
    // The particle filter draws its particles from stream 0 of `--seed`.
    let own = rng(args.seed.unwrap_or(1), 0);
    let filter = Tracker::new(kind, ekf.state, ekf.covariance, own).map_err(|e| bad(&e))?;
    match steps {
        Steps::Plain(steps) => plain(
            &model, filter, &motion, noise, steps, m.dt_s, &mut out, &bad,
        )?,
        Steps::Raw(raw) => {
            let tracker = GatedTracker::new(filter, &model, &cal, motion, noise, rule)
                .map_err(|e| bad(&e))?;
            gated(tracker, n, raw, m.dt_s, &mut out, &bad)?
        }
    }
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

/// The filter at `t₀`: from `initial_state` and `initial_covariance`, or (raw steps only) from
/// the LM fix of `initial_snapshot`, reported as `start`.
fn initial_filter(
    m: &Measurements,
    model: &Model,
    cal: &Calibration,
    area: &Area,
    bad: &dyn Fn(&dyn std::fmt::Display) -> CliError,
) -> Result<(Ekf, Option<StartOut>), CliError> {
    match m.start().map_err(|e| bad(&e))? {
        Start::Given(x0, p0) => Ok((Ekf::new(x0, p0).map_err(|e| bad(&e))?, None)),
        Start::Snapshot(snap) => {
            let snap = Measurements::estimates("initial_snapshot", snap, model.link_count())
                .map_err(|e| bad(&e))?;
            let f = start_from_snapshot(model, cal, &snap, area, START_SPEED_SIGMA_MPS)
                .map_err(|e| bad(&format!("initial_snapshot: {e}")))?;
            let c = &f.ekf.covariance;
            let start = StartOut {
                position_m: [f.report.position.x, f.report.position.y],
                covariance_m2: [[c[(0, 0)], c[(0, 1)]], [c[(1, 0)], c[(1, 1)]]],
                termination: f.report.termination.as_str(),
                links_used: f.report.links_used,
                choices: names(&f.selection.choices),
                delays_used_s: f.selection.delays,
            };
            Ok((f.ekf, Some(start)))
        }
    }
}

/// The names of `choices`.
fn names(choices: &[Choice]) -> Vec<&'static str> {
    choices.iter().map(|c| c.name()).collect()
}

/// A core error of step `field` as the CLI reports it.
fn step_error(field: &str, e: Error, bad: &dyn Fn(&dyn std::fmt::Display) -> CliError) -> CliError {
    match e {
        // `delays_s[p]: …` of the core becomes `steps[k][p]: …`.
        Error::InvalidDelay { .. } => bad(&e.to_string().replacen("delays_s", field, 1)),
        other => bad(&format!("{field}: {other}")),
    }
}

/// The plain form: one delay (or null) per link and step.
#[allow(clippy::too_many_arguments)]
fn plain(
    model: &Model,
    mut filter: Tracker,
    motion: &ConstantVelocity,
    noise: MeasurementNoise,
    steps: &[Vec<Option<f64>>],
    dt_s: f64,
    out: &mut TrackOut,
    bad: &dyn Fn(&dyn std::fmt::Display) -> CliError,
) -> Result<(), CliError> {
    let n = model.link_count();
    for (k, z) in steps.iter().enumerate() {
        let field = format!("steps[{k}]");
        Measurements::check_plain_step(k, z, n).map_err(|e| bad(&e))?;
        filter.predict(motion);
        let summary = filter
            .update(model, z, noise)
            .map_err(|e| step_error(&field, e, bad))?;
        record(out, filter.state(), filter.covariance(), k, dt_s, &summary);
    }
    Ok(())
}

/// The raw form: every step (one list per each of `links` links) gated and associated by
/// `tracker`, with what it chose.
fn gated(
    mut tracker: GatedTracker<Tracker>,
    links: usize,
    raw: &[RawStep],
    dt_s: f64,
    out: &mut TrackOut,
    bad: &dyn Fn(&dyn std::fmt::Display) -> CliError,
) -> Result<(), CliError> {
    let (mut used, mut choices, mut removed) = (vec![], vec![], vec![]);
    for (k, step) in raw.iter().enumerate() {
        let field = format!("raw_steps[{k}]");
        let estimates = Measurements::estimates(&field, step, links).map_err(|e| bad(&e))?;
        let s = tracker
            .step(&estimates)
            .map_err(|e| step_error(&field, e, bad))?;
        let f = &tracker.filter;
        record(out, f.state(), f.covariance(), k, dt_s, &s.summary);
        choices.push(names(&s.selection.choices));
        used.push(s.selection.delays);
        removed.push(s.selection.static_removed);
    }
    out.delays_used_s = Some(used);
    out.choices = Some(choices);
    out.static_removed = Some(removed);
    Ok(())
}

/// Appends step `k`'s filter state `x` and covariance `p` to the output.
fn record(out: &mut TrackOut, x: &Vec4, p: &Mat4, k: usize, dt_s: f64, summary: &UpdateSummary) {
    out.t_s.push((k + 1) as f64 * dt_s);
    out.states.push((*x).into());
    out.covariances
        .push(std::array::from_fn(|i| std::array::from_fn(|j| p[(i, j)])));
    out.nis
        .push((summary.links_used > 0).then_some(summary.nis));
    out.links_used.push(summary.links_used);
}
