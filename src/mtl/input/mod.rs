//! Input and output schemas of one multi-target localization (spec `multi-target.md` §4, §6):
//! what a front end (the native CLI's `scatterloc mtl locate`, a page) reads from its user and
//! hands to [`crate::mtl::algorithm::locate`], and what it reports back.
//!
//! - [`NetworkInput`]: the TX and RX positions, an optional region `R` and the range standard
//!   deviation `cσ`; [`NetworkInput::validate`] turns it into a checked [`Network`].
//! - [`RangesInput`]: the measured ranges per TRP in Table I order (TRP `m` uses TX
//!   `m mod N_t` and RX `m div N_t`, 0-based); [`RangesInput::validate`] checks them against a
//!   [`Network`].
//! - [`ModelSpec`]: which blocking model scores the candidates (i.c.b §6.1, PPP §6.2, empirical
//!   §6.3) and its parameters; [`ModelSpec::build`] gives a boxed [`BlockingModel`] plus whether
//!   Algorithm 1 branches on consistency (off for i.c.b, whose vectors are all consistent).
//! - [`TargetReport`]: one detected target in serialisable form ([`target_reports`]).
//! - [`locate_request`]: a [`LocateRequest`] run through Algorithm 1, reported as a
//!   [`LocateDoc`] (`scatterloc mtl locate`, `scatterloc.mtl_locate` in Python).
//!
//! Every type is serde with `deny_unknown_fields`; positions are `[x, y]` in metres. Nothing
//! here panics on bad input: every check returns a named [`Error`] whose field is the JSON path
//! of the offending value (e.g. `tx[1]`, `ranges_m[3][0]`, `table.counts`).

use alloc::format;
use alloc::vec::Vec;

mod doc;
mod model;
pub use doc::{locate_request, LocateDoc, LocateStage, ModelSummary};
pub use model::{BuiltModel, ModelSpec, TrainingSpec};

use serde::{Deserialize, Serialize};

use crate::error::{check_finite, check_len, limits, Error, Result};
use crate::math::{Real, Vec2};
use crate::measure::rng;
use crate::mtl::algorithm::{Measurements, MtlConfig, Target};
use crate::mtl::blocking::{check_probability, BlockingModel, NodeBlockingModel};
use crate::mtl::empirical::{EmpiricalNodeModel, EmpiricalTable};
use crate::mtl::icb::IcbModel;
use crate::mtl::polygon::Rect;
use crate::mtl::ppp::{PppBlocking, PppNodeModel};
use crate::mtl::trp::TrpMap;

/// Default range standard deviation `cσ`, m (§7 table, \[P\] 0.1).
pub const DEFAULT_C_SIGMA_M: Real = 0.1;
/// Default DP detection probability `p_d` (§7 table, 0.9).
pub const DEFAULT_P_D: Real = 0.9;
/// Default LoS probability of the i.c.b model when neither `p_u` nor `p_los` is given (V-A,
/// \[P\] 0.9, so `p_u = 0.271`).
pub const DEFAULT_P_LOS: Real = 0.9;
/// Default disc-centre intensity `λ`, m⁻² (§7 table, 0.03).
pub const DEFAULT_LAMBDA: Real = 0.03;
/// Default disc diameter `D`, m (§7 table, V-B 0.6).
pub const DEFAULT_DIAMETER_M: Real = 0.6;
/// Default cells per side of an empirical table trained on the fly (0.5 m cells over the
/// `[0, 10]²` region, as the V-B experiment).
pub const DEFAULT_TRAINING_CELLS: usize = 20;
/// Default simulated scenes of an empirical table trained on the fly.
pub const DEFAULT_TRAINING_SCENES: usize = 400;
/// Most MPCs accepted per TRP (seeds grow with the square of this count, §4 complexity).
pub const MAX_RANGES_PER_TRP: usize = 256;

fn default_c_sigma() -> Real {
    DEFAULT_C_SIGMA_M
}

fn default_p_d() -> Real {
    DEFAULT_P_D
}

fn default_lambda() -> Real {
    DEFAULT_LAMBDA
}

fn default_diameter() -> Real {
    DEFAULT_DIAMETER_M
}

fn default_cells() -> usize {
    DEFAULT_TRAINING_CELLS
}

fn default_scenes() -> usize {
    DEFAULT_TRAINING_SCENES
}

fn default_seed() -> u64 {
    1
}

