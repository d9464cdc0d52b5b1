//! Browser end-to-end tests of the page's Plan panel and shared links (issue 14): Optimize on
//! sensors2019 in the page (the planner in a Web Worker, the nodes glide, the chart fills, before
//! → after); Stop, a node drag and a preset change cancel a running plan and Undo restores the
//! exact scenario; "Copy link" reopens the same scenario, view and ROI in a fresh page; tampered
//! links are named in the error banner and the page keeps its default scenario.

use std::time::{Duration, Instant};

use fantoccini::Client;
use serde_json::{json, Value};

use super::ui::{banner, click, poll};
use super::{console_errors, drag_on_plot, js, open, open_url, session, settle};

async fn plan_state(c: &Client) -> Result<Value, String> {
    js(c, "return window.plan.state()").await
}

/// Polls `window.plan.state()` until `done(state)`, at most `secs`.
async fn wait_plan(c: &Client, secs: u64, done: impl Fn(&Value) -> bool) -> Result<Value, String> {
    poll(c, "return window.plan.state()", secs, "plan", done).await
}

/// The plan finished and its final layout is applied (no glide left).
fn finished(s: &Value) -> bool {
    (s["state"] == "done" || s["state"] == "error") && s["gliding"] == false
}

/// `[[x, y], …]` of the scenario object's `receivers` or `transmitters`.
fn positions(s: &Value, kind: &str) -> Vec<[f64; 2]> {
    s[kind]
        .as_array()
        .map(|a| {
            a.iter()
                .filter_map(|n| serde_json::from_value(n["position_m"].clone()).ok())
                .collect()
        })
        .unwrap_or_default()
}

/// Base64url without padding (the page's `scenario=` encoding).
fn base64url(bytes: &[u8]) -> String {
    const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789-_";
    let mut out = String::new();
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            chunk.get(1).copied().unwrap_or(0),
            chunk.get(2).copied().unwrap_or(0),
        ];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for k in 0..=chunk.len() {
            out.push(A[((n >> (18 - 6 * k)) & 63) as usize] as char);
        }
    }
    out
}

