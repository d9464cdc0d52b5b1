//! The synthetic stand-in for the measurement case of [S] §5.3 (spec §9.6 **[choice]**): a
//! pedestrian walking a 60 s loop (circle of radius 8 m about (12, 6) m at 1.4 m/s) through
//! layout L4, observed through a static channel (the LoS and static reflectors, see
//! [`crate::track::gating`]), so that links drop out where the echo falls in the blind zone of a
//! static path (`cΔτ_p < c/B`) and the delays carry the noise of (E8).

use alloc::vec::Vec;

use crate::error::{Error, Result};
use crate::math::{cos, sin, Real, Vec2, Vec4};
use crate::track::gating::StaticChannel;

/// Duration of the loop walk, s (spec §9.6).
pub const LOOP_DURATION_S: Real = 60.0;

/// A circular walk at constant speed, counter-clockwise from angle 0 (the point `centre +
/// (radius, 0)`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LoopPath {
    /// Centre of the circle, m.
    pub centre_m: Vec2,
    /// Radius, m.
    pub radius_m: Real,
    /// Walking speed, m/s.
    pub speed_mps: Real,
}

impl Default for LoopPath {
    /// Spec §9.6: centre (12, 6) m, radius 8 m, 1.4 m/s.
    fn default() -> Self {
        LoopPath {
            centre_m: Vec2::new(12.0, 6.0),
            radius_m: 8.0,
            speed_mps: 1.4,
        }
    }
}

impl LoopPath {
    /// Checks a finite centre and a radius and speed `> 0`.
    pub fn validate(&self) -> Result<()> {
        if !(self.centre_m.x.is_finite() && self.centre_m.y.is_finite()) {
            return Err(Error::NonFinite {
                field: "loop.centre_m".into(),
            });
        }
        for (field, v) in [
            ("loop.radius_m", self.radius_m),
            ("loop.speed_mps", self.speed_mps),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(Error::NotPositive {
                    field: field.into(),
                    value: v,
                });
            }
        }
        Ok(())
    }

    /// The state `[x, y, vx, vy]` at time `t_s`.
    pub fn state_at(&self, t_s: Real) -> Vec4 {
        let angle = self.speed_mps / self.radius_m * t_s;
        let (s, c) = (sin(angle), cos(angle));
        Vec4::new(
            self.centre_m.x + self.radius_m * c,
            self.centre_m.y + self.radius_m * s,
            -self.speed_mps * s,
            self.speed_mps * c,
        )
    }

    /// The states at `dt_s, 2·dt_s, …, steps·dt_s` (the filter's update times).
    pub fn states(&self, dt_s: Real, steps: usize) -> Vec<Vec4> {
        (1..=steps)
            .map(|k| self.state_at(k as Real * dt_s))
            .collect()
    }
}

/// The default static channel of the stand-in for a receiver bandwidth `B`: one static point
/// reflector at (6, 18) m (a wall corner north of the loop), static-path jitter 0.3 ns (well
/// above the clusterer's floor 0.01/B), static amplitude 30, resolution `1/B`, and
/// `false_alarms` per link and snapshot spread over 200 ns after the LoS.
pub fn default_channel(bandwidth_hz: Real, false_alarms: Real) -> StaticChannel {
    StaticChannel {
        reflectors_m: alloc::vec![Vec2::new(6.0, 18.0)],
        static_sigma_s: 0.3e-9,
        static_amplitude: 30.0,
        resolution_s: 1.0 / bandwidth_hz,
        false_alarms,
        false_alarm_span_s: 200e-9,
    }
}

#[cfg(test)]
mod tests;
