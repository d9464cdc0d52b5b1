//! A fix and a bound with a free height (issue 40 §2, "in 3-D where the user asks"): the
//! unknowns `[x, y, δz]`. The Fisher matrix against an independent reference with explicit 3-D
//! vectors, its planar block against the planar Fisher bitwise, the height's gradient against
//! central differences, the information inequality (height unknown ≥ height known), the
//! unobservable height of a planar network (unbounded, not NaN), the LM fix from noise-free
//! delays, its Monte Carlo error against the bound over several seeds (tolerances from the
//! standard error), and the iteration bound reached.

use rand::SeedableRng as _;
use rand_distr::{Distribution, StandardNormal};

use scatterloc::localize::{
    crlb_free_z, fisher, fisher_free_z, locate_free_z, DelayMeasurements, LmConfig, Termination,
};
use scatterloc::math::{Real, Vec2, Vec3, PI};
use scatterloc::measure::{node_distance, unit_from_dz, vertical_unit, Model};
use scatterloc::Error;

use super::{len, nodes_3d, points, random_3d, room, sub, unit, C, P3};

/// A room whose nodes are at four different heights (a ceiling Tx, receivers on a shelf, a
/// desk and the ceiling): the height is observable.
fn mixed_room() -> scatterloc::Scenario {
    room(
        [0.0, 2.0, 2.8],
        &[
            [6.0, 2.0, 0.8],
            [3.0, 4.0, 2.2],
            [3.0, 0.0, 2.8],
            [6.0, 4.0, 1.4],
        ],
        1.0,
    )
}

/// Independent 3-D delays of every link at `[x, y, z]`, s.
fn ref_delays(txs: &[P3], rxs: &[P3], m: &Model, p: P3) -> Vec<Option<Real>> {
    m.network
        .links
        .iter()
        .map(|l| Some((len(sub(p, txs[l.tx])) + len(sub(p, rxs[l.rx]))) / C))
        .collect()
}

/// The independent 3×3 Fisher matrix at `[x, y, z]` for omni antennas (the rooms of this file):
/// SNR from the 3-D distances floored at 1 m, `F = Σ 8π²β²SNR/c² · g gᵀ`, `g` the sum of the 3-D
/// unit vectors node → target.
fn ref_fisher(s: &scatterloc::Scenario, m: &Model, p: P3) -> [[Real; 3]; 3] {
    let (txs, rxs) = nodes_3d(s);
    let pn = 1.380649e-23 * 290.0 * s.radio.bandwidth_hz * 10f64.powf(7.0 / 10.0);
    let beta2 = s.radio.bandwidth_hz * s.radio.bandwidth_hz / 12.0;
    let f = s.radio.carrier_hz;
    let ptx = 10f64.powf((14.0 - 30.0) / 10.0);
    let g_ant = 10f64.powf(0.3);
    let mut out = [[0.0; 3]; 3];
    for l in &m.network.links {
        let (a, b) = (sub(p, txs[l.tx]), sub(p, rxs[l.rx]));
        let (la, lb) = (len(a), len(b));
        let (ft, fr) = (la.max(1.0), lb.max(1.0));
        let snr =
            ptx * g_ant * g_ant * C * C / ((4.0 * PI).powi(3) * f * f * ft * ft * fr * fr * pn);
        let g = [
            a[0] / la + b[0] / lb,
            a[1] / la + b[1] / lb,
            a[2] / la + b[2] / lb,
        ];
        let w = 8.0 * PI * PI * beta2 * snr / (C * C);
        for i in 0..3 {
            for j in 0..3 {
                out[i][j] += w * g[i] * g[j];
            }
        }
    }
    out
}

