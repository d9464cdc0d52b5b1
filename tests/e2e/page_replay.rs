//! Issue 40 §3: the channel view's Replay — the opened recording fed frame by frame through the
//! core's live run (the chain of `cir track --follow`, in a worker), with real clicks:
//!
//! - the page's simulated walk (301 frames) replayed as fast as possible gives, at every frame
//!   where the live run has a state, the page's batch run's state and covariance (TRACK.json of
//!   Run on the same recording and settings) to 1e-9; the live run has no state only where the
//!   batch one has none, or between a segment's fix and its confirmation (the batch replays
//!   those; live reports them `searching`, docs/recording.md); each segment starts live at the
//!   batch segment's `confirmed_at`; every frame's object has the keys of the CLI's line; the
//!   map shows the last state and the track;
//! - Stop mid-way at 1×: no frame comes after it, the states so far are the first frames of the
//!   full replay (the same JSON text), and the view is usable (Run, then Replay again to the end).

use serde_json::Value;

use super::ui::{channel_state, click, select, wait_channel};
use super::{console_errors, js, open_hash, settle, with_browser};

/// The keys of a `cir track --follow` line (`study::LiveState`), in its order.
const LINE_KEYS: [&str; 10] = [
    "t_s",
    "state",
    "covariance",
    "segment",
    "links_used",
    "delays_s",
    "snapshot",
    "event",
    "end",
    "dropped_hypotheses",
];

/// Opens the channel view and simulates the page's walk (15 s at 50 ms, with its empty area).
async fn simulated(c: &fantoccini::Client, port: u16) -> Result<u64, String> {
    open_hash(c, port, "").await?;
    settle(c).await?;
    click(c, "mode-channel").await?;
    settle(c).await?;
    click(c, "chan-simulate").await?;
    let s = wait_channel(c, 300, "simulate", |s| {
        s["recording"].is_object() && s["running"].is_null()
    })
    .await?;
    Ok(s["recording"]["snapshots"].as_u64().unwrap_or(0))
}

/// Presses Replay at `speed` (the select's value) and returns the state once it started.
async fn start_replay(c: &fantoccini::Client, speed: &str, n: u64) -> Result<(), String> {
    select(c, "chan-replay-speed", speed).await?;
    click(c, "chan-replay").await?;
    wait_channel(c, 60, "replay started", |s| {
        s["replay"]["replays"] == n && s["replay"]["running"] == true
    })
    .await
    .map(|_| ())
}

/// Waits for the replay to end; its state.
async fn replay_end(c: &fantoccini::Client, secs: u64) -> Result<Value, String> {
    let s = wait_channel(c, secs, "replay", |s| {
        s["replay"].is_object() && s["replay"]["running"] == false
    })
    .await?;
    Ok(s)
}

/// The batch run's TRACK.json after Run number `n`.
async fn batch(c: &fantoccini::Client, n: u64) -> Result<Value, String> {
    click(c, "chan-run").await?;
    wait_channel(c, 600, "run", |s| s["runs"] == n && s["running"].is_null()).await?;
    let texts = js(c, "return window.channel.texts()").await?;
    serde_json::from_str(texts["track"].as_str().unwrap_or("null")).map_err(|e| e.to_string())
}

fn num(v: &Value) -> f64 {
    v.as_f64().unwrap_or(f64::NAN)
}

/// Largest |a − b| over two equal-shaped JSON arrays of numbers (nested); NaN on a shape or
/// null mismatch.
fn max_diff(a: &Value, b: &Value) -> f64 {
    match (a, b) {
        (Value::Array(x), Value::Array(y)) if x.len() == y.len() => x
            .iter()
            .zip(y)
            .map(|(p, q)| max_diff(p, q))
            .fold(0.0, |m, d| {
                if d.is_nan() || m.is_nan() {
                    f64::NAN
                } else {
                    m.max(d)
                }
            }),
        (Value::Number(_), Value::Number(_)) => (num(a) - num(b)).abs(),
        _ => f64::NAN,
    }
}

