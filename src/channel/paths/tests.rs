use super::*;
use alloc::vec;

use crate::math::Complex;
use crate::measure::{rng, standard_normal};

const DT: Real = 0.1;

fn pe(delay_s: Real, sigma_s: Real, snr: Real) -> PathEstimate {
    PathEstimate {
        delay_s,
        alpha: Complex::new(1.0, 0.0),
        sigma_s,
        snr,
        range_rate: None,
    }
}

fn snap(paths: Vec<PathEstimate>) -> Result<SnapshotEstimate> {
    Ok(SnapshotEstimate {
        paths,
        noise_var: 1.0,
        work: Default::default(),
    })
}

#[test]
fn a_constant_rate_path_keeps_one_id_and_seeds_are_the_kf_predictions() {
    // 1 m/s of bistatic-range rate, σ = 0.1 ns measurements, 200 snapshots.
    let rate = 1.0 / SPEED_OF_LIGHT;
    let sigma = 0.1e-9;
    let cfg = PathTrackerConfig::default();
    let mut tracker = PathTracker::new(cfg).unwrap();
    let mut r = rng(7, 0);
    // An independent textbook KF (standard covariance update) that the seeds must equal.
    let mut x = nalgebra::Vector2::new(0.0, 0.0);
    let mut p = nalgebra::Matrix2::zeros();
    let q = cfg.process_noise;
    for k in 0..200 {
        let t = k as Real * DT;
        let z = 50e-9 + rate * t + sigma * standard_normal(&mut r);
        let f = nalgebra::Matrix2::new(1.0, DT, 0.0, 1.0);
        let qm = nalgebra::Matrix2::new(
            q * DT * DT * DT / 3.0,
            q * DT * DT / 2.0,
            q * DT * DT / 2.0,
            q * DT,
        );
        if k > 0 {
            x = f * x;
            p = f * p * f.transpose() + qm;
        }
        let out = tracker
            .step(t, |seeds| {
                if k == 0 {
                    assert!(seeds.is_empty());
                } else {
                    assert_eq!(seeds.len(), 1);
                    assert!((seeds[0] - x[0]).abs() < 1e-9 * x[0], "k {k}");
                }
                snap(vec![pe(z, sigma, 100.0)])
            })
            .unwrap();
        if k == 0 {
            x = nalgebra::Vector2::new(z, 0.0);
            p = nalgebra::Matrix2::new(sigma * sigma, 0.0, 0.0, cfg.rate_sigma * cfg.rate_sigma);
        } else {
            let s = p[(0, 0)] + sigma * sigma;
            let kg = nalgebra::Vector2::new(p[(0, 0)] / s, p[(1, 0)] / s);
            x += kg * (z - x[0]);
            let h = nalgebra::RowVector2::new(1.0, 0.0);
            p = (nalgebra::Matrix2::identity() - kg * h) * p;
        }
        assert_eq!(out.len(), 1);
        assert_eq!(out[0].track_id, 0, "k {k}");
        // Confirmed from the third hit on (3 of 4).
        assert_eq!(out[0].confirmed, k >= 2, "k {k}");
        assert!((out[0].filtered_delay_s - x[0]).abs() < 1e-9 * x[0]);
        let rel = (out[0].filtered_sigma_s * out[0].filtered_sigma_s - p[(0, 0)]) / p[(0, 0)];
        assert!(rel.abs() < 1e-9, "k {k}: {rel}");
    }
    assert_eq!(tracker.live_tracks(), 1);
}

/// `P_ττ` after `k` hits of a static path with `q = 0`: information form of the 2-state fit with
/// the start prior `σ_τ̇²` on the rate (state at the first snapshot, then carried to the last).
fn closed_form_var(k: usize, sigma: Real, rate_sigma: Real) -> Real {
    let (mut j00, mut j01, mut j11) = (0.0, 0.0, 1.0 / (rate_sigma * rate_sigma));
    for i in 0..k {
        let ti = i as Real * DT;
        j00 += 1.0 / (sigma * sigma);
        j01 += ti / (sigma * sigma);
        j11 += ti * ti / (sigma * sigma);
    }
    let det = j00 * j11 - j01 * j01;
    let (p00, p01, p11) = (j11 / det, -j01 / det, j00 / det);
    let l = (k - 1) as Real * DT;
    p00 + 2.0 * l * p01 + l * l * p11
}

