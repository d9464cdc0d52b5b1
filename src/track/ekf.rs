//! Extended Kalman filter for the bistatic-delay tracker (spec §6, S16–S17).
//!
//! Shaped like adskalman-rs: predict and update are separate, the covariance update is the
//! Joseph form and is kept symmetric, and a missing measurement simply skips its row.
//!
//! The update is linearised once at the *predicted* position `r̂⁻` (`H = [J(r̂⁻), 0]`, E3) and
//! is the batch update `K = P⁻Hᵀ S⁻¹`, `S = H P⁻ Hᵀ + R`. Because `H` only sees the position
//! and `R = diag(r_p)` is diagonal, the batch update is evaluated in the 2-D position space
//! without an `m × m` solve (push-through identity): with `C = P⁻Πᵀ` (the first two columns of
//! `P⁻`), `P_rr = Π P⁻ Πᵀ`, the measurement's position information `M = Gᵀ R⁻¹ G` and
//! `b = Gᵀ R⁻¹ ν` (`G` the range Jacobian rows, `ν = z − h(r̂⁻)`),
//!
//! - `N = (I + M P_rr)⁻¹`, so `Gᵀ S⁻¹ = N Gᵀ R⁻¹` and `K = C N Gᵀ R⁻¹`, `K ν = C N b`;
//! - Joseph form `(I − KH) P⁻ (I − KH)ᵀ + K R Kᵀ = P⁻ − C Z Cᵀ` with
//!   `Z = N M + (N M)ᵀ − N (M + M P_rr M) Nᵀ` (symmetric; to first order insensitive to rounding
//!   in `N`, the property the Joseph form is chosen for), evaluated on the 10 unique entries;
//! - `NIS = νᵀ S⁻¹ ν = νᵀ R⁻¹ ν − bᵀ P_rr N b`.
//!
//! No allocation, one 2 × 2 inverse per update and no per-row division: `R⁻¹` is the link's
//! delay information from the link budget (E8). Internally ranges (`cτ`, `c²R`, `cJ`) are used,
//! which the spec states is identical to the delay domain.
//!
//! A step (issue 13 §3) uses fixed-size types only: the predict works on the 10 unique entries
//! of `P` (E7), pass 1 (`links`) evaluates the delays (E1), Jacobian rows (E3) and SNR (E8) of
//! the links together in fixed blocks of 4 links, with each transmitter's geometry and gain
//! evaluated once, and pass 2 (`batch`) is the 2 × 2 batch update above (S16–S17). The noise
//! option is resolved once per update; the Monte Carlo harness updates 4 filters per call with
//! their transmitter gains, the longest dependency chain of an update, side by side. The sums
//! of pass 1 are added in link order, so the results are bitwise those of a link-by-link loop.

use alloc::vec::Vec;

use crate::error::{check_len, limits, Error, Result};
use crate::math::{sqrt, Mat4, Real, Vec4, SPEED_OF_LIGHT};
use crate::measure::Model;
use crate::track::shared::{
    check_covariance, check_state, check_update, link_sigmas, predict_gaussian,
};
use crate::track::{ConstantVelocity, Filter, MeasurementNoise, PredictedDelay, UpdateSummary};

mod batch;
mod doppler;
mod links;

pub(crate) use batch::update_lanes;
pub(crate) use links::link_information;

/// The filter: state estimate `x̂ = [x, y, vx, vy]ᵀ` and its covariance `P`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ekf {
    /// `x̂`, m and m/s.
    pub state: Vec4,
    /// `P`, m², m²/s, m²/s².
    pub covariance: Mat4,
}

