//! Issue 38, every view looked at again as a first-time user: the multi-target view draws in its
//! theme's colours (its plot background is the theme's `--plot-bg`, measured on the canvas, and
//! every colour its legend shows is the colour the drawing reports it drew that symbol with, in
//! the dark and the light theme); the tracking view's zoom inset title ends left of the inset's
//! × button (the title's ink box, measured with the canvas' `measureText`, against the button's
//! box); the channel view's panel does not scroll sideways and its "No empty recording" button
//! lies inside it, at 1440×900 and on a 390×844 phone, in both themes.

use std::time::Duration;

use fantoccini::wd::TimeoutConfiguration;
use fantoccini::Client;
use serde_json::Value;

use super::page_theme::{reopen, set_theme};
use super::ui::{poll, wait_view};
use super::{console_errors, js, settle, with_browser};

const THEMES: [&str; 2] = ["dark", "light"];

/// The multi-target canvas and legend: the median colour of the middle half of the canvas (the
/// region, mostly background), `--plot-bg`, and per legend symbol the swatch's colour (computed
/// style) and the colour the drawing reports (`window.mtl.state().colors`), all as RGBA parsed
/// by a canvas.
const MTL_COLOURS: &str = "\
    const rgba = (css) => { if (!css) return null; const c = document.createElement('canvas'); \
        c.width = c.height = 1; const x = c.getContext('2d'); x.fillStyle = '#000'; \
        x.fillStyle = css; x.fillRect(0, 0, 1, 1); return [...x.getImageData(0, 0, 1, 1).data]; }; \
    const cv = document.getElementById('plot'); \
    const g = cv.getContext('2d'); \
    const d = g.getImageData(Math.round(cv.width / 4), Math.round(cv.height / 4), \
        Math.round(cv.width / 2), Math.round(cv.height / 2)).data; \
    const median = [0, 1, 2].map((c) => { const v = []; \
        for (let i = c; i < d.length; i += 4) v.push(d[i]); v.sort((p, q) => p - q); \
        return v[v.length >> 1]; }); \
    const css = getComputedStyle(document.documentElement); \
    const legend = document.querySelector('.legend.mtl-only'); \
    const sym = (cls, prop, pseudo) => { const e = legend.querySelector('.sym.' + cls); \
        return e ? rgba(getComputedStyle(e, pseudo || null)[prop]) : null; }; \
    const drawn = window.mtl.state().colors; \
    const pairs = [['hyp', 'hyp', 'borderTopColor'], ['hypRej', 'hyprej', 'borderTopColor'], \
        ['fa', 'fa', 'borderTopColor'], ['detected', 'fix', 'borderTopColor'], \
        ['blocked', 'blocked', 'borderTopColor'], ['los', 'los', 'borderTopColor'], \
        ['seed', 'seed', 'backgroundColor'], ['disc', 'disc', 'backgroundColor'], \
        ['discEdge', 'disc', 'borderTopColor'], ['region', 'region', 'backgroundColor'], \
        ['regionEdge', 'region', 'borderTopColor'], ['target', 'truth', 'backgroundColor', '::before']]; \
    return { theme: document.documentElement.dataset.theme, bgPixel: median, \
        plotBg: rgba(css.getPropertyValue('--plot-bg').trim()), reported: !!drawn, \
        symbols: pairs.map(([key, cls, prop, pseudo]) => ({ key, legend: sym(cls, prop, pseudo), \
            drawn: drawn ? rgba(drawn[key]) : null })) };";

/// The zoom inset's title and × button: the title the inset hook reports (text, full text, ink
/// box in canvas CSS px), re-measured with `measureText` in the font it was drawn with, and the
/// × button's box in the same coordinates.
const INSET_TITLE: &str = "\
    const ins = window.pictures.inset(); \
    const cv = document.getElementById('plot'); \
    const r = cv.getBoundingClientRect(); \
    const b = document.querySelector('.inset-close').getBoundingClientRect(); \
    const close = { x: b.left - r.left, y: b.top - r.top, w: b.width, h: b.height }; \
    const t = ins.title; \
    if (!ins.box || !t) return { error: 'no inset title reported', inset: ins, close }; \
    const g = document.createElement('canvas').getContext('2d'); \
    g.font = '600 11.5px system-ui, -apple-system, \"Segoe UI\", Roboto, sans-serif'; \
    const m = g.measureText(t.text); \
    return { box: ins.box, text: t.text, full: t.full, titleBox: t.box, \
        measuredRight: ins.box.x + 8 + m.actualBoundingBoxRight, close, \
        grip: document.querySelector('.inset-grip').getAttribute('aria-label') };";

