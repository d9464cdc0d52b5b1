//! Further walkers ([`ChannelScene::others`], issue 41): the main walker's recording is
//! untouched by them (superposition, its own rng stream), each adds its own paths whose truth
//! delays are the model's bistatic delays at its position, shadows a LoS it stands on by its
//! body's loss, makes the recording as long as the longest walk; bad walkers are named errors;
//! a scene and a truth without them serialise as before.

use alloc::string::ToString;
use alloc::vec;
use alloc::vec::Vec;

use super::scene::{Walker, MAX_OTHER_WALKERS};
use super::synthesize::synthesize_all;
use super::walkers::movers;
use super::*;
use crate::error::{Cancel, Error};
use crate::math::{db_to_linear, Complex, Real, Vec2};
use crate::measure::Model;
use crate::scenario::presets::sensors2019;
use crate::scenario::Scenario;

fn setup() -> (Scenario, Model) {
    let sc = sensors2019();
    let m = Model::new(&sc).unwrap();
    (sc, m)
}

/// No walls or scatterers, the main walker from (2, −3) east for 12 snapshots.
fn scene() -> ChannelScene {
    let mut s = ChannelScene::hangar();
    s.walls.clear();
    s.scatterers.clear();
    s.walk = Walk {
        waypoints_m: vec![[2.0, -3.0], [16.0, -3.0]],
        speed_mps: 1.4,
        turn_radius_m: 0.0,
    };
    s.duration_s = Some(11.0 * DEFAULT_DT_S);
    s
}

/// A walker standing (1 cm walk at 1 mm/s) at `at`.
fn standing(at: [f64; 2]) -> Walker {
    Walker {
        body: Body::default(),
        walk: Walk {
            waypoints_m: vec![at, [at[0] + 0.01, at[1]]],
            speed_mps: 1e-3,
            turn_radius_m: 0.0,
        },
    }
}

/// A further walker far from every LoS (no shadowing): the recording without noise is the one
/// without it plus, exactly up to rounding, its own paths with its own fluctuations (the
/// `walkers::Mover` of index 1 replayed); the main walker's truth is unchanged and the
/// further walker's Body paths lie at the model's bistatic delay of its position.
#[test]
#[allow(clippy::needless_range_loop)] // `s` indexes the truth, the states and the samples
fn a_further_walker_adds_its_own_paths_only() {
    let (sc, m) = setup();
    let alone = scene();
    let mut two = scene();
    two.others.push(standing([20.0, 2.0]));
    let (r1, t1, o1) = synthesize_all(&sc, &m, &alone, true, 5, false, Cancel::NEVER).unwrap();
    let (r2, t2, o2) = synthesize_all(&sc, &m, &two, true, 5, false, Cancel::NEVER).unwrap();
    assert!(o1.is_empty());
    assert_eq!(o2.len(), 1);
    assert_eq!(o2[0].len(), t2.t_s.len());
    assert_eq!(t1.states, t2.states);
    assert_eq!(t1.shadowed, t2.shadowed);
    // Replay the further walker alone.
    let links = m.link_count();
    let n = alone.subcarriers;
    let mut walkers = movers(&two, links, sc.target.rcs_m2, 5).unwrap();
    let fc = sc.radio.carrier_hz;
    let df = sc.radio.bandwidth_hz / n as Real;
    let f0 = -((n - 1) as Real) * 0.5 * df;
    let lambda = crate::math::SPEED_OF_LIGHT / fc;
    let mut scratch = Vec::new();
    let mut worst: Real = 0.0;
    let mut scale: Real = 0.0;
    for s in 0..t2.t_s.len() {
        for w in walkers.iter_mut() {
            w.draw(s, None);
        }
        let t = t2.t_s[s];
        let at = walkers[1].path.state_and_heading(t);
        assert_eq!(at.0, o2[0][s]);
        for p in 0..links {
            let l = &m.network.links[p];
            let lb = super::rays::LinkBudget {
                tx: m.network.transmitters[l.tx],
                rx: m.network.receivers[l.rx],
                dz_tx: m.network.transmitters_dz[l.tx],
                dz_rx: m.network.receivers_dz[l.rx],
                pattern: &m.patterns[l.tx],
                ptx_grx: crate::math::dbm_to_watt(sc.transmitters[l.tx].power_dbm)
                    * db_to_linear(sc.receivers[l.rx].gain_dbi),
                lambda,
            };
            let mut h = vec![Complex::new(0.0, 0.0); n];
            let mut truth = Vec::new();
            walkers[1].add(
                &lb,
                &[],
                at,
                t,
                p,
                sc.target.rcs_m2,
                true,
                [fc, f0, df],
                &mut h,
                &mut truth,
                &mut scratch,
            );
            let base = (s * links + p) * n;
            for (i, hi) in h.iter().enumerate() {
                let d = r2.samples[base + i] - r1.samples[base + i] - *hi;
                worst = worst.max(d.norm());
                scale = scale.max(r1.samples[base + i].norm());
            }
            // The truth: the main walker's paths, then the further walker's.
            let k = t1.paths[s][p].len();
            assert_eq!(t2.paths[s][p][..k], t1.paths[s][p][..]);
            assert_eq!(t2.paths[s][p][k..], truth[..]);
            let body = truth.iter().find(|x| x.kind == PathKind::Body).unwrap();
            let want = m.network.delay(p, Vec2::new(at.0[0], at.0[1]));
            assert!(
                (body.delay_s - want).abs() < 1e-18,
                "{} vs {want}",
                body.delay_s
            );
        }
    }
    assert!(worst > 0.0 || scale == 0.0);
    assert!(worst <= 1e-12 * scale, "{worst} against {scale}");
    assert!(
        r2.samples != r1.samples,
        "the further walker is in the recording"
    );
}

