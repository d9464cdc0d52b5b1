//! The front end's Doppler (issue 42 §2, §4): the CPI's maximum-likelihood frequency estimator
//! (`channel::ml_frequency`, D9) against its bound D4 on noisy sinusoids (several seeds,
//! integrated SNR 15 and 20 dB), and the whole front end on a simulated CPI recording: each
//! walker path's range rate against the truth's D1 with the σ the front end states.

use scatterloc::channel::{
    ml_frequency, path_rate, ChannelScene, SceneCpi, Simulated, SimulationRequest, TrackedPath,
};
use scatterloc::error::Cancel;
use scatterloc::math::{Complex, Real, Vec2, PI, SPEED_OF_LIGHT};
use scatterloc::measure::{range_rate, rng, standard_normal, uniform01};
use scatterloc::scenario::{presets, Scenario};
use scatterloc::study::{estimate_recording, ChannelRequest, RecordingEstimates, Sequential};
use scatterloc::Model;

/// `ml_frequency` attains D4: N = 16 snapshots 2.048 ms apart, a random frequency in the band
/// and a random phase per trial, complex noise at per-snapshot SNR ρ; the RMSE over 2000 trials
/// per seed divided by `1/√F_ff` (`F_ff = 8π²ρΣt²`) is within 10 % of 1 (the target)
/// at integrated SNR Nρ = 15 dB and 20 dB, on 3 seeds. A trial's standard error on the ratio is
/// ≈ 1/√(2·2000) = 1.6 %.
#[test]
fn the_cpi_frequency_estimator_attains_its_bound() {
    let (n, t) = (16usize, 2.048e-3);
    let times: Vec<Real> = (0..n).map(|k| k as Real * t).collect();
    let spread: Real = {
        let m = times.iter().sum::<Real>() / n as Real;
        times.iter().map(|v| (v - m) * (v - m)).sum()
    };
    for integrated_db in [15.0, 20.0] {
        let rho = 10f64.powf(integrated_db / 10.0) / n as Real;
        let bound = 1.0 / (8.0 * PI * PI * rho * spread).sqrt();
        for seed in 1..=3 {
            let mut g = rng(seed, 0xD0);
            let trials = 2000;
            let mut sum = 0.0;
            for _ in 0..trials {
                // Away from the band's edges (a wrap is not an estimation error).
                let f = (uniform01(&mut g) - 0.5) * 0.8 / t;
                let phase = 2.0 * PI * uniform01(&mut g);
                let sigma = (0.5 / rho).sqrt();
                let alpha: Vec<Complex> = times
                    .iter()
                    .map(|tn| {
                        let a = 2.0 * PI * f * tn + phase;
                        Complex::new(
                            a.cos() + sigma * standard_normal(&mut g),
                            a.sin() + sigma * standard_normal(&mut g),
                        )
                    })
                    .collect();
                let fh = ml_frequency(&times, &alpha).unwrap().unwrap();
                sum += (fh - f) * (fh - f);
            }
            let ratio = (sum / trials as Real).sqrt() / bound;
            eprintln!("integrated {integrated_db} dB, seed {seed}: RMSE/bound {ratio:.3}");
            assert!(
                (0.9..=1.1).contains(&ratio),
                "{integrated_db} dB seed {seed}: {ratio}"
            );
        }
    }
}

/// The range rate's sign and σ: `ṙ = −λ f_D` (D2), `σ = √(λ²/F + floor²)` (D5); a single
/// snapshot or zero amplitudes give none; bad inputs are named.
#[test]
fn path_rate_sign_sigma_and_errors() {
    let lambda = SPEED_OF_LIGHT / 5.2e9;
    let t: Vec<Real> = (0..8).map(|k| k as Real * 1e-3).collect();
    let rate = 1.3;
    // τ(t) = τ₀ + ṙt/c: α ∝ e^{−j2π f_c τ(t)}.
    let alpha: Vec<Complex> = t
        .iter()
        .map(|tn| {
            let a = -2.0 * PI * rate * tn / lambda;
            Complex::new(a.cos(), a.sin())
        })
        .collect();
    let r = path_rate(&t, &alpha, 100.0, lambda, 0.1).unwrap().unwrap();
    // The periodogram is flat to second order at its peak: the search resolves the frequency
    // to ~√ε of the grid step.
    assert!(
        (r.range_rate_mps - rate).abs() < 1e-6,
        "{}",
        r.range_rate_mps
    );
    let m = t.iter().sum::<Real>() / 8.0;
    let f: Real = 8.0 * PI * PI * 100.0 * t.iter().map(|v| (v - m).powi(2)).sum::<Real>();
    let want = (lambda * lambda / f + 0.01).sqrt();
    assert!((r.sigma_mps - want).abs() <= 1e-12 * want);
    assert!(path_rate(&t[..1], &alpha[..1], 100.0, lambda, 0.1)
        .unwrap()
        .is_none());
    assert!(
        path_rate(&t, &[Complex::new(0.0, 0.0); 8], 100.0, lambda, 0.1)
            .unwrap()
            .is_none()
    );
    assert!(path_rate(&t, &alpha[..3], 100.0, lambda, 0.1).is_err());
    let mut bad = t.clone();
    bad[3] = bad[2];
    let e = path_rate(&bad, &alpha, 100.0, lambda, 0.1).unwrap_err();
    assert!(e.to_string().contains("cpi.t_s"), "{e}");
}

