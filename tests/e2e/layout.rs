//! Issue 16, items 1, 2 and 7: the page at phone, tablet, laptop and desktop widths in each view
//! (no sideways scroll, plot and panel apart, the mode buttons whole and clickable), and a finger
//! drag (CDP touch events through chromedriver) on a HiDPI phone viewport.

use std::io::{Read, Write};
use std::net::TcpStream;
use std::time::Duration;

use fantoccini::{Client, Locator};
use serde_json::{json, Value};

use super::ui::{poll, view_ready};
use super::{
    connect, console_errors, js, open_hash, runtime, settle, start_server, Driver, MAP_HASH, SERIAL,
};

/// Viewports (CSS px, innerWidth × innerHeight): the issue's phone portrait, tablet portrait /
/// split screen, small laptop and desktop, then the narrowest phone, a phone in landscape and 4K.
const VIEWPORTS: [(u32, u32); 7] = [
    (390, 844),
    (800, 1000),
    (1024, 768),
    (1440, 900),
    (360, 740),
    (844, 390),
    (3840, 2160),
];

/// The three views: URL hash, mode name, and the mode whose button is clicked from it.
const VIEWS: [(&str, &str, &str); 3] = [
    ("", "snapshot", "tracking"),
    ("#mode=tracking", "tracking", "mtl"),
    ("#mode=mtl", "mtl", "snapshot"),
];

/// What the page measures of its own layout (CSS px; rects as [left, top, right, bottom]).
const MEASURE: &str = r#"
// The window's inner size less any scroll bar (documentElement.clientWidth × clientHeight).
const vw = document.documentElement.clientWidth, vh = document.documentElement.clientHeight;
const R = (e) => { const r = e.getBoundingClientRect(); return [r.left, r.top, r.right, r.bottom]; };
const inside = (a, b) => a[0] >= b[0] - 0.5 && a[1] >= b[1] - 0.5 && a[2] <= b[2] + 0.5 && a[3] <= b[3] + 0.5;
const overlap = (a, b) => Math.max(0, Math.min(a[2], b[2]) - Math.max(a[0], b[0]))
  * Math.max(0, Math.min(a[3], b[3]) - Math.max(a[1], b[1]));
const plotEl = document.getElementById('plot');
const plot = R(plotEl), card = R(document.querySelector('.plot-card'));
const panel = R(document.getElementById('panel'));
const topbar = R(document.querySelector('.topbar')), modes = R(document.querySelector('.modes'));
const view = [0, 0, vw, vh];
const buttons = ['snapshot', 'tracking', 'mtl'].map((m) => {
  const b = document.getElementById('mode-' + m);
  const r = R(b);
  const e = document.elementFromPoint((r[0] + r[2]) / 2, (r[1] + r[3]) / 2);
  return {
    id: b.id, rect: r,
    visible: inside(r, view) && inside(r, topbar) && inside(r, modes) && b.scrollWidth <= b.clientWidth,
    hit: !!e && (e === b || b.contains(e)),
  };
});
// Every visible control lies within the window's width (reachable without sideways scrolling).
const outside = [];
for (const e of document.querySelectorAll('button, input, select, label.button')) {
  const r = e.getBoundingClientRect();
  if (r.width === 0 || r.height === 0 || e.classList.contains('visually-hidden')) continue;
  if (r.left < -0.5 || r.right > vw + 0.5) outside.push(`${e.id || e.tagName} [${r.left.toFixed(1)}, ${r.right.toFixed(1)}]`);
}
// The status read-outs lengthen while dragging (the map's "… while dragging (… on release) …"):
// the plot keeps its size whatever they say (else the map jumps under the pointer mid-drag).
const reads = ['map-ms', 'mc-ms', 'mtl-ms'].map((id) => document.getElementById(id));
const saved = reads.map((e) => e.textContent);
for (const e of reads) e.textContent = 'map 1024×1024 while dragging (1024×1024 on release): 1234.5 ms · computing in a worker…';
const plotLong = R(plotEl);
reads.forEach((e, i) => { e.textContent = saved[i]; });
const dpr = window.devicePixelRatio || 1;
return {
  plotLong, plotSteady: plotLong.every((v, i) => Math.abs(v - plot[i]) <= 0.5),
  vw, vh, dpr, innerWidth: window.innerWidth,
  scrollWidth: document.documentElement.scrollWidth,
  bodyScrollWidth: document.body.scrollWidth,
  plot, card, panel, topbar,
  overlapPlotPanel: overlap(plot, panel),
  overlapCardPanel: overlap(card, panel),
  plotInCard: inside(plot, card),
  backing: [plotEl.width, plotEl.height],
  sharp: plotEl.width === Math.round((plot[2] - plot[0]) * dpr) && plotEl.height === Math.round((plot[3] - plot[1]) * dpr),
  buttons, outside,
  mode: window.pageState.mode,
};
"#;

