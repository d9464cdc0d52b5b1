//! Small dense solves of the estimator: the `K×K` Hermitian normal equations of the joint
//! amplitude fit and the inverse of the `3K×3K` real Fisher matrix (Gauss–Jordan with partial
//! pivoting; `None` when a pivot falls below `1e-12` of the largest diagonal entry).

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
