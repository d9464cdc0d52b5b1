//! The snapshot bound with Doppler at a point (issue 42 §1, `scatterloc crlb --doppler`): over
//! one CPI, the Fisher information of position and velocity from every link's delay and range
//! rate ([`state_fisher`], D7), its inverse, and per link the range rate and its σ (D1, D5) —
//! beside the same CPI's delay-only bound, which says nothing of the velocity.

use alloc::format;
use alloc::string::String;
use alloc::vec::Vec;

use serde::Serialize;

use crate::localize::MapQuantity;
use crate::math::{sqrt, Real, Vec2, Vec4};
use crate::measure::{range_rate, state_bounds, state_fisher, Cpi, Model};
use crate::study::CpiDoc;

/// One link's range rate and its σ.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct RangeRateDoc {
    /// `ṙ_p`, m/s (D1).
    pub range_rate_mps: Real,
    /// Its σ over the CPI, m/s (D5); `None` when unbounded (one snapshot).
    pub sigma_range_rate_mps: Option<Real>,
}

/// The bound at a point and velocity with and without the range rates.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DopplerDoc {
    /// The CPI.
    pub cpi: CpiDoc,
    /// The velocity the range rates are taken at, m/s.
    pub velocity_mps: [Real; 2],
    /// `√(tr P_rr)` with delays and range rates, m; `None` if singular.
    pub position_rmse_m: Option<Real>,
    /// `√(tr P_vv)` with delays and range rates, m/s; `None` if singular.
    pub velocity_rmse_mps: Option<Real>,
    /// `√(tr F_rr⁻¹)` from the CPI's delays alone (`N` × E8), m; `None` if singular. The delays
    /// of one CPI bound no velocity.
    pub delay_only_position_rmse_m: Option<Real>,
    /// The 4×4 Fisher matrix of `[x, y, vx, vy]` with both (D7), rows.
    pub fim: [[Real; 4]; 4],
    /// Per link, in scenario link order.
    pub links: Vec<RangeRateDoc>,
}

impl DopplerDoc {
    /// The bound of `model` at `at` moving at `velocity` over `cpi`.
    pub fn at(model: &Model, at: [Real; 2], velocity: [Real; 2], cpi: &Cpi) -> DopplerDoc {
        let r = Vec2::new(at[0], at[1]);
        let v = Vec2::new(velocity[0], velocity[1]);
        let x = Vec4::new(r.x, r.y, v.x, v.y);
        let f = state_fisher(model, &x, cpi, true);
        let both = state_bounds(&f);
        let delay = state_fisher(model, &x, cpi, false);
        let fp = delay.fixed_view::<2, 2>(0, 0).into_owned();
        let delay_only = nalgebra::Cholesky::new(fp)
            .map(|c| c.inverse())
            .map(|p| p[(0, 0)] + p[(1, 1)])
            .filter(|t| t.is_finite() && *t > 0.0)
            .map(sqrt);
        let links = (0..model.link_count())
            .map(|p| {
                let s = cpi.sigma_range_rate(model.snr(p, r));
                RangeRateDoc {
                    range_rate_mps: range_rate(&model.network, p, r, v),
                    sigma_range_rate_mps: s.is_finite().then_some(s),
                }
            })
            .collect();
        DopplerDoc {
            cpi: CpiDoc::from(cpi),
            velocity_mps: velocity,
            position_rmse_m: both.map(|b| b.0),
            velocity_rmse_mps: both.map(|b| b.1),
            delay_only_position_rmse_m: delay_only,
            fim: core::array::from_fn(|i| core::array::from_fn(|j| f[(i, j)])),
            links,
        }
    }
}

/// The texts of a map figure with Doppler (`crlb-map --doppler --out f.svg` and the page's
/// Save figure): title, subtitle, colour-bar label and the suffix of its length labels.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct DopplerMapText {
    /// `Position CRLB with Doppler` or `Velocity CRLB with Doppler`.
    pub title: String,
    /// The delay-only map's subtitle, then `· CPI N × T ms, v = (vx, vy) m/s · σṙ floor F m/s`.
    pub subtitle: String,
    /// The colour bar's label.
    pub colorbar_label: String,
    /// `""` (m) for the position map, `"/s"` for the velocity map.
    pub value_suffix: String,
}

impl DopplerMapText {
    /// The texts of the `quantity` map over `cpi` at `velocity` (m/s), `subtitle` being the
    /// delay-only figure's (`chart::default_titles`). The CPI and velocity part is the CLI's
    /// (`T` printed as `spacing_s · 1000`), the floor follows it.
    pub fn new(quantity: MapQuantity, cpi: &Cpi, velocity: [Real; 2], subtitle: &str) -> Self {
        let (title, label, suffix) = match quantity {
            MapQuantity::Position => ("Position", "RMSE bound √(σx² + σy²)", ""),
            MapQuantity::Velocity => ("Velocity", "velocity RMSE bound √(σvx² + σvy²)", "/s"),
        };
        DopplerMapText {
            title: format!("{title} CRLB with Doppler"),
            subtitle: format!(
                "{subtitle} · CPI {} × {} ms, v = ({}, {}) m/s{}",
                cpi.snapshots,
                cpi.spacing_s * 1e3,
                velocity[0],
                velocity[1],
                Self::floor_clause(cpi)
            ),
            colorbar_label: label.into(),
            value_suffix: suffix.into(),
        }
    }

    /// The subtitle's last clause, ` · σṙ floor F m/s`.
    pub fn floor_clause(cpi: &Cpi) -> String {
        format!(" · σṙ floor {} m/s", cpi.floor_mps)
    }
}
