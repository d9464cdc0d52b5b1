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

use nalgebra::Cholesky;

use crate::error::{check_len, limits, Error, Result};
use crate::math::{sqrt, Mat4, Real, Vec2, Vec4, PI, SPEED_OF_LIGHT};
use crate::measure::Model;
use crate::track::ConstantVelocity;

mod batch;
mod links;
mod nees;

pub(crate) use batch::{first_input_error, update_lanes};
pub(crate) use links::link_information;
pub(crate) use nees::{spd_quadratic_form, Ldl4};

/// Where the measurement noise `R = diag(σ_p²)` comes from (spec §6 \[choice\]).
#[derive(Debug, Clone, Copy)]
pub enum MeasurementNoise<'a> {
    /// Fixed `σ_p` per link, s (e.g. the parameter estimator's variances).
    Fixed(&'a [Real]),
    /// `σ_p` from the link budget (E8) at the predicted position — the simulation default.
    AtPrediction,
    /// `σ_p` from the link budget at a given position (the "oracle" option: the truth).
    At(Vec2),
}

impl MeasurementNoise<'_> {
    /// `Fixed` noise must give one σ per link (`LengthMismatch` of `sigma_s` otherwise).
    pub fn check_links(&self, n: usize) -> Result<()> {
        match self {
            MeasurementNoise::Fixed(s) if s.len() != n => Err(Error::LengthMismatch {
                field: "sigma_s",
                expected: n,
                found: s.len(),
            }),
            _ => Ok(()),
        }
    }

    /// `σ_p` of link `link`, s, for a filter whose predicted position is `r_pred`.
    pub fn sigma(&self, model: &Model, link: usize, r_pred: Vec2) -> Real {
        match *self {
            MeasurementNoise::Fixed(s) => s[link],
            MeasurementNoise::AtPrediction => model.sigma_delay(link, r_pred),
            MeasurementNoise::At(r) => model.sigma_delay(link, r),
        }
    }
}

/// The filter's predicted measurement of one link: `h_p(r̂⁻)` (E1) and the innovation standard
/// deviation `√S_pp`, `S_pp = J_p P_rr J_pᵀ + σ_p²` (E3, spec §6), both in seconds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PredictedDelay {
    /// `h_p(r̂⁻)`, s.
    pub delay_s: Real,
    /// `√S_pp`, s.
    pub innovation_sigma_s: Real,
}

impl PredictedDelay {
    /// `|τ − h_p(r̂⁻)| / √S_pp`: the normalised innovation of a candidate delay.
    pub fn normalized_innovation(&self, delay_s: Real) -> Real {
        (delay_s - self.delay_s).abs() / self.innovation_sigma_s
    }
}

/// Outcome of one update.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UpdateSummary {
    /// Normalised innovation squared `νᵀ S⁻¹ ν` (0 when no link was used).
    pub nis: Real,
    /// Links whose measurement was used.
    pub links_used: usize,
}

/// The filter: state estimate `x̂ = [x, y, vx, vy]ᵀ` and its covariance `P`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ekf {
    /// `x̂`, m and m/s.
    pub state: Vec4,
    /// `P`, m², m²/s, m²/s².
    pub covariance: Mat4,
}

/// Geometry of one node as seen from a point `r`: the unit vector node → `r` (zero when they
/// nearly coincide, as [`crate::measure::unit_from`]), the distance and `1/max(d, 1 m)²` (the
/// floored distance factor of the SNR, E8). One division and one square root; lane 0 of the
/// EKF's `links::NodeViews`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct NodeView {
    pub(crate) unit: Vec2,
    pub(crate) distance: Real,
    pub(crate) inv_floored_sq: Real,
}

impl NodeView {
    #[inline(always)]
    pub(crate) fn new(node: Vec2, r: Vec2) -> NodeView {
        let v = links::NodeViews::<1>::new(&[node.x], &[node.y], &[r.x], &[r.y]);
        NodeView {
            unit: Vec2::new(v.ux[0], v.uy[0]),
            distance: v.distance[0],
            inv_floored_sq: v.inv_floored_sq[0],
        }
    }
}

/// `8π²β²/c²`: turns an SNR into the range-domain information `1/(cσ_p)²`, 1/m² (E8).
#[inline(always)]
pub(crate) fn range_information_per_snr(model: &Model) -> Real {
    8.0 * PI * PI * model.beta2 / (SPEED_OF_LIGHT * SPEED_OF_LIGHT)
}

/// `1/(cσ)²` for a delay standard deviation `σ`, 1/m² (checked by the caller).
#[inline(always)]
fn information_from_sigma(sigma: Real) -> Real {
    let r = SPEED_OF_LIGHT * sigma;
    1.0 / (r * r)
}

