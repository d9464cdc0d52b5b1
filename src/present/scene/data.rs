//! The measurements of a scene (§7 steps (4)–(7) on the user's fixed discs): LoS of every
//! node–target segment, the true blocking vectors `γ` (M3), and per TRP the generator's own peaks
//! ([`trp_peaks`]: DPs kept w.p. `p_d` with noise `cσ`, Poisson clutter) on the stream
//! `rng(seed, 0)`, merged at the resolution `δ` ([`resolution_merge`]).

use alloc::vec::Vec;

use crate::error::Result;
use crate::math::{Real, Vec2};
use crate::measure::rng;
use crate::mtl::blocking::kron;
use crate::mtl::sim::generator::{resolution_merge, trp_peaks, Source};
use crate::mtl::sim::scene::{segment_distance_sq, Scene, TargetBlocking};
use crate::mtl::sim::settings::{GeometricIps, LosModel, NodeLayout, SimSettings};
use crate::mtl::trp::TrpMap;

use super::{v, MtlScene};

/// The measurements of a scene: per TRP the merged ranges and their sources, the true blocking.
pub(super) struct Data {
    pub scene: Scene,
    pub ranges: Vec<Vec<Real>>,
    pub sources: Vec<Vec<Source>>,
}

/// Steps (4)–(7) on the scene's fixed discs: LoS masks, `γ` (M3), the generator's peaks of
/// every TRP from the stream `rng(seed, 0)`, the resolution merge.
pub(super) fn measure(scene: &MtlScene, map: &TrpMap) -> Result<Data> {
    let pts = |l: &[[Real; 2]]| l.iter().map(v).collect::<Vec<Vec2>>();
    let (tx, rx) = (pts(&scene.transmitters), pts(&scene.receivers));
    let (targets, discs) = (pts(&scene.targets), pts(&scene.discs));
    let d = scene.diameter;
    let blocking = targets
        .iter()
        .map(|x| {
            let los = |nodes: &[Vec2]| {
                nodes.iter().enumerate().fold(0u64, |mask, (j, n)| {
                    mask | (u64::from(first_blocker(n, x, &discs, d).is_none()) << j)
                })
            };
            let (los_tx, los_rx) = (los(&tx), los(&rx));
            TargetBlocking {
                los_tx,
                los_rx,
                gamma: kron(map, los_tx, los_rx),
            }
        })
        .collect();
    let settings = SimSettings {
        region: scene.rect()?,
        nodes: NodeLayout::Fixed {
            tx: tx.clone(),
            rx: rx.clone(),
        },
        los: LosModel::Discs,
        lambda: scene.lambda,
        diameter: d,
        range_sigma: scene.range_sigma,
        resolution: scene.resolution,
        detection_radius: scene.detection_radius,
        p_d: scene.p_d,
        targets: targets.len().max(1),
        clutter_mean: scene.clutter_mean,
        r_max: scene.r_max_m(),
        geometric_ips: GeometricIps::default(),
    };
    let sc = Scene {
        tx,
        rx,
        targets,
        discs,
        blocking,
    };
    let mut stream = rng(scene.seed, 0);
    let (mut ranges, mut sources) = (Vec::new(), Vec::new());
    for m in 0..map.n_trps() {
        let kept = resolution_merge(
            trp_peaks(&settings, map, &sc, m, &mut stream),
            scene.resolution,
        );
        ranges.push(kept.iter().map(|p| p.0).collect());
        sources.push(kept.iter().map(|p| p.1).collect());
    }
    Ok(Data {
        scene: sc,
        ranges,
        sources,
    })
}

/// The first disc whose centre lies within `D/2` of `[a, b]` (the segment is blocked), if any.
pub(super) fn first_blocker(a: &Vec2, b: &Vec2, discs: &[Vec2], diameter: Real) -> Option<usize> {
    let r2 = 0.25 * diameter * diameter;
    discs
        .iter()
        .position(|c| segment_distance_sq(a, b, c) <= r2)
}
