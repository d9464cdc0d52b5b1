#![cfg(not(target_arch = "wasm32"))]
#![allow(missing_docs)] // criterion_group! generates an undocumented pub fn
//! Multi-target localization benchmarks (criterion; spec `multi-target.md` §4, §6, §7).
//!
//! Every case draws a fixed set of §7 realisations (`generate(settings, SEED, i)`) outside the
//! timed loop; each timed call runs on the next realisation of the set (cycling), so a reported
//! time is a mean over representative realisations, not one lucky scene. Blocking models are also
//! built outside the timed loop (the PPP model per realisation, from its nodes). Algorithm 1 runs
//! with `MtlConfig::default()` (`T_e = 3`, `T_b = 20`, `B_max = 16`) and `region = R`, as the V-B
//! experiment; i.c.b runs with `consistency = false` (§6.1), the node models with it on.
//!
//! Groups:
//! - `mtl_vb_3x3_k2`: one V-B realisation (3×3, `K = 2`, clutter mean 2 per TRP, 64 seeds):
//!   `generate` alone; `locate` with i.c.b (`p_u = VB_ICB_P_U`) from a cold intersection cache
//!   (what one call costs) and with a warm one (`locate_cached` on a cache filled by an earlier
//!   call: the algorithm without the §5.2 ellipse intersections); `locate` with the PPP model
//!   (`λ`, `D`, `p_d` of the settings, region `R`), bound (M10) and exact (M11), cold and warm,
//!   and M10 with its node tables memoised on the 1 µm location grid (`TableCached::on_grid`,
//!   as the experiments and the page run it).
//! - `mtl_growth_targets_3x3`: `K = 1..10` targets (V-B otherwise, 16 seeds each): staged
//!   (`locate`, i.c.b) vs `brute_force` (i.c.b) where the latter finishes in reasonable time.
//! - `mtl_growth_trps_k2`: `N_t × N_r` = 3×3 … 6×6 with `K = 2` (V-B otherwise, 16 seeds each):
//!   staged with i.c.b at every size; staged with `NodeBlockingModel<IndependentNodes>` (node LoS
//!   `p = √((1 − p_u)/p_d)`, the i.c.b `p_u` made node-correlated) and with the PPP model only
//!   at 3×3; `brute_force` (i.c.b) only at 3×3 (cut-offs below).
//!
//! Cut-offs, decided by timing single runs on this 2-core machine (under other load):
//! - `brute_force` vs `K` (3×3): ≈ 9 ms at `K = 1`, 0.06–0.14 s at 2, 0.4–0.6 s at 3, 1.3 s
//!   at 4, 1.6 s at 5 and 60 s at 10 per realisation (the matchings grow like `(N + 1)^M` with
//!   `N` MPCs per TRP, and `N` grows with `K`); benched for `K ≤ 3`.
//! - `brute_force` vs TRPs: 4×4 did not finish one realisation within a minute; 3×3 only.
//! - PPP model (both variants) and `IndependentNodes` vs TRPs: every blocking query evaluates all
//!   `2^(N_t+N_r)` node patterns (PPP: plus the convex clipping of all `2^(N_t+N_r)` rectangle
//!   intersections, from scratch at every location), and the candidates multiply with `M`; at
//!   4×4 one realisation took ≈ 6 s (`IndependentNodes`) and ≈ 32 s (PPP M10) before the
//!   case-2b two-pair rule, 0.10–0.37 s (`IndependentNodes`) after it, while 5×5 still takes
//!   9–223 s; both are benched at 3×3 only (4×4 would dominate the bench's run time).
//!
//! Where the time goes (perf, 3×3): with i.c.b the §5.2 ellipse intersections are ≈ 40 % of a
//! cold `locate` (≈ 390 MPC pairs per realisation, the 720-sample scan on the implicit quadratic
//! with stretches skipped by its Lipschitz bound), hence the warm-cache case. With the PPP model
//! the cache hardly matters: ≈ 3 700 `L_b` queries per realisation each need the
//! rectangle-intersection table at their location (≈ 45 convex clips, one per rectangle subset
//! whose intersection has area) unless `TableCached` has it (≈ 470 cells per realisation), about
//! half of the memoised run; the late seeds with their catch-up take ≈ 70 % of it, and the
//! consistency branching scores about 2.5× the candidates of i.c.b (`IndependentNodes`, whose
//! table is cheap, takes ≈ 3.4 ms per realisation).
//!
//! Run: `cargo bench --bench mtl` (about 2 minutes here; shorter: filter by group name).

