//! Multi-target localization under correlated blocking (spec `multi-target.md`, paper [A]):
//! `mtl_locate` runs Algorithm 1 on per-TRP range lists — the library's
//! `mtl::input::locate_request`, as `scatterloc mtl locate`.

use pyo3::prelude::*;

use scatterloc::mtl::algorithm::MtlConfig;
use scatterloc::mtl::empirical::EmpiricalTable;
use scatterloc::mtl::input::{
    from_json, locate_request, LocateDoc, LocateRequest, ModelSpec, NetworkInput, RangesInput,
    RegionInput, TrainingSpec, DEFAULT_DIAMETER_M, DEFAULT_LAMBDA, DEFAULT_P_D,
};

use crate::convert::{array, to_json_text, to_python};
use crate::errors::{arg_error, Core};
use crate::run::run_job;

/// The targets found by `mtl_locate`.
#[pyclass(module = "scatterloc", frozen)]
pub struct MtlResult {
    /// The targets' positions, m, shape (K, 2).
    #[pyo3(get)]
    positions: Py<PyAny>,
    /// Per target its score J (M2), shape (K,).
    #[pyo3(get)]
    scores: Py<PyAny>,
    /// Per target its blocking likelihood L_b, nats, shape (K,).
    #[pyo3(get)]
    blocking: Py<PyAny>,
    /// Per target its observed blocking vector ĝ (1 = the direct path was matched at that
    /// TRP), shape (K, M).
    #[pyo3(get)]
    direct_paths: Py<PyAny>,
    /// Per target its matching: a list of (trp, index into ranges[trp]) pairs.
    #[pyo3(get)]
    matchings: Vec<Vec<(usize, usize)>>,
    /// Candidates evaluated (the work counted against `max_candidates`).
    #[pyo3(get)]
    candidates: usize,
    doc: LocateDoc,
}

#[pymethods]
impl MtlResult {
    /// The document `scatterloc mtl locate` prints for the same input.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_python(py, &self.doc)
    }

    fn __len__(&self) -> usize {
        self.doc.count
    }

    fn __repr__(&self) -> String {
        format!(
            "MtlResult(targets={}, candidates={})",
            self.doc.count, self.doc.candidates
        )
    }
}

/// `inf` or a whole number ≥ 0 as a count (`usize::MAX` = ∞).
fn count_or_inf(obj: &Bound<'_, PyAny>, field: &str) -> PyResult<usize> {
    if let Ok(n) = obj.extract::<usize>() {
        return Ok(n);
    }
    match obj.extract::<f64>() {
        Ok(v) if v == f64::INFINITY => Ok(usize::MAX),
        _ => Err(arg_error(field, "expected a whole number >= 1 or inf")),
    }
}

