use super::*;

/// Tail probabilities at reference quantiles (χ² tables): P(χ²_k > q) = 1e-6 at q = 23.9281
/// (k = 1), 27.6310 (k = 2), 30.6648 (k = 3), 35.8882 (k = 5); and P(χ²_4 > 9.4877) = 0.05.
#[test]
fn chi_square_tail_matches_tables() {
    for (k, q, p) in [
        (1, 23.928127, 1e-6),
        (2, 27.631021, 1e-6),
        (3, 30.664850, 1e-6),
        (5, 35.888187, 1e-6),
        (4, 9.487729, 0.05),
    ] {
        let got = chi_square_upper_tail(k, q);
        assert!((got - p).abs() < 1e-5 * p, "k {k}: {got} vs {p}");
    }
    assert_eq!(chi_square_upper_tail(3, 0.0), 1.0);
}
