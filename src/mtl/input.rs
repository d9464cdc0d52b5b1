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
//!
//! Every type is serde with `deny_unknown_fields`; positions are `[x, y]` in metres. Nothing
//! here panics on bad input: every check returns a named [`Error`] whose field is the JSON path
//! of the offending value (e.g. `tx[1]`, `ranges_m[3][0]`, `table.counts`).

use alloc::boxed::Box;
use alloc::format;
use alloc::vec::Vec;

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::math::{Real, Vec2};
use crate::mtl::algorithm::{Measurements, MtlConfig, Target};
use crate::mtl::blocking::{check_probability, BlockingModel, NodeBlockingModel};
use crate::mtl::empirical::{EmpiricalNodeModel, EmpiricalTable};
use crate::mtl::icb::IcbModel;
use crate::mtl::polygon::Rect;
use crate::mtl::ppp::{PppBlocking, PppNodeModel};
use crate::mtl::trp::TrpMap;
use crate::simulate::rng;

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
            if p[0].is_finite() && p[1].is_finite() {
                Ok(Vec2::new(p[0], p[1]))
            } else {
                Err(Error::NonFinite {
                    field: format!("{field}[{j}]"),
                })
            }
        })
        .collect()
}

impl NetworkInput {
    /// Checks the network. Errors: [`Error::EmptyNodeList`] (`tx` / `rx`); [`Error::SizeLimit`]
    /// (`trps`, `nodes`) past [`crate::mtl::trp::MAX_TRPS`] / [`crate::mtl::trp::MAX_NODES`];
    /// [`Error::NonFinite`] (`tx[j]`, `rx[j]`, `region`, `c_sigma_m`); [`Error::InvertedArea`]
    /// (`region.x`, `region.y`); [`Error::NotPositive`] (`c_sigma_m`).
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
        if !self.c_sigma_m.is_finite() {
            return Err(Error::NonFinite {
                field: "c_sigma_m".into(),
            });
        }
        if self.c_sigma_m <= 0.0 {
            return Err(Error::NotPositive {
                field: "c_sigma_m".into(),
                value: self.c_sigma_m,
            });
        }
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
        if self.ranges_m.len() != m {
            return Err(Error::LengthMismatch {
                field: "ranges_m",
                expected: m,
                found: self.ranges_m.len(),
            });
        }
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
                if !r.is_finite() {
                    return Err(Error::NonFinite {
                        field: format!("ranges_m[{t}][{i}]"),
                    });
                }
                if r < 0.0 {
                    return Err(Error::OutOfRange {
                        field: format!("ranges_m[{t}][{i}]"),
                        value: r,
                        allowed: "a range ≥ 0 m",
                    });
                }
            }
        }
        Ok(())
    }
}

/// How an empirical table trained on the fly is simulated (§6.3,
/// [`EmpiricalTable::train_discs`]): the §7 disc process on the given network.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrainingSpec {
    /// Disc-centre intensity `λ`, m⁻² (default [`DEFAULT_LAMBDA`]).
    #[serde(default = "default_lambda")]
    pub lambda: Real,
    /// Disc diameter `D`, m (default [`DEFAULT_DIAMETER_M`]).
    #[serde(default = "default_diameter")]
    pub diameter_m: Real,
    /// Cells per side of the grid over the region (default [`DEFAULT_TRAINING_CELLS`]).
    #[serde(default = "default_cells")]
    pub cells: usize,
    /// Simulated scenes (default [`DEFAULT_TRAINING_SCENES`]).
    #[serde(default = "default_scenes")]
    pub scenes: usize,
    /// Seed of the training draws (stream `rng(seed, 0)`; default 1).
    #[serde(default = "default_seed")]
    pub seed: u64,
}

impl Default for TrainingSpec {
    fn default() -> Self {
        TrainingSpec {
            lambda: DEFAULT_LAMBDA,
            diameter_m: DEFAULT_DIAMETER_M,
            cells: DEFAULT_TRAINING_CELLS,
            scenes: DEFAULT_TRAINING_SCENES,
            seed: 1,
        }
    }
}

