//! The channel view's checks at open (issue 38 item 9): a recording whose links the scenario
//! lacks, or a truth file whose times are not the recording's, is named when it is opened,
//! not only at Run — with the same core checks the job makes at Run
//! ([`crate::channel::Recording::link_map`], [`Truth::check_times`]).

use alloc::format;
use alloc::vec::Vec;

use serde::Serialize;
use wasm_bindgen::prelude::*;

use super::{check_size, named, scenario_and_model};
use crate::channel::Recording;
use crate::csi::{open_recording, OpenOptions};
use crate::edge::wasm::base::err;
use crate::edge::wasm::json::to_js;
use crate::error::limits::{MAX_PAGE_RECORDING_BYTES, MAX_PAGE_TEXT_BYTES};
use crate::error::Error;
use crate::formats::Truth;

/// `channel_recording_summary`'s result.
#[derive(Serialize)]
struct OpenedRecording {
    snapshots: usize,
    links: usize,
    layout: &'static str,
    samples_per_link: usize,
    duration_s: f64,
    t_s: Vec<f64>,
}

/// A recording file of the page: a `.npz` or a Wi-Fi CSI tool's file (format by its first
/// bytes, every antenna pair as link `(tx, rx)`, the format's gain applied: the CLI's defaults),
/// within the page's cap.
pub(crate) fn page_recording(bytes: &[u8]) -> Result<Recording, Error> {
    let opts = OpenOptions {
        max_npz_bytes: MAX_PAGE_RECORDING_BYTES,
        convert: crate::csi::ConvertOptions::default(),
        ..OpenOptions::default()
    };
    open_recording(bytes, &opts).map(|o| o.recording)
}

/// Reads the bytes of a recording opened in the channel view (`.npz`, or a Wi-Fi CSI tool's
/// file: [`page_recording`]) and checks its links
/// against the scenario JSON `scenario_json` (the job's reader, caps and check, as at Run):
/// returns `{snapshots, links, layout ("cfr" | "cir"), samples_per_link, duration_s, t_s (the
/// snapshot times, s)}`. Throws the reader's named error (`npz: …`, the size cap), or
/// `links[4]: the link (transmitter 0, receiver 4) is not one of the scenario's 4 links` (the
/// page prefixes the file).
#[wasm_bindgen]
pub fn channel_recording_summary(
    scenario_json: &str,
    bytes: &js_sys::Uint8Array,
) -> Result<JsValue, JsError> {
    let (_, model) = scenario_and_model(scenario_json)?;
    // Before the bytes are copied into the module's memory.
    check_size(
        "recording",
        bytes.length() as usize,
        MAX_PAGE_RECORDING_BYTES,
    )
    .map_err(err)?;
    let rec = page_recording(&bytes.to_vec()).map_err(err)?;
    rec.link_map(&model).map_err(err)?;
    to_js(&OpenedRecording {
        snapshots: rec.snapshot_count(),
        links: rec.link_count(),
        layout: rec.layout.array(),
        samples_per_link: rec.samples_per_link(),
        duration_s: rec.t_s[rec.t_s.len() - 1] - rec.t_s[0],
        t_s: rec.t_s,
    })
}

/// Checks the truth file's text `truth_json` against the recording's snapshot times `t_s` as
/// the job does at Run (one state per snapshot, at the snapshot's time, finite and within the
/// core's limits). Throws `truth: 300 states for the recording's 1528 snapshots (one state per
/// snapshot)`, or the core's named error (`truth: t_s[4]: …`).
#[wasm_bindgen]
pub fn check_channel_truth(truth_json: &str, t_s: &[f64]) -> Result<(), JsError> {
    check_size("truth", truth_json.len(), MAX_PAGE_TEXT_BYTES as u64).map_err(err)?;
    let t = Truth::from_json(truth_json).map_err(named("truth"))?;
    if t.states.len() != t_s.len() {
        return Err(named("truth")(Error::InvalidFile {
            field: "states".into(),
            reason: format!(
                "{} states for the recording's {} snapshots (one state per snapshot)",
                t.states.len(),
                t_s.len()
            ),
        }));
    }
    t.check_times(t_s).map_err(named("truth"))
}
