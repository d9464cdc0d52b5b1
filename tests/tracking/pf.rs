#![cfg(not(target_arch = "wasm32"))]
//! The bootstrap particle filter (`filters-and-planning.md` §2): its initial cloud, prediction and
//! weights against closed forms, systematic resampling, determinism (seed only, any thread), the
//! log-space weights of an extreme step, named errors, and the near-linear case where the EKF,
//! the UKF and the PF must agree within their Monte Carlo error.

use crate::common;

use common::sensors_model as model;
use common::tracking::fast_motion;
use scatterloc::math::{Mat4, Real, Vec2, Vec4};
use scatterloc::measure::{self, rng};
use scatterloc::track::{paper_initial_covariance, TrackScenario, TruthSampler};
use scatterloc::track::{
    ConstantVelocity, Ekf, Filter, MeasurementNoise, ParticleFilter, PfConfig, Ukf, UkfParams,
};
use scatterloc::{Error, Model};

fn pf(n: usize, mean: Vec4, cov: Mat4, seed: u64) -> ParticleFilter {
    ParticleFilter::new(
        mean,
        cov,
        PfConfig {
            particles: n,
            roughening: None,
            regularized: false,
        },
        rng(seed, 0),
    )
    .unwrap()
}

/// The initial cloud and one prediction reproduce `(x̄₀, P₀)` and `(A x̄₀, A P₀ Aᵀ + Q)` within
/// their sampling error (20 000 particles: the standard error of a mean component is
/// `√(P_ii/N)`; 5 standard errors, on three seeds).
#[test]
fn cloud_and_prediction_match_their_moments() {
    let motion = fast_motion();
    let x0 = TrackScenario::I.mean_state();
    let p0 = paper_initial_covariance();
    let n = 20_000;
    for seed in 1..=3 {
        let mut f = pf(n, x0, p0, seed);
        for (mean, cov, what) in [(x0, p0, "initial")] {
            for i in 0..4 {
                let se = (cov[(i, i)] / n as Real).sqrt();
                assert!((f.state[i] - mean[i]).abs() < 5.0 * se, "{what} mean[{i}]");
                // Var of a sample variance ≈ 2σ⁴/N.
                let se_var = cov[(i, i)] * (2.0 / n as Real).sqrt();
                assert!(
                    (f.covariance[(i, i)] - cov[(i, i)]).abs() < 5.0 * se_var,
                    "{what} P[{i}][{i}]"
                );
            }
        }
        f.predict(&motion);
        let (m1, p1) = (motion.propagate(&x0), motion.propagate_covariance(&p0));
        for i in 0..4 {
            let se = (p1[(i, i)] / n as Real).sqrt();
            assert!(
                (f.state[i] - m1[i]).abs() < 5.0 * se,
                "predicted mean[{i}] seed {seed}"
            );
            let se_var = p1[(i, i)] * (2.0 / n as Real).sqrt();
            assert!((f.covariance[(i, i)] - p1[(i, i)]).abs() < 5.0 * se_var);
        }
    }
}

/// `−½ Σ_p (z_p − h_p(x_j))² / σ_p²` of every particle, σ_p at `r_pred` (spec §2), written out.
fn log_likelihoods(
    model: &Model,
    particles: &[Vec4],
    z: &[Option<Real>],
    r_pred: Vec2,
) -> Vec<Real> {
    particles
        .iter()
        .map(|x| {
            let r = Vec2::new(x[0], x[1]);
            -0.5 * (0..z.len())
                .map(|p| {
                    let s = model.sigma_delay(p, r_pred);
                    ((z[p].unwrap() - model.network.delay(p, r)) / s).powi(2)
                })
                .sum::<Real>()
        })
        .collect()
}

