//! Browser end-to-end test of the tracking mode: scenario II plays (the track marker moves), the
//! Monte Carlo in the Web Worker draws both curves of the plotters chart, and dragging a receiver
//! while it runs cancels and restarts it (no console errors); the browser's result equals the
//! native core's for the page's final scenario.

use std::time::Duration;

use fantoccini::{Client, Locator};
use serde_json::Value;

use scatterloc::math::Vec2;
use scatterloc::present::track_mean_state;
use scatterloc::track::ConstantVelocity;
use scatterloc::track::{paper_initial_covariance, PAPER_INTENSITY};
use scatterloc::track::{run_sequential, MonteCarloConfig};
use scatterloc::{Model, Scenario};

use super::ui::{click, mc_done, select, tracking_state, wait_tracking};
use super::{console_errors, drag_on_plot, js, open, settle, with_browser};

/// Pixels of the chart canvas in the EKF curve's blue (0, 114, 178) and the PCRLB curve's
/// vermillion (213, 94, 0), also where antialiasing blends them with the white background (grid, text
/// and frame are grey or black).
async fn chart_pixels(c: &Client) -> Result<(u64, u64), String> {
    let v = js(
        c,
        "const cv = document.getElementById('track-chart'); \
         const d = cv.getContext('2d').getImageData(0, 0, cv.width, cv.height).data; \
         let blue = 0, red = 0; \
         for (let i = 0; i < d.length; i += 4) { const r = d[i], g = d[i + 1], b = d[i + 2]; \
           if (b - r > 50 && b - g > 20) blue++; if (r - g > 40 && r - b > 80) red++; } \
         return [blue, red];",
    )
    .await?;
    let n: Vec<u64> = serde_json::from_value(v).map_err(|e| e.to_string())?;
    Ok((n[0], n[1]))
}

struct Outcome {
    first: Value,
    before_play: Value,
    playing: Value,
    blue_px: u64,
    red_px: u64,
    running_before_drag: Value,
    after_drag: Value,
    final_state: Value,
    rx_moved: (Vec<f64>, Vec<f64>),
    params: Value,
    result: Value,
    drawn: Value,
    errors: Vec<String>,
}

/// Picks `runs` in the Monte Carlo size select and waits for that study to finish.
async fn set_runs(c: &Client, runs: &str) -> Result<Value, String> {
    let gen = tracking_state(c).await?["mcGeneration"]
        .as_u64()
        .unwrap_or(0);
    let select = c
        .find(Locator::Id("mc-runs"))
        .await
        .map_err(|e| e.to_string())?;
    select
        .select_by_value(runs)
        .await
        .map_err(|e| e.to_string())?;
    wait_tracking(c, 60, |s| {
        mc_done(s) && s["mcGeneration"].as_u64().unwrap_or(0) > gen
    })
    .await
}

/// Drags receiver Rx2 by (60, 40) px in six moves, 60 ms apart. Returns its positions before
/// and after, m.
async fn drag_rx2(c: &Client) -> Result<(Vec<f64>, Vec<f64>), String> {
    let rx2 =
        "const r = window.app.nodes().receivers[1]; const p = window.view.toPixel(r.x, r.y); \
         const b = document.getElementById('plot').getBoundingClientRect(); \
         return [p.x - b.width / 2, p.y - b.height / 2, r.x, r.y];";
    let g: Vec<f64> = serde_json::from_value(js(c, rx2).await?).map_err(|e| e.to_string())?;
    drag_on_plot(c, [g[0], g[1]], &[(10.0, 7.0, 60); 6]).await?;
    let after: Vec<f64> = serde_json::from_value(js(c, rx2).await?).map_err(|e| e.to_string())?;
    Ok((g[2..].to_vec(), after[2..].to_vec()))
}

