#![cfg(not(target_arch = "wasm32"))]
#![allow(missing_docs)] // criterion_group! generates an undocumented pub fn
//! Core benchmarks (criterion): the LM snapshot fix (ours vs the `levenberg-marquardt` crate on the
//! same weighted problem), LM with the default grid-search start, the CRLB map kernel (scalar
//! reference, SIMD on one thread, SIMD on all cores; 256² and 512² at 4 links, 256² at 16 links)
//! and a single CRLB point. Scenario: preset `sensors2019` (layout L4, 4 links), truth (4, 1) m.
//!
//! Run: `cargo bench --bench core` (shorter: `-- --warm-up-time 1 --measurement-time 3`).

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};
use levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt};
use nalgebra::storage::Owned;
use nalgebra::{DVector, Dyn, OMatrix, Vector2, U2};

use scatterloc::localize::{self, DelayMeasurements, LmConfig};
use scatterloc::localize::{crlb_at, crlb_map, crlb_map_scalar, Grid};
use scatterloc::math::{Real, Vec2, SPEED_OF_LIGHT};
use scatterloc::measure::unit_from;
use scatterloc::native::{crlb_map_on, crlb_map_parallel, map_paths};
use scatterloc::scenario::Scenario;
use scatterloc::{measure, scenario::presets, Model};

const TRUTH: [Real; 2] = [4.0, 1.0];
const START_OFFSET: [Real; 2] = [2.0, 2.0];
const SEED: u64 = 2019;

/// The shared problem: L4 model, noisy delays at the truth (fixed seed), σ_p from (E8) at the truth.
struct Setup {
    scenario: Scenario,
    model: Model,
    delays: Vec<Option<Real>>,
    sigmas: Vec<Real>,
    start: Vec2,
}

fn setup() -> Setup {
    let scenario = presets::sensors2019();
    let model = Model::new(&scenario).unwrap();
    let truth = Vec2::new(TRUTH[0], TRUTH[1]);
    let delays = measure::noisy_delays(&model, truth, &mut measure::rng(SEED, 0))
        .into_iter()
        .map(Some)
        .collect();
    let sigmas = model.sigma_delays(truth);
    Setup {
        scenario,
        model,
        delays,
        sigmas,
        start: truth + Vec2::new(START_OFFSET[0], START_OFFSET[1]),
    }
}

impl Setup {
    fn ours(&self, initial: Option<Vec2>) -> localize::LmReport {
        let m = DelayMeasurements {
            delays_s: &self.delays,
            sigmas_s: &self.sigmas,
        };
        localize::locate(
            &self.model.network,
            &m,
            &LmConfig::default(),
            initial,
            &self.scenario.area_m,
        )
        .unwrap()
    }

    /// Rows of the range-domain problem: foci, measured range cτ̂ and 1/(cσ).
    fn rows(&self) -> Vec<Row> {
        (0..self.model.link_count())
            .map(|p| {
                let (tx, rx) = self.model.network.link_nodes(p);
                Row {
                    tx,
                    rx,
                    range: SPEED_OF_LIGHT * self.delays[p].unwrap(),
                    inv_sigma: 1.0 / (SPEED_OF_LIGHT * self.sigmas[p]),
                }
            })
            .collect()
    }
}

#[derive(Clone, Copy)]
struct Row {
    tx: Vec2,
    rx: Vec2,
    range: Real,
    inv_sigma: Real,
}

/// The same weighted NLS (E5) for the `levenberg-marquardt` crate, in range units:
/// residual_p = (cτ̂_p − (d_Tx + d_Rx))/(cσ_p), Jacobian row −(u_Tx + u_Rx)/(cσ_p).
#[derive(Clone)]
struct CrateProblem<'a> {
    rows: &'a [Row],
    p: Vector2<Real>,
}

