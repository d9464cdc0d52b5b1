//! The numbers of issue 41 §3 as seeded studies: Williams-15 (RMS GOSPA of the PMB tracker)
//! and the people scenario (GOSPA against the GNN baseline and the known-association bound,
//! label switches, cardinality error).

use scatterloc::math::{sqrt, Mat4, Real, Vec2, Vec4};
use scatterloc::measure::rng;
use scatterloc::track::multi::{
    delay_scans, people_layout, people_region, people_truth, position_scans, score_run, williams15,
    williams15_truth, BirthGrid, Births, DelayBirth, DelayLinks, Gnn, GnnManagement, MultiConfig,
    MultiTracker, Pmb, PositionSensor, RunScore, TargetEstimate,
};
use scatterloc::track::{ConstantVelocity, GospaConfig};
use scatterloc::Model;

/// One Williams-15 run of the PMB tracker: its score (GOSPA c = 10, p = 2).
pub fn williams_run(seed: u64, run: u64) -> RunScore {
    williams_run_with(seed, run, 20.0, 0.4)
}

pub fn williams_run_with(seed: u64, run: u64, gate: Real, thr: Real) -> RunScore {
    let w = williams15();
    let mut r = rng(seed, run);
    let truth = williams15_truth(&w, &mut r);
    let scans = position_scans(&truth, w.detection, w.sigma_m, w.clutter, w.side_m, &mut r);
    let sensor = PositionSensor {
        sigma_m: w.sigma_m,
        detection: w.detection,
        clutter_intensity: w.clutter / (w.side_m * w.side_m),
    };
    let births = Births::Poisson {
        initial: vec![w.birth(3.0)],
        per_scan: vec![w.birth(0.005)],
    };
    let cfg = MultiConfig {
        existence_threshold: thr,
        gate,
        prune: 1e-5,
        ..MultiConfig::new(w.motion)
    };
    let mut t = Pmb::new(cfg, births).unwrap();
    let est: Vec<Vec<TargetEstimate>> = scans
        .iter()
        .map(|s| {
            t.step(&sensor, s).unwrap();
            t.estimates()
        })
        .collect();
    score_run(&truth, &est, &GospaConfig { c: 10.0, p: 2.0 }).unwrap()
}

/// RMS GOSPA over `runs` runs: `√(Σ_runs Σ_k d_k² / (runs · K))`.
pub fn williams_rms(seed: u64, runs: u64) -> Real {
    let s: Real = (0..runs)
        .map(|r| williams_run(seed, r).mean_gospa_p(2.0))
        .sum();
    sqrt(s / runs as Real)
}

#[test]
#[ignore = "full size: 100 runs (cargo test --release --test tracking -- --ignored multi_studies::)"]
fn williams15_rms_gospa_full() {
    // Issue 41 asks RMS GOSPA ≤ 3.2. Measured (2026-12-07, exact marginals on clusters of ≤ 6):
    // seeds 1, 2, 3 give 3.095, 3.111, 3.155 (loopy BP alone: 3.135, 3.160, 3.201).
    let mut all = Vec::new();
    for seed in [1, 2, 3] {
        let rms = williams_rms(seed, 100);
        println!("williams15 seed {seed}: RMS GOSPA {rms:.3}");
        all.push(rms);
        assert!(rms <= 3.2, "seed {seed}: RMS GOSPA {rms}");
    }
}

/// The people scenario's constants (issue 41 §3): 10 Hz, `P_D = 0.9` per link, 5 clutter delays
/// per link and scan over a 60 ns window, 10 s.
pub const PEOPLE_DT_S: Real = 0.1;
/// Scans per run.
pub const PEOPLE_STEPS: usize = 100;
/// `P_D` per link.
pub const PEOPLE_PD: Real = 0.9;
/// Clutter delays per link and scan.
pub const PEOPLE_CLUTTER: Real = 5.0;
/// The clutter window after the direct path, s.
pub const PEOPLE_WINDOW_S: Real = 60e-9;
/// Process-noise intensity of the trackers, m²/s³.
pub const PEOPLE_Q: Real = 0.5;

/// One people run: truth, the PMB and GNN estimates' scores (GOSPA c = 1 m, p = 2) and the
/// per-step known-association bound `Σ_targets tr(PCRLB position)` (m²).
pub struct PeopleRun {
    pub pmb: RunScore,
    pub gnn: RunScore,
    pub bound_m2: Vec<Real>,
}

