//! `track` with range rates in the measurement file (issue 42 §5; docs/doppler.md D1, D5): the
//! file is made here from a known walk with the library (delays from `network.delay`, range
//! rates from `measure::range_rate`, seeded Gaussian noise of the link budget's and the CPI's σ).
//! The CLI's states, covariances, NIS and predicted range rates equal a library loop of
//! `Filter::predict` + `Filter::update_doppler` bit for bit (EKF, UKF, PF; the rates' σ from the
//! file's CPI, the flags' CPI, the default CPI or fixed per link); with the rates the velocity
//! RMSE is lower than without (several seeds, numbers printed); a file without rates (and
//! `--no-doppler`) gives the delay-only loop's output bit for bit; bad rate fields and flags are
//! named errors with exit status 2.

use serde_json::{json, Value};

use scatterloc::math::{Mat4, Real, Vec2, Vec4};
use scatterloc::measure::{
    range_rate, rng, standard_normal, Cpi, Rng, DEFAULT_RANGE_RATE_FLOOR_MPS,
};
use scatterloc::scenario::presets;
use scatterloc::track::{
    ConstantVelocity, Filter, FilterKind, MeasurementNoise, PfConfig, RangeRates, RateNoise,
    Tracker, UkfParams,
};
use scatterloc::Model;

use crate::common::cli::{fails, ok_json, TempDir};

const DT: Real = 0.1;
const Q: Real = 0.1;
const STEPS: usize = 60;

/// The walk: from (4, 2) m at (1.2, 0.4) m/s, turning slowly (a speed change in y).
fn truth(k: usize) -> Vec4 {
    let t = (k + 1) as Real * DT;
    let vy = 0.4 + 0.5 * (t / 3.0).sin();
    let y = 2.0 + 0.4 * t + 1.5 * (1.0 - (t / 3.0).cos());
    Vec4::new(4.0 + 1.2 * t, y, 1.2, vy)
}

/// The CPI the rates are simulated over (D5): 16 snapshots 2.048 ms apart, 0.1 m/s floor.
fn sim_cpi(model: &Model) -> Cpi {
    Cpi::new(model.carrier_hz, 16, 2.048e-3, DEFAULT_RANGE_RATE_FLOOR_MPS).unwrap()
}

/// Per step the noisy delays (σ of E8 at the truth, link 1 missing every 7th step) and range
/// rates (σ of the CPI at the truth, link 2 missing every 5th step), from `seed`.
#[allow(clippy::type_complexity)]
fn simulate(model: &Model, seed: u64) -> (Vec<Vec<Option<Real>>>, Vec<Vec<Option<Real>>>) {
    let cpi = sim_cpi(model);
    let mut g: Rng = rng(seed, 3);
    let (mut z, mut rates) = (Vec::new(), Vec::new());
    for k in 0..STEPS {
        let x = truth(k);
        let (r, v) = (Vec2::new(x[0], x[1]), Vec2::new(x[2], x[3]));
        let mut zk = Vec::new();
        let mut rk = Vec::new();
        for p in 0..model.link_count() {
            let d = model.network.delay(p, r) + model.sigma_delay(p, r) * standard_normal(&mut g);
            let s = cpi.sigma_range_rate(model.snr(p, r));
            let rate = range_rate(&model.network, p, r, v) + s * standard_normal(&mut g);
            zk.push((!(p == 1 && k % 7 == 3)).then_some(d));
            rk.push((!(p == 2 && k % 5 == 1)).then_some(rate));
        }
        z.push(zk);
        rates.push(rk);
    }
    (z, rates)
}

fn x0() -> Vec4 {
    truth(0) - Vec4::new(0.12 * DT, 0.0, 0.0, 0.0) + Vec4::new(0.2, -0.15, -0.6, 0.5)
}

fn p0() -> Mat4 {
    Mat4::from_diagonal(&Vec4::new(0.1, 0.1, 0.5, 0.5))
}

/// The measurement file: the CV model, the start, the delays and `extra` (the rate fields).
fn file(z: &[Vec<Option<Real>>], extra: Value) -> Value {
    let x = x0();
    let p = p0();
    let rows: Vec<Vec<Real>> = (0..4)
        .map(|i| (0..4).map(|j| p[(i, j)]).collect())
        .collect();
    let mut m = json!({
        "dt_s": DT, "process_noise": Q,
        "initial_state": [x[0], x[1], x[2], x[3]],
        "initial_covariance": rows,
        "steps": z,
    });
    for (k, v) in extra.as_object().unwrap() {
        m[k] = v.clone();
    }
    m
}

