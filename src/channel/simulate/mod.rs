//! The signal-level channel simulator (issue 25 §2): recordings in the layout of C1 of a scene
//! with walls (first- and second-order specular reflections by the image method), point
//! scatterers, and a walking person modelled as an extended, fluctuating scatterer that also
//! reflects via the walls and shadows the LoS and wall paths it stands in. Amplitudes come from
//! the scenario's link budget and Tx pattern (E8) and noise follows C3, so a path's `|α|²/P_n`
//! is the link budget's SNR. Seeded and deterministic (only `crate::math` functions). `scene`
//! holds the scene and its checks, `walk` the walker's path, `walkers` each walker's paths and
//! fluctuations (the main one and any further walkers of issue 41), `request` the CLI's and
//! the page's request, `truth` what the simulator knows, `geometry` and `rays` the paths of a link,
//! `signal` a path's phasors and the receiver clock, `synthesize` the recording snapshot by
//! snapshot.

mod geometry;
mod rays;
mod request;
mod scene;
mod signal;
mod synthesize;
mod truth;
mod walk;
mod walkers;

pub use request::{Simulated, SimulationRequest, DEFAULT_CALIBRATION_DURATION_S};
pub use scene::{
    Body, ChannelScene, Clock, PointScatterer, SceneCpi, Walker, Wall, DEFAULT_DT_S,
    DEFAULT_SUBCARRIERS, MAX_OTHER_WALKERS, MAX_SCENE_CPI_SNAPSHOTS,
};
pub use synthesize::simulate_recording;
pub use truth::{ChannelTruth, ClockState, PathKind, SimulationTruth, TruePath};
pub use walk::Walk;

#[cfg(test)]
mod tests;
#[cfg(test)]
mod walkers_tests;
