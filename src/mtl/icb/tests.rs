use super::*;

fn map9() -> TrpMap {
    TrpMap::new(3, 3).unwrap()
}

fn r4(x: Real) -> Real {
    (x * 1e4).round() / 1e4
}

#[test]
fn check_four_table_two_icb_row() {
    let icb = IcbModel::from_p_u(map9(), 0.5329).unwrap();
    let want = [0.1961, 0.2578, 0.2259, 0.1320, 0.0496, 0.0109, 0.0011];
    for (k, w) in (3..=9).zip(want) {
        assert_eq!(r4(icb.dp_count_pmf(k)), w, "k = {k}");
    }
    let low: Real = (0..=2).map(|k| icb.dp_count_pmf(k)).sum();
    assert_eq!(r4(low), 0.1267);
    let all: Real = (0..=9).map(|k| icb.dp_count_pmf(k)).sum();
    assert!((all - 1.0).abs() < 1e-12);
    assert_eq!(icb.dp_count_pmf(10), 0.0);
    // The pmf is the vector probability times the number of vectors of that weight.
    let v = PartialVector::full(&map9(), 0b111).unwrap();
    assert!((84.0 * icb.vector_probability(&v) - icb.dp_count_pmf(3)).abs() < 1e-15);
}

#[test]
fn check_five_thresholds() {
    let icb = IcbModel::from_p_u(map9(), 0.271).unwrap();
    let t: alloc::vec::Vec<Real> = [2, 4, 6]
        .iter()
        .map(|&n| r4(icb.threshold(n).unwrap()))
        .collect();
    assert_eq!(t, [4.8238, 6.8030, 8.7821]);
    let icb = IcbModel::from_p_u(map9(), 0.5329).unwrap();
    assert_eq!(r4(icb.threshold(0).unwrap()), 6.8509);
    assert_eq!(r4(icb.threshold(6).unwrap()), 6.0602);
    for n in 0..9 {
        assert!(icb.threshold(n + 1).unwrap() < icb.threshold(n).unwrap());
    }
    assert!(matches!(
        icb.threshold(10),
        Err(Error::SizeLimit { field: "n_u", .. })
    ));
}

#[test]
fn threshold_accepts_size_rule_when_p_u_below_half() {
    let map = map9();
    let icb = IcbModel::from_p_u(map, 0.271).unwrap();
    let x = Vec2::zeros();
    for n_u in 0..=9 {
        let tb = icb.threshold(n_u).unwrap();
        for ones in 0..512u64 {
            let v = PartialVector::full(&map, ones).unwrap();
            let lb = icb.blocking_likelihood(&x, &v).unwrap();
            let size_ok = v.weight() as usize >= 9 - n_u;
            // A tiny tolerance: at equality both sides are the same sum in another order.
            assert_eq!(lb <= tb + 1e-12, size_ok, "n_u {n_u} ones {ones:#b}");
        }
    }
}

#[test]
fn likelihood_matches_probability_and_edges() {
    let map = map9();
    let x = Vec2::zeros();
    let icb = IcbModel::new(map, 0.9, 0.8).unwrap();
    assert!((icb.p_u() - (1.0 - 0.9 * 0.64)).abs() < 1e-15);
    let v = PartialVector::new(&map, 0b1_0110_1101, 0b0_0100_1001).unwrap();
    let p = icb.probability(&x, &v).unwrap();
    let l = icb.blocking_likelihood(&x, &v).unwrap();
    assert!((l + ln(p)).abs() < 1e-12);
    // p_u = 0 or 1: ∞ or 0, never NaN.
    for p_u in [0.0, 1.0] {
        let icb = IcbModel::from_p_u(map, p_u).unwrap();
        for ones in [0u64, 0b1, 0x1ff] {
            let v = PartialVector::full(&map, ones).unwrap();
            let l = icb.blocking_likelihood(&x, &v).unwrap();
            assert!(!l.is_nan());
            assert_eq!(l == Real::INFINITY, icb.vector_probability(&v) == 0.0);
        }
        for n in 0..=9 {
            assert!(!icb.threshold(n).unwrap().is_nan());
        }
    }
}

#[test]
fn bad_inputs_are_named_errors() {
    for (p_d, p_los, field) in [
        (1.1, 0.5, "p_d"),
        (-0.1, 0.5, "p_d"),
        (0.9, 1.01, "p_los"),
        (0.9, Real::NAN, "p_los"),
    ] {
        match IcbModel::new(map9(), p_d, p_los) {
            Err(Error::OutOfRange { field: f, .. }) => assert_eq!(f, field),
            other => panic!("{other:?}"),
        }
    }
    assert!(IcbModel::from_p_u(map9(), 2.0).is_err());
    let icb = IcbModel::from_p_u(map9(), 0.3).unwrap();
    let big = TrpMap::new(4, 3).unwrap();
    let v = PartialVector::full(&big, 1 << 10).unwrap();
    assert!(matches!(
        icb.blocking_likelihood(&Vec2::zeros(), &v),
        Err(Error::IndexOutOfRange { field: "trps", .. })
    ));
}
