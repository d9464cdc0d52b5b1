use super::*;

/// 1-based TRP list → mask.
fn mask(trps: &[usize]) -> u64 {
    trps.iter().fold(0, |m, &t| m | 1 << (t - 1))
}

#[test]
fn kron_matches_definition() {
    let map = TrpMap::new(3, 2).unwrap();
    for a in 0..8u64 {
        for b in 0..4u64 {
            let g = kron(&map, a, b);
            for m in 0..6 {
                let want = (a >> map.tx(m) & 1) & (b >> map.rx(m) & 1);
                assert_eq!(g >> m & 1, want);
            }
            assert_eq!(g.count_ones(), a.count_ones() * b.count_ones());
        }
    }
}

#[test]
fn check_two_consistent_count_and_weights() {
    let map = TrpMap::new(3, 3).unwrap();
    let space = BlockingSpace::new(map);
    assert_eq!(space.consistent_full().len(), 50);
    let mut hist = [0usize; 10];
    let mut n = 0;
    for ones in 0..512u64 {
        let v = PartialVector::full(&map, ones).unwrap();
        let c = is_consistent(&map, &v);
        assert_eq!(c, space.is_consistent_by_enumeration(&v));
        if c {
            n += 1;
            hist[v.weight() as usize] += 1;
        }
    }
    assert_eq!(n, 50);
    assert_eq!(hist, [1, 9, 18, 6, 9, 0, 6, 0, 0, 1]);
}

#[test]
fn check_three_unit_hamming_sets() {
    let map = TrpMap::new(3, 3).unwrap();
    let space = BlockingSpace::new(map);
    let sets = |trps: &[usize]| {
        let v = PartialVector::full(&map, mask(trps)).unwrap();
        let mut n: Vec<u64> = space.neighbours(&v).iter().map(|g| g.ones()).collect();
        n.sort_unstable();
        (space.is_consistent(&v), n)
    };
    let (c, n) = sets(&[1, 9]);
    assert!(!c);
    let mut want = alloc::vec![mask(&[1]), mask(&[9])];
    want.sort_unstable();
    assert_eq!(n, want);
    let (c, n) = sets(&[1, 2, 4]);
    assert!(!c);
    let mut want = alloc::vec![mask(&[1, 2, 4, 5]), mask(&[1, 4]), mask(&[1, 2])];
    want.sort_unstable();
    assert_eq!(n, want);
    let (c, _) = sets(&[1, 2, 4, 5]);
    assert!(c);
}

#[test]
fn marginal_sums_and_relaxation() {
    let map = TrpMap::new(3, 3).unwrap();
    let node = IndependentNodes::new(
        &map,
        alloc::vec![0.9, 0.8, 0.7],
        alloc::vec![0.6, 0.95, 0.5],
    )
    .unwrap();
    let model = NodeBlockingModel::new(map, node, 0.9).unwrap();
    let space = model.space();
    let x = Vec2::zeros();
    let table = space.node_table(model.node_model(), &x);
    let total: Real = table.probabilities().iter().sum();
    assert!((total - 1.0).abs() < 1e-12);
    // Full-vector marginals sum to 1 over the consistent vectors, 0 elsewhere.
    let mut s = 0.0;
    for ones in 0..512u64 {
        let v = PartialVector::full(&map, ones).unwrap();
        let p = space.marginal(&table, &v);
        if !space.is_consistent(&v) {
            assert_eq!(p, 0.0);
        }
        s += p;
    }
    assert!((s - 1.0).abs() < 1e-12);
    // Empty S: P = 1, L_b = 0.
    let e = PartialVector::empty();
    assert!((model.probability(&x, &e).unwrap() - 1.0).abs() < 1e-12);
    assert_eq!(model.blocking_likelihood(&x, &e).unwrap(), 0.0);
    // ĝ = (1,1) on {TRP1, TRP2}: P(γ=(1,1)) = p_tx0 p_tx1 p_rx0, no heavier neighbours.
    let v = PartialVector::new(&map, mask(&[1, 2]), mask(&[1, 2])).unwrap();
    let p = model.probability(&x, &v).unwrap();
    assert!((p - 0.81 * 0.9 * 0.8 * 0.6).abs() < 1e-12);
    // ĝ = (1,0) on {1,2}: P(1,0) + (1 − p_d) P(1,1), times p_d.
    let v = PartialVector::new(&map, mask(&[1, 2]), mask(&[1])).unwrap();
    let p10 = 0.9 * 0.2 * 0.6;
    let p11 = 0.9 * 0.8 * 0.6;
    let p = model.probability(&x, &v).unwrap();
    assert!((p - 0.9 * (p10 + 0.1 * p11)).abs() < 1e-12);
    // Inconsistent with only lighter neighbours: P = 0, L_b = ∞.
    let v = PartialVector::full(&map, mask(&[1, 9])).unwrap();
    assert_eq!(model.probability(&x, &v).unwrap(), 0.0);
    assert_eq!(model.blocking_likelihood(&x, &v).unwrap(), Real::INFINITY);
}

