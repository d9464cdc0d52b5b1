#![cfg(not(target_arch = "wasm32"))]
#![allow(missing_docs)] // criterion_group! generates an undocumented pub fn
//! Tracking benchmarks (criterion): one EKF step (predict + update) with the 4 links of preset
//! `sensors2019` on scenario I (R from the link budget at the predicted position, spec §6), timed
//! over 256 consecutive steps of a track so the time per element is the time per step, its
//! parts, and the Monte Carlo harness: one `run_chunk` of the fast profile (T = 0.1 s) and of
//! the paper step (T = 2.048 ms), reported as EKF steps per second (criterion's throughput) and,
//! in an untimed summary on stderr, as ns per EKF step including truth sampling, measurement
//! simulation and NEES.
//!
//! The same step with delay + Doppler (issue 42 §4): the same warm filter and delays plus one
//! noisy range rate per link and step (D1; σ of a CPI of 16 snapshots 2.048 ms apart with a
//! 0.1 m/s floor, D5, at the truth), the rates' σ fixed (`RateNoise::Fixed`) or from the CPI at
//! the prediction (`RateNoise::Cpi`).
//!
//! Run: `cargo bench --bench tracking` (shorter: `-- --warm-up-time 1 --measurement-time 3`).

use std::hint::black_box;
use std::time::Instant;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};

use scatterloc::math::{Real, Vec2, Vec4};
use scatterloc::track::ConstantVelocity;
use scatterloc::track::{
    paper_initial_covariance, step_count, TrackScenario, TruthSampler, PAPER_INTENSITY,
    PAPER_STEP_S,
};
use scatterloc::track::{
    run_chunk, run_filter_chunk, run_truth_chunk, FilterKind, MonteCarloConfig, CHUNK_TRAJECTORIES,
};
use scatterloc::track::{Ekf, Filter, MeasurementNoise, ParticleFilter, PfConfig, Ukf, UkfParams};
use scatterloc::track::{RangeRates, RateNoise};
use scatterloc::{measure, scenario::presets, Model};

const SEED: u64 = 2019;
/// Steps run before the benchmarked ones, so `P` has its steady-state size (0.5 s at 2.048 ms).
const WARM_STEPS: usize = 244;
/// Consecutive steps per benchmark iteration (0.52 s of scenario I at 2.048 ms).
const BENCH_STEPS: usize = 256;

/// A filter after `WARM_STEPS` steps on a scenario-I truth, and the measurements (noisy delays
/// at the truth, σ from E8) of the next `BENCH_STEPS` steps with their truth.
struct StepSetup {
    model: Model,
    motion: ConstantVelocity,
    ekf: Ekf,
    z: Vec<Vec<Option<Real>>>,
    sigmas: Vec<Vec<Real>>,
    truth: Vec<Vec4>,
    /// Noisy range rates per step and link (D1), m/s.
    rates: Vec<Vec<Option<Real>>>,
    /// Their σ at the truth (the CPI's, D5), m/s.
    rate_sigmas: Vec<Vec<Real>>,
    /// The CPI of the rates.
    cpi: measure::Cpi,
}

fn step_setup() -> StepSetup {
    let model = Model::new(&presets::sensors2019()).unwrap();
    let motion = ConstantVelocity::new(PAPER_STEP_S, PAPER_INTENSITY);
    let s = TrackScenario::I;
    let sampler = TruthSampler::new(motion, s.mean_state(), &paper_initial_covariance()).unwrap();
    let mut truth = Vec::new();
    sampler.sample(
        WARM_STEPS + BENCH_STEPS,
        &mut measure::rng(SEED, 0),
        &mut truth,
    );
    let mut noise = measure::rng(SEED, 1);
    let z: Vec<Vec<Option<Real>>> = truth
        .iter()
        .map(|x| {
            measure::noisy_delays(&model, Vec2::new(x[0], x[1]), &mut noise)
                .into_iter()
                .map(Some)
                .collect()
        })
        .collect();
    let mut ekf = Ekf::new(s.mean_state(), paper_initial_covariance()).unwrap();
    for z in &z[1..=WARM_STEPS] {
        ekf.step(&motion, &model, z, MeasurementNoise::AtPrediction)
            .unwrap();
    }
    let bench = WARM_STEPS + 1..;
    let cpi = measure::Cpi::new(
        presets::sensors2019().radio.carrier_hz,
        16,
        2.048e-3,
        measure::DEFAULT_RANGE_RATE_FLOOR_MPS,
    )
    .unwrap();
    let mut rate_noise = measure::rng(SEED, 2);
    let rate_sigmas: Vec<Vec<Real>> = truth[bench.clone()]
        .iter()
        .map(|x| {
            (0..model.link_count())
                .map(|p| cpi.sigma_range_rate(model.snr(p, Vec2::new(x[0], x[1]))))
                .collect()
        })
        .collect();
    let rates = truth[bench.clone()]
        .iter()
        .zip(&rate_sigmas)
        .map(|(x, sr)| {
            let (r, v) = (Vec2::new(x[0], x[1]), Vec2::new(x[2], x[3]));
            (0..model.link_count())
                .map(|p| {
                    let rate = measure::range_rate(&model.network, p, r, v);
                    Some(rate + sr[p] * measure::standard_normal(&mut rate_noise))
                })
                .collect()
        })
        .collect();
    StepSetup {
        rates,
        rate_sigmas,
        cpi,
        sigmas: truth[bench.clone()]
            .iter()
            .map(|x| model.sigma_delays(Vec2::new(x[0], x[1])))
            .collect(),
        z: z[bench.clone()].to_vec(),
        truth: truth[bench].to_vec(),
        model,
        motion,
        ekf,
    }
}

