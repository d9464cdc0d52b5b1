//! Bistatic-delay geometry (spec §2–3): delays (E1), the delay Jacobian in s/m (E3) and iso-delay
//! ellipses.
//!
//! Rooms in 3-D (issue 40): the target moves in the horizontal plane at its height `z_t`; node
//! `n` sits at height `z_n`, so its vertical offset is `dz_n = z_n − z_t` and its distance to a
//! target at `r` (2-D) is `d_n = √(‖r − r_n‖² + dz_n²)`. The bistatic range is `d_Tx + d_Rx`
//! and its gradient with respect to the 2-D position is `(r − r_Tx)/d_Tx + (r − r_Rx)/d_Rx`:
//! the horizontal parts of the 3-D unit vectors. Every dz 0 is the planar model of the spec,
//! bitwise: the 3-D functions compute `dx² + (dy² + dz²)`, which is `dx² + dy²` exactly when
//! `dz = 0`, and the ranges take the planar code path then.

use alloc::vec::Vec;

use crate::math::{atan2, cos, sin, sqrt, Real, Vec2, PI, SPEED_OF_LIGHT};
use crate::measure::Ellipse;
use crate::scenario::LinkIndex;

/// Distances below this (m) make a unit vector zero (spec §3).
pub const UNIT_VECTOR_MIN_DISTANCE_M: Real = 1e-9;

/// Node positions, their vertical offsets from the target's plane and the link set 𝒫 of a
/// network, in link order.
#[derive(Debug, Clone, PartialEq)]
pub struct Network {
    /// Transmitter positions `r^Tx_k` (horizontal), m.
    pub transmitters: Vec<Vec2>,
    /// Receiver positions `r^Rx_l` (horizontal), m.
    pub receivers: Vec<Vec2>,
    /// Per transmitter `dz = z_Tx − z_target`, m (one per transmitter; all 0 in a planar room).
    pub transmitters_dz: Vec<Real>,
    /// Per receiver `dz = z_Rx − z_target`, m (one per receiver; all 0 in a planar room).
    pub receivers_dz: Vec<Real>,
    /// Links (k, l) in link order.
    pub links: Vec<LinkIndex>,
}

/// Unit vector from `node` to `r`, zero when they (nearly) coincide, and the distance (the
/// planar case of [`unit_from_dz`], bitwise).
#[inline(always)]
pub fn unit_from(node: Vec2, r: Vec2) -> (Vec2, Real) {
    unit_from_dz(node, 0.0, r)
}

/// The 3-D distance `√(‖r − node‖² + dz²)` from a node at vertical offset `dz` to the point `r`
/// of the target's plane, m, computed as `√(dx² + (dy² + dz²))` (bitwise `√(dx² + dy²)` when
/// `dz = 0`).
#[inline(always)]
pub fn node_distance(node: Vec2, dz: Real, r: Vec2) -> Real {
    let d = r - node;
    sqrt(d.x * d.x + (d.y * d.y + dz * dz))
}

/// The horizontal part of the 3-D unit vector from a node at vertical offset `dz` to the point
/// `r` of the target's plane, `(r − node)/d` (the node's term of the range gradient, E3), and
/// the 3-D distance `d` ([`node_distance`]). Zero when `d` is below
/// [`UNIT_VECTOR_MIN_DISTANCE_M`]; a point straight below or above the node (`r = node`,
/// `dz ≠ 0`) gets the zero vector too, as the gradient is there.
#[inline(always)]
pub fn unit_from_dz(node: Vec2, dz: Real, r: Vec2) -> (Vec2, Real) {
    let d = r - node;
    let n = sqrt(d.x * d.x + (d.y * d.y + dz * dz));
    if n < UNIT_VECTOR_MIN_DISTANCE_M {
        (Vec2::zeros(), n)
    } else {
        (d / n, n)
    }
}