async fn scenario_ii(c: &Client, port: u16) -> Result<Outcome, String> {
    open(c, port).await?;
    settle(c).await?;
    click(c, "mode-tracking").await?;
    let kind = c
        .find(Locator::Id("track-kind"))
        .await
        .map_err(|e| e.to_string())?;
    kind.select_by_value("II")
        .await
        .map_err(|e| e.to_string())?;
    let first = wait_tracking(c, 60, |s| s["kind"] == "II" && mc_done(s)).await?;
    let (blue_px, red_px) = chart_pixels(c).await?;

    let before_play = tracking_state(c).await?;
    click(c, "track-play").await?;
    tokio::time::sleep(Duration::from_millis(1200)).await;
    let playing = tracking_state(c).await?;
    click(c, "track-play").await?;

    // A large study (10 000 runs, about 50 times the default's time, some 0.3 s here) so that it
    // is still running when each of the drag's moves (60 ms apart) arrives; 1000 runs finished
    // before the first move on a fast run. Restarted, then Rx2 dragged while it runs.
    set_runs(c, "10000").await?;
    let running_before_drag = js(
        c,
        "window.tracking.restartMc(); return window.tracking.state();",
    )
    .await?;
    let rx_moved = drag_rx2(c).await?;
    let gen = running_before_drag["mcGeneration"].as_u64().unwrap_or(0);
    let after_drag = wait_tracking(c, 60, |s| {
        mc_done(s) && s["mcGeneration"].as_u64().unwrap_or(0) > gen
    })
    .await?;
    settle(c).await?;
    // Back to the default size: its (warm) wall time is the figure printed.
    let final_state = set_runs(c, "200").await?;
    let params = js(c, "return window.tracking.mcParams()").await?;
    let result = js(c, "return window.tracking.mcResult()").await?;
    let drawn = draw_trajectory(c).await?;
    Ok(Outcome {
        first,
        before_play,
        playing,
        blue_px,
        red_px,
        running_before_drag,
        after_drag,
        final_state,
        rx_moved,
        params,
        result,
        drawn,
        errors: console_errors(c).await?,
    })
}

/// "draw…": press on the map at (15, 20) m and drag to (25, 14) m; returns the state at step 0
/// once the restarted study has finished.
async fn draw_trajectory(c: &Client) -> Result<Value, String> {
    let kind = c
        .find(Locator::Id("track-kind"))
        .await
        .map_err(|e| e.to_string())?;
    kind.select_by_value("custom")
        .await
        .map_err(|e| e.to_string())?;
    let s = wait_tracking(c, 60, |s| s["kind"] == "custom" && mc_done(s)).await?;
    let gen = s["mcGeneration"].as_u64().unwrap_or(0);
    let px = js(
        c,
        "const a = window.view.toPixel(15, 20), b = window.view.toPixel(25, 14); \
         const r = document.getElementById('plot').getBoundingClientRect(); \
         return [a.x - r.width / 2, a.y - r.height / 2, b.x - a.x, b.y - a.y];",
    )
    .await?;
    let p: Vec<f64> = serde_json::from_value(px).map_err(|e| e.to_string())?;
    let half = |v: f64| (v / 2.0).round();
    let step = (half(p[2]), half(p[3]), 60);
    drag_on_plot(c, [p[0], p[1]], &[step, step]).await?;
    wait_tracking(c, 60, |s| {
        mc_done(s) && s["mcGeneration"].as_u64().unwrap_or(0) > gen
    })
    .await?;
    js(c, "window.tracking.seek(0); return window.tracking.state()").await
}

fn floats(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap_or(f64::NAN))
        .collect()
}

/// The model and the study the page ran with `params` (its worker message).
fn page_study(params: &Value) -> (Model, MonteCarloConfig) {
    let p = |k: &str| params[k].as_f64().unwrap();
    let scenario = Scenario::from_json(params["scenario"].as_str().unwrap()).unwrap();
    let mean = track_mean_state(
        params["kind"].as_str().unwrap(),
        Vec2::new(p("x0"), p("y0")),
        Vec2::new(p("vx"), p("vy")),
    )
    .unwrap();
    let cfg = MonteCarloConfig {
        motion: ConstantVelocity::new(p("dt_s"), PAPER_INTENSITY),
        steps: p("steps") as usize,
        mean_state: mean,
        initial_covariance: paper_initial_covariance(),
        trajectories: p("trajectories") as usize,
        noise_runs: p("noise_runs") as usize,
        seed: p("seed") as u64,
        oracle_noise: false,
    };
    (Model::new(&scenario).unwrap(), cfg)
}

