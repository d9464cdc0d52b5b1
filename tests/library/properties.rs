#![cfg(not(target_arch = "wasm32"))]
//! Property tests (proptest) of the core against the spec: Tx↔Rx symmetry of (E1)/(E3), the
//! Fisher matrix of (E8) is symmetric PSD, LM (§5) recovers noise-free truth, the CRLB map has no
//! NaN, and the scenario JSON round-trips. Case counts are modest for debug-profile speed.

use proptest::prelude::*;

use scatterloc::localize::{self, chi_square_upper_tail, DelayMeasurements, LmConfig};
use scatterloc::localize::{crlb_at, crlb_map, fisher, Grid};
use scatterloc::math::{Real, Vec2};
use scatterloc::measure::Network;
use scatterloc::scenario::presets;
use scatterloc::scenario::{
    Area, LinkIndex, LinkSpec, Pattern, Radio, Receiver, Scenario, Target, Transmitter,
};
use scatterloc::Model;

use crate::common;

use common::noise_free;

fn coord() -> impl Strategy<Value = Real> {
    -30.0..30.0f64
}

fn point() -> impl Strategy<Value = Vec2> {
    (coord(), coord()).prop_map(|(x, y)| Vec2::new(x, y))
}

fn pattern() -> impl Strategy<Value = Pattern> {
    prop_oneof![
        Just(Pattern::Omni),
        (-180.0..180.0f64, 1.0..=360.0f64, 0.0..40.0f64).prop_map(|(b, w, f)| {
            Pattern::Parabolic {
                boresight_deg: b,
                beamwidth_deg: w,
                floor_db: f,
            }
        }),
    ]
}

fn radio() -> impl Strategy<Value = Radio> {
    (
        1e8..1e11f64,
        1e6..1e9f64,
        prop_oneof![
            Just((None, None)),
            (0.0..20.0f64).prop_map(|nf| (Some(nf), None)),
            (-130.0..-50.0f64).prop_map(|p| (None, Some(p))),
        ],
        proptest::option::of(0.0..30.0f64),
    )
        .prop_map(|(carrier_hz, bandwidth_hz, (nf, np), pg)| Radio {
            carrier_hz,
            bandwidth_hz,
            noise_figure_db: nf,
            noise_power_dbm: np,
            processing_gain_db: pg,
        })
}

/// A random valid scenario: 1–3 transmitters, 1–4 receivers, full mesh or an explicit subset.
fn scenario() -> impl Strategy<Value = Scenario> {
    (
        "[a-zA-Z0-9 _-]{0,12}",
        radio(),
        prop::collection::vec((point(), -10.0..50.0f64, -10.0..20.0f64, pattern()), 1..=3),
        prop::collection::vec((point(), -10.0..20.0f64), 1..=4),
        0.01..1000.0f64,
        (-60.0..0.0f64, 1.0..100.0f64, -60.0..0.0f64, 1.0..100.0f64),
        // Explicit link list: a non-empty random subset (as a bit mask) in shuffled order.
        proptest::option::of((1u32..4096, any::<u64>())),
    )
        .prop_map(|(name, radio, txs, rxs, rcs, (x0, w, y0, h), links)| {
            let transmitters: Vec<Transmitter> = txs
                .into_iter()
                .enumerate()
                .map(|(i, (p, power, gain, pattern))| Transmitter {
                    name: format!("Tx{i}"),
                    height_m: 0.0,
                    position_m: [p.x, p.y],
                    power_dbm: power,
                    gain_dbi: gain,
                    pattern,
                })
                .collect();
            let receivers: Vec<Receiver> = rxs
                .into_iter()
                .enumerate()
                .map(|(i, (p, gain))| Receiver {
                    name: format!("Rx{i}"),
                    height_m: 0.0,
                    position_m: [p.x, p.y],
                    gain_dbi: gain,
                })
                .collect();
            let links = match links {
                None => LinkSpec::All,
                Some((mask, shuffle)) => {
                    let mut pairs: Vec<[String; 2]> = Vec::new();
                    for (k, t) in transmitters.iter().enumerate() {
                        for (l, r) in receivers.iter().enumerate() {
                            if mask & (1 << (k * 4 + l)) != 0 {
                                pairs.push([t.name.clone(), r.name.clone()]);
                            }
                        }
                    }
                    if pairs.is_empty() {
                        pairs.push([transmitters[0].name.clone(), receivers[0].name.clone()]);
                    }
                    let n = pairs.len();
                    pairs.rotate_left((shuffle % n as u64) as usize);
                    LinkSpec::List(pairs)
                }
            };
            Scenario {
                name,
                radio,
                transmitters,
                receivers,
                links,
                target: Target {
                    rcs_m2: rcs,
                    height_m: 0.0,
                },
                area_m: Area {
                    x: [x0, x0 + w],
                    y: [y0, y0 + h],
                },
            }
        })
}

