//! `preset`, `crlb` and `locate`: one scenario, one point or one snapshot of delays.

use serde::{Deserialize, Serialize};

use scatterloc::formats::Sigma;
use scatterloc::localize::crlb_at;
use scatterloc::localize::{locate as lm_locate, DelayMeasurements, LmConfig};
use scatterloc::{scenario::presets, Mat2, Vec2};

use super::io::{emit, emit_json, model_of, read_json_file, read_scenario};
use crate::cli::{CrlbArgs, LocateArgs, PresetArgs};
use crate::failure::CliError;

/// A symmetric 2×2 matrix as `[[a, b], [b, c]]` (upper triangle).
fn sym(m: &Mat2) -> [[f64; 2]; 2] {
    [[m[(0, 0)], m[(0, 1)]], [m[(0, 1)], m[(1, 1)]]]
}

/// `scatterloc preset NAME`.
pub fn preset(args: &PresetArgs) -> Result<(), CliError> {
    let s = presets::preset(&args.name).map_err(|e| CliError::usage(e.to_string()))?;
    emit(&s.to_json())
}

/// `scatterloc crlb --scenario S --at X,Y`.
pub fn crlb(args: &CrlbArgs) -> Result<(), CliError> {
    let at = args.at;
    let s = read_scenario(&args.scenario)?;
    let model = model_of(&s)?;
    let r = Vec2::new(at[0], at[1]);
    let pt = crlb_at(&model, r);
    let names = s
        .link_names()
        .map_err(|e| CliError::usage(format!("--scenario: {e}")))?;
    let links: Vec<LinkOut> = names
        .iter()
        .enumerate()
        .map(|(p, (tx, rx))| LinkOut {
            tx,
            rx,
            snr_db: 10.0 * model.snr(p, r).log10(),
            sigma_delay_s: model.sigma_delay(p, r),
            delay_s: model.network.delay(p, r),
        })
        .collect();
    let b = pt.bound;
    let out = CrlbOut {
        position_m: at,
        bounded: b.is_some(),
        sigma_x_m: b.map(|b| b.sigma_x_m),
        sigma_y_m: b.map(|b| b.sigma_y_m),
        rmse_bound_m: b.map(|b| b.rmse_m),
        fim_per_m2: sym(&pt.fisher_per_m2),
        covariance_m2: b.map(|b| sym(&b.covariance_m2)),
        ellipse_1sigma: pt.ellipse().map(|e| EllipseOut {
            semi_major_m: e.semi_major,
            semi_minor_m: e.semi_minor,
            angle_deg: e.angle_rad.to_degrees(),
        }),
        links,
    };
    emit_json(&out)
}

/// Output of `crlb` (keys in this order).
#[derive(Serialize)]
struct CrlbOut<'a> {
    position_m: [f64; 2],
    bounded: bool,
    sigma_x_m: Option<f64>,
    sigma_y_m: Option<f64>,
    rmse_bound_m: Option<f64>,
    fim_per_m2: [[f64; 2]; 2],
    covariance_m2: Option<[[f64; 2]; 2]>,
    ellipse_1sigma: Option<EllipseOut>,
    links: Vec<LinkOut<'a>>,
}

#[derive(Serialize)]
struct EllipseOut {
    semi_major_m: f64,
    semi_minor_m: f64,
    angle_deg: f64,
}

#[derive(Serialize)]
struct LinkOut<'a> {
    tx: &'a str,
    rx: &'a str,
    snr_db: f64,
    sigma_delay_s: f64,
    delay_s: f64,
}

/// The `--delays` file of `locate`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct DelaysFile {
    /// One per link in scenario link order; `null` = no measurement.
    delays_s: Vec<Option<f64>>,
    /// One σ for all links or one per link, s.
    sigma_s: Sigma,
    /// Start of the iteration, m (default: grid search over the area).
    #[serde(default)]
    initial_m: Option<[f64; 2]>,
}

/// `scatterloc locate --scenario S --delays D`.
pub fn locate(args: &LocateArgs) -> Result<(), CliError> {
    let dpath = args.delays.as_str();
    let s = read_scenario(&args.scenario)?;
    let bad = |m: String| CliError::usage(format!("--delays {dpath}: {m}"));
    let d: DelaysFile = read_json_file("delays", dpath)?;
    let model = model_of(&s)?;
    let sigmas = d
        .sigma_s
        .per_link(model.link_count())
        .map_err(|e| bad(e.to_string()))?;
    let m = DelayMeasurements {
        delays_s: &d.delays_s,
        sigmas_s: &sigmas,
    };
    let initial = d.initial_m.map(|p| Vec2::new(p[0], p[1]));
    let rep = lm_locate(&model.network, &m, &LmConfig::default(), initial, &s.area_m)
        .map_err(|e| bad(e.to_string()))?;
    emit_json(&LocateOut {
        position_m: [rep.position.x, rep.position.y],
        covariance_m2: rep.covariance_m2.as_ref().map(sym),
        cost: rep.cost,
        iterations: rep.iterations,
        termination: rep.termination.as_str(),
        converged: rep.termination.converged(),
        links_used: rep.links_used,
        start_m: [rep.start.x, rep.start.y],
    })
}

/// Output of `locate` (keys in this order).
#[derive(Serialize)]
struct LocateOut {
    position_m: [f64; 2],
    covariance_m2: Option<[[f64; 2]; 2]>,
    cost: f64,
    iterations: usize,
    termination: &'static str,
    converged: bool,
    links_used: usize,
    start_m: [f64; 2],
}
