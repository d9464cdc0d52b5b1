//! The frequency-domain view of a recording's link (C1, C2): the bins `f_n`, the system
//! response `P[n]`, and each snapshot's `H[n]` (a CIR mapped by a DFT, keeping the in-band bins).

use alloc::vec::Vec;

use crate::math::{Complex, Real};

/// The band an estimator works on: `f_n` (uniform, Hz) and `P[n]`.
#[derive(Debug, Clone, PartialEq)]
pub struct Band {
    /// Baseband frequencies `f_n`, Hz, uniformly spaced, increasing.
    pub freq_hz: Vec<Real>,
    /// The system response `P[n]` (all ones for a calibrated sounder).
    pub response: Vec<Complex>,
}
