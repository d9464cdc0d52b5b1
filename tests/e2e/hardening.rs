//! Browser end-to-end tests of issue 12's page items ("every hostile input bounded, named and
//! harmless"): a multi-target recompute stuck on a stale scene is replaced by the next edit; a
//! tiny cσ, a non-numeric seed and a hex number are rejected with named banners and change
//! nothing; an imported scenario with a huge area is rejected and the plot stays; a large network
//! keeps the map work of each drag move bounded and ends on the full-resolution map; URL options
//! name the option, the value and the allowed range.

use std::time::{Duration, Instant};

use fantoccini::{Client, Locator};
use serde_json::{json, Value};

use scatterloc::scenario::{Receiver, Transmitter};
use scatterloc::Scenario;

use super::ui::{banner, mtl_state, points, wait_banner, wait_view};
use super::{
    console_errors, drag_on_plot, js, open, open_hash, open_url, probe, session, settle, MAP_HASH,
    PROBE_HASH,
};

/// Sets input `id` to `value` and fires `change` (what Enter or leaving the field does).
async fn set_input(c: &Client, id: &str, value: &str) -> Result<(), String> {
    c.execute(
        "const i = document.getElementById(arguments[0]); i.value = arguments[1]; \
         i.dispatchEvent(new Event('change'));",
        vec![json!(id), json!(value)],
    )
    .await
    .map(|_| ())
    .map_err(|e| e.to_string())
}

/// FNV-1a of the plot canvas' pixels (what the user sees).
const PLOT_HASH: &str = "const c = document.getElementById('plot'); \
    const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data; \
    let h = 2166136261; for (let i = 0; i < d.length; i++) { h ^= d[i]; h = Math.imul(h, 16777619) >>> 0; } \
    return h;";

fn nearest(det: &[[f64; 2]], t: [f64; 2]) -> f64 {
    det.iter()
        .map(|d| (d[0] - t[0]).hypot(d[1] - t[1]))
        .fold(f64::INFINITY, f64::min)
}

/// Item 1: a slow multi-target scene (8 targets, clutter 10, cσ 2 m, T_e 6, T_b 30 nats) is
/// replaced by a later cheap edit (Reset, a real click): the worker busy with the stale scene is
/// terminated and a fresh one shows the later edit's view within seconds, with no reload; while
/// busy, the status says so and the last view stays drawn. The work budget of Algorithm 1 holds
/// in the page too: past it, a banner naming the budget, and the last view stays.
#[test]
#[ignore = "needs chromium + chromedriver and www/pkg (wasm-pack build); run with --ignored"]
fn mtl_stale_recompute_is_replaced_by_a_later_edit() {
    let (first, busy, status, after, recover, errors) = session(|c, port| async move {
        open_hash(&c, port, "#mode=mtl").await?;
        let first = wait_view(&c, 60).await?;
        let mut slow = first["scene"].clone();
        slow["targets"] = json!([
            [3.5, 4.0],
            [7.0, 5.5],
            [5.0, 5.0],
            [5.0, 7.0],
            [3.0, 6.0],
            [7.0, 3.0],
            [6.0, 8.5],
            [8.0, 6.0]
        ]);
        slow["clutter_mean"] = json!(10.0);
        slow["range_sigma"] = json!(2.0);
        slow["t_e"] = json!(6.0);
        slow["t_b"] = json!(30.0);
        // Past the default work budget (it would stop with a banner after about a second):
        // a budget of 10⁸ keeps the worker busy on the stale scene for minutes.
        slow["max_candidates"] = json!(100_000_000);
        let rejected = js(&c, &format!("return window.mtl.setScene({slow})")).await?;
        if !rejected.is_null() {
            return Err(format!("slow scene rejected: {rejected}"));
        }
        // Wait until the worker has been on the slow scene for 600 ms (its result must not come).
        let t0 = Instant::now();
        let busy = loop {
            let s = mtl_state(&c).await?;
            if s["pending"] == false {
                return Err(format!(
                    "the slow scene finished in {:?}: not slow; {s}",
                    t0.elapsed()
                ));
            }
            if s["busyMs"].as_f64().unwrap_or(0.0) > 600.0 {
                break s;
            }
            if t0.elapsed() > Duration::from_secs(20) {
                return Err(format!("worker never started the slow scene: {s}"));
            }
            tokio::time::sleep(Duration::from_millis(25)).await;
        };
        let status = js(
            &c,
            "const e = document.getElementById('mtl-status'); return e.hidden ? '' : e.textContent;",
        )
        .await?;
        let t_edit = Instant::now();
        c.find(Locator::Id("mtl-reset"))
            .await
            .map_err(|e| e.to_string())?
            .click()
            .await
            .map_err(|e| e.to_string())?;
        let after = wait_view(&c, 20).await?;
        let recover = t_edit.elapsed();
        // The work budget applies in the page: the same scene with a small budget is a banner
        // naming the budget, and the last view stays.
        slow["max_candidates"] = json!(5000);
        js(&c, &format!("return window.mtl.setScene({slow})")).await?;
        let budget = wait_banner(&c).await?;
        let kept = mtl_state(&c).await?;
        let budget_ok =
            budget.contains("more than 5000 candidates") && kept["detected"] == after["detected"];
        if !budget_ok {
            return Err(format!("budget banner {budget:?}, state {kept}"));
        }
        Ok((
            first,
            busy,
            status,
            after,
            recover,
            console_errors(&c).await?,
        ))
    });
    println!(
        "e2e: stuck multi-target recompute replaced: the later edit's view after {:.0} ms \
         ({} worker restart(s))",
        recover.as_secs_f64() * 1e3,
        after["restarts"]
    );
    assert!(errors.is_empty(), "console errors: {errors:?}");
    // While busy: the last view stays, the status says so.
    assert_eq!(
        busy["detected"], first["detected"],
        "the last view stays drawn"
    );
    let status = status.as_str().unwrap_or_default();
    assert!(status.starts_with("Computing the view…"), "{status:?}");
    // The later edit is shown, from a fresh worker, within a few seconds.
    assert!(recover < Duration::from_secs(5), "{recover:?}");
    assert!(after["restarts"].as_u64().unwrap_or(0) >= 1, "{after}");
    assert_eq!(after["viewGen"], after["gen"]);
    assert_eq!(after["scene"], first["scene"], "Reset: the default scene");
    let (t, d) = (points(&after["targets"]), points(&after["detected"]));
    assert_eq!(t.len(), 2, "{after}");
    for q in t {
        assert!(nearest(&d, q) < 0.5, "target {q:?} detected: {d:?}");
    }
}