/// Sizes the window so that the page's innerWidth × innerHeight is `w` × `h` (the window chrome
/// measured as outer − inner size; re-measured until the page reports the size, since a resize
/// lands asynchronously).
async fn set_viewport(c: &Client, w: u32, h: u32) -> Result<(), String> {
    let mut inner = Value::Null;
    for _ in 0..10 {
        let chrome = js(
            c,
            "return [outerWidth - innerWidth, outerHeight - innerHeight]",
        )
        .await?;
        let chrome: Vec<i64> = serde_json::from_value(chrome).map_err(|e| e.to_string())?;
        let (cw, ch) = (chrome[0].max(0) as u32, chrome[1].max(0) as u32);
        c.set_window_size(w + cw, h + ch)
            .await
            .map_err(|e| e.to_string())?;
        for _ in 0..10 {
            inner = js(c, "return [innerWidth, innerHeight]").await?;
            if inner == json!([w, h]) {
                return Ok(());
            }
            tokio::time::sleep(Duration::from_millis(50)).await;
        }
    }
    Err(format!("viewport {w}×{h} asked, {inner} set"))
}

/// Clicks the mode button `to` with a real (WebDriver) click and waits for the page to switch.
async fn click_mode(c: &Client, to: &str) -> Result<Value, String> {
    c.find(Locator::Id(&format!("mode-{to}")))
        .await
        .map_err(|e| e.to_string())?
        .click()
        .await
        .map_err(|e| format!("click #mode-{to}: {e}"))?;
    poll(
        c,
        "return {mode: window.pageState.mode, \
         pressed: ['snapshot', 'tracking', 'mtl'].filter((m) => \
           document.getElementById('mode-' + m).getAttribute('aria-pressed') === 'true'), \
         body: document.body.className}",
        5,
        &format!("#mode-{to} clicked"),
        |s| s["mode"] == to,
    )
    .await
}

/// One row of the layout table: viewport, view, measurements, and the state after the click.
struct Row {
    w: u32,
    h: u32,
    mode: &'static str,
    to: &'static str,
    m: Value,
    after_click: Value,
    errors: Vec<String>,
}

