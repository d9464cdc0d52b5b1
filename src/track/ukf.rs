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
//! Evaluation: the same quantities, equal up to rounding, with less work.
//!
//! - `h` only sees the position and `L` is lower triangular, so the four sigma points of the
//!   velocity columns `L_{:,2}`, `L_{:,3}` have `χ₀`'s position and its `𝒵₀`: five range
//!   evaluations, `𝒵₀` and the differences `d_k = 𝒵(x̂⁻ ± L_{:,j}) − 𝒵₀` (`j = 0, 1`), not nine.
//!   Columns 0 and 1 of `L` come from `P⁻ = L̃ D L̃ᵀ` ([`Ldl4`]: `L = L̃ √((n + λ) D)`), which is
//!   also the positive-definiteness test of `P⁻`.
//! - With `Wᵐ₀ + 2n Wᵢ = 1`: `δ = ẑ − 𝒵₀ = Wᵢ Σ_k d_k`,
//!   `S = R + Wᵢ Σ_k d_k d_kᵀ + (β − α²) δ δᵀ` (`Wᶜ₀ − Wᵐ₀ − 1 = β − α²`; lower triangle only)
//!   and `P_xz = C Eᵀ` with `C = [L_{:,0} L_{:,1}]`, `E = Wᵢ [d₀₊ − d₀₋, d₁₊ − d₁₋]`: the
//!   velocity points' terms cancel in pairs.
//! - `S = G Gᵀ` (Cholesky), `A = G⁻¹ E`, `b = G⁻¹ ν`: `K ν = C Aᵀ b`,
//!   `K S Kᵀ = P_xz S⁻¹ P_xzᵀ = C (Aᵀ A) Cᵀ` (a 2 × 2 core, symmetric by construction) and
//!   `NIS = bᵀ b`, one forward substitution and no `m × m` product.
//! - The new `P` is checked by its `LDLᵀ` pivots ([`Ldl4`]), not a second Cholesky.
//! - `R = diag((cσ_p)²)` is `1/w_p` from the EKF's pass 1 ([`link_information`]): each
//!   transmitter's gain is evaluated once per update, not once per link.
//!
//! The same code serves any number of links, with its work arrays on the stack for up to 8 and
//! on the heap above.
//!
//! Internally ranges (`cτ`, `c²R`) are used, as in the EKF (the same filter in other units). A
//! `P⁻` or `S` that is not positive definite, or a `P` that stops being so, is
//! [`Error::NotPositiveDefinite`] and leaves the filter unchanged.

use alloc::vec;
use alloc::vec::Vec;

use crate::error::{Error, Result};
use crate::math::{sqrt, Mat4, Real, Vec2, Vec4, SPEED_OF_LIGHT};
use crate::measure::Model;
use crate::track::ekf::link_information;
use crate::track::shared::{
    check_covariance, check_state, check_update, first_input_error, link_sigmas, predict_gaussian,
    Ldl4, NO_UPDATE,
};
use crate::track::{ConstantVelocity, Filter, MeasurementNoise, PredictedDelay, UpdateSummary};

/// State dimension `n`.
const N: usize = 4;

mod doppler;

/// The scaled unscented transform's parameters (spec §1 \[choice\]: α = 1, β = 2, κ = 0).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UkfParams {
    /// Spread of the sigma points, `10⁻⁴ ≤ α ≤ 1` ([`ALPHA_RANGE`]).
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

/// The range of the UKF's `α` (issue 24): `10⁻⁴ ≤ α ≤ 1`, the range E. A. Wan and R. van der
/// Merwe give for the scaled unscented transform ("The Unscented Kalman Filter", ch. 7 of S.
/// Haykin (ed.), *Kalman Filtering and Neural Networks*, Wiley 2001, §7.3). Below it the sigma
/// points collapse onto the mean (`n + λ = α²(n + κ)`; at `α = 10⁻³⁰⁰` it underflows to 0 and
/// every update failed with a not-positive-definite covariance); above 1 they spread wider than
/// the prior.
pub const ALPHA_RANGE: crate::error::limits::Range = crate::error::limits::Range {
    min: 1e-4,
    max: 1.0,
    allowed: "1e-4 to 1, Wan & van der Merwe",
};

