//! Small dense solves of the estimator: the `K×K` Hermitian normal equations of the joint
//! amplitude fit (Gauss–Jordan with partial pivoting), the inverse of a small real symmetric
//! matrix (the Gauss–Newton systems), and selected diagonal entries of the inverse of the
//! `3K×3K` real Fisher matrix (Cholesky of the Jacobi-scaled matrix, the wanted parameters
//! last: their block of the inverse is the inverse of the trailing Schur complement).

// `!(x > 0.0)` is meant: a NaN must fail these checks as well.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use alloc::vec::Vec;

use crate::math::{Complex, Real};

/// Solves `G x = b` (`G` row-major `k×k`, overwritten); `None` if singular.
pub(crate) fn solve_complex(
    g: &mut [Complex],
    b: &mut [Complex],
    k: usize,
) -> Option<Vec<Complex>> {
    let scale = (0..k).map(|i| g[i * k + i].norm_sqr()).fold(0.0, Real::max);
    let tol = scale * 1e-24;
    for c in 0..k {
        let p =
            (c..k).max_by(|&x, &y| g[x * k + c].norm_sqr().total_cmp(&g[y * k + c].norm_sqr()))?;
        if !(g[p * k + c].norm_sqr() > tol) {
            return None;
        }
        if p != c {
            for j in 0..k {
                g.swap(p * k + j, c * k + j);
            }
            b.swap(p, c);
        }
        let inv = Complex::new(1.0, 0.0) / g[c * k + c];
        for r in 0..k {
            if r == c {
                continue;
            }
            let f = g[r * k + c] * inv;
            if f == Complex::new(0.0, 0.0) {
                continue;
            }
            for j in c..k {
                let v = g[c * k + j];
                g[r * k + j] -= f * v;
            }
            let v = b[c];
            b[r] -= f * v;
        }
    }
    let x: Vec<Complex> = (0..k).map(|i| b[i] / g[i * k + i]).collect();
    if x.iter().all(|v| v.re.is_finite() && v.im.is_finite()) {
        Some(x)
    } else {
        None
    }
}

/// The inverse of the real `m×m` matrix `a` (row-major); `None` if singular.
pub(crate) fn inverse_sym(mut a: Vec<Real>, m: usize) -> Option<Vec<Real>> {
    let scale = (0..m).map(|i| a[i * m + i].abs()).fold(0.0, Real::max);
    let tol = scale * 1e-13;
    let mut inv = alloc::vec![0.0; m * m];
    for i in 0..m {
        inv[i * m + i] = 1.0;
    }
    for c in 0..m {
        let p = (c..m).max_by(|&x, &y| a[x * m + c].abs().total_cmp(&a[y * m + c].abs()))?;
        if !(a[p * m + c].abs() > tol) {
            return None;
        }
        if p != c {
            for j in 0..m {
                a.swap(p * m + j, c * m + j);
                inv.swap(p * m + j, c * m + j);
            }
        }
        let d = 1.0 / a[c * m + c];
        for j in 0..m {
            a[c * m + j] *= d;
            inv[c * m + j] *= d;
        }
        for r in 0..m {
            if r == c {
                continue;
            }
            let f = a[r * m + c];
            if f == 0.0 {
                continue;
            }
            for j in 0..m {
                a[r * m + j] -= f * a[c * m + j];
                inv[r * m + j] -= f * inv[c * m + j];
            }
        }
    }
    if inv.iter().all(|v| v.is_finite()) {
        Some(inv)
    } else {
        None
    }
}

/// The inverse of the symmetric positive (semi)definite `m×m` matrix `a` (row-major) after
/// Jacobi scaling (`D^{-1/2} a D^{-1/2}`, `D` its diagonal), so that parameters of very
/// different units (a delay in seconds beside an amplitude) do not fall under
/// [`inverse_sym`]'s tolerance, which is relative to the largest diagonal entry; `None` if a
/// diagonal entry is not positive or the scaled matrix is singular.
pub(crate) fn inverse_spd_scaled(mut a: Vec<Real>, m: usize) -> Option<Vec<Real>> {
    let s: Vec<Real> = (0..m)
        .map(|i| {
            let d = a[i * m + i];
            if d > 0.0 && d.is_finite() {
                Some(1.0 / crate::math::sqrt(d))
            } else {
                None
            }
        })
        .collect::<Option<Vec<Real>>>()?;
    for r in 0..m {
        for c in 0..m {
            a[r * m + c] *= s[r] * s[c];
        }
    }
    let mut inv = inverse_sym(a, m)?;
    for r in 0..m {
        for c in 0..m {
            inv[r * m + c] *= s[r] * s[c];
        }
    }
    Some(inv)
}