/// Issue 14 (a): Optimize in the page on sensors2019 (receivers, p90, ROI = the whole area,
/// grid 64, budget 10 000) through the panel's buttons: the receivers move (the transmitter
/// stays), p90 after < before on the requested grid, the chart got the history, the final layout
/// is plan.json's scenario, the progress messages stay throttled, no console errors. Prints the
/// page's wall time of the plan (issue target: ≤ 10 s; not asserted).
#[test]
#[ignore = "needs chromium + chromedriver and www/pkg (wasm-pack build); run with --ignored"]
fn plan_optimize_moves_receivers_and_lowers_p90() {
    let (before, after, st, result, text, wall, beams, errors) = session(|c, port| async move {
        open(&c, port).await?;
        settle(&c).await?;
        let before = js(&c, "return window.app.scenario()").await?;
        click(&c, "plan-toggle").await?;
        // The panel's defaults are the request: receivers, p90, grid 64, budget 10 000.
        let inputs = js(
            &c,
            "return ['plan-move', 'plan-objective', 'plan-grid', 'plan-budget', 'plan-seed'] \
             .map((id) => document.getElementById(id).value)",
        )
        .await?;
        if inputs != json!(["rx", "p90", "64", "10000", "1"]) {
            return Err(format!("panel defaults {inputs}"));
        }
        let t0 = Instant::now();
        click(&c, "plan-run").await?;
        let running = plan_state(&c).await?;
        if running["state"] != "running" {
            return Err(format!("not running after Optimize: {running}"));
        }
        let st = wait_plan(&c, 180, finished).await?;
        let wall = t0.elapsed();
        settle(&c).await?;
        let after = js(&c, "return window.app.scenario()").await?;
        let result = js(&c, "return window.plan.result()").await?;
        let text = js(
            &c,
            "return [document.getElementById('plan-result').textContent, \
             document.getElementById('plan-status').textContent, \
             (document.getElementById('error').hidden ? '' : document.getElementById('error-text').textContent)]",
        )
        .await?;
        // The transmitter with its beam, for coverage: positions and boresights glide too.
        let started = js(
            &c,
            "return window.plan.start({move: 'tx-boresight', objective: 'coverage:0.05', budget: 1500})",
        )
        .await?;
        if !started.is_null() {
            return Err(format!("start: {started}"));
        }
        let beams_state = wait_plan(&c, 60, finished).await?;
        settle(&c).await?;
        let beams = json!([
            beams_state,
            js(&c, "return window.plan.result()").await?,
            js(&c, "return window.app.scenario()").await?,
        ]);
        Ok((
            before,
            after,
            st,
            result,
            text,
            wall,
            beams,
            console_errors(&c).await?,
        ))
    });
    let secs = |k: &str| st[k].as_f64().unwrap_or(f64::NAN) / 1e3;
    println!(
        "e2e: plan in the page (sensors2019, 4 Rx, p90, grid 64, budget 10000): {:.2} s from the \
         Optimize click to the final layout ({:.2} s Optimize → result, {:.2} s in the worker's \
         plan_network); {} evaluations, {} progress messages, {} layouts glided, {} history points; \
         {}",
        wall.as_secs_f64(),
        secs("wallMs"),
        secs("workerMs"),
        st["evaluations"],
        st["messages"],
        st["improvements"],
        st["points"],
        text[0].as_str().unwrap_or_default()
    );
    assert!(errors.is_empty(), "console errors: {errors:?}");
    assert_eq!(st["state"], "done", "{st}");
    assert_eq!(text[2], "", "no error banner");
    let o = &result["objective"];
    let (b, a) = (o["before"].as_f64().unwrap(), o["after"].as_f64().unwrap());
    assert!(a < b, "p90 after {a} < before {b}");
    assert_eq!(o["label"], "p90");
    assert_eq!(o["grid"], 64);
    let roi: Vec<f64> = serde_json::from_value(o["roi"].clone()).unwrap();
    assert_eq!(roi, [-7.5, 30.0, -10.0, 26.0], "ROI = the whole area");
    assert_eq!(result["evaluations"], 10000);
    // The receivers moved; the transmitter did not; the page shows plan.json's layout.
    let (rx0, rx1) = (
        positions(&before, "receivers"),
        positions(&after, "receivers"),
    );
    assert_eq!(rx0.len(), 4);
    assert_eq!(rx1, positions(&result["scenario"], "receivers"));
    let moved = rx0
        .iter()
        .zip(&rx1)
        .filter(|(p, q)| (p[0] - q[0]).hypot(p[1] - q[1]) > 0.01)
        .count();
    assert!(moved >= 1, "receivers moved: {rx0:?} -> {rx1:?}");
    assert_eq!(
        positions(&before, "transmitters"),
        positions(&after, "transmitters")
    );
    // The chart: every improvement of plan.json's history, drawn.
    let history = result["history"].as_array().unwrap().len();
    assert!(history >= 2, "history {history}");
    assert_eq!(st["points"], history);
    assert_eq!(st["chartPoints"], history);
    assert!(st["improvements"].as_u64().unwrap() >= 1, "{st}");
    // At most about 30 progress messages per second of planning, besides those carrying an
    // improvement (at most one per frame), and the last flush.
    let messages = st["messages"].as_f64().unwrap();
    assert!(
        messages <= secs("workerMs") * 31.0 + st["improvements"].as_f64().unwrap() + 2.0,
        "{messages} messages in {:.2} s",
        secs("workerMs")
    );
    let shown = text[0].as_str().unwrap_or_default();
    assert!(
        shown.starts_with("p90 on the 64×64 ROI grid: ") && shown.contains(" → "),
        "{shown:?}"
    );
    // Coverage with the transmitter and its beam: done, and the page shows plan.json's layout.
    let (bs, br, bshown) = (&beams[0], &beams[1], &beams[2]);
    assert_eq!(bs["state"], "done", "{bs}");
    let bo = &br["objective"];
    assert_eq!(bo["kind"], "coverage");
    assert_eq!(bo["maximised"], true);
    assert!(
        bo["after"].as_f64().unwrap() >= bo["before"].as_f64().unwrap(),
        "{bo}"
    );
    assert_eq!(br["moved"], json!(["Tx"]));
    assert_eq!(bshown["transmitters"], br["scenario"]["transmitters"]);
    assert_eq!(bshown["receivers"], br["scenario"]["receivers"]);
}

