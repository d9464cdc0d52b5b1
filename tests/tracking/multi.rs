//! The multi-target tracker's parts against independent references: loopy BP against the
//! exact marginals (exact on trees, close on loops), the Kalman update against the
//! information-form closed form, the MAP cardinality against enumeration, the birth search on
//! noise-free delays; drawn walkers against their closed form and their delay scans; named
//! errors for bad scans and bad drawn paths; and the studies of issue 41 §3 at a size a
//! debug build runs (the full sizes are `multi_studies::*_full`, release).

use scatterloc::error::Error;
use scatterloc::formats::{RawEstimate, RawStep};
use scatterloc::math::{Mat4, Real, Vec2, Vec4};
use scatterloc::measure::{rng, uniform01};
use scatterloc::study::{simulate_people, MultiSettings, Walkers};
use scatterloc::track::multi::{
    bp_marginals, check_drawn_paths, clustered_marginals, delay_scans, exact_marginals,
    kalman_update, map_cardinality, people_layout, people_region, people_truth_drawn, BirthGrid,
    Births, DelayBirth, DelayLinks, Detection, DrawnPath, MultiConfig, Pmb, PositionSensor,
    MAX_BP_ITERATIONS, MAX_DETECTIONS_PER_SENSOR, MAX_EXACT_CLUSTER, MAX_WALKERS,
};
use scatterloc::track::ConstantVelocity;
use scatterloc::Model;

use crate::multi_studies::{people_run, williams_rms, PEOPLE_STEPS};

fn random_psi(n: usize, m: usize, seed: u64) -> Vec<Real> {
    let mut r = rng(seed, 0);
    (0..n * m)
        .map(|_| {
            let u = uniform01(&mut r);
            if u < 0.3 {
                0.0
            } else {
                10.0 * uniform01(&mut r)
            }
        })
        .collect()
}

#[test]
fn bp_is_exact_on_trees_and_close_on_loops() {
    let mut worst_loop: Real = 0.0;
    for seed in 0..300u64 {
        // A tree: one track or one measurement.
        for (n, m) in [(1, 5), (4, 1)] {
            let psi = random_psi(n, m, seed);
            let (bp, ex) = (bp_marginals(&psi, n, m), exact_marginals(&psi, n, m));
            assert!(bp.converged);
            for (a, b) in bp
                .track
                .iter()
                .zip(&ex.track)
                .chain(bp.free.iter().zip(&ex.free))
            {
                assert!((a - b).abs() < 1e-9, "tree seed {seed}: {a} vs {b}");
            }
        }
        let (n, m) = (3, 4);
        let psi = random_psi(n, m, seed + 1000);
        let (bp, ex) = (bp_marginals(&psi, n, m), exact_marginals(&psi, n, m));
        assert!(bp.iterations <= MAX_BP_ITERATIONS);
        for i in 0..n {
            let s: Real = bp.track[i * (m + 1)..(i + 1) * (m + 1)].iter().sum();
            assert!((s - 1.0).abs() < 1e-12);
        }
        for (a, b) in bp.track.iter().zip(&ex.track) {
            worst_loop = worst_loop.max((a - b).abs());
        }
    }
    // Loopy BP is approximate on loops; measured worst error over 300 random 3 × 4 problems.
    assert!(worst_loop < 0.15, "loopy BP error {worst_loop}");
    println!("loopy BP worst marginal error over 300 problems: {worst_loop:.4}");
}

