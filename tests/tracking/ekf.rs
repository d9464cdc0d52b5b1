#![cfg(not(target_arch = "wasm32"))]
//! Tracking, the EKF (spec §6) against a hand-written batch Kalman filter: one update, a run
//! with missing links and predict-only steps, the named errors of bad inputs and NEES. Every
//! expected number is the output of the reference filter below or a closed form stated next to
//! it. (Split from the former `tracking.rs`.)

use crate::common;

use nalgebra::{DMatrix, DVector};

use common::rel_close;
use common::sensors_model as model;
use common::tracking::{covariance_close, fast_motion};
use scatterloc::math::{Mat4, Real, Vec2, Vec4, SPEED_OF_LIGHT};
use scatterloc::track::ConstantVelocity;
use scatterloc::track::{paper_initial_covariance, TrackScenario, TruthSampler};
use scatterloc::track::{Ekf, Filter, MeasurementNoise, UpdateSummary};
use scatterloc::{measure, Error, Model};

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
    // Delays that are not a number in 0 < delay ≤ 1 s (issue 12, item 7): the first bad link in
    // link order is named.
    for v in [
        Real::NAN,
        Real::INFINITY,
        Real::NEG_INFINITY,
        0.0,
        -5e-8,
        1.5,
        1e308,
    ] {
        let mut z = good.clone();
        z[3] = Some(v);
        z[1] = Some(v);
        for noise in [
            MeasurementNoise::AtPrediction,
            MeasurementNoise::Fixed(&sig),
        ] {
            let e = f.update(&model, &z, noise, None).unwrap_err();
            assert!(
                matches!(e, Error::InvalidDelay { link: 1, value } if value.to_bits() == v.to_bits()),
                "{v}: {e:?}"
            );
            assert!(e.to_string().contains("[1]"), "{e}");
        }
    }
    // σ ≤ 0, NaN or infinite in Fixed noise (and one so small that 1/(cσ)² overflows).
    // And σ outside the documented 1e-15 ..= 1e-3 s (issue 12, item 7: 1e308 gave an exact fit).
    for bad in [
        0.0,
        -1e-11,
        Real::NAN,
        Real::INFINITY,
        1e-170,
        1e-16,
        2e-3,
        1e308,
    ] {
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
    assert!(matches!(
        g.step(&motion, &model, &z, MeasurementNoise::AtPrediction)
            .unwrap_err(),
        Error::InvalidDelay { link: 0, value } if value.is_nan()
    ));
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

/// The links' position information at `r` with the same σ on every link, written out here from
/// the geometry: `M = Σ_p g_p g_pᵀ/(cσ)²`, `g_p` the sum of the unit vectors from Tx and Rx (E3).
fn link_information(model: &Model, r: Vec2, sigma: Real) -> nalgebra::Matrix2<Real> {
    let w = 1.0 / (SPEED_OF_LIGHT * sigma).powi(2);
    (0..model.link_count())
        .map(|p| {
            let (tx, rx) = model.network.link_nodes(p);
            let g = (r - tx).normalize() + (r - rx).normalize();
            w * g * g.transpose()
        })
        .sum()
}

/// Issue 12, item 8: a prior of 10¹² m² (σ = 1000 km) is legitimate and is tracked. At the true
/// position (`ν = 0`), with fixed σ and velocity uncorrelated with position, the closed form is
/// `P⁺_rr = (P_rr⁻¹ + M)⁻¹ → M⁻¹` as the prior widens, `M = Σ g gᵀ/(cσ)²` (computed here from the
/// link geometry), the velocity block is untouched and the state does not move. The old
/// covariance-form update cancelled 10¹² against 10¹² and failed with "ekf.covariance: not
/// positive definite".
#[test]
fn a_wide_prior_is_tracked() {
    let model = model();
    let r = Vec2::new(20.0, 6.0);
    let n = model.link_count();
    let sig = vec![1e-10; n];
    let z: Vec<Option<Real>> = (0..n).map(|p| Some(model.network.delay(p, r))).collect();
    let m = link_information(&model, r, 1e-10);
    for var in [1e6, 1e8, 1e10, 1e12] {
        let p0 = Mat4::from_diagonal(&Vec4::new(var, var, 0.01, 0.01));
        let x0 = Vec4::new(r.x, r.y, 0.3, -0.2);
        let mut f = Ekf::new(x0, p0).unwrap();
        let s = f
            .update(&model, &z, MeasurementNoise::Fixed(&sig), None)
            .unwrap();
        assert_eq!(s.links_used, n);
        let expect = (nalgebra::Matrix2::identity() / var + m)
            .try_inverse()
            .unwrap();
        let got = f.covariance.fixed_view::<2, 2>(0, 0).into_owned();
        for (a, b) in got.iter().zip(expect.iter()) {
            rel_close(&format!("P⁺_rr at prior {var}"), *a, *b, 1e-7);
        }
        rel_close("P⁺_vxvx", f.covariance[(2, 2)], 0.01, 1e-12);
        rel_close("P⁺_vyvy", f.covariance[(3, 3)], 0.01, 1e-12);
        assert!((f.state - x0).norm() < 1e-9, "{}", f.state - x0);
    }
    // Past the limit it is a named error on the input, not on an internal matrix.
    let p0 = Mat4::from_diagonal(&Vec4::new(0.1, 0.1, 0.01, 1e308));
    let e = Ekf::new(Vec4::new(r.x, r.y, 0.0, 0.0), p0).unwrap_err();
    assert!(
        e.to_string().starts_with("initial_covariance[3][3]: 1e308"),
        "{e}"
    );
}

/// The two update forms (covariance form below `tr(M P_rr) = 10⁶`, information form above)
/// both equal the textbook batch Kalman filter (the reference above) on either side of the
/// switch, off the true position (`ν ≠ 0`) and with position–velocity correlation; there the
/// reference's own rounding is ≈ ε·10⁶.
#[test]
fn both_update_forms_agree_with_the_reference_at_the_switch() {
    let model = model();
    let r = Vec2::new(20.0, 6.0);
    let n = model.link_count();
    let sig = vec![3e-10; n];
    let z: Vec<Option<Real>> = (0..n)
        .map(|p| Some(model.network.delay(p, r) + 1e-10 * (p as Real - 1.5)))
        .collect();
    // tr(M P_rr) = var · tr(M) (M here at r; the prior mean is 5 cm off).
    let switch = 1e6 / link_information(&model, r, 3e-10).trace();
    for var in [switch * 0.98, switch * 1.02] {
        let mut p0 = Mat4::from_diagonal(&Vec4::new(var, var, 0.04, 0.04));
        p0[(0, 2)] = 0.1 * (var * 0.04).sqrt();
        p0[(2, 0)] = p0[(0, 2)];
        let x0 = Vec4::new(r.x + 0.05, r.y - 0.03, 0.3, -0.2);
        let mut f = Ekf::new(x0, p0).unwrap();
        let s = f
            .update(&model, &z, MeasurementNoise::Fixed(&sig), None)
            .unwrap();
        let reference = reference_update(&model, &x0, &p0, &z, &sig);
        assert_matches_reference(&format!("prior {var}"), &f, s.nis, &reference, 1e-7, 1e-6);
    }
}

/// Issue 13 §3: the fixed-size update (links in blocks of 4, transmitters' views shared, the
/// noise option resolved once) is step by step the textbook batch Kalman filter (the reference
/// above) over long runs: 400 steps at T = 10 ms on scenario II from `P(t₀)`, with `R` at the
/// prediction, given `R` (σ at the truth) and `R` at the truth, a link missing every 3rd step and
/// no link every 13th, on the 4 links of `sensors2019`, the 3 of `iclgnss2019` (one padded
/// block), a 3 × 3 mesh (9 links of 3 transmitters) and a 5 × 2 mesh (transmitters past the
/// table of 4). Each step's reference starts from the filter's own predicted state, so rounding
/// does not accumulate: state and covariance agree to 1e-12 relative after the first 3 updates
/// (1e-10 while the prior is wide, see `ekf_update_equals_batch_kalman_filter`), NIS to 1e-10
/// (`νᵀR⁻¹ν − bᵀP_rr N b` cancels while `P` is still wide: 1.8e-12 seen), and the
/// innovations to 1e-20 s (3·10⁻¹² m: they are differences of ranges of tens of metres, rounded
/// at ≈ 10⁻¹⁴ m, and may themselves be as small as 10⁻¹⁵ s).
#[test]
fn long_runs_equal_the_batch_kalman_filter_step_by_step() {
    let motion = ConstantVelocity::new(0.01, scatterloc::track::PAPER_INTENSITY);
    let s = TrackScenario::II;
    let sampler = TruthSampler::new(motion, s.mean_state(), &paper_initial_covariance()).unwrap();
    let mut truth = Vec::new();
    sampler.sample(400, &mut measure::rng(21, 0), &mut truth);
    let models = [
        ("sensors2019", model()),
        (
            "iclgnss2019",
            Model::new(&scatterloc::scenario::presets::iclgnss2019()).unwrap(),
        ),
        ("mesh 3x3", common::tracking::mesh(3, 3)),
        ("mesh 5x2", common::tracking::mesh(5, 2)),
    ];
    for (name, model) in &models {
        let n = model.link_count();
        for option in ["at prediction", "given", "at the truth"] {
            let mut rng = measure::rng(21, 1);
            let mut f = Ekf::new(s.mean_state(), paper_initial_covariance()).unwrap();
            for (k, x) in truth.iter().enumerate().skip(1) {
                let r = Vec2::new(x[0], x[1]);
                let mut z: Vec<Option<Real>> = measure::noisy_delays(model, r, &mut rng)
                    .into_iter()
                    .map(Some)
                    .collect();
                if k % 3 == 0 {
                    z[k % n] = None;
                }
                if k % 13 == 0 {
                    z.fill(None);
                }
                f.predict(&motion);
                let sigma_truth = model.sigma_delays(r);
                let (noise, sigmas) = match option {
                    "at prediction" => (
                        MeasurementNoise::AtPrediction,
                        model.sigma_delays(f.position()),
                    ),
                    "given" => (MeasurementNoise::Fixed(&sigma_truth), sigma_truth.clone()),
                    _ => (MeasurementNoise::At(r), sigma_truth.clone()),
                };
                let reference = reference_update(model, &f.state, &f.covariance, &z, &sigmas);
                let mut innovations = vec![Some(0.0); n];
                let u = f.update(model, &z, noise, Some(&mut innovations)).unwrap();
                let used = z.iter().filter(|v| v.is_some()).count();
                assert_eq!(u.links_used, used, "{name} {option} step {k}");
                let rel = if k <= 3 { 1e-10 } else { 1e-12 };
                let what = format!("{name} {option} step {k}");
                assert_matches_reference(&what, &f, u.nis, &reference, rel, 1e-10);
                for (a, b) in innovations.iter().zip(&reference.innovations) {
                    assert_eq!(a.is_some(), b.is_some(), "{what}");
                    if let (Some(a), Some(b)) = (a, b) {
                        common::abs_close(&what, *a, *b, 1e-20);
                    }
                }
            }
            // The filter tracks: within 2 cm of the truth at the end.
            let end = truth.last().unwrap();
            let off = (f.position() - Vec2::new(end[0], end[1])).norm();
            assert!(off < 0.02, "{name} {option}: {off} m off the truth");
        }
    }
}