/// Random network geometry (positions and full-mesh links).
fn network() -> impl Strategy<Value = Network> {
    (
        prop::collection::vec(point(), 1..=3),
        prop::collection::vec(point(), 1..=4),
    )
        .prop_map(|(transmitters, receivers)| {
            let links = (0..receivers.len())
                .flat_map(|rx| (0..transmitters.len()).map(move |tx| LinkIndex { tx, rx }))
                .collect();
            Network {
                transmitters_dz: vec![0.0; transmitters.len()],
                receivers_dz: vec![0.0; receivers.len()],
                transmitters,
                receivers,
                links,
            }
        })
}

/// The same network with every transmitter turned into a receiver and vice versa.
fn swapped(net: &Network) -> Network {
    Network {
        transmitters: net.receivers.clone(),
        receivers: net.transmitters.clone(),
        transmitters_dz: net.receivers_dz.clone(),
        receivers_dz: net.transmitters_dz.clone(),
        links: net
            .links
            .iter()
            .map(|l| LinkIndex { tx: l.rx, rx: l.tx })
            .collect(),
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    /// (E1) and (E3) are symmetric in the two foci: swapping Tx and Rx roles changes nothing.
    #[test]
    fn delay_and_jacobian_symmetric_under_tx_rx_swap(net in network(), r in point()) {
        let sw = swapped(&net);
        for p in 0..net.link_count() {
            prop_assert_eq!(net.delay(p, r), sw.delay(p, r));
            prop_assert_eq!(net.jacobian_row(p, r), sw.jacobian_row(p, r));
            prop_assert_eq!(net.los_delay(p), sw.los_delay(p));
        }
    }

    /// With omni antennas the link budget (E8) is symmetric in the foci too
    /// (SNR ∝ 1/(d_Tx² d_Rx²)), so the Fisher matrix is unchanged by the swap.
    #[test]
    fn fisher_symmetric_under_tx_rx_swap_with_omni(a in point(), b in point(), r in point()) {
        let mut s = presets::iclgnss2019(); // omni Tx (spec §9.3: [I] case)
        s.receivers.truncate(1);
        s.transmitters[0].position_m = [a.x, a.y];
        s.receivers[0].position_m = [b.x, b.y];
        let mut t = s.clone();
        t.transmitters[0].position_m = [b.x, b.y];
        t.receivers[0].position_m = [a.x, a.y];
        let (ms, mt) = (Model::new(&s).unwrap(), Model::new(&t).unwrap());
        let (fs, ft) = (fisher(&ms, r), fisher(&mt, r));
        prop_assert!((fs - ft).norm() <= 1e-12 * fs.norm(), "{} vs {}", fs, ft);
        let (ss, st) = (ms.snr(0, r), mt.snr(0, r));
        prop_assert!((ss - st).abs() <= 1e-12 * ss);
    }

    /// F(r) = Jᵀ F_τ J (E8) is symmetric positive semi-definite.
    #[test]
    fn fisher_symmetric_psd(s in scenario(), r in point()) {
        let m = Model::new(&s).unwrap();
        let f = fisher(&m, r);
        prop_assert!(f.iter().all(|v| v.is_finite()), "{}", f);
        let tr = f.trace();
        prop_assert!(tr >= 0.0);
        // Symmetric up to the rounding of (w·g_x)·g_y vs (w·g_y)·g_x per link.
        prop_assert!(
            (f[(0, 1)] - f[(1, 0)]).abs() <= 1e-14 * tr,
            "asymmetric {}", f
        );
        let eig = f.symmetric_eigenvalues();
        prop_assert!(eig.iter().all(|l| *l >= -1e-12 * tr), "eigenvalues {:?}, trace {}", eig, tr);
        // The bound, when reported, is F⁻¹ (and finite).
        if let Some(b) = crlb_at(&m, r).bound {
            prop_assert!(b.rmse_m.is_finite() && b.rmse_m > 0.0);
            // ‖F·F⁻¹ − I‖ is limited by the condition number (≤ 1e12 by SINGULAR_RCOND).
            let cond = eig.max() / eig.min();
            let id = f * b.covariance_m2;
            let err = (id - scatterloc::Mat2::identity()).norm();
            prop_assert!(err < 1e-14 * cond + 1e-12, "F F^-1 = {}, cond {}", id, cond);
        }
    }

    /// The CRLB map never contains NaN (unbounded cells are +∞), also with nodes on cell centres.
    #[test]
    fn crlb_map_has_no_nan(
        s in scenario(),
        nx in 2usize..12,
        ny in 2usize..12,
        centre_on_node in any::<bool>(),
    ) {
        let mut s = s;
        if centre_on_node {
            // Odd sizes, area centred on the first receiver → a cell centre lands on it.
            let c = s.receivers[0].position_m;
            s.area_m = Area { x: [c[0] - 5.0, c[0] + 5.0], y: [c[1] - 3.0, c[1] + 3.0] };
        }
        let (nx, ny) = if centre_on_node { (nx | 1, ny | 1) } else { (nx, ny) };
        let m = Model::new(&s).unwrap();
        let grid = Grid::new(s.area_m, nx, ny).unwrap();
        let mut out = vec![Real::NAN; grid.len()];
        crlb_map(&m, &grid, &mut out).unwrap();
        for v in &out {
            prop_assert!(!v.is_nan());
            prop_assert!(*v > 0.0);
        }
    }

    /// Scenario JSON round trip: to_json → from_json gives back the same scenario.
    #[test]
    fn scenario_json_round_trip(s in scenario()) {
        prop_assert!(s.validate().is_ok());
        let back = Scenario::from_json(&s.to_json());
        prop_assert_eq!(back, Ok(s));
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 128, ..ProptestConfig::default() })]

    /// Spec check 8 / §5: noise-free delays and a start ≤ 3 m off → LM converges to the truth
    /// within 1e-6 m, for random points in the L4 area using 3 or 4 of its links — except near
    /// a node, where the expected outcome is asserted instead ([`check_lm_outcome`]).
    #[test]
    fn lm_noise_free_recovers_truth(
        x in -7.5..30.0f64,
        y in -10.0..26.0f64,
        radius in 0.0..=3.0f64,
        angle in 0.0..std::f64::consts::TAU,
        drop in 0usize..5,
    ) {
        check_lm_outcome(drop, Vec2::new(x, y), radius, angle)?;
    }

    /// The same near the nodes, where uniform points in the area rarely fall: truths within
    /// 3.2 m of a random node (the spurious-minimum zone of [`check_lm_outcome`] and a margin).
    #[test]
    fn lm_noise_free_near_a_node_recovers_truth_or_reports_a_plausible_minimum(
        node in 0usize..5,
        distance in 0.05..3.2f64,
        bearing in 0.0..std::f64::consts::TAU,
        radius in 0.0..=3.0f64,
        angle in 0.0..std::f64::consts::TAU,
        drop in 0usize..5,
    ) {
        let s = presets::sensors2019();
        let n = s.transmitters.iter().map(|t| t.position_m)
            .chain(s.receivers.iter().map(|r| r.position_m))
            .nth(node)
            .unwrap();
        let truth = Vec2::new(n[0], n[1]) + distance * Vec2::new(bearing.cos(), bearing.sin());
        prop_assume!((-7.5..30.0).contains(&truth.x) && (-10.0..26.0).contains(&truth.y));
        check_lm_outcome(drop, truth, radius, angle)?;
    }
}