impl StepSetup {
    /// `BENCH_STEPS` consecutive predict + update steps from the warm filter.
    fn track(&self, fixed: bool) -> Ekf {
        let mut f = self.ekf;
        for (z, s) in self.z.iter().zip(&self.sigmas) {
            f.predict(&self.motion);
            let noise = if fixed {
                MeasurementNoise::Fixed(s)
            } else {
                MeasurementNoise::AtPrediction
            };
            f.update(&self.model, black_box(z), noise, None).unwrap();
        }
        f
    }

    /// `BENCH_STEPS` consecutive predict + update steps with delays and range rates, R of the
    /// delays from the link budget at the prediction, the rates' σ fixed or from the CPI.
    fn track_doppler(&self, fixed_rates: bool) -> Ekf {
        let mut f = self.ekf;
        for ((z, rates), sr) in self.z.iter().zip(&self.rates).zip(&self.rate_sigmas) {
            f.predict(&self.motion);
            let noise = if fixed_rates {
                RateNoise::Fixed(sr)
            } else {
                RateNoise::Cpi(self.cpi)
            };
            let rates = RangeRates {
                rates_mps: black_box(rates),
                noise,
            };
            f.update_doppler(
                &self.model,
                black_box(z),
                MeasurementNoise::AtPrediction,
                &rates,
            )
            .unwrap();
        }
        f
    }
}

/// The Monte Carlo study of scenario I at step `dt_s` over `duration_s` with `noise_runs`.
fn study(dt_s: Real, duration_s: Real, noise_runs: usize) -> MonteCarloConfig {
    let motion = ConstantVelocity::new(dt_s, PAPER_INTENSITY);
    MonteCarloConfig {
        motion,
        steps: step_count(duration_s, dt_s),
        mean_state: TrackScenario::I.mean_state(),
        initial_covariance: paper_initial_covariance(),
        trajectories: CHUNK_TRAJECTORIES,
        noise_runs,
        seed: SEED,
        oracle_noise: false,
    }
}

/// EKF steps in one chunk of `cfg`.
fn chunk_steps(cfg: &MonteCarloConfig) -> u64 {
    (cfg.trajectories.min(CHUNK_TRAJECTORIES) * cfg.noise_runs * cfg.steps) as u64
}

/// Untimed by criterion: the best of `reps` wall-clock runs of one chunk, ns per EKF step.
fn ns_per_step(model: &Model, cfg: &MonteCarloConfig, reps: usize) -> f64 {
    (0..reps)
        .map(|_| {
            let t = Instant::now();
            black_box(run_chunk(model, cfg, 0).unwrap());
            t.elapsed().as_nanos() as f64 / chunk_steps(cfg) as f64
        })
        .fold(f64::INFINITY, f64::min)
}