/// Checks a user-supplied state: finite, position within [`limits::COORDINATE_M`], velocity
/// within [`limits::VELOCITY_M_S`] (errors name `initial_state[i]`).
pub(crate) fn check_state(state: &Vec4) -> Result<()> {
    if state.iter().any(|v| !v.is_finite()) {
        return Err(Error::NonFinite {
            field: "initial_state".into(),
        });
    }
    for (i, range) in [
        limits::COORDINATE_M,
        limits::COORDINATE_M,
        limits::VELOCITY_M_S,
        limits::VELOCITY_M_S,
    ]
    .iter()
    .enumerate()
    {
        range.check(&alloc::format!("initial_state[{i}]"), state[i])?;
    }
    Ok(())
}

/// Relative asymmetry tolerated in a user-supplied covariance.
const SYMMETRY_TOLERANCE: Real = 1e-9;

/// Checks that `p` is finite, symmetric (to 1e-9 relative) and positive definite.
pub fn check_covariance(field: &str, p: &Mat4) -> Result<()> {
    if p.iter().any(|v| !v.is_finite()) {
        return Err(Error::NonFinite {
            field: field.into(),
        });
    }
    let scale = p.abs().max();
    if (p - p.transpose()).abs().max() > SYMMETRY_TOLERANCE * scale || Cholesky::new(*p).is_none() {
        return Err(Error::NotPositiveDefinite {
            field: field.into(),
        });
    }
    Ok(())
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

    /// Position part of the state, m.
    pub fn position(&self) -> Vec2 {
        Vec2::new(self.state[0], self.state[1])
    }

    /// Predict: `x̂⁻ = A x̂`, `P⁻ = A P Aᵀ + Q` (S16, E7).
    #[inline]
    pub fn predict(&mut self, motion: &ConstantVelocity) {
        self.state = motion.propagate(&self.state);
        self.covariance = motion.propagate_covariance(&self.covariance);
    }

    /// Update with delays `z` (s, one per link in scenario link order, `None` = missing; no link
    /// = nothing to do). On error the filter is left unchanged. `P` is taken as symmetric (its
    /// upper triangle is read).
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
        let n = model.link_count();
        check_len("measurement", n, z.len())?;
        noise.check_links(n)?;
        if let Some(out) = innovations.as_deref_mut() {
            check_len("innovations", n, out.len())?;
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

    /// Predict then update (one filter step).
    pub fn step(
        &mut self,
        motion: &ConstantVelocity,
        model: &Model,
        z: &[Option<Real>],
        noise: MeasurementNoise,
    ) -> Result<UpdateSummary> {
        let before = *self;
        self.predict(motion);
        self.update(model, z, noise, None)
            .inspect_err(|_| *self = before)
    }

    /// The predicted measurement of every link at the current state (call after
    /// [`Ekf::predict`]): `h_p(r̂⁻)` and `√S_pp` with `σ_p` from `noise`. A `σ_p` that is not
    /// finite and `> 0` is [`Error::InvalidSigma`]; `Fixed` noise of the wrong length is
    /// [`Error::LengthMismatch`].
    pub fn predicted_delays(
        &self,
        model: &Model,
        noise: MeasurementNoise,
    ) -> Result<alloc::vec::Vec<PredictedDelay>> {
        let n = model.link_count();
        noise.check_links(n)?;
        let r = self.position();
        let p_rr = self.covariance.fixed_view::<2, 2>(0, 0).into_owned();
        (0..n)
            .map(|link| {
                let sigma = noise.sigma(model, link, r);
                if !positive_finite(sigma) {
                    return Err(Error::InvalidSigma { link, value: sigma });
                }
                let j = model.network.jacobian_row(link, r);
                let s = (j.transpose() * p_rr * j)[0] + sigma * sigma;
                Ok(PredictedDelay {
                    delay_s: model.network.delay(link, r),
                    innovation_sigma_s: sqrt(s),
                })
            })
            .collect()
    }

    /// Normalised estimation error squared `(x̂ − x)ᵀ P⁻¹ (x̂ − x)` against a true state;
    /// `None` if `P` is not positive definite. `P` is taken as symmetric (a 4 × 4 `LDLᵀ`
    /// factorisation of its lower triangle; all pivots must be positive).
    pub fn nees(&self, truth: &Vec4) -> Option<Real> {
        spd_quadratic_form(&self.covariance, &(self.state - truth))
    }
}

/// `x > 0` and finite, as two float compares (`is_finite` becomes an integer classification
/// sequence in the hot loop).
#[inline(always)]
fn positive_finite(x: Real) -> bool {
    x > 0.0 && finite_probe(x) == 0.0
}

/// `x − x`: `0` for a finite `x`, NaN otherwise (a sum of probes is `0` iff all are finite).
#[inline(always)]
#[allow(clippy::eq_op)]
fn finite_probe(x: Real) -> Real {
    x - x
}
