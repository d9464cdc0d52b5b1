//! The scene of a simulated recording: walls, point scatterers, the walker's body and walk, any
//! further walkers ([`Walker`], issue 41), and the sounder settings (subcarriers, snapshot
//! interval, dynamic range).

use alloc::format;
use alloc::vec;
use alloc::vec::Vec;

use serde::{Deserialize, Serialize};

use super::walk::Walk;
use crate::error::limits::{
    COORDINATE_M, MAX_BODY_CENTRES, MAX_SCENE_SCATTERERS, MAX_SCENE_WALLS, MAX_SUBCARRIERS, RCS_M2,
};
use crate::error::{check_positive, Error, Result};

/// A wall: the segment `a_m`–`b_m` reflecting specularly with the (real) amplitude reflection
/// coefficient `gamma` (`|Γ| ≤ 1`; negative: a phase flip).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Wall {
    /// One end, m.
    pub a_m: [f64; 2],
    /// The other end, m.
    pub b_m: [f64; 2],
    /// Amplitude reflection coefficient Γ, in [−1, 1].
    pub gamma: f64,
}

/// A static point scatterer (pole, parked car) of radar cross section `rcs_m2`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PointScatterer {
    /// Position, m.
    pub position_m: [f64; 2],
    /// Radar cross section, m².
    pub rcs_m2: f64,
}

/// The walker as an extended scatterer: `centres` scattering centres on a circle of `radius_m`
/// (fixed angles `2πk/K` in the body frame, turning with the heading), each with RCS
/// `target.rcs_m2 / K` and a complex Gaussian fluctuation of unit mean power, AR(1) over
/// snapshots with coefficient `correlation` (0: independent, Swerling II); the body shadows a
/// LoS or wall path that passes within `shadow_radius_m` by `shadow_loss_db`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Body {
    /// Number of scattering centres K (1 to [`MAX_BODY_CENTRES`]).
    pub centres: usize,
    /// Radius of the circle of centres, m.
    pub radius_m: f64,
    /// Snapshot-to-snapshot correlation ρ of each centre's fluctuation, in [0, 1).
    pub correlation: f64,
    /// A LoS or wall path passing this close to the walker is shadowed, m.
    pub shadow_radius_m: f64,
    /// Attenuation of a shadowed path, dB (≥ 0).
    pub shadow_loss_db: f64,
    /// Micro-Doppler of the limbs (issue 42 §2; 0: off): every second centre (the limbs) swings
    /// along the heading by `limb_swing_m · sin(2π gait_hz t + kπ/2)` about its place, so its
    /// velocity adds `2π gait_hz limb_swing_m` at most to the body's — the sidebands of a
    /// walker's Doppler (Chen 2011, the Boulic–Thalmann gait); m, 0 … 1.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub limb_swing_m: f64,
    /// The gait's frequency, Hz (0 … 5; a walker's stride is about 1 Hz).
    #[serde(default = "default_gait_hz", skip_serializing_if = "is_default_gait")]
    pub gait_hz: f64,
}

/// A walking person's stride frequency, Hz.
fn default_gait_hz() -> f64 {
    1.0
}

fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

fn is_default_gait(v: &f64) -> bool {
    *v == default_gait_hz()
}

impl Default for Body {
    fn default() -> Body {
        Body {
            centres: 6,
            radius_m: 0.2,
            correlation: 0.9,
            shadow_radius_m: 0.3,
            shadow_loss_db: 15.0,
            limb_swing_m: 0.0,
            gait_hz: default_gait_hz(),
        }
    }
}

impl Body {
    /// Checks the fields; errors name `field` + `.centres`, `.radius_m`, `.correlation`,
    /// `.shadow_radius_m`, `.shadow_loss_db`.
    pub fn validate(&self, field: &str) -> Result<()> {
        let name = |f: &str| format!("{field}.{f}");
        if !(1..=MAX_BODY_CENTRES).contains(&self.centres) {
            return Err(Error::InvalidFile {
                field: name("centres"),
                reason: format!(
                    "{} centres; 1 to {MAX_BODY_CENTRES} are allowed",
                    self.centres
                ),
            });
        }
        let range = |f: &str, v: f64, lo: f64, hi: f64, allowed| {
            if v.is_finite() && (lo..=hi).contains(&v) {
                Ok(())
            } else {
                Err(Error::OutOfRange {
                    field: name(f),
                    value: v,
                    allowed,
                })
            }
        };
        range("radius_m", self.radius_m, 0.0, 10.0, "0 to 10 m")?;
        range(
            "correlation",
            self.correlation,
            0.0,
            0.999_999,
            "0 to 0.999999",
        )?;
        range(
            "shadow_radius_m",
            self.shadow_radius_m,
            0.0,
            10.0,
            "0 to 10 m",
        )?;
        range(
            "shadow_loss_db",
            self.shadow_loss_db,
            0.0,
            200.0,
            "0 to 200 dB",
        )?;
        range("limb_swing_m", self.limb_swing_m, 0.0, 1.0, "0 to 1 m")?;
        range("gait_hz", self.gait_hz, 0.0, 5.0, "0 to 5 Hz")
    }
}

