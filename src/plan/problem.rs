//! The planning problem (`filters-and-planning.md` §3): which nodes move, the constraints a layout
//! must keep, and the encoding of a layout as CMA-ES variables. Positions are scaled to `[0, 1]`
//! over the placement bounds (a sample outside is projected onto them, and the distance it
//! stuck out ranks it after its projection); a boresight is in turns (`1` = 360°, wrapped).

use alloc::format;
use alloc::string::{String, ToString};
use alloc::vec::Vec;
use core::cmp::Ordering;

use crate::error::{limits, Error, Result};
use crate::math::{sqrt, Real, Vec2, PI};
use crate::measure::Model;
use crate::scenario::{Area, Pattern, Scenario};

use super::objective::{RoiObjective, Score};

/// Which nodes the planner moves.
#[derive(Debug, Clone, PartialEq)]
pub enum MoveSpec {
    /// Every receiver (`rx`).
    Receivers,
    /// Every transmitter (`tx`).
    Transmitters,
    /// Every node (`all`).
    All,
    /// Every transmitter, and the boresight of each parabolic one (`tx-boresight`).
    TransmittersWithBoresight,
    /// The nodes of these names (positions only).
    Names(Vec<String>),
}

impl MoveSpec {
    /// `rx`, `tx`, `all`, `tx-boresight`, or a comma-separated list of node names.
    pub fn parse(text: &str) -> MoveSpec {
        match text.trim() {
            "rx" => MoveSpec::Receivers,
            "tx" => MoveSpec::Transmitters,
            "all" => MoveSpec::All,
            "tx-boresight" => MoveSpec::TransmittersWithBoresight,
            t => MoveSpec::Names(
                t.split(',')
                    .map(|s| s.trim().to_string())
                    .filter(|s| !s.is_empty())
                    .collect(),
            ),
        }
    }
}

/// A simple polygon, vertices in order (either orientation), m.
pub type Polygon = Vec<[Real; 2]>;

/// Most allowed polygons, and most vertices per polygon.
pub const MAX_POLYGONS: usize = 100;
/// Most vertices of an allowed polygon.
pub const MAX_POLYGON_VERTICES: usize = 1000;
/// Most variables of a plan (2 per moved node, 1 per turned beam).
pub const MAX_PLAN_DIMENSION: usize = 64;

/// Where moved nodes may go.
#[derive(Debug, Clone, PartialEq)]
pub struct Constraints {
    /// The placement rectangle of every moved node.
    pub bounds: Area,
    /// If not empty, every moved node must also lie in one of these (e.g. rooms).
    pub allowed: Vec<Polygon>,
    /// Smallest distance between any two nodes (moved or fixed), m.
    pub min_spacing_m: Real,
}

impl Constraints {
    /// Checks the rectangle, the polygons and the spacing (errors name `bounds`, `allowed[i]`,
    /// `min_spacing`).
    pub fn validate(&self) -> Result<()> {
        self.bounds.validate_as(["bounds.x", "bounds.y"])?;
        if self.allowed.len() > MAX_POLYGONS {
            return Err(Error::SizeLimit {
                field: "allowed",
                value: self.allowed.len(),
                min: 0,
                max: MAX_POLYGONS,
            });
        }
        for (i, poly) in self.allowed.iter().enumerate() {
            if !(3..=MAX_POLYGON_VERTICES).contains(&poly.len()) {
                return Err(Error::Infeasible {
                    field: format!("allowed[{i}]"),
                    reason: format!(
                        "{} vertices; a polygon has 3 to {MAX_POLYGON_VERTICES}",
                        poly.len()
                    ),
                });
            }
            for (j, v) in poly.iter().enumerate() {
                for c in v {
                    limits::COORDINATE_M.check(&format!("allowed[{i}][{j}]"), *c)?;
                }
            }
            if polygon_area(poly) == 0.0 {
                return Err(Error::Infeasible {
                    field: format!("allowed[{i}]"),
                    reason: "the polygon has no area".into(),
                });
            }
        }
        limits::COORDINATE_M.check("min_spacing", self.min_spacing_m)?;
        if self.min_spacing_m < 0.0 {
            return Err(Error::OutOfRange {
                field: "min_spacing".into(),
                value: self.min_spacing_m,
                allowed: "0 to 1e7 m",
            });
        }
        Ok(())
    }
}

/// A node of a scenario.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NodeRef {
    /// Transmitter `i`.
    Tx(usize),
    /// Receiver `i`.
    Rx(usize),
}