/// A further walker standing on link 1's LoS (Tx (0, 0) → Rx (10, 10)) shadows it by its body's
/// loss (15 dB), and the truth says so; the main walker, 3 m south of it, does not.
#[test]
fn a_further_walker_shadows_the_los_it_stands_on() {
    let (sc, m) = setup();
    let alone = scene();
    let mut two = scene();
    two.others.push(standing([5.0, 5.0]));
    let (_, t1, _) = synthesize_all(&sc, &m, &alone, true, 1, false, Cancel::NEVER).unwrap();
    let (_, t2, _) = synthesize_all(&sc, &m, &two, true, 1, false, Cancel::NEVER).unwrap();
    for s in 0..t1.t_s.len() {
        assert!(!t1.shadowed[s][1] && t2.shadowed[s][1]);
        let (a, b) = (&t1.paths[s][1][0], &t2.paths[s][1][0]);
        assert_eq!((a.kind, b.kind), (PathKind::Los, PathKind::Los));
        let ratio = b.power_w / a.power_w;
        assert!((ratio / db_to_linear(-15.0) - 1.0).abs() < 1e-12, "{ratio}");
    }
}

/// Without a duration the recording lasts the longest walk; the main walker waits at its end.
#[test]
fn the_recording_lasts_the_longest_walk() {
    let (sc, m) = setup();
    let mut s = scene();
    s.duration_s = None;
    s.dt_s = 0.5;
    s.walk.waypoints_m = vec![[2.0, -3.0], [4.8, -3.0]]; // 2 s
    s.others.push(Walker {
        body: Body::default(),
        walk: Walk {
            waypoints_m: vec![[20.0, 2.0], [20.0, 7.6]], // 4 s
            speed_mps: 1.4,
            turn_radius_m: 0.0,
        },
    });
    let (rec, truth, others) = synthesize_all(&sc, &m, &s, true, 1, false, Cancel::NEVER).unwrap();
    assert_eq!(rec.t_s.len(), 9);
    assert_eq!(truth.states[8], [4.8, -3.0, 0.0, 0.0]);
    let end = others[0][8];
    assert!(
        (end[0] - 20.0).abs() < 1e-9 && (end[1] - 7.6).abs() < 1e-9,
        "{end:?}"
    );
    // The empty area has neither walker.
    let (_, empty, none) = synthesize_all(&sc, &m, &s, false, 1, false, Cancel::NEVER).unwrap();
    assert!(empty.states.is_empty() && none.is_empty());
}

/// Bad further walkers are named errors.
#[test]
fn bad_further_walkers_are_named() {
    let name = |s: &ChannelScene| s.validate().unwrap_err().field().unwrap_or("").to_string();
    let mut s = scene();
    s.others = vec![standing([1.0, 1.0]); MAX_OTHER_WALKERS + 1];
    assert!(matches!(
        s.validate(),
        Err(Error::SizeLimit {
            field: "scene.others",
            ..
        })
    ));
    s.others.truncate(2);
    s.validate().unwrap();
    s.others[1].body.correlation = 1.5;
    assert_eq!(name(&s), "scene.others[1].body.correlation");
    s.others[1].body = Body::default();
    s.others[1].body.centres = 0;
    assert_eq!(name(&s), "scene.others[1].body.centres");
    s.others[1].body = Body::default();
    s.others[0].walk.speed_mps = -1.0;
    assert_eq!(name(&s), "scene.others[0].walk.speed_mps");
    s.others[0].walk.speed_mps = 1.0;
    s.others[0].walk.waypoints_m.truncate(1);
    assert_eq!(name(&s), "scene.others[0].walk.waypoints_m");
    let bad = serde_json::from_str::<ChannelScene>(
        r#"{"walk": {"waypoints_m": [[0,0],[1,1]], "speed_mps": 1},
            "others": [{"walk": {"waypoints_m": [[0,0],[1,1]], "speed_mps": 1}, "legs": 2}]}"#,
    );
    assert!(bad.unwrap_err().to_string().contains("legs"));
}

/// A scene and a truth without further walkers serialise without `others` (the files of one
/// walker are as before); with them, `others` round-trips.
#[test]
fn files_without_further_walkers_are_unchanged() {
    let (sc, m) = setup();
    let s = scene();
    let text = serde_json::to_string(&s).unwrap();
    assert!(!text.contains("others"));
    let req = SimulationRequest {
        scene: Some(s.clone()),
        calibration_duration_s: 0.004,
        ..SimulationRequest::default()
    };
    let sim = req.run(&sc, &m, Cancel::NEVER).unwrap();
    assert_eq!(
        serde_json::to_string(&sim.truth_file()).unwrap(),
        serde_json::to_string(&sim.truth).unwrap()
    );
    let mut two = s;
    two.others.push(standing([20.0, 2.0]));
    let back: ChannelScene = serde_json::from_str(&serde_json::to_string(&two).unwrap()).unwrap();
    assert_eq!(back, two);
    let sim = SimulationRequest {
        scene: Some(two),
        calibration_duration_s: 0.004,
        ..SimulationRequest::default()
    }
    .run(&sc, &m, Cancel::NEVER)
    .unwrap();
    let file = sim.truth_file();
    let back: SimulationTruth =
        serde_json::from_str(&serde_json::to_string(&file).unwrap()).unwrap();
    assert_eq!(back, file);
    assert_eq!(back.others.len(), 1);
}
