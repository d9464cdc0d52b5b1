//! Flags of the multi-target commands `mtl locate|table2|roc` (spec `multi-target.md`).

use clap::{Args, Subcommand};

use super::shard::ShardArgs;

use super::values::{
    count_or_inf, finite, probability, seed, threshold, threshold_or_inf, trp_order, whole,
    MtlModel, RocExperiment, TrpOrder,
};

/// `scatterloc mtl SUBCOMMAND`.
// Parsed once and moved once: the size of the largest variant does not matter.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Subcommand)]
pub enum MtlCommand {
    /// Locate several targets from per-TRP range lists (spec multi-target.md §4, Algorithm 1).
    ///
    /// Each TRP (transmitter-receiver pair) gives a list of bistatic ranges, each of which may
    /// be a target, a ghost or clutter. Algorithm 1 matches ranges across TRPs into candidate
    /// positions and keeps those a blocking model explains (§4-§6).
    ///
    /// Network file: {"tx": [[x, y], ..], "rx": [[x, y], ..], "region": {"min_m": [x, y],
    /// "max_m": [x, y]} (optional), "c_sigma_m": 0.1 (optional)}. Ranges file: {"ranges_m": [[r,
    /// ..] per TRP]}, TRP m (0-based) = TX m mod N_t, RX m div N_t.
    ///
    /// Models: icb (p_u, or 1 - p_d p_LoS^2; default p_d = p_LoS = 0.9), ppp (lambda 0.03, D 0.6
    /// m, p_d 0.9; --exact: M11), empirical (--table: EmpiricalTable JSON, else trained on the
    /// network from --lambda/--diameter).
    ///
    /// Prints {model, t_e, t_b, count, targets: [{position_m, matching: [[trp, mpc], ..], j,
    /// l_b, g: [0/1 per TRP], family}]} (with --out: the file, and {count, out} on stdout).
    Locate(MtlLocateArgs),
    /// Table II of [A]: the distribution of the number of direct paths at a target (spec multi-target.md §8).
    ///
    /// The "True" row from the generator of §7 with the V-B defaults, next to the i.c.b
    /// Binomial(9, 1 - 0.5329) row and the paper's values (spec check 4). Prints the table;
    /// --json also writes {columns, true, icb, draws, realisations, seed, ..}.
    Table2(Table2Args),
    /// The experiments of [A] Figs. 3-5: ROC and miss curves (spec multi-target.md §8).
    ///
    /// va = Fig. 3, ROC over T_e (size rule vs Bayesian i.c.b); vb = Fig. 4, ROC over T_b (PPP
    /// vs i.c.b); vc = Fig. 5, 1 - P_D over T_b (Bayesian vs genie). --empirical adds the
    /// empirical model (vb, vc); --exact uses (M11) for PPP.
    ///
    /// Progress on stderr; Ctrl-C stops (exit 130, no files written). Prints a summary table;
    /// --json: {config, curves: [{method, label, points: [{threshold, p_d, p_fa, detections,
    /// false_alarms, estimates}]}], disagreements, ..}. With --shard I/N: only realisations
    /// [I*R/N, (I+1)*R/N) into the part file --json PART.json (see `scatterloc merge`).
    Roc(RocArgs),
}

