//! The genie-aided method of Fig. 5 (spec `multi-target.md` §8, **\[C\]**). \[A\]: "running the
//! Bayesian MTL Algorithm on the true target matchings". For each target `k` the genie hands
//! Algorithm 1 only that target's surviving DP ranges (one range at each TRP where its DP
//! survived detection and the resolution merge, nothing elsewhere: no clutter, no other target),
//! with the same model and thresholds, and detects the target iff the algorithm returns an
//! estimate within `r_det` of `x_k`. So `|ℳ| ≥ n_min`, `L_b ≤ T_b` and `‖x̂ − x_k‖ ≤ r_det` are
//! checked exactly as in the spec's wording, and an inconsistent observed vector is handled by
//! the algorithm's case 2 branching (a fixed matching whose `ĝ` is inconsistent would
//! otherwise have `L_b = ∞`, which would make the genie worse than the algorithm).

use alloc::vec::Vec;

use crate::error::Result;
use crate::math::{Real, Vec2};
use crate::mtl::algorithm::{locate_cached, IntersectionCache, Measurements, MtlConfig};
use crate::mtl::blocking::BlockingModel;
use crate::mtl::sim::Realisation;

/// The genie's input for target `k` of `r`: its surviving DP ranges only, per TRP.
pub fn true_ranges(r: &Realisation, k: usize) -> Vec<Vec<Real>> {
    r.truth[k]
        .dp
        .iter()
        .zip(&r.trps)
        .map(|(dp, trp)| dp.map(|i| alloc::vec![trp.ranges[i]]).unwrap_or_default())
        .collect()
}

/// The genie's detections with Algorithm 1 settings `mtl` (positions of the estimates that lie
/// within `r_det` of their own target). `caches[k]` keeps target `k`'s ellipse intersections
/// across a sweep (resized as needed).
///
/// Errors: those of [`locate_cached`].
pub fn detections<B: BlockingModel + ?Sized>(
    input: &Measurements,
    r: &Realisation,
    model: &B,
    mtl: &MtlConfig,
    r_det: Real,
    caches: &mut Vec<IntersectionCache>,
) -> Result<Vec<Vec2>> {
    caches.resize_with(r.scene.targets.len(), IntersectionCache::new);
    let mut out = Vec::new();
    for (k, x) in r.scene.targets.iter().enumerate() {
        let ranges = true_ranges(r, k);
        let own = Measurements {
            ranges: &ranges,
            ..*input
        };
        let found = locate_cached(&own, model, mtl, &mut caches[k])?;
        if let Some(t) = found
            .targets
            .iter()
            .find(|t| (t.position - x).norm() <= r_det)
        {
            out.push(t.position);
        }
    }
    Ok(out)
}
