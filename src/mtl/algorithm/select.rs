//! Dedup, per-family caps (§4 step 4) and the final selection (step 5) of Algorithm 1.

use alloc::collections::BTreeMap;
use alloc::vec::Vec;
use core::cmp::Ordering;

use crate::math::Real;
use crate::mtl::algorithm::candidate::Candidate;
use crate::mtl::algorithm::{FinalTest, MtlConfig, Status, Target};

/// Resolution (nats) at which scores `J` are compared: candidates whose `J` truncate to the same
/// multiple tie, and ties go to the lower family. Copies of one matching reached along different
/// paths differ in `J` only by rounding; this keeps the choice between them independent of
/// rounding (e.g. of the TRP numbering, see the relabelling test).
pub const SCORE_RESOLUTION: Real = 1e-9;

/// Total order used everywhere a "lower `J`" choice is made: `J` at [`SCORE_RESOLUTION`], then
/// family, then exact `J`, then matching (results never depend on the production order).
pub fn by_score(a: &Candidate, b: &Candidate) -> Ordering {
    // Truncation (saturating; `J ≥ 0` as a sum of squares plus `L_b ≥ 0`), no_std-safe.
    let q = |j: Real| (j / SCORE_RESOLUTION) as i64;
    q(a.j)
        .cmp(&q(b.j))
        .then(a.family.cmp(&b.family))
        .then(a.j.total_cmp(&b.j))
        .then_with(|| a.matching.cmp(&b.matching))
}

/// Step 4 (\[P\]): candidates with identical `(ℳ, ĝ)` merge keeping the lower `J` (across
/// families); then at most `b_max` per family, lowest `J` first. Returns the survivors (sorted by
/// family, then `J`) and the dropped candidates with their status.
pub fn prune(
    mut cands: Vec<Candidate>,
    b_max: usize,
) -> (Vec<Candidate>, Vec<(Candidate, Status)>) {
    // Group identical (ℳ, ĝ) with the lowest score first in each group (no key copies).
    let same = |a: &Candidate, b: &Candidate| {
        a.matching
            .cmp(&b.matching)
            .then(a.g.set().cmp(&b.g.set()))
            .then(a.g.ones().cmp(&b.g.ones()))
    };
    cands.sort_by(|a, b| same(a, b).then_with(|| by_score(a, b)));
    let mut dropped = Vec::new();
    let mut unique: Vec<Candidate> = Vec::with_capacity(cands.len());
    for c in cands {
        match unique.last() {
            Some(u) if same(u, &c) == Ordering::Equal => dropped.push((c, Status::Duplicate)),
            _ => unique.push(c),
        }
    }
    unique.sort_by(|a, b| a.family.cmp(&b.family).then_with(|| by_score(a, b)));
    let mut kept = Vec::with_capacity(unique.len());
    let mut run = (usize::MAX, 0usize);
    for c in unique {
        if c.family != run.0 {
            run = (c.family, 0);
        }
        run.1 += 1;
        if run.1 <= b_max {
            kept.push(c);
        } else {
            dropped.push((c, Status::Capped));
        }
    }
    (kept, dropped)
}

/// The final test of step 5: `|ℳ| ≥ n_min` and either `L_b ≤ T_b` (Bayesian MTL) or the size
/// rule `|ℳ| ≥ M − N_u` (\[SM\], check 6).
pub fn accepted(c: &Candidate, cfg: &MtlConfig) -> bool {
    let n = c.matching.len();
    n >= cfg.n_min
        && match cfg.final_test {
            FinalTest::Blocking => c.l_b <= cfg.t_b,
            FinalTest::Size { min_matched } => n >= min_matched,
        }
}

/// Step 5: per family the accepted candidate of smallest `J`; then, if
/// [`MtlConfig::merge_final`], greedily in ascending `J` drop every target sharing at least
/// [`MtlConfig::merge_shared_pairs`] pairs with a kept one within
/// [`MtlConfig::merge_radius_m`] (\[P\]). Targets ascend in `J`.
pub fn finalize(live: &[Candidate], cfg: &MtlConfig) -> Vec<Target> {
    let mut best: BTreeMap<usize, &Candidate> = BTreeMap::new();
    for c in live.iter().filter(|c| accepted(c, cfg)) {
        match best.get(&c.family) {
            Some(b) if by_score(b, c) != Ordering::Greater => {}
            _ => {
                best.insert(c.family, c);
            }
        }
    }
    let mut winners: Vec<&Candidate> = best.into_values().collect();
    winners.sort_by(|a, b| by_score(a, b));
    let mut out: Vec<&Candidate> = Vec::new();
    for c in winners {
        let clash = cfg.merge_final
            && out.iter().any(|k| {
                Candidate::shared_pairs(&k.matching, &c.matching) >= cfg.merge_shared_pairs
                    && (k.x - c.x).norm() <= cfg.merge_radius_m
            });
        if !clash {
            out.push(c);
        }
    }
    out.into_iter().map(to_target).collect()
}

/// A candidate as a reported target.
pub fn to_target(c: &Candidate) -> Target {
    Target {
        position: c.x,
        matching: c.matching.clone(),
        g: c.g,
        j: c.j,
        l_b: c.l_b,
        family: c.family,
    }
}
