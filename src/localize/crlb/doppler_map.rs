//! The bound with Doppler over a grid (issue 42 §1, `crlb-map --quantity`): per cell the state
//! Fisher matrix of delays and range rates over one CPI (D7, [`state_fisher`]) for a target
//! moving at one velocity, and its position or velocity bound ([`state_bounds`]).

use crate::error::{Error, Result};
use crate::math::{Real, Vec2, Vec4};
use crate::measure::{state_bounds, state_fisher, Cpi, Model};

use super::Grid;

/// What a map with Doppler shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MapQuantity {
    /// `√(tr P_rr)`, m: the position bound with delays and range rates.
    Position,
    /// `√(tr P_vv)`, m/s: the velocity bound.
    Velocity,
}

/// Fills `out` (`grid.len()` cells, rows ascending in y) with `quantity`'s bound over `cpi` for
/// a target moving at `velocity` m/s; `+∞` where the information is singular. A wrong `out`
/// length or a non-finite velocity is a named error.
pub fn doppler_map(
    model: &Model,
    grid: &Grid,
    cpi: &Cpi,
    velocity: Vec2,
    quantity: MapQuantity,
    out: &mut [Real],
) -> Result<()> {
    if out.len() != grid.len() {
        return Err(Error::SizeLimit {
            field: "doppler map output",
            value: out.len(),
            min: grid.len(),
            max: grid.len(),
        });
    }
    if !(velocity.x.is_finite() && velocity.y.is_finite()) {
        return Err(Error::NonFinite {
            field: "velocity".into(),
        });
    }
    for j in 0..grid.ny {
        for i in 0..grid.nx {
            let x = Vec4::new(grid.x(i), grid.y(j), velocity.x, velocity.y);
            let b = state_bounds(&state_fisher(model, &x, cpi, true));
            out[j * grid.nx + i] = match (b, quantity) {
                (Some((p, _)), MapQuantity::Position) => p,
                (Some((_, v)), MapQuantity::Velocity) => v,
                (None, _) => Real::INFINITY,
            };
        }
    }
    Ok(())
}