/// Items 2 and 11: cσ = 1e-320, seed "abc", a seed past 2^53 − 1 and clutter "0x10" are each
/// rejected with a banner naming the field and the allowed range; the scene, the last view and
/// its read-out stay; then a valid cσ is computed and shown. The page's formatter is safe for
/// null and non-finite numbers.
#[test]
#[ignore = "needs chromium + chromedriver and www/pkg (wasm-pack build); run with --ignored"]
fn mtl_bad_numbers_are_named_and_change_nothing() {
    let (before, banners, unchanged, after, formatted, errors) = session(|c, port| async move {
        open_hash(&c, port, "#mode=mtl").await?;
        let before = wait_view(&c, 60).await?;
        let info = "return document.getElementById('mtl-info').textContent";
        let info_before = js(&c, info).await?;
        let mut banners = Vec::new();
        let mut unchanged = Vec::new();
        for (id, text) in [
            ("mtl-sigma", "1e-320"),
            ("mtl-seed", "abc"),
            ("mtl-seed", "9007199254740992"),
            ("mtl-clutter", "0x10"),
        ] {
            set_input(&c, id, text).await?;
            banners.push(wait_banner(&c).await?);
            let s = mtl_state(&c).await?;
            let invalid = js(
                &c,
                &format!("return document.getElementById('{id}').classList.contains('invalid')"),
            )
            .await?;
            unchanged.push(
                s["scene"] == before["scene"]
                    && s["viewGen"] == before["viewGen"]
                    && s["detected"] == before["detected"]
                    && js(&c, info).await? == info_before
                    && invalid == true,
            );
        }
        set_input(&c, "mtl-sigma", "0.2").await?;
        let t0 = Instant::now();
        let after = loop {
            let s = wait_view(&c, 20).await?;
            if s["scene"]["range_sigma"] == 0.2 || t0.elapsed() > Duration::from_secs(20) {
                break s;
            }
            tokio::time::sleep(Duration::from_millis(25)).await;
        };
        let after = json!([after, banner(&c).await?]);
        let formatted = c
            .execute_async(
                "const done = arguments[arguments.length - 1]; \
                 import('/js/dom.js').then((m) => done([null, undefined, NaN, Infinity, -Infinity, \
                 1.005e-320, 2.5].map((v) => m.fixed(v, 2))));",
                vec![],
            )
            .await
            .map_err(|e| e.to_string())?;
        Ok((
            before,
            banners,
            unchanged,
            after,
            formatted,
            console_errors(&c).await?,
        ))
    });
    assert!(errors.is_empty(), "console errors: {errors:?}");
    let expect = [
        "range_sigma (cσ): 1e-320 is out of range (allowed 0.001 … 1000 m)",
        "seed: \"abc\" is not a decimal number",
        "seed: 9007199254740992 is out of range (allowed an integer 0 … 9007199254740991)",
        "clutter_mean (clutter): \"0x10\" is not a decimal number",
    ];
    for (b, e) in banners.iter().zip(expect) {
        assert_eq!(b, e);
    }
    assert_eq!(unchanged, [true; 4], "a rejected edit changes nothing");
    let (s, b) = (&after[0], &after[1]);
    assert_eq!(
        s["scene"]["range_sigma"], 0.2,
        "the valid edit is shown: {s}"
    );
    assert_eq!(s["viewGen"], s["gen"]);
    assert!(s["viewGen"].as_u64() > before["viewGen"].as_u64());
    assert_eq!(b, "", "the banner is cleared by the valid edit");
    assert_eq!(formatted, json!(["—", "—", "—", "∞", "−∞", "0.00", "2.50"]));
}

