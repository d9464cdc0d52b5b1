//! One simulated snapshot for a scatterer at a known point, as the page shows it: noisy delays
//! (E2) with σ from the link budget at the truth (E8), each link's iso-delay ellipse (spec §2),
//! the weighted LM fix (E5–E6) with its 1σ ellipse, the CRLB with its 1σ ellipse at the truth
//! (§7), and a view radius around the truth that holds both ellipses (for a zoom inset).

use alloc::vec::Vec;

use crate::error::Result;
use crate::localize::{crlb_at, CrlbPoint};
use crate::localize::{locate, DelayMeasurements, LmConfig, LmReport};
use crate::math::{Real, Vec2, SPEED_OF_LIGHT};
use crate::measure::Ellipse;
use crate::measure::Model;
use crate::measure::{noisy_delays, rng};
use crate::scenario::{Area, LinkIndex};

/// Points of a link's whole iso-delay ellipse outline.
pub const OUTLINE_POINTS: usize = 160;
/// Points of a link's iso-delay arc near the truth.
pub const ARC_POINTS: usize = 48;
/// The view radius is this multiple of the farthest ellipse extent from the truth.
pub const VIEW_MARGIN: Real = 1.6;
/// Extent used when neither ellipse exists (unbounded CRLB and no fix), m.
pub const FALLBACK_EXTENT_M: Real = 0.05;

/// One link of a snapshot.
#[derive(Debug, Clone, PartialEq)]
pub struct LinkSim {
    /// The link's transmitter and receiver indices.
    pub link: LinkIndex,
    /// Simulated delay `τ̂_p = h_p(r) + w_p`, s (E2).
    pub delay_s: Real,
    /// `σ_p(r)` at the truth, s (E8).
    pub sigma_s: Real,
    /// Range noise `c·σ_p`, m.
    pub range_sigma_m: Real,
    /// Iso-delay ellipse of `τ̂_p`; `None` when `τ̂_p` is below the line-of-sight delay.
    pub ellipse: Option<Ellipse>,
    /// [`OUTLINE_POINTS`] points of that ellipse (a closed polygon); empty without one.
    pub outline: Vec<Vec2>,
    /// [`ARC_POINTS`] points of the ellipse near the truth, within about the view radius
    /// ([`Ellipse::arc_near`]); empty without an ellipse or when it passes farther away.
    pub arc: Vec<Vec2>,
}

/// The LM fix of a snapshot.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SnapshotFix {
    /// The solver's report.
    pub report: LmReport,
    /// The 1σ ellipse of its covariance `(JᵀR⁻¹J)⁻¹`; `None` when singular.
    pub ellipse: Option<Ellipse>,
    /// Distance from the truth, m.
    pub error_m: Real,
}

/// A simulated snapshot and everything drawn for it.
#[derive(Debug, Clone, PartialEq)]
pub struct SnapshotSimulation {
    /// True scatterer position, m.
    pub truth: Vec2,
    /// Seed of the noise stream.
    pub seed: u64,
    /// One entry per link, in link order.
    pub links: Vec<LinkSim>,
    /// The fix from the grid-search start, or why there is none (e.g. too few links).
    pub fix: Result<SnapshotFix>,
    /// The CRLB at the truth.
    pub crlb: CrlbPoint,
    /// A radius around the truth holding the CRLB and fix ellipses, with margin, m.
    pub view_radius_m: Real,
}

/// Simulates one snapshot for a scatterer at `truth` with noise stream `seed`
/// ([`rng`]`(seed, 0)`): delays and σ from the link budget at the truth, the LM fix with
/// [`LmConfig::default`] from the grid-search start over `area`, and the CRLB at the truth.
pub fn simulate_snapshot(model: &Model, area: &Area, truth: Vec2, seed: u64) -> SnapshotSimulation {
    let net = &model.network;
    let delays = noisy_delays(model, truth, &mut rng(seed, 0));
    let sigmas = model.sigma_delays(truth);
    let measured: Vec<Option<Real>> = delays.iter().copied().map(Some).collect();
    let m = DelayMeasurements {
        delays_s: &measured,
        sigmas_s: &sigmas,
    };
    let fix = locate(net, &m, &LmConfig::default(), None, area).map(|report| SnapshotFix {
        ellipse: report
            .covariance_m2
            .and_then(|c| Ellipse::from_covariance(report.position, &c, 1.0)),
        error_m: (report.position - truth).norm(),
        report,
    });
    let crlb = crlb_at(model, truth);
    let fix_reach = fix
        .as_ref()
        .map_or(0.0, |f| f.error_m + f.ellipse.map_or(0.0, |e| e.semi_major));
    let view_radius_m = view_radius(&crlb, fix_reach);
    let links = (0..net.link_count())
        .map(|p| link_sim(model, p, delays[p], sigmas[p], truth, view_radius_m))
        .collect();
    SnapshotSimulation {
        truth,
        seed,
        links,
        fix,
        crlb,
        view_radius_m,
    }
}

/// Link `p` of a scatterer at `truth` measured at `delay_s` with noise `sigma_s`: its iso-delay
/// ellipse, outline and the arc within about `view_radius_m` of the truth. Shared with the
/// track frames of [`crate::present`]. A link with a node off the target's plane (issue 40)
/// keeps the planar ellipse in `ellipse` (an approximation there) but draws the exact 3-D
/// iso-delay curve as its outline and arc ([`crate::measure::Network::iso_delay_curve`]).
pub(crate) fn link_sim(
    model: &Model,
    p: usize,
    delay_s: Real,
    sigma_s: Real,
    truth: Vec2,
    view_radius_m: Real,
) -> LinkSim {
    let ellipse = model.network.iso_delay_ellipse(p, delay_s);
    let planar = LinkSim {
        link: model.network.links[p],
        delay_s,
        sigma_s,
        range_sigma_m: SPEED_OF_LIGHT * sigma_s,
        ellipse,
        outline: ellipse.map_or_else(Vec::new, |e| e.polygon(OUTLINE_POINTS)),
        arc: ellipse.map_or_else(Vec::new, |e| e.arc_near(truth, view_radius_m, ARC_POINTS)),
    };
    if model.network.link_is_planar(p) {
        return planar;
    }
    let net = &model.network;
    LinkSim {
        outline: net.iso_delay_curve(p, delay_s, OUTLINE_POINTS),
        arc: net.iso_delay_arc_near(p, delay_s, truth, view_radius_m, ARC_POINTS),
        ..planar
    }
}

/// [`VIEW_MARGIN`] times how far from the truth the CRLB ellipse (semi-major axis) and an
/// estimate (`estimate_reach`: its miss plus its ellipse's semi-major axis) reach;
/// [`FALLBACK_EXTENT_M`] instead of that extent when it is not a finite positive length.
pub(crate) fn view_radius(crlb: &CrlbPoint, estimate_reach: Real) -> Real {
    let crlb_reach = crlb.ellipse().map_or(0.0, |e| e.semi_major);
    let r = crlb_reach.max(estimate_reach);
    VIEW_MARGIN
        * if r.is_finite() && r > 0.0 {
            r
        } else {
            FALLBACK_EXTENT_M
        }
}

#[cfg(test)]
mod tests;
