#![cfg(not(target_arch = "wasm32"))]
//! Tracking (spec §6, §8, §9.4–9.5): the CV model (E7), the EKF against a hand-written batch
//! Kalman filter, missing links, the posterior CRLB (E9) and the Monte Carlo harness — spec
//! checks 5, 10 and 11 (checks 4 and 9 are unit tests in `motion.rs` and `pcrlb.rs`), NEES
//! consistency, thread-count independence and the named errors of bad inputs.
//!
//! Every expected number is a spec value (its check is cited), a closed form stated next to
//! it, or the output of the reference filter below. Monte Carlo tolerances are derived from the
//! Monte Carlo error and stated where used; the runs use fixed seeds, so each test is
//! deterministic. Runs too slow for a debug build are `#[ignore]` (run them with
//! `cargo test --release --test tracking -- --ignored`); a smaller variant of each always runs.

use std::sync::atomic::{AtomicBool, Ordering};

use nalgebra::{DMatrix, DVector};

use scatterloc::math::{Mat4, Real, Vec2, Vec4};
use scatterloc::native::run_parallel;
use scatterloc::track::ConstantVelocity;
use scatterloc::track::{nominal_pcrlb_rmse, pcrlb_rmse};
use scatterloc::track::{
    paper_initial_covariance, step_count, TrackScenario, TruthSampler, PAPER_INTENSITY,
    PAPER_STEP_S,
};
use scatterloc::track::{
    run_pcrlb_sequential, run_sequential, MonteCarloConfig, MonteCarloResult, MAX_RUNS, MAX_STEPS,
};
use scatterloc::track::{Ekf, MeasurementNoise, UpdateSummary};
use scatterloc::{localize, measure, scenario::presets, Error, Mat2, Model};

/// The spec's fast profile step (§9.5), s.
const FAST_STEP_S: Real = 0.1;
/// The seed of the Monte Carlo runs below (the lead's reference runs use seed 1).
const SEED: u64 = 1;

fn model() -> Model {
    Model::new(&presets::sensors2019()).expect("preset is valid")
}

fn fast_motion() -> ConstantVelocity {
    ConstantVelocity::new(FAST_STEP_S, PAPER_INTENSITY)
}

/// The §9.5 study of scenario `s` over 10 s at step `dt_s`.
fn study(s: TrackScenario, dt_s: Real, trajectories: usize, noise_runs: usize) -> MonteCarloConfig {
    MonteCarloConfig {
        motion: ConstantVelocity::new(dt_s, PAPER_INTENSITY),
        steps: step_count(10.0, dt_s),
        mean_state: s.mean_state(),
        initial_covariance: paper_initial_covariance(),
        trajectories,
        noise_runs,
        seed: SEED,
        oracle_noise: false,
    }
}

/// Index of time `t` (s) at step `dt`.
fn at(t: Real, dt: Real) -> usize {
    (t / dt).round() as usize
}

#[track_caller]
fn rel_close(what: &str, got: Real, want: Real, rel: Real) {
    assert!(
        (got - want).abs() <= rel * want.abs(),
        "{what}: got {got}, want {want} (relative error {:.3e} > {rel:e})",
        ((got - want) / want).abs()
    );
}