/// Item 6: importing a scenario with `area_m.x = [−1e308, 1e308]` goes through the core's
/// validation: a banner names the field and the file; the scenario, the probe, the map image and
/// the view stay, and once the banner is dismissed the plot is pixel for pixel the one before;
/// a later edit (bandwidth 200 MHz) is shown, and a scenario file with a UTF-8 BOM imports.
#[test]
#[ignore = "needs chromium + chromedriver and www/pkg (wasm-pack build); run with --ignored"]
fn huge_area_import_is_rejected_and_the_plot_stays() {
    let mut v: Value =
        serde_json::from_str(&scatterloc::scenario::presets::sensors2019().to_json()).unwrap();
    v["area_m"]["x"] = json!([-1e308, 1e308]);
    let file =
        std::env::temp_dir().join(format!("scatterloc-e2e-huge-{}.json", std::process::id()));
    std::fs::write(&file, serde_json::to_string_pretty(&v).unwrap()).unwrap();
    let path = file.clone();
    // A valid scenario behind a UTF-8 byte-order mark (still accepted).
    let mut bom = scatterloc::scenario::presets::sensors2019();
    bom.name = "with-bom".into();
    let bom_file =
        std::env::temp_dir().join(format!("scatterloc-e2e-bom-{}.json", std::process::id()));
    std::fs::write(&bom_file, format!("\u{feff}{}", bom.to_json())).unwrap();
    let bom_path = bom_file.clone();
    let o = session(|c, port| async move {
        open_hash(&c, port, PROBE_HASH).await?;
        settle(&c).await?;
        let scenario = "return [window.app.scenario_json(), window.view.area]";
        let before = (
            js(&c, scenario).await?,
            js(&c, PLOT_HASH).await?,
            probe(&c).await?,
            js(&c, MAP_HASH).await?,
        );
        c.find(Locator::Id("import-file"))
            .await
            .map_err(|e| e.to_string())?
            .send_keys(path.to_str().unwrap())
            .await
            .map_err(|e| e.to_string())?;
        let b = wait_banner(&c).await?;
        settle(&c).await?;
        let (s, p, m) = (
            js(&c, scenario).await?,
            probe(&c).await?,
            js(&c, MAP_HASH).await?,
        );
        // The banner shifts the layout (the plot is redrawn at its new size): dismiss it first.
        js(&c, "document.getElementById('error-close').click()").await?;
        tokio::time::sleep(Duration::from_millis(300)).await;
        settle(&c).await?;
        let rejected = (s, js(&c, PLOT_HASH).await?, p, m);
        set_input(&c, "bandwidth", "200").await?;
        settle(&c).await?;
        let later = (
            js(&c, scenario).await?,
            js(&c, PLOT_HASH).await?,
            probe(&c).await?,
            banner(&c).await?,
        );
        c.find(Locator::Id("import-file"))
            .await
            .map_err(|e| e.to_string())?
            .send_keys(bom_path.to_str().unwrap())
            .await
            .map_err(|e| e.to_string())?;
        tokio::time::sleep(Duration::from_millis(300)).await;
        // The bandwidth edit above is unsaved: the page asks before the import replaces it.
        js(
            &c,
            "if (document.getElementById('confirm-dialog').open) \
             document.getElementById('confirm-ok').click()",
        )
        .await?;
        tokio::time::sleep(Duration::from_millis(300)).await;
        settle(&c).await?;
        let with_bom = json!([
            js(&c, "return window.app.scenario().name").await?,
            banner(&c).await?
        ]);
        Ok((
            before,
            b,
            rejected,
            later,
            with_bom,
            console_errors(&c).await?,
        ))
    });
    let _ = std::fs::remove_file(&file);
    let _ = std::fs::remove_file(&bom_file);
    let (before, b, rejected, later, with_bom, errors) = o;
    assert!(errors.is_empty(), "console errors: {errors:?}");
    assert!(
        b.contains("area_m.x") && b.contains("scatterloc-e2e-huge"),
        "banner: {b:?}"
    );
    assert_eq!(rejected.0, before.0, "scenario unchanged");
    assert_eq!(rejected.1, before.1, "plot pixels unchanged");
    assert_eq!(rejected.2, before.2, "probe unchanged");
    assert_eq!(rejected.3, before.3, "map image unchanged");
    let s = Scenario::from_json(later.0[0].as_str().unwrap()).unwrap();
    assert_eq!(s.radio.bandwidth_hz, 200e6, "the later edit is applied");
    assert_ne!(later.1, before.1, "and drawn");
    assert_ne!(later.2, before.2, "and the probe recomputed");
    assert_eq!(later.3, "", "banner cleared");
    assert_eq!(
        with_bom,
        json!(["with-bom", ""]),
        "a UTF-8 BOM file is imported"
    );
}

/// A 64 Tx × 64 Rx network (4096 links, the cap) in the sensors2019 area: nodes on two
/// interleaved 8 × 8 grids.
fn large_network() -> String {
    let mut s = scatterloc::scenario::presets::sensors2019();
    let (tx0, rx0) = (s.transmitters[0].clone(), s.receivers[0].clone());
    let at = |i: usize, off: f64| {
        [
            -5.0 + 4.5 * (i % 8) as f64 + off,
            -8.0 + 4.3 * (i / 8) as f64 + off,
        ]
    };
    s.transmitters = (0..64)
        .map(|i| Transmitter {
            name: format!("Tx{}", i + 1),
            height_m: 0.0,
            position_m: at(i, 0.0),
            ..tx0.clone()
        })
        .collect();
    s.receivers = (0..64)
        .map(|i| Receiver {
            name: format!("Rx{}", i + 1),
            height_m: 0.0,
            position_m: at(i, 2.2),
            ..rx0.clone()
        })
        .collect();
    s.name = "large-64x64".into();
    let json = s.to_json();
    let back = Scenario::from_json(&json).expect("valid large network");
    assert_eq!(back.transmitters.len() * back.receivers.len(), 4096);
    json
}

