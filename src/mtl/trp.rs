//! Transmitter–receiver pairs (TRPs) of the multi-target method: the TRP index map of Table I and
//! the range function (M1) of `shared/spec/multi-target.md` per TRP (the range itself lives in
//! [`crate::measure`]).
//!
//! The spec numbers TRPs, TXs and RXs from 1; this module numbers them from 0. TRP `m` (0-based)
//! uses TX `m mod N_t` and RX `m div N_t` — the TX index runs fastest (spec check 1), so spec TRP
//! `m + 1` is TX `(m mod N_t) + 1`, RX `(m div N_t) + 1`.

use crate::error::{Error, Result};
use crate::math::{Real, Vec2};
use crate::measure::{bistatic_range, range_and_gradient, range_gradient};

/// Largest number of TRPs `M = N_t N_r`: blocking vectors are bit masks in a `u64`.
pub const MAX_TRPS: usize = 64;

/// Largest number of nodes `N_t + N_r`: consistency and the marginal (M4) enumerate all
/// `2^{N_t+N_r}` node patterns, so the node count is capped to keep that table small
/// (65 536 patterns; 6×6 and 8×8 networks fit).
pub const MAX_NODES: usize = 16;

/// The TRP index map of Table I (spec check 1): TRP `m` ↔ (TX `m mod N_t`, RX `m div N_t`), all
/// 0-based.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TrpMap {
    n_tx: usize,
    n_rx: usize,
}

impl TrpMap {
    /// A map for `n_tx` transmitters and `n_rx` receivers.
    ///
    /// Errors: [`Error::EmptyNodeList`] (`transmitters` / `receivers`) when a count is 0;
    /// [`Error::SizeLimit`] (`trps`) when `n_tx · n_rx > 64` ([`MAX_TRPS`]), (`nodes`) when
    /// `n_tx + n_rx > 16` ([`MAX_NODES`]).
    pub fn new(n_tx: usize, n_rx: usize) -> Result<Self> {
        if n_tx == 0 {
            return Err(Error::EmptyNodeList {
                field: "transmitters",
            });
        }
        if n_rx == 0 {
            return Err(Error::EmptyNodeList { field: "receivers" });
        }
        let m = n_tx.saturating_mul(n_rx);
        if m > MAX_TRPS {
            return Err(Error::SizeLimit {
                field: "trps",
                value: m,
                min: 1,
                max: MAX_TRPS,
            });
        }
        if n_tx + n_rx > MAX_NODES {
            return Err(Error::SizeLimit {
                field: "nodes",
                value: n_tx + n_rx,
                min: 2,
                max: MAX_NODES,
            });
        }
        Ok(Self { n_tx, n_rx })
    }

    /// Number of transmitters `N_t`.
    pub fn n_tx(&self) -> usize {
        self.n_tx
    }

    /// Number of receivers `N_r`.
    pub fn n_rx(&self) -> usize {
        self.n_rx
    }

    /// Number of TRPs `M = N_t N_r`.
    pub fn n_trps(&self) -> usize {
        self.n_tx * self.n_rx
    }

    /// The mask with one bit per TRP (bits `0..M`).
    pub fn all_trps(&self) -> u64 {
        low_bits(self.n_trps())
    }

    /// TX index `m_t = m mod N_t` of TRP `m` (0-based; spec check 1).
    pub fn tx(&self, m: usize) -> usize {
        m % self.n_tx
    }

    /// RX index `m_r = m div N_t` of TRP `m` (0-based; spec check 1).
    pub fn rx(&self, m: usize) -> usize {
        m / self.n_tx
    }

    /// `(m_t, m_r)` of TRP `m`; [`Error::IndexOutOfRange`] (`trps`) when `m ≥ M`.
    pub fn pair(&self, m: usize) -> Result<(usize, usize)> {
        crate::error::checked_index("trps", m, self.n_trps())?;
        Ok((self.tx(m), self.rx(m)))
    }

    /// The TRP of TX `tx` and RX `rx`: `m = tx + N_t · rx`; [`Error::IndexOutOfRange`] when an
    /// index is past its list.
    pub fn trp(&self, tx: usize, rx: usize) -> Result<usize> {
        crate::error::checked_index("transmitters", tx, self.n_tx)?;
        crate::error::checked_index("receivers", rx, self.n_rx)?;
        Ok(tx + self.n_tx * rx)
    }

    /// Range `d_m(x)` (M1) of TRP `m` with TX positions `tx` and RX positions `rx`.
    ///
    /// Panics if `m ≥ M` or a position slice is shorter than its node count.
    pub fn range(&self, m: usize, x: &Vec2, tx: &[Vec2], rx: &[Vec2]) -> Real {
        bistatic_range(tx[self.tx(m)], rx[self.rx(m)], *x)
    }

    /// Gradient `∇d_m(x)` of [`TrpMap::range`] ([`crate::measure::range_gradient`]). Same panics.
    pub fn range_gradient(&self, m: usize, x: &Vec2, tx: &[Vec2], rx: &[Vec2]) -> Vec2 {
        range_gradient(tx[self.tx(m)], rx[self.rx(m)], *x)
    }

    /// [`TrpMap::range`] and [`TrpMap::range_gradient`] in one pass ([`crate::measure::range_and_gradient`]). Same panics.
    pub fn range_and_gradient(&self, m: usize, x: &Vec2, tx: &[Vec2], rx: &[Vec2]) -> (Real, Vec2) {
        range_and_gradient(tx[self.tx(m)], rx[self.rx(m)], *x)
    }
}

/// The mask of bits `0..n` (`n ≤ 64`).
pub(crate) fn low_bits(n: usize) -> u64 {
    if n >= 64 {
        u64::MAX
    } else {
        (1u64 << n) - 1
    }
}

#[cfg(test)]
mod tests;
