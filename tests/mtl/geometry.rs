//! Multi-target geometry and the PPP blocking model (spec multi-target.md §0 checks 7–9, §5, §6.2).
#![cfg(not(target_arch = "wasm32"))]

use proptest::prelude::*;
use scatterloc::mtl::blocking::NodePatternModel;
use scatterloc::mtl::geometry::{intersect, RangeEllipse};
use scatterloc::mtl::polygon::{
    area, clip_convex, intersection_area, node_rectangle, segment_rectangle, union_area, Rect,
};
use scatterloc::mtl::ppp::{p_los, PppBlocking, PppNodeModel};
use scatterloc::{Error, Real, Vec2};

fn v(x: Real, y: Real) -> Vec2 {
    Vec2::new(x, y)
}

fn on_both(e1: &RangeEllipse, e2: &RangeEllipse, pts: &[Vec2]) {
    for p in pts {
        assert!(e1.residual(*p).abs() < 1e-9, "{p:?}: {}", e1.residual(*p));
        assert!(e2.residual(*p).abs() < 1e-9, "{p:?}: {}", e2.residual(*p));
    }
}

#[test]
fn check7_all_three_cases() {
    let e1 = RangeEllipse::new(v(-3.0, 0.0), v(3.0, 0.0), 10.0).unwrap();
    let e2 = RangeEllipse::new(v(0.0, -3.0), v(0.0, 3.0), 10.0).unwrap();
    let pts = intersect(&e1, &e2, None);
    assert_eq!(pts.len(), 4);
    on_both(&e1, &e2, &pts);
    for sx in [-1.0, 1.0] {
        for sy in [-1.0, 1.0] {
            assert!(pts
                .iter()
                .any(|p| (p.x - sx * 3.1235).abs() < 5e-5 && (p.y - sy * 3.1235).abs() < 5e-5));
        }
    }

    let e1 = RangeEllipse::new(v(0.0, 0.0), v(10.0, 0.0), 14.0).unwrap();
    let e2 = RangeEllipse::new(v(0.0, 0.0), v(0.0, 10.0), 14.0).unwrap();
    let pts = intersect(&e1, &e2, None);
    assert_eq!(pts.len(), 2);
    on_both(&e1, &e2, &pts);
    for w in [4.8985, -1.6108] {
        assert!(pts
            .iter()
            .any(|p| (p.x - w).abs() < 5e-5 && (p.y - w).abs() < 5e-5));
    }
    // Swapping the ellipses gives the same points.
    let swapped = intersect(&e2, &e1, None);
    assert_eq!(swapped.len(), 2);
    for p in swapped.iter() {
        assert!(pts.iter().any(|q| (p - q).norm() < 1e-9));
    }

    let e1 = RangeEllipse::new(v(0.0, 0.0), v(10.0, 0.0), 12.0).unwrap();
    let e2 = RangeEllipse::new(v(10.0, 10.0), v(0.0, 10.0), 12.0).unwrap();
    assert!(intersect(&e1, &e2, None).is_empty());
}

#[test]
fn empty_and_degenerate_ellipses() {
    assert!(RangeEllipse::new(v(0.0, 0.0), v(10.0, 0.0), 9.0).is_none());
    let seg = RangeEllipse::new(v(0.0, 0.0), v(10.0, 0.0), 10.0).unwrap();
    assert!(seg.is_degenerate());
    // A circle of radius 2 about (5, 0) meets the focal segment at (3, 0) and (7, 0), where the
    // segment's range gradient vanishes: cond(G) = ∞, grazing, so both are dropped.
    let circle = RangeEllipse::new(v(5.0, 0.0), v(5.0, 0.0), 4.0).unwrap();
    assert!(intersect(&circle, &seg, None).is_empty());
    assert!(intersect(&seg, &circle, None).is_empty());
}

