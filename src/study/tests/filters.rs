//! The filter study: drivers, work items and shards give the same sums; the lead and widest
//! rules; the particle budget; a run cancelled inside its steps; a filter failing every run.

use alloc::string::ToString;

use super::*;
use crate::math::Shard;
use crate::track::{FilterKind, PfConfig, UkfParams};

#[test]
fn work_items_ranges_and_shards_give_the_same_sums() {
    let m = model();
    for seed in [1, 2, 3] {
        let cfg = config(40, 2, 6, seed);
        let kinds = [FilterKind::Ukf(UkfParams::default()), FilterKind::Ekf, PF];
        // Page order: chunk by chunk, the filters interleaved, two items per call.
        let mut items = FilterStudy::new(cfg, &kinds).unwrap();
        while !items.run_items(&m, 2).unwrap() {}
        // CLI order: filter by filter, the whole range.
        let mut whole = FilterStudy::new(cfg, &kinds).unwrap();
        whole
            .run_range(
                &m,
                0..cfg.chunk_count(),
                &mut Sequential::new(),
                &mut |_, _| {},
            )
            .unwrap();
        assert_eq!(items.sums(), whole.sums());
        // Three shards merged.
        let mut merged = FilterStudy::new(cfg, &kinds).unwrap();
        for i in 0..3 {
            let r = Shard::new(i, 3).unwrap().range(cfg.chunk_count());
            let mut part = FilterStudy::new(cfg, &kinds).unwrap();
            part.run_range(&m, r.clone(), &mut Sequential::new(), &mut |_, _| {})
                .unwrap();
            for (f, s) in part.sums().iter().enumerate() {
                merged.add_sums(f, s, r.len());
            }
        }
        assert_eq!(merged.sums(), whole.sums());
        assert_eq!(merged.results().unwrap(), whole.results().unwrap());
        // The EKF of the list is the EKF study alone.
        let mut ekf = FilterStudy::new(cfg, &[FilterKind::Ekf]).unwrap();
        ekf.run_items(&m, usize::MAX).unwrap();
        assert_eq!(ekf.sums()[0], whole.sums()[1]);
    }
}

#[cfg(all(feature = "parallel", not(target_arch = "wasm32")))]
#[test]
fn parallel_driver_equals_sequential() {
    use core::sync::atomic::AtomicBool;
    let m = model();
    let cfg = config(70, 2, 5, 9);
    let kinds = [FilterKind::Ekf, FilterKind::Ukf(UkfParams::default())];
    let cancel = AtomicBool::new(false);
    let mut seq = FilterStudy::new(cfg, &kinds).unwrap();
    seq.run_range(&m, 1..5, &mut Sequential::new(), &mut |_, _| {})
        .unwrap();
    for threads in [1, 2, 3] {
        let mut par = FilterStudy::new(cfg, &kinds).unwrap();
        let mut last = (0, 0);
        par.run_range(
            &m,
            1..5,
            &mut crate::native::Parallel::new(threads, &cancel),
            &mut |d, t| last = (d, t),
        )
        .unwrap();
        assert_eq!(par.sums(), seq.sums());
        // Progress ends at every run of both filters: chunks 1..5 are trajectories 16..70,
        // 2 filters × 54 trajectories × 2 noise runs.
        assert_eq!(last, (216, 216));
    }
}

#[test]
fn lead_is_the_ekf_else_the_first_and_the_bound_comes_from_the_widest() {
    let m = model();
    let cfg = config(48, 1, 4, 5);
    let ukf = FilterKind::Ukf(UkfParams::default());
    let lead = |kinds: &[FilterKind]| {
        let mut s = FilterStudy::new(cfg, kinds).unwrap();
        s.run_items(&m, usize::MAX).unwrap();
        let r = s.results().unwrap();
        (kinds[r.curves[r.lead].0].name(), r)
    };
    assert_eq!(lead(&[ukf, FilterKind::Ekf]).0, "ekf");
    assert_eq!(lead(&[ukf, PF]).0, "ukf");
    // The particle filter held to one chunk of three: it leads alone, the widest is the UKF,
    // whose bound (48 trajectories) the top-level curves carry.
    let budget = 16 * 4 * 40; // one chunk's runs × steps × particles
    let mut s = FilterStudy::with_particle_budget(cfg, &[PF, ukf], budget).unwrap();
    assert_eq!(s.filters()[0].chunks, 1);
    assert_eq!(s.filters()[0].runs_planned(&cfg), 16);
    assert_eq!(s.item_count(), 4);
    s.run_items(&m, usize::MAX).unwrap();
    let r = s.results().unwrap();
    assert_eq!((r.lead, r.widest), (0, 1));
    let top = r.top();
    assert_eq!(top.rmse_m, r.curves[0].1.rmse_m);
    assert_eq!(top.rmse_pcrlb_m, r.curves[1].1.rmse_pcrlb_m);
    assert_ne!(r.curves[0].1.rmse_pcrlb_m, r.curves[1].1.rmse_pcrlb_m);
}

#[test]
fn particle_chunks_is_the_whole_chunks_that_fit() {
    // 100 trajectories = 7 chunks; a chunk is 16 × 2 runs of 10 steps × 100 particles.
    let cfg = config(100, 2, 10, 1);
    let chunk = 16 * 2 * 10 * 100;
    for (budget, want) in [
        (0, 1),
        (chunk - 1, 1),
        (chunk, 1),
        (3 * chunk, 3),
        (3 * chunk + chunk / 2, 3),
        (7 * chunk, 7),
        (usize::MAX, 7),
    ] {
        assert_eq!(particle_chunks(&cfg, 100, budget), want, "budget {budget}");
    }
}