/// Item 9: with 4096 links (map 128²), every refresh of a real-mouse drag of a receiver computes
/// a reduced map on the main thread, the resolution the page's cost model picks for its frame
/// budget (the old page computed the full map per move); after the drag the full-resolution map
/// (from the worker) is shown and equals the core's map of the final scenario. The refresh and
/// kernel times are printed (docs/benchmarks.md), not asserted.
#[test]
#[ignore = "needs chromium + chromedriver and www/pkg (wasm-pack build); run with --ignored"]
fn large_network_drag_is_bounded_and_ends_on_the_full_map() {
    let text = large_network();
    let (imported, log, moved, fin, full_ms, same, errors) = session(|c, port| async move {
        open_hash(&c, port, "#res=128").await?;
        settle(&c).await?;
        let ok = c
            .execute(
                "return window.importScenarioText(arguments[0], 'large.json')",
                vec![json!(text)],
            )
            .await
            .map_err(|e| e.to_string())?;
        if ok != true {
            return Err(format!("import failed: {}", banner(&c).await?));
        }
        settle(&c).await?;
        let imported = js(&c, "return window.mapState()").await?;
        js(&c, "window.pageState.refreshLog.length = 0").await?;
        // Receiver Rx28 (index 27), inside the area; 12 moves of (−6, +5) px, 40 ms apart.
        let geo = js(
            &c,
            "const r = window.app.nodes().receivers[27]; const p = window.view.toPixel(r.x, r.y); \
             const b = document.getElementById('plot').getBoundingClientRect(); \
             return [p.x - b.width / 2, p.y - b.height / 2, r.x, r.y];",
        )
        .await?;
        let g: Vec<f64> = serde_json::from_value(geo).map_err(|e| e.to_string())?;
        drag_on_plot(&c, [g[0], g[1]], &[(-6.0, 5.0, 40); 12]).await?;
        settle(&c).await?;
        let log = js(&c, "return window.refreshLog()").await?;
        let log: Vec<Value> = serde_json::from_value(log).map_err(|e| e.to_string())?;
        let rx = js(
            &c,
            "const r = window.app.nodes().receivers[27]; return [r.x, r.y];",
        )
        .await?;
        let rx: Vec<f64> = serde_json::from_value(rx).map_err(|e| e.to_string())?;
        let fin = js(&c, "return window.mapState()").await?;
        // The core's map of the final scenario, here on the main thread, vs the one shown.
        let cmp = js(
            &c,
            "const n = 128; const b = new Float64Array(n * n); \
             const ms = window.app.compute_map(n, n, b); const v = window.pageState.values; \
             let same = v.length === b.length; \
             for (let i = 0; same && i < b.length; i++) same = Object.is(v[i], b[i]); \
             return [ms, same];",
        )
        .await?;
        Ok((
            imported,
            log,
            ((rx[0] - g[2]).hypot(rx[1] - g[3])),
            fin,
            cmp[0].as_f64().unwrap_or(f64::NAN),
            cmp[1] == true,
            console_errors(&c).await?,
        ))
    });
    let drag: Vec<&Value> = log.iter().filter(|r| r["dragging"] == true).collect();
    let ms = |k: &str| -> Vec<f64> { drag.iter().filter_map(|r| r[k].as_f64()).collect() };
    let (total, map) = (ms("ms"), ms("mapMs"));
    let med = |v: &[f64]| {
        let mut v = v.to_vec();
        v.sort_by(f64::total_cmp);
        v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
    };
    let max = |v: &[f64]| v.iter().copied().fold(0.0, f64::max);
    println!(
        "e2e: 64 Tx × 64 Rx (4096 links), map 128²: full map on the main thread {full_ms:.0} ms \
         (what each drag move cost before); during the drag {} refreshes at {:?}: refresh median \
         {:.1} ms (max {:.1}), map kernel median {:.1} ms (max {:.1}); after: {fin}",
        drag.len(),
        drag.iter()
            .map(|r| r["res"].as_str().unwrap_or("?"))
            .collect::<Vec<_>>(),
        med(&total),
        max(&total),
        med(&map),
        max(&map),
    );
    assert!(errors.is_empty(), "console errors: {errors:?}");
    assert_eq!(imported["full"], "128x128");
    assert_eq!(
        imported["res"], "128x128",
        "the import ends on the full map: {imported}"
    );
    assert!(moved > 1.0, "the receiver followed the mouse ({moved} m)");
    assert!(drag.len() >= 3, "refreshes during the drag: {log:?}");
    // The timings above are printed, not asserted (issue 39: a loaded machine failed a bound of
    // half the full map's time, 47.2 ms against 45.5 ms): the page's own timings are reported in
    // docs/benchmarks.md. What holds on any machine: every refresh during the drag drew a map
    // smaller than the full one, chosen by the page's cost model for its 10 ms budget.
    for r in &drag {
        let cells = |res: &str| -> Option<f64> {
            let (a, b) = res.split_once('x')?;
            Some(a.parse::<f64>().ok()? * b.parse::<f64>().ok()?)
        };
        let n = r["res"].as_str().and_then(cells);
        assert!(
            n.is_some_and(|n| n < 128.0 * 128.0),
            "a reduced map while dragging: {r}"
        );
    }
    assert_eq!(fin["res"], "128x128", "{fin}");
    assert_eq!(fin["source"], "worker", "{fin}");
    assert!(
        same,
        "the map shown is the core's full map of the final scenario"
    );
}

