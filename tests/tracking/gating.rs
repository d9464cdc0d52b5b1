#![cfg(not(target_arch = "wasm32"))]
//! The calibration stage, 3σ gating and association (spec §4): spec check 12, the calibration
//! of a simulated static channel, and the EKF fed through gating and association on the
//! synthetic stand-in of the measurement case (spec §9.6: a 60 s loop through L4 with blind-zone
//! dropouts and delay noise from E8).
//!
//! Every tolerance is derived next to its assertion (binomial Monte Carlo error, the sampling
//! error of a calibrated σ̄); the runs are seeded, so each test is deterministic.

use scatterloc::math::{erfc, sqrt, Real, Vec2, Vec4};
use scatterloc::track::gating::StaticChannel;
use scatterloc::track::gating::{default_channel, LoopPath};
use scatterloc::track::gating::{select, AssociationRule, Choice};
use scatterloc::track::gating::{start_from_snapshot, GatedTracker, START_SPEED_SIGMA_MPS};
use scatterloc::track::gating::{Calibration, ClusterConfig, LinkCalibration, StaticCluster};
use scatterloc::track::paper_initial_covariance;
use scatterloc::track::{ConstantVelocity, Filter, FilterKind, Tracker};
use scatterloc::track::{Ekf, MeasurementNoise, PfConfig, UkfParams};
use scatterloc::{measure, scenario::presets};

use crate::common;

use common::sensors_model as model;

/// Spec check 12: the probability that a Gaussian static estimate falls within 3σ, 0.9973.
const P_GATE: Real = 0.9973;

fn bandwidth() -> Real {
    presets::sensors2019().radio.bandwidth_hz
}

/// The stand-in's static channel ([`default_channel`]: one reflector, 0.3 ns jitter) with
/// `false_alarms` per link and snapshot.
fn channel(false_alarms: Real) -> StaticChannel {
    default_channel(bandwidth(), false_alarms)
}

/// Check 12 in closed form and by Monte Carlo on a known cluster: `P(|τ − τ̄| ≤ 3σ̄) =
/// 1 − erfc(3/√2) = 0.99730020`. With n = 10⁶ draws the removed fraction's standard error is
/// √(p(1 − p)/n) = 5.2·10⁻⁵; the tolerance is 4 of them.
#[test]
fn check12_gating_removes_a_gaussian_static_estimate_with_probability_0_9973() {
    let exact = 1.0 - erfc(3.0 / sqrt(2.0));
    assert!((exact - P_GATE).abs() < 5e-5, "{exact}");
    let cluster = StaticCluster {
        mean_s: 50e-9,
        sigma_s: 0.3e-9,
        count: 1,
        snapshots: 1,
        amplitude_db_mean: None,
        amplitude_db_sigma: None,
    };
    let link = LinkCalibration::from_clusters(0, vec![cluster]).unwrap();
    let n = 1_000_000;
    let mut rng = measure::rng(12, 0);
    let removed = (0..n)
        .filter(|_| {
            link.is_static(cluster.mean_s + cluster.sigma_s * measure::standard_normal(&mut rng))
        })
        .count();
    let p = removed as Real / n as Real;
    let tol = 4.0 * sqrt(exact * (1.0 - exact) / n as Real);
    assert!(
        (p - exact).abs() <= tol,
        "removed {p}, expected {exact} ± {tol}"
    );
}

