//! The Monte Carlo study of delay and Doppler (issue 42 §3–4; docs/doppler.md D5, D7, D8): one
//! filter tracks the same truths from the same delays twice — with the range rates of the scan's
//! CPI and without — against the PCRLB of each (the state recursion of E9 with the mean state
//! Fisher information over the runs' truths, D7), position and velocity RMSE and the mean NEES
//! per step.
//!
//! Each scan is one CPI of `N` snapshots: its delays have E8's σ over `√N` (`σ_τ/√N`, at the
//! truth; a delay drawn outside (0, 1] s is missing, and a link whose σ at the prediction is
//! beyond [`limits::DELAY_SIGMA_S`] is left out of the update), its range rates D5's σ (at the truth, the floor included as noise: the filter's model
//! is then exact). Run `k` draws its truth and both measurement sets from `rng(seed, k)`, so the
//! two filters see the same data and a result depends on the seed only.

use alloc::vec;
use alloc::vec::Vec;

use crate::error::{limits, Cancel, Error, Result};
use crate::math::{sqrt, Mat4, Real, Vec2, Vec4};
use crate::measure::{rng, standard_normal, state_fisher, Cpi, LinkMotion, Model};
use crate::track::{
    ConstantVelocity, Filter, FilterKind, MeasurementNoise, PosteriorInformation, RangeRates,
    RateNoise, Tracker, TruthSampler,
};

/// A CPI as the documents write it (`crlb --doppler`'s `doppler.cpi`, `track`'s `doppler.cpi`).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct CpiDoc {
    /// `N`.
    pub snapshots: usize,
    /// `T`, s.
    pub spacing_s: Real,
    /// `λ`, m.
    pub wavelength_m: Real,
    /// `σ_floor`, m/s.
    pub floor_mps: Real,
}

impl From<&Cpi> for CpiDoc {
    fn from(c: &Cpi) -> CpiDoc {
        CpiDoc {
            snapshots: c.snapshots,
            spacing_s: c.spacing_s,
            wavelength_m: c.wavelength_m,
            floor_mps: c.floor_mps,
        }
    }
}

/// Most runs of a Doppler study.
pub const MAX_DOPPLER_RUNS: usize = 100_000;

/// A Doppler Monte Carlo study: `runs` truths of `steps` scans from the prior
/// `𝒩(mean_state, initial_covariance)` on `motion`, each scan a CPI `cpi`, tracked by `filter`.
#[derive(Debug, Clone, PartialEq)]
pub struct DopplerStudy {
    /// The CV model (scan interval and `q`).
    pub motion: ConstantVelocity,
    /// `x̄₀`, m and m/s.
    pub mean_state: Vec4,
    /// `P(t₀)`.
    pub initial_covariance: Mat4,
    /// The CPI of every scan.
    pub cpi: Cpi,
    /// Scans after `t₀`.
    pub steps: usize,
    /// Monte Carlo runs (1 … [`MAX_DOPPLER_RUNS`]).
    pub runs: usize,
    /// Seed of the runs' streams.
    pub seed: u64,
    /// The filter of both arms.
    pub filter: FilterKind,
}

/// One arm's curves, one entry per step `0 … steps` (`None`: unbounded, or no run left).
#[derive(Debug, Clone, PartialEq, Default, serde::Serialize)]
pub struct DopplerArm {
    /// Position RMSE over the runs, m.
    pub position_rmse_m: Vec<Real>,
    /// Velocity RMSE, m/s.
    pub velocity_rmse_mps: Vec<Real>,
    /// Mean NEES (4 degrees of freedom).
    pub mean_nees: Vec<Real>,
    /// PCRLB of the position, m.
    pub position_bound_m: Vec<Option<Real>>,
    /// PCRLB of the velocity, m/s.
    pub velocity_bound_mps: Vec<Option<Real>>,
    /// The bound of each run's own truth, averaged: `√(mean_k tr P_k,rr)` with `P_k` the
    /// recursion of E9 on run `k`'s Fisher information alone, m (`None` where any run's is
    /// singular). Not a Bayesian bound: by Jensen it is ≥ the PCRLB of the mean information, and
    /// it is what an efficient filter reaches on trajectories that spread into geometries of
    /// unequal information (the diagnostic of docs/doppler.md, "Monte Carlo").
    pub position_per_run_bound_m: Vec<Option<Real>>,
    /// The same for the velocity, m/s.
    pub velocity_per_run_bound_mps: Vec<Option<Real>>,
    /// Runs whose filter failed (an update error or a covariance without NEES); they are left
    /// out of the RMSE and NEES (empty when every run failed).
    pub failed_runs: usize,
}

/// Both arms of a [`DopplerStudy`].
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct DopplerResult {
    /// Delays only.
    pub delay_only: DopplerArm,
    /// Delays and range rates.
    pub with_doppler: DopplerArm,
}

