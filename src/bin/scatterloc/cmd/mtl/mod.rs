//! `scatterloc mtl …`: the multi-target method of spec `multi-target.md` — `locate` (Algorithm 1
//! on a network and ranges file, §4), `table2` (Table II, §8) and `roc` (the §8 experiments V-A,
//! V-B, V-C with a progress bar, a summary table, JSON and a figure; sharded, and the merge of
//! its parts). The math is in `scatterloc::mtl`; these files turn the flags into its settings,
//! call it and format the results.

use plotters::coord::Shift;
use plotters::prelude::*;
use serde::Serialize;

use scatterloc::chart::{
    curve_chart_size, draw_curves, ChartError, CurveChartOptions, CurveSeries, LineKind, Marker,
};
use scatterloc::mtl::algorithm::MtlConfig;
use scatterloc::mtl::empirical::EmpiricalTable;
use scatterloc::mtl::experiment::{
    Experiment, ExperimentConfig, ExperimentResult, Method, Tally, MAX_REALISATIONS,
};
use scatterloc::mtl::input::{
    from_json, locate_request, LocateRequest, LocateStage, ModelSpec, NetworkInput, RangesInput,
    TrainingSpec, DEFAULT_DIAMETER_M, DEFAULT_LAMBDA, DEFAULT_P_D,
};
use scatterloc::mtl::sim::table2::{icb_row, table2_buckets, true_row};
use scatterloc::mtl::sim::{SimSettings, VB_ICB_P_U};
use scatterloc::native::run_experiment_range;
use scatterloc::Error;

use super::flags::with_flag;
use super::io::{emit, emit_summary, one_stdin, read_input};
use super::output::{check_writable, write_json_file, Figure, Format, OutputSet};
use super::parts::PartReader;
use super::shard;
use super::study::{cancelled, run_with_bar, threads};
use crate::cli::{MtlLocateArgs, MtlModel, RocArgs, RocExperiment, Table2Args};
use crate::failure::CliError;
use scatterloc::study::{PartFile, PartSet, RocConfig, RocStudy, ShardDoc, Timing};

mod locate;
mod roc;
mod table2;

pub use locate::mtl_locate;
pub use roc::{merge_roc, mtl_roc, roc_config_of};
pub use table2::mtl_table2;

/// A core error as a CLI error: the field replaced by its flag when a flag sets it, else
/// prefixed with `context` (the file it came from).
fn core_error(e: &Error, context: &str) -> CliError {
    if matches!(e, Error::Cancelled) {
        return cancelled();
    }
    match with_flag(e) {
        Some(text) => CliError::usage(text),
        None => CliError::usage(format!("{context}: {e}")),
    }
}

/// Reads and parses the JSON file of `--flag`.
fn read_file<T: serde::de::DeserializeOwned>(flag: &str, path: &str) -> Result<T, CliError> {
    let text = read_input(flag, path)?;
    from_json(&text).map_err(|e| CliError::usage(format!("--{flag} {path}: {e}")))
}

/// Whether `--name` (a flag of `mtl locate` that belongs to some models only) was given.
fn given(args: &MtlLocateArgs, name: &str) -> bool {
    match name {
        "lambda" => args.lambda.is_some(),
        "diameter" => args.diameter.is_some(),
        "exact" => args.exact,
        "table" => args.table.is_some(),
        "seed" => args.seed.is_some(),
        "scenes" => args.scenes.is_some(),
        "cells" => args.cells.is_some(),
        "p-u" => args.p_u.is_some(),
        "p-los" => args.p_los.is_some(),
        _ => false,
    }
}

/// Fails when any of `flags` was given: they do not apply to `what`.
fn refuse(args: &MtlLocateArgs, flags: &[&str], what: &str) -> Result<(), CliError> {
    match flags.iter().find(|f| given(args, f)) {
        Some(f) => Err(CliError::usage(format!("--{f}: not used {what}"))),
        None => Ok(()),
    }
}

/// The model spec from `--model` and its flags.
fn model_spec(args: &MtlLocateArgs) -> Result<ModelSpec, CliError> {
    let p_d = args.p_d;
    let training_flags = ["lambda", "diameter", "seed", "scenes", "cells"];
    match args.model.unwrap_or(MtlModel::Icb) {
        MtlModel::Icb => {
            refuse(
                args,
                &[
                    "lambda", "diameter", "exact", "table", "seed", "scenes", "cells",
                ],
                "with --model icb",
            )?;
            let (p_u, p_los) = (args.p_u, args.p_los);
            if p_u.is_some() && (p_d.is_some() || p_los.is_some()) {
                return Err(CliError::usage(
                    "--p-u: give --p-u or --p-d/--p-los, not both",
                ));
            }
            Ok(ModelSpec::Icb { p_u, p_d, p_los })
        }
        MtlModel::Ppp => {
            refuse(
                args,
                &["p-u", "p-los", "table", "seed", "scenes", "cells"],
                "with --model ppp",
            )?;
            Ok(ModelSpec::Ppp {
                lambda: args.lambda.unwrap_or(DEFAULT_LAMBDA),
                diameter_m: args.diameter.unwrap_or(DEFAULT_DIAMETER_M),
                p_d: p_d.unwrap_or(DEFAULT_P_D),
                exact: args.exact,
            })
        }
        MtlModel::Empirical => {
            refuse(args, &["p-u", "p-los", "exact"], "with --model empirical")?;
            let p_d = p_d.unwrap_or(DEFAULT_P_D);
            if let Some(path) = args.table.as_deref() {
                refuse(args, &training_flags, "with --table (the table is given)")?;
                let table: EmpiricalTable = read_file("table", path)?;
                // Checked here, so a bad field is named as the table's (not as a flag's).
                table
                    .validate()
                    .map_err(|e| CliError::usage(format!("--table {path}: {e}")))?;
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
                    lambda: args.lambda.unwrap_or(d.lambda),
                    diameter_m: args.diameter.unwrap_or(d.diameter_m),
                    cells: args.cells.unwrap_or(d.cells),
                    scenes: args.scenes.unwrap_or(d.scenes),
                    seed: args.seed.unwrap_or(d.seed),
                }),
            })
        }
    }
}

/// The Algorithm 1 settings from `--te`, `--tb`, `--b-max`, `--n-min`, `--order`.
fn mtl_config(args: &MtlLocateArgs) -> MtlConfig {
    let d = MtlConfig::default();
    MtlConfig {
        t_e: args.te.unwrap_or(d.t_e),
        t_b: args.tb.unwrap_or(d.t_b),
        b_max: args.b_max.unwrap_or(d.b_max),
        n_min: args.n_min.unwrap_or(d.n_min),
        max_candidates: args.max_candidates.unwrap_or(d.max_candidates),
        order: args.order.clone().map(|o| o.0),
        ..d
    }
}