/// The blocking model that scores candidates (§6), tagged by `kind`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase", deny_unknown_fields)]
pub enum ModelSpec {
    /// i.c.b (§6.1): `p_u` directly, or `p_u = 1 − p_d p_LoS²` (M7) from `p_d` and `p_los`
    /// (defaults [`DEFAULT_P_D`], [`DEFAULT_P_LOS`]). Giving `p_u` together with `p_d` or
    /// `p_los` is an error. Consistency branching off.
    Icb {
        /// Undetected-DP probability `p_u`.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        p_u: Option<Real>,
        /// DP detection probability `p_d`.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        p_d: Option<Real>,
        /// LoS probability `p_LoS` between any two points.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        p_los: Option<Real>,
    },
    /// PPP discs (§6.2) with the network's nodes and region. Consistency branching on.
    Ppp {
        /// Disc-centre intensity `λ`, m⁻².
        #[serde(default = "default_lambda")]
        lambda: Real,
        /// Disc diameter `D`, m.
        #[serde(default = "default_diameter")]
        diameter_m: Real,
        /// DP detection probability `p_d`.
        #[serde(default = "default_p_d")]
        p_d: Real,
        /// `true`: exact inclusion–exclusion (M11); `false`: the bound (M10) of \[A\].
        #[serde(default)]
        exact: bool,
    },
    /// Empirical node-pattern table (§6.3): exactly one of `table` (e.g. measured) or
    /// `training` (simulated now on the network's region, or the nodes' bounding box).
    /// Consistency branching on.
    Empirical {
        /// DP detection probability `p_d`.
        #[serde(default = "default_p_d")]
        p_d: Real,
        /// A ready table (its node counts must match the network).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        table: Option<EmpiricalTable>,
        /// Train a table on the network.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        training: Option<TrainingSpec>,
    },
}

/// A blocking model ready for Algorithm 1 ([`ModelSpec::build`]).
pub struct BuiltModel {
    /// The model, for the network's TRP map.
    pub model: Box<dyn BlockingModel + Send + Sync>,
    /// Whether Algorithm 1 branches on consistency (cases 2a/2b of §4): `false` for i.c.b,
    /// under which every vector is consistent (§6.1), `true` otherwise. Use as
    /// [`MtlConfig::consistency`].
    pub consistency: bool,
    /// `p_u` of an i.c.b model (for reports and the threshold (M8)); `None` otherwise.
    pub icb_p_u: Option<Real>,
}

impl core::fmt::Debug for BuiltModel {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("BuiltModel")
            .field("consistency", &self.consistency)
            .field("icb_p_u", &self.icb_p_u)
            .finish_non_exhaustive()
    }
}