/// Issue 14 (b): Stop cancels a running plan (budget 10⁶): state idle, the worker's progress
/// ends, the layout is the last one applied (or unchanged) and stays; Undo restores the exact
/// scenario JSON from before Optimize. A node drag and a preset change cancel a plan too.
#[test]
#[ignore = "needs chromium + chromedriver and www/pkg (wasm-pack build); run with --ignored"]
fn plan_stop_drag_and_preset_cancel_and_undo_restores() {
    let o = session(|c, port| async move {
        open(&c, port).await?;
        settle(&c).await?;
        let json0 = js(&c, "return window.app.scenario_json()").await?;
        // 1. Stop (the button).
        let started = js(&c, "return window.plan.start({budget: 1000000})").await?;
        if !started.is_null() {
            return Err(format!("start: {started}"));
        }
        wait_plan(&c, 60, |s| s["improvements"].as_u64().unwrap_or(0) >= 2).await?;
        click(&c, "plan-stop").await?;
        let stopped = plan_state(&c).await?;
        let layout = js(
            &c,
            "const a = window.plan.state().applied; \
             return [window.app.scenario(), a === null ? null : JSON.parse(a)]",
        )
        .await?;
        tokio::time::sleep(Duration::from_millis(1000)).await;
        settle(&c).await?;
        let later = json!([
            plan_state(&c).await?,
            js(&c, "return window.app.scenario()").await?
        ]);
        click(&c, "plan-undo").await?;
        settle(&c).await?;
        let undone = json!([
            js(&c, "return window.app.scenario_json()").await? == json0,
            plan_state(&c).await?["undo"],
            js(&c, "return document.getElementById('preset').value").await?,
        ]);
        // 2. A node drag: the transmitter (receivers move in this plan), by real mouse input.
        js(&c, "window.plan.start({budget: 1000000})").await?;
        wait_plan(&c, 60, |s| s["improvements"].as_u64().unwrap_or(0) >= 1).await?;
        let geo = js(
            &c,
            "const t = window.app.nodes().transmitters[0]; const p = window.view.toPixel(t.x, t.y); \
             const b = document.getElementById('plot').getBoundingClientRect(); \
             return [p.x - b.width / 2, p.y - b.height / 2];",
        )
        .await?;
        let g: Vec<f64> = serde_json::from_value(geo).map_err(|e| e.to_string())?;
        drag_on_plot(&c, [g[0], g[1]], &[(30.0, 20.0, 200)]).await?;
        settle(&c).await?;
        let dragged = json!([
            plan_state(&c).await?,
            js(&c, "return window.app.nodes().transmitters[0]").await?
        ]);
        // 3. A preset change (the scenario select), while the nodes glide to an improvement.
        js(&c, "window.plan.start({budget: 1000000})").await?;
        let gliding = c
            .execute_async(
                "const done = arguments[arguments.length - 1]; const t0 = performance.now(); \
                 const tick = () => { \
                   if (window.plan.state().gliding) { \
                     const p = document.getElementById('preset'); p.value = 'iclgnss2019'; \
                     p.dispatchEvent(new Event('change')); \
                     if (document.getElementById('confirm-dialog').open) document.getElementById('confirm-ok').click(); \
                     done(true); \
                   } else if (performance.now() - t0 > 30000) done(false); else setTimeout(tick, 2); \
                 }; tick();",
                vec![],
            )
            .await
            .map_err(|e| e.to_string())?;
        if gliding != true {
            return Err("no glide within 30 s".into());
        }
        settle(&c).await?;
        tokio::time::sleep(Duration::from_millis(500)).await;
        let preset = json!([
            plan_state(&c).await?,
            js(&c, "return window.app.scenario().name").await?
        ]);
        let banner_ok = banner(&c).await?;
        // 4. Bad requests: a typed budget that is not a number (named at once), an ROI outside
        // the area (named by the core, from the worker); nothing changes.
        let json1 = js(&c, "return window.app.scenario_json()").await?;
        let typed = js(
            &c,
            "document.getElementById('plan-budget').value = '1e3x'; \
             return [window.plan.start(), document.getElementById('error-text').textContent, \
             window.plan.state().state, document.getElementById('plan-budget').classList.contains('invalid')]",
        )
        .await?;
        js(
            &c,
            "document.getElementById('plan-budget').value = '10000'; window.plan.start({roi: [-100, 1, 2, 3]})",
        )
        .await?;
        let failed = wait_plan(&c, 30, |s| s["state"] != "running").await?;
        let bad = json!([
            typed,
            failed,
            banner(&c).await?,
            js(&c, "return window.app.scenario_json()").await? == json1,
        ]);
        Ok(json!({
            "stopped": stopped, "layout": layout, "later": later, "undone": undone,
            "dragged": dragged, "preset": preset, "bad": bad,
            "errors": console_errors(&c).await?, "banner": banner_ok,
        }))
    });
    println!(
        "e2e: plan stopped after {} evaluations ({} layouts applied)",
        o["stopped"]["evaluations"], o["stopped"]["improvements"]
    );
    assert_eq!(o["errors"], json!([]), "console errors");
    assert_eq!(o["banner"], "", "no error banner");
    let s = &o["stopped"];
    assert_eq!(s["state"], "idle", "{s}");
    assert_eq!(s["stopped"], "stopped");
    assert!(s["evaluations"].as_u64().unwrap() < 1_000_000, "{s}");
    assert_eq!(s["gliding"], false);
    // The layout is the last one applied (an improvement), complete.
    let (shown, applied) = (&o["layout"][0], &o["layout"][1]);
    assert!(!applied.is_null(), "an improvement was applied before Stop");
    for kind in ["receivers", "transmitters"] {
        assert_eq!(positions(shown, kind), positions(applied, kind), "{kind}");
    }
    // Nothing changes after Stop: no progress, no layout.
    assert_eq!(o["later"][0]["evaluations"], s["evaluations"]);
    assert_eq!(o["later"][0]["state"], "idle");
    assert_eq!(&o["later"][1], shown, "the layout stays");
    // Undo: the exact scenario JSON from before Optimize, and the preset name again.
    assert_eq!(o["undone"], json!([true, false, "sensors2019"]));
    // A node drag cancelled the second plan; the transmitter followed the mouse.
    let d = &o["dragged"][0];
    assert_eq!(d["state"], "idle", "{d}");
    assert_eq!(d["stopped"], "node dragged");
    let tx = &o["dragged"][1];
    assert!(
        tx["x"].as_f64().unwrap() > 0.5 && tx["y"].as_f64().unwrap() < -0.5,
        "transmitter dragged right and down: {tx}"
    );
    // A preset change cancelled the third and loaded the preset.
    let p = &o["preset"][0];
    assert_eq!(p["state"], "idle", "{p}");
    assert_eq!(p["stopped"], "scenario edited");
    assert_eq!(o["preset"][1], "iclgnss2019");
    // Bad requests: named in the banner, nothing runs or changes.
    let bad = &o["bad"];
    let typed = "plan budget: \"1e3x\" is not a decimal number";
    assert_eq!(
        bad[0],
        json!([typed, format!("Plan: {typed}"), "idle", true])
    );
    assert_eq!(bad[1]["state"], "error", "{}", bad[1]);
    assert_eq!(bad[1]["undo"], false, "nothing to undo");
    let b = bad[2].as_str().unwrap_or_default();
    assert!(
        b.starts_with("Plan: ") && b.contains("roi") && b.contains("must lie inside"),
        "{b:?}"
    );
    assert_eq!(bad[3], true, "the scenario is unchanged");
}

