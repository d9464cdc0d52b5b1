//! C8 checks 1–5 of the snapshot estimator, and its config and input errors.
//!
//! Tolerances of the Monte Carlo checks come from the standard error: an RMSE over `n` trials
//! has relative standard error ≈ `1/√(2n)`. The default run uses fewer trials than the spec's
//! (fast in debug); the full counts are the `#[ignore]`d `*_full` tests (release, via
//! scripts/reproduce.sh). `--nocapture` prints the measured values.

mod masked;

use alloc::vec;
use alloc::vec::Vec;

use nalgebra::DMatrix;
use rand::SeedableRng as _;
use rand_distr::{Distribution, StandardNormal, Uniform};
use rand_pcg::Pcg64;

use super::*;
use crate::channel::band::cis;
use crate::channel::{Band, Layout, Recording};
use crate::error::{limits, Error};
use crate::math::{cos, ln, round, sin, sqrt, Complex, Real, PI, SPEED_OF_LIGHT};

const N: usize = 241;
const B: Real = 120e6;
const DF: Real = B / (N as Real - 1.0);

fn band() -> Band {
    Band::flat(N, DF).unwrap()
}

fn cn(rng: &mut Pcg64, var: Real) -> Complex {
    let s = sqrt(var / 2.0);
    let a: Real = StandardNormal.sample(rng);
    let b: Real = StandardNormal.sample(rng);
    Complex::new(a * s, b * s)
}

fn phase(rng: &mut Pcg64) -> Complex {
    let u: Real = Uniform::new(0.0, 2.0 * PI).unwrap().sample(rng);
    Complex::new(cos(u), sin(u))
}

/// `H[n] = Σ α_i e^{−j2πf_nτ_i} + w[n]`, `w ~ CN(0, var)`.
fn response(b: &Band, paths: &[(Real, Complex)], var: Real, rng: &mut Pcg64) -> Vec<Complex> {
    b.freq_hz
        .iter()
        .map(|&f| {
            let mut h = Complex::new(0.0, 0.0);
            for &(t, a) in paths {
                h += a * cis(-2.0 * PI * f * t);
            }
            if var > 0.0 {
                h += cn(rng, var);
            }
            h
        })
        .collect()
}

/// The joint delay bounds (s) from the inverse Fisher matrix of C1, written independently of
/// [`fisher_matrix`]: the derivative columns built explicitly, `F = (2/σ²) Re(DᴴD)` by
/// nalgebra, inverted by nalgebra.
fn joint_bounds(b: &Band, paths: &[(Real, Complex)], var: Real) -> Vec<Real> {
    let k = paths.len();
    let n = b.len();
    let mut d = DMatrix::<Complex>::zeros(n, 3 * k);
    for (i, &(t, a)) in paths.iter().enumerate() {
        for (row, &f) in b.freq_hz.iter().enumerate() {
            let e = cis(-2.0 * PI * f * t);
            d[(row, 3 * i)] = a * e * Complex::new(0.0, -2.0 * PI * f);
            d[(row, 3 * i + 1)] = e;
            d[(row, 3 * i + 2)] = e * Complex::new(0.0, 1.0);
        }
    }
    let g = d.adjoint() * &d;
    let f = g.map(|v| 2.0 / var * v.re);
    let inv = f.try_inverse().unwrap();
    (0..k).map(|i| sqrt(inv[(3 * i, 3 * i)])).collect()
}

