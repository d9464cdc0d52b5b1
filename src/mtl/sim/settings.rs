//! Simulation settings of spec `multi-target.md` §7 (the settings table): every **\[P\]** value is a
//! field, [`SimSettings::va`] and [`SimSettings::vb`] give the table's defaults for the V-A and V-B
//! experiments, and [`SimSettings::validate`] rejects bad values with named errors.

use alloc::vec::Vec;

use crate::error::{check_positive, Error, Result};
use crate::math::{cos, sin, sqrt, Real, Vec2, PI};
use crate::mtl::blocking::check_probability;
use crate::mtl::polygon::Rect;
use crate::mtl::ppp::PppBlocking;
use crate::mtl::trp::TrpMap;

/// Largest number of targets per realisation accepted by [`SimSettings::validate`].
pub const MAX_TARGETS: usize = 1000;

/// Largest mean number of disc centres `λ·area(R)` or clutter peaks per TRP accepted by
/// [`SimSettings::validate`] (keeps one realisation bounded).
pub const MAX_POISSON_MEAN: Real = 10_000.0;

/// The i.c.b `p_u` of the V-B experiment, derived from Table II (§7 table, spec check 4).
pub const VB_ICB_P_U: Real = 0.5329;

/// Where the nodes of a realisation are (§7 generator step 2).
#[derive(Debug, Clone, PartialEq)]
pub enum NodeLayout {
    /// `n_tx` TXs then `n_rx` RXs drawn uniformly in `R \ S` by rejection (V-B).
    Uniform {
        /// Number of transmitters `N_t`.
        n_tx: usize,
        /// Number of receivers `N_r`.
        n_rx: usize,
    },
    /// Fixed positions (V-A: [`NodeLayout::hexagon`]).
    Fixed {
        /// TX positions, m.
        tx: Vec<Vec2>,
        /// RX positions, m.
        rx: Vec<Vec2>,
    },
}

impl NodeLayout {
    /// The V-A network (§7, **\[P\]**): a hexagon on the circle of radius `radius` m about
    /// `centre`, TXs at 90°, 210°, 330° and RXs at 30°, 150°, 270°.
    pub fn hexagon(centre: Vec2, radius: Real) -> NodeLayout {
        let at = |deg: Real| {
            let a = deg * PI / 180.0;
            centre + Vec2::new(radius * cos(a), radius * sin(a))
        };
        NodeLayout::Fixed {
            tx: [90.0, 210.0, 330.0].map(at).to_vec(),
            rx: [30.0, 150.0, 270.0].map(at).to_vec(),
        }
    }

    /// `(N_t, N_r)`.
    pub fn counts(&self) -> (usize, usize) {
        match self {
            NodeLayout::Uniform { n_tx, n_rx } => (*n_tx, *n_rx),
            NodeLayout::Fixed { tx, rx } => (tx.len(), rx.len()),
        }
    }
}

/// How line-of-sight is decided (§7 generator steps 1 and 4).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LosModel {
    /// PPP discs (V-B): centres a PPP of intensity `λ` in `R`; a segment is LoS iff no centre
    /// lies within `D/2` of it.
    Discs,
    /// No discs (V-A): each node–target segment is blocked independently w.p. `1 − p_los`
    /// (\[R\]; \[P\]: the blocking scatterer blocks that segment only).
    Independent {
        /// LoS probability of one node–target segment.
        p_los: Real,
    },
}

/// Optional geometric indirect paths (§1, §7): scatterer centres act as point reflectors.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct GeometricIps {
    /// Kind 1, TX → target → scatterer → RX.
    pub kind1: bool,
    /// Kind 2, TX → scatterer → target → RX.
    pub kind2: bool,
}

/// Settings of the §7 generator and metrics. Defaults: [`SimSettings::va`], [`SimSettings::vb`].
#[derive(Debug, Clone, PartialEq)]
pub struct SimSettings {
    /// Region `R` (\[P\] `[0, 10]²` m): disc centres, random nodes and targets live in it.
    pub region: Rect,
    /// Node layout (V-A hexagon, V-B uniform 3×3; Table I indexing).
    pub nodes: NodeLayout,
    /// LoS model (V-A independent, V-B discs).
    pub los: LosModel,
    /// Intensity `λ` of the disc centres, m⁻² (\[R/D\] `3/area(R) = 0.03`).
    pub lambda: Real,
    /// Disc diameter `D`, m (\[P\] V-A 0.2, V-B 0.6).
    pub diameter: Real,
    /// Range noise standard deviation `cσ`, m (\[P\] 0.1).
    pub range_sigma: Real,
    /// Resolution `δ`, m (\[P\] 0.3): a range within `δ` of the last kept one is discarded.
    pub resolution: Real,
    /// Detection radius `r_det` of the metrics (M12), m (\[P\] 0.5).
    pub detection_radius: Real,
    /// Probability `p_d` that a LoS DP is detected (\[R\] V-A / \[P\] 0.9).
    pub p_d: Real,
    /// Targets per realisation `K` (\[D/P\] 2).
    pub targets: usize,
    /// Mean number of clutter peaks per TRP (Poisson, \[P\] 2).
    pub clutter_mean: Real,
    /// Clutter peaks are uniform on `[0, r_max]`, m (\[P\] `2·diam(R)` = 28.28).
    pub r_max: Real,
    /// Geometric IPs (off by default).
    pub geometric_ips: GeometricIps,
}

