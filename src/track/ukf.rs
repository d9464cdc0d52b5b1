//! Unscented Kalman filter for the bistatic-delay tracker (`filters-and-planning.md` §1): the
//! scaled unscented transform with additive noise, on the EKF's motion model (E7) and
//! measurement model (E1, `R` from E8 as for the EKF).
//!
//! - Prediction: the UT of the linear CV model is exact, so it is the EKF's `A x̂`,
//!   `A P Aᵀ + Q` ([`ConstantVelocity::propagate`], [`ConstantVelocity::propagate_covariance`]).
//! - Update: sigma points redrawn from `(x̂⁻, P⁻)` (Stone Soup's choice): `L` the lower Cholesky
//!   factor of `(n + λ) P⁻`, `χ₀ = x̂⁻`, `χ_i = x̂⁻ ± L_{:,i}`; `𝒵_i = h(χ_i)` for the links
//!   present, `ẑ = Σ Wᵐ_i 𝒵_i`, `S = Σ Wᶜ_i (𝒵_i − ẑ)(𝒵_i − ẑ)ᵀ + R`, `P_xz` likewise,
//!   `K = P_xz S⁻¹`, `x̂ = x̂⁻ + K (z − ẑ)`, `P = P⁻ − K S Kᵀ`, then `P ← (P + Pᵀ)/2`.
//!
//! Internally ranges (`cτ`, `c²R`) are used, as in the EKF (the same filter in other units). A
//! `P⁻` or `S` that is not positive definite, or a `P` that stops being so, is
//! [`Error::NotPositiveDefinite`] and leaves the filter unchanged.

use alloc::vec;
use alloc::vec::Vec;

use nalgebra::{Cholesky, DMatrix, DVector};

use crate::error::{check_len, limits, Error, Result};
use crate::math::{sqrt, Mat4, Real, Vec2, Vec4, SPEED_OF_LIGHT};
use crate::measure::Model;
use crate::track::ekf::{check_covariance, check_state, first_input_error};
use crate::track::{ConstantVelocity, MeasurementNoise, UpdateSummary};

/// State dimension `n`.
const N: usize = 4;

/// The scaled unscented transform's parameters (spec §1 \[choice\]: α = 1, β = 2, κ = 0).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UkfParams {
    /// Spread of the sigma points, `0 < α ≤ 10`.
    pub alpha: Real,
    /// Prior knowledge of the distribution (2 is optimal for a Gaussian), `0 ≤ β ≤ 10`.
    pub beta: Real,
    /// Secondary scaling, with `n + κ > 0`, `|κ| ≤ 100`.
    pub kappa: Real,
}

impl Default for UkfParams {
    fn default() -> Self {
        UkfParams {
            alpha: 1.0,
            beta: 2.0,
            kappa: 0.0,
        }
    }
}

impl UkfParams {
    /// Checks the ranges (errors name `ukf_alpha`, `ukf_beta`, `ukf_kappa`).
    pub fn validate(&self) -> Result<()> {
        let out = |field: &str, value: Real, allowed: &'static str| Error::OutOfRange {
            field: field.into(),
            value,
            allowed,
        };
        if !(self.alpha.is_finite() && self.alpha > 0.0 && self.alpha <= 10.0) {
            return Err(out("ukf_alpha", self.alpha, "0 < alpha <= 10"));
        }
        if !(self.beta.is_finite() && (0.0..=10.0).contains(&self.beta)) {
            return Err(out("ukf_beta", self.beta, "0 <= beta <= 10"));
        }
        if !(self.kappa.is_finite() && self.kappa.abs() <= 100.0 && N as Real + self.kappa > 0.0) {
            return Err(out(
                "ukf_kappa",
                self.kappa,
                "n + kappa > 0 and |kappa| <= 100",
            ));
        }
        Ok(())
    }

    /// `λ = α² (n + κ) − n`.
    pub fn lambda(&self) -> Real {
        self.alpha * self.alpha * (N as Real + self.kappa) - N as Real
    }

    /// The weights `(Wᵐ₀, Wᶜ₀, W_i)`.
    pub fn weights(&self) -> (Real, Real, Real) {
        let l = self.lambda();
        let nl = N as Real + l;
        let wm0 = l / nl;
        (
            wm0,
            wm0 + 1.0 - self.alpha * self.alpha + self.beta,
            1.0 / (2.0 * nl),
        )
    }
}

