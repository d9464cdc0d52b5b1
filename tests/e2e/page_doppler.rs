//! Issue 42 §1/§5: the snapshot view's Doppler control. Turned on with a non-default CPI and
//! velocity (typed into the page's fields), the main map is the position bound with Doppler and
//! the map beside it the velocity bound; both equal `scatterloc crlb-map --doppler --quantity
//! position|velocity` on the same scenario, window and grid bit for bit. A bad field is named in
//! the banner and leaves the maps as they were; off is the delay-only map again. The pinned
//! probe and the hover read-out give the bounds with Doppler at a point (the probe's numbers
//! those of `scatterloc crlb --doppler` bit for bit), and Save figure writes the position and
//! the velocity map with Doppler as `crlb-map --doppler --out f.svg` draws them.

use serde_json::{json, Value};

use super::channel::cli;
use super::export::{save, PNG_SIGNATURE};
use super::svg::{embedded_png, svg_texts};
use super::ui::{banner, click, poll, select, temp_dir, type_in, wait_banner};
use super::{console_errors, js, open, open_hash, session, settle};

/// The page's last maps once the full-resolution map of `kernel` is shown and the page is idle:
/// `{res, window, position, velocity}` with the values as the hex of their IEEE-754 bits (exact,
/// `Infinity` included), plus the map's source and the velocity colour bar.
/// Turns Doppler on with every field away from its default: N = 24, T = 1.5 ms, floor
/// 0.05 m/s, v = (1.25, −0.5) m/s.
async fn doppler_on(c: &fantoccini::Client) -> Result<(), String> {
    select(c, "doppler-on", "on").await?;
    for (id, v) in [
        ("doppler-n", "24"),
        ("doppler-t", "1.5"),
        ("doppler-floor", "0.05"),
        ("doppler-vx", "1.25"),
        ("doppler-vy", "-0.5"),
    ] {
        type_in(c, id, v).await?;
    }
    Ok(())
}

async fn full_maps(c: &fantoccini::Client, kernel: &str) -> Result<Value, String> {
    let script = format!(
        "const s = window.mapState(); const d = window.doppler.maps(); \
         if (!window.pageIdle() || s.busy || s.res !== s.full || d.kernel !== '{kernel}') return null; \
         const bits = (a) => a === null ? null \
           : Array.from(new BigUint64Array(Float64Array.from(a).buffer), (x) => x.toString(16)); \
         return {{res: d.res, window: d.window, source: s.source, position: bits(d.position), \
           velocity: bits(d.velocity), state: window.doppler.state()}};"
    );
    let v = poll(c, &script, 120, "the full-resolution map", |v| !v.is_null()).await?;
    settle(c).await?;
    Ok(v)
}

/// Hex bit strings → values.
fn values(v: &Value) -> Vec<f64> {
    v.as_array()
        .expect("an array of bits")
        .iter()
        .map(|h| f64::from_bits(u64::from_str_radix(h.as_str().unwrap(), 16).unwrap()))
        .collect()
}

/// The CLI's map (`key`'s rows, null = unbounded) in row-major order, and its x and y.
fn cli_map(doc: &Value, key: &str) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let cells = doc[key]
        .as_array()
        .unwrap_or_else(|| panic!("no {key} in the CLI's JSON"))
        .iter()
        .flat_map(|row| row.as_array().unwrap().iter())
        .map(|v| v.as_f64().unwrap_or(f64::INFINITY))
        .collect();
    let f = |k: &str| -> Vec<f64> {
        doc[k]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect()
    };
    (cells, f("x_m"), f("y_m"))
}

/// The number of cells whose bits differ.
fn differing(a: &[f64], b: &[f64]) -> usize {
    assert_eq!(a.len(), b.len(), "map sizes");
    a.iter()
        .zip(b)
        .filter(|(x, y)| x.to_bits() != y.to_bits())
        .count()
}

