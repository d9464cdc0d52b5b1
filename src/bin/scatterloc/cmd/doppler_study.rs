//! `montecarlo --doppler` (issue 42 §3–4): one filter tracks the same truths with and without
//! the range rates of each scan's CPI against the PCRLB of each (`study::DopplerStudy`,
//! docs/doppler.md "Monte Carlo"). The curves per trajectory as JSON (`--json`), the figure
//! (`--out`: per trajectory the position RMSE beside its bound, delays only and with Doppler),
//! a one-line summary. Progress on stderr; Ctrl-C stops (exit 130, nothing written).

use serde::Serialize;

use scatterloc::chart::{tracking_size, FilterCurve, FiltersPanel, TrackingChartOptions};
use scatterloc::error::Cancel;
use scatterloc::study::{CpiDoc, DopplerResult, DopplerStudy};
use scatterloc::track::{paper_initial_covariance, ConstantVelocity};
use scatterloc::Model;

use super::filters::filter_kinds;
use super::output::{result_outputs, OutputSet};
use super::report::FiltersFigure;
use super::scenario::cpi_of;
use super::study::{flag_error, load_layout, run_with_bar, trajectories_of};
use crate::cli::{FilterName, MontecarloArgs};
use crate::failure::CliError;

/// The scan interval of a Doppler study unless `--dt` is given, s (one CPI per scan).
const DOPPLER_DT_S: f64 = 0.1;
/// Its length unless `--duration` is given, s.
const DOPPLER_DURATION_S: f64 = 3.0;
/// Its process noise unless `--process-noise` is given, m²/s³ (issue 42 §4's q).
const DOPPLER_Q: f64 = 1.0;
/// Its runs unless `--runs` is given.
const DOPPLER_RUNS: usize = 200;

/// One trajectory's result in the JSON.
#[derive(Serialize)]
struct TrajectoryDoc<'a> {
    trajectory: &'static str,
    filter: &'static str,
    runs: usize,
    seed: u64,
    dt_s: f64,
    process_noise: f64,
    cpi: CpiDoc,
    t_s: Vec<f64>,
    #[serde(flatten)]
    result: &'a DopplerResult,
}

/// Flags of the classic study that a Doppler study does not take.
fn refuse_others(args: &MontecarloArgs) -> Result<(), CliError> {
    let given = [
        ("--shard", args.shard.shard.is_some()),
        ("--noise-runs", args.noise_runs.is_some()),
        ("--oracle-noise", args.oracle_noise),
        ("--threads", args.threads.is_some()),
        ("--targets", args.targets.is_some()),
        ("--velocity", args.doppler.velocity != [0.0, 0.0]),
    ];
    match given.iter().find(|(_, g)| *g) {
        Some((flag, _)) => Err(CliError::usage(format!(
            "{flag}: not with --doppler (one filter with and without range rates, sequential)"
        ))),
        None => Ok(()),
    }
}

