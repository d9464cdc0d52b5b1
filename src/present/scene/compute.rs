//! Scene → view: the measurements ([`super::data`]), Algorithm 1 with its trace on the chosen
//! blocking model ([`super::model`]), and the drawable data ([`super::output`]).

use alloc::vec::Vec;

use crate::error::Result;
use crate::math::{Real, Vec2};
use crate::measure::iso_range_ellipse;
use crate::mtl::algorithm::candidate::Geometry;
use crate::mtl::algorithm::{
    select, stages, validate, Candidate, IntersectionCache, Measurements, MtlConfig, Pair, Status,
    Target,
};
use crate::mtl::sim::generator::Source;
use crate::mtl::sim::metrics::count_detections;
use crate::mtl::sim::scene::Scene;
use crate::mtl::trp::TrpMap;

use super::data::{first_blocker, measure, Data};
use super::model::{blocking_model, ViewCache};
use super::output::{
    DetectedView, HypothesisView, MetricsView, MtlView, RangeView, SeedView, SegmentView,
    StageCounts, TargetView, TrpView,
};
use super::MtlScene;

/// The view of `scene` (validated first; errors of [`MtlScene::validate`] and, never expected
/// after it, of Algorithm 1's own validation).
pub fn mtl_view(scene: &MtlScene) -> Result<MtlView> {
    mtl_view_cached(scene, &mut ViewCache::default())
}

/// [`mtl_view`] reusing (and filling) `cache`; identical results.
pub fn mtl_view_cached(scene: &MtlScene, cache: &mut ViewCache) -> Result<MtlView> {
    scene.validate()?;
    let map = scene.map()?;
    let rect = scene.rect()?;
    let data = measure(scene, &map)?;
    cache.prepare(scene);
    let ViewCache {
        tables,
        intersections: cache,
        ..
    } = cache;
    let (model, model_view) = blocking_model(scene, &map, tables)?;
    let cfg = MtlConfig {
        t_e: scene.t_e,
        t_b: scene.t_b,
        region: Some(rect),
        consistency: model_view.consistency,
        max_candidates: scene
            .max_candidates
            .unwrap_or(crate::mtl::algorithm::DEFAULT_MAX_CANDIDATES),
        ..MtlConfig::default()
    };
    let sc = &data.scene;
    let input = Measurements {
        tx: &sc.tx,
        rx: &sc.rx,
        ranges: &data.ranges,
        c_sigma_m: scene.range_sigma,
    };
    let order = validate(&input, model.as_ref(), &cfg)?;
    let mut run = stages::Run::new(&input, model.as_ref(), &cfg, order, cache);
    let live = run.run()?;
    let stages = stage_counts(run.stage_counts());
    let found = select::finalize(&live, &cfg);
    let geo = Geometry { map, input };
    let seeds = seeds(&geo, cache);

    let estimates: Vec<Vec2> = found.iter().map(|t| t.position).collect();
    let counts = count_detections(&sc.targets, &estimates, scene.detection_radius);
    let r2 = scene.detection_radius * scene.detection_radius;
    let detected: Vec<DetectedView> = found
        .iter()
        .map(|t| {
            let nearest = sc
                .targets
                .iter()
                .enumerate()
                .map(|(k, x)| (k, (x - t.position).norm()))
                .min_by(|a, b| a.1.total_cmp(&b.1));
            DetectedView {
                x: xy(&t.position),
                matching: pairs(&t.matching),
                j: t.j,
                l_b: t.l_b,
                family: t.family,
                nearest_target: nearest.map(|n| n.0),
                error_m: nearest.map(|n| n.1),
                hit: nearest.is_some_and(|n| n.1 * n.1 <= r2),
            }
        })
        .collect();
    let targets = sc
        .targets
        .iter()
        .zip(&sc.blocking)
        .enumerate()
        .map(|(k, (x, b))| TargetView {
            x: xy(x),
            los_trps: bits(b.gamma, map.n_trps()),
            dp_trps: (0..map.n_trps())
                .filter(|&m| data.sources[m].contains(&Source::Dp { target: k }))
                .collect(),
            detected: estimates.iter().any(|e| (e - x).norm_squared() <= r2),
        })
        .collect();
    Ok(MtlView {
        trps: trp_views(&data, &map, &found),
        seeds,
        hypotheses: live.iter().map(|c| hypothesis(c, &cfg)).collect(),
        detected,
        targets,
        segments: segments(scene, sc),
        metrics: MetricsView {
            targets: counts.targets,
            estimates: counts.estimates,
            detected: counts.detected,
            false_alarms: counts.false_alarms,
            p_d: (counts.targets > 0).then(|| counts.detected as Real / counts.targets as Real),
            p_fa: counts.false_alarms as Real / counts.estimates.max(1) as Real,
        },
        stages,
        model: model_view,
        mpcs: data.ranges.iter().map(Vec::len).sum(),
    })
}

