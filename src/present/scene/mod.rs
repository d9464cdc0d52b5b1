//! What a front end shows of one multi-target scene (spec `multi-target.md`): a user-placed
//! scene ([`MtlScene`]: nodes, targets, scatterer discs, noise, clutter, thresholds and the
//! blocking model) turned into drawable data ([`MtlView`]) by [`mtl_view`].
//!
//! The discs are deterministic scatterers: the DP of target `k` at TRP `m` exists iff both
//! node–target segments are LoS (no disc centre within `D/2`, [`segment_is_los`]); the §7
//! generator then keeps it w.p. `p_d`, adds range noise `cσ` and Poisson clutter and applies the
//! resolution merge (the generator's own [`trp_peaks`] and [`resolution_merge`] on the stream
//! `rng(seed, 0)`). Algorithm 1 runs on the ranges with the chosen blocking model (i.c.b (M7) or
//! PPP (M10/M11) with the scene's `λ`, `D`, `p_d`) and records its candidate trace.
//!
//! - this file: the scene (serde, `deny_unknown_fields`), its defaults and validation.
//! - [`data`]: the measurements of a scene (LoS, `γ`, seeded ranges with their truth).
//! - [`model`]: the blocking model and the [`ViewCache`] of PPP node tables.
//! - [`compute`]: scene → measurements → Algorithm 1 → view.
//! - [`output`]: the view types (serde, what JavaScript receives).
//!
//! [`segment_is_los`]: crate::mtl::sim::scene::segment_is_los
//! [`trp_peaks`]: crate::mtl::sim::generator::trp_peaks
//! [`resolution_merge`]: crate::mtl::sim::generator::resolution_merge

mod compute;
mod data;
mod model;
pub(super) mod output;

#[cfg(test)]
mod tests;

use alloc::format;
use alloc::string::String;
use alloc::vec::Vec;

use serde::{Deserialize, Serialize};

use crate::error::{check_non_negative, check_positive, limits, Error, Result};
use crate::math::{sqrt, Real, Vec2};
use crate::mtl::blocking::check_probability;
use crate::mtl::polygon::Rect;
use crate::mtl::trp::TrpMap;

pub use compute::{mtl_view, mtl_view_cached};
pub use model::{ViewCache, MAX_CACHED_TABLES};

/// Most transmitters (and, separately, receivers) of a page scene (keeps a recompute interactive:
/// the PPP model enumerates `2^{N_t+N_r}` node patterns per candidate).
pub const MAX_VIEW_NODES: usize = 4;
/// Most targets of a page scene.
pub const MAX_VIEW_TARGETS: usize = 8;
/// Most scatterer discs of a page scene.
pub const MAX_VIEW_DISCS: usize = 64;
/// Largest clutter mean per TRP of a page scene (the seed count grows with its square).
pub const MAX_VIEW_CLUTTER: Real = 10.0;

/// The blocking model Algorithm 1 scores candidates with (§6).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase", deny_unknown_fields)]
pub enum BlockingChoice {
    /// The PPP disc model (§6.2) with the scene's `λ`, `D`, `p_d` and region; consistency
    /// branching on.
    Ppp {
        /// `true`: exact inclusion–exclusion (M11); `false` (default): the bound (M10) of \[A\].
        #[serde(default)]
        exact: bool,
    },
    /// The i.c.b model (§6.1): exactly one of `p_u` (given directly) or `p_los` (then
    /// `p_u = 1 − p_d p_LoS²` (M7) with the scene's `p_d`). Consistency branching off.
    Icb {
        /// Undetected-DP probability `p_u`.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        p_u: Option<Real>,
        /// LoS probability `p_LoS` between any two points.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        p_los: Option<Real>,
    },
}

/// A multi-target scene as placed on the page. Field names follow
/// [`crate::mtl::sim::SimSettings`] (so errors name the same fields); positions are `[x, y]` m.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MtlScene {
    /// Region `R` as `[x_min, x_max, y_min, y_max]`, m: every node, target and disc centre lies
    /// in it; the PPP rectangles are clipped to it.
    pub region: [Real; 4],
    /// TX positions `u_j` (Table I: the TX index runs fastest over the TRPs).
    pub transmitters: Vec<[Real; 2]>,
    /// RX positions `v_j`.
    pub receivers: Vec<[Real; 2]>,
    /// True target positions `x_k` (may be empty).
    pub targets: Vec<[Real; 2]>,
    /// Scatterer disc centres (deterministic blockers of diameter `diameter`).
    pub discs: Vec<[Real; 2]>,
    /// Disc diameter `D`, m (> 0).
    pub diameter: Real,
    /// Disc intensity `λ` of the PPP model, m⁻² (≥ 0).
    pub lambda: Real,
    /// Probability `p_d` that a LoS DP is detected (data and models).
    pub p_d: Real,
    /// Range noise standard deviation `cσ`, m (> 0).
    pub range_sigma: Real,
    /// Resolution `δ`, m (≥ 0).
    pub resolution: Real,
    /// Mean number of clutter peaks per TRP (Poisson, `0 … MAX_VIEW_CLUTTER`).
    pub clutter_mean: Real,
    /// Clutter peaks are uniform on `[0, r_max]`, m; absent: `2·diam(R)`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub r_max: Option<Real>,
    /// Detection radius `r_det` of the metrics (M12), m (> 0).
    pub detection_radius: Real,
    /// Seed of the noise, detection and clutter draws (stream `rng(seed, 0)`).
    pub seed: u64,
    /// Ellipse-test threshold `T_e`, in units of `σ_e` (≥ 0).
    pub t_e: Real,
    /// Blocking-test threshold `T_b`, nats (≥ 0).
    pub t_b: Real,
    /// The blocking model.
    pub model: BlockingChoice,
    /// The work budget of Algorithm 1, candidates (absent: the default
    /// [`crate::mtl::algorithm::DEFAULT_MAX_CANDIDATES`], as the CLI): a scene past it is the
    /// named [`Error::WorkLimit`] (`ranges`), not minutes of work.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_candidates: Option<usize>,
}