/// At 390, 800, 1024 and 1440 px (and 360 × 740, 844 × 390 landscape, 3840 × 2160), in each view: no horizontal scroll, the plot canvas inside its
/// card and clear of the panel, every control within the window's width, the canvas' backing
/// store sharp (CSS size × devicePixelRatio), the plot's size independent of the status bar's
/// read-outs (they lengthen while dragging), and the three mode buttons whole inside the top bar,
/// on top at their centres (elementFromPoint) and switching the view when clicked.
#[test]
#[ignore = "needs chromium + chromedriver and www/pkg (wasm-pack build); run with --ignored"]
fn layout_at_four_widths_in_three_views() {
    let _serial = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    let port = start_server();
    let driver = Driver::start();
    let rows = runtime().block_on(async {
        let c = connect(&driver).await;
        let r = async {
            let mut rows = Vec::new();
            for (w, h) in VIEWPORTS {
                set_viewport(&c, w, h).await?;
                for (hash, mode, to) in VIEWS {
                    open_hash(&c, port, hash).await?;
                    view_ready(&c).await?;
                    let m = js(&c, MEASURE).await?;
                    let after_click = click_mode(&c, to).await?;
                    rows.push(Row {
                        w,
                        h,
                        mode,
                        to,
                        m,
                        after_click,
                        errors: console_errors(&c).await?,
                    });
                }
            }
            Ok::<_, String>(rows)
        }
        .await;
        let _ = c.close().await;
        r
    });
    drop(driver);
    let rows = rows.unwrap_or_else(|e| panic!("{e}"));

    let mut failures = Vec::new();
    for r in &rows {
        let m = &r.m;
        let f = |v: &Value| v.as_f64().unwrap_or(f64::NAN);
        let rect = |v: &Value| -> String {
            let v: Vec<f64> = serde_json::from_value(v.clone()).unwrap_or_default();
            format!("{v:.0?}")
        };
        println!(
            "layout {:>4}×{:<4} {:<8}: scrollWidth {} (clientWidth {}), plot {} card {} panel {}, \
             overlap plot/panel {} card/panel {}, backing {} dpr {}",
            r.w,
            r.h,
            r.mode,
            m["scrollWidth"],
            m["vw"],
            rect(&m["plot"]),
            rect(&m["card"]),
            rect(&m["panel"]),
            m["overlapPlotPanel"],
            m["overlapCardPanel"],
            m["backing"],
            m["dpr"],
        );
        let mut fail = |what: String| failures.push(format!("{}×{} {}: {what}", r.w, r.h, r.mode));
        if m["innerWidth"] != json!(r.w) {
            fail(format!("innerWidth {}", m["innerWidth"]));
        }
        if m["mode"] != r.mode {
            fail(format!("page opened in mode {}", m["mode"]));
        }
        if f(&m["scrollWidth"]) > f(&m["vw"]) {
            fail(format!(
                "scrolls sideways: scrollWidth {} > clientWidth {}",
                m["scrollWidth"], m["vw"]
            ));
        }
        if f(&m["overlapPlotPanel"]) > 0.0 || f(&m["overlapCardPanel"]) > 0.0 {
            fail(format!(
                "plot {} / card {} overlap the panel {}",
                rect(&m["plot"]),
                rect(&m["card"]),
                rect(&m["panel"])
            ));
        }
        if m["plotInCard"] != true {
            fail(format!(
                "plot canvas {} outside its card {}",
                rect(&m["plot"]),
                rect(&m["card"])
            ));
        }
        let p: Vec<f64> = serde_json::from_value(m["plot"].clone()).unwrap_or_default();
        if p.len() != 4 || p[2] - p[0] < 200.0 || p[3] - p[1] < 200.0 {
            fail(format!("plot canvas too small: {}", rect(&m["plot"])));
        }
        if m["plotSteady"] != true {
            fail(format!(
                "the plot {} resizes to {} when the status read-outs lengthen",
                rect(&m["plot"]),
                rect(&m["plotLong"])
            ));
        }
        if m["sharp"] != true {
            fail(format!(
                "backing store {} is not CSS size × dpr {}",
                m["backing"], m["dpr"]
            ));
        }
        if m["outside"].as_array().is_some_and(|a| !a.is_empty()) {
            fail(format!("controls outside the window: {}", m["outside"]));
        }
        for b in m["buttons"].as_array().into_iter().flatten() {
            if b["visible"] != true {
                fail(format!(
                    "#{} not whole inside the window and the top bar: {}",
                    b["id"].as_str().unwrap_or("?"),
                    rect(&b["rect"])
                ));
            }
            if b["hit"] != true {
                fail(format!(
                    "#{} not on top at its centre",
                    b["id"].as_str().unwrap_or("?")
                ));
            }
        }
        let a = &r.after_click;
        let body_class = a["body"].as_str().unwrap_or("");
        let class_ok = match r.to {
            "tracking" => body_class.contains("mode-tracking"),
            "mtl" => body_class.contains("mode-mtl"),
            _ => !body_class.contains("mode-"),
        };
        if a["pressed"] != json!([r.to]) || !class_ok {
            fail(format!("click on #mode-{} gave {a}", r.to));
        }
        if !r.errors.is_empty() {
            fail(format!("console errors: {:?}", r.errors));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Chromium's DevTools protocol through chromedriver (`goog/cdp/execute`), for what WebDriver
/// has no command for (touch events, device emulation). A plain HTTP/1.1 POST, std only.
pub(super) fn cdp(
    driver_port: u16,
    session: &str,
    cmd: &str,
    params: Value,
) -> Result<Value, String> {
    let body = json!({ "cmd": cmd, "params": params }).to_string();
    let mut s = TcpStream::connect(("127.0.0.1", driver_port)).map_err(|e| e.to_string())?;
    s.set_read_timeout(Some(Duration::from_secs(30)))
        .map_err(|e| e.to_string())?;
    let req = format!(
        "POST /session/{session}/goog/cdp/execute HTTP/1.1\r\nHost: 127.0.0.1:{driver_port}\r\n\
         Content-Type: application/json; charset=utf-8\r\nContent-Length: {}\r\n\
         Connection: close\r\n\r\n{body}",
        body.len()
    );
    s.write_all(req.as_bytes()).map_err(|e| e.to_string())?;
    // Headers, then Content-Length bytes (chromedriver may keep the connection open).
    let mut buf = Vec::new();
    let mut chunk = [0u8; 4096];
    let (head, body_len, body_start) = loop {
        let n = s.read(&mut chunk).map_err(|e| format!("{cmd}: {e}"))?;
        if n == 0 {
            return Err(format!("{cmd}: connection closed mid-response"));
        }
        buf.extend_from_slice(&chunk[..n]);
        if let Some(i) = buf.windows(4).position(|w| w == b"\r\n\r\n") {
            let head = String::from_utf8_lossy(&buf[..i]).to_string();
            let len = head
                .lines()
                .find_map(|l| {
                    let (k, v) = l.split_once(':')?;
                    k.eq_ignore_ascii_case("content-length")
                        .then(|| v.trim().parse::<usize>().ok())?
                })
                .ok_or_else(|| format!("{cmd}: no Content-Length in {head}"))?;
            break (head, len, i + 4);
        }
    };
    while buf.len() < body_start + body_len {
        let n = s.read(&mut chunk).map_err(|e| format!("{cmd}: {e}"))?;
        if n == 0 {
            break;
        }
        buf.extend_from_slice(&chunk[..n]);
    }
    let json_body = String::from_utf8_lossy(&buf[body_start..]).to_string();
    if !head.starts_with("HTTP/1.1 200") {
        return Err(format!("{cmd}: {head} {json_body}"));
    }
    let v: Value =
        serde_json::from_str(json_body.trim()).map_err(|e| format!("{cmd}: {e}: {json_body}"))?;
    Ok(v["value"].clone())
}

/// What the touch test reads from the page.
struct TouchOutcome {
    dpr: f64,
    backing: Vec<f64>,
    css: Vec<f64>,
    before: Vec<f64>,
    after: Vec<f64>,
    expected: Vec<f64>,
    metre_per_px: f64,
    hash_before: u64,
    hash_after: u64,
    drag_maps: usize,
    map_matches_core: bool,
    scroll_y: Vec<f64>,
    errors: Vec<String>,
}

/// A finger drag on a 390 × 844 phone viewport at devicePixelRatio 2 (CDP device emulation with
/// touch): the touch starts 16 CSS px from receiver Rx2 (outside the mouse's 12 px pick radius,
/// inside the finger's 22 px), moves in 8 steps, and the receiver ends under the finger; the map
/// was recomputed while dragging and the final map is the core's map of the new geometry; the
/// page did not scroll; the plot canvas' backing store is twice its CSS size.
#[test]
#[ignore = "needs chromium + chromedriver and www/pkg (wasm-pack build); run with --ignored"]
fn touch_drag_moves_node_and_recomputes_map() {
    let _serial = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    let port = start_server();
    let driver = Driver::start();
    let dport = driver.port;
    let outcome = runtime().block_on(async {
        let c = connect(&driver).await;
        let r = async {
            let session = c
                .session_id()
                .await
                .map_err(|e| e.to_string())?
                .ok_or("no session id")?;
            cdp(
                dport,
                &session,
                "Emulation.setDeviceMetricsOverride",
                json!({"width": 390, "height": 844, "deviceScaleFactor": 2, "mobile": true}),
            )?;
            cdp(
                dport,
                &session,
                "Emulation.setTouchEmulationEnabled",
                json!({"enabled": true, "maxTouchPoints": 5}),
            )?;
            open_hash(&c, port, "").await?;
            settle(&c).await?;
            // Scrolled so that the plot is in view, as a user would see it.
            js(
                &c,
                "document.getElementById('plot').scrollIntoView({block: 'center'})",
            )
            .await?;
            settle(&c).await?;
            js(&c, "window.pageState.refreshLog.length = 0").await?;
            let hash_before = js(&c, MAP_HASH).await?.as_u64().unwrap_or(0);
            let geo = js(
                &c,
                "const r = window.app.nodes().receivers[1]; const p = window.view.toPixel(r.x, r.y); \
                 const c = document.getElementById('plot'); const b = c.getBoundingClientRect(); \
                 return [b.left + p.x, b.top + p.y, r.x, r.y, window.devicePixelRatio, \
                   c.width, c.height, b.width, b.height, window.scrollY, \
                   1 / window.view.scale];",
            )
            .await?;
            let g: Vec<f64> = serde_json::from_value(geo).map_err(|e| e.to_string())?;
            // Start 16 px left of the marker (a finger's miss), then 8 moves of (+6, +4) px.
            let (x0, y0) = ((g[0] - 16.0).round(), g[1].round());
            let point = |x: f64, y: f64| json!([{"x": x, "y": y, "radiusX": 8, "radiusY": 8, "force": 1, "id": 0}]);
            cdp(
                dport,
                &session,
                "Input.dispatchTouchEvent",
                json!({"type": "touchStart", "touchPoints": point(x0, y0)}),
            )?;
            let (mut x, mut y) = (x0, y0);
            for _ in 0..8 {
                x += 6.0;
                y += 4.0;
                tokio::time::sleep(Duration::from_millis(40)).await;
                cdp(
                    dport,
                    &session,
                    "Input.dispatchTouchEvent",
                    json!({"type": "touchMove", "touchPoints": point(x, y)}),
                )?;
            }
            let mid_scroll = js(&c, "return window.scrollY").await?.as_f64().unwrap_or(-1.0);
            cdp(
                dport,
                &session,
                "Input.dispatchTouchEvent",
                json!({"type": "touchEnd", "touchPoints": []}),
            )?;
            settle(&c).await?;
            tokio::time::sleep(Duration::from_millis(100)).await;
            settle(&c).await?;
            let fin = c
                .execute(
                    "const r = window.app.nodes().receivers[1]; \
                     const b = document.getElementById('plot').getBoundingClientRect(); \
                     const m = window.view.toMetre(arguments[0] - b.left, arguments[1] - b.top); \
                     return [r.x, r.y, m.x, m.y, window.scrollY];",
                    vec![json!(x), json!(y)],
                )
                .await
                .map_err(|e| e.to_string())?;
            let fin: Vec<f64> = serde_json::from_value(fin).map_err(|e| e.to_string())?;
            let hash_after = js(&c, MAP_HASH).await?.as_u64().unwrap_or(0);
            let log: Vec<Value> =
                serde_json::from_value(js(&c, "return window.refreshLog()").await?)
                    .map_err(|e| e.to_string())?;
            let drag_maps = log
                .iter()
                .filter(|r| r["dragging"] == true && r["map"] == true)
                .count();
            // The map shown vs the core's map of the final geometry at the page's resolution.
            let same = js(
                &c,
                "const n = window.pageState.res; const b = new Float64Array(n * n); \
                 window.app.compute_map(n, n, b); const v = window.pageState.values; \
                 let same = v.length === b.length; \
                 for (let i = 0; same && i < b.length; i++) same = Object.is(v[i], b[i]); \
                 return same;",
            )
            .await?;
            Ok::<_, String>(TouchOutcome {
                dpr: g[4],
                backing: vec![g[5], g[6]],
                css: vec![g[7], g[8]],
                before: vec![g[2], g[3]],
                after: fin[0..2].to_vec(),
                expected: fin[2..4].to_vec(),
                metre_per_px: g[10],
                hash_before,
                hash_after,
                drag_maps,
                map_matches_core: same == true,
                scroll_y: vec![g[9], mid_scroll, fin[4]],
                errors: console_errors(&c).await?,
            })
        }
        .await;
        let _ = c.close().await;
        r
    });
    drop(driver);
    let o = outcome.unwrap_or_else(|e| panic!("{e}"));
    println!(
        "touch: dpr {} backing {:?} for CSS {:?}; Rx2 {:?} -> {:?} (finger at {:?}), \
         {} map refreshes while dragging, scrollY {:?}",
        o.dpr, o.backing, o.css, o.before, o.after, o.expected, o.drag_maps, o.scroll_y
    );
    assert!(o.errors.is_empty(), "console errors: {:?}", o.errors);
    assert_eq!(o.dpr, 2.0, "device emulation");
    assert_eq!(
        o.backing,
        vec![(o.css[0] * 2.0).round(), (o.css[1] * 2.0).round()],
        "HiDPI backing store"
    );
    // Moved right and down by 48 × 32 CSS px (less the 16 px start offset), ending under the finger.
    let moved = (o.after[0] - o.before[0], o.after[1] - o.before[1]);
    assert!(
        moved.0 > 0.0 && moved.1 < 0.0,
        "Rx2 should follow the finger: {:?} -> {:?}",
        o.before,
        o.after
    );
    let off = (o.after[0] - o.expected[0]).hypot(o.after[1] - o.expected[1]);
    assert!(
        off <= 1.5 * o.metre_per_px,
        "Rx2 at {:?}, the finger at {:?} ({off} m apart)",
        o.after,
        o.expected
    );
    assert_ne!(o.hash_before, o.hash_after, "the map should be redrawn");
    assert!(o.drag_maps > 0, "no map recompute while dragging");
    assert!(
        o.map_matches_core,
        "the map shown is not the core's map of the final geometry"
    );
    assert!(
        o.scroll_y[1] == o.scroll_y[0] && o.scroll_y[2] == o.scroll_y[0],
        "the page scrolled during the drag: scrollY {:?}",
        o.scroll_y
    );
}
