//! Where new targets come from when a sensor measures one delay per link (issue 41 §1): a
//! single delay places a target anywhere on an ellipse, so a new target is proposed from the
//! delays that no track explains on several links at once. A fixed grid over the region holds
//! every link's delay `τ_p(r)` and its tolerance (half a cell's diagonal times `|∇τ_p|` plus
//! the gate times `σ_p`, E8) once per model; a scan scores each cell by the links that have a
//! free delay within tolerance, the best cells are refined by the planar LM fix (spec §5) on
//! those delays, and a fix is taken as a birth when at least `min_links` delays lie within the
//! gate of it. The delays used are removed and the search repeats, at most
//! `max_per_scan` births and `max_candidates` refinements per scan (the stated bounds).
//!
//! Cost: the cells a free delay reaches are one range of its link's cells sorted by delay, so
//! the links per cell are counted once per scan; a birth takes away one delay per link and
//! only the cells those reached are recounted; only cells that reach `min_links` are scored
//! (the same fixes, bit for bit, as scoring every cell at every refinement: the unit test's
//! reference).
//!
//! The snapshot solver of \[A\] (`mtl`) handles blocking with its own planar inputs; this
//! search is its one-target-at-a-time, gated counterpart on the tracker's model.

use alloc::vec;
use alloc::vec::Vec;

use crate::error::{Error, Result};
use crate::localize::{locate, DelayMeasurements, LmConfig};
use crate::math::{exp, ln, sqrt, Mat2, Real, Vec2, PI};
use crate::measure::Model;
use crate::scenario::Area;

/// Most grid cells of a birth search.
pub const MAX_BIRTH_CELLS: usize = 250_000;

/// The settings of the delay birth search.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DelayBirth {
    /// The region new targets appear in, m.
    pub region: Area,
    /// Grid spacing, m (default 0.25).
    pub step_m: Real,
    /// Delays within the gate needed for a birth (default: all links but two, at least 3).
    pub min_links: usize,
    /// Gate in σ of a delay (default 4).
    pub gate_sigmas: Real,
    /// Most births per scan (default 5).
    pub max_per_scan: usize,
    /// Most LM refinements per scan (default 12).
    pub max_candidates: usize,
    /// Expected new targets per scan over the region (default 0.01): with the fix's likelihood
    /// it sets a new target's existence (see [`BirthFix::log_evidence`]).
    pub rate: Real,
    /// Prior σ of a new target's velocity per axis, m/s (default 1.0).
    pub velocity_sigma: Real,
}

impl DelayBirth {
    /// The defaults above for `links` links over `region`.
    pub fn new(region: Area, links: usize) -> DelayBirth {
        DelayBirth {
            region,
            step_m: 0.25,
            min_links: links.saturating_sub(2).max(3),
            gate_sigmas: 4.0,
            max_per_scan: 5,
            max_candidates: 12,
            rate: 0.01,
            velocity_sigma: 1.0,
        }
    }

    /// Named errors for a bad setting.
    pub fn validate(&self, links: usize) -> Result<()> {
        let Area { x, y } = self.region;
        if !(x[0].is_finite() && x[1].is_finite() && y[0].is_finite() && y[1].is_finite())
            || x[0] >= x[1]
            || y[0] >= y[1]
        {
            return Err(Error::OutOfRange {
                field: "birth.region".into(),
                value: x[1] - x[0],
                allowed: "a finite region with x_min < x_max and y_min < y_max",
            });
        }
        if !(self.step_m.is_finite() && self.step_m > 0.0) {
            return Err(Error::NotPositive {
                field: "birth.step_m".into(),
                value: self.step_m,
            });
        }
        let cells = ((x[1] - x[0]) / self.step_m + 1.0) * ((y[1] - y[0]) / self.step_m + 1.0);
        if cells > MAX_BIRTH_CELLS as Real {
            return Err(Error::SizeLimit {
                field: "birth grid cells",
                value: cells as usize,
                min: 1,
                max: MAX_BIRTH_CELLS,
            });
        }
        if self.min_links < 3 || self.min_links > links {
            return Err(Error::SizeLimit {
                field: "birth.min_links",
                value: self.min_links,
                min: 3,
                max: links,
            });
        }
        for (field, v) in [
            ("birth.gate_sigmas", self.gate_sigmas),
            ("birth.velocity_sigma", self.velocity_sigma),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(Error::NotPositive {
                    field: field.into(),
                    value: v,
                });
            }
        }
        if !(self.rate.is_finite() && self.rate > 0.0) {
            return Err(Error::NotPositive {
                field: "birth.rate".into(),
                value: self.rate,
            });
        }
        Ok(())
    }
}