/// `a` and `b` agree entry by entry to `rel` of the scale `√(B_ii B_jj)` of the reference `b`
/// (a covariance's natural per-entry scale; exact zeros in `b` are not divided by).
#[track_caller]
fn covariance_close(what: &str, a: &Mat4, b: &Mat4, rel: Real) {
    for i in 0..4 {
        for j in 0..4 {
            let scale = (b[(i, i)] * b[(j, j)]).sqrt();
            assert!(
                (a[(i, j)] - b[(i, j)]).abs() <= rel * scale,
                "{what} [{i},{j}]: {} vs {} (scale {scale:e}, rel {:.3e} > {rel:e})",
                a[(i, j)],
                b[(i, j)],
                (a[(i, j)] - b[(i, j)]).abs() / scale
            );
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Motion model (E7). Check 4 (the Q entries at 2.048 ms) is the unit test motion::check4.
// ---------------------------------------------------------------------------------------------

/// `A(T₁)A(T₂) = A(T₁+T₂)` (exactly: the only non-trivial entries are `T₁ + T₂`), and `Q` is the
/// discretisation of continuous white-noise acceleration, so
/// `Q(T₁+T₂) = A(T₂) Q(T₁) A(T₂)ᵀ + Q(T₂)` (closed form; 1e-14 relative). `Q` is positive
/// definite: per axis `det q̃[[T³/3, T²/2], [T²/2, T]] = q̃²T⁴/12` (1e-12 relative), and its
/// Cholesky factor exists; the sampling factor satisfies `L Lᵀ = Q`.
#[test]
fn transition_composes_and_process_noise_is_a_psd_discretisation() {
    for (t1, t2) in [(PAPER_STEP_S, 0.1), (0.1, 0.1), (0.3, 1.7), (1e-3, 2.5)] {
        let q = PAPER_INTENSITY;
        let (m1, m2) = (ConstantVelocity::new(t1, q), ConstantVelocity::new(t2, q));
        let m12 = ConstantVelocity::new(t1 + t2, q);
        assert_eq!(m1.transition() * m2.transition(), m12.transition());
        let composed =
            m2.transition() * m1.process_noise() * m2.transition().transpose() + m2.process_noise();
        covariance_close("Q(T1+T2)", &composed, &m12.process_noise(), 1e-14);
        for m in [m1, m2, m12] {
            let (qm, t) = (m.process_noise(), m.dt_s);
            assert_eq!(qm, qm.transpose());
            for axis in [0, 2] {
                let (a, b) = (axis / 2, axis / 2 + 2); // x: (0, 2), y: (1, 3)
                let det = qm[(a, a)] * qm[(b, b)] - qm[(a, b)] * qm[(b, a)];
                rel_close("per-axis det Q", det, q * q * t.powi(4) / 12.0, 1e-12);
                assert!(qm[(a, a)] > 0.0 && det > 0.0);
            }
            assert!(qm.cholesky().is_some(), "Q(T={t}) not positive definite");
            let l = m.process_noise_factor();
            covariance_close("L Lᵀ = Q", &(l * l.transpose()), &qm, 1e-14);
        }
    }
}

/// Predict: `x̂⁻ = A x̂` exactly and `P⁻ = A P Aᵀ + Q` (structured evaluation against the plain
/// matrix product, 1e-15 relative), exactly symmetric.
#[test]
fn predict_is_a_p_at_plus_q() {
    let m = ConstantVelocity::new(0.37, PAPER_INTENSITY);
    let p = Mat4::new(
        0.30, 0.02, 0.011, -0.004, //
        0.02, 0.12, 0.003, 0.009, //
        0.011, 0.003, 0.05, 0.001, //
        -0.004, 0.009, 0.001, 0.02,
    );
    let mut f = Ekf::new(Vec4::new(1.0, -2.0, 0.7, 0.3), p).unwrap();
    f.predict(&m);
    let a = m.transition();
    assert_eq!(f.state, a * Vec4::new(1.0, -2.0, 0.7, 0.3));
    covariance_close(
        "A P Aᵀ + Q",
        &f.covariance,
        &(a * p * a.transpose() + m.process_noise()),
        1e-15,
    );
    assert_eq!(f.covariance, f.covariance.transpose());
}

// ---------------------------------------------------------------------------------------------
// The EKF against a hand-written batch Kalman filter (spec §6).
// ---------------------------------------------------------------------------------------------

/// The reference: one textbook batch update in the delay domain with `nalgebra::DMatrix`,
/// linearised at the predicted position: `H = [J(r̂⁻), 0]` (E3, s/m) over the available links,
/// `R = diag(σ_p²)`, `ν = z − h(r̂⁻)`, `S = H P Hᵀ + R`, `K = P Hᵀ S⁻¹`, `x̂ = x̂⁻ + K ν`,
/// Joseph form `P = (I − KH) P (I − KH)ᵀ + K R Kᵀ`, NIS `= νᵀ S⁻¹ ν`.
struct Reference {
    state: Vec4,
    covariance: Mat4,
    nis: Real,
    innovations: Vec<Option<Real>>,
}

fn reference_update(
    model: &Model,
    x: &Vec4,
    p: &Mat4,
    z: &[Option<Real>],
    sigmas: &[Real],
) -> Reference {
    let r = Vec2::new(x[0], x[1]);
    let (jac, h) = (model.network.jacobian(r), model.network.delays(r));
    let used: Vec<usize> = (0..z.len()).filter(|&i| z[i].is_some()).collect();
    let m = used.len();
    let mut innovations = vec![None; z.len()];
    if m == 0 {
        return Reference {
            state: *x,
            covariance: *p,
            nis: 0.0,
            innovations,
        };
    }
    let mut hm = DMatrix::<Real>::zeros(m, 4);
    let mut rm = DMatrix::<Real>::zeros(m, m);
    let mut nu = DVector::<Real>::zeros(m);
    for (row, &i) in used.iter().enumerate() {
        hm[(row, 0)] = jac[i].x;
        hm[(row, 1)] = jac[i].y;
        rm[(row, row)] = sigmas[i] * sigmas[i];
        nu[row] = z[i].unwrap() - h[i];
        innovations[i] = Some(nu[row]);
    }
    let pd = DMatrix::from_fn(4, 4, |i, j| p[(i, j)]);
    let s = &hm * &pd * hm.transpose() + &rm;
    let s_inv = s.clone().cholesky().expect("S is SPD").inverse();
    let k = &pd * hm.transpose() * &s_inv;
    let xd = DVector::from_fn(4, |i, _| x[i]) + &k * &nu;
    let ikh = DMatrix::<Real>::identity(4, 4) - &k * &hm;
    let pj = &ikh * &pd * ikh.transpose() + &k * &rm * k.transpose();
    let pj = (&pj + pj.transpose()) * 0.5;
    Reference {
        state: Vec4::from_fn(|i, _| xd[i]),
        covariance: Mat4::from_fn(|i, j| pj[(i, j)]),
        nis: (nu.transpose() * &s_inv * &nu)[(0, 0)],
        innovations,
    }
}

/// `got` equals the reference filter: state to `rel` of `max(|x_i|, 1)`, covariance entries
/// to `rel` of `√(P_ii P_jj)`, NIS to `rel_nis` relative.
#[track_caller]
fn assert_matches_reference(
    what: &str,
    f: &Ekf,
    nis: Real,
    r: &Reference,
    rel: Real,
    rel_nis: Real,
) {
    for i in 0..4 {
        let scale = r.state[i].abs().max(1.0);
        assert!(
            (f.state[i] - r.state[i]).abs() <= rel * scale,
            "{what}: state[{i}] {} vs {} (off {:e})",
            f.state[i],
            r.state[i],
            f.state[i] - r.state[i]
        );
    }
    covariance_close(what, &f.covariance, &r.covariance, rel);
    assert!(
        (nis - r.nis).abs() <= rel_nis * r.nis.max(1e-300),
        "{what}: NIS {nis} vs νᵀS⁻¹ν {} (rel {:.3e})",
        r.nis,
        ((nis - r.nis) / r.nis).abs()
    );
}

/// A filter after `steps` EKF steps on a scenario truth (R at prediction), and the truth.
fn tracked(
    s: TrackScenario,
    motion: &ConstantVelocity,
    steps: usize,
    seed: u64,
) -> (Ekf, Vec<Vec4>) {
    let model = model();
    let sampler = TruthSampler::new(*motion, s.mean_state(), &paper_initial_covariance()).unwrap();
    let mut truth = Vec::new();
    sampler.sample(steps + 5, &mut measure::rng(seed, 0), &mut truth);
    let mut noise = measure::rng(seed, 1);
    let mut f = Ekf::new(s.mean_state(), paper_initial_covariance()).unwrap();
    for x in &truth[1..=steps] {
        let z: Vec<Option<Real>> = measure::noisy_delays(&model, Vec2::new(x[0], x[1]), &mut noise)
            .into_iter()
            .map(Some)
            .collect();
        f.step(motion, &model, &z, MeasurementNoise::AtPrediction)
            .unwrap();
    }
    (f, truth)
}

/// One EKF update equals the batch Kalman filter with `H = [J(r̂⁻), 0]` and innovation
/// `z − h(r̂⁻)`: (a) at steady state (after 2 s of tracking) and (b) the first update from the
/// wide prior `P(t₀)`, for each scenario, with `R` given (`Fixed`) and from the link budget at the
/// prediction (`AtPrediction`, whose σ the reference takes from `Model::sigma_delay(p, r̂⁻)`).
/// At steady state, state and covariance agree to 1e-12 relative and NIS `= νᵀS⁻¹ν` to 1e-12.
/// From the wide prior (P_rr ≈ 0.1 m² against a posterior ≈ 1e-5 m²) every filter forms
/// `P⁺ = P⁻ − (≈ P⁻)`: the rounding of `P⁻` alone (2.2e-16 · 0.1) is ≈ 3e-12 of `P⁺` in each of
/// the two filters, so there 1e-10 is used for state, covariance and NIS. The reported
/// innovations are `z − h(r̂⁻)` in seconds (1e-9: a ≈ 0.3 m innovation is the difference of
/// ≈ 30 m ranges, rounded at 1e-15 of those).
#[test]
fn ekf_update_equals_batch_kalman_filter() {
    let model = model();
    let motion = fast_motion();
    for s in TrackScenario::ALL {
        for (case, steps, rel) in [("steady state", 20, 1e-12), ("first update", 0, 1e-10)] {
            let (mut f, truth) = tracked(s, &motion, steps, 7);
            f.predict(&motion);
            let x = truth[steps + 1];
            let mut rng = measure::rng(7, 99);
            let z: Vec<Option<Real>> =
                measure::noisy_delays(&model, Vec2::new(x[0], x[1]), &mut rng)
                    .into_iter()
                    .map(Some)
                    .collect();
            let r_pred = f.position();
            let sigma_pred = model.sigma_delays(r_pred);
            let fixed = [1.0e-11, 2.5e-11, 4.0e-11, 1.5e-11];
            let r = reference_update(&model, &f.state, &f.covariance, &z, &fixed);
            let mut g = f;
            let mut innovations = vec![Some(0.0); 4];
            let u = g
                .update(
                    &model,
                    &z,
                    MeasurementNoise::Fixed(&fixed),
                    Some(&mut innovations),
                )
                .unwrap();
            assert_eq!(u.links_used, 4);
            let what = format!("{} {case} fixed R", s.name());
            assert_matches_reference(&what, &g, u.nis, &r, rel, rel);
            for (a, b) in innovations.iter().zip(&r.innovations) {
                rel_close("innovation [s]", a.unwrap(), b.unwrap(), 1e-9);
            }
            let r = reference_update(&model, &f.state, &f.covariance, &z, &sigma_pred);
            let mut g = f;
            let u = g
                .update(&model, &z, MeasurementNoise::AtPrediction, None)
                .unwrap();
            let what = format!("{} {case} R at prediction", s.name());
            assert_matches_reference(&what, &g, u.nis, &r, rel, rel);
            // The update shrinks the position covariance (information only adds).
            assert!(g.covariance[(0, 0)] < f.covariance[(0, 0)]);
            assert!(g.covariance[(1, 1)] < f.covariance[(1, 1)]);
        }
    }
}

/// A run with a link missing mid-run (steps 10–14: link 2 is `None`; steps 20–22: only links 0
/// and 3) and steps without any link (15–17: predict only) follows the reference filter step by
/// step (1e-10 relative after up to 30 steps; rounding accumulates over the run). A step without
/// links leaves `x̂⁻ = A x̂` and `P⁻ = A P Aᵀ + Q` exactly (bitwise the predict), with a zero
/// summary; a missing link is reported as a `None` innovation and not counted.
#[test]
fn missing_link_mid_run_and_predict_only_steps() {
    let model = model();
    let motion = fast_motion();
    let s = TrackScenario::II;
    let sampler = TruthSampler::new(motion, s.mean_state(), &paper_initial_covariance()).unwrap();
    let mut truth = Vec::new();
    sampler.sample(30, &mut measure::rng(11, 0), &mut truth);
    let mut rng = measure::rng(11, 1);
    let mut f = Ekf::new(s.mean_state(), paper_initial_covariance()).unwrap();
    let (mut x_ref, mut p_ref) = (f.state, f.covariance);
    let a = motion.transition();
    for (n, x) in truth.iter().enumerate().skip(1) {
        let r = Vec2::new(x[0], x[1]);
        let sigmas = model.sigma_delays(r);
        let mut z: Vec<Option<Real>> = measure::noisy_delays(&model, r, &mut rng)
            .into_iter()
            .map(Some)
            .collect();
        match n {
            10..=14 => z[2] = None,
            15..=17 => z.fill(None),
            20..=22 => {
                z[1] = None;
                z[2] = None;
            }
            _ => {}
        }
        let used = z.iter().filter(|v| v.is_some()).count();
        f.predict(&motion);
        let predicted = f;
        x_ref = a * x_ref;
        p_ref = a * p_ref * a.transpose() + motion.process_noise();
        let mut innovations = vec![Some(1.0); 4];
        let u = f
            .update(
                &model,
                &z,
                MeasurementNoise::Fixed(&sigmas),
                Some(&mut innovations),
            )
            .unwrap();
        assert_eq!(u.links_used, used, "step {n}");
        for (i, zi) in z.iter().enumerate() {
            assert_eq!(innovations[i].is_some(), zi.is_some(), "step {n} link {i}");
        }
        if used == 0 {
            assert_eq!(
                u,
                UpdateSummary {
                    nis: 0.0,
                    links_used: 0
                }
            );
            assert_eq!(f, predicted, "step {n}: no link must be predict only");
        }
        let r = reference_update(&model, &x_ref, &p_ref, &z, &sigmas);
        assert_matches_reference(&format!("step {n}"), &f, u.nis, &r, 1e-10, 1e-8);
        (x_ref, p_ref) = (r.state, r.covariance);
    }
}

/// Bad inputs are named errors and leave the filter unchanged; `step` undoes its predict.
#[test]
fn ekf_bad_inputs_are_named_errors() {
    let model = model();
    let p0 = paper_initial_covariance();
    let x0 = TrackScenario::I.mean_state();
    // Non-finite state / covariance, asymmetric and indefinite covariance (Ekf::new).
    for v in [Real::NAN, Real::INFINITY] {
        let mut x = x0;
        x[2] = v;
        assert_eq!(
            Ekf::new(x, p0).unwrap_err(),
            Error::NonFinite {
                field: "initial_state".into()
            }
        );
        let mut p = p0;
        p[(1, 1)] = v;
        assert_eq!(
            Ekf::new(x0, p).unwrap_err(),
            Error::NonFinite {
                field: "initial_covariance".into()
            }
        );
    }
    let mut asym = p0;
    asym[(0, 1)] = 0.01; // [1, 0] stays 0
    let mut indefinite = p0;
    indefinite[(0, 1)] = 0.2; // |P01| > √(P00 P11) = 0.1
    indefinite[(1, 0)] = 0.2;
    let mut negative = p0;
    negative[(3, 3)] = -0.01;
    for p in [asym, indefinite, negative, Mat4::zeros()] {
        let e = Ekf::new(x0, p).unwrap_err();
        assert_eq!(
            e,
            Error::NotPositiveDefinite {
                field: "initial_covariance".into()
            }
        );
        assert!(e.to_string().contains("initial_covariance"), "{e}");
    }

    let motion = fast_motion();
    let mut f = Ekf::new(x0, p0).unwrap();
    f.predict(&motion);
    let before = f;
    let good: Vec<Option<Real>> = model
        .network
        .delays(f.position())
        .into_iter()
        .map(Some)
        .collect();
    let sig = [3e-11; 4];
    // Wrong lengths.
    assert_eq!(
        f.update(&model, &good[..3], MeasurementNoise::AtPrediction, None)
            .unwrap_err(),
        Error::LengthMismatch {
            field: "measurement",
            expected: 4,
            found: 3
        }
    );
    assert_eq!(
        f.update(&model, &good, MeasurementNoise::Fixed(&sig[..2]), None)
            .unwrap_err(),
        Error::LengthMismatch {
            field: "sigma_s",
            expected: 4,
            found: 2
        }
    );
    let mut short = vec![None; 5];
    assert_eq!(
        f.update(
            &model,
            &good,
            MeasurementNoise::AtPrediction,
            Some(&mut short)
        )
        .unwrap_err(),
        Error::LengthMismatch {
            field: "innovations",
            expected: 4,
            found: 5
        }
    );
    // Non-finite delays: the first bad link in link order is named.
    for v in [Real::NAN, Real::INFINITY, Real::NEG_INFINITY] {
        let mut z = good.clone();
        z[3] = Some(v);
        z[1] = Some(v);
        for noise in [
            MeasurementNoise::AtPrediction,
            MeasurementNoise::Fixed(&sig),
        ] {
            let e = f.update(&model, &z, noise, None).unwrap_err();
            assert_eq!(e, Error::NonFiniteDelay { link: 1 });
            assert!(e.to_string().contains("[1]"), "{e}");
        }
    }
    // σ ≤ 0, NaN or infinite in Fixed noise (and one so small that 1/(cσ)² overflows).
    for bad in [0.0, -1e-11, Real::NAN, Real::INFINITY, 1e-170] {
        let mut s = sig;
        s[2] = bad;
        let e = f
            .update(&model, &good, MeasurementNoise::Fixed(&s), None)
            .unwrap_err();
        assert!(
            matches!(e, Error::InvalidSigma { link: 2, value } if value.to_bits() == bad.to_bits()),
            "σ = {bad}: {e:?}"
        );
        assert_eq!(f, before, "σ = {bad}: the filter must be left unchanged");
        // A bad σ on a missing link is not used, so it is not an error.
        let mut z = good.clone();
        z[2] = None;
        assert_eq!(
            f.update(&model, &z, MeasurementNoise::Fixed(&s), None)
                .unwrap()
                .links_used,
            3
        );
        f = before;
    }
    // Nothing above changed the filter.
    assert_eq!(f, before);
    // `step` restores the filter (predict included) on error.
    let mut z = good.clone();
    z[0] = Some(Real::NAN);
    let mut g = Ekf::new(x0, p0).unwrap();
    let g0 = g;
    assert_eq!(
        g.step(&motion, &model, &z, MeasurementNoise::AtPrediction)
            .unwrap_err(),
        Error::NonFiniteDelay { link: 0 }
    );
    assert_eq!(g, g0);
    // NEES of a singular covariance is None, not NaN.
    let mut h = g0;
    h.covariance[(2, 2)] = 0.0;
    assert_eq!(h.nees(&x0), None);
}

/// NEES `(x̂ − x)ᵀ P⁻¹ (x̂ − x)` equals the quadratic form with nalgebra's Cholesky inverse
/// (1e-13 relative) and, for a diagonal `P`, the closed form `Σ e_i²/P_ii`.
#[test]
fn nees_is_the_quadratic_form() {
    let (f, truth) = tracked(TrackScenario::III, &fast_motion(), 15, 3);
    let e = f.state - truth[15];
    let want = e.dot(&(f.covariance.cholesky().unwrap().inverse() * e));
    rel_close("NEES", f.nees(&truth[15]).unwrap(), want, 1e-13);
    let d = Ekf::new(
        Vec4::zeros(),
        Mat4::from_diagonal(&Vec4::new(0.1, 0.2, 0.01, 0.04)),
    )
    .unwrap();
    let x = Vec4::new(0.3, -0.2, 0.05, 0.1);
    let closed = 0.09 / 0.1 + 0.04 / 0.2 + 0.0025 / 0.01 + 0.01 / 0.04;
    rel_close("NEES diagonal", d.nees(&x).unwrap(), closed, 1e-15);
}

// ---------------------------------------------------------------------------------------------
// Motion model and Monte Carlo configuration errors.
// ---------------------------------------------------------------------------------------------

#[test]
fn motion_and_study_bad_inputs_are_named_errors() {
    assert_eq!(
        ConstantVelocity::validated(0.0, 0.01).unwrap_err(),
        Error::NotPositive {
            field: "dt_s".into(),
            value: 0.0
        }
    );
    assert_eq!(
        ConstantVelocity::validated(-0.1, 0.01).unwrap_err(),
        Error::NotPositive {
            field: "dt_s".into(),
            value: -0.1
        }
    );
    assert_eq!(
        ConstantVelocity::validated(Real::NAN, 0.01).unwrap_err(),
        Error::NonFinite {
            field: "dt_s".into()
        }
    );
    assert_eq!(
        ConstantVelocity::validated(0.1, 0.0).unwrap_err(),
        Error::NotPositive {
            field: "process_noise".into(),
            value: 0.0
        }
    );
    assert!(ConstantVelocity::validated(0.1, 0.01).is_ok());

    let ok = study(TrackScenario::I, FAST_STEP_S, 10, 2);
    assert!(ok.validate().is_ok());
    let size = |field: &'static str, value: usize, max: usize| Error::SizeLimit {
        field,
        value,
        min: 1,
        max,
    };
    let cases: Vec<(MonteCarloConfig, Error)> = vec![
        (
            MonteCarloConfig {
                trajectories: 0,
                ..ok
            },
            size("runs", 0, MAX_RUNS),
        ),
        (
            MonteCarloConfig {
                trajectories: MAX_RUNS + 1,
                ..ok
            },
            size("runs", MAX_RUNS + 1, MAX_RUNS),
        ),
        (
            MonteCarloConfig {
                noise_runs: 0,
                ..ok
            },
            size("noise_runs", 0, MAX_RUNS),
        ),
        (
            MonteCarloConfig {
                trajectories: 5000,
                noise_runs: 2001,
                ..ok
            },
            size("runs*noise_runs", 5000 * 2001, MAX_RUNS),
        ),
        (
            MonteCarloConfig { steps: 0, ..ok },
            size("steps", 0, MAX_STEPS),
        ),
        (
            MonteCarloConfig {
                steps: MAX_STEPS + 1,
                ..ok
            },
            size("steps", MAX_STEPS + 1, MAX_STEPS),
        ),
        (
            MonteCarloConfig {
                motion: ConstantVelocity::new(0.0, PAPER_INTENSITY),
                ..ok
            },
            Error::NotPositive {
                field: "dt_s".into(),
                value: 0.0,
            },
        ),
        (
            MonteCarloConfig {
                motion: ConstantVelocity::new(0.1, -1.0),
                ..ok
            },
            Error::NotPositive {
                field: "process_noise".into(),
                value: -1.0,
            },
        ),
        (
            MonteCarloConfig {
                mean_state: Vec4::new(0.0, Real::NAN, 0.0, 0.0),
                ..ok
            },
            Error::NonFinite {
                field: "initial_state".into(),
            },
        ),
        (
            MonteCarloConfig {
                initial_covariance: -paper_initial_covariance(),
                ..ok
            },
            Error::NotPositiveDefinite {
                field: "initial_covariance".into(),
            },
        ),
    ];
    let model = model();
    let never = AtomicBool::new(false);
    for (cfg, want) in cases {
        assert_eq!(cfg.validate().unwrap_err(), want);
        // Every driver validates before doing any work.
        assert_eq!(run_sequential(&model, &cfg, |_, _| true).unwrap_err(), want);
        // The PCRLB-only driver ignores `noise_runs` (it runs no filter).
        if let Err(e) = (MonteCarloConfig {
            noise_runs: 1,
            ..cfg
        })
        .validate()
        {
            assert_eq!(
                run_pcrlb_sequential(&model, &cfg, |_, _| true).unwrap_err(),
                e
            );
        }
        assert_eq!(
            run_parallel(&model, &cfg, 1, &never, |_, _| {}).unwrap_err(),
            want
        );
    }
}

/// A cancel request stops every driver with `Error::Cancelled`: a flag already set, a flag set
/// from the progress callback after the first wave, and `on_chunk` returning `false`.
#[test]
fn cancel_stops_with_cancelled() {
    let model = model();
    let cfg = MonteCarloConfig {
        steps: 5,
        ..study(TrackScenario::I, FAST_STEP_S, 200, 1)
    };
    let set = AtomicBool::new(true);
    assert_eq!(
        run_parallel(&model, &cfg, 2, &set, |_, _| {}).unwrap_err(),
        Error::Cancelled
    );
    let flag = AtomicBool::new(false);
    let mut calls = 0;
    let r = run_parallel(&model, &cfg, 1, &flag, |done, total| {
        calls += 1;
        assert!(done < total, "cancelled before the end");
        flag.store(true, Ordering::Relaxed);
    });
    assert_eq!(r.unwrap_err(), Error::Cancelled);
    assert_eq!(calls, 1);
    let mut chunks = Vec::new();
    let r = run_sequential(&model, &cfg, |done, total| {
        chunks.push((done, total));
        done < 3
    });
    assert_eq!(r.unwrap_err(), Error::Cancelled);
    assert_eq!(chunks, vec![(1, 13), (2, 13), (3, 13)]); // ⌈200/16⌉ = 13 chunks
    assert_eq!(
        run_pcrlb_sequential(&model, &cfg, |_, _| false).unwrap_err(),
        Error::Cancelled
    );
}

// ---------------------------------------------------------------------------------------------
// Monte Carlo harness: determinism and what a run computes.
// ---------------------------------------------------------------------------------------------

/// 1 thread, 2 threads and the sequential driver give bitwise equal curves (3 chunks, the last
/// one partial; 3 noise runs per trajectory), and the progress ends at (runs, runs).
#[test]
fn identical_results_for_one_and_two_threads_and_sequential() {
    let model = model();
    let cfg = MonteCarloConfig {
        steps: 40,
        ..study(TrackScenario::II, FAST_STEP_S, 37, 3)
    };
    let never = AtomicBool::new(false);
    let mut last = (0, 0);
    let one = run_parallel(&model, &cfg, 1, &never, |d, t| last = (d, t)).unwrap();
    assert_eq!(last, (111, 111));
    let two = run_parallel(&model, &cfg, 2, &never, |_, _| {}).unwrap();
    let seq = run_sequential(&model, &cfg, |_, _| true).unwrap();
    assert_eq!(one, two);
    assert_eq!(one, seq);
    assert_eq!((one.runs, one.failed_runs, one.seed), (111, 0, SEED));
    assert_eq!(one.t_s.len(), 41);
    // The PCRLB-only driver walks the same truth trajectories: the same curve, bitwise.
    assert_eq!(
        run_pcrlb_sequential(&model, &cfg, |_, _| true).unwrap(),
        seq.rmse_pcrlb_m
    );
    // Another seed changes the curves (the seed is used).
    let other = run_sequential(&model, &MonteCarloConfig { seed: 2, ..cfg }, |_, _| true).unwrap();
    assert_ne!(other.rmse_ekf_m, seq.rmse_ekf_m);
}

/// The harness computes what its documentation says: trajectory `i` from stream
/// `rng(seed, 2i)`, noise run `j` from `rng(seed, 2(i·N_noise + j) + 1)` with one standard normal
/// per link in link order, `z_p = τ_p(r) + σ_p(r) w`, an `Ekf::update` with R at the prediction,
/// ε_EKF = √(mean ‖r̂ − r‖²), mean NEES, and E9 with the mean `F(r_true)` (`localize::fisher`). Rebuilt
/// here from the public API for 2 trajectories × 5 noise runs; equal to 1e-12 relative (the harness
/// evaluates delays, σ and F from shared per-node geometry, equal up to rounding).
#[test]
fn monte_carlo_reproduces_independent_filter_runs() {
    let model = model();
    let cfg = MonteCarloConfig {
        steps: 30,
        ..study(TrackScenario::III, FAST_STEP_S, 2, 5)
    };
    let got = run_sequential(&model, &cfg, |_, _| true).unwrap();
    let sampler = TruthSampler::new(cfg.motion, cfg.mean_state, &cfg.initial_covariance).unwrap();
    let (mut se, mut nees) = (vec![0.0; 31], vec![0.0; 31]);
    let mut fisher = vec![Mat2::zeros(); 30];
    let mut truth = Vec::new();
    for i in 0..2u64 {
        sampler.sample(30, &mut measure::rng(SEED, 2 * i), &mut truth);
        for (n, x) in truth.iter().enumerate().skip(1) {
            fisher[n - 1] += localize::fisher(&model, Vec2::new(x[0], x[1])) / 2.0;
        }
        for j in 0..5u64 {
            let mut rng = measure::rng(SEED, 2 * (i * 5 + j) + 1);
            let mut f = Ekf::new(cfg.mean_state, cfg.initial_covariance).unwrap();
            for (n, x) in truth.iter().enumerate() {
                if n > 0 {
                    let r = Vec2::new(x[0], x[1]);
                    let z: Vec<Option<Real>> = (0..4)
                        .map(|p| {
                            Some(
                                model.network.delay(p, r)
                                    + model.sigma_delay(p, r) * measure::standard_normal(&mut rng),
                            )
                        })
                        .collect();
                    f.step(&cfg.motion, &model, &z, MeasurementNoise::AtPrediction)
                        .unwrap();
                }
                se[n] += (f.position() - Vec2::new(x[0], x[1])).norm_squared();
                nees[n] += f.nees(x).unwrap();
            }
        }
    }
    let pcrlb = pcrlb_rmse(&cfg.motion, &cfg.initial_covariance, &fisher).unwrap();
    for n in 0..=30 {
        rel_close("ε_EKF", got.rmse_ekf_m[n], (se[n] / 10.0).sqrt(), 1e-12);
        rel_close("NEES", got.nees[n], nees[n] / 10.0, 1e-12);
        rel_close(
            "ε_PCRLB",
            got.rmse_pcrlb_m[n].unwrap(),
            pcrlb[n].unwrap(),
            1e-12,
        );
    }
}

// ---------------------------------------------------------------------------------------------
// Check 5 and check 10: the posterior CRLB.
// ---------------------------------------------------------------------------------------------

/// Check 5: ε_PCRLB(t₀) = √(0.1 + 0.1) = 0.4472 m exactly (F_B(t₀) = P(t₀)⁻¹) for the Monte Carlo
/// and the nominal bound; ε_EKF(t₀) is the sample RMS of the initial errors x(t₀) − x̄₀ ~ 𝒩(0, P₀),
/// so it is 0.4472 m within Monte Carlo error: ‖e‖² = 0.1·χ²₂ has mean 0.2 and sd 0.2, so with
/// N = 2000 independent trajectories (noise runs share x(t₀)) ε² has relative sd 1/√N = 2.2 %;
/// 4 sd → ε within 4.5 %. The bound holds at every step of the nominal recursion: ε_PCRLB ≤ 0.4472
/// after measurements only add information (checked over 10 s).
#[test]
fn check5_initial_bound_and_error() {
    let model = model();
    let cfg = MonteCarloConfig {
        steps: 1,
        ..study(TrackScenario::I, FAST_STEP_S, 2000, 1)
    };
    let mc = run_sequential(&model, &cfg, |_, _| true).unwrap();
    rel_close(
        "ε_PCRLB(t0) MC (check 5)",
        mc.rmse_pcrlb_m[0].unwrap(),
        0.2f64.sqrt(),
        1e-15,
    );
    rel_close(
        "ε_PCRLB(t0) (check 5, 4 digits)",
        mc.rmse_pcrlb_m[0].unwrap(),
        0.4472,
        5e-5 / 0.4472,
    );
    rel_close(
        "ε_EKF(t0) sample",
        mc.rmse_ekf_m[0],
        0.2f64.sqrt(),
        4.0 / (2000f64).sqrt() / 2.0,
    );
    for s in TrackScenario::ALL {
        let nominal = nominal_pcrlb_rmse(
            &model,
            &fast_motion(),
            &s.mean_state(),
            &paper_initial_covariance(),
            100,
        )
        .unwrap();
        rel_close(
            "nominal ε_PCRLB(t0) (check 5)",
            nominal[0].unwrap(),
            0.2f64.sqrt(),
            1e-15,
        );
        assert!(nominal
            .iter()
            .all(|v| v.unwrap() <= 0.2f64.sqrt() * (1.0 + 1e-15)));
    }
}

/// Spec check 10 table, cm at 1, 2, 5, 10 s.
const CHECK10_FAST: [[Real; 4]; 3] = [
    [0.459, 0.529, 0.671, 1.29],
    [2.90, 3.02, 1.98, 1.29],
    [3.49, 3.19, 1.39, 0.46],
];
const CHECK10_PAPER: [[Real; 4]; 3] = [
    [0.140, 0.158, 0.195, 0.350],
    [0.725, 0.768, 0.518, 0.350],
    [0.841, 0.810, 0.373, 0.140],
];

fn check10(dt: Real, table: &[[Real; 4]; 3]) {
    let model = model();
    for (s, want) in TrackScenario::ALL.iter().zip(table) {
        let cfg = study(*s, dt, 5000, 1);
        let pcrlb = run_pcrlb_sequential(&model, &cfg, |_, _| true).unwrap();
        for (t, w) in [1.0, 2.0, 5.0, 10.0].iter().zip(want) {
            let got = pcrlb[at(*t, dt)].unwrap() * 100.0;
            rel_close(
                &format!("check 10: T {dt} s, scenario {} at {t} s [cm]", s.name()),
                got,
                *w,
                0.05,
            );
        }
    }
}

/// Spec check 10, fast profile: the Monte Carlo PCRLB over 5000 truth trajectories (seed 1) is
/// within 5 % of the table. (The PCRLB needs only the truth trajectories and their Fisher
/// matrices: `run_pcrlb_sequential`, no EKF runs.) Monte Carlo spread over seeds 1–5 (5000
/// trajectories each): scenario II at 10 s 1.27–1.36 cm, III at 5 s 1.33–1.43 cm — E[F] is
/// heavy-tailed near the nodes — every other entry within ±1 %; seed 1 gives 1.327 and 1.410.
#[test]
fn check10_monte_carlo_pcrlb_fast_profile() {
    check10(FAST_STEP_S, &CHECK10_FAST);
}

/// Spec check 10 at the paper step 2.048 ms (4883 steps, 5000 trajectories: 7.3·10⁷ truth
/// steps; ≈ 6 s in release, minutes in a debug build, so ignored by default). Seed 1 is within
/// 1 % of the table except scenario III at 5 s (0.358 cm, −4.0 %; seed 2: 0.375) and II at 10 s
/// (0.353, +0.9 %).
#[test]
#[ignore = "paper step: run with --release -- --ignored"]
fn check10_monte_carlo_pcrlb_paper_step() {
    check10(PAPER_STEP_S, &CHECK10_PAPER);
}

/// Check 9 against check 10 in scenario I: away from nodes and baselines F(r) varies slowly, so
/// the nominal bound (F at the mean path) and the Monte Carlo bound (mean F) agree — the spec's
/// tables differ by 0.2 %, 0.2 %, 0.4 % at 1, 2, 5 s (and by 5 % at 10 s, where the spread of the
/// paths is larger). Here within 1 % up to 5 s, from 2000 trajectories (MC spread < 0.3 % there).
#[test]
fn nominal_and_monte_carlo_pcrlb_agree_in_scenario_i() {
    let model = model();
    let s = TrackScenario::I;
    let nominal = nominal_pcrlb_rmse(
        &model,
        &fast_motion(),
        &s.mean_state(),
        &paper_initial_covariance(),
        100,
    )
    .unwrap();
    let mc = run_pcrlb_sequential(&model, &study(s, FAST_STEP_S, 2000, 1), |_, _| true).unwrap();
    for t in [0.5, 1.0, 2.0, 3.0, 4.0, 5.0] {
        let n = at(t, FAST_STEP_S);
        rel_close(
            &format!("MC vs nominal at {t} s"),
            mc[n].unwrap(),
            nominal[n].unwrap(),
            0.01,
        );
    }
    // And the nominal values are check 9's (0.4581, 0.5278, 0.6685 cm).
    for (t, w) in [(1.0, 0.4581), (2.0, 0.5278), (5.0, 0.6685)] {
        rel_close(
            "check 9",
            nominal[at(t, FAST_STEP_S)].unwrap() * 100.0,
            w,
            1e-3,
        );
    }
}

// ---------------------------------------------------------------------------------------------
// Check 11: EKF against the PCRLB, and NEES consistency.
// ---------------------------------------------------------------------------------------------

/// Runs the three scenarios and checks spec check 11:
/// - ε_EKF ≥ ε_PCRLB up to Monte Carlo error at every step: the sample RMSE of N independent
///   2-D Gaussian errors has relative sd ≤ √(1/(2N)) (‖e‖² has variance 2 tr Σ² ≤ 2 (tr Σ)²);
///   N = trajectories (noise runs of one trajectory share its initial error), 3 sd;
/// - scenario I: ε_EKF/ε_PCRLB ≤ 1.05 for 1 ≤ t ≤ 5 s;
/// - at 10 s the ratio exceeds 1.2 in II and III.
///
/// Returns the ratios at 10 s.
fn check11(trajectories: usize, noise_runs: usize) -> [Real; 3] {
    let model = model();
    let slack = 1.0 - 3.0 * (1.0 / (2.0 * trajectories as Real)).sqrt();
    TrackScenario::ALL.map(|s| {
        let r: MonteCarloResult = run_sequential(
            &model,
            &study(s, FAST_STEP_S, trajectories, noise_runs),
            |_, _| true,
        )
        .unwrap();
        assert_eq!(r.failed_runs, 0);
        let ratio: Vec<Real> = r
            .rmse_ekf_m
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
        ratio[100]
    })
}

/// Spec check 11 at the spec's size, 1000 × 10 runs (3·10⁶ EKF steps: ≈ 0.5 s in release, about
/// a minute in a debug build). Seed 1 ratios at 10 s: I 1.19, II 1.79, III 1.29; seeds 1–5 give
/// I ≤ 1.018 on [1, 5] s, II 1.51–1.81 and III 1.27–1.35 at 10 s.
#[test]
#[ignore = "3e6 EKF steps: run with --release -- --ignored"]
fn check11_ekf_vs_pcrlb_fast_profile() {
    let at10 = check11(1000, 10);
    assert!(
        (at10[1] - 1.79).abs() < 0.01 && (at10[2] - 1.29).abs() < 0.01,
        "{at10:?}"
    );
}

/// Spec check 11 at 200 × 5 runs (always run). Over seeds 1–8 at this size the scenario I ratio
/// stays ≤ 1.04 on [1, 5] s and the 10 s ratios are II 1.39–1.79, III 1.25–1.39, so the
/// thresholds of check 11 hold with margin; the lower bound uses N = 200 (slack 15 %).
#[test]
fn check11_ekf_vs_pcrlb_small() {
    check11(200, 5);
}

/// NEES consistency on scenario I (fast profile, 1000 independent runs: one noise run per
/// trajectory). For a consistent filter the mean NEES of N runs is χ²₄ₙ/N; its 99 % band
/// [χ²₄ₙ(0.005)/N, χ²₄ₙ(0.995)/N] is [3.773, 4.234] for N = 1000 (Wilson–Hilferty; the
/// skewness-corrected normal approximation 4N ± z√(8N) + (2/3)(z² − 1) gives the same to 1e-4).
/// It must hold at ≥ 90 % of the 101 steps. The exceptions are the first updates from the wide
/// prior (P₀ = 0.1 m² against sub-centimetre measurements: the linearisation error makes the EKF
/// over-confident; mean NEES ≈ 54, 34, 9, 4.8, 4.3 at steps 1–5 for seeds 1–6), so from
/// t = 0.6 s on ≥ 95 % must hold (seeds 1–6: 97–100 %).
#[test]
fn nees_consistent_on_scenario_i() {
    let model = model();
    let n_runs = 1000;
    let r = run_sequential(
        &model,
        &study(TrackScenario::I, FAST_STEP_S, n_runs, 1),
        |_, _| true,
    )
    .unwrap();
    assert_eq!(r.runs, n_runs);
    let k = 4.0 * n_runs as Real;
    let z = 2.575_829_303_548_900_4; // standard normal 0.995 quantile
    let wh = |z: Real| {
        k * (1.0 - 2.0 / (9.0 * k) + z * (2.0 / (9.0 * k)).sqrt()).powi(3) / n_runs as Real
    };
    let (lo, hi) = (wh(-z), wh(z));
    assert!(
        (lo - 3.7734).abs() < 1e-3 && (hi - 4.2341).abs() < 1e-3,
        "band [{lo}, {hi}]"
    );
    let inside = |v: &Real| (lo..=hi).contains(v);
    let all = r.nees.iter().filter(|v| inside(v)).count() as Real / r.nees.len() as Real;
    let late =
        r.nees[6..].iter().filter(|v| inside(v)).count() as Real / (r.nees.len() - 6) as Real;
    assert!(
        all >= 0.90,
        "NEES in the 99 % band at {:.1} % of steps: {:?}",
        all * 100.0,
        r.nees
    );
    assert!(
        late >= 0.95,
        "NEES in the band at {:.1} % of steps from 0.6 s",
        late * 100.0
    );
    // The initial NEES is the prior's own: (x(t0) − x̄0)ᵀ P0⁻¹ (x(t0) − x̄0) ~ χ²₄ per run.
    assert!(inside(&r.nees[0]), "NEES(t0) = {}", r.nees[0]);
}