/// Item 11: `#runs=1000000000` names the option, the value and the allowed choices (the study runs
/// with the default); a hex number typed into a scenario field is rejected (named, nothing
/// changed) and `16` then is accepted.
#[test]
#[ignore = "needs chromium + chromedriver and www/pkg (wasm-pack build); run with --ignored"]
fn url_options_and_typed_numbers_are_strict() {
    let (url_banner, runs, hex_banner, unchanged, after, errors) = session(|c, port| async move {
        open_hash(&c, port, "#mode=tracking&runs=1000000000").await?;
        let url_banner = wait_banner(&c).await?;
        let runs = js(&c, "return document.getElementById('mc-runs').value").await?;
        js(&c, "document.getElementById('error-close').click()").await?;
        settle(&c).await?;
        let before = js(&c, "return window.app.scenario_json()").await?;
        set_input(&c, "bandwidth", "0x10").await?;
        let hex_banner = wait_banner(&c).await?;
        settle(&c).await?;
        let unchanged = js(&c, "return window.app.scenario_json()").await? == before;
        set_input(&c, "bandwidth", "16").await?;
        settle(&c).await?;
        let after = js(&c, "return window.app.scenario().radio.bandwidth_hz").await?;
        Ok((
            url_banner,
            runs,
            hex_banner,
            unchanged,
            json!([after, banner(&c).await?]),
            console_errors(&c).await?,
        ))
    });
    assert!(errors.is_empty(), "console errors: {errors:?}");
    assert_eq!(
        url_banner,
        "URL option runs: \"1000000000\" is not one of 50, 200, 1000, 10000"
    );
    assert_eq!(runs, "200", "the default study size stays");
    assert_eq!(
        hex_banner,
        "radio.bandwidth_hz (MHz): \"0x10\" is not a decimal number"
    );
    assert!(unchanged);
    assert_eq!(after[0].as_f64(), Some(16e6), "the later edit is applied");
    assert_eq!(after[1], "", "banner cleared");
}

