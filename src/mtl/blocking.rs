//! Blocking vectors over TRPs (spec §3): the Kronecker form `γ = γ^R ⊗ γ^T` (M3), consistency of
//! full and partial vectors, the unit-Hamming neighbour sets and the relaxed probability (M5),
//! the marginal (M4) of a node-pattern model, and the blocking likelihood `L_b = −ln P`.
//!
//! Representation: a blocking vector is a `u64` bit mask, bit `m` = TRP `m` (0-based, TRP order of
//! [`TrpMap`]); a node vector `a` (TXs) or `b` (RXs) is a mask over node indices. A *partial*
//! vector ([`PartialVector`]) is a pair of masks: the processed TRP set `S` and the TRPs of `S`
//! holding a DP (`ĝ_m = 1`).

use alloc::vec::Vec;

use crate::error::{Error, Result};
use crate::math::{ln, round, Real, Vec2};
use crate::mtl::trp::{low_bits, TrpMap};

/// A blocking vector `ĝ` on a processed TRP set `S` (spec §3): `ones ⊆ set`, both bit masks over
/// TRPs. With `S` = all TRPs it is a full vector.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct PartialVector {
    set: u64,
    ones: u64,
}

impl PartialVector {
    /// The vector on TRP set `set` with DPs (`ĝ_m = 1`) at `ones`.
    ///
    /// Errors: [`Error::IndexOutOfRange`] (`trps`) when `set` has a bit at or past `M`;
    /// [`Error::OutOfRange`] (`blocking_vector.ones`, value = the first offending 0-based TRP) when
    /// `ones` has a bit outside `set`.
    pub fn new(map: &TrpMap, set: u64, ones: u64) -> Result<Self> {
        let outside = set & !map.all_trps();
        if outside != 0 {
            return Err(Error::IndexOutOfRange {
                field: "trps",
                index: outside.trailing_zeros() as usize,
                len: map.n_trps(),
            });
        }
        let stray = ones & !set;
        if stray != 0 {
            return Err(Error::OutOfRange {
                field: "blocking_vector.ones".into(),
                value: stray.trailing_zeros() as Real,
                allowed: "DPs only at processed TRPs",
            });
        }
        Ok(Self { set, ones })
    }

    /// The full vector (`S` = all TRPs) with DPs at `ones`; errors as [`PartialVector::new`].
    pub fn full(map: &TrpMap, ones: u64) -> Result<Self> {
        Self::new(map, map.all_trps(), ones)
    }

    /// The empty vector (`S = ∅`).
    pub fn empty() -> Self {
        Self { set: 0, ones: 0 }
    }

    /// This vector extended (or overwritten) at TRP `m` with `ĝ_m = dp`. Panics if `m ≥ 64`.
    pub fn with(self, m: usize, dp: bool) -> Self {
        let bit = 1u64 << m;
        Self {
            set: self.set | bit,
            ones: if dp {
                self.ones | bit
            } else {
                self.ones & !bit
            },
        }
    }

    /// The processed TRP set `S` as a mask.
    pub fn set(&self) -> u64 {
        self.set
    }

    /// The TRPs with `ĝ_m = 1` as a mask.
    pub fn ones(&self) -> u64 {
        self.ones
    }

    /// `|S|`.
    pub fn len(&self) -> u32 {
        self.set.count_ones()
    }

    /// `S = ∅`.
    pub fn is_empty(&self) -> bool {
        self.set == 0
    }

    /// Hamming weight `|ĝ|` (number of DPs).
    pub fn weight(&self) -> u32 {
        self.ones.count_ones()
    }

    /// `ĝ_m` if `m ∈ S`, else `None`.
    pub fn get(&self, m: usize) -> Option<bool> {
        if m < 64 && self.set >> m & 1 == 1 {
            Some(self.ones >> m & 1 == 1)
        } else {
            None
        }
    }
}

/// `γ = b ⊗ a` (M3): bit `m` is `a_{m_t} b_{m_r}` for TX vector `a` and RX vector `b` (masks over
/// node indices; bits past `N_t` / `N_r` are ignored).
pub fn kron(map: &TrpMap, a: u64, b: u64) -> u64 {
    let a = a & low_bits(map.n_tx());
    let mut g = 0u64;
    for r in 0..map.n_rx() {
        if b >> r & 1 == 1 {
            g |= a << (r * map.n_tx());
        }
    }
    g
}