/// The hangar's straight walk recorded in CPIs (16 snapshots 2.048 ms apart per 0.1 s scan),
/// through the front end with `cpi_snapshots = 16`: per scan and link the estimate nearest the
/// walker's true delay (within 1.5 ns) carries a range rate, compared with the truth's D1 at
/// the scan's time, on 2 seeds.
///
/// - The default body (6 scattering centres on a 0.2 m circle, each fluctuating as an AR(1)
///   process of correlation 0.9 per 0.1 s): median error below 0.1 m/s and 90th percentile below
///   0.3 m/s. Measured: median 0.04 m/s, 90th percentile 0.20 m/s; the tail (errors of 0.2–0.4 m/s
///   at 20–35 dB, once 3.7 m/s at 15 dB) is the centres' fluctuation: their sum fades and turns
///   within a CPI, a Doppler spread the floor of 0.1 m/s does not cover (normalised RMS 3.4).
/// - A quasi-static body (correlation 0.9999): the stated σ holds (normalised RMS within
///   [0.2, 1.5]; measured 0.33, the floor dominating).
#[test]
fn the_front_end_reads_the_walkers_range_rates() {
    for quasi_static in [false, true] {
        front_end_rates(quasi_static);
    }
}

/// The hangar's straight walk from (2, 4) m to (14, 7) m over `duration_s`, recorded in CPIs
/// (16 snapshots 2.048 ms apart per 0.1 s scan) with the body `body` makes of the default one,
/// simulated with `seed`, and its estimates through the front end with `cpi_snapshots = 16`.
fn cpi_walk(
    s: &Scenario,
    model: &Model,
    duration_s: Real,
    body: impl Fn(&mut ChannelScene),
    seed: u64,
) -> (Simulated, RecordingEstimates) {
    let mut scene = ChannelScene::hangar();
    scene.walk.waypoints_m = vec![[2.0, 4.0], [14.0, 7.0]];
    scene.dt_s = 0.1;
    scene.duration_s = Some(duration_s);
    body(&mut scene);
    scene.cpi = Some(SceneCpi {
        snapshots: 16,
        spacing_s: 2.048e-3,
    });
    let sim = SimulationRequest {
        scene: Some(scene),
        seed,
        ..SimulationRequest::default()
    }
    .run(s, model, Cancel::NEVER)
    .unwrap();
    let req = ChannelRequest {
        cpi_snapshots: Some(16),
        ..ChannelRequest::default()
    };
    let (_, est) = estimate_recording(
        model,
        s.radio.bandwidth_hz,
        &sim.recording,
        Some(&sim.calibration),
        &req.front_end(sim.recording.synchronized),
        &mut Sequential::new(),
        &|_| {},
    )
    .unwrap();
    (sim, est)
}

/// The estimate of scan `k`, link `p` nearest the walker's true delay `tau`: of those within
/// 1.5 ns of it, the strongest.
fn walker_estimate(
    est: &RecordingEstimates,
    k: usize,
    p: usize,
    tau: Real,
) -> Option<&TrackedPath> {
    est.paths[k][p]
        .iter()
        .filter(|t| (t.estimate.delay_s - tau).abs() < 1.5e-9)
        .max_by(|a, b| a.estimate.snr.total_cmp(&b.estimate.snr))
}

