//! GOSPA (`α = 2`, issue 41 §1) against an independent reference written here from the
//! definition — the minimum over every partial assignment of pairs closer than `c` of
//! `Σ d^p + c^p/2 · (n + m − 2|γ|)`, enumerated — on random sets, closed forms, the metric's
//! axioms (identity, symmetry, triangle inequality for p ≥ 1) and the named errors.

use scatterloc::track::{gospa, GospaConfig, MAX_GOSPA_POINTS};
use scatterloc::{Error, Real, Vec2};

/// The definition, by enumeration: each truth is left out or paired with an unused estimate
/// closer than `c`. Returns `(distance^p, localisation, missed count, false count)`.
fn reference(x: &[Vec2], y: &[Vec2], c: Real, p: Real) -> (Real, Real, usize, usize) {
    /// The enumeration's fixed inputs and its best so far.
    struct Search<'a> {
        x: &'a [Vec2],
        y: &'a [Vec2],
        c: Real,
        p: Real,
        used: Vec<bool>,
        best: (Real, Real, usize, usize),
    }
    fn go(s: &mut Search, i: usize, loc: Real, pairs: usize) {
        let (n, m) = (s.x.len(), s.y.len());
        if i == n {
            let un = (n - pairs + m - pairs) as Real;
            let total = loc + s.c.powf(s.p) / 2.0 * un;
            if total < s.best.0 {
                s.best = (total, loc, n - pairs, m - pairs);
            }
            return;
        }
        go(s, i + 1, loc, pairs);
        for j in 0..m {
            let (a, b) = (s.x[i], s.y[j]);
            let d = ((a.x - b.x).powi(2) + (a.y - b.y).powi(2)).sqrt();
            if !s.used[j] && d < s.c {
                s.used[j] = true;
                go(s, i + 1, loc + d.powf(s.p), pairs + 1);
                s.used[j] = false;
            }
        }
    }
    let mut s = Search {
        x,
        y,
        c,
        p,
        used: vec![false; y.len()],
        best: (Real::INFINITY, 0.0, 0, 0),
    };
    go(&mut s, 0, 0.0, 0);
    s.best
}

fn lcg(s: &mut u64) -> Real {
    *s = s
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    (*s >> 11) as Real / (1u64 << 53) as Real
}

fn points(s: &mut u64, n: usize, span: Real) -> Vec<Vec2> {
    (0..n)
        .map(|_| Vec2::new(lcg(s) * span, lcg(s) * span))
        .collect()
}

#[test]
fn gospa_equals_the_definition_enumerated() {
    let mut s = 41u64;
    let mut with_cutoff_pairs = 0;
    for case in 0..800 {
        let (n, m) = ((lcg(&mut s) * 6.0) as usize, (lcg(&mut s) * 6.0) as usize);
        let c = [0.5, 1.0, 3.0, 10.0][case % 4];
        let p = [1.0, 2.0, 3.5][case % 3];
        let (x, y) = (points(&mut s, n, 4.0), points(&mut s, m, 4.0));
        let got = gospa(&x, &y, &GospaConfig { c, p }).unwrap();
        let (want_p, loc, missed, false_) = reference(&x, &y, c, p);
        let tol = 1e-12 * want_p.max(1.0);
        assert!(
            (got.distance.powf(p) - want_p).abs() <= 1e-10 * want_p.max(1.0),
            "case {case}"
        );
        assert!(
            (got.localisation + got.missed + got.false_ - want_p).abs() <= tol,
            "case {case}"
        );
        // The split is unique up to ties of equal total; on random reals it is the reference's.
        assert!(
            (got.localisation - loc).abs() <= tol,
            "case {case}: {} vs {loc}",
            got.localisation
        );
        assert_eq!(
            (got.missed_count, got.false_count),
            (missed, false_),
            "case {case}"
        );
        let want_missed = c.powf(p) / 2.0 * missed as Real;
        assert!(
            (got.missed - want_missed).abs() <= 1e-15 * want_missed,
            "case {case}"
        );
        assert!(got.pairs.iter().all(|&(i, j)| (x[i] - y[j]).norm() < c));
        if n.min(m) > got.pairs.len() {
            with_cutoff_pairs += 1;
        }
    }
    // The cut-off (a pair at d ≥ c reported as one missed and one false) was exercised.
    assert!(with_cutoff_pairs > 100, "{with_cutoff_pairs}");
}