/// The largest prior variance (any diagonal entry of `initial_covariance`) the UKF starts from
/// (issue 24), m² or m²/s²: σ = 100 m, ten times the areas of this project's scenarios. The
/// sigma points lie `√((n + λ) P)` off the mean, and from a wider prior the unscented transform
/// samples the delays far outside the network: on the sensors2019 track of `tests/cli/filters.rs`
/// (20 steps, cσ ≈ 1 cm) the UKF came within 1 cm of the EKF after 10 steps from diag(10⁴), but
/// was 1 km off after 2 steps and still 0.5 m off after 20 from diag(10⁶), and from diag(10¹¹)
/// its innovation covariance lost `R` to rounding (`ukf.innovation_covariance` in every step).
/// The EKF, whose update switches to the information form for wide priors, takes up to 10¹².
pub const MAX_PRIOR_VARIANCE: Real = 1e4;

impl UkfParams {
    /// Checks the ranges (errors name `ukf_alpha`, `ukf_beta`, `ukf_kappa`).
    pub fn validate(&self) -> Result<()> {
        let out = |field: &str, value: Real, allowed: &'static str| Error::OutOfRange {
            field: field.into(),
            value,
            allowed,
        };
        ALPHA_RANGE.check("ukf_alpha", self.alpha)?;
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
    /// A filter at `state` with covariance `covariance` (validated as for the EKF, and each
    /// variance at most [`MAX_PRIOR_VARIANCE`]: [`Error::OutOfRange`]
    /// `initial_covariance[i][i]`) and `params`.
    pub fn new(state: Vec4, covariance: Mat4, params: UkfParams) -> Result<Ukf> {
        check_state(&state)?;
        check_covariance("initial_covariance", &covariance)?;
        for i in 0..N {
            let v = covariance[(i, i)];
            if v > MAX_PRIOR_VARIANCE {
                return Err(Error::OutOfRange {
                    field: alloc::format!("initial_covariance[{i}][{i}]"),
                    value: v,
                    allowed: "at most 1e4 for the UKF; the EKF takes up to 1e12",
                });
            }
        }
        params.validate()?;
        Ok(Ukf {
            state,
            covariance,
            params,
        })
    }

