use super::*;
use crate::present::{ARC_POINTS, OUTLINE_POINTS, VIEW_MARGIN};
use crate::scenario::presets::sensors2019;
use crate::track::simulate_track;
use crate::track::ConstantVelocity;
use crate::track::{paper_initial_covariance, PAPER_INTENSITY};

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
    let run = simulate_track(&model, &motion, &mean, &p0, 100, 3, Default::default()).unwrap();
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
