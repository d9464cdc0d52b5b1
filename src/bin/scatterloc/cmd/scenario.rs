//! `preset`, `crlb` and `locate`: one scenario, one point or one snapshot of delays.

use serde::Deserialize;

use scatterloc::formats::Sigma;
use scatterloc::localize::{locate as lm_locate, locate_free_z, DelayMeasurements, LmConfig};
use scatterloc::math::Vec3;
use scatterloc::measure::Cpi;
use scatterloc::present::{CrlbDoc, CrlbFreeZDoc, DopplerDoc, FixDoc, FixFreeZDoc};
use scatterloc::{scenario::presets, Scenario, Vec2};

use super::flags::{at_flag, in_file};
use super::io::{emit, emit_json, model_of, one_stdin, read_json_file, read_scenario};
use crate::cli::{CrlbArgs, DopplerArgs, LocateArgs, PresetArgs};
use crate::failure::CliError;

/// `scatterloc preset NAME`.
pub fn preset(args: &PresetArgs) -> Result<(), CliError> {
    let s = presets::preset(&args.name).map_err(|e| CliError::usage(e.to_string()))?;
    emit(&s.to_json())
}

/// `scatterloc crlb --scenario S --at X,Y`.
pub fn crlb(args: &CrlbArgs) -> Result<(), CliError> {
    if args.free_z && args.doppler.on {
        return Err(CliError::usage(
            "--doppler: not with --free-z (the bound with Doppler is planar)".to_string(),
        ));
    }
    let s = read_scenario(&args.scenario)?;
    let model = model_of(&s)?;
    if args.free_z {
        let height = args.height.unwrap_or(s.target.height_m);
        return emit_json(&CrlbFreeZDoc::at(&s, &model, args.at, height));
    }
    let doc = CrlbDoc::at(&s, &model, args.at).map_err(|e| at_flag("scenario", e))?;
    if !args.doppler.on {
        return emit_json(&doc);
    }
    let cpi = cpi_of(&args.doppler, &s)?;
    emit_json(&WithDoppler {
        crlb: &doc,
        doppler: DopplerDoc::at(&model, args.at, args.doppler.velocity, &cpi),
    })
}

/// The CPI of the `--doppler` flags on `s`'s carrier; a bad setting is a usage error naming it.
pub(super) fn cpi_of(d: &DopplerArgs, s: &Scenario) -> Result<Cpi, CliError> {
    Cpi::new(
        s.radio.carrier_hz,
        d.cpi,
        d.cpi_spacing_s,
        d.range_rate_floor,
    )
    .map_err(|e| CliError::usage(e.to_string()))
}

/// `crlb --doppler`'s document: `crlb`'s keys, then `doppler`.
#[derive(serde::Serialize)]
struct WithDoppler<'a> {
    #[serde(flatten)]
    crlb: &'a CrlbDoc,
    doppler: DopplerDoc,
}

/// The `--delays` file of `locate`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct DelaysFile {
    /// One per link in scenario link order; `null` = no measurement.
    delays_s: Vec<Option<f64>>,
    /// One σ for all links or one per link, s.
    sigma_s: Sigma,
    /// Start of the iteration, m: [x, y], or [x, y, z] with `--free-z` (default: grid search
    /// over the area, at the scenario's target height).
    #[serde(default)]
    initial_m: Option<Vec<f64>>,
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
    let (cfg, z_t) = (LmConfig::default(), s.target.height_m);
    if args.free_z {
        let initial = match d.initial_m.as_deref() {
            None => None,
            Some(&[x, y]) => Some(Vec3::new(x, y, 0.0)),
            Some(&[x, y, z]) => Some(Vec3::new(x, y, z - z_t)),
            Some(_) => {
                return Err(bad(
                    "initial_m: expected [x, y] or [x, y, z] (metres)".into()
                ))
            }
        };
        let rep = locate_free_z(&model.network, &m, &cfg, initial, &s.area_m)
            .map_err(|e| bad(e.to_string()))?;
        return emit_json(&FixFreeZDoc::new(&rep, z_t));
    }
    let initial = match d.initial_m.as_deref() {
        None => None,
        Some(&[x, y]) => Some(Vec2::new(x, y)),
        Some(_) => {
            return Err(bad(
                "initial_m: expected [x, y] (metres; [x, y, z] needs --free-z)".into(),
            ))
        }
    };
    let rep =
        lm_locate(&model.network, &m, &cfg, initial, &s.area_m).map_err(|e| bad(e.to_string()))?;
    emit_json(&FixDoc::from(&rep))
}