proptest! {
    #[test]
    fn random_ellipse_pairs(
        u1 in (-10.0..10.0f64, -10.0..10.0f64), v1 in (-10.0..10.0f64, -10.0..10.0f64),
        u2 in (-10.0..10.0f64, -10.0..10.0f64), v2 in (-10.0..10.0f64, -10.0..10.0f64),
        x1 in 0.01..20.0f64, x2 in 0.01..20.0f64,
    ) {
        let (u1, v1, u2, v2) = (v(u1.0, u1.1), v(v1.0, v1.1), v(u2.0, u2.1), v(v2.0, v2.1));
        let e1 = RangeEllipse::new(u1, v1, (v1 - u1).norm() + x1).unwrap();
        let e2 = RangeEllipse::new(u2, v2, (v2 - u2).norm() + x2).unwrap();
        let pts = intersect(&e1, &e2, None);
        prop_assert!(pts.len() <= 4);
        for p in pts.iter() {
            prop_assert!(e1.residual(*p).abs() < 1e-9, "{:?} {}", p, e1.residual(*p));
            prop_assert!(e2.residual(*p).abs() < 1e-9, "{:?} {}", p, e2.residual(*p));
        }
        for (i, p) in pts.iter().enumerate() {
            for q in &pts[..i] {
                prop_assert!((p - q).norm() >= 1e-6);
            }
        }
    }

    #[test]
    fn random_ppp_patterns(
        x in (0.5..9.5f64, 0.5..9.5f64),
        nodes in proptest::collection::vec((0.0..10.0f64, 0.0..10.0f64), 4),
        lambda in 0.0..0.2f64, d in 0.1..2.0f64,
    ) {
        let region = Rect::new(v(0.0, 0.0), v(10.0, 10.0)).unwrap();
        let m = PppBlocking::new(lambda, d, Some(region), true).unwrap();
        let tx: Vec<Vec2> = nodes[..2].iter().map(|p| v(p.0, p.1)).collect();
        let rx: Vec<Vec2> = nodes[2..].iter().map(|p| v(p.0, p.1)).collect();
        let areas = m.node_areas(v(x.0, x.1), &tx, &rx).unwrap();
        let mut total = 0.0;
        for k in 0..16u64 {
            let exact = areas.probability(lambda, true, k & 3, k >> 2);
            let bound = areas.probability(lambda, false, k & 3, k >> 2);
            prop_assert!(exact >= -1e-15);
            prop_assert!(bound <= exact + 1e-12, "{} > {}", bound, exact);
            total += exact;
        }
        prop_assert!((total - 1.0).abs() < 1e-12, "{}", total);
    }
}

#[test]
fn polygon_closed_forms() {
    let sq = [v(0.0, 0.0), v(1.0, 0.0), v(1.0, 1.0), v(0.0, 1.0)];
    assert_eq!(area(&sq), 1.0);
    let tri = [v(0.0, 0.0), v(2.0, 0.0), v(0.0, 2.0)];
    assert_eq!(area(&tri), 2.0);
    // The unit square cut by x + y ≤ 2 is the whole square; by x + y ≤ 1, half of it.
    assert!((area(&clip_convex(&sq, &tri)) - 1.0).abs() < 1e-15);
    let half = [v(0.0, 0.0), v(1.0, 0.0), v(0.0, 1.0)];
    assert!((area(&clip_convex(&sq, &half)) - 0.5).abs() < 1e-15);
    // Rotated rectangles: d × D, unclipped, at any angle.
    for k in 0..12 {
        let th = k as Real * 0.5;
        let node = v(3.0 + 7.0 * th.cos(), -1.0 + 7.0 * th.sin());
        let r = segment_rectangle(v(3.0, -1.0), node, 0.4);
        assert!((area(&r) - 7.0 * 0.4).abs() < 1e-12);
    }
    // Two perpendicular rectangles through a common centre: union = 2·dD − D².
    let a = segment_rectangle(v(-2.0, 0.0), v(2.0, 0.0), 0.5);
    let b = segment_rectangle(v(0.0, -2.0), v(0.0, 2.0), 0.5);
    assert!((intersection_area(&[&a, &b]) - 0.25).abs() < 1e-14);
    assert!((union_area(&[a.to_vec(), b.to_vec()]).unwrap() - (4.0 - 0.25)).abs() < 1e-14);
    // Clipping to a region: half the rectangle leaves it.
    let region = Rect::new(v(0.0, 0.0), v(10.0, 5.0)).unwrap();
    let r = node_rectangle(v(0.0, 0.0), v(4.0, 0.0), 0.6, Some(&region));
    assert!((area(&r) - 4.0 * 0.3).abs() < 1e-14);
}

#[test]
fn check8() {
    assert!((p_los(0.03, 5.0, 0.6) - 0.91393).abs() < 5e-6);
    let m = PppBlocking::new(0.03, 0.6, None, true).unwrap();
    assert_eq!(m.p_los(5.0), p_los(0.03, 5.0, 0.6));
}

