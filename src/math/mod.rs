//! The numeric base of the core: scalar and small-matrix aliases, physical constants and the
//! elementary functions (`scalar`), and the two pieces that make a study's result independent of
//! how its work is split: [`ExactSum`] (exact, order-independent sums) and [`Shard`] (one of `N`
//! contiguous shares of a study's work units).

mod exact_sum;
mod scalar;
mod shard;

pub use exact_sum::ExactSum;
pub use scalar::*;
pub use shard::{Shard, MAX_SHARDS};