/// Selected diagonal entries of the inverse of the symmetric positive definite `m×m` matrix
/// `a` (row-major): `(a⁻¹)_ii` for `i` in `wanted`, in that order. Jacobi-scaled first (as
/// [`inverse_spd_scaled`]), the rows and columns of `wanted` moved last, then Cholesky
/// `a = LLᵀ`: the trailing block `L₂₂` factors the Schur complement `S` of the other
/// parameters, and `S⁻¹` is `wanted`'s block of `a⁻¹`, so `(a⁻¹)_ii = Σ_j ((L₂₂⁻¹)_ji)²`.
/// `m³/6 + k³/6` multiply-adds against [`inverse_spd_scaled`]'s `≈ 2m³` (the estimator's Fisher
/// matrix: `m = 3K`, `k = K`). `None` if a diagonal entry is not positive or a pivot of the
/// scaled matrix falls to `1e-13` (singular to working precision).
pub(crate) fn inverse_diagonal_spd(a: &[Real], m: usize, wanted: &[usize]) -> Option<Vec<Real>> {
    if a.len() != m * m || wanted.iter().any(|&w| w >= m) {
        return None;
    }
    let s: Vec<Real> = (0..m)
        .map(|i| {
            let d = a[i * m + i];
            (d > 0.0 && d.is_finite()).then(|| 1.0 / crate::math::sqrt(d))
        })
        .collect::<Option<Vec<Real>>>()?;
    // The order: the other parameters first, then `wanted` as given.
    let mut order: Vec<usize> = (0..m).filter(|i| !wanted.contains(i)).collect();
    let first = order.len();
    order.extend_from_slice(wanted);
    let n = order.len();
    let mut l = alloc::vec![0.0; n * n];
    for (r, &i) in order.iter().enumerate() {
        for (c, &j) in order.iter().enumerate().take(r + 1) {
            l[r * n + c] = a[i * m + j] * s[i] * s[j];
        }
    }
    // Cholesky in place (lower triangle).
    for c in 0..n {
        let mut d = l[c * n + c];
        for k in 0..c {
            d -= l[c * n + k] * l[c * n + k];
        }
        if !(d > 1e-13) {
            return None;
        }
        let d = crate::math::sqrt(d);
        l[c * n + c] = d;
        for r in c + 1..n {
            let mut v = l[r * n + c];
            for k in 0..c {
                v -= l[r * n + k] * l[c * n + k];
            }
            l[r * n + c] = v / d;
        }
    }
    // `M = L₂₂⁻¹` column by column (forward substitution), and the squared column norms.
    let k = n - first;
    let at = |r: usize, c: usize| l[(first + r) * n + first + c];
    let mut out = Vec::with_capacity(k);
    let mut col = alloc::vec![0.0; k];
    for (i, &w) in wanted.iter().enumerate() {
        let mut norm = 0.0;
        for r in 0..k {
            let mut v = if r == i { 1.0 } else { 0.0 };
            for (c, x) in col.iter().enumerate().take(r).skip(i) {
                v -= at(r, c) * x;
            }
            col[r] = if r < i { 0.0 } else { v / at(r, r) };
            norm += col[r] * col[r];
        }
        out.push(norm * s[w] * s[w]);
    }
    out.iter().all(|v| v.is_finite()).then_some(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng as _, SeedableRng as _};
    use rand_pcg::Pcg64;

    /// A random symmetric positive definite matrix `BᵀB + εI` with rows of very different
    /// scales (the Fisher matrix's delays beside amplitudes).
    fn spd(rng: &mut Pcg64, m: usize) -> Vec<Real> {
        let b: Vec<Real> = (0..m * m).map(|_| rng.random_range(-1.0..1.0)).collect();
        let scale: Vec<Real> = (0..m).map(|i| if i % 3 == 0 { 1e8 } else { 1.0 }).collect();
        let mut a = alloc::vec![0.0; m * m];
        for r in 0..m {
            for c in 0..m {
                let v: Real = (0..m).map(|k| b[k * m + r] * b[k * m + c]).sum();
                a[r * m + c] = (v + if r == c { 0.1 } else { 0.0 }) * scale[r] * scale[c];
            }
        }
        a
    }

    /// The Schur-complement diagonal equals the full inverse's (Gauss–Jordan, written
    /// independently above) within rounding, for any choice and order of the wanted indices.
    #[test]
    fn inverse_diagonal_matches_the_full_inverse() {
        for seed in 0..20 {
            let mut rng = Pcg64::seed_from_u64(seed);
            let m = 3 * rng.random_range(1..9usize);
            let a = spd(&mut rng, m);
            let full = inverse_spd_scaled(a.clone(), m).expect("positive definite");
            let wanted: Vec<usize> = (0..m).step_by(3).rev().collect();
            let diag = inverse_diagonal_spd(&a, m, &wanted).expect("positive definite");
            for (&w, &d) in wanted.iter().zip(&diag) {
                let r = full[w * m + w];
                assert!((d - r).abs() <= 1e-9 * r, "seed {seed}: {d} against {r}");
            }
            let all: Vec<usize> = (0..m).collect();
            let diag = inverse_diagonal_spd(&a, m, &all).unwrap();
            for (i, d) in diag.iter().enumerate() {
                let r = full[i * m + i];
                assert!(
                    (d - r).abs() <= 1e-9 * r,
                    "seed {seed}, all: {d} against {r}"
                );
            }
        }
    }

    /// A 2×2 closed form, and singular or indefinite input refused.
    #[test]
    fn inverse_diagonal_closed_form_and_refusals() {
        // [[4, 2], [2, 3]]⁻¹ = [[3, −2], [−2, 4]] / 8
        let a = [4.0, 2.0, 2.0, 3.0];
        let d = inverse_diagonal_spd(&a, 2, &[0, 1]).unwrap();
        assert!((d[0] - 3.0 / 8.0).abs() < 1e-15 && (d[1] - 0.5).abs() < 1e-15);
        assert!(inverse_diagonal_spd(&[1.0, 1.0, 1.0, 1.0], 2, &[0]).is_none());
        assert!(inverse_diagonal_spd(&[1.0, 2.0, 2.0, 1.0], 2, &[1]).is_none());
        assert!(inverse_diagonal_spd(&[0.0, 0.0, 0.0, 1.0], 2, &[1]).is_none());
        assert!(inverse_diagonal_spd(&[1.0], 1, &[1]).is_none());
    }
}