/// `scatterloc montecarlo --doppler`.
pub fn doppler_montecarlo(args: &MontecarloArgs) -> Result<(), CliError> {
    refuse_others(args)?;
    let s = &args.study;
    let (_, scenario) = load_layout(s.preset.as_deref(), s.scenario.as_deref())?;
    let model = Model::new(&scenario).map_err(|e| super::flags::at_flag("scenario", e))?;
    let trajectories = trajectories_of(s.trajectory);
    let dt = s.dt.unwrap_or(DOPPLER_DT_S);
    let q = s.process_noise.unwrap_or(DOPPLER_Q);
    let motion = ConstantVelocity::validated(dt, q).map_err(flag_error)?;
    let steps = super::study::checked_steps(s.duration.unwrap_or(DOPPLER_DURATION_S), dt)?;
    let names = args
        .filters
        .as_ref()
        .map_or(vec![FilterName::Ekf], |f| f.0.clone());
    if names.len() != 1 {
        return Err(CliError::usage(
            "--filters: one filter with --doppler (it runs with and without range rates)",
        ));
    }
    let filter = filter_kinds(&names, &args.settings, "filters")?[0];
    let cpi = cpi_of(&args.doppler, &scenario)?;
    let runs = args.runs.unwrap_or(DOPPLER_RUNS);
    let seed = args.seed.unwrap_or(1);
    let (figure, json) = result_outputs(args.out.as_deref(), args.json.as_deref())?;
    let studies: Vec<DopplerStudy> = trajectories
        .iter()
        .map(|t| DopplerStudy {
            motion,
            mean_state: t.mean_state(),
            initial_covariance: paper_initial_covariance(),
            cpi,
            steps,
            runs,
            seed,
            filter,
        })
        .collect();
    let total = runs * studies.len();
    let (results, _) = run_with_bar(total, "runs", "doppler", |cancel, progress| {
        let stop = || cancel.load(std::sync::atomic::Ordering::SeqCst);
        let mut out = Vec::with_capacity(studies.len());
        for (k, st) in studies.iter().enumerate() {
            let r = st.run_with(&model, Cancel::when(&stop), &mut |done| {
                progress(k * runs + done, total)
            })?;
            out.push(r);
        }
        Ok(out)
    })?;
    let results = results.map_err(flag_error)?;
    let t_s: Vec<f64> = (0..=steps).map(|k| k as f64 * dt).collect();
    let docs: Vec<TrajectoryDoc> = trajectories
        .iter()
        .zip(&results)
        .map(|(t, r)| TrajectoryDoc {
            trajectory: t.name(),
            filter: filter.name(),
            runs,
            seed,
            dt_s: dt,
            process_noise: q,
            cpi: CpiDoc::from(&cpi),
            t_s: t_s.clone(),
            result: r,
        })
        .collect();
    let mut files = OutputSet::new();
    if let Some((path, format)) = figure {
        let titles: Vec<[String; 2]> = trajectories
            .iter()
            .map(|t| {
                [
                    format!("Scenario {}, delays", t.name()),
                    format!("Scenario {}, delays + Doppler", t.name()),
                ]
            })
            .collect();
        let label = format!("{} RMSE", filter.name().to_uppercase());
        let curves: Vec<[FilterCurve; 2]> = results
            .iter()
            .map(|r| {
                [&r.delay_only, &r.with_doppler].map(|a| FilterCurve {
                    label: &label,
                    rmse_m: &a.position_rmse_m,
                })
            })
            .collect();
        let mut panels = Vec::new();
        for ((r, c), tt) in results.iter().zip(&curves).zip(&titles) {
            for (i, arm) in [&r.delay_only, &r.with_doppler].into_iter().enumerate() {
                panels.push(FiltersPanel {
                    title: &tt[i],
                    t_s: &t_s,
                    curves: core::slice::from_ref(&c[i]),
                    rmse_pcrlb_m: &arm.position_bound_m,
                    legend_note: None,
                });
            }
        }
        let opts = TrackingChartOptions {
            title: "Position RMSE against the PCRLB, without and with Doppler".into(),
            subtitle: Some(format!(
                "{runs} runs, scans {dt} s apart, each a CPI of {} × {} ms, q = {q} m²/s³",
                cpi.snapshots,
                cpi.spacing_s * 1e3
            )),
        };
        let fig = FiltersFigure {
            panels,
            opts: &opts,
        };
        files.figure("out", path, format, tracking_size(fig.panels.len()), &fig)?;
    }
    if super::study::interrupted() {
        return Err(super::study::cancelled());
    }
    match json {
        Some(p) => files.json("json", p, &docs)?,
        None if figure.is_none() => {
            super::io::emit(
                &serde_json::to_string(&docs)
                    .map_err(|e| CliError::output(format!("encoding JSON: {e}")))?,
            )?;
        }
        None => {}
    }
    files.commit()?;
    if json.is_some() || figure.is_some() {
        let end: Vec<serde_json::Value> = docs
            .iter()
            .map(|d| {
                let last = |v: &[f64]| v.last().copied();
                let lastb = |v: &[Option<f64>]| v.last().copied().flatten();
                serde_json::json!({
                    "trajectory": d.trajectory,
                    "end_s": t_s.last(),
                    "position_rmse_m": [last(&d.result.delay_only.position_rmse_m), last(&d.result.with_doppler.position_rmse_m)],
                    "position_pcrlb_m": [lastb(&d.result.delay_only.position_bound_m), lastb(&d.result.with_doppler.position_bound_m)],
                    "velocity_rmse_mps": [last(&d.result.delay_only.velocity_rmse_mps), last(&d.result.with_doppler.velocity_rmse_mps)],
                    "velocity_pcrlb_mps": [lastb(&d.result.delay_only.velocity_bound_mps), lastb(&d.result.with_doppler.velocity_bound_mps)],
                })
            })
            .collect();
        super::io::emit(
            &serde_json::json!({
                "doppler": end,
                "json": json,
                "out": figure.map(|f| f.0),
            })
            .to_string(),
        )?;
    }
    Ok(())
}
