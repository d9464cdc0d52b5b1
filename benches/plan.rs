//! The planner (issue 14): a whole plan of sensors2019's 4 receivers for p90 over the area at
//! ROI grid 64 (search grid 32, 10 000 evaluations, the CLI's and the page's default), and how
//! the cost grows with the search grid and the number of variables. Run with
//! `cargo bench --bench plan`. Issue 29: the main plan and the evaluations also on the kernel the
//! CLI and Python give the planner (`native::crlb_map_exact`, the widest exact path of this CPU:
//! the same plan as the core's kernel).
#![allow(missing_docs)] // criterion_group! generates an undocumented pub fn

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};

use scatterloc::plan::{plan, MoveSpec, Objective, PlanConfig, RoiObjective};
use scatterloc::scenario::presets;
use scatterloc::{native, Model};

fn benches(c: &mut Criterion) {
    let s = presets::sensors2019();
    let base = PlanConfig {
        budget: 10_000,
        ..PlanConfig::new(Objective::P90, s.area_m)
    };
    let mut g = c.benchmark_group("plan_sensors2019_p90");
    g.sample_size(10);
    for (name, cfg) in [
        ("4_rx_grid64_search32_10000_evals", base.clone()),
        (
            "4_rx_grid64_search32_10000_evals_exact_path",
            PlanConfig {
                kernel: native::crlb_map_exact,
                ..base.clone()
            },
        ),
        (
            "4_rx_grid64_search64_10000_evals",
            PlanConfig {
                coarse_grid: 64,
                ..base.clone()
            },
        ),
        (
            "1_rx_grid64_search32_10000_evals",
            PlanConfig {
                movable: MoveSpec::Names(vec!["Rx2".into()]),
                ..base.clone()
            },
        ),
        (
            "all_5_nodes_grid64_search32_10000_evals",
            PlanConfig {
                movable: MoveSpec::All,
                ..base.clone()
            },
        ),
        (
            "tx_and_beam_grid64_search32_10000_evals",
            PlanConfig {
                movable: MoveSpec::TransmittersWithBoresight,
                ..base.clone()
            },
        ),
    ] {
        g.bench_function(name, |b| {
            b.iter(|| plan(black_box(&s), &cfg, |_| true).unwrap())
        });
    }
    g.finish();
    // One evaluation: the map kernel over the search grid plus the objective.
    let model = Model::new(&s).unwrap();
    let mut g = c.benchmark_group("plan_evaluation_p90");
    for side in [16, 32, 64, 128] {
        let mut roi = RoiObjective::new(Objective::P90, s.area_m, side).unwrap();
        g.bench_function(format!("grid{side}"), |b| {
            b.iter(|| roi.evaluate(black_box(&model)))
        });
        let mut roi = RoiObjective::new(Objective::P90, s.area_m, side)
            .unwrap()
            .with_kernel(native::crlb_map_exact);
        g.bench_function(format!("grid{side}_exact_path"), |b| {
            b.iter(|| roi.evaluate(black_box(&model)))
        });
    }
    g.finish();
}

criterion_group!(plan_benches, benches);
criterion_main!(plan_benches);
