//! Unit tests of the multi-target view.

use alloc::string::ToString;
use alloc::vec::Vec;

use super::output::MtlView;
use super::*;
use crate::mtl::algorithm::{locate, Measurements, MtlConfig, MtlOutput};
use crate::mtl::blocking::{NodeBlockingModel, NodeTableCache, TableCached, TABLE_GRID_M};
use crate::mtl::ppp::{PppBlocking, PppNodeModel};

fn finite(v: &MtlView) -> bool {
    let text = serde_json::to_string(v).unwrap();
    // serde_json writes non-finite numbers as null: scan every number of the view instead.
    fn all_finite(v: &serde_json::Value) -> bool {
        match v {
            serde_json::Value::Number(n) => n.as_f64().is_some_and(f64::is_finite),
            serde_json::Value::Array(a) => a.iter().all(all_finite),
            serde_json::Value::Object(o) => o.values().all(all_finite),
            _ => true,
        }
    }
    let value: serde_json::Value = serde_json::from_str(&text).unwrap();
    all_finite(&value) && !text.contains("NaN")
}

/// The default (V-B) scene: both targets found within 0.5 m, no false alarm, TX 1 → T1 blocked by
/// the disc at (2.3, 2.5) (so T1 has 6 LoS TRPs, T2 all 9), one view entry per TRP.
#[test]
fn default_scene_detects_both_targets() {
    let s = MtlScene::vb();
    s.validate().unwrap();
    let view = mtl_view(&s).unwrap();
    assert_eq!(view.trps.len(), 9);
    assert_eq!(view.metrics.targets, 2);
    assert_eq!(view.metrics.detected, 2, "{:?}", view.detected);
    assert_eq!(view.metrics.false_alarms, 0);
    for (k, t) in view.targets.iter().enumerate() {
        assert!(t.detected, "target {k}");
        let best = view
            .detected
            .iter()
            .map(|d| (d.x[0] - t.x[0]).hypot(d.x[1] - t.x[1]))
            .fold(f64::INFINITY, f64::min);
        assert!(best < 0.5, "target {k}: {best}");
    }
    assert_eq!(view.targets[0].los_trps, [1, 2, 4, 5, 7, 8]);
    assert_eq!(view.targets[1].los_trps.len(), 9);
    let blocked: Vec<_> = view.segments.iter().filter(|s| s.blocked).collect();
    assert_eq!(blocked.len(), 1);
    assert_eq!(
        (
            blocked[0].node,
            blocked[0].index,
            blocked[0].target,
            blocked[0].disc
        ),
        ("tx", 0, 0, Some(0))
    );
    // Every detection's matching is drawn: its ranges know the detection.
    for (i, d) in view.detected.iter().enumerate() {
        for &[m, k] in &d.matching {
            assert!(view.trps[m].ranges[k].matched_by.contains(&i));
        }
    }
    assert!(!view.seeds.is_empty() && !view.hypotheses.is_empty());
    assert_eq!(view.stages.len(), 8, "stages 2..=9");
    assert!(finite(&view));
}