pub fn people_run(walkers: usize, seed: u64, run: u64) -> PeopleRun {
    let model = Model::new(&people_layout()).unwrap();
    let mut r = rng(seed, run);
    let truth = people_truth(walkers, PEOPLE_STEPS, PEOPLE_DT_S, &mut r);
    let scans = delay_scans(
        &model,
        &truth,
        PEOPLE_PD,
        PEOPLE_CLUTTER,
        PEOPLE_WINDOW_S,
        &mut r,
    );
    let links = DelayLinks::new(&model, PEOPLE_PD, PEOPLE_CLUTTER, PEOPLE_WINDOW_S, None).unwrap();
    let motion = ConstantVelocity::new(PEOPLE_DT_S, PEOPLE_Q);
    let cfg = MultiConfig::new(motion);
    let grid = BirthGrid::new(
        &model,
        DelayBirth::new(people_region(), model.link_count()),
        None,
    )
    .unwrap();
    let mut pmb = MultiTracker::Pmb(Pmb::new(cfg, Births::Delays(grid.clone())).unwrap());
    let mut gnn = MultiTracker::Gnn(Gnn::new(cfg, GnnManagement::default(), Some(grid)).unwrap());
    let g = GospaConfig { c: 1.0, p: 2.0 };
    let run_one = |t: &mut MultiTracker| {
        let est: Vec<Vec<TargetEstimate>> = scans
            .iter()
            .map(|s| {
                t.step(&links, s).unwrap();
                t.estimates()
            })
            .collect();
        score_run(&truth, &est, &g).unwrap()
    };
    let pmb_score = run_one(&mut pmb);
    let gnn_score = run_one(&mut gnn);
    // Known association: per target the PCRLB (E9) with the expected information P_D F(r)
    // at its true path, from a prior of 0.1 m per axis (position) and 1 m/s (velocity).
    let p0 = Mat4::from_diagonal(&Vec4::new(0.01, 0.01, 1.0, 1.0));
    let n_targets = truth.steps[0].len();
    let mut bound = vec![0.0; truth.steps.len()];
    for t in 0..n_targets {
        let fishers: Vec<_> = truth
            .steps
            .iter()
            .skip(1)
            .map(|s| {
                let x = s[t].1;
                scatterloc::localize::fisher(&model, Vec2::new(x[0], x[1])) * PEOPLE_PD
            })
            .collect();
        let b = scatterloc::track::pcrlb_rmse(&motion, &p0, &fishers).unwrap();
        for (k, v) in b.iter().enumerate() {
            bound[k] += v.map_or(Real::INFINITY, |v| v * v);
        }
    }
    PeopleRun {
        pmb: pmb_score,
        gnn: gnn_score,
        bound_m2: bound,
    }
}

#[test]
#[ignore = "full size: 3 seeds × 20 runs of 3 and 5 walkers (release)"]
fn people_full() {
    for walkers in [3, 5] {
        // Crossing labels: pooled over the seeds' runs (issue 41: "≥ 90 % of runs").
        let (mut kept_all, mut runs_all) = (0usize, 0usize);
        for seed in [7, 8, 9] {
            let runs = 20;
            let (mut gp, mut gg, mut loc, mut bnd, mut card, mut cn) =
                (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
            let (mut kept, mut gnn_kept, mut late_p, mut late_g) = (0, 0, 0.0, 0.0);
            for run in 0..runs {
                let r = people_run(walkers, seed, run);
                gp += r.pmb.steps.iter().map(|s| s.gospa).sum::<Real>() / PEOPLE_STEPS as Real;
                gg += r.gnn.steps.iter().map(|s| s.gospa).sum::<Real>() / PEOPLE_STEPS as Real;
                late_p += r.pmb.steps[10..].iter().map(|s| s.gospa).sum::<Real>();
                late_g += r.gnn.steps[10..].iter().map(|s| s.gospa).sum::<Real>();
                for (k, s) in r.pmb.steps.iter().enumerate().skip(10) {
                    loc += s.localisation;
                    bnd += r.bound_m2[k];
                    card += s.cardinality_error as Real;
                    cn += 1.0;
                }
                let crossing = |s: &RunScore| {
                    s.switches.get(&0).copied().unwrap_or(0)
                        + s.switches.get(&1).copied().unwrap_or(0)
                };
                kept += usize::from(crossing(&r.pmb) == 0);
                gnn_kept += usize::from(crossing(&r.gnn) == 0);
            }
            let (gp, gg) = (gp / runs as Real, gg / runs as Real);
            println!(
                "people {walkers} walkers seed {seed}: mean GOSPA pmb {gp:.4} m, gnn {gg:.4} m \
                 ({:.0} % below); after 1 s pmb {:.4}, gnn {:.4}; localisation / bound {:.3}; \
                 crossing labels kept pmb {kept}/{runs}, gnn {gnn_kept}/{runs}; mean cardinality \
                 error after 1 s {:.4}",
                100.0 * (1.0 - gp / gg),
                late_p / (runs as Real * (PEOPLE_STEPS - 10) as Real),
                late_g / (runs as Real * (PEOPLE_STEPS - 10) as Real),
                loc / bnd,
                card / cn
            );
            assert!(gp <= 0.7 * gg, "GOSPA {gp} vs GNN {gg}");
            assert!(loc <= 1.5 * bnd, "localisation {loc} vs bound {bnd}");
            assert!(card / cn < 0.1, "cardinality error {}", card / cn);
            kept_all += kept;
            runs_all += runs as usize;
        }
        println!("people {walkers} walkers: crossing labels kept in {kept_all}/{runs_all} runs");
        assert!(
            kept_all * 10 >= runs_all * 9,
            "labels kept at the crossing in {kept_all}/{runs_all}"
        );
    }
}
