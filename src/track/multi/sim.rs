//! The multi-target scenarios (issue 41 §3): Williams-15 (the standard check of the PMBM
//! literature, defined by García-Fernández's MTT repository: 4 targets that meet at the
//! midpoint of 81 steps, position measurements) and people walking in a delay network
//! (crossing, side by side, one standing still a while), with their scans: detections with
//! probability `P_D`, Gaussian noise, Poisson clutter uniform over the region or the delay
//! window. Seeded: a scan depends on the seed only.

use alloc::format;
use alloc::vec;
use alloc::vec::Vec;

use crate::error::limits::COORDINATE_M;
use crate::error::{check_positive, Error, Result};
use crate::math::{exp, sqrt, Mat4, Real, Vec2, Vec4};
use crate::measure::{standard_normal, uniform01, Model, Rng};
use crate::scenario::{presets, Area, Pattern, Scenario, Transmitter};
use crate::track::multi::sensors::Detection;
use crate::track::multi::Component;
use crate::track::ConstantVelocity;

/// The true targets: per step, `(label, [x, y, vx, vy])` of each target present.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Truth {
    /// Per step, the targets present.
    pub steps: Vec<Vec<(u64, Vec4)>>,
}

impl Truth {
    /// Positions at step `k`.
    pub fn positions(&self, k: usize) -> Vec<Vec2> {
        self.steps[k]
            .iter()
            .map(|(_, x)| Vec2::new(x[0], x[1]))
            .collect()
    }
}

/// The constants of Williams-15 (García-Fernández et al., TAES 54(4), 2018, Fig. 2; the MTT
/// repository's `ScenarioWilliams15.m`): `T = 1`, `q̃ = 0.01`, `R = I`, `P_D = 0.9`,
/// `p_S = 0.99`, 10 clutter per scan over `[0, 300]²`, 81 steps, 4 targets at
/// `(150, 150)` at step 41 (`P = 0.1 I`), target 1 gone from step 41; birth intensity
/// `0.005 𝒩([100, 100, 0, 0], diag(150², 150², 1, 1))` per scan and `3 ×` that Gaussian at the
/// start; GOSPA `c = 10`, `p = 2`, 100 runs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Williams15 {
    /// Steps (81).
    pub steps: usize,
    /// `P_D` (0.9).
    pub detection: Real,
    /// Mean clutter per scan (10).
    pub clutter: Real,
    /// Side of the square region, m (300).
    pub side_m: Real,
    /// Measurement σ per axis, m (1).
    pub sigma_m: Real,
    /// The CV model (`T = 1`, `q̃ = 0.01`).
    pub motion: ConstantVelocity,
}

/// Williams-15's constants.
pub fn williams15() -> Williams15 {
    Williams15 {
        steps: 81,
        detection: 0.9,
        clutter: 10.0,
        side_m: 300.0,
        sigma_m: 1.0,
        motion: ConstantVelocity::new(1.0, 0.01),
    }
}

impl Williams15 {
    /// The birth Gaussian `𝒩([100, 100, 0, 0], diag(150², 150², 1, 1))` with weight `w`.
    pub fn birth(&self, w: Real) -> Component {
        Component {
            weight: w,
            state: Vec4::new(100.0, 100.0, 0.0, 0.0),
            covariance: Mat4::from_diagonal(&Vec4::new(150.0 * 150.0, 150.0 * 150.0, 1.0, 1.0)),
        }
    }
}

