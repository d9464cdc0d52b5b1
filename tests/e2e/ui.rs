//! The browser tests' shared steps, one place for every module: acting on the page as a user
//! does (click, choose in a `<select>`, type into an input, keys), reading it (the error banner,
//! the views' state hooks, colours) and waiting for it (a script polled until a condition holds).

use std::path::PathBuf;
use std::time::{Duration, Instant};

use fantoccini::actions::{InputSource, KeyAction, KeyActions};
use fantoccini::{Client, Locator};
use serde_json::Value;

use super::{console_errors, js, settle};

/// WebDriver's Control and Shift keys (modifiers for [`press`]).
pub(super) const CONTROL: char = '\u{E009}';
pub(super) const SHIFT: char = '\u{E008}';
// WebDriver's Enter and "no key" (which releases the modifiers held in a text).
const ENTER: char = '\u{E007}';
const NULL_KEY: char = '\u{E000}';
/// WebDriver's Home, End and Right arrow keys, as text for [`keys`].
pub(super) const HOME: &str = "\u{E011}";
pub(super) const END: &str = "\u{E010}";
pub(super) const RIGHT: &str = "\u{E014}";

/// Clicks element `id` (a real click: it must be visible and enabled).
pub(super) async fn click(c: &Client, id: &str) -> Result<(), String> {
    let e = c.find(Locator::Id(id)).await.map_err(|e| e.to_string())?;
    e.click().await.map_err(|e| format!("click {id}: {e}"))
}

/// Chooses `value` in `<select>` `id` as a user does.
pub(super) async fn select(c: &Client, id: &str, value: &str) -> Result<(), String> {
    let e = c.find(Locator::Id(id)).await.map_err(|e| e.to_string())?;
    e.select_by_value(value)
        .await
        .map_err(|e| format!("select {id} = {value}: {e}"))
}

/// Types `text` over the whole content of input `id` (Ctrl+A, the text, Enter).
pub(super) async fn type_in(c: &Client, id: &str, text: &str) -> Result<(), String> {
    let e = c.find(Locator::Id(id)).await.map_err(|e| e.to_string())?;
    e.click().await.map_err(|e| format!("click {id}: {e}"))?;
    e.send_keys(&format!("{CONTROL}a{NULL_KEY}{text}{ENTER}"))
        .await
        .map_err(|e| format!("type into {id}: {e}"))
}

/// Keys typed into element `id` (it gets the focus).
pub(super) async fn keys(c: &Client, id: &str, k: &str) -> Result<(), String> {
    let e = c.find(Locator::Id(id)).await.map_err(|e| e.to_string())?;
    e.send_keys(k)
        .await
        .map_err(|e| format!("keys to {id}: {e}"))
}

/// Presses `keys` in turn (each down then up) on the focused element, with the modifiers `mods`
/// held throughout.
pub(super) async fn press(c: &Client, mods: &[char], keys: &[char]) -> Result<(), String> {
    let mut k = KeyActions::new("keyboard".to_string());
    for &m in mods {
        k = k.then(KeyAction::Down { value: m });
    }
    for &key in keys {
        k = k
            .then(KeyAction::Down { value: key })
            .then(KeyAction::Up { value: key });
    }
    for &m in mods.iter().rev() {
        k = k.then(KeyAction::Up { value: m });
    }
    c.perform_actions(k).await.map_err(|e| e.to_string())
}

/// The error banner's text, or "" while it is hidden.
pub(super) async fn banner(c: &Client) -> Result<String, String> {
    let v = js(
        c,
        "const e = document.getElementById('error'); \
         return e.hidden ? '' : document.getElementById('error-text').textContent;",
    )
    .await?;
    Ok(v.as_str().unwrap_or_default().to_string())
}

/// The error banner's text once it is shown (at most 10 s), or "".
pub(super) async fn wait_banner(c: &Client) -> Result<String, String> {
    let t0 = Instant::now();
    loop {
        let b = banner(c).await?;
        if !b.is_empty() || t0.elapsed() > Duration::from_secs(10) {
            return Ok(b);
        }
        tokio::time::sleep(Duration::from_millis(30)).await;
    }
}

