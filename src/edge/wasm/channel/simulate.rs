//! The page's "Simulate walk": [`simulate_channel`] runs the core's simulation use case
//! ([`SimulationRequest`], the one home of `cir simulate`'s defaults and checks) and returns the
//! files `cir simulate` writes, after the page's own check that the recordings fit the page.

use alloc::string::String;
use alloc::vec::Vec;

use wasm_bindgen::prelude::*;

use super::{check_size, scenario_and_model};
use crate::channel::{ChannelScene, Recording, SimulationRequest};
use crate::edge::wasm::base::err;
use crate::edge::wasm::json::to_json;
use crate::error::limits::{MAX_PAGE_RECORDING_BYTES, MAX_PAGE_TEXT_BYTES};
use crate::error::{Cancel, Error};
use crate::npz;

/// The files of `cir simulate` for one scenario and simulation request.
#[wasm_bindgen]
pub struct SimulatedChannel {
    recording: Vec<u8>,
    calibration: Vec<u8>,
    truth_json: String,
    scene_json: String,
    summary: String,
}

#[wasm_bindgen]
impl SimulatedChannel {
    /// `recording.npz` (the walk, with the person), bytes.
    pub fn recording(&self) -> Vec<u8> {
        self.recording.clone()
    }

    /// `calibration.npz` (the empty area, its own noise stream), bytes.
    pub fn calibration(&self) -> Vec<u8> {
        self.calibration.clone()
    }

    /// `truth.json` as text: `{t_s: [s…], states: [[x, y, vx, vy]…], resolved: [[bool per
    /// link]…]}` (one state per snapshot of the recording).
    pub fn truth_json(&self) -> String {
        self.truth_json.clone()
    }

    /// `scene.json` as text: the scene simulated (the hangar or the one given, with the
    /// request's overrides applied).
    pub fn scene_json(&self) -> String {
        self.scene_json.clone()
    }

    /// The summary `cir simulate` prints, as JSON text: `{snapshots, calibration_snapshots,
    /// links, subcarriers}`.
    pub fn summary_json(&self) -> String {
        self.summary.clone()
    }
}

/// Simulates the recordings of `cir simulate` on scenario JSON `scenario_json` (schema v1):
/// `settings_json` is `""` or the core's `SimulationRequest` as JSON, `{scene?: <scene JSON
/// object, default the hangar>, walk?: [[x, y], …] (m, ≥ 2 points; the CLI's --walk),
/// speed_mps?: m/s (--speed), duration_s?: s (--duration), dt_s?: s (--dt),
/// calibration_duration_s?: s (--calibration-duration, default 1), seed?: integer (--seed,
/// default 1)}`; unknown fields are refused. Before anything is simulated, both recordings
/// must fit the page ([`MAX_PAGE_RECORDING_BYTES`] of complex128 samples: `duration_s` or
/// `calibration_duration_s` named). Throws the core's named error (`walk`, `speed_mps`,
/// `duration_s`, `scene.walls[0].gamma`, …).
#[wasm_bindgen]
pub fn simulate_channel(
    scenario_json: &str,
    settings_json: &str,
) -> Result<SimulatedChannel, JsError> {
    let (scenario, model) = scenario_and_model(scenario_json)?;
    let req: SimulationRequest = if settings_json.trim().is_empty() {
        SimulationRequest::default()
    } else {
        check_size("settings", settings_json.len(), MAX_PAGE_TEXT_BYTES as u64).map_err(err)?;
        crate::scenario::parse_json(settings_json)
            .map_err(|e| JsError::new(&alloc::format!("settings: {e}")))?
    };
    let (scene, empty) = req.scenes().map_err(err)?;
    check_simulated_size("duration_s", &scene, model.link_count())?;
    check_simulated_size("calibration_duration_s", &empty, model.link_count())?;
    // The page's worker is ended by terminating it: nothing to ask here.
    let sim = req.run(&scenario, &model, Cancel::NEVER).map_err(err)?;
    let enc = |r: &Recording| {
        npz::write_recording(r).map_err(|e| JsError::new(&alloc::format!("recording: {e}")))
    };
    Ok(SimulatedChannel {
        recording: enc(&sim.recording)?,
        calibration: enc(&sim.calibration)?,
        truth_json: to_json(&sim.truth)?,
        scene_json: to_json(&sim.scene)?,
        summary: to_json(&serde_json::json!({
            "snapshots": sim.recording.t_s.len(),
            "calibration_snapshots": sim.calibration.t_s.len(),
            "links": model.link_count(),
            "subcarriers": sim.scene.subcarriers,
        }))?,
    })
}

/// [`Error::SizeLimit`] of `field` when a (validated) `scene` on `links` links would make a
/// recording of more than [`MAX_PAGE_RECORDING_BYTES`] of complex128 samples (checked before
/// anything is simulated: the simulator's own cap is for the CLI's memory).
fn check_simulated_size(
    field: &'static str,
    scene: &ChannelScene,
    links: usize,
) -> Result<(), JsError> {
    let duration = match scene.duration_s {
        Some(d) => d,
        None => scene.walk.duration_s().map_err(err)?,
    };
    let per_snapshot = (links * scene.subcarriers * 16).max(1) as f64;
    let max = MAX_PAGE_RECORDING_BYTES as f64 / per_snapshot;
    let snapshots = duration / scene.dt_s + 1.0;
    if snapshots.is_nan() || snapshots > max {
        return Err(err(Error::SizeLimit {
            field,
            value: snapshots.min(usize::MAX as f64) as usize,
            min: 1,
            max: max as usize,
        }));
    }
    Ok(())
}