/// The grid of one model: per cell and link, the delay and its tolerance (built once).
#[derive(Debug, Clone)]
pub struct BirthGrid {
    settings: DelayBirth,
    cells: Vec<Vec2>,
    links: usize,
    /// `cells × links`: delay, s.
    delay: Vec<Real>,
    /// `cells × links`: tolerance, s.
    tolerance: Vec<Real>,
    /// Per link, the cells in increasing order of their delay, and those delays.
    by_delay: Vec<(Vec<u32>, Vec<Real>)>,
    /// Per link, the largest tolerance of any cell, s.
    max_tolerance: Vec<Real>,
}

/// A proposed new target: its fix, the fix's covariance, the delay used per link (index into
/// that link's list) and how many links it used.
#[derive(Debug, Clone, PartialEq)]
pub struct BirthFix {
    /// Position, m.
    pub position: Vec2,
    /// `(JᵀR⁻¹J)⁻¹`, m².
    pub covariance: Mat2,
    /// Per link, the index of the delay used.
    pub used: Vec<Option<usize>>,
    /// `Σ_used ln 𝒩(z_p; τ_p(r̂), σ_p²) + ln(2π √det P)`: the Laplace approximation of
    /// `ln ∫ Π_used 𝒩(z_p; τ_p(r), σ_p²) dr` (1/s^k · m²).
    pub log_evidence: Real,
}

impl BirthFix {
    /// The existence of the new target: `Λ/(1 + Λ)` with
    /// `Λ = (rate/area) · P_D^k (1 − P_D)^(L−k) · e^{log_evidence} / λ_c^k` for `k` links used
    /// of `L` (the new-target hypothesis against "all clutter", in the log domain).
    pub fn existence(&self, rate: Real, region: &Area, pd: Real, clutter_intensity: Real) -> Real {
        let area = (region.x[1] - region.x[0]) * (region.y[1] - region.y[0]);
        let k = self.used.iter().flatten().count() as Real;
        let l = self.used.len() as Real;
        let log_lambda = ln(rate / area)
            + k * ln(pd / clutter_intensity)
            + (l - k) * ln(1.0 - pd)
            + self.log_evidence;
        // Λ/(1 + Λ) = 1/(1 + e^{−ln Λ}), stable for any sign.
        1.0 / (1.0 + exp(-log_lambda))
    }
}

impl BirthGrid {
    /// The grid of `model` for `settings` (validated).
    pub fn new(model: &Model, settings: DelayBirth, sigma_s: Option<&[Real]>) -> Result<Self> {
        let links = model.link_count();
        settings.validate(links)?;
        let Area { x, y } = settings.region;
        let step = settings.step_m;
        let nx = ((x[1] - x[0]) / step) as usize + 1;
        let ny = ((y[1] - y[0]) / step) as usize + 1;
        let half_diag = step * core::f64::consts::FRAC_1_SQRT_2;
        let mut cells = Vec::with_capacity(nx * ny);
        let mut delay = Vec::with_capacity(nx * ny * links);
        let mut tolerance = Vec::with_capacity(nx * ny * links);
        for iy in 0..ny {
            for ix in 0..nx {
                let r = Vec2::new(x[0] + ix as Real * step, y[0] + iy as Real * step);
                cells.push(r);
                for p in 0..links {
                    let sigma = sigma_s.map_or_else(|| model.sigma_delay(p, r), |s| s[p]);
                    let g = model.network.jacobian_row(p, r).norm();
                    delay.push(model.network.delay(p, r));
                    tolerance.push(half_diag * g + settings.gate_sigmas * sigma);
                }
            }
        }
        // Per link, the cells sorted by delay: a free delay's candidate cells are one range.
        let n = cells.len();
        let by_delay = (0..links)
            .map(|p| {
                let mut order: Vec<u32> = (0..n as u32).collect();
                order.sort_by(|&a, &b| {
                    delay[a as usize * links + p].total_cmp(&delay[b as usize * links + p])
                });
                let d = order
                    .iter()
                    .map(|&c| delay[c as usize * links + p])
                    .collect();
                (order, d)
            })
            .collect();
        let max_tolerance = (0..links)
            .map(|p| {
                (0..n)
                    .map(|c| tolerance[c * links + p])
                    .fold(0.0, Real::max)
            })
            .collect();
        Ok(BirthGrid {
            settings,
            cells,
            links,
            delay,
            tolerance,
            by_delay,
            max_tolerance,
        })
    }

    /// The settings.
    pub fn settings(&self) -> &DelayBirth {
        &self.settings
    }

