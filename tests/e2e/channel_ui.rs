//! Issue 26 §1, the channel view's controls with real input: the view opened from the top bar,
//! a malformed recording chosen through the file input (chromedriver types the file's path, as
//! a user picks it) is named in the banner with the core reader's own message, a malformed
//! number is named, "Simulate walk" makes a recording of the current scenario, Run estimates
//! and tracks it in the worker and Stop cancels a run (nothing replaces the result), the time
//! cursor moved with the keyboard on its range input shows on the map exactly the track's state,
//! the links used and the truth of that snapshot (TRACK.json and truth.json, the page's own
//! result texts), its line moves right on both charts, the save buttons produce the delay
//! figure (SVG, PNG) and the track file (the TRACK.json text plus the newline the CLI writes),
//! and the settings hook round-trips and refuses a bad value by name.
//!
//! Issue 36: a recording of a walk that leaves the area and comes back (simulated by the CLI),
//! opened through the file inputs without an empty area's recording, is tracked with the
//! background learnt from the recording (the CLI's `cir track` without `--calibration`, number
//! for number) in two segments; the status line names them and the loss's reason, the error
//! chart marks the gap and the loss, and in the gap the map draws no position and the first
//! segment alone.

use std::time::{Duration, Instant};

use fantoccini::{Client, Locator};
use serde_json::{json, Value};

use super::ui::{banner, channel_state, click, keys, wait_banner, wait_channel, END, HOME, RIGHT};
use super::{console_errors, js, open_hash, settle, with_browser};

const PNG_SIGNATURE: [u8; 8] = [0x89, b'P', b'N', b'G', 0x0d, 0x0a, 0x1a, 0x0a];

async fn dismiss(c: &Client) -> Result<(), String> {
    js(c, "document.getElementById('error-close').click()")
        .await
        .map(|_| ())
}

/// Chooses `what` in #chan-save-what, clicks Save and reads the file through its download link.
async fn save(c: &Client, what: &str) -> Result<(Value, String, Vec<u8>), String> {
    let before = js(
        c,
        "return Number(document.getElementById('chan-save').dataset.count || 0)",
    )
    .await?
    .as_u64()
    .unwrap_or(0);
    js(
        c,
        &format!("document.getElementById('chan-save-what').value = '{what}';"),
    )
    .await?;
    click(c, "chan-save").await?;
    let t0 = Instant::now();
    let info = loop {
        let got = js(
            c,
            "return { info: window.figureExport.last(), \
                      count: Number(document.getElementById('chan-save').dataset.count || 0) }",
        )
        .await?;
        if got["count"].as_u64() == Some(before + 1) && got["info"]["href"].is_string() {
            break got["info"].clone();
        }
        let b = banner(c).await?;
        if !b.is_empty() || t0.elapsed() > Duration::from_secs(30) {
            return Err(format!("save {what}: no file (banner {b:?})"));
        }
        tokio::time::sleep(Duration::from_millis(25)).await;
    };
    let content = c
        .execute_async(
            "const done = arguments[arguments.length - 1]; \
             fetch(window.figureExport.last().href).then((r) => r.arrayBuffer()).then((b) => \
               done({ text: new TextDecoder().decode(b), head: Array.from(new Uint8Array(b.slice(0, 8))) }), \
               (e) => done({ error: String(e) }));",
            vec![],
        )
        .await
        .map_err(|e| e.to_string())?;
    if let Some(e) = content.get("error") {
        return Err(format!("reading the download link: {e}"));
    }
    let head: Vec<u8> =
        serde_json::from_value(content["head"].clone()).map_err(|e| e.to_string())?;
    Ok((
        info,
        content["text"].as_str().unwrap_or_default().to_string(),
        head,
    ))
}

struct Outcome {
    mode_pressed: Value,
    bad_banner: String,
    pfa_banner: String,
    simulated: Value,
    after_stop: Value,
    done: Value,
    track: Value,
    truth: Value,
    /// The state after the cursor was moved to each step, in the order Home, 5 × →, End.
    cursors: Vec<Value>,
    saved_track: (Value, String),
    saved_svg: (Value, String),
    saved_png: (Value, Vec<u8>),
    settings: Value,
    applied: Value,
    refused: Value,
    errors: Vec<String>,
}