impl Ekf {
    /// A filter at `state` with covariance `covariance` (validated: position within
    /// [`limits::COORDINATE_M`], velocity within [`limits::VELOCITY_M_S`], covariance finite,
    /// symmetric PD, no variance above [`limits::MAX_INITIAL_VARIANCE`]).
    pub fn new(state: Vec4, covariance: Mat4) -> Result<Ekf> {
        check_state(&state)?;
        check_covariance("initial_covariance", &covariance)?;
        for i in 0..4 {
            let v = covariance[(i, i)];
            if v > limits::MAX_INITIAL_VARIANCE {
                return Err(Error::OutOfRange {
                    field: alloc::format!("initial_covariance[{i}][{i}]"),
                    value: v,
                    allowed: "a variance of at most 1e12",
                });
            }
        }
        Ok(Ekf { state, covariance })
    }

    /// Update with delays `z` (s, one per link in scenario link order, `None` = missing; no link
    /// = nothing to do) by the batch Joseph-form update (S17, module docs). On error the filter
    /// is left unchanged. `P` is taken as symmetric (its upper triangle is read).
    ///
    /// `innovations`, if given, receives `z_p − h_p(r̂⁻)` in seconds for the used links and `None`
    /// for the others.
    pub fn update(
        &mut self,
        model: &Model,
        z: &[Option<Real>],
        noise: MeasurementNoise,
        mut innovations: Option<&mut [Option<Real>]>,
    ) -> Result<UpdateSummary> {
        check_update(model, z, noise)?;
        if let Some(out) = innovations.as_deref_mut() {
            check_len("innovations", model.link_count(), out.len())?;
            out.fill(None);
        }
        let innovation = |_lane: usize, link: usize, nu: Real| {
            if let Some(out) = innovations.as_deref_mut() {
                out[link] = Some(nu / SPEED_OF_LIGHT);
            }
        };
        let [summary] = update_lanes(
            core::array::from_mut(self),
            model,
            [z],
            [true],
            noise,
            innovation,
        );
        summary
    }
}

/// The EKF behind the filter seam: its own predict (S16, E7), predicted delays from the
/// Jacobian (E3) and update (S17).
impl Filter for Ekf {
    fn name(&self) -> &'static str {
        "ekf"
    }

    /// Predict: `x̂⁻ = A x̂`, `P⁻ = A P Aᵀ + Q` (S16, E7).
    #[inline]
    fn predict(&mut self, motion: &ConstantVelocity) {
        predict_gaussian(&mut self.state, &mut self.covariance, motion);
    }

    /// The predicted measurement of every link at the current state (call after
    /// [`Filter::predict`]): `h_p(r̂⁻)` (E1) and `√S_pp`, `S_pp = J_p P_rr J_pᵀ + σ_p²` from the
    /// Jacobian (E3), with `σ_p` from `noise`. A `σ_p` that is not finite and `> 0` is
    /// [`Error::InvalidSigma`]; `Fixed` noise of the wrong length is [`Error::LengthMismatch`].
    fn predicted_delays(
        &self,
        model: &Model,
        noise: MeasurementNoise,
    ) -> Result<Vec<PredictedDelay>> {
        let r = self.position();
        let sigmas = link_sigmas(model, noise, r)?;
        let p_rr = self.covariance.fixed_view::<2, 2>(0, 0).into_owned();
        Ok(sigmas
            .iter()
            .enumerate()
            .map(|(link, sigma)| {
                let j = model.network.jacobian_row(link, r);
                let s = (j.transpose() * p_rr * j)[0] + sigma * sigma;
                PredictedDelay {
                    delay_s: model.network.delay(link, r),
                    innovation_sigma_s: sqrt(s),
                }
            })
            .collect())
    }

    fn update(
        &mut self,
        model: &Model,
        z: &[Option<Real>],
        noise: MeasurementNoise,
    ) -> Result<UpdateSummary> {
        Ekf::update(self, model, z, noise, None)
    }

    fn update_doppler(
        &mut self,
        model: &Model,
        z: &[Option<Real>],
        noise: MeasurementNoise,
        rates: &crate::track::RangeRates,
    ) -> Result<UpdateSummary> {
        Ekf::update_doppler(self, model, z, noise, rates)
    }

    fn state(&self) -> &Vec4 {
        &self.state
    }

    fn covariance(&self) -> &Mat4 {
        &self.covariance
    }
}
