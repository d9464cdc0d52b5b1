//! Value parsers of the flags: each returns the message of a bad value without the flag, which
//! [`super::one_line`] puts in front (`--at: expected X,Y …`). The messages are those of the
//! hand-written parser this replaced.

use clap::ValueEnum;
use scatterloc::error::limits;

/// A finite number (`--dt 0.1`, `--x-min -5`).
pub fn finite(v: &str) -> Result<f64, String> {
    v.trim()
        .parse::<f64>()
        .ok()
        .filter(|x| x.is_finite())
        .ok_or_else(|| format!("expected a finite number, got '{v}'"))
}

/// A non-negative whole number (`--runs 5000`).
pub fn whole(v: &str) -> Result<usize, String> {
    v.trim()
        .parse::<usize>()
        .map_err(|_| format!("expected a whole number, got '{v}'"))
}

/// A random seed: a non-negative whole number.
pub fn seed(v: &str) -> Result<u64, String> {
    whole(v).map(|s| s as u64)
}

/// `X,Y`: two numbers in metres, each within [`limits::COORDINATE_M`].
pub fn xy(v: &str) -> Result<[f64; 2], String> {
    let bad = || {
        format!(
            "expected X,Y (two numbers in metres, each {}), got '{v}'",
            limits::COORDINATE_M.allowed
        )
    };
    let (x, y) = v.split_once(',').ok_or_else(bad)?;
    let x: f64 = x.trim().parse().map_err(|_| bad())?;
    let y: f64 = y.trim().parse().map_err(|_| bad())?;
    if limits::COORDINATE_M.contains(x) && limits::COORDINATE_M.contains(y) {
        Ok([x, y])
    } else {
        Err(bad())
    }
}

/// `X0,X1,Y0,Y1`: a rectangle, four numbers in metres, each within [`limits::COORDINATE_M`]
/// (the order of the edges is checked where the rectangle is used).
pub fn rect(v: &str) -> Result<[f64; 4], String> {
    let bad = || {
        format!(
            "expected X0,X1,Y0,Y1 (four numbers in metres, each {}), got '{v}'",
            limits::COORDINATE_M.allowed
        )
    };
    let parts: Vec<&str> = v.split(',').collect();
    if parts.len() != 4 {
        return Err(bad());
    }
    let mut out = [0.0; 4];
    for (o, p) in out.iter_mut().zip(parts) {
        *o = p.trim().parse().map_err(|_| bad())?;
        if !limits::COORDINATE_M.contains(*o) {
            return Err(bad());
        }
    }
    Ok(out)
}

/// A probability in `[0, 1]`.
pub fn probability(v: &str) -> Result<f64, String> {
    match finite(v)? {
        p if (0.0..=1.0).contains(&p) => Ok(p),
        p => Err(format!("{p} is not a probability in [0, 1]")),
    }
}

/// A detection threshold: a finite number `≥ 0` (`--te`).
pub fn threshold(v: &str) -> Result<f64, String> {
    non_negative(finite(v)?)
}

/// A detection threshold that may be infinite: a number `≥ 0`, or `inf` / `∞` (`--tb`).
pub fn threshold_or_inf(v: &str) -> Result<f64, String> {
    match v.trim() {
        "inf" | "∞" => Ok(f64::INFINITY),
        _ => threshold(v),
    }
}

fn non_negative(t: f64) -> Result<f64, String> {
    if t < 0.0 {
        Err(format!("{t} is negative (a threshold must be ≥ 0)"))
    } else {
        Ok(t)
    }
}

/// A count `≥ 1`, or `inf` (no limit: `usize::MAX`) (`--b-max`).
pub fn count_or_inf(v: &str) -> Result<usize, String> {
    let n = if v.trim().eq_ignore_ascii_case("inf") {
        usize::MAX
    } else {
        whole(v)?
    };
    if n == 0 {
        return Err("must be ≥ 1 (or inf)".into());
    }
    Ok(n)
}

/// `--order 0,1,..`: 0-based TRP indices.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TrpOrder(pub Vec<usize>);

