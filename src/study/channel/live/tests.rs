//! The live run against the batch run (`estimate_recording` + `cir_track`) on simulated walks.

use alloc::vec::Vec;

use super::*;
use crate::channel::{rounded_to_f32, simulate_recording, ChannelScene};
use crate::scenario::presets;
use crate::study::channel::{cir_track, estimate_recording};
use crate::study::Sequential;

/// Snapshot `k`'s samples, link-major (a frame's).
fn block(rec: &Recording, k: usize) -> &[Complex] {
    let per = rec.links.len() * rec.samples_per_link();
    &rec.samples[k * per..(k + 1) * per]
}

/// Every frame of a simulated walk (its samples rounded to `f32`, as a stream carries them) fed
/// to a live run gives, at every snapshot where the live run reports a state, the batch run's
/// state, covariance and delays to the bit; where it reports none, the batch run has none either
/// or has one replayed later (a segment's snapshots between its fix and its confirmation); a
/// segment starts live exactly at the batch segment's `confirmed_at`. Three seeds, with and
/// without receivers on a common clock (`los` delays: the background's direct path, C10).
#[test]
fn live_equals_batch_on_simulated_walks() {
    let scenario = presets::preset("sensors2019").unwrap();
    let model = Model::new(&scenario).unwrap();
    let bw = scenario.radio.bandwidth_hz;
    let mut compared = 0;
    let mut started = 0;
    for seed in 1..=3u64 {
        let mut scene = ChannelScene::hangar();
        scene.duration_s = Some(2.4);
        scene.dt_s = 0.02;
        let (walk, _) = simulate_recording(&scenario, &model, &scene, true, seed).unwrap();
        let mut rec = rounded_to_f32(&walk);
        if seed == 3 {
            rec.synchronized = Some(false);
        }
        let req = ChannelRequest::default();
        let cfg = req.front_end(rec.synchronized);
        let (statics, est) = estimate_recording(
            &model,
            bw,
            &rec,
            None,
            &cfg,
            &mut Sequential::new(),
            &|_| {},
        )
        .unwrap();
        let batch = cir_track(
            &req,
            &model,
            &scenario.area_m,
            &statics.calibration,
            &est,
            Cancel::NEVER,
        )
        .unwrap();

        let header = FrameHeader::of_recording(&rec).unwrap();
        let (live_statics, front) =
            LiveFront::new(&model, bw, &header, rec.t_s[0], block(&rec, 0), None, &cfg).unwrap();
        assert_eq!(live_statics, statics, "seed {seed}: statics");
        let mut run = LiveRun::new(&req, &model, &scenario.area_m, &live_statics, front).unwrap();
        let confirmed: Vec<usize> = batch.segments.iter().map(|s| s.confirmed_at).collect();
        let mut seen_starts = Vec::new();
        for k in 0..rec.t_s.len() {
            let out = run.push(rec.t_s[k], block(&rec, k)).unwrap();
            assert_eq!(out.snapshot, k);
            assert_eq!(out.dropped_hypotheses, 0);
            assert!(run.replay_window() <= LIVE_REPLAY_SNAPSHOTS);
            if out.event == "started" {
                seen_starts.push(k);
            }
            match out.state {
                Some(x) => {
                    compared += 1;
                    assert_eq!(Some(x), batch.states[k], "seed {seed}, snapshot {k}");
                    assert_eq!(out.covariance, batch.covariances[k], "seed {seed}, {k}");
                    assert_eq!(out.delays_s, batch.delays_used_s[k], "seed {seed}, {k}");
                    assert_eq!(
                        out.links_used.len(),
                        batch.links_used[k],
                        "seed {seed}, {k}"
                    );
                }
                None => {
                    // Batch has a state here only inside a segment confirmed later.
                    if batch.states[k].is_some() {
                        assert!(
                            batch
                                .segments
                                .iter()
                                .any(|s| s.first <= k && k < s.confirmed_at),
                            "seed {seed}, snapshot {k}: batch state, live none"
                        );
                    }
                }
            }
        }
        assert_eq!(seen_starts, confirmed, "seed {seed}: segment starts");
        started += seen_starts.len();
    }
    // The comparison is not empty: tracks started and states compared.
    assert!(started >= 3, "{started} segments");
    assert!(compared > 150, "{compared} states compared");
}

/// A frame whose time does not increase, or of the wrong size, is refused naming the frame;
/// the run goes on with the next good frame.
#[test]
fn bad_frames_name_the_frame() {
    let scenario = presets::preset("sensors2019").unwrap();
    let model = Model::new(&scenario).unwrap();
    let mut scene = ChannelScene::hangar();
    scene.duration_s = Some(0.1);
    scene.dt_s = 0.02;
    let (rec, _) = simulate_recording(&scenario, &model, &scene, true, 1).unwrap();
    let req = ChannelRequest::default();
    let cfg = req.front_end(rec.synchronized);
    let header = FrameHeader::of_recording(&rec).unwrap();
    let bw = scenario.radio.bandwidth_hz;
    let (st, front) =
        LiveFront::new(&model, bw, &header, rec.t_s[0], block(&rec, 0), None, &cfg).unwrap();
    let mut run = LiveRun::new(&req, &model, &scenario.area_m, &st, front).unwrap();
    run.push(rec.t_s[0], block(&rec, 0)).unwrap();
    let e = run.push(rec.t_s[0], block(&rec, 1)).unwrap_err();
    assert_eq!(e.field(), Some("frames[1]"), "{e}");
    let e = run.push(rec.t_s[1], &block(&rec, 1)[1..]).unwrap_err();
    assert!(e.to_string().starts_with("frames[1]: "), "{e}");
    let out = run.push(rec.t_s[1], block(&rec, 1)).unwrap();
    assert_eq!(out.snapshot, 1);
}