/// `scatterloc mtl locate`.
#[derive(Debug, Args)]
pub struct MtlLocateArgs {
    /// Network JSON file ('-' = standard input): transmitters, receivers, optional region.
    #[arg(long, value_name = "FILE")]
    pub network: String,
    /// Ranges JSON file ('-' = standard input): {"ranges_m": [[r, ..] per TRP]}, m.
    #[arg(long, value_name = "FILE")]
    pub ranges: String,
    /// Blocking model that scores candidates [default: icb].
    #[arg(long, value_name = "MODEL", ignore_case = true)]
    pub model: Option<MtlModel>,
    /// Ellipse-test threshold T_e, in units of sigma_e (M6), >= 0 [default: 3].
    #[arg(long, value_name = "T", value_parser = threshold)]
    pub te: Option<f64>,
    /// Blocking-test threshold T_b, nats, >= 0 or inf [default: 20].
    #[arg(long, value_name = "T|inf", value_parser = threshold_or_inf)]
    pub tb: Option<f64>,
    /// Largest number of candidates per family B_max, >= 1 or inf [default: 16].
    #[arg(long, value_name = "N|inf", value_parser = count_or_inf)]
    pub b_max: Option<usize>,
    /// Work budget: the most candidates Algorithm 1 may evaluate, 1 ..= 100000000 (about 4 us
    /// and at most 100 bytes each) [default: 250000].
    #[arg(long, value_name = "N", value_parser = whole)]
    pub max_candidates: Option<usize>,
    /// Smallest matching size n_min of a target (TRPs that see it) [default: 3].
    #[arg(long, value_name = "N", value_parser = whole)]
    pub n_min: Option<usize>,
    /// TRP order pi: a permutation of the 0-based TRPs, comma-separated [default: 0,1,2,..].
    #[arg(long, value_name = "0,1,..", value_parser = trp_order)]
    pub order: Option<TrpOrder>,
    /// icb: probability p_u that a TRP misses a target (instead of --p-d/--p-los).
    #[arg(long, value_name = "P", value_parser = probability)]
    pub p_u: Option<f64>,
    /// Detection probability p_d [default: 0.9].
    #[arg(long, value_name = "P", value_parser = probability)]
    pub p_d: Option<f64>,
    /// icb: line-of-sight probability p_LoS of each node [default: 0.9].
    #[arg(long, value_name = "P", value_parser = probability)]
    pub p_los: Option<f64>,
    /// ppp, empirical: blocker density lambda, 1/m^2 [default: 0.03].
    #[arg(long, value_name = "L", value_parser = finite)]
    pub lambda: Option<f64>,
    /// ppp, empirical: blocker diameter D, m [default: 0.6].
    #[arg(long, value_name = "D", value_parser = finite)]
    pub diameter: Option<f64>,
    /// ppp: the exact blocking probability (M11) instead of the approximation.
    #[arg(long)]
    pub exact: bool,
    /// empirical: an EmpiricalTable JSON file (instead of training one).
    #[arg(long, value_name = "FILE")]
    pub table: Option<String>,
    /// empirical training: grid cells per axis [default: 20].
    #[arg(long, value_name = "N", value_parser = whole)]
    pub cells: Option<usize>,
    /// empirical training: random scenes [default: 400].
    #[arg(long, value_name = "N", value_parser = whole)]
    pub scenes: Option<usize>,
    /// empirical training: random seed [default: 1].
    #[arg(long, value_name = "N", value_parser = seed)]
    pub seed: Option<u64>,
    /// Write the result to this .json file; stdout then gets {count, out}.
    #[arg(long, value_name = "OUT.json")]
    pub out: Option<String>,
}

/// `scatterloc mtl table2`.
#[derive(Debug, Args)]
pub struct Table2Args {
    /// Target draws of the generator, 1..=10000000 [default: 100000].
    #[arg(long, value_name = "N", value_parser = whole)]
    pub draws: Option<usize>,
    /// Random seed [default: 1].
    #[arg(long, value_name = "N", value_parser = seed)]
    pub seed: Option<u64>,
    /// Also write the table to this .json file.
    #[arg(long, value_name = "OUT.json")]
    pub json: Option<String>,
}

/// `scatterloc mtl roc`.
#[derive(Debug, Args)]
pub struct RocArgs {
    /// The experiment: va (Fig. 3), vb (Fig. 4) or vc (Fig. 5).
    #[arg(
        long,
        value_name = "va|vb|vc",
        ignore_case = true,
        hide_possible_values = true
    )]
    pub experiment: RocExperiment,
    /// Random realisations, 1..=100000 [default: 100].
    #[arg(long, value_name = "N", value_parser = whole)]
    pub realizations: Option<usize>,
    /// Random seed [default: 1].
    #[arg(long, value_name = "N", value_parser = seed)]
    pub seed: Option<u64>,
    /// Worker threads, 0..=256, 0 = all cores [default: 0].
    #[arg(long, value_name = "N", value_parser = whole)]
    pub threads: Option<usize>,
    /// Add the empirical model (vb, vc).
    #[arg(long)]
    pub empirical: bool,
    /// Use the exact PPP blocking probability (M11) (vb, vc).
    #[arg(long)]
    pub exact: bool,
    /// Work budget of Algorithm 1 per run, candidates, 1 ..= 100000000 (see `mtl locate`)
    /// [default: 250000].
    #[arg(long, value_name = "N", value_parser = whole)]
    pub max_candidates: Option<usize>,
    /// Figure: .svg or .png.
    #[arg(long, value_name = "FIG.{svg,png}")]
    pub out: Option<String>,
    /// The curves as a .json file (with --shard: the part file).
    #[arg(long, value_name = "OUT.json")]
    pub json: Option<String>,
    #[command(flatten)]
    pub shard: ShardArgs,
}
