//! The page's Replay binding (issue 40 §3): `ChannelReplay.push(k)` returns, frame by frame,
//! exactly the JSON line `cir track --follow` writes — the library's own live run
//! (`LiveFront`, `LiveRun`, `LiveState::to_json`) on the same recording, text for text — and
//! its states are the page's batch run's (`ChannelJob`'s TRACK.json) bit for bit wherever the
//! live run has one; frames out of order and past the end are named errors.

use js_sys::Uint8Array;
use serde_json::{json, Value};
use wasm_bindgen_test::*;

use scatterloc::channel::FrameHeader;
use scatterloc::scenario::presets;
use scatterloc::study::{ChannelRequest, LiveFront, LiveRun};
use scatterloc::wasm::{self, ChannelJob, ChannelReplay};
use scatterloc::{Model, Scenario};

use super::{err, get, ok};

#[wasm_bindgen_test]
fn replay_is_the_live_run_and_equals_the_batch_run() {
    let s = presets::sensors2019().to_json();
    let sim = json!({ "duration_s": 4.0, "dt_s": 0.05, "calibration_duration_s": 0.4 });
    let sim = ok(wasm::simulate_channel(&s, &sim.to_string()));
    let (rec, cal) = (sim.recording(), sim.calibration());
    let (recb, calb) = (
        Uint8Array::from(rec.as_slice()),
        Uint8Array::from(cal.as_slice()),
    );

    // The batch run of the page.
    let mut job = ok(ChannelJob::new(&s, &recb, Some(calb.clone()), None, ""));
    for _ in 0..100_000 {
        if get(&ok(job.step(50.0)), "finished").as_bool() == Some(true) {
            break;
        }
    }
    let track: Value = serde_json::from_str(&ok(job.track_json())).unwrap();

    // The library's live run on the same files and the default settings.
    let scenario = Scenario::from_json(&s).unwrap();
    let model = Model::new(&scenario).unwrap();
    let r = scatterloc::npz::read_recording(&rec).unwrap();
    let empty = scatterloc::npz::read_recording(&cal).unwrap();
    let req = ChannelRequest::default();
    let cfg = req.front_end(r.synchronized);
    let header = FrameHeader::of_recording(&r).unwrap();
    let per = r.links.len() * r.samples_per_link();
    let frame = |k: usize| &r.samples[k * per..(k + 1) * per];
    let bw = scenario.radio.bandwidth_hz;
    let (statics, front) =
        LiveFront::new(&model, bw, &header, r.t_s[0], frame(0), Some(&empty), &cfg).unwrap();
    let mut live = LiveRun::new(&req, &model, &scenario.area_m, &statics, front).unwrap();

    let mut replay = ok(ChannelReplay::new(&s, &recb, Some(calb), ""));
    let n = replay.frames();
    assert_eq!(n, r.t_s.len());
    assert_eq!(n, 81, "4 s at 50 ms");
    let m = err(replay.push(1));
    assert!(m.starts_with("replay"), "{m}");
    let (mut compared, mut started) = (0, 0);
    for k in 0..n {
        let line = ok(replay.push(k));
        let want = live.push(r.t_s[k], frame(k)).unwrap().to_json().unwrap();
        assert_eq!(line, want, "frame {k}");
        let v: Value = serde_json::from_str(&line).unwrap();
        started += usize::from(v["event"] == "started");
        if !v["state"].is_null() {
            compared += 1;
            assert_eq!(v["state"], track["states"][k], "frame {k}");
            assert_eq!(v["covariance"], track["covariances"][k], "frame {k}");
        }
        assert!(!ok(replay.overlay()).is_null());
    }
    assert_eq!(replay.pushed(), n);
    let m = err(replay.push(n));
    assert!(m.starts_with("replay"), "{m}");
    let segments = track["segments"].as_array().unwrap();
    assert_eq!(started, segments.len());
    assert!(compared > 20, "{compared} states compared");
}
