//! Experiment configuration (spec `multi-target.md` §8): which experiment, its generator
//! settings, sweep and every reconstruction choice, and the curves it produces.

use alloc::string::String;
use alloc::vec::Vec;

use crate::error::{Error, Result};
use crate::math::Real;
use crate::mtl::algorithm::MtlConfig;
use crate::mtl::sim::{SimSettings, VB_ICB_P_U};

/// Largest number of realisations of one experiment.
pub const MAX_REALISATIONS: usize = 100_000;

/// Largest number of sweep points.
pub const MAX_SWEEP_POINTS: usize = 1000;

/// Which experiment of §8.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Experiment {
    /// V-A, Fig. 3: ROC over `T_e` per `N_u`, size rule vs Bayesian MTL with i.c.b and (M8).
    Va,
    /// V-B, Fig. 4: ROC over `T_b`, PPP (M10 or M11) vs i.c.b (`p_u = 0.5329`) [vs empirical].
    Vb,
    /// V-C, Fig. 5: `1 − P_D` over `T_b`, Bayesian MTL (PPP) vs the genie.
    Vc,
}

impl Experiment {
    /// `"va"`, `"vb"`, `"vc"`.
    pub fn name(self) -> &'static str {
        match self {
            Experiment::Va => "va",
            Experiment::Vb => "vb",
            Experiment::Vc => "vc",
        }
    }

    /// The swept threshold: `"T_e"` (V-A) or `"T_b"` (V-B, V-C).
    pub fn swept(self) -> &'static str {
        match self {
            Experiment::Va => "T_e",
            Experiment::Vb | Experiment::Vc => "T_b",
        }
    }

    /// Parses `va`, `vb`, `vc` (case-insensitive).
    pub fn parse(s: &str) -> Option<Experiment> {
        match s.to_ascii_lowercase().as_str() {
            "va" | "v-a" => Some(Experiment::Va),
            "vb" | "v-b" => Some(Experiment::Vb),
            "vc" | "v-c" => Some(Experiment::Vc),
            _ => None,
        }
    }
}

/// Training of the empirical model (§6.3) for each V-B realisation's network.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EmpiricalTraining {
    /// Cells per side of the grid over `R` (**\[P\]** 20, i.e. 0.5 m cells).
    pub cells: usize,
    /// Simulated disc scenes (**\[P\]** 400; one point per cell per scene).
    pub scenes: usize,
}

impl Default for EmpiricalTraining {
    fn default() -> Self {
        Self {
            cells: 20,
            scenes: 400,
        }
    }
}

/// Everything an experiment run depends on (with the seed).
#[derive(Debug, Clone, PartialEq)]
pub struct ExperimentConfig {
    /// Which experiment.
    pub experiment: Experiment,
    /// Generator settings (§7; [`SimSettings::va`] or [`SimSettings::vb`]).
    pub settings: SimSettings,
    /// Realisations (§7: 100).
    pub realisations: usize,
    /// Seed; realisation `i` uses the stream `rng(seed, i)`.
    pub seed: u64,
    /// Swept threshold values (`T_e` for V-A, `T_b` for V-B/V-C), ascending.
    pub sweep: Vec<Real>,
    /// `N_u` values of V-A (**\[P\]** {2, 4, 6}).
    pub n_u: Vec<usize>,
    /// Fixed `T_e` of V-B and V-C (**\[P\]** 3).
    pub t_e: Real,
    /// `p_u` of the V-B i.c.b curve (**\[D\]** 0.5329, Table II).
    pub icb_p_u: Real,
    /// PPP likelihood: `false` = the bound (M10) of \[A\] (default), `true` = exact (M11).
    pub ppp_exact: bool,
    /// Add an empirical-model curve to V-B (and V-C) with this training; `None` = no.
    pub empirical: Option<EmpiricalTraining>,
    /// Algorithm 1 settings shared by every curve (`t_e`, `t_b`, `final_test`, `consistency`
    /// and `stage_blocking_test` are set per curve).
    pub mtl: MtlConfig,
}

