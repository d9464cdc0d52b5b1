#![cfg(not(target_arch = "wasm32"))]
//! Tracking, spec check 11 (the EKF against the PCRLB) and NEES consistency of the EKF, fast
//! profile. Monte Carlo tolerances are derived from the Monte Carlo standard error and stated
//! where used. Runs too slow for a debug build are `#[ignore]` (run them with
//! `cargo test --release --test tracking -- --ignored check11::`); a smaller variant of each always
//! runs.
//! (Split from the former `tracking.rs`.)

use crate::common;

use common::sensors_model as model;
use common::tracking::{at, study, FAST_STEP_S};
use scatterloc::math::Real;
use scatterloc::track::{finish, run_chunk, run_sequential, MonteCarloConfig, PartialSums};
use scatterloc::track::{MonteCarloResult, StudySums, TrackScenario};

/// Runs the three scenarios and checks spec check 11:
/// - ε_EKF ≥ ε_PCRLB up to Monte Carlo error at every step: the sample RMSE of N independent
///   2-D Gaussian errors has relative sd ≤ √(1/(2N)) (‖e‖² has variance 2 tr Σ² ≤ 2 (tr Σ)²);
///   N = trajectories (noise runs of one trajectory share its initial error), 3 sd;
/// - scenario I: ε_EKF/ε_PCRLB ≤ 1.05 for 1 ≤ t ≤ 5 s;
/// - at 10 s the ratio exceeds 1.2 in II and III.
///
/// Returns the ratios at 10 s and their delete-a-group jackknife standard errors: the study is
/// run chunk by chunk (as `run_sequential` runs it, so the curves are the same), each chunk of
/// [`scatterloc::track::CHUNK_TRAJECTORIES`] trajectories a group; with chunk g left out the
/// ratio is `q₋g`, and `SE² = (G − 1)/G · Σ_g (q₋g − mean q₋·)²`. The SE covers both the EKF's
/// and the bound's Monte Carlo error (the same truths enter both) and needs no Gaussian
/// assumption (near the nodes the squared errors are heavy-tailed).
fn check11(trajectories: usize, noise_runs: usize) -> ([Real; 3], [Real; 3]) {
    let model = model();
    let slack = 1.0 - 3.0 * (1.0 / (2.0 * trajectories as Real)).sqrt();
    let mut se = [0.0; 3];
    let at10 = TrackScenario::ALL.map(|s| {
        let cfg = study(s, FAST_STEP_S, trajectories, noise_runs);
        let parts: Vec<PartialSums> = (0..cfg.chunk_count())
            .map(|c| run_chunk(&model, &cfg, c).unwrap())
            .collect();
        let result = |skip: Option<usize>| -> MonteCarloResult {
            let mut sums = StudySums::new(cfg.steps);
            for (g, p) in parts.iter().enumerate() {
                if Some(g) != skip {
                    sums.add(p);
                }
            }
            finish(&cfg, &sums).unwrap()
        };
        let r = result(None);
        assert_eq!(r.failed_runs, 0);
        let ratio: Vec<Real> = r
            .rmse_m
            .iter()
            .zip(&r.rmse_pcrlb_m)
            .map(|(e, p)| e / p.unwrap())
            .collect();
        for (n, q) in ratio.iter().enumerate() {
            assert!(
                *q >= slack,
                "check 11 {}: ε_EKF/ε_PCRLB = {q} < {slack} at step {n}",
                s.name()
            );
        }
        if s == TrackScenario::I {
            for (n, q) in ratio.iter().enumerate().take(51).skip(10) {
                assert!(*q <= 1.05, "check 11 I: ratio {q} > 1.05 at step {n}");
            }
        } else {
            assert!(
                ratio[100] > 1.2,
                "check 11 {}: ratio at 10 s {} ≤ 1.2",
                s.name(),
                ratio[100]
            );
        }
        let loo: Vec<Real> = (0..parts.len())
            .map(|g| {
                let r = result(Some(g));
                r.rmse_m[100] / r.rmse_pcrlb_m[100].unwrap()
            })
            .collect();
        let g = loo.len() as Real;
        let mean = loo.iter().sum::<Real>() / g;
        let row = TrackScenario::ALL.iter().position(|x| *x == s).unwrap();
        se[row] = ((g - 1.0) / g * loo.iter().map(|q| (q - mean).powi(2)).sum::<Real>()).sqrt();
        println!(
            "check 11 {}: ratio at 10 s {:.4}, jackknife SE {:.4}",
            s.name(),
            ratio[100],
            se[row]
        );
        ratio[100]
    });
    (at10, se)
}