/// Whether `v` is consistent (spec §3): `∃ a, b` with `a_{m_t} b_{m_r} = ĝ_m ∀ m ∈ S`.
///
/// Exact in `O(M)`: the smallest node vectors that produce every DP are `a*` = TXs of the DPs and
/// `b*` = RXs of the DPs; any other solution contains them, so a solution exists iff `b* ⊗ a*`
/// has no DP on a TRP of `S` where `ĝ_m = 0`. (Agrees with enumerating all `2^{N_t+N_r}` pairs;
/// see [`BlockingSpace::is_consistent_by_enumeration`].)
pub fn is_consistent(map: &TrpMap, v: &PartialVector) -> bool {
    let mut a = 0u64;
    let mut b = 0u64;
    let mut rest = v.ones;
    while rest != 0 {
        let m = rest.trailing_zeros() as usize;
        rest &= rest - 1;
        a |= 1 << map.tx(m);
        b |= 1 << map.rx(m);
    }
    kron(map, a, b) & v.set == v.ones
}

/// `p` checked to lie in `[0, 1]`; else [`Error::OutOfRange`] naming `field` (NaN included).
pub fn check_probability(field: &str, p: Real) -> Result<Real> {
    if (0.0..=1.0).contains(&p) {
        Ok(p)
    } else {
        Err(Error::OutOfRange {
            field: field.into(),
            value: p,
            allowed: "a probability in [0, 1]",
        })
    }
}

/// `p^n` by repeated multiplication (`p^0 = 1`, also for `p = 0`), `no_std`-safe.
pub fn powu(p: Real, n: u32) -> Real {
    let mut r = 1.0;
    for _ in 0..n {
        r *= p;
    }
    r
}

/// The blocking likelihood `L_b = −ln P` (spec §3): `+∞` when `P = 0` (or is not a number),
/// never NaN; rounding above 1 is clamped so `L_b ≥ 0`.
pub fn blocking_likelihood(p: Real) -> Real {
    if p > 0.0 {
        (-ln(p)).max(0.0)
    } else {
        Real::INFINITY
    }
}

/// A blocking model at node level (spec §6): `P_node(γ^T = a, γ^R = b | x)`, the probability of
/// TX LoS vector `a` and RX LoS vector `b` (masks over node indices) for a target at `x`. Summed
/// over all `2^{N_t+N_r}` patterns it should be 1.
pub trait NodePatternModel {
    /// `P_node(γ^T = a, γ^R = b | x)`.
    fn node_pattern_probability(&self, x: &Vec2, a: u64, b: u64) -> Real;

    /// `P_node` of all `2^{n_tx+n_rx}` patterns at `x`, indexed `a | b << n_tx`. The default
    /// calls [`NodePatternModel::node_pattern_probability`] per pattern; models with a shared
    /// per-location cost (the PPP areas) override it to pay that cost once.
    fn pattern_probabilities_at(&self, x: &Vec2, n_tx: usize, n_rx: usize) -> Vec<Real> {
        let mask_a = low_bits(n_tx);
        (0..1u64 << (n_tx + n_rx))
            .map(|i| self.node_pattern_probability(x, i & mask_a, i >> n_tx))
            .collect()
    }
}

/// The per-candidate blocking query shared by all blocking models (i.c.b, PPP, empirical): the
/// probability `P(γ̂_S(x) = ĝ)` of an observed (partial) vector at `x` and `L_b = −ln P`.
pub trait BlockingModel {
    /// The TRP map the model was built for.
    fn trp_map(&self) -> &TrpMap;

    /// `P(γ̂_S(x) = ĝ)` for the observed vector `v` (e.g. (M5) or the i.c.b form of §6.1).
    ///
    /// Errors: [`Error::IndexOutOfRange`] (`trps`) when `v` names a TRP past this model's `M`.
    fn probability(&self, x: &Vec2, v: &PartialVector) -> Result<Real>;

    /// `L_b(x, S, ĝ) = −ln P(γ̂_S(x) = ĝ)`: `+∞` when the probability is 0, never NaN.
    fn blocking_likelihood(&self, x: &Vec2, v: &PartialVector) -> Result<Real> {
        Ok(blocking_likelihood(self.probability(x, v)?))
    }
}

/// [`Error::IndexOutOfRange`] (`trps`) unless `v` lies within `map`'s TRPs.
pub fn check_vector(map: &TrpMap, v: &PartialVector) -> Result<()> {
    PartialVector::new(map, v.set, v.ones).map(|_| ())
}

/// The precomputed blocking-vector structure of one [`TrpMap`]: `b ⊗ a` for every node pattern
/// and the sorted list of distinct consistent full vectors.
#[derive(Debug, Clone, PartialEq)]
pub struct BlockingSpace {
    map: TrpMap,
    /// `patterns[a | b << N_t] = b ⊗ a`.
    patterns: Vec<u64>,
    /// Distinct consistent full vectors, ascending.
    consistent: Vec<u64>,
}