    /// New targets from the free delays `free[p]` (s, with their σ if known) of each link:
    /// at most `max_per_scan` fixes, each with at least `min_links` gated delays, no delay used
    /// twice. `sigma_s` fixes σ per link (else E8 at the fix, or the delay's own σ).
    pub fn search(
        &self,
        model: &Model,
        free: &[Vec<(Real, Option<Real>)>],
        sigma_s: Option<&[Real]>,
    ) -> Vec<BirthFix> {
        let s = &self.settings;
        let mut used: Vec<Vec<bool>> = free.iter().map(|d| vec![false; d.len()]).collect();
        let mut sorted: Vec<Vec<(Real, usize)>> = free
            .iter()
            .map(|d| {
                let mut v: Vec<(Real, usize)> =
                    d.iter().enumerate().map(|(i, (t, _))| (*t, i)).collect();
                v.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
                v
            })
            .collect();
        let mut births = Vec::new();
        // Counted once per scan; a birth removes its delays and only their cells are recounted.
        let mut counts = vec![0u16; self.cells.len()];
        self.count_hits(&sorted, &mut counts);
        // The cells that reach `min_links`, in cell order (so ties go to the first cell, as a
        // scan over every cell would); counts only fall, so the list only shrinks.
        let mut candidates: Vec<u32> = (0..self.cells.len() as u32)
            .filter(|&c| counts[c as usize] as usize >= s.min_links)
            .collect();
        let mut tried = vec![false; candidates.len()];
        let mut refinements = 0;
        while births.len() < s.max_per_scan && refinements < s.max_candidates {
            let links_with_free = sorted.iter().filter(|v| !v.is_empty()).count();
            if links_with_free < s.min_links {
                break;
            }
            // The best untried cell: most links with a free delay in tolerance, then the
            // smallest sum of squared normalised misfits.
            let mut best: Option<(usize, usize, Real)> = None;
            for (i, &c) in candidates.iter().enumerate() {
                if tried[i] {
                    continue;
                }
                let (count, misfit) = self.score(&sorted, c as usize);
                if count >= s.min_links
                    && best.is_none_or(|(_, bc, bm)| count > bc || (count == bc && misfit < bm))
                {
                    best = Some((i, count, misfit));
                }
            }
            let Some((i, _, _)) = best else { break };
            let c = candidates[i] as usize;
            tried[i] = true;
            refinements += 1;
            let r0 = self.cells[c];
            // The nearest free delay per link at the cell, then LM on them.
            let pick: Vec<Option<(Real, usize)>> = (0..self.links)
                .map(|p| {
                    let k = c * self.links + p;
                    nearest_entry(&sorted[p], self.delay[k])
                        .filter(|(d, _)| (d - self.delay[k]).abs() <= self.tolerance[k])
                })
                .collect();
            if let Some(fix) = self.refine(model, free, &pick, r0, sigma_s) {
                for (p, u) in fix.used.iter().enumerate() {
                    if let Some(i) = *u {
                        used[p][i] = true;
                    }
                }
                for (p, v) in sorted.iter_mut().enumerate() {
                    // A birth uses at most one delay per link.
                    let removed = v.iter().find(|(_, i)| used[p][*i]).map(|e| e.0);
                    v.retain(|(_, i)| !used[p][*i]);
                    if let Some(d) = removed {
                        self.uncount(p, d, v, &mut counts);
                    }
                }
                births.push(fix);
                candidates.retain(|&c| counts[c as usize] as usize >= s.min_links);
                tried.clear();
                tried.resize(candidates.len(), false);
            }
        }
        births
    }

    /// Links with a free delay within cell `c`'s tolerance and the sum of their squared
    /// normalised misfits (the nearest delay per link).
    fn score(&self, sorted: &[Vec<(Real, usize)>], c: usize) -> (usize, Real) {
        let (mut count, mut misfit) = (0usize, 0.0);
        for (p, list) in sorted.iter().enumerate() {
            let k = c * self.links + p;
            if let Some(d) = nearest(list, self.delay[k]) {
                let e = (d - self.delay[k]) / self.tolerance[k];
                if e.abs() <= 1.0 {
                    count += 1;
                    misfit += e * e;
                }
            }
        }
        (count, misfit)
    }

