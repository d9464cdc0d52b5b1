//! `scatterloc mtl …`: the multi-target method of spec `multi-target.md` — `locate` (Algorithm 1
//! on a network and ranges file, §4), `table2` (Table II, §8) and `roc` (the §8 experiments V-A,
//! V-B, V-C with a progress bar, a summary table, JSON and a figure). The math is in
//! `scatterloc::mtl`; this file parses flags, calls it and formats the results.

use std::ffi::OsString;

use plotters::coord::Shift;
use plotters::prelude::*;
use serde::Serialize;

use scatterloc::chart::{
    curve_chart_size, draw_curves, ChartError, CurveChartOptions, CurveSeries, LineKind, Marker,
};
use scatterloc::mtl::algorithm::{locate, MtlConfig};
use scatterloc::mtl::empirical::EmpiricalTable;
use scatterloc::mtl::experiment::{
    EmpiricalTraining, Experiment, ExperimentConfig, ExperimentResult, Method, MAX_REALISATIONS,
};
use scatterloc::mtl::input::{
    from_json, target_reports, ModelSpec, NetworkInput, RangesInput, TargetReport, TrainingSpec,
    DEFAULT_DIAMETER_M, DEFAULT_LAMBDA, DEFAULT_P_D,
};
use scatterloc::mtl::sim::table2::{icb_row, table2_buckets, true_row};
use scatterloc::mtl::sim::{LosModel, NodeLayout, SimSettings, VB_ICB_P_U};
use scatterloc::native::run_experiment_parallel;
use scatterloc::Error;

use crate::commands::{emit, parse_args, read_input};
use crate::output::{check_writable, write_figure, write_json_file, Figure, Format};
use crate::study::{cancelled, run_with_bar, seed, threads};
use crate::CliError;

mod locate;
mod roc;
mod table2;

/// `scatterloc mtl SUBCOMMAND …`.
pub fn mtl(argv: &[OsString]) -> Result<(), CliError> {
    let Some(first) = argv.first() else {
        return Err(CliError::usage(
            "mtl: missing subcommand (locate, table2 or roc)",
        ));
    };
    let rest = &argv[1..];
    match first.to_str().unwrap_or("") {
        "locate" => locate::mtl_locate(rest),
        "table2" => table2::mtl_table2(rest),
        "roc" => roc::mtl_roc(rest),
        "help" | "--help" | "-h" => emit(crate::USAGE.trim_end()),
        other => Err(CliError::usage(format!(
            "mtl: unknown subcommand '{}' (expected locate, table2 or roc)",
            if other.is_empty() {
                first.to_string_lossy()
            } else {
                other.into()
            }
        ))),
    }
}

/// The flag that sets a core field, for messages.
fn flag_of(field: &str) -> Option<&'static str> {
    Some(match field {
        "t_e" => "--te",
        "t_b" => "--tb",
        "b_max" => "--b-max",
        "n_min" => "--n-min",
        "order" => "--order",
        "p_u" => "--p-u",
        "p_d" => "--p-d",
        "p_los" => "--p-los",
        "lambda" => "--lambda",
        "diameter" => "--diameter",
        "scenes" => "--scenes",
        "nx" | "ny" | "nx*ny*patterns" => "--cells",
        "realisations" => "--realizations",
        "threads" => "--threads",
        "draws" => "--draws",
        _ => return None,
    })
}

/// A core error as a CLI error: the field replaced by its flag when a flag sets it, else
/// prefixed with `context` (the file it came from).
fn core_error(e: &Error, context: &str) -> CliError {
    if matches!(e, Error::Cancelled) {
        return cancelled();
    }
    let text = e.to_string();
    let field = match e {
        Error::SizeLimit { field, .. } | Error::LengthMismatch { field, .. } => field.to_string(),
        Error::NonFinite { field }
        | Error::NotPositive { field, .. }
        | Error::OutOfRange { field, .. } => field.clone(),
        _ => String::new(),
    };
    match flag_of(&field) {
        Some(flag) => CliError::usage(text.replacen(&field, flag, 1)),
        None => CliError::usage(format!("{context}: {text}")),
    }
}

/// Reads and parses the JSON file of `--flag`.
fn read_file<T: serde::de::DeserializeOwned>(flag: &str, path: &str) -> Result<T, CliError> {
    let text = read_input(flag, path)?;
    from_json(&text).map_err(|e| CliError::usage(format!("--{flag} {path}: {e}")))
}

/// `--name` as a probability in `[0, 1]`, if given.
fn probability(args: &crate::args::Args, name: &str) -> Result<Option<f64>, CliError> {
    match args.number(name)? {
        Some(p) if !(0.0..=1.0).contains(&p) => Err(CliError::usage(format!(
            "--{name}: {p} is not a probability in [0, 1]"
        ))),
        p => Ok(p),
    }
}

