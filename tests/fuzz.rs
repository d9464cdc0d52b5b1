#![cfg(not(target_arch = "wasm32"))]
//! Mutation fuzzing of every input kind (issue 12, "make it stay fixed"): each test takes valid
//! documents of one kind (presets, the docs/cli.md examples, files the CLI writes), mutates keys,
//! types and numbers to extremes (`fuzz/mutate.rs`), and runs them through the library's
//! parse-and-run entry points in process, or through the built `scatterloc` binary for the files
//! only the CLI parses. The invariant (`fuzz/check.rs`): `Ok` with finite outputs, or a named
//! error (one line, at most 1000 bytes, naming the input), within a time and memory budget.
//!
//! Case counts: small by default (CI, debug build); `SCATTERLOC_FUZZ_CASES=N` sets every kind
//! (`scripts/fuzz.sh` runs 10⁴ per kind in release). The RNG is ChaCha with a fixed seed
//! (`SCATTERLOC_FUZZ_SEED`, default 12), so a run is deterministic; shrunk failures are saved in
//! `tests/fuzz.proptest-regressions`. Failures the current code is known to have are listed in
//! [`KNOWN`] (issue 12 items being fixed in `src/`): they are counted and printed, not failed,
//! unless `SCATTERLOC_FUZZ_STRICT=1`.

use proptest::prelude::*;
use serde::Deserialize;
use serde_json::Value;
use std::process::Command;

use scatterloc::localize::{crlb_at, crlb_map, locate, DelayMeasurements, Grid, LmConfig};
use scatterloc::math::{Mat4, Vec2, Vec4};
use scatterloc::mtl::algorithm::{locate as mtl_locate, MtlConfig};
use scatterloc::mtl::empirical::EmpiricalTable;
use scatterloc::mtl::input::{from_json, target_reports, LocateRequest, ModelSpec, NetworkInput};
use scatterloc::present::{mtl_view, MtlScene};
use scatterloc::present::{simulate_snapshot, Session};
use scatterloc::scenario::{parse_json, presets, Area, Scenario};
use scatterloc::track::gating::{Calibration, ClusterConfig};
use scatterloc::track::{ConstantVelocity, Ekf, MeasurementNoise};
use scatterloc::{Error, Model};

#[path = "fuzz/check.rs"]
mod check;
#[path = "fuzz/docs.rs"]
mod docs;
#[allow(dead_code)]
#[path = "common/multipath.rs"]
mod multipath;
#[path = "fuzz/mutate.rs"]
mod mutate;
#[path = "fuzz/parts.rs"]
mod parts;
#[path = "fuzz/runner.rs"]
mod runner;

use check::{
    check_cli, check_message, clip, core_err, fail, finite, guarded, nonfinite_in_debug, run_child,
    run_cli, CaseDir, Class, Failure, Pass, Verdict,
};
use mutate::{apply, mutations, Mutation, EXTREMES};
use runner::{fuzz, Case, Known};

// ------------------------------------------------------------------------------- known failures

/// Failures the current code is known to have, each naming its issue: counted and printed, not
/// failed (unless `SCATTERLOC_FUZZ_STRICT=1`). Empty: every failure the fuzzer found for
/// issue 12 (long messages, wide priors, positions and link-budget values out of range, areas
/// of ±1e308, the unbounded multi-target work) is fixed, so any failure now fails the test.
const KNOWN: &[Known] = &[];

// ------------------------------------------------------------------------------- helpers

/// A document kind's strategy: one of `bases`, mutated up to `max` times (arrays grow up to
/// [`mutate::MAX_GROW`] elements).
fn docs(bases: Vec<Value>, max: usize) -> impl Strategy<Value = (Value, Vec<Mutation>)> {
    (
        prop::sample::select(bases),
        mutations(max, mutate::MAX_GROW),
    )
}

/// Longest list of the `network_ranges` kind (a child process killed at the time limit, as each
/// run-away case costs the whole limit); longer lists are fuzzed by the CLI kind `cli_mtl`.
const MTL_IN_PROCESS_GROW: usize = 9;

/// [`docs`] for the in-process multi-target kinds (lists grow to [`MTL_IN_PROCESS_GROW`]).
fn mtl_docs(bases: Vec<Value>, max: usize) -> impl Strategy<Value = (Value, Vec<Mutation>)> {
    (
        prop::sample::select(bases),
        mutations(max, MTL_IN_PROCESS_GROW),
    )
}

fn mutated(case: &(Value, Vec<Mutation>)) -> mutate::Mutated {
    apply(&case.0, &case.1)
}

fn what(m: &mutate::Mutated) -> String {
    if m.what.is_empty() {
        "the base document".into()
    } else {
        m.what.join("; ")
    }
}

/// A finished in-process case.
fn case(m: &mutate::Mutated, verdict: Verdict) -> Case {
    Case {
        verdict,
        what: format!("{} | doc: {}", what(m), clip(&m.text, 400)),
    }
}

/// `Err` → the message check; `Ok` → the value.
macro_rules! named {
    ($e:expr) => {
        match $e {
            Ok(v) => v,
            Err(e) => return core_err(&e),
        }
    };
}

