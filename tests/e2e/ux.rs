//! Issue 26 §4–5, orientation and themes, with real input: the Help dialog (button, `?`,
//! Escape, focus back), the theme toggle (the canvas' own background follows the theme's CSS
//! variable), no probe in the status bar unless one is asked for (Shift+click or `probe=x,y`,
//! whose value is the native core's bound), the target dragged in the snapshot view, a
//! double-click that fits the zoom placing no target, and inputs showing rounded numbers while
//! the scenario keeps the exact ones.

use std::time::Duration;

use fantoccini::actions::{
    Actions, InputSource, KeyAction, KeyActions, MouseActions, PointerAction, MOUSE_BUTTON_LEFT,
};
use fantoccini::{Client, Locator};
use serde_json::Value;

use scatterloc::localize::crlb_at;
use scatterloc::{Model, Scenario, Vec2};

use super::{console_errors, drag_on_plot, js, open, open_hash, settle, with_browser};

const ESCAPE: char = '\u{E00C}';
const SHIFT: char = '\u{E008}';
const ENTER: char = '\u{E007}';

/// Presses `key` (down, up) on whatever has the focus.
async fn key(c: &Client, key: char) -> Result<(), String> {
    let k = KeyActions::new("keyboard".to_string())
        .then(KeyAction::Down { value: key })
        .then(KeyAction::Up { value: key });
    c.perform_actions(k).await.map_err(|e| e.to_string())
}

/// The id of the focused element.
async fn focused(c: &Client) -> Result<String, String> {
    Ok(js(
        c,
        "return document.activeElement ? document.activeElement.id : ''",
    )
    .await?
    .as_str()
    .unwrap_or_default()
    .to_string())
}

async fn help_open(c: &Client) -> Result<bool, String> {
    Ok(js(c, "return document.getElementById('help').open").await? == Value::Bool(true))
}

/// Clicks (or, with `shift`, Shift+clicks) the plot `n` times at canvas pixel (x, y), 60 ms
/// between the clicks (a double-click when n = 2).
async fn click_plot(c: &Client, x: f64, y: f64, n: usize, shift: bool) -> Result<(), String> {
    let canvas = c
        .find(Locator::Id("plot"))
        .await
        .map_err(|e| e.to_string())?;
    let b: Vec<f64> = serde_json::from_value(
        js(
            c,
            "const b = document.getElementById('plot').getBoundingClientRect(); return [b.width, b.height];",
        )
        .await?,
    )
    .map_err(|e| e.to_string())?;
    let mut mouse = MouseActions::new("mouse".to_string()).then(PointerAction::MoveToElement {
        element: canvas,
        duration: None,
        x: (x - b[0] / 2.0).round(),
        y: (y - b[1] / 2.0).round(),
    });
    let mut keys = KeyActions::new("keyboard".to_string()).then(if shift {
        KeyAction::Down { value: SHIFT }
    } else {
        KeyAction::Pause {
            duration: Duration::ZERO,
        }
    });
    for i in 0..n {
        if i > 0 {
            mouse = mouse.then(PointerAction::Pause {
                duration: Duration::from_millis(60),
            });
            keys = keys.then(KeyAction::Pause {
                duration: Duration::ZERO,
            });
        }
        mouse = mouse
            .then(PointerAction::Down {
                button: MOUSE_BUTTON_LEFT,
            })
            .then(PointerAction::Up {
                button: MOUSE_BUTTON_LEFT,
            });
        for _ in 0..2 {
            keys = keys.then(KeyAction::Pause {
                duration: Duration::ZERO,
            });
        }
    }
    if shift {
        keys = keys.then(KeyAction::Up { value: SHIFT });
    }
    c.perform_actions(Actions::from(keys).and(mouse))
        .await
        .map_err(|e| e.to_string())
}

/// A canvas pixel of empty map (no node or target within 40 px), CSS px.
async fn empty_pixel(c: &Client) -> Result<[f64; 2], String> {
    let v = js(
        c,
        "const r = window.view.rect; const n = window.app.nodes(); const t = window.pageState.target; \
         const pts = [...n.transmitters, ...n.receivers, ...(t ? [t] : [])].map((q) => window.view.toPixel(q.x, q.y)); \
         for (let fy = 0.2; fy < 0.9; fy += 0.05) for (let fx = 0.2; fx < 0.9; fx += 0.05) { \
           const p = { x: Math.round(r.x + fx * r.w), y: Math.round(r.y + fy * r.h) }; \
           if (pts.every((q) => Math.hypot(q.x - p.x, q.y - p.y) > 40)) return [p.x, p.y]; } \
         return null;",
    )
    .await?;
    serde_json::from_value(v).map_err(|e| format!("no empty pixel: {e}"))
}

