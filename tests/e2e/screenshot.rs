//! The docs screenshots (docs/screenshot-tracking.png by default; any mode through
//! `SCATTERLOC_SCREENSHOT_HASH`; `mode=channel` simulates, estimates and tracks a walk first), taken through the same browser harness as the end-to-end tests.
//! Not a test (it asserts nothing): `cargo run --example screenshot` (examples/screenshot.rs).

use super::ui::{mc_done, wait_tracking};
use super::{connect, js, open_hash, runtime, settle, start_server, Driver, SERIAL};

/// Writes docs/screenshot-tracking.png (tracking mode, scenario II at 4.5 s, the particle
/// filter animated, EKF, UKF and PF in the Monte Carlo, after a warm Monte Carlo re-run).
/// `SCATTERLOC_SCREENSHOT_HASH` (page options), `SCATTERLOC_SCREENSHOT_OUT` (a path) and
/// `SCATTERLOC_SCREENSHOT_SIZE` (the viewport, `WIDTHxHEIGHT` CSS px; 1400x900 by default) override.
/// Needs chromium + chromedriver (`CHROMEDRIVER`) and the page's wasm in www/pkg.
pub(crate) fn tracking_screenshot() {
    let hash = std::env::var("SCATTERLOC_SCREENSHOT_HASH")
        .unwrap_or_else(|_| "#mode=tracking&track=II&step=45&filter=pf&filters=ekf,ukf,pf".into());
    let out = std::env::var("SCATTERLOC_SCREENSHOT_OUT").unwrap_or_else(|_| {
        concat!(env!("CARGO_MANIFEST_DIR"), "/docs/screenshot-tracking.png").into()
    });
    let size: Vec<u32> = std::env::var("SCATTERLOC_SCREENSHOT_SIZE")
        .unwrap_or_else(|_| "1400x900".into())
        .split('x')
        .map(|v| {
            v.trim()
                .parse()
                .expect("SCATTERLOC_SCREENSHOT_SIZE: WIDTHxHEIGHT")
        })
        .collect();
    assert_eq!(size.len(), 2, "SCATTERLOC_SCREENSHOT_SIZE: WIDTHxHEIGHT");
    let _serial = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    let port = start_server();
    let driver = Driver::start();
    let png = runtime().block_on(async {
        let c = connect(&driver).await;
        let r = async {
            // A 1400 × 900 viewport by default, like docs/screenshot.png.
            let chrome = js(
                &c,
                "return [outerWidth - innerWidth, outerHeight - innerHeight]",
            )
            .await?;
            let chrome: Vec<u32> = serde_json::from_value(chrome).map_err(|e| e.to_string())?;
            c.set_window_size(size[0] + chrome[0], size[1] + chrome[1])
                .await
                .map_err(|e| e.to_string())?;
            open_hash(&c, port, &hash).await?;
            // The docs' screenshots are in the dark theme unless asked (`SCATTERLOC_SCREENSHOT_THEME`
            // = light); headless Chromium reports a light system preference.
            let theme =
                std::env::var("SCATTERLOC_SCREENSHOT_THEME").unwrap_or_else(|_| "dark".into());
            js(
                &c,
                &format!("window.theme.set({})", serde_json::json!(theme)),
            )
            .await?;
            if hash.contains("mode=tracking") {
                let s = wait_tracking(&c, 60, mc_done).await?;
                // Once more with the worker warm (the first run includes its start-up).
                js(&c, "window.tracking.restartMc()").await?;
                let gen = s["mcGeneration"].as_u64().unwrap_or(0);
                wait_tracking(&c, 60, |s| {
                    mc_done(s) && s["mcGeneration"].as_u64().unwrap_or(0) > gen
                })
                .await?;
            }
            if hash.contains("mode=mtl") {
                // The worker's first view of the scene (ellipses, hypotheses, detections).
                let t0 = std::time::Instant::now();
                loop {
                    let s = js(&c, "return window.mtl.state()").await?;
                    if s["pending"] == false && s["viewGen"].as_u64().unwrap_or(0) > 0 {
                        break;
                    }
                    if t0.elapsed() > std::time::Duration::from_secs(60) {
                        return Err(format!("no multi-target view in 60 s; last state {s}"));
                    }
                    tokio::time::sleep(std::time::Duration::from_millis(25)).await;
                }
            }
            if hash.contains("mode=channel") {
                // Simulate a walk, estimate and track it, and put the time cursor at 2/3.
                let state = "return window.channel.state()";
                let wait = async |what: &str, done: &dyn Fn(&serde_json::Value) -> bool| {
                    let t0 = std::time::Instant::now();
                    loop {
                        let s = js(&c, state).await?;
                        if done(&s) {
                            return Ok::<_, String>(s);
                        }
                        if t0.elapsed() > std::time::Duration::from_secs(600) {
                            return Err(format!(
                                "channel view: no {what} in 600 s; last state {s}"
                            ));
                        }
                        tokio::time::sleep(std::time::Duration::from_millis(100)).await;
                    }
                };
                js(&c, "document.getElementById('chan-simulate').click()").await?;
                wait("recording", &|s| {
                    s["recording"].is_object() && s["running"].is_null()
                })
                .await?;
                js(&c, "document.getElementById('chan-run').click()").await?;
                let s = wait("result", &|s| s["runs"] == 1 && s["running"].is_null()).await?;
                let k = s["steps"].as_u64().unwrap_or(1) * 2 / 3;
                js(&c, &format!("window.channel.seek({k})")).await?;
            }
            settle(&c).await?;
            c.screenshot().await.map_err(|e| e.to_string())
        }
        .await;
        let _ = c.close().await;
        r
    });
    drop(driver);
    std::fs::write(&out, png.unwrap_or_else(|e| panic!("{e}"))).unwrap();
    println!("wrote {out}");
}
