#![cfg(not(target_arch = "wasm32"))]
//! Algorithm 1 of `shared/spec/multi-target.md` (§4) and its brute-force reference: noise-free
//! detection, blocked TRPs (cases 1 and 2b), staged = brute force on random small instances,
//! check 6 (i.c.b + (M8) = the size rule), invariance to node relabelling, and bad inputs.
//!
//! The random instances here are simple (targets uniform, node LoS independent, `p_d` misses,
//! range noise, uniform clutter); the full §7 generator lives in `scatterloc::mtl::sim`.

use rand::Rng as _;
use scatterloc::math::{Real, Vec2};
use scatterloc::measure::bistatic_range;
use scatterloc::measure::{self, Rng};
use scatterloc::mtl::algorithm::{
    locate, locate_cached, FinalTest, IntersectionCache, Measurements, MtlConfig, MtlOutput, Pair,
    Status, Target,
};
use scatterloc::mtl::blocking::{kron, BlockingModel, IndependentNodes, NodeBlockingModel};
use scatterloc::mtl::brute::brute_force;
use scatterloc::mtl::icb::IcbModel;
use scatterloc::mtl::trp::TrpMap;
use scatterloc::Error;

/// The V-A network (§7): TX at 90°, 210°, 330°, RX at 30°, 150°, 270° on the 5 m circle
/// about (5, 5).
fn hexagon() -> (Vec<Vec2>, Vec<Vec2>) {
    let at = |deg: Real| {
        let t = deg.to_radians();
        Vec2::new(5.0 + 5.0 * t.cos(), 5.0 + 5.0 * t.sin())
    };
    (
        vec![at(90.0), at(210.0), at(330.0)],
        vec![at(30.0), at(150.0), at(270.0)],
    )
}

fn map9() -> TrpMap {
    TrpMap::new(3, 3).unwrap()
}

/// One random realisation.
struct Instance {
    ranges: Vec<Vec<Real>>,
    truth: Vec<Vec2>,
}

/// Range noise: bounded uniform `±cσ` (so a true DP always passes `T_e ≥ 3`, see the staged =
/// brute-force test) or Gaussian.
#[derive(Clone, Copy)]
enum Noise {
    Uniform(Real),
    Gaussian(Real),
}

/// `k` targets uniform in `[2, 8]²` (redrawn until the targets' ranges differ by at least
/// `separation` m at every TRP), every node–target LoS independently with `p_node`, DPs kept
/// with `p_d`, noise, then `clutter` uniform ranges on `[0, 28.28]` per TRP with prob. 1/2 each.
fn instance(
    rng: &mut Rng,
    k: usize,
    (p_node, p_d): (Real, Real),
    noise: Noise,
    clutter: usize,
    separation: Real,
) -> Instance {
    let map = map9();
    let (tx, rx) = hexagon();
    let mut ranges = vec![Vec::new(); 9];
    let mut truth: Vec<Vec2> = Vec::new();
    for _ in 0..k {
        let x = loop {
            let x = Vec2::new(rng.random_range(2.0..8.0), rng.random_range(2.0..8.0));
            let apart = |y: &Vec2| {
                (0..9).all(|m| {
                    (map.range(m, &x, &tx, &rx) - map.range(m, y, &tx, &rx)).abs() >= separation
                })
            };
            if truth.iter().all(apart) {
                break x;
            }
        };
        let a = (0..3).fold(0u64, |m, j| {
            m | ((rng.random::<Real>() < p_node) as u64) << j
        });
        let b = (0..3).fold(0u64, |m, j| {
            m | ((rng.random::<Real>() < p_node) as u64) << j
        });
        let g = kron(&map, a, b);
        for (m, r) in ranges.iter_mut().enumerate() {
            if g >> m & 1 == 1 && rng.random::<Real>() < p_d {
                let n = match noise {
                    Noise::Uniform(s) => rng.random_range(-s..=s),
                    Noise::Gaussian(s) => s * measure::standard_normal(rng),
                };
                r.push(map.range(m, &x, &tx, &rx) + n);
            }
        }
        truth.push(x);
    }
    for r in ranges.iter_mut() {
        for _ in 0..clutter {
            if rng.random::<bool>() {
                r.push(rng.random_range(0.0..28.28));
            }
        }
        r.sort_by(Real::total_cmp);
    }
    Instance { ranges, truth }
}