/// The CLI's `crlb` view of one point: the bound (finite or unbounded) and per link the SNR in
/// dB, σ_τ and the delay, all finite.
fn check_point(model: &Model, at: Vec2) -> Result<(), Failure> {
    let pt = crlb_at(model, at);
    nonfinite_in_debug(&format!("crlb_at({at:?})"), &format!("{pt:?}"))?;
    if let Some(e) = pt.ellipse() {
        nonfinite_in_debug("crlb ellipse", &format!("{e:?}"))?;
    }
    for p in 0..model.link_count() {
        finite(&format!("link {p} snr_db"), 10.0 * model.snr(p, at).log10())?;
        let s = model.sigma_delay(p, at);
        finite(&format!("link {p} sigma_delay_s"), s)?;
        if s <= 0.0 {
            return Err(fail(
                Class::NonFinite,
                format!("link {p} sigma_delay_s = {s} (not > 0)"),
            ));
        }
        finite(&format!("link {p} delay_s"), model.network.delay(p, at))?;
    }
    Ok(())
}

fn centre(a: &Area) -> Vec2 {
    Vec2::new(0.5 * (a.x[0] + a.x[1]), 0.5 * (a.y[0] + a.y[1]))
}

/// A CRLB map over `area` (as the page's `compute_map` and `crlb-map`): no NaN (∞ = unbounded).
fn check_map(model: &Model, area: Area, nx: usize, ny: usize) -> Verdict {
    let grid = named!(Grid::new(area, nx, ny));
    let mut buf = vec![0.0; grid.len()];
    named!(crlb_map(model, &grid, &mut buf));
    if let Some(k) = buf.iter().position(|v| v.is_nan() || *v < 0.0) {
        return Err(fail(
            Class::NonFinite,
            format!("crlb_map cell {k} = {}", buf[k]),
        ));
    }
    for (i, j) in [(0, 0), (nx - 1, ny - 1)] {
        let c = named!(grid.cell_center(i, j));
        finite("cell centre x", c.x)?;
        finite("cell centre y", c.y)?;
    }
    Ok(Pass::Ok)
}

// ------------------------------------------------------------------------------- scenario

/// Scenario JSON → `Scenario::from_json` → `Model::new` → the CRLB at the area's centre and at
/// the first Tx, a 6 × 5 CRLB map, and the LM fix (grid start) from noise-free delays at the
/// centre.
fn run_scenario(text: &str) -> Verdict {
    let s = named!(Scenario::from_json(text));
    let model = named!(Model::new(&s));
    let c = centre(&s.area_m);
    finite("area centre x", c.x)?;
    finite("area centre y", c.y)?;
    check_point(&model, c)?;
    let t = s.transmitters[0].position_m;
    check_point(&model, Vec2::new(t[0], t[1]))?;
    check_map(&model, s.area_m, 6, 5)?;
    let delays: Vec<Option<f64>> = model.network.delays(c).into_iter().map(Some).collect();
    let sigmas = model.sigma_delays(c);
    let m = DelayMeasurements {
        delays_s: &delays,
        sigmas_s: &sigmas,
    };
    let rep = named!(locate(
        &model.network,
        &m,
        &LmConfig::default(),
        None,
        &s.area_m
    ));
    nonfinite_in_debug("LM report", &format!("{rep:?}"))?;
    Ok(Pass::Ok)
}

#[test]
fn fuzz_scenario() {
    fuzz(
        file!(),
        "scenario",
        160,
        KNOWN,
        docs(docs::scenarios(), 4),
        |c| {
            let m = mutated(c);
            case(&m, guarded(&m.text, || run_scenario(&m.text)))
        },
    );
}

// ------------------------------------------------------------------------------- page edits

