//! C11 on synthetic delay lists: a walker's delays with noise among clutter start a track within
//! `confirm_n` snapshots of the first, a gap in the echo ends it (misses) and the search starts
//! it again, a walker leaving the area ends it (outside_area), a single-snapshot ghost is never
//! confirmed, and the settings' errors are named.

use alloc::vec;
use alloc::vec::Vec;

use rand_distr::{Distribution, StandardNormal, Uniform};

use super::loss::outside;
use super::*;
use crate::math::{sqrt, Real, Vec2, Vec4, SPEED_OF_LIGHT};
use crate::measure::{rng, Model};
use crate::scenario::{presets, Area};
use crate::track::gating::{AssociationRule, Calibration, DelayEstimate, LinkCalibration};
use crate::track::FilterKind;

const DT: Real = 0.1;

struct Walk {
    model: Model,
    area: Area,
    cal: Calibration,
}

fn walk() -> Walk {
    let s = presets::preset("sensors2019").unwrap();
    let model = Model::new(&s).unwrap();
    let cal = Calibration {
        links: vec![LinkCalibration::default(); model.link_count()],
    };
    Walk {
        model,
        area: s.area_m,
        cal,
    }
}

/// Position at time `t`: a 1.4 m/s walk along +x from (2, 4).
fn truth(t: Real) -> Vec2 {
    Vec2::new(2.0 + 1.4 * t, 4.0)
}

/// Snapshot `k`: the echo (noise σ 0.1 m of path length) on every link unless `gap(k)`, plus
/// two clutter delays per link uniform over 0 … 200 ns; each with the σ the channel chain
/// gives (the estimator's widened by a person's 0.2 m extent in quadrature).
fn snapshots(
    w: &Walk,
    count: usize,
    seed: u64,
    pos: &dyn Fn(Real) -> Vec2,
    gap: &dyn Fn(usize) -> bool,
) -> Vec<Vec<Vec<DelayEstimate>>> {
    let mut r = rng(seed, 7);
    let sigma = 0.1 / SPEED_OF_LIGHT;
    let given = sqrt(0.1 * 0.1 + 0.2 * 0.2) / SPEED_OF_LIGHT;
    (0..count)
        .map(|k| {
            let d = w.model.network.delays(pos(k as Real * DT));
            d.iter()
                .map(|&tau| {
                    let mut l = Vec::new();
                    if !gap(k) {
                        let e: Real = StandardNormal.sample(&mut r);
                        l.push(DelayEstimate {
                            delay_s: tau + sigma * e,
                            amplitude: 1.0,
                            sigma_s: Some(given),
                        });
                    }
                    for _ in 0..2 {
                        l.push(DelayEstimate {
                            delay_s: Uniform::new(1e-9, 200e-9).unwrap().sample(&mut r),
                            amplitude: 0.5,
                            sigma_s: Some(given),
                        });
                    }
                    l
                })
                .collect()
        })
        .collect()
}

fn setup(w: &Walk) -> SegmentSetup<'_> {
    SegmentSetup {
        model: &w.model,
        calibration: &w.cal,
        area: &w.area,
        kind: FilterKind::Ekf,
        process_noise: 1.0,
        rule: AssociationRule::Gated,
        estimate_sigmas: true,
        gate_sigma_s: Some(0.2 / SPEED_OF_LIGHT),
        segments: SegmentConfig::default(),
    }
}

