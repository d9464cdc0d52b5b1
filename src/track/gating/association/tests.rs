use super::AssociationRule::{Gated, Spec};
use super::*;
use crate::track::gating::{LinkCalibration, StaticCluster};
use alloc::vec;

fn est(delay_ns: Real, amplitude: Real) -> DelayEstimate {
    DelayEstimate {
        delay_s: delay_ns * 1e-9,
        amplitude,
        sigma_s: None,
    }
}

fn pred(delay_ns: Real, sigma_ns: Real) -> PredictedDelay {
    PredictedDelay {
        delay_s: delay_ns * 1e-9,
        innovation_sigma_s: sigma_ns * 1e-9,
    }
}

#[test]
fn the_association_rule_of_spec_section_4() {
    let c = [est(50.0, 1.0), est(70.0, 3.0), est(90.0, 2.0)];
    assert_eq!(associate(&[], None, Spec), (None, Choice::Absent));
    // One candidate is taken even far from the prediction.
    assert_eq!(
        associate(&c[..1], Some(&pred(100.0, 1.0)), Spec),
        (Some(0), Choice::Single)
    );
    // No track: the largest amplitude.
    assert_eq!(associate(&c, None, Spec), (Some(1), Choice::Strongest));
    // Nearest within 3σ of the prediction (|89 − 90|/1 = 1).
    assert_eq!(
        associate(&c, Some(&pred(89.0, 1.0)), Spec),
        (Some(2), Choice::Nearest)
    );
    // Just inside the gate (2.99σ) passes; just beyond it (3.01σ) falls back to the amplitude.
    assert_eq!(
        associate(&c, Some(&pred(47.01, 1.0)), Spec),
        (Some(0), Choice::Nearest)
    );
    assert_eq!(
        associate(&c, Some(&pred(46.99, 1.0)), Spec),
        (Some(1), Choice::Strongest)
    );
    // Gated: a lone or nearest candidate only inside the gate; no track: as the spec's.
    assert_eq!(
        associate(&c[..1], Some(&pred(100.0, 1.0)), Gated),
        (None, Choice::Absent)
    );
    assert_eq!(
        associate(&c[..1], Some(&pred(52.0, 1.0)), Gated),
        (Some(0), Choice::Single)
    );
    assert_eq!(
        associate(&c, Some(&pred(46.99, 1.0)), Gated),
        (None, Choice::Absent)
    );
    assert_eq!(
        associate(&c, Some(&pred(89.0, 1.0)), Gated),
        (Some(2), Choice::Nearest)
    );
    assert_eq!(associate(&c, None, Gated), (Some(1), Choice::Strongest));
}

#[test]
fn select_gates_then_associates_per_link() {
    let cluster = |mean_ns: Real, sigma_ns: Real| StaticCluster {
        mean_s: mean_ns * 1e-9,
        sigma_s: sigma_ns * 1e-9,
        count: 10,
        snapshots: 10,
        amplitude_db_mean: None,
        amplitude_db_sigma: None,
    };
    let cal = Calibration {
        links: vec![
            LinkCalibration {
                clusters: vec![cluster(40.0, 0.1), cluster(60.0, 0.1)],
            },
            LinkCalibration::default(),
        ],
    };
    let raw = vec![
        vec![est(40.05, 9.0), est(55.0, 1.0), est(60.29, 9.0)],
        vec![],
    ];
    let s = select(&cal, &raw, None, Spec).unwrap();
    assert_eq!(s.delays, vec![Some(55.0e-9), None]);
    assert_eq!(s.choices, vec![Choice::Single, Choice::Absent]);
    assert_eq!(s.static_removed, vec![2, 0]);
    // Bad input is named.
    let bad = vec![vec![est(Real::NAN, 1.0)], vec![]];
    assert!(matches!(
        select(&cal, &bad, None, Spec).unwrap_err(),
        Error::InvalidDelay { link: 0, value } if value.is_nan()
    ));
    // Zero, negative and absurd delays too (issue 12, item 7).
    for d_ns in [0.0, -50.0, 2e9] {
        let e = est(d_ns, 1.0);
        let bad = vec![vec![e], vec![]];
        assert_eq!(
            select(&cal, &bad, None, Spec).unwrap_err(),
            Error::InvalidDelay {
                link: 0,
                value: e.delay_s
            }
        );
    }
    let bad = vec![vec![], vec![est(50.0, Real::INFINITY)]];
    assert_eq!(
        select(&cal, &bad, None, Spec).unwrap_err().to_string(),
        "estimates[1][0].amplitude: not a finite number"
    );
    assert!(matches!(
        select(&cal, &raw[..1], None, Spec),
        Err(Error::LengthMismatch {
            expected: 2,
            found: 1,
            ..
        })
    ));
    assert!(matches!(
        select(&cal, &raw, Some(&[pred(1.0, 1.0)]), Spec),
        Err(Error::LengthMismatch {
            field: "predictions",
            ..
        })
    ));
}