#[test]
fn clustered_marginals_are_exact_per_small_cluster_and_bp_on_a_large_one() {
    // Block-diagonal weights: clusters of 2 × 3 and 3 × 2 (and an unlinked track and measurement)
    // enumerate exactly, so the whole equals the exact marginals of the whole problem.
    for seed in 0..200u64 {
        let (n, m) = (6, 6);
        let a = random_psi(2, 3, seed);
        let b = random_psi(3, 2, seed + 7000);
        let mut psi = vec![0.0; n * m];
        for i in 0..2 {
            for j in 0..3 {
                psi[i * m + j] = a[i * 3 + j];
            }
        }
        for i in 0..3 {
            for j in 0..2 {
                psi[(i + 2) * m + j + 3] = b[i * 2 + j];
            }
        }
        let (c, ex) = (
            clustered_marginals(&psi, n, m, 6),
            exact_marginals(&psi, n, m),
        );
        for (x, y) in c
            .track
            .iter()
            .zip(&ex.track)
            .chain(c.free.iter().zip(&ex.free))
        {
            assert!((x - y).abs() < 1e-12, "seed {seed}: {x} vs {y}");
        }
    }
    // One cluster larger than the exact limit (6, and the cap MAX_EXACT_CLUSTER), or exact = 0:
    // loopy BP on it, bit for bit.
    for (k, exact) in [(7, 6), (MAX_EXACT_CLUSTER + 1, usize::MAX), (3, 0)] {
        let psi: Vec<Real> = (0..k * k).map(|v| 1.0 + (v % 5) as Real).collect();
        let (c, bp) = (
            clustered_marginals(&psi, k, k, exact),
            bp_marginals(&psi, k, k),
        );
        assert_eq!(c.track, bp.track);
        assert_eq!(c.free, bp.free);
    }
}

#[test]
fn bp_reaches_its_iteration_bound_on_a_hard_loop() {
    // Strong, symmetric weights on a full bipartite loop converge slowly: the bound is reached
    // and reported, the marginals stay probabilities.
    let (n, m) = (6, 6);
    let psi = vec![1e6; n * m];
    let bp = bp_marginals(&psi, n, m);
    assert!(bp.iterations <= MAX_BP_ITERATIONS);
    for v in bp.track.iter().chain(&bp.free) {
        assert!(v.is_finite() && (0.0..=1.0).contains(v));
    }
    let psi = [5.0, 0.0, 0.0, 5.0];
    let bp = bp_marginals(&psi, 2, 2);
    assert!(bp.converged && bp.iterations < MAX_BP_ITERATIONS);
}

#[test]
fn kalman_update_equals_the_information_form() {
    let sensor = PositionSensor {
        sigma_m: 0.7,
        detection: 0.9,
        clutter_intensity: 1e-4,
    };
    let mut r = rng(5, 0);
    for _ in 0..200 {
        let x = Vec4::new(uniform01(&mut r) * 10.0, 3.0, 0.5, -0.2);
        let a = Mat4::from_fn(|i, j| uniform01(&mut r) - 0.5 + if i == j { 1.5 } else { 0.0 });
        let p = a * a.transpose();
        let z = [x[0] + 0.3, x[1] - 0.8];
        let obs = scatterloc::track::multi::MeasurementModel::observe(&sensor, 0, &x, None);
        let u = kalman_update(&x, &p, &obs, &z).unwrap();
        // Information form: P⁺ = (P⁻¹ + Hᵀ R⁻¹ H)⁻¹, x⁺ = x + P⁺ Hᵀ R⁻¹ (z − Hx).
        let mut h = nalgebra::Matrix2x4::<Real>::zeros();
        h[(0, 0)] = 1.0;
        h[(1, 1)] = 1.0;
        let rinv = nalgebra::Matrix2::<Real>::identity() / 0.49;
        let pp = (p.try_inverse().unwrap() + h.transpose() * rinv * h)
            .try_inverse()
            .unwrap();
        let nu = nalgebra::Vector2::new(z[0] - x[0], z[1] - x[1]);
        let xp = x + pp * h.transpose() * rinv * nu;
        assert!((u.state - xp).norm() < 1e-9 * (1.0 + xp.norm()));
        assert!((u.covariance - pp).norm() < 1e-9 * (1.0 + pp.norm()));
        // Predictive likelihood: 𝒩(z; Hx, H P Hᵀ + R).
        let s = h * p * h.transpose() + nalgebra::Matrix2::identity() * 0.49;
        let d2 = (nu.transpose() * s.try_inverse().unwrap() * nu)[0];
        let ll = -0.5 * d2 - (2.0 * std::f64::consts::PI).ln() - 0.5 * s.determinant().ln();
        assert!((u.log_likelihood - ll).abs() < 1e-9);
        assert!((u.distance2 - d2).abs() < 1e-9 * (1.0 + d2));
    }
}

