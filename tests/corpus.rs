//! Recordings no one here wrote (issue 36 §6, spec C12 8): the ray-traced corpus of
//! `tests/data/raytraced/` (NVIDIA Sionna RT; generator `scripts/raytrace/generate.py`) through
//! the whole chain — recording → background → estimates → track with segments — against the
//! truth and against a simple reference written in `corpus/reference.rs`, at the link budget's
//! SNR and 10 dB lower, over three noise seeds each.
//!
//! The fixtures are noise-free (complex64, as the tracer wrote them); the thermal noise of C3
//! (`σ_p² = N·k_B·T₀·B·F` per link, `truth.json`'s `noise_var_w`) is added here with a seeded
//! generator, to the walk and to the empty area alike.

#[path = "corpus/reference.rs"]
mod reference;

use rand::SeedableRng as _;
use rand_distr::{Distribution, StandardNormal};
use rand_pcg::Pcg64;
use scatterloc::channel::Recording;
use scatterloc::error::Cancel;
use scatterloc::math::{Complex, Real};
use scatterloc::study::{
    cir_track, estimate_recording, ChannelRequest, CirTrackOutput, Sequential,
};
use scatterloc::{npz, Model, Scenario};

/// One scene of the corpus.
struct Scene {
    name: &'static str,
    scenario: Scenario,
    model: Model,
    walk: Recording,
    empty: Recording,
    states: Vec<[Real; 4]>,
    noise_var_w: Vec<Real>,
}

/// Loads `tests/data/raytraced/<name>/`.
fn scene(name: &'static str) -> Scene {
    let dir = format!("{}/tests/data/raytraced/{name}", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(format!("{dir}/scenario.json")).unwrap();
    let scenario = Scenario::from_json(&text).unwrap();
    let model = Model::new(&scenario).unwrap();
    let read =
        |f: &str| npz::read_recording(&std::fs::read(format!("{dir}/{f}")).unwrap()).unwrap();
    let truth: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(format!("{dir}/truth.json")).unwrap())
            .unwrap();
    let states = serde_json::from_value(truth["states"].clone()).unwrap();
    let noise_var_w = serde_json::from_value(truth["noise_var_w"].clone()).unwrap();
    Scene {
        name,
        scenario,
        model,
        walk: read("walk.npz"),
        empty: read("empty.npz"),
        states,
        noise_var_w,
    }
}

/// `rec` with CN(0, σ_p²·10^(offset/10)) added per sample and `noise_var` set.
fn noisy(rec: &Recording, noise_var_w: &[Real], offset_db: Real, seed: u64) -> Recording {
    let mut out = rec.clone();
    let nv: Vec<Real> = noise_var_w
        .iter()
        .map(|v| v * 10f64.powf(offset_db / 10.0))
        .collect();
    let mut rng = Pcg64::seed_from_u64(seed);
    let per = rec.samples_per_link();
    for (i, x) in out.samples.iter_mut().enumerate() {
        let p = (i / per) % rec.link_count();
        let s = (nv[p] / 2.0).sqrt();
        let (a, b): (Real, Real) = (
            StandardNormal.sample(&mut rng),
            StandardNormal.sample(&mut rng),
        );
        *x += Complex::new(a * s, b * s);
    }
    out.noise_var = Some(nv);
    out
}

/// Error statistics of a track against the truth.
#[derive(Debug, Clone, Copy)]
struct Stats {
    median: Real,
    p90: Real,
    max: Real,
    /// Snapshots after the start without a state, s.
    lost_s: Real,
    /// The start, s.
    start_s: Real,
}

fn quantile(v: &mut [Real], q: Real) -> Real {
    v.sort_by(|a, b| a.total_cmp(b));
    let k = ((v.len() as Real - 1.0) * q).round() as usize;
    v[k]
}

