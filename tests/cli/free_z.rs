//! `crlb --free-z` and `locate --free-z` (issue 40 §2: the target's height unknown where the
//! user asks): the CLI prints the library's documents (`CrlbFreeZDoc`, `FixFreeZDoc`) with
//! absolute heights; a fix from noise-free 3-D delays lands on the truth; planar layouts are
//! unbounded (nulls, not NaN); bad flags and files are named errors.

use serde_json::{json, Value};

use scatterloc::localize::{locate_free_z, DelayMeasurements, LmConfig};
use scatterloc::math::{Real, Vec3};
use scatterloc::present::{CrlbFreeZDoc, FixFreeZDoc};
use scatterloc::{Model, Scenario};

use crate::common::cli::{fails, ok_json, run, TempDir};

/// sensors2019 with the Tx and receivers at four heights, the target plane at 1.0 m.
fn lifted() -> Scenario {
    let mut s = scatterloc::scenario::presets::sensors2019();
    s.transmitters[0].height_m = 2.8;
    for (r, h) in s.receivers.iter_mut().zip([2.8, 0.8, 2.2, 1.5]) {
        r.height_m = h;
    }
    s.target.height_m = 1.0;
    s
}

/// 3-D delays (the library's distances, cross-checked by hand in spec_checks_3d) at `[x, y, z]`.
fn delays_at(s: &Scenario, p: [Real; 3]) -> Vec<Option<Real>> {
    let d3 = |n: [Real; 2], h: Real| {
        ((p[0] - n[0]).powi(2) + (p[1] - n[1]).powi(2) + (p[2] - h).powi(2)).sqrt()
    };
    let c = scatterloc::math::SPEED_OF_LIGHT;
    let t = &s.transmitters[0];
    s.receivers
        .iter()
        .map(|r| Some((d3(t.position_m, t.height_m) + d3(r.position_m, r.height_m)) / c))
        .collect()
}

#[test]
fn crlb_free_z_prints_the_librarys_document() {
    let dir = TempDir::new();
    let s = lifted();
    let f = dir.write_text("s.json", &s.to_json());
    let model = Model::new(&s).unwrap();
    for (at, h) in [([5.0, 2.0], None), ([-2.0, 6.5], Some(1.6))] {
        let mut args = vec!["crlb", "--scenario", &f, "--at"];
        let at_s = format!("{},{}", at[0], at[1]);
        args.push(&at_s);
        args.push("--free-z");
        let hs = h.map(|h: Real| h.to_string());
        if let Some(hs) = &hs {
            args.extend(["--height", hs.as_str()]);
        }
        let got = ok_json(&args);
        let want = CrlbFreeZDoc::at(&s, &model, at, h.unwrap_or(1.0));
        assert_eq!(got, serde_json::to_value(&want).unwrap());
        assert_eq!(got["bounded"], json!(true));
        let (h3, known) = (
            got["rmse_bound_m"].as_f64().unwrap(),
            got["height_known_rmse_bound_m"].as_f64().unwrap(),
        );
        assert!(h3 >= known && got["sigma_z_m"].as_f64().unwrap() > 0.0);
    }
    // At the stated height, the height-known bound is `scatterloc crlb`'s.
    let plain = ok_json(&["crlb", "--scenario", &f, "--at", "5,2"]);
    let free = ok_json(&["crlb", "--scenario", &f, "--at", "5,2", "--free-z"]);
    assert_eq!(free["height_known_rmse_bound_m"], plain["rmse_bound_m"]);
    assert_eq!(free["position_m"], json!([5.0, 2.0, 1.0]));
}

#[test]
fn crlb_free_z_of_a_planar_layout_is_unbounded_with_nulls() {
    let dir = TempDir::new();
    let f = dir.write_text(
        "s.json",
        &scatterloc::scenario::presets::sensors2019().to_json(),
    );
    let v = ok_json(&["crlb", "--scenario", &f, "--at", "5,2", "--free-z"]);
    assert_eq!(v["bounded"], json!(false));
    for k in [
        "sigma_x_m",
        "sigma_z_m",
        "rmse_bound_m",
        "rmse_3d_bound_m",
        "covariance_m2",
    ] {
        assert_eq!(v[k], Value::Null, "{k}");
    }
    assert!(v["height_known_rmse_bound_m"].as_f64().unwrap() > 0.0);
    // --height needs --free-z (a usage error, exit 2).
    let out = run(&["crlb", "--scenario", &f, "--at", "5,2", "--height", "1"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--free-z"));
}

#[test]
fn locate_free_z_finds_the_height_and_prints_the_librarys_fix() {
    let dir = TempDir::new();
    let s = lifted();
    let f = dir.write_text("s.json", &s.to_json());
    let model = Model::new(&s).unwrap();
    for (truth, start) in [
        ([4.0, 1.0, 1.4], None),
        ([-3.0, 5.0, 0.6], Some(json!([-2.0, 4.0]))),
        ([7.5, -2.0, 1.0], Some(json!([7.0, -1.0, 1.5]))),
    ] {
        let delays = delays_at(&s, truth);
        let sig = vec![3e-11; delays.len()];
        let mut file = json!({"delays_s": delays, "sigma_s": 3e-11});
        if let Some(st) = &start {
            file["initial_m"] = st.clone();
        }
        let d = dir.write_text("d.json", &file.to_string());
        let got = ok_json(&["locate", "--scenario", &f, "--delays", &d, "--free-z"]);
        let p: Vec<Real> = got["position_m"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        let err =
            ((p[0] - truth[0]).powi(2) + (p[1] - truth[1]).powi(2) + (p[2] - truth[2]).powi(2))
                .sqrt();
        assert!(err < 1e-6, "{truth:?}: {p:?}");
        assert_eq!(got["converged"], json!(true));
        // The same document as the library's.
        let initial = start.map(|v| {
            let a: Vec<Real> = serde_json::from_value(v).unwrap();
            Vec3::new(a[0], a[1], a.get(2).copied().unwrap_or(1.0) - 1.0)
        });
        let m = DelayMeasurements {
            delays_s: &delays,
            sigmas_s: &sig,
        };
        let rep =
            locate_free_z(&model.network, &m, &LmConfig::default(), initial, &s.area_m).unwrap();
        assert_eq!(
            got,
            serde_json::to_value(FixFreeZDoc::new(&rep, 1.0)).unwrap()
        );
    }
}

#[test]
fn locate_names_a_bad_start_length() {
    let dir = TempDir::new();
    let s = lifted();
    let f = dir.write_text("s.json", &s.to_json());
    let delays = delays_at(&s, [4.0, 1.0, 1.0]);
    let d = dir.write_text(
        "d.json",
        &json!({"delays_s": delays, "sigma_s": 3e-11, "initial_m": [1.0, 2.0, 3.0, 4.0]})
            .to_string(),
    );
    fails(
        &["locate", "--scenario", &f, "--delays", &d, "--free-z"],
        &["initial_m", "[x, y, z]"],
    );
    let d3 = dir.write_text(
        "d3.json",
        &json!({"delays_s": delays, "sigma_s": 3e-11, "initial_m": [1.0, 2.0, 3.0]}).to_string(),
    );
    fails(
        &["locate", "--scenario", &f, "--delays", &d3],
        &["initial_m", "--free-z"],
    );
}