use std::hint::black_box;
use std::time::Duration;

use criterion::measurement::WallTime;
use criterion::{criterion_group, criterion_main, BenchmarkGroup, Criterion, SamplingMode};

use scatterloc::math::Real;
use scatterloc::mtl::algorithm::{
    locate, locate_cached, IntersectionCache, Measurements, MtlConfig,
};
use scatterloc::mtl::blocking::{
    BlockingModel, IndependentNodes, NodeBlockingModel, NodeTableCache, TableCached, TABLE_GRID_M,
};
use scatterloc::mtl::brute::brute_force;
use scatterloc::mtl::icb::IcbModel;
use scatterloc::mtl::ppp::{PppBlocking, PppNodeModel};
use scatterloc::mtl::sim::{generate, NodeLayout, Realisation, SimSettings, VB_ICB_P_U};

const SEED: u64 = 2024;
/// Realisations of the V-B case (group `mtl_vb_3x3_k2`).
const VB_REALISATIONS: u64 = 64;
/// Realisations per point of the growth groups.
const GROWTH_REALISATIONS: u64 = 16;
/// Largest `K` (3×3) at which `brute_force` is benched (see the module docs).
const BRUTE_MAX_TARGETS: usize = 3;
/// Largest `N_t = N_r` at which `brute_force`, the PPP model and `IndependentNodes` are benched.
const NODE_MODEL_MAX_SIDE: usize = 3;

/// One pre-generated realisation and its range lists.
struct Case {
    r: Realisation,
    ranges: Vec<Vec<Real>>,
}

impl Case {
    fn input(&self, s: &SimSettings) -> Measurements<'_> {
        Measurements {
            tx: &self.r.scene.tx,
            rx: &self.r.scene.rx,
            ranges: &self.ranges,
            c_sigma_m: s.range_sigma,
        }
    }
}

/// V-B with `n × n` nodes and `k` targets (noise, clutter, discs as V-B).
fn settings(n: usize, k: usize) -> SimSettings {
    SimSettings {
        nodes: NodeLayout::Uniform { n_tx: n, n_rx: n },
        targets: k,
        ..SimSettings::vb()
    }
}

/// Realisations `0..count` of `s`; prints the mean number of MPCs per TRP (untimed).
fn cases(s: &SimSettings, count: u64, label: &str) -> Vec<Case> {
    let out: Vec<Case> = (0..count)
        .map(|i| {
            let r = generate(s, SEED, i).unwrap();
            Case {
                ranges: r.ranges(),
                r,
            }
        })
        .collect();
    let mpcs: usize = out.iter().flat_map(|c| c.ranges.iter().map(Vec::len)).sum();
    let trps = out.iter().map(|c| c.ranges.len()).sum::<usize>();
    eprintln!(
        "setup {label}: {count} realisations, {:.2} MPCs per TRP",
        mpcs as f64 / trps as f64
    );
    out
}

/// The PPP model (§6.2) for the nodes of `c`: `λ`, `D`, `p_d` of `s`, centres in `R`.
fn ppp(s: &SimSettings, c: &Case, exact: bool) -> NodeBlockingModel<PppNodeModel> {
    let m = PppBlocking::new(s.lambda, s.diameter, Some(s.region), exact).unwrap();
    let nodes = PppNodeModel::new(m, c.r.scene.tx.clone(), c.r.scene.rx.clone()).unwrap();
    NodeBlockingModel::new(s.map().unwrap(), nodes, s.p_d).unwrap()
}

/// i.c.b with the V-B `p_u` (Table II).
fn icb(s: &SimSettings) -> IcbModel {
    IcbModel::from_p_u(s.map().unwrap(), VB_ICB_P_U).unwrap()
}

