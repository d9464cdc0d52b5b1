//! Unit tests of the §7 simulation module.

use alloc::vec;
use alloc::vec::Vec;

use super::scene::{is_free, segment_distance_sq, segment_is_los};
use super::*;
use crate::math::Vec2;
use crate::mtl::icb::IcbModel;

#[test]
fn presets_hold_the_section_7_table() {
    let b = SimSettings::vb();
    assert!((b.lambda - 0.03).abs() < 1e-15);
    assert_eq!((b.diameter, b.range_sigma, b.resolution), (0.6, 0.1, 0.3));
    assert_eq!((b.detection_radius, b.p_d, b.targets), (0.5, 0.9, 2));
    assert_eq!(b.clutter_mean, 2.0);
    assert!((b.r_max - 28.2843).abs() < 1e-4);
    assert_eq!(b.nodes, NodeLayout::Uniform { n_tx: 3, n_rx: 3 });
    assert_eq!(b.los, LosModel::Discs);
    assert_eq!(b.geometric_ips, GeometricIps::default());
    let a = SimSettings::va();
    assert_eq!(a.diameter, 0.2);
    let LosModel::Independent { p_los } = a.los else {
        panic!("V-A uses independent blocking")
    };
    // p_u = 1 − p_d p_LoS² = 0.271 (§7 table).
    let p_u = IcbModel::new(a.map().unwrap(), a.p_d, p_los).unwrap().p_u();
    assert!((p_u - 0.271).abs() < 1e-12);
    assert!(a.validate().is_ok() && b.validate().is_ok());
}

#[test]
fn resolution_merge_keeps_the_earliest() {
    let peaks = vec![
        (5.0, 'c'),
        (1.0, 'a'),
        (1.2, 'b'),
        (1.45, 'd'),
        (1.61, 'e'),
        (9.0, 'f'),
    ];
    let kept = resolution_merge(peaks, 0.3);
    // 1.2 is within 0.3 of the kept 1.0 (dropped); 1.45 is 0.45 past it (kept); 1.61 is within
    // 0.3 of the kept 1.45 (dropped): distances count from the last *kept* peak.
    assert_eq!(kept, vec![(1.0, 'a'), (1.45, 'd'), (5.0, 'c'), (9.0, 'f')]);
    let chained = resolution_merge(vec![(0.0, 0), (0.25, 1), (0.5, 2), (0.75, 3)], 0.3);
    assert_eq!(chained, vec![(0.0, 0), (0.5, 2)]);
    assert!(resolution_merge(Vec::<(f64, ())>::new(), 0.3).is_empty());
}

#[test]
fn segment_geometry() {
    let (a, b) = (Vec2::new(0.0, 0.0), Vec2::new(10.0, 0.0));
    assert!((segment_distance_sq(&a, &b, &Vec2::new(5.0, 2.0)) - 4.0).abs() < 1e-12);
    assert!((segment_distance_sq(&a, &b, &Vec2::new(-3.0, 4.0)) - 25.0).abs() < 1e-12);
    assert!((segment_distance_sq(&a, &a, &Vec2::new(3.0, 4.0)) - 25.0).abs() < 1e-12);
    let discs = [Vec2::new(5.0, 0.29), Vec2::new(20.0, 0.0)];
    assert!(!segment_is_los(&a, &b, &discs, 0.6, None));
    assert!(segment_is_los(&a, &b, &discs, 0.6, Some(0)));
    assert!(segment_is_los(&a, &b, &discs, 0.5, None));
    assert!(!is_free(&Vec2::new(5.0, 0.0), &discs, 0.6));
    assert!(is_free(&Vec2::new(5.0, 1.0), &discs, 0.6));
}

#[test]
fn metrics_on_a_hand_made_case() {
    let t = [Vec2::new(0.0, 0.0), Vec2::new(5.0, 5.0)];
    // One estimate near target 0, one 0.5 m from target 1 (counts as within), one far off.
    let e = [
        Vec2::new(0.3, 0.0),
        Vec2::new(5.0, 5.5),
        Vec2::new(9.0, 9.0),
    ];
    let c = count_detections(&t, &e, 0.5);
    assert_eq!(
        (c.detected, c.false_alarms, c.estimates, c.targets),
        (2, 1, 3, 2)
    );
    let mut m = Metrics::new();
    assert_eq!((m.p_d(), m.p_fa()), (0.0, 0.0));
    m.add(&t, &e, 0.5).unwrap();
    // Second realisation: no estimate at all → N_D = 0, N_FA/max(K̂, 1) = 0.
    m.add(&t, &[], 0.5).unwrap();
    assert_eq!(m.realisations(), 2);
    assert!((m.p_d() - 0.5).abs() < 1e-15); // (2/2 + 0/2) / 2
    assert!((m.p_fa() - 1.0 / 6.0).abs() < 1e-15); // (1/3 + 0) / 2
    let mut n = Metrics::new();
    n.add(&t[..1], &[Vec2::new(3.0, 0.0)], 0.5).unwrap(); // N_D 0/1, N_FA 1/1
    m.merge(&n);
    assert!((m.p_d() - 1.0 / 3.0).abs() < 1e-15);
    assert!((m.p_fa() - (1.0 / 3.0 + 1.0) / 3.0).abs() < 1e-15);
    assert!(m.add(&[], &e, 0.5).is_err());
}

#[test]
fn table2_buckets_fold_low_counts() {
    let pmf = [0.1, 0.2, 0.3, 0.05, 0.05, 0.0, 0.1, 0.0, 0.0, 0.2];
    let b = table2_buckets(&pmf);
    assert_eq!(b.len(), 8);
    assert!((b[0] - 0.6).abs() < 1e-15);
    assert_eq!(&b[1..], &pmf[3..]);
}

#[test]
fn scene_is_the_generators_scene() {
    let s = SimSettings::vb();
    for i in 0..20 {
        let r = generate(&s, 9, i).unwrap();
        assert_eq!(draw_scene(&s, 9, i).unwrap(), r.scene);
        for (b, t) in r.scene.blocking.iter().zip(&r.truth) {
            // Surviving DPs lie where γ says LoS.
            assert_eq!(t.detected & !b.gamma, 0);
        }
    }
}
