use super::*;

#[test]
fn range_and_gaps() {
    let t = [0.0, 1.0, 2.0, 3.0];
    let ekf = [0.447, 0.02, Real::NAN, 0.004];
    let pcrlb = [Some(0.447), None, Some(0.01), Some(0.0022)];
    let p = TrackingPanel {
        title: "I",
        t_s: &t,
        rmse_ekf_m: &ekf,
        rmse_pcrlb_m: &pcrlb,
    };
    let (lo, hi) = y_range(&[p]);
    // 2.2 mm is within 15 % of 2 mm: one more 1-2-5 step below; 0.447 m fits under 0.5 m.
    assert_eq!((lo, hi), (0.001, 0.5));
    let drawable = |t: Real, v: Real| t.is_finite() && v.is_finite() && v > 0.0;
    let parts = segments(t.iter().copied().zip(ekf.iter().copied()), drawable);
    assert_eq!(parts.len(), 2);
    assert_eq!(parts[1], [(3.0, 0.004)]);
    let bound = pcrlb.iter().map(|v| v.unwrap_or(Real::NAN));
    assert_eq!(segments(t.iter().copied().zip(bound), drawable).len(), 2);
    assert_eq!(y_range(&[]), (1e-3, 1.0));
}
