//! The blocking model of a scene (§6): i.c.b (M7) or PPP (M10/M11) with the scene's `λ`, `D`,
//! `p_d` and region; the PPP node tables memoised per location in a [`ViewCache`].

use alloc::boxed::Box;
use alloc::vec::Vec;

use crate::error::Result;
use crate::math::{Real, Vec2};
use crate::mtl::algorithm::IntersectionCache;
use crate::mtl::blocking::{
    BlockingModel, NodeBlockingModel, NodeTableCache, PartialVector, TableCached, TABLE_GRID_M,
};
use crate::mtl::icb::IcbModel;
use crate::mtl::ppp::{PppBlocking, PppNodeModel};
use crate::mtl::trp::TrpMap;

use super::output::ModelView;
use super::{v, BlockingChoice, MtlScene};

/// Most node tables a [`ViewCache`] keeps (about 0.5 kB each for 3 + 3 nodes); it empties when
/// full.
pub const MAX_CACHED_TABLES: usize = 16_384;

/// PPP node tables `P_node(a, b | x)` by location, kept between views of scenes with the same
/// nodes and PPP parameters (a front end recomputing on every drag): candidates built from
/// ranges that did not change land on the same `x` and reuse their table. Ellipse
/// intersections are kept the same way. Results are those of [`super::mtl_view`].
#[derive(Debug, Default)]
pub struct ViewCache {
    key: Vec<u64>,
    pub(super) tables: NodeTableCache,
    /// Ellipse intersections by (TRP, range) pair: a drag that moves one target leaves the pairs
    /// of every other range as they were (the cache checks its nodes and region itself).
    pub(super) intersections: IntersectionCache,
}

impl ViewCache {
    /// Keep the tables iff they were computed for the PPP parameters and nodes of `scene` (and
    /// are not too many); a scene with the i.c.b model leaves them as they are.
    pub(super) fn prepare(&mut self, scene: &MtlScene) {
        let BlockingChoice::Ppp { exact } = scene.model else {
            return;
        };
        let nodes = scene.transmitters.iter().chain(&scene.receivers).flatten();
        let params = [scene.lambda, scene.diameter, Real::from(u8::from(exact))];
        let numbers = scene.region.iter().chain(&params).chain(nodes);
        let n_tx = scene.transmitters.len() as u64;
        let key: Vec<u64> = core::iter::once(n_tx)
            .chain(numbers.map(|x| x.to_bits()))
            .collect();
        let tables = self.tables.get_mut();
        if self.key != key || tables.len() > MAX_CACHED_TABLES {
            tables.clear();
            self.key = key;
        }
    }

    /// Node tables held.
    pub fn len(&self) -> usize {
        self.tables.borrow().len()
    }

    /// Whether no table is held.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// The scene's blocking model for Algorithm 1 and its description.
pub(super) fn blocking_model<'a>(
    scene: &MtlScene,
    map: &TrpMap,
    tables: &'a NodeTableCache,
) -> Result<(Box<dyn BlockingModel + 'a>, ModelView)> {
    Ok(match scene.model {
        BlockingChoice::Ppp { exact } => {
            let ppp = PppBlocking::new(scene.lambda, scene.diameter, Some(scene.rect()?), exact)?;
            let pts = |l: &[[Real; 2]]| l.iter().map(v).collect::<Vec<Vec2>>();
            let nodes = PppNodeModel::new(ppp, pts(&scene.transmitters), pts(&scene.receivers))?;
            let model = Owned {
                inner: NodeBlockingModel::new(*map, nodes, scene.p_d)?,
                tables,
            };
            let label = alloc::format!(
                "PPP discs (M{}), λ = {} m⁻², D = {} m, p_d = {}",
                if exact { 11 } else { 10 },
                scene.lambda,
                scene.diameter,
                scene.p_d
            );
            let view = ModelView {
                kind: "ppp",
                p_u: None,
                exact: Some(exact),
                consistency: true,
                label,
            };
            (Box::new(model), view)
        }
        BlockingChoice::Icb { p_u, p_los } => {
            let model = match (p_u, p_los) {
                (Some(p), _) => IcbModel::from_p_u(*map, p)?,
                (None, Some(p)) => IcbModel::new(*map, scene.p_d, p)?,
                (None, None) => IcbModel::from_p_u(*map, Real::NAN)?,
            };
            let label = match p_los {
                Some(p) if p_u.is_none() => alloc::format!(
                    "i.c.b, p_u = 1 − p_d p_LoS² = {:.4} (p_d = {}, p_LoS = {p})",
                    model.p_u(),
                    scene.p_d
                ),
                _ => alloc::format!("i.c.b, p_u = {}", model.p_u()),
            };
            let view = ModelView {
                kind: "icb",
                p_u: Some(model.p_u()),
                exact: None,
                consistency: false,
                label,
            };
            (Box::new(model), view)
        }
    })
}

/// The scene's PPP model with the view cache's tables ([`TableCached`] over an owned model).
struct Owned<'a> {
    inner: NodeBlockingModel<PppNodeModel>,
    tables: &'a NodeTableCache,
}

impl BlockingModel for Owned<'_> {
    fn trp_map(&self) -> &TrpMap {
        self.inner.trp_map()
    }

    fn probability(&self, x: &Vec2, g: &PartialVector) -> Result<Real> {
        TableCached::on_grid(&self.inner, self.tables, TABLE_GRID_M).probability(x, g)
    }
}
