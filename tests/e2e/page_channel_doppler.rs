//! Issue 42 §2 in the channel view: "CPI snapshots" on a CPI recording (`cir simulate --scene`
//! with the scene's `cpi`: the hangar's first leg, 1 s, each 0.1 s scan 8 snapshots 2.048 ms
//! apart) opened through the file inputs with its empty area: Run's EST.json carries the paths'
//! `range_rate_mps` of `scatterloc cir estimate --cpi-snapshots 8` on the same files, bit for
//! bit (the count of rated paths printed).

use scatterloc::channel::{ChannelScene, SceneCpi};
use serde_json::Value;

use super::channel::cli;
use super::ui::{temp_dir, type_in, wait_channel};
use super::{console_errors, js, open_hash, settle, with_browser};

/// The hangar's first leg, 1 s, each 0.1 s scan a CPI of 8 snapshots 2.048 ms apart (the CLI
/// test's scene, tests/cli/cir_doppler.rs).
fn scene() -> ChannelScene {
    let mut s = ChannelScene::hangar();
    s.walk.waypoints_m = vec![[2.0, 4.0], [14.0, 7.0]];
    s.dt_s = 0.1;
    s.duration_s = Some(1.0);
    s.cpi = Some(SceneCpi {
        snapshots: 8,
        spacing_s: 2.048e-3,
    });
    s
}

#[test]
#[ignore = "needs chromium + chromedriver and www/pkg (wasm-pack build); run with --ignored"]
fn cpi_snapshots_give_the_cli_range_rates() {
    let dir = temp_dir("chan-doppler");
    let p = |n: &str| dir.join(n).to_string_lossy().into_owned();
    std::fs::write(p("s.json"), cli(&["preset", "sensors2019"])).unwrap();
    std::fs::write(p("scene.json"), serde_json::to_vec(&scene()).unwrap()).unwrap();
    cli(&[
        "cir",
        "simulate",
        "--scenario",
        &p("s.json"),
        "--scene",
        &p("scene.json"),
        "--out-dir",
        &p("sim"),
        "--seed",
        "3",
    ]);
    cli(&[
        "cir",
        "estimate",
        "--scenario",
        &p("s.json"),
        "--cir",
        &p("sim/recording.npz"),
        "--calibration",
        &p("sim/calibration.npz"),
        "--cpi-snapshots",
        "8",
        "--out",
        &p("est.json"),
    ]);
    let want: Value = serde_json::from_slice(&std::fs::read(p("est.json")).unwrap()).unwrap();
    let sim = dir.join("sim");
    let o = with_browser(async |c, port, _| {
        open_hash(c, port, "#mode=channel").await?;
        settle(c).await?;
        // The page opens with the sensors2019 preset, the CLI's scenario here.
        for (id, path, key) in [
            ("chan-file", sim.join("recording.npz"), "recording"),
            ("chan-cal-file", sim.join("calibration.npz"), "calibration"),
        ] {
            let b = super::page_channel::choose(c, id, &path, key).await?;
            if !b.is_empty() {
                return Err(format!("{id}: {b}"));
            }
        }
        type_in(c, "chan-cpi", "8").await?;
        settle(c).await?;
        let settings = js(c, "return window.channel.settings()").await?;
        js(c, "document.getElementById('chan-run').click()").await?;
        wait_channel(c, 600, "run", |s| s["runs"] == 1 && s["running"].is_null()).await?;
        let text = js(c, "return window.channel.texts().estimates").await?;
        let figure = js(c, "return window.channel.texts().figure").await?;
        Ok((settings, text, figure, console_errors(c).await?))
    });
    let _ = std::fs::remove_dir_all(&dir);
    let (settings, text, figure, errors) = o;
    assert!(errors.is_empty(), "console errors: {errors:?}");
    assert_eq!(settings["cpi_snapshots"], 8, "{settings}");
    let got: Value = serde_json::from_str(text.as_str().unwrap_or("null")).unwrap();
    assert_eq!(got["t_s"], want["t_s"]);
    assert_eq!(want["t_s"].as_array().unwrap().len(), 11);
    let (mut rated, mut paths) = (0, 0);
    let scans = want["estimates"].as_array().unwrap();
    for (k, scan) in scans.iter().enumerate() {
        for (l, list) in scan.as_array().unwrap().iter().enumerate() {
            let list = list.as_array().unwrap();
            let page = got["estimates"][k][l].as_array().unwrap();
            assert_eq!(page.len(), list.len(), "scan {k} link {l}");
            for (g, w) in page.iter().zip(list) {
                paths += 1;
                assert_eq!(g["delay_s"], w["delay_s"], "scan {k} link {l}");
                // Bit for bit: the same f64s written by the same serialiser.
                assert_eq!(g.get("range_rate_mps"), w.get("range_rate_mps"));
                rated += usize::from(w.get("range_rate_mps").is_some());
            }
        }
    }
    println!(
        "{rated} of {paths} paths with a range rate over {} scans",
        scans.len()
    );
    assert!(rated > 40, "{rated}");
    // The delay picture draws them (issue 42 §5: a tick of slope ṙ through each estimate): its
    // points carry the same `[ṙ, σ]` as EST.json's paths, link by link, in the same order.
    let fig: Value = serde_json::from_str(figure.as_str().unwrap_or("null")).unwrap();
    let links = fig["links"].as_array().expect("the figure's links");
    let mut drawn = 0;
    for (l, link) in links.iter().enumerate() {
        let points = link["estimates"].as_array().unwrap();
        let rates: Vec<&Value> = points
            .iter()
            .filter_map(|p| p.get("range_rate_mps"))
            .collect();
        let want: Vec<Value> = scans
            .iter()
            .flat_map(|scan| scan[l].as_array().unwrap().iter())
            .filter_map(|w| w.get("range_rate_mps").cloned())
            .collect();
        assert_eq!(rates.len(), want.len(), "link {l}");
        for (g, w) in rates.iter().zip(&want) {
            assert_eq!(*g, w, "link {l}");
        }
        drawn += rates.len();
    }
    assert_eq!(drawn, rated);
}
