//! Reading the inputs (files or standard input, JSON with errors naming the field) and writing
//! results to stdout.

use std::io::{Read, Write};

use serde::de::DeserializeOwned;
use serde::Serialize;

use scatterloc::scenario::parse_json;
use scatterloc::{Model, Scenario};

use crate::CliError;

/// Writes `text` and a newline to stdout.
pub fn emit(text: &str) -> Result<(), CliError> {
    let mut out = std::io::stdout().lock();
    writeln!(out, "{text}")
        .and_then(|_| out.flush())
        .map_err(|e| CliError::output(format!("stdout: {e}")))
}

/// Pretty JSON on stdout (serde_json writes non-finite numbers as `null`).
pub fn emit_json<T: Serialize>(v: &T) -> Result<(), CliError> {
    let text = serde_json::to_string_pretty(v)
        .map_err(|e| CliError::output(format!("encoding JSON: {e}")))?;
    emit(&text)
}

/// Reads a file (or stdin for `-`) named by `--flag`. A leading UTF-8 byte-order mark is
/// dropped (editors on some systems write one; the page accepts it too).
pub fn read_input(flag: &str, path: &str) -> Result<String, CliError> {
    let res = if path == "-" {
        let mut s = String::new();
        std::io::stdin().read_to_string(&mut s).map(|_| s)
    } else {
        std::fs::read_to_string(path)
    };
    res.map(|mut s| {
        if s.starts_with('\u{feff}') {
            s.drain(..'\u{feff}'.len_utf8());
        }
        s
    })
    .map_err(|e| CliError::usage(format!("--{flag}: cannot read '{path}': {e}")))
}

/// Reads and validates the scenario file `path` of `--scenario`.
pub fn read_scenario(path: &str) -> Result<Scenario, CliError> {
    let text = read_input("scenario", path)?;
    Scenario::from_json(&text).map_err(|e| CliError::usage(format!("--scenario {path}: {e}")))
}

/// The model of a validated scenario.
pub fn model_of(s: &Scenario) -> Result<Model, CliError> {
    Model::new(s).map_err(|e| CliError::usage(format!("--scenario: {e}")))
}

/// Reads and parses the JSON file named by `--flag` (errors: `--flag PATH: field: problem`).
pub fn read_json_file<T: DeserializeOwned>(flag: &str, path: &str) -> Result<T, CliError> {
    let text = read_input(flag, path)?;
    parse_json(&text).map_err(|e| {
        CliError::usage(format!(
            "--{flag} {path}: {}",
            e.to_string().replace(
                "data did not match any variant of untagged enum Sigma",
                "expected a number or a list of numbers (one per link)",
            )
        ))
    })
}