impl ModelSpec {
    /// The model's name: `icb`, `ppp` or `empirical`.
    pub fn name(&self) -> &'static str {
        match self {
            ModelSpec::Icb { .. } => "icb",
            ModelSpec::Ppp { .. } => "ppp",
            ModelSpec::Empirical { .. } => "empirical",
        }
    }

    /// The model for `network`.
    ///
    /// Errors: [`Error::OutOfRange`] (`p_u`, `p_d`, `p_los`) outside `[0, 1]`, (`p_u`) given
    /// with `p_d` or `p_los`, (`table`) when both or neither of `table` / `training` are given;
    /// the PPP errors of [`PppBlocking::new`] (`lambda`, `diameter`) and
    /// [`crate::mtl::ppp::MAX_PPP_NODES`]; for an empirical table the errors of
    /// [`EmpiricalTable::validate`] and [`Error::LengthMismatch`] (`table.n_tx` / `table.n_rx`)
    /// when its node counts differ from the network's; for training those of
    /// [`EmpiricalTable::new`] (`nx`, …) and [`EmpiricalTable::train_discs`] (`scenes`,
    /// `lambda`, …) and [`Network::region_or_bounds`].
    pub fn build(&self, network: &Network) -> Result<BuiltModel> {
        let map = network.map;
        match *self {
            ModelSpec::Icb { p_u, p_d, p_los } => {
                let model = match p_u {
                    Some(p_u) => {
                        if p_d.is_some() || p_los.is_some() {
                            return Err(Error::OutOfRange {
                                field: "p_u".into(),
                                value: p_u,
                                allowed: "give p_u or p_d/p_los, not both",
                            });
                        }
                        IcbModel::from_p_u(map, p_u)?
                    }
                    None => IcbModel::new(
                        map,
                        p_d.unwrap_or(DEFAULT_P_D),
                        p_los.unwrap_or(DEFAULT_P_LOS),
                    )?,
                };
                Ok(BuiltModel {
                    icb_p_u: Some(model.p_u()),
                    model: Box::new(model),
                    consistency: false,
                })
            }
            ModelSpec::Ppp {
                lambda,
                diameter_m,
                p_d,
                exact,
            } => {
                check_probability("p_d", p_d)?;
                let ppp = PppBlocking::new(lambda, diameter_m, network.region, exact)?;
                let node = PppNodeModel::new(ppp, network.tx.clone(), network.rx.clone())?;
                Ok(BuiltModel {
                    model: Box::new(NodeBlockingModel::new(map, node, p_d)?),
                    consistency: true,
                    icb_p_u: None,
                })
            }
            ModelSpec::Empirical {
                p_d,
                ref table,
                training,
            } => {
                check_probability("p_d", p_d)?;
                let table = match (table, training) {
                    (Some(t), None) => {
                        t.validate()?;
                        for (field, have, want) in [
                            ("table.n_tx", t.n_tx, map.n_tx()),
                            ("table.n_rx", t.n_rx, map.n_rx()),
                        ] {
                            if have != want {
                                return Err(Error::LengthMismatch {
                                    field,
                                    expected: want,
                                    found: have,
                                });
                            }
                        }
                        t.clone()
                    }
                    (None, Some(s)) => {
                        let region = network.region_or_bounds()?;
                        let mut t =
                            EmpiricalTable::new(&region, s.cells, s.cells, map.n_tx(), map.n_rx())?;
                        t.train_discs(
                            &network.tx,
                            &network.rx,
                            s.lambda,
                            s.diameter_m,
                            s.scenes,
                            &mut rng(s.seed, 0),
                        )?;
                        t
                    }
                    (Some(_), Some(_)) | (None, None) => {
                        return Err(Error::OutOfRange {
                            field: "table".into(),
                            value: table.is_some() as u8 as Real,
                            allowed: "give exactly one of table or training",
                        })
                    }
                };
                let node = EmpiricalNodeModel::new(table)?;
                Ok(BuiltModel {
                    model: Box::new(NodeBlockingModel::new(map, node, p_d)?),
                    consistency: true,
                    icb_p_u: None,
                })
            }
        }
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
mod tests {
    use super::*;
    use crate::mtl::algorithm::locate;

    fn hexagon() -> NetworkInput {
        let at = |deg: Real| {
            let a = deg.to_radians();
            [5.0 + 5.0 * a.cos(), 5.0 + 5.0 * a.sin()]
        };
        NetworkInput {
            tx: [90.0, 210.0, 330.0].map(at).to_vec(),
            rx: [30.0, 150.0, 270.0].map(at).to_vec(),
            region: Some(RegionInput {
                min_m: [0.0, 0.0],
                max_m: [10.0, 10.0],
            }),
            c_sigma_m: 0.1,
        }
    }

    fn exact_ranges(net: &Network, targets: &[Vec2]) -> RangesInput {
        RangesInput {
            ranges_m: (0..net.map.n_trps())
                .map(|m| {
                    targets
                        .iter()
                        .map(|x| net.map.range(m, x, &net.tx, &net.rx))
                        .collect()
                })
                .collect(),
        }
    }

    #[test]
    fn json_round_trip_and_defaults() {
        let net = hexagon();
        let text = serde_json::to_string(&net).unwrap();
        assert_eq!(from_json::<NetworkInput>(&text).unwrap(), net);
        let short: NetworkInput = from_json(r#"{"tx": [[0, 0]], "rx": [[1, 0]]}"#).unwrap();
        assert_eq!((short.c_sigma_m, short.region), (0.1, None));
        for spec in [
            ModelSpec::Icb {
                p_u: Some(0.3),
                p_d: None,
                p_los: None,
            },
            ModelSpec::Ppp {
                lambda: 0.03,
                diameter_m: 0.2,
                p_d: 0.9,
                exact: true,
            },
            ModelSpec::Empirical {
                p_d: 0.9,
                table: None,
                training: Some(TrainingSpec::default()),
            },
        ] {
            let text = serde_json::to_string(&spec).unwrap();
            assert_eq!(from_json::<ModelSpec>(&text).unwrap(), spec, "{text}");
        }
        let ppp: ModelSpec = from_json(r#"{"kind": "ppp"}"#).unwrap();
        assert_eq!(
            ppp,
            ModelSpec::Ppp {
                lambda: 0.03,
                diameter_m: 0.6,
                p_d: 0.9,
                exact: false
            }
        );
        let r = RangesInput {
            ranges_m: alloc::vec![alloc::vec![1.0, 2.5], alloc::vec![]],
        };
        let text = serde_json::to_string(&r).unwrap();
        assert_eq!(from_json::<RangesInput>(&text).unwrap(), r);
    }

    #[test]
    fn parse_errors_name_the_field() {
        let e = from_json::<NetworkInput>(r#"{"tx": [[0, 0]], "rx": [[1, 0]], "cs": 1}"#);
        assert!(matches!(e, Err(Error::Parse { ref message }) if message.contains("cs")));
        let e = from_json::<NetworkInput>(r#"{"tx": [[0, "a"]], "rx": [[1, 0]]}"#);
        assert!(matches!(e, Err(Error::Parse { ref message }) if message.contains("tx[0]")));
        let e = from_json::<ModelSpec>(r#"{"kind": "magic"}"#);
        assert!(matches!(e, Err(Error::Parse { ref message }) if message.contains("magic")));
    }

    #[test]
    fn bad_networks_and_ranges_are_named_errors() {
        let mut net = hexagon();
        net.tx.clear();
        assert_eq!(net.validate(), Err(Error::EmptyNodeList { field: "tx" }));
        let mut net = hexagon();
        net.rx[2][1] = Real::NAN;
        assert!(matches!(net.validate(), Err(Error::NonFinite { field }) if field == "rx[2]"));
        let mut net = hexagon();
        net.c_sigma_m = 0.0;
        assert!(matches!(
            net.validate(),
            Err(Error::NotPositive { field, .. }) if field == "c_sigma_m"
        ));
        let mut net = hexagon();
        net.region = Some(RegionInput {
            min_m: [0.0, 5.0],
            max_m: [10.0, 5.0],
        });
        assert!(matches!(
            net.validate(),
            Err(Error::InvertedArea {
                field: "region.y",
                ..
            })
        ));
        let mut net = hexagon();
        net.tx = alloc::vec![[0.0, 0.0]; 9];
        net.rx = alloc::vec![[1.0, 0.0]; 9];
        assert!(matches!(net.validate(), Err(Error::SizeLimit { .. })));

        let net = hexagon().validate().unwrap();
        let mut r = exact_ranges(&net, &[Vec2::new(4.0, 5.0)]);
        r.ranges_m.pop();
        assert!(matches!(
            r.validate(&net),
            Err(Error::LengthMismatch {
                field: "ranges_m",
                expected: 9,
                found: 8
            })
        ));
        let mut r = exact_ranges(&net, &[Vec2::new(4.0, 5.0)]);
        r.ranges_m[3][0] = Real::NAN;
        assert!(
            matches!(r.validate(&net), Err(Error::NonFinite { field }) if field == "ranges_m[3][0]")
        );
        r.ranges_m[3][0] = -1.0;
        assert!(matches!(
            r.validate(&net),
            Err(Error::OutOfRange { field, .. }) if field == "ranges_m[3][0]"
        ));
        r.ranges_m[3] = alloc::vec![1.0; MAX_RANGES_PER_TRP + 1];
        assert!(matches!(r.validate(&net), Err(Error::SizeLimit { .. })));
    }

    #[test]
    fn bad_models_are_named_errors() {
        let net = hexagon().validate().unwrap();
        let err = |s: ModelSpec| s.build(&net).err().unwrap();
        assert!(matches!(
            err(ModelSpec::Icb { p_u: Some(0.2), p_d: Some(0.9), p_los: None }),
            Error::OutOfRange { field, .. } if field == "p_u"
        ));
        assert!(matches!(
            err(ModelSpec::Icb { p_u: None, p_d: None, p_los: Some(1.5) }),
            Error::OutOfRange { field, .. } if field == "p_los"
        ));
        assert!(matches!(
            err(ModelSpec::Ppp { lambda: -1.0, diameter_m: 0.6, p_d: 0.9, exact: false }),
            Error::OutOfRange { field, .. } if field == "lambda"
        ));
        assert!(matches!(
            err(ModelSpec::Ppp { lambda: 0.03, diameter_m: 0.6, p_d: 2.0, exact: false }),
            Error::OutOfRange { field, .. } if field == "p_d"
        ));
        assert!(matches!(
            err(ModelSpec::Empirical { p_d: 0.9, table: None, training: None }),
            Error::OutOfRange { field, .. } if field == "table"
        ));
        let region = net.region.unwrap();
        let table = EmpiricalTable::new(&region, 2, 2, 2, 3).unwrap();
        assert!(matches!(
            err(ModelSpec::Empirical {
                p_d: 0.9,
                table: Some(table),
                training: None
            }),
            Error::LengthMismatch {
                field: "table.n_tx",
                ..
            }
        ));
        let training = TrainingSpec {
            scenes: usize::MAX,
            ..TrainingSpec::default()
        };
        assert!(matches!(
            err(ModelSpec::Empirical {
                p_d: 0.9,
                table: None,
                training: Some(training)
            }),
            Error::SizeLimit {
                field: "scenes",
                ..
            }
        ));
    }

    /// Two targets in the V-A hexagon with exact ranges: every model finds both.
    #[test]
    fn every_model_finds_two_exact_targets() {
        let net = hexagon().validate().unwrap();
        let truth = [Vec2::new(3.0, 4.0), Vec2::new(6.5, 6.0)];
        let ranges = exact_ranges(&net, &truth);
        ranges.validate(&net).unwrap();
        let training = TrainingSpec {
            cells: 10,
            scenes: 20,
            ..TrainingSpec::default()
        };
        for spec in [
            ModelSpec::Icb {
                p_u: None,
                p_d: None,
                p_los: None,
            },
            ModelSpec::Ppp {
                lambda: 0.03,
                diameter_m: 0.2,
                p_d: 0.9,
                exact: false,
            },
            ModelSpec::Empirical {
                p_d: 0.9,
                table: None,
                training: Some(training),
            },
        ] {
            let built = spec.build(&net).unwrap();
            assert_eq!(built.consistency, spec.name() != "icb");
            let cfg = net.config(&MtlConfig::default(), &built);
            let out = locate(&net.measurements(&ranges.ranges_m), &*built.model, &cfg).unwrap();
            let reports = target_reports(&net.map, &out.targets);
            assert_eq!(reports.len(), 2, "{}", spec.name());
            for x in truth {
                assert!(
                    reports.iter().any(|r| {
                        (r.position_m[0] - x.x).abs() < 1e-6 && (r.position_m[1] - x.y).abs() < 1e-6
                    }),
                    "{}: {x:?} not found",
                    spec.name()
                );
            }
            assert!(reports
                .iter()
                .all(|r| r.g == [1; 9] && r.matching.len() == 9));
        }
    }
}
