//! The walker's trajectory: straight segments between waypoints joined by circular arcs (rounded
//! corners), walked at constant speed.

use alloc::format;
use alloc::vec::Vec;

use serde::{Deserialize, Serialize};

use crate::error::limits::{COORDINATE_M, MAX_WAYPOINTS};
use crate::error::{check_positive, Error, Result};
use crate::math::{atan2, cos, sin, sqrt, Real};

/// A walk: waypoints joined by straight segments whose corners are rounded by arcs of
/// `turn_radius_m` (clamped where a segment is too short for the full radius), walked at
/// `speed_mps` from the first waypoint; the walker stops at the last one.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Walk {
    /// Waypoints `[x, y]`, m (at least two; consecutive ones distinct).
    pub waypoints_m: Vec<[f64; 2]>,
    /// Walking speed, m/s.
    pub speed_mps: f64,
    /// Radius of the arcs that round the corners, m (0: sharp corners).
    #[serde(default)]
    pub turn_radius_m: f64,
}

/// One piece of the rounded polyline.
#[derive(Debug, Clone, Copy)]
enum Piece {
    /// From `start` along the unit `dir` for `len` m.
    Line {
        start: [Real; 2],
        dir: [Real; 2],
        len: Real,
    },
    /// An arc around `centre` of `radius`, from angle `phi0`, turning by `sweep` rad (signed:
    /// positive counter-clockwise).
    Arc {
        centre: [Real; 2],
        radius: Real,
        phi0: Real,
        sweep: Real,
    },
}

impl Piece {
    fn len(&self) -> Real {
        match *self {
            Piece::Line { len, .. } => len,
            Piece::Arc { radius, sweep, .. } => radius * sweep.abs(),
        }
    }

    /// Position and unit tangent `s` m into the piece.
    fn at(&self, s: Real) -> ([Real; 2], [Real; 2]) {
        match *self {
            Piece::Line { start, dir, .. } => ([start[0] + s * dir[0], start[1] + s * dir[1]], dir),
            Piece::Arc {
                centre,
                radius,
                phi0,
                sweep,
            } => {
                let sign = if sweep < 0.0 { -1.0 } else { 1.0 };
                let phi = phi0 + sign * s / radius;
                let (c, sn) = (cos(phi), sin(phi));
                (
                    [centre[0] + radius * c, centre[1] + radius * sn],
                    [-sign * sn, sign * c],
                )
            }
        }
    }
}

/// A validated walk compiled into pieces.
#[derive(Debug, Clone)]
pub(crate) struct Path {
    pieces: Vec<Piece>,
    /// Cumulative length at the start of each piece, m.
    starts: Vec<Real>,
    total_m: Real,
    speed: Real,
    end: [Real; 2],
    end_dir: [Real; 2],
}

fn sub(a: [Real; 2], b: [Real; 2]) -> [Real; 2] {
    [a[0] - b[0], a[1] - b[1]]
}

fn norm(a: [Real; 2]) -> Real {
    sqrt(a[0] * a[0] + a[1] * a[1])
}

impl Walk {
    /// Checks the walk: ≥ 2 (and ≤ [`MAX_WAYPOINTS`]) finite waypoints in
    /// [`COORDINATE_M`], consecutive ones ≥ 1 mm apart, speed > 0, radius ≥ 0. Errors name
    /// `field` + `.waypoints_m[i]`, `.speed_mps`, `.turn_radius_m`.
    pub fn validate(&self, field: &str) -> Result<()> {
        let n = self.waypoints_m.len();
        if !(2..=MAX_WAYPOINTS).contains(&n) {
            return Err(Error::InvalidFile {
                field: format!("{field}.waypoints_m"),
                reason: format!("{n} waypoints; 2 to {MAX_WAYPOINTS} are needed"),
            });
        }
        for (i, w) in self.waypoints_m.iter().enumerate() {
            for v in w {
                COORDINATE_M.check(&format!("{field}.waypoints_m[{i}]"), *v)?;
            }
            if i > 0 && norm(sub(*w, self.waypoints_m[i - 1])) < 1e-3 {
                return Err(Error::InvalidFile {
                    field: format!("{field}.waypoints_m[{i}]"),
                    reason: "closer than 1 mm to the previous waypoint".into(),
                });
            }
        }
        check_positive(&format!("{field}.speed_mps"), self.speed_mps)?;
        if self.speed_mps > 1e3 {
            return Err(Error::OutOfRange {
                field: format!("{field}.speed_mps"),
                value: self.speed_mps,
                allowed: "0 to 1000 m/s",
            });
        }
        if !(self.turn_radius_m.is_finite() && (0.0..=1e4).contains(&self.turn_radius_m)) {
            return Err(Error::OutOfRange {
                field: format!("{field}.turn_radius_m"),
                value: self.turn_radius_m,
                allowed: "0 to 1e4 m",
            });
        }
        Ok(())
    }

