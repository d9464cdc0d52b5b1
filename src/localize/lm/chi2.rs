//! The χ² upper tail, used to judge whether a fix's cost is plausible.

use crate::math::{erfc, exp, sqrt, Real, PI};

/// Upper-tail probability `P(χ²_k > x)` of the χ² distribution with `k ≥ 1` degrees of freedom,
/// in closed form for integer `k`: `e^{−x/2} Σ_{j<k/2} (x/2)^j/j!` for even `k`;
/// `erfc(√(x/2)) + √(2x/π) e^{−x/2} Σ_{j<(k−1)/2} x^j/(1·3···(2j+1))` for odd `k`.
pub fn chi_square_upper_tail(k: usize, x: Real) -> Real {
    if x.is_nan() || x <= 0.0 {
        return 1.0;
    }
    let e = exp(-0.5 * x);
    if k.is_multiple_of(2) {
        let (mut term, mut sum) = (1.0, 0.0);
        for j in 0..k / 2 {
            if j > 0 {
                term *= 0.5 * x / j as Real;
            }
            sum += term;
        }
        (e * sum).min(1.0)
    } else {
        let (mut term, mut sum) = (1.0, 0.0);
        for j in 0..(k - 1) / 2 {
            if j > 0 {
                term *= x / (2 * j + 1) as Real;
            }
            sum += term;
        }
        (erfc(sqrt(0.5 * x)) + sqrt(2.0 * x / PI) * e * sum).min(1.0)
    }
}

#[cfg(test)]
mod tests;
