//! Transmit antenna pattern (spec §9.3):
//! `G_Tx(ψ)[dBi] = G₀ − min(12 (ψ/ψ_3dB)², A_m)`, ψ the angle between boresight and Tx→point.

use crate::math::{acos, cos, db_to_linear, deg_to_rad, exp, sin, Real, Vec2};
use crate::scenario::Pattern;

/// A compiled Tx pattern: linear gains, boresight unit vector and the Gaussian-in-ψ exponent.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TxPattern {
    /// Peak gain `G₀`, linear.
    pub peak_gain: Real,
    /// `None` for omni; otherwise the directional parameters.
    pub beam: Option<Beam>,
}

/// Parameters of the parabolic (in dB) main beam.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Beam {
    /// Boresight unit vector (cos φ₀, sin φ₀).
    pub boresight: Vec2,
    /// `12·ln(10)/10 / ψ_3dB²`, so that `G = G₀·exp(−k ψ²)` inside the floor, 1/rad².
    pub exponent_per_rad2: Real,
    /// ψ beyond which the floor applies: `ψ_3dB·√(A_m/12)`, rad.
    pub floor_angle_rad: Real,
    /// Floor gain `G₀·10^(−A_m/10)`, linear.
    pub floor_gain: Real,
}

impl TxPattern {
    /// Compiles the JSON pattern with peak gain `gain_dbi`.
    pub fn new(gain_dbi: Real, pattern: &Pattern) -> TxPattern {
        let peak_gain = db_to_linear(gain_dbi);
        let beam = match *pattern {
            Pattern::Omni => None,
            Pattern::Parabolic {
                boresight_deg,
                beamwidth_deg,
                floor_db,
            } => {
                let phi = deg_to_rad(boresight_deg);
                let psi3 = deg_to_rad(beamwidth_deg);
                Some(Beam {
                    boresight: Vec2::new(cos(phi), sin(phi)),
                    exponent_per_rad2: 1.2 * core::f64::consts::LN_10 / (psi3 * psi3),
                    floor_angle_rad: psi3 * crate::math::sqrt(floor_db / 12.0),
                    floor_gain: peak_gain * db_to_linear(-floor_db),
                })
            }
        };
        TxPattern { peak_gain, beam }
    }

    /// Linear gain toward the unit direction `u` (Tx → point). A zero `u` (point on the Tx)
    /// gets the peak gain.
    #[inline(always)]
    pub fn gain_toward(&self, u: Vec2) -> Real {
        match &self.beam {
            None => self.peak_gain,
            Some(b) => {
                if u.x == 0.0 && u.y == 0.0 {
                    return self.peak_gain;
                }
                let c = (u.x * b.boresight.x + u.y * b.boresight.y).clamp(-1.0, 1.0);
                let psi = acos(c);
                if psi >= b.floor_angle_rad {
                    b.floor_gain
                } else {
                    self.peak_gain * exp(-b.exponent_per_rad2 * psi * psi)
                }
            }
        }
    }
}