/// The channel panel's overflow: its scroll and client widths, its box and the "No empty
/// recording" button's box (viewport CSS px), and the page's own scroll and client widths.
const CHANNEL_PANEL: &str = "\
    const p = document.getElementById('panel'); \
    const box = (e) => { const r = e.getBoundingClientRect(); \
        return { left: r.left, right: r.right, top: r.top, bottom: r.bottom }; }; \
    const pr = box(p); \
    return { scrollWidth: p.scrollWidth, clientWidth: p.clientWidth, \
        panel: { left: pr.left, right: pr.left + p.clientLeft + p.clientWidth }, \
        button: box(document.getElementById('chan-cal-clear')), \
        pageScroll: document.documentElement.scrollWidth, pageClient: document.documentElement.clientWidth };";

fn rgba(v: &Value) -> Option<Vec<i64>> {
    serde_json::from_value(v.clone()).ok()
}

/// Channel-wise equal within `tol` (8-bit; the canvas parse of one CSS colour is exact).
fn near(a: &[i64], b: &[i64], tol: i64) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| (x - y).abs() <= tol)
}

/// The problems of one multi-target measurement (empty: drawn in the theme's colours).
fn mtl_problems(v: &Value) -> Vec<String> {
    let theme = v["theme"].as_str().unwrap_or("?");
    let mut bad = Vec::new();
    match (rgba(&v["bgPixel"]), rgba(&v["plotBg"])) {
        (Some(px), Some(bg)) if near(&px, &bg[..3], 1) => {}
        (px, bg) => bad.push(format!(
            "{theme}: plot background pixel {px:?}, --plot-bg {bg:?}"
        )),
    }
    if v["reported"] != true {
        bad.push(format!(
            "{theme}: the drawing reports no colours (mtl.state().colors)"
        ));
    }
    for s in v["symbols"].as_array().into_iter().flatten() {
        let key = s["key"].as_str().unwrap_or("?");
        match (rgba(&s["legend"]), rgba(&s["drawn"])) {
            (Some(l), Some(d)) if near(&l, &d, 0) => {}
            (l, d) => bad.push(format!("{theme}: {key}: legend {l:?}, drawn {d:?}")),
        }
    }
    bad
}

async fn mtl_measure(c: &Client, port: u16) -> Result<(Vec<Value>, Vec<String>), String> {
    c.set_window_size(1440, 900)
        .await
        .map_err(|e| e.to_string())?;
    reopen(c, port, "#mode=mtl").await?;
    wait_view(c, 120).await?;
    settle(c).await?;
    let mut out = Vec::new();
    for theme in THEMES {
        set_theme(c, theme).await?;
        out.push(js(c, MTL_COLOURS).await?);
    }
    js(c, "window.theme.set(null)").await?;
    Ok((out, console_errors(c).await?))
}

#[test]
#[ignore = "needs chromedriver + Chromium + wasm build in www/pkg"]
fn mtl_draws_in_theme_colours() {
    let (runs, errors) = with_browser(async |c, port, _| mtl_measure(c, port).await);
    let mut bad = Vec::new();
    for v in &runs {
        println!(
            "multi-target {}: background pixel {} (--plot-bg {})",
            v["theme"], v["bgPixel"], v["plotBg"]
        );
        for s in v["symbols"].as_array().into_iter().flatten() {
            println!(
                "  {:<10} legend {} drawn {}",
                s["key"].as_str().unwrap_or("?"),
                s["legend"],
                s["drawn"]
            );
        }
        bad.extend(mtl_problems(v));
    }
    assert!(bad.is_empty(), "multi-target colours:\n{}", bad.join("\n"));
    assert!(errors.is_empty(), "console errors: {errors:?}");
}

async fn inset_measure(c: &Client, port: u16) -> Result<(Vec<Value>, Vec<String>), String> {
    c.set_window_size(1440, 900)
        .await
        .map_err(|e| e.to_string())?;
    reopen(c, port, "#mode=tracking&track=II&step=45").await?;
    poll(
        c,
        "return window.pictures.inset()",
        60,
        "tracking inset",
        |v| v["box"].is_object(),
    )
    .await?;
    settle(c).await?;
    let mut out = Vec::new();
    for theme in THEMES {
        set_theme(c, theme).await?;
        let mut v = js(c, INSET_TITLE).await?;
        v["theme"] = Value::from(theme);
        out.push(v);
    }
    js(c, "window.theme.set(null)").await?;
    Ok((out, console_errors(c).await?))
}