/// The library's loop: predict, then (with rates) the predicted range rates and
/// `update_doppler`, else `update`; the states, covariances, NIS and predicted rates.
struct Run {
    states: Vec<[Real; 4]>,
    covariances: Vec<[[Real; 4]; 4]>,
    nis: Vec<Option<Real>>,
    predicted: Vec<Vec<Real>>,
}

fn library(
    model: &Model,
    kind: FilterKind,
    z: &[Vec<Option<Real>>],
    rates: Option<(&[Vec<Option<Real>>], RateNoise)>,
) -> Run {
    let motion = ConstantVelocity::new(DT, Q);
    let mut f = Tracker::new(kind, x0(), p0(), rng(1, 0)).unwrap();
    let mut out = Run {
        states: vec![],
        covariances: vec![],
        nis: vec![],
        predicted: vec![],
    };
    for (k, zk) in z.iter().enumerate() {
        f.predict(&motion);
        let u = match rates {
            Some((r, noise)) => {
                let pred = f.predicted_range_rates(model, noise).unwrap();
                out.predicted
                    .push(pred.iter().map(|p| p.range_rate_mps).collect());
                let rr = RangeRates {
                    rates_mps: &r[k],
                    noise,
                };
                f.update_doppler(model, zk, MeasurementNoise::AtPrediction, &rr)
                    .unwrap()
            }
            None => f.update(model, zk, MeasurementNoise::AtPrediction).unwrap(),
        };
        out.states.push((*f.state()).into());
        let c = f.covariance();
        out.covariances.push(core::array::from_fn(|i| {
            core::array::from_fn(|j| c[(i, j)])
        }));
        out.nis.push((u.links_used > 0).then_some(u.nis));
    }
    out
}

/// The CLI's output equals the library's run bit for bit.
fn assert_same(what: &str, got: &Value, want: &Run) {
    let states: Vec<[Real; 4]> = serde_json::from_value(got["states"].clone()).unwrap();
    let cov: Vec<[[Real; 4]; 4]> = serde_json::from_value(got["covariances"].clone()).unwrap();
    let nis: Vec<Option<Real>> = serde_json::from_value(got["nis"].clone()).unwrap();
    assert_eq!(states, want.states, "{what}: states");
    assert_eq!(cov, want.covariances, "{what}: covariances");
    assert_eq!(nis, want.nis, "{what}: nis");
    if !want.predicted.is_empty() {
        let pred: Vec<Vec<Real>> =
            serde_json::from_value(got["doppler"]["predicted_range_rates_mps"].clone()).unwrap();
        assert_eq!(pred, want.predicted, "{what}: predicted range rates");
    }
}

/// The scenario file and model.
fn setup(dir: &TempDir) -> (String, Model) {
    let s = presets::sensors2019();
    (
        dir.write_text("s.json", &s.to_json()),
        Model::new(&s).unwrap(),
    )
}

fn track(scenario: &str, m: &str, extra: &[&str]) -> Value {
    let mut args = vec!["track", "--scenario", scenario, "--measurements", m];
    args.extend_from_slice(extra);
    ok_json(&args)
}

