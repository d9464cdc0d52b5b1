//! Bistatic-delay geometry (spec §2–3): delays (E1), the delay Jacobian in s/m (E3) and iso-delay
//! ellipses.

use alloc::vec::Vec;

use crate::math::{atan2, sqrt, Real, Vec2, SPEED_OF_LIGHT};
use crate::measure::Ellipse;
use crate::scenario::LinkIndex;

/// Distances below this (m) make a unit vector zero (spec §3).
pub const UNIT_VECTOR_MIN_DISTANCE_M: Real = 1e-9;

/// Node positions and the link set 𝒫 of a network, in link order.
#[derive(Debug, Clone, PartialEq)]
pub struct Network {
    /// Transmitter positions `r^Tx_k`, m.
    pub transmitters: Vec<Vec2>,
    /// Receiver positions `r^Rx_l`, m.
    pub receivers: Vec<Vec2>,
    /// Links (k, l) in link order.
    pub links: Vec<LinkIndex>,
}

/// Unit vector from `node` to `r`, zero when they (nearly) coincide, and the distance.
#[inline(always)]
pub fn unit_from(node: Vec2, r: Vec2) -> (Vec2, Real) {
    let d = r - node;
    let n = sqrt(d.x * d.x + d.y * d.y);
    if n < UNIT_VECTOR_MIN_DISTANCE_M {
        (Vec2::zeros(), n)
    } else {
        (d / n, n)
    }
}

/// Bistatic range `d(r) = ‖r − r^Tx‖ + ‖r − r^Rx‖`, m: `c·τ` of (E1) and the range function
/// (M1) of the multi-target layer. The one home of the range; every layer calls it.
#[inline]
pub fn bistatic_range(tx: Vec2, rx: Vec2, r: Vec2) -> Real {
    (r - tx).norm() + (r - rx).norm()
}

/// Gradient of [`bistatic_range`] with respect to `r`: `u^Tx + u^Rx` (E3 times `c`), unitless.
/// A term whose node (nearly) coincides with `r` contributes the zero vector
/// ([`UNIT_VECTOR_MIN_DISTANCE_M`]); zero on the Tx–Rx baseline segment.
#[inline]
pub fn range_gradient(tx: Vec2, rx: Vec2, r: Vec2) -> Vec2 {
    unit_from(tx, r).0 + unit_from(rx, r).0
}

/// [`bistatic_range`] and [`range_gradient`] from the two distances computed once (the same
/// values, bitwise).
#[inline]
pub fn range_and_gradient(tx: Vec2, rx: Vec2, r: Vec2) -> (Real, Vec2) {
    let (ut, nt) = unit_from(tx, r);
    let (ur, nr) = unit_from(rx, r);
    (nt + nr, ut + ur)
}

/// Bistatic delay `τ = (‖r − r^Tx‖ + ‖r − r^Rx‖)/c`, s (E1).
#[inline]
pub fn bistatic_delay(tx: Vec2, rx: Vec2, r: Vec2) -> Real {
    bistatic_range(tx, rx, r) / SPEED_OF_LIGHT
}

/// Gradient of the bistatic delay with respect to `r`, s/m: `(u^Tx + u^Rx)/c` (E3).
/// Zero on the Tx–Rx baseline segment.
#[inline]
pub fn delay_gradient(tx: Vec2, rx: Vec2, r: Vec2) -> Vec2 {
    range_gradient(tx, rx, r) / SPEED_OF_LIGHT
}

impl Network {
    /// Number of links |𝒫|.
    pub fn link_count(&self) -> usize {
        self.links.len()
    }

    /// Transmitter and receiver position of link `p`.
    #[inline]
    pub fn link_nodes(&self, p: usize) -> (Vec2, Vec2) {
        let l = self.links[p];
        (self.transmitters[l.tx], self.receivers[l.rx])
    }

    /// Delay `τ_p(r)` of link `p`, s (E1).
    #[inline]
    pub fn delay(&self, p: usize, r: Vec2) -> Real {
        let (tx, rx) = self.link_nodes(p);
        bistatic_delay(tx, rx, r)
    }

    /// `h(r)`: the delays of all links in link order, s (E2).
    pub fn delays(&self, r: Vec2) -> Vec<Real> {
        (0..self.links.len()).map(|p| self.delay(p, r)).collect()
    }

    /// Row `p` of the Jacobian `J(r)`, s/m (E3).
    #[inline]
    pub fn jacobian_row(&self, p: usize, r: Vec2) -> Vec2 {
        let (tx, rx) = self.link_nodes(p);
        delay_gradient(tx, rx, r)
    }

    /// The full Jacobian `J(r)` as rows in link order, s/m (E3).
    pub fn jacobian(&self, r: Vec2) -> Vec<Vec2> {
        (0..self.links.len())
            .map(|p| self.jacobian_row(p, r))
            .collect()
    }

    /// Line-of-sight delay of link `p`: `‖r^Rx − r^Tx‖/c`, s.
    pub fn los_delay(&self, p: usize) -> Real {
        let (tx, rx) = self.link_nodes(p);
        (rx - tx).norm() / SPEED_OF_LIGHT
    }

    /// Iso-delay ellipse of a measured delay on link `p` (spec §2): foci at the link's nodes,
    /// semi-major `a = cτ/2`, semi-minor `√(a² − f²)`. `None` when the delay is below the LoS
    /// delay or not finite (no such ellipse exists).
    pub fn iso_delay_ellipse(&self, p: usize, delay_s: Real) -> Option<Ellipse> {
        let (tx, rx) = self.link_nodes(p);
        iso_delay_ellipse(tx, rx, delay_s)
    }
}

/// Iso-delay ellipse with foci `tx`, `rx` for delay `delay_s` (spec §2); `None` if it does not exist.
pub fn iso_delay_ellipse(tx: Vec2, rx: Vec2, delay_s: Real) -> Option<Ellipse> {
    iso_range_ellipse(tx, rx, SPEED_OF_LIGHT * delay_s)
}

/// Iso-range ellipse `{x : ‖x − tx‖ + ‖x − rx‖ = range_m}` (multi-target spec §5.1): semi-major
/// `a = ρ/2`, focal half-distance `f = ‖rx − tx‖/2`, semi-minor `b = √(a² − f²)`. `None` if the
/// range is not finite or `ρ < 2f`; a degenerate ellipse (`b = 0`, the segment) when `ρ = 2f`.
pub fn iso_range_ellipse(tx: Vec2, rx: Vec2, range_m: Real) -> Option<Ellipse> {
    if !range_m.is_finite() {
        return None;
    }
    let a = range_m / 2.0;
    let axis = rx - tx;
    let f = axis.norm() / 2.0;
    if a < f {
        return None;
    }
    let b = sqrt((a * a - f * f).max(0.0));
    Some(Ellipse {
        center: (tx + rx) / 2.0,
        semi_major: a,
        semi_minor: b,
        angle_rad: atan2(axis.y, axis.x),
    })
}