/// A layout in plain units: the moved nodes' positions (m) and the turned beams' boresights (°).
#[derive(Debug, Clone, PartialEq)]
pub struct Layout {
    /// Positions of the moved nodes, in [`PlanSpace::moved`] order, m.
    pub positions: Vec<Vec2>,
    /// Boresights of the turned transmitters, in [`PlanSpace::turned`] order, degrees in `[0, 360)`.
    pub boresights_deg: Vec<Real>,
}

/// The moved nodes, the turned beams and the constraints of a plan over a base scenario.
#[derive(Debug, Clone)]
pub struct PlanSpace {
    base: Scenario,
    moved: Vec<NodeRef>,
    turned: Vec<usize>,
    constraints: Constraints,
    /// Positions of the nodes that stay.
    fixed: Vec<(NodeRef, Vec2)>,
}

impl PlanSpace {
    /// Resolves `spec` on `base` and checks the constraints, failing with a named error when no
    /// node moves, a name is unknown, there are too many variables, two fixed nodes are closer
    /// than the spacing, or the moved nodes cannot be that far apart inside the bounds.
    pub fn new(base: &Scenario, spec: &MoveSpec, constraints: Constraints) -> Result<PlanSpace> {
        base.validate()?;
        constraints.validate()?;
        let txs = (0..base.transmitters.len()).map(NodeRef::Tx);
        let rxs = (0..base.receivers.len()).map(NodeRef::Rx);
        let mut turned = Vec::new();
        let moved: Vec<NodeRef> = match spec {
            MoveSpec::Receivers => rxs.collect(),
            MoveSpec::Transmitters => txs.collect(),
            MoveSpec::All => txs.chain(rxs).collect(),
            MoveSpec::TransmittersWithBoresight => {
                turned = (0..base.transmitters.len())
                    .filter(|&i| matches!(base.transmitters[i].pattern, Pattern::Parabolic { .. }))
                    .collect();
                txs.collect()
            }
            MoveSpec::Names(names) => {
                let mut v = Vec::new();
                for name in names {
                    crate::error::limits::check_name("move", name)?;
                    let node = base
                        .transmitters
                        .iter()
                        .position(|t| &t.name == name)
                        .map(NodeRef::Tx)
                        .or_else(|| {
                            base.receivers
                                .iter()
                                .position(|r| &r.name == name)
                                .map(NodeRef::Rx)
                        })
                        .ok_or_else(|| Error::UnknownNode {
                            field: "move".into(),
                            name: name.clone(),
                        })?;
                    if !v.contains(&node) {
                        v.push(node);
                    }
                }
                v
            }
        };
        if moved.is_empty() {
            return Err(Error::Infeasible {
                field: "move".into(),
                reason: "no node to move".into(),
            });
        }
        let dimension = 2 * moved.len() + turned.len();
        if dimension > MAX_PLAN_DIMENSION {
            return Err(Error::SizeLimit {
                field: "move (variables: 2 per node, 1 per beam)",
                value: dimension,
                min: 1,
                max: MAX_PLAN_DIMENSION,
            });
        }
        let all = (0..base.transmitters.len())
            .map(NodeRef::Tx)
            .chain((0..base.receivers.len()).map(NodeRef::Rx));
        let fixed: Vec<(NodeRef, Vec2)> = all
            .filter(|n| !moved.contains(n))
            .map(|n| (n, position(base, n)))
            .collect();
        let s = constraints.min_spacing_m;
        let name = |n: NodeRef| match n {
            NodeRef::Tx(i) => base.transmitters[i].name.clone(),
            NodeRef::Rx(i) => base.receivers[i].name.clone(),
        };
        for (i, (a, pa)) in fixed.iter().enumerate() {
            for (b, pb) in &fixed[i + 1..] {
                let d = (pa - pb).norm();
                if d < s {
                    return Err(Error::Infeasible {
                        field: "min_spacing".into(),
                        reason: format!(
                            "the fixed nodes {} and {} are {d} m apart, less than {s} m",
                            name(*a),
                            name(*b)
                        ),
                    });
                }
            }
        }
        // Disjoint discs of radius s/2 around the moved nodes fit in the bounds grown by s/2.
        let b = constraints.bounds;
        let room = (b.x[1] - b.x[0] + s) * (b.y[1] - b.y[0] + s);
        let need = moved.len() as Real * PI * s * s / 4.0;
        if moved.len() > 1 && need > room {
            return Err(Error::Infeasible {
                field: "min_spacing".into(),
                reason: format!(
                    "{} moved nodes cannot be {s} m apart inside the bounds",
                    moved.len()
                ),
            });
        }
        Ok(PlanSpace {
            base: base.clone(),
            moved,
            turned,
            constraints,
            fixed,
        })
    }

