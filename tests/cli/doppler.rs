//! `crlb --doppler` (issue 42 §1): the CLI prints `crlb`'s document plus the library's
//! `DopplerDoc` (the bound on position and velocity over one CPI from delays and range rates,
//! docs/doppler.md), bit for bit; the delay-only position bound of the CPI is `crlb`'s divided
//! by √N; the velocity is bounded only with Doppler; bad CPI flags are named usage errors.

use serde_json::json;

use scatterloc::measure::Cpi;
use scatterloc::present::DopplerDoc;
use scatterloc::Model;

use crate::common::cli::{fails, ok_json, TempDir};

#[test]
fn crlb_doppler_prints_the_librarys_document() {
    let dir = TempDir::new();
    let s = scatterloc::scenario::presets::sensors2019();
    let f = dir.write_text("s.json", &s.to_json());
    let model = Model::new(&s).unwrap();
    for (at, v, n, t, floor) in [
        ([10.0, 0.0], [1.0, 0.5], 16usize, 2.048e-3, 0.1),
        ([-3.0, 7.5], [0.0, 0.0], 4, 0.05, 0.0),
        ([20.0, 10.0], [-1.2, 0.3], 64, 1e-3, 0.3),
    ] {
        let (at_s, v_s) = (format!("{},{}", at[0], at[1]), format!("{},{}", v[0], v[1]));
        let (n_s, t_s, f_s) = (n.to_string(), t.to_string(), floor.to_string());
        let got = ok_json(&[
            "crlb",
            "--scenario",
            &f,
            "--at",
            &at_s,
            "--doppler",
            "--velocity",
            &v_s,
            "--cpi",
            &n_s,
            "--cpi-spacing-s",
            &t_s,
            "--range-rate-floor",
            &f_s,
        ]);
        let plain = ok_json(&["crlb", "--scenario", &f, "--at", &at_s]);
        let cpi = Cpi::new(s.radio.carrier_hz, n, t, floor).unwrap();
        let want = serde_json::to_value(DopplerDoc::at(&model, at, v, &cpi)).unwrap();
        assert_eq!(got["doppler"], want);
        // `crlb`'s own keys are unchanged.
        let mut rest = got.clone();
        rest.as_object_mut().unwrap().remove("doppler");
        assert_eq!(rest, plain);
        // The CPI's delays alone: N snapshots of E8, so √N below one snapshot's bound.
        let one = plain["rmse_bound_m"].as_f64().unwrap();
        let cpi_delay = want["delay_only_position_rmse_m"].as_f64().unwrap();
        assert!((cpi_delay * (n as f64).sqrt() - one).abs() <= 1e-12 * one);
        // Doppler only adds information; it bounds the velocity.
        assert!(want["position_rmse_m"].as_f64().unwrap() <= cpi_delay * (1.0 + 1e-12));
        assert!(want["velocity_rmse_mps"].as_f64().unwrap() > 0.0);
    }
}

#[test]
fn bad_doppler_flags_are_named() {
    let dir = TempDir::new();
    let s = scatterloc::scenario::presets::sensors2019();
    let f = dir.write_text("s.json", &s.to_json());
    let base = ["crlb", "--scenario", f.as_str(), "--at", "10,0"];
    let with = |extra: &[&str]| -> Vec<String> {
        base.iter().chain(extra).map(|s| s.to_string()).collect()
    };
    for (extra, needle) in [
        (vec!["--doppler", "--cpi", "0"], "cpi.snapshots"),
        (vec!["--doppler", "--cpi-spacing-s", "0"], "cpi.spacing_s"),
        (
            vec!["--doppler", "--range-rate-floor", "-1"],
            "cpi.floor_mps",
        ),
        (vec!["--doppler", "--velocity", "1,nan"], "velocity"),
        (vec!["--velocity", "1,0"], "--doppler"),
        (vec!["--doppler", "--free-z"], "--free-z"),
    ] {
        let args = with(&extra);
        let refs: Vec<&str> = args.iter().map(|s| s.as_str()).collect();
        fails(&refs, &[needle]);
    }
    // One snapshot: no Doppler information, the velocity unbounded (null), never NaN.
    let one = ok_json(
        &with(&["--doppler", "--cpi", "1"])
            .iter()
            .map(|s| s.as_str())
            .collect::<Vec<_>>(),
    );
    assert_eq!(one["doppler"]["velocity_rmse_mps"], json!(null));
    assert_eq!(
        one["doppler"]["links"][0]["sigma_range_rate_mps"],
        json!(null)
    );
}