/// The UKF: state estimate `x̂ = [x, y, vx, vy]ᵀ`, its covariance `P` and the UT parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ukf {
    /// `x̂`, m and m/s.
    pub state: Vec4,
    /// `P`, m², m²/s, m²/s².
    pub covariance: Mat4,
    /// The unscented transform's parameters.
    pub params: UkfParams,
}

impl Ukf {
    /// A filter at `state` with covariance `covariance` (validated as for the EKF) and `params`.
    pub fn new(state: Vec4, covariance: Mat4, params: UkfParams) -> Result<Ukf> {
        check_state(&state)?;
        check_covariance("initial_covariance", &covariance)?;
        params.validate()?;
        Ok(Ukf {
            state,
            covariance,
            params,
        })
    }

    /// Position part of the state, m.
    pub fn position(&self) -> Vec2 {
        Vec2::new(self.state[0], self.state[1])
    }

    /// Predict: the unscented transform of the linear CV model, `A x̂`, `A P Aᵀ + Q` (E7).
    pub fn predict(&mut self, motion: &ConstantVelocity) {
        self.state = motion.propagate(&self.state);
        self.covariance = motion.propagate_covariance(&self.covariance);
    }

    /// Update with delays `z` (s, one per link, `None` = missing) by the unscented transform of
    /// `h` around `(x̂⁻, P⁻)` (spec §1). No link: nothing to do. On error the filter is
    /// unchanged.
    pub fn update(
        &mut self,
        model: &Model,
        z: &[Option<Real>],
        noise: MeasurementNoise,
    ) -> Result<UpdateSummary> {
        let links = model.link_count();
        check_len("measurement", links, z.len())?;
        noise.check_links(links)?;
        let m = z.iter().filter(|v| v.is_some()).count();
        if m == 0 {
            return Ok(UpdateSummary {
                nis: 0.0,
                links_used: 0,
            });
        }
        let (x, p) = (self.state, self.covariance);
        let r_pred = self.position();
        let points = sigma_points(&x, &p, &self.params)?;
        let weights = self.params.weights();
        // Up to 8 links on the stack (no allocation), more in dynamic matrices.
        let (dx, ksk, nis) = if m <= 8 {
            let mut used = [0usize; 8];
            for (slot, link) in used.iter_mut().zip((0..links).filter(|&l| z[l].is_some())) {
                *slot = link;
            }
            let used = &used[..m];
            let (mut zc, mut r) = ([0.0; 8], [0.0; 8]);
            measurement(model, z, noise, r_pred, used, &mut zc[..m], &mut r[..m])?;
            if m <= 4 {
                ut_update::<4>(model, used, &points, weights, &zc[..m], &r[..m])?
            } else {
                ut_update::<8>(model, used, &points, weights, &zc[..m], &r[..m])?
            }
        } else {
            let used: Vec<usize> = (0..links).filter(|&l| z[l].is_some()).collect();
            let (mut zc, mut r) = (vec![0.0; m], vec![0.0; m]);
            measurement(model, z, noise, r_pred, &used, &mut zc, &mut r)?;
            ut_update_dyn(model, &used, &points, weights, &zc, &r)?
        };
        let p_new = p - ksk;
        let p_new = (p_new + p_new.transpose()) * 0.5;
        let x_new = x + dx;
        if x_new.iter().any(|v| !v.is_finite()) || Cholesky::new(p_new).is_none() {
            return Err(Error::NotPositiveDefinite {
                field: "ukf.covariance".into(),
            });
        }
        self.state = x_new;
        self.covariance = p_new;
        Ok(UpdateSummary { nis, links_used: m })
    }