/// The browser's study against the native core on the page's final scenario: largest relative
/// difference over t, ε_EKF, ε_PCRLB and NEES.
fn native_difference(params: &Value, result: &Value) -> f64 {
    let (model, cfg) = page_study(params);
    let native = run_sequential(&model, &cfg, |_, _| true).unwrap();
    assert_eq!(result["runs"].as_u64(), Some(native.runs as u64));
    let pcrlb: Vec<f64> = native
        .rmse_pcrlb_m
        .iter()
        .map(|v| v.unwrap_or(f64::NAN))
        .collect();
    let mut worst: f64 = 0.0;
    for (key, n) in [
        ("t_s", &native.t_s),
        ("rmse_ekf_m", &native.rmse_m),
        ("rmse_pcrlb_m", &pcrlb),
        ("nees", &native.nees),
    ] {
        let b = floats(&result[key]);
        assert_eq!(b.len(), n.len(), "{key}");
        for (x, y) in b.iter().zip(n) {
            let rel = if x == y { 0.0 } else { (x / y - 1.0).abs() };
            worst = worst.max(rel);
        }
    }
    worst
}

/// Issue 3 §5 end to end: pick scenario II, play, the track moves and the chart shows both
/// curves; a receiver drag during a Monte Carlo run restarts it without console errors.
#[test]
#[ignore = "needs chromium + chromedriver and www/pkg (wasm-pack build); run with --ignored"]
fn tracking_scenario_ii_plays_and_monte_carlo_restarts_on_drag() {
    let o = with_browser(async |c, port, _| scenario_ii(c, port).await);

    let f = &o.final_state;
    let ms = f["mcMs"].as_f64().unwrap();
    let runs = f["mcRuns"].as_u64().unwrap();
    let steps = f["steps"].as_u64().unwrap();
    println!(
        "e2e: browser Monte Carlo {runs}x{steps}: {ms:.0} ms (worker compute {:.0} ms; first run \
         after picking II: {:.0} ms; 10000x{steps} after the drag: {:.0} ms)",
        f["mcComputeMs"].as_f64().unwrap_or(f64::NAN),
        o.first["mcMs"].as_f64().unwrap_or(f64::NAN),
        o.after_drag["mcMs"].as_f64().unwrap_or(f64::NAN),
    );
    assert!(o.errors.is_empty(), "console errors: {:?}", o.errors);
    assert_eq!(
        (runs, steps),
        (200, 100),
        "default study 200 runs × 100 steps"
    );
    assert_eq!(o.first["mcRuns"], 200);

    // The chart shows both curves.
    assert_eq!(o.first["chartSeries"], 2, "{}", o.first);
    assert!(
        o.blue_px > 100 && o.red_px > 100,
        "chart pixels: EKF {} PCRLB {}",
        o.blue_px,
        o.red_px
    );

    // Play moves the track marker.
    let (s0, s1) = (&o.before_play, &o.playing);
    let (n0, n1) = (s0["step"].as_u64().unwrap(), s1["step"].as_u64().unwrap());
    assert!(n1 >= n0 + 5, "step advances while playing: {n0} -> {n1}");
    assert_ne!(s0["truth"], s1["truth"], "the truth marker moves");
    assert_ne!(s0["estimate"], s1["estimate"], "the EKF marker moves");
    assert_eq!(s1["playing"], true);

    // The drag cancelled a running study and a new one finished.
    assert_eq!(o.running_before_drag["mcState"], "running");
    let g0 = o.running_before_drag["mcGeneration"].as_u64().unwrap();
    assert!(
        o.after_drag["mcGeneration"].as_u64().unwrap() > g0 + 1,
        "{} -> {}",
        o.running_before_drag,
        o.after_drag
    );
    let superseded = |s: &Value| s["mcSuperseded"].as_u64().unwrap();
    let cancelled = superseded(&o.after_drag) - superseded(&o.running_before_drag);
    println!("e2e: running studies cancelled by the six drag moves: {cancelled}");
    assert!(cancelled > 0, "no running study was cancelled by the drag");
    assert_eq!(o.after_drag["chartSeries"], 2);
    assert_eq!(o.after_drag["mcRuns"], 10000);
    let (a, b) = &o.rx_moved;
    assert!(
        (a[0] - b[0]).hypot(a[1] - b[1]) > 1.0,
        "Rx2 moved: {a:?} -> {b:?}"
    );

    // A drawn trajectory: the EKF starts at the pressed point; the drag end sets the velocity.
    let d = &o.drawn;
    assert_eq!(d["kind"], "custom");
    let (x0, y0) = (
        d["drawn"]["x0"].as_f64().unwrap(),
        d["drawn"]["y0"].as_f64().unwrap(),
    );
    let (x1, y1) = (
        d["drawn"]["x1"].as_f64().unwrap(),
        d["drawn"]["y1"].as_f64().unwrap(),
    );
    assert!((x0 - 15.0).hypot(y0 - 20.0) < 0.2, "start ({x0}, {y0})");
    assert!((x1 - 25.0).hypot(y1 - 14.0) < 0.3, "end ({x1}, {y1})");
    assert_eq!(
        d["estimate"],
        serde_json::json!([x0, y0]),
        "EKF starts at the drawn start"
    );

    // The study is the native core's for the page's final scenario (platform libm may differ
    // in the last bits of exp/ln/sin).
    let params_rx = Scenario::from_json(o.params["scenario"].as_str().unwrap()).unwrap();
    assert_eq!(params_rx.receivers[1].position_m, [b[0], b[1]]);
    let worst = native_difference(&o.params, &o.result);
    println!("e2e: browser vs native Monte Carlo: max relative difference {worst:e}");
    assert!(worst < 1e-9, "browser vs native: {worst:e}");
}

