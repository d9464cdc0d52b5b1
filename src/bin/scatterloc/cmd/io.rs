//! Reading the inputs (files or standard input, JSON with errors naming the field) and writing
//! results to stdout.

use std::io::Read;

use serde::de::DeserializeOwned;
use serde::Serialize;

use scatterloc::error::limits;
use scatterloc::scenario::parse_json;
use scatterloc::{Model, Scenario};

use super::flags::{at_flag, in_file};
use crate::failure::CliError;

/// `text` and a newline.
fn line(text: &str) -> Vec<u8> {
    let mut bytes = Vec::with_capacity(text.len() + 1);
    bytes.extend_from_slice(text.as_bytes());
    bytes.push(b'\n');
    bytes
}

/// Writes a command's result `text` and a newline to stdout, checked ([`crate::stdout::write`]:
/// a closed stdout is an error).
pub fn emit(text: &str) -> Result<(), CliError> {
    crate::stdout::write(&line(text))
}

/// Writes the summary line of a command whose results went to files
/// ([`crate::stdout::write_summary`]).
pub fn emit_summary(text: &str) -> Result<(), CliError> {
    crate::stdout::write_summary(&line(text))
}

/// Pretty JSON on stdout (serde_json writes non-finite numbers as `null`).
pub fn emit_json<T: Serialize>(v: &T) -> Result<(), CliError> {
    let text = serde_json::to_string_pretty(v)
        .map_err(|e| CliError::output(format!("encoding JSON: {e}")))?;
    emit(&text)
}

/// Refuses more than one of a command's `inputs` (flag, path if given) on standard input (`-`):
/// it can be read only once, so the second would read nothing (issue 37). Checked before
/// anything is read; the error names the flags.
pub fn one_stdin(inputs: &[(&str, Option<&str>)]) -> Result<(), CliError> {
    let on_stdin: Vec<String> = inputs
        .iter()
        .filter(|(_, path)| *path == Some("-"))
        .map(|(flag, _)| format!("--{flag}"))
        .collect();
    if on_stdin.len() > 1 {
        return Err(CliError::usage(format!(
            "{}: more than one input is '-', but standard input can be read only once; give \
             all but one of them as files",
            on_stdin.join(" / ")
        )));
    }
    Ok(())
}

/// Reads a file (or stdin for `-`) named by `--flag`, at most [`limits::MAX_INPUT_BYTES`]
/// (a larger input, or an endless one such as `/dev/zero`, is refused after reading one byte
/// past the cap). A leading UTF-8 byte-order mark is dropped (editors on some systems write
/// one; the page accepts it too).
pub fn read_input(flag: &str, path: &str) -> Result<String, CliError> {
    read_input_named(&format!("--{flag}"), path)
}

/// [`read_input`] with `what` (a flag with its dashes, or e.g. `PART a.json`) naming the input
/// in errors.
pub fn read_input_named(what: &str, path: &str) -> Result<String, CliError> {
    let bytes = read_capped(what, path, limits::MAX_INPUT_BYTES, "input")?;
    let mut s = String::from_utf8(bytes)
        .map_err(|e| CliError::usage(format!("{what}: cannot read '{path}': {e}")))?;
    if s.starts_with('\u{feff}') {
        s.drain(..'\u{feff}'.len_utf8());
    }
    Ok(s)
}

/// Reads the binary file `path` of `--flag` (a recording), at most `cap` bytes (a larger one is
/// refused after reading one byte past the cap; `-` = standard input).
pub fn read_bytes(flag: &str, path: &str, cap: u64) -> Result<Vec<u8>, CliError> {
    read_capped(&format!("--{flag}"), path, cap, "recording")
}

/// The bytes of `path` (`-` = standard input) named by `what` in errors, at most `cap` of them:
/// a larger input, or an endless one such as `/dev/zero`, is refused after reading one byte
/// past the cap ("the largest `kind` read").
fn read_capped(what: &str, path: &str, cap: u64, kind: &str) -> Result<Vec<u8>, CliError> {
    let mut bytes = Vec::new();
    let res = if path == "-" {
        std::io::stdin()
            .lock()
            .take(cap + 1)
            .read_to_end(&mut bytes)
    } else {
        std::fs::File::open(path).and_then(|f| f.take(cap + 1).read_to_end(&mut bytes))
    };
    res.map_err(|e| CliError::usage(format!("{what}: cannot read '{path}': {e}")))?;
    if bytes.len() as u64 > cap {
        return Err(CliError::usage(format!(
            "{what}: '{path}' is larger than {} MiB, the largest {kind} read",
            cap >> 20
        )));
    }
    Ok(bytes)
}

/// Reads and validates the scenario file `path` of `--scenario`.
pub fn read_scenario(path: &str) -> Result<Scenario, CliError> {
    let text = read_input("scenario", path)?;
    Scenario::from_json(&text).map_err(|e| in_file("scenario", path, e))
}

/// The model of a validated scenario.
pub fn model_of(s: &Scenario) -> Result<Model, CliError> {
    Model::new(s).map_err(|e| at_flag("scenario", e))
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
