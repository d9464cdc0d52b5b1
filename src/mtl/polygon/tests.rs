use super::*;

fn v(x: Real, y: Real) -> Vec2 {
    Vec2::new(x, y)
}

fn unit_square(ox: Real, oy: Real) -> Vec<Vec2> {
    alloc::vec![
        v(ox, oy),
        v(ox + 1.0, oy),
        v(ox + 1.0, oy + 1.0),
        v(ox, oy + 1.0)
    ]
}

#[test]
fn areas() {
    assert_eq!(area(&unit_square(3.0, -2.0)), 1.0);
    let tri = [v(0.0, 0.0), v(4.0, 0.0), v(0.0, 3.0)];
    assert_eq!(area(&tri), 6.0);
    let mut cw = tri;
    cw.reverse();
    assert_eq!(signed_area(&cw), -6.0);
    assert_eq!(area(&[v(0.0, 0.0), v(1.0, 1.0)]), 0.0);
}

#[test]
fn clipping_squares_and_triangles() {
    let a = unit_square(0.0, 0.0);
    let b = unit_square(0.5, 0.25);
    assert!((area(&clip_convex(&a, &b)) - 0.375).abs() < 1e-15);
    // Clockwise clip polygon gives the same result.
    let mut bcw = b.clone();
    bcw.reverse();
    assert!((area(&clip_convex(&a, &bcw)) - 0.375).abs() < 1e-15);
    // Disjoint and edge-touching squares: empty.
    assert!(clip_convex(&a, &unit_square(2.0, 0.0)).is_empty());
    assert!(clip_convex(&a, &unit_square(1.0, 0.0)).is_empty());
    // Triangle x+y ≤ 1 in the unit square: the triangle itself.
    let tri = [v(0.0, 0.0), v(1.0, 0.0), v(0.0, 1.0)];
    assert!((area(&clip_convex(&a, &tri)) - 0.5).abs() < 1e-15);
    // Two triangles: the square cut by both diagonals → quarter.
    let tri2 = [v(1.0, 0.0), v(1.0, 1.0), v(0.0, 0.0)];
    assert!((area(&clip_convex(&tri, &tri2)) - 0.25).abs() < 1e-15);
}

#[test]
fn rotated_rectangle() {
    let r = segment_rectangle(v(1.0, 2.0), v(4.0, 6.0), 0.6);
    assert!((area(&r) - 5.0 * 0.6).abs() < 1e-12);
    assert!(signed_area(&r) > 0.0);
    assert_eq!(area(&segment_rectangle(v(1.0, 1.0), v(1.0, 1.0), 0.6)), 0.0);
    let region = Rect::new(v(0.0, 0.0), v(10.0, 10.0)).unwrap();
    let r = node_rectangle(v(5.0, 5.0), v(5.0, 0.0), 0.6, Some(&region));
    assert!((area(&r) - 3.0).abs() < 1e-12);
    let r = node_rectangle(v(5.0, 5.0), v(5.0, 0.0), 0.6, None);
    assert!((area(&r) - 3.0).abs() < 1e-12);
}

#[test]
fn unions() {
    let a = unit_square(0.0, 0.0);
    let b = unit_square(0.5, 0.0);
    let c = unit_square(0.25, 0.5);
    let u2 = union_area(&[a.clone(), b.clone()]).unwrap();
    assert!((u2 - 1.5).abs() < 1e-15);
    // Three squares: [0, 1.5]×[0, 1] ∪ [0.25, 1.25]×[1, 1.5] = 1.5 + 0.5.
    let u3 = union_area(&[a, b, c]).unwrap();
    assert!((u3 - 2.0).abs() < 1e-14, "{u3}");
    assert_eq!(union_area::<Vec<Vec2>>(&[]).unwrap(), 0.0);
}

/// The subset search (which skips the subtrees of intersections already inside the next
/// polygon) gives bitwise the areas of clipping each subset one polygon at a time.
#[test]
fn subset_search_equals_direct_clipping() {
    let region = Rect::new(v(0.0, 0.0), v(10.0, 10.0)).unwrap();
    let mut seed = 0x2545_f491_4f6c_dd1du64;
    let mut rnd = || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as Real / (1u64 << 53) as Real * 10.0
    };
    let mut nested = 0;
    for _ in 0..200 {
        let x = v(rnd(), rnd());
        let rects: Vec<Vec<Vec2>> = (0..6)
            .map(|_| node_rectangle(x, v(rnd(), rnd()), 0.6, Some(&region)))
            .collect();
        let table = subset_intersection_areas(&rects).unwrap();
        for (mask, &want) in table.iter().enumerate().skip(1) {
            let polys: Vec<&[Vec2]> = (0..6)
                .filter(|i| mask >> i & 1 == 1)
                .map(|i| rects[i].as_slice())
                .collect();
            assert_eq!(
                want.to_bits(),
                intersection_area(&polys).to_bits(),
                "{mask:b}"
            );
        }
        nested += (1..64usize)
            .filter(|&m| m.count_ones() > 1 && table[m] == table[m & (m - 1)])
            .count();
    }
    // The skipped case occurs (supersets with the same intersection).
    assert!(nested > 100, "{nested}");
}

#[test]
fn bad_rect() {
    assert!(matches!(
        Rect::new(v(0.0, 0.0), v(0.0, 1.0)),
        Err(Error::InvertedArea {
            field: "region.x",
            ..
        })
    ));
    assert!(matches!(
        Rect::new(v(0.0, Real::NAN), v(1.0, 1.0)),
        Err(Error::NonFinite { .. })
    ));
}