/// Check 12 end to end: cluster 2000 calibration snapshots of the empty area (4 links × 2 static
/// paths), then gate 50 000 further empty snapshots. The clusters are found with their means
/// and σ̄ to the sampling error (σ̄: relative SE 1/√(2·2000) = 1.6 %, 5 SE allowed), and the
/// removed fraction of the 4·10⁵ static estimates is 0.9973 within 1·10⁻³: binomial SE 8·10⁻⁵,
/// plus the effect of the σ̄ errors, 2·3·φ(3)·1.6 % = 4·10⁻⁴ per cluster, averaged over 8.
#[test]
fn check12_calibrated_clusters_gate_the_static_paths() {
    let model = model();
    let ch = channel(0.0);
    let cfg = ClusterConfig::for_bandwidth(bandwidth()).unwrap();
    let mut rng = measure::rng(12, 1);
    let cal = Calibration::from_snapshots(
        &ch.calibration_snapshots(&model, 2000, &mut rng),
        model.link_count(),
        &cfg,
    )
    .unwrap();
    for p in 0..model.link_count() {
        let statics = ch.static_delays(&model, p);
        let c = &cal.links[p].clusters;
        assert_eq!(c.len(), statics.len(), "link {p}: {c:?}");
        for (c, s) in c.iter().zip(&statics) {
            assert_eq!((c.count, c.snapshots), (2000, 2000));
            assert!(
                (c.mean_s - s).abs() < 5.0 * ch.static_sigma_s / sqrt(2000.0),
                "{c:?} vs {s}"
            );
            assert!(
                (c.sigma_s / ch.static_sigma_s - 1.0).abs() < 5.0 / sqrt(4000.0),
                "{c:?}"
            );
        }
    }
    let (mut total, mut removed) = (0usize, 0usize);
    for _ in 0..50_000 {
        let snap = ch.snapshot(&model, None, &mut rng);
        let s = select(&cal, &snap, None, AssociationRule::Spec).unwrap();
        total += snap.iter().map(Vec::len).sum::<usize>();
        removed += s.static_removed.iter().sum::<usize>();
    }
    let p = removed as Real / total as Real;
    assert_eq!(total, 400_000);
    assert!((p - P_GATE).abs() < 1e-3, "removed fraction {p}");
}

fn circle(t: Real) -> Vec4 {
    LoopPath::default().state_at(t)
}

/// What [`run_loop`] counted.
#[derive(Debug)]
struct LoopStats {
    /// (step, link) pairs whose echo is resolved from every static path.
    resolved: usize,
    /// Of those, the pairs where association took the echo (within 6 σ_p of the true delay).
    echo_taken: usize,
    /// (step, link) pairs whose echo lies in a blind zone (not resolved).
    unresolved: usize,
    /// Of those, the pairs left without a measurement.
    dropped: usize,
    /// Static paths of the links over those pairs (the estimates that could leak in).
    unresolved_static_paths: usize,
    /// Steps whose position error is inside the filter's 99.9 % χ²(2) ellipse (13.8).
    consistent: usize,
    /// Largest position error after the first second, m.
    worst_after_1s_m: Real,
    /// RMS position error after the first second, m.
    rms_after_1s_m: Real,
}

const LOOP_STEPS: usize = 600;

impl LoopStats {
    /// The tracking bounds shared by the loop tests, each a claim about every seed:
    /// - the echo taken at ≥ 99.2 % of the resolved pairs. A resolved echo is missed when noise
    ///   or a false alarm inside the innovation gate wins the association; pooled over seeds
    ///   1–8 the three gated loop tests miss 52 of 44 712 resolved pairs (p̂ = 0.12 %; the worst
    ///   run, seed 7 with false alarms, 11 of 1863). With p = 0.12 % a run's 1863 pairs give 2.2
    ///   misses, binomial SE 1.5; 99.2 % allows 14, 8 SE above the mean, leaving room for the
    ///   clustering of misses in time (one perturbed step misses several links) that makes the
    ///   count over-dispersed;
    /// - the error inside the filter's 99.9 % ellipse at ≥ 98 % of the steps (a consistent filter
    ///   leaves 0.1 %, 0.6 of 600 steps; 12 allowed; seeds 1–8: 0 to 6 outside);
    /// - a divergence guard: the error stays below 0.5 m after the first second. The CRLB along
    ///   the loop is a few mm to cm, more where links drop out; tracked runs reach 0.09–0.26 m
    ///   (seeds 1–8, the maximum over 590 steps including the blind zones), lost ones ≥ 1 m.
    fn assert_tracked(&self) {
        let st = self;
        assert!(
            st.echo_taken as Real >= 0.992 * st.resolved as Real,
            "{st:?}"
        );
        assert!(st.consistent as Real >= 0.98 * LOOP_STEPS as Real, "{st:?}");
        assert!(st.worst_after_1s_m < 0.5, "{st:?}");
    }
}