#[test]
fn check9_example() {
    let region = Rect::new(v(0.0, 0.0), v(10.0, 10.0)).unwrap();
    let tx = vec![v(1.0, 1.0), v(9.0, 2.0), v(2.0, 8.0)];
    let rx = vec![v(8.0, 8.5), v(5.0, 0.5), v(0.5, 5.0)];
    let x = v(5.0, 5.0);
    for exact in [true, false] {
        let m = PppBlocking::new(0.03, 0.6, Some(region), exact).unwrap();
        let areas = m.node_areas(x, &tx, &rx).unwrap();
        for (n, w) in [3.3941, 3.0000, 2.5456, 2.7659, 2.7000, 2.7000]
            .iter()
            .enumerate()
        {
            assert!(
                (areas.area(n) - w).abs() < 5e-5,
                "|A_{n}| = {}",
                areas.area(n)
            );
        }
        assert!((areas.union_area(0b111_111) - 16.0805).abs() < 5e-5);
        let p = |a, b| m.node_pattern_probability(x, &tx, &rx, a, b).unwrap();
        assert!((p(0b111, 0b111) - 0.617291).abs() < 5e-7);
        assert!((p(0b110, 0b111) - 0.059138).abs() < 5e-7);
        assert!((p(0b100, 0b111) - 0.005100).abs() < 5e-7);
        let model = PppNodeModel::new(m, tx.clone(), rx.clone()).unwrap();
        let total: Real = model.pattern_probabilities(x).unwrap().iter().sum();
        if exact {
            assert!((total - 1.0).abs() < 1e-12, "{total}");
        } else {
            assert!(total <= 1.0 + 1e-12);
        }
        assert_eq!(
            model.node_pattern_probability(&x, 0b100, 0b111),
            p(0b100, 0b111)
        );
    }
}

#[test]
fn bound_equals_exact_iff_disjoint() {
    let x = v(0.0, 0.0);
    // Opposite directions: the rectangles only touch along x = 0, so the NLoS polygons are
    // disjoint and (M10) = (M11).
    let tx = [v(5.0, 0.0), v(-5.0, 0.0)];
    let exact = PppBlocking::new(0.05, 0.6, None, true).unwrap();
    let bound = PppBlocking {
        exact: false,
        ..exact
    };
    let (pe, pb) = (
        exact.node_pattern_probability(x, &tx, &[], 0, 0).unwrap(),
        bound.node_pattern_probability(x, &tx, &[], 0, 0).unwrap(),
    );
    assert!((pe - pb).abs() < 1e-15, "{pe} {pb}");
    let want = (1.0 - (-0.05 * 3.0 as Real).exp()).powi(2);
    assert!((pe - want).abs() < 1e-15);
    // Nearly parallel rectangles overlap: the bound is strictly below the exact value.
    let tx = [v(5.0, 0.0), v(5.0, 0.2)];
    let (pe, pb) = (
        exact.node_pattern_probability(x, &tx, &[], 0, 0).unwrap(),
        bound.node_pattern_probability(x, &tx, &[], 0, 0).unwrap(),
    );
    assert!(pb < pe - 1e-6, "{pb} {pe}");
}

#[test]
fn bad_inputs_are_named_errors() {
    assert!(matches!(
        PppBlocking::new(-0.01, 0.6, None, true),
        Err(Error::OutOfRange { ref field, .. }) if field == "lambda"
    ));
    assert!(matches!(
        PppBlocking::new(0.03, 0.0, None, true),
        Err(Error::NotPositive { ref field, .. }) if field == "diameter"
    ));
    assert!(matches!(
        PppBlocking::new(0.03, -1.0, None, true),
        Err(Error::NotPositive { .. })
    ));
    assert!(matches!(
        PppBlocking::new(0.03, Real::INFINITY, None, true),
        Err(Error::NotPositive { .. })
    ));
    let m = PppBlocking::new(0.03, 0.6, None, true).unwrap();
    let e = m
        .node_pattern_probability(v(1.0, 1.0), &[v(0.0, 0.0)], &[v(Real::NAN, 0.0)], 1, 0)
        .unwrap_err();
    assert_eq!(e.to_string(), "rx[0]: not a finite number");
    let e = m
        .node_pattern_probability(v(Real::NAN, 1.0), &[v(0.0, 0.0)], &[], 1, 0)
        .unwrap_err();
    assert_eq!(e.to_string(), "x: not a finite number");
    assert!(PppNodeModel::new(m, vec![v(0.0, Real::INFINITY)], vec![]).is_err());
    assert!(matches!(
        Rect::new(v(0.0, 0.0), v(-1.0, 1.0)),
        Err(Error::InvertedArea { .. })
    ));
    let many = vec![v(1.0, 1.0); 21];
    assert!(matches!(
        m.node_areas(v(0.0, 0.0), &many, &[]),
        Err(Error::SizeLimit { .. })
    ));
}

