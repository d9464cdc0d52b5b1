//! The signal-level channel simulator (issue 25 §2): recordings in the layout of C1 of a scene
//! with walls (first- and second-order specular reflections by the image method), point
//! scatterers, and a walking person modelled as an extended, fluctuating scatterer that also
//! reflects via the walls and shadows the LoS and wall paths it stands in. Amplitudes come from
//! the scenario's link budget and Tx pattern (E8) and noise follows C3, so a path's
//! `|α|²/P_n` is the link budget's SNR. Seeded and deterministic (only `crate::math`
//! functions).
//!
//! Per snapshot `s` and link `p` (C1, C3):
//! `H_p[n] = Σ_i α_i e^{−j2π f_n τ_i} + w[n]`, `f_n = (n − (N−1)/2)·Δf`, `Δf = B/N`,
//! `w ~ CN(0, σ_p²)`, `σ_p² = N·P_n/G_p` (`G_p` the processing gain, 1 when none is
//! configured), raised to `N·max_i|α_i|²·10^(−DR/10)` when a dynamic range DR is set (the
//! strongest path over the recording). `α_i = √P_i · e^{−j2π f_c τ_i}` times the product of
//! the reflection coefficients and, for the body, the centre's fluctuation.

use alloc::vec;
use alloc::vec::Vec;

use serde::{Deserialize, Serialize};

use crate::channel::{Layout, Recording};
use crate::error::limits::MAX_CHANNEL_SAMPLES;
use crate::error::{check_len, limits, Cancel, Error, Result};
use crate::math::{
    cos, db_to_linear, dbm_to_watt, sin, sqrt, Complex, Real, Vec2, PI, SPEED_OF_LIGHT,
};
use crate::measure::SNR_DISTANCE_FLOOR_M;
use crate::measure::{noise_power_w, rng, standard_normal, unit_from, Model, Rng};
use crate::scenario::Scenario;

mod request;
mod scene;
mod walk;

pub use request::{Simulated, SimulationRequest, DEFAULT_CALIBRATION_DURATION_S};
pub use scene::{
    Body, ChannelScene, Clock, PointScatterer, Wall, DEFAULT_DT_S, DEFAULT_SUBCARRIERS,
};
pub use walk::Walk;

#[cfg(test)]
mod tests;

/// Bins between fresh `cos`/`sin` evaluations of a path's phasor (the recursion in between
/// rotates by `e^{−j2πΔfτ}`; re-anchoring bounds the accumulated rounding).
const REANCHOR_BINS: usize = 32;
/// rng streams: the noise of a recording with the walker, of the empty-area calibration
/// recording, and the body's fluctuations.
const STREAM_NOISE: u64 = 0x25_01;
const STREAM_NOISE_EMPTY: u64 = 0x25_02;
const STREAM_BODY: u64 = 0x25_03;
/// rng streams of the receivers' clocks (C10): the walk's and the empty area's.
const STREAM_CLOCK: u64 = 0x36_01;
const STREAM_CLOCK_EMPTY: u64 = 0x36_02;

/// What a path of the truth is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PathKind {
    /// Tx → Rx.
    Los,
    /// Tx → wall → Rx.
    Wall,
    /// Tx → wall → wall → Rx.
    WallWall,
    /// Tx → point scatterer → Rx.
    Scatterer,
    /// Tx → walker → Rx (the sum of the body's centres; reported at the walker's centre).
    Body,
    /// Tx → wall → walker → Rx or Tx → walker → wall → Rx.
    BodyWall,
}

/// One true path of a link in a snapshot.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TruePath {
    /// What it is.
    pub kind: PathKind,
    /// Propagation delay τ, s.
    pub delay_s: f64,
    /// Mean received power `|α|²`, W (after shadowing; for the body the mean over its
    /// fluctuation, evaluated at the walker's centre with the full `target.rcs_m2`).
    pub power_w: f64,
}

/// What the simulator knows. Readable as a [`crate::formats::Truth`] (`t_s`, `states`; the
/// other fields are ignored there).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ChannelTruth {
    /// Snapshot times, s.
    pub t_s: Vec<f64>,
    /// The walker's `[x, y, vx, vy]` per snapshot (empty for the empty-area recording).
    #[serde(default)]
    pub states: Vec<[f64; 4]>,
    /// Per snapshot, per link (recording order) the true paths.
    pub paths: Vec<Vec<Vec<TruePath>>>,
    /// Per snapshot, per link whether the walker shadows the LoS.
    pub shadowed: Vec<Vec<bool>>,
    /// Per snapshot, per link what the receiver's clock did (C10; empty for a synchronised
    /// sounder).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub clock: Vec<Vec<ClockState>>,
}

