//! Browser end-to-end tests of the page state (www/js/state.js): every field set through the
//! page's own controls (real mouse and keyboard input) comes back from "Copy link" and from
//! "Save state" / "Open state" (one named assertion per field); a bad state file is named and
//! changes nothing; undo/redo of a node drag, a keyboard move, a panel edit, an import, Optimize,
//! a target placement, a tracking setting and a multi-target drag restores the exact previous
//! state; a scenario switch over unsaved edits asks first; an Optimize that finds no better layout
//! keeps the current one and says so.

use std::time::{Duration, Instant};

use fantoccini::{Client, Locator};
use serde_json::{json, Value};

use super::ui::{banner, click, press, select, type_in, wait_view, CONTROL, SHIFT};
use super::{console_errors, drag_on_plot, js, open, open_url, session, settle};

const RIGHT: char = '\u{E014}';

/// The page is idle and the history has looked at the last change.
pub(super) async fn quiet(c: &Client) -> Result<(), String> {
    settle(c).await?;
    let t0 = Instant::now();
    loop {
        let h = js(c, "return window.pageStateModel.history()").await?;
        let plan = js(c, "return window.plan.state()").await?;
        if h["pending"] == false && h["busy"] == false && plan["gliding"] == false {
            settle(c).await?;
            return Ok(());
        }
        if t0.elapsed() > Duration::from_secs(60) {
            return Err(format!("history never settled: {h}"));
        }
        tokio::time::sleep(Duration::from_millis(30)).await;
    }
}

pub(super) async fn capture(c: &Client) -> Result<Value, String> {
    js(c, "return window.pageStateModel.capture()").await
}

/// The part undo covers: every section but the mode and the view.
async fn doc(c: &Client) -> Result<Value, String> {
    let mut s = capture(c).await?;
    let o = s.as_object_mut().ok_or("state is not an object")?;
    o.remove("mode");
    o.remove("view");
    Ok(s)
}

async fn history_index(c: &Client) -> Result<i64, String> {
    Ok(js(c, "return window.pageStateModel.history().index")
        .await?
        .as_i64()
        .unwrap_or(-1))
}

/// CSS px from the plot's centre of map point (x, y) m (the view on screen).
async fn at(c: &Client, x: f64, y: f64) -> Result<[f64; 2], String> {
    let v = c
        .execute(
            "const v = window.pageState.mode === 'mtl' ? null : window.view; \
             if (!v) return window.mtl.pixelFromCentre(arguments[0], arguments[1]); \
             const p = v.toPixel(arguments[0], arguments[1]); \
             const b = document.getElementById('plot').getBoundingClientRect(); \
             return [p.x - b.width / 2, p.y - b.height / 2];",
            vec![json!(x), json!(y)],
        )
        .await
        .map_err(|e| e.to_string())?;
    serde_json::from_value(v).map_err(|e| e.to_string())
}

/// A point (m) at fractions (fx, fy) of the map window shown.
async fn window_point(c: &Client, fx: f64, fy: f64) -> Result<[f64; 2], String> {
    let a = js(c, "return Array.from(window.view.area)").await?;
    let a: Vec<f64> = serde_json::from_value(a).map_err(|e| e.to_string())?;
    Ok([a[0] + fx * (a[1] - a[0]), a[2] + fy * (a[3] - a[2])])
}

/// CSS px from the plot's centre of a map point with no object under it, near fractions
/// (fx, fy) of the window shown.
async fn empty_at(c: &Client, fx: f64, fy: f64) -> Result<[f64; 2], String> {
    let v = c
        .execute(
            "const [fx, fy] = arguments; const v = window.view; \
             const b = document.getElementById('plot').getBoundingClientRect(); \
             for (const d of [0, 0.05, -0.05, 0.1, -0.1, 0.15, -0.15]) for (const e of [0, 0.05, -0.05, 0.1, -0.1]) { \
               const [x0, x1, y0, y1] = v.area; \
               const p = v.toPixel(x0 + (fx + d) * (x1 - x0), y0 + (fy + e) * (y1 - y0)); \
               if (!window.zoom.hitAt(p.x, p.y)) return [p.x - b.width / 2, p.y - b.height / 2]; } \
             return null;",
            vec![json!(fx), json!(fy)],
        )
        .await
        .map_err(|e| e.to_string())?;
    serde_json::from_value(v).map_err(|e| format!("no empty point near ({fx}, {fy}): {e}"))
}