#[test]
fn the_filtered_sigma_of_a_static_path_is_the_closed_form_fit() {
    let sigma = 1e-11;
    let cfg = PathTrackerConfig {
        process_noise: 0.0,
        ..PathTrackerConfig::default()
    };
    let mut tracker = PathTracker::new(cfg).unwrap();
    let mut r = rng(3, 1);
    for k in 1..=30usize {
        let z = 80e-9 + sigma * standard_normal(&mut r);
        let out = tracker
            .step(k as Real * DT, |_| snap(vec![pe(z, sigma, 1e3)]))
            .unwrap();
        let var = out[0].filtered_sigma_s * out[0].filtered_sigma_s;
        let exact = closed_form_var(k, sigma, cfg.rate_sigma);
        assert!(
            ((var - exact) / exact).abs() < 1e-9,
            "k {k}: {var} vs {exact}"
        );
        // With a rate prior much wider than σ/Δt the fit is the least-squares line's end value:
        // var = σ²(4k − 2)/(k(k + 1)) (the prior only shrinks it, here by < 1e-3).
        if k >= 2 {
            let kf = k as Real;
            let ls = sigma * sigma * (4.0 * kf - 2.0) / (kf * (kf + 1.0));
            assert!(var <= ls && (ls - var) / ls < 1e-3, "k {k}: {var} vs {ls}");
        }
    }
}

#[test]
fn a_one_snapshot_false_alarm_is_never_confirmed_and_ends() {
    let cfg = PathTrackerConfig::default();
    let mut tracker = PathTracker::new(cfg).unwrap();
    let mut alarm_id = None;
    for k in 0..30 {
        let mut paths = vec![pe(30e-9, 0.1e-9, 1e3)];
        if k == 5 {
            paths.push(pe(500e-9, 0.1e-9, 20.0));
        }
        let out = tracker.step(k as Real * DT, |_| snap(paths)).unwrap();
        for o in &out {
            if o.estimate.delay_s == 500e-9 {
                assert!(!o.confirmed);
                alarm_id = Some(o.track_id);
            } else {
                assert_eq!(o.track_id, 0);
            }
        }
        // The alarm's track lives through its K = 5 misses (snapshots 6–10), then ends.
        let live = if (5..10).contains(&k) { 2 } else { 1 };
        assert_eq!(tracker.live_tracks(), live, "k {k}");
    }
    assert_eq!(alarm_id, Some(1));
}

#[test]
fn a_path_missing_k_times_ends_and_returns_with_a_new_id() {
    let cfg = PathTrackerConfig::default();
    let mut tracker = PathTracker::new(cfg).unwrap();
    let mut ids = Vec::new();
    // Seen in 0–9, missing 10–13 (4 < K misses: kept), seen 14–19, missing 20–24 (K = 5:
    // ended), seen again 25–29.
    for k in 0..30 {
        let seen = !(10..14).contains(&k) && !(20..25).contains(&k);
        let paths = if seen {
            vec![pe(70e-9, 0.1e-9, 1e3)]
        } else {
            vec![]
        };
        let out = tracker.step(k as Real * DT, |_| snap(paths)).unwrap();
        if seen {
            ids.push((k, out[0].track_id, out[0].confirmed));
        } else {
            assert!(out.is_empty());
        }
    }
    for &(k, id, confirmed) in &ids {
        let expected = if k < 25 { 0 } else { 1 };
        assert_eq!(id, expected, "k {k}");
        // The new track is tentative again until its third hit.
        if k >= 25 {
            assert_eq!(confirmed, k >= 27, "k {k}");
        }
    }
}