fn run<B: BlockingModel + ?Sized>(
    ranges: &[Vec<Real>],
    cs: Real,
    model: &B,
    cfg: &MtlConfig,
) -> MtlOutput {
    let (tx, rx) = hexagon();
    let input = Measurements {
        tx: &tx,
        rx: &rx,
        ranges,
        c_sigma_m: cs,
    };
    locate(&input, model, cfg).unwrap()
}

/// [`run`] sharing ellipse intersections through `cache`.
fn run_cached<B: BlockingModel + ?Sized>(
    ranges: &[Vec<Real>],
    cs: Real,
    model: &B,
    cfg: &MtlConfig,
    cache: &mut IntersectionCache,
) -> MtlOutput {
    let (tx, rx) = hexagon();
    let input = Measurements {
        tx: &tx,
        rx: &rx,
        ranges,
        c_sigma_m: cs,
    };
    locate_cached(&input, model, cfg, cache).unwrap()
}

fn node_model(p: Real, p_d: Real) -> NodeBlockingModel<IndependentNodes> {
    let map = map9();
    let nodes = IndependentNodes::new(&map, vec![p; 3], vec![p; 3]).unwrap();
    NodeBlockingModel::new(map, nodes, p_d).unwrap()
}

/// Exact ranges of `targets` at every TRP whose bit is set in `dps[k]`, sorted.
fn exact_ranges(targets: &[Vec2], dps: &[u64]) -> Vec<Vec<Real>> {
    let (tx, rx) = hexagon();
    let map = map9();
    (0..9)
        .map(|m| {
            let mut r: Vec<Real> = targets
                .iter()
                .zip(dps)
                .filter(|(_, g)| *g >> m & 1 == 1)
                .map(|(x, _)| bistatic_range(tx[map.tx(m)], rx[map.rx(m)], *x))
                .collect();
            r.sort_by(Real::total_cmp);
            r
        })
        .collect()
}

/// Whether `a` and `b` pair up one-to-one within `tol` (greedy nearest).
fn same_positions(a: &[Vec2], b: &[Vec2], tol: Real) -> bool {
    if a.len() != b.len() {
        return false;
    }
    let mut free: Vec<bool> = vec![true; b.len()];
    a.iter().all(|p| {
        let best = (0..b.len())
            .filter(|&j| free[j])
            .min_by(|&i, &j| (b[i] - p).norm().total_cmp(&(b[j] - p).norm()));
        match best {
            Some(j) if (b[j] - p).norm() <= tol => {
                free[j] = false;
                true
            }
            _ => false,
        }
    })
}

fn positions(t: &[Target]) -> Vec<Vec2> {
    t.iter().map(|t| t.position).collect()
}

#[test]
fn noise_free_targets_found_with_full_matchings() {
    let model = node_model(0.9, 0.9);
    let cfg = MtlConfig::default();
    let sets: [&[Vec2]; 3] = [
        &[Vec2::new(3.5, 4.2)],
        &[Vec2::new(3.5, 4.2), Vec2::new(6.3, 6.1)],
        &[Vec2::new(5.2, 2.9), Vec2::new(4.1, 6.8)],
    ];
    for truth in sets {
        let ranges = exact_ranges(truth, &vec![0x1ff; truth.len()]);
        let out = run(&ranges, 0.01, &model, &cfg);
        assert_eq!(
            out.targets.len(),
            truth.len(),
            "{:?}",
            positions(&out.targets)
        );
        assert!(same_positions(&positions(&out.targets), truth, 1e-6));
        for t in &out.targets {
            assert_eq!(t.matching.len(), 9);
            assert_eq!(t.g.ones(), 0x1ff);
            assert!(t.l_b.is_finite() && t.j >= t.l_b);
        }
    }
}