struct HelpTheme {
    after_click: (bool, String),
    after_escape: (bool, String),
    after_key: bool,
    after_close: (bool, String),
    themes: Vec<(String, String, Value, Value)>,
    errors: Vec<String>,
}

async fn help_and_theme(c: &Client, port: u16) -> Result<HelpTheme, String> {
    open(c, port).await?;
    settle(c).await?;
    js(c, "window.theme.set(null)").await?;
    // The Help button (a real click), then Escape.
    c.find(Locator::Id("help-open"))
        .await
        .map_err(|e| e.to_string())?
        .click()
        .await
        .map_err(|e| e.to_string())?;
    let after_click = (help_open(c).await?, focused(c).await?);
    key(c, ESCAPE).await?;
    let after_escape = (help_open(c).await?, focused(c).await?);
    // `?` from the focused plot, then the Close button.
    js(c, "document.getElementById('plot').focus()").await?;
    key(c, '?').await?;
    let after_key = help_open(c).await?;
    c.find(Locator::Id("help-close"))
        .await
        .map_err(|e| e.to_string())?
        .click()
        .await
        .map_err(|e| e.to_string())?;
    let after_close = (help_open(c).await?, focused(c).await?);
    // The theme toggle, twice: <html data-theme>, aria-pressed, the CSS variable and the
    // canvas' top-left pixel (the plot background, drawn with the variable's colour).
    let mut themes = Vec::new();
    for _ in 0..3 {
        let v = js(
            c,
            "const c = document.getElementById('plot'); \
             const d = c.getContext('2d').getImageData(1, 1, 1, 1).data; \
             const probe = document.createElement('canvas').getContext('2d'); \
             probe.fillStyle = window.theme.colors()['--plot-bg']; probe.fillRect(0, 0, 1, 1); \
             const want = probe.getImageData(0, 0, 1, 1).data; \
             return [document.documentElement.dataset.theme, \
                     document.getElementById('theme-toggle').getAttribute('aria-pressed'), \
                     [d[0], d[1], d[2]], [want[0], want[1], want[2]]];",
        )
        .await?;
        themes.push((
            v[0].as_str().unwrap_or("").to_string(),
            v[1].as_str().unwrap_or("").to_string(),
            v[2].clone(),
            v[3].clone(),
        ));
        c.find(Locator::Id("theme-toggle"))
            .await
            .map_err(|e| e.to_string())?
            .click()
            .await
            .map_err(|e| e.to_string())?;
        settle(c).await?;
    }
    js(c, "window.theme.set(null)").await?;
    Ok(HelpTheme {
        after_click,
        after_escape,
        after_key,
        after_close,
        themes,
        errors: console_errors(c).await?,
    })
}

/// Help: opened by the button (focus on Close), closed by Escape (focus back on the button),
/// opened by `?`, closed by Close (focus back on the plot); the theme toggle flips the theme and
/// the canvas is redrawn in the theme's plot colour.
#[test]
#[ignore = "needs chromium + chromedriver and www/pkg (wasm-pack build); run with --ignored"]
fn help_dialog_and_theme_toggle() {
    let o = with_browser(async |c, port, _| help_and_theme(c, port).await);
    println!(
        "help: {:?} {:?} {} {:?}",
        o.after_click, o.after_escape, o.after_key, o.after_close
    );
    println!("themes: {:?}", o.themes);
    assert_eq!(o.after_click, (true, "help-close".to_string()));
    assert_eq!(o.after_escape, (false, "help-open".to_string()));
    assert!(o.after_key, "? opens the help");
    assert_eq!(o.after_close, (false, "plot".to_string()));
    let t = &o.themes;
    assert_ne!(t[0].0, t[1].0, "the toggle switches the theme");
    assert_eq!(t[0].0, t[2].0, "and back");
    for (theme, pressed, pixel, want) in t {
        assert_eq!(pressed, if theme == "light" { "true" } else { "false" });
        assert_eq!(pixel, want, "{theme}: canvas background = --plot-bg");
    }
    assert_ne!(t[0].2, t[1].2, "the canvas changed colour");
    assert!(o.errors.is_empty(), "console errors: {:?}", o.errors);
}

