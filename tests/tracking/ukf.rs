#![cfg(not(target_arch = "wasm32"))]
//! The UKF (`filters-and-planning.md` §1) against an independent implementation written here
//! straight from the spec's formulas with `nalgebra::DMatrix`, in the delay domain: a fixed
//! 200-step sequence of each trajectory with missing links, to 1e-10; its prediction against the
//! EKF's (exact for the linear CV model); the near-linear limit (a tight prior) against the EKF's
//! update; and the named errors.

use crate::common;

use nalgebra::{Cholesky, DMatrix, DVector};

use common::sensors_model as model;
use common::tracking::{fast_motion, mesh};
use scatterloc::math::{Mat4, Real, Vec2, Vec4, SPEED_OF_LIGHT};
use scatterloc::track::{paper_initial_covariance, TrackScenario, TruthSampler};
use scatterloc::track::{ConstantVelocity, Ekf, Filter, MeasurementNoise, Ukf, UkfParams};
use scatterloc::{measure, Error, Model};

/// One reference UKF step (spec §1), with `σ_p` from the link budget at the predicted position.
fn reference_step(
    model: &Model,
    motion: &ConstantVelocity,
    params: &UkfParams,
    x: &DVector<Real>,
    p: &DMatrix<Real>,
    z: &[Option<Real>],
) -> (DVector<Real>, DMatrix<Real>, DMatrix<Real>) {
    let n = 4;
    let a = DMatrix::from_fn(4, 4, |i, j| motion.transition()[(i, j)]);
    let q = DMatrix::from_fn(4, 4, |i, j| motion.process_noise()[(i, j)]);
    // Prediction: A x, A P Aᵀ + Q.
    let xp = &a * x;
    let pp = &a * p * a.transpose() + q;
    let used: Vec<usize> = (0..z.len()).filter(|&i| z[i].is_some()).collect();
    let m = used.len();
    if m == 0 {
        return (xp, pp.clone(), pp);
    }
    let lambda = params.alpha * params.alpha * (n as Real + params.kappa) - n as Real;
    let wm0 = lambda / (n as Real + lambda);
    let wc0 = wm0 + 1.0 - params.alpha * params.alpha + params.beta;
    let wi = 1.0 / (2.0 * (n as Real + lambda));
    let l = Cholesky::new(&pp * (n as Real + lambda)).unwrap().l();
    let mut chi = vec![xp.clone()];
    for i in 0..n {
        chi.push(&xp + l.column(i));
    }
    for i in 0..n {
        chi.push(&xp - l.column(i));
    }
    // h: the bistatic delay (E1) written out: (|r − Tx| + |r − Rx|)/c.
    let h = |c: &DVector<Real>| {
        DVector::from_iterator(
            m,
            used.iter().map(|&k| {
                let (tx, rx) = model.network.link_nodes(k);
                let d = |node: Vec2| ((c[0] - node.x).powi(2) + (c[1] - node.y).powi(2)).sqrt();
                (d(tx) + d(rx)) / SPEED_OF_LIGHT
            }),
        )
    };
    let zs: Vec<DVector<Real>> = chi.iter().map(h).collect();
    let w = |i: usize| if i == 0 { (wm0, wc0) } else { (wi, wi) };
    let mut zhat = DVector::zeros(m);
    for (i, zi) in zs.iter().enumerate() {
        zhat += w(i).0 * zi;
    }
    let r_pred = Vec2::new(xp[0], xp[1]);
    let mut s = DMatrix::from_diagonal(&DVector::from_iterator(
        m,
        used.iter().map(|&k| model.sigma_delay(k, r_pred).powi(2)),
    ));
    let mut pxz = DMatrix::zeros(n, m);
    for (i, zi) in zs.iter().enumerate() {
        s += w(i).1 * (zi - &zhat) * (zi - &zhat).transpose();
        pxz += w(i).1 * (&chi[i] - &xp) * (zi - &zhat).transpose();
    }
    // K = P_xz S⁻¹, solved with S's Cholesky factor (S is symmetric positive definite). With an
    // explicit inverse instead, S's condition number (~10⁵ on the first update from the wide
    // prior) costs ~10⁻⁷ of the updated P, and the two filters part by ~10⁻⁸ m/s one step later.
    let k = Cholesky::new(s.clone())
        .unwrap()
        .solve(&pxz.transpose())
        .transpose();
    let zv = DVector::from_iterator(m, used.iter().map(|&i| z[i].unwrap()));
    let xn = &xp + &k * (zv - zhat);
    let pn = &pp - &k * &s * k.transpose();
    let pn = (&pn + pn.transpose()) * 0.5;
    (xn, pn, pp)
}