/// Parses [`TrpOrder`].
pub fn trp_order(v: &str) -> Result<TrpOrder, String> {
    v.split(',')
        .map(|t| t.trim().parse::<usize>())
        .collect::<Result<Vec<_>, _>>()
        .map(TrpOrder)
        .map_err(|_| format!("expected comma-separated 0-based TRP indices, got '{v}'"))
}

/// `--targets` of `track`: `auto` tracks an unknown number of targets (issue 41).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum TargetsMode {
    /// Every target the delays show: births, deaths and labels (docs/multi-target.md).
    Auto,
}

/// `--method` of `track --targets auto`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum MultiMethod {
    /// The PMB tracker with belief-propagation association.
    Pmb,
    /// Global nearest neighbour with an EKF per track (the baseline).
    Gnn,
}

/// `--association` of `track` (spec §4).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Association {
    /// One candidate is taken; of several the nearest to the prediction within 3σ, else the
    /// strongest.
    Spec,
    /// With a track only candidates within 3σ of the prediction (robust to false alarms and gate
    /// leaks).
    Gated,
}

impl Association {
    /// The name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Association::Spec => "spec",
            Association::Gated => "gated",
        }
    }
}

/// `--start` of `simulate-walk`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum WalkStart {
    /// The raw snapshot at t0 as `initial_snapshot` (the filter starts from its LM fix).
    Snapshot,
    /// The true state and P(t0) of spec §9.5 as `initial_state` / `initial_covariance`.
    Truth,
}

/// `--trajectory` of the studies: one of the trajectories of spec §9.4, or all three.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Trajectory {
    /// Trajectory I.
    #[value(name = "I", alias = "1")]
    One,
    /// Trajectory II.
    #[value(name = "II", alias = "2")]
    Two,
    /// Trajectory III.
    #[value(name = "III", alias = "3")]
    Three,
    /// I, II and III in turn.
    #[value(name = "all")]
    All,
}

/// `--model` of `mtl locate` (multi-target §5, §6).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum MtlModel {
    /// Independent, common blocking (i.c.b): p_u, or 1 - p_d p_LoS^2.
    #[value(alias = "i.c.b")]
    Icb,
    /// Poisson point process of blocking discs (lambda, D, p_d; --exact: M11).
    Ppp,
    /// Empirical LoS-pattern table (--table FILE, or trained on the network).
    Empirical,
}

/// `--experiment` of `mtl roc` (multi-target §8).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum RocExperiment {
    /// [A] Fig. 3: ROC over T_e, size rule vs Bayesian i.c.b.
    #[value(alias = "v-a")]
    Va,
    /// [A] Fig. 4: ROC over T_b, PPP vs i.c.b.
    #[value(alias = "v-b")]
    Vb,
    /// [A] Fig. 5: 1 - P_D over T_b, Bayesian vs genie.
    #[value(alias = "v-c")]
    Vc,
}

/// `--shard`: shard `I` of `N` (0-based), or `env` (from the batch system's variables).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ShardSpec {
    /// `I/N`, checked: `1 ≤ N ≤` [`scatterloc::math::MAX_SHARDS`], `I < N`.
    Given(scatterloc::math::Shard),
    /// `env`: `SLURM_ARRAY_TASK_ID` (+ `SLURM_ARRAY_TASK_COUNT`) or `JOB_COMPLETION_INDEX`
    /// (+ `--shards N`).
    Env,
}

/// Parses [`ShardSpec`]: `I/N` or `env`.
pub fn shard_spec(v: &str) -> Result<ShardSpec, String> {
    use scatterloc::math::{Shard, MAX_SHARDS};
    let t = v.trim();
    if t.eq_ignore_ascii_case("env") {
        return Ok(ShardSpec::Env);
    }
    let bad = || {
        format!("expected I/N (shard I of N, 0-based: 0 ≤ I < N ≤ {MAX_SHARDS}) or env, got '{v}'")
    };
    let (i, n) = t.split_once('/').ok_or_else(bad)?;
    let i: usize = i.trim().parse().map_err(|_| bad())?;
    let n: usize = n.trim().parse().map_err(|_| bad())?;
    Shard::new(i, n).map(ShardSpec::Given).ok_or_else(bad)
}