impl LeastSquaresProblem<Real, Dyn, U2> for CrateProblem<'_> {
    type ResidualStorage = Owned<Real, Dyn>;
    type JacobianStorage = Owned<Real, Dyn, U2>;
    type ParameterStorage = Owned<Real, U2>;

    fn set_params(&mut self, x: &Vector2<Real>) {
        self.p = *x;
    }

    fn params(&self) -> Vector2<Real> {
        self.p
    }

    fn residuals(&self) -> Option<DVector<Real>> {
        Some(DVector::from_iterator(
            self.rows.len(),
            self.rows.iter().map(|r| {
                (r.range - ((self.p - r.tx).norm() + (self.p - r.rx).norm())) * r.inv_sigma
            }),
        ))
    }

    fn jacobian(&self) -> Option<OMatrix<Real, Dyn, U2>> {
        let mut j = OMatrix::<Real, Dyn, U2>::zeros(self.rows.len());
        for (i, r) in self.rows.iter().enumerate() {
            let g = unit_from(r.tx, self.p).0 + unit_from(r.rx, self.p).0;
            j[(i, 0)] = -g.x * r.inv_sigma;
            j[(i, 1)] = -g.y * r.inv_sigma;
        }
        Some(j)
    }
}

/// Crate settings comparable to ours (spec §5: stop at a step < 1e-6 m or a relative cost
/// decrease < 1e-12). The crate's xtol is relative to the (scaled) parameter norm, so
/// 1e-6 m / |r| with |r| ≈ 4.1 m at the truth → 2.5e-7.
fn crate_solver() -> LevenbergMarquardt<Real> {
    LevenbergMarquardt::new().with_xtol(2.5e-7).with_ftol(1e-12)
}

fn crate_fix(rows: &[Row], start: Vec2) -> (Vec2, levenberg_marquardt::MinimizationReport<Real>) {
    let (p, report) = crate_solver().minimize(CrateProblem { rows, p: start });
    (p.p, report)
}

fn benches(c: &mut Criterion) {
    let s = setup();
    let rows = s.rows();
    let truth = Vec2::new(TRUTH[0], TRUTH[1]);

    // Untimed sanity check: both solvers (and the grid start) reach the same minimum.
    let ours = s.ours(Some(s.start));
    let (theirs, report) = crate_fix(&rows, s.start);
    let grid = s.ours(None);
    assert!(ours.termination.converged(), "{ours:?}");
    assert!(report.termination.was_successful(), "{report:?}");
    assert!(grid.termination.converged(), "{grid:?}");
    let gap = (ours.position - theirs).norm();
    assert!(gap <= 1e-6, "ours {ours:?} vs crate {theirs:?}");
    assert!((ours.position - grid.position).norm() <= 1e-6);
    // The crate minimises ½‖r‖², ours 𝓛 = ‖r‖² (E5).
    assert!((2.0 * report.objective_function / ours.cost - 1.0).abs() < 1e-6);
    eprintln!(
        "setup: truth {truth:?}, start {:?}\n  ours : {:?} after {} it. ({:?}), cost {:.6}, error {:.3} mm\n  crate: {:?} after {} evaluations ({:?}), |ours - crate| = {gap:.2e} m\n  grid start {:?} → {} it.",
        s.start,
        ours.position,
        ours.iterations,
        ours.termination,
        ours.cost,
        (ours.position - truth).norm() * 1e3,
        theirs,
        report.number_of_evaluations,
        report.termination,
        grid.start,
        grid.iterations,
    );

    let mut g = c.benchmark_group("lm_fix_4_links");
    g.bench_function("scatterloc_lm_start_truth+(2,2)", |b| {
        b.iter(|| s.ours(black_box(Some(s.start))))
    });
    g.bench_function("levenberg_marquardt_crate_start_truth+(2,2)", |b| {
        b.iter(|| crate_fix(black_box(&rows), black_box(s.start)).0)
    });
    g.bench_function("scatterloc_lm_grid_start_0.5m", |b| {
        b.iter(|| s.ours(black_box(None)))
    });
    g.finish();

    // The map kernel: scalar reference, SIMD on one thread, SIMD with rows on both cores.
    for (name, scenario, side) in [
        ("crlb_map_256x256_4_links", s.scenario.clone(), 256),
        ("crlb_map_512x512_4_links", s.scenario.clone(), 512),
        ("crlb_map_256x256_16_links", sixteen_links(), 256),
    ] {
        let model = Model::new(&scenario).unwrap();
        let grid = Grid::new(scenario.area_m, side, side).unwrap();
        let mut out = vec![0.0; grid.len()];
        let mut g = c.benchmark_group(name);
        g.bench_function("scalar", |b| {
            b.iter(|| crlb_map_scalar(&model, black_box(&grid), &mut out).unwrap())
        });
        g.bench_function("simd_1_thread", |b| {
            b.iter(|| crlb_map(&model, black_box(&grid), &mut out).unwrap())
        });
        g.bench_function("simd_2_threads", |b| {
            b.iter(|| crlb_map_parallel(&model, black_box(&grid), &mut out, 0).unwrap())
        });
        // Issue 29: every kernel path this CPU has, one thread (`portable` = `simd_1_thread`).
        for path in map_paths() {
            g.bench_function(format!("path_{}", path.name()), |b| {
                b.iter(|| crlb_map_on(path, &model, black_box(&grid), &mut out).unwrap())
            });
        }
        g.finish();
        assert!(out.iter().all(|v| !v.is_nan()));
    }

    cpu_peaks(c);
    path_peaks(c);

    c.bench_function("crlb_at_single_point", |b| {
        b.iter(|| crlb_at(&s.model, black_box(truth)))
    });
}