/// RMSE (m of path length) of the strongest path's delay (modulo `1/Δf`) over the trials that
/// detect a path,
/// the C4 bound (m), the outlier rate among detections (|error| > 1/(2B)) and the miss rate.
fn single_path(snr_db: Real, trials: usize, seed: u64) -> (Real, Real, Real, Real) {
    let b = band();
    let mut est = Estimator::new(b.clone(), EstimatorConfig::default()).unwrap();
    let mut rng = Pcg64::seed_from_u64(seed);
    let snr = crate::math::db_to_linear(snr_db);
    let var = N as Real / snr;
    let (mut se, mut outl, mut miss) = (0.0, 0usize, 0usize);
    for _ in 0..trials {
        let tau: Real = Uniform::new(0.0, 200e-9).unwrap().sample(&mut rng);
        let a = phase(&mut rng);
        let h = response(&b, &[(tau, a)], var, &mut rng);
        let r = est.estimate(&h, None, &[]).unwrap();
        let best = r
            .paths
            .iter()
            .max_by(|x, y| x.alpha.norm_sqr().total_cmp(&y.alpha.norm_sqr()));
        let Some(best) = best else {
            miss += 1;
            continue;
        };
        // Delays are ambiguous modulo 1/Δf (C1): a path 0.1 ns after the window's start is
        // estimated just before it as often as after, i.e. folded to the window's end.
        let span = b.unambiguous_s();
        let d = best.delay_s - tau;
        let err = d - span * crate::math::round(d / span);
        if err.abs() > 0.5 / B {
            outl += 1;
        }
        se += err * err;
    }
    let det = (trials - miss).max(1) as Real;
    let rmse = sqrt(se / det) * SPEED_OF_LIGHT;
    let bound = b.delay_bound_s(snr) * SPEED_OF_LIGHT;
    (
        rmse,
        bound,
        outl as Real / det,
        miss as Real / trials as Real,
    )
}

fn check1(trials: usize) {
    // 10 % (the spec's margin); plus 3 standard errors of the RMSE estimate: 1/√(2n) relative.
    let tol = 0.10 + 3.0 / sqrt(2.0 * trials as Real);
    for seed in [1u64, 2, 3] {
        for snr_db in [20.0, 30.0] {
            let (rmse, bound, out, miss) = single_path(snr_db, trials, seed);
            assert_eq!(miss, 0.0);
            std::println!(
                "C8.1 seed {seed} SNR {snr_db} dB: RMSE {:.4} m, C4 {:.4} m, ratio {:.3}, outliers {out}",
                rmse,
                bound,
                rmse / bound
            );
            assert!((rmse / bound - 1.0).abs() <= tol, "ratio {}", rmse / bound);
        }
        let (rmse, bound, out, miss) = single_path(10.0, trials, seed);
        std::println!("C8.1 seed {seed} SNR 10 dB: RMSE {rmse:.4} m over detections, C4 {bound:.4} m, outlier rate {out:.4}, miss rate {miss:.4} (γ = {:.1} > SNR 10)", ln(1024.0 / 1e-3));
        assert!(rmse.is_finite() && rmse < SPEED_OF_LIGHT * 2e-6);
    }
}

/// C4 itself: 9.7 cm at 20 dB and 3.1 cm at 30 dB for N = 241 over 120 MHz.
#[test]
fn c4_bound_values() {
    let b = band();
    let c20 = b.delay_bound_s(100.0) * SPEED_OF_LIGHT;
    let c30 = b.delay_bound_s(1000.0) * SPEED_OF_LIGHT;
    assert!((c20 - 0.097).abs() < 0.001, "{c20}");
    assert!((c30 - 0.031).abs() < 0.0005, "{c30}");
    let want = DF * DF * ((N * N) as Real - 1.0) / 12.0;
    assert!((b.beta_sq() / want - 1.0).abs() < 1e-12);
}

/// C8 check 1 (fast: 300 trials per seed and SNR).
#[test]
fn c8_1_single_path() {
    check1(300);
}

/// C8 check 1 at the spec's 2000 trials.
#[test]
#[ignore = "slow in debug (2000 trials × 3 seeds × 3 SNRs); run in release by scripts/reproduce.sh"]
fn c8_1_single_path_full() {
    check1(2000);
}

fn check2(p_fa: Real, snapshots: usize, seed: u64) -> Real {
    let b = band();
    let cfg = EstimatorConfig {
        p_fa,
        ..EstimatorConfig::default()
    };
    let mut est = Estimator::new(b.clone(), cfg).unwrap();
    let mut rng = Pcg64::seed_from_u64(seed);
    let mut hits = 0usize;
    let mut nv = 0.0;
    for _ in 0..snapshots {
        let h = response(&b, &[], 1.0, &mut rng);
        let r = est.estimate(&h, None, &[]).unwrap();
        nv += r.noise_var;
        if !r.paths.is_empty() {
            hits += 1;
        }
    }
    let frac = hits as Real / snapshots as Real;
    std::println!(
        "C8.2 seed {seed} P_fa {p_fa}: detection fraction {frac:.5} over {snapshots} (ratio {:.3}); mean σ̂² {:.4} (true 1)",
        frac / p_fa,
        nv / snapshots as Real
    );
    frac
}

