//! The paths of one link: its link budget ([`LinkBudget`]: Friis and bistatic radar powers with the
//! Tx pattern, E8), the static rays (LoS, first- and second-order wall reflections by the image
//! method, point scatterers) and the body's paths through a point, direct and via each wall.
//!
//! Heights (issue 40): the walls are vertical, so the image method runs in the plane and a
//! reflection leaves heights unchanged; a path's length is `√(L_xy² + Δz²)` with `L_xy` its
//! unfolded horizontal length and `Δz` the height difference of its ends. The body and the
//! point scatterers are in the target's plane; the Tx nodes' and Rx nodes' vertical offsets from
//! it are [`LinkBudget::dz_tx`], [`LinkBudget::dz_rx`]. The Tx gain is taken toward the 3-D
//! direction of the path's first leg ([`crate::measure::unit_from_dz`]). Shadowing by the walker
//! is tested on the horizontal projection of a path.

use alloc::vec::Vec;

use super::geometry::{dist, dist_dz, segment_distance, v, Line};
use super::{ChannelScene, PathKind};
use crate::math::{cos, sin, Real, Vec2, PI, SPEED_OF_LIGHT};
use crate::measure::{unit_from_dz, SNR_DISTANCE_FLOOR_M};

/// One link's constants.
pub(super) struct LinkBudget<'a> {
    pub(super) tx: Vec2,
    pub(super) rx: Vec2,
    /// The Tx's vertical offset from the target's plane, m (0 in a planar room).
    pub(super) dz_tx: Real,
    /// The Rx's vertical offset from the target's plane, m (0 in a planar room).
    pub(super) dz_rx: Real,
    pub(super) pattern: &'a crate::measure::TxPattern,
    /// `P_Tx·G_Rx`, W.
    pub(super) ptx_grx: Real,
    pub(super) lambda: Real,
}

impl LinkBudget<'_> {
    /// The Tx gain toward the point `p` that lies `dz` below the Tx (3-D direction).
    fn gain_toward(&self, p: Vec2, dz: Real) -> Real {
        self.pattern.gain_toward(unit_from_dz(self.tx, dz, p).0)
    }

    /// The Tx's height above the point of a straight (unfolded) path from the Tx to an end `dz`
    /// below it, at horizontal distance `along` of the path's horizontal length `total`.
    fn drop_at(dz: Real, along: Real, total: Real) -> Real {
        if dz == 0.0 || total <= 0.0 {
            dz
        } else {
            dz * (along / total).min(1.0)
        }
    }

    /// Friis power over the (unfolded, 3-D) length `len`, Tx gain toward `first` (the first
    /// bounce or the Rx), which lies `first_dz` below the Tx, W.
    pub(super) fn friis(&self, first: Vec2, first_dz: Real, len: Real) -> Real {
        let l = len.max(SNR_DISTANCE_FLOOR_M);
        let k = self.lambda / (4.0 * PI * l);
        self.ptx_grx * self.gain_toward(first, first_dz) * k * k
    }

    /// Bistatic radar power of a scatterer of RCS `rcs` at distances `d1`, `d2` (floored at
    /// 1 m as in E8), Tx gain toward `first`, `first_dz` below the Tx, W.
    pub(super) fn radar(&self, first: Vec2, first_dz: Real, d1: Real, d2: Real, rcs: Real) -> Real {
        let d1 = d1.max(SNR_DISTANCE_FLOOR_M);
        let d2 = d2.max(SNR_DISTANCE_FLOOR_M);
        let four_pi3 = (4.0 * PI) * (4.0 * PI) * (4.0 * PI);
        self.ptx_grx * rcs * self.lambda * self.lambda * self.gain_toward(first, first_dz)
            / (four_pi3 * d1 * d1 * d2 * d2)
    }
}

/// A static path of one link: its truth, its amplitude without shadowing, and the polyline it
/// follows (checked against the walker for shadowing when `shadowable`).
pub(super) struct StaticRay {
    pub(super) kind: PathKind,
    pub(super) delay: Real,
    pub(super) power: Real,
    /// Real factor of the reflections (product of Γ).
    pub(super) sign: Real,
    pub(super) points: [Vec2; 4],
    pub(super) npoints: usize,
    pub(super) shadowable: bool,
}

