#![cfg(not(target_arch = "wasm32"))]
//! Blocking vectors and models of the multi-target method (`shared/spec/multi-target.md` §3,
//! §6.1): spec checks 1–5 and 10 through the public API, the partial-consistency property, and
//! bad inputs as named errors.

use proptest::prelude::*;
use scatterloc::math::{Real, Vec2};
use scatterloc::mtl::blocking::{
    is_consistent, BlockingModel, BlockingSpace, IndependentNodes, NodeBlockingModel,
    NodeTableCache, PartialVector, TableCached, TABLE_GRID_M,
};
use scatterloc::mtl::empirical::{EmpiricalNodeModel, EmpiricalTable};
use scatterloc::mtl::icb::IcbModel;
use scatterloc::mtl::polygon::Rect;
use scatterloc::mtl::ppp::{PppBlocking, PppNodeModel};
use scatterloc::mtl::trp::TrpMap;
use scatterloc::Error;

/// 1-based TRP list → mask.
fn mask(trps: &[usize]) -> u64 {
    trps.iter().fold(0, |m, &t| m | 1 << (t - 1))
}

fn r4(x: Real) -> Real {
    (x * 1e4).round() / 1e4
}

#[test]
fn check_1_trp_map() {
    let map = TrpMap::new(3, 3).unwrap();
    let pairs: Vec<(usize, usize)> = (0..9)
        .map(|m| {
            let (t, r) = map.pair(m).unwrap();
            (t + 1, r + 1)
        })
        .collect();
    assert_eq!(
        pairs,
        [
            (1, 1),
            (2, 1),
            (3, 1),
            (1, 2),
            (2, 2),
            (3, 2),
            (1, 3),
            (2, 3),
            (3, 3)
        ]
    );
}

#[test]
fn check_2_consistent_vectors() {
    let map = TrpMap::new(3, 3).unwrap();
    let space = BlockingSpace::new(map);
    let mut hist = [0usize; 10];
    for &g in space.consistent_full() {
        hist[g.count_ones() as usize] += 1;
    }
    assert_eq!(space.consistent_full().len(), 50);
    assert_eq!(hist, [1, 9, 18, 6, 9, 0, 6, 0, 0, 1]);
    let direct = (0..512u64)
        .filter(|&g| is_consistent(&map, &PartialVector::full(&map, g).unwrap()))
        .count();
    assert_eq!(direct, 50);
}

#[test]
fn check_3_unit_hamming_sets() {
    let map = TrpMap::new(3, 3).unwrap();
    let space = BlockingSpace::new(map);
    let neighbours = |trps: &[usize]| {
        let v = PartialVector::full(&map, mask(trps)).unwrap();
        let mut n: Vec<u64> = space.neighbours(&v).iter().map(|g| g.ones()).collect();
        n.sort_unstable();
        (space.is_consistent(&v), n)
    };
    let sorted = |mut v: Vec<u64>| {
        v.sort_unstable();
        v
    };
    assert_eq!(
        neighbours(&[1, 9]),
        (false, sorted(vec![mask(&[1]), mask(&[9])]))
    );
    assert_eq!(
        neighbours(&[1, 2, 4]),
        (
            false,
            sorted(vec![mask(&[1, 2, 4, 5]), mask(&[1, 4]), mask(&[1, 2])])
        )
    );
    assert!(neighbours(&[1, 2, 4, 5]).0);
}

#[test]
fn check_4_and_5_icb() {
    let map = TrpMap::new(3, 3).unwrap();
    let icb = IcbModel::from_p_u(map, 0.5329).unwrap();
    let pmf: Vec<Real> = (3..=9).map(|k| r4(icb.dp_count_pmf(k))).collect();
    assert_eq!(
        pmf,
        [0.1961, 0.2578, 0.2259, 0.1320, 0.0496, 0.0109, 0.0011]
    );
    assert_eq!(r4((0..=2).map(|k| icb.dp_count_pmf(k)).sum()), 0.1267);
    assert_eq!(r4(icb.threshold(0).unwrap()), 6.8509);
    assert_eq!(r4(icb.threshold(6).unwrap()), 6.0602);
    let icb = IcbModel::from_p_u(map, 0.271).unwrap();
    let tb: Vec<Real> = [2, 4, 6]
        .iter()
        .map(|&n| r4(icb.threshold(n).unwrap()))
        .collect();
    assert_eq!(tb, [4.8238, 6.8030, 8.7821]);
}

