//! Monte Carlo evaluation of the tracker against its bound ([S] §5.2, spec §8, §9.5):
//! `N_traj` truth trajectories from the prior, each with `N_noise` measurement-noise sequences;
//! `ε_EKF(t_n) = √(mean ‖r̂ − r‖²)`, `ε_PCRLB(t_n)` from (E9) with `E[F̃]` the mean over the same
//! truth trajectories, and the average NEES.
//!
//! Work is split into fixed chunks of trajectories whose partial sums are combined in chunk
//! order, and every trajectory and noise run draws from its own stream `rng(seed, index)`, so
//! the result depends on the seed only — not on how many threads run the chunks. This module
//! is `no_std`: the browser worker runs chunks one after another; `crate::parallel` runs them on
//! threads.

use alloc::vec;
use alloc::vec::Vec;

use crate::ekf::{
    range_information_per_snr, spd_quadratic_form, update_lanes, Ekf, MeasurementNoise, NodeView,
};
use crate::error::{Error, Result};
use crate::math::{sqrt, Mat2, Mat4, Real, Vec2, Vec4, SPEED_OF_LIGHT};
use crate::model::{sigma_delay_from_snr, Model};
use crate::motion::ConstantVelocity;
use crate::pcrlb::pcrlb_rmse;
use crate::simulate::{rng, standard_normal, Rng};
use crate::trajectory::{step_count, TruthSampler};

/// Trajectories per chunk (the unit of parallel work and of deterministic reduction).
pub const CHUNK_TRAJECTORIES: usize = 16;
/// Largest number of EKF runs (`trajectories × noise_runs`) accepted.
pub const MAX_RUNS: usize = 10_000_000;
/// Largest number of steps per run accepted.
pub const MAX_STEPS: usize = 1_000_000;

/// A Monte Carlo study.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MonteCarloConfig {
    /// Motion model (step `T`, intensity `q̃`).
    pub motion: ConstantVelocity,
    /// Number of steps after `t₀`.
    pub steps: usize,
    /// Prior mean `x̄₀` (truth mean and filter start).
    pub mean_state: Vec4,
    /// Prior covariance `P(t₀)` (truth spread and filter start).
    pub initial_covariance: Mat4,
    /// Truth trajectories `N_traj`.
    pub trajectories: usize,
    /// Noise sequences per trajectory `N_noise`.
    pub noise_runs: usize,
    /// Seed of every random stream.
    pub seed: u64,
    /// `true`: the EKF's `R` uses the link budget at the truth ("oracle"); default `false`: at
    /// the predicted position (spec §6).
    pub oracle_noise: bool,
}

impl MonteCarloConfig {
    /// The study for `steps` of `motion` covering `duration_s`.
    pub fn steps_for(motion: &ConstantVelocity, duration_s: Real) -> usize {
        step_count(duration_s, motion.dt_s)
    }

    /// Checks counts against the caps and the covariance.
    pub fn validate(&self) -> Result<()> {
        ConstantVelocity::validated(self.motion.dt_s, self.motion.intensity)?;
        let cap = |field: &'static str, value: usize, max: usize| {
            if value == 0 || value > max {
                Err(Error::SizeLimit {
                    field,
                    value,
                    min: 1,
                    max,
                })
            } else {
                Ok(())
            }
        };
        cap("runs", self.trajectories, MAX_RUNS)?;
        cap("noise_runs", self.noise_runs, MAX_RUNS)?;
        cap(
            "runs*noise_runs",
            self.trajectories.saturating_mul(self.noise_runs),
            MAX_RUNS,
        )?;
        cap("steps", self.steps, MAX_STEPS)?;
        if self.mean_state.iter().any(|v| !v.is_finite()) {
            return Err(Error::NonFinite {
                field: "initial_state".into(),
            });
        }
        crate::ekf::check_covariance("initial_covariance", &self.initial_covariance)
    }

    /// Number of chunks.
    pub fn chunk_count(&self) -> usize {
        self.trajectories.div_ceil(CHUNK_TRAJECTORIES)
    }

    /// Total EKF runs.
    pub fn runs(&self) -> usize {
        self.trajectories * self.noise_runs
    }
}