/// One call the page makes on its `App` (each a `Session` edit or a computation on it).
#[derive(Clone, Debug)]
enum PageOp {
    Area([f64; 4]),
    MoveTx(usize, [f64; 2]),
    MoveRx(usize, [f64; 2]),
    AddTx([f64; 2]),
    AddRx([f64; 2]),
    RemoveTx(usize),
    RemoveRx(usize),
    Carrier(f64),
    Bandwidth(f64),
    NoiseFigure(f64),
    Rcs(f64),
    TxPower(usize, f64),
    TxGain(usize, f64),
    TxPattern(usize, &'static str, [f64; 3]),
    RxGain(usize, f64),
    Map(usize, usize),
    CellCenter([usize; 4]),
    CrlbAt([f64; 2]),
    SimulateFix([f64; 2], u32),
}

/// Numbers a page can pass: extremes, NaN/±∞ (JavaScript has them), and plain values.
fn page_num() -> impl Strategy<Value = f64> {
    prop_oneof![
        3 => prop::sample::select(EXTREMES),
        1 => prop::sample::select(&[f64::NAN, f64::INFINITY, f64::NEG_INFINITY][..]),
        3 => -60.0..60.0f64,
    ]
}

fn page_index() -> impl Strategy<Value = usize> {
    prop_oneof![4 => 0..6usize, 1 => Just(usize::MAX)]
}

fn page_size() -> impl Strategy<Value = usize> {
    prop::sample::select(&[0usize, 1, 2, 7, 33, 4097, 1 << 40, usize::MAX][..])
}

fn page_op() -> impl Strategy<Value = PageOp> {
    let pt = || [page_num(), page_num()];
    prop_oneof![
        [page_num(), page_num(), page_num(), page_num()].prop_map(PageOp::Area),
        (page_index(), pt()).prop_map(|(i, p)| PageOp::MoveTx(i, p)),
        (page_index(), pt()).prop_map(|(i, p)| PageOp::MoveRx(i, p)),
        pt().prop_map(PageOp::AddTx),
        pt().prop_map(PageOp::AddRx),
        page_index().prop_map(PageOp::RemoveTx),
        page_index().prop_map(PageOp::RemoveRx),
        page_num().prop_map(PageOp::Carrier),
        page_num().prop_map(PageOp::Bandwidth),
        page_num().prop_map(PageOp::NoiseFigure),
        page_num().prop_map(PageOp::Rcs),
        (page_index(), page_num()).prop_map(|(i, v)| PageOp::TxPower(i, v)),
        (page_index(), page_num()).prop_map(|(i, v)| PageOp::TxGain(i, v)),
        (
            page_index(),
            prop::sample::select(&["omni", "parabolic", "Parabolic", ""][..]),
            [page_num(), page_num(), page_num()]
        )
            .prop_map(|(i, k, a)| PageOp::TxPattern(i, k, a)),
        (page_index(), page_num()).prop_map(|(i, v)| PageOp::RxGain(i, v)),
        (page_size(), page_size()).prop_map(|(a, b)| PageOp::Map(a.min(4097), b.min(4097))),
        [page_size(), page_size(), page_size(), page_size()].prop_map(PageOp::CellCenter),
        pt().prop_map(PageOp::CrlbAt),
        (pt(), any::<u32>()).prop_map(|(p, s)| PageOp::SimulateFix(p, s)),
    ]
}

/// The page's `point()` check: non-finite coordinates are refused (named) before the core.
/// The page's points pass `wasm::point` first: both coordinates within ±1e7 m.
fn page_point(p: [f64; 2]) -> Option<Vec2> {
    let ok = |v: f64| scatterloc::error::limits::COORDINATE_M.contains(v);
    (ok(p[0]) && ok(p[1])).then(|| Vec2::new(p[0], p[1]))
}

/// Runs the page's calls in order on a session of the preset; after every accepted edit the
/// page redraws: the CRLB at the area's centre and an 8 × 6 map must be finite (∞ = unbounded).
fn run_page(preset: &str, ops: &[PageOp]) -> Verdict {
    let mut session = named!(Session::new(named!(presets::preset(preset))));
    let mut errors = 0;
    for op in ops {
        let v = page_op_run(&mut session, op, &mut errors);
        v.map_err(|f| fail(f.class, format!("after {op:?}: {}", f.detail)))?;
    }
    Ok(if errors > 0 { Pass::Err } else { Pass::Ok })
}

/// One page call and the redraw after an accepted edit.
fn page_op_run(session: &mut Session, op: &PageOp, errors: &mut usize) -> Result<(), Failure> {
    {
        let edit: Option<Result<(), Error>> = match *op {
            PageOp::Area([a, b, c, d]) => Some(session.edit(|s| {
                s.set_area(Area {
                    x: [a, b],
                    y: [c, d],
                })
            })),
            PageOp::MoveTx(i, p) => Some(session.edit(|s| s.move_transmitter(i, p))),
            PageOp::MoveRx(i, p) => Some(session.edit(|s| s.move_receiver(i, p))),
            PageOp::AddTx(p) => Some(session.edit(|s| s.add_transmitter(p)).map(drop)),
            PageOp::AddRx(p) => Some(session.edit(|s| s.add_receiver(p)).map(drop)),
            PageOp::RemoveTx(i) => Some(session.edit(|s| s.remove_transmitter(i))),
            PageOp::RemoveRx(i) => Some(session.edit(|s| s.remove_receiver(i))),
            PageOp::Carrier(v) => Some(session.edit(|s| s.set_carrier_hz(v))),
            PageOp::Bandwidth(v) => Some(session.edit(|s| s.set_bandwidth_hz(v))),
            PageOp::NoiseFigure(v) => Some(session.edit(|s| s.set_noise_figure_db(v))),
            PageOp::Rcs(v) => Some(session.edit(|s| s.set_rcs_m2(v))),
            PageOp::TxPower(i, v) => Some(session.edit(|s| s.set_tx_power_dbm(i, v))),
            PageOp::TxGain(i, v) => Some(session.edit(|s| s.set_tx_gain_dbi(i, v))),
            PageOp::TxPattern(i, k, [b, w, f]) => {
                Some(session.edit(|s| s.set_tx_pattern_kind(i, k, b, w, f)))
            }
            PageOp::RxGain(i, v) => Some(session.edit(|s| s.set_rx_gain_dbi(i, v))),
            PageOp::Map(nx, ny) => {
                if check_map(session.model(), session.scenario().area_m, nx, ny)? == Pass::Err {
                    *errors += 1;
                }
                None
            }
            PageOp::CellCenter([nx, ny, i, j]) => {
                match Grid::new(session.scenario().area_m, nx, ny).and_then(|g| g.cell_center(i, j))
                {
                    Ok(c) => {
                        finite("cell_center x", c.x)?;
                        finite("cell_center y", c.y)?;
                    }
                    Err(e) => {
                        core_err(&e)?;
                        *errors += 1;
                    }
                }
                None
            }
            PageOp::CrlbAt(p) => {
                if let Some(p) = page_point(p) {
                    let pt = crlb_at(session.model(), p);
                    nonfinite_in_debug("crlb_at", &format!("{pt:?}"))?;
                    if let Some(e) = pt.ellipse() {
                        nonfinite_in_debug("crlb_at ellipse", &format!("{e:?}"))?;
                    }
                }
                None
            }
            PageOp::SimulateFix(p, seed) => {
                if let Some(p) = page_point(p) {
                    let s = session.scenario();
                    let sim = simulate_snapshot(session.model(), &s.area_m, p, seed.into());
                    nonfinite_in_debug("simulate_fix", &format!("{sim:?}"))?;
                }
                None
            }
        };
        match edit {
            Some(Err(e)) => {
                core_err(&e)?;
                *errors += 1;
            }
            Some(Ok(())) => {
                let s = session.scenario();
                let c = centre(&s.area_m);
                finite("area centre x", c.x)?;
                finite("area centre y", c.y)?;
                check_point(session.model(), c)?;
                check_map(session.model(), s.area_m, 8, 6)?;
            }
            None => {}
        }
    }
    Ok(())
}

#[test]
fn fuzz_page_edits() {
    let strategy = (
        prop::sample::select(&["sensors2019", "iclgnss2019"][..]),
        prop::collection::vec(page_op(), 1..=6),
    );
    fuzz(file!(), "page_edits", 100, KNOWN, strategy, |(p, ops)| {
        let desc = format!("{p}: {ops:?}");
        Case {
            verdict: guarded(&desc, || run_page(p, ops)),
            what: desc,
        }
    });
}

// ------------------------------------------------------------------------------- mtl scene (page)

/// A page scene → `MtlScene::from_json` → `mtl_view`: every number of the view finite.
fn run_mtl_scene(text: &str) -> Verdict {
    let scene = named!(MtlScene::from_json(text));
    let view = named!(mtl_view(&scene));
    nonfinite_in_debug("mtl view", &format!("{view:?}"))?;
    Ok(Pass::Ok)
}

/// Each case runs in a child process (this test re-run by [`run_child`]; [`check::child_main`]
/// runs the case there): a run-away view (e.g. a huge `t_e`) cannot be stopped from inside.
#[test]
fn fuzz_mtl_scene() {
    if check::child_main("mtl_scene", run_mtl_scene) {
        return;
    }
    let dir = CaseDir::new("mtl_scene");
    fuzz(
        file!(),
        "mtl_scene",
        32,
        KNOWN,
        mtl_docs(docs::mtl_scenes(), 4),
        |c| {
            let m = mutated(c);
            let v = run_child("mtl_scene", "fuzz_mtl_scene", &dir, &m.text);
            case(&m, v)
        },
    );
}

// ------------------------------------------------------------------------------- network + ranges

/// A multi-target request (`{network, ranges, model}`, the `mtl locate` inputs) →
/// `mtl::input` validation → model build → Algorithm 1 → target reports, all finite.
fn run_mtl_request(text: &str) -> Verdict {
    let req: LocateRequest = named!(from_json(text));
    let net = named!(req.network.validate());
    named!(req.ranges.validate(&net));
    let built = named!(req.model.build(&net));
    let cfg = net.config(&MtlConfig::default(), &built);
    let out = named!(mtl_locate(
        &net.measurements(&req.ranges.ranges_m),
        &*built.model,
        &cfg
    ));
    let reps = target_reports(&net.map, &out.targets);
    nonfinite_in_debug("mtl targets", &format!("{reps:?}"))?;
    Ok(Pass::Ok)
}

/// Each case runs in a child process (this test re-run by [`run_child`]; [`check::child_main`]
/// runs the case there): Algorithm 1 cannot be stopped from inside when it runs away, a child
/// can be killed.
#[test]
fn fuzz_network_ranges() {
    if check::child_main("network_ranges", run_mtl_request) {
        return;
    }
    let dir = CaseDir::new("network_ranges");
    fuzz(
        file!(),
        "network_ranges",
        32,
        KNOWN,
        mtl_docs(docs::mtl_requests(), 4),
        |c| {
            let m = mutated(c);
            let v = run_child("network_ranges", "fuzz_network_ranges", &dir, &m.text);
            case(&m, v)
        },
    );
}

// ------------------------------------------------------------------------------- empirical table

/// An empirical table (the `--table` file) → `EmpiricalTable` → the empirical model of the
/// docs network → Algorithm 1 on the two-target ranges.
fn run_table(text: &str) -> Verdict {
    let table: EmpiricalTable = named!(from_json(text));
    let net_in: NetworkInput = serde_json::from_value(docs::network()).expect("network");
    let net = net_in.validate().expect("valid network");
    let spec = ModelSpec::Empirical {
        p_d: 0.9,
        table: Some(table),
        training: None,
    };
    let built = named!(spec.build(&net));
    let ranges: Vec<Vec<f64>> =
        serde_json::from_value(docs::ranges()[1]["ranges_m"].clone()).expect("ranges");
    let cfg = net.config(&MtlConfig::default(), &built);
    let out = named!(mtl_locate(&net.measurements(&ranges), &*built.model, &cfg));
    nonfinite_in_debug(
        "mtl targets",
        &format!("{:?}", target_reports(&net.map, &out.targets)),
    )?;
    Ok(Pass::Ok)
}

#[test]
fn fuzz_empirical_table() {
    fuzz(
        file!(),
        "empirical_table",
        24,
        KNOWN,
        mtl_docs(vec![docs::empirical_table().clone()], 4),
        |c| {
            let m = mutated(c);
            case(&m, guarded(&m.text, || run_table(&m.text)))
        },
    );
}

// ------------------------------------------------------------------------------- calibration

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SnapshotsFile {
    snapshots: Vec<Vec<Vec<f64>>>,
}

/// A calibration snapshots file → `gating::Calibration::from_snapshots` with the L4 preset's
/// clusterer defaults (4 links, B = 120 MHz): finite clusters.
fn run_calibration(text: &str) -> Verdict {
    let f: SnapshotsFile = named!(parse_json(text));
    let cfg = ClusterConfig::for_bandwidth(1.2e8).expect("B");
    let cal = named!(Calibration::from_snapshots(&f.snapshots, 4, &cfg));
    nonfinite_in_debug("calibration", &format!("{cal:?}"))?;
    Ok(Pass::Ok)
}

#[test]
fn fuzz_calibration() {
    fuzz(
        file!(),
        "calibration",
        100,
        KNOWN,
        docs(vec![docs::walk().snapshots.clone()], 4),
        |c| {
            let m = mutated(c);
            case(&m, guarded(&m.text, || run_calibration(&m.text)))
        },
    );
}

// ------------------------------------------------------------------------------- EKF tracking

/// The `steps` form of a measurements file (as `track` reads it).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct StepsFile {
    dt_s: f64,
    process_noise: f64,
    initial_state: [f64; 4],
    initial_covariance: [[f64; 4]; 4],
    #[serde(default)]
    sigma_s: Option<f64>,
    steps: Vec<Vec<Option<f64>>>,
}