/// `TableCached`: bitwise the wrapped model at exact locations; on the 1 µm grid, the wrapped
/// model at the nearest grid point (whatever the query order), within 2e-6 nats of the exact
/// `L_b` (V-B PPP: λ = 0.03 m⁻², D = 0.6 m; 1.0e-6 measured, see `TABLE_GRID_M`).
#[test]
fn table_cache_exact_and_on_grid() {
    let map = TrpMap::new(3, 3).unwrap();
    let region = Rect::new(Vec2::new(0.0, 0.0), Vec2::new(10.0, 10.0)).unwrap();
    let ppp = PppBlocking::new(0.03, 0.6, Some(region), false).unwrap();
    let tx = vec![
        Vec2::new(1.0, 1.0),
        Vec2::new(9.0, 2.0),
        Vec2::new(2.0, 8.0),
    ];
    let rx = vec![
        Vec2::new(8.0, 8.5),
        Vec2::new(5.0, 0.5),
        Vec2::new(0.5, 5.0),
    ];
    let nodes = PppNodeModel::new(ppp, tx, rx).unwrap();
    let model = NodeBlockingModel::new(map, nodes, 0.9).unwrap();
    let mut seed = 7u64;
    let mut rnd = || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 11) as Real / (1u64 << 53) as Real
    };
    let queries: Vec<(Vec2, PartialVector)> = (0..300)
        .map(|_| {
            let x = Vec2::new(0.2 + 9.6 * rnd(), 0.2 + 9.6 * rnd());
            let set = (rnd() * 512.0) as u64 | 1;
            let ones = (rnd() * 512.0) as u64 & set;
            (x, PartialVector::new(&map, set, ones).unwrap())
        })
        .collect();
    let (exact_tables, grid_tables, reverse_tables) = (
        NodeTableCache::default(),
        NodeTableCache::default(),
        NodeTableCache::default(),
    );
    let exact = TableCached::new(&model, &exact_tables);
    let grid = TableCached::on_grid(&model, &grid_tables, TABLE_GRID_M);
    let reverse = TableCached::on_grid(&model, &reverse_tables, TABLE_GRID_M);
    let mut largest = 0.0 as Real;
    for (x, v) in &queries {
        let want = model.blocking_likelihood(x, v).unwrap();
        assert_eq!(
            exact.blocking_likelihood(x, v).unwrap().to_bits(),
            want.to_bits()
        );
        let snapped = Vec2::new(
            (x.x / TABLE_GRID_M).round() * TABLE_GRID_M,
            (x.y / TABLE_GRID_M).round() * TABLE_GRID_M,
        );
        let on_grid = grid.blocking_likelihood(x, v).unwrap();
        let at_snapped = model.blocking_likelihood(&snapped, v).unwrap();
        assert_eq!(on_grid.to_bits(), at_snapped.to_bits());
        if want.is_finite() {
            largest = largest.max((on_grid - want).abs());
        } else {
            assert_eq!(on_grid, want);
        }
        // Another point of the same cell gives the same value.
        let near = snapped + Vec2::new(0.3 * TABLE_GRID_M, -0.3 * TABLE_GRID_M);
        assert_eq!(
            grid.blocking_likelihood(&near, v).unwrap().to_bits(),
            on_grid.to_bits()
        );
    }
    assert!(largest <= 2e-6, "{largest}");
    for (x, v) in queries.iter().rev() {
        assert_eq!(
            reverse.blocking_likelihood(x, v).unwrap().to_bits(),
            grid.blocking_likelihood(x, v).unwrap().to_bits()
        );
    }
    // A step that is not positive and finite means exact locations.
    for step in [0.0, -1.0, Real::NAN] {
        let tables = NodeTableCache::default();
        let m = TableCached::on_grid(&model, &tables, step);
        let (x, v) = &queries[0];
        assert_eq!(
            m.blocking_likelihood(x, v).unwrap().to_bits(),
            model.blocking_likelihood(x, v).unwrap().to_bits()
        );
    }
}