struct Gestures {
    probe_default: (bool, String, String),
    probe_pinned: (bool, f64, f64, f64, f64),
    probe_cleared: bool,
    drag: (Value, Value, [f64; 2], f64),
    dbl_none: (bool, bool, Value),
    dbl_kept: (Value, Value, bool),
    errors: Vec<String>,
}

async fn gestures(c: &Client, port: u16) -> Result<Gestures, String> {
    open(c, port).await?;
    settle(c).await?;
    // No probe by default, anywhere in the status bar.
    let v = js(
        c,
        "const p = document.getElementById('probe'); \
         return [p.hidden || p.getClientRects().length === 0, \
                 document.querySelector('.statusbar').innerText, p.dataset.rmseM];",
    )
    .await?;
    let probe_default = (
        v[0] == true,
        v[1].as_str().unwrap_or("").to_string(),
        v[2].as_str().unwrap_or("").to_string(),
    );
    // Shift+click pins it (and places no target).
    let [px, py] = empty_pixel(c).await?;
    // The metre point aimed at and the metres of one CSS pixel, before the click.
    let aim: Vec<f64> = serde_json::from_value(
        js(
            c,
            &format!("const m = window.view.toMetre({px}, {py}); return [m.x, m.y, 1 / window.view.len(1)];"),
        )
        .await?,
    )
    .map_err(|e| e.to_string())?;
    click_plot(c, px, py, 1, true).await?;
    settle(c).await?;
    let v = js(
        c,
        &format!(
            "const p = document.getElementById('probe'); const m = window.view.toMetre({px}, {py}); \
             return [!p.hidden && p.getClientRects().length > 0, Number(p.dataset.x), Number(p.dataset.y), \
                     Number(p.dataset.rmseM), window.app.rmse_at(Number(p.dataset.x), Number(p.dataset.y)), \
                     Math.hypot(Number(p.dataset.x) - {ax}, Number(p.dataset.y) - {ay}) / {mpp}, m.y, \
                     window.pageState.target === null];",
            ax = aim[0],
            ay = aim[1],
            mpp = aim[2]
        ),
    )
    .await?;
    let f = |i: usize| v[i].as_f64().unwrap_or(f64::NAN);
    if v[7] != true {
        return Err("Shift+click placed a target".into());
    }
    let probe_pinned = (v[0] == true, f(5), f(3), f(4), f(1));
    c.find(Locator::Id("probe-clear"))
        .await
        .map_err(|e| e.to_string())?
        .click()
        .await
        .map_err(|e| e.to_string())?;
    let probe_cleared = js(c, "return document.getElementById('probe').hidden").await? == true;

    // The target: placed at (6, 4), then dragged by (+40, +30) px with the real mouse.
    js(c, "window.placeTarget(6, 4)").await?;
    settle(c).await?;
    let t0 = js(c, "return window.pageState.target").await?;
    let p: Vec<f64> = serde_json::from_value(
        js(
            c,
            "const t = window.view.toPixel(6, 4); const b = document.getElementById('plot').getBoundingClientRect(); \
             return [t.x, t.y, b.width, b.height];",
        )
        .await?,
    )
    .map_err(|e| e.to_string())?;
    let start = [(p[0] - p[2] / 2.0).round(), (p[1] - p[3] / 2.0).round()];
    drag_on_plot(c, start, &[(20.0, 15.0, 150), (20.0, 15.0, 150)]).await?;
    settle(c).await?;
    let t1 = js(c, "return window.pageState.target").await?;
    let end = js(
        c,
        &format!(
            "const b = document.getElementById('plot').getBoundingClientRect(); \
             const m = window.view.toMetre({} + b.width / 2, {} + b.height / 2); \
             const s = window.pageState.snap; return [m.x, m.y, window.view.len(1), s.truth.x, s.truth.y];",
            start[0] + 40.0,
            start[1] + 30.0
        ),
    )
    .await?;
    let e: Vec<f64> = serde_json::from_value(end).map_err(|e| e.to_string())?;
    let tx = t1["x"].as_f64().unwrap_or(f64::NAN);
    let ty = t1["y"].as_f64().unwrap_or(f64::NAN);
    if e[3] != tx || e[4] != ty {
        return Err(format!(
            "the snapshot does not follow the target: {e:?} vs {t1}"
        ));
    }
    // Distance (px) between the dropped target and the release point.
    let drag = (
        t0,
        t1.clone(),
        [e[0], e[1]],
        (tx - e[0]).hypot(ty - e[1]) * e[2],
    );

    // Zoomed in without a target, a double-click on empty map fits and places nothing.
    js(c, "document.getElementById('target-clear').click()").await?;
    for _ in 0..2 {
        js(c, "document.getElementById('zoom-in').click()").await?;
    }
    settle(c).await?;
    let [qx, qy] = empty_pixel(c).await?;
    click_plot(c, qx, qy, 2, false).await?;
    tokio::time::sleep(Duration::from_millis(200)).await;
    settle(c).await?;
    let v = js(
        c,
        "return [window.zoom.state().zoomed, window.pageState.target === null, window.pageState.target];",
    )
    .await?;
    let dbl_none = (v[0] == true, v[1] == true, v[2].clone());
    // With a target: a double-click that fits leaves it where it was (same noise seed).
    js(c, "window.placeTarget(6, 4)").await?;
    settle(c).await?;
    js(c, "document.getElementById('zoom-in').click()").await?;
    settle(c).await?;
    let before = js(c, "return window.pageState.target").await?;
    let [qx, qy] = empty_pixel(c).await?;
    click_plot(c, qx, qy, 2, false).await?;
    tokio::time::sleep(Duration::from_millis(200)).await;
    settle(c).await?;
    let after = js(c, "return window.pageState.target").await?;
    let zoomed = js(c, "return window.zoom.state().zoomed").await? == true;
    Ok(Gestures {
        probe_default,
        probe_pinned,
        probe_cleared,
        drag,
        dbl_none,
        dbl_kept: (before, after, zoomed),
        errors: console_errors(c).await?,
    })
}

