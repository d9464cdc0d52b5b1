//! One chunk of a study: sampling its truth trajectories with their per-step truth tables
//! (delays, `σ_p` and `F` at the truth), then the EKF noise runs over them, filtered a few at a
//! time.

use alloc::vec;
use alloc::vec::Vec;

use super::{MonteCarloConfig, PartialSums, CHUNK_TRAJECTORIES};
use crate::error::{check_every, Cancel, Error, Result};
use crate::math::{Mat2, Real, Vec2, Vec4, SPEED_OF_LIGHT};
use crate::measure::{rng, standard_normal, Rng};
use crate::measure::{sigma_delay_from_snr, Model};
use crate::track::TruthSampler;
use crate::track::{
    range_information_per_snr, spd_quadratic_form, update_lanes, Ekf, MeasurementNoise, NodeView,
};
use crate::track::{step_ns, Filter, FilterKind, Tracker};

/// Salt of the particle filters' own streams (particles, resampling), apart from the
/// measurement-noise streams, so every filter of a study sees the same measurements.
const PF_STREAM_SALT: u64 = 0x5046_5f53_5452_4541;

/// Per step and link of one truth trajectory: the true delay and `σ_p` at the truth (E8). Shared
/// by all noise runs of the trajectory, interleaved so a measurement reads one cache line.
#[derive(Debug, Clone, Copy, Default)]
struct TruthLink {
    delay: Real,
    sigma: Real,
}

/// Scratch buffers reused across trajectories of a chunk.
struct Scratch {
    truth: Vec<Vec4>,
    /// `links × (steps + 1)` entries, step-major (step 0 unused).
    table: Vec<TruthLink>,
    measurement: Vec<Option<Real>>,
    squared_error: Vec<Real>,
    nees: Vec<Real>,
    /// Transmitter views at the current truth point (one per Tx).
    tx_views: Vec<(NodeView, Real)>,
    rx_views: Vec<NodeView>,
}

impl Scratch {
    fn new(model: &Model, steps: usize, with_filter: bool) -> Scratch {
        let links = model.link_count();
        let table_len = if with_filter { links * (steps + 1) } else { 0 };
        Scratch {
            truth: Vec::with_capacity(steps + 1),
            table: vec![TruthLink::default(); table_len],
            measurement: vec![None; LANES * links],
            squared_error: vec![0.0; LANES * (steps + 1)],
            nees: vec![0.0; LANES * (steps + 1)],
            tx_views: Vec::with_capacity(model.network.transmitters.len()),
            rx_views: Vec::with_capacity(model.network.receivers.len()),
        }
    }
}

/// For truth step `n` at `r`: the delays and `σ_p(r)` of every link into `s.table` (if it is
/// sized for them) and `F(r)` (E8). One square root per node and one Tx gain per transmitter
/// instead of per link; equal to [`Network::delay`](crate::measure::Network::delay),
/// [`Model::sigma_delay`] and [`fisher`](crate::localize::fisher) up to rounding.
fn truth_step(model: &Model, s: &mut Scratch, n: usize, r: Vec2) -> Mat2 {
    let net = &model.network;
    s.tx_views.clear();
    for (k, (&tx, &dz)) in net
        .transmitters
        .iter()
        .zip(&net.transmitters_dz)
        .enumerate()
    {
        let v = NodeView::new(tx, dz, r);
        s.tx_views.push((v, model.patterns[k].gain_toward(v.unit)));
    }
    s.rx_views.clear();
    s.rx_views.extend(
        net.receivers
            .iter()
            .zip(&net.receivers_dz)
            .map(|(&rx, &dz)| NodeView::new(rx, dz, r)),
    );
    let links = net.links.len();
    let info_per_snr = range_information_per_snr(model);
    let fill = s.table.len() >= links * (n + 1);
    let (mut f00, mut f01, mut f11) = (0.0, 0.0, 0.0);
    for (p, l) in net.links.iter().enumerate() {
        let (tv, gain) = s.tx_views[l.tx];
        let rv = s.rx_views[l.rx];
        let snr = model.snr_scale[p] * gain * tv.inv_floored_sq * rv.inv_floored_sq;
        if fill {
            s.table[n * links + p] = TruthLink {
                delay: (tv.distance + rv.distance) / SPEED_OF_LIGHT,
                sigma: sigma_delay_from_snr(model.beta2, snr),
            };
        }
        // F += w g gᵀ, w = 8π²β² SNR / c² (range-domain information, 1/m²).
        let w = info_per_snr * snr;
        let (gx, gy) = (tv.unit.x + rv.unit.x, tv.unit.y + rv.unit.y);
        f00 += w * gx * gx;
        f01 += w * gx * gy;
        f11 += w * gy * gy;
    }
    Mat2::new(f00, f01, f01, f11)
}