impl BlockingSpace {
    /// Enumerate the `2^{N_t+N_r}` node patterns of `map` (at most 65 536, see
    /// [`crate::mtl::trp::MAX_NODES`]).
    pub fn new(map: TrpMap) -> Self {
        let n = map.n_tx() + map.n_rx();
        let count = 1usize << n;
        let mask_a = low_bits(map.n_tx());
        let patterns: Vec<u64> = (0..count as u64)
            .map(|i| kron(&map, i & mask_a, i >> map.n_tx()))
            .collect();
        let mut consistent = patterns.clone();
        consistent.sort_unstable();
        consistent.dedup();
        Self {
            map,
            patterns,
            consistent,
        }
    }

    /// The TRP map.
    pub fn map(&self) -> &TrpMap {
        &self.map
    }

    /// Number of node patterns `2^{N_t+N_r}`.
    pub fn n_patterns(&self) -> usize {
        self.patterns.len()
    }

    /// `(a, b, b ⊗ a)` of node pattern index `i = a | b << N_t`.
    pub fn pattern(&self, i: usize) -> (u64, u64, u64) {
        let i64 = i as u64;
        (
            i64 & low_bits(self.map.n_tx()),
            i64 >> self.map.n_tx(),
            self.patterns[i],
        )
    }

    /// The distinct consistent full vectors (masks), ascending.
    pub fn consistent_full(&self) -> &[u64] {
        &self.consistent
    }

    /// Whether `v` is consistent (the `O(M)` test of [`is_consistent`]).
    pub fn is_consistent(&self, v: &PartialVector) -> bool {
        is_consistent(&self.map, v)
    }

    /// Whether some consistent full vector agrees with `v` on `S` (the definition, by
    /// enumeration; equal to [`BlockingSpace::is_consistent`]).
    pub fn is_consistent_by_enumeration(&self, v: &PartialVector) -> bool {
        self.consistent.iter().any(|g| g & v.set == v.ones)
    }

    /// The unit-Hamming neighbour set `𝒩(ĝ) = {g ∈ 𝒞_S : d_H(g, ĝ) ≤ 1}` (M5), all on the same
    /// `S`: `ĝ` itself first if consistent, then the single-bit flips in ascending TRP order.
    pub fn neighbours(&self, v: &PartialVector) -> Vec<PartialVector> {
        let flips = (0..64)
            .filter(|m| v.set >> m & 1 == 1)
            .map(|m| PartialVector {
                set: v.set,
                ones: v.ones ^ 1 << m,
            });
        core::iter::once(*v)
            .chain(flips)
            .filter(|g| self.is_consistent(g))
            .collect()
    }

    /// `P_node` of every node pattern at `x`, indexed like [`BlockingSpace::pattern`]; evaluate
    /// once per location and reuse for many (M4)/(M5) queries.
    pub fn node_table<N: NodePatternModel + ?Sized>(&self, model: &N, x: &Vec2) -> NodeTable {
        let mut probs = model.pattern_probabilities_at(x, self.map.n_tx(), self.map.n_rx());
        // A model returning the wrong length is a bug; never index out of bounds for it.
        probs.resize(self.patterns.len(), 0.0);
        NodeTable { probs }
    }

    /// The marginal (M4) `P(γ_S(x) = g) = Σ P_node(a, b | x)` over the node patterns with
    /// `b ⊗ a = g` on `S`, from a [`NodeTable`] of this space.
    pub fn marginal(&self, table: &NodeTable, g: &PartialVector) -> Real {
        self.patterns
            .iter()
            .zip(&table.probs)
            .filter(|(p, _)| *p & g.set == g.ones)
            .map(|(_, q)| q)
            .sum()
    }

