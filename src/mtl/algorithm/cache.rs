//! Ellipse-intersection seeds (§4 steps 1 and 3, §5.2) cached per pair of MPCs, so runs on the
//! same measurements with other thresholds (ROC sweeps, check 6, the brute-force reference)
//! intersect each pair of ellipses once.

use alloc::collections::BTreeMap;
use alloc::vec::Vec;

use crate::math::{Real, Vec2};
use crate::mtl::algorithm::candidate::{Geometry, Pair};
use crate::mtl::geometry::{intersect_with, RangeEllipse, SampleTable};
use crate::mtl::polygon::Rect;

/// Intersection points of the ellipses of two (TRP, MPC) pairs, computed on first use. The cache
/// remembers the measurements and region it was filled for and empties itself when called with
/// others.
#[derive(Debug, Clone, Default)]
pub struct IntersectionCache {
    tx: Vec<Vec2>,
    rx: Vec<Vec2>,
    ranges: Vec<Vec<Real>>,
    region: Option<Rect>,
    points: BTreeMap<(Pair, Pair), Vec<Vec2>>,
    /// The §5.2 sample angles' cos/sin, built on first use.
    table: Option<alloc::boxed::Box<SampleTable>>,
}

impl IntersectionCache {
    /// An empty cache.
    pub fn new() -> Self {
        Self::default()
    }

    /// Make the cache valid for `geo` and `region` (emptying it if they changed).
    pub fn prepare(&mut self, geo: &Geometry, region: Option<&Rect>) {
        let input = &geo.input;
        let same = self.tx == input.tx
            && self.rx == input.rx
            && self.ranges == input.ranges
            && self.region.as_ref() == region;
        if !same {
            self.tx = input.tx.to_vec();
            self.rx = input.rx.to_vec();
            self.ranges = input.ranges.to_vec();
            self.region = region.copied();
            self.points.clear();
        }
    }

    /// The intersection points (§5.2, region of [`IntersectionCache::prepare`]) of the ellipses of
    /// `p` and `q`, sorted by `(x, y)`; empty when an ellipse does not exist (`r < 2f`) or they do not meet. Call
    /// [`IntersectionCache::prepare`] first.
    pub fn points(&mut self, geo: &Geometry, p: Pair, q: Pair) -> &[Vec2] {
        let key = if p <= q { (p, q) } else { (q, p) };
        let region = self.region;
        let table = self
            .table
            .get_or_insert_with(|| alloc::boxed::Box::new(SampleTable::new()));
        self.points.entry(key).or_insert_with(|| {
            let (tx, rx, map) = (geo.input.tx, geo.input.rx, geo.map);
            let ellipse =
                |p: Pair| RangeEllipse::new(tx[map.tx(p.trp)], rx[map.rx(p.trp)], geo.range_of(p));
            let mut pts = match (ellipse(key.0), ellipse(key.1)) {
                (Some(a), Some(b)) => intersect_with(&a, &b, region.as_ref(), table).to_vec(),
                _ => Vec::new(),
            };
            // By position, so the seed (and family) order does not depend on the TRP numbering.
            pts.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
            pts
        })
    }
}
