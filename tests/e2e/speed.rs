//! Browser end-to-end timing of the SIMD map kernel (issue 13 §2): the page's own `#map-ms`
//! kernel time while a receiver is dragged with the real mouse, for sensors2019 at 256² and
//! 512² (4 links) and with four transmitters at 256² (16 links). Timings are printed, never
//! asserted (they depend on the machine); the test asserts that the drag really recomputed the
//! map at the requested resolution and that the page logged no error.

use std::time::Duration;

use serde_json::{json, Value};

use scatterloc::scenario::{presets, Pattern};

use super::{console_errors, drag_on_plot, js, open_hash, session, settle};

/// sensors2019 with four transmitters (the preset's parabolic Tx at four corners of its
/// receivers, boresights turned inwards): 16 links.
fn sixteen_links() -> String {
    let mut s = presets::sensors2019();
    let tx = s.transmitters[0].clone();
    s.transmitters = [
        (0.0, 0.0, 10.0),
        (20.0, 0.0, 100.0),
        (20.0, 20.0, 190.0),
        (0.0, 20.0, 280.0),
    ]
    .iter()
    .enumerate()
    .map(|(i, &(x, y, b))| {
        let mut t = tx.clone();
        t.name = format!("Tx{i}");
        t.position_m = [x, y];
        if let Pattern::Parabolic { boresight_deg, .. } = &mut t.pattern {
            *boresight_deg = b;
        }
        t
    })
    .collect();
    s.name = "sensors2019-16-links".into();
    s.to_json()
}

/// What one case measured: kernel times (ms) of the drag's refreshes at full resolution, of the
/// map after the drag, and of 9 more kernel runs through the page's bench hook; the whole
/// main-thread refresh (map, overlays, drawing) of every drag refresh.
struct Timing {
    drag_ms: Vec<f64>,
    refresh_ms: Vec<f64>,
    drag_refreshes: usize,
    after_ms: f64,
    after_res: String,
    bench_ms: Vec<f64>,
    links: usize,
    errors: Vec<String>,
}

fn median(v: &[f64]) -> f64 {
    let mut v = v.to_vec();
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
}

fn measure(res: usize, scenario: Option<String>) -> Timing {
    session(|c, port| async move {
        open_hash(&c, port, &format!("#res={res}")).await?;
        settle(&c).await?;
        if let Some(text) = scenario {
            let ok = c
                .execute(
                    "return window.importScenarioText(arguments[0], 'speed.json')",
                    vec![json!(text)],
                )
                .await
                .map_err(|e| e.to_string())?;
            if ok != true {
                return Err("import of the 16-link scenario failed".into());
            }
            settle(&c).await?;
        }
        let links = js(
            &c,
            "return window.app.nodes().transmitters.length * window.app.nodes().receivers.length",
        )
        .await?
        .as_u64()
        .unwrap_or(0) as usize;
        js(&c, "window.pageState.refreshLog.length = 0").await?;
        // Receiver Rx2 (index 1): 16 moves of (+4, −3) px, 40 ms apart.
        let geo = js(
            &c,
            "const r = window.app.nodes().receivers[1]; const p = window.view.toPixel(r.x, r.y); \
             const b = document.getElementById('plot').getBoundingClientRect(); \
             return [p.x - b.width / 2, p.y - b.height / 2];",
        )
        .await?;
        let g: Vec<f64> = serde_json::from_value(geo).map_err(|e| e.to_string())?;
        drag_on_plot(&c, [g[0], g[1]], &[(4.0, -3.0, 40); 16]).await?;
        settle(&c).await?;
        tokio::time::sleep(Duration::from_millis(100)).await;
        settle(&c).await?;
        let log: Vec<Value> = serde_json::from_value(js(&c, "return window.refreshLog()").await?)
            .map_err(|e| e.to_string())?;
        let full = format!("{res}x{res}");
        let drag: Vec<&Value> = log.iter().filter(|r| r["dragging"] == true).collect();
        let refresh_ms = drag.iter().filter_map(|r| r["ms"].as_f64()).collect();
        let drag_ms = drag
            .iter()
            .filter(|r| r["res"].as_str() == Some(full.as_str()))
            .filter_map(|r| r["mapMs"].as_f64())
            .collect();
        let after = js(
            &c,
            "const d = document.getElementById('map-ms').dataset; return [Number(d.ms), d.res];",
        )
        .await?;
        let bench = js(&c, "return window.benchMap(9)").await?;
        Ok(Timing {
            drag_ms,
            refresh_ms,
            drag_refreshes: drag.len(),
            after_ms: after[0].as_f64().unwrap_or(f64::NAN),
            after_res: after[1].as_str().unwrap_or("?").to_string(),
            bench_ms: serde_json::from_value(bench["kernel_ms"].clone())
                .map_err(|e| e.to_string())?,
            links,
            errors: console_errors(&c).await?,
        })
    })
}

#[test]
#[ignore = "needs chromium + chromedriver and www/pkg (wasm-pack build); run with --ignored"]
fn map_kernel_timing_while_dragging() {
    let cases = [
        ("256² 4 links", 256, None, 4),
        ("512² 4 links", 512, None, 4),
        ("256² 16 links", 256, Some(sixteen_links()), 16),
    ];
    for (name, res, scenario, links) in cases {
        let t = measure(res, scenario);
        let all: Vec<f64> = t.drag_ms.iter().copied().chain([t.after_ms]).collect();
        println!(
            "e2e speed: map {name} in Chromium (#map-ms): median {:.2} ms over {} full-resolution \
             refreshes of a mouse drag and the map after it ({} drag refreshes; min {:.2}, max \
             {:.2}); page bench hook, 9 more runs: median {:.2} ms",
            median(&all),
            all.len(),
            t.drag_refreshes,
            all.iter().copied().fold(f64::INFINITY, f64::min),
            all.iter().copied().fold(0.0, f64::max),
            median(&t.bench_ms),
        );
        println!(
            "e2e speed: drag refresh {name} (the page's whole refresh: map, overlays, drawing): \
             median {:.2} ms over {} refreshes (max {:.2})",
            median(&t.refresh_ms),
            t.refresh_ms.len(),
            t.refresh_ms.iter().copied().fold(0.0, f64::max),
        );
        assert!(
            t.errors.is_empty(),
            "{name}: console errors: {:?}",
            t.errors
        );
        assert_eq!(t.links, links, "{name}: link count");
        assert!(t.drag_refreshes >= 3, "{name}: the drag refreshed the map");
        assert_eq!(
            t.after_res,
            format!("{res}x{res}"),
            "{name}: full map after the drag"
        );
        assert!(
            t.after_ms.is_finite() && t.after_ms > 0.0,
            "{name}: kernel time shown"
        );
    }
}