/// A measurements file (steps form, one σ) → `ConstantVelocity::validated` → `Ekf::new` →
/// predict and update per step on the L4 model: finite state, covariance and NIS.
fn run_ekf(text: &str) -> Verdict {
    let f: StepsFile = named!(parse_json(text));
    let model = Model::new(&presets::sensors2019()).expect("preset");
    let motion = named!(ConstantVelocity::validated(f.dt_s, f.process_noise));
    let sig;
    let noise = match f.sigma_s {
        Some(s) if !(s.is_finite() && s > 0.0) => {
            return check_message(&format!("sigma_s: must be > 0 (got {s})"))
        }
        Some(s) => {
            sig = vec![s; model.link_count()];
            MeasurementNoise::Fixed(&sig)
        }
        None => MeasurementNoise::AtPrediction,
    };
    let p0 = Mat4::from_fn(|i, j| f.initial_covariance[i][j]);
    let mut ekf = named!(Ekf::new(Vec4::from(f.initial_state), p0));
    for z in &f.steps {
        ekf.predict(&motion);
        let s = named!(ekf.update(&model, z, noise, None));
        if s.links_used > 0 {
            finite("nis", s.nis)?;
        }
        nonfinite_in_debug("ekf", &format!("{:?} {:?}", ekf.state, ekf.covariance))?;
    }
    Ok(Pass::Ok)
}

