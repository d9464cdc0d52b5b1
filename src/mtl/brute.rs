//! Brute-force reference for Algorithm 1 (spec multi-target.md §4) on small instances: every
//! matching (each TRP: one of its MPCs or none) is fitted and tested on its own, with no stages,
//! no order and no caps. Tests compare it with [`crate::mtl::algorithm::locate`].
//!
//! **Definition.** A matching `ℳ` with `|ℳ| ≥ n_min` is *accepted* when, at its ML location `x̂`
//! (Gauss–Newton on `Σ_ℳ (r − d_m(x))²` from each intersection point (§5.2) of the ellipses of
//! its *seed*, the first two of its pairs (lexicographic, pairs sorted by TRP) whose ellipses
//! exist and intersect; the start giving the smallest `J` is kept):
//! - every pair passes the ellipse test of (M6) against the rest of the matching,
//!   `|r_{m,i} − d_m(x̂)| ≤ T_e σ_e` with `σ_e² = c²σ²(1 + η_mᵀ(G_{−m}ᵀG_{−m})⁻¹η_m)` and `G_{−m}`
//!   the gradient rows of `ℳ \ {(m, i)}`;
//! - the final test of [`crate::mtl::algorithm::select::accepted`] holds for `ĝ` on all TRPs
//!   (`ĝ_m = 1` iff `m` is matched): `L_b ≤ T_b` or the size rule.
//!
//! Accepted matchings are reported as targets after the same final merge as the staged algorithm
//! (ascending `J` (M2), a matching sharing ≥ `merge_shared_pairs` pairs with a kept one is
//! dropped; always applied here). "Staged = brute force" means: the same number of targets and a
//! one-to-one pairing of their positions within a tolerance (see `tests/mtl/algorithm.rs`).
//!
//! Speed-up (documented, \[P\] of this reference): from a start `x₀` an MPC is only tried when
//! its normalized error at `x₀` against the two seed pairs is at most [`SCREEN_FACTOR`]`·T_e`.

use alloc::collections::BTreeMap;
use alloc::vec::Vec;

use crate::error::Result;
use crate::math::{Real, Vec2};
use crate::mtl::algorithm::candidate::{Candidate, Geometry, Pair};
use crate::mtl::algorithm::{select, validate, IntersectionCache, Measurements, MtlConfig, Target};
use crate::mtl::blocking::{BlockingModel, PartialVector};

/// An MPC whose normalized error at a start point exceeds this times `T_e` is not tried from it.
pub const SCREEN_FACTOR: Real = 3.0;

/// All accepted matchings (one entry per distinct matching, lowest `J`), ascending `J`; each has
/// its own family id; ellipse intersections come from `cache` (shareable with
/// [`crate::mtl::algorithm::locate_cached`]). Errors as [`crate::mtl::algorithm::validate`].
pub fn accepted_matchings<B: BlockingModel + ?Sized>(
    input: &Measurements,
    model: &B,
    cfg: &MtlConfig,
    cache: &mut IntersectionCache,
) -> Result<Vec<Candidate>> {
    validate(input, model, cfg)?;
    let map = *model.trp_map();
    let geo = Geometry { map, input: *input };
    let n = map.n_trps();
    let pairs: Vec<Pair> = (0..n)
        .flat_map(|trp| (0..input.ranges[trp].len()).map(move |mpc| Pair { trp, mpc }))
        .collect();
    cache.prepare(&geo, cfg.region.as_ref());
    let mut seeds = BTreeMap::new();
    for (k, &p) in pairs.iter().enumerate() {
        for &q in pairs[k + 1..].iter().filter(|q| q.trp != p.trp) {
            let pts = cache.points(&geo, p, q);
            if !pts.is_empty() {
                seeds.insert((p, q), pts.to_vec());
            }
        }
    }
    let mut found: BTreeMap<Vec<Pair>, Candidate> = BTreeMap::new();
    for (&(p, q), points) in &seeds {
        let seed = [p, q];
        for &x0 in points {
            // Options per other TRP: the screened MPCs.
            let options: Vec<Vec<Pair>> = (0..n)
                .filter(|&t| t != p.trp && t != q.trp)
                .map(|t| {
                    pairs
                        .iter()
                        .copied()
                        .filter(|o| o.trp == t)
                        .filter(|o| {
                            let z = geo.normalized_error(&seed, &x0, t, geo.range_of(*o));
                            matches!(z, Some(z) if z <= SCREEN_FACTOR * cfg.t_e)
                        })
                        .collect()
                })
                .collect();
            let mut chosen = seed.to_vec();
            enumerate(&options, 0, &mut chosen, &mut |m| {
                let mut m = m.to_vec();
                m.sort_unstable();
                if canonical_seed(&m, &seeds) == Some((p, q)) {
                    evaluate(&geo, model, cfg, &m, x0, &mut found)?;
                }
                Ok(())
            })?;
        }
    }
    let mut out: Vec<Candidate> = found.into_values().collect();
    out.sort_by(select::by_score);
    for (f, c) in out.iter_mut().enumerate() {
        c.family = f;
    }
    Ok(out)
}