async fn run(c: &Client, port: u16, bad: &str) -> Result<Outcome, String> {
    open_hash(c, port, "").await?;
    settle(c).await?;
    click(c, "mode-channel").await?;
    settle(c).await?;
    let mode_pressed = js(c, "return [document.body.className, document.getElementById('mode-channel').getAttribute('aria-pressed')]").await?;
    js(c, "window.figureExport.setDryRun(true)").await?;

    // A malformed recording through the file input.
    c.find(Locator::Id("chan-file"))
        .await
        .map_err(|e| e.to_string())?
        .send_keys(bad)
        .await
        .map_err(|e| e.to_string())?;
    let bad_banner = wait_banner(c).await?;
    dismiss(c).await?;

    // A malformed number, typed into P_fa and committed with Enter (change).
    let pfa = c
        .find(Locator::Id("chan-pfa"))
        .await
        .map_err(|e| e.to_string())?;
    pfa.clear().await.map_err(|e| e.to_string())?;
    pfa.send_keys("0x10\u{E007}")
        .await
        .map_err(|e| e.to_string())?;
    let pfa_banner = wait_banner(c).await?;
    pfa.clear().await.map_err(|e| e.to_string())?;
    pfa.send_keys("0.001\u{E007}")
        .await
        .map_err(|e| e.to_string())?;
    dismiss(c).await?;

    // Simulate a walk through the scenario.
    click(c, "chan-simulate").await?;
    let simulated = wait_channel(c, 300, "simulate", |s| {
        s["recording"].is_object() && s["running"].is_null()
    })
    .await?;

    // Run, and stop it while it estimates.
    click(c, "chan-run").await?;
    wait_channel(c, 120, "run started", |s| {
        s["running"] == "run" && s["progress"].is_object()
    })
    .await?;
    click(c, "chan-stop").await?;
    let after_stop = wait_channel(c, 30, "stop", |s| s["running"].is_null()).await?;

    // Run to the end.
    click(c, "chan-run").await?;
    let done = wait_channel(c, 900, "run", |s| s["runs"] == 1 && s["running"].is_null()).await?;
    let texts = js(c, "return window.channel.texts()").await?;
    let track: Value = serde_json::from_str(texts["track"].as_str().unwrap_or("null"))
        .map_err(|e| e.to_string())?;
    // The simulated truth as the page holds it (the file the simulator wrote).
    let truth = js(c, "return window.channel.truthStates()").await?;

    // The cursor, with the keyboard on the range input.
    let mut cursors = Vec::new();
    keys(c, "chan-scrub", HOME).await?;
    settle(c).await?;
    cursors.push(channel_state(c).await?);
    for _ in 0..5 {
        keys(c, "chan-scrub", RIGHT).await?;
    }
    settle(c).await?;
    cursors.push(channel_state(c).await?);
    keys(c, "chan-scrub", END).await?;
    settle(c).await?;
    cursors.push(channel_state(c).await?);

    // A picture of the view at the last snapshot, for a look by eye (temp dir).
    if let Ok(png) = c.screenshot().await {
        let _ = std::fs::write(
            std::env::temp_dir().join("scatterloc-e2e-channel-view.png"),
            png,
        );
    }
    js(
        c,
        "document.getElementById('chan-figures').scrollIntoView()",
    )
    .await?;
    if let Ok(png) = c.screenshot().await {
        let _ = std::fs::write(
            std::env::temp_dir().join("scatterloc-e2e-channel-charts.png"),
            png,
        );
    }

    // Saves.
    let (i, t, _) = save(c, "track-json").await?;
    let saved_track = (i, t);
    let (i, t, _) = save(c, "delays-svg").await?;
    let saved_svg = (i, t);
    let (i, _, h) = save(c, "delays-png").await?;
    let saved_png = (i, h);

    // The settings hook.
    let settings = js(c, "return window.channel.settings()").await?;
    let applied = js(
        c,
        "const s = window.channel.settings(); window.channel.applySettings({ ...s, filter: 'ukf', p_fa: 0.01, step: 3 }); \
         return { settings: window.channel.settings(), filter: document.getElementById('chan-filter').value, \
                  pfa: document.getElementById('chan-pfa').value, step: window.channel.state().step };",
    )
    .await?;
    let refused = js(
        c,
        "const before = window.channel.settings(); let message = null; \
         try { window.channel.applySettings({ ...before, p_fa: 2 }); } catch (e) { message = e.message; } \
         let unknown = null; try { window.channel.applySettings({ colour: 1 }); } catch (e) { unknown = e.message; } \
         return { message, unknown, same: JSON.stringify(before) === JSON.stringify(window.channel.settings()) };",
    )
    .await?;
    Ok(Outcome {
        mode_pressed,
        bad_banner,
        pfa_banner,
        simulated,
        after_stop,
        done,
        track,
        truth,
        cursors,
        saved_track,
        saved_svg,
        saved_png,
        settings,
        applied,
        refused,
        errors: console_errors(c).await?,
    })
}

