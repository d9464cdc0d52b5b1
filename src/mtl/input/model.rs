//! The blocking-model part of the input schema (§6): i.c.b, PPP or empirical, and how to
//! build it for a network.

use super::*;
use alloc::boxed::Box;

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