/// Seeds of the loop tests (fixed in advance, not picked from results; the old tests used 96–98).
const LOOP_SEEDS: std::ops::RangeInclusive<u64> = 1..=8;

/// Spec §9.6 synthetic stand-in: 60 s on the loop at T = 0.1 s (600 snapshots) with the static
/// paths of [`channel`] and `false_alarms` per link and snapshot, after a calibration of 500
/// snapshots of the empty area (without false alarms: see the calibration module on why). The
/// EKF (CV, q̃ = 0.1 m²/s³: the loop's 0.245 m/s² centripetal acceleration is a manoeuvre the
/// spec's q̃ = 0.01 for a near-straight walk does not cover) starts at the truth with P(t₀) of
/// §9.5, σ_p from the link budget at the prediction.
fn run_loop(false_alarms: Real, rule: AssociationRule, seed: u64) -> LoopStats {
    run_loop_from(false_alarms, rule, seed, false)
}

/// [`run_loop`]; with `lm_start` the filter starts from an LM fix of the snapshot at t₀ (spec
/// §9.6, "LM at t₀ = 0"; no track yet: the largest amplitude per link) instead of the truth.
fn run_loop_from(
    false_alarms: Real,
    rule: AssociationRule,
    seed: u64,
    lm_start: bool,
) -> LoopStats {
    run_loop_with(FilterKind::Ekf, false_alarms, rule, seed, lm_start)
}

/// [`run_loop_from`] with any filter of the seam behind the gating (a [`Tracker`] of `kind`
/// started where the EKF would be; the particle filter's own stream is stream 7 of `seed`).
fn run_loop_with(
    kind: FilterKind,
    false_alarms: Real,
    rule: AssociationRule,
    seed: u64,
    lm_start: bool,
) -> LoopStats {
    let model = model();
    let cfg = ClusterConfig::for_bandwidth(bandwidth()).unwrap();
    let mut rng = measure::rng(seed, 0);
    let snaps = channel(0.0).calibration_snapshots(&model, 500, &mut rng);
    let cal = Calibration::from_snapshots(&snaps, model.link_count(), &cfg).unwrap();
    let ch = channel(false_alarms);
    let dt = 0.1;
    let motion = ConstantVelocity::validated(dt, 0.1).unwrap();
    let ekf = if lm_start {
        let r0 = Vec2::new(circle(0.0)[0], circle(0.0)[1]);
        let snap = ch.snapshot(&model, Some(r0), &mut rng);
        let area = presets::sensors2019().area_m;
        let start = start_from_snapshot(&model, &cal, &snap, &area, START_SPEED_SIGMA_MPS).unwrap();
        // The fix is consistent with its covariance (inside the 99.9 % χ²(2) ellipse).
        let e = start.report.position - r0;
        let c = start.report.covariance_m2.unwrap();
        assert!(
            (e.transpose() * c.try_inverse().unwrap() * e)[0] <= 13.8,
            "{e:?} vs {c:?}"
        );
        assert!(start
            .selection
            .choices
            .iter()
            .all(|c| *c == Choice::Strongest || *c == Choice::Single));
        start.ekf
    } else {
        Ekf::new(circle(0.0), paper_initial_covariance()).unwrap()
    };
    let noise = MeasurementNoise::AtPrediction;
    let filter = Tracker::new(kind, ekf.state, ekf.covariance, measure::rng(seed, 7)).unwrap();
    let mut tracker = GatedTracker::new(filter, &model, &cal, motion, noise, rule).unwrap();
    let mut st = LoopStats {
        resolved: 0,
        echo_taken: 0,
        unresolved: 0,
        dropped: 0,
        unresolved_static_paths: 0,
        consistent: 0,
        worst_after_1s_m: 0.0,
        rms_after_1s_m: 0.0,
    };
    let mut sum_sq = (0.0, 0usize);
    for k in 1..=LOOP_STEPS {
        let truth = circle(k as Real * dt);
        let r = Vec2::new(truth[0], truth[1]);
        let snap = ch.snapshot(&model, Some(r), &mut rng);
        let step = tracker.step(&snap).unwrap();
        for p in 0..model.link_count() {
            let tau = model.network.delay(p, r);
            let sigma = model.sigma_delay(p, r);
            if ch.resolved(&model, p, tau) {
                st.resolved += 1;
                if step.selection.delays[p].is_some_and(|d| (d - tau).abs() <= 6.0 * sigma) {
                    st.echo_taken += 1;
                }
            } else {
                st.unresolved += 1;
                st.unresolved_static_paths += ch.static_delays(&model, p).len();
                if step.selection.choices[p] == Choice::Absent {
                    st.dropped += 1;
                }
            }
        }
        let e = tracker.filter.position() - r;
        let p_rr = tracker
            .filter
            .covariance()
            .fixed_view::<2, 2>(0, 0)
            .into_owned();
        if (e.transpose() * p_rr.try_inverse().unwrap() * e)[0] <= 13.8 {
            st.consistent += 1;
        }
        if k as Real * dt > 1.0 {
            st.worst_after_1s_m = st.worst_after_1s_m.max(e.norm());
            sum_sq = (sum_sq.0 + e.norm_squared(), sum_sq.1 + 1);
        }
    }
    st.rms_after_1s_m = (sum_sq.0 / sum_sq.1 as Real).sqrt();
    println!(
        "{} {rule:?}, {false_alarms} false alarms per link and snapshot, LM start {lm_start}: {st:?}",
        kind.name()
    );
    st
}

