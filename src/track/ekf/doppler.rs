//! The EKF's delay-and-Doppler update (issue 42 §3; D3, D8; S17): the rows of
//! [`rows`](crate::track::doppler) see the velocity, so the batch update of the [`ekf`](super)
//! module runs in the full 4-D state instead of the position plane — the posterior of
//! `M = Hᵀ R⁻¹ H`, `b = Hᵀ R⁻¹ ν`: `P = (P⁻⁻¹ + M)⁻¹`, `x̂ = x̂⁻ + P b` and
//! `NIS = νᵀ R⁻¹ ν − bᵀ P b`, the push-through identity's `P = P⁻ N`, `N = (I + M P⁻)⁻¹`.
//!
//! It is computed in factored form (issue 42 §4), no general inverse and no allocation:
//! `P⁻ = L D Lᵀ` (`L` unit lower triangular, `D > 0` diagonal), each row `h` turned into
//! `Lᵀ h` as it arrives so `Y = D⁻¹ + Lᵀ M L` is accumulated on its upper triangle, then
//! `Y = K E Kᵀ` and, with `V = K⁻¹ Lᵀ`, `P = Vᵀ E⁻¹ V` (on its upper triangle; `P⁻ Y P⁻`-free).
//! `Y` is `D^{-1/2} (I + D^{1/2} Lᵀ M L D^{1/2}) D^{-1/2}`, a matrix of eigenvalues ≥ 1 scaled
//! by a diagonal, which elimination without pivoting does not feel: the factorisation is as
//! well conditioned as the Joseph form's `N`, and the posterior is a sum of positive
//! semidefinite terms `v_k v_kᵀ / e_k`, symmetric by construction and positive definite even
//! when it is 10⁻⁶ of the prior. It is accepted as the delay-only update's posterior is (a
//! finite state and a positive, finite diagonal).

use super::Ekf;
use crate::error::{Error, Result};
use crate::math::{Mat4, Real, Vec4};
use crate::measure::Model;
use crate::track::doppler::{check_rates, rows, RangeRates, Row};
use crate::track::shared::{positive_finite, NO_UPDATE};
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
        let not_pd = || Error::NotPositiveDefinite {
            field: "ekf.covariance".into(),
        };
        // `P⁻ = L D Lᵀ` of the symmetrised prior.
        let c = &self.covariance;
        let mut prior = [0.0; 10];
        let mut k = 0;
        for i in 0..4 {
            for j in i..4 {
                prior[k] = (c[(i, j)] + c[(j, i)]) * 0.5;
                k += 1;
            }
        }
        let prior = Ldl::new(&prior).ok_or_else(not_pd)?;
        // `Y − D⁻¹ = Lᵀ M L = Σ w (Lᵀh)(Lᵀh)ᵀ` on its upper triangle; a delay row `[g, 0]`
        // stays `[g₀ + l₁₀ g₁, g₁, 0, 0]` and touches 3 entries.
        let l = &prior.l;
        let mut acc = Accumulator {
            l,
            y: [0.0; 10],
            b: Vec4::zeros(),
            chi2: 0.0,
        };
        let links = rows(model, &self.state, z, noise, rates, |_, row| acc.add(&row))?;
        let Accumulator { mut y, b, chi2, .. } = acc;
        if links == 0 {
            return Ok(NO_UPDATE);
        }
        for (i, k) in [0, 4, 7, 9].into_iter().enumerate() {
            y[k] += prior.inv[i];
        }
        // `Y = K E Kᵀ`; `V = K⁻¹ Lᵀ` (rows `v_k`), `P = Σ_k v_k v_kᵀ / e_k`.
        let post = Ldl::new(&y).ok_or_else(not_pd)?;
        let kinv = post.unit_inverse();
        let mut v = [[0.0; 4]; 4];
        for (r, vr) in v.iter_mut().enumerate() {
            for (j, vrj) in vr.iter_mut().enumerate() {
                // `Σ_i K⁻¹[r][i] Lᵀ[i][j]` over `i ≤ min(r, j)`, both unit triangular.
                let mut s = if r <= j { l[r][j] } else { kinv[r][j] };
                for i in 0..r.min(j) {
                    s += kinv[r][i] * l[i][j];
                }
                *vrj = s;
            }
        }
        let v = Mat4::from_fn(|r, c| v[r][c]);
        let w = Mat4::from_fn(|r, c| v[(r, c)] * post.inv[r]);
        let mut u = [0.0; 10];
        let mut k = 0;
        for i in 0..4 {
            for j in i..4 {
                u[k] = v[(0, i)] * w[(0, j)]
                    + v[(1, i)] * w[(1, j)]
                    + v[(2, i)] * w[(2, j)]
                    + v[(3, i)] * w[(3, j)];
                k += 1;
            }
        }
        let covariance = symmetric(&u);
        // `x̂ − x̂⁻ = P b = Vᵀ E⁻¹ (V b)`, `bᵀ P b = Σ (V b)_k² / e_k`.
        let gain = w.tr_mul(&(v * b));
        let state = self.state + gain;
        let nis = chi2 - b.dot(&gain);
        // The delay-only update's acceptance (a finite state, a positive finite diagonal): the
        // posterior is a sum of positive semidefinite terms with positive `e_k` (module docs),
        // so a full factorisation here only re-tested what the pivots of `Y` already had
        // (issue 42 §4).
        self.commit(state, covariance, nis.max(0.0), links)
    }
}

