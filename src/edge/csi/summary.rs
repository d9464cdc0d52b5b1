//! What a CSI file held, as JSON: `cir convert`'s report, the page's summary and Python's
//! `Recording.csi` (one home, so the three say the same).

use alloc::string::String;
use alloc::vec::Vec;

use serde_json::{json, Value};

use super::open::CsiSummary;
use crate::channel::{Layout, Recording};

/// How many dropped or skipped frames the summary lists (the counts are always complete).
pub const LISTED: usize = 8;

impl CsiSummary {
    /// The summary of this capture and the `recording` made of it: `format`, `device`,
    /// `frame_format`, `frames_read`, `frames` (in the recording), `dropped` / `skipped`
    /// (counts and the first [`LISTED`]), `bandwidth_hz`, `center_hz` (null where the format
    /// does not say), `spacing_hz`, `n_rx`, `n_tx`, `subcarriers` (count), `subcarrier_range`,
    /// `pilots`, `grid_bins` (the uniform grid's length) and `masked_bins` (grid bins without a
    /// subcarrier, `P[n] = 0`), `links`, `gain_applied`, `unoccupied` (reported subcarriers left out
    /// as unoccupied: count and range), `notes`.
    pub fn to_json(&self, recording: &Recording) -> Value {
        let c = &self.capture;
        let grid = match &recording.layout {
            Layout::Cfr { freq_hz, .. } => freq_hz.len(),
            Layout::Cir { .. } => 0,
        };
        let first = |v: &[(usize, String)]| -> Vec<Value> {
            v.iter()
                .take(LISTED)
                .map(|(i, r)| json!({"frame": i, "reason": r}))
                .collect()
        };
        json!({
            "format": c.format.name(),
            "device": c.device,
            "frame_format": c.frame_format,
            "frames_read": c.t_s.len(),
            "frames": recording.t_s.len(),
            "duration_s": recording.t_s.last().copied().unwrap_or(0.0),
            "dropped": {
                "count": self.dropped.len(),
                "first": self.dropped.iter().take(LISTED)
                    .map(|(i, t)| json!({"frame": i, "t_s": t}))
                    .collect::<Vec<_>>(),
                "why": "time not increasing",
            },
            "skipped": {"count": c.skipped.len(), "first": first(&c.skipped)},
            "bandwidth_hz": c.bandwidth_hz,
            "center_hz": c.center_hz,
            "spacing_hz": c.spacing_hz,
            "n_rx": c.n_rx,
            "n_tx": c.n_tx,
            "subcarriers": c.subcarriers.len(),
            "subcarrier_range": [c.subcarriers.first(), c.subcarriers.last()],
            "pilots": c.pilots.len(),
            "grid_bins": grid,
            "masked_bins": grid.saturating_sub(c.subcarriers.len()),
            "links": recording.links,
            "gain_applied": self.gain_applied,
            "unoccupied": {
                "count": self.unoccupied.len(),
                "range": [self.unoccupied.first(), self.unoccupied.last()],
            },
            "notes": c.notes,
        })
    }
}
