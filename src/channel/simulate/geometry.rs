//! The plane geometry of the image method: walls as lines ([`Line`]: mirror images, sides,
//! crossings) and the distance from a point to a segment (shadowing).

use super::Wall;
use crate::math::{sqrt, Real, Vec2};

pub(super) fn v(p: [f64; 2]) -> Vec2 {
    Vec2::new(p[0], p[1])
}

fn cross(a: Vec2, b: Vec2) -> Real {
    a.x * b.y - a.y * b.x
}

pub(super) fn dist(a: Vec2, b: Vec2) -> Real {
    let d = b - a;
    sqrt(d.x * d.x + d.y * d.y)
}

/// The 3-D distance between `a` and a point `dz` below or above `b`: `√(‖b − a‖² + dz²)`
/// ([`dist`], bitwise, when `dz = 0`).
pub(super) fn dist_dz(a: Vec2, b: Vec2, dz: Real) -> Real {
    if dz == 0.0 {
        dist(a, b)
    } else {
        let d = b - a;
        sqrt(d.x * d.x + (d.y * d.y + dz * dz))
    }
}

/// A wall as a line: a point, the direction `b − a`, and `Γ`.
#[derive(Debug, Clone, Copy)]
pub(super) struct Line {
    pub(super) a: Vec2,
    pub(super) d: Vec2,
    pub(super) gamma: Real,
}

impl Line {
    pub(super) fn new(w: &Wall) -> Line {
        Line {
            a: v(w.a_m),
            d: v(w.b_m) - v(w.a_m),
            gamma: w.gamma,
        }
    }

    /// The mirror image of `p` in the wall's line.
    pub(super) fn mirror(&self, p: Vec2) -> Vec2 {
        let dd = self.d.x * self.d.x + self.d.y * self.d.y;
        let t = ((p - self.a).x * self.d.x + (p - self.a).y * self.d.y) / dd;
        let foot = self.a + self.d * t;
        foot * 2.0 - p
    }

    /// Which side of the line `p` is on (signed, zero on it).
    pub(super) fn side(&self, p: Vec2) -> Real {
        cross(self.d, p - self.a)
    }

    /// Where the segment `p`–`q` crosses the wall segment, if it does (strictly from opposite
    /// sides, the crossing on the wall's segment).
    pub(super) fn crossing(&self, p: Vec2, q: Vec2) -> Option<Vec2> {
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
pub(super) fn segment_distance(p: Vec2, a: Vec2, b: Vec2) -> Real {
    let d = b - a;
    let dd = d.x * d.x + d.y * d.y;
    let t = if dd > 0.0 {
        (((p - a).x * d.x + (p - a).y * d.y) / dd).clamp(0.0, 1.0)
    } else {
        0.0
    };
    dist(p, a + d * t)
}
