//! `scatterloc cir convert IN OUT.npz` and the one way every `cir` command opens a recording
//! file: `.npz` or a Wi-Fi CSI tool's file (issue 40), through [`scatterloc::csi::open_recording`].

use scatterloc::csi::{open_recording, ConvertOptions, OpenOptions, Opened, PairLink};
use scatterloc::error::limits;
use scatterloc::npz;

use super::flags::in_file;
use super::io::{emit_summary, read_bytes};
use super::output::{check_distinct, check_writable, OutputSet};
use crate::cli::{CirConvertArgs, CsiArgs};
use crate::failure::CliError;

/// The reader's options of `csi`'s flags (`--links` parsed; its errors name the flag).
pub fn options(csi: &CsiArgs) -> Result<OpenOptions, CliError> {
    let links = match &csi.links {
        Some(text) => {
            Some(PairLink::parse_list(text).map_err(|e| CliError::usage(format!("--links: {e}")))?)
        }
        None => None,
    };
    Ok(OpenOptions {
        format: csi.format.clone(),
        convert: ConvertOptions {
            links,
            apply_gain: !csi.raw_gain,
            keep_unoccupied: csi.all_subcarriers,
        },
        max_npz_bytes: limits::MAX_RECORDING_BYTES,
    })
}

/// Opens the recording file `--flag PATH` (`-` = standard input) as `csi` says; errors name
/// the flag and the file.
pub fn open(flag: &str, path: &str, csi: &CsiArgs) -> Result<Opened, CliError> {
    let opts = options(csi)?;
    let bytes = read_bytes(flag, path, limits::MAX_RECORDING_BYTES)?;
    open_recording(&bytes, &opts).map_err(|e| match flag {
        // The positional input of `cir convert`.
        "IN" => CliError::usage(format!("IN {path}: {e}")),
        _ => in_file(flag, path, e),
    })
}

/// `scatterloc cir convert IN OUT.npz [--format F] [--links MAP] [--raw-gain]`: writes the
/// recording and prints what the file held (the summary of
/// [`scatterloc::csi::CsiSummary::to_json`]; a `.npz` in gives its own shape).
pub fn cir_convert(args: &CirConvertArgs) -> Result<(), CliError> {
    if !args.output.to_ascii_lowercase().ends_with(".npz") {
        return Err(CliError::usage(format!(
            "OUT: '{}' must end in .npz (the recording format of docs/recording.md)",
            args.output
        )));
    }
    check_writable("OUT", &args.output)?;
    check_distinct(&[("IN", args.input.as_str()), ("OUT", args.output.as_str())])?;
    let opened = open("IN", &args.input, &args.csi)?;
    let bytes = npz::write_recording(&opened.recording)
        .map_err(|e| CliError::output(format!("OUT: {e}")))?;
    let mut files = OutputSet::new();
    files.bytes("OUT", &args.output, &bytes)?;
    files.commit()?;
    let rec = &opened.recording;
    let mut doc = match &opened.csi {
        Some(s) => s.to_json(rec),
        None => serde_json::json!({
            "format": "npz",
            "frames": rec.t_s.len(),
            "links": rec.links,
            "samples_per_link": rec.samples_per_link(),
        }),
    };
    doc["out"] = serde_json::Value::from(args.output.clone());
    emit_summary(&doc.to_string())
}
