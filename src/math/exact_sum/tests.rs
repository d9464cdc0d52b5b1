use alloc::vec::Vec;

use super::ExactSum;

/// splitmix64: a small deterministic generator, independent of the crate's streams.
struct Gen(u64);

impl Gen {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }

    fn shuffle<T>(&mut self, v: &mut [T]) {
        for i in (1..v.len()).rev() {
            v.swap(i, self.below(i as u64 + 1) as usize);
        }
    }
}

/// Scale of the integer reference: every test value is `m · 2^k` with `k ≥ -SCALE`.
const SCALE: i32 = 40;

/// `2^e` for `|e| ≤ 1000`.
fn pow2(e: i32) -> f64 {
    f64::from_bits(((1023 + e) as u64) << 52)
}

/// `m · 2^k` as `f64` (exact: `|m| < 2^53`) and as the integer `m · 2^(k + SCALE)`.
fn scaled(m: i64, k: i32) -> (f64, i128) {
    assert!(m.unsigned_abs() < 1 << 53 && k >= -SCALE && k + SCALE <= 60);
    (m as f64 * pow2(k), (m as i128) << (k + SCALE))
}

/// The exact sum of integer-scaled values, correctly rounded: `i128 as f64` rounds to nearest,
/// ties to even, and the scaling by a power of two is exact.
fn reference(ints: &[i128]) -> f64 {
    let s: i128 = ints.iter().sum();
    s as f64 * pow2(-SCALE)
}

/// `count` random values with mantissas of up to `bits` bits and exponents in `exponents`.
fn values(g: &mut Gen, count: usize, bits: u32, exponents: &[i32]) -> (Vec<f64>, Vec<i128>) {
    (0..count)
        .map(|_| {
            let m = (g.next() >> (64 - bits)) as i64;
            let m = if g.next() & 1 == 1 { -m } else { m };
            scaled(m, exponents[g.below(exponents.len() as u64) as usize])
        })
        .unzip()
}

fn sum(xs: &[f64]) -> ExactSum {
    xs.iter().copied().collect()
}

#[test]
fn equals_the_correctly_rounded_integer_reference() {
    let mut g = Gen(1);
    let wide: Vec<i32> = (-SCALE..=7).collect();
    for case in 0..2000 {
        let count = 1 + g.below(200) as usize;
        let (xs, ints) = values(&mut g, count, 53, &wide);
        let want = reference(&ints);
        let got = sum(&xs).value();
        assert_eq!(
            got.to_bits(),
            want.to_bits(),
            "case {case}: {got} vs {want}"
        );
    }
}

#[test]
fn rounds_ties_to_even_across_partials() {
    // Three large values (ulp 512 near their sum, about 2^61), a few middle ones that often put
    // the sum exactly half-way between two doubles, and sometimes a tiny one (2^-40, too far
    // below to share a partial with the middle ones) that decides the rounding of the tie.
    let mut g = Gen(7);
    let mut ties = 0;
    for case in 0..4000 {
        let (mut xs, mut ints) = values(&mut g, 3, 52, &[8]);
        let n = 1 + g.below(4) as usize;
        let (mid, mid_ints) = values(&mut g, n, 3, &[6, 7, 8]);
        xs.extend(mid);
        ints.extend(mid_ints);
        ties += usize::from(is_tie(ints.iter().sum()));
        let n = g.below(2) as usize;
        let (tiny, tiny_ints) = values(&mut g, n, 2, &[-SCALE]);
        xs.extend(tiny);
        ints.extend(tiny_ints);
        g.shuffle(&mut xs);
        let want = reference(&ints);
        assert_eq!(
            sum(&xs).value().to_bits(),
            want.to_bits(),
            "case {case}: {xs:?}"
        );
    }
    assert!(ties > 200, "only {ties} ties exercised");
}

/// Whether the integer `s` is exactly half-way between two neighbouring doubles.
fn is_tie(s: i128) -> bool {
    let bits = 128 - s.unsigned_abs().leading_zeros();
    bits > 54 && {
        let drop = bits - 53;
        s.unsigned_abs() & ((1u128 << drop) - 1) == 1u128 << (drop - 1)
    }
}

#[test]
fn known_ties_and_cancellations() {
    let one = 1.0;
    let ulp = pow2(-52);
    let cases: [(&[f64], f64); 9] = [
        (&[one, ulp / 2.0], one),
        (&[one + ulp, ulp / 2.0], one + 2.0 * ulp),
        (&[one, ulp / 2.0, pow2(-80)], one + ulp),
        (&[one, ulp / 2.0, -pow2(-80)], one),
        (&[pow2(-80), ulp / 2.0, one], one + ulp),
        // Python's example: the 1e-16 makes 1 + 1e16 round up to …02.
        (&[1e-16, 1.0, 1e16], 10000000000000002.0),
        (&[1e100, 1.0, -1e100], 1.0),
        (&[1e100, 1.0, -1e100, 1e-100, -1e-100], 1.0),
        (&[0.1; 10], 1.0),
    ];
    for (xs, want) in cases {
        let mut perm = xs.to_vec();
        let mut g = Gen(3);
        for _ in 0..20 {
            g.shuffle(&mut perm);
            assert_eq!(sum(&perm).value(), want, "{perm:?}");
        }
    }
    // A plain sum of ten 0.1 is 0.9999999999999999.
    assert_ne!([0.1; 10].iter().sum::<f64>(), 1.0);
    assert_eq!(ExactSum::new().value().to_bits(), 0.0f64.to_bits());
    assert_eq!(sum(&[-0.0]).value().to_bits(), 0.0f64.to_bits());
    assert_eq!(sum(&[1.5, -1.5]).value().to_bits(), 0.0f64.to_bits());
}

