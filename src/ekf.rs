//! Extended Kalman filter for the bistatic-delay tracker (spec §6, S16–S17).
//!
//! Shaped like adskalman-rs: predict and update are separate, the covariance update is the
//! Joseph form and is kept symmetric, and a missing measurement simply skips its row.
//!
//! The update is linearised once at the *predicted* position `r̂⁻` (`H = [J(r̂⁻), 0]`, E3) and
//! the rows of the available links are processed one scalar at a time against that fixed
//! linearisation. With a diagonal `R` this equals the batch update `K = P⁻Hᵀ S⁻¹` exactly, needs no
//! matrix inverse and no allocation, and the summed normalised scalar innovations equal the
//! batch NIS `νᵀ S⁻¹ ν`. Internally ranges (`cτ`, `c²R`, `cJ`) are used, which the spec states
//! is identical to the delay domain.

use nalgebra::Cholesky;

use crate::error::{Error, Result};
use crate::geometry::unit_from;
use crate::math::{Mat4, Real, Vec2, Vec4, SPEED_OF_LIGHT};
use crate::model::{sigma_delay_from_snr, Model};
use crate::motion::ConstantVelocity;

/// Where the measurement noise `R = diag(σ_p²)` comes from (spec §6 [choice]).
#[derive(Debug, Clone, Copy)]
pub enum MeasurementNoise<'a> {
    /// Fixed `σ_p` per link, s (e.g. the parameter estimator's variances).
    Fixed(&'a [Real]),
    /// `σ_p` from the link budget (E8) at the predicted position — the simulation default.
    AtPrediction,
    /// `σ_p` from the link budget at a given position (the "oracle" option: the truth).
    At(Vec2),
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

/// Rows handled per pass of [`Ekf::update`] (stack buffer; more links are done in blocks).
const ROW_BLOCK: usize = 16;

/// One available link linearised at the predicted position, range units.
#[derive(Debug, Clone, Copy, Default)]
struct Row {
    gx: Real,
    gy: Real,
    r_var: Real,
    nu_pred: Real,
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
    /// A filter at `state` with covariance `covariance` (validated: finite, symmetric PD).
    pub fn new(state: Vec4, covariance: Mat4) -> Result<Ekf> {
        if state.iter().any(|v| !v.is_finite()) {
            return Err(Error::NonFinite {
                field: "initial_state".into(),
            });
        }
        check_covariance("initial_covariance", &covariance)?;
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
    /// = nothing to do). On error the filter is left unchanged.
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
        if z.len() != n {
            return Err(Error::LengthMismatch {
                field: "measurement",
                expected: n,
                found: z.len(),
            });
        }
        if let MeasurementNoise::Fixed(s) = noise {
            if s.len() != n {
                return Err(Error::LengthMismatch {
                    field: "sigma_s",
                    expected: n,
                    found: s.len(),
                });
            }
        }
        if let Some(out) = innovations.as_deref_mut() {
            if out.len() != n {
                return Err(Error::LengthMismatch {
                    field: "innovations",
                    expected: n,
                    found: out.len(),
                });
            }
            out.fill(None);
        }
        let predicted = self.state;
        let r_pred = Vec2::new(predicted[0], predicted[1]);
        let (mut x, mut p) = (predicted, self.covariance);
        let mut summary = UpdateSummary {
            nis: 0.0,
            links_used: 0,
        };
        // Tx gain toward r̂⁻ of the last transmitter seen (links of one Tx share it).
        let mut tx_gain: Option<(usize, Real)> = None;
        let mut rows = [Row::default(); ROW_BLOCK];
        let mut next = 0;
        while next < n {
            // Pass 1: the rows of up to ROW_BLOCK available links, all at the fixed r̂⁻, so their
            // square roots and divisions overlap instead of waiting on P.
            let mut m = 0;
            while next < n && m < ROW_BLOCK {
                let link = next;
                next += 1;
                let Some(zi) = z[link] else { continue };
                if !zi.is_finite() {
                    return Err(Error::NonFiniteDelay { link });
                }
                let (tx, rx) = model.network.link_nodes(link);
                let (ut, dt) = unit_from(tx, r_pred);
                let (ur, dr) = unit_from(rx, r_pred);
                let sigma = match noise {
                    MeasurementNoise::Fixed(s) => s[link],
                    MeasurementNoise::AtPrediction => {
                        let k = model.network.links[link].tx;
                        let gain = match tx_gain {
                            Some((kk, g)) if kk == k => g,
                            _ => model.patterns[k].gain_toward(ut),
                        };
                        tx_gain = Some((k, gain));
                        sigma_delay_from_snr(
                            model.beta2,
                            model.snr_from_geometry(link, gain, dt, dr),
                        )
                    }
                    MeasurementNoise::At(r) => model.sigma_delay(link, r),
                };
                if !(sigma.is_finite() && sigma > 0.0) {
                    return Err(Error::InvalidSigma { link, value: sigma });
                }
                let nu_pred = SPEED_OF_LIGHT * zi - (dt + dr);
                if let Some(out) = innovations.as_deref_mut() {
                    out[link] = Some(nu_pred / SPEED_OF_LIGHT);
                }
                // Row of cH: [gx, gy, 0, 0]; range variance c²σ².
                rows[m] = Row {
                    gx: ut.x + ur.x,
                    gy: ut.y + ur.y,
                    r_var: (SPEED_OF_LIGHT * sigma) * (SPEED_OF_LIGHT * sigma),
                    nu_pred,
                };
                m += 1;
            }
            // Pass 2: sequential scalar updates against the fixed linearisation (= batch).
            for row in &rows[..m] {
                let (gx, gy, r_var) = (row.gx, row.gy, row.r_var);
                let nu = row.nu_pred - (gx * (x[0] - predicted[0]) + gy * (x[1] - predicted[1]));
                let ph: Vec4 = p.column(0) * gx + p.column(1) * gy;
                let s = gx * ph[0] + gy * ph[1] + r_var;
                if !(s.is_finite() && s > 0.0) {
                    return Err(Error::NotPositiveDefinite {
                        field: "ekf.innovation_covariance".into(),
                    });
                }
                let inv_s = 1.0 / s;
                let k = ph * inv_s;
                x += k * nu;
                summary.nis += nu * nu * inv_s;
                summary.links_used += 1;
                // Joseph form (I − k h) P (I − k h)ᵀ + k r kᵀ, as products with the rank-one
                // factor: X = P (I − k h)ᵀ = P − ph kᵀ; then (I − k h) X = X − k (h X).
                let xm = p - ph * k.transpose();
                let hx = xm.row(0) * gx + xm.row(1) * gy;
                p = xm - k * hx + (k * k.transpose()) * r_var;
            }
        }
        if summary.links_used > 0 {
            p = (p + p.transpose()) * 0.5;
            if x.iter().any(|v| !v.is_finite())
                || (0..4).any(|i| !(p[(i, i)] > 0.0) || !p[(i, i)].is_finite())
            {
                return Err(Error::NotPositiveDefinite {
                    field: "ekf.covariance".into(),
                });
            }
            self.state = x;
            self.covariance = p;
        }
        Ok(summary)
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

    /// Normalised estimation error squared `(x̂ − x)ᵀ P⁻¹ (x̂ − x)` against a true state;
    /// `None` if `P` is not positive definite.
    pub fn nees(&self, truth: &Vec4) -> Option<Real> {
        let e = self.state - truth;
        Cholesky::new(self.covariance).map(|c| e.dot(&c.solve(&e)))
    }
}