/// Polls `script` (a `return …`) until `done` holds of its value (at most `secs`); the error
/// names `what` and the last value.
pub(super) async fn poll(
    c: &Client,
    script: &str,
    secs: u64,
    what: &str,
    done: impl Fn(&Value) -> bool,
) -> Result<Value, String> {
    poll_checked(c, script, secs, what, false, done).await
}

/// [`poll`], failing at once on a console error when `fail_on_console` (a job that threw will not
/// reach its state).
async fn poll_checked(
    c: &Client,
    script: &str,
    secs: u64,
    what: &str,
    fail_on_console: bool,
    done: impl Fn(&Value) -> bool,
) -> Result<Value, String> {
    let t0 = Instant::now();
    loop {
        let v = js(c, script).await?;
        if done(&v) {
            return Ok(v);
        }
        if fail_on_console {
            let errors = console_errors(c).await?;
            if !errors.is_empty() {
                return Err(format!("{what}: console errors {errors:?}; state {v}"));
            }
        }
        if t0.elapsed() > Duration::from_secs(secs) {
            return Err(format!("{what}: not after {secs} s; last {v}"));
        }
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
}

/// The channel view's state hook (`window.channel.state()`).
pub(super) async fn channel_state(c: &Client) -> Result<Value, String> {
    js(c, "return window.channel.state()").await
}

/// Polls the channel view's state until `done` holds (at most `secs`), failing fast on a console
/// error.
pub(super) async fn wait_channel(
    c: &Client,
    secs: u64,
    what: &str,
    done: impl Fn(&Value) -> bool,
) -> Result<Value, String> {
    poll_checked(c, "return window.channel.state()", secs, what, true, done).await
}

/// The tracking view's state hook (`window.tracking.state()`).
pub(super) async fn tracking_state(c: &Client) -> Result<Value, String> {
    js(c, "return window.tracking.state()").await
}

/// Polls the tracking view's state until `done` holds (at most `secs`).
pub(super) async fn wait_tracking(
    c: &Client,
    secs: u64,
    done: impl Fn(&Value) -> bool,
) -> Result<Value, String> {
    poll(c, "return window.tracking.state()", secs, "tracking", done).await
}

/// The tracking view's Monte Carlo study is done.
pub(super) fn mc_done(s: &Value) -> bool {
    s["mcState"] == "done"
}

/// The multi-target view's state hook (`window.mtl.state()`).
pub(super) async fn mtl_state(c: &Client) -> Result<Value, String> {
    js(c, "return window.mtl.state()").await
}

/// Waits for the multi-target view's worker to answer the latest scene (at most `secs`).
pub(super) async fn wait_view(c: &Client, secs: u64) -> Result<Value, String> {
    poll(c, "return window.mtl.state()", secs, "no view", |s| {
        s["pending"] == false && s["viewGen"].as_u64().unwrap_or(0) > 0
    })
    .await
}

/// Waits until the view on screen has drawn: the page idle and, in the multi-target view, its
/// worker's first result.
pub(super) async fn view_ready(c: &Client) -> Result<(), String> {
    settle(c).await?;
    if js(c, "return window.pageState.mode").await? == "mtl" {
        wait_view(c, 60).await?;
    }
    settle(c).await
}

/// A JSON list of points `[[x, y]…]` (empty where it is not one).
pub(super) fn points(v: &Value) -> Vec<[f64; 2]> {
    serde_json::from_value(v.clone()).unwrap_or_default()
}

/// WCAG relative luminance of an 8-bit sRGB colour `[r, g, b, …]`.
pub(super) fn luminance(c: &[f64]) -> f64 {
    let lin = |v: f64| {
        let s = v / 255.0;
        if s <= 0.04045 {
            s / 12.92
        } else {
            ((s + 0.055) / 1.055).powf(2.4)
        }
    };
    0.2126 * lin(c[0]) + 0.7152 * lin(c[1]) + 0.0722 * lin(c[2])
}

/// WCAG contrast ratio of two colours (`[r, g, b, …]`, 8 bit).
pub(super) fn contrast(a: &[f64], b: &[f64]) -> f64 {
    let (la, lb) = (luminance(a), luminance(b));
    (la.max(lb) + 0.05) / (la.min(lb) + 0.05)
}

/// A fresh, empty directory `scatterloc-e2e-<name>-<pid>` in the system's temp directory.
pub(super) fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("scatterloc-e2e-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}