/// This CPU's throughput for the map kernel's operations, in the kernel's vector type
/// (`wide::f64x4`: 2 SSE2 registers in the default build, one AVX register with
/// `-C target-cpu=x86-64-v3`): 8 independent chains so that throughput, not latency, limits.
/// Criterion's throughput is lanes (f64 results) per second.
fn cpu_peaks(c: &mut Criterion) {
    use criterion::Throughput;
    use wide::f64x4;
    const CHAINS: usize = 8;
    const REPS: usize = 1000;
    let mut g = c.benchmark_group("cpu_peak_f64x4");
    g.throughput(Throughput::Elements((CHAINS * REPS * 4) as u64));
    let one = black_box(f64x4::ONE);
    g.bench_function("sqrt", |b| {
        b.iter(|| {
            let mut acc = [f64x4::splat(2.0); CHAINS];
            for _ in 0..REPS {
                for x in acc.iter_mut() {
                    *x = (*x + one).sqrt();
                }
            }
            acc
        })
    });
    g.bench_function("div", |b| {
        let three = black_box(f64x4::splat(3.0));
        b.iter(|| {
            let mut acc = [f64x4::splat(2.0); CHAINS];
            for _ in 0..REPS {
                for x in acc.iter_mut() {
                    *x = three / (*x + one);
                }
            }
            acc
        })
    });
    // One multiply and one add per lane and step (2 flops), 6 chains: 12 of the 16 SSE2
    // registers (16 chains spilled to memory and measured 35 % less, issue 29).
    const MUL_ADD_CHAINS: usize = 6;
    g.throughput(Throughput::Elements((MUL_ADD_CHAINS * REPS * 4 * 2) as u64));
    g.bench_function("mul_add_flops", |b| {
        let m = black_box(f64x4::splat(1.000_000_1));
        let a = black_box(f64x4::splat(1e-9));
        b.iter(|| {
            let mut acc = [f64x4::splat(1.0); MUL_ADD_CHAINS];
            for _ in 0..REPS {
                for x in acc.iter_mut() {
                    *x = *x * m + a;
                }
            }
            acc
        })
    });
    g.finish();
}

