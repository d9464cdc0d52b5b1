#![cfg(not(target_arch = "wasm32"))]
#![allow(missing_docs)] // criterion_group! generates an undocumented pub fn
//! Channel front-end benchmarks (criterion, issue 25 §6): one snapshot of one link through the
//! C5 estimator (`Estimator::estimate`, noise estimated from the data, default config: 4×
//! oversampling, P_fa = 10⁻³), flat band over 120 MHz. Rows: N = 241 with 1, 4 and 8 paths
//! (target ≤ 25 µs at 8 paths); the cost versus N (61 … 961 bins, 4 paths) and versus the path
//! count (N = 241, 1 … 12 paths). Paths 30 dB apart from the noise, 2/B apart.
//!
//!
//! Issue 36 §7, on a recording no one here wrote (the ray-traced `open` fixture of
//! `tests/data/raytraced/`, 201 snapshots × 4 links × 241 bins, its thermal noise added with
//! seed 1 as `tests/corpus.rs` does): `raytraced_open/estimate` the whole front end
//! (`estimate_recording`: background from the empty area, C5 per link-snapshot; divide by 804
//! link-snapshots), `raytraced_open/track` the tracker on those estimates (`cir_track`, C11
//! segments), `raytraced_open/delay_image` one link's delay figure (`present::delay_image`,
//! chirp-z; × 4 for the page's figure).
//!
//! Run: `cargo bench --bench channel` (shorter: `-- --warm-up-time 1 --measurement-time 3`).

use std::hint::black_box;
use std::time::Instant;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use rand::SeedableRng as _;
use rand_distr::{Distribution, StandardNormal};
use rand_pcg::Pcg64;

use scatterloc::channel::{Band, Estimator, EstimatorConfig, Layout, Recording};
use scatterloc::error::Cancel;
use scatterloc::math::{cos, sin, sqrt, Complex, Real, PI};
use scatterloc::present::{delay_image, ImageConfig};
use scatterloc::study::{cir_track, estimate_recording, ChannelRequest, EstimationRun, Sequential};
use scatterloc::{npz, Model, Scenario};

const B: Real = 120e6;

fn snapshot(n: usize, k: usize, seed: u64) -> (Band, Vec<Complex>) {
    let band = Band::flat(n, B / (n as Real - 1.0)).unwrap();
    let mut rng = Pcg64::seed_from_u64(seed);
    let var = n as Real / 1000.0; // each path at 30 dB integrated SNR
    let h = band
        .freq_hz
        .iter()
        .map(|&f| {
            let mut h = Complex::new(0.0, 0.0);
            for i in 0..k {
                let tau = 40e-9 + i as Real * 2.0 / B;
                let ph = -2.0 * PI * f * tau + i as Real;
                h += Complex::new(cos(ph), sin(ph));
            }
            let a: Real = StandardNormal.sample(&mut rng);
            let b: Real = StandardNormal.sample(&mut rng);
            h + Complex::new(a, b) * sqrt(var / 2.0)
        })
        .collect();
    (band, h)
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("estimate_n241");
    for k in [1usize, 4, 8] {
        let (band, h) = snapshot(241, k, 7);
        let mut est = Estimator::new(band, EstimatorConfig::default()).unwrap();
        // 8 paths 2/B apart: the coupled group's residual can add one more (measured: 9).
        let found = est.estimate(&h, None, &[]).unwrap().paths.len();
        assert!((k..=k + 1).contains(&found), "{k} paths: {found} found");
        g.bench_with_input(BenchmarkId::new("paths", k), &k, |bch, _| {
            bch.iter(|| black_box(est.estimate(black_box(&h), None, &[]).unwrap()))
        });
    }
    g.finish();
    let mut g = c.benchmark_group("estimate_vs_n_4paths");
    for n in [61usize, 121, 241, 481, 961] {
        let (band, h) = snapshot(n, 4, 8);
        let mut est = Estimator::new(band, EstimatorConfig::default()).unwrap();
        g.bench_with_input(BenchmarkId::new("bins", n), &n, |bch, _| {
            bch.iter(|| black_box(est.estimate(black_box(&h), None, &[]).unwrap()))
        });
    }
    g.finish();
    let mut g = c.benchmark_group("estimate_vs_k_n241");
    for k in [2usize, 6, 12] {
        let (band, h) = snapshot(241, k, 9);
        let mut est = Estimator::new(band, EstimatorConfig::default()).unwrap();
        g.bench_with_input(BenchmarkId::new("paths", k), &k, |bch, _| {
            bch.iter(|| black_box(est.estimate(black_box(&h), None, &[]).unwrap()))
        });
    }
    g.finish();
}

