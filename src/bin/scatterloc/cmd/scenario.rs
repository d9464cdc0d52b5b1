//! `preset`, `crlb` and `locate`: one scenario, one point or one snapshot of delays.

use serde::Deserialize;

use scatterloc::formats::Sigma;
use scatterloc::localize::{locate as lm_locate, DelayMeasurements, LmConfig};
use scatterloc::present::{CrlbDoc, FixDoc};
use scatterloc::{scenario::presets, Vec2};

use super::flags::{at_flag, in_file};
use super::io::{emit, emit_json, model_of, one_stdin, read_json_file, read_scenario};
use crate::cli::{CrlbArgs, LocateArgs, PresetArgs};
use crate::failure::CliError;

/// `scatterloc preset NAME`.
pub fn preset(args: &PresetArgs) -> Result<(), CliError> {
    let s = presets::preset(&args.name).map_err(|e| CliError::usage(e.to_string()))?;
    emit(&s.to_json())
}

/// `scatterloc crlb --scenario S --at X,Y`.
pub fn crlb(args: &CrlbArgs) -> Result<(), CliError> {
    let s = read_scenario(&args.scenario)?;
    let model = model_of(&s)?;
    let doc = CrlbDoc::at(&s, &model, args.at).map_err(|e| at_flag("scenario", e))?;
    emit_json(&doc)
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
    one_stdin(&[("scenario", Some(&args.scenario)), ("delays", Some(dpath))])?;
    let s = read_scenario(&args.scenario)?;
    let bad = |m: String| in_file("delays", dpath, m);
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
    emit_json(&FixDoc::from(&rep))
}
