use super::*;

#[test]
fn the_loop_closes_after_its_period_and_moves_at_its_speed() {
    let p = LoopPath::default();
    let period = 2.0 * crate::math::PI * p.radius_m / p.speed_mps; // 35.9 s
    let (a, b) = (p.state_at(3.0), p.state_at(3.0 + period));
    assert!((a - b).norm() < 1e-12);
    assert!((Vec2::new(a[2], a[3]).norm() - 1.4).abs() < 1e-12);
    // Velocity is the derivative of position (central difference, h = 1 ms).
    let (m, q) = (p.state_at(3.0 - 1e-3), p.state_at(3.0 + 1e-3));
    assert!(((q[0] - m[0]) / 2e-3 - a[2]).abs() < 1e-6);
    assert!(((q[1] - m[1]) / 2e-3 - a[3]).abs() < 1e-6);
    assert_eq!(p.states(0.1, 600).len(), 600);
    assert!(LoopPath { radius_m: 0.0, ..p }.validate().is_err());
}