/// One draw of Williams-15's truth: the 4 states drawn at the midpoint and run forward and
/// backward by the CV model (`TrajectoryWilliams15.m`, scenario 1).
pub fn williams15_truth(w: &Williams15, rng: &mut Rng) -> Truth {
    let n = w.steps;
    let mid = n.div_ceil(2) - 1; // 0-based step 40 of 81
    let motion = w.motion;
    let l = motion.process_noise_factor();
    let a = motion.transition();
    let a_inv = a.try_inverse().unwrap_or(a);
    let mut states = vec![vec![Vec4::zeros(); 4]; n];
    for x in states[mid].iter_mut() {
        *x = Vec4::new(
            w.side_m / 2.0 + sqrt(0.1) * standard_normal(rng),
            w.side_m / 2.0 + sqrt(0.1) * standard_normal(rng),
            sqrt(0.1) * standard_normal(rng),
            sqrt(0.1) * standard_normal(rng),
        );
    }
    let noise = |rng: &mut Rng| {
        l * Vec4::new(
            standard_normal(rng),
            standard_normal(rng),
            standard_normal(rng),
            standard_normal(rng),
        )
    };
    let (mut f, mut b) = (states[mid].clone(), states[mid].clone());
    for k in 1..=mid {
        for t in 0..4 {
            f[t] = a * f[t] + noise(rng);
            b[t] = a_inv * (b[t] + noise(rng));
        }
        states[mid + k] = f.clone();
        states[mid - k] = b.clone();
    }
    let steps = (0..n)
        .map(|k| {
            (0..4)
                .filter(|&t| t != 0 || k < mid)
                .map(|t| (t as u64, states[k][t]))
                .collect()
        })
        .collect();
    Truth { steps }
}

/// A Poisson count of mean `lambda` (Knuth's product of uniforms; at most `8λ + 64` draws, the
/// stated bound, far in the tail for the means used here).
pub fn poisson(lambda: Real, rng: &mut Rng) -> usize {
    let limit = exp(-lambda);
    let (mut k, mut p) = (0usize, 1.0);
    let cap = (8.0 * lambda) as usize + 64;
    loop {
        p *= uniform01(rng);
        if p <= limit || k >= cap {
            return k;
        }
        k += 1;
    }
}

/// Position scans of `truth`: each target detected with probability `P_D` with noise `σ`
/// per axis, then Poisson clutter uniform over `[0, side]²` (one sensor).
pub fn position_scans(
    truth: &Truth,
    detection: Real,
    sigma_m: Real,
    clutter: Real,
    side_m: Real,
    rng: &mut Rng,
) -> Vec<Vec<Vec<Detection>>> {
    truth
        .steps
        .iter()
        .map(|targets| {
            let mut d = Vec::new();
            for (_, x) in targets {
                if uniform01(rng) < detection {
                    let p = Vec2::new(
                        x[0] + sigma_m * standard_normal(rng),
                        x[1] + sigma_m * standard_normal(rng),
                    );
                    d.push(Detection::position(p));
                }
            }
            for _ in 0..poisson(clutter, rng) {
                let p = Vec2::new(side_m * uniform01(rng), side_m * uniform01(rng));
                d.push(Detection::position(p));
            }
            vec![d]
        })
        .collect()
}

/// The people layout: `sensors2019` (\[S\]: Tx at the origin, 4 receivers) with a second,
/// omnidirectional transmitter at (14, 4) m: 2 Tx × 4 Rx = 8 links.
pub fn people_layout() -> Scenario {
    let mut s = presets::sensors2019();
    s.name = "people-2x4".into();
    s.transmitters.push(Transmitter {
        name: "Tx2".into(),
        height_m: 0.0,
        position_m: [14.0, 4.0],
        power_dbm: 37.0,
        gain_dbi: 9.0,
        pattern: Pattern::Omni,
    });
    s
}

/// The region the people walk in, m.
pub fn people_region() -> Area {
    Area {
        x: [0.5, 9.5],
        y: [0.5, 8.5],
    }
}

/// People walking for `steps` scans at spacing `dt_s` (`walkers` in 1..=5, capped) in
/// [`people_region`]: 0 and 1 cross at the middle of the run; 2 and 3 walk side by side 0.7 m
/// apart; 4 stands still for the first half, then walks. Each path's ends move by
/// 𝒩(0, 0.2²) m per run.
pub fn people_truth(walkers: usize, steps: usize, dt_s: Real, rng: &mut Rng) -> Truth {
    people_truth_in(&people_region(), walkers, steps, dt_s, rng)
}