#[test]
fn fuzz_ekf() {
    fuzz(
        file!(),
        "ekf",
        200,
        KNOWN,
        docs(docs::measurements(), 4),
        |c| {
            let m = mutated(c);
            case(&m, guarded(&m.text, || run_ekf(&m.text)))
        },
    );
}

// ------------------------------------------------------------------------------- the CLI kinds

/// Runs `scatterloc <args>` with `files` (name, text) written to this thread's case directory
/// (`{name}` in an argument is replaced by its path).
fn cli_case(
    kind: &str,
    args: &[&str],
    files: &[(&str, &str)],
    allow_null: &dyn Fn(&str, &Value) -> bool,
) -> Verdict {
    thread_local! {
        static DIRS: std::cell::RefCell<Vec<CaseDir>> = const { std::cell::RefCell::new(vec![]) };
    }
    DIRS.with(|d| {
        let mut d = d.borrow_mut();
        if d.is_empty() {
            d.push(CaseDir::new(kind));
        }
        let dir = &d[0];
        let mut args: Vec<String> = args.iter().map(|s| s.to_string()).collect();
        for (name, text) in files {
            let p = dir.write(name, text);
            for a in &mut args {
                if a == &format!("{{{name}}}") {
                    *a = p.clone();
                }
            }
        }
        let mut run = run_cli(&args);
        // Messages name the case files by path: shorten it (the same for every case).
        run.stderr = run.stderr.replace(&*dir.0.to_string_lossy(), "$DIR");
        check_cli(&run, allow_null)
    })
}

/// `"k1.k2[i]…"` → the value at that path of `doc`.
fn at<'a>(doc: &'a Value, path: &str) -> Option<&'a Value> {
    let mut cur = doc;
    for part in path.split('.') {
        let (key, idx) = match part.find('[') {
            Some(k) => (&part[..k], &part[k..]),
            None => (part, ""),
        };
        if !key.is_empty() {
            cur = cur.get(key)?;
        }
        for i in idx.split(['[', ']']).filter(|s| !s.is_empty()) {
            cur = cur.get(i.parse::<usize>().ok()?)?;
        }
    }
    Some(cur)
}

