use super::*;

#[test]
fn table_one_three_by_three() {
    // Spec check 1, printed 1-based.
    let map = TrpMap::new(3, 3).unwrap();
    let tx: alloc::vec::Vec<usize> = (0..9).map(|m| map.tx(m) + 1).collect();
    let rx: alloc::vec::Vec<usize> = (0..9).map(|m| map.rx(m) + 1).collect();
    assert_eq!(tx, [1, 2, 3, 1, 2, 3, 1, 2, 3]);
    assert_eq!(rx, [1, 1, 1, 2, 2, 2, 3, 3, 3]);
    for m in 0..9 {
        let (t, r) = map.pair(m).unwrap();
        assert_eq!(map.trp(t, r).unwrap(), m);
    }
    assert!(map.pair(9).is_err());
    assert!(map.trp(3, 0).is_err());
    assert_eq!(map.all_trps(), 0x1ff);
}

#[test]
fn bad_sizes_are_named_errors() {
    assert_eq!(
        TrpMap::new(0, 3),
        Err(Error::EmptyNodeList {
            field: "transmitters"
        })
    );
    assert_eq!(
        TrpMap::new(3, 0),
        Err(Error::EmptyNodeList { field: "receivers" })
    );
    assert!(matches!(
        TrpMap::new(9, 8),
        Err(Error::SizeLimit { field: "trps", .. })
    ));
    assert!(matches!(
        TrpMap::new(1, 16),
        Err(Error::SizeLimit { field: "nodes", .. })
    ));
    assert!(TrpMap::new(8, 8).is_ok());
    assert_eq!(TrpMap::new(8, 8).unwrap().all_trps(), u64::MAX);
}

#[test]
fn range_and_gradient() {
    let map = TrpMap::new(2, 1).unwrap();
    let tx = [Vec2::new(0.0, 0.0), Vec2::new(10.0, 0.0)];
    let rx = [Vec2::new(0.0, 10.0)];
    let x = Vec2::new(3.0, 4.0);
    let d = map.range(1, &x, &tx, &rx);
    let expect = (49.0f64 + 16.0).sqrt() + (9.0f64 + 36.0).sqrt();
    assert!((d - expect).abs() < 1e-12);
    let g = map.range_gradient(1, &x, &tx, &rx);
    let h = 1e-6;
    let gx = (map.range(1, &Vec2::new(x.x + h, x.y), &tx, &rx)
        - map.range(1, &Vec2::new(x.x - h, x.y), &tx, &rx))
        / (2.0 * h);
    let gy = (map.range(1, &Vec2::new(x.x, x.y + h), &tx, &rx)
        - map.range(1, &Vec2::new(x.x, x.y - h), &tx, &rx))
        / (2.0 * h);
    assert!((g.x - gx).abs() < 1e-7 && (g.y - gy).abs() < 1e-7);
    // On a node the singular term is dropped, never NaN.
    let g0 = range_gradient(tx[0], rx[0], tx[0]);
    assert!(g0.x.is_finite() && g0.y.is_finite());
}
