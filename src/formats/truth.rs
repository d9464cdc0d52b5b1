//! The truth file of a simulated walk (`simulate-walk`'s `truth.json`, `track --truth`): the
//! true states at the track's times (spec §9.6) and whether each link's echo was resolved.

use alloc::format;
use alloc::vec::Vec;

use serde::{Deserialize, Serialize};

use crate::error::{limits, Error, Result};
use crate::scenario::parse_json;

/// The true states at the track's times. `resolved` is written by `simulate-walk` and optional
/// on input; other keys are ignored on input.
///
/// # Example
///
/// ```
/// use scatterloc::formats::Truth;
///
/// let t = Truth::from_json(r#"{"t_s": [0.1, 0.2], "states": [[0,0,1,0], [0.1,0,1,0]]}"#)
///     .unwrap();
/// t.check_times(&[0.1, 0.2]).unwrap();
/// // The track's times must be the truth's.
/// let e = t.check_times(&[0.1, 0.3]).unwrap_err();
/// assert_eq!(e.to_string(), "t_s[1]: 0.2 but the track's step is at 0.3 s");
/// // Positions are coordinates (±1e7 m), velocities within ±1e6 m/s.
/// let far = Truth::from_json(r#"{"t_s": [0.1], "states": [[1e100, 0, 1, 0]]}"#).unwrap();
/// let e = far.check_times(&[0.1]).unwrap_err();
/// assert_eq!(e.to_string(), "states[0][0]: 1e100 is out of range (-1e7 to 1e7 m)");
/// ```
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
pub struct Truth {
    /// Times, s (must equal the track's).
    pub t_s: Vec<f64>,
    /// `[x, y, vx, vy]` per time.
    pub states: Vec<[f64; 4]>,
    /// Per step, per link: whether the echo was resolved from every static path.
    #[serde(default)]
    pub resolved: Vec<Vec<bool>>,
}

impl Truth {
    /// Parses a truth file (errors name the field: [`Error::Parse`]).
    pub fn from_json(text: &str) -> Result<Truth> {
        parse_json(text)
    }

    /// Checks that the times are the track's `t_s` (to 1e-9 relative) and every state is
    /// finite, its position within [`limits::COORDINATE_M`] and its velocity within
    /// [`limits::VELOCITY_M_S`], as a tracker's states ([`Error::InvalidFile`] of `t_s`,
    /// [`Error::NonFinite`] of `states[k]`, [`Error::OutOfRange`] of `states[k][i]`; issue 37:
    /// states at 1e100 m gave a median error of 1e100 m, at 1e160 m none).
    pub fn check_times(&self, t_s: &[f64]) -> Result<()> {
        let n = t_s.len();
        if self.t_s.len() != n || self.states.len() != n {
            return Err(Error::InvalidFile {
                field: "t_s".into(),
                reason: format!(
                    "{} times and {} states, the track has {n} steps",
                    self.t_s.len(),
                    self.states.len()
                ),
            });
        }
        if let Some(k) =
            (0..n).find(|&k| (self.t_s[k] - t_s[k]).abs() > 1e-9 * t_s[k].abs().max(1.0))
        {
            return Err(Error::InvalidFile {
                field: format!("t_s[{k}]"),
                reason: format!("{} but the track's step is at {} s", self.t_s[k], t_s[k]),
            });
        }
        if let Some(k) = self
            .states
            .iter()
            .position(|s| s.iter().any(|v| !v.is_finite()))
        {
            return Err(Error::NonFinite {
                field: format!("states[{k}]"),
            });
        }
        let ranges = [
            limits::COORDINATE_M,
            limits::COORDINATE_M,
            limits::VELOCITY_M_S,
            limits::VELOCITY_M_S,
        ];
        for (k, s) in self.states.iter().enumerate() {
            for (i, (v, range)) in s.iter().zip(&ranges).enumerate() {
                if !range.contains(*v) {
                    range.check(&format!("states[{k}][{i}]"), *v)?;
                }
            }
        }
        Ok(())
    }
}
