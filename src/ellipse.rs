//! Ellipses: iso-delay contours (spec §2) and 1σ covariance ellipses (CRLB, LM, EKF).

use alloc::vec::Vec;

use crate::math::{atan2, cos, sin, sqrt, Mat2, Real, Vec2, PI};

/// An ellipse given by centre, semi-axes and the orientation of the semi-major axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ellipse {
    /// Centre, m.
    pub center: Vec2,
    /// Semi-major axis `a`, m.
    pub semi_major: Real,
    /// Semi-minor axis `b ≤ a`, m.
    pub semi_minor: Real,
    /// Angle of the major axis from +x toward +y, rad.
    pub angle_rad: Real,
}

impl Ellipse {
    /// The `k`-σ ellipse `{r : (r−c)ᵀ Σ⁻¹ (r−c) = k²}` of a symmetric positive semi-definite
    /// covariance `Σ` (m²). `None` if `Σ` has a non-finite entry or a negative eigenvalue.
    pub fn from_covariance(center: Vec2, cov: &Mat2, k: Real) -> Option<Ellipse> {
        let (a, b, c) = (cov[(0, 0)], 0.5 * (cov[(0, 1)] + cov[(1, 0)]), cov[(1, 1)]);
        if !(a.is_finite() && b.is_finite() && c.is_finite()) {
            return None;
        }
        let mean = 0.5 * (a + c);
        let half_diff = 0.5 * (a - c);
        let radius = sqrt(half_diff * half_diff + b * b);
        let (l1, l2) = (mean + radius, mean - radius);
        if l2 < -1e-12 * l1.abs().max(Real::MIN_POSITIVE) {
            return None;
        }
        let angle = 0.5 * atan2(2.0 * b, a - c);
        Some(Ellipse {
            center,
            semi_major: k * sqrt(l1.max(0.0)),
            semi_minor: k * sqrt(l2.max(0.0)),
            angle_rad: angle,
        })
    }

    /// Point at parameter `theta` (rad) on the ellipse.
    pub fn point(&self, theta: Real) -> Vec2 {
        let (ct, st) = (cos(theta), sin(theta));
        let (ca, sa) = (cos(self.angle_rad), sin(self.angle_rad));
        let (u, v) = (self.semi_major * ct, self.semi_minor * st);
        self.center + Vec2::new(ca * u - sa * v, sa * u + ca * v)
    }

    /// `n` points evenly spaced in the parameter, for drawing (closed by the caller).
    pub fn polygon(&self, n: usize) -> Vec<Vec2> {
        (0..n)
            .map(|i| self.point(2.0 * PI * i as Real / n as Real))
            .collect()
    }
}
