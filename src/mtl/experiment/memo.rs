//! A memoising [`BlockingModel`] wrapper for threshold sweeps: across the `T_b` values of one
//! realisation, Algorithm 1 meets the same candidates (same refined `x̂`, same `ĝ`) again and
//! again, so their probabilities are computed once. Keys are the exact bit patterns of `x̂` and
//! `ĝ`, so results are bitwise those of the wrapped model.

use alloc::collections::BTreeMap;
use core::cell::RefCell;

use crate::error::Result;
use crate::math::{Real, Vec2};
use crate::mtl::blocking::{BlockingModel, PartialVector};
use crate::mtl::trp::TrpMap;

/// Largest number of memoised entries; beyond it the cache is cleared (bounded memory).
pub const MAX_ENTRIES: usize = 1 << 20;

/// `inner` with its probabilities memoised by `(x̂, ĝ)` (one thread: not `Sync`).
#[derive(Debug)]
pub struct Memoized<'a, B: ?Sized> {
    inner: &'a B,
    cache: RefCell<BTreeMap<[u64; 4], Real>>,
}

impl<'a, B: BlockingModel + ?Sized> Memoized<'a, B> {
    /// Wraps `inner` with an empty cache.
    pub fn new(inner: &'a B) -> Self {
        Self {
            inner,
            cache: RefCell::new(BTreeMap::new()),
        }
    }
}

impl<B: BlockingModel + ?Sized> BlockingModel for Memoized<'_, B> {
    fn trp_map(&self) -> &TrpMap {
        self.inner.trp_map()
    }

    fn probability(&self, x: &Vec2, v: &PartialVector) -> Result<Real> {
        let key = [x.x.to_bits(), x.y.to_bits(), v.set(), v.ones()];
        if let Some(&p) = self.cache.borrow().get(&key) {
            return Ok(p);
        }
        let p = self.inner.probability(x, v)?;
        let mut cache = self.cache.borrow_mut();
        if cache.len() >= MAX_ENTRIES {
            cache.clear();
        }
        cache.insert(key, p);
        Ok(p)
    }
}