/// Several identical targets from unlabelled range lists (spec `multi-target.md` §4,
/// Algorithm 1 of [A]). `tx`, `rx`: node positions (N_t, 2), (N_r, 2), m; `ranges`: one list
/// per TRP of its measured bistatic ranges (m) in Table I order — TRP m uses Tx m mod N_t and
/// Rx m div N_t — any number per TRP. `region` `(x0, x1, y0, y1)` bounds the seeds (and the
/// PPP rectangles); `c_sigma` is the range noise cσ, m.
///
/// `model`: `"icb"` (`p_u`, or `p_d` and `p_los`), `"ppp"` (`lambda_`, `diameter`, `p_d`,
/// `exact`) or `"empirical"` (`table`, a dict as the CLI's `--table`, or trained on the
/// network from `lambda_`, `diameter`, `cells`, `scenes`, `seed`). A setting of another model is
/// an error naming it, as the CLI's flags. Algorithm 1: `te` (σ), `tb` (nats, may be inf),
/// `b_max` (may be inf), `n_min`, `order` (a TRP permutation), `max_candidates` (the work
/// budget). The same result as `scatterloc mtl locate` (`to_dict()` is its output).
#[pyfunction]
#[pyo3(signature = (
    tx, rx, ranges, *, region = None, c_sigma = 0.1, model = "icb", p_u = None, p_d = None,
    p_los = None, lambda_ = None, diameter = None, exact = None, table = None, cells = None,
    scenes = None, seed = None, te = None, tb = None, b_max = None, n_min = None, order = None,
    max_candidates = None
))]
#[allow(clippy::too_many_arguments)]
pub fn mtl_locate(
    py: Python<'_>,
    tx: &Bound<'_, PyAny>,
    rx: &Bound<'_, PyAny>,
    ranges: &Bound<'_, PyAny>,
    region: Option<(f64, f64, f64, f64)>,
    c_sigma: f64,
    model: &str,
    p_u: Option<f64>,
    p_d: Option<f64>,
    p_los: Option<f64>,
    lambda_: Option<f64>,
    diameter: Option<f64>,
    exact: Option<bool>,
    table: Option<&Bound<'_, PyAny>>,
    cells: Option<usize>,
    scenes: Option<usize>,
    seed: Option<u64>,
    te: Option<f64>,
    tb: Option<f64>,
    b_max: Option<&Bound<'_, PyAny>>,
    n_min: Option<usize>,
    order: Option<Vec<usize>>,
    max_candidates: Option<usize>,
) -> PyResult<MtlResult> {
    let given = [
        ("p_u", p_u.is_some()),
        ("p_los", p_los.is_some()),
        ("lambda_", lambda_.is_some()),
        ("diameter", diameter.is_some()),
        ("exact", exact.is_some()),
        ("table", table.is_some()),
        ("cells", cells.is_some()),
        ("scenes", scenes.is_some()),
        ("seed", seed.is_some()),
    ];
    let refuse = |names: &[&str], what: &str| -> PyResult<()> {
        match given.iter().find(|(n, g)| *g && names.contains(n)) {
            Some((n, _)) => Err(arg_error(n, format!("not used {what}"))),
            None => Ok(()),
        }
    };
    let training = ["lambda_", "diameter", "seed", "scenes", "cells"];
    let spec = match model {
        "icb" => {
            refuse(
                &[
                    "lambda_", "diameter", "exact", "table", "seed", "scenes", "cells",
                ],
                "with model='icb'",
            )?;
            if p_u.is_some() && (p_d.is_some() || p_los.is_some()) {
                return Err(arg_error("p_u", "give p_u or p_d/p_los, not both"));
            }
            ModelSpec::Icb { p_u, p_d, p_los }
        }
        "ppp" => {
            refuse(
                &["p_u", "p_los", "table", "seed", "scenes", "cells"],
                "with model='ppp'",
            )?;
            ModelSpec::Ppp {
                lambda: lambda_.unwrap_or(DEFAULT_LAMBDA),
                diameter_m: diameter.unwrap_or(DEFAULT_DIAMETER_M),
                p_d: p_d.unwrap_or(DEFAULT_P_D),
                exact: exact.unwrap_or(false),
            }
        }
        "empirical" => {
            refuse(&["p_u", "p_los", "exact"], "with model='empirical'")?;
            let p_d = p_d.unwrap_or(DEFAULT_P_D);
            match table {
                Some(t) => {
                    refuse(&training, "with a table (the table is given)")?;
                    let table: EmpiricalTable = from_json(&to_json_text(t, "table")?).py()?;
                    table.validate().py()?;
                    ModelSpec::Empirical {
                        p_d,
                        table: Some(table),
                        training: None,
                    }
                }
                None => {
                    let d = TrainingSpec::default();
                    ModelSpec::Empirical {
                        p_d,
                        table: None,
                        training: Some(TrainingSpec {
                            lambda: lambda_.unwrap_or(d.lambda),
                            diameter_m: diameter.unwrap_or(d.diameter_m),
                            cells: cells.unwrap_or(d.cells),
                            scenes: scenes.unwrap_or(d.scenes),
                            seed: seed.unwrap_or(d.seed),
                        }),
                    }
                }
            }
        }
        other => {
            return Err(arg_error(
                "model",
                format!("'{other}' is not 'icb', 'ppp' or 'empirical'"),
            ))
        }
    };
    let nodes = |obj: &Bound<'_, PyAny>, field: &str| -> PyResult<Vec<[f64; 2]>> {
        let (p, lead) = crate::convert::points(obj, field, scatterloc::error::limits::MAX_NODES)?;
        if lead.len() != 1 {
            return Err(arg_error(field, "expected node positions of shape (N, 2)"));
        }
        Ok(p)
    };
    let ranges_m: Vec<Vec<f64>> = ranges
        .extract()
        .map_err(|_| arg_error("ranges", "expected one list of ranges (m) per TRP"))?;
    let network = NetworkInput {
        tx: nodes(tx, "tx")?,
        rx: nodes(rx, "rx")?,
        region: region.map(|(x0, x1, y0, y1)| RegionInput {
            min_m: [x0, y0],
            max_m: [x1, y1],
        }),
        c_sigma_m: c_sigma,
    };
    let d = MtlConfig::default();
    let cfg = MtlConfig {
        t_e: te.unwrap_or(d.t_e),
        t_b: tb.unwrap_or(d.t_b),
        b_max: b_max
            .map(|b| count_or_inf(b, "b_max"))
            .transpose()?
            .unwrap_or(d.b_max),
        n_min: n_min.unwrap_or(d.n_min),
        max_candidates: max_candidates.unwrap_or(d.max_candidates),
        order,
        ..d
    };
    let req = LocateRequest {
        network,
        ranges: RangesInput { ranges_m },
        model: spec,
    };
    // Training an empirical table or a hard scene takes up to seconds: off the GIL. Algorithm 1
    // has no cancel point; its work is capped by `max_candidates` (≈ 1 s at the default), and
    // a Ctrl-C during it raises KeyboardInterrupt when it returns.
    let doc = run_job(py, 1, None, |_| {
        locate_request(&req, &cfg).map_err(|(_, e)| e)
    })?;
    let k = doc.targets.len();
    let trps = doc.targets.first().map_or(0, |t| t.g.len());
    let pos: Vec<f64> = doc.targets.iter().flat_map(|t| t.position_m).collect();
    Ok(MtlResult {
        positions: array(py, pos, &[k, 2])?.unbind(),
        scores: array(py, doc.targets.iter().map(|t| t.j).collect(), &[k])?.unbind(),
        blocking: array(py, doc.targets.iter().map(|t| t.l_b).collect(), &[k])?.unbind(),
        direct_paths: array(
            py,
            doc.targets
                .iter()
                .flat_map(|t| t.g.iter().map(|&g| g as i64))
                .collect(),
            &[k, trps],
        )?
        .unbind(),
        matchings: doc
            .targets
            .iter()
            .map(|t| t.matching.iter().map(|m| (m[0], m[1])).collect())
            .collect(),
        candidates: doc.candidates,
        doc,
    })
}
