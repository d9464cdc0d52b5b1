//! Issue 40 §2 in the page: the panel edits the heights of the nodes and of the target's plane
//! (docs/rooms-3d.md "In the page") through the core's edits (`App.set_tx_height_m`,
//! `set_rx_height_m`, `set_target_height_m`). Typed into the panel, they give the probe's CRLB,
//! the map, the placed target's LM fix and its CRLB of the native core for the same scenario
//! (built here from the page's planar one with the core's own edits), and they come back from
//! undo/redo, the saved state and the link. A bad height is named in the banner (the page's
//! strict parser for text that is no number, the core's message for a value it refuses) and
//! changes nothing.

use serde_json::{json, Value};

use scatterloc::present::{simulate_snapshot, track_mean_state};
use scatterloc::track::{paper_initial_covariance, run_sequential, simulate_track};
use scatterloc::track::{ConstantVelocity, FilterKind, MonteCarloConfig, PAPER_INTENSITY};

use super::state::{capture, quiet};
use super::ui::{banner, click, mc_done, select, type_in, wait_banner, wait_tracking};
use super::*;

/// The panel's three height inputs, as shown (`[tx-h, rx-h, target-h]`), read as numbers (the
/// input still focused keeps the text as typed, `1.0`; the others show the value, `1`).
const HEIGHTS_SHOWN: &str =
    "return ['tx-h', 'rx-h', 'target-h'].map((id) => Number(document.getElementById(id).value));";

/// WebDriver's Backspace: typed over the selected text, it empties the input.
const BACKSPACE: &str = "\u{E003}";

/// The page's scenario JSON text.
async fn scenario_json(c: &Client) -> Result<String, String> {
    Ok(js(c, "return window.app.scenario_json()")
        .await?
        .as_str()
        .unwrap_or_default()
        .to_string())
}

/// A JSON array of numbers as `f64`s.
fn nums(v: &Value) -> Vec<f64> {
    v.as_array()
        .map(|a| a.iter().map(|x| x.as_f64().unwrap_or(f64::NAN)).collect())
        .unwrap_or_default()
}

/// Relative difference `|a/b − 1|`.
fn rel(a: f64, b: f64) -> f64 {
    (a / b - 1.0).abs()
}

/// The page's planar scenario with the heights the test types: Tx 2.5 m, Rx2 2.8 m, target 1.0 m,
/// set by the core's edits.
fn with_heights(planar: &str) -> Scenario {
    let mut s = Scenario::from_json(planar).expect("the page's scenario is valid");
    s.set_tx_height_m(0, 2.5).unwrap();
    s.set_rx_height_m(1, 2.8).unwrap();
    s.set_target_height_m(1.0).unwrap();
    s
}