#[test]
fn gospa_closed_forms() {
    let cfg = GospaConfig { c: 2.0, p: 2.0 };
    let a = [
        Vec2::new(0.0, 0.0),
        Vec2::new(5.0, 5.0),
        Vec2::new(-3.0, 1.0),
    ];
    // Identical sets: 0.
    assert_eq!(gospa(&a, &a, &cfg).unwrap().distance, 0.0);
    // No estimates: every truth missed, (c^p/2 · n)^(1/p) = (2·3)^(1/2).
    let g = gospa(&a, &[], &cfg).unwrap();
    assert!((g.distance - 6f64.sqrt()).abs() < 1e-15 && g.missed_count == 3 && g.false_ == 0.0);
    // Nothing true, two estimates: √(2·2).
    let g = gospa(&[], &a[..2], &cfg).unwrap();
    assert!((g.distance - 2.0).abs() < 1e-15 && g.false_count == 2);
    // One pair at d = 1.2 < c: the distance is d; at d = 2.5 ≥ c: one missed, one false, c.
    let g = gospa(&[Vec2::zeros()], &[Vec2::new(1.2, 0.0)], &cfg).unwrap();
    assert!((g.distance - 1.2).abs() < 1e-15 && g.pairs == [(0, 0)]);
    let g = gospa(&[Vec2::zeros()], &[Vec2::new(0.0, 2.5)], &cfg).unwrap();
    assert!((g.distance - 2.0).abs() < 1e-15 && (g.missed_count, g.false_count) == (1, 1));
    // p = 1: a plain sum; one pair at 0.5 and one extra estimate: 0.5 + c/2 = 1.5.
    let g = gospa(
        &[Vec2::zeros()],
        &[Vec2::new(0.3, 0.4), Vec2::new(9.0, 9.0)],
        &GospaConfig { c: 2.0, p: 1.0 },
    )
    .unwrap();
    assert!((g.distance - 1.5).abs() < 1e-15);
}

#[test]
fn gospa_is_a_metric_on_random_sets() {
    let mut s = 5u64;
    for case in 0..300 {
        let cfg = GospaConfig {
            c: [1.0, 2.5][case % 2],
            p: [1.0, 2.0, 4.0][case % 3],
        };
        let sets: Vec<Vec<Vec2>> = (0..3)
            .map(|_| {
                let n = (lcg(&mut s) * 5.0) as usize;
                points(&mut s, n, 3.0)
            })
            .collect();
        let d = |a: &[Vec2], b: &[Vec2]| gospa(a, b, &cfg).unwrap().distance;
        let (ab, ba) = (d(&sets[0], &sets[1]), d(&sets[1], &sets[0]));
        assert!(
            (ab - ba).abs() <= 1e-12 * ab.max(1.0),
            "symmetry, case {case}"
        );
        let (bc, ac) = (d(&sets[1], &sets[2]), d(&sets[0], &sets[2]));
        assert!(
            ac <= ab + bc + 1e-12,
            "triangle, case {case}: {ac} > {ab} + {bc}"
        );
        assert_eq!(d(&sets[2], &sets[2]), 0.0);
    }
}

#[test]
fn gospa_names_bad_input() {
    let x = [Vec2::zeros()];
    let bad = |c: Real, p: Real| gospa(&x, &x, &GospaConfig { c, p }).unwrap_err();
    assert!(matches!(bad(0.0, 2.0), Error::NotPositive { .. }));
    assert!(matches!(bad(Real::NAN, 2.0), Error::NotPositive { .. }));
    assert!(matches!(bad(1.0, 0.5), Error::OutOfRange { .. }));
    assert!(matches!(bad(1.0, Real::INFINITY), Error::OutOfRange { .. }));
    let e = gospa(
        &[Vec2::new(0.0, Real::NAN)],
        &x,
        &GospaConfig { c: 1.0, p: 2.0 },
    )
    .unwrap_err();
    assert!(e.to_string().contains("truth[0]"), "{e}");
    let many = vec![Vec2::zeros(); MAX_GOSPA_POINTS + 1];
    let e = gospa(&x, &many, &GospaConfig { c: 1.0, p: 2.0 }).unwrap_err();
    assert!(
        matches!(
            e,
            Error::SizeLimit {
                field: "estimates",
                ..
            }
        ),
        "{e}"
    );
}