/// The spec's three reference seeds at the fast profile, ε_EKF/ε_PCRLB at 10 s (spec check 11:
/// I 1.17–1.20, II 1.60–2.05, III 1.35–1.36).
const SPEC_REFERENCE_AT_10S: [(Real, Real); 3] = [(1.17, 1.20), (1.60, 2.05), (1.35, 1.36)];

/// Spec check 11 at the spec's size, 1000 × 10 runs (3·10⁶ EKF steps: ≈ 0.5 s in release, about
/// a minute in a debug build), seed 1. Besides check 11 itself ([`check11`]):
/// - in II and III the 10 s ratio exceeds 1.2 by more than 2 of its jackknife SEs (one-sided
///   97.7 %: the spec's threshold holds beyond the Monte Carlo error of this run, not by luck);
/// - each 10 s ratio lies within 4 SE of the range of the spec's reference seeds (a run of the
///   same study with another seed scatters by its SE; the spec does not say which seeds or
///   implementation gave its ranges, so this checks consistency, not identity).
///
/// Seed 1 gives I 1.187 (SE 0.013), II 1.787 (SE 0.112), III 1.288 (SE 0.027) at 10 s. II's SE is
/// 6 %, 2.8× the Gaussian √(1/(2N)) = 2.2 %: near the nodes the errors are heavy-tailed, as the
/// spread over seeds 1–5 (II 1.51–1.81, III 1.27–1.35; I ≤ 1.018 on [1, 5] s) shows. (The former
/// test pinned seed 1's own ratios, II 1.79 and III 1.29, to an unsourced ±0.01.)
#[test]
#[ignore = "3e6 EKF steps: run with --release -- --ignored"]
fn check11_ekf_vs_pcrlb_fast_profile() {
    let (at10, se) = check11(1000, 10);
    for (j, s) in TrackScenario::ALL.iter().enumerate() {
        if *s != TrackScenario::I {
            assert!(
                at10[j] - 2.0 * se[j] > 1.2,
                "check 11 {}: ratio {} − 2 SE ({}) ≤ 1.2",
                s.name(),
                at10[j],
                se[j]
            );
        }
        let (lo, hi) = SPEC_REFERENCE_AT_10S[j];
        assert!(
            at10[j] >= lo - 4.0 * se[j] && at10[j] <= hi + 4.0 * se[j],
            "check 11 {}: ratio {} outside the spec's reference [{lo}, {hi}] ± 4 SE ({})",
            s.name(),
            at10[j],
            se[j]
        );
    }
}

/// Spec check 11 at 200 × 5 runs (always run). Over seeds 1–8 at this size the scenario I ratio
/// stays ≤ 1.04 on [1, 5] s and the 10 s ratios are II 1.39–1.79, III 1.25–1.39, so the
/// thresholds of check 11 hold with margin; the lower bound uses N = 200 (slack 15 %).
#[test]
fn check11_ekf_vs_pcrlb_small() {
    check11(200, 5);
}

/// The two-sided band of the mean NEES of `n_runs` independent runs of a consistent filter
/// (4-D state): `χ²₄ₙ/n` quantiles for standard normal quantile `z`, by Wilson–Hilferty
/// (`k(1 − 2/(9k) ± z√(2/(9k)))³/n`, `k = 4n`; the skewness-corrected normal approximation
/// `4n ± z√(8n) + (2/3)(z² − 1)` agrees to 1e-3 for n ≥ 1000).
fn nees_band(n_runs: usize, z: Real) -> (Real, Real) {
    let k = 4.0 * n_runs as Real;
    let wh = |z: Real| k * (1.0 - 2.0 / (9.0 * k) + z * (2.0 / (9.0 * k)).sqrt()).powi(3);
    (wh(-z) / n_runs as Real, wh(z) / n_runs as Real)
}

