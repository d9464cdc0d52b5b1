//! White-noise-acceleration (constant-velocity) motion model (spec §6, E7 = S13, S14).

use crate::math::{sqrt, Mat4, Real, Vec4};

/// The CV model for a step `T` and intensity `q̃`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ConstantVelocity {
    /// Time step `T = t_n − t_{n−1}`, s.
    pub dt_s: Real,
    /// Process-noise intensity `q̃`, m²/s³ (papers: σ_q² = 0.01).
    pub intensity: Real,
}

impl ConstantVelocity {
    /// The model; `dt_s` and `intensity` are validated by callers that take user input
    /// (see [`ConstantVelocity::validated`]).
    pub fn new(dt_s: Real, intensity: Real) -> ConstantVelocity {
        ConstantVelocity { dt_s, intensity }
    }

    /// The model after checking `dt_s > 0` and `intensity > 0`, both finite.
    pub fn validated(dt_s: Real, intensity: Real) -> crate::Result<ConstantVelocity> {
        for (field, v) in [("dt_s", dt_s), ("process_noise", intensity)] {
            if !v.is_finite() {
                return Err(crate::Error::NonFinite {
                    field: field.into(),
                });
            }
            if v <= 0.0 {
                return Err(crate::Error::NotPositive {
                    field: field.into(),
                    value: v,
                });
            }
        }
        Ok(ConstantVelocity { dt_s, intensity })
    }

    /// State transition `A` (E7), state `[x, y, vx, vy]`.
    pub fn transition(&self) -> Mat4 {
        let t = self.dt_s;
        Mat4::new(
            1.0, 0.0, t, 0.0, //
            0.0, 1.0, 0.0, t, //
            0.0, 0.0, 1.0, 0.0, //
            0.0, 0.0, 0.0, 1.0,
        )
    }

    /// Process-noise covariance `Q` (E7).
    pub fn process_noise(&self) -> Mat4 {
        let (t, q) = (self.dt_s, self.intensity);
        let (a, b, c) = (q * t * t * t / 3.0, q * t * t / 2.0, q * t);
        Mat4::new(
            a, 0.0, b, 0.0, //
            0.0, a, 0.0, b, //
            b, 0.0, c, 0.0, //
            0.0, b, 0.0, c,
        )
    }

    /// `x ↦ A x`.
    #[inline]
    pub fn propagate(&self, x: &Vec4) -> Vec4 {
        let t = self.dt_s;
        Vec4::new(x[0] + t * x[2], x[1] + t * x[3], x[2], x[3])
    }

    /// `P ↦ A P Aᵀ + Q`, exploiting the structure of `A` (about 30 flops instead of 128).
    #[inline]
    pub fn propagate_covariance(&self, p: &Mat4) -> Mat4 {
        let t = self.dt_s;
        // B = A P: rows 0, 1 gain t × rows 2, 3.
        let mut b = *p;
        for c in 0..4 {
            b[(0, c)] += t * p[(2, c)];
            b[(1, c)] += t * p[(3, c)];
        }
        // A P Aᵀ = B Aᵀ: columns 0, 1 gain t × columns 2, 3.
        let mut out = b;
        for r in 0..4 {
            out[(r, 0)] += t * b[(r, 2)];
            out[(r, 1)] += t * b[(r, 3)];
        }
        out + self.process_noise()
    }

    /// A lower-triangular `L` with `L Lᵀ = Q`, for sampling process noise: the x and y blocks are
    /// independent 2×2 blocks `q̃ [[T³/3, T²/2], [T²/2, T]]`, with closed-form Cholesky factors.
    pub fn process_noise_factor(&self) -> Mat4 {
        let (t, q) = (self.dt_s, self.intensity);
        let l11 = sqrt(q * t * t * t / 3.0);
        let l21 = q * t * t / 2.0 / l11;
        let l22 = sqrt((q * t - l21 * l21).max(0.0));
        Mat4::new(
            l11, 0.0, 0.0, 0.0, //
            0.0, l11, 0.0, 0.0, //
            l21, 0.0, l22, 0.0, //
            0.0, l21, 0.0, l22,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Spec check 4: T = 2.048 ms, q̃ = 0.01 → Q11 = 2.8633e-11 m², Q13 = 2.0972e-8,
    /// Q33 = 2.048e-5 (m/s)².
    #[test]
    fn check4_process_noise() {
        let q = ConstantVelocity::new(2.048e-3, 0.01).process_noise();
        assert!((q[(0, 0)] / 2.8633e-11 - 1.0).abs() < 5e-5);
        assert!((q[(0, 2)] / 2.0972e-8 - 1.0).abs() < 5e-5);
        assert!((q[(2, 2)] / 2.048e-5 - 1.0).abs() < 1e-12);
        assert_eq!(q[(1, 1)], q[(0, 0)]);
        assert_eq!(q[(0, 1)], 0.0);
        assert_eq!(q, q.transpose());
    }

    /// The structured `A P Aᵀ + Q` equals the plain matrix product; `L Lᵀ = Q`.
    #[test]
    fn structured_products_match_plain_algebra() {
        let m = ConstantVelocity::new(0.1, 0.01);
        let p = Mat4::new(
            2.0, 0.3, 0.1, -0.2, //
            0.3, 1.5, 0.05, 0.1, //
            0.1, 0.05, 0.4, 0.02, //
            -0.2, 0.1, 0.02, 0.3,
        );
        let a = m.transition();
        let plain = a * p * a.transpose() + m.process_noise();
        assert!((m.propagate_covariance(&p) - plain).abs().max() < 1e-15);
        let x = Vec4::new(1.0, 2.0, 3.0, 4.0);
        assert_eq!(m.propagate(&x), a * x);
        let l = m.process_noise_factor();
        assert!((l * l.transpose() - m.process_noise()).abs().max() < 1e-18);
    }
}
