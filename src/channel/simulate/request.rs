//! The simulation use case (`cir simulate`, the page's "Simulate", `scatterloc.
//! simulate_recording`): a scene with the walk's overrides, the walk's recording and the empty
//! area's, the truth — one home for its defaults and checks, so the three edges only convert.

use serde::{Deserialize, Serialize};

use super::synthesize::{synthesize, synthesize_all};
use super::{ChannelScene, ChannelTruth, SimulationTruth};
use crate::channel::Recording;
use crate::error::{Cancel, Error, Result};
use crate::measure::Model;
use crate::scenario::Scenario;

/// Default length of the empty area's recording, s.
pub const DEFAULT_CALIBRATION_DURATION_S: f64 = 1.0;

/// A simulation: the scene (default the hangar of docs/reproduction.md) with optional
/// overrides of the walk, the length of the empty area's recording and the seed. JSON: this
/// object with any subset of its fields, unknown ones refused.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SimulationRequest {
    /// The scene (`None`: [`ChannelScene::hangar`]).
    pub scene: Option<ChannelScene>,
    /// The walk's waypoints, m (at least two), replacing the scene's.
    pub walk: Option<alloc::vec::Vec<[f64; 2]>>,
    /// The walking speed, m/s, replacing the scene's.
    pub speed_mps: Option<f64>,
    /// The recording's length, s (default: the scene's, else the walk's duration).
    pub duration_s: Option<f64>,
    /// The snapshot interval, s, replacing the scene's.
    pub dt_s: Option<f64>,
    /// The empty area's recording, s (default 1).
    pub calibration_duration_s: f64,
    /// The seed (default 1).
    pub seed: u64,
}

impl Default for SimulationRequest {
    fn default() -> Self {
        SimulationRequest {
            scene: None,
            walk: None,
            speed_mps: None,
            duration_s: None,
            dt_s: None,
            calibration_duration_s: DEFAULT_CALIBRATION_DURATION_S,
            seed: 1,
        }
    }
}

/// What a simulation made.
#[derive(Debug, Clone, PartialEq)]
pub struct Simulated {
    /// The walk's recording.
    pub recording: Recording,
    /// The empty area's recording (its own noise stream).
    pub calibration: Recording,
    /// The truth of the walk.
    pub truth: ChannelTruth,
    /// The states `[x, y, vx, vy]` per snapshot of each further walker of the scene
    /// ([`ChannelScene::others`], issue 41; empty without).
    pub others: alloc::vec::Vec<alloc::vec::Vec<[f64; 4]>>,
    /// The scene simulated (overrides applied).
    pub scene: ChannelScene,
}

impl SimulationRequest {
    /// The walk's scene and the empty area's, checked. An error names the request's field
    /// it came from: `walk`, `speed_mps`, `duration_s`, `dt_s`, `calibration_duration_s`, else
    /// the scene's own (`scene.walls[0].gamma`, …).
    pub fn scenes(&self) -> Result<(ChannelScene, ChannelScene)> {
        let mut scene = self.scene.clone().unwrap_or_else(ChannelScene::hangar);
        if let Some(w) = &self.walk {
            scene.walk.waypoints_m = w.clone();
        }
        if let Some(v) = self.speed_mps {
            scene.walk.speed_mps = v;
        }
        if let Some(d) = self.duration_s {
            scene.duration_s = Some(d);
        }
        if let Some(dt) = self.dt_s {
            scene.dt_s = dt;
        }
        scene.validate().map_err(|e| self.attribute(e))?;
        let mut empty = scene.clone();
        empty.duration_s = Some(self.calibration_duration_s);
        empty.validate().map_err(|e| Error::InvalidFile {
            field: "calibration_duration_s".into(),
            reason: strip_field(&e),
        })?;
        Ok((scene, empty))
    }

    /// An error of the overridden scene under the name of the override that set the field.
    fn attribute(&self, e: Error) -> Error {
        let field = e.field().unwrap_or("");
        let name = if self.walk.is_some() && field.starts_with("scene.walk.waypoints") {
            "walk"
        } else if self.speed_mps.is_some() && field == "scene.walk.speed_mps" {
            "speed_mps"
        } else if self.duration_s.is_some() && field == "scene.duration_s" {
            "duration_s"
        } else if self.dt_s.is_some() && field == "scene.dt_s" {
            "dt_s"
        } else {
            return e;
        };
        Error::InvalidFile {
            field: name.into(),
            reason: strip_field(&e),
        }
    }

    /// Simulates both recordings on `model` (of `scenario`); `cancel` is asked once per
    /// snapshot. Errors: [`SimulationRequest::scenes`]'s, the simulator's (its caps on
    /// samples, truth and work name `duration_s`, or `calibration_duration_s` for the empty
    /// area), [`Error::Cancelled`].
    pub fn run(&self, scenario: &Scenario, model: &Model, cancel: Cancel) -> Result<Simulated> {
        let (scene, empty) = self.scenes()?;
        let (recording, truth, others) =
            synthesize_all(scenario, model, &scene, true, self.seed, true, cancel)
                .map_err(|e| self.attribute(e))?;
        let (calibration, _) = synthesize(scenario, model, &empty, false, self.seed, true, cancel)
            .map_err(|e| match e {
                Error::Cancelled => e,
                _ => Error::InvalidFile {
                    field: "calibration_duration_s".into(),
                    reason: strip_field(&e),
                },
            })?;
        Ok(Simulated {
            recording,
            calibration,
            truth,
            others,
            scene,
        })
    }
}

impl Simulated {
    /// The truth as `cir simulate` writes it (`truth.json`): the [`ChannelTruth`]'s keys, and
    /// `others` with further walkers.
    pub fn truth_file(&self) -> SimulationTruth {
        SimulationTruth {
            truth: self.truth.clone(),
            others: self.others.clone(),
        }
    }
}

/// `e`'s message without its leading `field: `.
fn strip_field(e: &Error) -> alloc::string::String {
    let text = alloc::string::ToString::to_string(e);
    match e.field() {
        Some(f) => text
            .strip_prefix(f)
            .and_then(|t| t.strip_prefix(": "))
            .map(alloc::string::ToString::to_string)
            .unwrap_or(text),
        None => text,
    }
}
