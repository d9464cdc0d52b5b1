//! `scatterloc mtl locate`: Algorithm 1 (§4) on a network file and a ranges file.

use super::*;

/// Output of `mtl locate`.
#[derive(Serialize)]
struct LocateOut<'a> {
    model: &'a ModelSummary,
    t_e: f64,
    /// `null` = ∞.
    t_b: Option<f64>,
    count: usize,
    /// Candidates evaluated (the work counted against `--max-candidates`).
    candidates: usize,
    targets: Vec<TargetReport>,
}

/// The model used by `mtl locate` (a table is summarised by its shape).
#[derive(Serialize)]
struct ModelSummary {
    kind: &'static str,
    consistency: bool,
    #[serde(skip_serializing_if = "Option::is_none")]
    p_u: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    p_d: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    lambda: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    diameter_m: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    exact: Option<bool>,
    #[serde(skip_serializing_if = "Option::is_none")]
    training: Option<TrainingSpec>,
    #[serde(skip_serializing_if = "Option::is_none")]
    table_cells: Option<[usize; 2]>,
}

/// `scatterloc mtl locate`.
pub fn mtl_locate(args: &MtlLocateArgs) -> Result<(), CliError> {
    let net_path = args.network.as_str();
    let ranges_path = args.ranges.as_str();
    let spec = model_spec(args)?;
    let cfg = mtl_config(args);
    let out_path = match args.out.as_deref() {
        Some(p) => {
            Format::of("out", p, &[Format::Json])?;
            check_writable("out", p)?;
            Some(p)
        }
        None => None,
    };
    let net_in: NetworkInput = read_file("network", net_path)?;
    let network = net_in
        .validate()
        .map_err(|e| CliError::usage(format!("--network {net_path}: {e}")))?;
    let ranges: RangesInput = read_file("ranges", ranges_path)?;
    ranges
        .validate(&network)
        .map_err(|e| CliError::usage(format!("--ranges {ranges_path}: {e}")))?;
    let built = spec
        .build(&network)
        .map_err(|e| core_error(&e, "--model"))?;
    let cfg = network.config(&cfg, &built);
    let out = locate(&network.measurements(&ranges.ranges_m), &*built.model, &cfg)
        .map_err(|e| core_error(&e, &format!("--ranges {ranges_path}")))?;
    let summary = match &spec {
        ModelSpec::Icb { p_d, .. } => ModelSummary {
            kind: "icb",
            consistency: built.consistency,
            p_u: built.icb_p_u,
            p_d: *p_d,
            lambda: None,
            diameter_m: None,
            exact: None,
            training: None,
            table_cells: None,
        },
        ModelSpec::Ppp {
            lambda,
            diameter_m,
            p_d,
            exact,
        } => ModelSummary {
            kind: "ppp",
            consistency: built.consistency,
            p_u: None,
            p_d: Some(*p_d),
            lambda: Some(*lambda),
            diameter_m: Some(*diameter_m),
            exact: Some(*exact),
            training: None,
            table_cells: None,
        },
        ModelSpec::Empirical {
            p_d,
            table,
            training,
        } => ModelSummary {
            kind: "empirical",
            consistency: built.consistency,
            p_u: None,
            p_d: Some(*p_d),
            lambda: None,
            diameter_m: None,
            exact: None,
            training: *training,
            table_cells: table.as_ref().map(|t| [t.nx, t.ny]),
        },
    };
    let targets = target_reports(&network.map, &out.targets);
    let doc = LocateOut {
        model: &summary,
        t_e: cfg.t_e,
        t_b: cfg.t_b.is_finite().then_some(cfg.t_b),
        count: targets.len(),
        candidates: out.evaluated(),
        targets,
    };
    match out_path {
        None => emit(
            &serde_json::to_string(&doc)
                .map_err(|e| CliError::output(format!("encoding JSON: {e}")))?,
        ),
        Some(p) => {
            write_json_file("out", p, &doc)?;
            emit_summary(&format!(
                "{{\"count\":{},\"out\":{}}}",
                doc.count,
                serde_json::to_string(p).unwrap_or_default()
            ))
        }
    }
}
