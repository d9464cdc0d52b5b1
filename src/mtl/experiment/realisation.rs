//! One realisation of an experiment (spec `multi-target.md` §8): generate it (§7), build the
//! blocking models for its network, run Algorithm 1 for every curve and threshold, and count
//! detections and false alarms (M12).

use alloc::vec::Vec;

use crate::error::{Error, Result};
use crate::math::Vec2;
use crate::measure::rng;
use crate::mtl::algorithm::{
    locate_cached, FinalTest, IntersectionCache, Measurements, MtlConfig, Target,
};
use crate::mtl::blocking::{
    BlockingModel, NodeBlockingModel, NodeTableCache, TableCached, TABLE_GRID_M,
};
use crate::mtl::empirical::{EmpiricalNodeModel, EmpiricalTable};
use crate::mtl::experiment::memo::Memoized;
use crate::mtl::experiment::{genie, Experiment, ExperimentConfig, Method};
use crate::mtl::icb::IcbModel;
use crate::mtl::ppp::{PppBlocking, PppNodeModel};
use crate::mtl::sim::{count_detections, generate, DetectionCounts, LosModel, Realisation};

/// Stream offset of the empirical model's training draws: realisation `i` trains on the stream
/// `rng(seed, TRAINING_STREAM + i)`, disjoint from the generator's `rng(seed, i)`.
pub const TRAINING_STREAM: u64 = 1 << 40;

/// What one realisation contributes to the sums.
#[derive(Debug, Clone, PartialEq)]
pub struct RealisationCounts {
    /// Targets `K`.
    pub targets: usize,
    /// `[curve][point]` counts, curves in [`ExperimentConfig::curves`] order.
    pub counts: Vec<Vec<DetectionCounts>>,
    /// V-A: thresholds at which the size rule and Bayesian i.c.b disagreed (check 6: 0).
    pub disagreements: u64,
}

/// The estimates' positions.
fn positions(targets: &[Target]) -> Vec<Vec2> {
    targets.iter().map(|t| t.position).collect()
}

/// Realisation `index` of `cfg` (not validated here; see [`ExperimentConfig::validate`]).
///
/// Errors: those of the generator ([`generate`]) and of the models' constructors;
/// [`crate::Error::WorkLimit`] (`realisation {index}: ranges`) when Algorithm 1 exceeds its
/// budget on this realisation.
pub fn evaluate(cfg: &ExperimentConfig, index: u64) -> Result<RealisationCounts> {
    evaluate_unnamed(cfg, index).map_err(|e| match e {
        crate::Error::WorkLimit { field, limit } => crate::Error::WorkLimit {
            field: alloc::format!("realisation {index}: {field}"),
            limit,
        },
        e => e,
    })
}

fn evaluate_unnamed(cfg: &ExperimentConfig, index: u64) -> Result<RealisationCounts> {
    let s = &cfg.settings;
    let r = generate(s, cfg.seed, index)?;
    let ranges = r.ranges();
    let input = Measurements {
        tx: &r.scene.tx,
        rx: &r.scene.rx,
        ranges: &ranges,
        c_sigma_m: s.range_sigma,
    };
    let mut run = Runner {
        cfg,
        input,
        truth: &r.scene.targets,
        cache: IntersectionCache::new(),
    };
    let (counts, disagreements) = match cfg.experiment {
        Experiment::Va => run.va()?,
        Experiment::Vb | Experiment::Vc => (run.vb_vc(&r, index)?, 0),
    };
    Ok(RealisationCounts {
        targets: r.scene.targets.len(),
        counts,
        disagreements,
    })
}

struct Runner<'a> {
    cfg: &'a ExperimentConfig,
    input: Measurements<'a>,
    truth: &'a [Vec2],
    cache: IntersectionCache,
}