    /// The relaxed probability (M5) of the observed `ĝ` with DP detection probability `p_d`:
    /// `Σ_{g ∈ 𝒩(ĝ), g ≥ ĝ} p_d^{|ĝ|} (1 − p_d)^{|g|−|ĝ|} P(γ_S = g)`, 0 when `𝒩(ĝ) = ∅`
    /// (only "no error" and "one DP missed" terms enter). `p_d` is not validated here.
    pub fn relaxed_probability(&self, table: &NodeTable, v: &PartialVector, p_d: Real) -> Real {
        // One pass over the node patterns: pattern `i` contributes to `P(γ_S = g)` for
        // `g = (b ⊗ a)|_S`, which differs from `ĝ` by `d = g ⊕ ĝ`. The terms of (M5) are `g = ĝ`
        // (`d = 0`, weight 1) and `g = ĝ` plus one DP (`d` one bit outside `ĝ`, weight `1 − p_d`);
        // an inconsistent `g` has no pattern, so its marginal is 0 as the definition requires.
        let (mut exact, mut one_missed) = (0.0, 0.0);
        for (&pattern, &q) in self.patterns.iter().zip(&table.probs) {
            let d = (pattern & v.set) ^ v.ones;
            if d == 0 {
                exact += q;
            } else if d & (d - 1) == 0 && d & v.ones == 0 {
                one_missed += q;
            }
        }
        powu(p_d, v.weight()) * (exact + (1.0 - p_d) * one_missed)
    }
}

/// `P_node(a, b | x)` of every node pattern at one location (see [`BlockingSpace::node_table`]).
#[derive(Debug, Clone, PartialEq)]
pub struct NodeTable {
    probs: Vec<Real>,
}

impl NodeTable {
    /// The probabilities, indexed `a | b << N_t`.
    pub fn probabilities(&self) -> &[Real] {
        &self.probs
    }
}

/// A Bayesian blocking model built from a [`NodePatternModel`]: (M4) marginals relaxed by (M5)
/// with detection probability `p_d`.
#[derive(Debug, Clone)]
pub struct NodeBlockingModel<N> {
    space: BlockingSpace,
    node: N,
    p_d: Real,
}

impl<N: NodePatternModel> NodeBlockingModel<N> {
    /// The model for `map` with node-pattern model `node` and DP detection probability `p_d`;
    /// [`Error::OutOfRange`] (`p_d`) unless `p_d ∈ [0, 1]`.
    pub fn new(map: TrpMap, node: N, p_d: Real) -> Result<Self> {
        let p_d = check_probability("p_d", p_d)?;
        Ok(Self {
            space: BlockingSpace::new(map),
            node,
            p_d,
        })
    }

    /// The precomputed blocking space.
    pub fn space(&self) -> &BlockingSpace {
        &self.space
    }

    /// The node-pattern model.
    pub fn node_model(&self) -> &N {
        &self.node
    }

    /// DP detection probability `p_d`.
    pub fn p_d(&self) -> Real {
        self.p_d
    }

    /// (M5) from a node table already evaluated at the candidate's location (no validation).
    pub fn probability_with_table(&self, table: &NodeTable, v: &PartialVector) -> Real {
        self.space.relaxed_probability(table, v, self.p_d)
    }
}

impl<N: NodePatternModel> BlockingModel for NodeBlockingModel<N> {
    fn trp_map(&self) -> &TrpMap {
        self.space.map()
    }

    fn probability(&self, x: &Vec2, v: &PartialVector) -> Result<Real> {
        check_vector(self.space.map(), v)?;
        let table = self.space.node_table(&self.node, x);
        Ok(self.probability_with_table(&table, v))
    }
}

/// Node tables by location (the bits of `x.x`, `x.y`, after any snapping to a grid), shared by
/// a [`TableCached`] model and kept by its owner for as long as the node model does not change.
pub type NodeTableCache = core::cell::RefCell<alloc::collections::BTreeMap<(u64, u64), NodeTable>>;

/// Most tables a [`NodeTableCache`] holds through [`TableCached`]; it empties when full.
pub const MAX_CACHED_TABLES: usize = 1 << 16;

/// The location grid of [`TableCached::on_grid`] used by the experiments and the page, m.
///
/// Algorithm 1 reaches the same least-squares location along several paths (a matching grown in
/// another order, a late seed's catch-up) and Gauss–Newton lands within ≈ 1e-10 m of it each
/// time, so tables memoised on this grid are reused. Moving `x` by ≤ 0.71 µm changes `L_b` by
/// ≤ 1.1e-6 nats on random V-B queries (tested in `tests/mtl/blocking.rs`), far below the
/// `T_b` steps of 0.25 nats. Outcomes are not bitwise those at exact locations: near-ties in `J`
/// between candidates that reach the same matching along different paths can resolve the other
/// way. The measurements behind this choice are in `docs/benchmarks.md` (table grid).
pub const TABLE_GRID_M: Real = 1e-6;

