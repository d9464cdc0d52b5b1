//! The §7 generator, metrics (M12) and Table II helpers of spec `multi-target.md` (checks 4, 11).
#![cfg(not(target_arch = "wasm32"))]

use scatterloc::measure::bistatic_range;
use scatterloc::mtl::sim::*;
use scatterloc::mtl::trp::TrpMap;
use scatterloc::{Error, Vec2};

use crate::common;

use common::within_abs;

/// Spec check 11's columns (≤2, 3, …, 9) and its tolerance.
const CHECK_11: [f64; 8] = [0.034, 0.029, 0.045, 0.0, 0.224, 0.0, 0.0, 0.669];
const CHECK_11_TOL: f64 = 0.005;

/// Table II "True" columns (≤2, 3, …, 9) of `realisations · 2` V-B target draws, and the exact
/// zeros of weights 5, 7, 8.
fn check_11_columns(seed: u64, realisations: u64) -> Vec<f64> {
    let row = true_row(&SimSettings::vb(), seed, realisations).unwrap();
    let b = table2_buckets(&row);
    println!(
        "check 11, seed {seed}, {} draws (≤2, 3, …, 9): {b:.4?}",
        2 * realisations
    );
    // Weights 5, 7, 8 never occur (γ = γ^R ⊗ γ^T, check 2): exactly 0.
    assert_eq!((row[5], row[7], row[8]), (0.0, 0.0, 0.0));
    assert!(within_abs(row.iter().sum::<f64>(), 1.0, 1e-12));
    b
}

/// Check 11 (±0.005 of the spec's columns) on one run.
fn check_11(seed: u64, realisations: u64) {
    let b = check_11_columns(seed, realisations);
    for (i, (&got, &want)) in b.iter().zip(&CHECK_11).enumerate() {
        assert!(
            within_abs(got, want, CHECK_11_TOL),
            "column {i}: {got} vs {want}"
        );
    }
}

/// Spec check 11 at its size, 10⁵ target draws (5·10⁴ realisations × K = 2), over seeds 1–5.
///
/// What is true. The binomial standard error of P(9) ≈ 0.67 at 10⁵ draws is
/// √(p(1−p)/10⁵) ≈ 0.0015 (the two targets of a realisation share its scene, so up to
/// √2 · 0.0015 = 0.0021 with n = 5·10⁴ realisations as the independent units; seeds 1–8 spread
/// with sd 0.0017). This generator's P(9) converges to ≈ 0.667 (seeds 1–8 at 10⁵ draws:
/// 0.6657, 0.6669, 0.6697, 0.6671, 0.6650, 0.6673, 0.6697, 0.6672; 10⁶ draws: 0.6664, 0.6659),
/// 0.002–0.003 below the spec's 0.669, so the ±0.005 band is only ≈ 1.5–2 SE from the limit at
/// 10⁵ draws: "every 10⁵-draw run is within ±0.005" holds for most seeds but not all (≈ 5 % of
/// seeds fail) and is not asserted per seed. Asserted instead:
/// - pooled over the seeds (5·10⁵ draws, SE ≤ 0.0021/√5 = 0.00095 for P(9)), every column is
///   within the spec's ±0.005 (P(9): the limit's 0.0028 margin is ≥ 3 SE; the other columns
///   have SE ≤ 0.0009 and margins ≥ 0.002);
/// - each seed agrees with the pooled value to 4.5 binomial SE of a seed,
///   `4.5 · √(p(1−p)/5·10⁴)` (realisations as the units, the conservative count), so a seed
///   fails with probability < 1e-5 per column.
#[test]
fn check_11_true_row_of_table_two() {
    let realisations = 50_000u64;
    let runs: Vec<Vec<f64>> = (1..=5)
        .map(|seed| check_11_columns(seed, realisations))
        .collect();
    let pooled: Vec<f64> = (0..CHECK_11.len())
        .map(|i| runs.iter().map(|r| r[i]).sum::<f64>() / runs.len() as f64)
        .collect();
    println!("check 11, pooled over seeds 1–5: {pooled:.4?}");
    for (i, (&got, &want)) in pooled.iter().zip(&CHECK_11).enumerate() {
        assert!(
            within_abs(got, want, CHECK_11_TOL),
            "pooled column {i}: {got} vs {want} ± {CHECK_11_TOL}"
        );
    }
    for (seed, run) in (1..=5).zip(&runs) {
        for (i, (&got, &p)) in run.iter().zip(&pooled).enumerate() {
            let tol = 4.5 * (p * (1.0 - p) / realisations as f64).sqrt();
            assert!(
                within_abs(got, p, tol),
                "seed {seed}, column {i}: {got} vs pooled {p} ± {tol}"
            );
        }
    }
}