/// A further walker of a scene (issue 41: several people in a recording): its own walk and
/// body, simulated exactly as the main walker — its body paths direct and via the walls, its
/// own fluctuations (an rng stream per walker), shadowing the LoS and wall paths.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Walker {
    /// The walker's body (default [`Body::default`]).
    #[serde(default)]
    pub body: Body,
    /// The walker's walk.
    pub walk: Walk,
}

/// Most further walkers of a scene ([`ChannelScene::others`]; five people in all).
pub const MAX_OTHER_WALKERS: usize = 4;

/// [S]'s snapshot interval `T_g`, s.
pub const DEFAULT_DT_S: f64 = 2.048e-3;
/// Default number of subcarriers N.
pub const DEFAULT_SUBCARRIERS: usize = 241;

fn default_dt() -> f64 {
    DEFAULT_DT_S
}
fn default_subcarriers() -> usize {
    DEFAULT_SUBCARRIERS
}
fn default_true() -> bool {
    true
}

/// The static and mobile scene of a simulated recording and the sounder's settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ChannelScene {
    /// Reflecting walls.
    #[serde(default)]
    pub walls: Vec<Wall>,
    /// Static point scatterers.
    #[serde(default)]
    pub scatterers: Vec<PointScatterer>,
    /// The walker's body.
    #[serde(default)]
    pub body: Body,
    /// The walker's walk.
    pub walk: Walk,
    /// Further walkers (up to four, `MAX_OTHER_WALKERS`; none by default, and then not written).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub others: Vec<Walker>,
    /// Number of frequency bins N (C1), spacing `B/N`.
    #[serde(default = "default_subcarriers")]
    pub subcarriers: usize,
    /// Snapshot interval, s.
    #[serde(default = "default_dt")]
    pub dt_s: f64,
    /// Recording length, s (`None`: the walk's duration).
    #[serde(default)]
    pub duration_s: Option<f64>,
    /// Sounder dynamic range, dB: the noise floor is at least the strongest path minus this
    /// (`None`: thermal noise only).
    #[serde(default)]
    pub dynamic_range_db: Option<f64>,
    /// Second-order wall–wall reflections.
    #[serde(default = "default_true")]
    pub second_order: bool,
    /// Body–wall double reflections.
    #[serde(default = "default_true")]
    pub double_reflections: bool,
    /// Receivers without a common clock (C10): per-snapshot timing offsets, carrier phases,
    /// AGC gain steps and phase noise (`None`: a synchronised sounder).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub clock: Option<Clock>,
    /// Coherent processing intervals (issue 42 §2): each scan, `dt_s` apart, is a burst of
    /// snapshots (`None`: one snapshot per scan). The walk's recording only; the empty area's
    /// stays one snapshot per scan.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cpi: Option<SceneCpi>,
}

/// Most snapshots of a scene's CPI.
pub const MAX_SCENE_CPI_SNAPSHOTS: usize = 1024;

/// A burst of `snapshots` snapshots `spacing_s` apart starting at each scan time `k·dt_s`: the
/// phase progression of every moving path over it is the Doppler the front end measures
/// (docs/doppler.md D1–D2). The body's fluctuation keeps its correlation `ρ` per `dt_s`, so
/// over a gap `Δt` it is `ρ^(Δt/dt_s)`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneCpi {
    /// Snapshots per scan, `N` (1 … [`MAX_SCENE_CPI_SNAPSHOTS`]).
    pub snapshots: usize,
    /// Their spacing `T`, s; `(N − 1)·T < dt_s`.
    pub spacing_s: f64,
}

