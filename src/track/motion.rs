//! White-noise-acceleration (constant-velocity) motion model (spec §6, E7 = S13, S14).

use crate::error::limits;
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

    /// The model after checking `dt_s` against [`limits::DT_S`] and `intensity` against
    /// [`limits::PROCESS_NOISE`].
    pub fn validated(dt_s: Real, intensity: Real) -> crate::Result<ConstantVelocity> {
        limits::DT_S.check("dt_s", dt_s)?;
        limits::PROCESS_NOISE.check("process_noise", intensity)?;
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

    /// `P ↦ A P Aᵀ + Q` for a symmetric `P` (its upper triangle is read), exploiting the
    /// structure of `A` (about 20 flops instead of 128); the result is exactly symmetric.
    /// With `B = A P` (rows 0, 1 gain `T` × rows 2, 3) and `A P Aᵀ = B Aᵀ` (columns 0, 1 gain
    /// `T` × columns 2, 3), the 10 unique entries are evaluated and mirrored.
    #[inline]
    pub fn propagate_covariance(&self, p: &Mat4) -> Mat4 {
        let t = self.dt_s;
        let q = self.process_noise();
        let (p00, p01, p02, p03) = (p[(0, 0)], p[(0, 1)], p[(0, 2)], p[(0, 3)]);
        let (p11, p12, p13) = (p[(1, 1)], p[(1, 2)], p[(1, 3)]);
        let (p22, p23, p33) = (p[(2, 2)], p[(2, 3)], p[(3, 3)]);
        // Rows 0, 1 of B (columns 2, 3 are also rows/columns of the result).
        let (b02, b03) = (p02 + t * p22, p03 + t * p23);
        let (b12, b13) = (p12 + t * p23, p13 + t * p33);
        let o00 = (p00 + t * p02) + t * b02 + q[(0, 0)];
        let o01 = (p01 + t * p12) + t * b03;
        let o11 = (p11 + t * p13) + t * b13 + q[(1, 1)];
        let (o02, o03) = (b02 + q[(0, 2)], b03);
        let (o12, o13) = (b12, b13 + q[(1, 3)]);
        let (o22, o23, o33) = (p22 + q[(2, 2)], p23, p33 + q[(3, 3)]);
        Mat4::new(
            o00, o01, o02, o03, //
            o01, o11, o12, o13, //
            o02, o12, o22, o23, //
            o03, o13, o23, o33,
        )
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
mod tests;
