//! Wi-Fi CSI files (issue 40): `read_csi` (a CSI tool's file as the library's reader found it:
//! the raw values, subcarriers, antennas, times, gain) and the CSI keywords of
//! `read_recording` (the library's `csi::open_recording`, as `scatterloc cir convert`). This
//! file only converts types.

use numpy::Complex64;
use pyo3::prelude::*;

use scatterloc::csi::{
    open_recording, read_capture, ConvertOptions, CsiFormat, OpenOptions, Opened, PairLink,
};
use scatterloc::error::limits;

use crate::convert::{array, path_string, to_python};
use crate::errors::arg_error;
use crate::run::run_quick;

/// The bytes of `path`, at most the CLI's recording cap.
pub fn read_file(path: &Bound<'_, PyAny>) -> PyResult<Vec<u8>> {
    use std::io::Read;
    let p = path_string(path)?;
    let f = std::fs::File::open(&p)?;
    let mut bytes = Vec::new();
    f.take(limits::MAX_RECORDING_BYTES + 1)
        .read_to_end(&mut bytes)?;
    if bytes.len() as u64 > limits::MAX_RECORDING_BYTES {
        return Err(arg_error(
            "path",
            format!("'{p}' is larger than {} bytes", limits::MAX_RECORDING_BYTES),
        ));
    }
    Ok(bytes)
}

/// Opens a recording file (`.npz` or CSI) with the keywords of `read_recording`.
pub fn open(
    py: Python<'_>,
    path: &Bound<'_, PyAny>,
    format: Option<String>,
    links: Option<String>,
    raw_gain: bool,
    all_subcarriers: bool,
) -> PyResult<Opened> {
    let bytes = read_file(path)?;
    let links = match links {
        Some(t) => Some(PairLink::parse_list(&t).map_err(|e| arg_error("links", e.to_string()))?),
        None => None,
    };
    let opts = OpenOptions {
        format,
        convert: ConvertOptions {
            links,
            apply_gain: !raw_gain,
            keep_unoccupied: all_subcarriers,
        },
        max_npz_bytes: limits::MAX_RECORDING_BYTES,
    };
    run_quick(py, || open_recording(&bytes, &opts))
}

/// Reads a Wi-Fi CSI tool's file as the library's reader finds it (no conversion): a dict with
/// `format`, `device`, `frame_format`, `center_hz` (None where the format does not say),
/// `bandwidth_hz`, `spacing_hz`, `n_rx`, `n_tx`, `t_s` (frames,), `subcarriers` (K,) int32,
/// `pilots` int32, `csi` (frames, n_rx, n_tx, K) complex128 — the values as written, unscaled —,
/// `gain` (frames,) or None (the RSSI/AGC factor the format reports), `notes`, `skipped`
/// ([(frame, reason)]). `format`: `auto` (default: by the first bytes) or one of `intel5300`,
/// `nexmon`, `picoscenes`, `feitcsi`, `esp32`.
#[pyfunction]
#[pyo3(signature = (path, *, format = None))]
pub fn read_csi<'py>(
    py: Python<'py>,
    path: &Bound<'py, PyAny>,
    format: Option<String>,
) -> PyResult<Bound<'py, PyAny>> {
    let bytes = read_file(path)?;
    let fmt = match format.as_deref() {
        None | Some("auto") => None,
        Some(name) => Some(CsiFormat::parse(name).map_err(|e| arg_error("format", e.to_string()))?),
    };
    let cap = run_quick(py, || read_capture(&bytes, fmt))?;
    let d = pyo3::types::PyDict::new(py);
    d.set_item("format", cap.format.name())?;
    d.set_item("device", &cap.device)?;
    d.set_item("frame_format", &cap.frame_format)?;
    d.set_item("center_hz", cap.center_hz)?;
    d.set_item("bandwidth_hz", cap.bandwidth_hz)?;
    d.set_item("spacing_hz", cap.spacing_hz)?;
    d.set_item("n_rx", cap.n_rx)?;
    d.set_item("n_tx", cap.n_tx)?;
    let frames = cap.t_s.len();
    let k = cap.subcarriers.len();
    d.set_item("t_s", array(py, cap.t_s.clone(), &[frames])?)?;
    d.set_item("subcarriers", array(py, cap.subcarriers.clone(), &[k])?)?;
    d.set_item(
        "pilots",
        array(py, cap.pilots.clone(), &[cap.pilots.len()])?,
    )?;
    let csi: Vec<Complex64> = cap.csi.iter().map(|z| Complex64::new(z.re, z.im)).collect();
    d.set_item("csi", array(py, csi, &[frames, cap.n_rx, cap.n_tx, k])?)?;
    match &cap.gain {
        Some(g) => d.set_item("gain", array(py, g.clone(), &[frames])?)?,
        None => d.set_item("gain", py.None())?,
    }
    d.set_item("notes", to_python(py, &cap.notes)?)?;
    d.set_item("skipped", to_python(py, &cap.skipped)?)?;
    Ok(d.into_any())
}