/// Samples truth trajectory `traj` into `s.truth`, fills its per-step tables and adds its
/// Fisher matrices to `sums`.
fn prepare_trajectory(
    model: &Model,
    cfg: &MonteCarloConfig,
    sampler: &TruthSampler,
    traj: usize,
    s: &mut Scratch,
    sums: &mut PartialSums,
) {
    sampler.sample(cfg.steps, &mut rng(cfg.seed, 2 * traj as u64), &mut s.truth);
    // Per step: true delays, σ_p at the truth (E8), and F(r_true) for E[F̃].
    for n in 1..s.truth.len() {
        let x = s.truth[n];
        sums.fisher[n] += truth_step(model, s, n, Vec2::new(x[0], x[1]));
    }
    sums.trajectories += 1;
}

/// Trajectories of chunk `chunk`.
fn chunk_range(cfg: &MonteCarloConfig, chunk: usize) -> core::ops::Range<usize> {
    let first = chunk * CHUNK_TRAJECTORIES;
    first.min(cfg.trajectories)..(first + CHUNK_TRAJECTORIES).min(cfg.trajectories)
}

/// Noise runs of one trajectory that are filtered together, step by step (independent filters
/// interleaved so the processor overlaps their dependency chains; each keeps its own stream, so
/// results do not depend on this number).
const LANES: usize = 4;

/// Runs chunk `chunk` (trajectories `chunk·16 …`) of the study and returns its sums.
/// Trajectory `i` uses stream `rng(seed, 2i)`; its noise run `j` uses `rng(seed, 2(i·N_noise + j) + 1)`.
pub fn run_chunk(model: &Model, cfg: &MonteCarloConfig, chunk: usize) -> Result<PartialSums> {
    run_chunk_in(model, cfg, chunk, Cancel::NEVER)
}

/// [`run_chunk`] that asks `cancel` every millisecond or so of work, inside a run too
/// ([`check_every`] steps of [`step_ns`]), and stops with [`Error::Cancelled`] (issue 24).
pub fn run_chunk_in(
    model: &Model,
    cfg: &MonteCarloConfig,
    chunk: usize,
    cancel: Cancel,
) -> Result<PartialSums> {
    let every = check_every(LANES as Real * step_ns(FilterKind::Ekf, model.link_count()));
    let steps = cfg.steps;
    let sampler = TruthSampler::new(cfg.motion, cfg.mean_state, &cfg.initial_covariance)?;
    // Validated once here; every run starts from a copy.
    let start = Ekf::new(cfg.mean_state, cfg.initial_covariance);
    let mut sums = PartialSums::new(steps);
    let mut s = Scratch::new(model, steps, true);
    for traj in chunk_range(cfg, chunk) {
        prepare_trajectory(model, cfg, &sampler, traj, &mut s, &mut sums);
        let mut first = 0;
        while first < cfg.noise_runs {
            let count = (cfg.noise_runs - first).min(LANES);
            let streams: [u64; LANES] = core::array::from_fn(|j| {
                2 * (traj as u64 * cfg.noise_runs as u64 + (first + j) as u64) + 1
            });
            let ok = match &start {
                Ok(ekf) => run_filters(model, cfg, *ekf, &mut s, &streams[..count], cancel, every)?,
                Err(e) => core::array::from_fn(|_| Err(e.clone())),
            };
            // Add the runs in run order (the reduction order does not depend on LANES).
            for (j, ok) in ok.into_iter().enumerate().take(count) {
                if let Err(e) = ok {
                    sums.fail(e);
                } else {
                    let lane = j * (steps + 1)..(j + 1) * (steps + 1);
                    for ((a, e), (b, v)) in sums
                        .squared_error
                        .iter_mut()
                        .zip(&s.squared_error[lane.clone()])
                        .zip(sums.nees.iter_mut().zip(&s.nees[lane]))
                    {
                        *a += e;
                        *b += v;
                    }
                    sums.runs += 1;
                }
            }
            first += count;
        }
    }
    Ok(sums)
}