    /// Predict then update (one filter step); on error the filter is left as before the step.
    pub fn step(
        &mut self,
        motion: &ConstantVelocity,
        model: &Model,
        z: &[Option<Real>],
        noise: MeasurementNoise,
    ) -> Result<UpdateSummary> {
        let before = *self;
        self.predict(motion);
        self.update(model, z, noise).inspect_err(|_| *self = before)
    }

    /// Normalised estimation error squared against a true state (`None` if `P` is not positive
    /// definite).
    pub fn nees(&self, truth: &Vec4) -> Option<Real> {
        crate::track::spd_quadratic_form(&self.covariance, &(self.state - truth))
    }
}

/// The measured ranges `c·z` and the range variances `(cσ_p)²` of the links `used` (σ from
/// `noise` at `r_pred`) into `zc` and `r`, each σ evaluated once; a bad delay or σ is the EKF's
/// named error ([`first_input_error`]).
fn measurement(
    model: &Model,
    z: &[Option<Real>],
    noise: MeasurementNoise,
    r_pred: Vec2,
    used: &[usize],
    zc: &mut [Real],
    r: &mut [Real],
) -> Result<()> {
    let fixed = matches!(noise, MeasurementNoise::Fixed(_));
    let mut ok = true;
    for ((&link, zk), rk) in used.iter().zip(zc.iter_mut()).zip(r.iter_mut()) {
        let tau = z[link].unwrap_or_default();
        let sigma = noise.sigma(model, link, r_pred);
        let s = SPEED_OF_LIGHT * sigma;
        *zk = SPEED_OF_LIGHT * tau;
        *rk = s * s;
        ok &= limits::DELAY_S.contains(tau)
            && sigma.is_finite()
            && sigma > 0.0
            && (!fixed || limits::DELAY_SIGMA_S.contains(sigma))
            && rk.is_finite()
            && *rk > 0.0;
    }
    if !ok {
        return Err(
            first_input_error(model, z, noise, r_pred).unwrap_or(Error::InvalidSigma {
                link: used[0],
                value: Real::NAN,
            }),
        );
    }
    Ok(())
}

/// `𝒵_i = c·h(χ_i)` of the links `used` (ranges, m): each node's distance once (E1: a link's
/// range is the sum of its two).
#[inline]
fn ranges(model: &Model, used: &[usize], chi: &Vec4, out: &mut [Real]) {
    let net = &model.network;
    let dist = |n: Vec2| {
        let (dx, dy) = (chi[0] - n.x, chi[1] - n.y);
        sqrt(dx * dx + dy * dy)
    };
    // The links of one transmitter are consecutive for a full mesh; reuse its distance.
    let mut last_tx = (usize::MAX, 0.0);
    for (o, &link) in out.iter_mut().zip(used) {
        let l = net.links[link];
        if last_tx.0 != l.tx {
            last_tx = (l.tx, dist(net.transmitters[l.tx]));
        }
        *o = last_tx.1 + dist(net.receivers[l.rx]);
    }
}

