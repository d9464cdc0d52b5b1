//! Issue 38 §6, §7, §9 in the channel view, with real input (files chosen through the file
//! inputs, a mouse drag, the keyboard, typed settings) on recordings the CLI simulates:
//!
//! - §6: after Run, a node dragged or moved with the keyboard, a setting changed and another
//!   recording opened each mark the result stale — the status line names the change ("stale:
//!   Rx2 moved …"), the map draws the track faded and dashed, the charts are faded — until Run
//!   again.
//! - §7: the delay picture of a 1528-snapshot recording: one colour bar, the time cursor in a
//!   colour of its own that the legend shows, the truth over the estimates, the static estimates
//!   grey as the legend and the docs say, the range axis robust to the outliers (those beyond it
//!   counted and marked), and the saved SVG small (the bytes printed, capped at 2 MB).
//! - §9: a recording with a link the scenario lacks and a truth file of another length are
//!   named in the banner when opened; the "Empty area" line follows its from/to fields as they
//!   are typed; the progress reports every phase after the estimates (track, figure, the results
//!   handed over, read and drawn on the page) instead of sitting at 95 % with the last count.

use std::path::Path;
use std::time::{Duration, Instant};

use fantoccini::{Client, Locator};
use serde_json::Value;

use super::channel::cli;
use super::ui::{banner, channel_state, keys, temp_dir, wait_channel, RIGHT};
use super::{console_errors, drag_on_plot, js, open_hash, settle, with_browser};

const TAB: &str = "\u{E004}";
const ENTER: &str = "\u{E007}";

/// `cir simulate` of `scenario` (a file in `dir`) into `dir/out`: `duration` s at `dt` s.
fn simulate(dir: &Path, scenario: &str, out: &str, duration: &str, dt: &str, seed: &str) -> Value {
    let p = |n: &str| dir.join(n).to_string_lossy().into_owned();
    let sim = cli(&[
        "cir",
        "simulate",
        "--scenario",
        &p(scenario),
        "--out-dir",
        &p(out),
        "--duration",
        duration,
        "--dt",
        dt,
        "--calibration-duration",
        "0.4",
        "--seed",
        seed,
    ]);
    serde_json::from_slice(&sim).unwrap()
}

/// The page's sensors2019 preset as a file in `dir` (the scenario the page opens with).
fn preset(dir: &Path) {
    let s = cli(&["preset", "sensors2019"]);
    std::fs::write(dir.join("s.json"), s).unwrap();
}

