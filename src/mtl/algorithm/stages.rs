//! The stages of Algorithm 1 (§4 steps 1–4): seeds from ellipse intersections, the extension of
//! every live candidate by the next TRP of `π` with the ellipse test (M6), the consistency
//! branching (cases 1 / 2a / 2b), late seeds, and the per-stage dedup and caps.

use alloc::vec::Vec;

use crate::error::{Error, Result};
use crate::math::Vec2;
use crate::mtl::algorithm::cache::IntersectionCache;
use crate::mtl::algorithm::candidate::{Candidate, Geometry, Pair};
use crate::mtl::algorithm::{select, Measurements, MtlConfig, Status, TraceEntry};
use crate::mtl::blocking::{BlockingModel, BlockingSpace, PartialVector};

/// The state of one run of Algorithm 1.
pub struct Run<'a, 'c, B: ?Sized> {
    geo: Geometry<'a>,
    cache: &'c mut IntersectionCache,
    model: &'a B,
    cfg: &'a MtlConfig,
    order: Vec<usize>,
    space: Option<BlockingSpace>,
    next_family: usize,
    trace: Vec<Vec<TraceEntry>>,
    /// Per stage (2, 3, …), how many candidates ended with each [`Status`] (by
    /// [`Status::index`]); kept whether or not the trace is.
    counts: Vec<[usize; 6]>,
    /// Candidates evaluated so far (every [`Run::record`]), against [`MtlConfig::max_candidates`].
    evaluated: usize,
}

impl<'a, 'c, B: BlockingModel + ?Sized> Run<'a, 'c, B> {
    /// A run on validated input (see [`crate::mtl::algorithm::validate`]) with TRP order `order`,
    /// seeds taken from `cache`.
    pub fn new(
        input: &Measurements<'a>,
        model: &'a B,
        cfg: &'a MtlConfig,
        order: Vec<usize>,
        cache: &'c mut IntersectionCache,
    ) -> Self {
        let map = *model.trp_map();
        let geo = Geometry { map, input: *input };
        cache.prepare(&geo, cfg.region.as_ref());
        Self {
            geo,
            cache,
            model,
            cfg,
            order,
            space: cfg.consistency.then(|| BlockingSpace::new(map)),
            next_family: 0,
            trace: Vec::new(),
            counts: Vec::new(),
            evaluated: 0,
        }
    }