/// The unscented update for at most `M` links in fixed-size (stack) matrices: the `m` links
/// present fill the leading block, the rest of `S` is the identity and of `P_xz`, `ν` zero, so
/// the padded solve leaves the leading block's results. Returns `K ν`, `K S Kᵀ` and the NIS.
fn ut_update<const M: usize>(
    model: &Model,
    used: &[usize],
    points: &[Vec4; 2 * N + 1],
    (wm0, wc0, wi): (Real, Real, Real),
    zc: &[Real],
    r: &[Real],
) -> Result<(Vec4, Mat4, Real)> {
    use nalgebra::{SMatrix, SVector};
    let m = used.len();
    let mut zs = [SVector::<Real, M>::zeros(); 2 * N + 1];
    for (zi, chi) in zs.iter_mut().zip(points) {
        ranges(model, used, chi, &mut zi.as_mut_slice()[..m]);
    }
    let mut z_hat = zs[0] * wm0;
    for zi in &zs[1..] {
        z_hat += zi * wi;
    }
    let mut s = SMatrix::<Real, M, M>::identity();
    let mut nu = SVector::<Real, M>::zeros();
    for k in 0..m {
        s[(k, k)] = r[k];
        nu[k] = zc[k] - z_hat[k];
    }
    let mut pxz = SMatrix::<Real, N, M>::zeros();
    for (i, (zi, chi)) in zs.iter().zip(points).enumerate() {
        let wc = if i == 0 { wc0 } else { wi };
        let mut dz = zi - z_hat;
        for v in dz.as_mut_slice()[m..].iter_mut() {
            *v = 0.0;
        }
        let dx = chi - points[0];
        s += (dz * dz.transpose()) * wc;
        pxz += (dx * dz.transpose()) * wc;
    }
    let chol = Cholesky::new(s).ok_or_else(|| Error::NotPositiveDefinite {
        field: "ukf.innovation_covariance".into(),
    })?;
    // K = P_xz S⁻¹ = (S⁻¹ P_zx)ᵀ.
    let k = chol.solve(&pxz.transpose()).transpose();
    let nis = nu.dot(&chol.solve(&nu));
    Ok((k * nu, k * s * k.transpose(), nis))
}

/// [`ut_update`] for any number of links, in heap matrices.
fn ut_update_dyn(
    model: &Model,
    used: &[usize],
    points: &[Vec4; 2 * N + 1],
    (wm0, wc0, wi): (Real, Real, Real),
    zc: &[Real],
    r: &[Real],
) -> Result<(Vec4, Mat4, Real)> {
    let m = used.len();
    let zs: Vec<DVector<Real>> = points
        .iter()
        .map(|chi| {
            let mut v = DVector::zeros(m);
            ranges(model, used, chi, v.as_mut_slice());
            v
        })
        .collect();
    let mut z_hat = &zs[0] * wm0;
    for zi in &zs[1..] {
        z_hat += zi * wi;
    }
    let mut s = DMatrix::<Real>::from_diagonal(&DVector::from_column_slice(r));
    let nu = DVector::from_fn(m, |k, _| zc[k] - z_hat[k]);
    let mut pxz = DMatrix::<Real>::zeros(N, m);
    for (i, (zi, chi)) in zs.iter().zip(points).enumerate() {
        let wc = if i == 0 { wc0 } else { wi };
        let dz = zi - &z_hat;
        let dx = DVector::from_column_slice((chi - points[0]).as_slice());
        s += wc * &dz * dz.transpose();
        pxz += wc * dx * dz.transpose();
    }
    let chol = Cholesky::new(s.clone()).ok_or_else(|| Error::NotPositiveDefinite {
        field: "ukf.innovation_covariance".into(),
    })?;
    let k = chol.solve(&pxz.transpose()).transpose();
    let nis = nu.dot(&chol.solve(&nu));
    let dx = &k * &nu;
    let ksk = &k * &s * k.transpose();
    Ok((
        Vec4::new(dx[0], dx[1], dx[2], dx[3]),
        Mat4::from_fn(|i, j| ksk[(i, j)]),
        nis,
    ))
}

/// The `2n + 1` sigma points of `(x, P)`: `x`, `x ± L_{:,i}` with `L Lᵀ = (n + λ) P`.
fn sigma_points(x: &Vec4, p: &Mat4, params: &UkfParams) -> Result<[Vec4; 2 * N + 1]> {
    let scaled = p * (N as Real + params.lambda());
    let l = Cholesky::new(scaled)
        .ok_or_else(|| Error::NotPositiveDefinite {
            field: "ukf.covariance".into(),
        })?
        .l();
    let mut pts = [*x; 2 * N + 1];
    for i in 0..N {
        let col: Vec4 = l.column(i).into_owned();
        pts[1 + i] = x + col;
        pts[1 + N + i] = x - col;
    }
    Ok(pts)
}