/// The view's detections are Algorithm 1's: bitwise those of `locate` with the PPP model's node
/// tables on the 1 µm grid (what the view runs; the memo across views changes nothing). With the
/// plain model near-ties in `J` may resolve otherwise (see `TABLE_GRID_M`): on seed 3 one false
/// alarm is another ghost.
#[test]
fn detections_equal_locate() {
    for seed in 0..4 {
        let mut s = MtlScene::vb();
        s.seed = seed;
        let view = mtl_view(&s).unwrap();
        let ranges: Vec<Vec<f64>> = view
            .trps
            .iter()
            .map(|t| t.ranges.iter().map(|r| r.range_m).collect())
            .collect();
        let pts = |l: &[[f64; 2]]| l.iter().map(v).collect::<Vec<_>>();
        let (tx, rx) = (pts(&s.transmitters), pts(&s.receivers));
        let rect = s.rect().unwrap();
        let ppp = PppBlocking::new(s.lambda, s.diameter, Some(rect), false).unwrap();
        let nodes = PppNodeModel::new(ppp, tx.clone(), rx.clone()).unwrap();
        let model = NodeBlockingModel::new(s.map().unwrap(), nodes, s.p_d).unwrap();
        let cfg = MtlConfig {
            t_e: s.t_e,
            t_b: s.t_b,
            region: Some(rect),
            ..MtlConfig::default()
        };
        let input = Measurements {
            tx: &tx,
            rx: &rx,
            ranges: &ranges,
            c_sigma_m: s.range_sigma,
        };
        let positions = |out: MtlOutput| -> Vec<[f64; 2]> {
            out.targets
                .iter()
                .map(|t| [t.position.x, t.position.y])
                .collect()
        };
        let tables = NodeTableCache::default();
        let on_grid = TableCached::on_grid(&model, &tables, TABLE_GRID_M);
        let a = positions(locate(&input, &on_grid, &cfg).unwrap());
        let b: Vec<[f64; 2]> = view.detected.iter().map(|d| d.x).collect();
        assert_eq!(a, b, "seed {seed}");
    }
}

/// A disc placed on a node–target segment blocks it (and removes those DPs); moved off, LoS.
#[test]
fn disc_on_a_segment_blocks_it() {
    let mut s = MtlScene::vb();
    s.discs = alloc::vec![[4.25, 2.25]]; // the midpoint of Rx2 (5, 0.5) → T1 (3.5, 4)
    let view = mtl_view(&s).unwrap();
    let hit: Vec<_> = view.segments.iter().filter(|g| g.blocked).collect();
    assert!(!hit.is_empty());
    for g in &hit {
        assert_eq!(g.disc, Some(0));
    }
    let on = hit
        .iter()
        .find(|g| g.node == "rx" && g.index == 1 && g.target == 0);
    let on = on.expect("Rx2 → T1 blocked");
    // No DP of that target at any TRP of RX 2 (TRPs 3, 4, 5).
    let t = &view.targets[on.target];
    assert!(t.los_trps.iter().all(|m| !(3..6).contains(m)), "{t:?}");
    s.discs = alloc::vec![[9.5, 9.5]];
    let view = mtl_view(&s).unwrap();
    assert!(view.segments.iter().all(|g| !g.blocked));
    assert!(view.targets.iter().all(|t| t.los_trps.len() == 9));
}

/// Both i.c.b forms and the exact PPP model run; the i.c.b model turns consistency off.
#[test]
fn model_switch() {
    let mut s = MtlScene::vb();
    s.model = BlockingChoice::Icb {
        p_u: Some(0.5329),
        p_los: None,
    };
    s.t_b = 20.0;
    let v = mtl_view(&s).unwrap();
    assert_eq!((v.model.kind, v.model.consistency), ("icb", false));
    assert_eq!(v.model.p_u, Some(0.5329));
    assert!(finite(&v));
    s.model = BlockingChoice::Icb {
        p_u: None,
        p_los: Some(0.9),
    };
    let v = mtl_view(&s).unwrap();
    assert!((v.model.p_u.unwrap() - (1.0 - 0.9 * 0.81)).abs() < 1e-12);
    s.model = BlockingChoice::Ppp { exact: true };
    s.t_b = 6.0;
    let v = mtl_view(&s).unwrap();
    assert_eq!((v.model.kind, v.model.exact), ("ppp", Some(true)));
    assert_eq!(v.metrics.detected, 2);
}