/// [`run_chunk`] for any [`FilterKind`]. The truth trajectories, their streams and every noise
/// run's measurements are those of the EKF study (run `j` of trajectory `i` draws its noise from
/// the same stream in the same order), so the filters of one study are compared on the same
/// data; the EKF takes [`run_chunk`] itself. A particle filter's own draws come from a salted
/// stream per run.
pub fn run_filter_chunk(
    model: &Model,
    cfg: &MonteCarloConfig,
    filter: FilterKind,
    chunk: usize,
) -> Result<PartialSums> {
    run_filter_chunk_in(model, cfg, filter, chunk, Cancel::NEVER)
}

/// [`run_filter_chunk`] that asks `cancel` every millisecond or so of work, inside a run too
/// ([`check_every`] steps of [`step_ns`]: every step of a particle filter with 10⁶ particles),
/// and stops with [`Error::Cancelled`] (issue 24). Results equal [`run_filter_chunk`]'s.
pub fn run_filter_chunk_in(
    model: &Model,
    cfg: &MonteCarloConfig,
    filter: FilterKind,
    chunk: usize,
    cancel: Cancel,
) -> Result<PartialSums> {
    if filter == FilterKind::Ekf {
        return run_chunk_in(model, cfg, chunk, cancel);
    }
    let every = check_every(step_ns(filter, model.link_count()));
    let steps = cfg.steps;
    let sampler = TruthSampler::new(cfg.motion, cfg.mean_state, &cfg.initial_covariance)?;
    // Validated once (bad settings fail the study; a bad prior fails every run, as for the EKF).
    filter.validate()?;
    let mut sums = PartialSums::new(steps);
    let mut s = Scratch::new(model, steps, true);
    for traj in chunk_range(cfg, chunk) {
        prepare_trajectory(model, cfg, &sampler, traj, &mut s, &mut sums);
        for j in 0..cfg.noise_runs {
            let stream = 2 * (traj as u64 * cfg.noise_runs as u64 + j as u64) + 1;
            if let Err(e) = run_other_filter(model, cfg, filter, &mut s, stream, cancel, every)? {
                sums.fail(e);
            } else {
                for ((a, e), (b, v)) in sums
                    .squared_error
                    .iter_mut()
                    .zip(&s.squared_error[..steps + 1])
                    .zip(sums.nees.iter_mut().zip(&s.nees[..steps + 1]))
                {
                    *a += e;
                    *b += v;
                }
                sums.runs += 1;
            }
        }
    }
    Ok(sums)
}

/// A filter's outcome on one run: `Ok` counted, `Err` its failure (the run is excluded).
type RunOutcome = core::result::Result<(), Error>;

/// A filter (the UKF or the particle filter; the EKF's studies take [`run_chunk`]'s lanes) over the prepared truth with the measurements of noise stream
/// `stream`; fills lane 0 of `s.squared_error` and `s.nees`; the inner error if the filter
/// failed; [`Error::Cancelled`] when `cancel` asks (checked every `every` steps).
fn run_other_filter(
    model: &Model,
    cfg: &MonteCarloConfig,
    filter: FilterKind,
    s: &mut Scratch,
    stream: u64,
    cancel: Cancel,
    every: usize,
) -> Result<RunOutcome> {
    let links = model.link_count();
    let steps = s.truth.len();
    let mut noise_rng = rng(cfg.seed, stream);
    let own = rng(cfg.seed ^ PF_STREAM_SALT, stream);
    let mut f = match Tracker::new(filter, cfg.mean_state, cfg.initial_covariance, own) {
        Ok(f) => f,
        Err(e) => return Ok(Err(e)),
    };
    let (truth, table) = (&s.truth[..steps], &s.table[..links * steps]);
    let z = &mut s.measurement[..links];
    for n in 0..steps {
        if n % every == 0 {
            cancel.check()?;
        }
        let x = &truth[n];
        if n > 0 {
            let row = &table[n * links..(n + 1) * links];
            for (m, t) in z.iter_mut().zip(row) {
                *m = Some(t.delay + t.sigma * standard_normal(&mut noise_rng));
            }
            let noise = if cfg.oracle_noise {
                MeasurementNoise::At(Vec2::new(x[0], x[1]))
            } else {
                MeasurementNoise::AtPrediction
            };
            if let Err(e) = f.step(&cfg.motion, model, z, noise) {
                return Ok(Err(e));
            }
        }
        let e = f.state() - x;
        s.squared_error[n] = e[0] * e[0] + e[1] * e[1];
        match spd_quadratic_form(f.covariance(), &e) {
            Some(v) => s.nees[n] = v,
            None => return Ok(Err(not_pd_nees(f.name()))),
        }
    }
    Ok(Ok(()))
}

