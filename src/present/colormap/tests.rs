use super::*;

#[test]
fn render_uses_the_spanning_scale_or_grey() {
    let values = [0.01, 0.1, Real::INFINITY];
    let mut rgba = [0u8; 12];
    let scale = render_rgba(&values, &mut rgba).unwrap().unwrap();
    assert_eq!((scale.min, scale.max), (0.01, 0.1));
    assert_eq!(rgba[8..11], UNBOUNDED_RGB);
    assert_ne!(rgba[0..3], rgba[4..7]);
    assert_eq!(render_rgba(&[Real::INFINITY], &mut rgba[..4]), Ok(None));
    assert_eq!(rgba[..4], [72, 72, 80, 255]);
    let e = render_rgba(&values, &mut rgba[..8]).unwrap_err();
    assert!(e.to_string().starts_with("rgba buffer"), "{e}");
}

#[test]
fn bar_ticks_and_gradient() {
    assert!(LogScale::new(Real::NAN, 1.0).is_none());
    assert!(LogScale::new(0.5, 0.5).is_none());
    let t = LogScale::new(0.003, 0.5).unwrap().ticks(usize::MAX);
    assert_eq!(t[1].1.label, "1 cm");
    assert!(t.iter().all(|(f, _)| (0.0..=1.0).contains(f)));
    let g = colorbar_rgba(16);
    assert_eq!(g.len(), 64);
    assert_eq!(g[..3], viridis(0.0));
    assert_eq!(colorbar_rgba(0).len(), 8);
}