#[test]
#[ignore = "needs chromium + chromedriver and www/pkg (wasm-pack build); run with --ignored"]
fn replay_as_fast_as_possible_equals_the_batch_run() {
    let (frames, track, end, errors) = with_browser(async |c, port, _| {
        let frames = simulated(c, port).await?;
        let track = batch(c, 1).await?;
        start_replay(c, "0", 1).await?;
        let end = replay_end(c, 600).await?;
        settle(c).await?;
        let end = if end["replay"]["ended"] == "done" {
            channel_state(c).await?
        } else {
            end
        };
        Ok((frames, track, end, console_errors(c).await?))
    });
    assert!(errors.is_empty(), "console errors: {errors:?}");
    let rp = &end["replay"];
    assert_eq!(rp["ended"], "done", "{}", rp["error"]);
    assert_eq!(
        frames, 301,
        "the page's simulated walk: 0 … 15 s every 50 ms"
    );
    let states = rp["states"].as_array().unwrap();
    let lines = rp["lines"].as_array().unwrap();
    assert_eq!(states.len() as u64, frames);
    assert_eq!(rp["done"].as_u64(), Some(frames));

    let t = track["t_s"].as_array().unwrap();
    let bs = track["states"].as_array().unwrap();
    let bc = track["covariances"].as_array().unwrap();
    let segs = track["segments"].as_array().unwrap();
    assert_eq!(t.len() as u64, frames);
    // Snapshots the batch run replays after a segment's confirmation ([first, confirmed_at)).
    let before_confirmation = |k: usize| {
        segs.iter().any(|g| {
            let (f, c) = (
                g["first"].as_u64().unwrap(),
                g["confirmed_at"].as_u64().unwrap(),
            );
            (f..c).contains(&(k as u64))
        })
    };
    let (mut compared, mut worst_x, mut worst_p) = (0, 0.0f64, 0.0f64);
    let mut starts = Vec::new();
    for (k, s) in states.iter().enumerate() {
        // The CLI's line, key for key and in its order.
        let text = lines[k].as_str().unwrap();
        let keys: Vec<String> = serde_json::from_str::<serde_json::Map<String, Value>>(text)
            .unwrap()
            .keys()
            .cloned()
            .collect();
        let mut sorted = LINE_KEYS.map(String::from).to_vec();
        sorted.sort();
        let mut got = keys.clone();
        got.sort();
        assert_eq!(got, sorted, "frame {k}: {text}");
        assert!(text.starts_with("{\"t_s\":"), "frame {k}: {text}");
        assert_eq!(s["snapshot"].as_u64(), Some(k as u64));
        assert_eq!(num(&s["t_s"]), num(&t[k]), "frame {k}: time");
        assert_eq!(s["dropped_hypotheses"], 0);
        if s["event"] == "started" {
            starts.push(k as u64);
        }
        if s["state"].is_null() {
            assert!(
                bs[k].is_null() || before_confirmation(k),
                "frame {k}: no live state where the batch run has {} outside a confirmation",
                bs[k]
            );
            continue;
        }
        compared += 1;
        let dx = max_diff(&s["state"], &bs[k]);
        let dp = max_diff(&s["covariance"], &bc[k]);
        assert!(
            dx <= 1e-9,
            "frame {k}: state {} vs batch {} ({dx})",
            s["state"],
            bs[k]
        );
        assert!(dp <= 1e-9, "frame {k}: covariance differs by {dp}");
        worst_x = worst_x.max(dx);
        worst_p = worst_p.max(dp);
    }
    let confirmed: Vec<u64> = segs
        .iter()
        .map(|g| g["confirmed_at"].as_u64().unwrap())
        .collect();
    assert_eq!(
        starts, confirmed,
        "segments start live at the batch run's confirmations"
    );
    let batch_states = bs.iter().filter(|x| !x.is_null()).count();
    eprintln!(
        "replay: {frames} frames, {compared} states compared with the batch run's {batch_states} \
         (max |Δx| {worst_x:e}, max |ΔP| {worst_p:e}), {} segments, latency median {} ms, max {} \
         ms, push median {} ms, wall {} ms",
        segs.len(),
        rp["latencyMs"]["median"],
        rp["latencyMs"]["max"],
        rp["pushMs"]["median"],
        rp["wallMs"]
    );
    assert!(!segs.is_empty(), "the batch run tracked the walk");
    // Every batch state but those the batch run replays before a segment's confirmation.
    let replayed = (0..bs.len())
        .filter(|&k| !bs[k].is_null() && before_confirmation(k))
        .count();
    assert_eq!(
        compared,
        batch_states - replayed,
        "{compared} of {batch_states}"
    );
    assert!(compared > 200, "{compared}");
    // The map: the replay's last state and its segments.
    let last = states.last().unwrap();
    let drawn = &end["drawn"];
    if !last["state"].is_null() {
        assert_eq!(drawn["estimate"][0], last["state"][0], "{drawn}");
        assert_eq!(drawn["estimate"][1], last["state"][1], "{drawn}");
        assert!(drawn["sigma"].is_object(), "{drawn}");
    }
    let with_state = states.iter().filter(|s| !s["state"].is_null()).count() as u64;
    assert_eq!(drawn["track_points"].as_u64(), Some(with_state), "{drawn}");
    assert!(rp["latencyMs"]["median"].is_number() && rp["pushMs"]["max"].is_number());
}