impl Default for MtlScene {
    /// [`MtlScene::vb`].
    fn default() -> Self {
        MtlScene::vb()
    }
}

impl MtlScene {
    /// The V-B setting (§7) as a fixed scene: `R = [0, 10]²`, the 3 TX + 3 RX of spec check 9,
    /// two targets, three discs of `D = 0.6` m (`λ = 0.03` m⁻² puts three in `R` on average; the
    /// one at (2.3, 2.5) blocks TX 1 → target 1), `p_d = 0.9`, `cσ = 0.1` m, `δ = 0.3` m, clutter
    /// mean 2 per TRP on `[0, 2·diam(R)]`, `r_det = 0.5` m, `T_e = 3`, PPP model (bound (M10)),
    /// seed 8. `T_b = 6` nats: at the top of the Fig. 4 sweep (20 nats) this scene shows about ten
    /// false alarms (3-matchings of clutter); at 6 both targets and no ghost (seed 8).
    pub fn vb() -> MtlScene {
        MtlScene {
            region: [0.0, 10.0, 0.0, 10.0],
            transmitters: alloc::vec![[1.0, 1.0], [9.0, 2.0], [2.0, 8.0]],
            receivers: alloc::vec![[8.0, 8.5], [5.0, 0.5], [0.5, 5.0]],
            targets: alloc::vec![[3.5, 4.0], [7.0, 5.5]],
            discs: alloc::vec![[2.3, 2.5], [7.5, 3.5], [4.0, 7.5]],
            diameter: 0.6,
            lambda: 0.03,
            p_d: 0.9,
            range_sigma: 0.1,
            resolution: 0.3,
            clutter_mean: 2.0,
            r_max: None,
            detection_radius: 0.5,
            seed: 8,
            t_e: 3.0,
            t_b: 6.0,
            model: BlockingChoice::Ppp { exact: false },
            max_candidates: None,
        }
    }

    /// Parses and validates a scene. Errors: [`Error::Parse`] (syntax, a missing, unknown or
    /// mistyped field — JSON has no NaN, so a NaN sent as `null` lands here with its path), then
    /// those of [`MtlScene::validate`].
    pub fn from_json(text: &str) -> Result<MtlScene> {
        let s: MtlScene = crate::scenario::parse_json(text)?;
        s.validate()?;
        Ok(s)
    }

    /// Compact JSON of this scene (the schema [`MtlScene::from_json`] reads).
    pub fn to_json(&self) -> String {
        serde_json::to_string(self).unwrap_or_default()
    }

    /// The region as a [`Rect`].
    pub fn rect(&self) -> Result<Rect> {
        let [x0, x1, y0, y1] = self.region;
        Rect::new(Vec2::new(x0, y0), Vec2::new(x1, y1))
    }

    /// The TRP map of the nodes (Table I).
    pub fn map(&self) -> Result<TrpMap> {
        TrpMap::new(self.transmitters.len(), self.receivers.len())
    }

    /// `r_max`, or `2·diam(R)` when absent.
    pub fn r_max_m(&self) -> Real {
        self.r_max.unwrap_or_else(|| {
            let [x0, x1, y0, y1] = self.region;
            2.0 * sqrt((x1 - x0) * (x1 - x0) + (y1 - y0) * (y1 - y0))
        })
    }

