//! Issue 41 §2: "Save figure" and "Export data" with "Several people" on in the tracking view.
//! Before the run's document arrives the people's data is the named error "no multi-target run
//! yet"; once it has, Save figure writes the run's map (people_map_svg: every track's legend
//! entry and, at the last scan, the label `#n` of every target reported there, each track's line
//! in the page's colour of its place) and its GOSPA chart (people_chart_svg, "GOSPA chart"), as
//! SVG and as the canvases' PNG, named `<scenario>-tracking-people-{map,gospa}.<ext>`; Export data
//! writes the people (`<scenario>-tracking-people.csv|json`) with every number of the document,
//! bit for bit; the Monte Carlo curves are off while several people are on. Off gives the labels
//! back.

use std::time::Duration;

use fantoccini::Client;
use serde_json::{json, Value};

use scatterloc::present::LINK_RGB;

use super::channel::cli;
use super::svg::{count, svg_texts};
use super::ui::{banner, click, poll, select, temp_dir, wait_tracking};
use super::{console_errors, js, open, settle, with_browser};

use super::export::{save, Saved, PNG_SIGNATURE};

/// The labels of the figure and data choices.
const CHOICES: &str = "const o = (s, v) => document.querySelector(`#${s} option[value=\"${v}\"]`); \
    return { rmse: o('figure-what', 'rmse').textContent, track: o('data-what', 'track').textContent, \
             mcHidden: o('data-what', 'mc').hidden, mcDisabled: o('data-what', 'mc').disabled };";

struct Outcome {
    before: Value,
    choices_on: Value,
    choices_off: Value,
    doc: Value,
    step: Value,
    scenario: Value,
    seed: Value,
    map_svg: Saved,
    map_png: Saved,
    chart_svg: Saved,
    chart_png: Saved,
    csv: Value,
    json: Value,
    mc: Value,
    banner: String,
    errors: Vec<String>,
}

async fn run(c: &Client) -> Result<Outcome, String> {
    settle(c).await?;
    click(c, "mode-tracking").await?;
    wait_tracking(c, 120, |s| s["mcState"] == "done").await?;
    settle(c).await?;
    js(
        c,
        "window.figureExport.setDryRun(true); window.pictures.data.setDryRun(true);",
    )
    .await?;
    let gen = js(c, "return window.tracking.state().multi.generation")
        .await?
        .as_u64()
        .unwrap_or(0);
    // On: the run starts and the old document is dropped at once, so until the worker answers
    // there is no document (checked in the same script, before any message can arrive).
    let before = js(
        c,
        "const w = document.getElementById('multi-walkers'); w.value = '3'; \
         w.dispatchEvent(new Event('change')); \
         let message = null; \
         try { window.pictures.data.text('track', 'csv'); } catch (e) { message = String(e.message || e); } \
         return message;",
    )
    .await?;
    select(c, "multi-walkers", "3").await?;
    poll(
        c,
        "return window.tracking.state().multi",
        180,
        "several people",
        |m| {
            m["generation"].as_u64().unwrap_or(0) > gen
                && (m["state"] == "done" || m["state"] == "error")
        },
    )
    .await?;
    settle(c).await?;
    js(c, "window.tracking.seek(1e9)").await?;
    tokio::time::sleep(Duration::from_millis(50)).await;
    settle(c).await?;
    let doc = js(c, "return window.tracking.state().multi.doc").await?;
    let step = js(c, "return window.tracking.state().step").await?;
    let scenario = js(c, "return window.app.scenario_json()").await?;
    let seed = js(c, "return window.tracking.state().multi.params.seed").await?;
    let choices_on = js(c, CHOICES).await?;
    let map_svg = save(c, "map", "svg").await?;
    let map_png = save(c, "map", "png").await?;
    let chart_svg = save(c, "rmse", "svg").await?;
    let chart_png = save(c, "rmse", "png").await?;
    // Export data: the button (its file name) and the texts.
    js(
        c,
        "document.getElementById('data-what').value = 'track'; \
         document.getElementById('data-format').value = 'csv';",
    )
    .await?;
    click(c, "data-save").await?;
    let csv = js(c, "return window.pictures.data.last()").await?;
    js(c, "document.getElementById('data-format').value = 'json';").await?;
    click(c, "data-save").await?;
    let json = js(c, "return window.pictures.data.last()").await?;
    let mc = js(
        c,
        "try { window.pictures.data.text('mc', 'csv'); return null; } \
         catch (e) { return String(e.message || e); }",
    )
    .await?;
    let (banner_text, errors) = (banner(c).await?, console_errors(c).await?);
    select(c, "multi-walkers", "off").await?;
    settle(c).await?;
    let choices_off = js(c, CHOICES).await?;
    Ok(Outcome {
        before,
        choices_on,
        choices_off,
        doc,
        step,
        scenario,
        seed,
        map_svg,
        map_png,
        chart_svg,
        chart_png,
        csv,
        json,
        mc,
        banner: banner_text,
        errors,
    })
}

