use super::*;

fn v(x: Real, y: Real) -> Vec2 {
    Vec2::new(x, y)
}

fn example() -> (PppBlocking, Vec<Vec2>, Vec<Vec2>) {
    let region = Rect::new(v(0.0, 0.0), v(10.0, 10.0)).unwrap();
    let m = PppBlocking::new(0.03, 0.6, Some(region), true).unwrap();
    let tx = alloc::vec![v(1.0, 1.0), v(9.0, 2.0), v(2.0, 8.0)];
    let rx = alloc::vec![v(8.0, 8.5), v(5.0, 0.5), v(0.5, 5.0)];
    (m, tx, rx)
}

#[test]
fn check8() {
    assert!((p_los(0.03, 5.0, 0.6) - 0.91393).abs() < 5e-6);
}

#[test]
fn check9_example() {
    let (m, tx, rx) = example();
    let areas = m.node_areas(v(5.0, 5.0), &tx, &rx).unwrap();
    let want = [3.3941, 3.0000, 2.5456, 2.7659, 2.7000, 2.7000];
    for (n, w) in want.iter().enumerate() {
        assert!((areas.area(n) - w).abs() < 5e-5, "A_{n}: {}", areas.area(n));
    }
    assert!((areas.union_area(63) - 16.0805).abs() < 5e-5);
    let p = |a, b, exact| areas.probability(0.03, exact, a, b);
    assert!((p(0b111, 0b111, true) - 0.617291).abs() < 5e-7);
    assert!((p(0b110, 0b111, true) - 0.059138).abs() < 5e-7);
    assert!((p(0b100, 0b111, true) - 0.005100).abs() < 5e-7);
    for (a, b) in [(0b111, 0b111), (0b110, 0b111), (0b100, 0b111)] {
        assert!((p(a, b, false) - p(a, b, true)).abs() < 1e-15);
    }
    let total: Real = (0..64u64).map(|k| p(k & 7, k >> 3, true)).sum();
    assert!((total - 1.0).abs() < 1e-12, "{total}");
    for k in 0..64u64 {
        assert!(p(k & 7, k >> 3, false) <= p(k & 7, k >> 3, true) + 1e-15);
    }
    assert_eq!(
        m.node_pattern_probability(v(5.0, 5.0), &tx, &rx, 0b110, 0b111)
            .unwrap(),
        p(0b110, 0b111, true)
    );
    let nm = PppNodeModel::new(m, tx, rx).unwrap();
    let all = nm.pattern_probabilities(v(5.0, 5.0)).unwrap();
    assert_eq!(all.len(), 64);
    // The all-pattern transform equals the per-pattern formula up to rounding, for (M11)
    // and (M10), on every pattern.
    for k in 0..64u64 {
        assert!((all[k as usize] - p(k & 7, k >> 3, true)).abs() < 1e-15);
    }
    let bound = PppNodeModel::new(
        PppBlocking { exact: false, ..m },
        nm.tx.clone(),
        nm.rx.clone(),
    )
    .unwrap()
    .pattern_probabilities(v(5.0, 5.0))
    .unwrap();
    for k in 0..64u64 {
        assert!((bound[k as usize] - p(k & 7, k >> 3, false)).abs() < 1e-15);
    }
    assert_eq!(
        nm.node_pattern_probability(&v(5.0, 5.0), 0b110, 0b111),
        p(0b110, 0b111, true)
    );
    assert_eq!(nm.node_pattern_probability(&v(Real::NAN, 5.0), 0, 0), 0.0);
}

#[test]
fn bad_inputs() {
    assert!(matches!(
        PppBlocking::new(-0.1, 0.6, None, true),
        Err(Error::OutOfRange { .. })
    ));
    assert!(matches!(
        PppBlocking::new(Real::NAN, 0.6, None, true),
        Err(Error::NonFinite { .. })
    ));
    assert!(matches!(
        PppBlocking::new(0.03, 0.0, None, true),
        Err(Error::NotPositive { .. })
    ));
    let m = PppBlocking::new(0.03, 0.6, None, true).unwrap();
    let e = m
        .node_pattern_probability(v(0.0, 0.0), &[v(1.0, Real::NAN)], &[v(2.0, 2.0)], 1, 1)
        .unwrap_err();
    assert_eq!(
        e,
        Error::NonFinite {
            field: "tx[0]".into()
        }
    );
    assert!(m
        .node_pattern_probability(v(Real::INFINITY, 0.0), &[], &[], 0, 0)
        .is_err());
}