/// One snapshot of a link's receiver clock (C10): `H' = g·e^{jφ}·e^{−j2πf_nδ}·e^{jε_n}·H`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ClockState {
    /// Timing offset `δ`, s.
    pub delay_s: f64,
    /// Carrier phase `φ`, rad.
    pub phase_rad: f64,
    /// Gain `|g|`, dB.
    pub gain_db: f64,
}

// ---------------------------------------------------------------------------------------------
// Geometry.

fn v(p: [f64; 2]) -> Vec2 {
    Vec2::new(p[0], p[1])
}

fn cross(a: Vec2, b: Vec2) -> Real {
    a.x * b.y - a.y * b.x
}

fn dist(a: Vec2, b: Vec2) -> Real {
    let d = b - a;
    sqrt(d.x * d.x + d.y * d.y)
}

/// A wall as a line: a point, the direction `b − a`, and `Γ`.
#[derive(Debug, Clone, Copy)]
struct Line {
    a: Vec2,
    d: Vec2,
    gamma: Real,
}

impl Line {
    fn new(w: &Wall) -> Line {
        Line {
            a: v(w.a_m),
            d: v(w.b_m) - v(w.a_m),
            gamma: w.gamma,
        }
    }

    /// The mirror image of `p` in the wall's line.
    fn mirror(&self, p: Vec2) -> Vec2 {
        let dd = self.d.x * self.d.x + self.d.y * self.d.y;
        let t = ((p - self.a).x * self.d.x + (p - self.a).y * self.d.y) / dd;
        let foot = self.a + self.d * t;
        foot * 2.0 - p
    }

    /// Which side of the line `p` is on (signed, zero on it).
    fn side(&self, p: Vec2) -> Real {
        cross(self.d, p - self.a)
    }

    /// Where the segment `p`–`q` crosses the wall segment, if it does (strictly from opposite
    /// sides, the crossing on the wall's segment).
    fn crossing(&self, p: Vec2, q: Vec2) -> Option<Vec2> {
        let (sp, sq) = (self.side(p), self.side(q));
        if sp * sq >= 0.0 {
            return None;
        }
        let t = sp / (sp - sq);
        let x = p + (q - p) * t;
        let dd = self.d.x * self.d.x + self.d.y * self.d.y;
        let s = ((x - self.a).x * self.d.x + (x - self.a).y * self.d.y) / dd;
        (0.0..=1.0).contains(&s).then_some(x)
    }
}

/// Distance from `p` to the segment `a`–`b`, m.
fn segment_distance(p: Vec2, a: Vec2, b: Vec2) -> Real {
    let d = b - a;
    let dd = d.x * d.x + d.y * d.y;
    let t = if dd > 0.0 {
        (((p - a).x * d.x + (p - a).y * d.y) / dd).clamp(0.0, 1.0)
    } else {
        0.0
    };
    dist(p, a + d * t)
}

// ---------------------------------------------------------------------------------------------
// Link budget.

/// One link's constants.
struct LinkBudget<'a> {
    tx: Vec2,
    rx: Vec2,
    pattern: &'a crate::measure::TxPattern,
    /// `P_Tx·G_Rx`, W.
    ptx_grx: Real,
    lambda: Real,
}

impl LinkBudget<'_> {
    fn gain_toward(&self, p: Vec2) -> Real {
        self.pattern.gain_toward(unit_from(self.tx, p).0)
    }

    /// Friis power over the (unfolded) length `len`, Tx gain toward `first` (the first bounce
    /// or the Rx), W.
    fn friis(&self, first: Vec2, len: Real) -> Real {
        let l = len.max(SNR_DISTANCE_FLOOR_M);
        let k = self.lambda / (4.0 * PI * l);
        self.ptx_grx * self.gain_toward(first) * k * k
    }

    /// Bistatic radar power of a scatterer of RCS `rcs` at distances `d1`, `d2` (floored at
    /// 1 m as in E8), Tx gain toward `first`, W.
    fn radar(&self, first: Vec2, d1: Real, d2: Real, rcs: Real) -> Real {
        let d1 = d1.max(SNR_DISTANCE_FLOOR_M);
        let d2 = d2.max(SNR_DISTANCE_FLOOR_M);
        let four_pi3 = (4.0 * PI) * (4.0 * PI) * (4.0 * PI);
        self.ptx_grx * rcs * self.lambda * self.lambda * self.gain_toward(first)
            / (four_pi3 * d1 * d1 * d2 * d2)
    }
}