/// The bits of a JSON number (`null`: NaN is not written; the caller checks emptiness).
fn bits(v: &Value) -> u64 {
    v.as_f64()
        .unwrap_or_else(|| panic!("{v} is not a number"))
        .to_bits()
}

/// Numbers equal bit for bit, everything else as JSON; differences into `diffs`.
fn same(a: &Value, b: &Value, path: &str, diffs: &mut Vec<String>) {
    match (a, b) {
        (Value::Number(x), Value::Number(y)) => {
            if x.as_f64().map(f64::to_bits) != y.as_f64().map(f64::to_bits) {
                diffs.push(format!("{path}: {x} vs {y}"));
            }
        }
        (Value::Array(x), Value::Array(y)) if x.len() == y.len() => {
            for (i, (p, q)) in x.iter().zip(y).enumerate() {
                same(p, q, &format!("{path}[{i}]"), diffs);
            }
        }
        (Value::Object(x), Value::Object(y)) if x.len() == y.len() => {
            for (k, p) in x {
                match y.get(k) {
                    Some(q) => same(p, q, &format!("{path}.{k}"), diffs),
                    None => diffs.push(format!("{path}.{k}: missing")),
                }
            }
        }
        _ if a == b => {}
        _ => diffs.push(format!("{path}: {a} vs {b}")),
    }
}

/// The CSV's rows checked against the document, bit for bit; returns (truth rows, track rows).
fn check_csv(text: &str, doc: &Value) -> (usize, usize) {
    let mut lines = text.lines();
    let head: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(head[..4], ["scan", "t_s", "kind", "label"]);
    assert_eq!(head.len(), 25);
    let num = |s: &str| s.parse::<f64>().unwrap().to_bits();
    let (mut n_truth, mut n_track) = (0, 0);
    for line in lines {
        let f: Vec<&str> = line.split(',').collect();
        let k: usize = f[0].parse().unwrap();
        let label: u64 = f[3].parse().unwrap();
        let (t_s, list) = match f[2] {
            "truth" => {
                n_truth += 1;
                (&doc["truth"]["t_s"][k], &doc["truth"]["targets"][k])
            }
            _ => {
                n_track += 1;
                (&doc["track"]["t_s"][k], &doc["track"]["targets"][k])
            }
        };
        assert_eq!(num(f[1]), bits(t_s), "{line}");
        let t = list
            .as_array()
            .unwrap()
            .iter()
            .find(|t| t["label"].as_u64() == Some(label))
            .unwrap_or_else(|| panic!("{line}: no label {label} at scan {k}"));
        for j in 0..4 {
            assert_eq!(num(f[4 + j]), bits(&t["state"][j]), "{line}");
        }
        if f[2] == "track" {
            assert_eq!(num(f[8]), bits(&t["existence"]), "{line}");
            for c in 0..16 {
                assert_eq!(
                    num(f[9 + c]),
                    bits(&t["covariance"][c / 4][c % 4]),
                    "{line}"
                );
            }
        } else {
            assert!(f[8..].iter().all(|c| c.is_empty()), "{line}");
        }
    }
    (n_truth, n_track)
}

fn items(v: &Value) -> usize {
    v.as_array()
        .unwrap()
        .iter()
        .map(|s| s.as_array().unwrap().len())
        .sum()
}

