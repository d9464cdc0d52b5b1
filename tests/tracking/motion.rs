#![cfg(not(target_arch = "wasm32"))]
//! Tracking, the motion model (spec §6, E7): `A(T)` composes, `Q(T)` is the PSD discretisation
//! of white-noise acceleration and the EKF predict is `A P Aᵀ + Q`. Check 4 (the Q entries at
//! 2.048 ms) is the unit test `motion::check4`. (Split from the former `tracking.rs`.)

use crate::common;

use common::rel_close;
use common::tracking::covariance_close;
use scatterloc::math::{Mat4, Vec4};
use scatterloc::track::ConstantVelocity;
use scatterloc::track::{Ekf, Filter, PAPER_INTENSITY, PAPER_STEP_S};

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
