//! Data association for one sensor's scan: the marginal association probabilities by loopy
//! belief propagation (Williams & Lau, IEEE TAES 50(4), 2014; the same messages as Meyer et al.,
//! Proc. IEEE 106(2), 2018, eqs. (26)–(27)), cost linear in the gated pairs per iteration; and
//! the global-nearest-neighbour hard assignment of the baseline (one optimal assignment,
//! [`assign`]).
//!
//! The weights are normalised as in Williams & Lau: `ψ_ij = w_ij / (w_i0 · w_0j)`, where `w_i0`
//! is track `i` producing no measurement, `w_0j` measurement `j` coming from clutter or a new
//! target, and `w_ij` track `i` producing measurement `j`.

use alloc::vec;
use alloc::vec::Vec;

use crate::math::{assign, Real};

/// Iterations of the message passing at most (its stated bound).
pub const MAX_BP_ITERATIONS: usize = 200;
/// Convergence: the largest change of a measurement-to-track message below this.
pub const BP_TOLERANCE: Real = 1e-10;

/// The marginals of one sensor's association.
#[derive(Debug, Clone, PartialEq)]
pub struct Marginals {
    /// `n × (m + 1)`, row-major: column 0 = track `i` unassociated, column `j + 1` = track `i`
    /// produced measurement `j`. Each row sums to 1.
    pub track: Vec<Real>,
    /// Per measurement, the probability that no existing track produced it.
    pub free: Vec<Real>,
    /// Iterations used (≤ [`MAX_BP_ITERATIONS`]).
    pub iterations: usize,
    /// Whether the messages met [`BP_TOLERANCE`] within the bound.
    pub converged: bool,
}

/// Loopy BP on the `n × m` row-major weights `psi` (≥ 0, finite; 0 = gated out).
pub fn bp_marginals(psi: &[Real], n: usize, m: usize) -> Marginals {
    debug_assert_eq!(psi.len(), n * m);
    // ν_{j→i} (measurement to track), stored n × m; μ_{i→j} likewise.
    let mut nu = vec![1.0; n * m];
    let mut mu = vec![0.0; n * m];
    let mut iterations = 0;
    let mut converged = n == 0 || m == 0;
    while !converged && iterations < MAX_BP_ITERATIONS {
        iterations += 1;
        for i in 0..n {
            let row = &psi[i * m..(i + 1) * m];
            let s: Real = (0..m).map(|j| row[j] * nu[i * m + j]).sum();
            for (j, &w) in row.iter().enumerate() {
                let k = i * m + j;
                mu[k] = w / (1.0 + s - w * nu[k]);
            }
        }
        let mut change: Real = 0.0;
        for j in 0..m {
            let s: Real = (0..n).map(|i| mu[i * m + j]).sum();
            for i in 0..n {
                let k = i * m + j;
                let new = 1.0 / (1.0 + s - mu[k]);
                change = change.max((new - nu[k]).abs());
                nu[k] = new;
            }
        }
        converged = change < BP_TOLERANCE;
    }
    let mut track = vec![0.0; n * (m + 1)];
    for i in 0..n {
        let out = &mut track[i * (m + 1)..(i + 1) * (m + 1)];
        out[0] = 1.0;
        for j in 0..m {
            out[j + 1] = psi[i * m + j] * nu[i * m + j];
        }
        let total: Real = out.iter().sum();
        out.iter_mut().for_each(|v| *v /= total);
    }
    // The measurement's belief: 1 (free) against Σ_i μ_{i→j} with the final messages.
    let free = (0..m)
        .map(|j| {
            let s: Real = (0..n)
                .map(|i| {
                    let k = i * m + j;
                    let row = &psi[i * m..(i + 1) * m];
                    let t: Real = (0..m).map(|l| row[l] * nu[i * m + l]).sum();
                    psi[k] / (1.0 + t - psi[k] * nu[k])
                })
                .sum();
            1.0 / (1.0 + s)
        })
        .collect();
    Marginals {
        track,
        free,
        iterations,
        converged,
    }
}

/// The exact marginals by enumerating every association (tests and tiny problems: at most
/// `n, m ≤ 7`): the same weights as [`bp_marginals`].
pub fn exact_marginals(psi: &[Real], n: usize, m: usize) -> Marginals {
    let mut track = vec![0.0; n * (m + 1)];
    let mut free = vec![0.0; m];
    let mut total = 0.0;
    let mut used = vec![false; m];
    let mut pick = vec![0usize; n];
    #[allow(clippy::too_many_arguments)]
    fn walk(
        i: usize,
        w: Real,
        psi: &[Real],
        n: usize,
        m: usize,
        used: &mut [bool],
        pick: &mut [usize],
        acc: &mut (Vec<Real>, Vec<Real>, Real),
    ) {
        if i == n {
            acc.2 += w;
            for (t, &j) in pick.iter().enumerate() {
                acc.0[t * (m + 1) + j] += w;
            }
            for (j, u) in used.iter().enumerate() {
                if !u {
                    acc.1[j] += w;
                }
            }
            return;
        }
        pick[i] = 0;
        walk(i + 1, w, psi, n, m, used, pick, acc);
        for j in 0..m {
            let p = psi[i * m + j];
            if !used[j] && p > 0.0 {
                used[j] = true;
                pick[i] = j + 1;
                walk(i + 1, w * p, psi, n, m, used, pick, acc);
                used[j] = false;
            }
        }
    }
    let mut acc = (core::mem::take(&mut track), core::mem::take(&mut free), 0.0);
    walk(0, 1.0, psi, n, m, &mut used, &mut pick, &mut acc);
    total += acc.2;
    let (mut track, mut free) = (acc.0, acc.1);
    track.iter_mut().for_each(|v| *v /= total);
    free.iter_mut().for_each(|v| *v /= total);
    Marginals {
        track,
        free,
        iterations: 0,
        converged: true,
    }
}

