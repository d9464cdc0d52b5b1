//! The optimal assignment (linear sum assignment) of a rectangular cost matrix: the shortest
//! augmenting path method with row and column potentials (Kuhn–Munkres in the Jonker–Volgenant
//! form), `O(n²·m)` for `n ≤ m`. Written here because the core is `no_std` (the well-kept
//! assignment crates need `std` or `ndarray`); the GOSPA metric (issue 41) and the multi-target
//! association use it. Checked against brute-force enumeration in `tests.rs`.

use alloc::vec;
use alloc::vec::Vec;

use crate::math::Real;

/// An optimal assignment: `rows[i]` is the column of row `i` (`None` for the rows a wide-side
/// shortage leaves out), and the total cost of the pairs.
#[derive(Debug, Clone, PartialEq)]
pub struct Assignment {
    /// Column per row, `None` where the row is not assigned (only when rows > columns).
    pub rows: Vec<Option<usize>>,
    /// Σ cost of the assigned pairs.
    pub cost: Real,
}

/// The minimum-cost assignment of `min(n, m)` pairs of the `n × m` row-major `cost` matrix
/// (finite entries; the caller checks). Every row is assigned when `n ≤ m`, every column when
/// `n > m`. Deterministic: ties go to the lowest column index found first.
pub fn assign(cost: &[Real], n: usize, m: usize) -> Assignment {
    debug_assert_eq!(cost.len(), n * m);
    if n == 0 || m == 0 {
        return Assignment {
            rows: vec![None; n],
            cost: 0.0,
        };
    }
    if n > m {
        // Solve the transpose (rows ≤ columns), then map back.
        let mut t = vec![0.0; n * m];
        for i in 0..n {
            for j in 0..m {
                t[j * n + i] = cost[i * m + j];
            }
        }
        let a = assign(&t, m, n);
        let mut rows = vec![None; n];
        for (j, r) in a.rows.iter().enumerate() {
            if let Some(i) = r {
                rows[*i] = Some(j);
            }
        }
        return Assignment { rows, cost: a.cost };
    }
    // Potentials u (rows, 1-based with a virtual row 0) and v (columns, with a virtual column 0);
    // way[j] the previous column on the augmenting path; col_row[j] the row of column j.
    let inf = Real::INFINITY;
    let (mut u, mut v) = (vec![0.0; n + 1], vec![0.0; m + 1]);
    let mut col_row = vec![0usize; m + 1];
    let mut way = vec![0usize; m + 1];
    let (mut minv, mut used) = (vec![inf; m + 1], vec![false; m + 1]);
    for i in 1..=n {
        col_row[0] = i;
        let mut j0 = 0usize;
        minv.iter_mut().for_each(|x| *x = inf);
        used.iter_mut().for_each(|x| *x = false);
        // Each pass marks one more column used: at most m + 1 passes.
        loop {
            used[j0] = true;
            let i0 = col_row[j0];
            let (mut delta, mut j1) = (inf, 0usize);
            for j in 1..=m {
                if !used[j] {
                    let cur = cost[(i0 - 1) * m + (j - 1)] - u[i0] - v[j];
                    if cur < minv[j] {
                        minv[j] = cur;
                        way[j] = j0;
                    }
                    if minv[j] < delta {
                        delta = minv[j];
                        j1 = j;
                    }
                }
            }
            if j1 == 0 {
                // Only non-finite reduced costs remain (a caller's non-finite entry): stop.
                break;
            }
            for j in 0..=m {
                if used[j] {
                    u[col_row[j]] += delta;
                    v[j] -= delta;
                } else {
                    minv[j] -= delta;
                }
            }
            j0 = j1;
            if col_row[j0] == 0 {
                break;
            }
        }
        // Augment along the path (at most m steps back to the virtual column 0).
        while j0 != 0 {
            let j1 = way[j0];
            col_row[j0] = col_row[j1];
            j0 = j1;
        }
    }
    let mut rows = vec![None; n];
    for j in 1..=m {
        if col_row[j] != 0 {
            rows[col_row[j] - 1] = Some(j - 1);
        }
    }
    let total = rows
        .iter()
        .enumerate()
        .filter_map(|(i, j)| j.map(|j| cost[i * m + j]))
        .sum();
    Assignment { rows, cost: total }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Brute force: the minimum over all injective maps of the smaller side into the larger.
    fn brute(cost: &[Real], n: usize, m: usize) -> Real {
        fn go(cost: &[Real], n: usize, m: usize, i: usize, used: &mut [bool]) -> Real {
            if i == n {
                return 0.0;
            }
            let mut best = Real::INFINITY;
            for j in 0..m {
                if !used[j] {
                    used[j] = true;
                    best = best.min(cost[i * m + j] + go(cost, n, m, i + 1, used));
                    used[j] = false;
                }
            }
            best
        }
        if n <= m {
            go(cost, n, m, 0, &mut vec![false; m])
        } else {
            let mut t = vec![0.0; n * m];
            for i in 0..n {
                for j in 0..m {
                    t[j * n + i] = cost[i * m + j];
                }
            }
            go(&t, m, n, 0, &mut vec![false; n])
        }
    }

    fn lcg(s: &mut u64) -> Real {
        *s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (*s >> 11) as Real / (1u64 << 53) as Real
    }

    #[test]
    fn equals_brute_force_on_random_rectangles() {
        let mut s = 7u64;
        for case in 0..600 {
            let (n, m) = (
                1 + (lcg(&mut s) * 6.0) as usize,
                1 + (lcg(&mut s) * 6.0) as usize,
            );
            // Integer costs make ties (several optima) common; real ones make them rare.
            let ints = case % 2 == 0;
            let cost: Vec<Real> = (0..n * m)
                .map(|_| {
                    let x = lcg(&mut s) * 10.0;
                    if ints {
                        x.floor()
                    } else {
                        x
                    }
                })
                .collect();
            let a = assign(&cost, n, m);
            let want = brute(&cost, n, m);
            assert!(
                (a.cost - want).abs() <= 1e-12 * want.max(1.0),
                "{n}×{m}: {} vs {want}",
                a.cost
            );
            // A valid assignment: min(n, m) pairs, no column twice.
            let cols: Vec<usize> = a.rows.iter().flatten().copied().collect();
            assert_eq!(cols.len(), n.min(m));
            let mut sorted = cols.clone();
            sorted.sort_unstable();
            sorted.dedup();
            assert_eq!(sorted.len(), cols.len());
        }
    }

    #[test]
    fn empty_sides_assign_nothing() {
        assert_eq!(assign(&[], 0, 3).rows, Vec::<Option<usize>>::new());
        assert_eq!(assign(&[], 2, 0).rows, vec![None, None]);
    }
}