/// LM on noise-free delays of `truth` in L4 (Rx `drop` left out when `drop < 4`), started
/// `radius` m off at `angle`. The expected outcome:
/// - always a converged termination (step or cost tolerance, or an exact fit);
/// - away from the nodes (≥ 1.6 m with 4 links, ≥ 3.0 m with 3), the truth within 1e-6 m
///   (spec check 8);
/// - nearer a node, the truth within 1e-6 m *or* a spurious local minimum whose cost is
///   statistically plausible: its χ²ₘ₋₂ upper tail is at least the restart threshold
///   (`LmConfig::restart_tail_probability`, 1e-3), so the restart rule, which repeats every
///   implausible fix from the grid search, correctly did not fire, and no test on the cost can
///   tell it from the truth.
///
/// The cost (E5) has genuine spurious local minima next to the nodes (see
/// `lm_spurious_local_minimum_near_a_receiver`). A scan of the L4 area (0.25 m grid of truths ×
/// 16 starts at 3 m, 350 320 pairs per link set) ended in one for ~1 % of pairs with plain LM;
/// with the restart and the grid multi-start (`LmConfig` defaults) for 0.058 % (4 links) /
/// 0.09–0.14 % (3 links), all with the truth within 1.52 m / 2.80 m of a node. 6000 random
/// pairs with the truth ≤ 3 m from a node per link set: 0.4 % (4 links) / 0.6–1.2 % (3 links)
/// spurious, every one converged and plausible (smallest tail 1.04e-3), truths ≤ 1.46 m /
/// 2.80 m from a node; ≈ 4 % were rescued by the restart.
fn check_lm_outcome(
    drop: usize,
    truth: Vec2,
    radius: Real,
    angle: Real,
) -> Result<(), TestCaseError> {
    let mut s = presets::sensors2019();
    if drop < 4 {
        // Explicit list of 3 links (Rx `drop` left out).
        s.links = LinkSpec::List(
            s.receivers
                .iter()
                .enumerate()
                .filter(|(l, _)| *l != drop)
                .map(|(_, r)| ["Tx".to_string(), r.name.clone()])
                .collect(),
        );
    }
    let m = Model::new(&s).unwrap();
    prop_assume!(crlb_at(&m, truth).bound.is_some());
    let keep_out = if drop < 4 { 3.0 } else { 1.6 };
    let near = s
        .transmitters
        .iter()
        .map(|t| t.position_m)
        .chain(s.receivers.iter().map(|r| r.position_m))
        .map(|n| (truth - Vec2::new(n[0], n[1])).norm())
        .fold(Real::INFINITY, Real::min);
    let (delays, sigmas) = noise_free(&m, truth);
    let meas = DelayMeasurements {
        delays_s: &delays,
        sigmas_s: &sigmas,
    };
    let start = truth + radius * Vec2::new(angle.cos(), angle.sin());
    let config = LmConfig::default();
    let rep = localize::locate(&m.network, &meas, &config, Some(start), &s.area_m).unwrap();
    let err = (rep.position - truth).norm();
    let tail = chi_square_upper_tail(m.link_count() - 2, rep.cost);
    let what = format!(
        "truth {truth:?} ({near:.2} m from a node), start {start:?}, links {}: error {err} m, \
         {:?} after {} it., cost {} (χ² tail {tail:e}), restarted {}",
        m.link_count(),
        rep.termination,
        rep.iterations,
        rep.cost,
        rep.restarted
    );
    prop_assert!(rep.termination.converged(), "{}", what);
    if err > 1e-6 {
        prop_assert!(
            near < keep_out,
            "spurious fix away from the nodes: {}",
            what
        );
        prop_assert!(
            tail >= config.restart_tail_probability.unwrap(),
            "spurious fix with an implausible cost: {}",
            what
        );
    }
    Ok(())
}