/// Runs every snapshot; per snapshot the state (None outside segments) and the segments
/// `(first, last, reason)`.
#[allow(clippy::type_complexity)]
fn run(
    w: &Walk,
    snaps: &[Vec<Vec<DelayEstimate>>],
) -> (Vec<Option<Vec4>>, Vec<(usize, usize, Option<EndReason>)>) {
    let mut t = SegmentTracker::searching(setup(w), rng(1, 0)).unwrap();
    let replay = |j: usize| Ok((j as Real * DT, snaps[j].clone()));
    let mut states = vec![None; snaps.len()];
    let mut segs: Vec<(usize, usize, Option<EndReason>)> = Vec::new();
    for (k, s) in snaps.iter().enumerate() {
        match t.step(k, k as Real * DT, s, &replay).unwrap() {
            SegmentEvent::Searching { hypotheses } => {
                assert!(hypotheses <= SegmentConfig::default().max_hypotheses)
            }
            SegmentEvent::Started { start, steps } => {
                assert_eq!(steps[0].k, start.k);
                assert_eq!(steps.last().unwrap().k, k);
                for st in &steps {
                    states[st.k] = Some(st.state);
                }
                segs.push((start.k, k, None));
            }
            SegmentEvent::Tracked(st) => {
                states[k] = Some(st.state);
                segs.last_mut().unwrap().1 = k;
            }
            SegmentEvent::Lost(r) => {
                let last = segs.last_mut().unwrap();
                last.2 = Some(r);
            }
        }
    }
    (states, segs)
}

fn error(s: &Vec4, p: Vec2) -> Real {
    sqrt((s[0] - p.x) * (s[0] - p.x) + (s[1] - p.y) * (s[1] - p.y))
}

#[test]
fn starts_from_the_first_snapshots_among_clutter_and_holds() {
    let w = walk();
    for seed in [1u64, 2, 3] {
        let snaps = snapshots(&w, 100, seed, &truth, &|_| false);
        let (states, segs) = run(&w, &snaps);
        assert_eq!(segs.len(), 1, "seed {seed}: {segs:?}");
        // The first fix is at snapshot 0 and confirmed M snapshots later.
        assert_eq!(segs[0].0, 0, "seed {seed}");
        assert_eq!(segs[0].2, None);
        let worst = states
            .iter()
            .enumerate()
            .filter_map(|(k, s)| s.map(|s| error(&s, truth(k as Real * DT))))
            .fold(0.0, Real::max);
        assert!(worst < 0.5, "seed {seed}: worst error {worst} m");
    }
}

/// The echo vanishes for 2 s (twice `miss_time_s`): the track ends before the echo returns, by
/// `misses` (≥ 1 s after the echo's last snapshot; later when clutter falls in two links'
/// gates at once) or `innovation`, and a new segment starts within `confirm_n` snapshots of
/// the echo's return.
#[test]
fn a_gap_ends_the_segment_and_the_search_restarts() {
    let w = walk();
    let gap = |k: usize| (40..60).contains(&k);
    for seed in [4u64, 5, 6] {
        let snaps = snapshots(&w, 120, seed, &truth, &gap);
        let (states, segs) = run(&w, &snaps);
        assert_eq!(segs.len(), 2, "seed {seed}: {segs:?}");
        std::println!("seed {seed}: {segs:?}");
        assert!(
            matches!(segs[0].2, Some(EndReason::Misses | EndReason::Innovation)),
            "seed {seed}: {segs:?}"
        );
        assert!((40..60).contains(&segs[0].1), "seed {seed}: {segs:?}");
        assert!(segs[1].0 >= 51 && segs[1].1 == 119, "seed {seed}: {segs:?}");
        assert!(
            segs[1].0 <= 60 + SegmentConfig::default().confirm_n,
            "{segs:?}"
        );
        for (k, state) in states
            .iter()
            .enumerate()
            .take(segs[1].0)
            .skip(segs[0].1 + 1)
        {
            assert!(
                state.is_none(),
                "seed {seed}: a state at {k} between segments"
            );
        }
    }
}

/// A walker heading out of the area: the segment ends `outside_area` and no state is ever
/// reported more than the margin outside.
#[test]
fn leaving_the_area_ends_the_segment() {
    let w = walk();
    // From (26, 4) towards +x at 1.4 m/s: out of x ≤ 30 after ≈ 2.9 s, past the margin at 4.3 s.
    let pos = |t: Real| Vec2::new(26.0 + 1.4 * t, 4.0);
    let snaps = snapshots(&w, 80, 7, &pos, &|_| false);
    let (states, segs) = run(&w, &snaps);
    assert!(!segs.is_empty());
    assert_eq!(segs[0].2, Some(EndReason::OutsideArea), "{segs:?}");
    let margin = SegmentConfig::default().area_margin_m;
    for s in states.iter().flatten() {
        assert!(!outside(&w.area, margin, s), "{s:?}");
    }
}