/// What the filters test saw in the page.
struct FiltersOutcome {
    /// State after the animated track switched to the particle filter.
    pf_track: Value,
    /// That track's `failed_at`, `filter`, `particles` and entries.
    pf_data: Value,
    /// State once the three-filter study finished, its parameters and its result.
    done: Value,
    params: Value,
    result: Value,
    errors: Vec<String>,
}

async fn three_filters(c: &Client, port: u16) -> Result<FiltersOutcome, String> {
    open(c, port).await?;
    settle(c).await?;
    click(c, "mode-tracking").await?;
    select(c, "track-kind", "II").await?;
    wait_tracking(c, 60, |s| s["kind"] == "II" && mc_done(s)).await?;
    select(c, "track-filter", "pf").await?;
    let pf_track = wait_tracking(c, 60, |s| s["filter"] == "pf").await?;
    let pf_data = js(
        c,
        "const d = window.tracking.trackData(); \
         return {failed_at: d.failed_at, filter: d.filter, particles: d.particles, \
                 entries: d.truth.length, ellipses: d.ellipses.filter((e) => e).length};",
    )
    .await?;
    let gen = tracking_state(c).await?["mcGeneration"]
        .as_u64()
        .unwrap_or(0);
    click(c, "mc-ukf").await?;
    click(c, "mc-pf").await?;
    let done = wait_tracking(c, 180, |s| {
        mc_done(s)
            && s["mcFilters"] == "ekf,ukf,pf"
            && s["mcGeneration"].as_u64().unwrap_or(0) > gen
    })
    .await?;
    let params = js(
        c,
        "return {...window.tracking.mcParams(), note: document.getElementById('mc-pf-note').textContent, \
                 status: document.getElementById('mc-status').textContent};",
    )
    .await?;
    let result = js(c, "return window.tracking.mcResult()").await?;
    let errors = console_errors(c).await?;
    Ok(FiltersOutcome {
        pf_track,
        pf_data,
        done,
        params,
        result,
        errors,
    })
}