/// A rectangle `[min_m, max_m]`, m (the region `R`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RegionInput {
    /// Lower-left corner `[x, y]`, m.
    pub min_m: [Real; 2],
    /// Upper-right corner `[x, y]`, m.
    pub max_m: [Real; 2],
}

impl RegionInput {
    /// The checked rectangle: [`Error::NonFinite`] (`region`), [`Error::InvertedArea`]
    /// (`region.x` / `region.y`).
    pub fn rect(&self) -> Result<Rect> {
        Rect::new(
            Vec2::new(self.min_m[0], self.min_m[1]),
            Vec2::new(self.max_m[0], self.max_m[1]),
        )
    }
}

impl From<Rect> for RegionInput {
    fn from(r: Rect) -> Self {
        RegionInput {
            min_m: [r.min.x, r.min.y],
            max_m: [r.max.x, r.max.y],
        }
    }
}

/// The network file: node positions, optional region and range noise.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NetworkInput {
    /// Transmitter positions `u_j` as `[x, y]`, m (TX `j` is 0-based).
    pub tx: Vec<[Real; 2]>,
    /// Receiver positions `v_j` as `[x, y]`, m.
    pub rx: Vec<[Real; 2]>,
    /// Region `R`: seeds outside it enlarged by 1 m are dropped (§5.2), the PPP rectangles are
    /// clipped to it (§6.2) and an empirical table trained on the fly covers it. Absent: no
    /// seed filter, no clipping, and training over the nodes' bounding box.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub region: Option<RegionInput>,
    /// Range standard deviation `cσ`, m (default [`DEFAULT_C_SIGMA_M`]).
    #[serde(default = "default_c_sigma")]
    pub c_sigma_m: Real,
}

/// A checked network ([`NetworkInput::validate`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Network {
    /// The TRP map (Table I).
    pub map: TrpMap,
    /// Transmitter positions, m.
    pub tx: Vec<Vec2>,
    /// Receiver positions, m.
    pub rx: Vec<Vec2>,
    /// Region `R`, if given.
    pub region: Option<Rect>,
    /// Range standard deviation `cσ`, m.
    pub c_sigma_m: Real,
}

fn points(field: &str, list: &[[Real; 2]]) -> Result<Vec<Vec2>> {
    list.iter()
        .enumerate()
        .map(|(j, p)| {
            let name = format!("{field}[{j}]");
            check_finite(&name, p[0])?;
            check_finite(&name, p[1])?;
            limits::COORDINATE_M.check(&name, p[0])?;
            limits::COORDINATE_M.check(&name, p[1])?;
            Ok(Vec2::new(p[0], p[1]))
        })
        .collect()
}

impl NetworkInput {
    /// Checks the network. Errors: [`Error::EmptyNodeList`] (`tx` / `rx`); [`Error::SizeLimit`]
    /// (`trps`, `nodes`) past [`crate::mtl::trp::MAX_TRPS`] / [`crate::mtl::trp::MAX_NODES`];
    /// [`Error::NonFinite`] (`tx[j]`, `rx[j]`, `region`, `c_sigma_m`); [`Error::InvertedArea`]
    /// (`region.x`, `region.y`); [`Error::OutOfRange`] (`tx[j]`, `rx[j]`, `region` outside
    /// [`limits::COORDINATE_M`], `c_sigma_m` outside [`limits::C_SIGMA_M`]).
    pub fn validate(&self) -> Result<Network> {
        if self.tx.is_empty() {
            return Err(Error::EmptyNodeList { field: "tx" });
        }
        if self.rx.is_empty() {
            return Err(Error::EmptyNodeList { field: "rx" });
        }
        let map = TrpMap::new(self.tx.len(), self.rx.len())?;
        let tx = points("tx", &self.tx)?;
        let rx = points("rx", &self.rx)?;
        let region = self.region.as_ref().map(RegionInput::rect).transpose()?;
        limits::C_SIGMA_M.check("c_sigma_m", self.c_sigma_m)?;
        Ok(Network {
            map,
            tx,
            rx,
            region,
            c_sigma_m: self.c_sigma_m,
        })
    }
}

impl Network {
    /// The region for models that need one: [`Network::region`] if given, else the bounding box
    /// of the nodes. [`Error::InvertedArea`] (`region.x` / `region.y`) when the nodes lie on one
    /// vertical or horizontal line and no region is given.
    pub fn region_or_bounds(&self) -> Result<Rect> {
        if let Some(r) = self.region {
            return Ok(r);
        }
        let (mut lo, mut hi) = (self.tx[0], self.tx[0]);
        for p in self.tx.iter().chain(&self.rx) {
            lo = Vec2::new(lo.x.min(p.x), lo.y.min(p.y));
            hi = Vec2::new(hi.x.max(p.x), hi.y.max(p.y));
        }
        Rect::new(lo, hi)
    }