/// One snapshot with a consistent ghost (the delays of a point 8 m away on every link), then
/// only clutter: never confirmed.
#[test]
fn a_one_snapshot_ghost_is_never_confirmed() {
    let w = walk();
    let ghost = |_t: Real| Vec2::new(10.0, 12.0);
    let mut snaps = snapshots(&w, 30, 8, &ghost, &|k| k > 0);
    // Clutter only after the first snapshot.
    let (states, segs) = run(&w, &snaps);
    assert!(segs.is_empty(), "{segs:?}");
    assert!(states.iter().all(Option::is_none));
    // The same ghost held still for 30 snapshots is a (static) target: confirmed.
    snaps = snapshots(&w, 30, 8, &ghost, &|_| false);
    let (_, segs) = run(&w, &snaps);
    assert_eq!(segs.len(), 1);
}

#[test]
fn settings_errors_are_named() {
    let bad = |c: SegmentConfig| c.validate().unwrap_err().to_string();
    let d = SegmentConfig::default();
    assert!(bad(SegmentConfig { confirm_m: 11, ..d }).starts_with("segments.confirm_m"));
    assert!(bad(SegmentConfig { min_links: 2, ..d }).starts_with("segments.min_links"));
    assert!(bad(SegmentConfig {
        miss_time_s: 0.0,
        ..d
    })
    .starts_with("segments.miss_time_s"));
    assert!(bad(SegmentConfig {
        fix_tail_probability: 1.0,
        ..d
    })
    .starts_with("segments.fix_tail_probability"));
    assert!(bad(SegmentConfig {
        grid_step_m: Real::NAN,
        ..d
    })
    .starts_with("segments.grid_step_m"));
    // Times must increase.
    let w = walk();
    let mut t = SegmentTracker::searching(setup(&w), rng(1, 0)).unwrap();
    let s = vec![Vec::new(); 4];
    let replay = |_: usize| Ok((0.0, vec![Vec::new(); 4]));
    t.step(0, 1.0, &s, &replay).unwrap();
    assert!(t.step(1, 1.0, &s, &replay).is_err());
}

/// The most extreme valid input a held track can get — at snapshot 40 the echo alone on every
/// link with σ = 10⁻¹⁵ s (the smallest `DELAY_SIGMA_S` allows), one fifth of a millimetre —
/// ends the segment there (by `innovation`, or by `filter` had the filter failed numerically:
/// none of EKF, UKF and PF does on this input, measured), never the run, and the search starts
/// a new segment after it, for each filter.
#[test]
fn an_extreme_update_ends_the_segment_not_the_run() {
    let w = walk();
    let mut snaps = snapshots(&w, 90, 11, &truth, &|_| false);
    for l in snaps[40].iter_mut() {
        l.truncate(1);
        l[0].sigma_s = Some(1e-15);
    }
    for kind in [
        FilterKind::Ekf,
        FilterKind::Ukf(crate::track::UkfParams::default()),
        FilterKind::Pf(crate::track::PfConfig::default()),
    ] {
        let name = kind.name();
        let mut t =
            SegmentTracker::searching(SegmentSetup { kind, ..setup(&w) }, rng(1, 0)).unwrap();
        let replay = |j: usize| Ok((j as Real * DT, snaps[j].clone()));
        let mut events = Vec::new();
        for (k, s) in snaps.iter().enumerate() {
            match t.step(k, k as Real * DT, s, &replay).unwrap() {
                SegmentEvent::Started { start, .. } => events.push((start.k, "started")),
                SegmentEvent::Lost(r) => events.push((k, r.name())),
                _ => {}
            }
        }
        assert!(events.len() >= 3, "{name}: {events:?}");
        assert!(
            events[0].1 == "started" && events[0].0 < 15,
            "{name}: {events:?}"
        );
        assert!(
            events[1].0 == 40 && matches!(events[1].1, "innovation" | "filter"),
            "{name}: {events:?}"
        );
        assert!(
            events[2].1 == "started" && events[2].0 > 40,
            "{name}: {events:?}"
        );
    }
}