/// C8 check 2 (fast: P_fa = 10⁻², 10⁴ noise-only snapshots, ≈ 100 expected detections, so a
/// factor 2 is > 4 standard errors).
#[test]
fn c8_2_false_alarms() {
    for seed in [11u64, 12] {
        let f = check2(1e-2, 10_000, seed);
        assert!((0.5e-2..=2e-2).contains(&f), "{f}");
    }
}

/// C8 check 2 at the default P_fa = 10⁻³ over 10⁵ snapshots (≈ 100 expected).
#[test]
#[ignore = "10⁵ snapshots: slow in debug; run in release by scripts/reproduce.sh"]
fn c8_2_false_alarms_full() {
    let f = check2(1e-3, 100_000, 13);
    assert!((0.5e-3..=2e-3).contains(&f), "{f}");
}

/// The noise estimate (median of the periodogram / ln 2) is unbiased on noise to its standard
/// error: the mean of σ̂² over 2000 noise-only snapshots (max_paths irrelevant: noise only).
#[test]
fn median_noise_unbiased() {
    let b = band();
    let mut est = Estimator::new(b.clone(), EstimatorConfig::default()).unwrap();
    let mut rng = Pcg64::seed_from_u64(5);
    let n = 2000;
    let v: Vec<Real> = (0..n)
        .map(|_| {
            let h = response(&b, &[], 2.5, &mut rng);
            est.estimate(&h, None, &[]).unwrap().noise_var
        })
        .collect();
    let mean = v.iter().sum::<Real>() / n as Real;
    let sd = sqrt(v.iter().map(|x| (x - mean) * (x - mean)).sum::<Real>() / (n - 1) as Real);
    let se = sd / sqrt(n as Real);
    std::println!("σ̂² mean {mean:.5} (true 2.5), sd {sd:.4}, SE {se:.5}");
    // 4 SE plus the O(1/N) small-sample bias of a median (≤ 1/(2·241) relative)
    assert!(
        (mean - 2.5).abs() <= 4.0 * se + 2.5 / (2.0 * N as Real),
        "{mean}"
    );
}

/// Found-rate and RMSE of each of `truth`'s paths listed in `watch` (nearest estimate within
/// 0.5/B), against the joint bound (its mean square over the trials' random path phases: the
/// two-path bound depends on the paths' relative phase).
fn multi(
    truth: &[(Real, Complex)],
    var: Real,
    watch: &[usize],
    trials: usize,
    seed: u64,
) -> Vec<(Real, Real, Real)> {
    let b = band();
    let mut est = Estimator::new(b.clone(), EstimatorConfig::default()).unwrap();
    let mut rng = Pcg64::seed_from_u64(seed);
    let mut bsq = vec![0.0; watch.len()];
    let mut found = vec![0usize; watch.len()];
    let mut se = vec![0.0; watch.len()];
    for _ in 0..trials {
        let ph: Vec<(Real, Complex)> = truth
            .iter()
            .map(|&(t, a)| (t, a * phase(&mut rng)))
            .collect();
        let h = response(&b, &ph, var, &mut rng);
        let r = est.estimate(&h, None, &[]).unwrap();
        let bd = joint_bounds(&b, &ph, var);
        for (w, &i) in watch.iter().enumerate() {
            bsq[w] += bd[i] * bd[i] / trials as Real;
            let t = truth[i].0;
            let near = r
                .paths
                .iter()
                .map(|p| p.delay_s - t)
                .min_by(|x, y| x.abs().total_cmp(&y.abs()));
            if let Some(e) = near.filter(|e| e.abs() < 0.5 / B) {
                found[w] += 1;
                se[w] += e * e;
            }
        }
    }
    watch
        .iter()
        .enumerate()
        .map(|(w, _)| {
            let f = found[w] as Real / trials as Real;
            let rmse = sqrt(se[w] / found[w].max(1) as Real);
            (f, rmse * SPEED_OF_LIGHT, sqrt(bsq[w]) * SPEED_OF_LIGHT)
        })
        .collect()
}

