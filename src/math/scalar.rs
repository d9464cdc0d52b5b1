//! Scalar and small-matrix aliases, physical constants and the few elementary functions the
//! core needs. With `std` the platform's libm is used; without it the `libm` crate, so the same
//! code builds for `wasm32v1-none`.

/// The one floating-point type of the crate.
pub type Real = f64;
/// A 2-D position or direction in metres, `r = [x, y]ᵀ`.
pub type Vec2 = nalgebra::Vector2<Real>;
/// A symmetric 2×2 matrix (Fisher information in 1/m², covariance in m²).
pub type Mat2 = nalgebra::Matrix2<Real>;
/// A tracking state `[x, y, vx, vy]ᵀ` (m, m/s) (S11).
pub type Vec4 = nalgebra::Vector4<Real>;
/// A 4×4 matrix over the tracking state (transition, covariance, information).
pub type Mat4 = nalgebra::Matrix4<Real>;
/// A complex number of [`Real`]s (channel responses and path amplitudes, spec C1).
pub type Complex = nalgebra::Complex<Real>;

/// Speed of light in vacuum `c`, m/s.
pub const SPEED_OF_LIGHT: Real = 299_792_458.0;
/// Boltzmann constant `k_B`, J/K.
pub const BOLTZMANN: Real = 1.380_649e-23;
/// Reference noise temperature `T₀`, K (spec §7).
pub const REFERENCE_TEMPERATURE_K: Real = 290.0;
/// π.
pub const PI: Real = core::f64::consts::PI;

/// Square root.
#[inline(always)]
pub fn sqrt(x: Real) -> Real {
    #[cfg(feature = "std")]
    {
        x.sqrt()
    }
    #[cfg(not(feature = "std"))]
    {
        libm::sqrt(x)
    }
}

/// Arc cosine.
#[inline(always)]
pub fn acos(x: Real) -> Real {
    #[cfg(feature = "std")]
    {
        x.acos()
    }
    #[cfg(not(feature = "std"))]
    {
        libm::acos(x)
    }
}

/// Natural exponential.
#[inline(always)]
pub fn exp(x: Real) -> Real {
    #[cfg(feature = "std")]
    {
        x.exp()
    }
    #[cfg(not(feature = "std"))]
    {
        libm::exp(x)
    }
}

/// Base-10 logarithm.
#[inline(always)]
pub fn log10(x: Real) -> Real {
    #[cfg(feature = "std")]
    {
        x.log10()
    }
    #[cfg(not(feature = "std"))]
    {
        libm::log10(x)
    }
}

/// Natural logarithm.
#[inline(always)]
pub fn ln(x: Real) -> Real {
    #[cfg(feature = "std")]
    {
        x.ln()
    }
    #[cfg(not(feature = "std"))]
    {
        libm::log(x)
    }
}

/// Complementary error function.
#[inline(always)]
pub fn erfc(x: Real) -> Real {
    libm::erfc(x)
}

/// Cosine.
#[inline(always)]
pub fn cos(x: Real) -> Real {
    #[cfg(feature = "std")]
    {
        x.cos()
    }
    #[cfg(not(feature = "std"))]
    {
        libm::cos(x)
    }
}

/// Sine.
#[inline(always)]
pub fn sin(x: Real) -> Real {
    #[cfg(feature = "std")]
    {
        x.sin()
    }
    #[cfg(not(feature = "std"))]
    {
        libm::sin(x)
    }
}

/// Two-argument arc tangent.
#[inline(always)]
pub fn atan2(y: Real, x: Real) -> Real {
    #[cfg(feature = "std")]
    {
        y.atan2(x)
    }
    #[cfg(not(feature = "std"))]
    {
        libm::atan2(y, x)
    }
}

/// Nearest integer, halves away from zero.
#[inline(always)]
pub fn round(x: Real) -> Real {
    #[cfg(feature = "std")]
    {
        x.round()
    }
    #[cfg(not(feature = "std"))]
    {
        libm::round(x)
    }
}

/// Decibels to a linear power ratio: `10^(db/10)`.
#[inline]
pub fn db_to_linear(db: Real) -> Real {
    exp(db * (core::f64::consts::LN_10 / 10.0))
}

/// A linear power ratio to decibels: `10·log10(x)`.
#[inline]
pub fn linear_to_db(x: Real) -> Real {
    10.0 * log10(x)
}

/// dBm to watts.
#[inline]
pub fn dbm_to_watt(dbm: Real) -> Real {
    db_to_linear(dbm - 30.0)
}

/// Watts to dBm.
#[inline]
pub fn watt_to_dbm(w: Real) -> Real {
    linear_to_db(w) + 30.0
}

/// Degrees to radians.
#[inline]
pub fn deg_to_rad(deg: Real) -> Real {
    deg * (PI / 180.0)
}

/// Radians to degrees.
#[inline]
pub fn rad_to_deg(rad: Real) -> Real {
    rad * (180.0 / PI)
}

/// The elementary functions of iterations whose path must not depend on the platform (the
/// planner's CMA-ES; the channel front end — simulator, estimator, figures — whose page results
/// must equal the CLI's): always the `libm` crate, so native and wasm builds get the same bits.
/// (With `std`, [`exp`], [`ln`], [`cos`], … are the platform's, which differ in the last bits:
/// through the estimator's joint Fisher matrix that was 1.3·10⁻¹² relative in a path's σ̂_τ.)
pub mod portable {
    use super::Real;

    /// Natural exponential, the same bits on every platform.
    #[inline]
    pub fn exp(x: Real) -> Real {
        libm::exp(x)
    }

    /// Natural logarithm, the same bits on every platform.
    #[inline]
    pub fn ln(x: Real) -> Real {
        libm::log(x)
    }

    /// Cosine, the same bits on every platform.
    #[inline]
    pub fn cos(x: Real) -> Real {
        libm::cos(x)
    }

    /// Sine, the same bits on every platform.
    #[inline]
    pub fn sin(x: Real) -> Real {
        libm::sin(x)
    }

    /// Base-10 logarithm, the same bits on every platform.
    #[inline]
    pub fn log10(x: Real) -> Real {
        libm::log10(x)
    }

    /// `atan2(y, x)`, the same bits on every platform.
    #[inline]
    pub fn atan2(y: Real, x: Real) -> Real {
        libm::atan2(y, x)
    }

    /// Decibels to a linear power ratio `10^(db/10)`, the same bits on every platform.
    #[inline]
    pub fn db_to_linear(db: Real) -> Real {
        exp(db * (core::f64::consts::LN_10 / 10.0))
    }

    /// dBm to watts, the same bits on every platform.
    #[inline]
    pub fn dbm_to_watt(dbm: Real) -> Real {
        db_to_linear(dbm - 30.0)
    }
}