    /// The Algorithm 1 input for `ranges` (checked by [`RangesInput::validate`]).
    pub fn measurements<'a>(&'a self, ranges: &'a [Vec<Real>]) -> Measurements<'a> {
        Measurements {
            tx: &self.tx,
            rx: &self.rx,
            ranges,
            c_sigma_m: self.c_sigma_m,
        }
    }

    /// `base` with this network's region as the seed filter of §5.2 and the consistency
    /// branching of `model` (see [`BuiltModel::consistency`]).
    pub fn config(&self, base: &MtlConfig, model: &BuiltModel) -> MtlConfig {
        MtlConfig {
            region: self.region,
            consistency: model.consistency,
            ..base.clone()
        }
    }
}

/// The ranges file: the measured MPC ranges of every TRP.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RangesInput {
    /// `ranges_m[m]` = the ranges `r_{m,i}` of TRP `m`, m, in Table I order: TRP `m` uses TX
    /// `m mod N_t` and RX `m div N_t` (0-based). An empty list = no MPC at that TRP.
    pub ranges_m: Vec<Vec<Real>>,
}

impl RangesInput {
    /// Checks the ranges against `network`. Errors: [`Error::LengthMismatch`] (`ranges_m`) unless
    /// there is one list per TRP (`N_t · N_r`); [`Error::SizeLimit`] (`ranges_m per TRP`) above
    /// [`MAX_RANGES_PER_TRP`]; [`Error::NonFinite`] (`ranges_m[m][i]`); [`Error::OutOfRange`]
    /// (`ranges_m[m][i]`) for a negative range.
    pub fn validate(&self, network: &Network) -> Result<()> {
        let m = network.map.n_trps();
        check_len("ranges_m", m, self.ranges_m.len())?;
        for (t, rs) in self.ranges_m.iter().enumerate() {
            if rs.len() > MAX_RANGES_PER_TRP {
                return Err(Error::SizeLimit {
                    field: "ranges_m per TRP",
                    value: rs.len(),
                    min: 0,
                    max: MAX_RANGES_PER_TRP,
                });
            }
            for (i, &r) in rs.iter().enumerate() {
                limits::RANGE_M.check(&format!("ranges_m[{t}][{i}]"), r)?;
            }
        }
        Ok(())
    }
}

/// One detected target in serialisable form.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TargetReport {
    /// Estimated position `x̂` as `[x, y]`, m.
    pub position_m: [Real; 2],
    /// The matching `ℳ` as `[trp, mpc]` pairs (0-based: `ranges_m[trp][mpc]`), by TRP.
    pub matching: Vec<[usize; 2]>,
    /// Score `J` (M2).
    pub j: Real,
    /// Blocking likelihood `L_b`, nats.
    pub l_b: Real,
    /// Observed blocking vector `ĝ`, one entry per TRP: 1 = DP matched, 0 = none.
    pub g: Vec<u8>,
    /// Family (seed) id.
    pub family: usize,
}

/// The reports of `targets` (in their order) for a network with TRP map `map`.
pub fn target_reports(map: &TrpMap, targets: &[Target]) -> Vec<TargetReport> {
    targets
        .iter()
        .map(|t| TargetReport {
            position_m: [t.position.x, t.position.y],
            matching: t.matching.iter().map(|p| [p.trp, p.mpc]).collect(),
            j: t.j,
            l_b: t.l_b,
            g: (0..map.n_trps())
                .map(|m| u8::from(t.g.get(m) == Some(true)))
                .collect(),
            family: t.family,
        })
        .collect()
}

/// Parses a JSON document (any schema of this module) into `T`; [`Error::Parse`] names the path
/// of the offending field (same as [`crate::scenario::parse_json`]).
pub fn from_json<T: serde::de::DeserializeOwned>(text: &str) -> Result<T> {
    crate::scenario::parse_json(text)
}

/// A convenience holding what one localization needs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LocateRequest {
    /// The network.
    pub network: NetworkInput,
    /// The ranges.
    pub ranges: RangesInput,
    /// The blocking model.
    pub model: ModelSpec,
}

/// The name of the model kinds, for messages: `icb, ppp, empirical`.
pub const MODEL_KINDS: &str = "icb, ppp, empirical";

#[cfg(test)]
mod tests;
