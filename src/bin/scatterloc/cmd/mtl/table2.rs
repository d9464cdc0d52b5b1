//! `scatterloc mtl table2`: Table II of [A] (§8), the generator's "True" row and the i.c.b row.

use super::*;

/// Table II as printed in \[A\]: `[≤2, 3, …, 9]`.
const PAPER_TRUE: [f64; 8] = [0.0700, 0.0150, 0.0750, 0.0, 0.1750, 0.0, 0.0, 0.6650];
/// The i.c.b row as printed (the `≤ 2` entry is a typo per spec check 4).
const PAPER_ICB: [f64; 8] = [
    0.3367, 0.1961, 0.2578, 0.2259, 0.1320, 0.0496, 0.0109, 0.0011,
];
/// Largest `--draws` of `mtl table2`.
const MAX_DRAWS: usize = 10_000_000;

/// One row of Table II in the JSON file.
#[derive(Serialize)]
struct Table2Row {
    /// `P(k DPs)`, `k = 0..=M`.
    pmf: Vec<f64>,
    /// `[P(≤ 2), P(3), …, P(M)]`.
    buckets: Vec<f64>,
    /// The paper's values of the same buckets.
    paper: [f64; 8],
}

/// The `--json` file of `mtl table2`.
#[derive(Serialize)]
struct Table2Doc {
    columns: Vec<String>,
    #[serde(rename = "true")]
    true_row: Table2Row,
    icb: Table2Row,
    draws: usize,
    realisations: usize,
    seed: u64,
    icb_p_u: f64,
    diameter_m: f64,
    lambda: f64,
    p_d: f64,
}

/// `scatterloc mtl table2`.
pub fn mtl_table2(args: &Table2Args) -> Result<(), CliError> {
    let draws = args.draws.unwrap_or(100_000);
    if !(1..=MAX_DRAWS).contains(&draws) {
        return Err(CliError::usage(format!(
            "--draws: {draws} is outside the allowed range 1..={MAX_DRAWS}"
        )));
    }
    let seed = args.seed.unwrap_or(1);
    let json = match args.json.as_deref() {
        Some(p) => {
            Format::of("json", p, &[Format::Json])?;
            check_writable("json", p)?;
            Some(p)
        }
        None => None,
    };
    let s = SimSettings::vb();
    let k = s.targets;
    let realisations = draws.div_ceil(k);
    let map = s.map().map_err(|e| core_error(&e, "table2"))?;
    let truth = true_row(&s, seed, realisations as u64).map_err(|e| core_error(&e, "table2"))?;
    let icb = icb_row(map, VB_ICB_P_U).map_err(|e| core_error(&e, "table2"))?;
    let (tb, ib) = (table2_buckets(&truth), table2_buckets(&icb));
    let columns: Vec<String> = std::iter::once("<=2".to_string())
        .chain((3..=map.n_trps()).map(|k| k.to_string()))
        .collect();

    let mut text = String::new();
    text.push_str("Table II (V-B): distribution of the number of DPs at a target point\n");
    text.push_str(&format!("{:<13}", "DPs"));
    for c in &columns {
        text.push_str(&format!("{:>8}", c.replace("<=", "≤")));
    }
    text.push('\n');
    let row = |name: &str, v: &[f64], mark: Option<usize>| {
        let mut line = format!("{name:<13}");
        for (i, x) in v.iter().enumerate() {
            let cell = format!("{x:.4}{}", if mark == Some(i) { "*" } else { "" });
            line.push_str(&format!("{cell:>8}"));
        }
        line.push('\n');
        line
    };
    text.push_str(&row("True", &tb, None));
    text.push_str(&row("  paper", &PAPER_TRUE, None));
    text.push_str(&row("i.c.b", &ib, None));
    text.push_str(&row("  paper", &PAPER_ICB, Some(0)));
    text.push_str(&format!(
        "True: {} target draws ({realisations} realisations × K = {k}) of the §7 generator, \
         V-B defaults (D = {} m, λ = {} m⁻², p_d = {}), seed {seed}.\n",
        realisations * k,
        s.diameter,
        s.lambda,
        s.p_d
    ));
    text.push_str(&format!(
        "i.c.b: Binomial({}, 1 − p_u) with p_u = {VB_ICB_P_U} (spec check 4).\n",
        map.n_trps()
    ));
    text.push_str(&format!(
        "* the paper prints 0.3367 (its row then sums to 1.21): a typo (spec check 4); the \
         Binomial value is {:.4}.",
        ib[0]
    ));
    if let Some(p) = json {
        let doc = Table2Doc {
            columns,
            true_row: Table2Row {
                pmf: truth,
                buckets: tb,
                paper: PAPER_TRUE,
            },
            icb: Table2Row {
                pmf: icb,
                buckets: ib,
                paper: PAPER_ICB,
            },
            draws: realisations * k,
            realisations,
            seed,
            icb_p_u: VB_ICB_P_U,
            diameter_m: s.diameter,
            lambda: s.lambda,
            p_d: s.p_d,
        };
        write_json_file("json", p, &doc)?;
        return emit_summary(&text);
    }
    emit(&text)
}
