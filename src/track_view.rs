//! What a front end shows of a simulated track ([`TrackRun`], spec §6): the prior mean of a
//! named or drawn trajectory, the EKF's 1σ position ellipse per step, and for the step on
//! screen a frame shaped like a snapshot ([`crate::snapshot`]) — the truth, the estimate with
//! its ellipse and miss, each link's measured iso-delay ellipse (outline and the arc near the
//! truth), the snapshot CRLB at the truth (§7) and a zoom radius holding them — so the page draws
//! a track step with the same code as a snapshot.

use alloc::string::ToString;
use alloc::vec::Vec;

use crate::crlb::{crlb_at, CrlbPoint};
use crate::ellipse::Ellipse;
use crate::error::{checked_index, Error, Result};
use crate::math::{sqrt, Mat2, Mat4, Real, Vec2, Vec4};
use crate::model::Model;
use crate::snapshot::{link_sim, view_radius, LinkSim};
use crate::track_sim::TrackRun;
use crate::trajectory::TrackScenario;

/// Trajectory kinds a front end offers: the three scenarios of §9.4 and a drawn one.
pub const TRAJECTORY_KINDS: [&str; 4] = ["I", "II", "III", "custom"];

/// The prior mean `x̄₀ = [r̄; v̄]` of trajectory `kind`: `I`, `II`, `III` (spec §9.4; `start` and
/// `velocity` are ignored) or `custom` (`start`, `velocity` as given; must be finite).
pub fn track_mean_state(kind: &str, start: Vec2, velocity: Vec2) -> Result<Vec4> {
    if TRAJECTORY_KINDS[..3].contains(&kind) {
        return TrackScenario::parse(kind).map(TrackScenario::mean_state);
    }
    if kind != "custom" {
        return Err(Error::OutOfRange {
            field: alloc::format!("trajectory \"{kind}\""),
            value: Real::NAN,
            allowed: "I, II, III or custom",
        });
    }
    finite("x0", start.x)?;
    finite("y0", start.y)?;
    finite("vx", velocity.x)?;
    finite("vy", velocity.y)?;
    Ok(Vec4::new(start.x, start.y, velocity.x, velocity.y))
}

fn finite(field: &str, v: Real) -> Result<Real> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(Error::NonFinite {
            field: field.to_string(),
        })
    }
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
        finite(field, v)?;
    }
    if finite("duration_s", duration_s)? <= 0.0 {
        return Err(Error::NotPositive {
            field: "duration_s".to_string(),
            value: duration_s,
        });
    }
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
mod tests {
    use super::*;
    use crate::motion::ConstantVelocity;
    use crate::presets::sensors2019;
    use crate::snapshot::{ARC_POINTS, OUTLINE_POINTS, VIEW_MARGIN};
    use crate::track_sim::simulate_track;
    use crate::trajectory::{paper_initial_covariance, PAPER_INTENSITY};

    #[test]
    fn mean_states_by_name_or_drawn() {
        let z = Vec2::zeros();
        let m = track_mean_state("II", z, z).unwrap();
        assert_eq!(m, TrackScenario::II.mean_state());
        let c = track_mean_state("custom", Vec2::new(1.0, 2.0), Vec2::new(0.5, -1.0)).unwrap();
        assert_eq!(c, Vec4::new(1.0, 2.0, 0.5, -1.0));
        let e = track_mean_state("IV", z, z).unwrap_err().to_string();
        assert!(
            e.contains("trajectory \"IV\"") && e.contains("custom"),
            "{e}"
        );
        let e = track_mean_state("custom", z, Vec2::new(Real::NAN, 0.0));
        assert_eq!(e.unwrap_err().to_string(), "vx: not a finite number");
        let v = velocity_through(Vec2::new(1.0, 1.0), Vec2::new(11.0, -4.0), 10.0).unwrap();
        assert_eq!(v, Vec2::new(1.0, -0.5));
        assert!(velocity_through(z, z, 0.0).is_err());
    }

    /// A frame has the run's numbers: truth, estimate, its covariance ellipse, one link per
    /// measurement with outline and arc, and a zoom radius holding the ellipses.
    #[test]
    fn frames_follow_the_run() {
        let model = Model::new(&sensors2019()).unwrap();
        let motion = ConstantVelocity::new(0.1, PAPER_INTENSITY);
        let mean = TrackScenario::II.mean_state();
        let p0 = paper_initial_covariance();
        let run = simulate_track(&model, &motion, &mean, &p0, 100, 3).unwrap();
        let f0 = track_frame(&model, &run, 0).unwrap();
        assert!(f0.links.is_empty());
        assert_eq!(f0.estimate.position, Vec2::new(mean[0], mean[1]));
        assert!((f0.estimate.sigma_m - 0.2_f64.sqrt()).abs() < 1e-15);
        let a0 = f0.estimate.ellipse.unwrap();
        assert!((a0.semi_major - 0.1_f64.sqrt()).abs() < 1e-12);
        let f = track_frame(&model, &run, 40).unwrap();
        assert_eq!((f.step, f.t_s), (40, run.t_s[40]));
        assert_eq!(f.truth, Vec2::new(run.truth[40][0], run.truth[40][1]));
        assert_eq!(f.links.len(), 4);
        for (p, l) in f.links.iter().enumerate() {
            assert_eq!(l.delay_s, run.delays_s[40][p]);
            assert_eq!(l.outline.len(), OUTLINE_POINTS);
            assert_eq!(l.arc.len(), ARC_POINTS);
        }
        let e = f.estimate;
        assert!(e.error_m < 0.05 && e.sigma_m < 0.05, "{e:?}");
        let reach = e.error_m + e.ellipse.unwrap().semi_major;
        assert!(f.view_radius_m >= VIEW_MARGIN * reach);
        let err = track_frame(&model, &run, 101).unwrap_err().to_string();
        assert!(err.contains("steps[101]"), "{err}");
    }
}
