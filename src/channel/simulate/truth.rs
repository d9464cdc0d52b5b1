//! What the simulator knows of a recording it made ([`ChannelTruth`]): per snapshot the walker's
//! state, per link the true paths ([`TruePath`], [`PathKind`]) and whether the walker shadows the
//! LoS, and what each receiver's clock did ([`ClockState`], C10); with further walkers (issue 41)
//! their states beside it ([`SimulationTruth`]).

use alloc::vec::Vec;

use serde::{Deserialize, Serialize};

/// What a path of the truth is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PathKind {
    /// Tx → Rx.
    Los,
    /// Tx → wall → Rx.
    Wall,
    /// Tx → wall → wall → Rx.
    WallWall,
    /// Tx → point scatterer → Rx.
    Scatterer,
    /// Tx → walker → Rx (the sum of the body's centres; reported at the walker's centre).
    Body,
    /// Tx → wall → walker → Rx or Tx → walker → wall → Rx.
    BodyWall,
}

/// One true path of a link in a snapshot.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TruePath {
    /// What it is.
    pub kind: PathKind,
    /// Propagation delay τ, s.
    pub delay_s: f64,
    /// Mean received power `|α|²`, W (after shadowing; for the body the mean over its
    /// fluctuation, evaluated at the walker's centre with the full `target.rcs_m2`).
    pub power_w: f64,
}

/// What the simulator knows. Readable as a [`crate::formats::Truth`] (`t_s`, `states`; the
/// other fields are ignored there).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ChannelTruth {
    /// Snapshot times, s.
    pub t_s: Vec<f64>,
    /// The walker's `[x, y, vx, vy]` per snapshot (empty for the empty-area recording).
    #[serde(default)]
    pub states: Vec<[f64; 4]>,
    /// Per snapshot, per link (recording order) the true paths.
    pub paths: Vec<Vec<Vec<TruePath>>>,
    /// Per snapshot, per link whether the walker shadows the LoS.
    pub shadowed: Vec<Vec<bool>>,
    /// Per snapshot, per link what the receiver's clock did (C10; empty for a synchronised
    /// sounder).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub clock: Vec<Vec<ClockState>>,
}

/// One snapshot of a link's receiver clock (C10): `H' = g·e^{jφ}·e^{−j2πf_nδ}·e^{jε_n}·H`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ClockState {
    /// Timing offset `δ`, s.
    pub delay_s: f64,
    /// Carrier phase `φ`, rad.
    pub phase_rad: f64,
    /// Gain `|g|`, dB.
    pub gain_db: f64,
}

/// The truth of a simulation as `cir simulate` writes it (`truth.json`): the [`ChannelTruth`]'s
/// keys and, with further walkers ([`super::ChannelScene::others`], issue 41), `others`: per
/// further walker its `[x, y, vx, vy]` per snapshot (not written when there are none, so the
/// file of a single walker is the [`ChannelTruth`]'s).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SimulationTruth {
    /// The main walker's truth and every link's paths (of every walker).
    #[serde(flatten)]
    pub truth: ChannelTruth,
    /// Per further walker, its state per snapshot.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub others: Vec<Vec<[f64; 4]>>,
}
