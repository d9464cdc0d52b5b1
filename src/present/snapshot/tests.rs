use super::*;
use crate::error::Error;
use crate::scenario::presets::sensors2019;

fn l4() -> (Model, Area) {
    let s = sensors2019();
    (Model::new(&s).unwrap(), s.area_m)
}

#[test]
fn deterministic_for_a_seed() {
    let (model, area) = l4();
    let t = Vec2::new(6.0, 4.0);
    let a = simulate_snapshot(&model, &area, t, 7);
    assert_eq!(a, simulate_snapshot(&model, &area, t, 7));
    assert_ne!(a.links, simulate_snapshot(&model, &area, t, 8).links);
    assert_eq!(a.links.len(), 4);
    assert!(a.links.iter().all(|l| l.outline.len() == OUTLINE_POINTS));
    assert!(a.links.iter().all(|l| l.arc.len() == ARC_POINTS));
}

/// Spec §0 check 7 at L4 (4, 1): CRLB RMSE 0.426 cm; the fix lands within a few σ.
#[test]
fn fix_lands_within_a_few_sigma_at_l4() {
    let (model, area) = l4();
    let t = Vec2::new(4.0, 1.0);
    for seed in 0..20 {
        let s = simulate_snapshot(&model, &area, t, seed);
        let rmse = s.crlb.bound.unwrap().rmse_m;
        assert!((rmse / 0.00426 - 1.0).abs() < 1e-3, "CRLB {rmse} m");
        let fix = s.fix.as_ref().unwrap();
        assert!(fix.report.termination.converged());
        assert!(fix.error_m < 5.0 * rmse, "seed {seed}: {} m", fix.error_m);
        assert!(fix.ellipse.unwrap().semi_major > 0.0);
        let reach = fix.error_m + fix.ellipse.unwrap().semi_major;
        let crlb_a = s.crlb.ellipse().unwrap().semi_major;
        assert_eq!(s.view_radius_m, VIEW_MARGIN * reach.max(crlb_a));
        for (p, l) in s.links.iter().enumerate() {
            assert_eq!(l.link, model.network.links[p]);
            assert_eq!(l.sigma_s, model.sigma_delay(p, t));
            assert_eq!(l.range_sigma_m, SPEED_OF_LIGHT * l.sigma_s);
        }
    }
}

/// On a link's baseline the true delay is the LoS delay, so noise puts the measurement on
/// either side: an ellipse exists exactly when the delay reaches the LoS delay.
#[test]
fn ellipses_exist_iff_delay_reaches_line_of_sight() {
    let (model, area) = l4();
    let (tx, rx) = model.network.link_nodes(0);
    let on_baseline = (tx + rx) / 2.0;
    let (mut with, mut without) = (0, 0);
    for seed in 0..40 {
        let s = simulate_snapshot(&model, &area, on_baseline, seed);
        for (p, l) in s.links.iter().enumerate() {
            let exists = l.delay_s >= model.network.los_delay(p);
            assert_eq!(l.ellipse.is_some(), exists, "seed {seed} link {p}");
            assert_eq!(l.outline.is_empty(), !exists);
            if !exists {
                assert!(l.arc.is_empty());
            }
        }
        if s.links[0].ellipse.is_some() {
            with += 1;
        } else {
            without += 1;
        }
    }
    assert!(with > 0 && without > 0, "{with} / {without}");
}

#[test]
fn too_few_links_is_a_named_error_not_a_panic() {
    let mut s = sensors2019();
    s.receivers.truncate(1);
    let model = Model::new(&s).unwrap();
    let snap = simulate_snapshot(&model, &s.area_m, Vec2::new(3.0, 4.0), 1);
    assert!(matches!(snap.fix, Err(Error::TooFewLinks { .. })));
    assert!(snap.crlb.bound.is_none());
    assert_eq!(snap.view_radius_m, VIEW_MARGIN * FALLBACK_EXTENT_M);
}
