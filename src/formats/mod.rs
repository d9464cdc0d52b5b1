//! The files the tracker reads and writes, one serde type per format (issue 23 §1): the
//! measurements of `track` with `steps` or `raw_steps` ([`Measurements`]), the calibration
//! snapshots of `calibrate` ([`CalibrationSnapshots`]), the calibration result
//! ([`CalibrationResult`]) and the truth of a simulated walk ([`Truth`]). Each parses with
//! `from_json` (errors name the field, [`crate::Error::Parse`]) and checks what serde cannot
//! (lengths per link, step counts, times) with named [`crate::Error`]s; the CLI reads and
//! writes through them, so the files of `simulate-walk`, `calibrate` and `track` have one
//! definition each; the detections of other tools and of `cir estimate` ([`Detections`],
//! JSON lines, docs/detections.md) convert to a [`Measurements`]. The measurement model is
//! spec E1 (delays), the gating E4 and the association spec §4.

mod calibration;
mod detections;
mod measurements;
mod truth;

pub use calibration::{CalibrationResult, CalibrationSnapshots};
pub use detections::{DelayUnit, DetectionFrame, DetectionLine, Detections};
pub use measurements::{
    one_list_per_link, CheckedRates, CpiFields, Measurements, RangeRateFields, RateSigma,
    RawEstimate, RawStep, Sigma, Start, Steps, RANGE_RATE_KEYS,
};
pub use truth::Truth;

#[cfg(test)]
mod tests;