#[test]
fn map_cardinality_equals_enumeration() {
    let mut r = rng(9, 0);
    for _ in 0..300 {
        let n = 1 + (uniform01(&mut r) * 8.0) as usize;
        let e: Vec<Real> = (0..n).map(|_| uniform01(&mut r)).collect();
        let mut p = vec![0.0; n + 1];
        for mask in 0u32..(1 << n) {
            let w: Real = (0..n)
                .map(|i| if mask >> i & 1 == 1 { e[i] } else { 1.0 - e[i] })
                .product();
            p[mask.count_ones() as usize] += w;
        }
        let best = (0..=n).fold(0, |b, k| if p[k] > p[b] { k } else { b });
        assert_eq!(map_cardinality(&e), best);
    }
}

#[test]
fn birth_search_finds_targets_from_noise_free_delays() {
    let model = Model::new(&people_layout()).unwrap();
    let grid = BirthGrid::new(&model, DelayBirth::new(people_region(), 8), None).unwrap();
    let targets = [
        Vec2::new(2.3, 1.7),
        Vec2::new(7.9, 6.2),
        Vec2::new(5.6, 3.1),
    ];
    let free: Vec<Vec<(Real, Option<Real>)>> = (0..8)
        .map(|p| {
            targets
                .iter()
                .map(|t| (model.network.delay(p, *t), None))
                .collect()
        })
        .collect();
    let fixes = grid.search(&model, &free, None);
    assert_eq!(fixes.len(), 3);
    for t in targets {
        let d = fixes
            .iter()
            .map(|f| (f.position - t).norm())
            .fold(Real::INFINITY, Real::min);
        assert!(d < 1e-6, "target {t:?}: nearest fix {d} m");
    }
    for f in &fixes {
        assert_eq!(f.used.iter().flatten().count(), 8);
        let r = f.existence(0.01, &people_region(), 0.9, 5.0 / 60e-9);
        assert!(r > 0.999, "{r}");
    }
    // Delays on too few links give no birth.
    let few: Vec<Vec<(Real, Option<Real>)>> = (0..8)
        .map(|p| if p < 4 { free[p].clone() } else { vec![] })
        .collect();
    assert!(grid.search(&model, &few, None).is_empty());
}

#[test]
fn bad_scans_are_named_and_leave_the_tracker_unchanged() {
    let model = Model::new(&people_layout()).unwrap();
    let links = DelayLinks::new(&model, 0.9, 5.0, 60e-9, None).unwrap();
    let cfg = MultiConfig::new(ConstantVelocity::new(0.1, 0.5));
    let grid = BirthGrid::new(&model, DelayBirth::new(people_region(), 8), None).unwrap();
    let mut t = Pmb::new(cfg, Births::Delays(grid)).unwrap();
    let good: Vec<Vec<Detection>> = (0..8)
        .map(|p| {
            vec![Detection::delay(
                model.network.delay(p, Vec2::new(4.0, 4.0)),
                None,
            )]
        })
        .collect();
    t.step(&links, &good).unwrap();
    let before = t.bernoullis().to_vec();
    let e = t.step(&links, &good[..7]).unwrap_err().to_string();
    assert!(
        e.contains("scan") && e.contains('8') && e.contains('7'),
        "{e}"
    );
    let mut nan = good.clone();
    nan[3][0] = Detection::delay(Real::NAN, None);
    assert!(t
        .step(&links, &nan)
        .unwrap_err()
        .to_string()
        .contains("scan[3][0]"));
    let mut bad_sigma = good.clone();
    bad_sigma[2][0].sigma = Some(-1.0);
    assert!(t.step(&links, &bad_sigma).is_err());
    let mut flood = good.clone();
    flood[0] = vec![Detection::delay(5e-8, None); MAX_DETECTIONS_PER_SENSOR + 1];
    let e = t.step(&links, &flood).unwrap_err().to_string();
    assert!(e.contains("detections per link"), "{e}");
    assert_eq!(t.bernoullis(), &before[..]);
    // Empty scans are fine: the target's existence decays.
    let empty = vec![Vec::new(); 8];
    let r0 = t.estimates()[0].existence;
    t.step(&links, &empty).unwrap();
    assert!(t.bernoullis().iter().all(|b| b.existence < r0));
    // Thousands of clutter delays at the cap: one scan in bounded work, finite output.
    let mut r = rng(3, 0);
    let heavy: Vec<Vec<Detection>> = (0..8)
        .map(|p| {
            let lo = model.network.los_delay(p);
            (0..MAX_DETECTIONS_PER_SENSOR)
                .map(|_| Detection::delay(lo + 60e-9 * uniform01(&mut r), None))
                .collect()
        })
        .collect();
    t.step(&links, &heavy).unwrap();
    for e in t.estimates() {
        assert!(e.state.iter().all(|v| v.is_finite()));
    }
    // Bad settings are named.
    assert!(DelayLinks::new(&model, 1.0, 5.0, 60e-9, None).is_err());
    assert!(DelayLinks::new(&model, 0.9, -1.0, 60e-9, None).is_err());
    let bad = MultiConfig {
        survival: 1.5,
        ..cfg
    };
    assert!(Pmb::new(
        bad,
        Births::Poisson {
            initial: vec![],
            per_scan: vec![]
        }
    )
    .is_err());
}

