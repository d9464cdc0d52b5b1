//! The EKF's delay-and-Doppler update (issue 42 §3; D3, D8; S17): the rows of
//! [`rows`](crate::track::doppler) see the velocity, so the batch update of the [`ekf`](super)
//! module runs in the full 4-D state instead of the position plane — the same push-through
//! identity with `Π = I`: `M = Hᵀ R⁻¹ H`, `b = Hᵀ R⁻¹ ν`, `N = (I + M P⁻)⁻¹`,
//! `x̂ = x̂⁻ + P⁻ N b`, Joseph form `P = P⁻ − P⁻ Z P⁻` with
//! `Z = N M + (N M)ᵀ − N (M + M P⁻ M) Nᵀ`, and `NIS = νᵀ R⁻¹ ν − bᵀ P⁻ N b`. One 4 × 4 inverse,
//! no `m × m` solve, no allocation. The covariance is computed as the equal
//! `(I − A M) P⁻ (I − A M)ᵀ + A M Aᵀ` with `A = P⁻ N` (`K H = A M`), on its upper triangle, and
//! `M` is accumulated on its upper triangle (issue 42 §4: fewer products, the same matrices up
//! to rounding).

use super::Ekf;
use crate::error::{Error, Result};
use crate::math::{Mat4, Real, Vec4};
use crate::measure::Model;
use crate::track::doppler::{check_rates, rows, RangeRates};
use crate::track::shared::{Ldl4, NO_UPDATE};
use crate::track::{Filter, MeasurementNoise, UpdateSummary};

impl Ekf {
    /// Update with delays `z` (s, `None` = missing) and range rates `rates` (m/s, `None` =
    /// missing), both one per link in scenario link order, linearised once at the predicted
    /// state (module docs). Without rates it is the delay-only update ([`Ekf::update`]) up to
    /// rounding. On error the filter is left unchanged: bad delays and σ as in the delay-only
    /// update, a rate or its σ out of range named (`range_rates[p]`, `range_rate_sigma_mps[p]`).
    pub fn update_doppler(
        &mut self,
        model: &Model,
        z: &[Option<Real>],
        noise: MeasurementNoise,
        rates: &RangeRates,
    ) -> Result<UpdateSummary> {
        check_rates(model, z, noise, rates, self.position())?;
        // `M = Hᵀ R⁻¹ H`, accumulated on its upper triangle (the lower is its mirror): a
        // delay row `[g, 0]` touches the position block only.
        let (mut u, mut b, mut chi2) = ([0.0; 10], Vec4::zeros(), 0.0);
        let links = rows(model, &self.state, z, noise, rates, |_, row| {
            let h = row.h;
            let wh = h * row.w;
            if row.rate {
                let mut k = 0;
                for i in 0..4 {
                    for j in i..4 {
                        u[k] += wh[i] * h[j];
                        k += 1;
                    }
                }
            } else {
                u[0] += wh[0] * h[0];
                u[1] += wh[0] * h[1];
                u[4] += wh[1] * h[1];
            }
            b += wh * row.nu;
            chi2 += row.w * row.nu * row.nu;
        })?;
        if links == 0 {
            return Ok(NO_UPDATE);
        }
        let m = symmetric(&u);
        let not_pd = || Error::NotPositiveDefinite {
            field: "ekf.covariance".into(),
        };
        let p = (self.covariance + self.covariance.transpose()) * 0.5;
        let n = (Mat4::identity() + m * p)
            .try_inverse()
            .ok_or_else(not_pd)?;
        // `A = P⁻ N` (the information form's posterior), `K H = A M`; the Joseph form
        // `(I − A M) P⁻ (I − A M)ᵀ + A M Aᵀ` is `P⁻ − P⁻ Z P⁻` of the module docs.
        let a = p * n;
        let am = a * m;
        let t = Mat4::identity() - am;
        let covariance = upper_sum(&(t * p), &t, &am, &a);
        let gain = a * b;
        let state = self.state + gain;
        let nis = chi2 - b.dot(&gain);
        if state.iter().any(|v| !v.is_finite()) || Ldl4::new(&covariance).is_none() {
            return Err(not_pd());
        }
        self.state = state;
        self.covariance = covariance;
        Ok(UpdateSummary {
            nis: nis.max(0.0),
            links_used: links,
        })
    }
}

/// The symmetric matrix of upper triangle `u` (row by row: `m00 m01 m02 m03 m11 m12 …`).
#[inline(always)]
fn symmetric(u: &[Real; 10]) -> Mat4 {
    Mat4::new(
        u[0], u[1], u[2], u[3], //
        u[1], u[4], u[5], u[6], //
        u[2], u[5], u[7], u[8], //
        u[3], u[6], u[8], u[9],
    )
}

/// `X Yᵀ + V Wᵀ`, computed on the upper triangle and mirrored (the Joseph form's two terms,
/// symmetric by construction).
#[inline(always)]
fn upper_sum(x: &Mat4, y: &Mat4, v: &Mat4, w: &Mat4) -> Mat4 {
    let mut u = [0.0; 10];
    let mut k = 0;
    for i in 0..4 {
        for j in i..4 {
            let mut s = 0.0;
            for l in 0..4 {
                s += x[(i, l)] * y[(j, l)];
            }
            let mut q = 0.0;
            for l in 0..4 {
                q += v[(i, l)] * w[(j, l)];
            }
            u[k] = s + q;
            k += 1;
        }
    }
    symmetric(&u)
}