/// Independent node LoS with `p_d p² = 1 − p_u` (the i.c.b `p_u`, correlated through nodes).
fn indep(s: &SimSettings) -> NodeBlockingModel<IndependentNodes> {
    let map = s.map().unwrap();
    let p = ((1.0 - VB_ICB_P_U) / s.p_d).sqrt();
    let n = IndependentNodes::new(&map, vec![p; map.n_tx()], vec![p; map.n_rx()]).unwrap();
    NodeBlockingModel::new(map, n, s.p_d).unwrap()
}

/// The V-B configuration of Algorithm 1 (`consistency` off for i.c.b).
fn mtl_cfg(s: &SimSettings, consistency: bool) -> MtlConfig {
    MtlConfig {
        region: Some(s.region),
        consistency,
        ..MtlConfig::default()
    }
}

/// Bench `f(i)` on realisation `i`, cycling through `0..n` across iterations.
fn cycle<R>(g: &mut BenchmarkGroup<WallTime>, name: &str, n: usize, mut f: impl FnMut(usize) -> R) {
    let mut i = 0;
    g.bench_function(name, |b| {
        b.iter(|| {
            let r = f(i);
            i = (i + 1) % n;
            r
        })
    });
}

/// `locate` from a cold cache on realisation `i` with `model(i)`.
fn staged<'a, B: BlockingModel + 'a>(
    s: &'a SimSettings,
    cs: &'a [Case],
    cfg: &'a MtlConfig,
    model: impl Fn(usize) -> &'a B + 'a,
) -> impl FnMut(usize) -> usize + 'a {
    move |i| {
        locate(&cs[i].input(s), model(i), black_box(cfg))
            .unwrap()
            .targets
            .len()
    }
}

/// `locate_cached` on realisation `i` with a per-realisation cache filled by an untimed run.
fn staged_warm<'a, B: BlockingModel + 'a>(
    s: &'a SimSettings,
    cs: &'a [Case],
    cfg: &'a MtlConfig,
    model: impl Fn(usize) -> &'a B + 'a,
) -> impl FnMut(usize) -> usize + 'a {
    let mut caches: Vec<IntersectionCache> = cs
        .iter()
        .enumerate()
        .map(|(i, c)| {
            let mut cache = IntersectionCache::new();
            locate_cached(&c.input(s), model(i), cfg, &mut cache).unwrap();
            cache
        })
        .collect();
    move |i| {
        locate_cached(&cs[i].input(s), model(i), black_box(cfg), &mut caches[i])
            .unwrap()
            .targets
            .len()
    }
}

/// `brute_force` (cold cache) on realisation `i`.
fn brute<'a, B: BlockingModel + 'a>(
    s: &'a SimSettings,
    cs: &'a [Case],
    cfg: &'a MtlConfig,
    model: &'a B,
) -> impl FnMut(usize) -> usize + 'a {
    move |i| {
        brute_force(
            &cs[i].input(s),
            model,
            black_box(cfg),
            &mut IntersectionCache::new(),
        )
        .unwrap()
        .len()
    }
}

/// A group of slow cases: 10 flat samples.
fn slow_group<'c>(
    c: &'c mut Criterion,
    name: &str,
    measurement_s: u64,
) -> BenchmarkGroup<'c, WallTime> {
    let mut g = c.benchmark_group(name);
    g.sampling_mode(SamplingMode::Flat)
        .sample_size(10)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(measurement_s));
    g
}