#[test]
fn williams15_at_debug_size() {
    // 3 seeds × 30 runs (the full check is 100 runs, release): the RMS GOSPA of the PMB
    // tracker. Measured at full size: see multi_studies::williams15_rms_gospa_full.
    for seed in [11, 12, 13] {
        let rms = williams_rms(seed, 30);
        assert!(rms < 3.45, "seed {seed}: RMS GOSPA {rms}");
    }
}

#[test]
fn people_at_debug_size() {
    // 3 seeds × 6 runs of 3 walkers: PMB beats GNN by ≥ 30 % in mean GOSPA, localisation within
    // 1.5× of the known-association bound after the first second, no cardinality error.
    for seed in [21, 22, 23] {
        let (mut gp, mut gg, mut loc, mut bnd, mut card) = (0.0, 0.0, 0.0, 0.0, 0usize);
        for run in 0..6 {
            let r = people_run(3, seed, run);
            gp += r.pmb.steps.iter().map(|s| s.gospa).sum::<Real>();
            gg += r.gnn.steps.iter().map(|s| s.gospa).sum::<Real>();
            for (k, s) in r.pmb.steps.iter().enumerate().skip(10) {
                loc += s.localisation;
                bnd += r.bound_m2[k];
                card += s.cardinality_error;
            }
        }
        assert!(gp <= 0.7 * gg, "seed {seed}: PMB {gp} vs GNN {gg}");
        assert!(
            loc <= 1.5 * bnd,
            "seed {seed}: localisation {loc} vs bound {bnd}"
        );
        assert!(
            card <= 6 * (PEOPLE_STEPS - 10) / 10,
            "seed {seed}: cardinality errors {card}"
        );
    }
}