/// Fails when any of `flags` was given: they do not apply to `what`.
fn refuse(args: &crate::args::Args, flags: &[&str], what: &str) -> Result<(), CliError> {
    for f in flags {
        if args.get(f).is_some() || args.switch(f) {
            return Err(CliError::usage(format!("--{f}: not used {what}")));
        }
    }
    Ok(())
}

/// The model spec from `--model` and its flags.
fn model_spec(args: &crate::args::Args) -> Result<ModelSpec, CliError> {
    let kind = args.get("model").unwrap_or("icb");
    let p_d = probability(args, "p-d")?;
    let training_flags = ["lambda", "diameter", "seed", "scenes", "cells"];
    match kind.to_ascii_lowercase().as_str() {
        "icb" | "i.c.b" => {
            refuse(
                args,
                &[
                    "lambda", "diameter", "exact", "table", "seed", "scenes", "cells",
                ],
                "with --model icb",
            )?;
            let p_u = probability(args, "p-u")?;
            let p_los = probability(args, "p-los")?;
            if p_u.is_some() && (p_d.is_some() || p_los.is_some()) {
                return Err(CliError::usage(
                    "--p-u: give --p-u or --p-d/--p-los, not both",
                ));
            }
            Ok(ModelSpec::Icb { p_u, p_d, p_los })
        }
        "ppp" => {
            refuse(
                args,
                &["p-u", "p-los", "table", "seed", "scenes", "cells"],
                "with --model ppp",
            )?;
            Ok(ModelSpec::Ppp {
                lambda: args.number("lambda")?.unwrap_or(DEFAULT_LAMBDA),
                diameter_m: args.number("diameter")?.unwrap_or(DEFAULT_DIAMETER_M),
                p_d: p_d.unwrap_or(DEFAULT_P_D),
                exact: args.switch("exact"),
            })
        }
        "empirical" => {
            refuse(args, &["p-u", "p-los", "exact"], "with --model empirical")?;
            let p_d = p_d.unwrap_or(DEFAULT_P_D);
            if let Some(path) = args.get("table") {
                refuse(args, &training_flags, "with --table (the table is given)")?;
                let table: EmpiricalTable = read_file("table", path)?;
                return Ok(ModelSpec::Empirical {
                    p_d,
                    table: Some(table),
                    training: None,
                });
            }
            let d = TrainingSpec::default();
            Ok(ModelSpec::Empirical {
                p_d,
                table: None,
                training: Some(TrainingSpec {
                    lambda: args.number("lambda")?.unwrap_or(d.lambda),
                    diameter_m: args.number("diameter")?.unwrap_or(d.diameter_m),
                    cells: args.integer("cells")?.unwrap_or(d.cells),
                    scenes: args.integer("scenes")?.unwrap_or(d.scenes),
                    seed: args.integer("seed")?.map_or(d.seed, |s| s as u64),
                }),
            })
        }
        other => Err(CliError::usage(format!(
            "--model: unknown model '{other}' (expected icb, ppp or empirical)"
        ))),
    }
}

/// `--te`, `--tb` (non-negative numbers; `--tb inf` allowed).
fn threshold(args: &crate::args::Args, name: &str, default: f64) -> Result<f64, CliError> {
    let Some(v) = args.get(name) else {
        return Ok(default);
    };
    let t = match v.trim() {
        "inf" | "∞" if name == "tb" => f64::INFINITY,
        s => s
            .parse::<f64>()
            .ok()
            .filter(|x| x.is_finite())
            .ok_or_else(|| {
                CliError::usage(format!("--{name}: expected a finite number, got '{v}'"))
            })?,
    };
    if t < 0.0 {
        return Err(CliError::usage(format!(
            "--{name}: {t} is negative (a threshold must be ≥ 0)"
        )));
    }
    Ok(t)
}

/// The Algorithm 1 settings from `--te`, `--tb`, `--b-max`, `--n-min`, `--order`.
fn mtl_config(args: &crate::args::Args) -> Result<MtlConfig, CliError> {
    let d = MtlConfig::default();
    let b_max = match args.get("b-max") {
        Some(v) if v.trim().eq_ignore_ascii_case("inf") => usize::MAX,
        _ => args.integer("b-max")?.unwrap_or(d.b_max),
    };
    if b_max == 0 {
        return Err(CliError::usage("--b-max: must be ≥ 1 (or inf)"));
    }
    let order = match args.get("order") {
        None => None,
        Some(v) => Some(
            v.split(',')
                .map(|t| t.trim().parse::<usize>())
                .collect::<Result<Vec<_>, _>>()
                .map_err(|_| {
                    CliError::usage(format!(
                        "--order: expected comma-separated 0-based TRP indices, got '{v}'"
                    ))
                })?,
        ),
    };
    Ok(MtlConfig {
        t_e: threshold(args, "te", d.t_e)?,
        t_b: threshold(args, "tb", d.t_b)?,
        b_max,
        n_min: args.integer("n-min")?.unwrap_or(d.n_min),
        order,
        ..d
    })
}