    /// The cells within tolerance of free delay `d` on link `p`: one range of the link's delay
    /// order, checked cell by cell.
    fn cells_of(&self, p: usize, d: Real) -> impl Iterator<Item = usize> + '_ {
        let (order, delays) = &self.by_delay[p];
        let m = self.max_tolerance[p];
        let lo = delays.partition_point(|&x| x < d - m);
        let hi = delays.partition_point(|&x| x <= d + m);
        order[lo..hi].iter().map(|&c| c as usize).filter(move |&c| {
            let k = c * self.links + p;
            (d - self.delay[k]).abs() <= self.tolerance[k]
        })
    }

    /// `counts[c]` = the links with a free delay within cell `c`'s tolerance (a link's mark
    /// per cell, so two delays of one link count once).
    fn count_hits(&self, sorted: &[Vec<(Real, usize)>], counts: &mut [u16]) {
        let mut seen = vec![0u32; self.cells.len()];
        for (p, list) in sorted.iter().enumerate() {
            for &(d, _) in list {
                for c in self.cells_of(p, d) {
                    if seen[c] != p as u32 + 1 {
                        seen[c] = p as u32 + 1;
                        counts[c] = counts[c].saturating_add(1);
                    }
                }
            }
        }
    }

    /// Link `p`'s delay `d` was used by a birth (`left`: the link's free delays now, sorted):
    /// a cell it reached loses the link unless a delay left still reaches it.
    fn uncount(&self, p: usize, d: Real, left: &[(Real, usize)], counts: &mut [u16]) {
        for c in self.cells_of(p, d) {
            let k = c * self.links + p;
            let still = nearest(left, self.delay[k])
                .is_some_and(|e| (e - self.delay[k]).abs() <= self.tolerance[k]);
            if !still {
                counts[c] = counts[c].saturating_sub(1);
            }
        }
    }

    fn refine(
        &self,
        model: &Model,
        free: &[Vec<(Real, Option<Real>)>],
        pick: &[Option<(Real, usize)>],
        r0: Vec2,
        sigma_s: Option<&[Real]>,
    ) -> Option<BirthFix> {
        let s = &self.settings;
        let sigma_at = |p: usize, i: Option<usize>, r: Vec2| -> Real {
            i.and_then(|i| free[p][i].1)
                .unwrap_or_else(|| sigma_s.map_or_else(|| model.sigma_delay(p, r), |v| v[p]))
        };
        let delays: Vec<Option<Real>> = pick.iter().map(|e| e.map(|(d, _)| d)).collect();
        let sigmas: Vec<Real> = (0..self.links)
            .map(|p| sigma_at(p, pick[p].map(|e| e.1), r0))
            .collect();
        let cfg = LmConfig {
            max_iterations: 30,
            restart_tail_probability: None,
            ..LmConfig::default()
        };
        let m = DelayMeasurements {
            delays_s: &delays,
            sigmas_s: &sigmas,
        };
        let area = Area {
            x: [s.region.x[0] - 5.0, s.region.x[1] + 5.0],
            y: [s.region.y[0] - 5.0, s.region.y[1] + 5.0],
        };
        let fix = locate(&model.network, &m, &cfg, Some(r0), &area).ok()?;
        let r = fix.position;
        let inside = |v: Real, lim: [Real; 2]| v >= lim[0] - s.step_m && v <= lim[1] + s.step_m;
        if !(inside(r.x, s.region.x) && inside(r.y, s.region.y)) {
            return None;
        }
        // Keep the delays within the gate of the fix.
        let mut used = vec![None; self.links];
        let mut info = Mat2::zeros();
        let mut log_evidence = 0.0;
        for p in 0..self.links {
            if let Some((d, i)) = pick[p] {
                let sigma = sigma_at(p, Some(i), r);
                let e = (d - model.network.delay(p, r)) / sigma;
                if e.abs() <= s.gate_sigmas {
                    used[p] = Some(i);
                    log_evidence += -0.5 * e * e - ln(sqrt(2.0 * PI) * sigma);
                    let j = model.network.jacobian_row(p, r);
                    info += j * j.transpose() / (sigma * sigma);
                }
            }
        }
        if used.iter().flatten().count() < s.min_links {
            return None;
        }
        let covariance = info.try_inverse()?;
        if !(covariance[(0, 0)] > 0.0 && covariance[(1, 1)] > 0.0) {
            return None;
        }
        log_evidence += ln(2.0 * PI * sqrt(covariance.determinant()));
        Some(BirthFix {
            position: r,
            covariance,
            used,
            log_evidence,
        })
    }
}

/// The value in `v` (sorted by value) nearest `t`.
fn nearest(v: &[(Real, usize)], t: Real) -> Option<Real> {
    nearest_entry(v, t).map(|e| e.0)
}

fn nearest_entry(v: &[(Real, usize)], t: Real) -> Option<(Real, usize)> {
    if v.is_empty() {
        return None;
    }
    let i = v.partition_point(|e| e.0 < t);
    let cand = [i.checked_sub(1), (i < v.len()).then_some(i)];
    cand.into_iter()
        .flatten()
        .min_by(|&a, &b| (v[a].0 - t).abs().total_cmp(&(v[b].0 - t).abs()))
        .map(|k| v[k])
}

#[cfg(test)]
#[path = "birth_tests.rs"]
mod tests;