/// The loop under the gated rule without false alarms, seeds 1–8: blind-zone pairs drop out
/// (≥ 99 %: only a static estimate that leaked through the 3σ gate, 0.27 % each by check 12,
/// and fell inside the innovation gate could stand in; seeds 1–8 keep 0 or 1 of 537); the loop
/// does cross blind zones (the Tx–Rx2 baseline's among them); and the bounds of
/// [`LoopStats::assert_tracked`] hold.
#[test]
fn gated_ekf_tracks_the_loop_through_blind_zones() {
    for seed in LOOP_SEEDS {
        let st = run_loop(0.0, AssociationRule::Gated, seed);
        assert!(st.unresolved > 0, "{st:?}");
        assert!(st.dropped as Real >= 0.99 * st.unresolved as Real, "{st:?}");
        st.assert_tracked();
    }
}

/// With 0.5 false alarms per link and snapshot the gated rule keeps the track (bounds as above;
/// blind-zone pairs drop out unless a false alarm falls inside the innovation gate: ≥ 90 %,
/// seeds 1–8 drop ≥ 534 of 537), while the spec's rule, which takes a lone candidate however
/// far from the prediction, loses it (an error of metres) for every seed: a blind-zone pair has
/// a false alarm as its lone candidate with probability 1 − e^(−0.5) = 39 %, ≈ 200 wild updates
/// per run (seeds 1–8: worst errors 44 m to 7.9 km).
///
/// Without false alarms the spec's rule takes a static estimate that leaked through the 3σ
/// gate (0.27 % each, check 12) whenever its link's echo is in a blind zone. The number of such
/// leaks is a count of rare independent events: Poisson with mean `λ = 0.0027 · Σ (static paths
/// of the link)` over the blind-zone pairs (≈ 2.9 per run, 23 over the 8 seeds); pooled over the
/// seeds it must lie within λ ± 4.5 √λ (seeds 1–8: 4, 4, 4, 3, 2, 6, 4, 4, total 31). Whether a
/// leak loses the track depends on how far the static path is from the echo (up to the
/// resolution, 2.5 m of range), so the claim per seed is not "the track is lost" (a seed with no
/// leak, probability e^(−2.9) ≈ 5 %, keeps it); asserted is that the spec rule's track is lost
/// (> 1 m) in most seeds (≥ 5 of 8; seeds 1–8: all 8, worst errors 1.05 m to 164 m).
#[test]
fn gated_association_survives_false_alarms_and_leaks_where_the_spec_rule_does_not() {
    let (mut leaks, mut expected, mut lost) = (0usize, 0.0, 0usize);
    for seed in LOOP_SEEDS {
        let st = run_loop(0.5, AssociationRule::Gated, seed);
        assert!(
            st.unresolved > 0 && st.dropped as Real >= 0.9 * st.unresolved as Real,
            "{st:?}"
        );
        st.assert_tracked();
        let spec = run_loop(0.5, AssociationRule::Spec, seed);
        assert!(spec.worst_after_1s_m > 1.0, "seed {seed}: {spec:?}");
        let leak = run_loop(0.0, AssociationRule::Spec, seed);
        leaks += leak.unresolved - leak.dropped;
        expected += (1.0 - P_GATE) * leak.unresolved_static_paths as Real;
        if leak.worst_after_1s_m > 1.0 {
            lost += 1;
        }
    }
    let tol = 4.5 * expected.sqrt();
    assert!(
        (leaks as Real - expected).abs() <= tol,
        "{leaks} leaks, expected {expected:.1} ± {tol:.1}"
    );
    assert!(lost >= 5, "spec rule lost the track in {lost} of 8 seeds");
}