/// Issue 29: this CPU's throughput on each kernel path's registers (`Lanes` of `native`),
/// compiled with the path's target features (pulp's `vectorize`): multiply-adds (fused on the
/// fast paths: one operation; two on the exact ones) over 12 independent chains (16 spilled
/// AVX2's 16 registers and measured half the rate), and the
/// square-root-and-division pair `√(a/b)` of the exact paths. Throughput: lane operations
/// (results) per second.
fn path_peaks(c: &mut Criterion) {
    #[cfg(target_arch = "x86_64")]
    {
        use criterion::Throughput;
        use scatterloc::math::Lanes;
        use scatterloc::native::{Avx2, Avx512};
        const REPS: usize = 1000;
        const CHAINS: usize = 12;
        struct MulAdd<L: Lanes>(L::Arch);
        impl<L: Lanes> pulp::NullaryFnOnce for MulAdd<L> {
            type Output = Real;
            #[inline(always)]
            fn call(self) -> Real {
                let m = L::splat(self.0, black_box(1.000_000_1));
                let a = L::splat(self.0, black_box(1e-9));
                let mut acc = [L::splat(self.0, 1.0); CHAINS];
                for _ in 0..REPS {
                    for x in acc.iter_mut() {
                        *x = L::mul_add(*x, m, a);
                    }
                }
                acc.iter().map(|x| x.lane(0)).sum()
            }
        }
        struct Divider<L: Lanes>(L::Arch);
        impl<L: Lanes> pulp::NullaryFnOnce for Divider<L> {
            type Output = Real;
            #[inline(always)]
            fn call(self) -> Real {
                let one = L::splat(self.0, black_box(1.0));
                let three = L::splat(self.0, black_box(3.0));
                let mut acc = [L::splat(self.0, 2.0); 8];
                for _ in 0..REPS {
                    for x in acc.iter_mut() {
                        *x = L::root_ratio(three, *x + one);
                    }
                }
                acc.iter().map(|x| x.lane(0)).sum()
            }
        }
        let mut g = c.benchmark_group("cpu_peak_paths");
        if let Some(s) = pulp::x86::V3::try_new() {
            g.throughput(Throughput::Elements((CHAINS * REPS * 4) as u64));
            g.bench_function("avx2_fma", |b| {
                b.iter(|| s.vectorize(MulAdd::<Avx2<true>>(s)))
            });
            g.throughput(Throughput::Elements((2 * CHAINS * REPS * 4) as u64));
            g.bench_function("avx2_mul_add", |b| {
                b.iter(|| s.vectorize(MulAdd::<Avx2<false>>(s)))
            });
            g.throughput(Throughput::Elements((8 * REPS * 4) as u64));
            g.bench_function("avx2_sqrt_div_pair", |b| {
                b.iter(|| s.vectorize(Divider::<Avx2<false>>(s)))
            });
        }
        if let Some(s) = pulp::x86::V4::try_new() {
            g.throughput(Throughput::Elements((CHAINS * REPS * 8) as u64));
            g.bench_function("avx512_fma", |b| {
                b.iter(|| s.vectorize(MulAdd::<Avx512<true>>(s)))
            });
            g.throughput(Throughput::Elements((2 * CHAINS * REPS * 8) as u64));
            g.bench_function("avx512_mul_add", |b| {
                b.iter(|| s.vectorize(MulAdd::<Avx512<false>>(s)))
            });
            g.throughput(Throughput::Elements((8 * REPS * 8) as u64));
            g.bench_function("avx512_sqrt_div_pair", |b| {
                b.iter(|| s.vectorize(Divider::<Avx512<false>>(s)))
            });
        }
        g.finish();
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = c;
}

/// sensors2019 with 4 transmitters (the preset's parabolic Tx turned to four boresights) and its 4
/// receivers: 16 links, the page's third timing target.
fn sixteen_links() -> Scenario {
    let mut s = presets::sensors2019();
    let tx = s.transmitters[0].clone();
    s.transmitters = [
        (0.0, 0.0, 10.0),
        (20.0, 0.0, 100.0),
        (20.0, 20.0, 190.0),
        (0.0, 20.0, 280.0),
    ]
    .iter()
    .enumerate()
    .map(|(i, &(x, y, boresight))| {
        let mut t = tx.clone();
        t.name = format!("Tx{i}");
        t.position_m = [x, y];
        if let scatterloc::scenario::Pattern::Parabolic { boresight_deg, .. } = &mut t.pattern {
            *boresight_deg = boresight;
        }
        t
    })
    .collect();
    s
}

criterion_group!(core, benches);
criterion_main!(core);