/// The scene round-trips through JSON; bad input gives named errors, never a panic.
#[test]
fn errors_are_named() {
    let s = MtlScene::vb();
    assert_eq!(MtlScene::from_json(&s.to_json()).unwrap(), s);
    let e = |f: &dyn Fn(&mut MtlScene)| {
        let mut s = MtlScene::vb();
        f(&mut s);
        let a = s.validate().unwrap_err().to_string();
        let b = mtl_view(&s).unwrap_err().to_string();
        assert_eq!(a, b);
        a
    };
    let m = e(&|s| s.discs.push([1.1, 1.1]));
    assert!(m.starts_with("discs[3]:") && m.contains("D/2"), "{m}");
    let m = e(&|s| s.discs[0] = [3.5, 3.8]);
    assert!(m.starts_with("discs[0]:"), "{m}");
    let m = e(&|s| s.targets[1] = [11.0, 5.0]);
    assert!(m.starts_with("targets[1]:") && m.contains("region"), "{m}");
    let m = e(&|s| s.targets[0] = [f64::NAN, 5.0]);
    assert_eq!(m, "targets[0]: not a finite number");
    let m = e(&|s| s.t_e = -1.0);
    assert!(m.starts_with("t_e:"), "{m}");
    let m = e(&|s| s.t_b = f64::NAN);
    assert!(m.starts_with("t_b:"), "{m}");
    let m = e(&|s| s.range_sigma = 0.0);
    assert!(m.starts_with("range_sigma:"), "{m}");
    // Fuzz (issue 12): r_max 3e301 gave ellipses with infinite axes.
    let m = e(&|s| s.r_max = Some(3e301));
    assert!(m.starts_with("r_max: 3e301 is out of range"), "{m}");
    let m = e(&|s| s.p_d = 1.5);
    assert!(m.starts_with("p_d:"), "{m}");
    let m = e(&|s| s.clutter_mean = 50.0);
    assert!(m.starts_with("clutter_mean:"), "{m}");
    let m = e(&|s| s.transmitters.clear());
    assert!(m.starts_with("transmitters:"), "{m}");
    let m = e(&|s| s.receivers.extend([[1.0, 2.0]; 4]));
    assert!(m.starts_with("receivers:"), "{m}");
    let m = e(&|s| s.region = [0.0, 0.0, 0.0, 10.0]);
    assert!(m.starts_with("region.x:"), "{m}");
    let m = e(&|s| {
        s.model = BlockingChoice::Icb {
            p_u: Some(0.5),
            p_los: Some(0.9),
        }
    });
    assert!(m.contains("exactly one of p_u, p_los"), "{m}");
    let m = e(&|s| {
        s.model = BlockingChoice::Icb {
            p_u: Some(-0.1),
            p_los: None,
        }
    });
    assert!(m.starts_with("model.p_u:"), "{m}");
    // JSON: unknown field, NaN sent as null, bad syntax.
    let j = s.to_json().replace("\"lambda\"", "\"lamda\"");
    let m = MtlScene::from_json(&j).unwrap_err().to_string();
    assert!(m.contains("lamda"), "{m}");
    let j = s.to_json().replace("\"t_e\":3.0", "\"t_e\":null");
    let m = MtlScene::from_json(&j).unwrap_err().to_string();
    assert!(m.contains("t_e"), "{m}");
    assert!(MtlScene::from_json("{").is_err());
}

/// No targets, no discs, no clutter: nothing detected, metrics defined, nothing NaN.
#[test]
fn empty_scene() {
    let mut s = MtlScene::vb();
    s.targets.clear();
    s.discs.clear();
    s.clutter_mean = 0.0;
    let v = mtl_view(&s).unwrap();
    assert_eq!(v.mpcs, 0);
    assert!(v.detected.is_empty() && v.segments.is_empty());
    assert_eq!((v.metrics.p_d, v.metrics.p_fa), (None, 0.0));
    assert!(finite(&v));
}