/// The probe is hidden until asked for (Shift+click pins it at the click, its value the core's
/// bound there; × removes it); the target is dragged with the mouse (the snapshot follows, the
/// noise seed stays); a double-click that fits the zoom places no target and keeps a placed one.
#[test]
#[ignore = "needs chromium + chromedriver and www/pkg (wasm-pack build); run with --ignored"]
fn probe_on_request_target_drag_and_double_click() {
    let o = with_browser(async |c, port, _| gestures(c, port).await);
    println!("probe default: {:?}", o.probe_default);
    println!("probe pinned: {:?}", o.probe_pinned);
    println!("drag: {:?}", o.drag);
    println!("double-click: {:?} / {:?}", o.dbl_none, o.dbl_kept);
    assert!(o.probe_default.0, "no probe shown by default");
    assert!(
        !o.probe_default.1.contains("probe"),
        "status bar: {}",
        o.probe_default.1
    );
    assert_eq!(o.probe_default.2, "");
    let (shown, dist_px, value, core, _) = o.probe_pinned;
    assert!(shown, "Shift+click shows the probe");
    // The click lands on a whole viewport pixel, within a pixel of the one aimed at.
    assert!(dist_px < 1.5, "probe at the click ({dist_px} px away)");
    assert_eq!(value, core, "the probe's value is the core's bound there");
    assert!(o.probe_cleared, "× removes the probe");
    let (t0, t1, _, px) = &o.drag;
    assert_eq!(t0["seed"], t1["seed"], "the drag keeps the noise seed");
    assert!(
        t1["x"].as_f64().unwrap() > 6.0 && t1["y"].as_f64().unwrap() < 4.0,
        "the target moved right and down: {t0} -> {t1}"
    );
    assert!(*px < 1.5, "the target is where the mouse let go ({px} px)");
    assert!(!o.dbl_none.0, "the double-click fitted the zoom");
    assert!(o.dbl_none.1, "and placed no target: {}", o.dbl_none.2);
    assert!(!o.dbl_kept.2, "fitted again");
    assert_eq!(
        o.dbl_kept.0, o.dbl_kept.1,
        "the placed target stays as it was"
    );
    assert!(o.errors.is_empty(), "console errors: {:?}", o.errors);
}

struct Rounded {
    exact: [f64; 2],
    shown: [String; 2],
    after_y: [f64; 2],
    after_same: [f64; 2],
    native: f64,
    page: f64,
    errors: Vec<String>,
}