#[test]
#[ignore = "10⁶ draws, ~30 s in debug; run with --ignored"]
fn check_11_with_a_million_draws() {
    // SE ≈ 0.0005: the ±0.005 band of check 11 then holds with > 5 SE margin for any seed.
    check_11(2018, 500_000);
}

#[test]
fn check_4_icb_row_of_table_two() {
    let row = icb_row(TrpMap::new(3, 3).unwrap(), VB_ICB_P_U).unwrap();
    let b = table2_buckets(&row);
    let printed = [
        0.1267, 0.1961, 0.2578, 0.2259, 0.1320, 0.0496, 0.0109, 0.0011,
    ];
    for (&got, &want) in b.iter().zip(&printed) {
        assert!(within_abs(got, want, 5e-5), "{got} vs {want}");
    }
    assert!(icb_row(TrpMap::new(3, 3).unwrap(), 1.5).is_err());
}

#[test]
fn realisations_depend_on_the_seed_only() {
    for s in [SimSettings::va(), SimSettings::vb()] {
        for i in 0..5 {
            assert_eq!(generate(&s, 7, i).unwrap(), generate(&s, 7, i).unwrap());
            assert_ne!(generate(&s, 7, i).unwrap(), generate(&s, 8, i).unwrap());
            assert_ne!(generate(&s, 7, i).unwrap(), generate(&s, 7, i + 1).unwrap());
        }
    }
}

#[test]
fn va_hexagon_positions() {
    let r = generate(&SimSettings::va(), 1, 0).unwrap();
    let h = 5.0 * 3f64.sqrt() / 2.0;
    let tx = [(5.0, 10.0), (5.0 - h, 2.5), (5.0 + h, 2.5)];
    let rx = [(5.0 + h, 7.5), (5.0 - h, 7.5), (5.0, 0.0)];
    for (p, &(x, y)) in r.scene.tx.iter().zip(&tx).chain(r.scene.rx.iter().zip(&rx)) {
        assert!(
            within_abs(p.x, x, 1e-12) && within_abs(p.y, y, 1e-12),
            "{p:?} vs ({x}, {y})"
        );
    }
    assert!(r.scene.discs.is_empty());
}

#[test]
fn va_node_segments_are_blocked_independently() {
    // Each node–target segment is LoS w.p. p_LoS = 0.9, so a TRP has γ_m = 1 w.p. 0.81.
    // 4000 realisations × 2 targets × 9 TRPs: SE of the frequency ≈ √(0.81·0.19/72000) ≈ 0.0015.
    let s = SimSettings::va();
    let (mut ones, mut n) = (0u32, 0u32);
    for i in 0..4000 {
        for b in draw_scene(&s, 3, i).unwrap().blocking {
            ones += b.dp_count();
            n += 9;
        }
    }
    assert!(within_abs(ones as f64 / n as f64, 0.81, 0.006));
}

#[test]
fn vb_nodes_and_targets_avoid_the_discs() {
    let s = SimSettings::vb();
    for i in 0..200 {
        let sc = draw_scene(&s, 4, i).unwrap();
        for p in sc.tx.iter().chain(&sc.rx).chain(&sc.targets) {
            assert!(s.region.contains(*p));
            assert!(sc.discs.iter().all(|c| (p - c).norm() > 0.3));
        }
        assert_eq!((sc.tx.len(), sc.rx.len(), sc.targets.len()), (3, 3, 2));
    }
}

#[test]
fn clutter_mean_is_two_per_trp() {
    // p_d = 0 (no DPs) and δ = 0 (ties have probability 0): every range is clutter.
    // 3000 realisations × 9 TRPs of Poisson(2): SE of the mean = √(2/27000) ≈ 0.0086; ±0.04.
    let mut s = SimSettings::vb();
    s.p_d = 0.0;
    s.resolution = 0.0;
    let (mut total, mut n) = (0usize, 0usize);
    for i in 0..3000 {
        for t in generate(&s, 5, i).unwrap().trps {
            assert!(t.ranges.iter().all(|&r| (0.0..=s.r_max).contains(&r)));
            assert!(t.sources.iter().all(|&src| src == Source::Clutter));
            total += t.ranges.len();
            n += 1;
        }
    }
    let mean = total as f64 / n as f64;
    assert!(within_abs(mean, 2.0, 0.04), "clutter mean {mean}");
}

