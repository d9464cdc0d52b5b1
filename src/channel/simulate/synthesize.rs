//! The recording of a scene (C1, C3), snapshot by snapshot. Per snapshot `s` and link `p`:
//! `H_p[n] = Σ_i α_i e^{−j2π f_n τ_i} + w[n]`, `f_n = (n − (N−1)/2)·Δf`, `Δf = B/N`,
//! `w ~ CN(0, σ_p²)`, `σ_p² = N·P_n/G_p` (`G_p` the processing gain, 1 when none is
//! configured), raised to `N·max_i|α_i|²·10^(−DR/10)` when a dynamic range DR is set (the
//! strongest path over the recording). `α_i = √P_i · e^{−j2π f_c τ_i}` times the product of
//! the reflection coefficients and, for the body, the centre's fluctuation.
//!
//! The truth and the work are capped by name ([`limits::MAX_TRUTH_PATHS`],
//! [`limits::MAX_SIMULATION_WORK`], [`MAX_CHANNEL_SAMPLES`]); the rng streams of the noise, the body
//! and the clocks are fixed, so a seed gives the same recording on every platform.

use alloc::vec;
use alloc::vec::Vec;

use super::geometry::Line;
use super::rays::{static_rays, LinkBudget, StaticRay};
use super::signal::{add_path, apply_clock, cis_neg, complex_normal};
use super::walkers::movers;
use super::{ChannelScene, ChannelTruth, ClockState, PathKind, TruePath};
use crate::channel::{Layout, Recording};
use crate::error::limits::MAX_CHANNEL_SAMPLES;
use crate::error::{check_len, limits, Cancel, Error, Result};
use crate::math::{db_to_linear, dbm_to_watt, sqrt, Complex, Real, SPEED_OF_LIGHT};
use crate::measure::{noise_power_w, rng, Model};
use crate::scenario::Scenario;

/// rng streams: the noise of a recording with the walker and of the empty-area calibration
/// recording (the bodies' fluctuations: [`super::walkers`]).
const STREAM_NOISE: u64 = 0x25_01;
const STREAM_NOISE_EMPTY: u64 = 0x25_02;
/// rng streams of the receivers' clocks (C10): the walk's and the empty area's.
const STREAM_CLOCK: u64 = 0x36_01;
const STREAM_CLOCK_EMPTY: u64 = 0x36_02;

/// The simulator's caps on the truth's path entries and on its work
/// ([`limits::MAX_TRUTH_PATHS`], [`limits::MAX_SIMULATION_WORK`]), named as `scene.duration_s`
/// (the request names it `duration_s`).
struct Budget {
    snapshots: usize,
    bins: usize,
}

impl Budget {
    /// `entries` path entries in the first `done` snapshots.
    fn check(&self, entries: usize, done: usize) -> Result<()> {
        if entries <= limits::MAX_TRUTH_PATHS {
            return Ok(());
        }
        Err(Error::InvalidFile {
            field: "scene.duration_s".into(),
            reason: alloc::format!(
                "the truth would hold more than {} true paths (already {entries} in {done} of {} \
                 snapshots): fewer scatterers, walls or links, or a shorter duration",
                limits::MAX_TRUTH_PATHS,
                self.snapshots
            ),
        })
    }

    /// `work` path × bin products in the first `done` snapshots.
    fn check_work(&self, work: u64, done: usize) -> Result<()> {
        if work <= limits::MAX_SIMULATION_WORK {
            return Ok(());
        }
        Err(Error::InvalidFile {
            field: "scene.duration_s".into(),
            reason: alloc::format!(
                "more than {} path × subcarrier products ({work} in {done} of {} snapshots of \
                 {} subcarriers): fewer scatterers or subcarriers, or a shorter duration",
                limits::MAX_SIMULATION_WORK,
                self.snapshots,
                self.bins
            ),
        })
    }
}

/// Simulates a recording of `scene` on `model`'s links (compiled from `scenario`), with the
/// walker (`with_person`) or of the empty area (the calibration recording, its own noise
/// stream), seeded by `seed`. Layout C1 (`Cfr`, no system response), `noise_var` per link.
///
/// Errors: the scene's [`ChannelScene::validate`], a model of another scenario
/// ([`Error::LengthMismatch`]), more than [`MAX_CHANNEL_SAMPLES`] samples
/// ([`Error::SizeLimit`] of `scene.duration_s`).
pub fn simulate_recording(
    scenario: &Scenario,
    model: &Model,
    scene: &ChannelScene,
    with_person: bool,
    seed: u64,
) -> Result<(Recording, ChannelTruth)> {
    synthesize(
        scenario,
        model,
        scene,
        with_person,
        seed,
        true,
        Cancel::NEVER,
    )
}

/// Per further walker, its `[x, y, vx, vy]` per snapshot.
pub(super) type WalkerStates = Vec<Vec<[Real; 4]>>;

