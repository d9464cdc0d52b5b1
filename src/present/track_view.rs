//! What a front end shows of a simulated track ([`TrackRun`], spec §6): the prior mean of a
//! named or drawn trajectory, the EKF's 1σ position ellipse per step, and for the step on
//! screen a frame shaped like a snapshot ([`crate::present`]) — the truth, the estimate with
//! its ellipse and miss, each link's measured iso-delay ellipse (outline and the arc near the
//! truth), the snapshot CRLB at the truth (§7) and a zoom radius holding them — so the page draws
//! a track step with the same code as a snapshot.

use alloc::vec::Vec;

use crate::error::{check_finite, check_positive, checked_index, Error, Result};
use crate::localize::{crlb_at, CrlbPoint};
use crate::math::{sqrt, Mat2, Mat4, Real, Vec2, Vec4};
use crate::measure::Ellipse;
use crate::measure::Model;
use crate::present::{link_sim, view_radius, LinkSim};
use crate::track::TrackRun;
use crate::track::TrackScenario;

/// Trajectory kinds a front end offers: the three scenarios of §9.4 and a drawn one.
pub const TRAJECTORY_KINDS: [&str; 4] = ["I", "II", "III", "custom"];

/// The prior mean `x̄₀ = [r̄; v̄]` of trajectory `kind`: `I`, `II`, `III` (spec §9.4; `start` and
/// `velocity` are ignored) or `custom` (`start`, `velocity` as given; must be finite).
pub fn track_mean_state(kind: &str, start: Vec2, velocity: Vec2) -> Result<Vec4> {
    if TRAJECTORY_KINDS[..3].contains(&kind) {
        return TrackScenario::parse(kind).map(TrackScenario::mean_state);
    }
    if kind != "custom" {
        return Err(Error::UnknownTrajectory {
            field: "trajectory".into(),
            name: kind.into(),
            known: "I, II, III, custom",
        });
    }
    check_finite("x0", start.x)?;
    check_finite("y0", start.y)?;
    check_finite("vx", velocity.x)?;
    check_finite("vy", velocity.y)?;
    Ok(Vec4::new(start.x, start.y, velocity.x, velocity.y))
}

/// The constant velocity that carries `start` to `end` in `duration_s` (a trajectory drawn as
/// a drag from its start to where it should be at the end), m/s.
pub fn velocity_through(start: Vec2, end: Vec2, duration_s: Real) -> Result<Vec2> {
    for (field, v) in [
        ("x0", start.x),
        ("y0", start.y),
        ("x1", end.x),
        ("y1", end.y),
    ] {
        check_finite(field, v)?;
    }
    check_positive("duration_s", duration_s)?;
    Ok((end - start) / duration_s)
}

/// The `k`-σ ellipse of the position block of a state covariance, centred at the state's
/// position; `None` if that block is not a covariance.
pub fn position_ellipse(state: &Vec4, covariance: &Mat4, k: Real) -> Option<Ellipse> {
    let block: Mat2 = covariance.fixed_view::<2, 2>(0, 0).into();
    Ellipse::from_covariance(Vec2::new(state[0], state[1]), &block, k)
}

/// The EKF's estimate at one step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrackEstimate {
    /// Estimated position, m.
    pub position: Vec2,
    /// Estimated velocity, m/s.
    pub velocity: Vec2,
    /// 1σ ellipse of the position covariance (true scale).
    pub ellipse: Option<Ellipse>,
    /// `√(P_xx + P_yy)`, the filter's own position RMS, m.
    pub sigma_m: Real,
    /// Distance from the truth, m.
    pub error_m: Real,
    /// Normalised innovation squared of the step's update (0 at `t₀`).
    pub nis: Real,
}

/// One step of a track as drawn: snapshot-shaped, with the EKF estimate in place of the fix.
#[derive(Debug, Clone, PartialEq)]
pub struct TrackFrame {
    /// Step index `n`.
    pub step: usize,
    /// `t_n`, s.
    pub t_s: Real,
    /// True position, m.
    pub truth: Vec2,
    /// True velocity, m/s.
    pub truth_velocity: Vec2,
    /// The estimate.
    pub estimate: TrackEstimate,
    /// The step's measurement per link (iso-delay ellipse, outline, arc); empty at `t₀`.
    pub links: Vec<LinkSim>,
    /// The snapshot CRLB at the truth (§7), for scale.
    pub crlb: CrlbPoint,
    /// A radius around the truth holding the estimate's and the CRLB's ellipses, m.
    pub view_radius_m: Real,
}

/// The estimate of `run` at step `n` (which must exist: `n < run.estimates.len()`).
pub fn track_estimate(run: &TrackRun, n: usize) -> Result<TrackEstimate> {
    let n = checked_index("steps", n, run.estimates.len())?;
    let (x, p, truth) = (&run.estimates[n], &run.covariances[n], &run.truth[n]);
    Ok(TrackEstimate {
        position: Vec2::new(x[0], x[1]),
        velocity: Vec2::new(x[2], x[3]),
        ellipse: position_ellipse(x, p, 1.0),
        sigma_m: sqrt(p[(0, 0)] + p[(1, 1)]),
        error_m: (Vec2::new(x[0] - truth[0], x[1] - truth[1])).norm(),
        nis: run.nis[n],
    })
}

/// The frame of step `n` of `run`, simulated on `model`.
pub fn track_frame(model: &Model, run: &TrackRun, n: usize) -> Result<TrackFrame> {
    let estimate = track_estimate(run, n)?;
    let x = &run.truth[n];
    let truth = Vec2::new(x[0], x[1]);
    let crlb = crlb_at(model, truth);
    let reach = estimate.error_m + estimate.ellipse.map_or(0.0, |e| e.semi_major);
    let view_radius_m = view_radius(&crlb, reach);
    let (delays, sigmas) = (&run.delays_s[n], &run.sigmas_s[n]);
    let links = (0..delays.len().min(sigmas.len()).min(model.link_count()))
        .map(|p| link_sim(model, p, delays[p], sigmas[p], truth, view_radius_m))
        .collect();
    Ok(TrackFrame {
        step: n,
        t_s: run.t_s[n],
        truth,
        truth_velocity: Vec2::new(x[2], x[3]),
        estimate,
        links,
        crlb,
        view_radius_m,
    })
}

#[cfg(test)]
mod tests;
