//! Table II of spec `multi-target.md` §8: the distribution of the number of DPs at target points,
//! the "True" row from the generator (spec check 11) and the i.c.b row from
//! Binomial`(M, 1 − p_u)` (spec check 4). Rows are pmfs over `0..=M` DPs; [`table2_buckets`]
//! folds one into the printed columns `≤ 2, 3, …, M`.

use alloc::vec;
use alloc::vec::Vec;

use crate::error::{Error, Result};
use crate::math::Real;
use crate::mtl::icb::IcbModel;
use crate::mtl::sim::scene::draw_scene;
use crate::mtl::sim::settings::SimSettings;
use crate::mtl::trp::TrpMap;

/// The i.c.b row: `P(k DPs)` for `k = 0..=M`, the Binomial`(M, 1 − p_u)` pmf of
/// [`IcbModel::dp_count_pmf`]. Errors: [`Error::OutOfRange`] (`p_u`) outside `[0, 1]`.
pub fn icb_row(map: TrpMap, p_u: Real) -> Result<Vec<Real>> {
    let model = IcbModel::from_p_u(map, p_u)?;
    Ok((0..=map.n_trps()).map(|k| model.dp_count_pmf(k)).collect())
}

/// DP counts `|γ(x_k)|` of every target of realisations `0..realisations` (streams
/// `(seed, i)`; the same scenes as [`super::generate`]).
///
/// Errors: those of [`draw_scene`]; [`Error::SizeLimit`] (`realisations`) when 0.
pub fn dp_counts(s: &SimSettings, seed: u64, realisations: u64) -> Result<Vec<u32>> {
    if realisations == 0 {
        return Err(Error::SizeLimit {
            field: "realisations",
            value: 0,
            min: 1,
            max: usize::MAX,
        });
    }
    let mut counts = Vec::with_capacity(realisations as usize * s.targets);
    for i in 0..realisations {
        let scene = draw_scene(s, seed, i)?;
        counts.extend(scene.blocking.iter().map(|b| b.dp_count()));
    }
    Ok(counts)
}

/// The "True" row: the empirical pmf over `0..=M` of [`dp_counts`] (`realisations · K` target
/// draws). Same errors.
pub fn true_row(s: &SimSettings, seed: u64, realisations: u64) -> Result<Vec<Real>> {
    let m = s.map()?.n_trps();
    let counts = dp_counts(s, seed, realisations)?;
    let mut row = vec![0.0; m + 1];
    for &c in &counts {
        row[c as usize] += 1.0;
    }
    let n = counts.len() as Real;
    row.iter_mut().for_each(|p| *p /= n);
    Ok(row)
}

/// Table II's columns from a pmf over `0..=M`: `[P(≤ 2), P(3), …, P(M)]` (for 3×3: `≤2, 3, …, 9`;
/// a shorter pmf gives just `[P(≤ 2)]` plus what exists).
pub fn table2_buckets(pmf: &[Real]) -> Vec<Real> {
    let low: Real = pmf.iter().take(3).sum();
    core::iter::once(low)
        .chain(pmf.iter().skip(3).copied())
        .collect()
}