/// A truth of `steps` steps and its noisy delays, every 7th step missing link 2, every 23rd
/// missing all links.
fn sequence(
    model: &Model,
    s: TrackScenario,
    motion: &ConstantVelocity,
    steps: usize,
    seed: u64,
) -> Vec<Vec<Option<Real>>> {
    let sampler = TruthSampler::new(*motion, s.mean_state(), &paper_initial_covariance()).unwrap();
    let mut truth = Vec::new();
    sampler.sample(steps + 1, &mut measure::rng(seed, 0), &mut truth);
    let mut noise = measure::rng(seed, 1);
    truth[1..=steps]
        .iter()
        .enumerate()
        .map(|(k, x)| {
            let mut z: Vec<Option<Real>> =
                measure::noisy_delays(model, Vec2::new(x[0], x[1]), &mut noise)
                    .into_iter()
                    .map(Some)
                    .collect();
            if k % 7 == 3 {
                z[2] = None;
            }
            if k % 23 == 11 {
                z.fill(None);
            }
            z
        })
        .collect()
}

/// sensors2019 (4 links), a 2 × 3 mesh (6 links) and a 3 × 3 mesh (9 links): the UKF's
/// stack path for up to 4 and up to 8 links and its heap path.
#[test]
fn ukf_equals_the_spec_formulas_over_200_steps() {
    let motion = fast_motion();
    for (model, s, params) in [
        (model(), TrackScenario::I, UkfParams::default()),
        (model(), TrackScenario::II, UkfParams::default()),
        (
            model(),
            TrackScenario::III,
            UkfParams {
                alpha: 0.5,
                beta: 2.0,
                kappa: 1.0,
            },
        ),
        (mesh(2, 3), TrackScenario::I, UkfParams::default()),
        (mesh(3, 3), TrackScenario::II, UkfParams::default()),
    ] {
        let zs = sequence(&model, s, &motion, 200, 4);
        let mut f = Ukf::new(s.mean_state(), paper_initial_covariance(), params).unwrap();
        let mut x = DVector::from_column_slice(s.mean_state().as_slice());
        let mut p = DMatrix::from_fn(4, 4, |i, j| paper_initial_covariance()[(i, j)]);
        let mut worst: Real = 0.0;
        for (k, z) in zs.iter().enumerate() {
            f.step(&motion, &model, z, MeasurementNoise::AtPrediction)
                .unwrap();
            let (xn, pn, pp) = reference_step(&model, &motion, &params, &x, &p, z);
            (x, p) = (xn, pn);
            for i in 0..4 {
                let d = (f.state[i] - x[i]).abs();
                worst = worst.max(d);
                assert!(
                    d <= 1e-10,
                    "{s:?} step {k}: state[{i}] {} vs {}",
                    f.state[i],
                    x[i]
                );
            }
            // `P = P⁻ − K S Kᵀ` cancels: both sides carry rounding of order cond(S)·ε of `P⁻`
            // (S's condition number is up to ~10⁶ here), so P is compared on P⁻'s scale.
            for i in 0..4 {
                for j in 0..4 {
                    let scale = (pp[(i, i)] * pp[(j, j)]).sqrt();
                    assert!(
                        (f.covariance[(i, j)] - p[(i, j)]).abs() <= 1e-9 * scale,
                        "{s:?} step {k}: P[{i}][{j}] {} vs {}",
                        f.covariance[(i, j)],
                        p[(i, j)]
                    );
                }
            }
        }
        println!(
            "{s:?}, {} links: largest state difference over 200 steps {worst:.2e}",
            model.link_count()
        );
    }
}

