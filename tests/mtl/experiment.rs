//! The §8 experiments of spec `multi-target.md` as ROC sweeps: check 6 on the Fig. 3 data
//! (size rule ≡ Bayesian i.c.b), the expected shapes of Fig. 4 (i.c.b false alarms before
//! detections, as [A] says; PPP the other way round, the spec's expectation, not a claim of
//! [A]), Fig. 5 as docs/reproduction.md reports it (the genie misses more at low T_b, the two
//! close at high T_b), thread-count independence, and named errors for bad configurations.

#![cfg(not(target_arch = "wasm32"))]

use std::sync::atomic::AtomicBool;

use scatterloc::mtl::experiment::{
    grid, run_sequential, Curve, EmpiricalTraining, Experiment, ExperimentConfig, Method,
};
use scatterloc::mtl::sim::LosModel;
use scatterloc::native::run_experiment_parallel;
use scatterloc::Error;

fn run(cfg: &ExperimentConfig, threads: usize) -> scatterloc::mtl::experiment::ExperimentResult {
    run_experiment_parallel(cfg, threads, &AtomicBool::new(false), |_, _| {}).unwrap()
}

fn curve(r: &[Curve], m: Method) -> &Curve {
    r.iter().find(|c| c.spec.method == m).unwrap()
}

/// Spec check 6 on the Fig. 3 setting: for every realisation, N_u ∈ {2, 4, 6} and every T_e the
/// size rule and Bayesian MTL with i.c.b and T_b(N_u) (M8) return the same detections; P_FA
/// grows with N_u (N_u = 6 gives very high false alarms, as in [AMB]).
#[test]
fn fig3_size_rule_and_icb_are_identical() {
    let mut cfg = ExperimentConfig::new(Experiment::Va);
    cfg.realisations = 12;
    let r = run(&cfg, 0);
    assert_eq!(r.disagreements, 0);
    assert_eq!(r.curves.len(), 6);
    for pair in r.curves.chunks(2) {
        assert_eq!(pair[0].spec.method, Method::SizeRule);
        assert_eq!(pair[1].spec.method, Method::Icb);
        assert_eq!(pair[0].points, pair[1].points);
    }
    let max_fa = |c: &Curve| c.points.iter().map(|p| p.p_fa).fold(0.0, f64::max);
    let (fa2, fa6) = (max_fa(&r.curves[1]), max_fa(&r.curves[5]));
    assert!(fa6 > 0.5 && fa6 > fa2, "P_FA N_u=2 {fa2}, N_u=6 {fa6}");
    // A larger T_e admits more ellipses: more false alarms at the widest gate, and (N_u = 2, 4)
    // more detections. For N_u = 6, P_D peaks near T_e = 1 and then falls slightly: ghosts
    // within the merge radius that share two of a target's pairs win the final merge on J.
    for c in &r.curves {
        let (first, last) = (c.points[0], *c.points.last().unwrap());
        assert!(last.p_fa >= first.p_fa, "{}", c.label);
        if c.spec.n_u != Some(6) {
            assert!(last.p_d > first.p_d, "{}", c.label);
        }
    }
}

/// Fig. 4: sweeping T_b, the i.c.b model (p_u = 0.5329 > 0.5) picks up false alarms before
/// detections — its first non-empty threshold has P_FA > P_D — while the PPP model detects
/// before it false-alarms (spec §8's expectation; [A] says nothing about the PPP curve's
/// order). Also: P_D and the number of estimates never decrease with T_b at the
/// end of the sweep (all thresholds pass).
#[test]
fn fig4_icb_false_alarms_before_detections_ppp_not() {
    let mut cfg = ExperimentConfig::new(Experiment::Vb);
    cfg.realisations = 12;
    cfg.sweep = grid(0.0, 12.0, 1.0);
    let r = run(&cfg, 0);
    let first = |c: &Curve| *c.points.iter().find(|p| p.estimates > 0).unwrap();
    let icb = first(curve(&r.curves, Method::Icb));
    let ppp = first(curve(&r.curves, Method::Ppp));
    assert!(icb.p_fa > 0.5 && icb.p_fa > icb.p_d, "i.c.b {icb:?}");
    assert!(ppp.p_d > 0.1 && ppp.p_fa < ppp.p_d, "PPP {ppp:?}");
    // At T_b = 0 nothing passes (L_b > 0 for every candidate).
    assert!(r.curves.iter().all(|c| c.points[0].estimates == 0));
}