    /// Length of the rounded path, m.
    pub fn length_m(&self) -> Result<Real> {
        Ok(self.compile()?.total_m)
    }

    /// Time to walk it, s.
    pub fn duration_s(&self) -> Result<Real> {
        let p = self.compile()?;
        Ok(p.total_m / p.speed)
    }

    /// The state `[x, y, vx, vy]` at `t` s (before 0: the start at rest; after the end: the last
    /// waypoint at rest).
    pub fn state_at(&self, t: Real) -> Result<[Real; 4]> {
        Ok(self.compile()?.state_at(t))
    }

    /// Validates and compiles into straight and arc pieces.
    pub(crate) fn compile(&self) -> Result<Path> {
        self.validate("walk")?;
        let w = &self.waypoints_m;
        let m = w.len();
        // Unit directions and lengths of the segments.
        let seg: Vec<([Real; 2], Real)> = (0..m - 1)
            .map(|i| {
                let d = sub(w[i + 1], w[i]);
                let l = norm(d);
                ([d[0] / l, d[1] / l], l)
            })
            .collect();
        // Per interior corner: tangent distance t, radius, signed turn.
        let mut cut = alloc::vec![0.0; m];
        let mut arcs: Vec<Option<Piece>> = alloc::vec![None; m];
        for i in 1..m - 1 {
            let (u1, l1) = seg[i - 1];
            let (u2, l2) = seg[i];
            let cross = u1[0] * u2[1] - u1[1] * u2[0];
            let dot = u1[0] * u2[0] + u1[1] * u2[1];
            let turn = atan2(cross, dot);
            if self.turn_radius_m <= 0.0 || cross.abs() < 1e-12 || 1.0 + dot < 1e-9 {
                continue; // straight on, a U-turn, or sharp corners: no arc
            }
            let tan_half = cross.abs() / (1.0 + dot);
            let t_max = 0.5 * l1.min(l2);
            let t = (self.turn_radius_m * tan_half).min(t_max);
            let radius = t / tan_half;
            let p_in = [w[i][0] - t * u1[0], w[i][1] - t * u1[1]];
            let sign = if cross > 0.0 { 1.0 } else { -1.0 };
            let normal = [-sign * u1[1], sign * u1[0]];
            let centre = [p_in[0] + radius * normal[0], p_in[1] + radius * normal[1]];
            let phi0 = atan2(p_in[1] - centre[1], p_in[0] - centre[0]);
            cut[i] = t;
            arcs[i] = Some(Piece::Arc {
                centre,
                radius,
                phi0,
                sweep: turn,
            });
        }
        let mut pieces = Vec::new();
        for i in 0..m - 1 {
            let (u, l) = seg[i];
            let a = cut[i];
            let b = cut[i + 1];
            let len = l - a - b;
            if len > 0.0 {
                pieces.push(Piece::Line {
                    start: [w[i][0] + a * u[0], w[i][1] + a * u[1]],
                    dir: u,
                    len,
                });
            }
            if let Some(arc) = arcs[i + 1] {
                pieces.push(arc);
            }
        }
        let mut starts = Vec::with_capacity(pieces.len());
        let mut total = 0.0;
        for p in &pieces {
            starts.push(total);
            total += p.len();
        }
        Ok(Path {
            pieces,
            starts,
            total_m: total,
            speed: self.speed_mps,
            end: w[m - 1],
            end_dir: seg[m - 2].0,
        })
    }
}

impl Path {
    /// Duration of the walk, s.
    pub(crate) fn duration_s(&self) -> Real {
        self.total_m / self.speed
    }

    /// `[x, y, vx, vy]` at `t`, and the unit heading (kept at rest).
    pub(crate) fn state_and_heading(&self, t: Real) -> ([Real; 4], [Real; 2]) {
        let s = self.speed * t;
        if s >= self.total_m || self.pieces.is_empty() {
            return ([self.end[0], self.end[1], 0.0, 0.0], self.end_dir);
        }
        let s = s.max(0.0);
        // Last piece starting at or before s.
        let k = self.starts.partition_point(|&a| a <= s).saturating_sub(1);
        let (p, d) = self.pieces[k].at(s - self.starts[k]);
        let v = if t < 0.0 { 0.0 } else { self.speed };
        ([p[0], p[1], v * d[0], v * d[1]], d)
    }

    /// `[x, y, vx, vy]` at `t`.
    pub(crate) fn state_at(&self, t: Real) -> [Real; 4] {
        self.state_and_heading(t).0
    }
}
