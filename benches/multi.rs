#![cfg(not(target_arch = "wasm32"))]
#![allow(missing_docs)] // criterion_group! generates an undocumented pub fn
//! Multi-target benchmarks (criterion, issue 41 §3 "≤ 1 ms per scan for 5 targets × 8 links"):
//! one scan of the PMB tracker and of the GNN baseline on the people scenario (2 Tx × 4 Rx, 5
//! walkers, P_D = 0.9, 5 clutter delays per link, 10 Hz), timed over the 80 scans after the
//! first 20 (every target confirmed: the steady state), so the time per element is the time per
//! scan including the birth search on the scan's free delays (over the walk region, 1221 cells,
//! and over the scenario's whole area, 21 900 cells); and the birth search alone on a scan with
//! no track (every delay free).
//!
//! Run: `cargo bench --bench multi` (shorter: `-- --warm-up-time 1 --measurement-time 3`).

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};

use scatterloc::math::Real;
use scatterloc::measure::rng;
use scatterloc::track::multi::{
    delay_scans, people_layout, people_region, people_truth, BirthGrid, Births, DelayBirth,
    DelayLinks, Gnn, GnnManagement, MultiConfig, MultiTracker, Pmb, Scan,
};
use scatterloc::track::ConstantVelocity;
use scatterloc::Model;

fn benches(c: &mut Criterion) {
    let model = Model::new(&people_layout()).unwrap();
    let mut r = rng(41, 0);
    let truth = people_truth(5, 100, 0.1, &mut r);
    let scans: Vec<Scan> = delay_scans(&model, &truth, 0.9, 5.0, 60e-9, &mut r);
    let links = DelayLinks::new(&model, 0.9, 5.0, 60e-9, None).unwrap();
    let cfg = MultiConfig::new(ConstantVelocity::new(0.1, 0.5));
    let grid = BirthGrid::new(
        &model,
        DelayBirth::new(people_region(), model.link_count()),
        None,
    )
    .unwrap();
    // Births over the whole scenario area (37.5 m × 36 m, 21 900 cells): the CLI's default.
    let area_grid = BirthGrid::new(
        &model,
        DelayBirth::new(people_layout().area_m, model.link_count()),
        None,
    )
    .unwrap();
    let trackers = [
        (
            "pmb",
            MultiTracker::Pmb(Pmb::new(cfg, Births::Delays(grid.clone())).unwrap()),
        ),
        (
            "pmb_births_over_the_area",
            MultiTracker::Pmb(Pmb::new(cfg, Births::Delays(area_grid.clone())).unwrap()),
        ),
        (
            "gnn",
            MultiTracker::Gnn(Gnn::new(cfg, GnnManagement::default(), Some(grid.clone())).unwrap()),
        ),
    ];
    let mut g = c.benchmark_group("multi_scan_5x8");
    g.throughput(Throughput::Elements(80));
    for (name, mut t) in trackers {
        for s in &scans[..20] {
            t.step(&links, s).unwrap();
        }
        assert_eq!(t.estimates().len(), 5, "{name}: all five walkers confirmed");
        g.bench_function(name, |b| {
            b.iter(|| {
                let mut t = t.clone();
                for s in &scans[20..] {
                    t.step(&links, black_box(s)).unwrap();
                }
                black_box(t.estimates().len())
            })
        });
    }
    g.finish();
    let free: Vec<Vec<(Real, Option<Real>)>> = scans[0]
        .iter()
        .map(|l| l.iter().map(|d| (d.value[0], None)).collect())
        .collect();
    c.bench_function("birth_search_5_walkers_8_links", |b| {
        b.iter(|| black_box(grid.search(&model, black_box(&free), None).len()))
    });
    c.bench_function("birth_search_5_walkers_8_links_over_the_area", |b| {
        b.iter(|| black_box(area_grid.search(&model, black_box(&free), None).len()))
    });
}

criterion_group!(multi, benches);
criterion_main!(multi);