#[test]
fn permutations_and_splits_do_not_change_the_value() {
    let mut g = Gen(11);
    let exps: Vec<i32> = (-SCALE..=20).collect();
    for case in 0..200 {
        let count = 2 + g.below(300) as usize;
        let (mut xs, ints) = values(&mut g, count, 53, &exps);
        let want = reference(&ints);
        let whole = sum(&xs);
        for _ in 0..10 {
            g.shuffle(&mut xs);
            // Split into random pieces, summed apart and merged in a random order.
            let cuts = 1 + g.below(8) as usize;
            let mut pieces: Vec<ExactSum> = (0..cuts).map(|_| ExactSum::new()).collect();
            for &x in &xs {
                pieces[g.below(cuts as u64) as usize].add(x);
            }
            g.shuffle(&mut pieces);
            let mut merged = ExactSum::new();
            pieces.iter().for_each(|p| merged.merge(p));
            assert_eq!(merged.value().to_bits(), want.to_bits(), "case {case}");
            assert_eq!(sum(&xs).value().to_bits(), want.to_bits(), "case {case}");
            assert_eq!(merged, whole, "case {case}");
        }
    }
}

#[test]
fn merge_equals_sequential_adds() {
    let mut g = Gen(5);
    let (xs, _) = values(&mut g, 500, 53, &[-30, -3, 0, 4, 17]);
    let (a, b) = xs.split_at(173);
    let mut merged = sum(a);
    merged.merge(&sum(b));
    let sequential = sum(&xs);
    assert_eq!(merged, sequential);
    assert_eq!(merged.value().to_bits(), sequential.value().to_bits());
    // Merging into an empty sum, and an empty sum into one, changes nothing.
    let mut empty = ExactSum::new();
    empty.merge(&sequential);
    assert_eq!(empty.value().to_bits(), sequential.value().to_bits());
    let mut same = sequential.clone();
    same.merge(&ExactSum::new());
    assert_eq!(same, sequential);
    assert_ne!(sum(&[1.0]), sum(&[1.0, 1e-300]));
}

#[test]
fn non_finite_addends_are_summed_apart() {
    let inf = f64::INFINITY;
    assert_eq!(sum(&[1.0, inf, 2.0]).value(), inf);
    assert_eq!(sum(&[-inf, 1.0]).value(), -inf);
    assert!(sum(&[inf, 1.0, -inf]).value().is_nan());
    assert!(sum(&[f64::NAN, 1.0]).value().is_nan());
    let (mut a, b) = (sum(&[1.0, inf]), sum(&[-inf]));
    a.merge(&b);
    assert!(a.value().is_nan());
    // Intermediate overflow of finite addends: ±∞ (documented; Python raises).
    assert_eq!(sum(&[f64::MAX, f64::MAX]).value(), inf);
    assert_eq!(sum(&[-f64::MAX, -f64::MAX, 1.0]).value(), -inf);
    // Near the top of the range, exact while the running sums stay finite.
    assert_eq!(sum(&[f64::MAX, -f64::MAX, f64::MAX]).value(), f64::MAX);
}

#[test]
fn serde_round_trips_exactly() {
    let mut g = Gen(9);
    let (xs, _) = values(&mut g, 300, 53, &[-40, -20, 0, 20]);
    let mut s = sum(&xs);
    s.add(1e-300);
    s.add(1e300);
    let text = serde_json::to_string(&s).unwrap();
    let back: ExactSum = serde_json::from_str(&text).unwrap();
    assert_eq!(back, s);
    assert_eq!(back.value().to_bits(), s.value().to_bits());
    assert_eq!(back.partials(), s.partials());
    for (special, name) in [
        (f64::INFINITY, "\"inf\""),
        (f64::NEG_INFINITY, "\"-inf\""),
        (f64::NAN, "\"nan\""),
    ] {
        let text = serde_json::to_string(&sum(&[1.0, special])).unwrap();
        assert_eq!(text, name);
        let back: ExactSum = serde_json::from_str(&text).unwrap();
        assert_eq!(back.value().to_bits(), special.to_bits());
    }
    assert_eq!(serde_json::to_string(&ExactSum::new()).unwrap(), "[]");
    // Any array of finite numbers is a valid accumulator of their sum.
    let back: ExactSum = serde_json::from_str("[1e16, 1.0, 1e-16]").unwrap();
    assert_eq!(back.value(), 10000000000000002.0);
    assert!(serde_json::from_str::<ExactSum>("\"infinity\"").is_err());
    assert!(serde_json::from_str::<ExactSum>("{}").is_err());
}