#[test]
fn two_paths_with_different_rates_keep_their_ids() {
    for seed in 0..3 {
        let mut tracker = PathTracker::new(PathTrackerConfig::default()).unwrap();
        let mut r = rng(seed, 2);
        let sigma = 0.3e-9;
        let (r1, r2) = (0.5 / SPEED_OF_LIGHT, -0.5 / SPEED_OF_LIGHT);
        for k in 0..200 {
            let t = k as Real * DT;
            let z1 = 40e-9 + r1 * t + sigma * standard_normal(&mut r);
            let z2 = 150e-9 + r2 * t + sigma * standard_normal(&mut r);
            let out = tracker
                .step(t, |_| snap(vec![pe(z1, sigma, 100.0), pe(z2, sigma, 50.0)]))
                .unwrap();
            assert_eq!(out.len(), 2);
            assert_eq!(
                (out[0].track_id, out[1].track_id),
                (0, 1),
                "seed {seed} k {k}"
            );
        }
        assert_eq!(tracker.live_tracks(), 2);
    }
}

#[test]
fn the_cap_drops_the_weakest_tentative_track() {
    let cfg = PathTrackerConfig {
        max_tracks: 2,
        ..PathTrackerConfig::default()
    };
    let mut tracker = PathTracker::new(cfg).unwrap();
    let paths = vec![
        pe(10e-9, 0.1e-9, 100.0),
        pe(50e-9, 0.1e-9, 10.0),
        pe(90e-9, 0.1e-9, 1000.0),
    ];
    let out = tracker.step(0.0, |_| snap(paths.clone())).unwrap();
    assert_eq!(
        out.iter().map(|o| o.track_id).collect::<Vec<_>>(),
        [0, 1, 2]
    );
    assert_eq!(tracker.live_tracks(), 2);
    // Next snapshot: the 50 ns track (SNR 10) was dropped, so its estimate starts track 3.
    let out = tracker.step(DT, |seeds| {
        assert_eq!(seeds.len(), 2);
        assert!((seeds[0] - 10e-9).abs() < 1e-18 && (seeds[1] - 90e-9).abs() < 1e-18);
        snap(paths)
    });
    let ids: Vec<u32> = out.unwrap().iter().map(|o| o.track_id).collect();
    assert_eq!(ids, [0, 3, 2]);
}

#[test]
fn bad_settings_and_times_are_named_errors() {
    let bad = |f: fn(&mut PathTrackerConfig), field: &str| {
        let mut c = PathTrackerConfig::default();
        f(&mut c);
        let e = PathTracker::new(c).unwrap_err();
        assert!(alloc::format!("{e:?}").contains(field), "{e:?}");
    };
    bad(|c| c.gate = 0.0, "paths.gate");
    bad(|c| c.gate = Real::NAN, "paths.gate");
    bad(|c| c.confirm_m = 5, "paths.confirm_m");
    bad(|c| c.confirm_m = 0, "paths.confirm_m");
    bad(|c| c.confirm_n = 65, "paths.confirm_n");
    bad(|c| c.end_misses = 0, "paths.end_misses");
    bad(|c| c.process_noise = -1.0, "paths.process_noise");
    bad(|c| c.rate_sigma = 0.0, "paths.rate_sigma");
    bad(|c| c.max_tracks = 0, "paths.max_tracks");
    let mut t = PathTracker::new(PathTrackerConfig::default()).unwrap();
    t.step(1.0, |_| snap(vec![])).unwrap();
    for time in [1.0, 0.5, Real::NAN] {
        let e = t.step(time, |_| snap(vec![])).unwrap_err();
        assert!(alloc::format!("{e:?}").contains("paths.t_s"), "{e:?}");
    }
    let e = t.step(2.0, |_| snap(vec![pe(1e-8, 0.0, 1.0)])).unwrap_err();
    assert!(alloc::format!("{e:?}").contains("paths.estimate[0].sigma_s"));
    // The estimator's error is passed through and the tracker is unchanged.
    let e = t.step(2.0, |_| Err(Error::Cancelled)).unwrap_err();
    assert_eq!(e, Error::Cancelled);
    t.step(2.0, |_| snap(vec![])).unwrap();
}