#[test]
fn ukf_prediction_is_the_ekfs_and_a_tight_prior_gives_the_ekf_update() {
    let model = model();
    let motion = fast_motion();
    let x0 = Vec4::new(3.0, 4.0, 1.0, -0.5);
    let p0 = Mat4::from_diagonal(&Vec4::new(0.3, 0.2, 0.05, 0.05));
    let mut u = Ukf::new(x0, p0, UkfParams::default()).unwrap();
    let mut e = Ekf::new(x0, p0).unwrap();
    u.predict(&motion);
    e.predict(&motion);
    assert_eq!((u.state, u.covariance), (e.state, e.covariance));
    // Near-linear: a 1 mm prior, where h is linear to ~1e-4 relative over the sigma points.
    let tight = Mat4::from_diagonal(&Vec4::new(1e-6, 1e-6, 1e-6, 1e-6));
    let truth = Vec2::new(3.002, 3.999);
    let z: Vec<Option<Real>> = model.network.delays(truth).into_iter().map(Some).collect();
    let mut u = Ukf::new(x0, tight, UkfParams::default()).unwrap();
    let mut e = Ekf::new(x0, tight).unwrap();
    u.update(&model, &z, MeasurementNoise::AtPrediction)
        .unwrap();
    e.update(&model, &z, MeasurementNoise::AtPrediction, None)
        .unwrap();
    let (du, de) = (u.state - x0, e.state - x0);
    assert!(de.norm() > 1e-5, "the update moves the state: {de}");
    assert!(
        (du - de).norm() <= 1e-3 * de.norm(),
        "UKF correction {du} vs EKF {de}"
    );
    for i in 0..4 {
        for j in 0..4 {
            assert!((u.covariance[(i, j)] - e.covariance[(i, j)]).abs() <= 1e-3 * 1e-6);
        }
    }
}

#[test]
fn ukf_bad_inputs_are_named_and_leave_the_filter_unchanged() {
    let model = model();
    let motion = fast_motion();
    let x0 = TrackScenario::I.mean_state();
    let p0 = paper_initial_covariance();
    for (params, field) in [
        (
            UkfParams {
                alpha: 0.0,
                ..UkfParams::default()
            },
            "ukf_alpha",
        ),
        (
            UkfParams {
                beta: -1.0,
                ..UkfParams::default()
            },
            "ukf_beta",
        ),
        (
            UkfParams {
                kappa: -4.0,
                ..UkfParams::default()
            },
            "ukf_kappa",
        ),
        (
            UkfParams {
                alpha: Real::NAN,
                ..UkfParams::default()
            },
            "ukf_alpha",
        ),
    ] {
        let e = Ukf::new(x0, p0, params).unwrap_err();
        assert!(e.to_string().contains(field), "{e}");
    }
    let mut f = Ukf::new(x0, p0, UkfParams::default()).unwrap();
    let before = f;
    let mut z = vec![Some(1e-7); 4];
    z[1] = Some(-1.0);
    assert!(matches!(
        f.step(&motion, &model, &z, MeasurementNoise::AtPrediction),
        Err(Error::InvalidDelay { link: 1, .. })
    ));
    assert_eq!(f, before);
    assert!(matches!(
        f.step(&motion, &model, &z[..3], MeasurementNoise::AtPrediction),
        Err(Error::LengthMismatch { .. })
    ));
    // A covariance that stopped being positive definite is a reported outcome.
    let mut bad = f;
    bad.covariance[(0, 0)] = -1.0;
    let ok = vec![Some(1e-7); 4];
    assert!(matches!(
        bad.update(&model, &ok, MeasurementNoise::AtPrediction),
        Err(Error::NotPositiveDefinite { .. })
    ));
    // No link: nothing to do.
    let s = f
        .update(&model, &[None; 4], MeasurementNoise::AtPrediction)
        .unwrap();
    assert_eq!((s.links_used, s.nis), (0, 0.0));
    assert_eq!(f, before);
}