impl DopplerStudy {
    /// Runs the study on `model` (sequentially: `runs × steps × 2` filter steps). Named errors for a run
    /// count outside 1 … [`MAX_DOPPLER_RUNS`], no steps, or a bad prior.
    pub fn run(&self, model: &Model) -> Result<DopplerResult> {
        self.run_with(model, Cancel::NEVER, &mut |_| {})
    }

    /// [`DopplerStudy::run`], asking `cancel` before each run ([`Error::Cancelled`]) and calling
    /// `progress` with the runs done after each.
    pub fn run_with(
        &self,
        model: &Model,
        cancel: Cancel,
        progress: &mut dyn FnMut(usize),
    ) -> Result<DopplerResult> {
        if !(1..=MAX_DOPPLER_RUNS).contains(&self.runs) {
            return Err(Error::SizeLimit {
                field: "runs",
                value: self.runs,
                min: 1,
                max: MAX_DOPPLER_RUNS,
            });
        }
        if self.steps == 0 {
            return Err(Error::SizeLimit {
                field: "steps",
                value: 0,
                min: 1,
                max: crate::track::MAX_STEPS,
            });
        }
        self.filter.validate()?;
        let sampler = TruthSampler::new(self.motion, self.mean_state, &self.initial_covariance)?;
        let steps = self.steps;
        let mut arms = [Acc::new(steps), Acc::new(steps)];
        let mut fisher = [vec![Mat4::zeros(); steps], vec![Mat4::zeros(); steps]];
        // Per arm and step: Σ_k tr P_k,rr and Σ_k tr P_k,vv of the runs' own recursions, and
        // whether every run's stayed bounded.
        let mut per_run = [
            vec![(0.0, 0.0, true); steps + 1],
            vec![(0.0, 0.0, true); steps + 1],
        ];
        let mut truth = Vec::new();
        for k in 0..self.runs {
            cancel.check()?;
            let mut g = rng(self.seed, k as u64);
            sampler.sample(steps, &mut g, &mut truth);
            for (d, (f, sums)) in fisher.iter_mut().zip(&mut per_run).enumerate() {
                let mut own = PosteriorInformation::new(&self.initial_covariance)?;
                add_bound(&mut sums[0], &own);
                // Once a run's recursion fails, its later steps are unbounded too.
                let mut alive = true;
                for (n, x) in truth.iter().skip(1).enumerate() {
                    let fx = state_fisher(model, x, &self.cpi, d == 1);
                    f[n] += fx;
                    alive = alive && own.step_state(&self.motion, &fx).is_ok();
                    if alive {
                        add_bound(&mut sums[n + 1], &own);
                    } else {
                        sums[n + 1].2 = false;
                    }
                }
            }
            let scans = self.scans(model, &truth, &mut g);
            let start = self.mean_state;
            for (d, acc) in arms.iter_mut().enumerate() {
                let filter_rng = rng(self.seed ^ 0x005E_EDD0_991E, (2 * k + d) as u64);
                let mut f = Tracker::new(self.filter, start, self.initial_covariance, filter_rng)?;
                acc.run(model, &mut f, &truth, &scans, d == 1, self);
            }
            progress(k + 1);
        }
        let mut out = arms.map(|a| a.finish());
        let runs = self.runs as Real;
        for (arm, sums) in out.iter_mut().zip(&per_run) {
            for &(p, v, ok) in sums {
                arm.position_per_run_bound_m
                    .push(ok.then(|| sqrt(p / runs)));
                arm.velocity_per_run_bound_mps
                    .push(ok.then(|| sqrt(v / runs)));
            }
        }
        for (arm, f) in out.iter_mut().zip(&fisher) {
            let mut fb = PosteriorInformation::new(&self.initial_covariance)?;
            arm.position_bound_m.push(fb.position_rmse());
            arm.velocity_bound_mps.push(fb.velocity_rmse());
            for fk in f {
                let ok = fb
                    .step_state(&self.motion, &(fk / self.runs as Real))
                    .is_ok();
                arm.position_bound_m.push(fb.position_rmse().filter(|_| ok));
                arm.velocity_bound_mps
                    .push(fb.velocity_rmse().filter(|_| ok));
            }
        }
        let [delay_only, with_doppler] = out;
        Ok(DopplerResult {
            delay_only,
            with_doppler,
        })
    }
}

/// One scan's measurements: the delays and the range rates of every link.
struct Scan {
    delays: Vec<Option<Real>>,
    rates: Vec<Option<Real>>,
}