/// [`people_truth`] with the paths stretched from [`people_region`] onto `region` (the
/// side-by-side spacing stays 0.7 m).
pub fn people_truth_in(
    region: &Area,
    walkers: usize,
    steps: usize,
    dt_s: Real,
    rng: &mut Rng,
) -> Truth {
    let plans: [([Real; 2], [Real; 2], Real); 5] = [
        ([1.5, 1.5], [8.5, 7.5], 0.0),
        ([1.5, 7.5], [8.5, 1.5], 0.0),
        ([8.5, 2.6], [1.5, 2.6], 0.0),
        ([8.5, 3.3], [1.5, 3.3], 0.0),
        ([3.0, 6.0], [7.0, 6.5], 0.5),
    ];
    let base = people_region();
    let map = |p: [Real; 2]| {
        Vec2::new(
            region.x[0]
                + (p[0] - base.x[0]) * (region.x[1] - region.x[0]) / (base.x[1] - base.x[0]),
            region.y[0]
                + (p[1] - base.y[0]) * (region.y[1] - region.y[0]) / (base.y[1] - base.y[0]),
        )
    };
    let w = walkers.clamp(1, MAX_WALKERS);
    let jitter = |rng: &mut Rng| Vec2::new(0.2 * standard_normal(rng), 0.2 * standard_normal(rng));
    let mut paths: Vec<(Vec2, Vec2, Real)> = plans[..w]
        .iter()
        .map(|(a, b, still)| {
            let a = map(*a) + jitter(rng);
            let b = map(*b) + jitter(rng);
            (a, b, *still)
        })
        .collect();
    if w >= 4 {
        // Side by side with walker 2: its path moved 0.7 m to the side.
        let side = Vec2::new(0.0, 0.7);
        paths[3] = (paths[2].0 + side, paths[2].1 + side, 0.0);
    }
    walk(&paths, steps, dt_s)
}

/// The most walkers a run holds (the plans of [`people_truth_in`], the drawn paths of
/// [`people_truth_drawn`]).
pub const MAX_WALKERS: usize = 5;

/// A walker's drawn path: its start `[x0, y0]` and end `[x1, y1]`, m.
pub type DrawnPath = ([Real; 2], [Real; 2]);

/// Checks drawn walker paths: 1 ..= [`MAX_WALKERS`] of them ([`Error::SizeLimit`] `paths`),
/// every coordinate finite and in [`COORDINATE_M`] ([`Error::NonFinite`] or
/// [`Error::OutOfRange`] naming `paths[i].x0` … `paths[i].y1`).
pub fn check_drawn_paths(paths: &[DrawnPath]) -> Result<()> {
    if !(1..=MAX_WALKERS).contains(&paths.len()) {
        return Err(Error::SizeLimit {
            field: "paths",
            value: paths.len(),
            min: 1,
            max: MAX_WALKERS,
        });
    }
    for (i, (a, b)) in paths.iter().enumerate() {
        for (name, v) in [("x0", a[0]), ("y0", a[1]), ("x1", b[0]), ("y1", b[1])] {
            COORDINATE_M.check(&format!("paths[{i}].{name}"), v)?;
        }
    }
    Ok(())
}

/// Walkers on drawn paths (labels `0..n` in the order given): walker `i` walks the straight
/// line from its start to its end at constant velocity over the run, `(steps − 1) dt_s` (the
/// convention of the single-target drawn trajectory: press = start, release = where it is at
/// the end), so at scan `k` it is at `a + (b − a) k dt_s / ((steps − 1) dt_s)` with velocity
/// `(b − a) / ((steps − 1) dt_s)`. Checked by [`check_drawn_paths`]; `dt_s` must be > 0
/// ([`Error::NotPositive`]).
pub fn people_truth_drawn(paths: &[DrawnPath], steps: usize, dt_s: Real) -> Result<Truth> {
    check_drawn_paths(paths)?;
    check_positive("dt_s", dt_s)?;
    let paths: Vec<(Vec2, Vec2, Real)> = paths
        .iter()
        .map(|(a, b)| (Vec2::new(a[0], a[1]), Vec2::new(b[0], b[1]), 0.0))
        .collect();
    Ok(walk(&paths, steps, dt_s))
}

