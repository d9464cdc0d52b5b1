//! [`Shard`]: one of `N` contiguous shares of a study's work units (Monte Carlo chunks,
//! multi-target realisations), for studies split over processes or machines.

use core::ops::Range;

/// Most shards a study may be split into.
pub const MAX_SHARDS: usize = 100_000;

/// Shard `index` of `count`: the work units `[index·C/count, (index+1)·C/count)` of a study with
/// `C` units ([`Shard::range`]). The shards of one count cover every unit exactly once, in order;
/// with more shards than units some are empty. Every unit draws from its own random stream, so
/// the units a shard runs do not depend on the count.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    index: usize,
    count: usize,
}

impl Shard {
    /// The whole study (shard 0 of 1).
    pub const WHOLE: Shard = Shard { index: 0, count: 1 };

    /// Shard `index` of `count`; `None` unless `1 ≤ count ≤` [`MAX_SHARDS`] and `index < count`.
    pub fn new(index: usize, count: usize) -> Option<Shard> {
        ((1..=MAX_SHARDS).contains(&count) && index < count).then_some(Shard { index, count })
    }

    /// The 0-based index.
    pub fn index(self) -> usize {
        self.index
    }

    /// The number of shards.
    pub fn count(self) -> usize {
        self.count
    }

    /// This shard's units of a study with `total` units.
    pub fn range(self, total: usize) -> Range<usize> {
        // 128-bit products: no overflow for any usize total.
        let at = |i: usize| (i as u128 * total as u128 / self.count as u128) as usize;
        at(self.index)..at(self.index + 1)
    }
}

#[cfg(test)]
mod tests;