/// The failure of a run whose covariance stopped being positive definite (its NEES).
fn not_pd_nees(filter: &str) -> Error {
    Error::NotPositiveDefinite {
        field: alloc::format!("{filter}.covariance"),
    }
}

/// The truth half of [`run_chunk`] alone: the same trajectories (same streams) and their Fisher
/// sums, no EKF runs (`runs = 0`). What the Monte Carlo PCRLB needs; see
/// [`run_pcrlb_sequential`](super::run_pcrlb_sequential).
pub fn run_truth_chunk(model: &Model, cfg: &MonteCarloConfig, chunk: usize) -> Result<PartialSums> {
    let sampler = TruthSampler::new(cfg.motion, cfg.mean_state, &cfg.initial_covariance)?;
    let mut sums = PartialSums::new(cfg.steps);
    let mut s = Scratch::new(model, cfg.steps, false);
    for traj in chunk_range(cfg, chunk) {
        prepare_trajectory(model, cfg, &sampler, traj, &mut s, &mut sums);
    }
    Ok(sums)
}

/// EKF runs from `start` over the prepared truth, one per stream in `streams` (at most
/// [`LANES`]), advanced together step by step (one [`update_lanes`] call updates all of them).
/// Fills lane `j`'s `s.squared_error` and `s.nees`; lane `j`'s error for a run whose filter
/// failed numerically; [`Error::Cancelled`] when `cancel` asks (checked every `every` steps).
fn run_filters(
    model: &Model,
    cfg: &MonteCarloConfig,
    start: Ekf,
    s: &mut Scratch,
    streams: &[u64],
    cancel: Cancel,
    every: usize,
) -> Result<[RunOutcome; LANES]> {
    let links = model.link_count();
    let steps = s.truth.len();
    let count = streams.len().min(LANES);
    let mut ekf = [start; LANES];
    let mut rngs: [Rng; LANES] =
        core::array::from_fn(|j| rng(cfg.seed, streams.get(j).copied().unwrap_or(0)));
    let mut alive: [bool; LANES] = core::array::from_fn(|j| j < count);
    let mut outcome: [RunOutcome; LANES] = core::array::from_fn(|_| Ok(()));
    let (truth, table) = (&s.truth[..steps], &s.table[..links * steps]);
    let measurement = &mut s.measurement[..LANES * links];
    for n in 0..steps {
        if n % every == 0 {
            cancel.check()?;
        }
        let x = &truth[n];
        if n > 0 {
            let row = &table[n * links..(n + 1) * links];
            for (j, z) in measurement.chunks_exact_mut(links.max(1)).enumerate() {
                if alive[j] {
                    ekf[j].predict(&cfg.motion);
                    for (m, t) in z.iter_mut().zip(row) {
                        *m = Some(t.delay + t.sigma * standard_normal(&mut rngs[j]));
                    }
                }
            }
            let noise = if cfg.oracle_noise {
                MeasurementNoise::At(Vec2::new(x[0], x[1]))
            } else {
                MeasurementNoise::AtPrediction
            };
            let zs: [&[Option<Real>]; LANES] =
                core::array::from_fn(|j| &measurement[j * links..(j + 1) * links]);
            let done = update_lanes(&mut ekf, model, zs, alive, noise, |_, _, _| {});
            for ((a, d), o) in alive.iter_mut().zip(done).zip(&mut outcome) {
                if let (true, Err(e)) = (*a, d) {
                    *a = false;
                    *o = Err(e);
                }
            }
        }
        for j in 0..LANES {
            if alive[j] {
                let e = ekf[j].state - x;
                let k = j * steps + n;
                s.squared_error[k] = e[0] * e[0] + e[1] * e[1];
                match spd_quadratic_form(&ekf[j].covariance, &e) {
                    Some(v) => s.nees[k] = v,
                    None => {
                        alive[j] = false;
                        outcome[j] = Err(not_pd_nees("ekf"));
                    }
                }
            }
        }
    }
    Ok(outcome)
}