/// After one update, the weights are `∝ exp(−½ Σ (z − h(x_j))²/σ_p²)` (σ_p at the predicted
/// mean), recomputed here from the particles; they sum to 1; the estimate is their weighted mean.
#[test]
fn weights_are_the_gaussian_likelihood_normalised() {
    let model = model();
    let x0 = Vec4::new(3.0, 4.0, 0.5, 0.0);
    let p0 = Mat4::from_diagonal(&Vec4::new(0.01, 0.01, 0.01, 0.01));
    let mut f = pf(500, x0, p0, 7);
    let truth = Vec2::new(3.05, 3.98);
    let z: Vec<Option<Real>> = model.network.delays(truth).into_iter().map(Some).collect();
    let before: Vec<Vec4> = f.particles().to_vec();
    let r_pred = f.position();
    let u = f
        .update(&model, &z, MeasurementNoise::AtPrediction)
        .unwrap();
    assert_eq!(u.summary.links_used, 4);
    let loglik = log_likelihoods(&model, &before, &z, r_pred);
    let max = loglik.iter().copied().fold(Real::NEG_INFINITY, Real::max);
    let w: Vec<Real> = loglik.iter().map(|l| (l - max).exp()).collect();
    let total: Real = w.iter().sum();
    let mut mean = Vec4::zeros();
    for (x, wj) in before.iter().zip(&w) {
        mean += *wj / total * x;
    }
    assert!((f.state - mean).norm() < 1e-9, "{} vs {mean}", f.state);
    let ess = 1.0 / w.iter().map(|wj| (wj / total).powi(2)).sum::<Real>();
    assert!((u.ess - ess).abs() < 1e-6 * ess, "{} vs {ess}", u.ess);
    if !u.resampled {
        let sum: Real = f.log_weights().iter().map(|l| l.exp()).sum();
        assert!((sum - 1.0).abs() < 1e-12);
    }
}

/// Systematic resampling keeps each particle `⌊N w_i⌋` or `⌈N w_i⌉` times (the weights
/// recomputed here from the particles, as above); after it all weights are `1/N`.
#[test]
fn systematic_resampling_copies_in_proportion_to_the_weights() {
    let model = model();
    let x0 = Vec4::new(3.0, 4.0, 0.0, 0.0);
    let p0 = Mat4::from_diagonal(&Vec4::new(0.01, 0.01, 0.01, 0.01));
    for seed in 1..=5 {
        let mut f = pf(400, x0, p0, seed);
        let z: Vec<Option<Real>> = model
            .network
            .delays(Vec2::new(3.1, 3.95))
            .into_iter()
            .map(Some)
            .collect();
        let before: Vec<Vec4> = f.particles().to_vec();
        let r_pred = f.position();
        let u = f
            .update(&model, &z, MeasurementNoise::AtPrediction)
            .unwrap();
        assert!(
            u.resampled,
            "seed {seed}: a 10 cm prior against cm-level delays collapses"
        );
        let loglik = log_likelihoods(&model, &before, &z, r_pred);
        let max = loglik.iter().copied().fold(Real::NEG_INFINITY, Real::max);
        let total: Real = loglik.iter().map(|l| (l - max).exp()).sum();
        let n = before.len() as Real;
        for (x, l) in before.iter().zip(&loglik) {
            let expected = n * (l - max).exp() / total;
            let copies = f.particles().iter().filter(|y| *y == x).count() as Real;
            assert!(
                copies >= expected.floor() - 1e-9 && copies <= expected.ceil() + 1e-9,
                "seed {seed}: {copies} copies for N·w = {expected}"
            );
        }
        for l in f.log_weights() {
            assert!((l + n.ln()).abs() < 1e-12);
        }
    }
}

