//! The documents of the single-snapshot use cases (issue 27): the CRLB at a point with its
//! per-link budget ([`CrlbDoc`], `scatterloc crlb`) and a Levenberg–Marquardt fix
//! ([`FixDoc`], `scatterloc locate`), built once here for the CLI and the Python package so
//! both report the same numbers under the same keys.

use alloc::string::String;
use alloc::vec::Vec;

use serde::Serialize;

use crate::error::Result;
use crate::localize::{crlb_at, LmReport};
use crate::math::{log10, Mat2, Real, Vec2};
use crate::measure::Model;
use crate::scenario::Scenario;

/// A symmetric 2×2 matrix as `[[a, b], [b, c]]` (its upper triangle).
pub fn sym2(m: &Mat2) -> [[Real; 2]; 2] {
    [[m[(0, 0)], m[(0, 1)]], [m[(0, 1)], m[(1, 1)]]]
}

/// The 1σ error ellipse of a bound.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct EllipseDoc {
    /// Semi-major axis, m.
    pub semi_major_m: Real,
    /// Semi-minor axis, m.
    pub semi_minor_m: Real,
    /// Angle of the major axis from +x, degrees.
    pub angle_deg: Real,
}

/// One link at the point.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LinkDoc {
    /// Transmitter name.
    pub tx: String,
    /// Receiver name.
    pub rx: String,
    /// SNR of the scatterer's echo, dB (E8).
    pub snr_db: Real,
    /// The delay σ of the link budget, s (E8).
    pub sigma_delay_s: Real,
    /// The noise-free bistatic delay, s (E1).
    pub delay_s: Real,
}

/// The CRLB at one point (spec §7, E8, S18–S24; keys in the order `scatterloc crlb` prints).
/// Unbounded (singular Fisher matrix): `bounded` false and the sigmas, covariance and ellipse
/// `None`, never NaN.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CrlbDoc {
    /// The point, m.
    pub position_m: [Real; 2],
    /// Whether the Fisher matrix is invertible.
    pub bounded: bool,
    /// `σx`, m (S18).
    pub sigma_x_m: Option<Real>,
    /// `σy`, m (S19).
    pub sigma_y_m: Option<Real>,
    /// `√(σx² + σy²)`, m (S24).
    pub rmse_bound_m: Option<Real>,
    /// `F(r)`, 1/m² (E8).
    pub fim_per_m2: [[Real; 2]; 2],
    /// `F⁻¹`, m².
    pub covariance_m2: Option<[[Real; 2]; 2]>,
    /// The 1σ ellipse.
    pub ellipse_1sigma: Option<EllipseDoc>,
    /// Per link, in scenario link order.
    pub links: Vec<LinkDoc>,
}

impl CrlbDoc {
    /// The bound of `model` (compiled from `scenario`) at `at`.
    pub fn at(scenario: &Scenario, model: &Model, at: [Real; 2]) -> Result<CrlbDoc> {
        let r = Vec2::new(at[0], at[1]);
        let pt = crlb_at(model, r);
        let links = scenario
            .link_names()?
            .into_iter()
            .enumerate()
            .map(|(p, (tx, rx))| LinkDoc {
                tx,
                rx,
                snr_db: 10.0 * log10(model.snr(p, r)),
                sigma_delay_s: model.sigma_delay(p, r),
                delay_s: model.network.delay(p, r),
            })
            .collect();
        let b = pt.bound;
        Ok(CrlbDoc {
            position_m: at,
            bounded: b.is_some(),
            sigma_x_m: b.map(|b| b.sigma_x_m),
            sigma_y_m: b.map(|b| b.sigma_y_m),
            rmse_bound_m: b.map(|b| b.rmse_m),
            fim_per_m2: sym2(&pt.fisher_per_m2),
            covariance_m2: b.map(|b| sym2(&b.covariance_m2)),
            ellipse_1sigma: pt.ellipse().map(|e| EllipseDoc {
                semi_major_m: e.semi_major,
                semi_minor_m: e.semi_minor,
                angle_deg: e.angle_rad.to_degrees(),
            }),
            links,
        })
    }
}

/// A weighted Levenberg–Marquardt fix (spec §5, E5–E6; keys in the order `scatterloc locate`
/// prints).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FixDoc {
    /// `r̂`, m.
    pub position_m: [Real; 2],
    /// `(JᵀR⁻¹J)⁻¹` at `r̂`, m² (`None` when singular).
    pub covariance_m2: Option<[[Real; 2]; 2]>,
    /// `𝓛(r̂)` (E5).
    pub cost: Real,
    /// Iterations (Jacobian evaluations).
    pub iterations: usize,
    /// Why it stopped ([`crate::localize::Termination::as_str`]).
    pub termination: &'static str,
    /// Whether the termination means a converged fix.
    pub converged: bool,
    /// Links that carried a measurement.
    pub links_used: usize,
    /// Where the kept iteration started, m.
    pub start_m: [Real; 2],
}

impl From<&LmReport> for FixDoc {
    fn from(rep: &LmReport) -> FixDoc {
        FixDoc {
            position_m: [rep.position.x, rep.position.y],
            covariance_m2: rep.covariance_m2.as_ref().map(sym2),
            cost: rep.cost,
            iterations: rep.iterations,
            termination: rep.termination.as_str(),
            converged: rep.termination.converged(),
            links_used: rep.links_used,
            start_m: [rep.start.x, rep.start.y],
        }
    }
}