/// Issue 24, the page's URL options: each bad, repeated or unknown option is named in the banner
/// with what is allowed (never "Internal error"), the console stays clean, and the rest of the
/// link still applies (`check`, a script, gives what the other options set). The ranges are the
/// panel's (a choice one of its `<select>`'s values) and the core's (coordinates within ±10⁷ m,
/// an area side of at least 10⁻³ m: `limits::COORDINATE_M`, `limits::MIN_AREA_SPAN_M`; the
/// zoom limits of `www/js/view.js`, 10⁻⁴ … 8 times the area). Before issue 24, `view=0,10,0,1e308`
/// and `target=1e308,4` gave "Internal error: window.y …" and a console error, and the others
/// were accepted silently.
#[test]
#[ignore = "needs chromium + chromedriver and www/pkg (wasm-pack build); run with --ignored"]
fn url_options_bad_ones_are_named_and_the_rest_applies() {
    const RES: &str = "document.getElementById('resolution').value";
    const ZOOMED: &str = "window.zoom.state().zoomed";
    const TARGET: &str =
        "(window.pageState.target && [window.pageState.target.x, window.pageState.target.y])";
    const KIND: &str = "window.tracking.state().kind";
    const RUNS: &str = "document.getElementById('mc-runs').value";
    const PLAYING: &str = "window.tracking.state().playing";
    const ROI: &str = "window.plan.state().roiCustom";
    const PLAY: &str = "URL option play: \"{}\" is not one of 0, 1";
    let mut cases: Vec<(String, String, String, Value)> = vec![
        (
            "#res=128&view=0,10,0,1e308".into(),
            "URL option view.y: 1e308 is out of range (-1e7 to 1e7 m)".into(),
            format!("[{RES}, {ZOOMED}]"),
            json!(["128", false]),
        ),
        (
            "#res=128&target=1e308,4".into(),
            "URL option target.x: 1e308 is out of range (-1e7 to 1e7 m)".into(),
            format!("[{RES}, {TARGET}]"),
            json!(["128", null]),
        ),
        (
            // Inside the core's coordinate range, but no zoom or pan reaches it.
            "#target=4,1&view=5e6,5.00001e6,5e6,5.00001e6".into(),
            "URL option view: the window's x centre 5000005".into(),
            format!("[{TARGET}, {ZOOMED}]"),
            json!([[4, 1], false]),
        ),
        (
            // Below the core's smallest area side (the precision rule of every area).
            "#target=4,1&view=0,1e-9,0,1e-9".into(),
            "URL option view.x: 1e-9 is out of range (a span of at least 1e-3 m)".into(),
            format!("[{TARGET}, {ZOOMED}]"),
            json!([[4, 1], false]),
        ),
        (
            // Above the core's smallest side, below the zoom's smallest window.
            "#target=4,1&view=0,0.002,0,0.002".into(),
            "URL option view: the window's x side of 0.002 m is outside 0.0001 … 8 times".into(),
            format!("[{TARGET}, {ZOOMED}]"),
            json!([[4, 1], false]),
        ),
        (
            "#target=4,1&roi=0,1e-9,0,1e-9".into(),
            "URL option roi.x: 1e-9 is out of range (a span of at least 1e-3 m)".into(),
            format!("[{TARGET}, {ROI}]"),
            json!([[4, 1], false]),
        ),
        (
            "#mode=tracking&track=II&filters=ekf,ekf".into(),
            "URL option filters: \"ekf\" is given twice (distinct filters of ekf, ukf, pf)".into(),
            format!("[{KIND}, window.tracking.state().mcFilters]"),
            json!(["II", "ekf"]),
        ),
        (
            "#mode=tracking&track=III&runs=1e4".into(),
            "URL option runs: \"1e4\" is not one of 50, 200, 1000, 10000".into(),
            format!("[{KIND}, {RUNS}]"),
            json!(["III", "200"]),
        ),
        (
            "#mode=tracking&track=III&runs=1000.0".into(),
            "URL option runs: \"1000.0\" is not one of 50, 200, 1000, 10000".into(),
            format!("[{KIND}, {RUNS}]"),
            json!(["III", "200"]),
        ),
        (
            "#res=128&colour=red".into(),
            "URL option colour: unknown (known options: mode, preset, res,".into(),
            format!("[{RES}]"),
            json!(["128"]),
        ),
        (
            "#target=4,1&res=128&res=512".into(),
            "URL option res: given 2 times (at most once)".into(),
            format!("[{TARGET}, {RES}]"),
            json!([[4, 1], "256"]),
        ),
        (
            "#mode=tracking&track=custom&custom=1e308,0,1,1".into(),
            "URL option custom.start.x: 1e308 is out of range (-1e7 to 1e7 m)".into(),
            format!("[{KIND}]"),
            json!(["custom"]),
        ),
        (
            "#target=4,1&seed=1.5".into(),
            "URL option seed: 1.5 is not an integer (allowed an integer 0 … 4294967295)".into(),
            format!("[{TARGET}]"),
            json!([[4, 1]]),
        ),
        (
            "#mode=tracking&track=II&step=1e5".into(),
            "URL option step: 1e5 is out of range (allowed an integer 0 … 10000)".into(),
            format!("[{KIND}, window.tracking.state().step]"),
            json!(["II", 0]),
        ),
        (
            "#res=128&z=abcd&scenario=abcd".into(),
            "URL option z and scenario: both given (one scenario at most)".into(),
            format!("[{RES}]"),
            json!(["128"]),
        ),
        (
            // The good options are taken (the control case): no banner.
            "#mode=tracking&track=II&play=1&runs=10000&filters=ekf,ukf".into(),
            String::new(),
            format!("[{KIND}, {PLAYING}, {RUNS}, window.tracking.state().mcFilters]"),
            json!(["II", true, "10000", "ekf,ukf"]),
        ),
    ];
    for v in ["2", "true", "yes"] {
        cases.push((
            format!("#mode=tracking&track=II&play={v}"),
            PLAY.replace("{}", v),
            format!("[{KIND}, {PLAYING}]"),
            json!(["II", false]),
        ));
    }
    let plan: Vec<(String, String)> = cases
        .iter()
        .map(|(h, _, check, _)| (h.clone(), check.clone()))
        .collect();
    let results = session(|c, port| async move {
        let mut out = Vec::new();
        for (hash, check) in plan {
            open_url(&c, &format!("http://127.0.0.1:{port}/{hash}")).await?;
            settle(&c).await?;
            out.push(json!([
                banner(&c).await?,
                js(&c, &format!("return {check}")).await?,
                console_errors(&c).await?,
            ]));
        }
        Ok(out)
    });
    for ((hash, want, _, applied), r) in cases.iter().zip(&results) {
        println!("e2e: {hash} -> {:?}", r[0]);
        let b = r[0].as_str().unwrap_or_default();
        if want.is_empty() {
            assert_eq!(b, "", "{hash}: no banner");
        } else {
            assert!(
                b.starts_with(want.as_str()),
                "{hash}: banner {b:?}, want {want:?}"
            );
        }
        assert!(!b.contains("Internal error"), "{hash}: {b:?}");
        assert_eq!(&r[1], applied, "{hash}: the rest of the link applies");
        assert_eq!(r[2], json!([]), "{hash}: console errors");
    }
}

/// What the page writes it reads (issue 24): "Copy link" of a window at the zoom limits (the
/// smallest window, panned to the pan limit; the largest) gives a link that reopens that window
/// exactly, with no banner.
#[test]
#[ignore = "needs chromium + chromedriver and www/pkg (wasm-pack build); run with --ignored"]
fn copy_link_at_the_zoom_limits_reopens_the_same_window() {
    let results = session(|c, port| async move {
        let mut out = Vec::new();
        for (factor, dx, dy) in [(1e-9, 1e7, -1e7), (1e9, -1e7, 1e7), (1e-9, 0.0, 0.0)] {
            open_url(&c, &format!("http://127.0.0.1:{port}/#res=128")).await?;
            settle(&c).await?;
            let link = c
                .execute_async(
                    "const [f, dx, dy, done] = arguments; const v = window.view; \
                     v.zoomAt(v.rect.x + v.rect.w / 3, v.rect.y + v.rect.h / 4, f); v.panBy(dx, dy); \
                     window.shareLink().then((l) => done([l, Array.from(v.area)]), \
                       (e) => done(['error: ' + e.message, null]));",
                    vec![json!(factor), json!(dx), json!(dy)],
                )
                .await
                .map_err(|e| e.to_string())?;
            let url = link[0].as_str().unwrap_or_default().to_string();
            if !url.starts_with("http") {
                return Err(format!("no link: {link}"));
            }
            open_url(&c, &url).await?;
            settle(&c).await?;
            out.push(json!([
                link[1],
                js(&c, "return Array.from(window.view.area)").await?,
                banner(&c).await?,
                console_errors(&c).await?,
                url.contains("view="),
            ]));
        }
        Ok(out)
    });
    for r in &results {
        println!("e2e: zoom-limit link: {} -> {} {:?}", r[0], r[1], r[2]);
        assert_eq!(r[4], true, "the link carries the window: {r}");
        assert_eq!(r[0], r[1], "the window comes back exactly: {r}");
        assert_eq!(r[2], "", "no banner: {r}");
        assert_eq!(r[3], json!([]), "console errors: {r}");
    }
}

