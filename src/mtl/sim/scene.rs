//! Steps (1)–(4) of the §7 generator (spec `multi-target.md`): disc centres, nodes, targets and
//! the true blocking vector of every target. [`draw_scene`] stops here, so experiments that only
//! need blocking statistics (Table II "True", spec check 11) skip the ranges; the full generator
//! ([`super::generate`]) continues from the same random stream, so both give the same scene.

use alloc::vec::Vec;

use rand::Rng as _;
use rand_distr::{Distribution, Poisson};

use crate::error::{Error, Result};
use crate::math::{Real, Vec2};
use crate::measure::Rng;
use crate::mtl::blocking::kron;
use crate::mtl::polygon::Rect;
use crate::mtl::sim::settings::{LosModel, NodeLayout, SimSettings};

/// Rejection sampling in `R \ S` gives up after this many draws for one point.
pub const MAX_REJECTIONS: usize = 100_000;

/// The true blocking of one target (§1, §3): node LoS vectors and `γ = γ^R ⊗ γ^T` (M3).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TargetBlocking {
    /// Bit `j`: the segment TX `j` – target is LoS (`γ^T`).
    pub los_tx: u64,
    /// Bit `j`: the segment RX `j` – target is LoS (`γ^R`).
    pub los_rx: u64,
    /// Bit `m`: TRP `m` sees both segments LoS, i.e. the target has a DP there before the
    /// detection draw `p_d` (the blocking vector `γ(x_k)` of (M3)).
    pub gamma: u64,
}

impl TargetBlocking {
    /// Number of TRPs with a DP, `|γ|` (the Table II statistic).
    pub fn dp_count(&self) -> u32 {
        self.gamma.count_ones()
    }
}

/// Nodes, targets, scatterer discs and true blocking of one realisation (steps (1)–(4)).
#[derive(Debug, Clone, PartialEq)]
pub struct Scene {
    /// TX positions `u_j`, m.
    pub tx: Vec<Vec2>,
    /// RX positions `v_j`, m.
    pub rx: Vec<Vec2>,
    /// Target positions `x_k`, m.
    pub targets: Vec<Vec2>,
    /// Disc centres, m (diameter [`SimSettings::diameter`]); empty for V-A.
    pub discs: Vec<Vec2>,
    /// Blocking of each target, same order as `targets`.
    pub blocking: Vec<TargetBlocking>,
}

/// A Poisson count with the given mean (0 for a mean ≤ 0).
pub(crate) fn poisson(rng: &mut Rng, mean: Real) -> usize {
    match Poisson::new(mean) {
        Ok(p) => {
            let n: Real = p.sample(rng);
            n as usize
        }
        Err(_) => 0,
    }
}

/// A uniform value in `[0, 1)`.
#[inline]
pub(crate) fn uniform(rng: &mut Rng) -> Real {
    rng.random::<Real>()
}

fn uniform_in(rng: &mut Rng, r: &Rect) -> Vec2 {
    let x = r.min.x + (r.max.x - r.min.x) * uniform(rng);
    let y = r.min.y + (r.max.y - r.min.y) * uniform(rng);
    Vec2::new(x, y)
}

/// Squared distance from `c` to the segment `[a, b]`.
pub fn segment_distance_sq(a: &Vec2, b: &Vec2, c: &Vec2) -> Real {
    let ab = b - a;
    let len2 = ab.norm_squared();
    let t = if len2 > 0.0 {
        ((c - a).dot(&ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (a + ab * t - c).norm_squared()
}

/// Whether `[a, b]` is LoS (§7 step (4)): no disc centre within `D/2` of it, ignoring the disc
/// `skip` (a reflecting scatterer at an end of the segment).
pub fn segment_is_los(
    a: &Vec2,
    b: &Vec2,
    discs: &[Vec2],
    diameter: Real,
    skip: Option<usize>,
) -> bool {
    let r2 = 0.25 * diameter * diameter;
    discs
        .iter()
        .enumerate()
        .all(|(i, c)| Some(i) == skip || segment_distance_sq(a, b, c) > r2)
}

/// Whether `p` lies outside every disc (`R \ S` without the region test).
pub fn is_free(p: &Vec2, discs: &[Vec2], diameter: Real) -> bool {
    let r2 = 0.25 * diameter * diameter;
    discs.iter().all(|c| (p - c).norm_squared() > r2)
}

fn uniform_free(rng: &mut Rng, s: &SimSettings, discs: &[Vec2]) -> Result<Vec2> {
    for _ in 0..MAX_REJECTIONS {
        let p = uniform_in(rng, &s.region);
        if is_free(&p, discs, s.diameter) {
            return Ok(p);
        }
    }
    Err(Error::OutOfRange {
        field: "diameter".into(),
        value: s.diameter,
        allowed: "discs must leave free space in the region for nodes and targets",
    })
}

/// Steps (1)–(4) of the §7 generator with `rng` (no validation; see [`super::generate`]).
pub(crate) fn draw_scene_with(s: &SimSettings, rng: &mut Rng) -> Result<Scene> {
    // (1) Disc centres: a PPP of intensity λ in R (V-B only).
    let discs: Vec<Vec2> = match s.los {
        LosModel::Discs => {
            let n = poisson(rng, s.lambda * s.region.area());
            (0..n).map(|_| uniform_in(rng, &s.region)).collect()
        }
        LosModel::Independent { .. } => Vec::new(),
    };
    // (2) Nodes.
    let (tx, rx) = match &s.nodes {
        NodeLayout::Uniform { n_tx, n_rx } => {
            let tx = (0..*n_tx)
                .map(|_| uniform_free(rng, s, &discs))
                .collect::<Result<_>>()?;
            let rx = (0..*n_rx)
                .map(|_| uniform_free(rng, s, &discs))
                .collect::<Result<_>>()?;
            (tx, rx)
        }
        NodeLayout::Fixed { tx, rx } => (tx.clone(), rx.clone()),
    };
    // (3) Targets.
    let targets: Vec<Vec2> = (0..s.targets)
        .map(|_| uniform_free(rng, s, &discs))
        .collect::<Result<_>>()?;
    // (4) LoS of every node–target segment and γ = γ^R ⊗ γ^T (M3).
    let map = s.map()?;
    let blocking = targets
        .iter()
        .map(|x| {
            let mut los = |nodes: &[Vec2]| {
                let mut mask = 0u64;
                for (j, node) in nodes.iter().enumerate() {
                    let ok = match s.los {
                        LosModel::Discs => segment_is_los(node, x, &discs, s.diameter, None),
                        LosModel::Independent { p_los } => uniform(rng) < p_los,
                    };
                    mask |= (ok as u64) << j;
                }
                mask
            };
            let los_tx = los(&tx);
            let los_rx = los(&rx);
            TargetBlocking {
                los_tx,
                los_rx,
                gamma: kron(&map, los_tx, los_rx),
            }
        })
        .collect();
    Ok(Scene {
        tx,
        rx,
        targets,
        discs,
        blocking,
    })
}

/// Steps (1)–(4) of realisation `index` (stream `(seed, index)`): the same scene as
/// [`super::generate`] with the same arguments, without ranges. Errors: those of
/// [`SimSettings::validate`]; [`Error::OutOfRange`] (`diameter`) when rejection sampling finds no
/// free point in [`MAX_REJECTIONS`] draws.
pub fn draw_scene(s: &SimSettings, seed: u64, index: u64) -> Result<Scene> {
    s.validate()?;
    draw_scene_with(s, &mut crate::measure::rng(seed, index))
}
