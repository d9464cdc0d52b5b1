use super::*;

/// Spec check 4: T = 2.048 ms, q̃ = 0.01 → Q11 = 2.8633e-11 m², Q13 = 2.0972e-8,
/// Q33 = 2.048e-5 (m/s)².
#[test]
fn check4_process_noise() {
    let q = ConstantVelocity::new(2.048e-3, 0.01).process_noise();
    assert!((q[(0, 0)] / 2.8633e-11 - 1.0).abs() < 5e-5);
    assert!((q[(0, 2)] / 2.0972e-8 - 1.0).abs() < 5e-5);
    assert!((q[(2, 2)] / 2.048e-5 - 1.0).abs() < 1e-12);
    assert_eq!(q[(1, 1)], q[(0, 0)]);
    assert_eq!(q[(0, 1)], 0.0);
    assert_eq!(q, q.transpose());
}

/// The structured `A P Aᵀ + Q` equals the plain matrix product; `L Lᵀ = Q`.
#[test]
fn structured_products_match_plain_algebra() {
    let m = ConstantVelocity::new(0.1, 0.01);
    let p = Mat4::new(
        2.0, 0.3, 0.1, -0.2, //
        0.3, 1.5, 0.05, 0.1, //
        0.1, 0.05, 0.4, 0.02, //
        -0.2, 0.1, 0.02, 0.3,
    );
    let a = m.transition();
    let plain = a * p * a.transpose() + m.process_noise();
    assert!((m.propagate_covariance(&p) - plain).abs().max() < 1e-15);
    let x = Vec4::new(1.0, 2.0, 3.0, 4.0);
    assert_eq!(m.propagate(&x), a * x);
    let l = m.process_noise_factor();
    assert!((l * l.transpose() - m.process_noise()).abs().max() < 1e-18);
}