/// Spec check 9, second half: the PPP example's marginals (M4) and relaxed blocking likelihoods
/// (M5) with p_d = 0.9 — P(γ_{1,2,4} = (1,1,1)) = 0.711133, P(γ_{1,2} = (1,1)) = 0.763783,
/// L_b = 0.65698 for ĝ = (1,1,1) on {1,2,4}, and L_b = 2.95956 for the inconsistent
/// ĝ = (1,1,1,0) on {1,2,4,5} (only its heavier neighbour enters (M5)). TRPs are 1-based in the
/// spec and 0-based here.
#[test]
fn check9_marginals_and_blocking_likelihoods() {
    use scatterloc::mtl::blocking::{blocking_likelihood, BlockingSpace, PartialVector};
    use scatterloc::mtl::trp::TrpMap;
    let region = Rect::new(v(0.0, 0.0), v(10.0, 10.0)).unwrap();
    let tx = vec![v(1.0, 1.0), v(9.0, 2.0), v(2.0, 8.0)];
    let rx = vec![v(8.0, 8.5), v(5.0, 0.5), v(0.5, 5.0)];
    let x = v(5.0, 5.0);
    let nodes = PppNodeModel::new(
        PppBlocking::new(0.03, 0.6, Some(region), true).unwrap(),
        tx,
        rx,
    )
    .unwrap();
    let map = TrpMap::new(3, 3).unwrap();
    let space = BlockingSpace::new(map);
    let table = space.node_table(&nodes, &x);
    let bits = |trps: &[usize]| trps.iter().fold(0u64, |m, t| m | 1 << (t - 1));
    let vector =
        |set: &[usize], ones: &[usize]| PartialVector::new(&map, bits(set), bits(ones)).unwrap();
    let g124 = vector(&[1, 2, 4], &[1, 2, 4]);
    assert!((space.marginal(&table, &g124) - 0.711133).abs() < 5e-7);
    assert!((space.marginal(&table, &vector(&[1, 2], &[1, 2])) - 0.763783).abs() < 5e-7);
    let lb = |g: &PartialVector| blocking_likelihood(space.relaxed_probability(&table, g, 0.9));
    assert!((lb(&g124) - 0.65698).abs() < 5e-6, "{}", lb(&g124));
    let g1245 = vector(&[1, 2, 4, 5], &[1, 2, 4]);
    assert!((lb(&g1245) - 2.95956).abs() < 5e-6, "{}", lb(&g1245));
}

/// The §5.2 scan finds sign changes with the implicit quadratic of ellipse 2 instead of `h`
/// itself: on 2 000 random ellipse pairs (ranges 6–30 m, foci in a 10 m square) the points equal
/// an independent count of the sign changes of `h` at the 720 sample angles (the transversal
/// crossings; tangencies are grazing and dropped), each on both ellipses within 1e-9 m.
#[test]
fn intersection_scan_finds_every_sampled_sign_change_of_h() {
    let mut seed = 0x9e37_79b9_7f4a_7c15u64;
    let mut rnd = |lo: Real, hi: Real| {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        lo + (hi - lo) * ((seed >> 11) as Real / (1u64 << 53) as Real)
    };
    let mut total = 0;
    for _ in 0..2000 {
        let mut ell = || loop {
            let (u, w) = (
                v(rnd(0.0, 10.0), rnd(0.0, 10.0)),
                v(rnd(0.0, 10.0), rnd(0.0, 10.0)),
            );
            if let Some(e) = RangeEllipse::new(u, w, rnd(6.0, 30.0)) {
                break e;
            }
        };
        let (e1, e2) = (ell(), ell());
        let pts = intersect(&e1, &e2, None);
        on_both(&e1, &e2, &pts);
        let n = scatterloc::mtl::geometry::INTERSECTION_SAMPLES;
        let h: Vec<Real> = (0..n)
            .map(|k| e2.residual(e1.point(2.0 * std::f64::consts::PI * k as Real / n as Real)))
            .collect();
        let changes = (0..n)
            .filter(|&k| (h[k] > 0.0) != (h[(k + 1) % n] > 0.0))
            .count();
        assert_eq!(pts.len(), changes.min(4), "{e1:?} {e2:?}");
        total += pts.len();
    }
    assert!(total > 2000, "{total}");
}