/// Heights typed into the panel change the probe, the map and the placed target's fix to the
/// native core's numbers for the same 3-D scenario; undo/redo, the state and the link keep them.
#[test]
#[ignore = "needs chromium + chromedriver and www/pkg (wasm-pack build); run with --ignored"]
fn heights_typed_in_the_panel_give_the_cores_crlb_and_fix() {
    let o = session(|c, port| async move {
        open_hash(&c, port, PROBE_HASH).await?;
        quiet(&c).await?;
        let planar = scenario_json(&c).await?;
        let shown0 = js(&c, HEIGHTS_SHOWN).await?;
        let probe0 = probe(&c).await?;
        let map0 = js(&c, MAP_HASH).await?;
        // Through the panel, as a user does: Tx (the only one), then Rx2, then the target.
        type_in(&c, "tx-h", "2.5").await?;
        quiet(&c).await?;
        select(&c, "rx-select", "1").await?;
        quiet(&c).await?;
        type_in(&c, "rx-h", "2.8").await?;
        quiet(&c).await?;
        let before_target = scenario_json(&c).await?;
        type_in(&c, "target-h", "1.0").await?;
        quiet(&c).await?;
        let edited = scenario_json(&c).await?;
        let shown1 = js(&c, HEIGHTS_SHOWN).await?;
        let probe1 = probe(&c).await?;
        let map1 = js(&c, MAP_HASH).await?;
        let banner1 = banner(&c).await?;
        // Undo the target height, then redo it (the buttons).
        click(&c, "undo").await?;
        quiet(&c).await?;
        let undone = json!([
            scenario_json(&c).await?,
            js(&c, HEIGHTS_SHOWN).await?,
            probe(&c).await?
        ]);
        click(&c, "redo").await?;
        quiet(&c).await?;
        let redone = json!([
            scenario_json(&c).await?,
            js(&c, HEIGHTS_SHOWN).await?,
            probe(&c).await?
        ]);
        // A target placed in the 3-D scenario: its snapshot (LM fix, CRLB) and read-out.
        js(&c, "window.placeTarget(6, 3)").await?;
        quiet(&c).await?;
        let snap = js(
            &c,
            "const s = window.pageState.snap; \
             return {seed: s.seed, fix: s.fix && [s.fix.x, s.fix.y], fix_error: s.fix_error, \
             rmse: s.crlb.rmse_m, info: document.getElementById('target-info').textContent};",
        )
        .await?;
        // The state (as "Save state" writes it) restored in a fresh page, then the link.
        let state = capture(&c).await?;
        let link: String = c
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
        let errors = console_errors(&c).await?;
        open(&c, port).await?;
        quiet(&c).await?;
        let restore = js(
            &c,
            &format!(
                "return window.pageStateModel.restore(JSON.parse({}));",
                serde_json::to_string(&state.to_string()).unwrap()
            ),
        )
        .await?;
        quiet(&c).await?;
        let from_state = json!([
            restore,
            scenario_json(&c).await?,
            js(&c, HEIGHTS_SHOWN).await?
        ]);
        open_url(&c, &link).await?;
        quiet(&c).await?;
        let from_link = json!([
            scenario_json(&c).await?,
            js(&c, HEIGHTS_SHOWN).await?,
            banner(&c).await?
        ]);
        Ok(json!({
            "planar": planar, "shown0": shown0, "probe0": probe0, "map0": map0,
            "before_target": before_target, "edited": edited, "shown1": shown1, "probe1": probe1,
            "map1": map1, "banner1": banner1, "undone": undone, "redone": redone, "snap": snap,
            "from_state": from_state, "from_link": from_link, "link": link, "errors": errors,
        }))
    });
    assert_eq!(o["errors"], json!([]), "console errors");
    assert_eq!(o["banner1"], "", "no banner after valid heights");
    assert_eq!(
        nums(&o["shown0"]),
        [0.0, 0.0, 0.0],
        "a planar page shows heights 0"
    );

    // The page's scenario is the core's edits of its planar one, field for field.
    let planar = o["planar"].as_str().unwrap();
    let want = with_heights(planar);
    let page = Scenario::from_json(o["edited"].as_str().unwrap()).unwrap();
    assert_eq!(page, want, "the page's scenario = the core's edits");
    assert_eq!(nums(&o["shown1"]), [2.5, 2.8, 1.0]);

    // The probe at (4, 1): the native core's CRLB for the 3-D scenario (and not the planar one).
    let at = Vec2::new(4.0, 1.0);
    let native = |s: &Scenario| {
        crlb_at(&Model::new(s).unwrap(), at)
            .bound
            .expect("bounded at the probe")
            .rmse_m
    };
    let planar_s = Scenario::from_json(planar).unwrap();
    let (p0, p1) = (o["probe0"].as_f64().unwrap(), o["probe1"].as_f64().unwrap());
    let (n0, n1) = (native(&planar_s), native(&want));
    println!(
        "e2e heights: probe (4, 1) planar {p0} (core {n0}), 3-D {p1} (core {n1}); rel {:e}",
        rel(p1, n1)
    );
    assert!(rel(p0, n0) <= 1e-12, "planar probe {p0} vs core {n0}");
    assert!(rel(p1, n1) <= 1e-12, "3-D probe {p1} vs core {n1}");
    assert!(
        rel(n1, n0) > 1e-6,
        "the heights change the bound: {n0} -> {n1}"
    );
    assert_ne!(o["map0"], o["map1"], "the map is recomputed");

    // Undo: the target's plane back to 0 (the scenario before that edit); redo: 1.0 again.
    let before_target = Scenario::from_json(o["before_target"].as_str().unwrap()).unwrap();
    let undone = Scenario::from_json(o["undone"][0].as_str().unwrap()).unwrap();
    assert_eq!(
        undone, before_target,
        "undo restores the scenario before the edit"
    );
    assert_eq!(undone.target.height_m, 0.0);
    assert_eq!(nums(&o["undone"][1]), [2.5, 2.8, 0.0]);
    assert!(rel(o["undone"][2].as_f64().unwrap(), native(&before_target)) <= 1e-12);
    let redone = Scenario::from_json(o["redone"][0].as_str().unwrap()).unwrap();
    assert_eq!(redone, want, "redo reapplies it");
    assert_eq!(nums(&o["redone"][1]), [2.5, 2.8, 1.0]);
    assert!(rel(o["redone"][2].as_f64().unwrap(), n1) <= 1e-12);

    // The placed target's snapshot = the core's simulate_snapshot of the 3-D scenario.
    let snap = &o["snap"];
    let seed = snap["seed"].as_u64().unwrap();
    let model = Model::new(&want).unwrap();
    let sim = simulate_snapshot(&model, &want.area_m, Vec2::new(6.0, 3.0), seed);
    let fix = sim.fix.as_ref().expect("the core finds a fix");
    let page_fix = snap["fix"].as_array().expect("the page shows a fix");
    println!(
        "e2e heights: fix at (6, 3) seed {seed}: page ({}, {}), core ({}, {}); CRLB {} vs {}",
        page_fix[0],
        page_fix[1],
        fix.report.position.x,
        fix.report.position.y,
        snap["rmse"],
        sim.crlb.rmse_m()
    );
    assert!((page_fix[0].as_f64().unwrap() - fix.report.position.x).abs() <= 1e-9);
    assert!((page_fix[1].as_f64().unwrap() - fix.report.position.y).abs() <= 1e-9);
    assert!(rel(snap["rmse"].as_f64().unwrap(), sim.crlb.rmse_m()) <= 1e-12);
    let info = snap["info"].as_str().unwrap_or_default();
    assert!(
        info.contains("6.000 m, 3.000 m · h 1.000 m"),
        "the read-out names the target's plane: {info}"
    );

    // The state and the link bring the heights back exactly.
    assert_eq!(o["from_state"][0], Value::Null, "the state restores");
    let st = Scenario::from_json(o["from_state"][1].as_str().unwrap()).unwrap();
    assert_eq!(st, want, "the saved state keeps the heights");
    assert_eq!(
        o["from_state"][2][2], 1.0,
        "target height shown after restore"
    );
    let ln = Scenario::from_json(o["from_link"][0].as_str().unwrap()).unwrap();
    assert_eq!(ln, want, "the link keeps the heights ({})", o["link"]);
    assert_eq!(o["from_link"][1][0], 2.5);
    assert_eq!(o["from_link"][1][2], 1.0);
    assert_eq!(o["from_link"][2], "", "no banner from the link");
}