#[test]
fn ground_truth_matches_the_ranges() {
    for s in [SimSettings::va(), SimSettings::vb()] {
        let map = s.map().unwrap();
        for i in 0..300 {
            let r = generate(&s, 6, i).unwrap();
            let sc = &r.scene;
            for (m, t) in r.trps.iter().enumerate() {
                assert!(t.ranges.windows(2).all(|w| w[1] - w[0] > s.resolution));
                let (u, v) = (sc.tx[map.tx(m)], sc.rx[map.rx(m)]);
                for (k, truth) in r.truth.iter().enumerate() {
                    let Some(i) = truth.dp[m] else {
                        assert_eq!(truth.detected >> m & 1, 0);
                        continue;
                    };
                    assert_eq!(t.sources[i], Source::Dp { target: k });
                    assert_eq!(sc.blocking[k].gamma >> m & 1, 1);
                    let d = bistatic_range(u, v, sc.targets[k]);
                    assert!((t.ranges[i] - d).abs() <= 5.0 * s.range_sigma);
                }
            }
        }
    }
}

#[test]
fn geometric_ips_have_path_lengths() {
    let mut s = SimSettings::vb();
    s.geometric_ips = GeometricIps {
        kind1: true,
        kind2: true,
    };
    s.clutter_mean = 0.0;
    let map = s.map().unwrap();
    let mut seen = [0usize; 2];
    for i in 0..300 {
        let r = generate(&s, 11, i).unwrap();
        let sc = &r.scene;
        for (m, t) in r.trps.iter().enumerate() {
            let (u, v) = (sc.tx[map.tx(m)], sc.rx[map.rx(m)]);
            for (&rg, src) in t.ranges.iter().zip(&t.sources) {
                if let Source::Ip {
                    kind,
                    target,
                    scatterer,
                } = *src
                {
                    let (x, y) = (sc.targets[target], sc.discs[scatterer]);
                    let (a, b) = if kind == 1 { (u, v) } else { (v, u) };
                    let len = (a - x).norm() + (x - y).norm() + (y - b).norm();
                    assert!((rg - len).abs() <= 5.0 * s.range_sigma);
                    seen[kind as usize - 1] += 1;
                }
            }
        }
    }
    assert!(seen[0] > 0 && seen[1] > 0, "{seen:?}");
    // Off by default: no IP sources.
    let r = generate(&SimSettings::vb(), 11, 0).unwrap();
    let no_ip = |t: &TrpRanges| t.sources.iter().all(|s| !matches!(s, Source::Ip { .. }));
    assert!(r.trps.iter().all(no_ip));
}

#[test]
fn bad_settings_are_named_errors() {
    let field_of = |e: Error| match e {
        Error::OutOfRange { field, .. }
        | Error::NotPositive { field, .. }
        | Error::NonFinite { field } => field,
        Error::SizeLimit { field, .. } | Error::InvertedArea { field, .. } => field.into(),
        Error::EmptyNodeList { field } => field.into(),
        other => panic!("unexpected {other:?}"),
    };
    let check = |f: &dyn Fn(&mut SimSettings), want: &str| {
        let mut s = SimSettings::vb();
        f(&mut s);
        let e = generate(&s, 0, 0).unwrap_err();
        assert!(e.to_string().contains(want), "{e}");
        assert_eq!(field_of(e.clone()), want);
        assert_eq!(draw_scene(&s, 0, 0).unwrap_err().to_string(), e.to_string());
    };
    check(&|s| s.lambda = -0.1, "lambda");
    check(&|s| s.diameter = 0.0, "diameter");
    check(&|s| s.diameter = -1.0, "diameter");
    check(&|s| s.targets = 0, "targets");
    check(&|s| s.region.max.x = -1.0, "region.x");
    check(&|s| s.region.min.y = 20.0, "region.y");
    check(&|s| s.p_d = 1.5, "p_d");
    check(&|s| s.p_d = f64::NAN, "p_d");
    check(&|s| s.los = LosModel::Independent { p_los: -0.1 }, "p_los");
    check(&|s| s.range_sigma = -0.1, "range_sigma");
    check(&|s| s.resolution = f64::INFINITY, "resolution");
    check(&|s| s.clutter_mean = -2.0, "clutter_mean");
    check(&|s| s.detection_radius = 0.0, "detection_radius");
    check(&|s| s.r_max = 0.0, "r_max");
    check(
        &|s| s.nodes = NodeLayout::Uniform { n_tx: 0, n_rx: 3 },
        "transmitters",
    );
    check(
        &|s| {
            s.nodes = NodeLayout::Fixed {
                tx: vec![Vec2::new(f64::NAN, 0.0)],
                rx: vec![Vec2::new(1.0, 0.0)],
            }
        },
        "nodes.tx[0]",
    );
    // Discs covering the whole region: rejection sampling gives up with a named error.
    check(
        &|s| {
            s.lambda = 1.0;
            s.diameter = 30.0;
        },
        "diameter",
    );
    assert!(true_row(&SimSettings::vb(), 0, 0).is_err());
}