/// A static path of one link: its truth, its amplitude without shadowing, and the polyline it
/// follows (checked against the walker for shadowing when `shadowable`).
struct StaticRay {
    kind: PathKind,
    delay: Real,
    power: Real,
    /// Real factor of the reflections (product of Γ).
    sign: Real,
    points: [Vec2; 4],
    npoints: usize,
    shadowable: bool,
}

/// The static paths of a link (LoS, walls, wall–wall, point scatterers).
fn static_rays(lb: &LinkBudget, lines: &[Line], scene: &ChannelScene) -> Vec<StaticRay> {
    let (tx, rx) = (lb.tx, lb.rx);
    let mut rays = Vec::new();
    let z = Vec2::zeros();
    let d = dist(tx, rx);
    rays.push(StaticRay {
        kind: PathKind::Los,
        delay: d / SPEED_OF_LIGHT,
        power: lb.friis(rx, d),
        sign: 1.0,
        points: [tx, rx, z, z],
        npoints: 2,
        shadowable: true,
    });
    for w in lines {
        let img = w.mirror(rx);
        if w.side(tx) * w.side(rx) <= 0.0 {
            continue;
        }
        if let Some(p) = w.crossing(tx, img) {
            let len = dist(tx, img);
            rays.push(StaticRay {
                kind: PathKind::Wall,
                delay: len / SPEED_OF_LIGHT,
                power: lb.friis(p, len) * w.gamma * w.gamma,
                sign: w.gamma,
                points: [tx, p, rx, z],
                npoints: 3,
                shadowable: true,
            });
        }
    }
    if scene.second_order {
        for (i, wi) in lines.iter().enumerate() {
            for (j, wj) in lines.iter().enumerate() {
                if i == j {
                    continue;
                }
                // Tx → wall i → wall j → Rx: images T1 (in i), T2 (T1 in j).
                let t1 = wi.mirror(tx);
                let t2 = wj.mirror(t1);
                let Some(q) = wj.crossing(rx, t2) else {
                    continue;
                };
                let Some(p) = wi.crossing(q, t1) else {
                    continue;
                };
                // The legs must stay on the reflecting sides.
                if wj.side(p) * wj.side(rx) <= 0.0 || wi.side(tx) * wi.side(q) <= 0.0 {
                    continue;
                }
                let len = dist(t2, rx);
                let g = wi.gamma * wj.gamma;
                rays.push(StaticRay {
                    kind: PathKind::WallWall,
                    delay: len / SPEED_OF_LIGHT,
                    power: lb.friis(p, len) * g * g,
                    sign: g,
                    points: [tx, p, q, rx],
                    npoints: 4,
                    shadowable: true,
                });
            }
        }
    }
    for s in &scene.scatterers {
        let p = v(s.position_m);
        let (d1, d2) = (dist(tx, p), dist(p, rx));
        rays.push(StaticRay {
            kind: PathKind::Scatterer,
            delay: (d1 + d2) / SPEED_OF_LIGHT,
            power: lb.radar(p, d1, d2, s.rcs_m2),
            sign: 1.0,
            points: [tx, p, rx, z],
            npoints: 3,
            shadowable: false,
        });
    }
    rays
}

/// Whether the polyline passes within `radius` of `p`.
fn passes_near(points: &[Vec2], p: Vec2, radius: Real) -> bool {
    points
        .windows(2)
        .any(|w| segment_distance(p, w[0], w[1]) < radius)
}

