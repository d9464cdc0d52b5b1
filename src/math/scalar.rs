//! Scalar and small-matrix aliases, physical constants and the few elementary functions the
//! core needs. The transcendental functions (`exp`, `ln`, `log10`, `cos`, `sin`, `acos`,
//! `atan2`) are the `libm` crate's on every platform, with or without `std`: the platform's own
//! (glibc natively, Rust's musl port in wasm) differ in the last bit for some arguments, and
//! iterations that stop at a tolerance (the LM start fix, the estimator's fits) carried that to
//! 10⁻⁷ relative between the CLI and the page (issue 26). Now native and wasm give the same bits.
//! `sqrt` and `round` are exact (IEEE) everywhere and stay the platform's.

/// The one floating-point type of the crate.
pub type Real = f64;
/// A 2-D position or direction in metres, `r = [x, y]ᵀ`.
pub type Vec2 = nalgebra::Vector2<Real>;
/// A symmetric 2×2 matrix (Fisher information in 1/m², covariance in m²).
pub type Mat2 = nalgebra::Matrix2<Real>;
/// A 3-D position `[x, y, z]ᵀ` in metres (a fix with a free height, issue 40 §2).
pub type Vec3 = nalgebra::Vector3<Real>;
/// A symmetric 3×3 matrix (Fisher information or covariance over `[x, y, z]`).
pub type Mat3 = nalgebra::Matrix3<Real>;
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

/// A Fisher matrix whose reciprocal condition number `λ_min/λ_max` is below this is treated as
/// singular: the position is unbounded along some direction (collinear or too few informative
/// links, a point on a baseline with too few other links). The one rule of every bound: the
/// snapshot CRLB (`localize`) and the bound with Doppler (`measure::state_bounds`, on the
/// matrix scaled to a unit diagonal).
pub const SINGULAR_RCOND: Real = 1e-12;

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
    libm::acos(x)
}

/// `x^y` (`libm`'s: the same bits natively and in wasm).
#[inline(always)]
pub fn pow(x: Real, y: Real) -> Real {
    libm::pow(x, y)
}

/// Natural exponential.
#[inline(always)]
pub fn exp(x: Real) -> Real {
    libm::exp(x)
}

/// Base-10 logarithm.
#[inline(always)]
pub fn log10(x: Real) -> Real {
    libm::log10(x)
}

/// Natural logarithm.
#[inline(always)]
pub fn ln(x: Real) -> Real {
    libm::log(x)
}

/// Complementary error function.
#[inline(always)]
pub fn erfc(x: Real) -> Real {
    libm::erfc(x)
}

/// Cosine.
#[inline(always)]
pub fn cos(x: Real) -> Real {
    libm::cos(x)
}

/// Sine.
#[inline(always)]
pub fn sin(x: Real) -> Real {
    libm::sin(x)
}

/// Sine and cosine together, `(sin x, cos x)`: the same bits as [`sin`] and [`cos`] (one
/// argument reduction instead of two).
#[inline(always)]
pub fn sincos(x: Real) -> (Real, Real) {
    libm::sincos(x)
}

/// Two-argument arc tangent.
#[inline(always)]
pub fn atan2(y: Real, x: Real) -> Real {
    libm::atan2(y, x)
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

/// Largest integer not above `x`.
#[inline(always)]
pub fn floor(x: Real) -> Real {
    #[cfg(feature = "std")]
    {
        x.floor()
    }
    #[cfg(not(feature = "std"))]
    {
        libm::floor(x)
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

#[cfg(test)]
mod tests {
    use super::*;

    /// `sincos` is bit-identical to `sin` and `cos` (the estimator's phasors rely on it), over
    /// every argument range of the argument reduction: tiny, `|x| < π/4`, medium, huge.
    #[test]
    fn sincos_is_sin_and_cos_bit_for_bit() {
        let mut x: Real = 1e-300;
        while x < 1e300 {
            for v in [x, -x, x * 1.234_567, -x * 0.987_654] {
                let (s, c) = sincos(v);
                assert_eq!(s.to_bits(), sin(v).to_bits(), "sin {v}");
                assert_eq!(c.to_bits(), cos(v).to_bits(), "cos {v}");
            }
            x *= 1.37;
        }
    }
}