/// Issue 15, the page: the animated track runs the chosen filter (the particle filter, with its
/// 1σ ellipses), and the Monte Carlo runs the ticked filters in the worker on the same truth and
/// delays — the EKF and UKF over every run, the PF over the runs its particle budget allows — with
/// one chart curve per filter; the browser's UKF and PF curves are the native core's.
#[test]
#[ignore = "needs chromium + chromedriver and www/pkg (wasm-pack build); run with --ignored"]
fn tracking_page_runs_the_chosen_filters() {
    let o = with_browser(async |c, port, _| three_filters(c, port).await);
    assert!(o.errors.is_empty(), "console errors: {:?}", o.errors);

    // The animated particle-filter track: 100 steps, every step with its 1σ ellipse.
    assert_eq!(o.pf_track["particles"], 1000, "{}", o.pf_track);
    let d = &o.pf_data;
    assert_eq!(
        (&d["filter"], &d["particles"]),
        (&Value::from("pf"), &Value::from(1000))
    );
    assert_eq!(d["entries"], 101, "{d}");
    assert!(d["failed_at"].is_null(), "{d}");
    assert_eq!(d["ellipses"], 101, "{d}");

    // The study: every filter's curve and the PCRLB on the chart; the PF within its budget.
    let ms = o.done["mcMs"].as_f64().unwrap_or(f64::NAN);
    println!(
        "e2e: browser Monte Carlo EKF + UKF (200 runs) + PF (192 runs × 1000 particles) × 100 \
         steps: {ms:.0} ms; {}",
        o.params["note"]
    );
    assert_eq!(o.done["chartSeries"], 4, "{}", o.done);
    let r = &o.result;
    let names: Vec<&String> = r["filters"].as_object().unwrap().keys().collect();
    assert_eq!(names.len(), 3, "{names:?}");
    // 2·10⁷ particle-steps / (100 steps × 1000 particles) = 200 runs: 12 whole chunks of 16.
    assert_eq!(r["filters"]["pf"]["runs_planned"], 192);
    assert_eq!(r["filters"]["ukf"]["runs_planned"], 200);
    assert!(
        o.params["note"]
            .as_str()
            .unwrap()
            .contains("192 runs × 1000 particles"),
        "{}",
        o.params["note"]
    );
    assert_eq!(r["particles"], 1000);
    assert_eq!(r["filters"]["ekf"]["rmse_m"], r["rmse_ekf_m"]);

    // The browser's filters against the native core's chunks on the same scenario.
    let worst = native_filters_difference(&o.params, r);
    println!("e2e: browser vs native UKF and PF curves: max relative difference {worst:e}");
    assert!(worst < 1e-9, "browser vs native: {worst:e}");
}

/// The browser's UKF and PF curves against [`run_filter_chunk`] natively on the page's scenario:
/// the largest relative difference of RMSE and NEES (runs counted must be equal).
fn native_filters_difference(params: &Value, result: &Value) -> f64 {
    use scatterloc::track::{finish, run_filter_chunk, FilterKind, PfConfig, StudySums};
    let (model, cfg) = page_study(params);
    let pf = FilterKind::Pf(PfConfig {
        particles: params["particles"].as_f64().unwrap() as usize,
        roughening: None,
        regularized: true,
    });
    let mut worst: f64 = 0.0;
    for (name, kind) in [("ukf", FilterKind::Ukf(Default::default())), ("pf", pf)] {
        let b = &result["filters"][name];
        let chunks = b["chunk_count"].as_u64().unwrap() as usize;
        let mut sums = StudySums::new(cfg.steps);
        for c in 0..chunks {
            sums.add(&run_filter_chunk(&model, &cfg, kind, c).unwrap());
        }
        let native = finish(&cfg, &sums).unwrap();
        assert_eq!(b["runs"].as_u64(), Some(native.runs as u64), "{name}");
        for (key, n) in [("rmse_m", &native.rmse_m), ("nees", &native.nees)] {
            let v = floats(&b[key]);
            assert_eq!(v.len(), n.len(), "{name} {key}");
            for (x, y) in v.iter().zip(n) {
                let rel = if x == y { 0.0 } else { (x / y - 1.0).abs() };
                worst = worst.max(rel);
            }
        }
    }
    worst
}