/// A bad height: text that is no number is named by the page's strict parser, a value the core
/// refuses (past ±1e7 m, or NaN through the binding) by the core's message; the scenario, the
/// probe and the shown heights stay, the input is marked; a valid height then clears the banner.
/// A negative height is a height below the floor's reference, which the core takes: so does the
/// page.
#[test]
#[ignore = "needs chromium + chromedriver and www/pkg (wasm-pack build); run with --ignored"]
fn a_bad_height_is_named_and_changes_nothing() {
    let o = session(|c, port| async move {
        open_hash(&c, port, PROBE_HASH).await?;
        quiet(&c).await?;
        type_in(&c, "rx-h", "2.8").await?;
        quiet(&c).await?;
        let good = json!([scenario_json(&c).await?, probe(&c).await?]);
        let mut bad = Vec::new();
        for (id, text) in [
            ("rx-h", "1e8"),
            ("rx-h", "NaN"),
            ("target-h", "-2e7"),
            ("tx-h", "abc"),
            ("target-h", BACKSPACE),
        ] {
            // Each banner is a new one: the last is dismissed first.
            if !banner(&c).await?.is_empty() {
                click(&c, "error-close").await?;
            }
            type_in(&c, id, text).await?;
            let b = wait_banner(&c).await?;
            settle(&c).await?;
            let invalid = js(
                &c,
                &format!("return document.getElementById('{id}').classList.contains('invalid')"),
            )
            .await?;
            bad.push(json!([
                id,
                text,
                b,
                invalid,
                scenario_json(&c).await?,
                probe(&c).await?
            ]));
        }
        // NaN cannot be typed (the parser refuses the text): straight to the binding.
        let nan = js(
            &c,
            "try { window.app.set_rx_height_m(0, NaN); return 'accepted'; } \
             catch (e) { return e.message; }",
        )
        .await?;
        let after_nan = scenario_json(&c).await?;
        // A valid edit clears the banner; then a negative height.
        type_in(&c, "target-h", "1").await?;
        quiet(&c).await?;
        let cleared = json!([banner(&c).await?, scenario_json(&c).await?]);
        type_in(&c, "rx-h", "-1.5").await?;
        quiet(&c).await?;
        let negative = json!([
            banner(&c).await?,
            scenario_json(&c).await?,
            probe(&c).await?
        ]);
        Ok(json!({
            "good": good, "bad": bad, "nan": nan, "after_nan": after_nan, "cleared": cleared,
            "negative": negative, "errors": console_errors(&c).await?,
        }))
    });
    assert_eq!(o["errors"], json!([]), "console errors");
    let good = Scenario::from_json(o["good"][0].as_str().unwrap()).unwrap();
    assert_eq!(good.receivers[0].height_m, 2.8);
    // The core's messages for the same edits.
    let core_err = |f: &dyn Fn(&mut Scenario) -> scatterloc::Result<()>| {
        f(&mut good.clone()).unwrap_err().to_string()
    };
    let expect = [
        core_err(&|s| s.set_rx_height_m(0, 1e8)),
        "receivers[0].height_m: \"NaN\" is not a decimal number".to_string(),
        core_err(&|s| s.set_target_height_m(-2e7)),
        "transmitters[0].height_m: \"abc\" is not a decimal number".to_string(),
        "target.height_m: empty (a decimal number is required)".to_string(),
    ];
    for (b, want) in o["bad"].as_array().unwrap().iter().zip(&expect) {
        println!("e2e heights: {} = {:?}: {}", b[0], b[1], b[2]);
        assert_eq!(b[2], want.as_str(), "banner for {b}");
        assert!(b[2]
            .as_str()
            .unwrap()
            .starts_with(match b[0].as_str().unwrap() {
                "rx-h" => "receivers[0].height_m",
                "tx-h" => "transmitters[0].height_m",
                _ => "target.height_m",
            }));
        assert_eq!(b[3], true, "the input is marked: {b}");
        assert_eq!(b[4], o["good"][0], "the scenario stays: {b}");
        assert_eq!(b[5], o["good"][1], "the probe stays: {b}");
    }
    assert!(expect[0].contains("out of range"), "{}", expect[0]);
    assert_eq!(o["nan"], core_err(&|s| s.set_rx_height_m(0, f64::NAN)));
    assert_eq!(o["after_nan"], o["good"][0], "NaN changes nothing");
    assert_eq!(o["cleared"][0], "", "a valid height clears the banner");
    let cleared = Scenario::from_json(o["cleared"][1].as_str().unwrap()).unwrap();
    assert_eq!(cleared.target.height_m, 1.0);
    // Negative: taken, as the core takes it, and the probe is the core's.
    let mut neg = cleared.clone();
    neg.set_rx_height_m(0, -1.5).unwrap();
    assert_eq!(o["negative"][0], "");
    let page_neg = Scenario::from_json(o["negative"][1].as_str().unwrap()).unwrap();
    assert_eq!(page_neg, neg);
    let native = crlb_at(&Model::new(&neg).unwrap(), Vec2::new(4.0, 1.0))
        .bound
        .unwrap()
        .rmse_m;
    assert!(rel(o["negative"][2].as_f64().unwrap(), native) <= 1e-12);
}