/// The position `[x, y]` of a state `[x, y, vx, vy]` or a point (`None`: `null`).
fn position(v: &Value) -> Option<[f64; 2]> {
    let a = v.as_array()?;
    Some([a.first()?.as_f64()?, a.get(1)?.as_f64()?])
}

#[test]
#[ignore = "needs chromium + chromedriver and www/pkg (wasm-pack build); run with --ignored"]
fn channel_view_simulate_run_stop_scrub_save() {
    // Not a zip archive: the core's reader names what is wrong.
    let bytes = b"PK\x03\x04 this is not a recording".to_vec();
    let bad = std::env::temp_dir().join(format!("scatterloc-e2e-bad-{}.npz", std::process::id()));
    std::fs::write(&bad, &bytes).unwrap();
    let expected = match scatterloc::npz::read_recording(&bytes) {
        Err(e) => e.to_string(),
        Ok(_) => panic!("the malformed file was read"),
    };
    let path = bad.to_str().unwrap().to_string();
    let o = with_browser(async |c, port, _| run(c, port, &path).await);
    let _ = std::fs::remove_file(&bad);
    assert!(o.errors.is_empty(), "console errors: {:?}", o.errors);

    assert!(
        o.mode_pressed[0].as_str().unwrap().contains("mode-channel"),
        "{:?}",
        o.mode_pressed
    );
    assert_eq!(o.mode_pressed[1], "true");
    let name = bad.file_name().unwrap().to_str().unwrap();
    assert_eq!(o.bad_banner, format!("Recording {name}: {expected}"));
    assert_eq!(o.pfa_banner, "P_fa: \"0x10\" is not a decimal number");

    // The simulated recording: the scenario's links.
    let rec = &o.simulated["recording"];
    println!("simulated: {rec}");
    assert!(rec["snapshots"].as_u64().unwrap() >= 2, "{rec}");
    assert_eq!(
        rec["links"].as_u64(),
        Some(4),
        "sensors2019 has 4 links: {rec}"
    );

    // Stop: the run ended without a result.
    assert_eq!(o.after_stop["stopped"], 1, "{}", o.after_stop);
    assert_eq!(o.after_stop["runs"], 0, "{}", o.after_stop);
    assert_eq!(o.after_stop["statusState"], "stopped", "{}", o.after_stop);

    // The run: one state slot per snapshot of the recording.
    let d = &o.done;
    println!(
        "channel run: wall {} ms, worker {} ms, timings {}",
        d["wallMs"], d["workerMs"], d["timings"]
    );
    println!("status: {}", d["status"]);
    let status = d["status"].as_str().unwrap();
    assert!(status.contains("segment"), "{status}");
    assert!(
        status.contains("background from the empty area's recording"),
        "{status}"
    );
    let t_s = o.track["t_s"].as_array().unwrap();
    let states = o.track["states"].as_array().unwrap();
    assert_eq!(t_s.len() as u64, rec["snapshots"].as_u64().unwrap());
    assert_eq!(d["steps"].as_u64(), Some(t_s.len() as u64));
    assert!(
        states.iter().any(|s| !s.is_null()),
        "the track never started"
    );

    // The cursor: Home → 0, five → → 5, End → the last snapshot; the map drew that snapshot's
    // state, links and truth; the chart cursors move right.
    let last = t_s.len() - 1;
    let truth = o.truth.as_array().expect("truth states");
    let mut xs = Vec::new();
    for (s, k) in o.cursors.iter().zip([0, 5, last]) {
        assert_eq!(s["step"].as_u64(), Some(k as u64), "{s}");
        assert_eq!(s["t_s"].as_f64(), t_s[k].as_f64(), "t at step {k}");
        let drawn = &s["drawn"];
        assert_eq!(drawn["step"].as_u64(), Some(k as u64), "{drawn}");
        assert_eq!(
            position(&drawn["estimate"]),
            position(&states[k]),
            "estimate drawn at step {k}"
        );
        let used: Vec<usize> = o.track["delays_used_s"][k]
            .as_array()
            .unwrap()
            .iter()
            .enumerate()
            .filter(|(_, v)| !v.is_null())
            .map(|(p, _)| p)
            .collect();
        assert_eq!(drawn["links"], json!(used), "links drawn at step {k}");
        assert_eq!(
            position(&drawn["truth"]),
            position(&truth[k]),
            "truth drawn at step {k}"
        );
        assert!(position(&truth[k]).is_some(), "a true state at step {k}");
        let x = s["cursorX"]["delays"].as_f64().expect("delay cursor");
        let e = s["cursorX"]["errors"].as_f64().expect("error cursor");
        let b = &s["delayBox"]["x_px"];
        assert!(
            x >= b[0].as_f64().unwrap() - 0.5 && x <= b[1].as_f64().unwrap() + 0.5,
            "{x} in {b}"
        );
        xs.push((x, e));
    }
    assert!(
        xs[0].0 < xs[1].0 && xs[1].0 < xs[2].0,
        "delay cursor {xs:?}"
    );
    assert!(
        xs[0].1 < xs[1].1 && xs[1].1 < xs[2].1,
        "error cursor {xs:?}"
    );

    // The saved files.
    let (info, text) = &o.saved_track;
    assert!(
        info["name"]
            .as_str()
            .unwrap()
            .ends_with("-channel-track.json"),
        "{info}"
    );
    assert!(text.ends_with('\n'));
    let saved: Value = serde_json::from_str(text).unwrap();
    assert_eq!(saved, o.track);
    let (info, svg) = &o.saved_svg;
    assert_eq!(info["type"], "image/svg+xml");
    assert!(svg.contains("<svg"), "not an SVG");
    for l in o.done["links"].as_array().unwrap() {
        assert!(
            svg.contains(l.as_str().unwrap()),
            "link {l} in the delay figure"
        );
    }
    let (info, head) = &o.saved_png;
    assert_eq!(info["type"], "image/png");
    assert_eq!(head.as_slice(), PNG_SIGNATURE);

    // The settings: the CLI's defaults, applied and refused by name.
    let s = &o.settings;
    for (k, v) in [
        ("filter", json!("ekf")),
        ("particles", json!(1000)),
        ("seed", json!(1)),
        ("process_noise", json!(1)),
        ("p_fa", json!(0.001)),
        ("max_paths", json!(12)),
        ("extent_sigma_m", json!(0.2)),
        ("statics", json!("background")),
        ("delay_reference", json!("auto")),
        ("background_time_s", json!(10)),
        ("cpi_snapshots", json!(1)),
        ("range_rate_floor_mps", json!(0.1)),
        ("calibration", json!("file")),
    ] {
        assert_eq!(s[k], v, "setting {k}: {s}");
    }
    assert_eq!(o.applied["filter"], "ukf");
    assert_eq!(o.applied["pfa"], "0.01");
    assert_eq!(o.applied["step"], 3);
    assert_eq!(o.applied["settings"]["filter"], "ukf");
    assert_eq!(
        o.refused["message"],
        "channel setting p_fa: 2 is out of range (allowed 0 < P_fa < 1)"
    );
    assert!(
        o.refused["unknown"]
            .as_str()
            .unwrap()
            .starts_with("channel settings: unknown setting \"colour\""),
        "{}",
        o.refused
    );
    assert_eq!(o.refused["same"], true);
}