    /// Checks every field, each error naming it:
    /// - `region`: [`Error::NonFinite`] / [`Error::InvertedArea`] (`region.x`, `region.y`);
    /// - nodes: [`Error::EmptyNodeList`] (`transmitters`, `receivers`), [`Error::SizeLimit`]
    ///   (`transmitters`, `receivers` above [`MAX_VIEW_NODES`]; `targets` above
    ///   [`MAX_VIEW_TARGETS`]; `discs` above [`MAX_VIEW_DISCS`]);
    /// - positions: [`Error::NonFinite`] (`targets[k]`, …), [`Error::OutOfRange`] (`targets[k]`,
    ///   … outside the region);
    /// - [`Error::OutOfRange`] (`discs[j]`) when a disc covers a node or a target (centre within
    ///   `D/2`; value = the distance, m);
    /// - [`Error::NotPositive`] (`diameter`, `detection_radius`, `r_max`); [`Error::OutOfRange`]
    ///   (`range_sigma` outside [`limits::C_SIGMA_M`]);
    ///   [`Error::OutOfRange`] / [`Error::NonFinite`] (`lambda`, `resolution`, `clutter_mean`,
    ///   `t_e`, `t_b` negative or not finite; `clutter_mean` above [`MAX_VIEW_CLUTTER`]);
    ///   [`Error::OutOfRange`] (`p_d`, `model.p_u`, `model.p_los` outside `[0, 1]`);
    ///   [`Error::Parse`] (`model`) unless exactly one of `p_u`, `p_los` is given for i.c.b.
    pub fn validate(&self) -> Result<()> {
        let rect = self.rect()?;
        self.map()?;
        for (field, n, max) in [
            ("transmitters", self.transmitters.len(), MAX_VIEW_NODES),
            ("receivers", self.receivers.len(), MAX_VIEW_NODES),
            ("targets", self.targets.len(), MAX_VIEW_TARGETS),
            ("discs", self.discs.len(), MAX_VIEW_DISCS),
        ] {
            if n > max {
                return Err(Error::SizeLimit {
                    field,
                    value: n,
                    min: usize::from(field != "targets" && field != "discs"),
                    max,
                });
            }
        }
        for (name, list) in self.point_lists() {
            for (i, p) in list.iter().enumerate() {
                check_point(&rect, &format!("{name}[{i}]"), p)?;
            }
        }
        check_positive("diameter", self.diameter)?;
        check_non_negative("lambda", self.lambda, false, "a value ≥ 0")?;
        check_probability("p_d", self.p_d)?;
        limits::C_SIGMA_M.check("range_sigma", self.range_sigma)?;
        check_non_negative("resolution", self.resolution, false, "a value ≥ 0")?;
        check_non_negative("clutter_mean", self.clutter_mean, false, "a value ≥ 0")?;
        if self.clutter_mean > MAX_VIEW_CLUTTER {
            return Err(Error::OutOfRange {
                field: "clutter_mean".into(),
                value: self.clutter_mean,
                allowed: "a mean of at most 10 clutter peaks per TRP",
            });
        }
        if let Some(r) = self.r_max {
            check_positive("r_max", r)?;
            limits::RANGE_M.check("r_max", r)?;
        }
        check_positive("detection_radius", self.detection_radius)?;
        check_non_negative("t_e", self.t_e, false, "a value ≥ 0")?;
        check_non_negative("t_b", self.t_b, false, "a value ≥ 0")?;
        if let BlockingChoice::Icb { p_u, p_los } = self.model {
            match (p_u, p_los) {
                (Some(p), None) => check_probability("model.p_u", p).map(|_| ())?,
                (None, Some(p)) => check_probability("model.p_los", p).map(|_| ())?,
                _ => {
                    return Err(Error::Parse {
                        message: "model: the i.c.b model takes exactly one of p_u, p_los".into(),
                    })
                }
            }
        }
        self.check_discs()
    }

    /// The named point lists, in validation order.
    fn point_lists(&self) -> [(&'static str, &[[Real; 2]]); 4] {
        [
            ("transmitters", &self.transmitters),
            ("receivers", &self.receivers),
            ("targets", &self.targets),
            ("discs", &self.discs),
        ]
    }

    /// No disc centre within `D/2` of a node or a target (they are outside every scatterer).
    fn check_discs(&self) -> Result<()> {
        let r = 0.5 * self.diameter;
        for (j, c) in self.discs.iter().enumerate() {
            let others = self.transmitters.iter().chain(&self.receivers);
            for p in others.chain(&self.targets) {
                let d = (v(p) - v(c)).norm();
                if d <= r {
                    return Err(Error::OutOfRange {
                        field: format!("discs[{j}]"),
                        value: d,
                        allowed: "a disc centre more than D/2 from every node and target",
                    });
                }
            }
        }
        Ok(())
    }
}

/// `[x, y]` as a vector.
pub(crate) fn v(p: &[Real; 2]) -> Vec2 {
    Vec2::new(p[0], p[1])
}

fn check_point(rect: &Rect, field: &str, p: &[Real; 2]) -> Result<()> {
    if !(p[0].is_finite() && p[1].is_finite()) {
        return Err(Error::NonFinite {
            field: field.into(),
        });
    }
    if !rect.contains(v(p)) {
        let out = if (rect.min.x..=rect.max.x).contains(&p[0]) {
            p[1]
        } else {
            p[0]
        };
        return Err(Error::OutOfRange {
            field: field.into(),
            value: out,
            allowed: "a position inside the region",
        });
    }
    Ok(())
}
