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

    /// `n ≥ 2` points of the arc that passes near `p`, spanning about `±1.5·radius` of arc length
    /// around the point whose parameter matches `p`'s direction from the centre; empty when the
    /// ellipse stays farther than `2·radius` from `p` there. For drawing a small window around `p`
    /// (an iso-delay ellipse metres across, seen at millimetre scale) without a huge path.
    pub fn arc_near(&self, p: Vec2, radius: Real, n: usize) -> Vec<Vec2> {
        let (a, b) = (self.semi_major, self.semi_minor);
        let (ca, sa) = (cos(self.angle_rad), sin(self.angle_rad));
        let d = p - self.center;
        let (u, v) = (ca * d.x + sa * d.y, -sa * d.x + ca * d.y);
        let t0 = atan2(a * v, b * u);
        if !(radius.is_finite() && radius > 0.0 && t0.is_finite() && n >= 2)
            || (self.point(t0) - p).norm() > 2.0 * radius
        {
            return Vec::new();
        }
        let speed = sqrt(a * a * sin(t0) * sin(t0) + b * b * cos(t0) * cos(t0));
        if speed.is_nan() || speed <= 0.0 {
            return Vec::new();
        }
        let half = (1.5 * radius / speed).min(PI);
        (0..n)
            .map(|i| self.point(t0 - half + 2.0 * half * i as Real / (n - 1) as Real))
            .collect()
    }

    /// `n` points evenly spaced in the parameter, for drawing (closed by the caller).
    pub fn polygon(&self, n: usize) -> Vec<Vec2> {
        (0..n)
            .map(|i| self.point(2.0 * PI * i as Real / n as Real))
            .collect()
    }
}