fn check3(trials: usize) {
    let var = N as Real / 1000.0; // 30 dB each
    let truth = [
        (80e-9, Complex::new(1.0, 0.0)),
        (80e-9 + 1.0 / B, Complex::new(1.0, 0.0)),
    ];
    let tol = 1.5 * (1.0 + 3.0 / sqrt(2.0 * trials as Real));
    for seed in [21u64, 22, 23] {
        for (i, (f, rmse, bound)) in multi(&truth, var, &[0, 1], trials, seed)
            .into_iter()
            .enumerate()
        {
            std::println!("C8.3 seed {seed} path {i}: found {f:.3}, RMSE {rmse:.4} m, two-path bound {bound:.4} m, ratio {:.3}", rmse / bound);
            assert!(f >= 0.95, "found {f}");
            assert!(rmse <= tol * bound, "ratio {}", rmse / bound);
        }
    }
}

/// C8 check 3 (fast: 200 trials per seed).
#[test]
fn c8_3_two_paths() {
    check3(200);
}

/// C8 check 3 at 2000 trials per seed.
#[test]
#[ignore = "slow in debug; run in release by scripts/reproduce.sh"]
fn c8_3_two_paths_full() {
    check3(2000);
}

fn check4(trials: usize) {
    let var = 1.0;
    let amp = |snr_db: Real| {
        Complex::new(
            sqrt(crate::math::db_to_linear(snr_db) * var / N as Real),
            0.0,
        )
    };
    let los = 50e-9;
    let truth = [
        (los, amp(60.0)),
        (los + 12e-9, amp(50.0)),
        (los + 50e-9, amp(45.0)),
        (los + 70e-9, amp(40.0)),
        (los + 4.0 / B, amp(25.0)),
    ];
    let tol = 1.5 * (1.0 + 3.0 / sqrt(2.0 * trials as Real));
    for seed in [31u64, 32, 33] {
        let (f, rmse, bound) = multi(&truth, var, &[4], trials, seed)[0];
        std::println!("C8.4 seed {seed}: mobile found {f:.3}, RMSE {rmse:.4} m, joint bound {bound:.4} m, ratio {:.3}", rmse / bound);
        assert!(f >= 0.95, "found {f}");
        assert!(rmse <= tol * bound, "ratio {}", rmse / bound);
    }
}

/// C8 check 4 (fast: 150 trials per seed).
#[test]
fn c8_4_weak_mobile_path() {
    check4(150);
}

/// C8 check 4 at 2000 trials per seed.
#[test]
#[ignore = "slow in debug; run in release by scripts/reproduce.sh"]
fn c8_4_weak_mobile_path_full() {
    check4(2000);
}

/// C8 check 5: the same channel as a CIR (ideal band pulse, Δt = 1/(2B), M = 1024 taps) and as
/// a CFR at the CIR's in-band bins gives the same paths to within 10⁻² of the bound. The
/// taps are the band-limited (periodic, as from a sounder's IFFT) sinc
/// `Σ_q sinc(B(t − τ − qMΔt))`, written as its Fourier sum, so no truncation leaks.
/// A one-snapshot, one-link CIR recording of `m` taps at spacing `dt` from `t0` holding
/// `paths` band-limited to `B` (the sum over the DFT bins inside the band; `B/2 = kmax/T`
/// exactly, the edge bins carry half the weight), written independently of the reader.
fn cir_recording(m: usize, dt: Real, t0: Real, paths: &[(Real, Complex)]) -> Recording {
    let big_t = m as Real * dt;
    let kmax = round(B * big_t / 2.0) as i64;
    let taps: Vec<Complex> = (0..m)
        .map(|i| {
            let t = t0 + i as Real * dt;
            let mut acc = Complex::new(0.0, 0.0);
            for &(tau, a) in paths {
                for k in -kmax..=kmax {
                    let wgt = if k.abs() == kmax { 0.5 } else { 1.0 };
                    acc += a * cis(2.0 * PI * k as Real / big_t * (t - tau)) * (wgt / (B * big_t));
                }
            }
            acc
        })
        .collect();
    Recording {
        t_s: vec![0.0],
        links: vec![[0, 0]],
        layout: Layout::Cir {
            tap0_s: t0,
            tap_spacing_s: dt,
            pulse: None,
        },
        samples: taps,
        noise_var: None,
        synchronized: None,
    }
}

