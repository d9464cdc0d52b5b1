//! The measurement model of one scatterer: bistatic geometry, the one home of range, delay and
//! their gradients (E1, E3, and the range function (M1) of the multi-target layer), iso-delay and
//! covariance ellipses (spec §2), the Tx antenna pattern (§9.3), the link budget that sets each
//! link's SNR and delay standard deviation `σ_τ` (E8) in [`Model`], the range rate and a CPI's
//! Doppler information (`doppler.rs`, D1–D7), and seeded noise draws (E2).

mod doppler;
mod ellipse;
mod geometry;
mod model;
mod pattern;
mod simulate;

pub use doppler::{
    range_rate, range_rate_gradient, state_bounds, state_fisher, Cpi, LinkMotion, NodeMotion,
    DEFAULT_RANGE_RATE_FLOOR_MPS, MAX_CPI_SNAPSHOTS,
};
pub use ellipse::Ellipse;
pub use geometry::{
    bistatic_delay, bistatic_range, bistatic_range_dz, delay_gradient, iso_delay_ellipse,
    iso_range_ellipse, los_range_dz, node_distance, range_and_gradient, range_and_gradient_dz,
    range_gradient, unit_from, unit_from_dz, vertical_unit, Network, UNIT_VECTOR_MIN_DISTANCE_M,
};
pub use model::{
    noise_power_w, sigma_delay_from_snr, Model, DEFAULT_NOISE_FIGURE_DB, SNR_DISTANCE_FLOOR_M,
};
pub use pattern::{Beam, GainPolynomial, TxPattern, GAIN_POLYNOMIAL_TOLERANCE};
pub use simulate::{noisy_delays, rng, standard_normal, uniform01, Rng};
