//! Issue 16 §3: zoom and pan of the map in the three views, with real input through Chromium's
//! DevTools protocol (wheel, mouse drag, double-click, a two-finger pinch). After a zoom the CRLB
//! map is the core's map of the new window at the chosen grid (compared cell by cell with the
//! native map of that window), and the axes, the scale bar and the colour bar follow it.

use serde_json::{json, Value};

use scatterloc::localize::{crlb_map, Grid};
use scatterloc::scenario::Area;
use scatterloc::{scenario::presets, Model};

use super::layout::cdp;
use super::ui::{mc_done, wait_tracking};
use super::{console_errors, js, open, open_hash, settle, with_browser};

/// The map's values, the window and colour range they were drawn with, and its grid size.
type MapShown = (Vec<f64>, Vec<f64>, Vec<f64>, usize);

/// What the page showed after one gesture.
#[derive(Debug, Clone)]
struct Frame {
    zoom: Value,
    /// The map (snapshot, tracking).
    map: Option<MapShown>,
}

struct Outcome {
    /// "Copy link" after the wheel zoom, the page it opens, and a link with a bad window.
    link: String,
    shared: Frame,
    bad_view: (Value, Frame),
    snapshot: Vec<(&'static str, Frame)>,
    tracking: Vec<(&'static str, Frame)>,
    mtl: Vec<(&'static str, Frame)>,
    /// The plot pixel under the wheel, its metre point before and after the zoom.
    wheel_anchor: (Vec<f64>, Vec<f64>),
    pinch_anchor: (Vec<f64>, Vec<f64>),
    /// The pans' pointer travel as the page saw it, CSS px.
    snapshot_pan: [f64; 2],
    mtl_pan: [f64; 2],
    mtl_scene: (Value, Value),
    errors: Vec<String>,
}

async fn frame(c: &fantoccini::Client, with_map: bool) -> Result<Frame, String> {
    settle(c).await?;
    let zoom = js(c, "return window.zoom.state()").await?;
    let map = if with_map {
        let m = js(
            c,
            "const s = window.pageState; \
             return [Array.from(s.values), s.mapWindow, s.range, s.res];",
        )
        .await?;
        let values: Vec<f64> = m[0]
            .as_array()
            .ok_or("no map values")?
            .iter()
            .map(|v| v.as_f64().unwrap_or(f64::INFINITY))
            .collect();
        let window: Vec<f64> = serde_json::from_value(m[1].clone()).map_err(|e| e.to_string())?;
        let range: Vec<f64> = serde_json::from_value(m[2].clone()).map_err(|e| e.to_string())?;
        Some((values, window, range, m[3].as_u64().unwrap_or(0) as usize))
    } else {
        None
    };
    Ok(Frame { zoom, map })
}

/// The canvas' top-left corner in the viewport, CSS px.
async fn canvas_origin(c: &fantoccini::Client) -> Result<(f64, f64), String> {
    let r = js(
        c,
        "const b = document.getElementById('plot').getBoundingClientRect(); return [b.left, b.top];",
    )
    .await?;
    Ok((r[0].as_f64().unwrap_or(0.0), r[1].as_f64().unwrap_or(0.0)))
}

/// A plot pixel (canvas CSS px) near the fractions (fx, fy) of the plot with no object under it
/// within 30 px (so a press there pans).
async fn empty_pixel(c: &fantoccini::Client, fx: f64, fy: f64) -> Result<[f64; 2], String> {
    let p = c
        .execute(
            "const r = window.zoom.state().rect; \
             const ins = window.pictures ? window.pictures.inset().box : null; \
             const inInset = (x, y) => ins && x >= ins.x - 30 && x <= ins.x + ins.size + 30 \
               && y >= ins.y - 30 && y <= ins.y + ins.size + 30; \
             for (let k = 0; k < 400; k++) { \
               const x = r.x + r.w * Math.min(0.9, Math.max(0.1, arguments[0] + 0.03 * ((k % 20) - 10))); \
               const y = r.y + r.h * Math.min(0.9, Math.max(0.1, arguments[1] + 0.03 * (Math.floor(k / 20) - 10))); \
               let free = !inInset(x, y); \
               for (const [dx, dy] of [[0, 0], [30, 0], [-30, 0], [0, 30], [0, -30]]) \
                 if (window.zoom.hitAt(x + dx, y + dy)) free = false; \
               if (free) return [Math.round(x), Math.round(y)]; \
             } return null;",
            vec![json!(fx), json!(fy)],
        )
        .await
        .map_err(|e| e.to_string())?;
    serde_json::from_value(p).map_err(|e| format!("no empty pixel: {e}"))
}

async fn metre_at(c: &fantoccini::Client, p: [f64; 2]) -> Result<Vec<f64>, String> {
    let m = c
        .execute(
            "const m = window.zoom.toMetre(arguments[0], arguments[1]); return [m.x, m.y];",
            vec![json!(p[0]), json!(p[1])],
        )
        .await
        .map_err(|e| e.to_string())?;
    serde_json::from_value(m).map_err(|e| e.to_string())
}

fn mouse(
    dport: u16,
    session: &str,
    kind: &str,
    x: f64,
    y: f64,
    extra: Value,
) -> Result<(), String> {
    let mut params = json!({"type": kind, "x": x, "y": y});
    for (k, v) in extra.as_object().into_iter().flatten() {
        params[k] = v.clone();
    }
    cdp(dport, session, "Input.dispatchMouseEvent", params).map(|_| ())
}

/// A left-button drag from canvas pixel `p` by `d` CSS px in 4 moves.
/// Returns the pointer's travel from press to release as the page saw it (its pointerdown and
/// pointerup positions), CSS px.
async fn mouse_drag(
    c: &fantoccini::Client,
    dport: u16,
    session: &str,
    origin: (f64, f64),
    p: [f64; 2],
    d: [f64; 2],
) -> Result<[f64; 2], String> {
    js(
        c,
        "window.__press = {}; \
         for (const t of ['pointerdown', 'pointerup']) document.addEventListener(t, \
           (e) => { window.__press[t] = [e.clientX, e.clientY]; }, { capture: true, once: true });",
    )
    .await?;
    let (x, y) = (origin.0 + p[0], origin.1 + p[1]);
    mouse(dport, session, "mouseMoved", x, y, json!({}))?;
    tokio::time::sleep(std::time::Duration::from_millis(50)).await;
    let down = json!({"button": "left", "buttons": 1, "clickCount": 1});
    mouse(dport, session, "mousePressed", x, y, down.clone())?;
    for k in 1..=4 {
        let f = k as f64 / 4.0;
        tokio::time::sleep(std::time::Duration::from_millis(30)).await;
        mouse(
            dport,
            session,
            "mouseMoved",
            x + d[0] * f,
            y + d[1] * f,
            down.clone(),
        )?;
    }
    mouse(
        dport,
        session,
        "mouseReleased",
        x + d[0],
        y + d[1],
        json!({"button": "left", "buttons": 0, "clickCount": 1}),
    )?;
    // The release is handled before the caller reads the page.
    tokio::time::sleep(std::time::Duration::from_millis(100)).await;
    let seen = js(
        c,
        "const p = window.__press; return [p.pointerup[0] - p.pointerdown[0], p.pointerup[1] - p.pointerdown[1]];",
    )
    .await?;
    let travel: [f64; 2] = serde_json::from_value(seen).map_err(|e| e.to_string())?;
    println!("e2e zoom: drag of {d:?} px sent, {travel:?} px seen by the page");
    Ok(travel)
}

async fn run(c: &fantoccini::Client, port: u16, dport: u16) -> Result<Outcome, String> {
    let session = c
        .session_id()
        .await
        .map_err(|e| e.to_string())?
        .ok_or("no session id")?;
    open(c, port).await?;
    let origin = canvas_origin(c).await?;
    // Input lands on whole viewport pixels: the canvas pixel the browser will report.
    let snap = |p: [f64; 2]| {
        [
            (origin.0 + p[0]).round() - origin.0,
            (origin.1 + p[1]).round() - origin.1,
        ]
    };
    let wheel = |p: [f64; 2], dy: f64| {
        mouse(
            dport,
            &session,
            "mouseWheel",
            origin.0 + p[0],
            origin.1 + p[1],
            json!({"deltaX": 0, "deltaY": dy}),
        )
    };
    let drag = [80.0, -40.0];

    // Snapshot: wheel in (300 px up: ×2) about a plot point, pan by a drag, double-click back.
    let mut snapshot = vec![("home", frame(c, true).await?)];

    let p = snap(empty_pixel(c, 0.3, 0.6).await?);
    let before = metre_at(c, p).await?;
    wheel(p, -300.0)?;
    let f = frame(c, true).await?;
    let after = metre_at(c, p).await?;
    snapshot.push(("wheel", f));
    let link = c
        .execute_async(
            "const done = arguments[arguments.length - 1]; \
             window.shareLink().then(done, (e) => done('error: ' + e.message));",
            vec![],
        )
        .await
        .map_err(|e| e.to_string())?;
    let link = link.as_str().unwrap_or_default().to_string();
    let q = snap(empty_pixel(c, 0.5, 0.5).await?);
    let snapshot_pan = mouse_drag(c, dport, &session, origin, q, drag).await?;
    snapshot.push(("pan", frame(c, true).await?));
    let r = empty_pixel(c, 0.5, 0.5).await?;
    let (x, y) = (origin.0 + r[0], origin.1 + r[1]);
    for n in [1, 2] {
        mouse(
            dport,
            &session,
            "mousePressed",
            x,
            y,
            json!({"button": "left", "buttons": 1, "clickCount": n}),
        )?;
        mouse(
            dport,
            &session,
            "mouseReleased",
            x,
            y,
            json!({"button": "left", "buttons": 0, "clickCount": n}),
        )?;
    }
    snapshot.push(("double-click", frame(c, true).await?));

    // Tracking: the same view and map; the Zoom buttons and the wheel.
    js(c, "document.getElementById('mode-tracking').click()").await?;
    wait_tracking(c, 120, |s| {
        mc_done(s) && s["steps"].as_u64().unwrap_or(0) > 0
    })
    .await?;
    js(c, "window.tracking.pause()").await?;
    let mut tracking = vec![("home", frame(c, true).await?)];
    js(c, "document.getElementById('zoom-in').click()").await?;
    tracking.push(("button", frame(c, true).await?));
    let p = empty_pixel(c, 0.7, 0.3).await?;
    // The tracking view's plot head (its legend) is laid out on its own: the canvas may sit
    // lower or higher than in the snapshot view.
    let o = canvas_origin(c).await?;
    mouse(
        dport,
        &session,
        "mouseWheel",
        o.0 + p[0],
        o.1 + p[1],
        json!({"deltaX": 0, "deltaY": 300.0}),
    )?;
    tracking.push(("wheel out", frame(c, true).await?));
    js(c, "document.getElementById('zoom-reset').click()").await?;
    tracking.push(("reset", frame(c, true).await?));

    // Multi-target: a two-finger pinch (CDP touch) about the plot's centre, then a mouse pan.
    js(c, "document.getElementById('mode-mtl').click()").await?;
    settle(c).await?;
    let scene_before = js(c, "return window.mtl.state().scene").await?;
    let mut mtl = vec![("home", frame(c, false).await?)];
    cdp(
        dport,
        &session,
        "Emulation.setTouchEmulationEnabled",
        json!({"enabled": true, "maxTouchPoints": 5}),
    )?;
    // Touch emulation may restyle the page (coarse-pointer sizes): measure again.
    settle(c).await?;
    let origin = canvas_origin(c).await?;
    let rect = js(c, "return window.zoom.state().rect").await?;
    let mid = [
        (origin.0 + rect["x"].as_f64().unwrap_or(0.0) + rect["w"].as_f64().unwrap_or(0.0) / 2.0)
            .round()
            - origin.0,
        (origin.1 + rect["y"].as_f64().unwrap_or(0.0) + rect["h"].as_f64().unwrap_or(0.0) / 2.0)
            .round()
            - origin.1,
    ];
    let pinch_before = metre_at(c, mid).await?;
    let fingers = |half: f64| {
        json!([
            {"x": origin.0 + mid[0] - half, "y": origin.1 + mid[1], "id": 0, "radiusX": 6, "radiusY": 6, "force": 1},
            {"x": origin.0 + mid[0] + half, "y": origin.1 + mid[1], "id": 1, "radiusX": 6, "radiusY": 6, "force": 1},
        ])
    };
    cdp(
        dport,
        &session,
        "Input.dispatchTouchEvent",
        json!({"type": "touchStart", "touchPoints": fingers(40.0)}),
    )?;
    for half in [50.0, 60.0, 70.0, 80.0] {
        tokio::time::sleep(std::time::Duration::from_millis(30)).await;
        cdp(
            dport,
            &session,
            "Input.dispatchTouchEvent",
            json!({"type": "touchMove", "touchPoints": fingers(half)}),
        )?;
    }
    cdp(
        dport,
        &session,
        "Input.dispatchTouchEvent",
        json!({"type": "touchEnd", "touchPoints": []}),
    )?;
    cdp(
        dport,
        &session,
        "Emulation.setTouchEmulationEnabled",
        json!({"enabled": false}),
    )?;
    let f = frame(c, false).await?;
    let pinch_after = metre_at(c, mid).await?;
    mtl.push(("pinch", f));
    let q = snap(empty_pixel(c, 0.5, 0.5).await?);
    let mtl_pan = mouse_drag(c, dport, &session, origin, q, drag).await?;
    mtl.push(("pan", frame(c, false).await?));
    let scene_after = js(c, "return window.mtl.state().scene").await?;
    js(c, "document.getElementById('zoom-reset').click()").await?;
    mtl.push(("reset", frame(c, false).await?));

    let mut errors = console_errors(c).await?;
    // "Copy link" carries the zoomed window: the link opens on it, with its map; a bad window in
    // a link is named in the banner and the area is shown.
    let hash = link.split_once('#').map(|(_, h)| h).unwrap_or_default();
    c.goto("about:blank").await.map_err(|e| e.to_string())?;
    open_hash(c, port, &format!("#{hash}")).await?;
    let shared = frame(c, true).await?;
    errors.extend(console_errors(c).await?);
    c.goto("about:blank").await.map_err(|e| e.to_string())?;
    open_hash(c, port, "#view=1,1,0,1").await?;
    let bad_view = (
        js(
            c,
            "return document.getElementById('error-text').textContent",
        )
        .await?,
        frame(c, false).await?,
    );
    Ok(Outcome {
        link,
        shared,
        bad_view,
        snapshot,
        tracking,
        mtl,
        wheel_anchor: (before, after),
        pinch_anchor: (pinch_before, pinch_after),
        snapshot_pan,
        mtl_pan,
        mtl_scene: (scene_before, scene_after),
        errors,
    })
}

fn window(f: &Frame) -> [f64; 4] {
    serde_json::from_value(f.zoom["window"].clone()).expect("window")
}

fn home(f: &Frame) -> [f64; 4] {
    serde_json::from_value(f.zoom["home"].clone()).expect("home")
}

fn close(a: f64, b: f64, scale: f64, what: &str) {
    assert!((a - b).abs() <= 1e-9 * scale, "{what}: {a} vs {b}");
}

/// The window `w` is `h` zoomed by `factor` (its width `factor` times smaller), same aspect.
fn assert_zoomed(w: [f64; 4], h: [f64; 4], factor: f64, what: &str) {
    let span = h[1] - h[0];
    close(
        (h[1] - h[0]) / (w[1] - w[0]),
        factor,
        1.0,
        &format!("{what}: x zoom"),
    );
    close(
        (h[3] - h[2]) / (w[3] - w[2]),
        factor,
        1.0,
        &format!("{what}: y zoom"),
    );
    assert!(w.iter().all(|v| v.is_finite()), "{what}: {w:?} ({span})");
}

/// The map was recomputed for the window shown: drawn for exactly that window, at the full grid,
/// each cell the native core's value for that window's grid (1e-12 relative: wasm's libm against
/// glibc in the model's set-up), the colour bar spanning its values; the axis ticks lie in the
/// window and the scale bar is a fifth of it or less.
fn assert_map_follows(f: &Frame, model: &Model, what: &str) {
    let w = window(f);
    let (values, drawn, range, n) = f.map.as_ref().expect("map");
    assert_eq!(drawn.as_slice(), &w, "{what}: map drawn for another window");
    assert_eq!(values.len(), n * n, "{what}");
    assert_eq!(*n, 256, "{what}: the map at the chosen grid");
    let grid = Grid::new(
        Area {
            x: [w[0], w[1]],
            y: [w[2], w[3]],
        },
        *n,
        *n,
    )
    .unwrap();
    let mut want = vec![0.0; grid.len()];
    crlb_map(model, &grid, &mut want).unwrap();
    let worst = values
        .iter()
        .zip(&want)
        .map(|(a, b)| (a / b - 1.0).abs())
        .fold(0.0, f64::max);
    assert!(
        worst < 1e-12,
        "{what}: map vs native core over {w:?}: {worst:e}"
    );
    let lo = values.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    assert_eq!(range.as_slice(), &[lo, hi], "{what}: colour bar range");
    let ticks: Vec<f64> = serde_json::from_value(f.zoom["ticks"]["x"].clone()).expect("ticks");
    let yticks: Vec<f64> = serde_json::from_value(f.zoom["ticks"]["y"].clone()).expect("ticks");
    let eps = 1e-9 * (w[1] - w[0]);
    assert!(
        ticks.len() >= 2 && ticks.iter().all(|t| *t >= w[0] - eps && *t <= w[1] + eps),
        "{what}: x ticks {ticks:?} in {w:?}"
    );
    assert!(
        yticks.len() >= 2 && yticks.iter().all(|t| *t >= w[2] - eps && *t <= w[3] + eps),
        "{what}: y ticks {yticks:?} in {w:?}"
    );
    let bar = f.zoom["scaleBar"]["length_m"].as_f64().expect("scale bar");
    assert!(
        bar <= (w[1] - w[0]) / 5.0 + eps && bar >= (w[1] - w[0]) / 50.0,
        "{what}: scale bar {bar} m for {w:?}"
    );
}

/// A pan from window `a` to `b` (frame `f`, whose plot gives the scale) by a pointer travel of
/// `travel` CSS px: the same size, and the map moved exactly with the pointer (x: −dx, y: +dy in
/// metres per pixel; 1e-6 px). Until the status bar kept to one line this drifted by 0.93 px in
/// some runs: a reduced map's longer status text wrapped the bar and shrank the plot mid-drag.
fn assert_pan(a: [f64; 4], b: [f64; 4], f: &Frame, travel: [f64; 2], what: &str) {
    close(
        b[1] - b[0],
        a[1] - a[0],
        a[1] - a[0],
        &format!("{what}: width"),
    );
    close(
        b[3] - b[2],
        a[3] - a[2],
        a[3] - a[2],
        &format!("{what}: height"),
    );
    let scale = f.zoom["rect"]["w"].as_f64().unwrap() / (b[1] - b[0]);
    let moved = [(a[0] - b[0]) * scale, (b[2] - a[2]) * scale];
    let drift = ((moved[0] - travel[0]).powi(2) + (moved[1] - travel[1]).powi(2)).sqrt();
    println!("e2e zoom {what}: pointer {travel:?} px, map {moved:?} px (off by {drift:.3} px)");
    assert!(
        drift <= 1e-6,
        "{what}: the map moved {moved:?} px for a pointer travel of {travel:?} px"
    );
}

#[test]
#[ignore = "needs chromium + chromedriver and www/pkg (wasm-pack build); run with --ignored"]
fn wheel_pinch_and_pan_zoom_the_map_in_every_view() {
    let o = with_browser(async |c, port, dport| run(c, port, dport).await);
    assert!(o.errors.is_empty(), "console errors: {:?}", o.errors);
    for (view, frames) in [
        ("snapshot", &o.snapshot),
        ("tracking", &o.tracking),
        ("mtl", &o.mtl),
    ] {
        for (step, f) in frames.iter() {
            println!(
                "e2e zoom {view} {step}: window {:?} level {} scale bar {}",
                window(f),
                f.zoom["level"],
                f.zoom["scaleBar"]["label"]
            );
        }
    }
    let s = presets::sensors2019();
    let model = Model::new(&s).unwrap();
    let area = [s.area_m.x[0], s.area_m.x[1], s.area_m.y[0], s.area_m.y[1]];

    // Snapshot.
    let sn = &o.snapshot;
    assert_eq!(home(&sn[0].1), area);
    assert_eq!(window(&sn[0].1), area);
    assert_eq!(sn[0].1.zoom["zoomed"], false);
    assert_map_follows(&sn[0].1, &model, "snapshot home");
    // Wheel: 300 px up zooms in ×2 about the cursor, whose metre point stays under it.
    let w1 = window(&sn[1].1);
    assert_zoomed(w1, area, 2.0, "snapshot wheel");
    let (b, a) = &o.wheel_anchor;
    close(a[0], b[0], area[1] - area[0], "wheel anchor x");
    close(a[1], b[1], area[1] - area[0], "wheel anchor y");
    assert_eq!(sn[1].1.zoom["level"], "×2.0");
    assert_map_follows(&sn[1].1, &model, "snapshot wheel");
    // The shared link opens on the same window (to the last bit), with the map of that window.
    assert!(o.link.contains("view="), "{}", o.link);
    assert_eq!(window(&o.shared), w1, "{}", o.link);
    assert_map_follows(&o.shared, &model, "shared link");
    let (message, f) = &o.bad_view;
    let message = message.as_str().unwrap_or_default();
    assert!(message.contains("URL option view"), "{message}");
    assert_eq!(window(f), area, "a bad view option leaves the area shown");
    // Pan: the window keeps its size and moves with the pointer.
    assert_pan(
        w1,
        window(&sn[2].1),
        &sn[2].1,
        o.snapshot_pan,
        "snapshot pan",
    );
    assert_map_follows(&sn[2].1, &model, "snapshot pan");
    // Double-click on empty map: the whole area again.
    assert_eq!(window(&sn[3].1), area);
    assert_eq!(sn[3].1.zoom["level"], "fit");
    assert_map_follows(&sn[3].1, &model, "snapshot double-click");

    // Tracking: button ×1.5, wheel out 300 px (÷2) about another point, reset.
    let tr = &o.tracking;
    assert_eq!(window(&tr[0].1), area);
    assert_zoomed(window(&tr[1].1), area, 1.5, "tracking button");
    assert_map_follows(&tr[1].1, &model, "tracking button");
    assert_zoomed(window(&tr[2].1), area, 0.75, "tracking wheel out");
    assert_map_follows(&tr[2].1, &model, "tracking wheel out");
    assert_eq!(window(&tr[3].1), area);
    assert_map_follows(&tr[3].1, &model, "tracking reset");

    // Multi-target: the pinch doubled the fingers' spread (80 -> 160 px): ×2 about their
    // midpoint; the pan moved the window; neither moved an object; the button resets.
    let mt = &o.mtl;
    let mh = home(&mt[0].1);
    assert_eq!(window(&mt[0].1), mh);
    assert_zoomed(window(&mt[1].1), mh, 2.0, "mtl pinch");
    let (b, a) = &o.pinch_anchor;
    close(a[0], b[0], (mh[1] - mh[0]) * 1e3, "pinch anchor x");
    close(a[1], b[1], (mh[1] - mh[0]) * 1e3, "pinch anchor y");
    assert_pan(
        window(&mt[1].1),
        window(&mt[2].1),
        &mt[2].1,
        o.mtl_pan,
        "mtl pan",
    );
    assert_eq!(
        o.mtl_scene.0, o.mtl_scene.1,
        "the pinch and the pan moved no object"
    );
    assert_eq!(window(&mt[3].1), mh);
}