#[test]
#[ignore = "needs chromedriver + Chromium + wasm build in www/pkg"]
fn inset_title_clear_of_close_button() {
    let (runs, errors) = with_browser(async |c, port, _| inset_measure(c, port).await);
    let mut bad = Vec::new();
    for v in &runs {
        let theme = v["theme"].as_str().unwrap_or("?");
        println!("tracking inset {theme}: {v}");
        if let Some(e) = v["error"].as_str() {
            bad.push(format!("{theme}: {e}"));
            continue;
        }
        let close_x = v["close"]["x"].as_f64().unwrap_or(f64::NAN);
        let tb = &v["titleBox"];
        let right = tb["x"].as_f64().unwrap_or(f64::NAN) + tb["w"].as_f64().unwrap_or(f64::NAN);
        let measured = v["measuredRight"].as_f64().unwrap_or(f64::NAN);
        // The ink box must end left of the button (the reported box and a fresh measureText).
        if !(right < close_x && measured < close_x) {
            bad.push(format!(
                "{theme}: title {:?} ends at {right:.1} px (measured {measured:.1}), × starts at {close_x:.1}",
                v["text"]
            ));
        }
        // A cut title keeps its full text as the header's accessible name.
        let full = v["full"].as_str().unwrap_or("");
        if full.is_empty() || !v["grip"].as_str().unwrap_or("").starts_with(full) {
            bad.push(format!(
                "{theme}: full title {full:?} not in the header's name {}",
                v["grip"]
            ));
        }
    }
    assert!(bad.is_empty(), "inset title:\n{}", bad.join("\n"));
    assert!(errors.is_empty(), "console errors: {errors:?}");
}

async fn channel_measure(c: &Client, port: u16) -> Result<(Vec<Value>, Vec<String>), String> {
    c.update_timeouts(TimeoutConfiguration::new(
        Some(Duration::from_secs(60)),
        None,
        None,
    ))
    .await
    .map_err(|e| e.to_string())?;
    let mut out = Vec::new();
    for (w, h) in [(1440u32, 900u32), (390, 844)] {
        c.set_window_size(w, h).await.map_err(|e| e.to_string())?;
        reopen(c, port, "#mode=channel").await?;
        for theme in THEMES {
            set_theme(c, theme).await?;
            let mut v = js(c, CHANNEL_PANEL).await?;
            v["theme"] = Value::from(theme);
            v["window"] = Value::from(format!("{w}x{h}"));
            out.push(v);
        }
    }
    js(c, "window.theme.set(null)").await?;
    Ok((out, console_errors(c).await?))
}

#[test]
#[ignore = "needs chromedriver + Chromium + wasm build in www/pkg"]
fn channel_panel_no_sideways_scroll() {
    let (runs, errors) = with_browser(async |c, port, _| channel_measure(c, port).await);
    let mut bad = Vec::new();
    for v in &runs {
        let at = format!(
            "{} {}",
            v["window"].as_str().unwrap_or("?"),
            v["theme"].as_str().unwrap_or("?")
        );
        println!("channel panel {at}: {v}");
        let f = |p: &Value| p.as_f64().unwrap_or(f64::NAN);
        // NaN (a missing number) compares false, so it fails too.
        let le = |a: f64, b: f64| a <= b;
        if !le(f(&v["scrollWidth"]), f(&v["clientWidth"])) {
            bad.push(format!(
                "{at}: panel scrollWidth {} > clientWidth {}",
                v["scrollWidth"], v["clientWidth"]
            ));
        }
        if !le(f(&v["pageScroll"]), f(&v["pageClient"])) {
            bad.push(format!(
                "{at}: page scrollWidth {} > clientWidth {}",
                v["pageScroll"], v["pageClient"]
            ));
        }
        let (b, p) = (&v["button"], &v["panel"]);
        if !(f(&b["left"]) >= f(&p["left"]) - 0.5
            && f(&b["right"]) <= f(&p["right"]) + 0.5
            && f(&b["right"]) > f(&b["left"]))
        {
            bad.push(format!(
                "{at}: \"No empty recording\" {b} outside the panel {p}"
            ));
        }
    }
    assert!(bad.is_empty(), "channel panel:\n{}", bad.join("\n"));
    assert!(errors.is_empty(), "console errors: {errors:?}");
}