/// Issue 14 (c): after a short plan and an ROI drawn on the map (a real drag), "Copy link" and
/// that link opened in a fresh page give the same scenario JSON (node positions bit for bit),
/// the same view and ROI; so does a link copied in the tracking view, and a hand-made
/// `scenario=` (plain base64url) link.
#[test]
#[ignore = "needs chromium + chromedriver and www/pkg (wasm-pack build); run with --ignored"]
fn copy_link_reopens_the_same_scenario_view_and_roi() {
    let mut custom = scatterloc::scenario::presets::sensors2019();
    custom.name = "hand-made".into();
    custom.receivers[0].position_m = [1.0 / 3.0, -2.0e-7];
    let custom_json = custom.to_json();
    let plain = base64url(custom_json.as_bytes());
    let o = session(|c, port| async move {
        open(&c, port).await?;
        settle(&c).await?;
        js(&c, "window.plan.start({budget: 400})").await?;
        wait_plan(&c, 60, finished).await?;
        settle(&c).await?;
        // Draw the ROI: "Draw ROI", then a drag on the map from (−4, 20) m to about (15, 0) m.
        click(&c, "plan-roi-draw").await?;
        let geo = js(
            &c,
            "const p = window.view.toPixel(-4, 20); \
             const b = document.getElementById('plot').getBoundingClientRect(); \
             return [p.x - b.width / 2, p.y - b.height / 2, window.view.len(19), window.view.len(20)];",
        )
        .await?;
        let g: Vec<f64> = serde_json::from_value(geo).map_err(|e| e.to_string())?;
        drag_on_plot(&c, [g[0], g[1]], &[(g[2].round(), g[3].round(), 300)]).await?;
        settle(&c).await?;
        let drawn = plan_state(&c).await?;
        click(&c, "share-copy").await?;
        let t0 = Instant::now();
        let link = loop {
            let v = js(&c, "return document.getElementById('share-url').value").await?;
            if v.as_str().is_some_and(|s| !s.is_empty()) {
                break v.as_str().unwrap().to_string();
            }
            if t0.elapsed() > Duration::from_secs(10) {
                return Err("no link shown".into());
            }
            tokio::time::sleep(Duration::from_millis(25)).await;
        };
        let view = "return [window.app.scenario_json(), window.pageState.mode, \
                    window.plan.state().roi, window.plan.state().roiCustom, window.plan.state().open, \
                    document.getElementById('preset').value]";
        let here = js(&c, view).await?;
        open_url(&c, &link).await?;
        settle(&c).await?;
        let there = js(&c, view).await?;
        let there_banner = banner(&c).await?;
        let there_errors = console_errors(&c).await?;
        // The tracking view's link.
        click(&c, "mode-tracking").await?;
        settle(&c).await?;
        let link2: String = c
            .execute_async(
                "const done = arguments[arguments.length - 1]; \
                 window.shareLink().then(done, (e) => done('error: ' + e.message));",
                vec![],
            )
            .await
            .map_err(|e| e.to_string())?
            .as_str()
            .unwrap_or_default()
            .to_string();
        open_url(&c, &link2).await?;
        settle(&c).await?;
        let tracking = js(&c, view).await?;
        // A plain base64url link made by hand.
        let base = link.split('#').next().unwrap_or_default().to_string();
        open_url(&c, &format!("{base}#scenario={plain}")).await?;
        settle(&c).await?;
        let hand = json!([
            js(&c, view).await?,
            banner(&c).await?,
            console_errors(&c).await?
        ]);
        Ok(json!({
            "drawn": drawn, "link": link, "here": here, "there": there,
            "there_banner": there_banner, "there_errors": there_errors,
            "link2": link2, "tracking": tracking, "hand": hand,
        }))
    });
    let link = o["link"].as_str().unwrap();
    println!(
        "e2e: shared link of a planned view: {} characters",
        link.len()
    );
    let drawn = &o["drawn"];
    assert_eq!(drawn["roiCustom"], true, "the ROI was drawn: {drawn}");
    let roi: Vec<f64> = serde_json::from_value(drawn["roi"].clone()).unwrap();
    for (v, want) in roi.iter().zip([-4.0, 15.0, 0.0, 20.0]) {
        assert!((v - want).abs() < 0.5, "ROI {roi:?}");
    }
    assert!(
        link.contains("#mode=snapshot&") && link.contains("&roi="),
        "{link}"
    );
    let (here, there) = (&o["here"], &o["there"]);
    assert_eq!(o["there_banner"], "", "no banner");
    assert_eq!(o["there_errors"], json!([]), "console errors");
    assert_ne!(
        here[0].as_str().unwrap(),
        scatterloc::scenario::presets::sensors2019().to_json(),
        "a planned layout"
    );
    assert_eq!(there[0], here[0], "the same scenario JSON");
    assert_eq!(there[1], "snapshot");
    assert_eq!(there[2], here[2], "the same ROI");
    assert_eq!(there[3], true);
    assert_eq!(there[4], true, "the Plan panel is open to show the ROI");
    assert_eq!(there[5], "", "the preset select says imported / edited");
    let tracking = &o["tracking"];
    assert!(
        o["link2"].as_str().unwrap().contains("#mode=tracking&"),
        "{}",
        o["link2"]
    );
    assert_eq!(tracking[0], here[0]);
    assert_eq!(tracking[1], "tracking");
    assert_eq!(tracking[2], here[2]);
    let hand = &o["hand"];
    assert_eq!(hand[1], "", "no banner for the hand-made link");
    assert_eq!(hand[2], json!([]));
    assert_eq!(hand[0][0].as_str().unwrap(), custom_json, "bit for bit");
    assert_eq!(hand[0][1], "snapshot");
}

