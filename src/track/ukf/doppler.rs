//! The UKF's delay-and-Doppler update (issue 42 §3; D1, D3; `filters-and-planning.md` §1): the
//! range-rate rows see the velocity, so all `2n + 1 = 9` sigma points of `(x̂⁻, P⁻)` are carried
//! through the rows' measurement functions (the delay-only update needs only the four off
//! `χ₀`'s position): `ẑ = Σ Wᵐ_i 𝒵_i`, `S = Σ Wᶜ_i (𝒵_i − ẑ)(𝒵_i − ẑ)ᵀ + R`,
//! `C = Σ Wᶜ_i (χ_i − x̂⁻)(𝒵_i − ẑ)ᵀ`, `K = C S⁻¹`, `x̂ = x̂⁻ + K (z − ẑ)`, `P = P⁻ − K S Kᵀ`,
//! `NIS = (z − ẑ)ᵀ S⁻¹ (z − ẑ)`; `R` from the rows' noise at `x̂⁻`.

use alloc::vec::Vec;

use nalgebra::{DMatrix, DVector};

use super::{Ukf, N};
use crate::error::{Error, Result};
use crate::math::{Mat4, Real, Vec4};
use crate::measure::Model;
use crate::track::doppler::{check_rates, rows, RangeRates, Row};
use crate::track::shared::{Ldl4, NO_UPDATE};
use crate::track::{Filter, MeasurementNoise, UpdateSummary};

impl Ukf {
    /// Update with delays `z` (s) and range rates `rates` (m/s), `None` = missing, one per link
    /// (module docs). Without rates it is the delay-only update ([`Filter::update`]) up to
    /// rounding. On error the filter is left unchanged (errors as [`Ekf::update_doppler`]'s).
    ///
    /// [`Ekf::update_doppler`]: crate::track::Ekf::update_doppler
    pub fn update_doppler(
        &mut self,
        model: &Model,
        z: &[Option<Real>],
        noise: MeasurementNoise,
        rates: &RangeRates,
    ) -> Result<UpdateSummary> {
        check_rates(model, z, noise, rates, self.position())?;
        let mut list: Vec<(usize, Row)> = Vec::new();
        let links = rows(model, &self.state, z, noise, rates, |p, row| {
            list.push((p, row))
        })?;
        if links == 0 {
            return Ok(NO_UPDATE);
        }
        let not_pd = |field: &str| Error::NotPositiveDefinite {
            field: field.into(),
        };
        let (x, p) = (
            self.state,
            (self.covariance + self.covariance.transpose()) * 0.5,
        );
        let spread = N as Real + self.params.lambda();
        let l = nalgebra::Cholesky::new(p * spread)
            .ok_or_else(|| not_pd("ukf.covariance"))?
            .l();
        let points: Vec<Vec4> = core::iter::once(x)
            .chain((0..N).map(|i| x + l.column(i)))
            .chain((0..N).map(|i| x - l.column(i)))
            .collect();
        let (wm0, wc0, wi) = self.params.weights();
        let weight = |i: usize, zero: Real| if i == 0 { zero } else { wi };
        let m = list.len();
        let zs = DMatrix::from_fn(m, points.len(), |k, i| {
            let (link, row) = &list[k];
            row.value_at(model, *link, &points[i])
        });
        let mut zhat = DVector::zeros(m);
        for i in 0..points.len() {
            zhat += zs.column(i) * weight(i, wm0);
        }
        let mut s = DMatrix::from_diagonal(&DVector::from_iterator(
            m,
            list.iter().map(|(_, r)| 1.0 / r.w),
        ));
        let mut c = DMatrix::<Real>::zeros(N, m);
        for (i, xi) in points.iter().enumerate() {
            let dz = zs.column(i) - &zhat;
            let w = weight(i, wc0);
            s += &dz * dz.transpose() * w;
            let dx = DVector::from_column_slice((xi - x).as_slice());
            c += dx * dz.transpose() * w;
        }
        let nu = DVector::from_iterator(m, list.iter().map(|(_, r)| r.z)) - zhat;
        let chol = nalgebra::Cholesky::new(s.clone())
            .ok_or_else(|| not_pd("ukf.innovation_covariance"))?;
        // K = C S⁻¹ (S symmetric): Kᵀ = S⁻¹ Cᵀ.
        let kt = chol.solve(&c.transpose());
        let k = kt.transpose();
        let dx = &k * &nu;
        let state = x + Vec4::from_column_slice(dx.as_slice());
        let ksk = &k * &s * &kt;
        let q = Mat4::from_fn(|i, j| 0.5 * (ksk[(i, j)] + ksk[(j, i)]));
        let covariance = p - q;
        let nis = nu.dot(&chol.solve(&nu));
        if state.iter().any(|v| !v.is_finite()) || Ldl4::new(&covariance).is_none() {
            return Err(not_pd("ukf.covariance"));
        }
        (self.state, self.covariance) = (state, covariance);
        Ok(UpdateSummary {
            nis,
            links_used: links,
        })
    }
}