impl SceneCpi {
    /// Checks the fields against the scan interval `dt_s` (errors name `scene.cpi.*`).
    pub fn validate(&self, dt_s: f64) -> Result<()> {
        too_many(
            "scene.cpi.snapshots",
            self.snapshots,
            1,
            MAX_SCENE_CPI_SNAPSHOTS,
        )?;
        check_positive("scene.cpi.spacing_s", self.spacing_s)?;
        let span = (self.snapshots - 1) as f64 * self.spacing_s;
        if span.is_nan() || span >= dt_s {
            return Err(Error::OutOfRange {
                field: "scene.cpi.spacing_s".into(),
                value: self.spacing_s,
                allowed:
                    "(snapshots − 1)·spacing_s below scene.dt_s (a burst ends before the next scan)",
            });
        }
        Ok(())
    }

    /// The time of snapshot `s` of a recording with scans `dt_s` apart, and the gap since the
    /// previous snapshot (`None` for the first).
    pub fn time_of(&self, s: usize, dt_s: f64) -> (f64, Option<f64>) {
        let n = self.snapshots;
        let t = |s: usize| (s / n) as f64 * dt_s + (s % n) as f64 * self.spacing_s;
        (t(s), s.checked_sub(1).map(|q| t(s) - t(q)))
    }
}

/// What a receiver without the transmitter's clock does to each snapshot of a link (C10),
/// every draw seeded: `H'[n] = g·e^{jφ}·e^{−j2πf_nδ}·e^{jε_n}·H[n]` before the thermal noise.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Clock {
    /// Timing offset `δ` of each snapshot and link, uniform in `[−x, x]`, s (0: none).
    pub timing_offset_s: f64,
    /// A carrier phase `φ` of each snapshot and link, uniform in `[0, 2π)`.
    pub carrier_phase: bool,
    /// AGC: every [`Clock::agc_every`] snapshots the link's gain `|g|` steps by a uniform
    /// `[−x, x]` dB, s (0: a fixed gain of 1).
    pub agc_step_db: f64,
    /// Snapshots between AGC steps (≥ 1).
    pub agc_every: usize,
    /// Phase noise `ε_n`, independent per bin and snapshot, Gaussian of this σ, rad (0: none).
    pub phase_noise_rad: f64,
}

impl Default for Clock {
    fn default() -> Self {
        Clock {
            timing_offset_s: 0.0,
            carrier_phase: false,
            agc_step_db: 0.0,
            agc_every: 1,
            phase_noise_rad: 0.0,
        }
    }
}

impl Clock {
    /// Whether it makes delays relative (a timing offset or a carrier phase): the recording is
    /// then not `synchronized`.
    pub fn free_running(&self) -> bool {
        self.timing_offset_s > 0.0 || self.carrier_phase
    }

    /// Checks the fields (`scene.clock.*`): offset 0 … 1 ms, AGC step 0 … 20 dB, `agc_every`
    /// ≥ 1, phase noise 0 … π rad.
    pub fn validate(&self) -> Result<()> {
        let range = |field: &str, v: f64, hi: f64, allowed| {
            if v.is_finite() && (0.0..=hi).contains(&v) {
                Ok(())
            } else {
                Err(Error::OutOfRange {
                    field: field.into(),
                    value: v,
                    allowed,
                })
            }
        };
        range(
            "scene.clock.timing_offset_s",
            self.timing_offset_s,
            1e-3,
            "0 to 1e-3 s",
        )?;
        range(
            "scene.clock.agc_step_db",
            self.agc_step_db,
            20.0,
            "0 to 20 dB",
        )?;
        range(
            "scene.clock.phase_noise_rad",
            self.phase_noise_rad,
            core::f64::consts::PI,
            "0 to π rad",
        )?;
        too_many("scene.clock.agc_every", self.agc_every, 1, usize::MAX)
    }
}

fn check_point(field: &str, p: &[f64; 2]) -> Result<()> {
    for v in p {
        COORDINATE_M.check(field, *v)?;
    }
    Ok(())
}

fn too_many(field: &'static str, value: usize, min: usize, max: usize) -> Result<()> {
    if (min..=max).contains(&value) {
        Ok(())
    } else {
        Err(Error::SizeLimit {
            field,
            value,
            min,
            max,
        })
    }
}