#[test]
#[ignore = "needs chromium + chromedriver and www/pkg (wasm-pack build); run with --ignored"]
fn replay_stop_cancels_and_leaves_the_view_usable() {
    let (stopped, later, buttons, full, errors) = with_browser(async |c, port, _| {
        simulated(c, port).await?;
        // 1×: 15 s of frames; stopped after 20 of them.
        start_replay(c, "1", 1).await?;
        wait_channel(c, 60, "20 frames", |s| {
            s["replay"]["done"].as_u64() >= Some(20)
        })
        .await?;
        click(c, "chan-stop").await?;
        let stopped = replay_end(c, 10).await?;
        // Frames still in flight when Stop was pressed are not taken.
        tokio::time::sleep(std::time::Duration::from_millis(600)).await;
        let later = channel_state(c).await?;
        let buttons = js(
            c,
            "return ['chan-run', 'chan-replay', 'chan-stop', 'chan-simulate'].map((id) => \
             document.getElementById(id).disabled)",
        )
        .await?;
        // Usable: Run to the end, then Replay again to the end.
        let track = batch(c, 1).await?;
        start_replay(c, "0", 2).await?;
        let full = replay_end(c, 600).await?;
        Ok((
            stopped,
            later,
            buttons,
            (track, full),
            console_errors(c).await?,
        ))
    });
    assert!(errors.is_empty(), "console errors: {errors:?}");
    let rp = &stopped["replay"];
    assert_eq!(rp["ended"], "stopped");
    let n = rp["done"].as_u64().unwrap();
    assert!((20..301).contains(&n), "stopped after {n} frames");
    assert_eq!(
        later["replay"]["done"].as_u64(),
        Some(n),
        "no frame after Stop"
    );
    assert_eq!(later["replay"]["running"], false);
    assert_eq!(later["stopped"], 1);
    assert!(later["running"].is_null());
    assert_eq!(
        buttons,
        serde_json::json!([false, false, true, false]),
        "Run, Replay, Stop, Simulate"
    );
    let (track, full) = full;
    let f = &full["replay"];
    assert_eq!(f["ended"], "done", "{}", f["error"]);
    assert_eq!(f["done"].as_u64(), Some(301));
    assert_eq!(track["t_s"].as_array().unwrap().len(), 301);
    // The stopped replay's frames are the full replay's first ones, to the byte.
    let a = rp["lines"].as_array().unwrap();
    let b = f["lines"].as_array().unwrap();
    assert_eq!(a.len() as u64, n);
    assert_eq!(a[..], b[..a.len()]);
}
