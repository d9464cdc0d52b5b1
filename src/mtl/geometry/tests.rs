use super::*;

fn v(x: Real, y: Real) -> Vec2 {
    Vec2::new(x, y)
}

fn check(e1: &RangeEllipse, e2: &RangeEllipse, pts: &[Vec2]) {
    for p in pts {
        assert!(e1.residual(*p).abs() < 1e-9, "{p:?}");
        assert!(e2.residual(*p).abs() < 1e-9, "{p:?}");
    }
}

#[test]
fn ellipse_of_trp() {
    let e = RangeEllipse::new(v(-3.0, 0.0), v(3.0, 0.0), 10.0).unwrap();
    assert_eq!(e.ellipse.semi_major, 5.0);
    assert_eq!(e.ellipse.semi_minor, 4.0);
    assert!(!e.is_degenerate());
    assert!(RangeEllipse::new(v(-3.0, 0.0), v(3.0, 0.0), 5.9).is_none());
    assert!(RangeEllipse::new(v(-3.0, 0.0), v(3.0, 0.0), Real::NAN).is_none());
    assert!(RangeEllipse::new(v(-3.0, Real::NAN), v(3.0, 0.0), 10.0).is_none());
    assert!(RangeEllipse::new(v(-3.0, 0.0), v(3.0, 0.0), 6.0)
        .unwrap()
        .is_degenerate());
}

#[test]
fn check7_four_points() {
    let e1 = RangeEllipse::new(v(-3.0, 0.0), v(3.0, 0.0), 10.0).unwrap();
    let e2 = RangeEllipse::new(v(0.0, -3.0), v(0.0, 3.0), 10.0).unwrap();
    let pts = intersect(&e1, &e2, None);
    assert_eq!(pts.len(), 4);
    check(&e1, &e2, &pts);
    let s = sqrt(400.0 / 41.0);
    for p in pts.iter() {
        assert!((p.x.abs() - s).abs() < 1e-9 && (p.y.abs() - s).abs() < 1e-9);
        assert!((p.x.abs() - 3.1235).abs() < 5e-5);
    }
}

#[test]
fn check7_two_and_none() {
    let e1 = RangeEllipse::new(v(0.0, 0.0), v(10.0, 0.0), 14.0).unwrap();
    let e2 = RangeEllipse::new(v(0.0, 0.0), v(0.0, 10.0), 14.0).unwrap();
    let pts = intersect(&e1, &e2, None);
    assert_eq!(pts.len(), 2);
    check(&e1, &e2, &pts);
    for want in [4.8985, -1.6108] {
        assert!(pts
            .iter()
            .any(|p| (p.x - want).abs() < 5e-5 && (p.y - want).abs() < 5e-5));
    }
    let e3 = RangeEllipse::new(v(0.0, 0.0), v(10.0, 0.0), 12.0).unwrap();
    let e4 = RangeEllipse::new(v(10.0, 10.0), v(0.0, 10.0), 12.0).unwrap();
    assert!(intersect(&e3, &e4, None).is_empty());
}

#[test]
fn confocal_and_region_and_grazing() {
    let e1 = RangeEllipse::new(v(0.0, 0.0), v(10.0, 0.0), 14.0).unwrap();
    assert!(intersect(&e1, &e1, None).is_empty());
    let e1b = RangeEllipse::new(v(10.0, 0.0), v(0.0, 0.0), 16.0).unwrap();
    assert!(intersect(&e1, &e1b, None).is_empty());
    // Region [0,10]²: (−1.6108, −1.6108) lies outside even when enlarged by 1 m.
    let e2 = RangeEllipse::new(v(0.0, 0.0), v(0.0, 10.0), 14.0).unwrap();
    let r = Rect::new(v(0.0, 0.0), v(10.0, 10.0)).unwrap();
    let pts = intersect(&e1, &e2, Some(&r));
    assert_eq!(pts.len(), 1);
    assert!((pts[0].x - 4.8985).abs() < 5e-5);
    // Two circles (coincident foci) touching externally: a tangency, grazing → dropped.
    let c1 = RangeEllipse::new(v(0.0, 0.0), v(0.0, 0.0), 2.0).unwrap();
    let c2 = RangeEllipse::new(v(2.0, 0.0), v(2.0, 0.0), 2.0).unwrap();
    assert!(intersect(&c1, &c2, None).is_empty());
    // Circles crossing transversally: two points.
    let c3 = RangeEllipse::new(v(1.0, 0.0), v(1.0, 0.0), 2.0).unwrap();
    let pts = intersect(&c1, &c3, None);
    assert_eq!(pts.len(), 2);
    check(&c1, &c3, &pts);
}

#[test]
fn condition() {
    assert!((condition_number(v(1.0, 0.0), v(0.0, 1.0)) - 1.0).abs() < 1e-15);
    assert!((condition_number(v(2.0, 0.0), v(0.0, 1.0)) - 2.0).abs() < 1e-15);
    assert_eq!(condition_number(v(1.0, 1.0), v(2.0, 2.0)), Real::INFINITY);
}