fn benches(c: &mut Criterion) {
    let s = step_setup();
    // Untimed sanity check: every benchmarked step uses all 4 links, and the filter stays near
    // the truth (within 5 mm over the 0.5 s; the bound there is ≈ 0.2 cm).
    let mut f = s.ekf;
    let mut worst: Real = 0.0;
    for (z, x) in s.z.iter().zip(&s.truth) {
        let u = f
            .step(&s.motion, &s.model, z, MeasurementNoise::AtPrediction)
            .unwrap();
        assert_eq!(u.links_used, 4);
        worst = worst.max((f.position() - Vec2::new(x[0], x[1])).norm());
    }
    assert!(worst < 5e-3, "filter {worst} m off the truth");
    // The same with range rates: all 4 links, near the truth.
    for fixed in [true, false] {
        let f = s.track_doppler(fixed);
        let x = s.truth.last().unwrap();
        let err = (f.position() - Vec2::new(x[0], x[1])).norm();
        assert!(err < 5e-3, "doppler filter {err} m off the truth");
    }
    eprintln!(
        "setup: scenario I, {BENCH_STEPS} steps of {PAPER_STEP_S} s after {WARM_STEPS}, largest position error {:.3} mm",
        worst * 1e3
    );

    // Per element = one step: consecutive dependent steps, as in a track.
    let mut g = c.benchmark_group("ekf_step_4_links");
    g.throughput(Throughput::Elements(BENCH_STEPS as u64));
    g.bench_function("predict+update_R_at_prediction", |b| {
        b.iter(|| s.track(false))
    });
    g.bench_function("predict+update_R_fixed", |b| b.iter(|| s.track(true)));
    // Issue 42 §4: delay + Doppler on the 4 links (≤ 250 ns asked).
    g.bench_function("predict+update_doppler_rates_sigma_fixed", |b| {
        b.iter(|| s.track_doppler(true))
    });
    g.bench_function("predict+update_doppler_rates_sigma_cpi", |b| {
        b.iter(|| s.track_doppler(false))
    });
    g.bench_function("predict_only", |b| {
        b.iter(|| {
            let mut f = s.ekf;
            for _ in 0..BENCH_STEPS {
                f.predict(black_box(&s.motion));
            }
            f
        })
    });
    let filters: Vec<Ekf> = {
        let mut f = s.ekf;
        s.z.iter()
            .map(|z| {
                f.step(&s.motion, &s.model, z, MeasurementNoise::AtPrediction)
                    .unwrap();
                f
            })
            .collect()
    };
    g.bench_function("nees", |b| {
        b.iter(|| {
            filters
                .iter()
                .zip(&s.truth)
                .map(|(f, x)| black_box(f).nees(x).unwrap())
                .sum::<Real>()
        })
    });
    g.finish();

    // The UKF and the particle filter (issue 15) on the same steps, from the warm EKF's state
    // and covariance: consecutive dependent steps, R from the link budget at the prediction.
    let mut g = c.benchmark_group("ukf_step_4_links");
    g.throughput(Throughput::Elements(BENCH_STEPS as u64));
    let ukf = Ukf::new(s.ekf.state, s.ekf.covariance, UkfParams::default()).unwrap();
    g.bench_function("predict+update_R_at_prediction", |b| {
        b.iter(|| {
            let mut f = ukf;
            for z in &s.z {
                f.step(
                    &s.motion,
                    &s.model,
                    black_box(z),
                    MeasurementNoise::AtPrediction,
                )
                .unwrap();
            }
            f
        })
    });
    g.finish();
    let mut g = c.benchmark_group("pf_step_4_links");
    g.throughput(Throughput::Elements(BENCH_STEPS as u64));
    g.sample_size(20);
    for n in [1000, 10_000] {
        let pf = ParticleFilter::new(
            s.ekf.state,
            s.ekf.covariance,
            PfConfig {
                particles: n,
                roughening: None,
                regularized: true,
            },
            measure::rng(SEED, 7),
        )
        .unwrap();
        g.bench_function(format!("{n}_particles"), |b| {
            b.iter(|| {
                let mut f = pf.clone();
                for z in &s.z {
                    f.step(
                        &s.motion,
                        &s.model,
                        black_box(z),
                        MeasurementNoise::AtPrediction,
                    )
                    .unwrap();
                }
                f.state
            })
        });
    }
    g.finish();

    gated_step(c);

    let fast = study(0.1, 10.0, 10);
    let paper = study(PAPER_STEP_S, 1.0, 50);
    let mut g = c.benchmark_group("montecarlo_chunk");
    g.sample_size(10);
    g.throughput(Throughput::Elements(chunk_steps(&fast)));
    g.bench_function("run_chunk_fast_0.1s_16x10x100", |b| {
        b.iter(|| run_chunk(&s.model, black_box(&fast), 0).unwrap())
    });
    g.throughput(Throughput::Elements(chunk_steps(&paper)));
    g.bench_function("run_chunk_paper_2.048ms_16x50x488", |b| {
        b.iter(|| run_chunk(&s.model, black_box(&paper), 0).unwrap())
    });
    g.throughput(Throughput::Elements(
        (CHUNK_TRAJECTORIES * fast.steps) as u64,
    ));
    g.bench_function("run_truth_chunk_fast_16x100", |b| {
        b.iter(|| run_truth_chunk(&s.model, black_box(&fast), 0).unwrap())
    });
    // The other filters on the same chunk (issue 15): the UKF on the fast profile, the PF with
    // 1000 particles on one noise run per trajectory.
    g.throughput(Throughput::Elements(chunk_steps(&fast)));
    let ukf = FilterKind::Ukf(UkfParams::default());
    g.bench_function("run_filter_chunk_ukf_fast_0.1s_16x10x100", |b| {
        b.iter(|| run_filter_chunk(&s.model, black_box(&fast), ukf, 0).unwrap())
    });
    let fast_one = MonteCarloConfig {
        noise_runs: 1,
        ..fast
    };
    g.throughput(Throughput::Elements(chunk_steps(&fast_one)));
    let pf = FilterKind::Pf(PfConfig {
        particles: 1000,
        roughening: None,
        regularized: true,
    });
    g.bench_function("run_filter_chunk_pf1000_fast_0.1s_16x1x100", |b| {
        b.iter(|| run_filter_chunk(&s.model, black_box(&fast_one), pf, 0).unwrap())
    });
    g.finish();

    eprintln!(
        "Monte Carlo throughput (best of 5, one thread, incl. truth, measurements, NEES):\n  fast profile 0.1 s, 16x10 runs x 100 steps: {:.1} ns per EKF step\n  paper step 2.048 ms, 16x50 runs x 488 steps: {:.1} ns per EKF step",
        ns_per_step(&s.model, &fast, 5),
        ns_per_step(&s.model, &paper, 5)
    );
}