/// The static paths of a link (LoS, walls, wall–wall, point scatterers).
pub(super) fn static_rays(lb: &LinkBudget, lines: &[Line], scene: &ChannelScene) -> Vec<StaticRay> {
    let (tx, rx) = (lb.tx, lb.rx);
    // The Tx's height above the Rx (a vertical wall keeps it along every reflected path).
    let h = lb.dz_tx - lb.dz_rx;
    let mut rays = Vec::new();
    let z = Vec2::zeros();
    let d = dist_dz(tx, rx, h);
    rays.push(StaticRay {
        kind: PathKind::Los,
        delay: d / SPEED_OF_LIGHT,
        power: lb.friis(rx, h, d),
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
            let len = dist_dz(tx, img, h);
            let first_dz = LinkBudget::drop_at(h, dist(tx, p), dist(tx, img));
            rays.push(StaticRay {
                kind: PathKind::Wall,
                delay: len / SPEED_OF_LIGHT,
                power: lb.friis(p, first_dz, len) * w.gamma * w.gamma,
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
                let len = dist_dz(t2, rx, h);
                let first_dz = LinkBudget::drop_at(h, dist(tx, p), dist(t2, rx));
                let g = wi.gamma * wj.gamma;
                rays.push(StaticRay {
                    kind: PathKind::WallWall,
                    delay: len / SPEED_OF_LIGHT,
                    power: lb.friis(p, first_dz, len) * g * g,
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
        let (d1, d2) = (dist_dz(tx, p, lb.dz_tx), dist_dz(p, rx, lb.dz_rx));
        rays.push(StaticRay {
            kind: PathKind::Scatterer,
            delay: (d1 + d2) / SPEED_OF_LIGHT,
            power: lb.radar(p, lb.dz_tx, d1, d2, s.rcs_m2),
            sign: 1.0,
            points: [tx, p, rx, z],
            npoints: 3,
            shadowable: false,
        });
    }
    rays
}

/// Whether the polyline passes within `radius` of `p`.
pub(super) fn passes_near(points: &[Vec2], p: Vec2, radius: Real) -> bool {
    points
        .windows(2)
        .any(|w| segment_distance(p, w[0], w[1]) < radius)
}

/// A body path through a point `c` (a centre or the walker): direct and via each wall, as
/// `(kind, delay, mean power, reflection factor)` for a scatterer of RCS `rcs` at `c`.
pub(super) fn body_paths(
    lb: &LinkBudget,
    lines: &[Line],
    c: Vec2,
    rcs: Real,
    double: bool,
    out: &mut Vec<(PathKind, Real, Real, Real)>,
) {
    let (tx, rx) = (lb.tx, lb.rx);
    let (zt, zr) = (lb.dz_tx, lb.dz_rx);
    let (d1, d2) = (dist_dz(tx, c, zt), dist_dz(c, rx, zr));
    out.push((
        PathKind::Body,
        (d1 + d2) / SPEED_OF_LIGHT,
        lb.radar(c, zt, d1, d2, rcs),
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
                let d1 = dist_dz(ti, c, zt);
                let first_dz = LinkBudget::drop_at(zt, dist(tx, p), dist(ti, c));
                out.push((
                    PathKind::BodyWall,
                    (d1 + d2) / SPEED_OF_LIGHT,
                    lb.radar(p, first_dz, d1, d2, rcs) * g2,
                    w.gamma,
                ));
            }
        }
        // Tx → c → wall → Rx: image of Rx.
        if w.side(rx) * w.side(c) > 0.0 {
            let ri = w.mirror(rx);
            if let Some(_p) = w.crossing(c, ri) {
                let d1 = dist_dz(tx, c, zt);
                let d2 = dist_dz(c, ri, zr);
                out.push((
                    PathKind::BodyWall,
                    (d1 + d2) / SPEED_OF_LIGHT,
                    lb.radar(c, zt, d1, d2, rcs) * g2,
                    w.gamma,
                ));
            }
        }
    }
}

/// Scattering centre `k` of `count` of a walker at `centre` heading along the unit `head`: at
/// angle `2πk/count` from the heading, `radius` from the centre.
pub(super) fn body_centre(
    centre: Vec2,
    head: [Real; 2],
    k: usize,
    count: usize,
    radius: Real,
) -> Vec2 {
    let phi = 2.0 * PI * k as Real / count as Real;
    let (c, sn) = (cos(phi), sin(phi));
    let off = Vec2::new(head[0] * c - head[1] * sn, head[1] * c + head[0] * sn);
    centre + off * radius
}