#[test]
fn free_z_fisher_matches_the_independent_3d_reference() {
    let mut checked = 0;
    for s in [mixed_room(), super::ceiling_room()] {
        let m = Model::new(&s).unwrap();
        let zt = s.target.height_m;
        for r in points(&s, 7) {
            for dz in [-0.6, 0.0, 0.45, 1.3] {
                let got = fisher_free_z(&m, r, dz);
                let want = ref_fisher(&s, &m, [r.x, r.y, zt + dz]);
                let scale = (0..3).map(|i| want[i][i]).fold(0.0, Real::max);
                for i in 0..3 {
                    for j in 0..3 {
                        let e = (got[(i, j)] - want[i][j]).abs() / scale;
                        assert!(
                            e < 1e-12,
                            "F[{i}][{j}] at {r:?}, δz {dz}: {} vs {}",
                            got[(i, j)],
                            want[i][j]
                        );
                    }
                }
                checked += 1;
            }
        }
    }
    assert_eq!(checked, 2 * 49 * 4);
}

#[test]
fn free_z_fisher_block_is_the_planar_fisher_bitwise() {
    let mut checked = 0;
    for seed in 0..12 {
        let s = random_3d(seed);
        let m = Model::new(&s).unwrap();
        for r in points(&s, 6) {
            let (f3, f2) = (fisher_free_z(&m, r, 0.0), fisher(&m, r));
            for (i, j) in [(0, 0), (0, 1), (1, 0), (1, 1)] {
                assert_eq!(
                    f3[(i, j)].to_bits(),
                    f2[(i, j)].to_bits(),
                    "seed {seed} at {r:?}"
                );
            }
            checked += 1;
        }
    }
    assert_eq!(checked, 12 * 36);
}

#[test]
fn the_heights_gradient_term_matches_central_differences() {
    // d/dδz √(‖r − n‖² + (dz − δz)²) = −(dz − δz)/d = vertical_unit(dz − δz, d). Central
    // differences with h = 1e-5 m have truncation error ≲ h²·|d'''| ≈ 1e-10/d² and rounding
    // ≈ 1e-16·d/h: 1e-8 absolute covers both for d ≥ 0.1 m.
    let mut st = 5u64;
    for _ in 0..2000 {
        let node = Vec2::new(unit(&mut st) * 10.0, unit(&mut st) * 10.0);
        let r = Vec2::new(unit(&mut st) * 10.0, unit(&mut st) * 10.0);
        let (dz, delta) = (unit(&mut st) * 3.0 - 0.5, unit(&mut st) * 2.0 - 1.0);
        let dist = |d: Real| node_distance(node, dz - d, r);
        let (_, d) = unit_from_dz(node, dz - delta, r);
        if d < 0.1 {
            continue;
        }
        let h = 1e-5;
        let fd = (dist(delta + h) - dist(delta - h)) / (2.0 * h);
        let got = vertical_unit(dz - delta, d);
        assert!((got - fd).abs() < 1e-8, "{got} vs {fd}");
    }
    // The zero vector where the unit vector is undefined (the target on the node).
    assert_eq!(vertical_unit(0.0, 0.0), 0.0);
}

#[test]
fn not_knowing_the_height_never_lowers_the_horizontal_bound() {
    // The information inequality: [F⁻¹]_xy ⪰ (F_xy)⁻¹ (the Schur complement), so the difference
    // of the 2×2 covariances is positive semidefinite and the horizontal RMSE can only grow.
    let mut checked = 0;
    for s in [
        mixed_room(),
        super::ceiling_room(),
        random_3d(4),
        random_3d(9),
    ] {
        let m = Model::new(&s).unwrap();
        for r in points(&s, 6) {
            for dz in [-0.4, 0.0, 0.8] {
                let pt = crlb_free_z(&m, r, dz);
                let Some(b3) = pt.bound else { continue };
                let f = pt.fisher_per_m2;
                let b2 = scatterloc::localize::bound_from_fisher(f[(0, 0)], f[(0, 1)], f[(1, 1)])
                    .expect("the planar block of a regular matrix is regular");
                let c3 = b3.covariance_m2;
                let c2 = b2.covariance_m2;
                let (a, b, c) = (
                    c3[(0, 0)] - c2[(0, 0)],
                    c3[(0, 1)] - c2[(0, 1)],
                    c3[(1, 1)] - c2[(1, 1)],
                );
                let tol = 1e-9 * (c3[(0, 0)] + c3[(1, 1)]);
                assert!(
                    a >= -tol && c >= -tol && a * c - b * b >= -tol * tol.max(a + c),
                    "{r:?}"
                );
                assert!(b3.rmse_m >= b2.rmse_m * (1.0 - 1e-12));
                assert!(b3.rmse_3d_m >= b3.rmse_m && b3.sigma_z_m > 0.0);
                checked += 1;
            }
        }
    }
    assert!(checked > 200, "{checked}");
}