/// Chooses `path` in the file input `id` (chromedriver types the path, as a user picks it) and
/// waits until the view has read it (`key` of the state names it, or the banner shows).
pub(crate) async fn choose(c: &Client, id: &str, path: &Path, key: &str) -> Result<String, String> {
    js(c, "document.getElementById('error-close').click()").await?;
    let name = path.file_name().unwrap().to_string_lossy().into_owned();
    c.find(Locator::Id(id))
        .await
        .map_err(|e| e.to_string())?
        .send_keys(path.to_str().unwrap())
        .await
        .map_err(|e| format!("{id}: {e}"))?;
    let t0 = Instant::now();
    loop {
        let s = channel_state(c).await?;
        let named = match &s[key] {
            Value::String(n) => n == &name,
            Value::Object(o) => o.get("name").and_then(Value::as_str) == Some(name.as_str()),
            _ => false,
        };
        let b = banner(c).await?;
        if named || !b.is_empty() {
            return Ok(b);
        }
        if t0.elapsed() > Duration::from_secs(30) {
            return Err(format!("{id}: {name} not read; state {s}"));
        }
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
}

/// Presses Run and waits for run number `n` to be shown.
async fn run(c: &Client, n: u64) -> Result<Value, String> {
    js(c, "document.getElementById('chan-run').click()").await?;
    wait_channel(c, 600, "run", |s| s["runs"] == n && s["running"].is_null()).await
}

/// What the stale checks read after each change.
fn stale_of(s: &Value) -> (Vec<String>, String, String, Option<bool>) {
    (
        serde_json::from_value(s["stale"].clone()).unwrap_or_default(),
        s["status"].as_str().unwrap_or_default().to_string(),
        s["statusState"].as_str().unwrap_or_default().to_string(),
        s["drawn"]["stale"].as_bool(),
    )
}

async fn figures_faded(c: &Client) -> Result<bool, String> {
    Ok(js(
        c,
        "const c = document.getElementById('chan-delays'); \
         return document.getElementById('chan-figures').classList.contains('stale') \
           && Number(getComputedStyle(c).opacity) < 1;",
    )
    .await?
    .as_bool()
    .unwrap_or(false))
}

/// Asserts the result is marked stale for `change` (status, map, charts) and returns the state.
async fn assert_stale(c: &Client, change: &str) -> Result<(), String> {
    settle(c).await?;
    let s = channel_state(c).await?;
    let (reasons, status, st, drawn) = stale_of(&s);
    if !reasons.iter().any(|r| r == change)
        || !status.starts_with("stale: ")
        || !status.contains(change)
        || st != "stale"
        || drawn != Some(true)
        || !figures_faded(c).await?
    {
        return Err(format!(
            "not marked stale for {change:?}: reasons {reasons:?}, status {status:?} ({st}), \
             map drawn stale {drawn:?}, charts faded {}",
            figures_faded(c).await?
        ));
    }
    Ok(())
}

/// Asserts the result shown is current (after a Run).
async fn assert_current(c: &Client) -> Result<(), String> {
    settle(c).await?;
    let s = channel_state(c).await?;
    let (reasons, status, st, drawn) = stale_of(&s);
    if !reasons.is_empty() || !status.starts_with("Done in") || st != "done" || drawn != Some(false)
    {
        return Err(format!(
            "not current: reasons {reasons:?}, status {status:?} ({st}), map stale {drawn:?}"
        ));
    }
    if figures_faded(c).await? {
        return Err("charts still faded".into());
    }
    Ok(())
}

/// Issue 38 §6: every change that invalidates a result — a node dragged, a node moved with the
/// keyboard, a setting typed, another recording opened — marks it stale in the status line
/// (naming the change), on the map (track faded and dashed) and on the charts, until Run.
#[test]
#[ignore = "needs chromium + chromedriver and www/pkg (wasm-pack build); run with --ignored"]
fn channel_result_goes_stale_on_every_change() {
    let dir = temp_dir("page-channel-stale");
    preset(&dir);
    simulate(&dir, "s.json", "a", "2.98", "0.02", "1");
    simulate(&dir, "s.json", "b", "2.98", "0.02", "2");
    std::fs::copy(dir.join("b/recording.npz"), dir.join("walk-b.npz")).unwrap();
    let errors = with_browser(async |c, port, _| {
        open_hash(c, port, "#mode=channel").await?;
        settle(c).await?;
        choose(c, "chan-file", &dir.join("a/recording.npz"), "recording").await?;
        choose(
            c,
            "chan-cal-file",
            &dir.join("a/calibration.npz"),
            "calibration",
        )
        .await?;
        choose(c, "chan-truth-file", &dir.join("a/truth.json"), "truth").await?;
        run(c, 1).await?;
        assert_current(c).await?;

        // 1. Rx2 dragged with the mouse.
        let g: Vec<f64> = serde_json::from_value(
            js(
                c,
                "const r = window.app.nodes().receivers[1]; const p = window.view.toPixel(r.x, r.y); \
                 const b = document.getElementById('plot').getBoundingClientRect(); \
                 return [p.x, p.y, b.width, b.height];",
            )
            .await?,
        )
        .map_err(|e| e.to_string())?;
        drag_on_plot(
            c,
            [g[0] - g[2] / 2.0, g[1] - g[3] / 2.0],
            &[(40.0, 30.0, 300)],
        )
        .await?;
        assert_stale(c, "Rx2 moved").await?;
        run(c, 2).await?;
        assert_current(c).await?;

        // 2. A node moved with the keyboard (Tab selects one, → moves it by 0.1 m).
        js(c, "document.getElementById('plot').focus()").await?;
        keys(c, "plot", TAB).await?;
        keys(c, "plot", RIGHT).await?;
        settle(c).await?;
        let moved: Vec<String> = serde_json::from_value(channel_state(c).await?["stale"].clone())
            .map_err(|e| e.to_string())?;
        let node = moved
            .iter()
            .find(|r| r.ends_with(" moved") && (r.starts_with("Tx") || r.starts_with("Rx")))
            .ok_or_else(|| format!("no node named as moved after the arrow key: {moved:?}"))?
            .clone();
        assert_stale(c, &node).await?;
        run(c, 3).await?;
        assert_current(c).await?;

        // 3. A setting typed (P_fa, committed with Enter).
        let pfa = c
            .find(Locator::Id("chan-pfa"))
            .await
            .map_err(|e| e.to_string())?;
        pfa.clear().await.map_err(|e| e.to_string())?;
        pfa.send_keys(&format!("0.01{ENTER}"))
            .await
            .map_err(|e| e.to_string())?;
        assert_stale(c, "P_fa changed").await?;
        run(c, 4).await?;
        assert_current(c).await?;

        // 4. Another recording opened: the result stays, marked stale.
        choose(c, "chan-file", &dir.join("walk-b.npz"), "recording").await?;
        assert_stale(c, "recording walk-b.npz opened").await?;
        let s = channel_state(c).await?;
        assert!(
            s["steps"].as_u64().unwrap_or(0) > 0,
            "the stale result stays shown"
        );
        run(c, 5).await?;
        assert_current(c).await?;
        console_errors(c).await
    });
    let _ = std::fs::remove_dir_all(&dir);
    assert!(errors.is_empty(), "console errors: {errors:?}");
}

/// The RGB of a CSS colour text `rgb(r, g, b)` / `rgba(…)`.
fn css_rgb(v: &Value) -> Vec<u64> {
    v.as_str()
        .unwrap_or_default()
        .trim_start_matches("rgba(")
        .trim_start_matches("rgb(")
        .trim_end_matches(')')
        .split(',')
        .take(3)
        .map(|x| x.trim().parse().unwrap_or(999))
        .collect()
}

/// Issue 38 §7: the delay picture of a 1528-snapshot recording (76.35 s at 50 ms, as the
/// issue's): one colour bar, a time cursor colour of its own shown by the legend, the truth
/// over the estimates, the static estimates grey (legend, picture and docs agree), every link's
/// range axis robust to the outliers (the estimates beyond it counted in the panel), and the
/// saved SVG under 2 MB.
#[test]
#[ignore = "needs chromium + chromedriver and www/pkg (wasm-pack build); run with --ignored"]
fn delays_picture_is_readable_and_small() {
    let dir = temp_dir("page-channel-delays");
    preset(&dir);
    let sum = simulate(&dir, "s.json", "long", "76.35", "0.05", "1");
    assert_eq!(sum["snapshots"], 1528, "{sum}");
    let o = with_browser(async |c, port, _| {
        open_hash(c, port, "#mode=channel").await?;
        settle(c).await?;
        js(c, "window.figureExport.setDryRun(true)").await?;
        choose(c, "chan-file", &dir.join("long/recording.npz"), "recording").await?;
        choose(c, "chan-truth-file", &dir.join("long/truth.json"), "truth").await?;
        let done = run(c, 1).await?;
        // The cursor at snapshot 700 (keyboard: End, then back is slow; set it as the slider does).
        js(
            c,
            "const s = document.getElementById('chan-scrub'); s.value = '700'; \
             s.dispatchEvent(new Event('input'));",
        )
        .await?;
        settle(c).await?;
        let s = channel_state(c).await?;
        let cursor = js(
            c,
            "const st = window.channel.state(); const cv = document.getElementById('chan-delays-cursor'); \
             const x = Math.round(st.cursorX.delays); const y = Math.round((st.delayBox.y_px[0] + st.delayBox.y_px[1]) / 2); \
             const d = cv.getContext('2d').getImageData(x - 1, y, 3, 1).data; \
             let best = null; for (let i = 0; i < 3; i++) { if (d[4 * i + 3] > 200) best = [d[4 * i], d[4 * i + 1], d[4 * i + 2]]; } \
             const sw = (c) => getComputedStyle(document.querySelector('#chan-delays-legend .sym.' + c)); \
             return { pixel: best, legend: sw('chan-cursor-sym').backgroundColor, \
               truth: sw('chan-truth').borderTopColor, est: sw('chan-est').backgroundColor, \
               stat: sw('chan-est-static').backgroundColor };",
        )
        .await?;
        let texts = js(c, "return window.channel.texts()").await?;
        let figure: Value = serde_json::from_str(texts["figure"].as_str().unwrap_or("null"))
            .map_err(|e| e.to_string())?;
        // The SVG as saved (through its download link).
        js(
            c,
            "document.getElementById('chan-save-what').value = 'delays-svg'; \
             document.getElementById('chan-save').click();",
        )
        .await?;
        let t0 = Instant::now();
        while js(
            c,
            "return Number(document.getElementById('chan-save').dataset.count || 0)",
        )
        .await?
        .as_u64()
            != Some(1)
        {
            if t0.elapsed() > Duration::from_secs(60) {
                return Err(format!("no SVG saved (banner {:?})", banner(c).await?));
            }
            tokio::time::sleep(Duration::from_millis(50)).await;
        }
        let svg = c
            .execute_async(
                "const done = arguments[arguments.length - 1]; \
                 fetch(window.figureExport.last().href).then((r) => r.text()).then(done, (e) => done('error ' + e));",
                vec![],
            )
            .await
            .map_err(|e| e.to_string())?;
        js(
            c,
            "document.getElementById('chan-figures').scrollIntoView()",
        )
        .await?;
        if let Ok(png) = c.screenshot().await {
            let _ = std::fs::write(
                std::env::temp_dir().join("scatterloc-e2e-page-channel-delays.png"),
                png,
            );
        }
        Ok((
            done,
            s,
            cursor,
            figure,
            svg.as_str().unwrap_or_default().to_string(),
            console_errors(c).await?,
        ))
    });
    let _ = std::fs::remove_dir_all(&dir);
    let (done, s, cursor, figure, svg, errors) = o;
    println!(
        "timings of the 1528-snapshot run: {} (wall {} ms)",
        done["timings"], done["wallMs"]
    );
    println!(
        "progress: {}",
        done["progressLog"].as_array().map_or(0, Vec::len)
    );
    assert!(errors.is_empty(), "console errors: {errors:?}");
    assert_eq!(s["step"], 700);

    // The cursor: its own colour, the legend's, not the truth's.
    let pixel: Vec<u64> = serde_json::from_value(cursor["pixel"].clone()).unwrap_or_default();
    let legend = css_rgb(&cursor["legend"]);
    let truth = css_rgb(&cursor["truth"]);
    assert_eq!(
        pixel, legend,
        "cursor drawn {pixel:?}, legend {legend:?}: {cursor}"
    );
    assert_eq!(
        truth,
        vec![213, 94, 0],
        "the legend's truth is the chart's vermillion"
    );
    assert_ne!(legend, truth, "the cursor is not in the truth's colour");
    // The legend's estimate colours are the chart's (chart::channel ESTIMATE_RGB, STATIC_ESTIMATE_RGB).
    assert_eq!(css_rgb(&cursor["est"]), vec![0, 114, 178]);
    assert_eq!(css_rgb(&cursor["stat"]), vec![150, 150, 150]);

    // The docs say the same.
    let docs = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/page.md"))
        .unwrap()
        .split_whitespace()
        .collect::<Vec<_>>()
        .join(" ");
    for words in [
        "estimated paths as blue dots",
        "grey inside a static cluster",
        "the truth dashed in vermillion",
        "magenta",
    ] {
        assert!(docs.contains(words), "docs/page.md does not say {words:?}");
    }

    // Robust axes: every link's axis within the walk's path lengths (the CLI's figure of this
    // recording stretched two links to 150 m and 370 m for one outlier each).
    let links = figure["links"].as_array().unwrap();
    let mut off = 0;
    for l in links {
        let r: Vec<f64> = serde_json::from_value(l["range_m"].clone()).unwrap();
        assert!(r[1] < 100.0, "{}: axis {r:?}", l["name"]);
        off += l["estimates"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|e| {
                let v = e["range_m"].as_f64().unwrap();
                v < r[0] || v > r[1]
            })
            .count();
    }
    println!("estimates beyond the robust axes: {off}");

    // The SVG: small, one colour bar, the estimates in the PNGs, the outliers marked.
    println!(
        "delays SVG of the 1528-snapshot recording: {} bytes",
        svg.len()
    );
    assert!(svg.len() < 2_000_000, "{} bytes", svg.len());
    let doc = roxmltree::Document::parse(&svg)
        .map_err(|e| e.to_string())
        .unwrap();
    let texts: Vec<String> = doc
        .descendants()
        .filter(|n| n.has_tag_name("text"))
        .map(|n| n.text().unwrap_or("").trim().to_string())
        .collect();
    assert_eq!(
        texts.iter().filter(|t| *t == "response power (dB)").count(),
        1,
        "{texts:?}"
    );
    assert!(
        !texts.iter().any(|t| t.contains("amplitude")),
        "a second colour bar: {texts:?}"
    );
    assert!(
        doc.descendants()
            .filter(|n| n.has_tag_name("circle"))
            .count()
            <= 4
    );
    assert_eq!(
        doc.descendants()
            .filter(|n| n.has_tag_name("image"))
            .count(),
        links.len()
    );
    if off > 0 {
        assert!(
            texts.iter().any(|t| t.contains("off the axis")),
            "{texts:?}"
        );
    }
}

/// Issue 38 §9: a recording with a link the scenario lacks and a truth file of another length
/// are named in the banner at open (and not taken); the "Empty area" line follows the from/to
/// fields as they are typed; the progress of a run reports every phase after the estimates in
/// order, the bar never going back, and never ends on the estimates' last count.
#[test]
#[ignore = "needs chromium + chromedriver and www/pkg (wasm-pack build); run with --ignored"]
fn bad_files_are_named_at_open_and_progress_is_honest() {
    let dir = temp_dir("page-channel-open");
    preset(&dir);
    // A scenario with a fifth receiver: its recording has link (Tx, Rx5), the page's lacks it.
    let mut five: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("s.json")).unwrap()).unwrap();
    let mut rx5 = five["receivers"][0].clone();
    rx5["name"] = "Rx5".into();
    rx5["position_m"] = serde_json::json!([4.0, -9.0]);
    five["receivers"].as_array_mut().unwrap().push(rx5);
    std::fs::write(dir.join("five.json"), five.to_string()).unwrap();
    simulate(&dir, "five.json", "five", "1.98", "0.02", "1");
    simulate(&dir, "s.json", "a", "2.98", "0.02", "1");
    simulate(&dir, "s.json", "other", "1.98", "0.02", "1");
    let o = with_browser(async |c, port, _| {
        open_hash(c, port, "#mode=channel").await?;
        settle(c).await?;
        let links = choose(c, "chan-file", &dir.join("five/recording.npz"), "recording").await?;
        let after_links = channel_state(c).await?;
        choose(c, "chan-file", &dir.join("a/recording.npz"), "recording").await?;
        let truth = choose(c, "chan-truth-file", &dir.join("other/truth.json"), "truth").await?;
        let after_truth = channel_state(c).await?;
        // The empty area as a time range; "to" typed, not yet committed.
        js(
            c,
            "const s = document.getElementById('chan-cal-source'); s.value = 'range'; \
             s.dispatchEvent(new Event('change'));",
        )
        .await?;
        let to = c
            .find(Locator::Id("chan-empty-to"))
            .await
            .map_err(|e| e.to_string())?;
        to.clear().await.map_err(|e| e.to_string())?;
        to.send_keys("0.5").await.map_err(|e| e.to_string())?;
        let line_typed = js(
            c,
            "return document.getElementById('chan-inputs').textContent",
        )
        .await?;
        to.send_keys(ENTER).await.map_err(|e| e.to_string())?;
        let from = c
            .find(Locator::Id("chan-empty-from"))
            .await
            .map_err(|e| e.to_string())?;
        from.clear().await.map_err(|e| e.to_string())?;
        from.send_keys("0.1").await.map_err(|e| e.to_string())?;
        let line_from = js(
            c,
            "return document.getElementById('chan-inputs').textContent",
        )
        .await?;
        from.send_keys(ENTER).await.map_err(|e| e.to_string())?;
        let done = run(c, 1).await?;
        Ok((
            links,
            after_links,
            truth,
            after_truth,
            line_typed,
            line_from,
            done,
            console_errors(c).await?,
        ))
    });
    let _ = std::fs::remove_dir_all(&dir);
    let (links, after_links, truth, after_truth, line_typed, line_from, done, errors) = o;
    assert!(errors.is_empty(), "console errors: {errors:?}");

    // The link the scenario lacks, named at open; the recording not taken.
    assert!(
        links.contains("Recording recording.npz")
            && links.contains("links[4]")
            && links.contains("not one of the scenario's 4 links"),
        "{links}"
    );
    assert!(
        after_links["recording"].is_null(),
        "{}",
        after_links["recording"]
    );
    // The truth of another length, named at open with both files; not taken.
    assert!(
        truth.contains("truth file truth.json")
            && truth.contains("100 states for the recording's 150 snapshots"),
        "{truth}"
    );
    assert!(after_truth["truth"].is_null());
    // The "Empty area" line follows the fields as typed (0 … 0.5 s: snapshots 0 … 0.5 at 20 ms).
    let line_typed = line_typed.as_str().unwrap_or_default();
    assert!(
        line_typed.contains("0.000 … 0.500 s of the recording (2"),
        "{line_typed}"
    );
    let line_from = line_from.as_str().unwrap_or_default();
    assert!(
        line_from.contains("0.100 … 0.500 s of the recording (2"),
        "{line_from}"
    );

    // Progress: every phase after the estimates, in order, the bar never going back.
    let log = done["progressLog"].as_array().expect("the progress log");
    let phases: Vec<&str> = log.iter().map(|p| p["phase"].as_str().unwrap()).collect();
    let mut order: Vec<&str> = phases.clone();
    order.dedup();
    assert_eq!(
        order,
        ["estimate", "track", "figure", "results", "load", "draw"],
        "{phases:?}"
    );
    let bars: Vec<f64> = log.iter().map(|p| p["bar"].as_f64().unwrap()).collect();
    assert!(bars.windows(2).all(|w| w[1] >= w[0] - 1e-12), "{bars:?}");
    let last_estimate = log.iter().rev().find(|p| p["phase"] == "estimate").unwrap();
    assert!(
        last_estimate["bar"].as_f64().unwrap() <= 0.6,
        "{last_estimate}"
    );
    // Each figure panel reported: 0 … 4 of 4 links.
    let figure: Vec<u64> = log
        .iter()
        .filter(|p| p["phase"] == "figure")
        .map(|p| p["done"].as_u64().unwrap())
        .collect();
    assert_eq!(figure.first(), Some(&0), "{figure:?}");
    assert!(figure.iter().all(|&d| d < 4), "{figure:?}");
    println!("progress log: {}", Value::Array(log.clone()));
    println!("timings: {} (wall {} ms)", done["timings"], done["wallMs"]);
}