/// `start, start + step, …, ≤ stop` (inclusive up to rounding).
pub fn grid(start: Real, stop: Real, step: Real) -> Vec<Real> {
    if !(step > 0.0 && start.is_finite() && stop.is_finite()) || stop < start {
        return Vec::new();
    }
    let n = ((stop - start) / step + 1e-9) as usize;
    (0..=n.min(MAX_SWEEP_POINTS))
        .map(|i| start + step * i as Real)
        .collect()
}

impl ExperimentConfig {
    /// The §7/§8 defaults of `experiment`: V-A hexagon, `T_e ∈ {0.5, 1, …, 5}`, `N_u ∈ {2, 4,
    /// 6}`, `B_max = ∞` (check 6); V-B/V-C random 3×3, `T_e = 3`, `T_b ∈ [0, 20]` step 0.25;
    /// 100 realisations, seed 1.
    pub fn new(experiment: Experiment) -> ExperimentConfig {
        let va = experiment == Experiment::Va;
        let settings = if va {
            SimSettings::va()
        } else {
            SimSettings::vb()
        };
        let mtl = MtlConfig {
            region: Some(settings.region),
            b_max: if va { usize::MAX } else { 16 },
            ..MtlConfig::default()
        };
        ExperimentConfig {
            experiment,
            settings,
            realisations: 100,
            seed: 1,
            sweep: if va {
                grid(0.5, 5.0, 0.5)
            } else {
                grid(0.0, 20.0, 0.25)
            },
            n_u: alloc::vec![2, 4, 6],
            t_e: 3.0,
            icb_p_u: VB_ICB_P_U,
            ppp_exact: false,
            empirical: None,
            mtl,
        }
    }

    /// Checks the configuration. Errors: those of [`SimSettings::validate`];
    /// [`Error::SizeLimit`] (`realisations` in 1..=[`MAX_REALISATIONS`], `sweep` in
    /// 1..=[`MAX_SWEEP_POINTS`] points, `n_u` non-empty for V-A); [`Error::OutOfRange`]
    /// (`sweep[i]`) for a negative or non-finite threshold, (`n_u[i]`) for `N_u > M`,
    /// (`t_e`), (`icb_p_u`) outside `(0, 1)`; [`Error::OutOfRange`] (`los`) when V-A is not run
    /// with independent blocking; [`Error::SizeLimit`] (`empirical.cells`, `empirical.scenes`).
    pub fn validate(&self) -> Result<()> {
        self.settings.validate()?;
        let size = |field, value: usize, min, max| {
            if (min..=max).contains(&value) {
                Ok(())
            } else {
                Err(Error::SizeLimit {
                    field,
                    value,
                    min,
                    max,
                })
            }
        };
        size("realisations", self.realisations, 1, MAX_REALISATIONS)?;
        size("sweep", self.sweep.len(), 1, MAX_SWEEP_POINTS)?;
        for (i, &t) in self.sweep.iter().enumerate() {
            if !(t.is_finite() && t >= 0.0) {
                return Err(Error::OutOfRange {
                    field: alloc::format!("sweep[{i}]"),
                    value: t,
                    allowed: "a finite threshold ≥ 0",
                });
            }
        }
        if !(self.t_e.is_finite() && self.t_e >= 0.0) {
            return Err(Error::OutOfRange {
                field: "t_e".into(),
                value: self.t_e,
                allowed: "a finite threshold ≥ 0",
            });
        }
        if !(self.icb_p_u > 0.0 && self.icb_p_u < 1.0) {
            return Err(Error::OutOfRange {
                field: "icb_p_u".into(),
                value: self.icb_p_u,
                allowed: "0 < p_u < 1",
            });
        }
        let m = self.settings.map()?.n_trps();
        if self.experiment == Experiment::Va {
            size("n_u", self.n_u.len(), 1, 64)?;
            if let Some((i, &n)) = self.n_u.iter().enumerate().find(|(_, &n)| n > m) {
                return Err(Error::OutOfRange {
                    field: alloc::format!("n_u[{i}]"),
                    value: n as Real,
                    allowed: "0 ≤ N_u ≤ M",
                });
            }
            if !matches!(
                self.settings.los,
                crate::mtl::sim::LosModel::Independent { .. }
            ) {
                return Err(Error::OutOfRange {
                    field: "los".into(),
                    value: 0.0,
                    allowed: "V-A needs independent blocking (the i.c.b assumption)",
                });
            }
        }
        if let Some(e) = self.empirical {
            size("empirical.cells", e.cells, 1, 256)?;
            size(
                "empirical.scenes",
                e.scenes,
                1,
                crate::mtl::empirical::MAX_TRAINING_SCENES,
            )?;
        }
        Ok(())
    }