impl ChannelScene {
    /// Checks every field; errors name it (`scene.walls[0].gamma`, `scene.body.centres`, …).
    pub fn validate(&self) -> Result<()> {
        too_many("scene.walls", self.walls.len(), 0, MAX_SCENE_WALLS)?;
        for (i, w) in self.walls.iter().enumerate() {
            check_point(&format!("scene.walls[{i}].a_m"), &w.a_m)?;
            check_point(&format!("scene.walls[{i}].b_m"), &w.b_m)?;
            let (dx, dy) = (w.b_m[0] - w.a_m[0], w.b_m[1] - w.a_m[1]);
            if dx * dx + dy * dy < 1e-6 {
                return Err(Error::InvalidFile {
                    field: format!("scene.walls[{i}]"),
                    reason: "a_m and b_m are closer than 1 mm".into(),
                });
            }
            if !(w.gamma.is_finite() && (-1.0..=1.0).contains(&w.gamma)) {
                return Err(Error::OutOfRange {
                    field: format!("scene.walls[{i}].gamma"),
                    value: w.gamma,
                    allowed: "-1 to 1",
                });
            }
        }
        too_many(
            "scene.scatterers",
            self.scatterers.len(),
            0,
            MAX_SCENE_SCATTERERS,
        )?;
        for (i, s) in self.scatterers.iter().enumerate() {
            check_point(&format!("scene.scatterers[{i}].position_m"), &s.position_m)?;
            RCS_M2.check(&format!("scene.scatterers[{i}].rcs_m2"), s.rcs_m2)?;
        }
        too_many("scene.body.centres", self.body.centres, 1, MAX_BODY_CENTRES)?;
        self.body.validate("scene.body")?;
        self.walk.validate("scene.walk")?;
        too_many("scene.others", self.others.len(), 0, MAX_OTHER_WALKERS)?;
        for (i, w) in self.others.iter().enumerate() {
            w.body.validate(&format!("scene.others[{i}].body"))?;
            w.walk.validate(&format!("scene.others[{i}].walk"))?;
        }
        too_many("scene.subcarriers", self.subcarriers, 2, MAX_SUBCARRIERS)?;
        let range = |field: &str, v: f64, lo: f64, hi: f64, allowed| {
            if v.is_finite() && (lo..=hi).contains(&v) {
                Ok(())
            } else {
                Err(Error::OutOfRange {
                    field: field.into(),
                    value: v,
                    allowed,
                })
            }
        };
        check_positive("scene.dt_s", self.dt_s)?;
        range("scene.dt_s", self.dt_s, 1e-9, 1e3, "1e-9 to 1000 s")?;
        if let Some(d) = self.duration_s {
            range("scene.duration_s", d, 0.0, 1e6, "0 to 1e6 s")?;
        }
        if let Some(d) = self.dynamic_range_db {
            range("scene.dynamic_range_db", d, 0.0, 300.0, "0 to 300 dB")?;
        }
        if let Some(c) = &self.clock {
            c.validate()?;
        }
        if let Some(c) = &self.cpi {
            c.validate(self.dt_s)?;
        }
        Ok(())
    }

    /// The hangar scene for the `sensors2019` preset (Tx (0, 0); Rx (−5, 12), (10, 10), (−6, −8),
    /// (12, −6); area x ∈ [−7.5, 30], y ∈ [−10, 26]): a wall along y = 24 (Γ = −0.6), two
    /// point scatterers and a ≈ 30 s walk at 1.4 m/s with three turns of radius 2.5 m, inside the
    /// area and more than 1 m from every node.
    pub fn hangar() -> ChannelScene {
        ChannelScene {
            walls: vec![Wall {
                a_m: [-8.0, 24.0],
                b_m: [30.0, 24.0],
                gamma: -0.6,
            }],
            scatterers: vec![
                PointScatterer {
                    position_m: [20.0, 14.0],
                    rcs_m2: 5.0,
                },
                PointScatterer {
                    position_m: [4.0, -8.0],
                    rcs_m2: 3.0,
                },
            ],
            body: Body::default(),
            walk: Walk {
                waypoints_m: vec![
                    [2.0, 4.0],
                    [16.0, 4.0],
                    [16.0, 16.0],
                    [4.0, 16.0],
                    [4.0, 8.0],
                ],
                speed_mps: 1.4,
                turn_radius_m: 2.5,
            },
            others: Vec::new(),
            subcarriers: DEFAULT_SUBCARRIERS,
            dt_s: DEFAULT_DT_S,
            duration_s: None,
            dynamic_range_db: None,
            second_order: true,
            double_reflections: true,
            clock: None,
            cpi: None,
        }
    }
}
