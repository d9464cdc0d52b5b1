//! Issue 16 §6: "Save figure" in the snapshot, tracking and multi-target views. The button is
//! clicked for real; the page builds the download link (the hooks' dry run leaves it unclicked,
//! so nothing lands in a downloads folder) and the test reads the file through the link's blob
//! URL. The SVGs parse as XML and hold every node's label, the colour bar (its label and tick
//! labels) and the view's overlay (target or track), the multi-target scene its nodes, layers and
//! the page's detection result; the PNGs start with the PNG signature; the file names are
//! `<scenario>-<view>-<figure>.<ext>`.

use std::time::{Duration, Instant};

use fantoccini::Client;
use serde_json::Value;

use scatterloc::localize::{crlb_map, Grid};
use scatterloc::present::{colorbar_ticks, LogScale};
use scatterloc::{scenario::presets, Model};

use super::svg::{count, svg_texts};
use super::ui::{click, mc_done, wait_tracking};
use super::{console_errors, js, open, settle, with_browser};

pub(super) const PNG_SIGNATURE: [u8; 8] = [0x89, b'P', b'N', b'G', 0x0d, 0x0a, 0x1a, 0x0a];

/// One saved file: the hook's record and the content read through the download link.
#[derive(Debug)]
pub(super) struct Saved {
    pub(super) info: Value,
    pub(super) text: String,
    pub(super) head: Vec<u8>,
}

/// Chooses `what` and `format` in the selects, clicks Save figure and waits for the file.
pub(super) async fn save(c: &Client, what: &str, format: &str) -> Result<Saved, String> {
    let before = js(
        c,
        "return Number(document.getElementById('figure-save').dataset.count || 0)",
    )
    .await?
    .as_u64()
    .unwrap_or(0);
    js(
        c,
        &format!(
            "document.getElementById('figure-what').value = '{what}'; \
             document.getElementById('figure-format').value = '{format}';"
        ),
    )
    .await?;
    click(c, "figure-save").await?;
    let t0 = Instant::now();
    // The record and the count are read in one script: read apart, a PNG (saved
    // asynchronously) can land between the two reads and pair the old record with the new count.
    let info = loop {
        let got = js(
            c,
            "return { info: window.figureExport.last(), \
                      count: Number(document.getElementById('figure-save').dataset.count || 0) }",
        )
        .await?;
        let info = &got["info"];
        if info["href"].is_string()
            && info["name"].is_string()
            && got["count"].as_u64() == Some(before + 1)
        {
            break info.clone();
        }
        let errors = console_errors(c).await?;
        if !errors.is_empty() || t0.elapsed() > Duration::from_secs(30) {
            return Err(format!(
                "no file saved ({what}, {format}); errors {errors:?}"
            ));
        }
        tokio::time::sleep(Duration::from_millis(25)).await;
    };
    let content = c
        .execute_async(
            "const done = arguments[arguments.length - 1]; \
             fetch(window.figureExport.last().href) \
               .then((r) => r.arrayBuffer()) \
               .then((b) => done({ text: new TextDecoder().decode(b), \
                                   head: Array.from(new Uint8Array(b.slice(0, 8))) }), \
                     (e) => done({ error: String(e) }));",
            vec![],
        )
        .await
        .map_err(|e| e.to_string())?;
    if let Some(e) = content.get("error") {
        return Err(format!("reading the download link: {e}"));
    }
    Ok(Saved {
        info,
        text: content["text"].as_str().unwrap_or_default().to_string(),
        head: serde_json::from_value(content["head"].clone()).map_err(|e| e.to_string())?,
    })
}

struct Outcome {
    snapshot_svg: Saved,
    snapshot_png: Saved,
    tracking_map_svg: Saved,
    tracking_rmse_svg: Saved,
    tracking_rmse_png: Saved,
    mtl_svg: Saved,
    mtl_png: Saved,
    /// The multi-target view's detection result (window.mtl.state().metrics).
    mtl_metrics: Value,
    errors: Vec<String>,
}

async fn run(c: &Client, port: u16) -> Result<Outcome, String> {
    open(c, port).await?;
    js(
        c,
        "window.figureExport.setDryRun(true); window.placeTarget(4, 1);",
    )
    .await?;
    settle(c).await?;
    let snapshot_svg = save(c, "map", "svg").await?;
    let snapshot_png = save(c, "map", "png").await?;

    click(c, "mode-tracking").await?;
    wait_tracking(c, 120, |s| {
        mc_done(s) && s["steps"].as_u64().unwrap_or(0) > 0
    })
    .await?;
    js(c, "window.tracking.pause(); window.tracking.seek(40);").await?;
    settle(c).await?;
    let tracking_map_svg = save(c, "map", "svg").await?;
    let tracking_rmse_svg = save(c, "rmse", "svg").await?;
    let tracking_rmse_png = save(c, "rmse", "png").await?;

    click(c, "mode-mtl").await?;
    settle(c).await?;
    let mtl_svg = save(c, "map", "svg").await?;
    let mtl_png = save(c, "map", "png").await?;
    let mtl_metrics = js(c, "return window.mtl.state().metrics").await?;
    Ok(Outcome {
        snapshot_svg,
        snapshot_png,
        tracking_map_svg,
        tracking_rmse_svg,
        tracking_rmse_png,
        mtl_svg,
        mtl_png,
        mtl_metrics,
        errors: console_errors(c).await?,
    })
}