/// The one-pass (M5) equals its definition: the sum over the unit-Hamming neighbours
/// `g ≥ ĝ` of `p_d^{|ĝ|} (1 − p_d)^{|g|−|ĝ|}` times the marginal (M4), on every partial vector
/// of 3×3 (all `3^9` assignments of "not processed / 0 / 1" to the TRPs).
#[test]
fn relaxed_probability_equals_its_definition() {
    let map = TrpMap::new(3, 3).unwrap();
    let node = IndependentNodes::new(
        &map,
        alloc::vec![0.9, 0.3, 0.7],
        alloc::vec![0.6, 0.95, 0.2],
    )
    .unwrap();
    let model = NodeBlockingModel::new(map, node, 0.85).unwrap();
    let space = model.space();
    let table = space.node_table(model.node_model(), &Vec2::zeros());
    let p_d = model.p_d();
    for code in 0..3usize.pow(9) {
        let (mut set, mut ones, mut c) = (0u64, 0u64, code);
        for m in 0..9 {
            match c % 3 {
                1 => set |= 1 << m,
                2 => {
                    set |= 1 << m;
                    ones |= 1 << m;
                }
                _ => {}
            }
            c /= 3;
        }
        let v = PartialVector::new(&map, set, ones).unwrap();
        let want: Real = space
            .neighbours(&v)
            .iter()
            .filter(|g| g.ones() & ones == ones)
            .map(|g| {
                powu(p_d, v.weight())
                    * powu(1.0 - p_d, g.weight() - v.weight())
                    * space.marginal(&table, g)
            })
            .sum();
        let got = space.relaxed_probability(&table, &v, p_d);
        assert!(
            (got - want).abs() <= 1e-15,
            "{set:b} {ones:b}: {got} {want}"
        );
    }
}

#[test]
fn bad_inputs_are_named_errors() {
    let map = TrpMap::new(3, 3).unwrap();
    assert!(matches!(
        PartialVector::new(&map, 1 << 9, 0),
        Err(Error::IndexOutOfRange {
            field: "trps",
            index: 9,
            len: 9
        })
    ));
    assert!(matches!(
        PartialVector::new(&map, 0b11, 0b100),
        Err(Error::OutOfRange { .. })
    ));
    let node = IndependentNodes::new(&map, alloc::vec![0.5; 3], alloc::vec![0.5; 3]).unwrap();
    for p_d in [-0.1, 1.5, Real::NAN] {
        match NodeBlockingModel::new(map, node.clone(), p_d) {
            Err(Error::OutOfRange { field, .. }) => assert_eq!(field, "p_d"),
            other => panic!("{other:?}"),
        }
    }
    assert!(matches!(
        IndependentNodes::new(&map, alloc::vec![0.5; 2], alloc::vec![0.5; 3]),
        Err(Error::LengthMismatch { field: "p_tx", .. })
    ));
    match IndependentNodes::new(&map, alloc::vec![0.5; 3], alloc::vec![0.5, 2.0, 0.5]) {
        Err(Error::OutOfRange { field, .. }) => assert_eq!(field, "p_rx[1]"),
        other => panic!("{other:?}"),
    }
    // A vector of a bigger network is refused by a smaller model.
    let big = TrpMap::new(4, 3).unwrap();
    let v = PartialVector::full(&big, 0).unwrap();
    let model = NodeBlockingModel::new(map, node, 0.9).unwrap();
    assert!(model.probability(&Vec2::zeros(), &v).is_err());
}

#[test]
fn likelihood_never_nan() {
    assert_eq!(blocking_likelihood(0.0), Real::INFINITY);
    assert_eq!(blocking_likelihood(Real::NAN), Real::INFINITY);
    assert_eq!(blocking_likelihood(1.0 + 1e-16), 0.0);
    assert!((blocking_likelihood(0.5) - core::f64::consts::LN_2).abs() < 1e-15);
}
