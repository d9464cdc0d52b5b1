use super::*;

#[test]
fn shards_cover_every_unit_once_in_order() {
    for total in [0, 1, 3, 16, 17, 313, 1000] {
        for count in [1, 2, 3, 4, 7, 20, 400] {
            let mut next = 0;
            for index in 0..count {
                let r = Shard::new(index, count).unwrap().range(total);
                assert_eq!(r.start, next, "{index}/{count} of {total}");
                assert!(r.len() <= total.div_ceil(count));
                next = r.end;
            }
            assert_eq!(next, total);
        }
    }
    assert_eq!(Shard::WHOLE.range(313), 0..313);
    assert_eq!(Shard::new(3, 20).unwrap().range(313), 46..62);
    let big = Shard::new(MAX_SHARDS - 1, MAX_SHARDS).unwrap();
    assert_eq!(big.range(usize::MAX).end, usize::MAX);
}

#[test]
fn bad_shards_are_refused() {
    assert!(Shard::new(0, 0).is_none());
    assert!(Shard::new(4, 4).is_none());
    assert!(Shard::new(0, MAX_SHARDS + 1).is_none());
    assert_eq!(
        Shard::new(0, MAX_SHARDS).map(Shard::count),
        Some(MAX_SHARDS)
    );
}
