//! The signal-level channel simulator — SKELETON: the simulator helper fills this in.

use crate::channel::Recording;
use crate::error::Result;
use crate::measure::Model;

/// The static and mobile scene of a simulated recording.
#[derive(Debug, Clone, PartialEq)]
pub struct ChannelScene {}

/// What the simulator knows: the true states and path delays.
#[derive(Debug, Clone, PartialEq)]
pub struct ChannelTruth {}

/// Simulates a recording of `scene` on `model`'s links.
pub fn simulate_recording(
    _model: &Model,
    _scene: &ChannelScene,
    _seed: u64,
) -> Result<(Recording, ChannelTruth)> {
    todo!("simulator helper")
}