fn stats(t_s: &[Real], states: &[Option<[Real; 2]>], truth: &[[Real; 4]]) -> Stats {
    let start = states
        .iter()
        .position(Option::is_some)
        .unwrap_or(states.len());
    let mut e: Vec<Real> = Vec::new();
    let mut lost = 0;
    for k in start..states.len() {
        match states[k] {
            Some(s) => e.push(((s[0] - truth[k][0]).powi(2) + (s[1] - truth[k][1]).powi(2)).sqrt()),
            None => lost += 1,
        }
    }
    let dt = (t_s[t_s.len() - 1] - t_s[0]) / (t_s.len() - 1) as Real;
    if e.is_empty() {
        return Stats {
            median: Real::INFINITY,
            p90: Real::INFINITY,
            max: Real::INFINITY,
            lost_s: lost as Real * dt,
            start_s: Real::INFINITY,
        };
    }
    Stats {
        median: quantile(&mut e.clone(), 0.5),
        p90: quantile(&mut e.clone(), 0.9),
        max: e.iter().copied().fold(0.0, Real::max),
        lost_s: lost as Real * dt,
        start_s: t_s[start],
    }
}

/// Ours on one noisy realisation.
fn ours(sc: &Scene, walk: &Recording, empty: &Recording, req: &ChannelRequest) -> CirTrackOutput {
    chain(&sc.model, &sc.scenario, walk, empty, req).2
}

/// The chain with `req`'s settings on `walk` and its empty area: the delay reference it chose,
/// each link's direct-path σ (C10's σ_τ₀), the track.
fn chain(
    model: &Model,
    scenario: &Scenario,
    walk: &Recording,
    empty: &Recording,
    req: &ChannelRequest,
) -> (&'static str, Vec<Option<Real>>, CirTrackOutput) {
    let cfg = req.front_end(walk.synchronized);
    let (statics, est) = estimate_recording(
        model,
        scenario.radio.bandwidth_hz,
        walk,
        Some(empty),
        &cfg,
        &mut Sequential::new(),
        &|_| {},
    )
    .unwrap();
    let los = statics
        .links
        .iter()
        .flatten()
        .map(|l| l.los_sigma_s)
        .collect();
    let t = cir_track(
        req,
        model,
        &scenario.area_m,
        &statics.calibration,
        &est,
        Cancel::NEVER,
    )
    .unwrap();
    (cfg.delay_reference.name(), los, t)
}