/// The counterexample proptest found for check 8 (3 links Tx–Rx1/Rx2/Rx4 of L4, truth 2.15 m
/// from Rx2, start 1.89 m off): LM stops at a point 2.6 m from the truth. This test pins down that
/// the core is not at fault — the stopping point is a genuine local minimum of (E5): the cost is
/// far above 0 (the noise-free global minimum) and rises in every direction.
#[test]
fn lm_spurious_local_minimum_near_a_receiver() {
    let mut s = presets::sensors2019();
    s.links = LinkSpec::List(
        ["Rx1", "Rx2", "Rx4"]
            .iter()
            .map(|r| ["Tx".to_string(), r.to_string()])
            .collect(),
    );
    let m = Model::new(&s).unwrap();
    let truth = Vec2::new(7.851613916740141, 9.832266393042653);
    let start = Vec2::new(9.700600236246107, 9.421372203574338);
    let (delays, sigmas) = noise_free(&m, truth);
    let meas = DelayMeasurements {
        delays_s: &delays,
        sigmas_s: &sigmas,
    };
    // Without the restart, LM stops in a genuine local minimum 2.6 m from the truth.
    let no_restart = LmConfig {
        restart_tail_probability: None,
        ..LmConfig::default()
    };
    let rep = localize::locate(&m.network, &meas, &no_restart, Some(start), &s.area_m).unwrap();
    let cost = |r: Vec2| -> Real {
        (0..m.link_count())
            .map(|p| ((m.network.delay(p, r) - m.network.delay(p, truth)) / sigmas[p]).powi(2))
            .sum()
    };
    assert!((rep.position - truth).norm() > 1.0, "{rep:?}");
    assert!(rep.cost > 1e3 && (rep.cost / cost(rep.position) - 1.0).abs() < 1e-9);
    for k in 0..16 {
        let a = k as Real * std::f64::consts::TAU / 16.0;
        let q = rep.position + 0.01 * Vec2::new(a.cos(), a.sin());
        assert!(
            cost(q) > rep.cost,
            "not a local minimum: lower cost toward {q:?}"
        );
    }
    // With the default restart the implausible cost (χ²₁ tail ≪ 1e-3) triggers the grid-search
    // start, which converges to the truth (§5, check 8).
    let rep = localize::locate(
        &m.network,
        &meas,
        &LmConfig::default(),
        Some(start),
        &s.area_m,
    )
    .unwrap();
    assert!(
        rep.restarted && (rep.position - truth).norm() <= 1e-6,
        "{rep:?}"
    );
    // From a start on the truth's side the same problem converges without a restart.
    let rep = localize::locate(
        &m.network,
        &meas,
        &LmConfig::default(),
        Some(truth + Vec2::new(-1.9, 0.4)),
        &s.area_m,
    )
    .unwrap();
    assert!(
        !rep.restarted && (rep.position - truth).norm() <= 1e-6,
        "{rep:?}"
    );
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    /// The calibration stage (spec §4) does not depend on the order of the snapshots nor of the
    /// estimates within one (bitwise: delays are sorted before any sum); its clusters are the
    /// spec's delay-only [choice] recomputed here from the definition (sort all delays, split
    /// where neighbours differ by more than g, keep the groups seen in ≥ 50 % of the snapshots,
    /// sample mean and σ floored at σ_min; 1e-12 relative); and a cluster gates exactly its
    /// 3σ̄ window (E4).
    #[test]
    fn calibration_is_order_free_and_gates_its_own_means(
        snaps in proptest::collection::vec(
            proptest::collection::vec(0.0..300e-9f64, 0..6), 1..40),
        seed in any::<u64>(),
    ) {
        use scatterloc::track::gating::{ClusterConfig, LinkCalibration};
        let cfg = ClusterConfig::for_bandwidth(120e6).unwrap();
        let a = LinkCalibration::from_snapshots(0, &snaps, &cfg).unwrap();
        // A deterministic shuffle of the snapshots and of each snapshot's estimates.
        let mut shuffled = snaps.clone();
        let mut s = seed | 1;
        let mut next = |n: usize| { s ^= s << 13; s ^= s >> 7; s ^= s << 17; (s % n as u64) as usize };
        for i in (1..shuffled.len()).rev() { let j = next(i + 1); shuffled.swap(i, j); }
        for v in &mut shuffled { for i in (1..v.len()).rev() { let j = next(i + 1); v.swap(i, j); } }
        let b = LinkCalibration::from_snapshots(0, &shuffled, &cfg).unwrap();
        prop_assert_eq!(&a, &b);
        let mut all: Vec<(Real, usize)> = snaps
            .iter()
            .enumerate()
            .flat_map(|(k, v)| v.iter().map(move |&d| (d, k)))
            .collect();
        all.sort_by(|p, q| p.0.total_cmp(&q.0));
        let mut want = Vec::new();
        for group in all.chunk_by(|p, q| q.0 - p.0 <= cfg.gap_s) {
            let mut seen: Vec<usize> = group.iter().map(|m| m.1).collect();
            seen.sort_unstable();
            seen.dedup();
            if 2 * seen.len() >= snaps.len() {
                let n = group.len() as Real;
                let mean = group.iter().map(|m| m.0).sum::<Real>() / n;
                let ss: Real = group.iter().map(|m| (m.0 - mean).powi(2)).sum();
                let sd = if group.len() > 1 { (ss / (n - 1.0)).sqrt() } else { 0.0 };
                want.push((mean, sd.max(cfg.sigma_floor_s), group.len(), seen.len()));
            }
        }
        prop_assert_eq!(a.clusters.len(), want.len(), "{:?} vs {:?}", &a.clusters, &want);
        for (c, w) in a.clusters.iter().zip(&want) {
            prop_assert_eq!((c.count, c.snapshots), (w.2, w.3));
            prop_assert!((c.mean_s - w.0).abs() <= 1e-12 * w.0.abs().max(1e-18), "{:?} vs {:?}", c, w);
            prop_assert!((c.sigma_s - w.1).abs() <= 1e-12 * w.1, "{:?} vs {:?}", c, w);
            prop_assert!(c.sigma_s >= cfg.sigma_floor_s);
            // E4: |τ − τ̄| ≤ 3σ̄, and no wider.
            for (k, inside) in [(-2.999, true), (2.999, true), (-3.001, false), (3.001, false)] {
                prop_assert_eq!(c.contains(c.mean_s + k * c.sigma_s), inside);
            }
        }
        for w in a.clusters.windows(2) {
            prop_assert!(w[1].mean_s - w[0].mean_s > cfg.gap_s);
        }
    }
}