/// Fig. 5, as docs/reproduction.md reports it (verdict "differs"): at low T_b the genie
/// (Algorithm 1 on the true matchings) misses **more** than Bayesian MTL — 1 − P_D 0.86 vs 0.75
/// at T_b = 2, a P_D gap MTL − genie of +0.11 — and at high T_b the two end close (0.160 vs
/// 0.150 for T_b ≥ 11: a gap of −0.01); the genie has no false alarms. Those numbers are from
/// the CLI run of 100 realisations, seed 1 (`mtl roc --experiment vc`).
///
/// Here: 8 seeds × 2 realisations (the 16 realisations of the former one-seed test, so the same
/// run time), each seed a group of 2·K = 4 targets. The gap `d` is the mean of the groups'
/// gaps and its standard error is `sd(d_g)/√8` over the groups (the realisations are
/// independent; the two methods see the same scenes, so the gap is a paired difference). With
/// the SE floored at one target in all (1/32), asserted:
/// - at T_b = 2 and 20 the gap is within 3 SE of the docs' value (+0.11 and −0.01);
/// - at T_b = 2 the gap is positive: the genie is not a benchmark there, the docs' verdict.
///
/// Seeds 1–8 give +0.188 (SE 0.062) at T_b = 2 and +0.000 (SE 0.047) at T_b = 20; the first
/// realisation of each of seeds 1–48 gives +0.104 (SE 0.030) and +0.021 (SE 0.033).
#[test]
fn fig5_genie_misses_more_at_low_threshold_as_documented() {
    const SEEDS: std::ops::RangeInclusive<u64> = 1..=8;
    // (T_b, the gap P_D(MTL) − P_D(genie) that docs/reproduction.md reports at it)
    const DOCS: [(f64, f64); 2] = [(2.0, 0.86 - 0.75), (20.0, 0.150 - 0.160)];
    let mut gaps = vec![Vec::new(); DOCS.len()];
    let mut targets = 0;
    for seed in SEEDS {
        let mut cfg = ExperimentConfig::new(Experiment::Vc);
        cfg.realisations = 2;
        cfg.seed = seed;
        cfg.sweep = DOCS.iter().map(|d| d.0).collect();
        let r = run(&cfg, 0);
        let (mtl, genie) = (
            curve(&r.curves, Method::Ppp),
            curve(&r.curves, Method::Genie),
        );
        targets += r.targets;
        for (j, (a, g)) in mtl.points.iter().zip(&genie.points).enumerate() {
            assert_eq!(g.false_alarms, 0, "seed {seed}: genie false alarms");
            gaps[j].push((a.detections as f64 - g.detections as f64) / r.targets as f64);
        }
    }
    for ((t_b, want), d) in DOCS.iter().zip(&gaps) {
        let n = d.len() as f64;
        let mean = d.iter().sum::<f64>() / n;
        let sd = (d.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
        let se = (sd / n.sqrt()).max(1.0 / targets as f64);
        println!("T_b {t_b}: P_D gap MTL − genie {mean:+.3} (SE {se:.3}), docs {want:+.3}");
        assert!(
            (mean - want).abs() <= 3.0 * se,
            "T_b {t_b}: gap {mean:+.3} vs the docs' {want:+.3} ± 3 SE ({se:.3})"
        );
    }
    let low = gaps[0].iter().sum::<f64>();
    assert!(low > 0.0, "T_b 2: the genie does not miss more ({low})");
}

/// Results depend on the seed only: 1 thread, 2 threads and the sequential driver agree
/// bitwise, including the empirical model's training draws.
#[test]
fn results_are_independent_of_thread_count() {
    let mut cfg = ExperimentConfig::new(Experiment::Vb);
    cfg.realisations = 6;
    cfg.sweep = vec![3.0, 6.0, 12.0];
    cfg.empirical = Some(EmpiricalTraining {
        cells: 10,
        scenes: 50,
    });
    let a = run(&cfg, 1);
    let b = run(&cfg, 2);
    let c = run_sequential(&cfg, |_, _| {}, || false).unwrap();
    assert_eq!(a, b);
    assert_eq!(a, c);
    assert_eq!(a.curves.len(), 3);
    let mut other = cfg.clone();
    other.seed = 2;
    assert_ne!(run(&other, 0).curves, a.curves);
}

#[test]
fn bad_configurations_are_named_errors() {
    let ok = ExperimentConfig::new(Experiment::Va);
    let err = |f: &dyn Fn(&mut ExperimentConfig)| {
        let mut c = ok.clone();
        f(&mut c);
        c.validate().unwrap_err()
    };
    assert!(matches!(
        err(&|c| c.realisations = 0),
        Error::SizeLimit {
            field: "realisations",
            ..
        }
    ));
    assert!(matches!(
        err(&|c| c.sweep = vec![]),
        Error::SizeLimit { field: "sweep", .. }
    ));
    assert!(
        matches!(err(&|c| c.sweep[3] = -1.0), Error::OutOfRange { field, .. } if field == "sweep[3]")
    );
    assert!(matches!(
        err(&|c| c.sweep[0] = f64::NAN),
        Error::OutOfRange { .. }
    ));
    assert!(
        matches!(err(&|c| c.n_u = vec![2, 10]), Error::OutOfRange { field, .. } if field == "n_u[1]")
    );
    assert!(matches!(err(&|c| c.t_e = -3.0), Error::OutOfRange { field, .. } if field == "t_e"));
    assert!(
        matches!(err(&|c| c.icb_p_u = 1.0), Error::OutOfRange { field, .. } if field == "icb_p_u")
    );
    assert!(
        matches!(err(&|c| c.settings.los = LosModel::Discs), Error::OutOfRange { field, .. } if field == "los")
    );
    assert!(
        matches!(err(&|c| c.settings.p_d = 2.0), Error::OutOfRange { field, .. } if field == "p_d")
    );
    assert!(matches!(
        err(&|c| c.empirical = Some(EmpiricalTraining {
            cells: 0,
            scenes: 1
        })),
        Error::SizeLimit {
            field: "empirical.cells",
            ..
        }
    ));
    let cancelled = run_experiment_parallel(&ok, 1, &AtomicBool::new(true), |_, _| {});
    assert_eq!(cancelled.unwrap_err(), Error::Cancelled);
    assert_eq!(
        run_sequential(&ok, |_, _| {}, || true).unwrap_err(),
        Error::Cancelled
    );
}