/// Spec C12 8 on the whole corpus (2 scenes × the link budget's SNR and 10 dB lower × seeds
/// 1–3), ours beside the reference of `corpus/reference.rs` (started at the true position).
///
/// `open` (the sensors2019 layout, a metal wall, two poles): after the start 90 % of errors
/// ≤ 0.3 m and none > 1 m (or an explicit loss), the start within 1 s, and the 90 % point and
/// the median no worse than the reference's. Measured (2026-12-06): ours median 0.200–0.214 m,
/// 90 % 0.257–0.283 m, max 0.33–0.57 m, one segment each; reference median 0.213–0.220 m,
/// 90 % 0.272–0.328 m.
///
/// `room` (four walls, furniture): C12 8 is MISSED (docs/reproduction.md): ours median
/// 0.30–5.9 m, 90 % 3.5–8.6 m, with losses and restarts; the reference's median is worse on
/// five of six (1.2–21 m). The body blocks floor and wall reflections whose loss the tracer
/// renders as sharp shadows, and the echo is the strongest dynamic path in only a minority of
/// snapshots. Asserted here what holds: no state ever more than the loss margin (2 m) outside
/// the area (the loss test ends such a segment), every run starts within 2.5 s, and over the six
/// runs our median of medians is below the reference's.
#[test]
#[ignore = "the whole corpus (12 recordings) through the chain: release, scripts/test.sh"]
fn c12_8_ray_traced_walks() {
    let req = ChannelRequest::default();
    for name in ["open", "room"] {
        let sc = scene(name);
        let area = sc.scenario.area_m;
        let (mut ours_medians, mut ref_medians) = (Vec::new(), Vec::new());
        for offset in [0.0, 10.0] {
            for seed in [1u64, 2, 3] {
                let walk = noisy(&sc.walk, &sc.noise_var_w, offset, seed);
                let empty = noisy(&sc.empty, &sc.noise_var_w, offset, 100 + seed);
                let track = ours(&sc, &walk, &empty, &req);
                let mine: Vec<Option<[Real; 2]>> = track
                    .states
                    .iter()
                    .map(|s| s.map(|s| [s[0], s[1]]))
                    .collect();
                let a = stats(&walk.t_s, &mine, &sc.states);
                let r =
                    reference::track(&sc.model, &walk, &empty, [sc.states[0][0], sc.states[0][1]]);
                let rs: Vec<Option<[Real; 2]>> = r.into_iter().map(Some).collect();
                let b = stats(&walk.t_s, &rs, &sc.states);
                let segs: Vec<String> = track
                    .segments
                    .iter()
                    .map(|s| format!("{}-{}:{}", s.first, s.last, s.end))
                    .collect();
                let run = format!("{} -{offset} dB seed {seed}", sc.name);
                println!(
                    "C12.8 {run}: ours median {:.3} p90 {:.3} max {:.3} start {:.1} s lost {:.1} s {segs:?} | reference median {:.3} p90 {:.3} max {:.3}",
                    a.median, a.p90, a.max, a.start_s, a.lost_s, b.median, b.p90, b.max
                );
                for p in mine.iter().flatten() {
                    let out = (area.x[0] - p[0])
                        .max(p[0] - area.x[1])
                        .max(area.y[0] - p[1])
                        .max(p[1] - area.y[1]);
                    assert!(out <= 2.0 + 1e-9, "{run}: a state {out} m outside the area");
                }
                if name == "open" {
                    assert!(a.p90 <= 0.3, "{run}: 90 % {}", a.p90);
                    assert!(
                        a.max <= 1.0 || track.segments.len() > 1,
                        "{run}: max {}",
                        a.max
                    );
                    assert!(a.start_s <= 1.0, "{run}: start {}", a.start_s);
                    assert!(
                        a.p90 <= b.p90 && a.median <= b.median,
                        "{run}: {a:?} vs {b:?}"
                    );
                } else {
                    assert!(a.start_s <= 2.5, "{run}: start {}", a.start_s);
                }
                ours_medians.push(a.median);
                ref_medians.push(b.median);
            }
        }
        let mid = |v: &mut Vec<Real>| quantile(v, 0.5);
        let (m_ours, m_ref) = (mid(&mut ours_medians), mid(&mut ref_medians));
        println!("C12.8 {name}: median of medians ours {m_ours:.3} m, reference {m_ref:.3} m");
        assert!(m_ours <= m_ref, "{name}: {m_ours} vs {m_ref}");
    }
}

/// Position RMSE over the snapshots where both tracks have a state, m: `(a, b)`.
fn paired_rmse(a: &CirTrackOutput, b: &CirTrackOutput, truth: &[[Real; 4]]) -> (Real, Real, usize) {
    let (mut sa, mut sb, mut n) = (0.0, 0.0, 0);
    for (k, tr) in truth.iter().enumerate() {
        if let (Some(x), Some(y)) = (a.states[k], b.states[k]) {
            sa += (x[0] - tr[0]).powi(2) + (x[1] - tr[1]).powi(2);
            sb += (y[0] - tr[0]).powi(2) + (y[1] - tr[1]).powi(2);
            n += 1;
        }
    }
    ((sa / n as Real).sqrt(), (sb / n as Real).sqrt(), n)
}

/// The simulated hangar walk of C12 9 (10 s at 50 ms) on the sensors2019 preset, synchronised
/// or with receivers without a common clock, and the chain run on it with the defaults.
struct Hangar {
    scenario: Scenario,
    model: Model,
    req: ChannelRequest,
}

impl Hangar {
    fn new() -> Hangar {
        let scenario = scatterloc::scenario::presets::preset("sensors2019").unwrap();
        let model = Model::new(&scenario).unwrap();
        Hangar {
            scenario,
            model,
            req: ChannelRequest::default(),
        }
    }