    /// The moved nodes.
    pub fn moved(&self) -> &[NodeRef] {
        &self.moved
    }

    /// The transmitters whose boresight turns.
    pub fn turned(&self) -> &[usize] {
        &self.turned
    }

    /// The constraints.
    pub fn constraints(&self) -> &Constraints {
        &self.constraints
    }

    /// The base scenario.
    pub fn base(&self) -> &Scenario {
        &self.base
    }

    /// Name of a node of the base scenario.
    pub fn name(&self, n: NodeRef) -> &str {
        match n {
            NodeRef::Tx(i) => &self.base.transmitters[i].name,
            NodeRef::Rx(i) => &self.base.receivers[i].name,
        }
    }

    /// Number of CMA-ES variables.
    pub fn dimension(&self) -> usize {
        2 * self.moved.len() + self.turned.len()
    }

    /// The base scenario's layout.
    pub fn base_layout(&self) -> Layout {
        Layout {
            positions: self
                .moved
                .iter()
                .map(|&n| position(&self.base, n))
                .collect(),
            boresights_deg: self
                .turned
                .iter()
                .map(|&i| match self.base.transmitters[i].pattern {
                    Pattern::Parabolic { boresight_deg, .. } => wrap_degrees(boresight_deg),
                    Pattern::Omni => 0.0,
                })
                .collect(),
        }
    }

    /// The variables of a layout (positions clamped into the bounds).
    pub fn encode(&self, layout: &Layout) -> Vec<Real> {
        let b = self.constraints.bounds;
        let mut x = Vec::with_capacity(self.dimension());
        for p in &layout.positions {
            x.push(((p.x - b.x[0]) / (b.x[1] - b.x[0])).clamp(0.0, 1.0));
            x.push(((p.y - b.y[0]) / (b.y[1] - b.y[0])).clamp(0.0, 1.0));
        }
        x.extend(layout.boresights_deg.iter().map(|d| d / 360.0));
        x
    }

    /// The layout of variables `x` and how far `x` lies outside the unit box (squared).
    pub fn decode(&self, x: &[Real]) -> (Layout, Real) {
        let b = self.constraints.bounds;
        let mut excess = 0.0;
        let mut unit = |v: Real| {
            let c = v.clamp(0.0, 1.0);
            excess += (v - c) * (v - c);
            c
        };
        let positions = x[..2 * self.moved.len()]
            .chunks_exact(2)
            .map(|u| {
                Vec2::new(
                    b.x[0] + unit(u[0]) * (b.x[1] - b.x[0]),
                    b.y[0] + unit(u[1]) * (b.y[1] - b.y[0]),
                )
            })
            .collect();
        let boresights_deg = x[2 * self.moved.len()..]
            .iter()
            .map(|t| wrap_degrees(t * 360.0))
            .collect();
        (
            Layout {
                positions,
                boresights_deg,
            },
            excess,
        )
    }

    /// How far a layout is from keeping the constraints, m (0 = feasible): the distance of every
    /// moved node outside the bounds (decoded layouts are inside by construction) and outside the
    /// allowed polygons, plus every spacing shortfall of a pair with a moved node.
    pub fn violation(&self, layout: &Layout) -> Real {
        let s = self.constraints.min_spacing_m;
        let b = self.constraints.bounds;
        let mut v = 0.0;
        for (i, p) in layout.positions.iter().enumerate() {
            // Outside the bounds (only a base layout can be).
            let dx = (b.x[0] - p.x).max(p.x - b.x[1]).max(0.0);
            let dy = (b.y[0] - p.y).max(p.y - b.y[1]).max(0.0);
            v += sqrt(dx * dx + dy * dy);
            if !self.constraints.allowed.is_empty() {
                v += self
                    .constraints
                    .allowed
                    .iter()
                    .map(|poly| distance_outside(poly, *p))
                    .fold(Real::INFINITY, Real::min);
            }
            if s > 0.0 {
                for q in layout.positions[i + 1..]
                    .iter()
                    .chain(self.fixed.iter().map(|(_, q)| q))
                {
                    v += (s - (p - q).norm()).max(0.0);
                }
            }
        }
        v
    }

    /// Writes a layout into a model compiled from the base scenario (positions; beams turned).
    pub fn apply_to_model(&self, layout: &Layout, model: &mut Model) {
        for (&n, p) in self.moved.iter().zip(&layout.positions) {
            match n {
                NodeRef::Tx(i) => model.network.transmitters[i] = *p,
                NodeRef::Rx(i) => model.network.receivers[i] = *p,
            }
        }
        for (&i, &deg) in self.turned.iter().zip(&layout.boresights_deg) {
            model.patterns[i].set_boresight_deg(deg);
        }
    }