/// Issue 37 item 3: a CIR whose taps start at `tap0_s ≠ 0` (a UWB accumulator excerpt around
/// the first path) sees the delays `[tap0, tap0 + MΔt)`, and they are searched there — they
/// came out one window length early (16 taps from 100 ns: 16.7 and 66.7 ns for paths at 150
/// and 200 ns; 64 taps from 1 µs: 516.7 and 133.3 ns for 1050 and 1200 ns). Noise-free taps
/// at a nominal noise: within 10⁻³/B of the truth.
#[test]
fn cir_delays_are_searched_in_the_tap_window() {
    let cases: [(usize, Real, Real, [Real; 2]); 4] = [
        (16, 1.0 / B, 100e-9, [150e-9, 200e-9]),
        (64, 1.0 / B, 1e-6, [1050e-9, 1200e-9]),
        (256, 1.0 / (2.0 * B), 2e-6, [2.2e-6, 2.9e-6]),
        (64, 1.0 / B, 0.0, [20e-9, 300e-9]),
    ];
    for (m, dt, t0, delays) in cases {
        let truth = [
            (delays[0], Complex::new(1.0, 0.0)),
            (delays[1], Complex::new(0.0, 0.5)),
        ];
        let rec = cir_recording(m, dt, t0, &truth);
        let (b, map) = Band::of_recording(&rec, B).unwrap();
        assert_eq!(b.delay_origin_s, t0);
        let mut h = Vec::new();
        map.fill(&rec, 0, 0, &mut h).unwrap();
        // A nominal noise: the weaker path at 40 dB (noise-free, the fit's own rounding-level
        // misfit would be detected as paths: issue 37 item 1, not this item).
        let var = b.len() as Real * 0.25e-4;
        let mut est = Estimator::new(b, EstimatorConfig::default()).unwrap();
        let e = est.estimate(&h, Some(var), &[]).unwrap();
        let got: Vec<Real> = e.paths.iter().map(|p| p.delay_s).collect();
        assert_eq!(got.len(), 2, "{m} taps from {t0}: {got:?}");
        for (g, t) in got.iter().zip(delays) {
            assert!((g - t).abs() < 1e-3 / B, "{m} taps from {t0}: {g} for {t}");
        }
    }
}

#[test]
fn c8_5_cir_equals_cfr() {
    let m = 1024usize;
    let dt = 1.0 / (2.0 * B);
    let t0 = -300e-9;
    let truth = [
        (40e-9, Complex::new(0.8, 0.3)),
        (55e-9, Complex::new(-0.2, 0.4)),
        (120e-9, Complex::new(0.1, -0.15)),
    ];
    let kmax = (m / 4) as i64;
    let rec = cir_recording(m, dt, t0, &truth);
    let (b, map) = Band::of_recording(&rec, B).unwrap();
    assert_eq!(b.len(), 2 * kmax as usize - 1);
    let mut h = Vec::new();
    map.fill(&rec, 0, 0, &mut h).unwrap();
    let mut rng = Pcg64::seed_from_u64(0);
    let cfr = response(&b, &truth, 0.0, &mut rng);
    let var = b.len() as Real * 0.1 / 1000.0; // a nominal noise: the weakest path at ≈ 20 dB
    let mut est = Estimator::new(b.clone(), EstimatorConfig::default()).unwrap();
    let a = est.estimate(&h, Some(var), &[]).unwrap();
    let c = est.estimate(&cfr, Some(var), &[]).unwrap();
    let bounds = joint_bounds(&b, &truth, var);
    assert_eq!(a.paths.len(), truth.len());
    assert_eq!(c.paths.len(), truth.len());
    for ((p, q), bd) in a.paths.iter().zip(&c.paths).zip(&bounds) {
        let d = (p.delay_s - q.delay_s).abs() / bd;
        let da = sqrt((p.alpha - q.alpha).norm_sqr()) / sqrt(q.alpha.norm_sqr());
        std::println!(
            "C8.5 τ {:.4} ns: |Δτ|/bound {d:.2e}, |Δα|/|α| {da:.2e}",
            q.delay_s * 1e9
        );
        assert!(d <= 1e-2, "{d}");
        assert!(da <= 1e-2, "{da}");
    }
}