/// The nulls `track` documents: `nis[k]` of a step with no link, a delay of a link whose choice
/// is `absent` (per step and in `start`).
fn track_nulls(path: &str, doc: &Value) -> bool {
    if let Some(k) = path.strip_prefix("nis[") {
        let k = k.trim_end_matches(']');
        return at(doc, &format!("links_used[{k}]")).and_then(Value::as_u64) == Some(0);
    }
    for prefix in ["delays_used_s", "start.delays_used_s"] {
        if let Some(rest) = path.strip_prefix(prefix) {
            let choice = prefix.replace("delays_used_s", "choices") + rest;
            return at(doc, &choice).and_then(Value::as_str) == Some("absent");
        }
    }
    false
}

#[test]
fn fuzz_cli_delays() {
    let scen = docs::sensors_text();
    fuzz(
        file!(),
        "cli_delays",
        48,
        KNOWN,
        docs(docs::delays(), 4),
        |c| {
            let m = mutated(c);
            let v = cli_case(
                "delays",
                &["locate", "--scenario", "{s.json}", "--delays", "{d.json}"],
                &[("s.json", &scen), ("d.json", &m.text)],
                &|p, _| p == "covariance_m2",
            );
            case(&m, v)
        },
    );
}

#[test]
fn fuzz_cli_measurements() {
    let scen = docs::sensors_text();
    fuzz(
        file!(),
        "cli_measurements",
        48,
        KNOWN,
        docs(docs::measurements(), 4),
        |c| {
            let m = mutated(c);
            let v = cli_case(
                "measurements",
                &[
                    "track",
                    "--scenario",
                    "{s.json}",
                    "--measurements",
                    "{m.json}",
                ],
                &[("s.json", &scen), ("m.json", &m.text)],
                &track_nulls,
            );
            case(&m, v)
        },
    );
}

/// Flags of a raw-steps `track` run: with or without the calibration, and the association rule.
const RAW_FLAGS: &[&[&str]] = &[
    &[],
    &["--calibration", "{c.json}"],
    &["--calibration", "{c.json}", "--association", "gated"],
    &["--association", "spec"],
];

#[test]
fn fuzz_cli_raw_steps() {
    let scen = docs::sensors_text();
    let w = docs::walk();
    let cal = w.calibration.to_string();
    let strategy = (
        docs(
            vec![w.raw_snapshot_start.clone(), w.raw_truth_start.clone()],
            4,
        ),
        prop::sample::select(RAW_FLAGS),
    );
    fuzz(
        file!(),
        "cli_raw_steps",
        48,
        KNOWN,
        strategy,
        |(c, flags)| {
            let m = mutated(c);
            let mut args = vec![
                "track",
                "--scenario",
                "{s.json}",
                "--measurements",
                "{m.json}",
            ];
            args.extend_from_slice(flags);
            let v = cli_case(
                "raw",
                &args,
                &[("s.json", &scen), ("m.json", &m.text), ("c.json", &cal)],
                &track_nulls,
            );
            let mut k = case(&m, v);
            k.what = format!("flags {flags:?}: {}", k.what);
            k
        },
    );
}

#[test]
fn fuzz_cli_calibration_file() {
    let scen = docs::sensors_text();
    let w = docs::walk();
    let meas = w.raw_snapshot_start.to_string();
    let strategy = (
        docs(vec![w.calibration.clone()], 4),
        prop::sample::select(&["spec", "gated"][..]),
    );
    fuzz(
        file!(),
        "cli_calibration_file",
        48,
        KNOWN,
        strategy,
        |(c, rule)| {
            let m = mutated(c);
            let v = cli_case(
                "calfile",
                &[
                    "track",
                    "--scenario",
                    "{s.json}",
                    "--measurements",
                    "{m.json}",
                    "--calibration",
                    "{c.json}",
                    "--association",
                    rule,
                ],
                &[("s.json", &scen), ("m.json", &meas), ("c.json", &m.text)],
                &track_nulls,
            );
            case(&m, v)
        },
    );
}

#[test]
fn fuzz_cli_snapshots() {
    let scen = docs::sensors_text();
    fuzz(
        file!(),
        "cli_snapshots",
        48,
        KNOWN,
        docs(vec![docs::walk().snapshots.clone()], 4),
        |c| {
            let m = mutated(c);
            let v = cli_case(
                "snapshots",
                &[
                    "calibrate",
                    "--scenario",
                    "{s.json}",
                    "--snapshots",
                    "{f.json}",
                ],
                &[("s.json", &scen), ("f.json", &m.text)],
                &|_, _| false,
            );
            case(&m, v)
        },
    );
}

/// Flags of an `mtl locate` run.
const MTL_FLAGS: &[&[&str]] = &[
    &[],
    &["--model", "ppp", "--tb", "6"],
    &["--model", "icb", "--tb", "inf"],
    &["--b-max", "inf"],
    &["--model", "empirical", "--cells", "4", "--scenes", "20"],
];