impl Runner<'_> {
    fn count(&self, estimates: &[Vec2]) -> DetectionCounts {
        count_detections(self.truth, estimates, self.cfg.settings.detection_radius)
    }

    fn run<B: BlockingModel + ?Sized>(
        &mut self,
        model: &B,
        mtl: &MtlConfig,
    ) -> Result<Vec<Target>> {
        Ok(locate_cached(&self.input, model, mtl, &mut self.cache)?.targets)
    }

    /// V-A: per `N_u`, the size rule and Bayesian i.c.b with `T_b(N_u)` (M8), sweeping `T_e`.
    fn va(&mut self) -> Result<(Vec<Vec<DetectionCounts>>, u64)> {
        let s = &self.cfg.settings;
        let LosModel::Independent { p_los } = s.los else {
            return Err(Error::OutOfRange {
                field: "los".into(),
                value: 0.0,
                allowed: "V-A needs independent blocking (the i.c.b assumption)",
            });
        };
        let map = s.map()?;
        let m = map.n_trps();
        let icb = IcbModel::new(map, s.p_d, p_los)?;
        // i.c.b: every vector is consistent (§6.1), B_max as configured (∞ for check 6).
        let base = MtlConfig {
            consistency: false,
            ..self.cfg.mtl.clone()
        };
        let mut counts = Vec::new();
        let mut disagreements = 0;
        for &n_u in &self.cfg.n_u {
            let t_b = icb.threshold(n_u)?;
            let (mut size, mut bayes) = (Vec::new(), Vec::new());
            for &t_e in &self.cfg.sweep {
                let size_cfg = MtlConfig {
                    t_e,
                    final_test: FinalTest::Size {
                        min_matched: m - n_u,
                    },
                    stage_blocking_test: false,
                    ..base.clone()
                };
                let bayes_cfg = MtlConfig {
                    t_e,
                    t_b,
                    ..base.clone()
                };
                let a = self.run(&icb, &size_cfg)?;
                let b = self.run(&icb, &bayes_cfg)?;
                let same = a.len() == b.len()
                    && a.iter()
                        .zip(&b)
                        .all(|(x, y)| x.matching == y.matching && x.position == y.position);
                disagreements += u64::from(!same);
                size.push(self.count(&positions(&a)));
                bayes.push(self.count(&positions(&b)));
            }
            counts.push(size);
            counts.push(bayes);
        }
        Ok((counts, disagreements))
    }

    /// Bayesian MTL with `model` at `T_e = cfg.t_e`, sweeping `T_b`.
    fn sweep_tb<B: BlockingModel + ?Sized>(
        &mut self,
        model: &B,
        consistency: bool,
    ) -> Result<Vec<DetectionCounts>> {
        let base = self.sweep_config(consistency);
        let model = Memoized::new(model);
        let mut out = Vec::with_capacity(self.cfg.sweep.len());
        for &t_b in &self.cfg.sweep {
            let targets = self.run(
                &model,
                &MtlConfig {
                    t_b,
                    ..base.clone()
                },
            )?;
            out.push(self.count(&positions(&targets)));
        }
        Ok(out)
    }

    /// The genie (Fig. 5) with `model` at `T_e = cfg.t_e`, sweeping `T_b`.
    fn sweep_genie<B: BlockingModel + ?Sized>(
        &mut self,
        r: &Realisation,
        model: &B,
    ) -> Result<Vec<DetectionCounts>> {
        let model = Memoized::new(model);
        let base = self.sweep_config(true);
        let mut caches = Vec::new();
        let mut out = Vec::with_capacity(self.cfg.sweep.len());
        for &t_b in &self.cfg.sweep {
            let mtl = MtlConfig {
                t_b,
                ..base.clone()
            };
            let r_det = self.cfg.settings.detection_radius;
            let found = genie::detections(&self.input, r, &model, &mtl, r_det, &mut caches)?;
            out.push(self.count(&found));
        }
        Ok(out)
    }

    /// The Bayesian settings of the `T_b` sweeps.
    fn sweep_config(&self, consistency: bool) -> MtlConfig {
        MtlConfig {
            t_e: self.cfg.t_e,
            consistency,
            final_test: FinalTest::Blocking,
            stage_blocking_test: true,
            ..self.cfg.mtl.clone()
        }
    }

    /// V-B / V-C: the PPP, i.c.b, empirical and genie curves, sweeping `T_b`.
    fn vb_vc(&mut self, r: &Realisation, index: u64) -> Result<Vec<Vec<DetectionCounts>>> {
        let cfg = self.cfg;
        let s = &cfg.settings;
        let map = s.map()?;
        let (tx, rx) = (r.scene.tx.clone(), r.scene.rx.clone());
        let ppp = NodeBlockingModel::new(
            map,
            PppNodeModel::new(
                PppBlocking::new(s.lambda, s.diameter, Some(s.region), cfg.ppp_exact)?,
                tx.clone(),
                rx.clone(),
            )?,
            s.p_d,
        )?;
        // Node tables by location, shared by the PPP curve and the genie (same model).
        let ppp_tables = NodeTableCache::default();
        let mut out = Vec::new();
        for spec in cfg.curves() {
            let curve = match spec.method {
                Method::Ppp => {
                    self.sweep_tb(&TableCached::on_grid(&ppp, &ppp_tables, TABLE_GRID_M), true)?
                }
                Method::Icb => {
                    let icb = IcbModel::from_p_u(map, cfg.icb_p_u)?;
                    self.sweep_tb(&icb, false)?
                }
                Method::Empirical => {
                    let training = cfg.empirical.unwrap_or_default();
                    let mut table = EmpiricalTable::new(
                        &s.region,
                        training.cells,
                        training.cells,
                        map.n_tx(),
                        map.n_rx(),
                    )?;
                    table.train_discs(
                        &tx,
                        &rx,
                        s.lambda,
                        s.diameter,
                        training.scenes,
                        &mut rng(cfg.seed, TRAINING_STREAM + index),
                    )?;
                    let model =
                        NodeBlockingModel::new(map, EmpiricalNodeModel::new(table)?, s.p_d)?;
                    let tables = NodeTableCache::default();
                    self.sweep_tb(&TableCached::on_grid(&model, &tables, TABLE_GRID_M), true)?
                }
                Method::Genie => {
                    self.sweep_genie(r, &TableCached::on_grid(&ppp, &ppp_tables, TABLE_GRID_M))?
                }
                Method::SizeRule => {
                    return Err(Error::OutOfRange {
                        field: "experiment".into(),
                        value: 0.0,
                        allowed: "the size rule belongs to V-A",
                    })
                }
            };
            out.push(curve);
        }
        Ok(out)
    }
}