/// The page's Doppler maps (worker and main thread) equal the CLI's bit for bit; bad fields are
/// named; off is the delay-only map.
#[test]
#[ignore = "needs chromium + chromedriver and www/pkg (wasm-pack build); run with --ignored"]
fn page_doppler_maps_equal_the_cli() {
    let o = session(|c, port| async move {
        open(&c, port).await?;
        settle(&c).await?;
        let before = js(&c, "return window.doppler.state()").await?;
        let hidden0 = js(&c, "return document.getElementById('vel-plot').hidden").await?;
        // On, with every field away from its default, and a zoomed window.
        doppler_on(&c).await?;
        click(&c, "zoom-in").await?;
        let full = full_maps(&c, "doppler").await?;
        let scenario = js(&c, "return window.app.scenario_json()").await?;
        let hidden1 = js(&c, "return document.getElementById('vel-plot').hidden").await?;
        let banner_on = banner(&c).await?;
        // The 128² grid: computed on the main thread or in the worker as the page's timing says.
        select(&c, "resolution", "128").await?;
        let small = full_maps(&c, "doppler").await?;
        // A bad field: named, the maps and the settings as they were.
        type_in(&c, "doppler-n", "0").await?;
        let bad_n = wait_banner(&c).await?;
        settle(&c).await?;
        let after_bad = js(&c, "return window.doppler.state()").await?;
        let n_invalid = js(
            &c,
            "return document.getElementById('doppler-n').classList.contains('invalid')",
        )
        .await?;
        type_in(&c, "doppler-n", "24").await?;
        settle(&c).await?;
        let banner_fixed = banner(&c).await?;
        type_in(&c, "doppler-t", "0x10").await?;
        let bad_t = wait_banner(&c).await?;
        type_in(&c, "doppler-t", "1.5").await?;
        settle(&c).await?;
        // One snapshot measures no Doppler: every cell unbounded (∞, never NaN), drawn as such.
        type_in(&c, "doppler-n", "1").await?;
        let single = full_maps(&c, "doppler").await?;
        let single_colours = js(
            &c,
            "return [window.doppler.cellColour(0), window.doppler.cellColour(128 * 128 - 1),              Array.from(window.wasm.unbounded_rgb())]",
        )
        .await?;
        type_in(&c, "doppler-n", "24").await?;
        settle(&c).await?;
        // Off: the delay-only map, no velocity map.
        select(&c, "doppler-on", "off").await?;
        let off = full_maps(&c, "delay").await?;
        let hidden2 = js(&c, "return document.getElementById('vel-plot').hidden").await?;
        // The binding itself: bad settings from JavaScript are exceptions naming the field.
        let binding = js(
            &c,
            "const ok = {window: [0, 10, 0, 10], nx: 4, ny: 4, \
               cpi: {snapshots: 16, spacing_ms: 2.048, floor_mps: 0.1}, velocity_mps: [1, 0]}; \
             const bad = [ \
               [{cpi: {...ok.cpi, snapshots: 0}}, 16], [{cpi: {...ok.cpi, spacing_ms: 0}}, 16], \
               [{cpi: {...ok.cpi, floor_mps: -1}}, 16], [{velocity_mps: [NaN, 0]}, 16], \
               [{window: [0, 0, 0, 10]}, 16], [{extra: 1}, 16], [{}, 15]]; \
             return bad.map(([o, len]) => { \
               try { window.app.compute_doppler_maps_in(JSON.stringify({...ok, ...o}), \
                 new Float64Array(len), new Float64Array(16)); return 'no error'; } \
               catch (e) { return `${e.name}: ${e.message}`; } });",
        )
        .await?;
        Ok(json!({
            "before": before, "hidden": [hidden0, hidden1, hidden2], "full": full, "small": small,
            "scenario": scenario, "banner_on": banner_on, "bad_n": bad_n, "after_bad": after_bad,
            "n_invalid": n_invalid, "banner_fixed": banner_fixed, "bad_t": bad_t, "off": off,
            "single": single, "single_colours": single_colours, "binding": binding,
            "errors": console_errors(&c).await?,
        }))
    });
    assert_eq!(o["errors"], json!([]), "console errors");
    assert_eq!(o["banner_on"], "", "no banner with good fields");
    assert_eq!(o["before"]["kernel"], "delay", "off by default");
    assert_eq!(o["before"]["on"], false);
    assert_eq!(
        o["hidden"],
        json!([true, false, true]),
        "the velocity map beside it only when on"
    );
    let want_settings = json!({"snapshots": 24, "spacing_ms": 1.5, "floor_mps": 0.05,
        "vx_mps": 1.25, "vy_mps": -0.5});
    assert_eq!(o["full"]["state"]["settings"], want_settings);

    // The CLI on the page's scenario, window and grid.
    let dir = temp_dir("doppler");
    let scenario = dir.join("scenario.json");
    std::fs::write(&scenario, o["scenario"].as_str().unwrap()).unwrap();
    let spacing_s = format!("{:?}", 1.5 / 1e3); // the binding's spacing_ms / 1000
    for (name, maps, snapshots) in [
        ("256", &o["full"], "24"),
        ("128", &o["small"], "24"),
        ("128", &o["single"], "1"),
    ] {
        let res = maps["res"].as_u64().unwrap() as usize;
        assert_eq!(name, res.to_string());
        let w: Vec<f64> = serde_json::from_value(maps["window"].clone()).unwrap();
        let pos = values(&maps["position"]);
        let vel = values(&maps["velocity"]);
        assert_eq!(pos.len(), res * res);
        for (quantity, key, page) in [
            ("position", "rmse_bound_m", &pos),
            ("velocity", "velocity_rmse_bound_mps", &vel),
        ] {
            let out = dir.join(format!("{quantity}-{res}-{snapshots}.json"));
            let n = res.to_string();
            let bounds = [
                format!("--x-min={:?}", w[0]),
                format!("--x-max={:?}", w[1]),
                format!("--y-min={:?}", w[2]),
                format!("--y-max={:?}", w[3]),
            ];
            let mut args = vec![
                "crlb-map",
                "--scenario",
                scenario.to_str().unwrap(),
                "--out",
                out.to_str().unwrap(),
                "--nx",
                &n,
                "--ny",
                &n,
                "--doppler",
                "--velocity=1.25,-0.5",
                "--cpi",
                snapshots,
                "--cpi-spacing-s",
                &spacing_s,
                "--range-rate-floor",
                "0.05",
                "--quantity",
                quantity,
            ];
            args.extend(bounds.iter().map(String::as_str));
            cli(&args);
            let doc: Value = serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
            let (cells, xs, ys) = cli_map(&doc, key);
            assert_eq!(xs.len(), res);
            assert_eq!(ys.len(), res);
            let d = differing(page, &cells);
            let finite = cells.iter().filter(|v| v.is_finite()).count();
            println!(
                "e2e: Doppler {quantity} map {res}², N = {snapshots} (source {}): {d} of {} cells \
                 differ from the CLI in their bits; {finite} bounded, range {:?}",
                maps["source"],
                cells.len(),
                cells.iter().copied().filter(|v| v.is_finite()).fold(
                    [f64::INFINITY, f64::NEG_INFINITY],
                    |[a, b], v| [a.min(v), b.max(v)]
                )
            );
            assert_eq!(
                d, 0,
                "{quantity} {res}²: the page's map equals the CLI's bit for bit"
            );
            if snapshots == "1" {
                assert_eq!(finite, 0, "{quantity}: one snapshot bounds nothing");
                assert!(page.iter().all(|v| *v == f64::INFINITY), "+∞, never NaN");
            } else {
                assert!(finite > 0, "{quantity}: some bounded cells");
            }
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
    // The velocity colour bar reads in m/s.
    let ticks = o["full"]["state"]["colourBar"]["ticks"].as_array().unwrap();
    let labels: Vec<&str> = ticks
        .iter()
        .filter_map(|t| t["label"].as_str())
        .filter(|l| !l.is_empty())
        .collect();
    assert!(
        !labels.is_empty() && labels.iter().all(|l| l.ends_with("/s")),
        "{labels:?}"
    );
    // Bad fields.
    let b = o["bad_n"].as_str().unwrap();
    assert!(
        b.starts_with("Doppler: Doppler N (cpi.snapshots): 0 is out of range"),
        "{b}"
    );
    assert_eq!(o["n_invalid"], true);
    assert_eq!(
        o["after_bad"]["settings"], want_settings,
        "the last good settings stay"
    );
    assert_eq!(o["banner_fixed"], "", "a fixed field clears its message");
    let b = o["bad_t"].as_str().unwrap();
    assert!(
        b.contains("Doppler T (cpi.spacing)") && b.contains("is not a decimal number"),
        "{b}"
    );
    // Unbounded cells drawn in the unbounded colour.
    let sc = o["single_colours"].as_array().unwrap();
    for cell in &sc[..2] {
        assert_eq!(
            cell.as_array().unwrap()[..3],
            sc[2].as_array().unwrap()[..3],
            "{sc:?}"
        );
    }
    // The binding's named errors.
    let b: Vec<String> = serde_json::from_value(o["binding"].clone()).unwrap();
    println!("e2e: Doppler binding errors: {b:?}");
    for (msg, field) in b.iter().zip([
        "cpi.snapshots",
        "cpi.spacing_s",
        "cpi.floor_mps",
        "velocity_mps",
        "window.x",
        "extra",
        "doppler map output",
    ]) {
        assert!(
            msg.starts_with("Error: ") && msg.contains(field),
            "{msg} names {field}"
        );
    }
    // Off.
    assert_eq!(o["off"]["velocity"], Value::Null);
    assert_eq!(o["off"]["state"]["on"], false);
}

/// The pinned probe's data attributes and text.
const PROBE: &str = "const e = document.getElementById('probe'); \
    return {...e.dataset, text: e.textContent, hidden: e.hidden};";

/// The Save figure choice "Velocity map": [hidden, disabled].
const VELOCITY_CHOICE: &str =
    "const o = document.querySelector('#figure-what option[value=velocity]'); \
    return [o.hidden, o.disabled];";

/// A probe attribute as a number (`Infinity` where unbounded).
fn attr(probe: &Value, key: &str) -> f64 {
    let s = probe[key]
        .as_str()
        .unwrap_or_else(|| panic!("no data-{key} in {probe}"));
    s.parse()
        .unwrap_or_else(|_| panic!("data-{key} = {s:?} is not a number"))
}

/// A bound of the CLI's `doppler` document (`null`: unbounded, +∞).
fn doc_bound(doc: &Value, key: &str) -> f64 {
    match &doc["doppler"][key] {
        Value::Null => f64::INFINITY,
        v => v
            .as_f64()
            .unwrap_or_else(|| panic!("{key} = {v} in the CLI's document")),
    }
}

/// `scatterloc crlb --doppler` at `at` with the page's settings (`snapshots`; T = 1.5 ms, floor
/// 0.05 m/s, v = (1.25, -0.5) m/s), its JSON.
fn cli_crlb(scenario: &str, at: [f64; 2], snapshots: &str) -> Value {
    let spacing_s = format!("{:?}", 1.5 / 1e3);
    let at = format!("--at={:?},{:?}", at[0], at[1]);
    let out = cli(&[
        "crlb",
        "--scenario",
        scenario,
        &at,
        "--doppler",
        "--velocity=1.25,-0.5",
        "--cpi",
        snapshots,
        "--cpi-spacing-s",
        &spacing_s,
        "--range-rate-floor",
        "0.05",
    ]);
    serde_json::from_slice(&out).expect("crlb --doppler writes JSON")
}

/// The number of elements of `page` and `cli` (two SVG documents) placed differently: both must
/// hold the same elements in the same order with the same text and the same attributes except
/// their geometry (`x`, `y`, `width`, `height`, `points`, …), and the map image in the same
/// place. (The CLI measures text with its bundled DejaVu Sans, the page's wasm build with
/// plotters' estimate, chart/layout.rs `register_fonts`: the node labels' boxes and the legend
/// differ in size and place.)
fn layout_differences(page: &str, cli: &str) -> usize {
    let (a, b) = (
        roxmltree::Document::parse(page).unwrap(),
        roxmltree::Document::parse(cli).unwrap(),
    );
    let elements = |d: &roxmltree::Document<'_>| -> Vec<_> {
        d.descendants()
            .filter(|n| n.is_element())
            .map(|n| {
                let geometry = [
                    "x", "y", "width", "height", "points", "x1", "y1", "x2", "y2", "cx", "cy", "r",
                    "d",
                ];
                let attrs: Vec<(String, String)> = n
                    .attributes()
                    .map(|a| (a.name().to_string(), a.value().to_string()))
                    .collect();
                let (place, rest): (Vec<_>, Vec<_>) = attrs
                    .into_iter()
                    .partition(|(k, _)| geometry.contains(&k.as_str()));
                let text = n.text().unwrap_or("").trim().to_string();
                (n.tag_name().name().to_string(), rest, text, place)
            })
            .collect()
    };
    let (ea, eb) = (elements(&a), elements(&b));
    assert_eq!(ea.len(), eb.len(), "element counts");
    let mut moved = 0;
    for (x, y) in ea.iter().zip(&eb) {
        assert_eq!((&x.0, &x.1, &x.2), (&y.0, &y.1, &y.2), "an element differs");
        if x.0 == "image" {
            assert_eq!(x.3, y.3, "the map image's place");
        }
        moved += usize::from(x.3 != y.3);
    }
    moved
}

/// With Doppler on, the pinned probe's bounds are `crlb --doppler`'s at that point bit for bit
/// (and unbounded, never NaN, with one snapshot); the hover read-out names the velocity bound;
/// Save figure writes the position and the velocity map with Doppler, whose SVGs equal `crlb-map
/// --doppler --quantity position|velocity --out f.svg` on the same window and grid except the
/// subtitle's σṙ-floor clause; off, the probe and the figure choices are the delay-only ones.
#[test]
#[ignore = "needs chromium + chromedriver and www/pkg (wasm-pack build); run with --ignored"]
fn page_doppler_probe_hover_and_figure_match_the_cli() {
    let o = session(|c, port| async move {
        open_hash(&c, port, "#probe=3.5,2.25").await?;
        settle(&c).await?;
        js(&c, "window.figureExport.setDryRun(true);").await?;
        let probe_off = js(&c, PROBE).await?;
        let choice_off = js(&c, VELOCITY_CHOICE).await?;
        doppler_on(&c).await?;
        let maps = full_maps(&c, "doppler").await?;
        let probe_on = js(&c, PROBE).await?;
        let choice_on = js(&c, VELOCITY_CHOICE).await?;
        // The hover read-out at a point of the plot, and the core's bound where it landed.
        let hover = js(
            &c,
            "const p = window.view.toPixel(2.2, 3.1); const m = window.view.toMetre(p.x, p.y); \
             const cv = document.getElementById('plot'); const b = cv.getBoundingClientRect(); \
             cv.dispatchEvent(new PointerEvent('pointermove', \
               { clientX: b.left + p.x, clientY: b.top + p.y, bubbles: true })); \
             const s = window.doppler.state().settings; \
             const job = {cpi: {snapshots: s.snapshots, spacing_ms: s.spacing_ms, \
               floor_mps: s.floor_mps}, velocity_mps: [s.vx_mps, s.vy_mps]}; \
             return {text: document.getElementById('readout').textContent, \
               at: window.app.doppler_at(m.x, m.y, JSON.stringify(job))};",
        )
        .await?;
        let view = js(
            &c,
            "return {window: Array.from(window.view.area), \
               res: Number(document.getElementById('resolution').value)}",
        )
        .await?;
        let position_svg = save(&c, "map", "svg").await?;
        let velocity_svg = save(&c, "velocity", "svg").await?;
        let position_png = save(&c, "map", "png").await?;
        let velocity_png = save(&c, "velocity", "png").await?;
        // Export data: the maps' values with their Doppler labels, and its velocity choice
        // (the button for the velocity JSON: its file name).
        js(
            &c,
            "window.pictures.data.setDryRun(true); \
             document.getElementById('data-what').value = 'velocity'; \
             document.getElementById('data-format').value = 'json';",
        )
        .await?;
        click(&c, "data-save").await?;
        let data = js(
            &c,
            "const d = window.pictures.data; \
             const o = document.querySelector('#data-what option[value=\"velocity\"]'); \
             const last = d.last(); \
             return {position: d.text('map', 'json'), velocity: last.text, name: last.name, \
               csv_head: d.text('velocity', 'csv').split('\\n')[0], shown: !o.hidden};",
        )
        .await?;
        // One snapshot: no Doppler, every bound with it unbounded.
        type_in(&c, "doppler-n", "1").await?;
        full_maps(&c, "doppler").await?;
        let probe_single = js(&c, PROBE).await?;
        select(&c, "doppler-on", "off").await?;
        full_maps(&c, "delay").await?;
        let probe_back = js(&c, PROBE).await?;
        let choice_back = js(&c, VELOCITY_CHOICE).await?;
        let name_back = save(&c, "map", "svg").await?.info["name"].clone();
        let scenario = js(&c, "return window.app.scenario_json()").await?;
        let figures = [position_svg, velocity_svg, position_png, velocity_png]
            .map(|f| json!({"info": f.info, "text": f.text, "head": f.head}));
        Ok(json!({
            "probe_off": probe_off, "probe_on": probe_on, "probe_single": probe_single,
            "probe_back": probe_back, "choices": [choice_off, choice_on, choice_back],
            "hover": hover, "view": view, "figures": figures, "name_back": name_back,
            "scenario": scenario, "maps_window": maps["window"], "data": data,
            "errors": console_errors(&c).await?,
        }))
    });
    assert_eq!(o["errors"], json!([]), "console errors");
    let dir = temp_dir("doppler-figure");
    let scenario = dir.join("scenario.json");
    std::fs::write(&scenario, o["scenario"].as_str().unwrap()).unwrap();
    let scenario = scenario.to_str().unwrap();

    // The probe: crlb --doppler's numbers at the pinned point, bit for bit.
    let p = &o["probe_on"];
    let at = [attr(p, "x"), attr(p, "y")];
    assert_eq!(at, [3.5, 2.25]);
    assert_eq!(p["doppler"], "on");
    let doc = cli_crlb(scenario, at, "24");
    for (key, field) in [
        ("rmseM", "position_rmse_m"),
        ("velocityMps", "velocity_rmse_mps"),
        ("delayOnlyM", "delay_only_position_rmse_m"),
    ] {
        let (page, cli) = (attr(p, key), doc_bound(&doc, field));
        println!("e2e: Doppler probe at {at:?}: data-{key} {page} vs crlb --doppler {field} {cli}");
        assert!(cli.is_finite(), "{field} is bounded with N = 24");
        assert_eq!(
            page.to_bits(),
            cli.to_bits(),
            "{key} equals {field} bit for bit"
        );
    }
    let text = p["text"].as_str().unwrap();
    assert!(
        text.contains("with Doppler") && text.contains("/s") && text.contains("delays only"),
        "{text}"
    );
    // Delay-only before: the single-snapshot bound, no Doppler numbers.
    assert_eq!(o["probe_off"]["doppler"], "off");
    assert_eq!(o["probe_off"]["velocityMps"], "");
    assert_ne!(attr(&o["probe_off"], "rmseM"), attr(p, "rmseM"));
    // One snapshot: unbounded (the CLI's null), shown as such; the delays alone still bound it.
    let s = &o["probe_single"];
    let single = cli_crlb(scenario, at, "1");
    assert_eq!(single["doppler"]["position_rmse_m"], Value::Null);
    assert_eq!(single["doppler"]["velocity_rmse_mps"], Value::Null);
    assert_eq!(s["rmseM"], "Infinity");
    assert_eq!(s["velocityMps"], "Infinity");
    let d1 = doc_bound(&single, "delay_only_position_rmse_m");
    assert_eq!(attr(s, "delayOnlyM").to_bits(), d1.to_bits());
    assert!(
        s["text"].as_str().unwrap().contains("unbounded"),
        "{}",
        s["text"]
    );
    // Off again: the delay-only probe as before.
    assert_eq!(o["probe_back"], o["probe_off"]);

    // The hover read-out: the position and velocity bounds with Doppler, the delay-only one.
    let h = &o["hover"];
    let text = h["text"].as_str().unwrap();
    println!("e2e: Doppler hover read-out: {text}");
    for label in ["position_label", "velocity_label", "delay_only_label"] {
        let l = h["at"][label].as_str().unwrap();
        assert!(text.contains(l), "{label} {l} in {text}");
    }
    assert!(
        text.contains("velocity bound") && text.contains("with Doppler"),
        "{text}"
    );
    assert!(h["at"]["velocity_label"].as_str().unwrap().ends_with("/s"));
    assert_eq!(h["at"]["bounded"], true);

    // Export data's velocity choice with Doppler on, its CSV column in m/s.
    assert_eq!(o["data"]["shown"], true);
    assert_eq!(
        o["data"]["name"],
        "sensors2019-snapshot-doppler-velocity.json"
    );
    assert_eq!(o["data"]["csv_head"], "x_m,y_m,rmse_mps");

    // Save figure's choices: "Velocity map" only with Doppler on.
    assert_eq!(
        o["choices"],
        json!([[true, true], [false, false], [true, true]])
    );
    assert_eq!(o["name_back"], "sensors2019-snapshot-map.svg");

    // The figures against crlb-map --doppler --out f.svg on the same window and grid.
    let w: Vec<f64> = serde_json::from_value(o["view"]["window"].clone()).unwrap();
    assert_eq!(
        o["maps_window"], o["view"]["window"],
        "the map shown is of the view"
    );
    let n = o["view"]["res"].as_u64().unwrap().to_string();
    let floor_clause = " · σṙ floor 0.05 m/s";
    let figures = o["figures"].as_array().unwrap();
    for (k, quantity) in ["position", "velocity"].into_iter().enumerate() {
        let (svg, png) = (&figures[k], &figures[k + 2]);
        assert_eq!(
            svg["info"]["name"],
            format!("sensors2019-snapshot-doppler-{quantity}.svg")
        );
        assert_eq!(svg["info"]["doppler"], true);
        assert_eq!(
            png["info"]["name"],
            format!("sensors2019-snapshot-doppler-{quantity}.png")
        );
        assert_eq!(png["head"], json!(PNG_SIGNATURE), "{quantity}: a PNG");
        let out = dir.join(format!("{quantity}.svg"));
        let spacing_s = format!("{:?}", 1.5 / 1e3);
        let bounds = [
            format!("--x-min={:?}", w[0]),
            format!("--x-max={:?}", w[1]),
            format!("--y-min={:?}", w[2]),
            format!("--y-max={:?}", w[3]),
        ];
        let mut args = vec![
            "crlb-map",
            "--scenario",
            scenario,
            "--out",
            out.to_str().unwrap(),
            "--nx",
            &n,
            "--ny",
            &n,
            "--doppler",
            "--velocity=1.25,-0.5",
            "--cpi",
            "24",
            "--cpi-spacing-s",
            &spacing_s,
            "--range-rate-floor",
            "0.05",
            "--quantity",
            quantity,
        ];
        args.extend(bounds.iter().map(String::as_str));
        cli(&args);
        let cli_svg = std::fs::read_to_string(&out).unwrap();
        // Export data's values equal `crlb-map --doppler --out f.json`'s bit for bit (null where
        // unbounded), labelled as that bound.
        let json_out = dir.join(format!("{quantity}.json"));
        let mut json_args = args.clone();
        json_args[4] = json_out.to_str().unwrap();
        cli(&json_args);
        let cli_json: Value =
            serde_json::from_str(&std::fs::read_to_string(&json_out).unwrap()).unwrap();
        let key = if quantity == "position" {
            "rmse_bound_m"
        } else {
            "velocity_rmse_bound_mps"
        };
        let cli_values: Vec<Value> = cli_json[key]
            .as_array()
            .unwrap()
            .iter()
            .flat_map(|row| row.as_array().unwrap().clone())
            .collect();
        let page_data: Value = serde_json::from_str(o["data"][quantity].as_str().unwrap()).unwrap();
        assert_eq!(
            page_data["rmse_m"],
            Value::Array(cli_values),
            "{quantity} data"
        );
        let label = page_data["quantity"].as_str().unwrap();
        assert!(
            label.contains(&format!("{quantity} RMSE bound"))
                && label.contains("with delays and range rates (Doppler)")
                && label.contains("CPI 24 × 1.5 ms, v = (1.25, -0.5) m/s")
                && label.ends_with(floor_clause),
            "{label}"
        );
        assert_eq!(
            page_data["units"],
            if quantity == "position" { "m" } else { "m/s" }
        );
        let page_svg = svg["text"].as_str().unwrap();
        // The map itself: the same embedded PNG (the same values on the same colour scale).
        let (a, b) = (
            embedded_png("page", page_svg),
            embedded_png("cli", &cli_svg),
        );
        assert_eq!(a, b, "{quantity}: the embedded map image");
        // The texts: title, subtitle (with the floor: both take `DopplerMapText`), axes, colour
        // bar, nodes: all equal.
        let (pt, ct) = (svg_texts("page", page_svg), svg_texts("cli", &cli_svg));
        assert_eq!(pt, ct, "{quantity}: the texts");
        let title = format!(
            "{}{} CRLB with Doppler",
            quantity[..1].to_uppercase(),
            &quantity[1..]
        );
        assert_eq!(pt.iter().filter(|t| **t == title).count(), 1, "{pt:?}");
        let want_cpi = "CPI 24 × 1.5 ms, v = (1.25, -0.5) m/s";
        assert!(
            pt.iter()
                .any(|t| t.contains(want_cpi) && t.ends_with(floor_clause)),
            "{pt:?}"
        );
        if quantity == "velocity" {
            assert!(
                pt.iter().any(|t| t == "velocity RMSE bound √(σvx² + σvy²)"),
                "{pt:?}"
            );
            assert!(
                pt.iter().filter(|t| t.ends_with("/s")).count() >= 3,
                "{pt:?}"
            );
        }
        // The whole file: byte-identical or not, the same elements in the same order with the
        // same attributes, except where the text layout places things (`layout_differences`).
        let page_same = page_svg.to_string();
        let same = page_same == cli_svg;
        let moved = layout_differences(&page_same, &cli_svg);
        println!(
            "e2e: Doppler {quantity} figure {n}²: page SVG {} bytes, CLI {} bytes; embedded map \
             image identical ({} bytes); {} texts, all equal; the whole SVG identical: {same}; \
             {moved} elements placed differently (node labels, legend: the text measure)",
            page_svg.len(),
            cli_svg.len(),
            a.len(),
            pt.len(),
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}