/// A scenario of `n` transmitters (names of about 100 characters, positions with 17 significant
/// digits, beams) and one receiver in the sensors2019 area, named `name`.
fn wide_scenario(n: usize, name: &str) -> String {
    let mut s = scatterloc::scenario::presets::sensors2019();
    let tx0 = s.transmitters[0].clone();
    s.transmitters = (0..n)
        .map(|i| Transmitter {
            name: format!("Tx{i:04}-{}", "n".repeat(94)),
            height_m: 0.0,
            position_m: [
                -4.123_456_789_012_345 + 0.011_111_111_111_111 * (i % 64) as f64,
                -7.987_654_321_098_765 + 0.031_111_111_111_111 * (i / 64) as f64,
            ],
            ..tx0.clone()
        })
        .collect();
    s.receivers.truncate(1);
    s.name = name.into();
    s.to_json()
}

/// Bytes of a scenario's compact JSON (what a link carries, share.js).
fn compact_len(json: &str) -> usize {
    serde_json::to_string(&serde_json::from_str::<Value>(json).unwrap())
        .unwrap()
        .len()
}

/// What the page writes it reads (issue 24): before, "Copy link" of a scenario over 1 MiB gave a
/// link the page then refused ("inflates to more than 1048576 bytes"). Now a scenario of about
/// 0.9 MiB of JSON (the link's cap is 1 MiB after inflating) gives a link that reopens the same
/// scenario, and one of about 1.1 MiB gives no link: the bar says it is too large, with the size
/// and the cap, and offers the scenario file (the panel's Export), which its button saves.
#[test]
#[ignore = "needs chromium + chromedriver and www/pkg (wasm-pack build); run with --ignored"]
fn copy_link_reads_back_or_offers_the_scenario_file() {
    const CAP: usize = 1 << 20; // share.js MAX_BYTES
    let per = compact_len(&wide_scenario(2, "x")) - compact_len(&wide_scenario(1, "x"));
    let base = compact_len(&wide_scenario(1, "x")) - per;
    let (n_under, n_over) = ((CAP * 9 / 10 - base) / per, (CAP * 11 / 10 - base) / per);
    assert!(
        n_over <= 4096,
        "{n_over} transmitters (the link cap is 4096)"
    );
    let under = wide_scenario(n_under, "under-cap");
    let over = wide_scenario(n_over, "over-cap");
    assert!(compact_len(&under) < CAP && compact_len(&over) > CAP);
    let (under_len, over_len) = (compact_len(&under), compact_len(&over));
    let o = session(|c, port| async move {
        open_hash(&c, port, "#res=128").await?;
        settle(&c).await?;
        let copy = async |c: &Client, text: &str, name: &str| -> Result<Value, String> {
            let ok = c
                .execute(
                    "return window.importScenarioText(arguments[0], arguments[1])",
                    vec![json!(text), json!(name)],
                )
                .await
                .map_err(|e| e.to_string())?;
            if ok != true {
                return Err(format!("import of {name} failed: {}", banner(c).await?));
            }
            settle(c).await?;
            js(c, "document.getElementById('share-note').textContent = ''").await?;
            c.find(Locator::Id("share-copy"))
                .await
                .map_err(|e| e.to_string())?
                .click()
                .await
                .map_err(|e| e.to_string())?;
            let t0 = Instant::now();
            loop {
                let s = js(
                    c,
                    "const $ = (id) => document.getElementById(id); \
                     return [$('share-note').textContent, $('share-url').value, $('share-url').hidden, \
                       $('share-save').hidden, $('share').hidden, window.app.scenario_json()];",
                )
                .await?;
                if s[0] != "" || t0.elapsed() > Duration::from_secs(20) {
                    return Ok(s);
                }
                tokio::time::sleep(Duration::from_millis(50)).await;
            }
        };
        let small = copy(&c, &under, "under-cap.json").await?;
        let large = copy(&c, &over, "over-cap.json").await?;
        // The offered file: the panel's Export (a download link clicked; recorded here).
        js(
            &c,
            "window.__downloads = []; \
             HTMLAnchorElement.prototype.click = function () { window.__downloads.push(this.download); };",
        )
        .await?;
        c.find(Locator::Id("share-save"))
            .await
            .map_err(|e| e.to_string())?
            .click()
            .await
            .map_err(|e| e.to_string())?;
        let saved = js(&c, "return window.__downloads").await?;
        let errors = console_errors(&c).await?;
        // The link of the 0.9 MiB scenario, opened as a fresh page.
        let url = small[1].as_str().unwrap_or_default().to_string();
        open_url(&c, &url).await?;
        settle(&c).await?;
        let reopened = json!([
            js(&c, "return window.app.scenario_json()").await?,
            banner(&c).await?,
            console_errors(&c).await?,
            url.len(),
        ]);
        Ok((small, large, saved, errors, reopened))
    });
    let (small, large, saved, errors, reopened) = o;
    println!(
        "e2e: copy link: {under_len} B of JSON -> a link of {} characters; {over_len} B -> {:?}",
        reopened[3], large[0]
    );
    assert!(errors.is_empty(), "console errors: {errors:?}");
    // Under the cap: a link, shown; it reopens the same scenario with no banner.
    assert_eq!(small[2], false, "the link field is shown: {}", small[0]);
    assert_eq!(small[3], true, "no file offered: {}", small[0]);
    assert!(small[1]
        .as_str()
        .unwrap_or_default()
        .contains("#mode=snapshot&res=128&"));
    let json = |v: &Value| serde_json::from_str::<Value>(v.as_str().unwrap_or_default()).unwrap();
    assert_eq!(
        json(&reopened[0]),
        json(&small[5]),
        "the link reopens the scenario"
    );
    assert_eq!(json(&reopened[0])["name"], "under-cap");
    assert_eq!(reopened[1], "", "no banner");
    assert_eq!(reopened[2], json!([]), "console errors");
    // Over it: no link; the size, the cap and the file offered.
    let note = large[0].as_str().unwrap_or_default();
    // The page's compact JSON (JSON.stringify: `20`, not serde's `20.0`) is a little shorter.
    let size: usize = note
        .strip_prefix("No link: the scenario is ")
        .and_then(|t| t.split_once(" bytes of JSON; a link carries at most 1048576 bytes (1 MiB)"))
        .and_then(|(n, _)| n.parse().ok())
        .unwrap_or_else(|| panic!("{note:?}"));
    assert!(size > CAP && size <= over_len, "{size} bytes: {note:?}");
    assert_eq!(large[1], "", "no link: {note}");
    assert_eq!(large[2], true, "the link field is hidden");
    assert_eq!(large[3], false, "the scenario file is offered");
    assert_eq!(large[4], false, "the bar is shown");
    assert_eq!(
        saved,
        json!(["over-cap.json"]),
        "the button saves the scenario file"
    );
}