    /// The updated `(x̂, NIS)` and `P` for the `m ≥ 1` links present (module docs).
    #[inline(always)]
    fn updated(
        &self,
        model: &Model,
        z: &[Option<Real>],
        noise: MeasurementNoise,
        sc: &mut Scratch,
    ) -> Result<((Vec4, Real), Mat4)> {
        let not_pd = |field: &str| Error::NotPositiveDefinite {
            field: field.into(),
        };
        let (x, p) = (&self.state, &self.covariance);
        let m = sc.m;
        measurement(model, z, noise, self.position(), &mut *sc.r)?;
        // Columns 0 and 1 of the Cholesky factor of (n + λ) P⁻ from P⁻ = L D Lᵀ.
        let f = Ldl4::new(p).ok_or_else(|| not_pd("ukf.covariance"))?;
        let spread = N as Real + self.params.lambda();
        let (s0, s1) = (sqrt(spread * f.d[0]), sqrt(spread * f.d[1]));
        let c = [
            Vec4::new(s0, f.l10 * s0, f.l20 * s0, f.l30 * s0),
            Vec4::new(0.0, s1, f.l21 * s1, f.l31 * s1),
        ];
        // 𝒵₀ and the range differences of the four sigma points off χ₀'s position.
        let at = |sign: Real, col: &Vec4| Vec2::new(x[0] + sign * col[0], x[1] + sign * col[1]);
        let points = [
            at(1.0, &c[0]),
            at(1.0, &c[1]),
            at(-1.0, &c[0]),
            at(-1.0, &c[1]),
        ];
        sigma_ranges(model, z, Vec2::new(x[0], x[1]), &points, sc.z0, sc.d);
        let (_, _, wi) = self.params.weights();
        let c_delta = self.params.beta - self.params.alpha * self.params.alpha;
        let (d0, rest) = sc.d.split_at_mut(m);
        let (d1, rest) = rest.split_at_mut(m);
        let (d2, d3) = rest.split_at_mut(m);
        // δ = ẑ − 𝒵₀, ν = z − ẑ (into z0's place).
        for (i, tau) in z.iter().filter_map(|v| *v).enumerate() {
            let delta = wi * (((d0[i] + d1[i]) + d2[i]) + d3[i]);
            sc.delta[i] = delta;
            sc.z0[i] = (SPEED_OF_LIGHT * tau - sc.z0[i]) - delta;
        }
        // S (lower triangle), then E = [e₀ e₁] into d0, d1.
        let (s, delta) = (&mut *sc.s, &*sc.delta);
        for i in 0..m {
            for j in 0..=i {
                let sum = ((d0[i] * d0[j] + d1[i] * d1[j]) + d2[i] * d2[j]) + d3[i] * d3[j];
                s[i * m + j] = wi * sum + c_delta * delta[i] * delta[j];
            }
            s[i * m + i] += sc.r[i];
        }
        for i in 0..m {
            d0[i] = wi * (d0[i] - d2[i]);
            d1[i] = wi * (d1[i] - d3[i]);
        }
        let nu = &mut *sc.z0;
        if !whiten(s, m, [d0, d1, &mut *nu]) {
            return Err(not_pd("ukf.innovation_covariance"));
        }
        // W = AᵀA, g = Aᵀb, NIS = bᵀb with A = G⁻¹E, b = G⁻¹ν.
        let dot = |a: &[Real], b: &[Real]| a.iter().zip(b).fold(0.0, |acc, (x, y)| acc + x * y);
        let (w00, w01, w11) = (dot(d0, d0), dot(d0, d1), dot(d1, d1));
        let (g0, g1) = (dot(d0, nu), dot(d1, nu));
        let nis = dot(nu, nu);
        // x̂ = x̂⁻ + C g, P = P⁻ − C W Cᵀ (symmetric; P⁻ read as (P⁻ + P⁻ᵀ)/2).
        let state = x + c[0] * g0 + c[1] * g1;
        let wc: [Vec4; 2] = [c[0] * w00 + c[1] * w01, c[0] * w01 + c[1] * w11];
        // The upper triangle, mirrored: P exactly symmetric.
        let e = |i: usize, j: usize| {
            let q = c[0][i] * wc[0][j] + c[1][i] * wc[1][j];
            0.5 * (p[(i, j)] + p[(j, i)]) - q
        };
        let (e00, e01, e02, e03) = (e(0, 0), e(0, 1), e(0, 2), e(0, 3));
        let (e11, e12, e13) = (e(1, 1), e(1, 2), e(1, 3));
        let (e22, e23, e33) = (e(2, 2), e(2, 3), e(3, 3));
        let covariance = Mat4::new(
            e00, e01, e02, e03, //
            e01, e11, e12, e13, //
            e02, e12, e22, e23, //
            e03, e13, e23, e33,
        );
        if state.iter().any(|v| !v.is_finite()) || Ldl4::new(&covariance).is_none() {
            return Err(not_pd("ukf.covariance"));
        }
        Ok(((state, nis), covariance))
    }
}