#[test]
fn fuzz_cli_mtl() {
    let bases: Vec<Value> = docs::ranges()
        .into_iter()
        .map(|r| serde_json::json!({"network": docs::network(), "ranges": r}))
        .collect();
    let strategy = (docs(bases, 4), prop::sample::select(MTL_FLAGS));
    fuzz(file!(), "cli_mtl", 24, KNOWN, strategy, |(c, flags)| {
        let m = mutated(c);
        // The two files of the case: each top-level part (absent = the text `null`).
        let doc = serde_json::from_str::<Value>(&m.text);
        let part = |k: &str| -> String {
            match &doc {
                Ok(doc) => doc.get(k).map_or("null".into(), Value::to_string),
                // Raw tokens made the document invalid JSON: cut it by hand.
                Err(_) => cut(&m.text, k),
            }
        };
        let (net, ranges) = (part("network"), part("ranges"));
        let mut args = vec![
            "mtl",
            "locate",
            "--network",
            "{n.json}",
            "--ranges",
            "{r.json}",
        ];
        args.extend_from_slice(flags);
        let v = cli_case(
            "mtl",
            &args,
            &[("n.json", &net), ("r.json", &ranges)],
            &|p, _| p == "t_b",
        );
        let mut k = case(&m, v);
        k.what = format!("flags {flags:?}: {}", k.what);
        k
    });
}

/// The text of top-level key `k` of `{"network":…,"ranges":…}` (either order) when the document
/// does not parse (raw tokens): from after `"k":` to the next top-level key or the end.
fn cut(text: &str, k: &str) -> String {
    let key = format!("\"{k}\":");
    let Some(start) = text.find(&key).map(|i| i + key.len()) else {
        return "null".into();
    };
    let rest = &text[start..];
    let other = if k == "network" {
        ",\"ranges\":"
    } else {
        ",\"network\":"
    };
    let end = rest.find(other).unwrap_or(rest.len().saturating_sub(1));
    rest[..end].to_string()
}

// ------------------------------------------------------------------------------- output targets

/// What a case plants in the output directory before the run (issue 24).
#[derive(Clone, Copy, Debug)]
enum Plant {
    /// Nothing: a new file.
    Nothing,
    /// A regular file at the target (replaced).
    File,
    /// A symbolic link at the target to a victim file (refused; the victim unchanged).
    LinkToVictim,
    /// A symbolic link at the target to `/dev/null` (refused: the data would be lost).
    LinkToNull,
    /// A FIFO at the target (refused, not blocking).
    Fifo,
    /// A directory at the target (refused).
    Directory,
    /// Links to the victim at the old predictable temporary names (never followed).
    LinksAtTemporaryNames,
}

const PLANTS: [Plant; 7] = [
    Plant::Nothing,
    Plant::File,
    Plant::LinkToVictim,
    Plant::LinkToNull,
    Plant::Fifo,
    Plant::Directory,
    Plant::LinksAtTemporaryNames,
];

/// The output-writing commands of a case: the arguments (`{out}` is the planted target, `{dir}`
/// its directory, `{s}` the scenario) and the target's file name.
const WRITERS: &[(&[&str], &str)] = &[
    (
        &[
            "crlb-map",
            "--scenario",
            "{s}",
            "--out",
            "{out}",
            "--nx",
            "16",
            "--ny",
            "16",
        ],
        "m.json",
    ),
    (
        &[
            "crlb-map",
            "--scenario",
            "{s}",
            "--out",
            "{out}",
            "--nx",
            "16",
            "--ny",
            "16",
        ],
        "m.png",
    ),
    (
        &[
            "plan",
            "--scenario",
            "{s}",
            "--out",
            "{dir}/p.json",
            "--figure",
            "{out}",
            "--grid",
            "8",
            "--move",
            "rx",
            "--objective",
            "p90",
            "--roi",
            "-7.5,30,-10,26",
            "--budget",
            "40",
        ],
        "p.svg",
    ),
    (
        &[
            "simulate-walk",
            "--scenario",
            "{s}",
            "--out-dir",
            "{dir}",
            "--duration",
            "1",
            "--calibration-snapshots",
            "5",
        ],
        "truth.json",
    ),
    (
        &[
            "montecarlo",
            "--trajectory",
            "I",
            "--runs",
            "4",
            "--noise-runs",
            "1",
            "--dt",
            "0.1",
            "--json",
            "{out}",
        ],
        "mc.json",
    ),
];