/// Every ellipse intersection of every pair of TRPs and MPCs (the cache holds them after the
/// run when late seeds are on, which covers all TRP pairs).
fn seeds(geo: &Geometry, cache: &mut IntersectionCache) -> Vec<SeedView> {
    let ranges = geo.input.ranges;
    let mut out = Vec::new();
    for a in 0..ranges.len() {
        for b in a + 1..ranges.len() {
            for i in 0..ranges[a].len() {
                for k in 0..ranges[b].len() {
                    let (p, q) = (Pair { trp: a, mpc: i }, Pair { trp: b, mpc: k });
                    for x in cache.points(geo, p, q) {
                        out.push(SeedView {
                            x: xy(x),
                            pairs: [[a, i], [b, k]],
                        });
                    }
                }
            }
        }
    }
    out
}

fn trp_views(data: &Data, map: &TrpMap, found: &[Target]) -> Vec<TrpView> {
    let sc = &data.scene;
    (0..map.n_trps())
        .map(|m| {
            let (u, w) = (sc.tx[map.tx(m)], sc.rx[map.rx(m)]);
            let ranges = data.ranges[m]
                .iter()
                .zip(&data.sources[m])
                .enumerate()
                .map(|(i, (&r, src))| {
                    let target = match src {
                        Source::Dp { target } => Some(*target),
                        _ => None,
                    };
                    let pair = Pair { trp: m, mpc: i };
                    RangeView {
                        range_m: r,
                        source: if target.is_some() { "dp" } else { "clutter" },
                        target,
                        ellipse: iso_range_ellipse(u, w, r).map(Into::into),
                        matched_by: (0..found.len())
                            .filter(|&t| found[t].matching.contains(&pair))
                            .collect(),
                    }
                })
                .collect();
            TrpView {
                trp: m,
                tx: map.tx(m),
                rx: map.rx(m),
                ranges,
            }
        })
        .collect()
}

fn hypothesis(c: &Candidate, cfg: &MtlConfig) -> HypothesisView {
    HypothesisView {
        x: xy(&c.x),
        matching: pairs(&c.matching),
        j: c.j,
        l_b: c.l_b,
        family: c.family,
        accepted: select::accepted(c, cfg),
    }
}

fn segments(scene: &MtlScene, sc: &Scene) -> Vec<SegmentView> {
    let mut out = Vec::new();
    for (k, x) in sc.targets.iter().enumerate() {
        for (node, list) in [("tx", &sc.tx), ("rx", &sc.rx)] {
            for (j, n) in list.iter().enumerate() {
                let disc = first_blocker(n, x, &sc.discs, scene.diameter);
                out.push(SegmentView {
                    node,
                    index: j,
                    target: k,
                    a: xy(n),
                    b: xy(x),
                    blocked: disc.is_some(),
                    disc,
                });
            }
        }
    }
    out
}

fn stage_counts(counts: &[[usize; 6]]) -> Vec<StageCounts> {
    counts
        .iter()
        .enumerate()
        .map(|(s, n)| {
            let at = |status: Status| n[status.index()];
            StageCounts {
                stage: s + 2,
                kept: at(Status::Kept),
                blocking: at(Status::Blocking),
                inconsistent: at(Status::Inconsistent),
                unlocatable: at(Status::Unlocatable),
                duplicate: at(Status::Duplicate),
                capped: at(Status::Capped),
            }
        })
        .collect()
}

fn xy(p: &Vec2) -> [Real; 2] {
    [p.x, p.y]
}

fn pairs(m: &[Pair]) -> Vec<[usize; 2]> {
    m.iter().map(|p| [p.trp, p.mpc]).collect()
}

/// The indices of the set bits of `mask` below `n`.
fn bits(mask: u64, n: usize) -> Vec<usize> {
    (0..n).filter(|&m| mask >> m & 1 == 1).collect()
}
