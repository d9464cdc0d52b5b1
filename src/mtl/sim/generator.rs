//! Steps (5)–(7) of the §7 generator (spec `multi-target.md`): DP ranges, optional geometric
//! IPs, clutter and the resolution merge, with the ground truth of every surviving range.

use alloc::vec::Vec;

use crate::error::Result;
use crate::math::{Real, Vec2};
use crate::measure::bistatic_range;
use crate::measure::{rng, standard_normal, Rng};
use crate::mtl::sim::scene::{draw_scene_with, poisson, segment_is_los, uniform, Scene};
use crate::mtl::sim::settings::SimSettings;
use crate::mtl::trp::TrpMap;

/// What produced a range (the ground truth of §1's decision variables).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Source {
    /// The direct path (DP) of target `target`.
    Dp {
        /// Target index.
        target: usize,
    },
    /// A geometric indirect path of kind 1 (TX → target → scatterer → RX) or 2 (TX →
    /// scatterer → target → RX).
    Ip {
        /// 1 or 2.
        kind: u8,
        /// Target index.
        target: usize,
        /// Index of the reflecting disc centre.
        scatterer: usize,
    },
    /// A clutter peak (IP or noise peak, uniform on `[0, R_max]`).
    Clutter,
}

/// The ranges one TRP reports, sorted ascending after the resolution merge, with their sources.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TrpRanges {
    /// Ranges `r_{m,i}`, m, ascending.
    pub ranges: Vec<Real>,
    /// `sources[i]` produced `ranges[i]` (the earliest peak of a merged group).
    pub sources: Vec<Source>,
}

/// Ground truth of one target.
#[derive(Debug, Clone, PartialEq)]
pub struct TargetTruth {
    /// Bit `m`: a DP at TRP `m` survived detection (`p_d`) and the resolution merge.
    pub detected: u64,
    /// `dp[m]`: index of the target's DP in TRP `m`'s range list, if it survived.
    pub dp: Vec<Option<usize>>,
}

/// One realisation of §7: the scene (nodes, targets, discs, true blocking vectors `γ` and DP
/// counts) plus the per-TRP range lists and their ground truth.
#[derive(Debug, Clone, PartialEq)]
pub struct Realisation {
    /// Nodes, targets, discs and blocking (steps (1)–(4)).
    pub scene: Scene,
    /// Per TRP (Table I order): surviving ranges and sources.
    pub trps: Vec<TrpRanges>,
    /// Per target: which surviving range is its DP at each TRP.
    pub truth: Vec<TargetTruth>,
}

impl Realisation {
    /// The range lists `r_m` (what the localisation algorithm sees).
    pub fn ranges(&self) -> Vec<Vec<Real>> {
        self.trps.iter().map(|t| t.ranges.clone()).collect()
    }
}

/// Realisation `index` of settings `s`, drawn from the stream `rng(seed, index)` (§7 steps
/// (1)–(7)); depends on `(s, seed, index)` only.
///
/// Errors: those of [`SimSettings::validate`] and of [`super::draw_scene`].
pub fn generate(s: &SimSettings, seed: u64, index: u64) -> Result<Realisation> {
    s.validate()?;
    let map = s.map()?;
    let mut rng = rng(seed, index);
    let scene = draw_scene_with(s, &mut rng)?;
    let mut trps = Vec::with_capacity(map.n_trps());
    let mut truth: Vec<TargetTruth> = (0..scene.targets.len())
        .map(|_| TargetTruth {
            detected: 0,
            dp: alloc::vec![None; map.n_trps()],
        })
        .collect();
    for m in 0..map.n_trps() {
        let peaks = trp_peaks(s, &map, &scene, m, &mut rng);
        let kept = resolution_merge(peaks, s.resolution);
        for (i, &(_, src)) in kept.iter().enumerate() {
            if let Source::Dp { target } = src {
                truth[target].detected |= 1 << m;
                truth[target].dp[m] = Some(i);
            }
        }
        trps.push(TrpRanges {
            ranges: kept.iter().map(|p| p.0).collect(),
            sources: kept.iter().map(|p| p.1).collect(),
        });
    }
    Ok(Realisation { scene, trps, truth })
}

/// Unsorted peaks of TRP `m`: steps (5) DPs, optional geometric IPs, (6) clutter.
pub fn trp_peaks(
    s: &SimSettings,
    map: &TrpMap,
    sc: &Scene,
    m: usize,
    rng: &mut Rng,
) -> Vec<(Real, Source)> {
    let (u, v) = (sc.tx[map.tx(m)], sc.rx[map.rx(m)]);
    let mut peaks = Vec::new();
    let noisy = |rng: &mut Rng, d: Real| d + s.range_sigma * standard_normal(rng);
    for (k, x) in sc.targets.iter().enumerate() {
        if sc.blocking[k].gamma >> m & 1 == 1 && uniform(rng) < s.p_d {
            peaks.push((
                noisy(rng, bistatic_range(u, v, *x)),
                Source::Dp { target: k },
            ));
        }
        let ips = s.geometric_ips;
        for (l, y) in sc.discs.iter().enumerate() {
            // Kind 1: u → x → y → v; kind 2: u → y → x → v. Every leg LoS, the reflecting disc
            // itself excepted.
            let paths = [(1u8, ips.kind1, u, v), (2u8, ips.kind2, v, u)];
            for (kind, on, near, far) in paths {
                if on && ip_is_los(s, sc, &near, x, y, &far, l) && uniform(rng) < s.p_d {
                    let len = (near - x).norm() + (x - y).norm() + (y - far).norm();
                    peaks.push((
                        noisy(rng, len),
                        Source::Ip {
                            kind,
                            target: k,
                            scatterer: l,
                        },
                    ));
                }
            }
        }
    }
    let n = poisson(rng, s.clutter_mean);
    for _ in 0..n {
        peaks.push((s.r_max * uniform(rng), Source::Clutter));
    }
    peaks
}

/// Whether the path `near → x → y → far` (target `x`, reflecting disc `l` at `y`) has all
/// legs LoS.
fn ip_is_los(
    s: &SimSettings,
    sc: &Scene,
    near: &Vec2,
    x: &Vec2,
    y: &Vec2,
    far: &Vec2,
    l: usize,
) -> bool {
    let d = s.diameter;
    segment_is_los(near, x, &sc.discs, d, None)
        && segment_is_los(x, y, &sc.discs, d, Some(l))
        && segment_is_los(y, far, &sc.discs, d, Some(l))
}

/// The resolution merge of §7 step (7) **\[R\]**: sort ascending; a peak within `δ` (`≤ δ`) of the
/// last kept one is discarded, so the earliest peak of a close group is kept.
pub fn resolution_merge<T>(mut peaks: Vec<(Real, T)>, delta: Real) -> Vec<(Real, T)> {
    peaks.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut kept: Vec<(Real, T)> = Vec::with_capacity(peaks.len());
    for p in peaks {
        match kept.last() {
            Some(last) if p.0 - last.0 <= delta => {}
            _ => kept.push(p),
        }
    }
    kept
}