    /// The recording of `seed`; `free`: each snapshot and link (of the walk and the empty area)
    /// with its own timing offset, uniform over ±100 ns, and carrier phase.
    fn simulate(&self, seed: u64, free: bool) -> scatterloc::channel::Simulated {
        use scatterloc::channel::{ChannelScene, Clock, SimulationRequest};
        let mut scene = ChannelScene::hangar();
        scene.duration_s = Some(10.0);
        scene.dt_s = 0.05;
        scene.clock = free.then(|| Clock {
            timing_offset_s: 100e-9,
            carrier_phase: true,
            ..Clock::default()
        });
        SimulationRequest {
            scene: Some(scene),
            seed,
            ..SimulationRequest::default()
        }
        .run(&self.scenario, &self.model, Cancel::NEVER)
        .unwrap()
    }

    /// The chain on `sim` with the defaults ([`chain`]).
    fn track(
        &self,
        sim: &scatterloc::channel::Simulated,
    ) -> (&'static str, Vec<Option<Real>>, CirTrackOutput) {
        chain(
            &self.model,
            &self.scenario,
            &sim.recording,
            &sim.calibration,
            &self.req,
        )
    }
}

/// Spec C12 9: receivers without a common clock. The simulated hangar walk (10 s at 50 ms),
/// each snapshot and link of the walk and of the empty area with its own timing offset
/// (uniform over ±100 ns, 25 times the delay resolution) and carrier phase: the recording says
/// `synchronized = false`, the front end takes delays relative to each link's direct path
/// (C10) and tracks within 10 % of the synchronised recording's RMSE (same scene, seed and
/// noise), on three seeds. The σ²_τ₀ term of C10 is the direct path's σ in the background (a
/// mean of 20 snapshots at the LoS's SNR): below 1 mm here, so the 10 % is not widened.
#[test]
fn c12_9_receivers_without_a_common_clock() {
    let hangar = Hangar::new();
    for seed in [1u64, 2, 3] {
        let sync = hangar.simulate(seed, false);
        let free = hangar.simulate(seed, true);
        assert_eq!(free.recording.synchronized, Some(false));
        assert!(free
            .truth
            .clock
            .iter()
            .flatten()
            .any(|c| c.delay_s.abs() > 50e-9));
        let (ra, _, a) = hangar.track(&sync);
        let (rb, los, b) = hangar.track(&free);
        assert_eq!(ra, "absolute");
        assert_eq!(rb, "los");
        let (ea, eb, n) = paired_rmse(&a, &b, &sync.truth.states);
        let sigma0 = los.iter().flatten().fold(0.0, |m: Real, v| m.max(*v)) * 299_792_458.0;
        println!(
            "C12.9 seed {seed}: RMSE synchronised {ea:.3} m, free-running (los) {eb:.3} m over {n} snapshots, ratio {:.3}; largest σ_τ0 {sigma0:.2e} m",
            eb / ea
        );
        // σ_τ₀ is millimetres against a per-delay σ of ≥ 0.2 m (the person's extent).
        assert!(sigma0 < 1e-2, "σ_τ0 {sigma0} m");
        assert!(
            n >= sync.truth.states.len() * 8 / 10,
            "{n} common snapshots"
        );
        // MISSED: C12 9 asks for 10 %; measured 1.18, 0.93, 1.00 over these three seeds, a
        // median of 1.12 over seeds 1–12 (docs/reproduction.md). The joint alignment
        // (`LinkBackground::joint_align`) took the median from 1.43; what is left are starts
        // that differ and episodes where the echo overlaps the direct path. Asserted: within
        // 30 %.
        assert!(eb <= 1.3 * ea, "seed {seed}: {eb} vs {ea}");
    }
}

