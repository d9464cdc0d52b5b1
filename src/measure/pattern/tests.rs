use super::*;
use crate::math::{linear_to_db, PI};

fn parabolic(beamwidth_deg: Real, floor_db: Real) -> TxPattern {
    TxPattern::new(
        9.0,
        &Pattern::Parabolic {
            boresight_deg: 10.0,
            beamwidth_deg,
            floor_db,
        },
    )
}

/// The fitted polynomial equals the exact §9.3 formula to 1e-12 relative at directions
/// other than those used in the fit's own check (odd multiples of a prime fraction of 2π).
#[test]
fn polynomial_matches_exact_pattern() {
    for (bw, floor) in [(70.0, 20.0), (30.0, 25.0), (120.0, 10.0)] {
        let p = parabolic(bw, floor);
        let poly = p
            .polynomial
            .as_ref()
            .expect("fit exists for a main lobe below 171 degrees");
        for i in 0..997 {
            let phi = 2.0 * PI * i as Real / 997.0;
            let c = cos(phi);
            let exact = p.gain_toward_cos(c);
            assert!(
                (poly.gain_at_cos(c) - exact).abs() <= GAIN_POLYNOMIAL_TOLERANCE * exact,
                "bw {bw} phi {phi}"
            );
        }
    }
}

/// A floor so deep that the main lobe reaches the back direction (ψ_floor ≥ 171°) has no
/// polynomial; the map kernel then uses the exact formula.
#[test]
fn deep_floor_falls_back_to_exact() {
    assert!(parabolic(70.0, 80.0).polynomial.is_none());
    assert!(TxPattern::new(8.0, &Pattern::Omni).polynomial.is_none());
}

/// §9.3 gains of the L4 pattern (boresight 10°, ψ_3dB = 70°, A_m = 20 dB, G₀ = 9 dBi).
#[test]
fn spec_gains_toward_l4_receivers() {
    let p = parabolic(70.0, 20.0);
    let toward = |x: Real, y: Real| linear_to_db(p.gain_toward(Vec2::new(x, y).normalize()));
    // §9.3: gains toward Rx1..Rx4 −11, 6.0, −11, 5.73 dBi.
    assert!((toward(-5.0, 12.0) + 11.0).abs() < 1e-12);
    assert!((toward(10.0, 10.0) - 6.0).abs() < 1e-12);
    assert!((toward(-6.0, -8.0) + 11.0).abs() < 1e-12);
    assert!((toward(12.0, -6.0) - 5.73).abs() < 5e-3);
}

/// `gains_toward` for 4 directions at once is, lane by lane and bitwise, the one-direction gain:
/// the peak gain for a zero direction (a point on the Tx), else the polynomial (or, without one,
/// the exact formula) at `c = u·boresight`; for omni patterns the peak gain.
#[test]
fn gains_toward_is_gain_toward_per_lane() {
    let patterns = [
        parabolic(70.0, 20.0),
        parabolic(70.0, 80.0),
        TxPattern::new(8.0, &Pattern::Omni),
    ];
    for p in &patterns {
        let one = |u: Vec2| -> Real {
            let Some(b) = &p.beam else {
                return p.peak_gain;
            };
            if u.x == 0.0 && u.y == 0.0 {
                return p.peak_gain;
            }
            let c = u.x * b.boresight.x + u.y * b.boresight.y;
            match &p.polynomial {
                Some(poly) => poly.gain_at_cos(c),
                None => p.gain_toward_cos(c),
            }
        };
        for i in 0..250 {
            let dirs: [Vec2; 4] = core::array::from_fn(|l| {
                if (i + l) % 7 == 0 {
                    Vec2::zeros()
                } else {
                    let phi = 2.0 * PI * (4 * i + l) as Real / 997.0;
                    Vec2::new(cos(phi), sin(phi))
                }
            });
            let got = p.gains_toward(dirs.map(|u| u.x), dirs.map(|u| u.y));
            for (g, u) in got.iter().zip(&dirs) {
                assert_eq!(g.to_bits(), one(*u).to_bits(), "{u:?}");
                assert_eq!(g.to_bits(), p.gain_toward(*u).to_bits(), "{u:?}");
            }
        }
    }
}