#[test]
fn blocked_tx_case_one_and_missed_dp_case_two_b() {
    let model = node_model(0.8, 0.9);
    let cfg = MtlConfig::default();
    let x = Vec2::new(4.4, 5.7);
    let map = map9();
    // TX 0 blocked: DPs missing at TRPs 0, 3, 6 (consistent, case 1); the seeds of π₁, π₂ do not
    // exist, the target comes from a late seed.
    let g = kron(&map, 0b110, 0b111);
    let out = run(&exact_ranges(&[x], &[g]), 0.01, &model, &cfg);
    assert_eq!(out.targets.len(), 1);
    assert!((out.targets[0].position - x).norm() < 1e-6);
    assert_eq!(out.targets[0].g.ones(), g);
    // One DP missed at TRP 4: inconsistent with a heavier neighbour (case 2b), kept with (M5).
    // (With frequent blocking a lighter neighbour — RX 1 blocked, 6 pairs — has the lower J (M2);
    // with LoS probability 0.97 the 8-pair matching wins.)
    let g = 0x1ff & !(1 << 4);
    let out = run(
        &exact_ranges(&[x], &[g]),
        0.01,
        &node_model(0.97, 0.9),
        &cfg,
    );
    assert_eq!(out.targets.len(), 1);
    assert!((out.targets[0].position - x).norm() < 1e-6);
    assert_eq!(out.targets[0].matching.len(), 8);
    // TX 0 blocked but TRP 0 shows an MPC at the DP range (error (b)): the inconsistent vector
    // loses that pair through a lighter neighbour (case 2b).
    let g = kron(&map, 0b110, 0b111) | 1;
    let out = run(&exact_ranges(&[x], &[g]), 0.01, &model, &cfg);
    assert_eq!(out.targets.len(), 1);
    let t = &out.targets[0];
    assert!((t.position - x).norm() < 1e-6);
    assert_eq!(t.g.ones(), kron(&map, 0b110, 0b111));
    assert!(t.matching.iter().all(|p| p.trp != 0));
}

#[test]
fn trace_records_every_stage() {
    let model = node_model(0.9, 0.9);
    let cfg = MtlConfig {
        trace: true,
        ..MtlConfig::default()
    };
    let ranges = exact_ranges(&[Vec2::new(3.0, 6.0)], &[0x1ff]);
    let out = run(&ranges, 0.01, &model, &cfg);
    assert_eq!(out.trace.len(), 8);
    assert!(out
        .trace
        .iter()
        .all(|s| s.iter().any(|e| e.status == Status::Kept)));
    let off = run(&ranges, 0.01, &model, &MtlConfig::default());
    assert!(off.trace.is_empty());
    assert_eq!(off.targets, out.targets);
    // The stage tallies are the trace's, and the same without it.
    let tallies: Vec<[usize; 6]> = out
        .trace
        .iter()
        .map(|stage| {
            let mut n = [0; 6];
            for e in stage {
                n[e.status.index()] += 1;
            }
            n
        })
        .collect();
    assert_eq!(out.stage_counts, tallies);
    assert_eq!(off.stage_counts, tallies);
    assert!(Status::ALL.iter().enumerate().all(|(i, s)| s.index() == i));
}

#[test]
fn staged_equals_brute_force_on_random_small_instances() {
    let icb = IcbModel::new(map9(), 0.9, 0.9).unwrap();
    let cs = 0.01;
    let cfg = MtlConfig {
        t_e: 4.0,
        t_b: icb.threshold(4).unwrap(),
        consistency: false,
        ..MtlConfig::default()
    };
    let (tx, rx) = hexagon();
    let mut detected = 0;
    for seed in 0..200 {
        let mut rng = measure::rng(seed, 4);
        let inst = instance(&mut rng, 2, (0.9, 0.9), Noise::Uniform(cs), 0, 0.3);
        let mut cache = IntersectionCache::new();
        let staged = run_cached(&inst.ranges, cs, &icb, &cfg, &mut cache);
        let input = Measurements {
            tx: &tx,
            rx: &rx,
            ranges: &inst.ranges,
            c_sigma_m: cs,
        };
        let brute = brute_force(&input, &icb, &cfg, &mut cache).unwrap();
        let (a, b) = (positions(&staged.targets), positions(&brute));
        assert!(
            same_positions(&a, &b, 0.05),
            "seed {seed}: staged {a:?} brute {b:?} truth {:?}",
            inst.truth
        );
        detected += a.len();
    }
    assert!(detected > 250, "only {detected} detections");
}

#[test]
fn check_6_icb_threshold_equals_size_rule() {
    let icb = IcbModel::new(map9(), 0.9, 0.9).unwrap();
    assert!(icb.p_u() < 0.5);
    let mut detected = [0usize; 3];
    for seed in 0..100 {
        let mut rng = measure::rng(seed, 6);
        let inst = instance(&mut rng, 2, (0.9, 0.9), Noise::Gaussian(0.05), 1, 0.0);
        let mut cache = IntersectionCache::new();
        for (k, n_u) in [2usize, 4, 6].into_iter().enumerate() {
            let base = MtlConfig {
                b_max: usize::MAX,
                consistency: false,
                ..MtlConfig::default()
            };
            let bayes = MtlConfig {
                t_b: icb.threshold(n_u).unwrap(),
                ..base.clone()
            };
            let size = MtlConfig {
                final_test: FinalTest::Size {
                    min_matched: 9 - n_u,
                },
                stage_blocking_test: false,
                ..base
            };
            let a = run_cached(&inst.ranges, 0.05, &icb, &bayes, &mut cache).targets;
            let b = run_cached(&inst.ranges, 0.05, &icb, &size, &mut cache).targets;
            let key = |t: &[Target]| {
                t.iter()
                    .map(|t| (t.matching.clone(), t.position))
                    .collect::<Vec<_>>()
            };
            assert_eq!(key(&a), key(&b), "seed {seed} N_u {n_u}");
            detected[k] += a.len();
        }
    }
    assert!(detected.iter().all(|&d| d > 50), "{detected:?}");
}