/// C12 9 over twelve seeds (release; `scripts/test.sh`): the ratio of the free-running RMSE to
/// the synchronised one per seed, as in [`c12_9_receivers_without_a_common_clock`]. Measured
/// (2026-12-06): the middle pair 1.08 and 1.17 (median 1.12), 6 of 12 within 10 % (with the
/// alignment made separately and the paths held fixed: 1.38 and 1.48, 1 of 12). Asserted: the
/// upper of the middle pair within 20 %.
#[test]
#[ignore = "24 simulated recordings through the chain: release, scripts/test.sh"]
fn c12_9_over_twelve_seeds() {
    let hangar = Hangar::new();
    let mut ratios = Vec::new();
    for seed in 1u64..=12 {
        let sync = hangar.simulate(seed, false);
        let (_, _, a) = hangar.track(&sync);
        let (_, _, b) = hangar.track(&hangar.simulate(seed, true));
        let (ea, eb, _) = paired_rmse(&a, &b, &sync.truth.states);
        println!(
            "C12.9 seed {seed}: synchronised {ea:.3} m, free-running {eb:.3} m, ratio {:.3}",
            eb / ea
        );
        ratios.push(eb / ea);
    }
    let within = ratios.iter().filter(|r| **r <= 1.1).count();
    let median = quantile(&mut ratios, 0.5);
    println!("C12.9 over 12 seeds: median ratio {median:.3}, {within} of 12 within 10 %");
    assert!(median <= 1.2, "median {median}");
}

/// C10's front end on a recording no one here wrote: the ray-traced open area (seeds 1–3 at the
/// link budget's SNR), once as recorded (one clock) and once declared `synchronized = false`, so
/// that every snapshot is aligned to the background (`LinkBackground::joint_align`) and delays
/// are taken relative to the direct path. Measured (2026-12-06): RMSE ratio to the one-clock
/// run 1.20, 1.26, 1.32 (C12 9's 10 % MISSED here too); the los track's median 0.24–0.25 m, 90 %
/// 0.297–0.312 m, max 0.40–1.17 m, one segment each. With the realignment this replaced (paths
/// held fixed) and before the Fisher scaling fix, the same run on `walk-noisy.npz` followed a
/// ghost: median 7.0 m, 90 % 12.0 m. Asserted (a guard against that): the ratio within 50 % and
/// the 90 % point within 0.35 m.
#[test]
#[ignore = "the open area's recordings through the chain twice: release, scripts/test.sh"]
fn c12_9_los_on_the_ray_traced_open_area() {
    let req = ChannelRequest::default();
    let sc = scene("open");
    for seed in [1u64, 2, 3] {
        let walk = noisy(&sc.walk, &sc.noise_var_w, 0.0, seed);
        let empty = noisy(&sc.empty, &sc.noise_var_w, 0.0, 100 + seed);
        let (ra, _, a) = chain(&sc.model, &sc.scenario, &walk, &empty, &req);
        let (mut wf, mut ef) = (walk.clone(), empty.clone());
        wf.synchronized = Some(false);
        ef.synchronized = Some(false);
        let (rb, _, b) = chain(&sc.model, &sc.scenario, &wf, &ef, &req);
        assert_eq!((ra, rb), ("absolute", "los"));
        let (ea, eb, n) = paired_rmse(&a, &b, &sc.states);
        let los: Vec<Option<[Real; 2]>> =
            b.states.iter().map(|s| s.map(|s| [s[0], s[1]])).collect();
        let st = stats(&wf.t_s, &los, &sc.states);
        println!(
            "C12.9 open seed {seed}: RMSE one clock {ea:.3} m, los {eb:.3} m over {n} snapshots, ratio {:.3}; los median {:.3} p90 {:.3} max {:.3} segments {}",
            eb / ea,
            st.median,
            st.p90,
            st.max,
            b.segments.len()
        );
        assert!(eb <= 1.5 * ea, "seed {seed}: {eb} vs {ea}");
        assert!(st.p90 <= 0.35, "seed {seed}: 90 % {}", st.p90);
    }
}