/// The same seed gives the same filter, on one thread or two at once; another seed another.
#[test]
fn particle_filter_depends_on_the_seed_only() {
    let model = model();
    let motion = fast_motion();
    let run = |seed: u64| {
        let mut f = pf(
            300,
            TrackScenario::II.mean_state(),
            paper_initial_covariance(),
            seed,
        );
        let mut truth_rng = rng(seed, 9);
        for k in 0..40 {
            let r = Vec2::new(2.0 + 0.05 * k as Real, 3.0);
            let z: Vec<Option<Real>> = measure::noisy_delays(&model, r, &mut truth_rng)
                .into_iter()
                .map(Some)
                .collect();
            f.step(&motion, &model, &z, MeasurementNoise::AtPrediction)
                .unwrap();
        }
        (f.state, f.covariance, f.particles().to_vec())
    };
    let a = run(5);
    let b: Vec<_> = std::thread::scope(|s| {
        let h: Vec<_> = (0..2).map(|_| s.spawn(|| run(5))).collect();
        h.into_iter().map(|h| h.join().unwrap()).collect()
    });
    for x in &b {
        assert_eq!(&a, x);
    }
    assert_ne!(a.0, run(6).0);
}

/// A step whose likelihoods all underflow in linear space (every particle thousands of σ away)
/// keeps finite, normalised weights (log-sum-exp) and collapses onto the best particles; bad
/// inputs are named errors and leave the filter unchanged.
#[test]
fn extreme_steps_stay_finite_and_bad_inputs_are_named() {
    let model = model();
    let motion = fast_motion();
    let mut f = pf(
        200,
        Vec4::new(20.0, 20.0, 0.0, 0.0),
        Mat4::identity() * 0.01,
        3,
    );
    let z: Vec<Option<Real>> = model
        .network
        .delays(Vec2::new(-5.0, -8.0))
        .into_iter()
        .map(Some)
        .collect();
    let u = f
        .update(&model, &z, MeasurementNoise::AtPrediction)
        .unwrap();
    assert!(u.ess >= 1.0 && u.ess < 2.0, "ESS {}", u.ess);
    assert!(u.resampled);
    assert!(f.state.iter().all(|v| v.is_finite()));
    assert!(f.log_weights().iter().all(|l| l.is_finite()));
    let before = f.clone();
    let mut bad = z.clone();
    bad[3] = Some(Real::NAN);
    assert!(matches!(
        f.step(&motion, &model, &bad, MeasurementNoise::AtPrediction),
        Err(Error::InvalidDelay { link: 3, .. })
    ));
    assert_eq!(f.particles(), before.particles());
    assert_eq!(f.state, before.state);
    for (cfg, field) in [
        (
            PfConfig {
                particles: 0,
                roughening: None,
                regularized: false,
            },
            "particles",
        ),
        (
            PfConfig {
                particles: 10,
                roughening: Some(-1.0),
                regularized: false,
            },
            "roughening",
        ),
    ] {
        let e = ParticleFilter::new(Vec4::zeros(), Mat4::identity(), cfg, rng(1, 0)).unwrap_err();
        assert!(e.to_string().contains(field), "{e}");
    }
}