fn front_end_rates(quasi_static: bool) {
    let s = presets::preset("sensors2019").unwrap();
    let model = Model::new(&s).unwrap();
    let body = |scene: &mut ChannelScene| {
        if quasi_static {
            scene.body.correlation = 0.9999;
        }
    };
    for seed in 1..=2 {
        let (sim, est) = cpi_walk(&s, &model, 3.0, body, seed);
        assert_eq!(est.len(), sim.recording.t_s.len() / 16);
        let (mut z2, mut abs, mut found) = (0.0, Vec::new(), 0);
        for (k, tk) in est.t_s.iter().enumerate() {
            let s_mid = k * 16 + 8;
            assert_eq!(*tk, sim.truth.t_s[s_mid]);
            let x = sim.truth.states[s_mid];
            let (r, v) = (Vec2::new(x[0], x[1]), Vec2::new(x[2], x[3]));
            for p in 0..model.link_count() {
                let tau = model.network.delay(p, r);
                let Some(best) = walker_estimate(&est, k, p, tau) else {
                    continue;
                };
                let Some(rate) = best.estimate.range_rate else {
                    continue;
                };
                found += 1;
                let truth = range_rate(&model.network, p, r, v);
                let e = rate.range_rate_mps - truth;
                z2 += (e / rate.sigma_mps).powi(2);
                abs.push(e.abs());
                if e.abs() > 0.2 {
                    eprintln!(
                        "k {k} link {p}: truth {truth:.3} est {:.3} σ {:.3} snr {:.1} dB",
                        rate.range_rate_mps,
                        rate.sigma_mps,
                        10.0 * best.estimate.snr.log10()
                    );
                }
            }
        }
        abs.sort_by(|a, b| a.total_cmp(b));
        let rms = (z2 / found as Real).sqrt();
        let median = abs[abs.len() / 2];
        eprintln!(
            "quasi-static {quasi_static}, seed {seed}: {found} walker rates of {} link-scans, normalised RMS {rms:.2}, \
             median |error| {median:.3} m/s, 90th percentile {:.3} m/s",
            est.len() * model.link_count(),
            abs[abs.len() * 9 / 10]
        );
        assert!(found >= est.len() * model.link_count() / 2, "{found}");
        if quasi_static {
            assert!((0.2..=1.5).contains(&rms), "seed {seed}: RMS {rms}");
        } else {
            assert!(median < 0.1, "seed {seed}: median {median}");
            assert!(abs[abs.len() * 9 / 10] < 0.3, "seed {seed}");
        }
    }
}

/// The simulator's micro-Doppler option (issue 42 §2): with the limbs swinging (every second
/// centre ±0.3 m along the heading at 1 Hz, up to 1.9 m/s beside the body's velocity) the
/// walker's measured range rate spreads about the body's: on the same seeds and a quasi-static
/// body, the median error against D1 at least doubles (measured in the output), while the scene
/// without limbs is the one of the other tests (the option off by default, not written).
#[test]
fn limbs_spread_the_walkers_doppler() {
    let s = presets::preset("sensors2019").unwrap();
    let model = Model::new(&s).unwrap();
    let median_error = |swing: Real, seed: u64| -> Real {
        let body = |scene: &mut ChannelScene| {
            scene.body.correlation = 0.9999;
            scene.body.limb_swing_m = swing;
        };
        let (sim, est) = cpi_walk(&s, &model, 2.0, body, seed);
        let mut errs = Vec::new();
        for k in 0..est.len() {
            let x = sim.truth.states[k * 16 + 8];
            let (r, v) = (Vec2::new(x[0], x[1]), Vec2::new(x[2], x[3]));
            for p in 0..model.link_count() {
                let tau = model.network.delay(p, r);
                let rate = walker_estimate(&est, k, p, tau).and_then(|t| t.estimate.range_rate);
                if let Some(rate) = rate {
                    errs.push((rate.range_rate_mps - range_rate(&model.network, p, r, v)).abs());
                }
            }
        }
        errs.sort_by(|a, b| a.total_cmp(b));
        errs[errs.len() / 2]
    };
    for seed in 1..=2 {
        let (still, swinging) = (median_error(0.0, seed), median_error(0.3, seed));
        eprintln!("seed {seed}: median |ṙ error| {still:.3} m/s without limbs, {swinging:.3} with");
        assert!(swinging > 2.0 * still, "seed {seed}: {swinging} vs {still}");
    }
    let json = serde_json::to_value(ChannelScene::hangar()).unwrap();
    assert!(json["body"].get("limb_swing_m").is_none() && json["body"].get("gait_hz").is_none());
}
