//! The EKF update of `L` filters at once: pass 1 ([`link_information`], E1, E3, E8), the folded
//! input checks, and pass 2, the batch Joseph-form update in the position space (S16–S17;
//! derivation in the [`ekf`](super) module docs).

use super::links::{link_information, Information};
use super::{Ekf, MeasurementNoise, UpdateSummary};
use crate::error::{Error, Result};
use crate::math::{Mat4, Real, Vec2, Vec4};
use crate::measure::Model;
use crate::track::shared::{finite_probe, first_input_error, positive_finite, NO_UPDATE};
use crate::track::Filter;

/// The EKF update of `L` independent filters against the same model and noise option, each
/// with its own delays `z[j]` (lengths checked by the caller); `active[j] = false` skips filter
/// `j` (its result is a zero summary). `L = 1` is [`Ekf::update`]; the Monte Carlo harness
/// updates a few noise runs in one call so that the processor overlaps their dependency chains
/// (the arithmetic of each filter is the same as with `L = 1`, so results are bitwise equal).
/// `innovation(j, p, ν_p)` receives each used link's range innovation, m. No allocation unless
/// an input is bad (the error names it).
#[inline(always)]
pub(crate) fn update_lanes<const L: usize>(
    filters: &mut [Ekf; L],
    model: &Model,
    z: [&[Option<Real>]; L],
    active: [bool; L],
    noise: MeasurementNoise,
    mut innovation: impl FnMut(usize, usize, Real),
) -> [Result<UpdateSummary>; L] {
    let r_pred: [Vec2; L] = core::array::from_fn(|j| filters[j].position());
    let info = link_information(model, &r_pred, &z, &active, noise, |j, p, nu, _| {
        innovation(j, p, nu)
    });
    let mut out = [NO_LINKS; L];
    for (j, out) in out.iter_mut().enumerate() {
        let a = &info[j];
        if !active[j] {
            continue;
        }
        if !a.valid {
            // On failure the inputs are re-scanned in link order for the named error.
            if let Some(e) = first_input_error(model, z[j], noise, r_pred[j]) {
                *out = Err(e);
                continue;
            }
        }
        if a.links_used > 0 {
            *out = filters[j].apply_information(a);
        }
    }
    out
}

/// The result of an update without links.
const NO_LINKS: Result<UpdateSummary> = Ok(NO_UPDATE);

impl Ekf {
    /// Pass 2 of an update: the batch update in the position space (module docs) from the
    /// accumulated information; the filter changes only on success.
    #[inline(always)]
    fn apply_information(&mut self, a: &Information) -> Result<UpdateSummary> {
        let (m00, m01, m11, b0, b1) = (a.m00, a.m01, a.m11, a.b0, a.b1);
        let p = &self.covariance;
        let (p00, p01, p02, p03) = (p[(0, 0)], p[(0, 1)], p[(0, 2)], p[(0, 3)]);
        let (p11, p12, p13) = (p[(1, 1)], p[(1, 2)], p[(1, 3)]);
        let (p22, p23, p33) = (p[(2, 2)], p[(2, 3)], p[(3, 3)]);
        // T = I + M P_rr, N = T⁻¹.
        let t00 = 1.0 + m00 * p00 + m01 * p01;
        let t01 = m00 * p01 + m01 * p11;
        let t10 = m01 * p00 + m11 * p01;
        let t11 = 1.0 + m01 * p01 + m11 * p11;
        if t00 + t11 > WIDE_PRIOR {
            return self.apply_information_wide(a);
        }
        let det = t00 * t11 - t01 * t10;
        if !positive_finite(det) {
            return Err(Error::NotPositiveDefinite {
                field: "ekf.innovation_covariance".into(),
            });
        }
        let inv_det = 1.0 / det;
        let (n00, n01, n10, n11) = (t11 * inv_det, -t01 * inv_det, -t10 * inv_det, t00 * inv_det);
        // N M.
        let nm00 = n00 * m00 + n01 * m01;
        let nm01 = n00 * m01 + n01 * m11;
        let nm10 = n10 * m00 + n11 * m01;
        let nm11 = n10 * m01 + n11 * m11;
        // X = M + M P_rr M (symmetric): Y = P_rr M, X = M + M Y.
        let y00 = p00 * m00 + p01 * m01;
        let y01 = p00 * m01 + p01 * m11;
        let y11 = p01 * m01 + p11 * m11;
        let x00 = m00 + (m00 * y00 + m01 * (p01 * m00 + p11 * m01));
        let x01 = m01 + (m00 * y01 + m01 * y11);
        let x11 = m11 + (m01 * y01 + m11 * y11);
        // U = N X, then N X Nᵀ.
        let u00 = n00 * x00 + n01 * x01;
        let u01 = n00 * x01 + n01 * x11;
        let u10 = n10 * x00 + n11 * x01;
        let u11 = n10 * x01 + n11 * x11;
        let z00 = 2.0 * nm00 - (u00 * n00 + u01 * n01);
        let z01 = (nm01 + nm10) - (u00 * n10 + u01 * n11);
        let z11 = 2.0 * nm11 - (u10 * n10 + u11 * n11);
        // Rows of C = P⁻Πᵀ: c_i = (P_i0, P_i1).
        let c = [(p00, p01), (p01, p11), (p02, p12), (p03, p13)];
        // Z c_j.
        let zc = c.map(|(a, b)| (z00 * a + z01 * b, z01 * a + z11 * b));
        let q = |i: usize, j: usize| c[i].0 * zc[j].0 + c[i].1 * zc[j].1;
        let (e00, e01, e02, e03) = (p00 - q(0, 0), p01 - q(0, 1), p02 - q(0, 2), p03 - q(0, 3));
        let (e11, e12, e13) = (p11 - q(1, 1), p12 - q(1, 2), p13 - q(1, 3));
        let (e22, e23, e33) = (p22 - q(2, 2), p23 - q(2, 3), p33 - q(3, 3));
        // K ν = C N b.
        let (v0, v1) = (n00 * b0 + n01 * b1, n10 * b0 + n11 * b1);
        let dx = c.map(|(a, b)| a * v0 + b * v1);
        let state = self.state + Vec4::new(dx[0], dx[1], dx[2], dx[3]);
        // NIS = νᵀR⁻¹ν − bᵀ P_rr N b; P_rr N b is the position correction (dx0, dx1).
        let nis = (a.nu_info_nu - (b0 * dx[0] + b1 * dx[1])).max(0.0);
        let covariance = Mat4::new(
            e00, e01, e02, e03, //
            e01, e11, e12, e13, //
            e02, e12, e22, e23, //
            e03, e13, e23, e33,
        );
        self.commit(state, covariance, nis, a.links_used)
    }