/// The UKF behind the filter seam: predict (E7), predicted delays from its sigma points and the
/// unscented update (spec §1).
impl Filter for Ukf {
    fn name(&self) -> &'static str {
        "ukf"
    }

    /// Predict: the unscented transform of the linear CV model, `A x̂`, `A P Aᵀ + Q` (E7).
    fn predict(&mut self, motion: &ConstantVelocity) {
        predict_gaussian(&mut self.state, &mut self.covariance, motion);
    }

    /// The predicted measurement of every link from the sigma points of `(x̂⁻, P⁻)` (spec §1):
    /// `ẑ_p = Σ Wᵐ_i h_p(χ_i)` and `√S_pp`, `S_pp = Σ Wᶜ_i (h_p(χ_i) − ẑ_p)² + σ_p²`, both s,
    /// with `σ_p` from `noise` at `r̂⁻`. As in the update (module docs) only the four sigma
    /// points off `χ₀`'s position are evaluated: with `d_k = h_p(χ_k) − h_p(χ₀)`,
    /// `δ = ẑ_p − h_p(χ₀) = Wᵢ Σ d_k` and `S_pp = Wᵢ Σ d_k² + (β − α²) δ² + σ_p²`. A `P⁻` or an
    /// `S_pp` that is not positive is [`Error::NotPositiveDefinite`].
    fn predicted_delays(
        &self,
        model: &Model,
        noise: MeasurementNoise,
    ) -> Result<Vec<PredictedDelay>> {
        let not_pd = |field: &str| Error::NotPositiveDefinite {
            field: field.into(),
        };
        let center = self.position();
        let sigmas = link_sigmas(model, noise, center)?;
        let f = Ldl4::new(&self.covariance).ok_or_else(|| not_pd("ukf.covariance"))?;
        let spread = N as Real + self.params.lambda();
        let (s0, s1) = (sqrt(spread * f.d[0]), sqrt(spread * f.d[1]));
        let points = [
            center + Vec2::new(s0, f.l10 * s0),
            center + Vec2::new(0.0, s1),
            center - Vec2::new(s0, f.l10 * s0),
            center - Vec2::new(0.0, s1),
        ];
        let (_, _, wi) = self.params.weights();
        let c_delta = self.params.beta - self.params.alpha * self.params.alpha;
        sigmas
            .iter()
            .enumerate()
            .map(|(link, sigma)| {
                let h0 = model.network.delay(link, center);
                let d = points.map(|r| model.network.delay(link, r) - h0);
                let delta = wi * (((d[0] + d[1]) + d[2]) + d[3]);
                let spread = wi * (((d[0] * d[0] + d[1] * d[1]) + d[2] * d[2]) + d[3] * d[3]);
                let s = spread + c_delta * delta * delta + sigma * sigma;
                if !(s > 0.0 && s.is_finite()) {
                    return Err(not_pd("ukf.innovation_covariance"));
                }
                Ok(PredictedDelay {
                    delay_s: h0 + delta,
                    innovation_sigma_s: sqrt(s),
                })
            })
            .collect()
    }

    /// Update with delays `z` (s, one per link, `None` = missing) by the unscented transform of
    /// `h` around `(x̂⁻, P⁻)` (spec §1, evaluated as in the module docs). No link: nothing to
    /// do. On error the filter is unchanged.
    fn update(
        &mut self,
        model: &Model,
        z: &[Option<Real>],
        noise: MeasurementNoise,
    ) -> Result<UpdateSummary> {
        let m = check_update(model, z, noise)?;
        if m == 0 {
            return Ok(NO_UPDATE);
        }
        // Up to 8 links on the stack (no allocation), more on the heap; the same code.
        let (x, p) = if m <= 4 {
            self.updated(
                model,
                z,
                noise,
                &mut Scratch::new(m, &mut [0.0; scratch_len(4)]),
            )?
        } else if m <= 8 {
            self.updated(
                model,
                z,
                noise,
                &mut Scratch::new(m, &mut [0.0; scratch_len(8)]),
            )?
        } else {
            let mut buf = vec![0.0; scratch_len(m)];
            self.updated(model, z, noise, &mut Scratch::new(m, &mut buf))?
        };
        (self.state, self.covariance) = (x.0, p);
        Ok(UpdateSummary {
            nis: x.1,
            links_used: m,
        })
    }

    fn update_doppler(
        &mut self,
        model: &Model,
        z: &[Option<Real>],
        noise: MeasurementNoise,
        rates: &crate::track::RangeRates,
    ) -> Result<UpdateSummary> {
        Ukf::update_doppler(self, model, z, noise, rates)
    }

    fn state(&self) -> &Vec4 {
        &self.state
    }

    fn covariance(&self) -> &Mat4 {
        &self.covariance
    }
}

/// The range variances `(cσ_p)² = 1/w_p` of the links present into `r`, from the EKF's pass 1
/// ([`link_information`]: each transmitter's gain evaluated once, not per link); a bad delay or
/// σ is the EKF's named error ([`first_input_error`]).
fn measurement(
    model: &Model,
    z: &[Option<Real>],
    noise: MeasurementNoise,
    r_pred: Vec2,
    r: &mut [Real],
) -> Result<()> {
    let mut slots = r.iter_mut();
    let [info] = link_information(model, &[r_pred], &[z], &[true], noise, |_, _, _, w| {
        if let Some(slot) = slots.next() {
            *slot = 1.0 / w;
        }
    });
    // Every w finite and positive (checked by pass 1); 1/w may still overflow.
    if !(info.valid && r.iter().fold(0.0, |a, v| a + v) < Real::INFINITY) {
        return Err(
            first_input_error(model, z, noise, r_pred).unwrap_or(Error::InvalidSigma {
                link: z.iter().position(Option::is_some).unwrap_or(0),
                value: Real::NAN,
            }),
        );
    }
    Ok(())
}

