//! Measurement simulation (E2): noisy delays `τ̂ = h(r) + w`, `w_p ~ 𝒩(0, σ_p²(r))` with `σ_p`
//! from the link budget at the true position (E8). Seeded, so a result depends on the seed only.

use alloc::vec::Vec;

use rand::SeedableRng;
use rand_distr::{Distribution, StandardNormal};
use rand_pcg::Pcg64Mcg;

use crate::math::{Real, Vec2};
use crate::measure::Model;

/// The crate's random number generator: PCG-64 MCG, seeded from a `u64`.
pub type Rng = Pcg64Mcg;

/// A generator for `(seed, stream)`: independent streams for run indices, the same numbers on
/// every platform and thread count.
pub fn rng(seed: u64, stream: u64) -> Rng {
    // SplitMix64 of the pair, so neighbouring (seed, stream) values give unrelated states.
    let mut z = seed ^ stream.wrapping_mul(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    Pcg64Mcg::seed_from_u64(z ^ (z >> 31))
}

/// One standard normal sample.
#[inline]
pub fn standard_normal(rng: &mut Rng) -> Real {
    StandardNormal.sample(rng)
}

/// One uniform sample in `[0, 1)`.
#[inline]
pub fn uniform01(rng: &mut Rng) -> Real {
    rand_distr::StandardUniform.sample(rng)
}

/// Noisy delays of every link for a scatterer at `r`, with `σ_p(r)` from the link budget, s.
pub fn noisy_delays(model: &Model, r: Vec2, rng: &mut Rng) -> Vec<Real> {
    (0..model.link_count())
        .map(|p| model.network.delay(p, r) + model.sigma_delay(p, r) * standard_normal(rng))
        .collect()
}