    /// The update in information form, `P⁺ = (P⁻¹ + Πᵀ M Π)⁻¹` and `x⁺ = x + P⁺ Πᵀ b`, for a
    /// prior much wider than the links' information (`tr(M P_rr) >` [`WIDE_PRIOR`]): there the
    /// covariance form subtracts two nearly equal large matrices and loses every digit (a prior
    /// of 10¹² m² against centimetre links). Both forms are the same update (matrix inversion
    /// lemma); this one costs two 4×4 Cholesky factorisations.
    #[cold]
    fn apply_information_wide(&mut self, a: &Information) -> Result<UpdateSummary> {
        let not_pd = || Error::NotPositiveDefinite {
            field: "ekf.covariance".into(),
        };
        let mut info = nalgebra::Cholesky::new(self.covariance)
            .ok_or_else(not_pd)?
            .inverse();
        info[(0, 0)] += a.m00;
        info[(0, 1)] += a.m01;
        info[(1, 0)] += a.m01;
        info[(1, 1)] += a.m11;
        let p = nalgebra::Cholesky::new(info).ok_or_else(not_pd)?.inverse();
        let covariance = (p + p.transpose()) * 0.5;
        let dx = covariance * Vec4::new(a.b0, a.b1, 0.0, 0.0);
        let state = self.state + dx;
        let nis = (a.nu_info_nu - (a.b0 * dx[0] + a.b1 * dx[1])).max(0.0);
        self.commit(state, covariance, nis, a.links_used)
    }

    /// Takes `state` and `covariance` if finite with a positive diagonal, else
    /// [`Error::NotPositiveDefinite`] (`ekf.covariance`) and the filter unchanged.
    #[inline(always)]
    pub(super) fn commit(
        &mut self,
        state: Vec4,
        covariance: Mat4,
        nis: Real,
        links_used: usize,
    ) -> Result<UpdateSummary> {
        let state_finite = finite_probe(state[0])
            + finite_probe(state[1])
            + finite_probe(state[2])
            + finite_probe(state[3]);
        let (e00, e11, e22, e33) = (
            covariance[(0, 0)],
            covariance[(1, 1)],
            covariance[(2, 2)],
            covariance[(3, 3)],
        );
        let diagonal_positive = e00 > 0.0 && e11 > 0.0 && e22 > 0.0 && e33 > 0.0;
        if !(diagonal_positive && state_finite == 0.0 && (e00 + e11 + e22 + e33) < Real::INFINITY) {
            return Err(Error::NotPositiveDefinite {
                field: "ekf.covariance".into(),
            });
        }
        self.state = state;
        self.covariance = covariance;
        Ok(UpdateSummary { nis, links_used })
    }
}

/// `tr(I + M P_rr)` above which an update takes the information form
/// ([`Ekf::apply_information_wide`]): the covariance form's relative rounding error grows like
/// `ε·tr(M P_rr)`, here ≈ 2·10⁻¹⁰.
const WIDE_PRIOR: Real = 1e6;
