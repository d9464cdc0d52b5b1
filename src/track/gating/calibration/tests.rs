use super::*;
use crate::math::sqrt;
use alloc::vec;

const B: Real = 120e6;

#[test]
fn clusters_split_at_the_gap_and_drop_sparse_ones() {
    let cfg = ClusterConfig::for_bandwidth(B).unwrap();
    // Four snapshots: a path at 40 ns (every snapshot), one at 60 ns (every snapshot), a
    // spurious 80 ns once (25 % < 50 %: dropped).
    let s = vec![
        vec![40.0e-9, 60.0e-9],
        vec![40.2e-9, 60.2e-9, 80.0e-9],
        vec![39.8e-9, 59.8e-9],
        vec![40.0e-9, 60.0e-9],
    ];
    let c = LinkCalibration::from_snapshots(0, &s, &cfg).unwrap();
    assert_eq!(c.clusters.len(), 2);
    assert!((c.clusters[0].mean_s - 40.0e-9).abs() < 1e-15);
    assert!((c.clusters[1].mean_s - 60.0e-9).abs() < 1e-15);
    assert_eq!((c.clusters[0].count, c.clusters[1].count), (4, 4));
    assert_eq!(c.clusters[0].snapshots, 4);
    // Sample std of {39.8, 40, 40, 40.2} ns = √(0.08/3) ns (above the floor 0.01/B = 0.083 ns).
    assert!((c.clusters[0].sigma_s - sqrt(0.08 / 3.0) * 1e-9).abs() < 1e-18);
    assert!(c.is_static(40.2e-9) && !c.is_static(41.0e-9) && !c.is_static(80.0e-9));
}

#[test]
fn identical_delays_get_the_sigma_floor() {
    let cfg = ClusterConfig::for_bandwidth(B).unwrap();
    let c = LinkCalibration::from_snapshots(0, &[vec![50e-9], vec![50e-9]], &cfg).unwrap();
    assert_eq!(c.clusters[0].sigma_s, 0.01 / B);
    assert!(c.is_static(50e-9 + 2.9 * 0.01 / B));
    assert!(!c.is_static(50e-9 + 3.1 * 0.01 / B));
}

#[test]
fn delays_closer_than_the_gap_chain_into_one_cluster() {
    // 5 ns steps < g = 8.33 ns chain; a 9 ns step splits.
    let cfg = ClusterConfig::for_bandwidth(B).unwrap();
    let s = vec![vec![10e-9, 15e-9, 20e-9, 29e-9]];
    let c = LinkCalibration::from_snapshots(0, &s, &cfg).unwrap();
    let counts: Vec<usize> = c.clusters.iter().map(|c| c.count).collect();
    assert_eq!(counts, vec![3, 1]);
}

#[test]
fn bad_calibrations_are_named_errors() {
    let cfg = ClusterConfig::for_bandwidth(B).unwrap();
    let e = LinkCalibration::from_snapshots(2, &[], &cfg).unwrap_err();
    assert!(matches!(e, Error::SizeLimit { value: 0, .. }), "{e}");
    let e = LinkCalibration::from_snapshots(2, &[vec![1e-8], vec![Real::NAN]], &cfg).unwrap_err();
    assert_eq!(e.to_string(), "calibration[1][2][0]: not a finite number");
    let bad = ClusterConfig {
        min_fraction: 1.5,
        ..cfg
    };
    assert!(LinkCalibration::from_snapshots(0, &[vec![]], &bad).is_err());
    assert!(ClusterConfig::for_bandwidth(0.0).is_err());
    let e = LinkCalibration::from_clusters(
        1,
        vec![StaticCluster {
            mean_s: 1e-8,
            sigma_s: 0.0,
            count: 1,
            snapshots: 1,
            amplitude_db_mean: None,
            amplitude_db_sigma: None,
        }],
    )
    .unwrap_err();
    assert!(
        e.to_string()
            .starts_with("calibration.links[1].clusters[0].sigma_s"),
        "{e}"
    );
    let cal = Calibration::default();
    assert!(matches!(
        cal.check_links(4),
        Err(Error::LengthMismatch {
            expected: 4,
            found: 0,
            ..
        })
    ));
}

#[test]
fn the_fifty_percent_rule_counts_snapshots_not_delays() {
    // One snapshot of four with three estimates near 70 ns: 4 delays but 1 snapshot of 4.
    let cfg = ClusterConfig::for_bandwidth(B).unwrap();
    let s = vec![
        vec![40e-9, 70e-9, 70.5e-9, 71e-9],
        vec![40e-9],
        vec![40e-9],
        vec![40e-9],
    ];
    let c = LinkCalibration::from_snapshots(0, &s, &cfg).unwrap();
    assert_eq!(c.clusters.len(), 1);
    assert_eq!((c.clusters[0].count, c.clusters[0].snapshots), (4, 4));
}

#[test]
fn an_empty_snapshot_list_gates_nothing() {
    let cfg = ClusterConfig::for_bandwidth(B).unwrap();
    let c = LinkCalibration::from_snapshots(0, &[vec![], vec![]], &cfg).unwrap();
    assert!(c.clusters.is_empty() && !c.is_static(1e-8));
}