/// The vertical component of the unit vector from a node at vertical distance `h` above the
/// target (`h = dz − δz`) to the target, for a node at 3-D distance `d`: the height's term of
/// the range gradient (issue 40 §2, a fix with a free height); 0 where [`unit_from_dz`] gives
/// the zero vector (the target on the node).
#[inline(always)]
pub fn vertical_unit(h: Real, d: Real) -> Real {
    if d < UNIT_VECTOR_MIN_DISTANCE_M {
        0.0
    } else {
        -h / d
    }
}

/// Bistatic range with vertical offsets (E1 in 3-D): `√(‖r − r^Tx‖² + dz_Tx²) +
/// √(‖r − r^Rx‖² + dz_Rx²)`, m. Both offsets 0 is [`bistatic_range`], bitwise.
#[inline]
pub fn bistatic_range_dz(tx: Vec2, dz_tx: Real, rx: Vec2, dz_rx: Real, r: Vec2) -> Real {
    if dz_tx == 0.0 && dz_rx == 0.0 {
        bistatic_range(tx, rx, r)
    } else {
        node_distance(tx, dz_tx, r) + node_distance(rx, dz_rx, r)
    }
}

/// [`bistatic_range_dz`] and its gradient with respect to the 2-D position `r`,
/// `(r − r^Tx)/d_Tx + (r − r^Rx)/d_Rx` with the 3-D distances (zero-distance rule of
/// [`unit_from_dz`]). Both offsets 0 is [`range_and_gradient`], bitwise.
#[inline]
pub fn range_and_gradient_dz(
    tx: Vec2,
    dz_tx: Real,
    rx: Vec2,
    dz_rx: Real,
    r: Vec2,
) -> (Real, Vec2) {
    let (ut, nt) = unit_from_dz(tx, dz_tx, r);
    let (ur, nr) = unit_from_dz(rx, dz_rx, r);
    (nt + nr, ut + ur)
}