/// One output-target case: `writers` processes at once run a command whose target holds
/// `plant`. The invariant (docs/cli.md, "Output safety"): a refused target is exit 2 naming the
/// flag and writes nothing; otherwise exit 0 and the target is a regular file holding one whole
/// output; the victim is never changed, nothing blocks (the time limit), no temporary is left.
fn run_output_target(cmd: usize, plant: Plant, writers: usize, dir: &CaseDir) -> Verdict {
    use std::os::unix::fs::symlink;
    let (args, name) = WRITERS[cmd];
    let out_dir = dir.0.join("out");
    let _ = std::fs::remove_dir_all(&out_dir);
    std::fs::create_dir_all(&out_dir).expect("out dir");
    let d = out_dir.to_string_lossy().into_owned();
    let target = out_dir.join(name);
    let scenario = dir.write("s.json", &docs::sensors_text());
    let victim = dir.write("victim.txt", "precious");
    let planted = match plant {
        Plant::Nothing => false,
        Plant::File => {
            std::fs::write(&target, "old").expect("plant");
            false
        }
        Plant::LinkToVictim => {
            symlink(&victim, &target).expect("plant");
            true
        }
        Plant::LinkToNull => {
            symlink("/dev/null", &target).expect("plant");
            true
        }
        Plant::Fifo => {
            let ok = Command::new("mkfifo")
                .arg(&target)
                .status()
                .expect("mkfifo");
            assert!(ok.success());
            true
        }
        Plant::Directory => {
            std::fs::create_dir(&target).expect("plant");
            true
        }
        Plant::LinksAtTemporaryNames => {
            let stem = name.split('.').next().unwrap_or(name);
            let ext = name.rsplit('.').next().unwrap_or("");
            for tmp in [
                format!("{stem}.tmp.{ext}"),
                format!("{name}.tmp"),
                format!("{stem}.tmp"),
            ] {
                symlink(&victim, out_dir.join(tmp)).expect("plant");
            }
            false
        }
    };
    let args: Vec<String> = args
        .iter()
        .map(|a| {
            a.replace("{out}", &target.to_string_lossy())
                .replace("{dir}", &d)
                .replace("{s}", &scenario)
        })
        .collect();
    let runs: Vec<check::CliRun> = std::thread::scope(|s| {
        let hs: Vec<_> = (0..writers).map(|_| s.spawn(|| run_cli(&args))).collect();
        hs.into_iter().map(|h| h.join().expect("run")).collect()
    });
    for run in &runs {
        // Summaries name the outputs not asked for as null (`out` of montecarlo without --out).
        let v = check_cli(run, &|p, _| p == "out" || p == "figure")?;
        if planted != (v == Pass::Err) {
            return Err(fail(
                Class::BadOutput,
                format!("{plant:?}: exit {:?}: {}", run.code, clip(&run.stderr, 300)),
            ));
        }
    }
    if std::fs::read_to_string(&victim).ok().as_deref() != Some("precious") {
        return Err(fail(
            Class::BadOutput,
            format!("{plant:?}: the link's target was written"),
        ));
    }
    let left: Vec<String> = std::fs::read_dir(&out_dir)
        .expect("list")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .filter(|f| f.starts_with(".scatterloc-"))
        .collect();
    if !left.is_empty() {
        return Err(fail(
            Class::BadOutput,
            format!("temporaries left: {left:?}"),
        ));
    }
    if planted {
        // Nothing new beside the planted target.
        let n = std::fs::read_dir(&out_dir).expect("list").count();
        if n != 1 {
            return Err(fail(
                Class::BadOutput,
                format!("{plant:?}: {n} entries after a refusal"),
            ));
        }
        return Ok(Pass::Err);
    }
    let bytes = std::fs::read(&target).unwrap_or_default();
    let whole = match name.rsplit('.').next() {
        Some("json") => serde_json::from_slice::<Value>(&bytes).is_ok(),
        Some("png") => bytes.starts_with(b"\x89PNG") && bytes.ends_with(b"IEND\xaeB`\x82"),
        _ => bytes.ends_with(b"</svg>\n") || bytes.ends_with(b"</svg>"),
    };
    if !whole || !std::fs::symlink_metadata(&target).is_ok_and(|m| m.is_file()) {
        return Err(fail(
            Class::BadOutput,
            format!("{plant:?}: {name} is not one whole output"),
        ));
    }
    Ok(Pass::Ok)
}

/// Issue 24: output targets with planted links, FIFOs, directories and files, and concurrent
/// writers, for each kind of output (JSON, PNG, SVG with its JSON, simulate-walk's three files,
/// a study's --json).
#[test]
fn fuzz_cli_output_targets() {
    let strategy = (
        0..WRITERS.len(),
        prop::sample::select(PLANTS.to_vec()),
        1usize..=2,
    );
    let dir = CaseDir::new("output_targets");
    fuzz(
        file!(),
        "cli_output_targets",
        24,
        KNOWN,
        strategy,
        |&(cmd, plant, writers)| Case {
            verdict: run_output_target(cmd, plant, writers, &dir),
            what: format!("{:?} with {plant:?}, {writers} writer(s)", WRITERS[cmd].0),
        },
    );
}

// ------------------------------------------------------------------------------- channel responses

/// Spec C12 7 in the fuzz suite: a random multipath response (`common/multipath.rs`: up to 64
/// paths, spacings down to 0.1/B, amplitudes over 60 dB, noise-free to 0 dB SNR, or a stated
/// `noise_var` of 1e-40) → the snapshot estimator with `max_paths` 1 … 64: finite paths within
/// every stated bound of its loops, within the time budget.
fn run_multipath(seed: u64, max_paths: usize) -> Verdict {
    let b = multipath::band();
    let mut est = multipath::estimator(&b, max_paths);
    match multipath::run(&mut est, &b, seed) {
        Ok(_) => Ok(Pass::Ok),
        Err(m) => Err(fail(Class::NonFinite, m)),
    }
}

#[test]
fn fuzz_multipath_responses() {
    let strategy = (any::<u64>(), 1usize..=64);
    fuzz(file!(), "multipath", 60, KNOWN, strategy, |(seed, k)| {
        let desc = format!("multipath seed {seed}, max_paths {k}");
        Case {
            verdict: guarded(&desc, || run_multipath(*seed, *k)),
            what: desc,
        }
    });
}