/// The global nearest neighbour: the assignment of at most one measurement per track and one
/// track per measurement that minimises `Σ cost_ij` over the assigned pairs, where a track left
/// unassigned costs 0 (`cost` `n × m`, `None` = gated out; assigned pairs have negative cost =
/// `−ln` of the likelihood ratio, so only pairs that beat "missed + clutter" are taken).
pub fn gnn_assignment(cost: &[Option<Real>], n: usize, m: usize) -> Vec<Option<usize>> {
    if n == 0 || m == 0 {
        return vec![None; n];
    }
    // Columns: the m measurements, then one "missed" column per track (0 for its own track, a
    // large cost for the others); gated-out pairs cost more than missing.
    let cols = m + n;
    let big = 1e12;
    let mut c = vec![big; n * cols];
    for i in 0..n {
        for j in 0..m {
            if let Some(v) = cost[i * m + j] {
                c[i * cols + j] = v.min(0.0);
            }
        }
        c[i * cols + m + i] = 0.0;
    }
    assign(&c, n, cols)
        .rows
        .into_iter()
        .enumerate()
        .map(|(i, j)| j.filter(|&j| j < m && cost[i * m + j].is_some_and(|v| v < 0.0)))
        .collect()
}

/// Most tracks or measurements of a cluster whose marginals [`clustered_marginals`] may
/// enumerate exactly (at most 8! · 2⁸ associations; larger clusters go to [`bp_marginals`]).
pub const MAX_EXACT_CLUSTER: usize = 8;

/// The marginals by clusters: the tracks and measurements linked by gated pairs (`ψ > 0`) form
/// independent clusters; a cluster of at most `exact` tracks and `exact` measurements (capped at
/// [`MAX_EXACT_CLUSTER`]) is enumerated exactly ([`exact_marginals`]), a larger one runs loopy
/// BP (`exact = 0`: BP everywhere). Tracks and measurements outside every pair are unassociated
/// / free with probability 1.
pub fn clustered_marginals(psi: &[Real], n: usize, m: usize, exact: usize) -> Marginals {
    let exact = exact.min(MAX_EXACT_CLUSTER);
    // Union–find over n tracks then m measurements.
    let mut parent: Vec<usize> = (0..n + m).collect();
    fn root(parent: &mut [usize], mut x: usize) -> usize {
        while parent[x] != x {
            parent[x] = parent[parent[x]];
            x = parent[x];
        }
        x
    }
    for i in 0..n {
        for j in 0..m {
            if psi[i * m + j] > 0.0 {
                let (a, b) = (root(&mut parent, i), root(&mut parent, n + j));
                if a != b {
                    parent[a.max(b)] = a.min(b);
                }
            }
        }
    }
    let mut track = vec![0.0; n * (m + 1)];
    let mut free = vec![1.0; m];
    for i in 0..n {
        track[i * (m + 1)] = 1.0;
    }
    let (mut iterations, mut converged) = (0, true);
    let mut done = vec![false; n + m];
    for start in 0..n {
        let r = root(&mut parent, start);
        if done[r] {
            continue;
        }
        done[r] = true;
        let rows: Vec<usize> = (0..n).filter(|&i| root(&mut parent, i) == r).collect();
        let cols: Vec<usize> = (0..m).filter(|&j| root(&mut parent, n + j) == r).collect();
        if cols.is_empty() {
            continue;
        }
        let (cn, cm) = (rows.len(), cols.len());
        let sub: Vec<Real> = rows
            .iter()
            .flat_map(|&i| cols.iter().map(move |&j| psi[i * m + j]))
            .collect();
        let mg = if cn <= exact && cm <= exact {
            exact_marginals(&sub, cn, cm)
        } else {
            bp_marginals(&sub, cn, cm)
        };
        iterations += mg.iterations;
        converged &= mg.converged;
        for (a, &i) in rows.iter().enumerate() {
            let row = &mut track[i * (m + 1)..(i + 1) * (m + 1)];
            row[0] = mg.track[a * (cm + 1)];
            for (b, &j) in cols.iter().enumerate() {
                row[j + 1] = mg.track[a * (cm + 1) + b + 1];
            }
        }
        for (b, &j) in cols.iter().enumerate() {
            free[j] = mg.free[b];
        }
    }
    Marginals {
        track,
        free,
        iterations,
        converged,
    }
}