#[test]
fn a_planar_network_leaves_the_height_unbounded_not_nan() {
    // Every node at the target's height: the height's gradient is 0 at δz = 0, F is singular.
    let s = room(
        [0.0, 2.0, 1.0],
        &[[6.0, 2.0, 1.0], [3.0, 4.0, 1.0], [3.0, 0.0, 1.0]],
        1.0,
    );
    let m = Model::new(&s).unwrap();
    let (txs, rxs) = nodes_3d(&s);
    for r in points(&s, 5) {
        let pt = crlb_free_z(&m, r, 0.0);
        assert!(pt.bound.is_none(), "{r:?}");
        assert_eq!(pt.fisher_per_m2[(2, 2)], 0.0);
        let delays = ref_delays(&txs, &rxs, &m, [r.x, r.y, 1.0]);
        let sig = m.sigma_delays(r);
        let meas = DelayMeasurements {
            delays_s: &delays,
            sigmas_s: &sig,
        };
        let fix = locate_free_z(&m.network, &meas, &LmConfig::default(), None, &s.area_m).unwrap();
        assert_eq!(fix.position.z, 0.0);
        assert!(fix.covariance_m2.is_none());
        assert!(fix.position.iter().all(|v| v.is_finite()) && fix.cost.is_finite());
    }
}

#[test]
fn the_free_height_fix_recovers_the_truth_from_noise_free_delays() {
    let cfg = LmConfig::default();
    let mut cases = 0;
    let all_ceiling = super::ceiling_room();
    for s in [mixed_room(), all_ceiling] {
        let m = Model::new(&s).unwrap();
        let (txs, rxs) = nodes_3d(&s);
        let zt = s.target.height_m;
        for r in points(&s, 4) {
            for z in [0.3, 1.0, 1.7] {
                let delays = ref_delays(&txs, &rxs, &m, [r.x, r.y, z]);
                let sig = m.sigma_delays(r);
                let meas = DelayMeasurements {
                    delays_s: &delays,
                    sigmas_s: &sig,
                };
                let truth = Vec3::new(r.x, r.y, z - zt);
                // The default start (the planar fix at the stated height) and two of the caller's.
                let starts = [
                    None,
                    Some(truth + Vec3::new(0.8, -0.5, 0.6)),
                    Some(truth + Vec3::new(-0.6, 0.4, -0.7)),
                ];
                for start in starts {
                    let fix = locate_free_z(&m.network, &meas, &cfg, start, &s.area_m).unwrap();
                    let err = (fix.position - truth).norm();
                    assert!(
                        err < 1e-6 && fix.termination.converged(),
                        "{}: truth {truth:?} from {start:?}: {:?} ({:?})",
                        s.name,
                        fix.position,
                        fix.termination
                    );
                    assert!(fix.covariance_m2.is_some());
                    cases += 1;
                }
            }
        }
    }
    assert_eq!(cases, 2 * 16 * 3 * 3);
}