/// `[path, value]` leaves of a state: objects are walked, arrays, null and the scenario JSON
/// (and the blocking model) are leaves.
fn leaves(v: &Value, path: &str, out: &mut Vec<(String, Value)>) {
    match v {
        Value::Object(m) if path != "scenario.json" && path != "mtl.scene.model" => {
            for (k, x) in m {
                let p = if path.is_empty() {
                    k.clone()
                } else {
                    format!("{path}.{k}")
                };
                leaves(x, &p, out);
            }
        }
        _ => out.push((path.to_string(), v.clone())),
    }
}

/// The value at dotted `path` (or null).
fn at_path<'a>(v: &'a Value, path: &str) -> &'a Value {
    path.split('.')
        .fold(v, |v, k| v.get(k).unwrap_or(&Value::Null))
}

/// Equal, numbers within 1e-12 (relative to their size, at least absolute).
pub(super) fn close(a: &Value, b: &Value) -> bool {
    match (a, b) {
        (Value::Number(x), Value::Number(y)) => {
            let (x, y) = (x.as_f64().unwrap(), y.as_f64().unwrap());
            (x - y).abs() <= 1e-12 * x.abs().max(y.abs()).max(1.0)
        }
        (Value::Array(x), Value::Array(y)) => {
            x.len() == y.len() && x.iter().zip(y).all(|(a, b)| close(a, b))
        }
        (Value::Object(x), Value::Object(y)) => {
            x.len() == y.len() && x.iter().all(|(k, a)| y.get(k).is_some_and(|b| close(a, b)))
        }
        _ => a == b,
    }
}

/// The fields of the state besides the multi-target scene's (those are the default scene's keys).
const FIELDS: &[&str] = &[
    "format",
    "version",
    "mode",
    "scenario.preset",
    "scenario.json",
    "grid.res",
    "target.point.x",
    "target.point.y",
    "target.point.seed",
    "target.next_seed",
    "doppler.on",
    "doppler.snapshots",
    "doppler.spacing_ms",
    "doppler.floor_mps",
    "doppler.vx_mps",
    "doppler.vy_mps",
    "plan.roi",
    "plan.move",
    "plan.objective",
    "plan.grid",
    "plan.t",
    "plan.budget",
    "plan.seed",
    "tracking.kind",
    "tracking.drawn.x0",
    "tracking.drawn.y0",
    "tracking.drawn.x1",
    "tracking.drawn.y1",
    "tracking.dt",
    "tracking.ex",
    "tracking.filter",
    "tracking.particles",
    "tracking.runs",
    "tracking.speed",
    "tracking.seed",
    "tracking.mc_filters",
    "multi.walkers",
    "multi.method",
    "multi.paths",
    "mtl.p_u",
    "mtl.p_los",
    "view.map",
    "view.mtl",
    "view.plan_open",
    "view.step",
    "colours.locked",
    "colours.min_m",
    "colours.max_m",
    "channel.filter",
    "channel.particles",
    "channel.seed",
    "channel.process_noise",
    "channel.p_fa",
    "channel.max_paths",
    "channel.extent_sigma_m",
    "channel.statics",
    "channel.delay_reference",
    "channel.background_time_s",
    "channel.cpi_snapshots",
    "channel.range_rate_floor_mps",
    "channel.targets",
    "channel.calibration",
    "channel.empty_from_s",
    "channel.empty_to_s",
    "channel.link",
    "channel.step",
    "channel.speed",
];
/// Fields the page has no control for (the multi-target region, range cap and detection radius
/// are the scene's own) and the envelope: they keep their default.
const NO_CONTROL: &[&str] = &[
    "channel.link",
    "channel.step",
    "format",
    "version",
    "mtl.scene.region",
    "mtl.scene.r_max",
    "mtl.scene.detection_radius",
    "mtl.scene.max_candidates",
];