/// Per-step sums of a set of runs (combined in a fixed order).
#[derive(Debug, Clone, PartialEq)]
pub struct PartialSums {
    /// Σ ‖r̂ − r‖² over runs, per step `0 … steps`.
    pub squared_error: Vec<Real>,
    /// Σ NEES over runs, per step.
    pub nees: Vec<Real>,
    /// Σ F(r_true) over trajectories, per step (index 0 unused: no measurement at t₀).
    pub fisher: Vec<Mat2>,
    /// Runs counted (those that did not fail).
    pub runs: usize,
    /// Runs whose filter reported a numerical failure (excluded from the sums).
    pub failed_runs: usize,
    /// Trajectories counted.
    pub trajectories: usize,
}

impl PartialSums {
    /// Zero sums for `steps` steps.
    pub fn new(steps: usize) -> PartialSums {
        PartialSums {
            squared_error: vec![0.0; steps + 1],
            nees: vec![0.0; steps + 1],
            fisher: vec![Mat2::zeros(); steps + 1],
            runs: 0,
            failed_runs: 0,
            trajectories: 0,
        }
    }

    /// Adds `other` (call in chunk order for a thread-count-independent result).
    pub fn merge(&mut self, other: &PartialSums) {
        for (a, b) in self.squared_error.iter_mut().zip(&other.squared_error) {
            *a += b;
        }
        for (a, b) in self.nees.iter_mut().zip(&other.nees) {
            *a += b;
        }
        for (a, b) in self.fisher.iter_mut().zip(&other.fisher) {
            *a += b;
        }
        self.runs += other.runs;
        self.failed_runs += other.failed_runs;
        self.trajectories += other.trajectories;
    }
}

/// The curves of a study.
#[derive(Debug, Clone, PartialEq)]
pub struct MonteCarloResult {
    /// `t_n = n T`, s, `n = 0 … steps`.
    pub t_s: Vec<Real>,
    /// `ε_EKF(t_n)`, m.
    pub rmse_ekf_m: Vec<Real>,
    /// `ε_PCRLB(t_n)`, m (`None` if the information became singular).
    pub rmse_pcrlb_m: Vec<Option<Real>>,
    /// Average NEES per step (4 degrees of freedom for a consistent filter).
    pub nees: Vec<Real>,
    /// EKF runs counted.
    pub runs: usize,
    /// EKF runs that failed numerically (excluded).
    pub failed_runs: usize,
    /// The seed.
    pub seed: u64,
}

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
/// instead of per link; equal to [`Network::delay`](crate::geometry::Network::delay),
/// [`Model::sigma_delay`] and [`fisher`](crate::crlb::fisher) up to rounding.
fn truth_step(model: &Model, s: &mut Scratch, n: usize, r: Vec2) -> Mat2 {
    let net = &model.network;
    s.tx_views.clear();
    for (k, &tx) in net.transmitters.iter().enumerate() {
        let v = NodeView::new(tx, r);
        s.tx_views.push((v, model.patterns[k].gain_toward(v.unit)));
    }
    s.rx_views.clear();
    s.rx_views
        .extend(net.receivers.iter().map(|&rx| NodeView::new(rx, r)));
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
            let ok = match start {
                Ok(ekf) => run_filters(model, cfg, ekf, &mut s, &streams[..count]),
                Err(_) => [false; LANES],
            };
            // Add the runs in run order (the reduction order does not depend on LANES).
            for (j, &ok) in ok.iter().enumerate().take(count) {
                if ok {
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
                } else {
                    sums.failed_runs += 1;
                }
            }
            first += count;
        }
    }
    Ok(sums)
}