/// A body path through a point `c` (a centre or the walker): direct and via each wall, as
/// `(kind, delay, mean power, reflection factor)` for a scatterer of RCS `rcs` at `c`.
fn body_paths(
    lb: &LinkBudget,
    lines: &[Line],
    c: Vec2,
    rcs: Real,
    double: bool,
    out: &mut Vec<(PathKind, Real, Real, Real)>,
) {
    let (tx, rx) = (lb.tx, lb.rx);
    let (d1, d2) = (dist(tx, c), dist(c, rx));
    out.push((
        PathKind::Body,
        (d1 + d2) / SPEED_OF_LIGHT,
        lb.radar(c, d1, d2, rcs),
        1.0,
    ));
    if !double {
        return;
    }
    for w in lines {
        let g2 = w.gamma * w.gamma;
        // Tx → wall → c → Rx: image of Tx.
        if w.side(tx) * w.side(c) > 0.0 {
            let ti = w.mirror(tx);
            if let Some(p) = w.crossing(ti, c) {
                let d1 = dist(ti, c);
                out.push((
                    PathKind::BodyWall,
                    (d1 + d2) / SPEED_OF_LIGHT,
                    lb.radar(p, d1, d2, rcs) * g2,
                    w.gamma,
                ));
            }
        }
        // Tx → c → wall → Rx: image of Rx.
        if w.side(rx) * w.side(c) > 0.0 {
            let ri = w.mirror(rx);
            if let Some(_p) = w.crossing(c, ri) {
                let d1 = dist(tx, c);
                let d2 = dist(c, ri);
                out.push((
                    PathKind::BodyWall,
                    (d1 + d2) / SPEED_OF_LIGHT,
                    lb.radar(c, d1, d2, rcs) * g2,
                    w.gamma,
                ));
            }
        }
    }
}

/// Scattering centre `k` of `count` of a walker at `centre` heading along the unit `head`: at
/// angle `2πk/count` from the heading, `radius` from the centre.
fn body_centre(centre: Vec2, head: [Real; 2], k: usize, count: usize, radius: Real) -> Vec2 {
    let phi = 2.0 * PI * k as Real / count as Real;
    let (c, sn) = (cos(phi), sin(phi));
    let off = Vec2::new(head[0] * c - head[1] * sn, head[1] * c + head[0] * sn);
    centre + off * radius
}

// ---------------------------------------------------------------------------------------------
// Synthesis.

/// `e^{−j2πx}`, with `x` reduced to its fractional part first (carrier phases are thousands of
/// cycles).
fn cis_neg(x: Real) -> Complex {
    let f = x - (x as i64) as Real;
    let a = 2.0 * PI * f;
    Complex::new(cos(a), -sin(a))
}

/// Adds `α e^{−j2π f_n τ}` for `f_n = f0 + n·df` to `h` by phasor recursion, re-anchored every
/// [`REANCHOR_BINS`] bins.
fn add_path(h: &mut [Complex], alpha: Complex, tau: Real, f0: Real, df: Real) {
    let step = cis_neg(df * tau);
    let mut z = Complex::new(0.0, 0.0);
    for (n, hn) in h.iter_mut().enumerate() {
        if n % REANCHOR_BINS == 0 {
            z = alpha * cis_neg((f0 + n as Real * df) * tau);
        }
        *hn += z;
        z *= step;
    }
}

/// The receiver clock `c` on snapshot `s` of one link's response `h` (bins `f0 + n·df`): draws
/// `δ` and `φ`, steps the AGC gain every `agc_every` snapshots, draws the phase noise, and
/// applies `g·e^{jφ}·e^{−j2πf_nδ}·e^{jε_n}`. Returns what it applied.
fn apply_clock(
    c: &Clock,
    s: usize,
    gain_db: &mut Real,
    r: &mut Rng,
    h: &mut [Complex],
    f0: Real,
    df: Real,
) -> ClockState {
    let uniform = |r: &mut Rng| crate::measure::uniform01(r);
    let delay = if c.timing_offset_s > 0.0 {
        c.timing_offset_s * (2.0 * uniform(r) - 1.0)
    } else {
        0.0
    };
    let phase = if c.carrier_phase {
        2.0 * PI * uniform(r)
    } else {
        0.0
    };
    if c.agc_step_db > 0.0 && s > 0 && s.is_multiple_of(c.agc_every) {
        *gain_db += c.agc_step_db * (2.0 * uniform(r) - 1.0);
    }
    let g = sqrt(db_to_linear(*gain_db));
    for (n, v) in h.iter_mut().enumerate() {
        let f = f0 + n as Real * df;
        let mut rot = phase - 2.0 * PI * f * delay;
        if c.phase_noise_rad > 0.0 {
            rot += c.phase_noise_rad * standard_normal(r);
        }
        *v *= Complex::new(cos(rot), sin(rot)) * g;
    }
    ClockState {
        delay_s: delay,
        phase_rad: phase,
        gain_db: *gain_db,
    }
}

