//! The cost model: a study's predicted CPU time, a track's, and the caps.

use alloc::string::ToString;

use super::*;
use crate::track::{FilterKind, PfConfig, UkfParams};

#[test]
fn predicted_cost_is_runs_times_steps_times_the_step_cost() {
    use crate::track::step_ns;
    let links = model().link_count();
    let pf = PfConfig {
        particles: 1000,
        roughening: None,
        regularized: true,
    };
    let cfg = config(40, 3, 50, 1);
    // The particle filter held to 1 chunk of the 3 (16 × 3 runs × 50 steps × 1000 ≤ 2.4e6).
    let s =
        FilterStudy::with_particle_budget(cfg, &[FilterKind::Ekf, FilterKind::Pf(pf)], 2_400_000)
            .unwrap();
    let ekf = 120.0 * 50.0 * step_ns(FilterKind::Ekf, links) * 1e-9;
    let pf_s = 48.0 * 50.0 * step_ns(FilterKind::Pf(pf), links) * 1e-9;
    let got = s.predicted_cpu_s(links, &(0..3));
    assert!((got - (ekf + pf_s)).abs() <= 1e-12 * got, "{got}");
    // A shard's chunks only: chunk 2 holds 8 trajectories, and no PF chunk.
    let shard = s.predicted_cpu_s(links, &(2..3));
    assert!((shard - 24.0 * 50.0 * step_ns(FilterKind::Ekf, links) * 1e-9).abs() <= 1e-15);
    // The model's large-link terms (docs/benchmarks.md "Cost model"): a 4096-link UKF step
    // ≈ 16 s (16 s measured in issue 24), a 1024-link one ≈ 0.25 s (measured 0.25 s).
    let ukf = FilterKind::Ukf(UkfParams::default());
    assert!((15.0e9..17.5e9).contains(&step_ns(ukf, 4096)));
    assert!((0.2e9..0.3e9).contains(&step_ns(ukf, 1024)));
    // The page (issue 24): a UKF or PF track on a 64 × 64 mesh is refused on its main thread
    // from the first step; its default tracks on sensors2019 (100 steps; the PF 1000
    // particles) are not.
    let pf1000 = FilterKind::Pf(pf);
    assert!(track_cpu_s(ukf, 4096, 1) > PAGE_TRACK_CPU_S);
    assert!(track_cpu_s(pf1000, 4096, 1) > PAGE_TRACK_CPU_S);
    for kind in [FilterKind::Ekf, ukf, pf1000] {
        assert!(track_cpu_s(kind, links, 100) < 0.01 * PAGE_TRACK_CPU_S);
    }
    // The cap: a named error with both times.
    let e = check_cost("runs", 90_000.0, MAX_CPU_S).unwrap_err();
    assert_eq!(e.field(), Some("runs"));
    assert!(
        e.to_string()
            .contains("90000 s of CPU time, over the cap of 86400 s"),
        "{e}"
    );
    assert!(check_cost("runs", MAX_CPU_S, MAX_CPU_S).is_ok());
}

/// With range rates (issue 42 §3) the UKF and the particle filter cost what `2L` measurement rows
/// cost, and the EKF its own calibration: 250 ns on sensors2019's 4 links, the criterion bench's
/// step (docs/benchmarks.md, "EKF step with Doppler"), twice and a bit the delay-only step.
#[test]
fn a_track_with_range_rates_costs_its_rows() {
    use crate::track::{step_ns, step_ns_doppler};
    let ukf = FilterKind::Ukf(UkfParams::default());
    let pf = FilterKind::Pf(PfConfig {
        particles: 500,
        roughening: None,
        regularized: true,
    });
    for links in [1, 4, 64, 1024] {
        for kind in [ukf, pf] {
            assert_eq!(step_ns_doppler(kind, links), step_ns(kind, 2 * links));
            let (a, b) = (
                track_doppler_cpu_s(kind, links, 100),
                track_cpu_s(kind, 2 * links, 100),
            );
            assert!((a - b).abs() <= 1e-15 * b, "{a} vs {b}");
        }
        let (d, r) = (
            step_ns_doppler(FilterKind::Ekf, links),
            step_ns(FilterKind::Ekf, links),
        );
        assert!(d > 1.5 * r, "{links} links: {d} vs {r}");
    }
    assert_eq!(step_ns_doppler(FilterKind::Ekf, 4), 250.0);
}