    /// The geometry of this run.
    pub fn geometry(&self) -> &Geometry<'a> {
        &self.geo
    }

    /// The recorded trace (empty unless [`MtlConfig::trace`]).
    pub fn into_trace(self) -> Vec<Vec<TraceEntry>> {
        self.trace
    }

    /// Per stage (stage 2 first), the number of candidates that ended with each [`Status`]
    /// (indexed by [`Status::index`]): the trace's tallies, also without the trace.
    pub fn stage_counts(&self) -> &[[usize; 6]] {
        &self.counts
    }

    /// All stages; returns the live candidates after the last one (all on `S` = every TRP).
    ///
    /// [`Error::WorkLimit`] (`ranges`) once more than [`MtlConfig::max_candidates`] candidates
    /// have been evaluated.
    pub fn run(&mut self) -> Result<Vec<Candidate>> {
        let m_total = self.order.len();
        if m_total < 2 {
            return Ok(Vec::new());
        }
        // Stage 2: seeds of π₁, π₂, kept iff L_b ≤ T_b.
        self.new_stage();
        let mut live = Vec::new();
        for seed in self.seeds(self.order[0], self.order[1]) {
            self.test(seed, &mut live)?;
        }
        live = self.prune(live);
        for s in 2..m_total {
            self.new_stage();
            let m = self.order[s];
            let mut next = Vec::new();
            for c in &live {
                self.extend(c, m, &mut next)?;
            }
            if self.cfg.late_seeds {
                self.late_seeds(s, &mut next)?;
            }
            live = self.prune(next);
        }
        Ok(live)
    }

    /// Seeds from every MPC pair of TRPs `a`, `b`: every ellipse intersection point (§5.2) with
    /// `ĝ = (1, 1)` on `{a, b}`, each a new family. Not yet scored.
    fn seeds(&mut self, a: usize, b: usize) -> Vec<Candidate> {
        let mut out = Vec::new();
        let g = PartialVector::empty().with(a, true).with(b, true);
        for i in 0..self.geo.input.ranges[a].len() {
            for k in 0..self.geo.input.ranges[b].len() {
                let (p, q) = (Pair { trp: a, mpc: i }, Pair { trp: b, mpc: k });
                for &x in self.cache.points(&self.geo, p, q) {
                    out.push(Candidate {
                        matching: if p < q {
                            alloc::vec![p, q]
                        } else {
                            alloc::vec![q, p]
                        },
                        x,
                        g,
                        family: self.next_family,
                        l_b: 0.0,
                        j: 0.0,
                    });
                    self.next_family += 1;
                }
            }
        }
        out
    }

    /// Step 3: late seeds of TRP `π_s` with every earlier `π_{s'}`, each run through the other
    /// processed TRPs in `π` order (\[C\]) when [`MtlConfig::late_seed_catch_up`] is set.
    fn late_seeds(&mut self, s: usize, out: &mut Vec<Candidate>) -> Result<()> {
        let m = self.order[s];
        for s2 in 0..s {
            let earlier = self.order[s2];
            for seed in self.seeds(m, earlier) {
                if !self.cfg.late_seed_catch_up {
                    self.test(seed, out)?;
                    continue;
                }
                let mut group = alloc::vec![seed];
                for s3 in (0..s).filter(|&t| t != s2) {
                    let t = self.order[s3];
                    let mut grown = Vec::new();
                    for c in &group {
                        self.extend(c, t, &mut grown)?;
                    }
                    group = grown;
                }
                out.extend(group);
            }
        }
        Ok(())
    }

    /// Step 2 for one candidate and TRP `m`: the MPCs passing the ellipse test each give a child
    /// (pair added, `ĝ_m = 1`, `x̂` refined); none passing gives the child with `ĝ_m = 0`.
    fn extend(&mut self, c: &Candidate, m: usize, out: &mut Vec<Candidate>) -> Result<()> {
        self.check_budget()?;
        let mut any = false;
        let inv = self.geo.information_inverse(&c.matching, &c.x);
        for (i, &r) in self.geo.input.ranges[m].iter().enumerate() {
            let pass = inv.is_some_and(|inv| {
                self.geo.normalized_error_with(&inv, &c.x, m, r) <= self.cfg.t_e
            });
            if !pass {
                continue;
            }
            any = true;
            let mut child = Candidate {
                matching: c.with_pair(Pair { trp: m, mpc: i }),
                g: c.g.with(m, true),
                ..c.without_matching()
            };
            match self.geo.refine(&child.matching, c.x, &self.cfg.refinement) {
                Some(x) => {
                    child.x = x;
                    self.settle(child, out)?;
                }
                None => self.record(&child, Status::Unlocatable),
            }
        }
        if !any {
            let child = Candidate {
                g: c.g.with(m, false),
                ..c.clone()
            };
            self.settle(child, out)?;
        }
        Ok(())
    }

    /// The consistency branching of step 2: case 1 (consistent: blocking test), case 2a
    /// (inconsistent, `𝒩 = ∅`: drop) and case 2b (a child per lighter neighbour with that pair
    /// removed; the candidate itself if a heavier neighbour exists, `L_b` from the model).
    fn settle(&mut self, c: Candidate, out: &mut Vec<Candidate>) -> Result<()> {
        let Some(space) = &self.space else {
            return self.test(c, out);
        };
        if space.is_consistent(&c.g) {
            return self.test(c, out);
        }
        let neighbours = space.neighbours(&c.g);
        if neighbours.is_empty() {
            self.record(&c, Status::Inconsistent);
            return Ok(());
        }
        let mut heavier = false;
        for nb in neighbours {
            if nb.ones() & c.g.ones() == c.g.ones() {
                heavier = true;
                continue;
            }
            let trp = (nb.ones() ^ c.g.ones()).trailing_zeros() as usize;
            let mut child = Candidate {
                matching: c.without(trp),
                g: nb,
                ..c.without_matching()
            };
            match self.relocate(&child.matching, c.x) {
                Some(x) => {
                    child.x = x;
                    self.test(child, out)?;
                }
                None => self.record(&child, Status::Unlocatable),
            }
        }
        if heavier {
            self.test(c, out)?;
        }
        Ok(())
    }

    /// The location of a case-2b child (a pair removed) from `x`: `None` below two pairs; for
    /// exactly two pairs the ellipse intersection (§5.2, as the seeds: the ML locations of a
    /// size-2 matching) nearest to `x`, `None` when the two ellipses do not meet (their
    /// least-squares point is then where the range gradients are parallel: no location);
    /// otherwise Gauss–Newton from `x` (§4, \[P\]).
    fn relocate(&mut self, matching: &[Pair], x: Vec2) -> Option<Vec2> {
        match *matching {
            [] | [_] => None,
            [p, q] => self
                .cache
                .points(&self.geo, p, q)
                .iter()
                .copied()
                .min_by(|a, b| (a - x).norm_squared().total_cmp(&(b - x).norm_squared())),
            _ => self.geo.refine(matching, x, &self.cfg.refinement),
        }
    }

    /// Score `c` (`L_b` from the model, `J` (M2)) and keep it iff it passes the stage blocking
    /// test.
    fn test(&mut self, mut c: Candidate, out: &mut Vec<Candidate>) -> Result<()> {
        self.check_budget()?;
        c.l_b = self.model.blocking_likelihood(&c.x, &c.g)?;
        c.j = self.geo.range_term(&c.matching, &c.x) + c.l_b;
        if !self.cfg.stage_blocking_test || c.l_b <= self.cfg.t_b {
            self.record(&c, Status::Kept);
            out.push(c);
        } else {
            self.record(&c, Status::Blocking);
        }
        Ok(())
    }

    /// Step 4: dedup and per-family caps, recorded in the trace.
    fn prune(&mut self, cands: Vec<Candidate>) -> Vec<Candidate> {
        let (kept, dropped) = select::prune(cands, self.cfg.b_max);
        for (c, status) in &dropped {
            self.record(c, *status);
        }
        kept
    }

    fn new_stage(&mut self) {
        self.counts.push([0; 6]);
        if self.cfg.trace {
            self.trace.push(Vec::new());
        }
    }

    /// [`Error::WorkLimit`] once the run has evaluated more than its budget.
    fn check_budget(&self) -> Result<()> {
        if self.evaluated > self.cfg.max_candidates {
            return Err(Error::WorkLimit {
                field: "ranges".into(),
                limit: self.cfg.max_candidates,
            });
        }
        Ok(())
    }

    fn record(&mut self, c: &Candidate, status: Status) {
        self.evaluated += 1;
        if let Some(stage) = self.counts.last_mut() {
            stage[status.index()] += 1;
        }
        if self.cfg.trace {
            if let Some(stage) = self.trace.last_mut() {
                stage.push(TraceEntry {
                    candidate: c.clone(),
                    status,
                });
            }
        }
    }
}