/// The seed of a (sorted) matching: its first two pairs, in lexicographic order, whose ellipses
/// intersect.
fn canonical_seed(m: &[Pair], seeds: &BTreeMap<(Pair, Pair), Vec<Vec2>>) -> Option<(Pair, Pair)> {
    (0..m.len())
        .flat_map(|i| (i + 1..m.len()).map(move |j| (m[i], m[j])))
        .find(|k| seeds.contains_key(k))
}

/// The brute-force targets: [`accepted_matchings`] after the final merge (see the module docs).
pub fn brute_force<B: BlockingModel + ?Sized>(
    input: &Measurements,
    model: &B,
    cfg: &MtlConfig,
    cache: &mut IntersectionCache,
) -> Result<Vec<Target>> {
    let all = accepted_matchings(input, model, cfg, cache)?;
    let merge = MtlConfig {
        merge_final: true,
        ..cfg.clone()
    };
    Ok(select::finalize(&all, &merge))
}

/// Every choice of "none or one option" per remaining TRP, calling `f` on each full matching.
fn enumerate(
    options: &[Vec<Pair>],
    k: usize,
    chosen: &mut Vec<Pair>,
    f: &mut impl FnMut(&[Pair]) -> Result<()>,
) -> Result<()> {
    if k == options.len() {
        return f(chosen);
    }
    enumerate(options, k + 1, chosen, f)?;
    for &p in &options[k] {
        chosen.push(p);
        enumerate(options, k + 1, chosen, f)?;
        chosen.pop();
    }
    Ok(())
}

/// Fit and test one matching from start `x0`; record it in `found` if accepted with a lower `J`.
fn evaluate<B: BlockingModel + ?Sized>(
    geo: &Geometry,
    model: &B,
    cfg: &MtlConfig,
    matching: &[Pair],
    x0: Vec2,
    found: &mut BTreeMap<Vec<Pair>, Candidate>,
) -> Result<()> {
    if matching.len() < cfg.n_min.max(2) {
        return Ok(());
    }
    let Some(x) = geo.refine(matching, x0, &cfg.refinement) else {
        return Ok(());
    };
    for (k, p) in matching.iter().enumerate() {
        let rest: Vec<Pair> = matching
            .iter()
            .enumerate()
            .filter(|&(j, _)| j != k)
            .map(|(_, q)| *q)
            .collect();
        match geo.normalized_error(&rest, &x, p.trp, geo.range_of(*p)) {
            Some(z) if z <= cfg.t_e => {}
            _ => return Ok(()),
        }
    }
    let ones = matching.iter().fold(0u64, |m, p| m | 1 << p.trp);
    let g = PartialVector::full(&geo.map, ones)?;
    let l_b = model.blocking_likelihood(&x, &g)?;
    let c = Candidate {
        matching: matching.to_vec(),
        x,
        g,
        family: 0,
        l_b,
        j: geo.range_term(matching, &x) + l_b,
    };
    if !select::accepted(&c, cfg) {
        return Ok(());
    }
    match found.get(&c.matching) {
        Some(old) if old.j <= c.j => {}
        _ => {
            found.insert(c.matching.clone(), c);
        }
    }
    Ok(())
}