#[test]
fn invariant_to_node_relabelling() {
    let model = node_model(0.85, 0.9);
    let map = map9();
    let (tx, rx) = hexagon();
    let (pt, pr) = ([2usize, 0, 1], [1usize, 2, 0]);
    let relabel = |m: usize| pt[map.tx(m)] + 3 * pr[map.rx(m)];
    let mut ties = Vec::new();
    for seed in 0..20 {
        let mut rng = measure::rng(seed, 8);
        let inst = instance(&mut rng, 2, (0.85, 0.9), Noise::Gaussian(0.02), 1, 0.0);
        let cfg = MtlConfig::default();
        let a = run(&inst.ranges, 0.02, &model, &cfg).targets;
        let (mut tx2, mut rx2) = (tx.clone(), rx.clone());
        for j in 0..3 {
            tx2[pt[j]] = tx[j];
            rx2[pr[j]] = rx[j];
        }
        let mut ranges2 = vec![Vec::new(); 9];
        for (m, r) in inst.ranges.iter().enumerate() {
            ranges2[relabel(m)] = r.clone();
        }
        let cfg2 = MtlConfig {
            order: Some((0..9).map(relabel).collect()),
            ..cfg
        };
        let input = Measurements {
            tx: &tx2,
            rx: &rx2,
            ranges: &ranges2,
            c_sigma_m: 0.02,
        };
        let b = locate(&input, &model, &cfg2).unwrap().targets;
        if a.len() != b.len() {
            // A rounding-level tie: relabelling changes the order of some sums, the fixes move by
            // ~1e-11 m, and a ghost family at the same place can survive instead of its
            // neighbour (seed 0 with the libm functions of issue 26: family 117 at
            // (5.178, 6.008) next to 116 at (5.186, 5.992)). Counted, at most one seed in 20.
            ties.push(seed);
            continue;
        }
        for (s, t) in a.iter().zip(&b) {
            // Gauss–Newton stops at ‖Δx‖ < 1e-9 m; ill-conditioned ghosts keep ~1e-9 m rounding.
            assert!((s.position - t.position).norm() < 1e-6, "seed {seed}");
            let mut mapped: Vec<Pair> = s
                .matching
                .iter()
                .map(|p| Pair {
                    trp: relabel(p.trp),
                    mpc: p.mpc,
                })
                .collect();
            mapped.sort();
            assert_eq!(mapped, t.matching);
        }
    }
    assert!(
        ties.len() <= 1,
        "target counts differ after relabelling for seeds {ties:?}"
    );
}

