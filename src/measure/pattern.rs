//! Transmit antenna pattern (spec §9.3):
//! `G_Tx(ψ)[dBi] = G₀ − min(12 (ψ/ψ_3dB)², A_m)`, ψ the angle between boresight and Tx→point.

use crate::math::Lanes;
use crate::math::{acos, cos, db_to_linear, deg_to_rad, exp, sin, Real, Vec2};
use crate::scenario::Pattern;

/// A compiled Tx pattern: linear gains, boresight unit vector and the Gaussian-in-ψ exponent.
#[derive(Debug, Clone, PartialEq)]
pub struct TxPattern {
    /// Peak gain `G₀`, linear.
    pub peak_gain: Real,
    /// `None` for omni; otherwise the directional parameters.
    pub beam: Option<Beam>,
    /// Fast form of the directional gain for the map kernel, when it fits (see [`GainPolynomial`]).
    pub polynomial: Option<GainPolynomial>,
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
        let mut pattern = TxPattern {
            peak_gain,
            beam,
            polynomial: None,
        };
        pattern.polynomial = GainPolynomial::fit(&pattern);
        pattern
    }

    /// Turns the beam to `boresight_deg` (an omni pattern is unchanged). The fitted polynomial
    /// does not depend on the boresight, so this equals compiling the turned pattern afresh
    /// (tested) without refitting: the planner turns beams per evaluation.
    pub fn set_boresight_deg(&mut self, boresight_deg: Real) {
        if let Some(b) = &mut self.beam {
            let phi = deg_to_rad(boresight_deg);
            b.boresight = Vec2::new(cos(phi), sin(phi));
            if let Some(p) = &mut self.polynomial {
                p.boresight = b.boresight;
            }
        }
    }

    /// Linear gain toward the unit direction `u` (Tx → point). A zero `u` (point on the Tx)
    /// gets the peak gain. In a 3-D room `u` is the horizontal part of the 3-D unit vector
    /// ([`crate::measure::unit_from_dz`]); the boresight is horizontal, so `u·b = cos ψ` with ψ
    /// the 3-D angle off boresight (a point straight below or above the Tx, `u = 0`, takes the
    /// peak gain, as on the Tx: a simplification at that one point). Uses the verified [`GainPolynomial`] when there is one (≤ 1e-12
    /// relative from the exact formula [`TxPattern::gain_toward_cos`]), so every consumer — point
    /// bound, map, simulation, EKF — sees the same gain without an `acos` and `exp` per call.
    #[inline(always)]
    pub fn gain_toward(&self, u: Vec2) -> Real {
        self.gains_toward([u.x], [u.y])[0]
    }

    /// [`TxPattern::gain_toward`] for `L` directions `(ux[l], uy[l])` at once, lane by lane the
    /// same operations (bitwise equal results); the Chebyshev recurrences of the lanes run side
    /// by side (the EKF updating several filters, the map kernel).
    #[inline(always)]
    pub fn gains_toward<const L: usize>(&self, ux: [Real; L], uy: [Real; L]) -> [Real; L] {
        let Some(b) = &self.beam else {
            return [self.peak_gain; L];
        };
        let c: [Real; L] = core::array::from_fn(|l| ux[l] * b.boresight.x + uy[l] * b.boresight.y);
        let mut gains = match &self.polynomial {
            Some(poly) => poly.gains_at_cos(c),
            None => c.map(|c| self.gain_toward_cos(c)),
        };
        for l in 0..L {
            if ux[l] == 0.0 && uy[l] == 0.0 {
                gains[l] = self.peak_gain;
            }
        }
        gains
    }
}

/// Highest Chebyshev degree tried for [`GainPolynomial`].
const MAX_POLY_DEGREE: usize = 40;
/// Largest relative error of [`GainPolynomial`] against the exact pattern that is accepted.
pub const GAIN_POLYNOMIAL_TOLERANCE: Real = 1e-12;

/// The main-lobe gain `G₀·exp(−k·acos(c)²)` as a Chebyshev series in `c = cos ψ` on
/// `[cos ψ_floor, 1]` (analytic there), with the floor below. Lets the CRLB map kernel evaluate the
/// §9.3 pattern with a few multiply-adds per cell instead of `acos` and `exp`; it is only built
/// when it matches the exact formula to [`GAIN_POLYNOMIAL_TOLERANCE`] (relative) everywhere.
#[derive(Debug, Clone, PartialEq)]
pub struct GainPolynomial {
    /// Boresight unit vector.
    pub boresight: Vec2,
    /// `cos ψ_floor`: below it the gain is the floor.
    pub floor_cos: Real,
    /// Floor gain, linear.
    pub floor_gain: Real,
    /// Chebyshev coefficients in `t = (2c − 1 − c_f)/(1 − c_f)`.
    pub coefficients: alloc::vec::Vec<Real>,
}