/// Line-of-sight range between two nodes at vertical offsets `dz_tx`, `dz_rx` (from the same
/// plane, so their height difference is `dz_rx − dz_tx`): `√(‖rx − tx‖² + (dz_rx − dz_tx)²)`, m;
/// `‖rx − tx‖` (bitwise) when the offsets are equal.
#[inline]
pub fn los_range_dz(tx: Vec2, dz_tx: Real, rx: Vec2, dz_rx: Real) -> Real {
    let h = dz_rx - dz_tx;
    if h == 0.0 {
        (rx - tx).norm()
    } else {
        node_distance(tx, h, rx)
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

    /// Transmitter and receiver position (horizontal) of link `p`.
    #[inline]
    pub fn link_nodes(&self, p: usize) -> (Vec2, Vec2) {
        let l = self.links[p];
        (self.transmitters[l.tx], self.receivers[l.rx])
    }

    /// Vertical offsets `(dz_Tx, dz_Rx)` of link `p`'s nodes from the target's plane, m.
    #[inline]
    pub fn link_dz(&self, p: usize) -> (Real, Real) {
        let l = self.links[p];
        (self.transmitters_dz[l.tx], self.receivers_dz[l.rx])
    }

    /// Whether every node lies in the target's plane (every dz 0): the planar model.
    pub fn is_planar(&self) -> bool {
        self.transmitters_dz
            .iter()
            .chain(&self.receivers_dz)
            .all(|&z| z == 0.0)
    }

    /// Unit vector (horizontal part, [`unit_from_dz`]) and 3-D distance from transmitter `k` to
    /// `r`.
    #[inline]
    pub fn tx_unit(&self, k: usize, r: Vec2) -> (Vec2, Real) {
        unit_from_dz(self.transmitters[k], self.transmitters_dz[k], r)
    }

    /// Unit vector (horizontal part, [`unit_from_dz`]) and 3-D distance from receiver `l` to `r`.
    #[inline]
    pub fn rx_unit(&self, l: usize, r: Vec2) -> (Vec2, Real) {
        unit_from_dz(self.receivers[l], self.receivers_dz[l], r)
    }

    /// The 3-D distances ([`node_distance`]) from `r` to every transmitter, then every receiver,
    /// into `out` (length `K + L`), m.
    pub fn node_distances_into(&self, r: Vec2, out: &mut [Real]) {
        let nodes = self.transmitters.iter().zip(&self.transmitters_dz);
        let nodes = nodes.chain(self.receivers.iter().zip(&self.receivers_dz));
        for (o, (n, &dz)) in out.iter_mut().zip(nodes) {
            *o = node_distance(*n, dz, r);
        }
    }

    /// Bistatic range `c·τ_p(r)` of link `p`, m (E1, 3-D: [`bistatic_range_dz`]).
    #[inline]
    pub fn range(&self, p: usize, r: Vec2) -> Real {
        let (tx, rx) = self.link_nodes(p);
        let (zt, zr) = self.link_dz(p);
        bistatic_range_dz(tx, zt, rx, zr, r)
    }

    /// Range and its gradient of link `p` at `r` ([`range_and_gradient_dz`]).
    #[inline]
    pub fn range_and_gradient(&self, p: usize, r: Vec2) -> (Real, Vec2) {
        let (tx, rx) = self.link_nodes(p);
        let (zt, zr) = self.link_dz(p);
        range_and_gradient_dz(tx, zt, rx, zr, r)
    }

    /// Delay `τ_p(r)` of link `p`, s (E1).
    #[inline]
    pub fn delay(&self, p: usize, r: Vec2) -> Real {
        self.range(p, r) / SPEED_OF_LIGHT
    }

    /// `h(r)`: the delays of all links in link order, s (E2).
    pub fn delays(&self, r: Vec2) -> Vec<Real> {
        (0..self.links.len()).map(|p| self.delay(p, r)).collect()
    }

    /// Row `p` of the Jacobian `J(r)`, s/m (E3).
    #[inline]
    pub fn jacobian_row(&self, p: usize, r: Vec2) -> Vec2 {
        let (tx, rx) = self.link_nodes(p);
        let (zt, zr) = self.link_dz(p);
        (unit_from_dz(tx, zt, r).0 + unit_from_dz(rx, zr, r).0) / SPEED_OF_LIGHT
    }

    /// The full Jacobian `J(r)` as rows in link order, s/m (E3).
    pub fn jacobian(&self, r: Vec2) -> Vec<Vec2> {
        (0..self.links.len())
            .map(|p| self.jacobian_row(p, r))
            .collect()
    }

    /// Line-of-sight delay of link `p`: the 3-D distance between its nodes over `c`, s (the
    /// nodes' own heights; `‖r^Rx − r^Tx‖/c` when they are at the same height).
    pub fn los_delay(&self, p: usize) -> Real {
        let (tx, rx) = self.link_nodes(p);
        let (zt, zr) = self.link_dz(p);
        los_range_dz(tx, zt, rx, zr) / SPEED_OF_LIGHT
    }

    /// Iso-delay ellipse of a measured delay on link `p` (spec §2): foci at the link's nodes,
    /// semi-major `a = cτ/2`, semi-minor `√(a² − f²)`. `None` when the delay is below the LoS
    /// delay or not finite (no such ellipse exists).
    ///
    /// In a 3-D room (a node off the target's plane) the set of points of the plane with this
    /// delay is not an ellipse in general; this is then the planar model's ellipse, an
    /// approximation (docs/rooms-3d.md) — [`Network::iso_delay_curve`] and
    /// [`Network::iso_delay_arc_near`] give the exact curve.
    pub fn iso_delay_ellipse(&self, p: usize, delay_s: Real) -> Option<Ellipse> {
        let (tx, rx) = self.link_nodes(p);
        iso_delay_ellipse(tx, rx, delay_s)
    }

    /// Whether link `p`'s nodes both lie in the target's plane (its iso-delay set there is the
    /// ellipse of [`Network::iso_delay_ellipse`]).
    pub fn link_is_planar(&self, p: usize) -> bool {
        self.link_dz(p) == (0.0, 0.0)
    }

    /// The exact iso-delay curve of link `p` in the target's plane, 3-D distances
    /// (`{r : d_Tx(r) + d_Rx(r) = cτ}`), as `n` points (a closed polyline, `n` clamped to
    /// `8..=4096`) at the angles `2πi/n` around the midpoint of the foci ([`IsoCurve`]). Empty
    /// when the delay is not finite or not above the range at that midpoint. With every dz 0 it
    /// lies on [`Network::iso_delay_ellipse`] (to the bisection's precision, tested).
    pub fn iso_delay_curve(&self, p: usize, delay_s: Real, n: usize) -> Vec<Vec2> {
        let Some(curve) = IsoCurve::new(self, p, delay_s) else {
            return Vec::new();
        };
        let n = n.clamp(8, 4096);
        (0..n)
            .map(|i| curve.at(2.0 * PI * i as Real / n as Real))
            .collect()
    }

    /// `n ≥ 2` points of the exact iso-delay curve of link `p` near `near` (as
    /// [`Ellipse::arc_near`]: about `±1.5·radius` of arc length around the curve's point in
    /// `near`'s direction from the midpoint of the foci; empty when that point is farther than
    /// `2·radius` from `near`, or no curve exists).
    pub fn iso_delay_arc_near(
        &self,
        p: usize,
        delay_s: Real,
        near: Vec2,
        radius: Real,
        n: usize,
    ) -> Vec<Vec2> {
        let Some(curve) = IsoCurve::new(self, p, delay_s) else {
            return Vec::new();
        };
        let d = near - curve.center;
        let t0 = atan2(d.y, d.x);
        if !(radius.is_finite() && radius > 0.0 && t0.is_finite() && n >= 2)
            || (curve.at(t0) - near).norm() > 2.0 * radius
        {
            return Vec::new();
        }
        // Arc length per radian there, by a central difference.
        let h = 1e-4;
        let speed = (curve.at(t0 + h) - curve.at(t0 - h)).norm() / (2.0 * h);
        if speed.is_nan() || speed <= 0.0 {
            return Vec::new();
        }
        let half = (1.5 * radius / speed).min(PI);
        (0..n)
            .map(|i| curve.at(t0 - half + 2.0 * half * i as Real / (n - 1) as Real))
            .collect()
    }
}

/// The iso-range set `{r : d_Tx(r) + d_Rx(r) = ρ}` of one link in the target's plane, found
/// along rays from the midpoint `center` of the foci: the range is convex (a sum of
/// `√(‖r − r_n‖² + dz²)`), so along a ray from a point inside (range below ρ) it crosses ρ exactly
/// once; at distance `s` it is at least `2s − ‖r_Rx − r_Tx‖`, so `s = ρ + ‖r_Rx − r_Tx‖` is past
/// the crossing, which bisection finds (64 halvings: a bound, and below an ulp of `s`).
struct IsoCurve {
    tx: Vec2,
    rx: Vec2,
    dz: (Real, Real),
    center: Vec2,
    range: Real,
    outer: Real,
}

impl IsoCurve {
    fn new(net: &Network, p: usize, delay_s: Real) -> Option<IsoCurve> {
        let (tx, rx) = net.link_nodes(p);
        let dz = net.link_dz(p);
        let range = SPEED_OF_LIGHT * delay_s;
        let center = (tx + rx) / 2.0;
        let inside = bistatic_range_dz(tx, dz.0, rx, dz.1, center) < range;
        (range.is_finite() && inside).then(|| IsoCurve {
            tx,
            rx,
            dz,
            center,
            range,
            outer: range + (rx - tx).norm(),
        })
    }

    /// The curve's point in the direction `theta` from the centre.
    fn at(&self, theta: Real) -> Vec2 {
        let dir = Vec2::new(cos(theta), sin(theta));
        let (mut lo, mut hi) = (0.0, self.outer);
        for _ in 0..64 {
            let mid = 0.5 * (lo + hi);
            let r = self.center + dir * mid;
            if bistatic_range_dz(self.tx, self.dz.0, self.rx, self.dz.1, r) < self.range {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        self.center + dir * (0.5 * (lo + hi))
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