/// One step of the spec §9.6 stand-in (`GatedTracker::step`: predict, the predicted delays and
/// innovation σ, 3σ gating against 2 static clusters per link, association, update) over the
/// first 256 snapshots of the 60 s loop at T = 0.1 s with 0.5 false alarms per link and
/// snapshot (about 3.5 estimates per link); and the gating + association alone.
fn gated_step(c: &mut Criterion) {
    use scatterloc::track::gating::GatedTracker;
    use scatterloc::track::gating::{default_channel, LoopPath};
    use scatterloc::track::gating::{select, AssociationRule};
    use scatterloc::track::gating::{Calibration, ClusterConfig};
    let model = Model::new(&presets::sensors2019()).unwrap();
    let b = presets::sensors2019().radio.bandwidth_hz;
    let mut rng = measure::rng(SEED, 7);
    let cfg = ClusterConfig::for_bandwidth(b).unwrap();
    let clean = default_channel(b, 0.0);
    let cal = Calibration::from_snapshots(
        &clean.calibration_snapshots(&model, 500, &mut rng),
        model.link_count(),
        &cfg,
    )
    .unwrap();
    let ch = default_channel(b, 0.5);
    let path = LoopPath::default();
    let snaps: Vec<_> = path
        .states(0.1, BENCH_STEPS)
        .iter()
        .map(|x| ch.snapshot(&model, Some(Vec2::new(x[0], x[1])), &mut rng))
        .collect();
    let motion = ConstantVelocity::new(0.1, 0.1);
    let ekf = Ekf::new(path.state_at(0.0), paper_initial_covariance()).unwrap();
    let noise = MeasurementNoise::AtPrediction;
    let rule = AssociationRule::Gated;
    let mut g = c.benchmark_group("gated_step_4_links");
    g.throughput(Throughput::Elements(BENCH_STEPS as u64));
    g.bench_function("predict+gate+associate+update", |bch| {
        bch.iter(|| {
            let mut t = GatedTracker::new(ekf, &model, &cal, motion, noise, rule).unwrap();
            for s in &snaps {
                black_box(t.step(black_box(s)).unwrap());
            }
            t.filter
        })
    });
    let preds = ekf.predicted_delays(&model, noise).unwrap();
    g.bench_function("gate+associate", |bch| {
        bch.iter(|| {
            for s in &snaps {
                black_box(select(&cal, black_box(s), Some(&preds), rule).unwrap());
            }
        })
    });
    g.finish();
}

criterion_group!(tracking, benches);
criterion_main!(tracking);