/// Sets every field of the state through the page's controls; returns the state.
async fn set_everything(c: &Client) -> Result<(), String> {
    // Snapshot view: the scenario (a preset, then a typed carrier), the grid, a target.
    select(c, "preset", "iclgnss2019").await?;
    quiet(c).await?;
    type_in(c, "carrier", "30").await?;
    type_in(c, "rx-gain", "3").await?;
    quiet(c).await?;
    select(c, "resolution", "128").await?;
    quiet(c).await?;
    drag_on_plot(c, empty_at(c, 0.37, 0.63).await?, &[]).await?;
    quiet(c).await?;
    // The Plan panel's settings and a drawn ROI.
    click(c, "plan-toggle").await?;
    select(c, "plan-move", "all").await?;
    select(c, "plan-objective", "coverage").await?;
    type_in(c, "plan-t", "0.25").await?;
    select(c, "plan-grid", "32").await?;
    type_in(c, "plan-budget", "500").await?;
    type_in(c, "plan-seed", "7").await?;
    click(c, "plan-roi-draw").await?;
    let [x0, y0] = window_point(c, 0.2, 0.25).await?;
    let [x1, y1] = window_point(c, 0.6, 0.7).await?;
    let a = at(c, x0, y0).await?;
    let b = at(c, x1, y1).await?;
    drag_on_plot(c, a, &[(b[0] - a[0], b[1] - a[1], 200)]).await?;
    quiet(c).await?;
    // The zoom window.
    click(c, "zoom-in").await?;
    quiet(c).await?;
    // Doppler (issue 42): on, with every field typed.
    select(c, "doppler-on", "on").await?;
    for (id, v) in [
        ("doppler-n", "32"),
        ("doppler-t", "1.024"),
        ("doppler-floor", "0.2"),
        ("doppler-vx", "-0.75"),
        ("doppler-vy", "1.5"),
    ] {
        type_in(c, id, v).await?;
    }
    quiet(c).await?;
    // Tracking: a drawn trajectory and every setting.
    click(c, "mode-tracking").await?;
    quiet(c).await?;
    select(c, "track-kind", "custom").await?;
    quiet(c).await?;
    let a = empty_at(c, 0.3, 0.3).await?;
    drag_on_plot(c, a, &[(60.0, -45.0, 200)]).await?;
    quiet(c).await?;
    select(c, "track-dt", "0.05").await?;
    type_in(c, "track-seed", "5").await?;
    select(c, "track-ex", "10").await?;
    select(c, "track-filter", "ukf").await?;
    click(c, "mc-pf").await?;
    click(c, "mc-ukf").await?;
    click(c, "mc-ekf").await?;
    select(c, "track-particles", "2000").await?;
    select(c, "mc-runs", "50").await?;
    select(c, "track-speed", "2").await?;
    quiet(c).await?;
    // Several people (issue 41): the method, then two walkers (the view turns multi-target) …
    select(c, "multi-method", "gnn").await?;
    select(c, "multi-walkers", "2").await?;
    super::ui::poll(
        c,
        "return window.tracking.state().multi.state;",
        180,
        "several people",
        |s| s == "done",
    )
    .await?;
    quiet(c).await?;
    // … then a drawn walker's path (the walkers "drawn", one press-drag on the map).
    select(c, "multi-walkers", "drawn").await?;
    quiet(c).await?;
    let a = empty_at(c, 0.35, 0.4).await?;
    drag_on_plot(c, a, &[(70.0, 40.0, 200)]).await?;
    super::ui::poll(
        c,
        "const m = window.tracking.state().multi; return m.paths.length === 1 ? m.state : 'drawing';",
        180,
        "a drawn walker",
        |s| s == "done",
    )
    .await?;
    quiet(c).await?;
    // The current step: Play for a moment, then Pause.
    click(c, "track-play").await?;
    tokio::time::sleep(Duration::from_millis(600)).await;
    click(c, "track-play").await?;
    quiet(c).await?;
    // The colour lock (snapshot and tracking views): ticked, with a typed range.
    click(c, "colour-lock").await?;
    type_in(c, "colour-min", "0.002").await?;
    type_in(c, "colour-max", "3").await?;
    quiet(c).await?;
    // The channel view's settings (its recordings are not part of the state; the link and the
    // step need a result and keep their default).
    click(c, "mode-channel").await?;
    quiet(c).await?;
    select(c, "chan-filter", "pf").await?;
    quiet(c).await?;
    for (id, v) in [
        ("chan-particles", "3000"),
        ("chan-seed", "4"),
        ("chan-q", "0.5"),
        ("chan-pfa", "0.0001"),
        ("chan-max-paths", "9"),
        ("chan-extent", "0.3"),
        ("chan-bg-time", "25"),
        ("chan-cpi", "4"),
        ("chan-rr-floor", "0.05"),
    ] {
        type_in(c, id, v).await?;
    }
    // The statics and the delay reference (issue 36).
    select(c, "chan-statics", "clusters").await?;
    select(c, "chan-delay-ref", "los").await?;
    quiet(c).await?;
    // Several people (issue 41 §2).
    select(c, "chan-targets", "several").await?;
    quiet(c).await?;
    select(c, "chan-cal-source", "range").await?;
    quiet(c).await?;
    type_in(c, "chan-empty-from", "0.5").await?;
    type_in(c, "chan-empty-to", "2.5").await?;
    select(c, "chan-speed", "2").await?;
    quiet(c).await?;
    // Multi-target: every number, the model and both of its probabilities, the sliders, the
    // scene's objects (added, removed, dragged) and its zoom window.
    click(c, "mode-mtl").await?;
    wait_view(c, 60).await?;
    for (id, v) in [
        ("mtl-seed", "9"),
        ("mtl-clutter", "2.5"),
        ("mtl-sigma", "0.23"),
        ("mtl-resolution", "0.37"),
        ("mtl-pd", "0.77"),
        ("mtl-lambda", "0.21"),
        ("mtl-diameter", "0.61"),
    ] {
        type_in(c, id, v).await?;
        wait_view(c, 60).await?;
    }
    select(c, "mtl-model", "icb-pu").await?;
    type_in(c, "mtl-pu", "0.4").await?;
    select(c, "mtl-model", "icb-plos").await?;
    type_in(c, "mtl-plos", "0.85").await?;
    for id in ["mtl-te", "mtl-tb"] {
        js(c, &format!("document.getElementById('{id}').focus()")).await?;
        press(c, &[], &[RIGHT]).await?;
        press(c, &[], &[RIGHT]).await?;
    }
    click(c, "mtl-add-target").await?;
    click(c, "mtl-remove-disc").await?;
    wait_view(c, 60).await?;
    let s = js(c, "return window.mtl.state().scene").await?;
    for (list, dx, dy) in [
        ("transmitters", 30.0, -20.0),
        ("receivers", -25.0, 15.0),
        ("targets", 20.0, 20.0),
    ] {
        let p: [f64; 2] = serde_json::from_value(s[list][0].clone()).map_err(|e| e.to_string())?;
        let a = at(c, p[0], p[1]).await?;
        drag_on_plot(c, a, &[(dx, dy, 200)]).await?;
        wait_view(c, 60).await?;
    }
    click(c, "zoom-in").await?;
    wait_view(c, 60).await?;
    quiet(c).await?;
    Ok(())
}

