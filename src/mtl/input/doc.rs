//! One multi-target localization as a use case (issue 27): a [`LocateRequest`]'s network,
//! ranges and model checked, the model built, Algorithm 1 run, and its report as one serde
//! document ([`LocateDoc`]) — what `scatterloc mtl locate` prints and `scatterloc.mtl_locate`
//! returns in Python.

use super::*;

/// The blocking model a localization used (a table is summarised by its shape).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ModelSummary {
    /// `icb`, `ppp` or `empirical`.
    pub kind: &'static str,
    /// Whether Algorithm 1 branched on consistency ([`BuiltModel::consistency`]).
    pub consistency: bool,
    /// i.c.b: `p_u` (given, or `1 − p_d p_LoS²`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub p_u: Option<Real>,
    /// `p_d` (i.c.b only when given).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub p_d: Option<Real>,
    /// PPP: `λ`, m⁻².
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lambda: Option<Real>,
    /// PPP: the disc diameter, m.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub diameter_m: Option<Real>,
    /// PPP: exact node probabilities (M11) or the bound (M10).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub exact: Option<bool>,
    /// Empirical, trained on the network: how.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub training: Option<TrainingSpec>,
    /// Empirical with a given table: its cells `[nx, ny]`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub table_cells: Option<[usize; 2]>,
}

impl ModelSummary {
    /// The summary of `spec` as built (`built`).
    pub fn of(spec: &ModelSpec, built: &BuiltModel) -> ModelSummary {
        let none = ModelSummary {
            kind: spec.name(),
            consistency: built.consistency,
            p_u: None,
            p_d: None,
            lambda: None,
            diameter_m: None,
            exact: None,
            training: None,
            table_cells: None,
        };
        match spec {
            ModelSpec::Icb { p_d, .. } => ModelSummary {
                p_u: built.icb_p_u,
                p_d: *p_d,
                ..none
            },
            ModelSpec::Ppp {
                lambda,
                diameter_m,
                p_d,
                exact,
            } => ModelSummary {
                p_d: Some(*p_d),
                lambda: Some(*lambda),
                diameter_m: Some(*diameter_m),
                exact: Some(*exact),
                ..none
            },
            ModelSpec::Empirical {
                p_d,
                table,
                training,
            } => ModelSummary {
                p_d: Some(*p_d),
                training: *training,
                table_cells: table.as_ref().map(|t| [t.nx, t.ny]),
                ..none
            },
        }
    }
}

/// The report of one localization (`scatterloc mtl locate`'s output; keys in this order).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LocateDoc {
    /// The model used.
    pub model: ModelSummary,
    /// The ellipse gate `T_e`, σ.
    pub t_e: Real,
    /// The blocking threshold `T_b`, nats (`null` = ∞).
    pub t_b: Option<Real>,
    /// Targets found.
    pub count: usize,
    /// Candidates evaluated (the work counted against [`MtlConfig::max_candidates`]).
    pub candidates: usize,
    /// The targets.
    pub targets: Vec<TargetReport>,
}

/// Where an input error of [`locate_request`] came from: the network, the ranges, the model's
/// settings or Algorithm 1's (its settings, its work budget).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LocateStage {
    /// [`NetworkInput::validate`].
    Network,
    /// [`RangesInput::validate`].
    Ranges,
    /// [`ModelSpec::build`].
    Model,
    /// [`crate::mtl::algorithm::locate`].
    Algorithm,
}

/// Runs one localization: the request's network and ranges checked, its model built, Algorithm
/// 1 with `base` (its region and consistency branching from the network and the model,
/// [`Network::config`]). Errors are the core's, with the stage they came from, so a front end
/// can say which input was wrong (the CLI names the file or the flag).
pub fn locate_request(
    req: &LocateRequest,
    base: &MtlConfig,
) -> core::result::Result<LocateDoc, (LocateStage, Error)> {
    let network = req
        .network
        .validate()
        .map_err(|e| (LocateStage::Network, e))?;
    req.ranges
        .validate(&network)
        .map_err(|e| (LocateStage::Ranges, e))?;
    let built = req
        .model
        .build(&network)
        .map_err(|e| (LocateStage::Model, e))?;
    let cfg = network.config(base, &built);
    let out = crate::mtl::algorithm::locate(
        &network.measurements(&req.ranges.ranges_m),
        &*built.model,
        &cfg,
    )
    .map_err(|e| (LocateStage::Algorithm, e))?;
    let targets = target_reports(&network.map, &out.targets);
    Ok(LocateDoc {
        model: ModelSummary::of(&req.model, &built),
        t_e: cfg.t_e,
        t_b: cfg.t_b.is_finite().then_some(cfg.t_b),
        count: targets.len(),
        candidates: out.evaluated(),
        targets,
    })
}