/// NEES consistency on scenario I (fast profile, 1000 independent runs per seed: one noise run
/// per trajectory), seeds 1–5.
///
/// For a consistent filter the mean NEES of N runs at one step is χ²₄ₙ/N (mean 4, sd √(8/N)).
/// The old test asked that it lie in the 99 % band at ≥ 90 % of the steps and ≥ 95 % from
/// 0.6 s, fractions set from seeds 1–6; the steps are correlated (the same runs), so a binomial
/// SE for such fractions does not hold. Asserted instead, for every seed:
/// - from t = 0.6 s on, every step's mean NEES lies in the two-sided 1 − 10⁻⁶ band
///   (z = 4.892: [3.578, 4.453] for N = 1000). By the union bound, which needs no independence
///   between steps, a consistent filter fails this with probability ≤ 95 steps · 5 seeds ·
///   10⁻⁶ < 10⁻³. Seeds 1–5: late minima 3.70–3.84, maxima 4.17–4.29;
/// - NEES(t₀) is the prior's own, (x(t₀) − x̄₀)ᵀ P₀⁻¹ (x(t₀) − x̄₀) ~ χ²₄ exactly: the same band;
/// - the transient: the first updates from the wide prior (P₀ = 0.1 m² against sub-centimetre
///   measurements) are over-confident through the linearisation error: mean NEES at step 1
///   far above the band (seeds 1–5: 54–62; steps 2–5 ≈ 34–40, 9–10, 4.7–5.1, 4.2–4.5).
///
/// Pooled over the five seeds (5000 runs) every late step is in the 1 − 10⁻⁶ band of N = 5000
/// ([3.807, 4.199]; the union bound over 95 steps again gives < 10⁻⁴), which would reveal a
/// bias of the NEES of ≈ 5 % that a single seed cannot.
#[test]
fn nees_consistent_on_scenario_i() {
    let model = model();
    let (n_runs, seeds) = (1000, 1..=5u64);
    let z = 4.891_638_475_714_8; // standard normal 1 − 5·10⁻⁷ quantile (two-sided 10⁻⁶)
    let (lo, hi) = nees_band(n_runs, z);
    assert!(
        (lo - 3.5776).abs() < 1e-3 && (hi - 4.4530).abs() < 1e-3,
        "band [{lo}, {hi}]"
    );
    // The 99 % band of the old test, as a check of `nees_band` against its quoted values.
    let (lo99, hi99) = nees_band(n_runs, 2.575_829_303_548_900_4);
    assert!((lo99 - 3.7734).abs() < 1e-3 && (hi99 - 4.2341).abs() < 1e-3);
    let late = at(0.6, FAST_STEP_S);
    let mut pooled = Vec::new();
    for seed in seeds.clone() {
        let r = run_sequential(
            &model,
            &MonteCarloConfig {
                seed,
                ..study(TrackScenario::I, FAST_STEP_S, n_runs, 1)
            },
            |_, _| true,
        )
        .unwrap();
        assert_eq!(r.runs, n_runs);
        println!("seed {seed}: NEES {:.3?}", &r.nees[..8]);
        assert!(
            (lo..=hi).contains(&r.nees[0]),
            "seed {seed}: NEES(t0) = {}",
            r.nees[0]
        );
        assert!(
            r.nees[1] > hi,
            "seed {seed}: NEES(t1) = {} not over-confident",
            r.nees[1]
        );
        for (n, v) in r.nees.iter().enumerate().skip(late) {
            assert!(
                (lo..=hi).contains(v),
                "seed {seed}: mean NEES {v} at step {n} outside [{lo}, {hi}]"
            );
        }
        pooled.push(r.nees);
    }
    let k = pooled.len() as Real;
    let (lo, hi) = nees_band(n_runs * pooled.len(), z);
    for n in late..pooled[0].len() {
        let v = pooled.iter().map(|r| r[n]).sum::<Real>() / k;
        assert!(
            (lo..=hi).contains(&v),
            "seeds pooled: mean NEES {v} at step {n} outside [{lo}, {hi}]"
        );
    }
}