#[test]
#[ignore = "needs chromium + chromedriver and www/pkg (wasm-pack build); run with --ignored"]
fn several_people_save_their_figure_and_data() {
    let o = with_browser(async |c, port, _| {
        open(c, port).await?;
        run(c).await
    });
    assert_eq!(o.errors, Vec::<String>::new(), "console errors");
    assert_eq!(o.banner, "", "no banner");
    assert_eq!(o.before, json!("no multi-target run yet"));
    assert_eq!(
        o.choices_on,
        json!({"rmse": "GOSPA chart", "track": "People (tracks and truth)", "mcHidden": true, "mcDisabled": true})
    );
    assert_eq!(
        o.choices_off,
        json!({"rmse": "RMSE chart", "track": "Track", "mcHidden": false, "mcDisabled": false})
    );
    let doc = &o.doc;
    let scans = doc["track"]["t_s"].as_array().unwrap().len();
    assert_eq!(
        o.step.as_u64(),
        Some(scans as u64 - 1),
        "the last scan shown"
    );

    // The map: named as the people's, from people_map_svg.
    let name = o.map_svg.info["name"].as_str().unwrap();
    assert!(name.ends_with("-tracking-people-map.svg"), "{name}");
    assert_eq!(o.map_svg.info["people"], true);
    let texts = svg_texts("people map", &o.map_svg.text);
    let tracks = doc["track"]["tracks"].as_array().unwrap();
    assert!(!tracks.is_empty());
    for t in tracks {
        let legend = format!("track #{}", t["label"]);
        assert_eq!(count(&texts, &legend), 1, "{legend} in {texts:?}");
    }
    let last = doc["track"]["targets"][scans - 1].as_array().unwrap();
    assert!(!last.is_empty(), "targets at the last scan");
    for t in last {
        let label = format!("#{}", t["label"]);
        assert_eq!(count(&texts, &label), 1, "{label} in {texts:?}");
    }
    assert_eq!(count(&texts, "true path"), 1);
    // Each track's line in the page's colour of its place (its linkColor(i)).
    let svg = roxmltree::Document::parse(&o.map_svg.text).unwrap();
    for (i, t) in tracks.iter().enumerate() {
        let [r, g, b] = LINK_RGB[i % LINK_RGB.len()];
        let hex = format!("#{r:02X}{g:02X}{b:02X}");
        let lines = svg
            .descendants()
            .filter(|n| n.has_tag_name("polyline") && n.attribute("stroke") == Some(hex.as_str()))
            .count();
        assert!(
            lines >= 1,
            "track {} (place {i}): no line in {hex}",
            t["label"]
        );
    }
    // The CLI's `track --targets auto --truth --figure` on the page's scenario and seed: the
    // same figure at the last scan (its ellipses at true scale): the same title and labels.
    let dir = temp_dir("page-multi-export");
    let scenario = dir.join("scenario.json");
    std::fs::write(&scenario, o.scenario.as_str().unwrap()).unwrap();
    let (s, walk) = (scenario.to_str().unwrap(), dir.join("walk"));
    let seed = o.seed.to_string();
    let w = walk.to_str().unwrap();
    cli(&[
        "simulate-walk",
        "--scenario",
        s,
        "--out-dir",
        w,
        "--walkers",
        "3",
        "--seed",
        &seed,
    ]);
    let (m, t, fig) = (
        walk.join("measurements.json"),
        walk.join("truth.json"),
        dir.join("f.svg"),
    );
    cli(&[
        "track",
        "--scenario",
        s,
        "--measurements",
        m.to_str().unwrap(),
        "--targets",
        "auto",
        "--truth",
        t.to_str().unwrap(),
        "--figure",
        fig.to_str().unwrap(),
    ]);
    let cli_svg = std::fs::read_to_string(&fig).unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    let cli_texts = svg_texts("CLI people map", &cli_svg);
    let labels = |v: &[String]| -> Vec<String> {
        let mut l: Vec<String> = v
            .iter()
            .filter(|t| {
                t.starts_with('#') || t.starts_with("track #") || t.starts_with("Several people")
            })
            .cloned()
            .collect();
        l.sort();
        l
    };
    assert_eq!(
        labels(&cli_texts),
        labels(&texts),
        "the CLI's figure and the page's"
    );
    assert_eq!(o.map_png.head, PNG_SIGNATURE);
    let name = o.map_png.info["name"].as_str().unwrap();
    assert!(name.ends_with("-tracking-people-map.png"), "{name}");

    // The GOSPA chart.
    let name = o.chart_svg.info["name"].as_str().unwrap();
    assert!(name.ends_with("-tracking-people-gospa.svg"), "{name}");
    let texts = svg_texts("GOSPA chart", &o.chart_svg.text);
    let legend = doc["gospa_label"].as_str().unwrap();
    assert_eq!(count(&texts, legend), 1, "{legend} in {texts:?}");
    assert_eq!(count(&texts, "GOSPA (m)"), 1, "{texts:?}");
    assert_eq!(o.chart_png.head, PNG_SIGNATURE);
    let name = o.chart_png.info["name"].as_str().unwrap();
    assert!(name.ends_with("-tracking-people-gospa.png"), "{name}");

    // The data: every number of the document, bit for bit.
    let name = o.csv["name"].as_str().unwrap();
    assert!(name.ends_with("-tracking-people.csv"), "{name}");
    let (n_truth, n_track) = check_csv(o.csv["text"].as_str().unwrap(), doc);
    assert_eq!(n_truth, items(&doc["truth"]["targets"]));
    assert_eq!(n_track, items(&doc["track"]["targets"]));
    println!(
        "e2e: several people exported: {n_truth} truth rows, {n_track} track rows, {} tracks, \
         map SVG {} bytes",
        tracks.len(),
        o.map_svg.text.len()
    );
    let name = o.json["name"].as_str().unwrap();
    assert!(name.ends_with("-tracking-people.json"), "{name}");
    let data: Value = serde_json::from_str(o.json["text"].as_str().unwrap()).unwrap();
    for key in ["truth", "track", "score"] {
        let mut d = Vec::new();
        same(&data[key], &doc[key], key, &mut d);
        assert!(
            d.is_empty(),
            "{key}: {} differences, first {:?}",
            d.len(),
            &d[..d.len().min(5)]
        );
    }
    assert_eq!(o.mc, json!("no Monte Carlo curves with several people on"));
}