    /// The curves this configuration produces, in output order.
    pub fn curves(&self) -> Vec<CurveSpec> {
        let mut out = Vec::new();
        match self.experiment {
            Experiment::Va => {
                for &n_u in &self.n_u {
                    out.push(CurveSpec {
                        method: Method::SizeRule,
                        n_u: Some(n_u),
                    });
                    out.push(CurveSpec {
                        method: Method::Icb,
                        n_u: Some(n_u),
                    });
                }
            }
            Experiment::Vb => {
                out.push(CurveSpec::new(Method::Ppp));
                out.push(CurveSpec::new(Method::Icb));
                if self.empirical.is_some() {
                    out.push(CurveSpec::new(Method::Empirical));
                }
            }
            Experiment::Vc => {
                out.push(CurveSpec::new(Method::Ppp));
                out.push(CurveSpec::new(Method::Genie));
                if self.empirical.is_some() {
                    out.push(CurveSpec::new(Method::Empirical));
                }
            }
        }
        out
    }
}

/// A detection method of the experiments.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Method {
    /// \[SM\]'s size rule `|ℳ| ≥ M − N_u` (V-A).
    SizeRule,
    /// Bayesian MTL with the i.c.b likelihood (V-A with `T_b` from (M8); V-B with the swept `T_b`).
    Icb,
    /// Bayesian MTL with the PPP likelihood (M10 or M11).
    Ppp,
    /// Bayesian MTL with the empirical model (§6.3), trained per network.
    Empirical,
    /// The genie-aided method of Fig. 5 (true matchings, PPP likelihood).
    Genie,
}

impl Method {
    /// Short machine name.
    pub fn name(self) -> &'static str {
        match self {
            Method::SizeRule => "size_rule",
            Method::Icb => "icb",
            Method::Ppp => "ppp",
            Method::Empirical => "empirical",
            Method::Genie => "genie",
        }
    }
}

/// One curve: a method and (V-A) its `N_u`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CurveSpec {
    /// The method.
    pub method: Method,
    /// `N_u` (V-A only).
    pub n_u: Option<usize>,
}

impl CurveSpec {
    fn new(method: Method) -> CurveSpec {
        CurveSpec { method, n_u: None }
    }

    /// A legend label, e.g. `Bayesian MTL, i.c.b (N_u = 2)`.
    pub fn label(&self, cfg: &ExperimentConfig) -> String {
        let base = match self.method {
            Method::SizeRule => String::from("size rule [SM]"),
            Method::Icb => alloc::format!(
                "Bayesian MTL, i.c.b{}",
                if cfg.experiment == Experiment::Va {
                    String::new()
                } else {
                    alloc::format!(" (p_u = {})", cfg.icb_p_u)
                }
            ),
            Method::Ppp => String::from(if cfg.ppp_exact {
                "Bayesian MTL, PPP (M11 exact)"
            } else {
                "Bayesian MTL, PPP (M10 bound)"
            }),
            Method::Empirical => String::from("Bayesian MTL, empirical (§6.3)"),
            Method::Genie => String::from("genie-aided, PPP"),
        };
        match self.n_u {
            Some(n) => alloc::format!("{base}, N_u = {n}"),
            None => base,
        }
    }
}