/// [`simulate_recording`], optionally without the additive noise (`noise_var` then still
/// gives the σ² the noisy version would use); `cancel` is asked once per snapshot.
pub(super) fn synthesize(
    scenario: &Scenario,
    model: &Model,
    scene: &ChannelScene,
    with_person: bool,
    seed: u64,
    add_noise: bool,
    cancel: Cancel,
) -> Result<(Recording, ChannelTruth)> {
    synthesize_all(scenario, model, scene, with_person, seed, add_noise, cancel)
        .map(|(r, t, _)| (r, t))
}

/// [`synthesize`] with the states `[x, y, vx, vy]` of each further walker
/// ([`ChannelScene::others`], issue 41) per snapshot (none without the walkers,
/// `with_person = false`). A scene without further walkers gives [`synthesize`]'s recording and
/// truth bit for bit.
pub(super) fn synthesize_all(
    scenario: &Scenario,
    model: &Model,
    scene: &ChannelScene,
    with_person: bool,
    seed: u64,
    add_noise: bool,
    cancel: Cancel,
) -> Result<(Recording, ChannelTruth, WalkerStates)> {
    scene.validate()?;
    check_len(
        "model.network.transmitters",
        scenario.transmitters.len(),
        model.network.transmitters.len(),
    )?;
    check_len(
        "model.network.receivers",
        scenario.receivers.len(),
        model.network.receivers.len(),
    )?;
    let links = &model.network.links;
    let mut walkers = movers(scene, links.len(), scenario.target.rcs_m2, seed)?;
    // The longest walk (the main walker's without further walkers).
    let duration = scene.duration_s.unwrap_or_else(|| {
        walkers
            .iter()
            .map(|w| w.path.duration_s())
            .fold(walkers[0].path.duration_s(), Real::max)
    });
    let n_bins = scene.subcarriers;
    let per_snapshot = links.len() * n_bins;
    let steps = duration / scene.dt_s * (1.0 + 1e-12);
    let cap = MAX_CHANNEL_SAMPLES;
    let too_big = |value: usize| Error::SizeLimit {
        field: "scene.duration_s",
        value,
        min: 1,
        max: cap / per_snapshot.max(1),
    };
    if steps >= cap as Real {
        return Err(too_big(usize::MAX));
    }
    // A CPI (the walk only) makes each scan a burst of its snapshots.
    let cpi = scene.cpi.filter(|_| with_person);
    let per_scan = cpi.map_or(1, |c| c.snapshots);
    let snapshots = match (steps as usize + 1).checked_mul(per_scan) {
        Some(s) => s,
        None => return Err(too_big(usize::MAX)),
    };
    match snapshots.checked_mul(per_snapshot) {
        Some(t) if t <= cap => {}
        _ => return Err(too_big(snapshots)),
    }

    let radio = &scenario.radio;
    let fc = radio.carrier_hz;
    let df = radio.bandwidth_hz / n_bins as Real;
    let f0 = -((n_bins - 1) as Real) * 0.5 * df;
    let lambda = SPEED_OF_LIGHT / fc;
    let lines: Vec<Line> = scene.walls.iter().map(Line::new).collect();
    let budgets: Vec<LinkBudget> = links
        .iter()
        .map(|l| LinkBudget {
            tx: model.network.transmitters[l.tx],
            rx: model.network.receivers[l.rx],
            dz_tx: model.network.transmitters_dz[l.tx],
            dz_rx: model.network.receivers_dz[l.rx],
            pattern: &model.patterns[l.tx],
            ptx_grx: dbm_to_watt(scenario.transmitters[l.tx].power_dbm)
                * db_to_linear(scenario.receivers[l.rx].gain_dbi),
            lambda,
        })
        .collect();
    let statics: Vec<Vec<StaticRay>> = budgets
        .iter()
        .map(|lb| static_rays(lb, &lines, scene))
        .collect();
    // The truth and the work grow with every path of every link and snapshot: refused by
    // name before anything is computed when the static paths alone exceed a cap, and as
    // soon as the walker's paths make them exceed it (issue 37 item 4).
    let static_count: usize = statics.iter().map(Vec::len).sum();
    let budget = Budget {
        snapshots,
        bins: n_bins,
    };
    budget.check(snapshots.saturating_mul(static_count), snapshots)?;
    budget.check_work(
        (snapshots as u64)
            .saturating_mul(static_count as u64)
            .saturating_mul(n_bins as u64),
        snapshots,
    )?;
    let (mut entries, mut work) = (0usize, 0u64);

    let k_centres = scene.body.centres;
    let mut others: WalkerStates = if with_person {
        vec![Vec::with_capacity(snapshots); scene.others.len()]
    } else {
        Vec::new()
    };
    let mut at = Vec::with_capacity(walkers.len());

    let clock = scene.clock.as_ref();
    let mut clock_rng = rng(
        seed,
        if with_person {
            STREAM_CLOCK
        } else {
            STREAM_CLOCK_EMPTY
        },
    );
    let mut gain_db = vec![0.0; links.len()];
    let mut clock_truth: Vec<Vec<ClockState>> = Vec::new();
    let mut t_s = Vec::with_capacity(snapshots);
    let mut states = Vec::new();
    let mut truth_paths = Vec::with_capacity(snapshots);
    let mut shadowed = Vec::with_capacity(snapshots);
    let mut samples = vec![Complex::new(0.0, 0.0); snapshots * per_snapshot];
    let mut max_power = vec![0.0; links.len()];
    let mut scratch = Vec::new();

    for s in 0..snapshots {
        cancel.check()?;
        let (t, gap) = match cpi {
            None => (s as Real * scene.dt_s, None),
            Some(c) => c.time_of(s, scene.dt_s),
        };
        t_s.push(t);
        at.clear();
        if with_person {
            at.extend(walkers.iter().map(|w| w.path.state_and_heading(t)));
            states.push(at[0].0);
            for (o, a) in others.iter_mut().zip(&at[1..]) {
                o.push(a.0);
            }
            // The bodies' fluctuations (each walker its own stream).
            for w in walkers.iter_mut() {
                w.draw(s, gap.map(|g| g / scene.dt_s));
            }
        }
        let mut snap_paths = Vec::with_capacity(links.len());
        let mut snap_shadow = Vec::with_capacity(links.len());
        for (p, lb) in budgets.iter().enumerate() {
            let h = &mut samples[(s * links.len() + p) * n_bins..][..n_bins];
            let mut truth = Vec::new();
            let mut los_shadowed = false;
            for ray in &statics[p] {
                // Shadowed by any walker, by each one it passes.
                let mut shade = false;
                let mut a = 1.0;
                for (w, (st, _)) in walkers.iter().zip(&at) {
                    if let Some(f) = w.shade(ray, st) {
                        shade = true;
                        a *= f;
                    }
                }
                if ray.kind == PathKind::Los {
                    los_shadowed = shade;
                }
                let power = ray.power * a * a;
                truth.push(TruePath {
                    kind: ray.kind,
                    delay_s: ray.delay,
                    power_w: power,
                });
                let alpha = cis_neg(fc * ray.delay) * (sqrt(ray.power) * a * ray.sign);
                add_path(h, alpha, ray.delay, f0, df);
            }
            // Every walker's paths; the work bound counts `1 + K` sets of one centre's paths
            // per walker (one set without the walkers).
            let mut rays = statics[p].len();
            if with_person {
                for (w, &a) in walkers.iter().zip(&at) {
                    let per_centre = w.add(
                        lb,
                        &lines,
                        a,
                        t,
                        p,
                        scenario.target.rcs_m2,
                        scene.double_reflections,
                        [fc, f0, df],
                        h,
                        &mut truth,
                        &mut scratch,
                    );
                    rays += w.rays(per_centre);
                }
            } else {
                rays += 1 + k_centres;
            }
            if let Some(c) = clock {
                let st = apply_clock(c, s, &mut gain_db[p], &mut clock_rng, h, f0, df);
                if p == 0 {
                    clock_truth.push(Vec::with_capacity(links.len()));
                }
                if let Some(row) = clock_truth.last_mut() {
                    row.push(st);
                }
            }
            for tp in &truth {
                max_power[p] = Real::max(max_power[p], tp.power_w);
            }
            entries = entries.saturating_add(truth.len());
            work = work.saturating_add((rays as u64).saturating_mul(n_bins as u64));
            budget.check(entries, s + 1)?;
            budget.check_work(work, s + 1)?;
            snap_paths.push(truth);
            snap_shadow.push(los_shadowed);
        }
        truth_paths.push(snap_paths);
        shadowed.push(snap_shadow);
    }

    // Noise (C3), optionally floored by the dynamic range.
    let gp = db_to_linear(radio.processing_gain_db.unwrap_or(0.0));
    let thermal = n_bins as Real * noise_power_w(radio) / gp;
    let noise_var: Vec<Real> = max_power
        .iter()
        .map(|&m| match scene.dynamic_range_db {
            Some(dr) => Real::max(thermal, n_bins as Real * m * db_to_linear(-dr)),
            None => thermal,
        })
        .collect();
    if add_noise {
        let stream = if with_person {
            STREAM_NOISE
        } else {
            STREAM_NOISE_EMPTY
        };
        let mut noise_rng = rng(seed, stream);
        for (i, x) in samples.iter_mut().enumerate() {
            let p = (i / n_bins) % links.len();
            *x += complex_normal(&mut noise_rng) * sqrt(noise_var[p]);
        }
    }

    let recording = Recording {
        t_s: t_s.clone(),
        links: links.iter().map(|l| [l.tx, l.rx]).collect(),
        layout: Layout::Cfr {
            freq_hz: (0..n_bins).map(|n| f0 + n as Real * df).collect(),
            system_response: None,
        },
        samples,
        noise_var: Some(noise_var),
        synchronized: clock.map(|c| !c.free_running()),
    };
    let truth = ChannelTruth {
        t_s,
        states,
        paths: truth_paths,
        shadowed,
        clock: clock_truth,
    };
    Ok((recording, truth, others))
}