#[test]
fn track_with_rates_is_the_librarys_doppler_loop() {
    let dir = TempDir::new();
    let (sf, model) = setup(&dir);
    let (z, rates) = simulate(&model, 11);
    let file_cpi = Cpi::new(model.carrier_hz, 8, 5e-3, 0.05).unwrap();
    let flags_cpi = Cpi::new(model.carrier_hz, 32, 1e-3, 0.2).unwrap();
    let default_cpi = sim_cpi(&model);
    let with_cpi = dir.write(
        "cpi.json",
        &file(
            &z,
            json!({"range_rates_mps": rates, "cpi": {"snapshots": 8, "spacing_s": 5e-3, "floor_mps": 0.05}}),
        ),
    );
    let bare = dir.write("bare.json", &file(&z, json!({"range_rates_mps": rates})));
    let sigmas = [0.12, 0.2, 0.15, 0.3];
    let fixed = dir.write(
        "fixed.json",
        &file(
            &z,
            json!({"range_rates_mps": rates, "range_rate_sigma_mps": sigmas}),
        ),
    );
    let flags = [
        "--doppler",
        "--cpi",
        "32",
        "--cpi-spacing-s",
        "1e-3",
        "--range-rate-floor",
        "0.2",
    ];
    let kinds = [
        ("ekf", FilterKind::Ekf),
        ("ukf", FilterKind::Ukf(UkfParams::default())),
        ("pf", FilterKind::Pf(PfConfig::default())),
    ];
    for (name, kind) in kinds {
        let cases: [(&str, &String, Vec<&str>, RateNoise); 4] = [
            ("file cpi", &with_cpi, vec![], RateNoise::Cpi(file_cpi)),
            (
                "flags cpi",
                &with_cpi,
                flags.to_vec(),
                RateNoise::Cpi(flags_cpi),
            ),
            ("default cpi", &bare, vec![], RateNoise::Cpi(default_cpi)),
            ("fixed sigma", &fixed, vec![], RateNoise::Fixed(&sigmas)),
        ];
        for (what, path, extra, noise) in cases {
            let mut args = vec!["--filter", name];
            args.extend(extra);
            let got = track(&sf, path, &args);
            let want = library(&model, kind, &z, Some((&rates, noise)));
            assert_same(&format!("{name}, {what}"), &got, &want);
            let d = &got["doppler"];
            assert_eq!(d["used"], json!(true));
            let sigma = if what == "fixed sigma" {
                "fixed"
            } else {
                "cpi"
            };
            assert_eq!(d["sigma"], json!(sigma), "{name} {what}");
            // The innovations are the rates less the predicted rates; null where missing.
            let inn: Vec<Vec<Option<Real>>> =
                serde_json::from_value(d["range_rate_innovations_mps"].clone()).unwrap();
            for (k, row) in inn.iter().enumerate() {
                for (p, v) in row.iter().enumerate() {
                    assert_eq!(*v, rates[k][p].map(|r| r - want.predicted[k][p]));
                }
            }
        }
    }
}

#[test]
fn files_without_rates_and_no_doppler_track_as_before() {
    let dir = TempDir::new();
    let (sf, model) = setup(&dir);
    let (z, rates) = simulate(&model, 12);
    let old = dir.write("old.json", &file(&z, json!({})));
    let new = dir.write("new.json", &file(&z, json!({"range_rates_mps": rates})));
    for (name, kind) in [
        ("ekf", FilterKind::Ekf),
        ("ukf", FilterKind::Ukf(UkfParams::default())),
        ("pf", FilterKind::Pf(PfConfig::default())),
    ] {
        let want = library(&model, kind, &z, None);
        let got = track(&sf, &old, &["--filter", name]);
        assert_same(&format!("{name} old file"), &got, &want);
        // The document of a file without rates: the keys it always had, no `doppler`.
        let keys: Vec<&String> = got.as_object().unwrap().keys().collect();
        assert_eq!(keys, ["covariances", "links_used", "nis", "states", "t_s"]);
        let ignored = track(&sf, &new, &["--filter", name, "--no-doppler"]);
        assert_same(&format!("{name} --no-doppler"), &ignored, &want);
        assert_eq!(ignored["doppler"]["used"], json!(false));
        assert!(ignored["doppler"]
            .get("predicted_range_rates_mps")
            .is_none());
        let mut rest = ignored.clone();
        rest.as_object_mut().unwrap().remove("doppler");
        assert_eq!(rest, got);
    }
}

/// The velocity RMSE over the run against the walk.
fn velocity_rmse(out: &Value) -> Real {
    let states: Vec<[Real; 4]> = serde_json::from_value(out["states"].clone()).unwrap();
    let sum: Real = states
        .iter()
        .enumerate()
        .map(|(k, s)| {
            let x = truth(k);
            (s[2] - x[2]).powi(2) + (s[3] - x[3]).powi(2)
        })
        .sum();
    (sum / states.len() as Real).sqrt()
}

#[test]
fn range_rates_lower_the_velocity_rmse() {
    let dir = TempDir::new();
    let (sf, model) = setup(&dir);
    for seed in [1, 2, 3] {
        let (z, rates) = simulate(&model, seed);
        let path = dir.write(
            &format!("m{seed}.json"),
            &file(&z, json!({"range_rates_mps": rates})),
        );
        for name in ["ekf", "ukf"] {
            let with = velocity_rmse(&track(&sf, &path, &["--filter", name]));
            let without = velocity_rmse(&track(&sf, &path, &["--filter", name, "--no-doppler"]));
            println!(
                "seed {seed} {name}: velocity RMSE {with:.4} m/s with range rates, \
                 {without:.4} m/s without ({:.2}x)",
                without / with
            );
            assert!(with < without, "seed {seed} {name}: {with} !< {without}");
        }
    }
}