/// The truth half of [`run_chunk`] alone: the same trajectories (same streams) and their Fisher
/// sums, no EKF runs (`runs = 0`). What the Monte Carlo PCRLB needs; see [`run_pcrlb_sequential`].
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
/// Fills lane `j`'s `s.squared_error` and `s.nees`; `false` for a run whose filter failed
/// numerically.
fn run_filters(
    model: &Model,
    cfg: &MonteCarloConfig,
    start: Ekf,
    s: &mut Scratch,
    streams: &[u64],
) -> [bool; LANES] {
    let links = model.link_count();
    let steps = s.truth.len();
    let count = streams.len().min(LANES);
    let mut ekf = [start; LANES];
    let mut rngs: [Rng; LANES] =
        core::array::from_fn(|j| rng(cfg.seed, streams.get(j).copied().unwrap_or(0)));
    let mut alive: [bool; LANES] = core::array::from_fn(|j| j < count);
    let (truth, table) = (&s.truth[..steps], &s.table[..links * steps]);
    let measurement = &mut s.measurement[..LANES * links];
    for n in 0..steps {
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
            for (a, d) in alive.iter_mut().zip(&done) {
                *a &= d.is_ok();
            }
        }
        for j in 0..LANES {
            if alive[j] {
                let e = ekf[j].state - x;
                let k = j * steps + n;
                s.squared_error[k] = e[0] * e[0] + e[1] * e[1];
                match spd_quadratic_form(&ekf[j].covariance, &e) {
                    Some(v) => s.nees[k] = v,
                    None => alive[j] = false,
                }
            }
        }
    }
    alive
}

/// Turns the combined sums into the curves (E9 with the Monte Carlo mean Fisher matrices).
pub fn finish(cfg: &MonteCarloConfig, sums: &PartialSums) -> Result<MonteCarloResult> {
    if sums.runs == 0 {
        return Err(Error::SizeLimit {
            field: "runs (successful)",
            value: 0,
            min: 1,
            max: MAX_RUNS,
        });
    }
    let runs = sums.runs as Real;
    let trajectories = sums.trajectories.max(1) as Real;
    let mean_fishers: Vec<Mat2> = sums.fisher[1..].iter().map(|f| f / trajectories).collect();
    Ok(MonteCarloResult {
        t_s: (0..=cfg.steps)
            .map(|n| n as Real * cfg.motion.dt_s)
            .collect(),
        rmse_ekf_m: sums.squared_error.iter().map(|v| sqrt(v / runs)).collect(),
        rmse_pcrlb_m: pcrlb_rmse(&cfg.motion, &cfg.initial_covariance, &mean_fishers)?,
        nees: sums.nees.iter().map(|v| v / runs).collect(),
        runs: sums.runs,
        failed_runs: sums.failed_runs,
        seed: cfg.seed,
    })
}

/// Runs the whole study on the calling thread, chunk by chunk. `on_chunk(done, total)` is called
/// after each chunk and may return `false` to cancel (then `Err(Error::Cancelled)`).
pub fn run_sequential(
    model: &Model,
    cfg: &MonteCarloConfig,
    mut on_chunk: impl FnMut(usize, usize) -> bool,
) -> Result<MonteCarloResult> {
    cfg.validate()?;
    let total = cfg.chunk_count();
    let mut sums = PartialSums::new(cfg.steps);
    for chunk in 0..total {
        sums.merge(&run_chunk(model, cfg, chunk)?);
        if !on_chunk(chunk + 1, total) {
            return Err(Error::Cancelled);
        }
    }
    finish(cfg, &sums)
}

/// The Monte Carlo PCRLB alone (spec §8, check 10): `ε_PCRLB(t_n)` from (E9) with `E[F̃]` the
/// mean over the study's truth trajectories — the same trajectories (streams `rng(seed, 2i)`),
/// chunks and merge order as [`run_sequential`], so the curve equals its `rmse_pcrlb_m`, but
/// without the EKF runs (`noise_runs` is ignored). `on_chunk` as in [`run_sequential`].
pub fn run_pcrlb_sequential(
    model: &Model,
    cfg: &MonteCarloConfig,
    mut on_chunk: impl FnMut(usize, usize) -> bool,
) -> Result<Vec<Option<Real>>> {
    MonteCarloConfig {
        noise_runs: 1,
        ..*cfg
    }
    .validate()?;
    let total = cfg.chunk_count();
    let mut sums = PartialSums::new(cfg.steps);
    for chunk in 0..total {
        sums.merge(&run_truth_chunk(model, cfg, chunk)?);
        if !on_chunk(chunk + 1, total) {
            return Err(Error::Cancelled);
        }
    }
    let trajectories = sums.trajectories.max(1) as Real;
    let mean_fishers: Vec<Mat2> = sums.fisher[1..].iter().map(|f| f / trajectories).collect();
    pcrlb_rmse(&cfg.motion, &cfg.initial_covariance, &mean_fishers)
}