fn vb(c: &mut Criterion) {
    let s = settings(3, 2);
    let cs = cases(&s, VB_REALISATIONS, "V-B 3x3 K=2");
    let n = cs.len();
    let icb = icb(&s);
    let (cfg_icb, cfg_node) = (mtl_cfg(&s, false), mtl_cfg(&s, true));
    let m10: Vec<_> = cs.iter().map(|c| ppp(&s, c, false)).collect();
    let m11: Vec<_> = cs.iter().map(|c| ppp(&s, c, true)).collect();

    let mut g = c.benchmark_group("mtl_vb_3x3_k2");
    g.warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(3));
    let mut index = 0u64;
    g.bench_function("generate", |b| {
        b.iter(|| {
            let r = generate(black_box(&s), SEED, index).unwrap();
            index = (index + 1) % VB_REALISATIONS;
            r
        })
    });
    g.sampling_mode(SamplingMode::Flat).sample_size(20);
    cycle(&mut g, "staged_icb", n, staged(&s, &cs, &cfg_icb, |_| &icb));
    cycle(
        &mut g,
        "staged_icb_warm_cache",
        n,
        staged_warm(&s, &cs, &cfg_icb, |_| &icb),
    );
    // ≈ 16 ms per call without the table memo: 10 samples over 8 s cover the 64 realisations.
    g.sample_size(10).measurement_time(Duration::from_secs(8));
    cycle(
        &mut g,
        "staged_ppp_m10",
        n,
        staged(&s, &cs, &cfg_node, |i| &m10[i]),
    );
    cycle(
        &mut g,
        "staged_ppp_m11",
        n,
        staged(&s, &cs, &cfg_node, |i| &m11[i]),
    );
    // As the experiments and the page run it: node tables memoised on the 1 µm location grid
    // within the call (`TableCached::on_grid` on a fresh cache; Algorithm 1 reaches the same
    // least-squares point along several paths).
    cycle(&mut g, "staged_ppp_m10_table_cache", n, |i| {
        let tables = NodeTableCache::default();
        let model = TableCached::on_grid(&m10[i], &tables, TABLE_GRID_M);
        locate(&cs[i].input(&s), &model, black_box(&cfg_node))
            .unwrap()
            .targets
            .len()
    });
    g.measurement_time(Duration::from_secs(5));
    cycle(
        &mut g,
        "staged_ppp_m10_warm_cache",
        n,
        staged_warm(&s, &cs, &cfg_node, |i| &m10[i]),
    );
    cycle(
        &mut g,
        "staged_ppp_m11_warm_cache",
        n,
        staged_warm(&s, &cs, &cfg_node, |i| &m11[i]),
    );
    g.finish();
}

fn growth_targets(c: &mut Criterion) {
    let sets: Vec<(usize, SimSettings, Vec<Case>)> = (1..=10)
        .map(|k| {
            let s = settings(3, k);
            let cs = cases(&s, GROWTH_REALISATIONS, &format!("3x3 K={k}"));
            (k, s, cs)
        })
        .collect();
    let mut g = slow_group(c, "mtl_growth_targets_3x3", 2);
    for (k, s, cs) in &sets {
        let (model, cfg) = (icb(s), mtl_cfg(s, false));
        let n = cs.len();
        cycle(
            &mut g,
            &format!("staged_icb/K={k}"),
            n,
            staged(s, cs, &cfg, |_| &model),
        );
        if *k <= BRUTE_MAX_TARGETS {
            cycle(
                &mut g,
                &format!("brute_icb/K={k}"),
                n,
                brute(s, cs, &cfg, &model),
            );
        }
    }
    g.finish();
}

fn growth_trps(c: &mut Criterion) {
    let sets: Vec<(usize, SimSettings, Vec<Case>)> = (3..=6)
        .map(|side| {
            let s = settings(side, 2);
            let cs = cases(&s, GROWTH_REALISATIONS, &format!("{side}x{side} K=2"));
            (side, s, cs)
        })
        .collect();
    let mut g = slow_group(c, "mtl_growth_trps_k2", 3);
    for (side, s, cs) in &sets {
        let size = format!("{side}x{side}");
        let n = cs.len();
        let (model, cfg_icb, cfg_node) = (icb(s), mtl_cfg(s, false), mtl_cfg(s, true));
        cycle(
            &mut g,
            &format!("staged_icb/{size}"),
            n,
            staged(s, cs, &cfg_icb, |_| &model),
        );
        if *side > NODE_MODEL_MAX_SIDE {
            continue;
        }
        let nodes = indep(s);
        cycle(
            &mut g,
            &format!("staged_indep_nodes/{size}"),
            n,
            staged(s, cs, &cfg_node, |_| &nodes),
        );
        let m10: Vec<_> = cs.iter().map(|c| ppp(s, c, false)).collect();
        cycle(
            &mut g,
            &format!("staged_ppp_m10/{size}"),
            n,
            staged(s, cs, &cfg_node, |i| &m10[i]),
        );
        cycle(
            &mut g,
            &format!("brute_icb/{size}"),
            n,
            brute(s, cs, &cfg_icb, &model),
        );
    }
    g.finish();
}

criterion_group!(mtl, vb, growth_targets, growth_trps);
criterion_main!(mtl);