/// A unit-mean-power circular complex Gaussian draw.
fn complex_normal(r: &mut Rng) -> Complex {
    let s = core::f64::consts::FRAC_1_SQRT_2;
    let re = standard_normal(r);
    let im = standard_normal(r);
    Complex::new(re * s, im * s)
}

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

/// [`simulate_recording`], optionally without the additive noise (`noise_var` then still
/// gives the σ² the noisy version would use); `cancel` is asked once per snapshot.
fn synthesize(
    scenario: &Scenario,
    model: &Model,
    scene: &ChannelScene,
    with_person: bool,
    seed: u64,
    add_noise: bool,
    cancel: Cancel,
) -> Result<(Recording, ChannelTruth)> {
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
    let path = scene.walk.compile()?;
    let duration = scene.duration_s.unwrap_or_else(|| path.duration_s());
    let links = &model.network.links;
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
    let snapshots = steps as usize + 1;
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

    let body = &scene.body;
    let k_centres = body.centres;
    let rcs_centre = scenario.target.rcs_m2 / k_centres as Real;
    let shadow_amp = sqrt(db_to_linear(-body.shadow_loss_db));
    let rho = body.correlation;
    let innov = sqrt(1.0 - rho * rho);
    let mut body_rng = rng(seed, STREAM_BODY);
    let mut fluct = vec![Complex::new(0.0, 0.0); links.len() * k_centres];

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
        let t = s as Real * scene.dt_s;
        t_s.push(t);
        let walker = with_person.then(|| path.state_and_heading(t));
        if let Some((st, _)) = walker {
            states.push(st);
        }
        // The body's fluctuations: AR(1), the first snapshot a fresh draw.
        if with_person {
            for g in fluct.iter_mut() {
                let w = complex_normal(&mut body_rng);
                *g = if s == 0 { w } else { *g * rho + w * innov };
            }
        }
        let mut snap_paths = Vec::with_capacity(links.len());
        let mut snap_shadow = Vec::with_capacity(links.len());
        for (p, lb) in budgets.iter().enumerate() {
            let h = &mut samples[(s * links.len() + p) * n_bins..][..n_bins];
            let mut truth = Vec::new();
            let mut los_shadowed = false;
            for ray in &statics[p] {
                let shade = match walker {
                    Some((st, _)) if ray.shadowable => passes_near(
                        &ray.points[..ray.npoints],
                        Vec2::new(st[0], st[1]),
                        body.shadow_radius_m,
                    ),
                    _ => false,
                };
                if ray.kind == PathKind::Los {
                    los_shadowed = shade;
                }
                let a = if shade { shadow_amp } else { 1.0 };
                let power = ray.power * a * a;
                truth.push(TruePath {
                    kind: ray.kind,
                    delay_s: ray.delay,
                    power_w: power,
                });
                let alpha = cis_neg(fc * ray.delay) * (sqrt(ray.power) * a * ray.sign);
                add_path(h, alpha, ray.delay, f0, df);
            }
            if let Some((st, head)) = walker {
                let centre = Vec2::new(st[0], st[1]);
                scratch.clear();
                body_paths(
                    lb,
                    &lines,
                    centre,
                    scenario.target.rcs_m2,
                    scene.double_reflections,
                    &mut scratch,
                );
                truth.extend(scratch.iter().map(|&(kind, delay_s, power_w, _)| TruePath {
                    kind,
                    delay_s,
                    power_w,
                }));
                for k in 0..k_centres {
                    let ck = body_centre(centre, head, k, k_centres, body.radius_m);
                    scratch.clear();
                    body_paths(
                        lb,
                        &lines,
                        ck,
                        rcs_centre,
                        scene.double_reflections,
                        &mut scratch,
                    );
                    let g = fluct[p * k_centres + k];
                    for &(_, tau, power, sign) in &scratch {
                        let alpha = cis_neg(fc * tau) * g * (sqrt(power) * sign);
                        add_path(h, alpha, tau, f0, df);
                    }
                }
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
            let rays = statics[p].len() + (1 + k_centres) * scratch.len().max(1);
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
    Ok((recording, truth))
}