/// Every field set through the page's controls comes back exactly from the link and from the
/// state file; a state file with one bad field is named in the banner and changes nothing.
#[test]
#[ignore = "needs chromium + chromedriver and www/pkg (wasm-pack build); run with --ignored"]
fn state_file_and_link_restore_every_field() {
    let file =
        std::env::temp_dir().join(format!("scatterloc-e2e-state-{}.json", std::process::id()));
    let bad_file = std::env::temp_dir().join(format!(
        "scatterloc-e2e-bad-state-{}.json",
        std::process::id()
    ));
    let (file2, bad2) = (file.clone(), bad_file.clone());
    let o = session(|c, port| async move {
        open(&c, port).await?;
        quiet(&c).await?;
        let defaults = capture(&c).await?;
        set_everything(&c).await?;
        let set = capture(&c).await?;
        let set_banner = banner(&c).await?;
        // Save state (the file's text, as downloaded) and Copy link.
        js(&c, "window.pageStateModel.setDryRun(true)").await?;
        click(&c, "state-save").await?;
        let saved = js(&c, "return window.pageStateModel.lastSaved()").await?;
        let text = saved["text"].as_str().unwrap_or_default().to_string();
        std::fs::write(&file2, &text).map_err(|e| e.to_string())?;
        click(&c, "share-copy").await?;
        let t0 = Instant::now();
        let link = loop {
            let v = js(&c, "return document.getElementById('share-url').value").await?;
            if let Some(s) = v.as_str().filter(|s| !s.is_empty()) {
                break s.to_string();
            }
            if t0.elapsed() > Duration::from_secs(10) {
                return Err("no link shown".into());
            }
            tokio::time::sleep(Duration::from_millis(25)).await;
        };
        // The link, as a fresh page.
        open_url(&c, &link).await?;
        wait_view(&c, 60).await?;
        quiet(&c).await?;
        let from_link = capture(&c).await?;
        let link_banner = banner(&c).await?;
        // The file, opened in a fresh page through the file input.
        open(&c, port).await?;
        quiet(&c).await?;
        c.find(Locator::Id("state-file"))
            .await
            .map_err(|e| e.to_string())?
            .send_keys(file2.to_str().unwrap())
            .await
            .map_err(|e| e.to_string())?;
        let t0 = Instant::now();
        while capture(&c).await?["mode"] != "mtl" {
            if t0.elapsed() > Duration::from_secs(20) {
                return Err(format!(
                    "the state file was not opened: {}",
                    banner(&c).await?
                ));
            }
            tokio::time::sleep(Duration::from_millis(30)).await;
        }
        wait_view(&c, 60).await?;
        quiet(&c).await?;
        let from_file = capture(&c).await?;
        let file_banner = banner(&c).await?;
        // One bad field (after a good change in an earlier section): named, nothing changed.
        let mut bad: Value = serde_json::from_str(&text).map_err(|e| e.to_string())?;
        bad["grid"]["res"] = json!(512);
        bad["tracking"]["dt"] = json!(0.3);
        std::fs::write(&bad2, bad.to_string()).map_err(|e| e.to_string())?;
        c.find(Locator::Id("state-file"))
            .await
            .map_err(|e| e.to_string())?
            .send_keys(bad2.to_str().unwrap())
            .await
            .map_err(|e| e.to_string())?;
        let t0 = Instant::now();
        let mut bad_banner = String::new();
        while bad_banner.is_empty() && t0.elapsed() < Duration::from_secs(10) {
            tokio::time::sleep(Duration::from_millis(30)).await;
            bad_banner = banner(&c).await?;
        }
        quiet(&c).await?;
        let after_bad = capture(&c).await?;
        Ok(json!({
            "defaults": defaults, "set": set, "set_banner": set_banner, "link": link,
            "from_link": from_link, "link_banner": link_banner, "from_file": from_file,
            "file_banner": file_banner, "bad_banner": bad_banner, "after_bad": after_bad,
            "file_name": saved["name"], "errors": console_errors(&c).await?,
        }))
    });
    let _ = std::fs::remove_file(&file);
    let _ = std::fs::remove_file(&bad_file);
    let (d, s) = (&o["defaults"], &o["set"]);
    println!(
        "e2e: state {} bytes as a file ({}), link of {} characters",
        s.to_string().len(),
        o["file_name"],
        o["link"].as_str().unwrap_or_default().len()
    );
    assert_eq!(o["set_banner"], "", "no banner while setting the fields");
    assert_eq!(o["link_banner"], "", "no banner on opening the link");
    assert_eq!(o["file_banner"], "", "no banner on opening the file");
    assert_eq!(o["errors"], json!([]), "console errors");
    // The state's fields are exactly these (and the default scene's keys under mtl.scene).
    let mut paths = Vec::new();
    leaves(s, "", &mut paths);
    let mut want: Vec<String> = FIELDS.iter().map(|f| f.to_string()).collect();
    let scene_keys: Vec<String> = d["mtl"]["scene"]
        .as_object()
        .expect("a scene")
        .keys()
        .map(|k| format!("mtl.scene.{k}"))
        .collect();
    assert!(scene_keys.len() >= 15, "{scene_keys:?}");
    want.extend(scene_keys);
    let mut got: Vec<String> = paths.iter().map(|(p, _)| p.clone()).collect();
    want.sort();
    got.sort();
    assert_eq!(got, want, "the state's fields");
    for (path, value) in &paths {
        if !NO_CONTROL.contains(&path.as_str()) {
            assert_ne!(
                value,
                at_path(d, path),
                "{path}: set to a non-default value"
            );
        }
        assert_eq!(
            at_path(&o["from_link"], path),
            value,
            "{path}: from the link"
        );
        assert_eq!(
            at_path(&o["from_file"], path),
            value,
            "{path}: from the state file"
        );
    }
    assert_eq!(s["mode"], "mtl");
    assert_eq!(s["tracking"]["mc_filters"], json!(["ukf", "pf"]));
    assert!(s["view"]["step"].as_u64().unwrap_or(0) > 0, "{}", s["view"]);
    let b = o["bad_banner"].as_str().unwrap_or_default();
    assert!(b.contains("state.tracking.dt") && b.contains("0.3"), "{b}");
    assert_eq!(
        o["after_bad"], o["from_file"],
        "a bad state file changes nothing"
    );
}