#[test]
fn the_free_height_fix_meets_its_bound_over_seeds() {
    // Efficient at this SNR (σ of a few mm): per axis the mean squared error over N fixes is
    // σ²_CRLB · χ²_N/N, whose relative standard error is √(2/N); the bias is within
    // 4σ_CRLB/√N. N = 1500 per seed, three seeds, 4.5 standard errors.
    let s = mixed_room();
    let m = Model::new(&s).unwrap();
    let (txs, rxs) = nodes_3d(&s);
    let zt = s.target.height_m;
    let cfg = LmConfig::default();
    let n = 1500;
    for (seed, r) in [
        (1u64, Vec2::new(2.1, 1.3)),
        (2, Vec2::new(4.2, 2.7)),
        (3, Vec2::new(3.3, 1.9)),
    ] {
        let bound = crlb_free_z(&m, r, 0.0).bound.expect("observable");
        let clean = ref_delays(&txs, &rxs, &m, [r.x, r.y, zt]);
        let sig = m.sigma_delays(r);
        let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
        let (mut sq, mut sum) = ([0.0; 3], [0.0; 3]);
        for _ in 0..n {
            let noisy: Vec<Option<Real>> = clean
                .iter()
                .zip(&sig)
                .map(|(d, s)| {
                    let e: Real = StandardNormal.sample(&mut rng);
                    Some(d.unwrap() + s * e)
                })
                .collect();
            let meas = DelayMeasurements {
                delays_s: &noisy,
                sigmas_s: &sig,
            };
            let fix = locate_free_z(&m.network, &meas, &cfg, None, &s.area_m).unwrap();
            assert!(fix.termination.converged());
            let e = fix.position - Vec3::new(r.x, r.y, 0.0);
            for i in 0..3 {
                sq[i] += e[i] * e[i];
                sum[i] += e[i];
            }
        }
        let var = [
            bound.sigma_x_m.powi(2),
            bound.sigma_y_m.powi(2),
            bound.sigma_z_m.powi(2),
        ];
        let se = (2.0 / n as Real).sqrt();
        for i in 0..3 {
            let ratio = sq[i] / n as Real / var[i];
            assert!(
                (ratio - 1.0).abs() < 4.5 * se,
                "seed {seed} axis {i}: MSE/CRLB {ratio}"
            );
            let bias = sum[i] / n as Real;
            assert!(
                bias.abs() < 4.5 * var[i].sqrt() / (n as Real).sqrt(),
                "seed {seed} axis {i}: bias {bias}"
            );
        }
    }
}

#[test]
fn the_free_height_fix_stops_at_its_iteration_bound_and_names_bad_input() {
    let s = mixed_room();
    let m = Model::new(&s).unwrap();
    let (txs, rxs) = nodes_3d(&s);
    let r = Vec2::new(2.0, 1.5);
    let delays = ref_delays(&txs, &rxs, &m, [r.x, r.y, 1.3]);
    let sig = m.sigma_delays(r);
    let meas = DelayMeasurements {
        delays_s: &delays,
        sigmas_s: &sig,
    };
    let cfg = LmConfig {
        max_iterations: 1,
        restart_tail_probability: None,
        ..LmConfig::default()
    };
    let fix = locate_free_z(
        &m.network,
        &meas,
        &cfg,
        Some(Vec3::new(5.0, 3.5, -0.8)),
        &s.area_m,
    )
    .unwrap();
    assert_eq!(
        (fix.termination, fix.iterations),
        (Termination::MaxIterations, 1)
    );
    let bad = locate_free_z(
        &m.network,
        &meas,
        &LmConfig::default(),
        Some(Vec3::new(1.0, Real::NAN, 0.0)),
        &s.area_m,
    );
    assert!(matches!(bad, Err(Error::NonFinite { .. })), "{bad:?}");
    let few: Vec<Option<Real>> = delays
        .iter()
        .enumerate()
        .map(|(p, d)| if p < 2 { *d } else { None })
        .collect();
    let meas = DelayMeasurements {
        delays_s: &few,
        sigmas_s: &sig,
    };
    let err = locate_free_z(&m.network, &meas, &LmConfig::default(), None, &s.area_m);
    assert!(
        matches!(
            err,
            Err(Error::TooFewLinks {
                available: 2,
                required: 3
            })
        ),
        "{err:?}"
    );
}