#[test]
fn config_and_input_errors() {
    let b = band();
    let bad = |cfg: EstimatorConfig| Estimator::new(b.clone(), cfg).is_err();
    let d = EstimatorConfig::default();
    assert!(bad(EstimatorConfig { p_fa: 0.0, ..d }));
    assert!(bad(EstimatorConfig { p_fa: 1.0, ..d }));
    assert!(bad(EstimatorConfig {
        p_fa: Real::NAN,
        ..d
    }));
    assert!(bad(EstimatorConfig { oversample: 3, ..d }));
    assert!(bad(EstimatorConfig {
        oversample: 65,
        ..d
    }));
    assert!(bad(EstimatorConfig { max_paths: 0, ..d }));
    assert!(bad(EstimatorConfig {
        max_paths: limits::MAX_PATHS + 1,
        ..d
    }));
    assert!(bad(EstimatorConfig {
        window_s: Some((1e-6, 0.0)),
        ..d
    }));
    assert!(bad(EstimatorConfig {
        window_s: Some((0.0, 3e-6)),
        ..d
    }));
    let mut e = Estimator::new(b.clone(), d).unwrap();
    assert!(matches!(
        e.estimate(&[Complex::new(1.0, 0.0); 10], None, &[]),
        Err(Error::LengthMismatch {
            expected: N,
            found: 10,
            ..
        })
    ));
    let mut h = vec![Complex::new(0.0, 0.0); N];
    let z = e.estimate(&h, None, &[]).unwrap();
    assert!(z.paths.is_empty() && z.noise_var == 0.0);
    let z = e.estimate(&h, Some(1.0), &[50e-9]).unwrap();
    assert!(z.paths.is_empty());
    assert!(e.estimate(&h, Some(0.0), &[]).is_err());
    h[3] = Complex::new(Real::NAN, 0.0);
    assert!(e.estimate(&h, None, &[]).is_err());
    // Issue 37 item 7: samples whose powers overflow gave `noise_var = inf` and exit 0.
    let mut rng = Pcg64::seed_from_u64(7);
    let paths = [
        (50e-9, Complex::new(1.0, 0.0)),
        (90e-9, Complex::new(0.0, 0.3)),
    ];
    let clean = response(&b, &paths, 1e-3, &mut rng);
    for scale in [1e-100, 1e-30, 1.0, 1e30, 5e99] {
        let x: Vec<Complex> = clean.iter().map(|v| v * scale).collect();
        let got = e.estimate(&x, None, &[]).unwrap();
        assert!(got.noise_var.is_finite() && got.noise_var > 0.0, "{scale}");
        assert_eq!(got.paths.len(), 2, "{scale}");
        assert!(got
            .paths
            .iter()
            .all(|p| p.sigma_s.is_finite() && p.snr.is_finite()));
    }
    for scale in [1e100, 1e300] {
        let x: Vec<Complex> = clean.iter().map(|v| v * scale).collect();
        let got = e.estimate(&x, None, &[]).unwrap_err().to_string();
        assert!(
            got.starts_with("response: ") && got.contains("1e100"),
            "{got}"
        );
    }
    assert!(e
        .estimate(&clean, Some(1e201), &[])
        .unwrap_err()
        .to_string()
        .starts_with("noise_var: "));
}