#[test]
fn bad_rate_fields_and_flags_are_named() {
    let dir = TempDir::new();
    let (sf, model) = setup(&dir);
    let (z, rates) = simulate(&model, 5);
    let mut bad_value = rates.clone();
    bad_value[2][1] = Some(3e6);
    let mut short = rates.clone();
    short[4].pop();
    let cases: Vec<(Value, Vec<&str>)> = vec![
        (
            json!({"range_rates_mps": rates[..10]}),
            vec!["range_rates_mps", "60"],
        ),
        (
            json!({"range_rates_mps": short}),
            vec!["range_rates_mps[4]", "4 range rates"],
        ),
        (
            json!({"range_rates_mps": bad_value}),
            vec!["range_rates_mps[2][1]"],
        ),
        (
            json!({"range_rates_mps": rates, "range_rate_sigma_mps": 0.0}),
            vec!["range_rate_sigma_mps"],
        ),
        (
            json!({"range_rates_mps": rates, "range_rate_sigma_mps": [0.1, 0.1]}),
            vec!["range_rate_sigma_mps"],
        ),
        (
            json!({"range_rates_mps": rates, "range_rate_sigma_mps": [0.1, 1e9, 0.1, 0.1]}),
            vec!["range_rate_sigma_mps[1]"],
        ),
        (
            json!({"range_rates_mps": rates, "cpi": {"snapshots": 0, "spacing_s": 1e-3}}),
            vec!["cpi.snapshots"],
        ),
        (
            json!({"range_rates_mps": rates, "cpi": {"snapshots": 4, "spacing_s": 1e-3, "bogus": 1}}),
            vec!["cpi", "bogus"],
        ),
        (
            json!({"range_rates_mps": rates, "range_rate_sigma_mps": 0.1,
                   "cpi": {"snapshots": 4, "spacing_s": 1e-3}}),
            vec!["cpi", "at most one"],
        ),
        (
            json!({"range_rate_sigma_mps": 0.1}),
            vec!["range_rate_sigma_mps", "range_rates_mps"],
        ),
        (json!({"range_rates_mps": "fast"}), vec!["range_rates_mps"]),
        (
            json!({"range_rates_mps": [[1.0, "x"]]}),
            vec!["range_rates_mps[0][1]"],
        ),
    ];
    for (i, (extra, needles)) in cases.into_iter().enumerate() {
        let path = dir.write(&format!("bad{i}.json"), &file(&z, extra));
        let mut n = vec!["--measurements"];
        n.extend(needles);
        fails(&["track", "--scenario", &sf, "--measurements", &path], &n);
    }
    // A bad old-style field still reads as before (the same message as without rates).
    let mut typo = file(&z, json!({"range_rates_mps": rates}));
    typo["dt"] = json!(0.1);
    let path = dir.write("typo.json", &typo);
    fails(
        &["track", "--scenario", &sf, "--measurements", &path],
        &["dt"],
    );
    // Rates with raw_steps.
    let raw = json!({"dt_s": 0.1, "process_noise": 0.1,
        "initial_snapshot": [[[3e-8, 1.0]], [[3e-8, 1.0]], [[3e-8, 1.0]], [[3e-8, 1.0]]],
        "raw_steps": [[[], [], [], []]], "range_rates_mps": [[0.1, 0.2, null, 0.0]]});
    let path = dir.write("raw.json", &raw);
    fails(
        &["track", "--scenario", &sf, "--measurements", &path],
        &["range_rates_mps", "raw_steps"],
    );
    // The flags.
    let old = dir.write("old.json", &file(&z, json!({})));
    let with = dir.write("with.json", &file(&z, json!({"range_rates_mps": rates})));
    let fixed = dir.write(
        "fixed.json",
        &file(
            &z,
            json!({"range_rates_mps": rates, "range_rate_sigma_mps": 0.1}),
        ),
    );
    for (m, extra, needle) in [
        (&old, vec!["--no-doppler"], "--no-doppler"),
        (&old, vec!["--doppler"], "--doppler"),
        (&with, vec!["--doppler", "--no-doppler"], "--no-doppler"),
        (&with, vec!["--cpi", "8"], "--doppler"),
        (&with, vec!["--doppler", "--cpi", "0"], "cpi.snapshots"),
        (
            &with,
            vec!["--doppler", "--cpi-spacing-s", "-1"],
            "cpi.spacing_s",
        ),
        (&with, vec!["--doppler", "--velocity", "1,0"], "--velocity"),
        (&fixed, vec!["--doppler"], "range_rate_sigma_mps"),
    ] {
        let mut args = vec!["track", "--scenario", sf.as_str(), "--measurements", m];
        args.extend(extra);
        fails(&args, &[needle]);
    }
}