/// The ranges `c·h` (m) of the links present, in link order, at `center` into `z0` and their
/// differences `d_k = 𝒵(points[k]) − 𝒵₀` into `d` (point-major, `z0.len()` per point): each
/// node's distances once (E1: a link's range is the sum of its two), the four points side by
/// side.
#[inline]
fn sigma_ranges(
    model: &Model,
    z: &[Option<Real>],
    center: Vec2,
    points: &[Vec2; 4],
    z0: &mut [Real],
    d: &mut [Real],
) {
    let m = z0.len();
    let net = &model.network;
    let (px, py) = (points.map(|p| p.x), points.map(|p| p.y));
    // 3-D node distances (E1): `√(dx² + (dy² + dz²))`, the planar bits when dz = 0.
    let dist = |n: Vec2, dz: Real| {
        let (dx, dy) = (center.x - n.x, center.y - n.y);
        let at: [Real; 4] = core::array::from_fn(|k| {
            let (dx, dy) = (px[k] - n.x, py[k] - n.y);
            sqrt(dx * dx + (dy * dy + dz * dz))
        });
        (sqrt(dx * dx + (dy * dy + dz * dz)), at)
    };
    let present = net.links.iter().zip(z).filter(|(_, v)| v.is_some());
    // The links of one transmitter are consecutive for a full mesh; reuse its distances.
    let mut last_tx = (usize::MAX, (0.0, [0.0; 4]));
    for ((i, z0), (l, _)) in z0.iter_mut().enumerate().zip(present) {
        if last_tx.0 != l.tx {
            last_tx = (
                l.tx,
                dist(net.transmitters[l.tx], net.transmitters_dz[l.tx]),
            );
        }
        let rx = dist(net.receivers[l.rx], net.receivers_dz[l.rx]);
        let ((t0, t), (r0, r)) = (last_tx.1, rx);
        *z0 = t0 + r0;
        for k in 0..4 {
            d[k * m + i] = (t[k] + r[k]) - *z0;
        }
    }
}

/// `S = G Gᵀ` (`S` the `m × m` lower triangle of `s`, row-major) into `s` in place (`G` lower,
/// with `1/G_jj` on the diagonal), then `v ← G⁻¹ v` for each of `vs`. `false` if `S` is not
/// positive definite (a pivot not finite and positive, the Cholesky criterion).
fn whiten(s: &mut [Real], m: usize, vs: [&mut [Real]; 3]) -> bool {
    for j in 0..m {
        let mut djj = s[j * m + j];
        for k in 0..j {
            djj -= s[j * m + k] * s[j * m + k];
        }
        let positive = djj > 0.0 && djj < Real::INFINITY;
        if !positive {
            return false;
        }
        let inv = 1.0 / sqrt(djj);
        s[j * m + j] = inv;
        for i in j + 1..m {
            let mut v = s[i * m + j];
            for k in 0..j {
                v -= s[i * m + k] * s[j * m + k];
            }
            s[i * m + j] = v * inv;
        }
    }
    let [a, b, c] = vs;
    for i in 0..m {
        let row = &s[i * m..=i * m + i];
        let (mut va, mut vb, mut vc) = (a[i], b[i], c[i]);
        for k in 0..i {
            va -= row[k] * a[k];
            vb -= row[k] * b[k];
            vc -= row[k] * c[k];
        }
        (a[i], b[i], c[i]) = (va * row[i], vb * row[i], vc * row[i]);
    }
    true
}

/// Length of the scratch of an update with `m` links: `𝒵₀`/`ν`, the four differences `d_k`,
/// `δ` and `R` (`m` each), and `S` (`m²`).
const fn scratch_len(m: usize) -> usize {
    m * m + 7 * m
}

/// The work arrays of an update with `m` links, carved from one buffer.
struct Scratch<'a> {
    m: usize,
    z0: &'a mut [Real],
    d: &'a mut [Real],
    delta: &'a mut [Real],
    r: &'a mut [Real],
    s: &'a mut [Real],
}

impl<'a> Scratch<'a> {
    #[inline(always)]
    fn new(m: usize, buf: &'a mut [Real]) -> Scratch<'a> {
        let (z0, rest) = buf.split_at_mut(m);
        let (d, rest) = rest.split_at_mut(4 * m);
        let (delta, rest) = rest.split_at_mut(m);
        let (r, rest) = rest.split_at_mut(m);
        Scratch {
            m,
            z0,
            d,
            delta,
            r,
            s: &mut rest[..m * m],
        }
    }
}
