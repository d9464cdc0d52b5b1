//! The numeric base of the core: scalar and small-matrix aliases, physical constants and the
//! elementary functions (`scalar`), and the two pieces that make a study's result independent of
//! how its work is split: [`ExactSum`] (exact, order-independent sums) and [`Shard`] (one of `N`
//! contiguous shares of a study's work units), and [`Lanes`], the vector operations of the CRLB
//! map kernel (implemented for `wide::f64x4` here and for this CPU's wider registers natively),
//! and the optimal assignment of a cost matrix ([`assign`]: GOSPA and multi-target association).

mod assignment;
mod exact_sum;
mod lanes;
mod scalar;
mod shard;

pub use assignment::{assign, Assignment};
pub use exact_sum::ExactSum;
pub use lanes::Lanes;
pub use scalar::*;
pub use shard::{Shard, MAX_SHARDS};
