//! The EKF's delay-and-Doppler update (issue 42 §3; D3, D8; S17): the rows of
//! [`rows`](crate::track::doppler) see the velocity, so the batch update of the [`ekf`](super)
//! module runs in the full 4-D state instead of the position plane — the same push-through
//! identity with `Π = I`: `M = Hᵀ R⁻¹ H`, `b = Hᵀ R⁻¹ ν`, `N = (I + M P⁻)⁻¹`,
//! `x̂ = x̂⁻ + P⁻ N b`, Joseph form `P = P⁻ − P⁻ Z P⁻` with
//! `Z = N M + (N M)ᵀ − N (M + M P⁻ M) Nᵀ`, and `NIS = νᵀ R⁻¹ ν − bᵀ P⁻ N b`. One 4 × 4 inverse,
//! no `m × m` solve, no allocation.

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
        let (mut m, mut b, mut chi2) = (Mat4::zeros(), Vec4::zeros(), 0.0);
        let links = rows(model, &self.state, z, noise, rates, |_, row| {
            let wh = row.h * row.w;
            m += wh * row.h.transpose();
            b += wh * row.nu;
            chi2 += row.w * row.nu * row.nu;
        })?;
        if links == 0 {
            return Ok(NO_UPDATE);
        }
        let not_pd = || Error::NotPositiveDefinite {
            field: "ekf.covariance".into(),
        };
        let p = (self.covariance + self.covariance.transpose()) * 0.5;
        let n = (Mat4::identity() + m * p)
            .try_inverse()
            .ok_or_else(not_pd)?;
        let nm = n * m;
        let z_mat = nm + nm.transpose() - n * (m + m * p * m) * n.transpose();
        let gain = p * (n * b);
        let state = self.state + gain;
        let c = p - p * z_mat * p;
        let covariance = (c + c.transpose()) * 0.5;
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