/// Near-linear case (far from the baselines, high SNR, a tight prior): the EKF, the UKF and the
/// PF (N = 10⁴) have the same mean squared position error after 30 steps, within the Monte Carlo
/// error of the paired differences (4 standard errors), over 40 runs.
#[test]
fn near_linear_ekf_ukf_and_pf_agree_within_monte_carlo_error() {
    let model = model();
    let motion = ConstantVelocity::new(0.1, 0.01);
    let start = Vec4::new(4.0, 3.0, 0.3, 0.2);
    let p0 = Mat4::from_diagonal(&Vec4::new(1e-4, 1e-4, 1e-4, 1e-4));
    let sampler = TruthSampler::new(motion, start, &p0).unwrap();
    let (runs, steps) = (40, 30);
    let mut se = [Vec::new(), Vec::new(), Vec::new()];
    for run in 0..runs {
        let mut truth = Vec::new();
        sampler.sample(steps + 1, &mut rng(100 + run, 0), &mut truth);
        let mut noise = rng(100 + run, 1);
        let mut e = Ekf::new(start, p0).unwrap();
        let mut u = Ukf::new(start, p0, UkfParams::default()).unwrap();
        let mut p = ParticleFilter::new(
            start,
            p0,
            PfConfig {
                particles: 10_000,
                roughening: None,
                regularized: false,
            },
            rng(100 + run, 2),
        )
        .unwrap();
        for x in &truth[1..=steps] {
            let z: Vec<Option<Real>> =
                measure::noisy_delays(&model, Vec2::new(x[0], x[1]), &mut noise)
                    .into_iter()
                    .map(Some)
                    .collect();
            e.step(&motion, &model, &z, MeasurementNoise::AtPrediction)
                .unwrap();
            u.step(&motion, &model, &z, MeasurementNoise::AtPrediction)
                .unwrap();
            p.step(&motion, &model, &z, MeasurementNoise::AtPrediction)
                .unwrap();
        }
        let t = truth[steps];
        let err = |s: Vec4| (s[0] - t[0]).powi(2) + (s[1] - t[1]).powi(2);
        se[0].push(err(e.state));
        se[1].push(err(u.state));
        se[2].push(err(p.state));
    }
    let mean = |v: &[Real]| v.iter().sum::<Real>() / v.len() as Real;
    let rmse: Vec<Real> = se.iter().map(|v| mean(v).sqrt()).collect();
    println!("near-linear RMSE after {steps} steps ({runs} runs): EKF {:.3} mm, UKF {:.3} mm, PF {:.3} mm", rmse[0] * 1e3, rmse[1] * 1e3, rmse[2] * 1e3);
    for (k, name) in [(1, "UKF"), (2, "PF")] {
        let d: Vec<Real> = se[k].iter().zip(&se[0]).map(|(a, b)| a - b).collect();
        let md = mean(&d);
        let sd = (d.iter().map(|x| (x - md).powi(2)).sum::<Real>() / (d.len() - 1) as Real).sqrt();
        let stderr = sd / (d.len() as Real).sqrt();
        assert!(
            md.abs() <= 4.0 * stderr + 1e-12,
            "{name}: mean squared error differs from the EKF's by {md:.3e} m² (standard error {stderr:.3e})"
        );
    }
}

/// Issue 26, the regularised filter's first update: the particles are redrawn from
/// `q = 𝒩(x̂⁺, κ P⁺)`, the EKF update of the prior (S17) widened by κ, and weighted by
/// `ln p(z | x) + ln 𝒩(x; x̄₀, P₀) − ln q(x)`, normalised — recomputed here from the drawn
/// particles with explicit inverses (5 seeds; the updates that resampled cannot be checked so and
/// are skipped, at least 3 must remain). The redrawn cloud's weighted mean is the EKF's within
/// 5 of its standard errors.
#[test]
fn regularized_first_update_is_importance_sampling_from_the_ekf_proposal() {
    use scatterloc::track::PROPOSAL_INFLATION;
    let model = model();
    let x0 = Vec4::new(3.0, 4.0, 0.5, 0.0);
    let p0 = Mat4::from_diagonal(&Vec4::new(0.01, 0.01, 0.01, 0.01));
    let z: Vec<Option<Real>> = model
        .network
        .delays(Vec2::new(3.05, 3.98))
        .into_iter()
        .map(Some)
        .collect();
    let noise = MeasurementNoise::AtPrediction;
    let mut ekf = Ekf::new(x0, p0).unwrap();
    ekf.update(&model, &z, noise, None).unwrap();
    let pq = ekf.covariance * PROPOSAL_INFLATION;
    let (p0_inv, pq_inv) = (p0.try_inverse().unwrap(), pq.try_inverse().unwrap());
    let n = 2000;
    let mut checked = 0;
    for seed in 1..=5 {
        let cfg = PfConfig {
            particles: n,
            ..PfConfig::default()
        };
        let mut f = ParticleFilter::new(x0, p0, cfg, rng(seed, 0)).unwrap();
        let r_pred = f.position();
        let u = f.update(&model, &z, noise).unwrap();
        if u.resampled {
            continue;
        }
        checked += 1;
        let loglik = log_likelihoods(&model, f.particles(), &z, r_pred);
        let l: Vec<Real> = f
            .particles()
            .iter()
            .zip(&loglik)
            .map(|(x, ll)| {
                let (a, b) = (x - x0, x - ekf.state);
                ll - 0.5 * (a.transpose() * p0_inv * a)[0] + 0.5 * (b.transpose() * pq_inv * b)[0]
            })
            .collect();
        let max = l.iter().copied().fold(Real::NEG_INFINITY, Real::max);
        let norm = max + l.iter().map(|v| (v - max).exp()).sum::<Real>().ln();
        for (got, want) in f.log_weights().iter().zip(&l) {
            assert!(
                (got - (want - norm)).abs() < 1e-7,
                "seed {seed}: {got} vs {}",
                want - norm
            );
        }
        for i in 0..4 {
            let se = (ekf.covariance[(i, i)] / u.ess).sqrt();
            assert!(
                (f.state[i] - ekf.state[i]).abs() < 5.0 * se,
                "seed {seed}: mean[{i}] {} vs EKF {}",
                f.state[i],
                ekf.state[i]
            );
        }
        assert_eq!(f.particles().len(), n);
    }
    assert!(checked >= 3, "only {checked} of 5 updates did not resample");
}