/// `rec` with CN(0, σ_p²) per sample (`noise_var_w[p]`, seeded) and `noise_var` set.
fn noisy(rec: &Recording, noise_var_w: &[Real], seed: u64) -> Recording {
    let mut out = rec.clone();
    let mut rng = Pcg64::seed_from_u64(seed);
    let per = rec.samples_per_link();
    for (i, x) in out.samples.iter_mut().enumerate() {
        let s = sqrt(noise_var_w[(i / per) % rec.link_count()] / 2.0);
        let a: Real = StandardNormal.sample(&mut rng);
        let b: Real = StandardNormal.sample(&mut rng);
        *x += Complex::new(a * s, b * s);
    }
    out.noise_var = Some(noise_var_w.to_vec());
    out
}

fn raytraced(c: &mut Criterion) {
    raytraced_fixture(c, "open");
    raytraced_fixture(c, "room");
}

/// The front end, the tracker and the delay figure on one ray-traced fixture.
fn raytraced_fixture(c: &mut Criterion, name: &str) {
    let dir = format!("{}/tests/data/raytraced/{name}", env!("CARGO_MANIFEST_DIR"));
    let read = |f: &str| std::fs::read(format!("{dir}/{f}")).expect("fixture");
    let scenario = Scenario::from_json(&String::from_utf8(read("scenario.json")).unwrap()).unwrap();
    let model = Model::new(&scenario).unwrap();
    let truth: serde_json::Value = serde_json::from_slice(&read("truth.json")).unwrap();
    let nv: Vec<Real> = serde_json::from_value(truth["noise_var_w"].clone()).unwrap();
    let walk = noisy(&npz::read_recording(&read("walk.npz")).unwrap(), &nv, 1);
    let empty = noisy(&npz::read_recording(&read("empty.npz")).unwrap(), &nv, 101);
    let req = ChannelRequest::default();
    let cfg = req.front_end(walk.synchronized);
    let bw = scenario.radio.bandwidth_hz;
    let estimate = || {
        estimate_recording(
            &model,
            bw,
            &walk,
            Some(&empty),
            &cfg,
            &mut Sequential::new(),
            &|_| {},
        )
        .unwrap()
    };
    let (statics, est) = estimate();
    // Per link-snapshot (the median): every unit of the sliced run timed alone, the
    // first of each link (its statics: the background fit) apart. Best of 5 per unit.
    let mut per = vec![Real::INFINITY; walk.t_s.len() * walk.link_count()];
    for _ in 0..5 {
        let mut run = EstimationRun::new(&model, bw, &walk, Some(&empty), &cfg).unwrap();
        for t in per.iter_mut().take(run.total()) {
            let t0 = Instant::now();
            run.run(&walk, Some(&empty), 1).unwrap();
            *t = t.min(t0.elapsed().as_secs_f64() * 1e6);
        }
    }
    let s = walk.t_s.len();
    let mut steps: Vec<Real> = per
        .iter()
        .enumerate()
        .filter(|(i, _)| i % s != 0)
        .map(|(_, t)| *t)
        .collect();
    steps.sort_by(Real::total_cmp);
    let q = |p: Real| steps[((steps.len() - 1) as Real * p).round() as usize];
    println!(
        "raytraced_{name} per link-snapshot (best of 5, {} units): median {:.1} µs, 90 % {:.1} µs, \
         max {:.1} µs, mean {:.1} µs",
        steps.len(),
        q(0.5),
        q(0.9),
        steps[steps.len() - 1],
        steps.iter().sum::<Real>() / steps.len() as Real
    );
    let works: Vec<_> = est.work.iter().flatten().collect();
    let paths: usize = est.paths.iter().flatten().map(Vec::len).sum();
    println!(
        "raytraced_{name}: {} link-snapshots, {:.2} periodogram passes and {:.2} paths each on \
         average",
        works.len(),
        works.iter().map(|w| w.passes).sum::<usize>() as Real / works.len() as Real,
        paths as Real / works.len() as Real
    );
    let mut g = c.benchmark_group(format!("raytraced_{name}"));
    g.sample_size(10);
    g.bench_function("estimate", |b| b.iter(|| black_box(estimate())));
    g.bench_function("track", |b| {
        b.iter(|| {
            black_box(
                cir_track(
                    &req,
                    &model,
                    &scenario.area_m,
                    &statics.calibration,
                    &est,
                    Cancel::NEVER,
                )
                .unwrap(),
            )
        })
    });
    let image = ImageConfig::new([0.0, 60.0]);
    let Layout::Cfr { freq_hz, .. } = &walk.layout else {
        panic!("the fixture is a cfr recording")
    };
    g.bench_function("delay_image", |b| {
        b.iter(|| {
            black_box(delay_image(freq_hz, &walk.t_s, |s| walk.response(s, 0), &image).unwrap())
        })
    });
    g.finish();
}

criterion_group!(benches, bench, raytraced);
criterion_main!(benches);