#[test]
fn bad_inputs_are_named_errors() {
    assert!(matches!(
        TrpMap::new(9, 8),
        Err(Error::SizeLimit { field: "trps", .. })
    ));
    assert!(matches!(
        TrpMap::new(0, 2),
        Err(Error::EmptyNodeList {
            field: "transmitters"
        })
    ));
    assert!(matches!(
        TrpMap::new(2, 0),
        Err(Error::EmptyNodeList { field: "receivers" })
    ));
    let map = TrpMap::new(3, 3).unwrap();
    for (p_d, p_los) in [(1.5, 0.5), (0.5, -0.5), (Real::NAN, 0.5)] {
        let e = IcbModel::new(map, p_d, p_los).unwrap_err();
        let text = e.to_string();
        assert!(
            text.starts_with("p_d") || text.starts_with("p_los"),
            "{text}"
        );
    }
    let node = IndependentNodes::new(&map, vec![0.5; 3], vec![0.5; 3]).unwrap();
    let e = NodeBlockingModel::new(map, node, 1.01).unwrap_err();
    assert!(e.to_string().starts_with("p_d:"), "{e}");
    let e = PartialVector::new(&map, mask(&[10]), 0).unwrap_err();
    assert!(e.to_string().starts_with("trps[9]"), "{e}");
}

/// A random network (≤ 4×4), its TRP count, and random node LoS probabilities.
fn network() -> impl Strategy<Value = (usize, usize, Vec<Real>, Vec<Real>)> {
    (1usize..=4, 1usize..=4).prop_flat_map(|(nt, nr)| {
        (
            Just(nt),
            Just(nr),
            proptest::collection::vec(0.0..=1.0f64, nt),
            proptest::collection::vec(0.0..=1.0f64, nr),
        )
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    /// A partial vector is consistent iff some consistent full vector agrees with it on S.
    #[test]
    fn partial_consistency_is_agreement_with_a_full_vector(
        (nt, nr) in (1usize..=4, 1usize..=4),
        set in any::<u64>(),
        ones in any::<u64>(),
    ) {
        let map = TrpMap::new(nt, nr).unwrap();
        let space = BlockingSpace::new(map);
        let set = set & map.all_trps();
        let v = PartialVector::new(&map, set, ones & set).unwrap();
        prop_assert_eq!(space.is_consistent(&v), space.is_consistent_by_enumeration(&v));
        // Every neighbour is consistent, on the same S, within Hamming distance 1.
        for g in space.neighbours(&v) {
            prop_assert!(space.is_consistent(&g));
            prop_assert_eq!(g.set(), v.set());
            prop_assert!((g.ones() ^ v.ones()).count_ones() <= 1);
        }
    }

    /// Check 10: extending S by one TRP (a DP or ĝ_m = 0) never decreases L_b — independent
    /// nodes with (M4)–(M5), an empirical table with random counts (§6.3), and i.c.b.
    #[test]
    fn extending_never_decreases_lb(
        (nt, nr, p_tx, p_rx) in network(),
        p_d in 0.0..=1.0f64,
        p_u in 0.0..=1.0f64,
        set in any::<u64>(),
        ones in any::<u64>(),
        m in 0usize..16,
        dp in any::<bool>(),
        counts in proptest::collection::vec(0u32..50, 256),
    ) {
        let map = TrpMap::new(nt, nr).unwrap();
        let m = m % map.n_trps();
        let set = set & map.all_trps() & !(1 << m);
        let v = PartialVector::new(&map, set, ones & set).unwrap();
        let w = v.with(m, dp);
        let x = Vec2::new(1.0, 2.0);
        let node = IndependentNodes::new(&map, p_tx, p_rx).unwrap();
        let bayes = NodeBlockingModel::new(map, node, p_d).unwrap();
        let icb = IcbModel::from_p_u(map, p_u).unwrap();
        let region = Rect::new(Vec2::new(0.0, 0.0), Vec2::new(4.0, 4.0)).unwrap();
        let mut table = EmpiricalTable::new(&region, 1, 1, nt, nr).unwrap();
        table.counts[0].copy_from_slice(&counts[..1 << (nt + nr)]);
        let empirical = EmpiricalNodeModel::new(table).unwrap();
        let empirical = NodeBlockingModel::new(map, empirical, p_d).unwrap();
        let models: [&dyn BlockingModel; 3] = [&bayes, &empirical, &icb];
        for model in models {
            let before = model.blocking_likelihood(&x, &v).unwrap();
            let after = model.blocking_likelihood(&x, &w).unwrap();
            prop_assert!(!before.is_nan() && !after.is_nan());
            prop_assert!(after >= before - 1e-12, "before {} after {}", before, after);
        }
        // (M5) stays a probability.
        let p = bayes.probability(&x, &v).unwrap();
        prop_assert!((0.0..=1.0 + 1e-12).contains(&p));
    }
}
