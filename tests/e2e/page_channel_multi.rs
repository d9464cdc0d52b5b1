//! Issue 41 §2 in the channel view: "People: several" on the crossing walkers' recording
//! (`cir simulate --scene` of `tests/common/crossing.rs`, 6 s at 20 Hz) opened through the file
//! inputs with its empty area and truth: Run gives the labelled tracks, ellipses' scans, truth
//! and score of `scatterloc cir track --targets auto --calibration --truth` on the same files
//! (every number within 1e-9 relative, the counts printed), the status line names the tracks, and
//! the map layer draws every track reported at the cursor with its label and 1σ ellipse, and
//! both true paths.

use std::path::Path;

use fantoccini::Client;
use serde_json::Value;

use super::channel::{check, cli, compare, Diff};
use super::ui::{channel_state, select, temp_dir, wait_channel};
use super::{console_errors, js, open_hash, settle, with_browser};

/// The crossing walkers' scene (shared with the library's and the CLI's tests).
#[path = "../common/crossing.rs"]
mod crossing;

/// The keys `cir track --targets auto` adds to the tracker's document (the page's people
/// document holds them beside its `track`).
const ADDED: [&str; 4] = ["extent_sigma_m", "statics", "delay_reference", "score"];

/// Chooses `path` in the file input `id` as a user picks it (page_channel's `choose`); a
/// banner is an error.
async fn choose(c: &Client, id: &str, path: &Path, key: &str) -> Result<(), String> {
    let b = super::page_channel::choose(c, id, path, key).await?;
    if b.is_empty() {
        Ok(())
    } else {
        Err(format!("{id}: {b}"))
    }
}

#[test]
#[ignore = "needs chromium + chromedriver and www/pkg (wasm-pack build); run with --ignored"]
fn several_people_in_the_channel_view_are_the_cli_track() {
    let dir = temp_dir("chan-multi");
    let p = |n: &str| dir.join(n).to_string_lossy().into_owned();
    std::fs::write(p("s.json"), cli(&["preset", "sensors2019"])).unwrap();
    std::fs::write(
        p("scene.json"),
        crossing::crossing_scene().to_string().as_bytes(),
    )
    .unwrap();
    // 6 s at the scene's 20 Hz: both walkers through the crossing (3.84 s and 4.84 s).
    cli(&[
        "cir",
        "simulate",
        "--scenario",
        &p("s.json"),
        "--scene",
        &p("scene.json"),
        "--duration",
        "6",
        "--out-dir",
        &p("sim"),
        "--seed",
        "1",
    ]);
    cli(&[
        "cir",
        "track",
        "--targets",
        "auto",
        "--scenario",
        &p("s.json"),
        "--cir",
        &p("sim/recording.npz"),
        "--calibration",
        &p("sim/calibration.npz"),
        "--truth",
        &p("sim/truth.json"),
        "--out",
        &p("track.json"),
    ]);
    let cli_doc: Value = serde_json::from_slice(&std::fs::read(p("track.json")).unwrap()).unwrap();

    let sim = dir.join("sim");
    let o = with_browser(async |c, port, _| {
        open_hash(c, port, "#mode=channel").await?;
        settle(c).await?;
        choose(c, "chan-file", &sim.join("recording.npz"), "recording").await?;
        choose(
            c,
            "chan-cal-file",
            &sim.join("calibration.npz"),
            "calibration",
        )
        .await?;
        choose(c, "chan-truth-file", &sim.join("truth.json"), "truth").await?;
        select(c, "chan-targets", "several").await?;
        js(c, "document.getElementById('chan-run').click()").await?;
        let done =
            wait_channel(c, 600, "run", |s| s["runs"] == 1 && s["running"].is_null()).await?;
        let text = js(c, "return window.channel.texts().people").await?;
        let doc: Value = serde_json::from_str(text.as_str().unwrap_or("null"))
            .map_err(|e| format!("people document: {e}"))?;
        // The cursor at the scan with the most people reported (the last such).
        let targets = doc["track"]["targets"]
            .as_array()
            .cloned()
            .unwrap_or_default();
        let step = (0..targets.len())
            .max_by_key(|&k| (targets[k].as_array().map_or(0, Vec::len), k))
            .unwrap_or(0);
        js(c, &format!("window.channel.seek({step})")).await?;
        settle(c).await?;
        let at = channel_state(c).await?;
        Ok((done, doc, at, step, console_errors(c).await?))
    });
    let _ = std::fs::remove_dir_all(&dir);
    let (done, doc, at, step, errors) = o;
    assert!(errors.is_empty(), "console errors: {errors:?}");
    let people = &done["people"];
    assert!(doc.is_object(), "no people document: {done}");

    // The labelled tracks, their settings and the score: the CLI's.
    let mut cli_track = cli_doc.as_object().unwrap().clone();
    cli_track.retain(|k, _| !ADDED.contains(&k.as_str()));
    let mut d = Diff::new(1e-9);
    compare("track", &doc["track"], &Value::Object(cli_track), &mut d);
    compare("score", &doc["score"], &cli_doc["score"], &mut d);
    for k in ["extent_sigma_m", "statics", "delay_reference"] {
        compare(k, &doc[k], &cli_doc[k], &mut d);
    }
    check("several people: page against cir track --targets auto", &d);
    let labels: Vec<u64> = cli_doc["tracks"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| t["label"].as_u64().unwrap())
        .collect();
    assert_eq!(people["labels"], serde_json::json!(labels));
    assert!(labels.len() >= 2, "both walkers tracked: labels {labels:?}");
    // One ellipse entry per reported target per scan; the truth both walkers.
    let scans = cli_doc["t_s"].as_array().unwrap().len();
    assert_eq!(doc["ellipses"].as_array().unwrap().len(), scans);
    for (k, scan) in cli_doc["targets"].as_array().unwrap().iter().enumerate() {
        assert_eq!(
            doc["ellipses"][k].as_array().unwrap().len(),
            scan.as_array().unwrap().len(),
            "scan {k}"
        );
    }
    assert_eq!(doc["truth"]["targets"][0].as_array().unwrap().len(), 2);
    println!(
        "labels {labels:?} over {scans} scans; mean GOSPA {} m, {} switches",
        cli_doc["score"]["mean_gospa_m"], cli_doc["score"]["switches"]
    );

    // The status line names the tracks.
    let status = done["status"].as_str().unwrap_or_default();
    let named = format!("{} labelled tracks", labels.len());
    assert!(status.contains(&named), "{status}");

    // The map at the cursor: every track reported there, in label order, with its 1σ ellipse
    // (the document's), and both true paths.
    let layer = &at["people"]["layer"];
    assert_eq!(layer["step"], step, "{layer}");
    let reported = &cli_doc["targets"][step];
    let drawn = layer["tracks"].as_array().unwrap();
    assert_eq!(drawn.len(), reported.as_array().unwrap().len(), "{layer}");
    for (i, t) in drawn.iter().enumerate() {
        assert_eq!(t["label"], reported[i]["label"]);
        let mut d = Diff::new(1e-9);
        compare("state", &t["state"], &reported[i]["state"], &mut d);
        compare("ellipse", &t["ellipse"], &doc["ellipses"][step][i], &mut d);
        check(&format!("drawn track {}", t["label"]), &d);
        assert!(t["ellipse"].is_object(), "no 1σ ellipse drawn: {t}");
    }
    assert_eq!(layer["truth"].as_array().unwrap().len(), 2);
    assert_eq!(at["drawn"]["people"], drawn.len());
}