#[test]
fn bad_filter_lists_are_named_errors() {
    let cfg = config(16, 1, 3, 1);
    let e = FilterStudy::new(cfg, &[]).unwrap_err();
    assert_eq!(e.field(), Some("filters"));
    let e = FilterStudy::new(cfg, &[FilterKind::Ekf, FilterKind::Ekf]).unwrap_err();
    assert_eq!(e.field(), Some("filters[1]"));
    let bad_pf = FilterKind::Pf(PfConfig {
        particles: 0,
        roughening: None,
        regularized: true,
    });
    assert_eq!(
        FilterStudy::new(cfg, &[bad_pf]).unwrap_err().field(),
        Some("particles")
    );
    let mut s = FilterStudy::new(cfg, &[FilterKind::Ekf]).unwrap();
    let e = s
        .run_range(&model(), 0..2, &mut Sequential::new(), &mut |_, _| {})
        .unwrap_err();
    assert_eq!(e.field(), Some("chunks"));
    assert_eq!(s.results().unwrap_err().field(), Some("runs (successful)"));
}

// Issue 24, "Long work".

/// A driver whose jobs' [`crate::error::Cancel`] asks to stop after `after` questions: the
/// in-run check of the chunk loop (not only the driver's between jobs) ends the study.
struct StopAfter {
    after: usize,
    asked: core::sync::atomic::AtomicUsize,
}

impl Driver for StopAfter {
    fn run<T: Send>(
        &mut self,
        jobs: usize,
        _batch: usize,
        job: &(dyn Fn(usize, crate::error::Cancel) -> crate::Result<T> + Sync),
        merge: &mut dyn FnMut(T),
        progress: &mut dyn FnMut(usize),
    ) -> crate::Result<()> {
        use core::sync::atomic::Ordering;
        let stop = || self.asked.fetch_add(1, Ordering::Relaxed) >= self.after;
        for i in 0..jobs {
            merge(job(i, crate::error::Cancel::when(&stop))?);
            progress(i + 1);
        }
        Ok(())
    }
}

#[test]
fn a_run_is_cancelled_inside_its_steps() {
    use core::sync::atomic::{AtomicUsize, Ordering};
    // One chunk of one run of a particle filter: 200 steps of 20 000 particles, ≈ 1.2 ms per
    // step predicted (step_ns), so every step asks (check_every = 1).
    let pf = FilterKind::Pf(PfConfig {
        particles: 20_000,
        roughening: None,
        regularized: true,
    });
    let links = model().link_count();
    assert_eq!(
        crate::error::check_every(crate::track::step_ns(pf, links)),
        1
    );
    let cfg = config(1, 1, 200, 3);
    let mut s = FilterStudy::new(cfg, &[pf]).unwrap();
    let mut driver = StopAfter {
        after: 3,
        asked: AtomicUsize::new(0),
    };
    let e = s
        .run_range(&model(), 0..1, &mut driver, &mut |_, _| {})
        .unwrap_err();
    assert_eq!(e, crate::Error::Cancelled);
    // Asked at steps 0, 1, 2 (go on) and 3 (stop): inside the one run, 196 steps before its end.
    assert_eq!(driver.asked.load(Ordering::Relaxed), 4);
    // The EKF's lanes ask every check_every(4 × step_ns) steps: 1 ms / (4 × 140 ns) = 1785.
    let ekf_ns = 4.0 * crate::track::step_ns(FilterKind::Ekf, links);
    assert_eq!(crate::error::check_every(ekf_ns), (1e6 / ekf_ns) as usize);
    // Never asked to stop: the sums are those of the plain driver, bit for bit.
    let mut never = StopAfter {
        after: usize::MAX,
        asked: AtomicUsize::new(0),
    };
    let cfg = config(16, 2, 20, 3);
    let kinds = [FilterKind::Ekf, FilterKind::Ukf(UkfParams::default())];
    let (mut a, mut b) = (
        FilterStudy::new(cfg, &kinds).unwrap(),
        FilterStudy::new(cfg, &kinds).unwrap(),
    );
    a.run_range(&model(), 0..1, &mut never, &mut |_, _| {})
        .unwrap();
    b.run_range(&model(), 0..1, &mut Sequential::new(), &mut |_, _| {})
        .unwrap();
    assert_eq!(a.sums(), b.sums());
}

#[test]
fn a_filter_failing_every_run_keeps_the_others_results() {
    // One particle: its covariance is zero, so no run has a NEES (every run fails).
    let pf = FilterKind::Pf(PfConfig {
        particles: 1,
        roughening: None,
        regularized: true,
    });
    let cfg = config(16, 1, 5, 1);
    let mut s = FilterStudy::new(cfg, &[FilterKind::Ekf, pf]).unwrap();
    s.run_range(&model(), 0..1, &mut Sequential::new(), &mut |_, _| {})
        .unwrap();
    let r = s.results().unwrap();
    assert_eq!(r.curves.len(), 1);
    assert_eq!(r.curves[0].0, 0, "the EKF's curves are kept");
    assert_eq!(r.curves[0].1.runs, 16);
    assert_eq!(r.failed.len(), 1);
    let (i, e) = &r.failed[0];
    assert_eq!(*i, 1);
    assert_eq!(e.field(), Some("particles"));
    let text = e.to_string();
    assert!(
        text.starts_with("particles: every run of the PF failed (16 of 16); the first: "),
        "{text}"
    );
    // The PF alone: no result, the same named error.
    let mut alone = FilterStudy::new(cfg, &[pf]).unwrap();
    alone
        .run_range(&model(), 0..1, &mut Sequential::new(), &mut |_, _| {})
        .unwrap();
    assert_eq!(alone.results().unwrap_err().to_string(), text);
}