impl DopplerStudy {
    /// The scans of one truth (module docs): per link a delay with `σ_τ/√N` and a range rate with
    /// D5's σ, both at the truth.
    fn scans(&self, model: &Model, truth: &[Vec4], g: &mut crate::measure::Rng) -> Vec<Scan> {
        let root_n = sqrt(self.cpi.snapshots as Real);
        truth
            .iter()
            .skip(1)
            .map(|x| {
                let (r, v) = (Vec2::new(x[0], x[1]), Vec2::new(x[2], x[3]));
                let links = model.link_count();
                let mut delays = Vec::with_capacity(links);
                let mut rates = Vec::with_capacity(links);
                for p in 0..links {
                    let m = LinkMotion::new(&model.network, p, r, v);
                    let s = model.sigma_delay(p, r) / root_n;
                    // A delay drawn at or below 0 (σ of the order of the delay: the truth far
                    // outside the network) is no measurement.
                    let d = model.network.delay(p, r) + s * standard_normal(g);
                    delays.push(limits::DELAY_S.contains(d).then_some(d));
                    let sr = self.cpi.sigma_range_rate(m.snr(model, p));
                    let e = standard_normal(g);
                    rates.push(sr.is_finite().then_some(m.range_rate_mps + sr * e));
                }
                Scan { delays, rates }
            })
            .collect()
    }
}

/// Sums of one arm over the runs.
struct Acc {
    pos2: Vec<Real>,
    vel2: Vec<Real>,
    nees: Vec<Real>,
    runs: usize,
    failed: usize,
}

impl Acc {
    fn new(steps: usize) -> Acc {
        Acc {
            pos2: vec![0.0; steps + 1],
            vel2: vec![0.0; steps + 1],
            nees: vec![0.0; steps + 1],
            runs: 0,
            failed: 0,
        }
    }

    /// One run of `f` over `scans` (with the rates if `doppler`), its errors added when every
    /// step succeeded. The delays' σ is the link budget's at the prediction over `√N`, the
    /// rates' the CPI's at the prediction.
    fn run(
        &mut self,
        model: &Model,
        f: &mut Tracker,
        truth: &[Vec4],
        scans: &[Scan],
        doppler: bool,
        study: &DopplerStudy,
    ) {
        let root_n = sqrt(study.cpi.snapshots as Real);
        let none = vec![None; model.link_count()];
        let mut errs = Vec::with_capacity(truth.len());
        let mut record = |f: &Tracker, x: &Vec4| {
            let e = f.state() - x;
            errs.push((
                e[0] * e[0] + e[1] * e[1],
                e[2] * e[2] + e[3] * e[3],
                f.nees(x),
            ));
        };
        record(f, &truth[0]);
        for (scan, x) in scans.iter().zip(&truth[1..]) {
            f.predict(&study.motion);
            let r = f.position();
            let sigmas: Vec<Real> = (0..model.link_count())
                .map(|p| model.sigma_delay(p, r) / root_n)
                .collect();
            // A link whose σ at the prediction is beyond any delay σ (the truth far outside
            // the network) carries nothing: its delay is left out.
            let z: Vec<Option<Real>> = scan
                .delays
                .iter()
                .zip(&sigmas)
                .map(|(d, s)| d.filter(|_| limits::DELAY_SIGMA_S.contains(*s)))
                .collect();
            let sigmas: Vec<Real> = sigmas
                .iter()
                .map(|s| s.clamp(limits::DELAY_SIGMA_S.min, limits::DELAY_SIGMA_S.max))
                .collect();
            let rates = RangeRates {
                rates_mps: if doppler { &scan.rates } else { &none },
                noise: RateNoise::Cpi(study.cpi),
            };
            let noise = MeasurementNoise::Fixed(&sigmas);
            if f.update_doppler(model, &z, noise, &rates).is_err() {
                self.failed += 1;
                return;
            }
            record(f, x);
        }
        if errs.iter().any(|(_, _, n)| n.is_none()) {
            self.failed += 1;
            return;
        }
        for (k, (p, v, n)) in errs.into_iter().enumerate() {
            self.pos2[k] += p;
            self.vel2[k] += v;
            self.nees[k] += n.unwrap_or_default();
        }
        self.runs += 1;
    }

    /// The curves (empty when every run failed).
    fn finish(self) -> DopplerArm {
        let n = self.runs as Real;
        let ok = self.runs > 0;
        let root = |v: &Vec<Real>| v.iter().filter(|_| ok).map(|s| sqrt(s / n)).collect();
        DopplerArm {
            position_rmse_m: root(&self.pos2),
            velocity_rmse_mps: root(&self.vel2),
            mean_nees: self.nees.iter().filter(|_| ok).map(|s| s / n).collect(),
            position_bound_m: Vec::new(),
            velocity_bound_mps: Vec::new(),
            position_per_run_bound_m: Vec::new(),
            velocity_per_run_bound_mps: Vec::new(),
            failed_runs: self.failed,
        }
    }
}

/// Adds `own`'s `tr P_rr` and `tr P_vv` (its bounds squared) to `sum`; an unbounded one marks
/// the step unbounded.
fn add_bound(sum: &mut (Real, Real, bool), own: &PosteriorInformation) {
    match (own.position_rmse(), own.velocity_rmse()) {
        (Some(p), Some(v)) => {
            sum.0 += p * p;
            sum.1 += v * v;
        }
        _ => sum.2 = false,
    }
}