/// What the two-segment run showed.
struct Segments {
    inputs: String,
    done: Value,
    track: Value,
    gap: Value,
    gap_info: String,
    last: Value,
    errors: Vec<String>,
}

async fn two_segments(
    c: &Client,
    port: u16,
    rec: &str,
    truth: &str,
    expected: &Value,
) -> Result<Segments, String> {
    open_hash(c, port, "").await?;
    settle(c).await?;
    click(c, "mode-channel").await?;
    settle(c).await?;
    for (id, path) in [("chan-file", rec), ("chan-truth-file", truth)] {
        c.find(Locator::Id(id))
            .await
            .map_err(|e| e.to_string())?
            .send_keys(path)
            .await
            .map_err(|e| e.to_string())?;
    }
    wait_channel(c, 60, "files", |s| {
        s["recording"].is_object() && s["truth"].is_string()
    })
    .await?;
    let inputs = js(
        c,
        "return document.getElementById('chan-inputs').textContent",
    )
    .await?
    .as_str()
    .unwrap_or_default()
    .to_string();
    click(c, "chan-run").await?;
    let done = wait_channel(c, 600, "run", |s| {
        (s["runs"] == 1 || s["statusState"] == "error") && s["running"].is_null()
    })
    .await?;
    let texts = js(c, "return window.channel.texts()").await?;
    let track: Value = serde_json::from_str(texts["track"].as_str().unwrap_or("null"))
        .map_err(|e| e.to_string())?;
    // A snapshot in the first gap (after the first loss).
    let segs = expected["segments"].as_array().cloned().unwrap_or_default();
    let k = segs
        .first()
        .and_then(|g| g["last"].as_u64())
        .map_or(0, |l| l + 2);
    js(c, &format!("window.channel.seek({k})")).await?;
    settle(c).await?;
    let gap = channel_state(c).await?;
    let gap_info = js(c, "return document.getElementById('chan-info').textContent")
        .await?
        .as_str()
        .unwrap_or_default()
        .to_string();
    keys(c, "chan-scrub", END).await?;
    settle(c).await?;
    let last = channel_state(c).await?;
    js(
        c,
        "document.getElementById('chan-figures').scrollIntoView()",
    )
    .await?;
    if let Ok(png) = c.screenshot().await {
        let _ = std::fs::write(
            std::env::temp_dir().join("scatterloc-e2e-channel-segments.png"),
            png,
        );
    }
    Ok(Segments {
        inputs,
        done,
        track,
        gap,
        gap_info,
        last,
        errors: console_errors(c).await?,
    })
}