/// The measurement case as spec §9.6 runs it: no track yet, so the snapshot at t₀ is gated,
/// each link takes its strongest remaining estimate (the echo, √SNR ≫ the false alarms' 1), LM
/// fixes the start (consistent with its covariance, checked in `run_loop_from`) and the gated
/// EKF, started at rest with σ_v = 2 m/s per component, locks on within the first second and
/// then meets the bounds of the truth-started runs, with false alarms, for seeds 1–8.
#[test]
fn lm_started_gated_track_meets_the_same_bounds() {
    for seed in LOOP_SEEDS {
        run_loop_from(0.5, AssociationRule::Gated, seed, true).assert_tracked();
    }
}

/// The prediction the association gates on is the filter's own: for every link, an update with
/// that link alone has NIS `νᵀS⁻¹ν = (ν/√S_pp)²` (the batch update's S for one row, spec §6),
/// to 1e-9 relative, at several states along the loop with P(t₀) of §9.5.
#[test]
fn predicted_delay_and_innovation_sigma_match_a_single_link_update() {
    let model = model();
    for t in [0.0, 7.0, 21.0, 33.0] {
        let ekf = Ekf::new(circle(t), paper_initial_covariance()).unwrap();
        let pred = ekf
            .predicted_delays(&model, MeasurementNoise::AtPrediction)
            .unwrap();
        for (p, pr) in pred.iter().enumerate() {
            assert_eq!(pr.delay_s, model.network.delay(p, ekf.position()));
            let z_val = pr.delay_s + 2.5 * pr.innovation_sigma_s;
            let mut z = vec![None; model.link_count()];
            z[p] = Some(z_val);
            let mut f = ekf;
            let s = f
                .update(&model, &z, MeasurementNoise::AtPrediction, None)
                .unwrap();
            let want = pr.normalized_innovation(z_val).powi(2);
            assert!(
                (s.nis / want - 1.0).abs() < 1e-9,
                "t {t} link {p}: {} vs {want}",
                s.nis
            );
        }
    }
    // A bad σ is named.
    let ekf = Ekf::new(circle(0.0), paper_initial_covariance()).unwrap();
    let e = ekf
        .predicted_delays(&model, MeasurementNoise::Fixed(&[1e-10, 0.0, 1e-10, 1e-10]))
        .unwrap_err();
    assert_eq!(
        e,
        scatterloc::Error::InvalidSigma {
            link: 1,
            value: 0.0
        }
    );
}