/// `2·diam(R)`: the default `R_max` of the clutter (§7 table).
pub fn default_r_max(region: &Rect) -> Real {
    let d = region.max - region.min;
    2.0 * sqrt(d.x * d.x + d.y * d.y)
}

impl SimSettings {
    /// The §7 defaults shared by V-A and V-B, with the given layout, LoS model and `D`.
    fn defaults(nodes: NodeLayout, los: LosModel, diameter: Real) -> SimSettings {
        let region = Rect {
            min: Vec2::new(0.0, 0.0),
            max: Vec2::new(10.0, 10.0),
        };
        SimSettings {
            region,
            nodes,
            los,
            lambda: 3.0 / region.area(),
            diameter,
            range_sigma: 0.1,
            resolution: 0.3,
            detection_radius: 0.5,
            p_d: 0.9,
            targets: 2,
            clutter_mean: 2.0,
            r_max: default_r_max(&region),
            geometric_ips: GeometricIps::default(),
        }
    }

    /// V-A (§7, Fig. 3): hexagon about (5, 5) of radius 5 m, independent blocking with
    /// `p_LoS = 0.9` (so `p_u = 1 − p_d p_LoS² = 0.271`), `D = 0.2` m.
    pub fn va() -> SimSettings {
        Self::defaults(
            NodeLayout::hexagon(Vec2::new(5.0, 5.0), 5.0),
            LosModel::Independent { p_los: 0.9 },
            0.2,
        )
    }

    /// V-B (§7, Table II, Fig. 4): 3×3 nodes uniform in `R \ S`, PPP discs with `D = 0.6` m.
    pub fn vb() -> SimSettings {
        Self::defaults(
            NodeLayout::Uniform { n_tx: 3, n_rx: 3 },
            LosModel::Discs,
            0.6,
        )
    }

    /// The TRP map of the layout (Table I).
    pub fn map(&self) -> Result<TrpMap> {
        let (n_tx, n_rx) = self.nodes.counts();
        TrpMap::new(n_tx, n_rx)
    }

    /// Checks every field. Errors (each naming its field): [`Error::InvertedArea`] /
    /// [`Error::NonFinite`] (`region`); [`Error::EmptyNodeList`] / [`Error::SizeLimit`] for the
    /// node counts (via [`TrpMap::new`]); [`Error::NonFinite`] (`nodes.tx[j]`, `nodes.rx[j]`);
    /// [`Error::NonFinite`] / [`Error::OutOfRange`] (`lambda`), [`Error::NotPositive`]
    /// (`diameter`) (via [`PppBlocking::new`]); [`Error::OutOfRange`] (`p_d`, `p_los`) outside
    /// `[0, 1]`; [`Error::OutOfRange`] (`range_sigma`, `resolution`, `clutter_mean`) when
    /// negative or not finite; [`Error::NonFinite`] / [`Error::NotPositive`] (`detection_radius`, `r_max`);
    /// [`Error::SizeLimit`] (`targets`) unless `1 ≤ K ≤` [`MAX_TARGETS`]; [`Error::OutOfRange`]
    /// (`lambda`, `clutter_mean`) when a Poisson mean exceeds [`MAX_POISSON_MEAN`].
    pub fn validate(&self) -> Result<()> {
        let region = Rect::new(self.region.min, self.region.max)?;
        self.map()?;
        if let NodeLayout::Fixed { tx, rx } = &self.nodes {
            for (name, list) in [("nodes.tx", tx), ("nodes.rx", rx)] {
                if let Some(j) = list
                    .iter()
                    .position(|p| !(p.x.is_finite() && p.y.is_finite()))
                {
                    return Err(Error::NonFinite {
                        field: alloc::format!("{name}[{j}]"),
                    });
                }
            }
        }
        PppBlocking::new(self.lambda, self.diameter, Some(region), true)?;
        check_mean("lambda", self.lambda * region.area())?;
        check_probability("p_d", self.p_d)?;
        if let LosModel::Independent { p_los } = self.los {
            check_probability("p_los", p_los)?;
        }
        check_non_negative("range_sigma", self.range_sigma)?;
        check_non_negative("resolution", self.resolution)?;
        check_non_negative("clutter_mean", self.clutter_mean)?;
        check_mean("clutter_mean", self.clutter_mean)?;
        check_positive("detection_radius", self.detection_radius)?;
        check_positive("r_max", self.r_max)?;
        if !(1..=MAX_TARGETS).contains(&self.targets) {
            return Err(Error::SizeLimit {
                field: "targets",
                value: self.targets,
                min: 1,
                max: MAX_TARGETS,
            });
        }
        Ok(())
    }
}

fn check_non_negative(field: &str, v: Real) -> Result<()> {
    if v.is_finite() && v >= 0.0 {
        Ok(())
    } else {
        Err(Error::OutOfRange {
            field: field.into(),
            value: v,
            allowed: "a finite value ≥ 0",
        })
    }
}

fn check_mean(field: &str, mean: Real) -> Result<()> {
    if mean <= MAX_POISSON_MEAN {
        Ok(())
    } else {
        Err(Error::OutOfRange {
            field: field.into(),
            value: mean,
            allowed: "a Poisson mean ≤ 10 000 per realisation",
        })
    }
}