/// Issue 26, the regularised filter's kernel: `h = (4/(N(d+2)))^(1/(d+4))` (0.40086 at N = 1000),
/// and after a resampling every particle is distinct (jittered), where the bootstrap SIR keeps
/// copies; the cloud's covariance then grows by about `1 + h²` (checked within 25 %).
#[test]
fn regularized_resampling_jitters_with_the_optimal_kernel() {
    use scatterloc::track::kernel_bandwidth;
    assert!((kernel_bandwidth(1000) - (4.0 / 6000.0 as Real).powf(0.125)).abs() < 1e-15);
    assert!((kernel_bandwidth(1000) - 0.40086).abs() < 1e-5);
    let model = model();
    let x0 = Vec4::new(3.0, 4.0, 0.0, 0.0);
    let p0 = Mat4::from_diagonal(&Vec4::new(0.01, 0.01, 0.01, 0.01));
    let z: Vec<Option<Real>> = model
        .network
        .delays(Vec2::new(3.1, 3.95))
        .into_iter()
        .map(Some)
        .collect();
    let motion = fast_motion();
    for (cfg, distinct) in [
        (PfConfig::bootstrap(1000), false),
        (PfConfig::default(), true),
    ] {
        let mut f = ParticleFilter::new(x0, p0, cfg, rng(4, 0)).unwrap();
        let mut resampled = false;
        for _ in 0..5 {
            f.predict(&motion);
            let u = f
                .update(&model, &z, MeasurementNoise::AtPrediction)
                .unwrap();
            if u.resampled {
                resampled = true;
                let estimate = f.covariance;
                let p = f.particles();
                let all_distinct = (1..p.len()).all(|j| p[j] != p[j - 1]);
                assert_eq!(all_distinct, distinct, "{cfg:?}");
                if distinct {
                    let mean: Vec4 = p.iter().sum::<Vec4>() / p.len() as Real;
                    let var =
                        p.iter().map(|x| (x[0] - mean[0]).powi(2)).sum::<Real>() / p.len() as Real;
                    let h2 = kernel_bandwidth(1000).powi(2);
                    let ratio = var / estimate[(0, 0)];
                    assert!((ratio / (1.0 + h2) - 1.0).abs() < 0.25, "{ratio}");
                }
                break;
            }
        }
        assert!(
            resampled,
            "{cfg:?}: a cm-level update of a 10 cm cloud resamples"
        );
    }
}