/// Walkers on straight paths `(start, end, still)` over `steps` scans at `dt_s`: each stands at
/// its start for the fraction `still` of the run, then walks to its end at constant velocity,
/// arriving at the last scan.
fn walk(paths: &[(Vec2, Vec2, Real)], steps: usize, dt_s: Real) -> Truth {
    let total = (steps.max(2) - 1) as Real * dt_s;
    let steps = (0..steps)
        .map(|k| {
            let t = k as Real * dt_s;
            paths
                .iter()
                .enumerate()
                .map(|(i, (a, b, still))| {
                    let t0 = still * total;
                    let span = total - t0;
                    let v = (b - a) / span;
                    let (p, v) = if t < t0 {
                        (*a, Vec2::zeros())
                    } else {
                        (a + v * (t - t0), v)
                    };
                    (i as u64, Vec4::new(p.x, p.y, v.x, v.y))
                })
                .collect()
        })
        .collect();
    Truth { steps }
}

/// Delay scans of `truth` on `model`'s links: each target detected on each link with
/// probability `P_D`, its delay with σ from E8 at the truth, then Poisson clutter (mean
/// `clutter` per link) uniform over `[τ_LOS, τ_LOS + window_s]` of the link.
pub fn delay_scans(
    model: &Model,
    truth: &Truth,
    detection: Real,
    clutter: Real,
    window_s: Real,
    rng: &mut Rng,
) -> Vec<Vec<Vec<Detection>>> {
    scans_of(model, truth, detection, clutter, window_s, None, rng)
}

/// [`delay_scans`] with each detection's range rate (issue 42 §3): a target's is `ṙ_p` of its
/// true state (D1) plus noise of σ `rate_sigma_mps`, a clutter detection's uniform over
/// [`CLUTTER_RATE_SPAN_MPS`](crate::track::multi::CLUTTER_RATE_SPAN_MPS) about 0 (the
/// detections carry `rate_sigma_mps` as their σ). The same stream gives the same delays as
/// [`delay_scans`] only without rates (the rates take draws).
pub fn delay_rate_scans(
    model: &Model,
    truth: &Truth,
    detection: Real,
    clutter: Real,
    window_s: Real,
    rate_sigma_mps: Real,
    rng: &mut Rng,
) -> Vec<Vec<Vec<Detection>>> {
    scans_of(
        model,
        truth,
        detection,
        clutter,
        window_s,
        Some(rate_sigma_mps),
        rng,
    )
}

fn scans_of(
    model: &Model,
    truth: &Truth,
    detection: Real,
    clutter: Real,
    window_s: Real,
    rate_sigma: Option<Real>,
    rng: &mut Rng,
) -> Vec<Vec<Vec<Detection>>> {
    let span = crate::track::multi::CLUTTER_RATE_SPAN_MPS;
    let links = model.link_count();
    truth
        .steps
        .iter()
        .map(|targets| {
            (0..links)
                .map(|p| {
                    let mut d = Vec::new();
                    for (_, x) in targets {
                        if uniform01(rng) < detection {
                            let r = Vec2::new(x[0], x[1]);
                            let s = model.sigma_delay(p, r);
                            let tau = model.network.delay(p, r) + s * standard_normal(rng);
                            d.push(match rate_sigma {
                                None => Detection::delay(tau, None),
                                Some(sr) => {
                                    let v = Vec2::new(x[2], x[3]);
                                    let rate = crate::measure::range_rate(&model.network, p, r, v);
                                    let rate = rate + sr * standard_normal(rng);
                                    Detection::delay_rate(tau, None, rate, sr)
                                }
                            });
                        }
                    }
                    let lo = model.network.los_delay(p);
                    for _ in 0..poisson(clutter, rng) {
                        let tau = lo + window_s * uniform01(rng);
                        d.push(match rate_sigma {
                            None => Detection::delay(tau, None),
                            Some(sr) => {
                                let rate = span * (uniform01(rng) - 0.5);
                                Detection::delay_rate(tau, None, rate, sr)
                            }
                        });
                    }
                    d
                })
                .collect()
        })
        .collect()
}