/// The sums of the rows: `Y − D⁻¹ = Lᵀ M L` on its upper triangle, `b = Hᵀ R⁻¹ ν` and
/// `νᵀ R⁻¹ ν` (module docs).
struct Accumulator<'a> {
    l: &'a [[Real; 4]; 4],
    y: [Real; 10],
    b: Vec4,
    chi2: Real,
}

impl Accumulator<'_> {
    /// Adds one row: `w (Lᵀh)(Lᵀh)ᵀ` to `Y` (a delay row `[g, 0]` stays `[g₀ + l₁₀ g₁, g₁, 0,
    /// 0]` and touches 3 entries), `w ν h` to `b`, `w ν²` to `χ²`. Inlined into each of the
    /// row loop's two call sites (a call per row cost 10 % of the step, issue 42 §4).
    #[inline(always)]
    fn add(&mut self, row: &Row) {
        let (l, y) = (self.l, &mut self.y);
        let h = row.h;
        let wh = h * row.w;
        if row.rate {
            let t = Vec4::new(
                h[0] + l[0][1] * h[1] + l[0][2] * h[2] + l[0][3] * h[3],
                h[1] + l[1][2] * h[2] + l[1][3] * h[3],
                h[2] + l[2][3] * h[3],
                h[3],
            );
            let wt = t * row.w;
            let mut k = 0;
            for i in 0..4 {
                for j in i..4 {
                    y[k] += wt[i] * t[j];
                    k += 1;
                }
            }
        } else {
            let t0 = h[0] + l[0][1] * h[1];
            let wt0 = t0 * row.w;
            y[0] += wt0 * t0;
            y[1] += wt0 * h[1];
            y[4] += wh[1] * h[1];
        }
        self.b += wh * row.nu;
        self.chi2 += row.w * row.nu * row.nu;
    }
}

/// `A = L D Lᵀ` of a symmetric 4 × 4 matrix given by its upper triangle (row by row), `L` unit
/// lower triangular stored transposed (`l[j][i] = L_ij`, `j < i`), with `1/d_i`; `None` unless
/// every pivot is finite and positive.
struct Ldl {
    l: [[Real; 4]; 4],
    inv: [Real; 4],
}

impl Ldl {
    #[inline(always)]
    fn new(a: &[Real; 10]) -> Option<Ldl> {
        let pivot = |d: Real| positive_finite(d).then(|| 1.0 / d);
        let i0 = pivot(a[0])?;
        let (l10, l20, l30) = (a[1] * i0, a[2] * i0, a[3] * i0);
        let i1 = pivot(a[4] - l10 * a[1])?;
        let a21 = a[5] - l20 * a[1];
        let a31 = a[6] - l30 * a[1];
        let (l21, l31) = (a21 * i1, a31 * i1);
        let i2 = pivot(a[7] - l20 * a[2] - l21 * a21)?;
        let a32 = a[8] - l30 * a[2] - l31 * a21;
        let l32 = a32 * i2;
        let i3 = pivot(a[9] - l30 * a[3] - l31 * a31 - l32 * a32)?;
        Some(Ldl {
            l: [
                [1.0, l10, l20, l30],
                [0.0, 1.0, l21, l31],
                [0.0, 0.0, 1.0, l32],
                [0.0, 0.0, 0.0, 1.0],
            ],
            inv: [i0, i1, i2, i3],
        })
    }

    /// `L⁻¹` (unit lower triangular, `[r][c]`, `c < r` meaningful).
    #[inline(always)]
    fn unit_inverse(&self) -> [[Real; 4]; 4] {
        let l = &self.l;
        let n10 = -l[0][1];
        let n21 = -l[1][2];
        let n32 = -l[2][3];
        let n20 = -l[0][2] - l[1][2] * n10;
        let n31 = -l[1][3] - l[2][3] * n21;
        let n30 = -l[0][3] - l[1][3] * n10 - l[2][3] * n20;
        [
            [1.0, 0.0, 0.0, 0.0],
            [n10, 1.0, 0.0, 0.0],
            [n20, n21, 1.0, 0.0],
            [n30, n31, n32, 1.0],
        ]
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
