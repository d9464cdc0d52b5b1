//! The walkers of a simulated recording (the main one and [`ChannelScene::others`], issue 41):
//! each a compiled walk, a body, and its own stream of fluctuations; what each adds to a link's
//! response and truth, and how it shadows a static ray. One code path for every walker, so the
//! main walker's recording is the one of a scene without further walkers, bit for bit.

use alloc::vec;
use alloc::vec::Vec;

use super::geometry::Line;
use super::rays::{body_centre, body_paths, passes_near, LinkBudget, StaticRay};
use super::signal::{add_path, cis_neg, complex_normal};
use super::walk::Path;
use super::{Body, ChannelScene, PathKind, TruePath};
use crate::error::Result;
use crate::math::{db_to_linear, sin, sqrt, Complex, Real, Vec2, PI};
use crate::measure::{rng, Rng};

/// rng stream of the main walker's body fluctuations (the value it has always had).
pub(super) const STREAM_BODY: u64 = 0x25_03;
/// rng stream of further walker `i`'s body fluctuations: this plus `i`.
const STREAM_BODY_OTHER: u64 = 0x41_10;

/// One walker while a recording is synthesised.
pub(super) struct Mover<'a> {
    pub(super) path: Path,
    body: &'a Body,
    rcs_centre: Real,
    shadow_amp: Real,
    rho: Real,
    innov: Real,
    rng: Rng,
    /// `fluct[p·K + k]`: centre `k`'s fluctuation on link `p`.
    fluct: Vec<Complex>,
}

/// The walkers of `scene` (the main one first), seeded by `seed`, for `links` links and a
/// target of RCS `rcs_m2`.
pub(super) fn movers<'a>(
    scene: &'a ChannelScene,
    links: usize,
    rcs_m2: Real,
    seed: u64,
) -> Result<Vec<Mover<'a>>> {
    let mut out = Vec::with_capacity(1 + scene.others.len());
    out.push(Mover::new(
        scene.walk.compile()?,
        &scene.body,
        links,
        rcs_m2,
        rng(seed, STREAM_BODY),
    ));
    for (i, w) in scene.others.iter().enumerate() {
        out.push(Mover::new(
            w.walk.compile()?,
            &w.body,
            links,
            rcs_m2,
            rng(seed, STREAM_BODY_OTHER + i as u64),
        ));
    }
    Ok(out)
}

impl<'a> Mover<'a> {
    fn new(path: Path, body: &'a Body, links: usize, rcs_m2: Real, rng: Rng) -> Mover<'a> {
        let rho = body.correlation;
        Mover {
            path,
            body,
            rcs_centre: rcs_m2 / body.centres as Real,
            shadow_amp: sqrt(db_to_linear(-body.shadow_loss_db)),
            rho,
            innov: sqrt(1.0 - rho * rho),
            rng,
            fluct: vec![Complex::new(0.0, 0.0); links * body.centres],
        }
    }

    /// The body's fluctuations of snapshot `s`: AR(1), the first snapshot a fresh draw. `gap`
    /// (a CPI's snapshots) is the time since the previous snapshot in scan intervals: the
    /// correlation is then `ρ^gap` (`None`: `ρ`, one scan).
    pub(super) fn draw(&mut self, s: usize, gap: Option<Real>) {
        let (rho, innov) = match gap {
            None => (self.rho, self.innov),
            Some(g) => {
                let r = crate::math::pow(self.rho, g);
                (r, sqrt(1.0 - r * r))
            }
        };
        for g in self.fluct.iter_mut() {
            let w = complex_normal(&mut self.rng);
            *g = if s == 0 { w } else { *g * rho + w * innov };
        }
    }

    /// The amplitude factor by which the walker at `st` shadows `ray` (1 when it does not).
    pub(super) fn shade(&self, ray: &StaticRay, st: &[Real; 4]) -> Option<Real> {
        (ray.shadowable
            && passes_near(
                &ray.points[..ray.npoints],
                Vec2::new(st[0], st[1]),
                self.body.shadow_radius_m,
            ))
        .then_some(self.shadow_amp)
    }

    /// Adds the walker's paths at state `st`, heading `head`, time `t_s` (the limbs' swing), on
    /// link `p` (budget `lb`) to the
    /// response `h` (bins `f0 + n·df`, carrier `fc`) and its truth (direct and via the walls,
    /// at the centre with the full `rcs_m2`); returns how many paths one centre has.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn add(
        &self,
        lb: &LinkBudget,
        lines: &[Line],
        (st, head): ([Real; 4], [Real; 2]),
        t_s: Real,
        p: usize,
        rcs_m2: Real,
        double_reflections: bool,
        [fc, f0, df]: [Real; 3],
        h: &mut [Complex],
        truth: &mut Vec<TruePath>,
        scratch: &mut Vec<(PathKind, Real, Real, Real)>,
    ) -> usize {
        let centre = Vec2::new(st[0], st[1]);
        let k_centres = self.body.centres;
        scratch.clear();
        body_paths(lb, lines, centre, rcs_m2, double_reflections, scratch);
        truth.extend(scratch.iter().map(|&(kind, delay_s, power_w, _)| TruePath {
            kind,
            delay_s,
            power_w,
        }));
        let swing = self.body.limb_swing_m;
        for k in 0..k_centres {
            let mut ck = body_centre(centre, head, k, k_centres, self.body.radius_m);
            if swing > 0.0 && k % 2 == 1 {
                // A limb: swung along the heading (micro-Doppler, `Body::limb_swing_m`).
                let phase = 2.0 * PI * self.body.gait_hz * t_s + 0.5 * PI * k as Real;
                ck += Vec2::new(head[0], head[1]) * (swing * sin(phase));
            }
            scratch.clear();
            body_paths(lb, lines, ck, self.rcs_centre, double_reflections, scratch);
            let g = self.fluct[p * k_centres + k];
            for &(_, tau, power, sign) in scratch.iter() {
                let alpha = cis_neg(fc * tau) * g * (sqrt(power) * sign);
                add_path(h, alpha, tau, f0, df);
            }
        }
        scratch.len()
    }

    /// The number of rays the work bound counts for this walker on a link, given the paths of
    /// one centre (`1 + K` sets of them, at least one each).
    pub(super) fn rays(&self, per_centre: usize) -> usize {
        (1 + self.body.centres) * per_centre.max(1)
    }
}