/// Waits for the plan to end (no glide left).
async fn plan_done(c: &Client) -> Result<Value, String> {
    let t0 = Instant::now();
    loop {
        let s = js(c, "return window.plan.state()").await?;
        if (s["state"] == "done" || s["state"] == "error") && s["gliding"] == false {
            return Ok(s);
        }
        if t0.elapsed() > Duration::from_secs(120) {
            return Err(format!("plan did not finish: {s}"));
        }
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
}

/// Undo and redo of every kind of edit: each undo restores the exact state before the edit
/// (numbers to 1e-12), redo the state after it.
#[test]
#[ignore = "needs chromium + chromedriver and www/pkg (wasm-pack build); run with --ignored"]
fn undo_and_redo_restore_every_kind_of_edit() {
    let scenario = scatterloc::scenario::presets::iclgnss2019()
        .to_json()
        .replace("\"iclgnss2019\"", "\"imported\"");
    let file =
        std::env::temp_dir().join(format!("scatterloc-e2e-undo-{}.json", std::process::id()));
    std::fs::write(&file, &scenario).unwrap();
    let file2 = file.clone();
    let o = session(|c, port| async move {
        open(&c, port).await?;
        quiet(&c).await?;
        let mut steps = Vec::new();
        // [name, before, after, after undo, after redo, history index before, after].
        async fn record(
            c: &Client,
            steps: &mut Vec<Value>,
            name: &str,
            before: Value,
            i0: i64,
            how: &str,
        ) -> Result<(), String> {
            quiet(c).await?;
            let after = doc(c).await?;
            let i1 = history_index(c).await?;
            match how {
                "keys" => {
                    js(c, "document.getElementById('plot').focus()").await?;
                    press(c, &[CONTROL], &['z']).await?;
                }
                _ => click(c, "undo").await?,
            }
            quiet(c).await?;
            let undone = doc(c).await?;
            match how {
                "keys" => press(c, &[SHIFT, CONTROL], &['z']).await?,
                _ => click(c, "redo").await?,
            }
            quiet(c).await?;
            let redone = doc(c).await?;
            steps.push(json!([name, before, after, undone, redone, i0, i1]));
            Ok(())
        }
        // An import (the page has no unsaved edits yet: no question).
        let (b, i) = (doc(&c).await?, history_index(&c).await?);
        c.find(Locator::Id("import-file"))
            .await
            .map_err(|e| e.to_string())?
            .send_keys(file2.to_str().unwrap())
            .await
            .map_err(|e| e.to_string())?;
        let t0 = Instant::now();
        while !js(&c, "return window.app.scenario().name === 'imported'")
            .await?
            .as_bool()
            .unwrap_or(false)
        {
            if t0.elapsed() > Duration::from_secs(10) {
                return Err(format!("import failed: {}", banner(&c).await?));
            }
            tokio::time::sleep(Duration::from_millis(30)).await;
        }
        record(&c, &mut steps, "import", b, i, "buttons").await?;
        // A node drag (many moves: one step).
        let (b, i) = (doc(&c).await?, history_index(&c).await?);
        let r = js(
            &c,
            "const r = window.app.nodes().receivers[0]; return [r.x, r.y]",
        )
        .await?;
        let a = at(&c, r[0].as_f64().unwrap(), r[1].as_f64().unwrap()).await?;
        drag_on_plot(
            &c,
            a,
            &[(15.0, 10.0, 100), (15.0, 10.0, 100), (10.0, -5.0, 100)],
        )
        .await?;
        record(&c, &mut steps, "node drag", b, i, "keys").await?;
        // A keyboard move (Shift+Right: 1 m).
        let (b, i) = (doc(&c).await?, history_index(&c).await?);
        js(&c, "document.getElementById('plot').focus()").await?;
        press(&c, &[SHIFT], &[RIGHT]).await?;
        record(&c, &mut steps, "keyboard move", b, i, "keys").await?;
        // Ctrl+Z in a text field is the field's own: the page's state stays.
        let (b, i) = (doc(&c).await?, history_index(&c).await?);
        click(&c, "rx-gain").await?;
        press(&c, &[CONTROL], &['z']).await?;
        quiet(&c).await?;
        let in_field = json!([history_index(&c).await? == i, doc(&c).await? == b]);
        // A panel edit.
        type_in(&c, "bandwidth", "250").await?;
        record(&c, &mut steps, "panel edit", b, i, "buttons").await?;
        // A target placement.
        let (b, i) = (doc(&c).await?, history_index(&c).await?);
        drag_on_plot(&c, empty_at(&c, 0.4, 0.55).await?, &[]).await?;
        record(&c, &mut steps, "target placement", b, i, "keys").await?;
        // Optimize (its own Undo button is the history's too).
        click(&c, "plan-toggle").await?;
        type_in(&c, "plan-budget", "1000").await?;
        quiet(&c).await?;
        let (b, i) = (doc(&c).await?, history_index(&c).await?);
        click(&c, "plan-run").await?;
        let plan = plan_done(&c).await?;
        record(&c, &mut steps, "optimize", b.clone(), i, "keys").await?;
        click(&c, "plan-undo").await?;
        quiet(&c).await?;
        let plan_undo = json!([plan, doc(&c).await?, b]);
        // A tracking setting.
        click(&c, "mode-tracking").await?;
        quiet(&c).await?;
        let (b, i) = (doc(&c).await?, history_index(&c).await?);
        select(&c, "track-dt", "0.02").await?;
        record(&c, &mut steps, "tracking setting", b, i, "buttons").await?;
        // A multi-target drag of a target, and of a slider.
        click(&c, "mode-mtl").await?;
        wait_view(&c, 60).await?;
        quiet(&c).await?;
        let (b, i) = (doc(&c).await?, history_index(&c).await?);
        let t = js(&c, "return window.mtl.state().scene.targets[0]").await?;
        let a = at(&c, t[0].as_f64().unwrap(), t[1].as_f64().unwrap()).await?;
        drag_on_plot(
            &c,
            a,
            &[(-12.0, 9.0, 80), (-12.0, 9.0, 80), (-12.0, 9.0, 80)],
        )
        .await?;
        wait_view(&c, 60).await?;
        record(&c, &mut steps, "multi-target drag", b, i, "keys").await?;
        let (b, i) = (doc(&c).await?, history_index(&c).await?);
        let slider = c
            .find(Locator::Id("mtl-tb"))
            .await
            .map_err(|e| e.to_string())?;
        slider.click().await.map_err(|e| e.to_string())?;
        wait_view(&c, 60).await?;
        record(&c, &mut steps, "multi-target slider", b, i, "buttons").await?;
        Ok(
            json!({"steps": steps, "in_field": in_field, "plan_undo": plan_undo,
            "errors": console_errors(&c).await?, "banner": banner(&c).await?}),
        )
    });
    let _ = std::fs::remove_file(&file);
    for s in o["steps"].as_array().unwrap() {
        let name = s[0].as_str().unwrap();
        println!("e2e: undo/redo {name}: history {} -> {}", s[5], s[6]);
        assert_ne!(s[1], s[2], "{name}: the edit changed the state");
        assert_eq!(
            s[6].as_i64().unwrap(),
            s[5].as_i64().unwrap() + 1,
            "{name}: one undo step"
        );
        assert!(
            close(&s[3], &s[1]),
            "{name}: undo restores the state before\n{}\n{}",
            s[3],
            s[1]
        );
        assert!(
            close(&s[4], &s[2]),
            "{name}: redo reapplies the edit\n{}\n{}",
            s[4],
            s[2]
        );
    }
    assert_eq!(o["steps"].as_array().unwrap().len(), 9);
    let f = &o["in_field"];
    assert_eq!(
        f,
        &json!([true, true]),
        "Ctrl+Z in a text field does not undo the page"
    );
    let p = &o["plan_undo"];
    assert_eq!(
        p[0]["kept"], false,
        "the plan found a better layout: {}",
        p[0]
    );
    assert!(
        close(&p[1], &p[2]),
        "the Plan panel's Undo restores the state before Optimize"
    );
    assert_eq!(o["banner"], "");
    assert_eq!(o["errors"], json!([]), "console errors");
}

/// Switching the scenario with unsaved edits asks first (the page's dialog): Cancel keeps
/// everything, Replace loads the preset; with no edits it does not ask.
#[test]
#[ignore = "needs chromium + chromedriver and www/pkg (wasm-pack build); run with --ignored"]
fn scenario_switch_over_unsaved_edits_asks_first() {
    let o = session(|c, port| async move {
        open(&c, port).await?;
        quiet(&c).await?;
        let dialog = "return document.getElementById('confirm-dialog').open";
        // No edits: no question.
        select(&c, "preset", "iclgnss2019").await?;
        quiet(&c).await?;
        let clean = json!([
            js(&c, dialog).await?,
            js(&c, "return window.app.scenario().name").await?
        ]);
        type_in(&c, "carrier", "31").await?;
        quiet(&c).await?;
        let edited = doc(&c).await?;
        select(&c, "preset", "sensors2019").await?;
        quiet(&c).await?;
        let asked = json!([
            js(&c, dialog).await?,
            js(
                &c,
                "return document.getElementById('confirm-text').textContent"
            )
            .await?
        ]);
        click(&c, "confirm-cancel").await?;
        quiet(&c).await?;
        let cancelled = json!([
            js(&c, dialog).await?,
            doc(&c).await? == edited,
            js(&c, "return document.getElementById('preset').value").await?
        ]);
        select(&c, "preset", "sensors2019").await?;
        quiet(&c).await?;
        let asked_again = js(&c, dialog).await?;
        click(&c, "confirm-ok").await?;
        quiet(&c).await?;
        let replaced = json!([
            js(&c, dialog).await?,
            js(&c, "return window.app.scenario_json()").await?,
            js(&c, "return window.wasm.preset_json('sensors2019')").await?,
            js(&c, "return document.getElementById('preset').value").await?
        ]);
        Ok(
            json!({"clean": clean, "asked": asked, "cancelled": cancelled, "asked_again": asked_again,
            "replaced": replaced, "errors": console_errors(&c).await?}),
        )
    });
    println!("e2e: confirm: {}", o["asked"][1]);
    assert_eq!(
        o["clean"],
        json!([false, "iclgnss2019"]),
        "no question without edits"
    );
    assert_eq!(o["asked"][0], true, "the dialog asks");
    assert!(o["asked"][1]
        .as_str()
        .unwrap_or_default()
        .contains("sensors2019"));
    assert_eq!(
        o["cancelled"],
        json!([false, true, ""]),
        "Cancel keeps everything"
    );
    assert_eq!(o["asked_again"], true);
    let r = &o["replaced"];
    assert_eq!(r[0], false);
    let j = |v: &Value| serde_json::from_str::<Value>(v.as_str().unwrap_or_default()).unwrap();
    assert_eq!(j(&r[1]), j(&r[2]), "Replace loads the preset");
    assert_eq!(r[3], "sensors2019");
    assert_eq!(o["errors"], json!([]), "console errors");
}

/// An Optimize that finds no better layout (coverage at a threshold no cell reaches) keeps the
/// current layout exactly, says so, and adds no undo step.
#[test]
#[ignore = "needs chromium + chromedriver and www/pkg (wasm-pack build); run with --ignored"]
fn optimize_without_improvement_keeps_the_layout_and_says_so() {
    let o = session(|c, port| async move {
        open(&c, port).await?;
        quiet(&c).await?;
        click(&c, "plan-toggle").await?;
        select(&c, "plan-objective", "coverage").await?;
        type_in(&c, "plan-t", "0.000001").await?;
        type_in(&c, "plan-budget", "200").await?;
        quiet(&c).await?;
        let before = json!([
            js(&c, "return window.app.scenario_json()").await?,
            history_index(&c).await?
        ]);
        click(&c, "plan-run").await?;
        let plan = plan_done(&c).await?;
        quiet(&c).await?;
        let after = json!([
            js(&c, "return window.app.scenario_json()").await?,
            history_index(&c).await?
        ]);
        let text = js(&c, "return [document.getElementById('plan-result').textContent, \
            document.getElementById('plan-status').textContent, document.getElementById('plan-undo').disabled]").await?;
        Ok(
            json!({"before": before, "after": after, "plan": plan, "text": text,
            "errors": console_errors(&c).await?}),
        )
    });
    println!(
        "e2e: optimize without improvement: {} · {}",
        o["text"][0], o["text"][1]
    );
    assert_eq!(o["plan"]["state"], "done", "{}", o["plan"]);
    assert_eq!(o["plan"]["kept"], true);
    assert_eq!(o["after"][0], o["before"][0], "the layout is kept exactly");
    assert_eq!(o["after"][1], o["before"][1], "no undo step");
    assert!(o["text"][0]
        .as_str()
        .unwrap_or_default()
        .contains("No better layout found"));
    assert!(o["text"][1]
        .as_str()
        .unwrap_or_default()
        .contains("no better layout found"));
    assert_eq!(o["text"][2], true, "nothing to undo");
    assert_eq!(o["errors"], json!([]), "console errors");
}