#[test]
fn crlb_map_with_doppler_is_the_librarys_map() {
    use scatterloc::localize::{doppler_map, Grid, MapQuantity};
    let dir = TempDir::new();
    let s = scatterloc::scenario::presets::sensors2019();
    let f = dir.write_text("s.json", &s.to_json());
    let model = Model::new(&s).unwrap();
    let grid = Grid::new(s.area_m, 12, 9).unwrap();
    let cpi = Cpi::new(s.radio.carrier_hz, 8, 5e-3, 0.05).unwrap();
    let v = scatterloc::Vec2::new(0.8, 0.6);
    for (quantity, q, key) in [
        ("position", MapQuantity::Position, "rmse_bound_m"),
        ("velocity", MapQuantity::Velocity, "velocity_rmse_bound_mps"),
    ] {
        let out = dir.path(&format!("{quantity}.json"));
        let summary = ok_json(&[
            "crlb-map",
            "--scenario",
            &f,
            "--out",
            &out,
            "--nx",
            "12",
            "--ny",
            "9",
            "--quantity",
            quantity,
            "--doppler",
            "--velocity",
            "0.8,0.6",
            "--cpi",
            "8",
            "--cpi-spacing-s",
            "5e-3",
            "--range-rate-floor",
            "0.05",
        ]);
        assert_eq!(summary["kernel"], "doppler");
        let doc: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
        let mut want = vec![0.0; grid.len()];
        doppler_map(&model, &grid, &cpi, v, q, &mut want).unwrap();
        let got: Vec<f64> = doc[key]
            .as_array()
            .unwrap()
            .iter()
            .flat_map(|row| row.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()))
            .collect();
        assert_eq!(got, want, "{quantity}");
        let unit = if quantity == "velocity" { "mps" } else { "m" };
        assert_eq!(
            summary[format!("min_{unit}")].as_f64().unwrap(),
            want.iter().copied().fold(f64::INFINITY, f64::min)
        );
    }
    // The velocity figure's colour bar reads in m/s.
    let svg = dir.path("v.svg");
    ok_json(&[
        "crlb-map",
        "--scenario",
        &f,
        "--out",
        &svg,
        "--nx",
        "24",
        "--ny",
        "24",
        "--quantity",
        "velocity",
        "--doppler",
    ]);
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.contains("m/s") && text.contains("Velocity CRLB with Doppler"));
    // Velocity needs --doppler; the Doppler flags need it too.
    fails(
        &[
            "crlb-map",
            "--scenario",
            &f,
            "--out",
            &dir.path("x.json"),
            "--quantity",
            "velocity",
        ],
        &["--doppler"],
    );
    fails(
        &[
            "crlb-map",
            "--scenario",
            &f,
            "--out",
            &dir.path("x.json"),
            "--cpi",
            "4",
        ],
        &["--doppler"],
    );
}

/// `montecarlo --doppler` (issue 42 §3): the JSON of each trajectory is the library's
/// `DopplerStudy` (both arms, bit for bit) for the EKF and the UKF; the figure is written;
/// flags of the classic study are refused by name (exit 2, nothing written).
#[test]
fn montecarlo_doppler_is_the_librarys_study() {
    use scatterloc::study::DopplerStudy;
    use scatterloc::track::{
        paper_initial_covariance, ConstantVelocity, FilterKind, TrackScenario, UkfParams,
    };
    let dir = TempDir::new();
    let s = scatterloc::scenario::presets::sensors2019();
    let f = dir.write_text("s.json", &s.to_json());
    let model = Model::new(&s).unwrap();
    for (name, kind) in [
        ("ekf", FilterKind::Ekf),
        ("ukf", FilterKind::Ukf(UkfParams::default())),
    ] {
        let (json, fig) = (
            dir.path(&format!("{name}.json")),
            dir.path(&format!("{name}.svg")),
        );
        let summary = ok_json(&[
            "montecarlo",
            "--doppler",
            "--scenario",
            &f,
            "--trajectory",
            "II",
            "--runs",
            "12",
            "--duration",
            "0.5",
            "--cpi",
            "8",
            "--cpi-spacing-s",
            "0.003",
            "--range-rate-floor",
            "0.05",
            "--filters",
            name,
            "--seed",
            "5",
            "--json",
            &json,
            "--out",
            &fig,
        ]);
        assert_eq!(summary["doppler"][0]["trajectory"], "II");
        let got: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
        let want = DopplerStudy {
            motion: ConstantVelocity::new(0.1, 1.0),
            mean_state: TrackScenario::II.mean_state(),
            initial_covariance: paper_initial_covariance(),
            cpi: Cpi::new(s.radio.carrier_hz, 8, 0.003, 0.05).unwrap(),
            steps: 5,
            runs: 12,
            seed: 5,
            filter: kind,
        }
        .run(&model)
        .unwrap();
        assert_eq!(
            got[0]["delay_only"],
            serde_json::to_value(&want.delay_only).unwrap()
        );
        assert_eq!(
            got[0]["with_doppler"],
            serde_json::to_value(&want.with_doppler).unwrap()
        );
        assert_eq!(got[0]["filter"], name);
        assert!(std::fs::read_to_string(&fig)
            .unwrap()
            .contains("delays + Doppler"));
    }
    let out = dir.path("no.json");
    for (extra, flag) in [
        (vec!["--shard", "0/2"], "--shard"),
        (vec!["--noise-runs", "3"], "--noise-runs"),
        (vec!["--velocity", "1,0"], "--velocity"),
        (vec!["--filters", "ekf,ukf"], "--filters"),
    ] {
        let mut args = vec!["montecarlo", "--doppler", "--runs", "2", "--json", &out];
        args.extend(extra);
        fails(&args, &[flag]);
    }
    assert!(!std::path::Path::new(&out).exists());
}
