//! The birth search against a reference written here: every cell scored from scratch at every
//! refinement (the search as first written, before counts were kept across refinements).

use super::*;
use crate::measure::rng;
use crate::track::multi::{delay_scans, people_layout, people_region, people_truth};

impl BirthGrid {
    /// The reference: each refinement scores every untried cell over every link.
    fn search_reference(
        &self,
        model: &Model,
        free: &[Vec<(Real, Option<Real>)>],
        sigma_s: Option<&[Real]>,
    ) -> (Vec<BirthFix>, usize) {
        let s = &self.settings;
        let mut used: Vec<Vec<bool>> = free.iter().map(|d| vec![false; d.len()]).collect();
        let mut births = Vec::new();
        let mut tried = vec![false; self.cells.len()];
        let mut refinements = 0;
        while births.len() < s.max_per_scan && refinements < s.max_candidates {
            let left: Vec<Vec<(Real, usize)>> = free
                .iter()
                .enumerate()
                .map(|(p, d)| {
                    let mut v: Vec<(Real, usize)> = d
                        .iter()
                        .enumerate()
                        .filter(|(i, _)| !used[p][*i])
                        .map(|(i, (t, _))| (*t, i))
                        .collect();
                    v.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
                    v
                })
                .collect();
            if left.iter().filter(|v| !v.is_empty()).count() < s.min_links {
                break;
            }
            let mut best: Option<(usize, usize, Real)> = None;
            for (c, _) in tried.iter().enumerate().filter(|(_, t)| !**t) {
                let (mut count, mut misfit) = (0usize, 0.0);
                for (p, list) in left.iter().enumerate() {
                    let k = c * self.links + p;
                    // The nearest delay by a linear scan.
                    let near = list.iter().map(|e| e.0).min_by(|a, b| {
                        (a - self.delay[k])
                            .abs()
                            .total_cmp(&(b - self.delay[k]).abs())
                    });
                    if let Some(d) = near {
                        let e = (d - self.delay[k]) / self.tolerance[k];
                        if e.abs() <= 1.0 {
                            count += 1;
                            misfit += e * e;
                        }
                    }
                }
                if count >= s.min_links
                    && best.is_none_or(|(_, bc, bm)| count > bc || (count == bc && misfit < bm))
                {
                    best = Some((c, count, misfit));
                }
            }
            let Some((c, _, _)) = best else { break };
            tried[c] = true;
            refinements += 1;
            let pick: Vec<Option<(Real, usize)>> = (0..self.links)
                .map(|p| {
                    let k = c * self.links + p;
                    nearest_entry(&left[p], self.delay[k])
                        .filter(|(d, _)| (d - self.delay[k]).abs() <= self.tolerance[k])
                })
                .collect();
            if let Some(fix) = self.refine(model, free, &pick, self.cells[c], sigma_s) {
                for (p, u) in fix.used.iter().enumerate() {
                    if let Some(i) = *u {
                        used[p][i] = true;
                    }
                }
                births.push(fix);
                tried.iter_mut().for_each(|t| *t = false);
            }
        }
        (births, refinements)
    }
}

/// Per link, free delays with their σ if known.
type Free = Vec<Vec<(Real, Option<Real>)>>;

/// The free delays of every scan of a seeded walk of `walkers` people, with clutter.
fn scans(model: &Model, walkers: usize, clutter: Real, seed: u64) -> Vec<Free> {
    let mut r = rng(seed, 0);
    let truth = people_truth(walkers, 30, 0.1, &mut r);
    delay_scans(model, &truth, 0.9, clutter, 60e-9, &mut r)
        .into_iter()
        .map(|scan| {
            scan.into_iter()
                .map(|l| l.into_iter().map(|d| (d.value[0], None)).collect())
                .collect()
        })
        .collect()
}

#[test]
fn search_equals_the_reference_bit_for_bit() {
    let model = Model::new(&people_layout()).unwrap();
    let whole = people_layout().area_m;
    let mut births = 0;
    let mut at_cap = 0;
    for (region, step) in [(people_region(), 0.25), (whole, 0.5)] {
        let settings = DelayBirth {
            step_m: step,
            ..DelayBirth::new(region, 8)
        };
        let grid = BirthGrid::new(&model, settings, None).unwrap();
        for seed in 1..=3 {
            for (walkers, clutter) in [(3, 5.0), (5, 5.0), (5, 40.0)] {
                for (k, free) in scans(&model, walkers, clutter, seed)
                    .iter()
                    .enumerate()
                    .step_by(7)
                {
                    let got = grid.search(&model, free, None);
                    let (want, refinements) = grid.search_reference(&model, free, None);
                    assert_eq!(got, want, "seed {seed}, {walkers} walkers, scan {k}");
                    births += got.len();
                    at_cap += usize::from(refinements == settings.max_candidates);
                }
            }
        }
    }
    // Both bounds of the loop are reached: births found, and the refinement cap hit.
    assert!(births > 50, "{births} births");
    assert!(at_cap > 0, "the refinement cap was never reached");
}