#[test]
#[ignore = "needs chromium + chromedriver and www/pkg (wasm-pack build); run with --ignored"]
fn channel_view_two_segments_without_calibration() {
    use super::channel::{check, cli, compare, Diff, TRACK_TOL};
    let dir = std::env::temp_dir().join(format!(
        "scatterloc-e2e-channel-segments-{}",
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let p = |n: &str| dir.join(n).to_string_lossy().into_owned();
    std::fs::write(p("s.json"), cli(&["preset", "sensors2019"])).unwrap();
    // Out along y = 4 m to x = 40 m (the area ends at x = 30 m) and back, then up: 23 s at 3 m/s.
    cli(&[
        "cir",
        "simulate",
        "--scenario",
        &p("s.json"),
        "--out-dir",
        &p("sim"),
        "--walk",
        "10,4 40,4 10,4 10,14",
        "--speed",
        "3",
        "--dt",
        "0.05",
        "--seed",
        "1",
    ]);
    let (rec, truth) = (p("sim/recording.npz"), p("sim/truth.json"));
    cli(&[
        "cir",
        "track",
        "--scenario",
        &p("s.json"),
        "--cir",
        &rec,
        "--truth",
        &truth,
        "--out",
        &p("track.json"),
    ]);
    let expected: Value = serde_json::from_slice(&std::fs::read(p("track.json")).unwrap()).unwrap();
    let segs = expected["segments"].as_array().unwrap().clone();
    let ends: Vec<&str> = segs.iter().map(|g| g["end"].as_str().unwrap()).collect();
    println!("the CLI's segments: {ends:?}");
    assert!(
        segs.len() >= 2 && ends[0] != "end",
        "the walk out of the area and back should give two segments, the first lost: {segs:?}"
    );
    let o = with_browser(async |c, port, _| two_segments(c, port, &rec, &truth, &expected).await);
    let _ = std::fs::remove_dir_all(&dir);
    assert!(o.errors.is_empty(), "console errors: {:?}", o.errors);
    assert!(
        o.inputs
            .contains("the background is learnt from the recording itself"),
        "{}",
        o.inputs
    );
    // The page's TRACK.json is the CLI's.
    let mut d = Diff::new(TRACK_TOL);
    compare("TRACK", &o.track, &expected, &mut d);
    check("TRACK.json of the walk out and back (page view)", &d);
    // The status line: where the statics came from, the segments and each loss's reason.
    let status = o.done["status"].as_str().unwrap();
    println!("status: {status}");
    assert!(
        status.contains("no empty area: background learnt from the recording"),
        "{status}"
    );
    assert!(
        status.contains(&format!("{} segments: ", segs.len())),
        "{status}"
    );
    let losses: Vec<&Value> = segs.iter().filter(|g| g["end"] != "end").collect();
    assert_eq!(status.matches("(lost: ").count(), losses.len(), "{status}");
    assert!(
        status.contains(&format!("(lost: {})", ends[0].replace('_', " "))),
        "{status}"
    );
    let st = &o.done["statics"];
    assert_eq!(st["source"], "none", "{st}");
    assert_eq!(st["statics"], "background", "{st}");
    // The error chart: each loss a labelled line inside the plot, the gaps shaded, the starts.
    let marks = &o.done["segmentMarks"];
    let b = &o.done["errorBox"]["x_px"];
    let (x0, x1) = (b[0].as_f64().unwrap(), b[1].as_f64().unwrap());
    let drawn = marks["losses"].as_array().unwrap();
    assert_eq!(drawn.len(), losses.len(), "{marks}");
    for (m, g) in drawn.iter().zip(&losses) {
        let x = m["x"].as_f64().unwrap();
        assert!(x >= x0 - 0.5 && x <= x1 + 0.5, "loss at {x} outside {b}");
        assert_eq!(m["end"], g["end"]);
        assert_eq!(
            m["label"].as_str().unwrap(),
            format!("lost: {}", g["end"].as_str().unwrap().replace('_', " "))
        );
        // At the snapshot of the loss, the one after the segment's last.
        let k = g["last"].as_u64().unwrap() as usize + 1;
        assert_eq!(m["t_s"], expected["t_s"][k]);
    }
    let gaps = marks["gaps"].as_array().unwrap();
    assert!(gaps.len() >= segs.len() - 1, "{marks}");
    for w in gaps {
        let (a, z) = (w[0].as_f64().unwrap(), w[1].as_f64().unwrap());
        assert!(x0 - 0.5 <= a && a < z && z <= x1 + 0.5, "gap {w} in {b}");
    }
    assert_eq!(marks["starts"].as_array().unwrap().len(), segs.len());
    assert_eq!(
        o.done["segments"].as_array().unwrap().len(),
        segs.len(),
        "{}",
        o.done["segments"]
    );
    // In the gap: no estimate, no ellipse, no link, the first segment alone.
    let g = &o.gap["drawn"];
    println!("in the gap: {g}; info {}", o.gap_info);
    assert_eq!(g["estimate"], Value::Null, "{g}");
    assert_eq!(g["sigma"], Value::Null, "{g}");
    assert_eq!(g["segment"], Value::Null, "{g}");
    assert_eq!(g["links"], json!([]), "{g}");
    assert_eq!(g["track_runs"], 1, "{g}");
    let first_len = segs[0]["last"].as_u64().unwrap() - segs[0]["first"].as_u64().unwrap() + 1;
    assert_eq!(g["track_points"].as_u64(), Some(first_len), "{g}");
    assert!(o.gap_info.contains("lost at"), "{}", o.gap_info);
    // At the end: every segment, each its own line, together every state.
    let l = &o.last["drawn"];
    let states = expected["states"].as_array().unwrap();
    assert_eq!(l["track_runs"].as_u64(), Some(segs.len() as u64), "{l}");
    assert_eq!(
        l["track_points"].as_u64(),
        Some(states.iter().filter(|x| !x.is_null()).count() as u64),
        "{l}"
    );
}