#[test]
fn bad_inputs_are_named_errors() {
    let model = node_model(0.9, 0.9);
    let (tx, rx) = hexagon();
    let ranges = exact_ranges(&[Vec2::new(5.0, 5.0)], &[0x1ff]);
    let cfg = MtlConfig::default();
    let ok = Measurements {
        tx: &tx,
        rx: &rx,
        ranges: &ranges,
        c_sigma_m: 0.1,
    };
    assert!(locate(&ok, &model, &cfg).is_ok());
    let err = |input: Measurements, cfg: &MtlConfig| locate(&input, &model, cfg).unwrap_err();
    assert_eq!(
        err(Measurements { tx: &[], ..ok }, &cfg),
        Error::EmptyNodeList {
            field: "transmitters"
        }
    );
    assert_eq!(
        err(Measurements { rx: &[], ..ok }, &cfg),
        Error::EmptyNodeList { field: "receivers" }
    );
    assert!(matches!(
        err(
            Measurements {
                ranges: &ranges[..8],
                ..ok
            },
            &cfg
        ),
        Error::LengthMismatch {
            field: "ranges",
            expected: 9,
            found: 8
        }
    ));
    let mut nan = ranges.clone();
    nan[4][0] = Real::NAN;
    assert_eq!(
        err(Measurements { ranges: &nan, ..ok }, &cfg),
        Error::NonFinite {
            field: "ranges[4][0]".into()
        }
    );
    // Outside the documented range 1e-3 ..= 1e3 m (item 3 of issue 12: 1e-320 gave "j": null).
    for cs in [0.0, -1.0, 1e-200, 1e-320, 9e-4, 1.1e3] {
        assert!(
            matches!(err(Measurements { c_sigma_m: cs, ..ok }, &cfg), Error::OutOfRange { ref field, .. } if field == "c_sigma_m")
        );
    }
    assert!(
        matches!(err(Measurements { c_sigma_m: Real::NAN, ..ok }, &cfg), Error::NonFinite { ref field } if field == "c_sigma_m")
    );
    for (bad, name) in [
        (
            MtlConfig {
                t_e: -1.0,
                ..cfg.clone()
            },
            "t_e",
        ),
        (
            MtlConfig {
                t_b: -0.5,
                ..cfg.clone()
            },
            "t_b",
        ),
        (
            MtlConfig {
                merge_radius_m: -1.0,
                ..cfg.clone()
            },
            "merge_radius_m",
        ),
    ] {
        assert!(
            matches!(err(ok, &bad), Error::OutOfRange { ref field, .. } if field == name),
            "{name}"
        );
    }
    assert!(matches!(
        err(
            ok,
            &MtlConfig {
                t_e: Real::NAN,
                ..cfg.clone()
            }
        ),
        Error::NonFinite { .. }
    ));
    assert!(matches!(
        err(
            ok,
            &MtlConfig {
                b_max: 0,
                ..cfg.clone()
            }
        ),
        Error::SizeLimit { field: "b_max", .. }
    ));
    assert!(matches!(
        err(
            ok,
            &MtlConfig {
                order: Some(vec![0, 1, 2]),
                ..cfg.clone()
            }
        ),
        Error::LengthMismatch { field: "order", .. }
    ));
    assert!(
        matches!(err(ok, &MtlConfig { order: Some(vec![0, 1, 2, 3, 4, 5, 6, 7, 7]), ..cfg.clone() }), Error::OutOfRange { ref field, .. } if field == "order")
    );
    let shifted = [tx[0], Vec2::new(Real::INFINITY, 0.0), tx[2]];
    assert_eq!(
        err(Measurements { tx: &shifted, ..ok }, &cfg),
        Error::NonFinite {
            field: "transmitters[1]".into()
        }
    );
    // The brute force validates the same way.
    assert!(brute_force(
        &Measurements { ranges: &nan, ..ok },
        &model,
        &cfg,
        &mut IntersectionCache::new()
    )
    .is_err());
    // Display names the field.
    assert!(err(Measurements { ranges: &nan, ..ok }, &cfg)
        .to_string()
        .contains("ranges[4][0]"));
}

/// Case 2b with two pairs left (§4 step 2; the \[P\] location rule of `stages::Run`): a child
/// whose matching drops to two pairs sits on an intersection of its two ellipses (the ML
/// locations of a size-2 matching, as the stage-2 seeds), never at a point off either ellipse.
/// Checked on every kept two-pair candidate of the later stages of 40 noisy, cluttered,
/// blocked instances under a node model (where case 2b occurs).
#[test]
fn two_pair_case_2b_children_sit_on_ellipse_intersections() {
    let model = node_model(0.8, 0.9);
    let cfg = MtlConfig {
        trace: true,
        ..MtlConfig::default()
    };
    let (tx, rx) = hexagon();
    let map = map9();
    let mut rng = measure::rng(77, 12);
    let (mut two_pair, mut unlocatable) = (0, 0);
    for _ in 0..40 {
        let inst = instance(&mut rng, 2, (0.8, 0.9), Noise::Gaussian(0.05), 2, 0.5);
        let out = run(&inst.ranges, 0.05, &model, &cfg);
        for stage in out.trace.iter().skip(1) {
            for e in stage {
                let c = &e.candidate;
                if e.status == Status::Unlocatable {
                    unlocatable += 1;
                }
                if e.status != Status::Kept || c.matching.len() != 2 {
                    continue;
                }
                two_pair += 1;
                for p in &c.matching {
                    let (u, v) = (tx[map.tx(p.trp)], rx[map.rx(p.trp)]);
                    let e = bistatic_range(u, v, c.x) - inst.ranges[p.trp][p.mpc];
                    assert!(e.abs() < 1e-9, "{c:?}: residual {e}");
                }
            }
        }
    }
    assert!(two_pair > 20 && unlocatable > 0, "{two_pair} {unlocatable}");
}