/// A [`NodeBlockingModel`] with its node table memoised per location: Algorithm 1's children that
/// keep their parent's location (no MPC passed, `ĝ_m = 0`), repeated queries across thresholds
/// and unchanged candidates of a previous run (a page recomputing on drag) reuse one node-table
/// computation (for the PPP model, one set of polygon clippings). With [`TableCached::new`] the
/// results are bitwise those of the wrapped model; with [`TableCached::on_grid`] the table at `x`
/// is the wrapped model's at the nearest grid point (a pure function of `x`: results do not
/// depend on the order of queries). Single-threaded (the cache is a `RefCell`); give each thread
/// its own.
#[derive(Debug)]
pub struct TableCached<'a, N> {
    inner: &'a NodeBlockingModel<N>,
    tables: &'a NodeTableCache,
    /// Grid step, m; 0 = exact locations.
    grid_m: Real,
}

impl<'a, N: NodePatternModel> TableCached<'a, N> {
    /// `inner` with the tables of `tables` (which must have been filled for this same node model,
    /// or be empty), at exact locations.
    pub fn new(inner: &'a NodeBlockingModel<N>, tables: &'a NodeTableCache) -> Self {
        Self {
            inner,
            tables,
            grid_m: 0.0,
        }
    }

    /// As [`TableCached::new`], with every location snapped to the nearest point of a square grid
    /// of step `grid_m` (through the origin) first; a step that is not finite and positive means
    /// exact locations. See [`TABLE_GRID_M`].
    pub fn on_grid(
        inner: &'a NodeBlockingModel<N>,
        tables: &'a NodeTableCache,
        grid_m: Real,
    ) -> Self {
        Self {
            inner,
            tables,
            grid_m: if grid_m.is_finite() && grid_m > 0.0 {
                grid_m
            } else {
                0.0
            },
        }
    }

    /// The location whose table stands for `x`.
    fn location(&self, x: &Vec2) -> Vec2 {
        let q = self.grid_m;
        if q == 0.0 {
            return *x;
        }
        let snap = |v: Real| {
            let s = round(v / q) * q;
            if s.is_finite() {
                s
            } else {
                v
            }
        };
        Vec2::new(snap(x.x), snap(x.y))
    }
}

impl<N: NodePatternModel> BlockingModel for TableCached<'_, N> {
    fn trp_map(&self) -> &TrpMap {
        self.inner.trp_map()
    }

    fn probability(&self, x: &Vec2, v: &PartialVector) -> Result<Real> {
        check_vector(self.trp_map(), v)?;
        let at = self.location(x);
        let key = (at.x.to_bits(), at.y.to_bits());
        let mut tables = self.tables.borrow_mut();
        if tables.len() >= MAX_CACHED_TABLES {
            tables.clear();
        }
        let inner = self.inner;
        let table = tables
            .entry(key)
            .or_insert_with(|| inner.space().node_table(inner.node_model(), &at));
        Ok(inner.probability_with_table(table, v))
    }
}

/// A simple node-pattern model: each TX `j` has LoS to the target with probability `p_tx[j]`,
/// each RX `j` with `p_rx[j]`, all independent and independent of `x`. A reference and test
/// model (with all probabilities equal to `p_LoS` its DPs are not independent, unlike i.c.b).
#[derive(Debug, Clone, PartialEq)]
pub struct IndependentNodes {
    p_tx: Vec<Real>,
    p_rx: Vec<Real>,
}

impl IndependentNodes {
    /// The model with per-node LoS probabilities for the nodes of `map`.
    ///
    /// Errors: [`Error::LengthMismatch`] (`p_tx` / `p_rx`) when a list does not have one entry per
    /// node; [`Error::OutOfRange`] (`p_tx[j]` / `p_rx[j]`) for a value outside `[0, 1]`.
    pub fn new(map: &TrpMap, p_tx: Vec<Real>, p_rx: Vec<Real>) -> Result<Self> {
        for (field, list, n) in [("p_tx", &p_tx, map.n_tx()), ("p_rx", &p_rx, map.n_rx())] {
            if list.len() != n {
                return Err(Error::LengthMismatch {
                    field,
                    expected: n,
                    found: list.len(),
                });
            }
            for (j, &p) in list.iter().enumerate() {
                check_probability(&alloc::format!("{field}[{j}]"), p)?;
            }
        }
        Ok(Self { p_tx, p_rx })
    }
}

impl NodePatternModel for IndependentNodes {
    fn node_pattern_probability(&self, _x: &Vec2, a: u64, b: u64) -> Real {
        let side = |ps: &[Real], mask: u64| {
            ps.iter()
                .enumerate()
                .map(|(j, &p)| if mask >> j & 1 == 1 { p } else { 1.0 - p })
                .product::<Real>()
        };
        side(&self.p_tx, a) * side(&self.p_rx, b)
    }
}

#[cfg(test)]
mod tests;