/// Issue 24: a 10 MB node name froze every interaction for 3.5–6 s. The core caps name lengths
/// (scenario validation names the field); every page path that takes a scenario goes through it:
/// an imported file (here through the same path as the file input) with a 10 MB transmitter name
/// is refused within a second with a banner naming the file and the name field, and a shared
/// link (`z=`) carrying a 500 kB name is refused the same way; the scenario stays. (The page has
/// no name input.) Passes once the core's name cap is in.
#[test]
#[ignore = "needs chromium + chromedriver and www/pkg (wasm-pack build); run with --ignored"]
fn long_node_names_are_refused_promptly_on_every_path() {
    let o = session(|c, port| async move {
        open(&c, port).await?;
        settle(&c).await?;
        let before = js(&c, "return window.app.scenario_json()").await?;
        let import = js(
            &c,
            "const s = JSON.parse(window.app.scenario_json()); \
             s.transmitters[0].name = 'x'.repeat(10_000_000); const text = JSON.stringify(s); \
             const t0 = performance.now(); const ok = window.importScenarioText(text, 'big-name.json'); \
             return [ok, performance.now() - t0];",
        )
        .await?;
        let import_banner = banner(&c).await?;
        let kept = js(&c, "return window.app.scenario_json()").await? == before;
        let errors = console_errors(&c).await?;
        let link = c
            .execute_async(
                "const done = arguments[arguments.length - 1]; \
                 const s = JSON.parse(window.app.scenario_json()); \
                 s.transmitters[0].name = 'y'.repeat(500_000); \
                 import('/js/share.js').then((m) => m.encodeScenario(JSON.stringify(s))) \
                   .then(([k, v]) => done(`${location.origin}/#${k}=${v}`), (e) => done('error: ' + e.message));",
                vec![],
            )
            .await
            .map_err(|e| e.to_string())?;
        open_url(&c, link.as_str().unwrap_or_default()).await?;
        settle(&c).await?;
        let url = json!([
            banner(&c).await?,
            js(&c, "return window.app.scenario_json()").await? == before,
            console_errors(&c).await?,
        ]);
        Ok((import, import_banner, kept, errors, url))
    });
    let (import, import_banner, kept, errors, url) = o;
    println!("e2e: 10 MB name: {import} {import_banner:?}; 500 kB name in a link: {url}");
    assert!(errors.is_empty(), "console errors: {errors:?}");
    // Refused, by the name cap (the banner below): the time it took is printed above, not
    // asserted (issue 39: tests do not time the wall clock).
    assert_eq!(import[0], false, "the import is refused");
    // The field as the core's validation names it (the cap's error, issue 24).
    assert!(
        import_banner.starts_with("Import of big-name.json failed: ")
            && import_banner.contains("transmitters[0].name"),
        "{import_banner:?}"
    );
    assert!(kept, "the scenario stays");
    let b = url[0].as_str().unwrap_or_default();
    assert!(
        b.starts_with("URL option z: ") && b.contains("transmitters[0].name"),
        "{b:?}"
    );
    assert_eq!(url[1], true, "the default scenario stays");
    assert_eq!(url[2], json!([]), "console errors");
}
