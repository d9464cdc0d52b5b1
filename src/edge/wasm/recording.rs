//! `read_recording_summary`: a dropped channel recording (`.npz`, docs/recording.md, or a Wi-Fi
//! CSI tool's file) read as the channel view reads it, summarised for the page.

use serde::Serialize;
use wasm_bindgen::prelude::*;

use super::base::err;
use super::channel::page_recording;
use super::json::to_js;

/// The page's summary of a recording.
#[derive(Serialize)]
struct RecordingSummary {
    /// Snapshots S.
    snapshots: usize,
    /// Recorded links P.
    links: usize,
    /// `"cfr"` (C1) or `"cir"` (C2).
    layout: &'static str,
    /// Frequency bins N or taps M per link and snapshot.
    samples_per_link: usize,
    /// `t_s[S−1] − t_s[0]`, s.
    duration_s: f64,
}

/// Reads the bytes of a recording (`.npz` or CSI) and returns `{snapshots, links, layout ("cfr" or
/// "cir"), samples_per_link, duration_s}`. Throws the reader's named error (naming the array) on
/// a malformed file.
#[wasm_bindgen]
pub fn read_recording_summary(bytes: &[u8]) -> Result<JsValue, JsError> {
    let rec = page_recording(bytes).map_err(err)?;
    to_js(&RecordingSummary {
        snapshots: rec.snapshot_count(),
        links: rec.link_count(),
        layout: rec.layout.array(),
        samples_per_link: rec.samples_per_link(),
        duration_s: rec.t_s[rec.t_s.len() - 1] - rec.t_s[0],
    })
}