/// Every node labelled once, the colour bar's label and at least two of its tick labels.
fn assert_map_figure(what: &str, texts: &[String], names: &[String], ticks: &[String]) {
    for n in names {
        assert_eq!(count(texts, n), 1, "{what}: node label {n} in {texts:?}");
    }
    assert_eq!(
        count(texts, "RMSE bound √(σx² + σy²)"),
        1,
        "{what}: colour bar label"
    );
    let shown = texts.iter().filter(|t| ticks.contains(t)).count();
    assert!(
        shown >= 2,
        "{what}: colour bar ticks {ticks:?} among {texts:?}"
    );
}

fn assert_png(what: &str, f: &Saved) {
    assert_eq!(f.head, PNG_SIGNATURE, "{what}: not a PNG");
    assert_eq!(f.info["type"], "image/png", "{what}");
}

#[test]
#[ignore = "needs chromium + chromedriver and www/pkg (wasm-pack build); run with --ignored"]
fn save_figure_writes_svg_and_png_of_each_view() {
    let o = with_browser(async |c, port, _| run(c, port).await);
    assert!(o.errors.is_empty(), "console errors: {:?}", o.errors);

    let s = presets::sensors2019();
    let names: Vec<String> = s
        .transmitters
        .iter()
        .map(|t| t.name.clone())
        .chain(s.receivers.iter().map(|r| r.name.clone()))
        .collect();
    let model = Model::new(&s).unwrap();
    let grid = Grid::new(s.area_m, 256, 256).unwrap();
    let mut v = vec![0.0; grid.len()];
    crlb_map(&model, &grid, &mut v).unwrap();
    let scale = LogScale::spanning(&v).unwrap();
    let ticks: Vec<String> = colorbar_ticks(scale.min, scale.max, 100)
        .into_iter()
        .map(|t| t.label)
        .filter(|l| !l.is_empty())
        .collect();

    for (f, name) in [
        (&o.snapshot_svg, "sensors2019-snapshot-map.svg"),
        (&o.snapshot_png, "sensors2019-snapshot-map.png"),
        (&o.tracking_map_svg, "sensors2019-tracking-map.svg"),
        (&o.tracking_rmse_svg, "sensors2019-tracking-rmse.svg"),
        (&o.tracking_rmse_png, "sensors2019-tracking-rmse.png"),
        (&o.mtl_svg, "multi-target-scene.svg"),
        (&o.mtl_png, "multi-target-scene.png"),
    ] {
        assert_eq!(f.info["name"], name, "{}", f.info);
        println!(
            "e2e: saved {name}: {} bytes in {:.0} ms",
            f.info["size"],
            f.info["ms"].as_f64().unwrap_or(f64::NAN)
        );
    }

    // Snapshot: the map figure with the target's snapshot.
    let t = svg_texts("snapshot map", &o.snapshot_svg.text);
    assert_map_figure("snapshot map", &t, &names, &ticks);
    for label in ["target", "LM fix ±1σ", "CRLB 1σ"] {
        assert_eq!(count(&t, label), 1, "snapshot map: {label} in {t:?}");
    }
    assert!(t.iter().any(|x| x.contains("sensors2019")), "{t:?}");
    assert_eq!(o.snapshot_svg.info["type"], "image/svg+xml");
    assert_png("snapshot map", &o.snapshot_png);

    // Tracking: the map with the track, and the Monte Carlo chart.
    let t = svg_texts("tracking map", &o.tracking_map_svg.text);
    assert_map_figure("tracking map", &t, &names, &ticks);
    for label in ["truth", "EKF track", "target"] {
        assert_eq!(count(&t, label), 1, "tracking map: {label} in {t:?}");
    }
    let t = svg_texts("tracking rmse", &o.tracking_rmse_svg.text);
    assert!(
        t.iter()
            .any(|x| x.starts_with("Position RMSE: EKF vs posterior CRLB")),
        "{t:?}"
    );
    // The EKF's label with its failed runs (issue 26): none of the page's 200.
    assert!(t.iter().any(|x| x == "EKF RMSE (0/200 failed)"), "{t:?}");
    assert_png("tracking rmse", &o.tracking_rmse_png);

    // Multi-target: the scene's nodes, its layers' legend and the page's own detection result.
    let t = svg_texts("multi-target scene", &o.mtl_svg.text);
    for name in ["Tx1", "Tx2", "Tx3", "Rx1", "Rx2", "Rx3"] {
        assert_eq!(count(&t, name), 1, "multi-target scene: {name} in {t:?}");
    }
    for label in ["region R", "target", "detected"] {
        assert_eq!(count(&t, label), 1, "multi-target scene: {label} in {t:?}");
    }
    let m = &o.mtl_metrics;
    let result = format!(
        "K̂/K = {}/{} · N_D = {} · N_FA = {}",
        m["estimates"], m["targets"], m["detected"], m["false_alarms"]
    );
    assert!(
        t.iter().any(|x| x.starts_with(&result)),
        "{result} in {t:?}"
    );
    assert_png("multi-target scene", &o.mtl_png);
}
