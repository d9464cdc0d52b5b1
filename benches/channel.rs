#![cfg(not(target_arch = "wasm32"))]
#![allow(missing_docs)] // criterion_group! generates an undocumented pub fn
//! Channel front-end benchmarks (criterion, issue 25 §6): one snapshot of one link through the
//! C5 estimator (`Estimator::estimate`, noise estimated from the data, default config: 4×
//! oversampling, P_fa = 10⁻³), flat band over 120 MHz. Rows: N = 241 with 1, 4 and 8 paths
//! (target ≤ 25 µs at 8 paths); the cost versus N (61 … 961 bins, 4 paths) and versus the path
//! count (N = 241, 1 … 12 paths). Paths 30 dB apart from the noise, 2/B apart.
//!
//! Run: `cargo bench --bench channel` (shorter: `-- --warm-up-time 1 --measurement-time 3`).

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use rand::SeedableRng as _;
use rand_distr::{Distribution, StandardNormal};
use rand_pcg::Pcg64;

use scatterloc::channel::{Band, Estimator, EstimatorConfig};
use scatterloc::math::{cos, sin, sqrt, Complex, Real, PI};

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
        assert_eq!(est.estimate(&h, None, &[]).unwrap().paths.len(), k);
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

criterion_group!(benches, bench);
criterion_main!(benches);