/// Issue 14 (d): tampered links (corrupted base64, base64 of invalid JSON, a scenario with a bad
/// field, bytes that are not deflate data, a corrupted copy of a real link, bad ROIs) each show
/// the error banner naming what was wrong, and the page keeps its default scenario.
#[test]
#[ignore = "needs chromium + chromedriver and www/pkg (wasm-pack build); run with --ignored"]
fn tampered_links_are_named_and_the_default_scenario_stays() {
    let good = scatterloc::scenario::presets::sensors2019().to_json();
    let bad_field = good.replace("\"bandwidth_hz\": 120000000.0", "\"bandwidth_hz\": -5.0");
    assert_ne!(good, bad_field);
    let cases: Vec<(String, &str)> = vec![
        (
            "#scenario=eyJuYW1lIjoi@@@".into(),
            "URL option scenario: not base64url: character \"@\" at position 12",
        ),
        (
            "#scenario=abcde".into(),
            "URL option scenario: not base64url: a length of 5 characters is impossible",
        ),
        (
            format!("#scenario={}", base64url(b"{\"name\": \"x\", oops}")),
            "URL option scenario: invalid JSON",
        ),
        (
            format!("#scenario={}", base64url(&[0xff, 0xfe, 0x7b])),
            "URL option scenario: not UTF-8 text",
        ),
        (
            format!("#scenario={}", base64url(bad_field.as_bytes())),
            "URL option scenario: radio.bandwidth_hz",
        ),
        (
            format!("#z={}", base64url(b"definitely not deflate data")),
            "URL option z: not deflate data",
        ),
        (
            "#mode=snapshot&roi=0,1,2".into(),
            "URL option roi: \"0,1,2\" is not 4 comma-separated numbers",
        ),
        (
            "#roi=-100,1,2,3".into(),
            "URL option roi: [-100, 1, 2, 3] m must lie inside the scenario area",
        ),
        (
            "#roi=5,1,2,3".into(),
            "URL option roi.x: the minimum 5 must be below the maximum 1",
        ),
        (
            "#roi=0,0x1,2,3".into(),
            "URL option roi[1]: \"0x1\" is not a decimal number",
        ),
    ];
    let hashes: Vec<String> = cases.iter().map(|(h, _)| h.clone()).collect();
    let o = session(|c, port| async move {
        open(&c, port).await?;
        settle(&c).await?;
        let default = js(&c, "return window.app.scenario_json()").await?;
        // A real link, its deflated scenario cut in half.
        let link: String = c
            .execute_async(
                "const done = arguments[arguments.length - 1]; \
                 window.app.move_receiver(0, 1.5, 2.5); \
                 window.shareLink().then(done, (e) => done('error: ' + e.message));",
                vec![],
            )
            .await
            .map_err(|e| e.to_string())?
            .as_str()
            .unwrap_or_default()
            .to_string();
        let (base, hash) = link.split_once('#').unwrap_or_default();
        let corrupt = match hash.find("z=") {
            Some(i) => hash[..i + 2 + (hash.len() - i - 2) / 2].to_string(),
            None => return Err(format!("no z= in {link}")),
        };
        let mut results = Vec::new();
        for hash in hashes.iter().chain([format!("#{corrupt}")].iter()) {
            open_url(&c, &format!("{base}#{}", hash.trim_start_matches('#'))).await?;
            settle(&c).await?;
            results.push(json!([
                hash,
                banner(&c).await?,
                js(&c, "return window.app.scenario_json()").await? == default,
                js(&c, "return document.body.dataset.error || null").await?,
                console_errors(&c).await?,
                js(&c, "return window.plan.state().roiCustom").await?,
            ]));
        }
        Ok(json!({"link": link, "results": results}))
    });
    let results = o["results"].as_array().unwrap();
    let wants = cases.iter().map(|(_, w)| *w).chain(["URL option z: "]);
    for (r, want) in results.iter().zip(wants) {
        println!("e2e: tampered {} -> {}", r[0], r[1]);
        let b = r[1].as_str().unwrap_or_default();
        assert!(b.contains(want), "{}: banner {b:?}, want {want:?}", r[0]);
        assert_eq!(r[2], true, "{}: the default scenario stays", r[0]);
        assert_eq!(r[3], Value::Null, "{}: page error", r[0]);
        assert_eq!(r[4], json!([]), "{}: console errors", r[0]);
        assert_eq!(r[5], false, "{}: no ROI taken", r[0]);
    }
}