/// The tracking view after height edits in the panel: the shown track (EKF) is the core's
/// `simulate_track` and the Monte Carlo study the core's `run_sequential`, both on the 3-D
/// scenario (the planar one with the core's edits), and they differ from the planar track.
#[test]
#[ignore = "needs chromium + chromedriver and www/pkg (wasm-pack build); run with --ignored"]
fn heights_retrack_and_restudy_in_the_tracking_view() {
    let o = session(|c, port| async move {
        open_hash(&c, port, "#mode=tracking").await?;
        let s0 = wait_tracking(&c, 60, mc_done).await?;
        quiet(&c).await?;
        let planar = scenario_json(&c).await?;
        let track0 = js(&c, "return window.tracking.trackData()").await?;
        // Each edit restarts the study: wait for the one after it (a later generation, done).
        let mut gen = s0["mcGeneration"].as_u64().unwrap_or(0);
        for (id, text) in [("target-h", "1.0"), ("rx-h", "2.8")] {
            type_in(&c, id, text).await?;
            quiet(&c).await?;
            let s = wait_tracking(&c, 60, |s| {
                mc_done(s) && s["mcGeneration"].as_u64().unwrap_or(0) > gen
            })
            .await?;
            gen = s["mcGeneration"].as_u64().unwrap_or(0);
        }
        quiet(&c).await?;
        Ok(json!({
            "planar": planar, "track0": track0,
            "track": js(&c, "return window.tracking.trackData()").await?,
            "params": js(&c, "return window.tracking.mcParams()").await?,
            "result": js(&c, "return window.tracking.mcResult()").await?,
            "banner": banner(&c).await?, "errors": console_errors(&c).await?,
        }))
    });
    assert_eq!(o["errors"], json!([]), "console errors");
    assert_eq!(o["banner"], "");
    let mut want = Scenario::from_json(o["planar"].as_str().unwrap()).unwrap();
    want.set_target_height_m(1.0).unwrap();
    want.set_rx_height_m(0, 2.8).unwrap();
    let (p, t) = (&o["params"], &o["track"]);
    let studied = Scenario::from_json(p["scenario"].as_str().unwrap()).unwrap();
    assert_eq!(studied, want, "the study runs on the edited scenario");
    assert_eq!(t["filter"], "ekf", "the default filter");

    // The shown track against the core's.
    let f = |k: &str| p[k].as_f64().unwrap();
    let mean = track_mean_state(
        p["kind"].as_str().unwrap(),
        Vec2::new(f("x0"), f("y0")),
        Vec2::new(f("vx"), f("vy")),
    )
    .unwrap();
    let motion = ConstantVelocity::new(f("dt_s"), PAPER_INTENSITY);
    let model = Model::new(&want).unwrap();
    let run = simulate_track(
        &model,
        &motion,
        &mean,
        &paper_initial_covariance(),
        f("steps") as usize,
        f("seed") as u64,
        FilterKind::Ekf,
    )
    .unwrap();
    let est = t["estimates"].as_array().unwrap();
    assert_eq!(est.len(), run.estimates.len());
    let mut worst: f64 = 0.0;
    for (e, n) in est.iter().zip(&run.estimates) {
        for k in 0..4 {
            worst = worst.max((e[k].as_f64().unwrap() - n[k]).abs());
        }
    }
    let moved = est
        .iter()
        .zip(o["track0"]["estimates"].as_array().unwrap())
        .map(|(a, b)| (a[0].as_f64().unwrap() - b[0].as_f64().unwrap()).abs())
        .fold(0.0, f64::max);
    println!("e2e heights: track vs core max |Δ| {worst:e}; vs planar track max |Δx| {moved} m");
    assert!(worst <= 1e-9, "track vs core: {worst:e}");
    assert!(moved > 1e-6, "the heights change the track");

    // The Monte Carlo study against the core's.
    let cfg = MonteCarloConfig {
        motion,
        steps: f("steps") as usize,
        mean_state: mean,
        initial_covariance: paper_initial_covariance(),
        trajectories: f("trajectories") as usize,
        noise_runs: f("noise_runs") as usize,
        seed: f("seed") as u64,
        oracle_noise: false,
    };
    let native = run_sequential(&model, &cfg, |_, _| true).unwrap();
    let r = &o["result"];
    assert_eq!(r["runs"].as_u64(), Some(native.runs as u64));
    let mut worst: f64 = 0.0;
    for (key, n) in [("rmse_ekf_m", &native.rmse_m), ("nees", &native.nees)] {
        let b = r[key].as_array().unwrap();
        assert_eq!(b.len(), n.len(), "{key}");
        for (x, y) in b.iter().zip(n) {
            worst = worst.max(rel(x.as_f64().unwrap(), *y));
        }
    }
    println!("e2e heights: Monte Carlo vs core max relative {worst:e}");
    assert!(worst <= 1e-9, "Monte Carlo vs core: {worst:e}");
}