#[test]
fn drawn_walkers_walk_their_lines_and_give_the_delay_scans_of_their_truth() {
    // Three drawn paths (one of them a person standing still: start = end), 101 scans at 0.1 s.
    let paths: Vec<DrawnPath> = vec![
        ([1.0, 2.0], [8.0, 7.5]),
        ([-3.5, 4.25], [6.0, -1.0]),
        ([5.0, 5.0], [5.0, 5.0]),
    ];
    let (steps, dt) = (101, 0.1);
    let truth = people_truth_drawn(&paths, steps, dt).unwrap();
    assert_eq!(truth.steps.len(), steps);
    let total = (steps - 1) as Real * dt;
    let near = |x: Real, want: Real| (x - want).abs() <= 1e-12 * (1.0 + want.abs());
    for (k, scan) in truth.steps.iter().enumerate() {
        assert_eq!(scan.len(), 3, "scan {k}");
        // The closed form: a + (b − a) k / (n − 1), velocity (b − a) / ((n − 1) T).
        let f = k as Real / (steps - 1) as Real;
        for (i, (label, x)) in scan.iter().enumerate() {
            let (a, b) = paths[i];
            assert_eq!(*label, i as u64);
            for c in 0..2 {
                let want = a[c] + (b[c] - a[c]) * f;
                assert!(near(x[c], want), "scan {k} walker {i}: {} vs {want}", x[c]);
                let v = (b[c] - a[c]) / total;
                assert!(
                    near(x[2 + c], v),
                    "scan {k} walker {i}: v {} vs {v}",
                    x[2 + c]
                );
                // Constant velocity: the same number at every scan.
                assert_eq!(x[2 + c], truth.steps[0][i].1[2 + c]);
            }
        }
    }
    // The use case: the same truth, and the delay scans of that truth for the same seed.
    let scenario = people_layout();
    let model = Model::new(&scenario).unwrap();
    let settings = MultiSettings::default();
    let (m, t) = simulate_people(
        &model,
        &people_region(),
        paths.clone(),
        steps,
        dt,
        0.5,
        &settings,
        7,
    )
    .unwrap();
    assert_eq!(t.to_truth(), truth);
    let mut r = rng(7, 0);
    let scans = delay_scans(
        &model,
        &truth,
        settings.detection_probability,
        settings.clutter,
        settings.clutter_window_s,
        &mut r,
    );
    let delays = |s: &RawStep| -> Vec<Vec<Real>> {
        s.iter()
            .map(|l| {
                l.iter()
                    .map(|e| match e {
                        RawEstimate::Pair([d, _]) => *d,
                        RawEstimate::WithSigma([d, _, _]) => *d,
                    })
                    .collect()
            })
            .collect()
    };
    let from_scans = |s: &Vec<Vec<Detection>>| -> Vec<Vec<Real>> {
        s.iter()
            .map(|l| l.iter().map(|d| d.value[0]).collect())
            .collect()
    };
    let mut got = vec![delays(m.initial_snapshot.as_ref().unwrap())];
    got.extend(m.raw_steps.as_ref().unwrap().iter().map(delays));
    let want: Vec<_> = scans.iter().map(from_scans).collect();
    assert_eq!(got.len(), steps);
    assert_eq!(got, want, "the delay scans of the drawn truth, bit for bit");
    assert!(want.iter().flatten().flatten().count() > steps * 8 * 3 / 2);
}

#[test]
fn bad_drawn_paths_are_named() {
    let ok = ([1.0, 2.0], [3.0, 4.0]);
    let size = |e: Error| match e {
        Error::SizeLimit { field, value, .. } => (field, value),
        e => panic!("{e}"),
    };
    assert_eq!(
        size(people_truth_drawn(&[], 10, 0.1).unwrap_err()),
        ("paths", 0)
    );
    assert_eq!(size(check_drawn_paths(&[ok; 6]).unwrap_err()), ("paths", 6));
    assert!(check_drawn_paths(&[ok; MAX_WALKERS]).is_ok());
    let field = |e: Error| e.field().map(String::from);
    let nan = [ok, ([1.0, Real::NAN], [3.0, 4.0])];
    let e = people_truth_drawn(&nan, 10, 0.1).unwrap_err();
    assert!(matches!(e, Error::NonFinite { .. }), "{e}");
    assert_eq!(field(e).as_deref(), Some("paths[1].y0"));
    let far = [([1.0, 2.0], [3.0, 1e8])];
    let e = check_drawn_paths(&far).unwrap_err();
    assert!(matches!(e, Error::OutOfRange { .. }), "{e}");
    assert_eq!(field(e).as_deref(), Some("paths[0].y1"));
    let e = people_truth_drawn(&[ok], 10, 0.0).unwrap_err();
    assert!(matches!(e, Error::NotPositive { .. }), "{e}");
    // Through the use case: the paths' errors, and the count's.
    let model = Model::new(&people_layout()).unwrap();
    let s = MultiSettings::default();
    let run = |w: Walkers| simulate_people(&model, &people_region(), w, 10, 0.1, 0.5, &s, 1);
    assert_eq!(size(run(Walkers::Drawn(vec![])).unwrap_err()), ("paths", 0));
    assert_eq!(
        size(run(Walkers::Drawn(vec![ok; 6])).unwrap_err()),
        ("paths", 6)
    );
    assert_eq!(size(run(Walkers::Count(6)).unwrap_err()), ("walkers", 6));
    assert_eq!(size(run(Walkers::Count(0)).unwrap_err()), ("walkers", 0));
    let e = run(Walkers::Drawn(far.to_vec())).unwrap_err();
    assert_eq!(field(e).as_deref(), Some("paths[0].y1"));
}