impl GainPolynomial {
    /// Fits the polynomial for a directional pattern; `None` for omni patterns or when no degree
    /// up to 40 reaches the tolerance (e.g. a floor so deep that the fit interval reaches `c = −1`).
    pub fn fit(pattern: &TxPattern) -> Option<GainPolynomial> {
        let beam = pattern.beam?;
        if beam.floor_angle_rad >= 0.95 * crate::math::PI {
            return None;
        }
        let floor_cos = cos(beam.floor_angle_rad);
        let exact = |c: Real| pattern.peak_gain * exp(-beam.exponent_per_rad2 * acos(c) * acos(c));
        let to_c = |t: Real| 0.5 * (t * (1.0 - floor_cos) + 1.0 + floor_cos);
        // Chebyshev interpolation at n first-kind nodes (discrete cosine transform).
        let n = MAX_POLY_DEGREE + 1;
        let pi = crate::math::PI;
        let values: alloc::vec::Vec<Real> = (0..n)
            .map(|j| exact(to_c(cos(pi * (j as Real + 0.5) / n as Real))))
            .collect();
        let mut coefficients: alloc::vec::Vec<Real> = (0..n)
            .map(|k| {
                let s: Real = (0..n)
                    .map(|j| values[j] * cos(pi * k as Real * (j as Real + 0.5) / n as Real))
                    .sum();
                s * 2.0 / n as Real
            })
            .collect();
        coefficients[0] *= 0.5;
        let scale = coefficients.iter().fold(0.0 as Real, |m, c| m.max(c.abs()));
        // Drop what is below rounding noise and far below the tolerance at the floor.
        let cutoff = (1e-15 * scale).max(0.01 * GAIN_POLYNOMIAL_TOLERANCE * beam.floor_gain);
        while coefficients.len() > 1 && coefficients.last().is_some_and(|c| c.abs() < cutoff) {
            coefficients.pop();
        }
        let poly = GainPolynomial {
            boresight: beam.boresight,
            floor_cos,
            floor_gain: beam.floor_gain,
            coefficients,
        };
        // Verify against the exact formula on a dense set of directions.
        let ok = (0..=2048).all(|i| {
            let c = to_c(-1.0 + 2.0 * i as Real / 2048.0);
            let e = pattern.gain_toward_cos(c);
            (poly.gain_at_cos(c) - e).abs() <= GAIN_POLYNOMIAL_TOLERANCE * e
        });
        ok.then_some(poly)
    }

    /// Gain for `c = cos ψ`, linear.
    #[inline(always)]
    pub fn gain_at_cos(&self, c: Real) -> Real {
        self.gains_at_cos([c])[0]
    }

    /// [`GainPolynomial::gain_at_cos`] for `L` directions at once (the same operations in the
    /// same order, so each result is bitwise equal); with `L = 4` the recurrence stays in vector
    /// registers (CRLB map kernel).
    #[inline(always)]
    pub fn gains_at_cos<const L: usize>(&self, c: [Real; L]) -> [Real; L] {
        let span = 1.0 - self.floor_cos;
        let t = c.map(|c| (2.0 * c - 1.0 - self.floor_cos) / span);
        // Clenshaw recurrence; `a − b2` first keeps the dependency chain through b1 short.
        let (mut b1, mut b2) = ([0.0; L], [0.0; L]);
        for &a in self.coefficients[1..].iter().rev() {
            for l in 0..L {
                let b0 = (a - b2[l]) + 2.0 * t[l] * b1[l];
                b2[l] = b1[l];
                b1[l] = b0;
            }
        }
        let mut out = [self.floor_gain; L];
        for l in 0..L {
            if c[l] > self.floor_cos {
                out[l] = (self.coefficients[0] + t[l] * b1[l] - b2[l]).max(self.floor_gain);
            }
        }
        out
    }
}

impl GainPolynomial {
    /// [`GainPolynomial::gains_at_cos`] for `N` vectors of directions (the CRLB map kernel;
    /// `N = 2` interleaves two recurrences so their latencies overlap). With an exact
    /// [`Lanes`] type it performs the same operations in the same order, so each lane is
    /// bitwise equal to the scalar result; a fused one rounds once per multiply-add. The floor
    /// is a branch-free blend.
    #[inline(always)]
    pub(crate) fn gains_at_cos_lanes<L: Lanes, const N: usize>(&self, c: [L; N]) -> [L; N] {
        // Plain loops, no closures: every step must inline into the caller, whose target
        // features (AVX2, AVX-512) the vector operations need (issue 29).
        let arch = c[0].arch();
        let two = L::splat(arch, 2.0);
        let one = L::splat(arch, 1.0);
        let fc = L::splat(arch, self.floor_cos);
        let zero = L::splat(arch, 0.0);
        let mut t = [zero; N];
        let mut t2 = [zero; N];
        for i in 0..N {
            t[i] = (c[i] * two - one - fc).div_const(1.0 - self.floor_cos);
            t2[i] = t[i] * two;
        }
        let (mut b1, mut b2) = ([zero; N], [zero; N]);
        for &a in self.coefficients[1..].iter().rev() {
            let a = L::splat(arch, a);
            for i in 0..N {
                let b0 = L::mul_add(t2[i], b1[i], a - b2[i]);
                b2[i] = b1[i];
                b1[i] = b0;
            }
        }
        let floor = L::splat(arch, self.floor_gain);
        let c0 = L::splat(arch, self.coefficients[0]);
        let mut out = [zero; N];
        for i in 0..N {
            let main = (L::mul_add(t[i], b1[i], c0) - b2[i]).max(floor);
            out[i] = L::select(c[i].gt(fc), main, floor);
        }
        out
    }
}

impl TxPattern {
    /// Exact gain for `c = cos ψ` (the §9.3 formula), linear.
    pub fn gain_toward_cos(&self, c: Real) -> Real {
        match &self.beam {
            None => self.peak_gain,
            Some(b) => {
                let psi = acos(c.clamp(-1.0, 1.0));
                if psi >= b.floor_angle_rad {
                    b.floor_gain
                } else {
                    self.peak_gain * exp(-b.exponent_per_rad2 * psi * psi)
                }
            }
        }
    }
}

#[cfg(test)]
mod tests;