async fn rounded(c: &Client, port: u16) -> Result<Rounded, String> {
    open_hash(c, port, "#probe=4,1").await?;
    settle(c).await?;
    // Drag Rx2: its coordinates get many decimals.
    let g: Vec<f64> = serde_json::from_value(
        js(
            c,
            "const r = window.app.nodes().receivers[1]; const p = window.view.toPixel(r.x, r.y); \
             const b = document.getElementById('plot').getBoundingClientRect(); \
             return [p.x - b.width / 2, p.y - b.height / 2];",
        )
        .await?,
    )
    .map_err(|e| e.to_string())?;
    drag_on_plot(c, [g[0], g[1]], &[(37.0, 23.0, 300)]).await?;
    settle(c).await?;
    let xy = "const r = window.app.nodes().receivers[1]; return [r.x, r.y];";
    let exact: [f64; 2] = serde_json::from_value(js(c, xy).await?).map_err(|e| e.to_string())?;
    let shown: [String; 2] = serde_json::from_value(
        js(
            c,
            "return [document.getElementById('rx-x').value, document.getElementById('rx-y').value];",
        )
        .await?,
    )
    .map_err(|e| e.to_string())?;
    // y typed anew (Enter): x keeps its exact value, not the rounded text beside it.
    let y = c
        .find(Locator::Id("rx-y"))
        .await
        .map_err(|e| e.to_string())?;
    js(
        c,
        "const e = document.getElementById('rx-y'); e.focus(); e.select();",
    )
    .await?;
    y.send_keys(&format!("7{ENTER}"))
        .await
        .map_err(|e| e.to_string())?;
    settle(c).await?;
    let after_y: [f64; 2] = serde_json::from_value(js(c, xy).await?).map_err(|e| e.to_string())?;
    // x committed unchanged (focus, Enter, blur): nothing moves.
    let x = c
        .find(Locator::Id("rx-x"))
        .await
        .map_err(|e| e.to_string())?;
    x.click().await.map_err(|e| e.to_string())?;
    x.send_keys(&ENTER.to_string())
        .await
        .map_err(|e| e.to_string())?;
    js(c, "document.getElementById('rx-x').blur()").await?;
    settle(c).await?;
    let after_same: [f64; 2] =
        serde_json::from_value(js(c, xy).await?).map_err(|e| e.to_string())?;
    let scenario = js(c, "return window.app.scenario_json()").await?;
    let s = Scenario::from_json(scenario.as_str().unwrap_or("")).map_err(|e| e.to_string())?;
    let model = Model::new(&s).map_err(|e| e.to_string())?;
    let native = crlb_at(&model, Vec2::new(4.0, 1.0))
        .bound
        .map_or(f64::NAN, |b| b.rmse_m);
    let page = js(
        c,
        "return Number(document.getElementById('probe').dataset.rmseM)",
    )
    .await?
    .as_f64()
    .unwrap_or(f64::NAN);
    Ok(Rounded {
        exact,
        shown,
        after_y,
        after_same,
        native,
        page,
        errors: console_errors(c).await?,
    })
}

/// A dragged receiver's inputs show its coordinates rounded (at most 3 decimals, within 5·10⁻⁴
/// of the exact value); editing y keeps x exact, committing x unchanged moves nothing; the
/// probe asked for by `probe=4,1` shows the native core's bound at (4, 1) for the final layout.
#[test]
#[ignore = "needs chromium + chromedriver and www/pkg (wasm-pack build); run with --ignored"]
fn inputs_show_rounded_numbers_and_keep_exact_ones() {
    let o = with_browser(async |c, port, _| rounded(c, port).await);
    println!(
        "exact {:?}, shown {:?}, after y {:?}, after x unchanged {:?}; probe {} vs native {}",
        o.exact, o.shown, o.after_y, o.after_same, o.page, o.native
    );
    for (i, t) in o.shown.iter().enumerate() {
        let decimals = t.split('.').nth(1).map_or(0, str::len);
        assert!(decimals <= 3, "{t}: at most 3 decimals");
        let v: f64 = t.parse().unwrap();
        assert!(
            (v - o.exact[i]).abs() <= 5e-4 + 1e-12,
            "{t} vs {}",
            o.exact[i]
        );
    }
    assert!(
        o.exact[0].to_string().split('.').nth(1).map_or(0, str::len) > 3,
        "the drag gave x more decimals than shown: {}",
        o.exact[0]
    );
    assert_eq!(o.after_y, [o.exact[0], 7.0], "x exact, y typed");
    assert_eq!(o.after_same, o.after_y, "an unchanged field moves nothing");
    assert!(
        (o.page / o.native - 1.0).abs() < 1e-9,
        "probe {} vs native {}",
        o.page,
        o.native
    );
    assert!(o.errors.is_empty(), "console errors: {:?}", o.errors);
}