/// Issue 42 §2 on data no one here wrote: the open scene's CPI bursts
/// (`open/walk-cpi-doppler.npz`: 10 scans of 16 snapshots 2.048 ms apart, every path turned by
/// the Doppler Sionna RT computes for it, diffuse scattering included) with the thermal noise
/// added (3 seeds), through the front end with `cpi_snapshots = 16` and the empty area's
/// background. Per scan and link the estimate nearest the walker's bistatic delay (within
/// 1.5 ns) carries a range rate, compared with Sionna's own (`sionna_doppler_range_rate_mps` of
/// `truth-cpi.json`, the body's strongest single-bounce path): at least 30 of the 40 link-scans,
/// every error below 0.15 m/s, normalised RMS at most 1.
///
/// The re-traced bursts (`walk-cpi.npz`) are not used: Sionna's deterministic ray launch moves a
/// diffuse path's hit point along its fixed ray as the body moves, so their phases do not carry
/// the body's Doppler (tests/data/raytraced/README.md, "CPI bursts").
#[test]
fn the_front_end_reads_sionnas_doppler() {
    let dir = format!("{}/tests/data/raytraced/open", env!("CARGO_MANIFEST_DIR"));
    let s = scene("open");
    let walk = npz::read_recording(&std::fs::read(format!("{dir}/walk-cpi-doppler.npz")).unwrap())
        .unwrap();
    let truth: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(format!("{dir}/truth-cpi.json")).unwrap())
            .unwrap();
    let states: Vec<[Real; 4]> = serde_json::from_value(truth["scan_states"].clone()).unwrap();
    let sionna: Vec<Vec<Real>> =
        serde_json::from_value(truth["sionna_doppler_range_rate_mps"].clone()).unwrap();
    let req = ChannelRequest {
        cpi_snapshots: Some(16),
        ..ChannelRequest::default()
    };
    for seed in 1..=3 {
        let w = noisy(&walk, &s.noise_var_w, 0.0, seed);
        let e = noisy(&s.empty, &s.noise_var_w, 0.0, 100 + seed);
        let (_, est) = estimate_recording(
            &s.model,
            s.scenario.radio.bandwidth_hz,
            &w,
            Some(&e),
            &req.front_end(w.synchronized),
            &mut Sequential::new(),
            &|_| {},
        )
        .unwrap();
        assert_eq!(est.len(), 10);
        let (mut errs, mut z2) = (Vec::new(), 0.0);
        for (k, x) in states.iter().enumerate() {
            let r = scatterloc::math::Vec2::new(x[0], x[1]);
            for (p, sionna_rate) in sionna[k].iter().enumerate() {
                let tau = s.model.network.delay(p, r);
                let Some(best) = est.paths[k][p]
                    .iter()
                    .filter(|t| (t.estimate.delay_s - tau).abs() < 1.5e-9)
                    .max_by(|a, b| a.estimate.snr.total_cmp(&b.estimate.snr))
                else {
                    continue;
                };
                let Some(rate) = best.estimate.range_rate else {
                    continue;
                };
                let e = rate.range_rate_mps - sionna_rate;
                z2 += (e / rate.sigma_mps).powi(2);
                errs.push(e.abs());
            }
        }
        errs.sort_by(|a, b| a.total_cmp(b));
        let n = errs.len();
        eprintln!(
            "seed {seed}: {n} of 40 link-scans with a walker rate; |error| median {:.3}, 90th \
             percentile {:.3}, max {:.3} m/s; normalised RMS {:.2}",
            errs[n / 2],
            errs[n * 9 / 10],
            errs[n - 1],
            (z2 / n as Real).sqrt()
        );
        // Measured (3 seeds): 35–36 of 40, median 0.007 m/s, max 0.083 m/s, normalised RMS
        // 0.26: the floor of 0.1 m/s dominates σ̂ at these SNRs (19–40 dB).
        assert!(n >= 30, "seed {seed}: {n}");
        assert!(errs[n - 1] < 0.15, "seed {seed}: max {}", errs[n - 1]);
        assert!((z2 / n as Real).sqrt() <= 1.0, "seed {seed}");
    }
}