/// The filters of the seam behind the same gating (issue 23): the §9.6 stand-in with 0.5
/// false alarms per link and snapshot under the gated rule, tracked by the EKF, the UKF and the
/// particle filter (1000 particles), each gating and associating on its own predicted delays
/// and innovation σ, seeds 1–4 (fixed in advance), truth and LM starts. Each meets the EKF's
/// bounds ([`LoopStats::assert_tracked`]), and the UKF's and PF's RMS position error after the
/// first second is at most 1.25 × the EKF's. Why 1.25: the measurement model is nearly linear
/// over the filter's spread (σ of a few cm against ranges of metres), so the UKF's and the
/// EKF's estimates differ to second order; the PF adds its Monte Carlo variance `P/N_eff`,
/// with `N_eff ≥ N/2 = 500` a factor `√(1 + 1/500)` on the RMS. What remains is a different
/// association in a few steps; measured (seeds 1–4, both starts): EKF 0.026–0.032 m, UKF within
/// 0.5 % of it, PF within 2 % (0.98–1.02×); 1.25 is 12 times that spread.
#[test]
fn every_filter_keeps_the_gated_track() {
    let kinds = [
        FilterKind::Ekf,
        FilterKind::Ukf(UkfParams::default()),
        FilterKind::Pf(PfConfig::default()),
    ];
    for seed in 1..=4 {
        for lm_start in [false, true] {
            let [ekf, ukf, pf] =
                kinds.map(|k| run_loop_with(k, 0.5, AssociationRule::Gated, seed, lm_start));
            println!(
                "seed {seed}, LM start {lm_start}: RMS after 1 s ekf {:.4} ukf {:.4} pf {:.4} m",
                ekf.rms_after_1s_m, ukf.rms_after_1s_m, pf.rms_after_1s_m
            );
            for st in [&ekf, &ukf, &pf] {
                st.assert_tracked();
            }
            for st in [&ukf, &pf] {
                assert!(
                    st.rms_after_1s_m <= 1.25 * ekf.rms_after_1s_m,
                    "seed {seed}: {st:?} vs the EKF's {ekf:?}"
                );
            }
        }
    }
}

/// The predicted delays the gating reads, filter against filter, at states along the loop with
/// P(t₀) = diag(0.1 m², 0.1 m², …) of §9.5 (position σ 0.32 m): the UKF's sigma-point `ẑ_p`,
/// `√S_pp` and the PF's weighted-particle ones (N = 100 000) against the EKF's Jacobian values
/// (E3). Tolerances, in units of the EKF's `√S_pp`:
/// - UKF − EKF mean ≤ 0.1: the range is convex, and the UT's mean carries the curvature term
///   `½ tr(∇²h P)` the linearisation drops (measured 0.006–0.070); UKF and PF σ within 2 % of
///   the EKF's (measured ≤ 0.96 % and ≤ 0.26 %: third-order terms);
/// - PF − UKF mean ≤ 4 standard errors of a weighted mean of N particles, `4/√N` = 0.013 (the
///   PF sees the same curvature; measured ≤ 0.006).
#[test]
fn every_filter_predicts_the_delays_the_ekf_does() {
    let model = model();
    let noise = MeasurementNoise::AtPrediction;
    let n = 100_000;
    for t in [0.0, 7.0, 21.0, 33.0] {
        let (x, p) = (circle(t), paper_initial_covariance());
        let ekf = Ekf::new(x, p)
            .unwrap()
            .predicted_delays(&model, noise)
            .unwrap();
        let ukf = Tracker::new(
            FilterKind::Ukf(UkfParams::default()),
            x,
            p,
            measure::rng(1, 0),
        )
        .unwrap()
        .predicted_delays(&model, noise)
        .unwrap();
        let pf_kind = FilterKind::Pf(PfConfig {
            particles: n,
            roughening: None,
            regularized: true,
        });
        let pf = Tracker::new(pf_kind, x, p, measure::rng(2, 0))
            .unwrap()
            .predicted_delays(&model, noise)
            .unwrap();
        for link in 0..model.link_count() {
            let (e, u, q) = (ekf[link], ukf[link], pf[link]);
            let sigma = e.innovation_sigma_s;
            let what = format!("t {t} link {link}: ekf {e:?} ukf {u:?} pf {q:?}");
            assert!((u.delay_s - e.delay_s).abs() <= 0.1 * sigma, "{what}");
            assert!(
                (q.delay_s - u.delay_s).abs() <= 4.0 / (n as Real).sqrt() * sigma,
                "{what}"
            );
            for s in [u.innovation_sigma_s, q.innovation_sigma_s] {
                assert!((s / sigma - 1.0).abs() <= 0.02, "{what}");
            }
        }
    }
}
