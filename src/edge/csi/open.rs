//! One entry for every recording file: `.npz` (docs/recording.md) or a CSI tool's file, by its
//! first bytes or by the user's `--format`.

use alloc::string::String;
use alloc::vec::Vec;

use super::capture::{to_recording, ConvertOptions, CsiCapture, CsiFormat};
use super::{esp32, feitcsi, intel5300, nexmon, picoscenes};
use crate::channel::Recording;
use crate::error::{Error, Result};

/// The CSI format of a file by its first bytes (`None`: not a CSI file this crate reads, or a
/// `.npz`). Order: the formats with a magic number first (pcap, PicoScenes), then the ESP32
/// text, then FeitCSI's and the Intel 5300's self-consistent length fields.
pub fn detect(bytes: &[u8]) -> Option<CsiFormat> {
    if nexmon::sniff(bytes) {
        Some(CsiFormat::Nexmon)
    } else if picoscenes::sniff(bytes) {
        Some(CsiFormat::PicoScenes)
    } else if esp32::sniff(bytes) {
        Some(CsiFormat::Esp32)
    } else if feitcsi::sniff(bytes) {
        Some(CsiFormat::FeitCsi)
    } else if intel5300::sniff(bytes) {
        Some(CsiFormat::Intel5300)
    } else {
        None
    }
}

/// Reads a CSI file of `format` (`None`: [`detect`]ed; a file no reader recognises is an
/// [`Error::InvalidFile`] naming `format`).
pub fn read_capture(bytes: &[u8], format: Option<CsiFormat>) -> Result<CsiCapture> {
    let format = match format.or_else(|| detect(bytes)) {
        Some(f) => f,
        None => {
            return Err(Error::InvalidFile {
                field: "format".into(),
                reason: "not a recording this tool reads: neither a .npz nor a CSI file of \
                         intel5300, nexmon, picoscenes, feitcsi or esp32 (say --format to \
                         force one)"
                    .into(),
            })
        }
    };
    // Each reader checks its capture (`CsiCapture::validate`) before it returns it.
    match format {
        CsiFormat::Intel5300 => intel5300::read(bytes),
        CsiFormat::Nexmon => nexmon::read(bytes),
        CsiFormat::PicoScenes => picoscenes::read(bytes),
        CsiFormat::FeitCsi => feitcsi::read(bytes),
        CsiFormat::Esp32 => esp32::read(bytes),
    }
}

/// How [`open_recording`] reads a file.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct OpenOptions {
    /// `None` or `Some("auto")`: by the first bytes; else a [`CsiFormat::name`] or `npz`.
    pub format: Option<String>,
    /// The conversion of a CSI file (ignored for `.npz`).
    pub convert: ConvertOptions,
    /// The size cap of a `.npz` (the npz reader's `max_bytes`).
    pub max_npz_bytes: u64,
}

/// A recording file opened: the recording, and for a CSI file what was found in it.
#[derive(Debug, Clone, PartialEq)]
pub struct Opened {
    /// The recording.
    pub recording: Recording,
    /// `None` for a `.npz`.
    pub csi: Option<CsiSummary>,
}

/// What a CSI file held and what its conversion did (for `cir convert`'s report, the page's
/// summary and Python).
#[derive(Debug, Clone, PartialEq)]
pub struct CsiSummary {
    /// The capture without its values (`csi` empty, to save memory).
    pub capture: CsiCapture,
    /// Frames dropped because their time did not increase: `(frame index, time s)`.
    pub dropped: Vec<(usize, f64)>,
    /// Whether the format's gain was applied.
    pub gain_applied: bool,
    /// The reported subcarriers left out as unoccupied.
    pub unoccupied: Vec<i32>,
}

fn is_npz(bytes: &[u8]) -> bool {
    bytes.starts_with(b"PK\x03\x04") || bytes.starts_with(b"PK\x05\x06")
}

/// Opens a recording file: a `.npz` (docs/recording.md) or a CSI tool's file converted by
/// [`super::to_recording`]. Errors: the readers' (naming the frame and field), an unknown
/// `format`.
pub fn open_recording(bytes: &[u8], options: &OpenOptions) -> Result<Opened> {
    let format = options.format.as_deref().unwrap_or("auto");
    let csi_format = match format {
        "auto" if is_npz(bytes) => None,
        "npz" => None,
        // Neither a zip nor a CSI file this crate recognises: the `.npz` reader's own message
        // (what a damaged `.npz` needs), saying that no CSI reader took it either.
        "auto" if detect(bytes).is_none() => {
            return match crate::npz::read_recording_within(bytes, options.max_npz_bytes) {
                Ok(recording) => Ok(Opened {
                    recording,
                    csi: None,
                }),
                Err(Error::InvalidFile { field, reason }) => Err(Error::InvalidFile {
                    field,
                    reason: alloc::format!(
                        "{reason}; nor a CSI file of intel5300, nexmon, picoscenes, feitcsi or \
                         esp32 (--format forces a reader)"
                    ),
                }),
                Err(e) => Err(e),
            };
        }
        "auto" => Some(None),
        name => Some(Some(CsiFormat::parse(name)?)),
    };
    match csi_format {
        None => Ok(Opened {
            recording: crate::npz::read_recording_within(bytes, options.max_npz_bytes)?,
            csi: None,
        }),
        Some(f) => {
            let mut capture = read_capture(bytes, f)?;
            let conversion = to_recording(&capture, &options.convert)?;
            capture.csi = Vec::new();
            Ok(Opened {
                recording: conversion.recording,
                csi: Some(CsiSummary {
                    capture,
                    dropped: conversion.dropped,
                    gain_applied: conversion.gain_applied,
                    unoccupied: conversion.unoccupied,
                }),
            })
        }
    }
}