    /// The base scenario with a layout applied.
    pub fn apply_to_scenario(&self, layout: &Layout) -> Scenario {
        let mut s = self.base.clone();
        for (&n, p) in self.moved.iter().zip(&layout.positions) {
            match n {
                NodeRef::Tx(i) => s.transmitters[i].position_m = [p.x, p.y],
                NodeRef::Rx(i) => s.receivers[i].position_m = [p.x, p.y],
            }
        }
        for (&i, &deg) in self.turned.iter().zip(&layout.boresights_deg) {
            if let Pattern::Parabolic { boresight_deg, .. } = &mut s.transmitters[i].pattern {
                *boresight_deg = deg;
            }
        }
        s
    }
}

/// An angle in degrees wrapped into `[0, 360)`.
fn wrap_degrees(d: Real) -> Real {
    let w = d - 360.0 * libm::floor(d / 360.0);
    if w >= 360.0 {
        0.0
    } else {
        w
    }
}

fn position(s: &Scenario, n: NodeRef) -> Vec2 {
    let p = match n {
        NodeRef::Tx(i) => s.transmitters[i].position_m,
        NodeRef::Rx(i) => s.receivers[i].position_m,
    };
    Vec2::new(p[0], p[1])
}

/// Twice the signed area (shoelace), m².
fn polygon_area(poly: &[[Real; 2]]) -> Real {
    let n = poly.len();
    (0..n)
        .map(|i| {
            let (a, b) = (poly[i], poly[(i + 1) % n]);
            a[0] * b[1] - b[0] * a[1]
        })
        .sum()
}

/// 0 inside (or on) the polygon, else the distance to its boundary, m.
pub(super) fn distance_outside(poly: &[[Real; 2]], p: Vec2) -> Real {
    let n = poly.len();
    let mut inside = false;
    let mut dmin = Real::INFINITY;
    for i in 0..n {
        let (a, b) = (poly[i], poly[(i + 1) % n]);
        // Crossing number (ray to +x).
        if (a[1] > p.y) != (b[1] > p.y) {
            let x = a[0] + (p.y - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
            if p.x < x {
                inside = !inside;
            }
        }
        let (ab, ap) = (
            Vec2::new(b[0] - a[0], b[1] - a[1]),
            Vec2::new(p.x - a[0], p.y - a[1]),
        );
        let len2 = ab.norm_squared();
        let t = if len2 > 0.0 {
            (ap.dot(&ab) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        dmin = dmin.min(sqrt((ap - t * ab).norm_squared()));
    }
    if inside {
        0.0
    } else {
        dmin
    }
}

/// The score of a candidate: constraint violation first, then the objective, then how far the
/// sample stuck out of the bounds (so a projection ranks before the samples projected onto it).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlanScore {
    /// [`PlanSpace::violation`], m.
    pub violation: Real,
    /// The objective over the ROI.
    pub score: Score,
    /// Squared distance of the sample outside the unit box.
    pub excess: Real,
}

impl PlanScore {
    /// `Less` = better.
    pub fn rank(&self, other: &PlanScore) -> Ordering {
        self.violation
            .total_cmp(&other.violation)
            .then(self.score.rank(&other.score))
            .then(self.excess.total_cmp(&other.excess))
    }

    /// Whether the layout keeps every constraint.
    pub fn feasible(&self) -> bool {
        self.violation == 0.0
    }
}

/// Evaluates CMA-ES variables: decode, write into the working model, score over the ROI.
pub(super) struct PlanSearch<'a> {
    pub space: &'a PlanSpace,
    pub model: Model,
    pub roi: RoiObjective,
}

impl PlanSearch<'_> {
    /// The score of a layout.
    pub fn score_layout(&mut self, layout: &Layout, excess: Real) -> PlanScore {
        self.space.apply_to_model(layout, &mut self.model);
        PlanScore {
            violation: self.space.violation(layout),
            score: self.roi.evaluate(&self.model),
            excess,
        }
    }
}

impl super::cmaes::SearchProblem for PlanSearch<'_> {
    type Score = PlanScore;

    fn dimension(&self) -> usize {
        self.space.dimension()
    }

    fn evaluate(&mut self, x: &[Real]) -> PlanScore {
        let (layout, excess) = self.space.decode(x);
        self.score_layout(&layout, excess)
    }

    fn rank(&self, a: &PlanScore, b: &PlanScore) -> Ordering {
        a.rank(b)
    }

    fn restart_point(&self, rng: &mut crate::measure::Rng, x: &mut [Real]) {
        use rand::Rng as _;
        for v in x.iter_mut() {
            *v = rng.random::<Real>();
        }
    }
}