/// A warm cache (the previous scene's node tables and ellipse intersections) changes nothing, also across a target drag
/// and a model change; a node move empties it.
#[test]
fn cache_is_transparent() {
    let mut cache = ViewCache::default();
    let mut s = MtlScene::vb();
    let cold = mtl_view(&s).unwrap();
    assert_eq!(mtl_view_cached(&s, &mut cache).unwrap(), cold);
    let n = cache.len();
    assert!(n > 0);
    // Ellipse pairs of ranges the drag leaves alone are reused, not recomputed.
    let pairs = cache.intersections.len();
    s.targets[1][0] -= 0.05;
    assert_eq!(
        mtl_view_cached(&s, &mut cache).unwrap(),
        mtl_view(&s).unwrap()
    );
    let grown = cache.intersections.len() - pairs;
    assert!(grown > 0 && grown < pairs, "{pairs} pairs, {grown} new");
    for step in 1..4 {
        s.targets[1][0] -= 0.1 * step as f64;
        let warm = mtl_view_cached(&s, &mut cache).unwrap();
        assert_eq!(warm, mtl_view(&s).unwrap(), "step {step}");
    }
    assert!(cache.len() > n);
    s.model = BlockingChoice::Icb {
        p_u: Some(0.5329),
        p_los: None,
    };
    assert_eq!(
        mtl_view_cached(&s, &mut cache).unwrap(),
        mtl_view(&s).unwrap()
    );
    s.model = BlockingChoice::Ppp { exact: false };
    s.transmitters[0] = [1.5, 1.0];
    assert_eq!(
        mtl_view_cached(&s, &mut cache).unwrap(),
        mtl_view(&s).unwrap()
    );
    assert!(cache.len() < n + 2000 && !cache.is_empty());
}

/// Issue 12, item 2: the page's stuck scene (8 targets, clutter 10, cσ 2, `T_e` 6, `T_b` 30)
/// ran for minutes. The view has the CLI's work budget: past it a named error, within it the
/// same view as without a budget.
#[test]
fn the_view_has_the_work_budget() {
    let mut s = MtlScene::vb();
    let used = |v: &MtlView| -> usize {
        v.stages
            .iter()
            .map(|c| c.kept + c.blocking + c.inconsistent + c.unlocatable + c.duplicate + c.capped)
            .sum()
    };
    let free = mtl_view(&s).unwrap();
    let n = used(&free);
    assert!(n > 10, "{n}");
    s.max_candidates = Some(n);
    assert_eq!(mtl_view(&s).unwrap(), free);
    s.max_candidates = Some(n / 4);
    let e = mtl_view(&s).unwrap_err();
    assert!(
        matches!(&e, Error::WorkLimit { field, limit } if field == "ranges" && *limit == n / 4),
        "{e:?}"
    );
    s.max_candidates = Some(0);
    assert!(mtl_view(&s)
        .unwrap_err()
        .to_string()
        .starts_with("max_candidates:"));
    // The stuck scene, with a budget small enough for a debug test.
    let mut stuck = MtlScene::vb();
    stuck.targets = alloc::vec![
        [2.0, 2.0],
        [3.0, 6.0],
        [5.0, 5.0],
        [6.5, 2.5],
        [7.5, 7.5],
        [4.0, 8.5],
        [8.5, 4.5],
        [1.5, 4.0]
    ];
    stuck.discs.clear();
    stuck.clutter_mean = 10.0;
    stuck.range_sigma = 2.0;
    stuck.t_e = 6.0;
    stuck.t_b = 30.0;
    stuck.max_candidates = Some(20_000);
    let e = mtl_view(&stuck).unwrap_err();
    assert!(matches!(e, Error::WorkLimit { .. }), "{e:?}");
}

#[test]
#[ignore = "timing; run with --release --include-ignored --nocapture"]
fn timing() {
    let mut s = MtlScene::vb();
    let n = 20u32;
    let t0 = std::time::Instant::now();
    for _ in 0..n {
        mtl_view(&s).unwrap();
    }
    let cold = t0.elapsed() / n;
    let mut cache = ViewCache::default();
    mtl_view_cached(&s, &mut cache).unwrap();
    let t0 = std::time::Instant::now();
    for _ in 0..n {
        s.targets[1][0] -= 0.01;
        mtl_view_cached(&s, &mut cache).unwrap();
    }
    std::println!(
        "V-B default: cold {cold:?}, drag (warm cache) {:?}",
        t0.elapsed() / n
    );
}