/// A seed is refined from its prediction and kept when it passes the CFAR test; a seed where
/// there is only noise is dropped.
#[test]
fn seeds_refined_and_tested() {
    let b = band();
    let mut e = Estimator::new(b.clone(), EstimatorConfig::default()).unwrap();
    let mut rng = Pcg64::seed_from_u64(9);
    let tau = 73.3e-9;
    let h = response(
        &b,
        &[(tau, Complex::new(1.0, 0.0))],
        N as Real / 1000.0,
        &mut rng,
    );
    let r = e.estimate(&h, None, &[tau + 0.2 / B, 400e-9]).unwrap();
    assert_eq!(r.paths.len(), 1, "{:?}", r.paths);
    let bound = b.delay_bound_s(1000.0);
    assert!((r.paths[0].delay_s - tau).abs() < 5.0 * bound);
    let s = r.paths[0].sigma_s / bound;
    assert!((s - 1.0).abs() < 0.3, "σ̂/C4 {s}");
}

/// A window restricts the search and sets G.
#[test]
fn window_sets_grid() {
    let b = band();
    let cfg = EstimatorConfig {
        window_s: Some((0.0, 1e-6)),
        ..EstimatorConfig::default()
    };
    let e = Estimator::new(b.clone(), cfg).unwrap();
    let full = Estimator::new(b, EstimatorConfig::default()).unwrap();
    assert_eq!(full.grid_cells(), 1024);
    assert_eq!(e.grid_cells(), 513); // cells 0 … 512 of 1024 over 2 µs
    assert!((full.threshold() - ln(1024.0 / 1e-3)).abs() < 1e-12);
}

/// The closed-form kernels `S_0, S_1, S_2` of a flat band equal the sums they replace, to
/// 1e-9 of the largest of each, over separations from 0 to the unambiguous span.
#[test]
fn closed_form_kernels_equal_the_sums() {
    let b = band();
    let e = Estimator::new(b.clone(), EstimatorConfig::default()).unwrap();
    let span = b.unambiguous_s();
    let (m0, m1, m2) = (
        e.kernel(0.0, 0).norm(),
        e.kernel(0.3 / B, 1).norm().max(1.0),
        e.kernel(0.0, 2).norm(),
    );
    for i in 0..4001 {
        let d = -span + 2.0 * span * i as Real / 4000.0;
        let (k0, k1, k2) = e.kernels(d);
        assert!((k0 - e.kernel(d, 0)).norm() <= 1e-9 * m0, "S0 at {d}");
        assert!(
            (k1 - e.kernel(d, 1)).norm() <= 1e-9 * m1 * DF * N as Real,
            "S1 at {d}"
        );
        assert!((k2 - e.kernel(d, 2)).norm() <= 1e-9 * m2, "S2 at {d}");
    }
}

/// The units of a recording do not matter: Wi-Fi CSI comes in raw integer units (amplitudes of
/// tens to thousands), a sounder in √W (10⁻⁶). Scaling a response and its noise by `s` scales
/// the amplitudes by `s` and leaves every delay and its σ from the joint Fisher matrix as they
/// are — which the joint bound of two coupled paths must show (the Fisher matrix mixes
/// `|α|²·f²` with `1`: unscaled, its inversion's tolerance called amplitudes of order one
/// singular and fell back to C4).
#[test]
fn estimates_do_not_depend_on_the_recording_units() {
    let b = band();
    let mut rng = Pcg64::seed_from_u64(11);
    let paths = [
        (100e-9, Complex::new(3e-5, 1e-5)),
        (107e-9, Complex::new(-1e-5, 2e-5)),
    ];
    let var = 1e-13;
    let h = response(&b, &paths, var, &mut rng);
    let want = joint_bounds(&b, &paths, var);
    for scale in [1.0, 1e3, 1e6, 1e9] {
        let hs: Vec<Complex> = h.iter().map(|v| v * scale).collect();
        let mut est = Estimator::new(b.clone(), EstimatorConfig::default()).unwrap();
        let e = est.estimate(&hs, Some(var * scale * scale), &[]).unwrap();
        assert_eq!(e.paths.len(), 2, "scale {scale}: {:?}", e.paths);
        for (p, w) in e.paths.iter().zip(&want) {
            // The fitted paths sit within a few σ of the truth: their joint bound is within
            // a few per cent of the bound at the true parameters.
            assert!(
                (p.sigma_s / w - 1.0).abs() < 0.1,
                "scale {scale}: σ {} s against the joint bound {w} s",
                p.sigma_s
            );
        }
    }
}
