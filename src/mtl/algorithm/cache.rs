//! Ellipse-intersection seeds (§4 steps 1 and 3, §5.2) cached per pair of MPCs, so runs on the
//! same measurements with other thresholds (ROC sweeps, check 6, the brute-force reference)
//! intersect each pair of ellipses once.

use alloc::collections::BTreeMap;
use alloc::vec::Vec;

use crate::math::Vec2;
use crate::mtl::algorithm::candidate::{Geometry, Pair};
use crate::mtl::geometry::{intersect_with, RangeEllipse, SampleTable};
use crate::mtl::polygon::Rect;

/// One ellipse as a cache key: its TRP and the bits of its range.
type EllipseKey = (usize, u64);

/// Most ellipse pairs a cache keeps; it empties when it would grow past this (a front end that
/// recomputes on every drag meets new ranges all the time).
pub const MAX_CACHED_PAIRS: usize = 1 << 15;

/// Intersection points of two range ellipses, computed on first use. Entries are keyed by the
/// ellipses themselves (TRP and range value, not the MPC's index), so runs on other ranges of
/// the same nodes reuse every pair whose two ranges did not change. The cache remembers the
/// nodes and region it was filled for and empties itself when called with others.
#[derive(Debug, Clone, Default)]
pub struct IntersectionCache {
    tx: Vec<Vec2>,
    rx: Vec<Vec2>,
    region: Option<Rect>,
    points: BTreeMap<(EllipseKey, EllipseKey), Vec<Vec2>>,
    /// The §5.2 sample angles' cos/sin, built on first use.
    table: Option<alloc::boxed::Box<SampleTable>>,
}

impl IntersectionCache {
    /// An empty cache.
    pub fn new() -> Self {
        Self::default()
    }

    /// Make the cache valid for the nodes of `geo` and `region` (emptying it if they changed, or
    /// if it holds [`MAX_CACHED_PAIRS`] pairs).
    pub fn prepare(&mut self, geo: &Geometry, region: Option<&Rect>) {
        let input = &geo.input;
        let same = self.tx == input.tx && self.rx == input.rx && self.region.as_ref() == region;
        if !same {
            self.tx = input.tx.to_vec();
            self.rx = input.rx.to_vec();
            self.region = region.copied();
            self.points.clear();
        } else if self.points.len() >= MAX_CACHED_PAIRS {
            self.points.clear();
        }
    }

    /// Number of ellipse pairs held.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// Whether no pair is held.
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// The intersection points (§5.2, region of [`IntersectionCache::prepare`]) of the ellipses of
    /// `p` and `q`, sorted by `(x, y)`; empty when an ellipse does not exist (`r < 2f`) or they do
    /// not meet. Call [`IntersectionCache::prepare`] first.
    pub fn points(&mut self, geo: &Geometry, p: Pair, q: Pair) -> &[Vec2] {
        let (p, q) = if p <= q { (p, q) } else { (q, p) };
        let key = (
            (p.trp, geo.range_of(p).to_bits()),
            (q.trp, geo.range_of(q).to_bits()),
        );
        let region = self.region;
        let table = self
            .table
            .get_or_insert_with(|| alloc::boxed::Box::new(SampleTable::new()));
        self.points.entry(key).or_insert_with(|| {
            let (tx, rx, map) = (geo.input.tx, geo.input.rx, geo.map);
            let ellipse =
                |p: Pair| RangeEllipse::new(tx[map.tx(p.trp)], rx[map.rx(p.trp)], geo.range_of(p));
            let mut pts = match (ellipse(p), ellipse(q)) {
                (Some(a), Some(b)) => intersect_with(&a, &b, region.as_ref(), table).to_vec(),
                _ => Vec::new(),
            };
            // By position, so the seed (and family) order does not depend on the TRP numbering.
            pts.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
            pts
        })
    }
}
