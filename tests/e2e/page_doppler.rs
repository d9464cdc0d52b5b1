//! Issue 42 §1/§5: the snapshot view's Doppler control. Turned on with a non-default CPI and
//! velocity (typed into the page's fields), the main map is the position bound with Doppler and
//! the map beside it the velocity bound; both equal `scatterloc crlb-map --doppler --quantity
//! position|velocity` on the same scenario, window and grid bit for bit. A bad field is named in
//! the banner and leaves the maps as they were; off is the delay-only map again.

use serde_json::{json, Value};

use super::channel::cli;
use super::ui::{banner, click, poll, select, temp_dir, type_in, wait_banner};
use super::{console_errors, js, open, session, settle};

/// The page's last maps once the full-resolution map of `kernel` is shown and the page is idle:
/// `{res, window, position, velocity}` with the values as the hex of their IEEE-754 bits (exact,
/// `Infinity` included), plus the map's source and the velocity colour bar.
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
        select(&c, "doppler-on", "on").await?;
        for (id, v) in [
            ("doppler-n", "24"),
            ("doppler-t", "1.5"),
            ("doppler-floor", "0.05"),
            ("doppler-vx", "1.25"),
            ("doppler-vy", "-0.5"),
        ] {
            type_in(&c, id, v).await?;
        }
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
