//! Delay and Doppler in the trackers (issue 42 §3; docs/doppler.md D1, D3, D5, D8): one scan's
//! range rates ([`RangeRates`]) and where their σ comes from ([`RateNoise`]), their checks, and
//! the measurement rows every filter's delay-and-Doppler update reads — each present delay as
//! the range row `[û_T + û_R, 0]` (E1, E3, in the range domain like the delay-only update) and
//! each present range rate as the row `[∂ṙ/∂r, ∂ṙ/∂v]` (D3), both from one evaluation of the
//! link ([`LinkMotion`]). A link may give either or both. A static path has `ṙ = 0`, so the range
//! rate is also the gate's strongest cue against walls (see the multi-target sensors).

use alloc::format;

use crate::error::{check_len, limits, Error, Result};
use crate::math::{Real, Vec2, Vec4, PI, SPEED_OF_LIGHT};
use crate::measure::{sigma_delay_from_snr, Cpi, LinkMotion, Model, NodeMotion};
use crate::track::shared::{
    first_input_error, information_from_sigma, positive_finite, range_information_per_snr,
};
use crate::track::MeasurementNoise;

/// Where the range rates' noise `σ_ṙ,p` comes from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum RateNoise<'a> {
    /// Fixed `σ_ṙ` per link, m/s (an estimator's own σ).
    Fixed(&'a [Real]),
    /// `σ_ṙ` of the CPI (D5) at the link's SNR at the predicted position.
    Cpi(Cpi),
    /// `σ_ṙ` of the CPI at the link's SNR at a given position (the oracle option).
    CpiAt(Cpi, Vec2),
}

impl RateNoise<'_> {
    /// `σ_ṙ` of link `p` for a filter at `r_pred` whose link geometry there is `geometry`
    /// (`+∞` where the CPI holds no Doppler information: that rate is then not used).
    #[inline]
    pub fn sigma(&self, model: &Model, p: usize, geometry: &LinkMotion) -> Real {
        match *self {
            RateNoise::Fixed(s) => s[p],
            RateNoise::Cpi(c) => c.sigma_range_rate(geometry.snr(model, p)),
            RateNoise::CpiAt(c, r) => c.sigma_range_rate(model.snr(p, r)),
        }
    }
}

/// One scan's measured range rates, m/s (one per link in scenario link order, `None` =
/// missing), and their noise.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RangeRates<'a> {
    /// `ṙ_p`, m/s.
    pub rates_mps: &'a [Option<Real>],
    /// Where `σ_ṙ,p` comes from.
    pub noise: RateNoise<'a>,
}

/// The filter's predicted range rate of one link, `ṙ_p(x̂⁻)` (D1), and its innovation σ
/// `√(H_p P H_pᵀ + σ_ṙ²)` (D3), m/s; `+∞` σ where the rate carries no information.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PredictedRate {
    /// `ṙ_p(x̂⁻)`, m/s.
    pub range_rate_mps: Real,
    /// `√S_pp`, m/s.
    pub innovation_sigma_mps: Real,
}

impl PredictedRate {
    /// `|ṙ − ṙ_p(x̂⁻)| / √S_pp` (0 when the σ is infinite).
    pub fn normalized_innovation(&self, rate_mps: Real) -> Real {
        (rate_mps - self.range_rate_mps).abs() / self.innovation_sigma_mps
    }
}

/// One measurement row in the range domain: whether it is a range rate (else a range), the
/// measured value `z` (m or m/s), `h` (a row of the state Jacobian at `x̂⁻`), the information
/// `w = 1/σ²` and the innovation `ν = z − h(x̂⁻)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Row {
    pub rate: bool,
    pub z: Real,
    pub h: Vec4,
    pub w: Real,
    pub nu: Real,
}

impl Row {
    /// This row's measurement function at the state `x` on link `p`: the range (E1) or the
    /// range rate (D1).
    #[inline]
    pub fn value_at(&self, model: &Model, p: usize, x: &Vec4) -> Real {
        let g = LinkMotion::new(
            &model.network,
            p,
            Vec2::new(x[0], x[1]),
            Vec2::new(x[2], x[3]),
        );
        if self.rate {
            g.range_rate_mps
        } else {
            g.range_m
        }
    }
}

/// The checks of a delay-and-Doppler update at the predicted position `r`: the delays as the
/// delay-only update checks them ([`first_input_error`]), then `rates` of one entry per link
/// (`LengthMismatch` of `range_rates`), `Fixed` rate noise of one σ per link (`LengthMismatch`
/// of `range_rate_sigma_mps`), each rate within [`limits::RANGE_RATE_M_S`] and each given σ
/// within [`limits::RANGE_RATE_SIGMA_M_S`] (`OutOfRange` naming the entry).
///
/// A delay's σ from the link budget (`AtPrediction`, `At`) is checked by [`rows`] at the same
/// position, in link order and with the same error, so the link budget is evaluated once per
/// link and update. When every other check passes this returns at once (no field name is
/// formatted); otherwise [`check_rates_named`] gives the first error in the order above.
pub(crate) fn check_rates(
    model: &Model,
    z: &[Option<Real>],
    noise: MeasurementNoise,
    rates: &RangeRates,
    r: Vec2,
) -> Result<()> {
    let n = model.link_count();
    check_len("measurement", n, z.len())?;
    noise.check_links(n)?;
    let delays_ok = match noise {
        // A given σ costs nothing to check: the delay-only update's own check.
        MeasurementNoise::Fixed(_) => first_input_error(model, z, noise, r).is_none(),
        _ => z.iter().flatten().all(|&t| limits::DELAY_S.contains(t)),
    };
    let sigmas = match rates.noise {
        RateNoise::Fixed(s) => Some(s),
        _ => None,
    };
    let ok = delays_ok
        && rates.rates_mps.len() == n
        && sigmas.is_none_or(|s| s.len() == n)
        && rates.rates_mps.iter().enumerate().all(|(p, rate)| {
            rate.is_none_or(|v| {
                limits::RANGE_RATE_M_S.contains(v)
                    && sigmas.is_none_or(|s| limits::RANGE_RATE_SIGMA_M_S.contains(s[p]))
            })
        });
    if ok {
        Ok(())
    } else {
        check_rates_named(model, z, noise, rates, r)
    }
}

/// [`check_rates`] in full, naming the first bad field (also a delay's σ from the link budget).
#[cold]
fn check_rates_named(
    model: &Model,
    z: &[Option<Real>],
    noise: MeasurementNoise,
    rates: &RangeRates,
    r: Vec2,
) -> Result<()> {
    let n = model.link_count();
    if let Some(e) = first_input_error(model, z, noise, r) {
        return Err(e);
    }
    check_len("range_rates", n, rates.rates_mps.len())?;
    if let RateNoise::Fixed(s) = rates.noise {
        check_len("range_rate_sigma_mps", n, s.len())?;
    }
    for (p, rate) in rates.rates_mps.iter().enumerate() {
        let Some(rate) = *rate else { continue };
        limits::RANGE_RATE_M_S.check(&format!("range_rates[{p}]"), rate)?;
        if let RateNoise::Fixed(s) = rates.noise {
            limits::RANGE_RATE_SIGMA_M_S.check(&format!("range_rate_sigma_mps[{p}]"), s[p])?;
        }
    }
    Ok(())
}

/// The rows of one update linearised at `x` (after [`check_rates`]), in link order, a link's
/// delay before its rate: `row(p, row)` for each. A rate whose σ is not finite and positive
/// carries no information and is skipped. A delay's σ from the link budget that the delay-only
/// update refuses ([`first_input_error`]'s test) is [`Error::InvalidSigma`] of its link, the
/// first in link order. The link budget (E8) is evaluated at most once per link. The number of
/// links that gave a row.
#[inline]
pub(crate) fn rows(
    model: &Model,
    x: &Vec4,
    z: &[Option<Real>],
    noise: MeasurementNoise,
    rates: &RangeRates,
    mut row: impl FnMut(usize, Row),
) -> Result<usize> {
    let (r, v) = (Vec2::new(x[0], x[1]), Vec2::new(x[2], x[3]));
    let info_per_snr = range_information_per_snr(model);
    // `8π²β²`: the delay's information per SNR in the time domain (E8).
    let delay_info_per_snr = 8.0 * PI * PI * model.beta2;
    // The last transmitter seen from `r` and, once a link needed it, its gain toward `r`:
    // shared by its links (the link order is Tx-fastest, spec §1; sensors2019's 4 links share
    // one transmitter).
    let mut tx_seen: Option<(usize, NodeMotion, Option<Real>)> = None;
    let snr_needed =
        matches!(noise, MeasurementNoise::AtPrediction) || matches!(rates.noise, RateNoise::Cpi(_));
    let mut links = 0;
    for p in 0..model.link_count() {
        let (zp, rate) = (z[p], rates.rates_mps[p]);
        if zp.is_none() && rate.is_none() {
            continue;
        }
        let link = model.network.links[p];
        let seen = match &mut tx_seen {
            Some((t, seen, gain)) if *t == link.tx => (seen, gain),
            slot => {
                let node = model.network.transmitters[link.tx];
                let dz = model.network.transmitters_dz[link.tx];
                let seen = slot.insert((link.tx, NodeMotion::new(node, dz, r, v), None));
                (&mut seen.1, &mut seen.2)
            }
        };
        let rx = NodeMotion::new(
            model.network.receivers[link.rx],
            model.network.receivers_dz[link.rx],
            r,
            v,
        );
        let g = LinkMotion::of_nodes(seen.0, &rx, v);
        // The link's SNR at `r` once (the same bits as `g.snr(model, p)`, the transmitter's
        // gain shared by the links of one transmitter), where a σ needs it.
        let snr = if snr_needed {
            let gain = *seen
                .1
                .get_or_insert_with(|| model.patterns[link.tx].gain_toward(g.unit_tx));
            model.snr_from_geometry(p, gain, g.distances_m.0, g.distances_m.1)
        } else {
            Real::NAN
        };
        let mut used = false;
        if let Some(tau) = zp {
            let (w, sigma) = match noise {
                MeasurementNoise::Fixed(_) => {
                    let sigma = noise.sigma(model, p, r);
                    let s = SPEED_OF_LIGHT * sigma;
                    (1.0 / (s * s), sigma)
                }
                MeasurementNoise::AtPrediction => {
                    // σ = 1/√(8π²β² SNR) is finite, > 0 and of finite information whenever
                    // 8π²β² SNR lies in [1e-300, 1e300]; only outside is it formed and tested.
                    let q = delay_info_per_snr * snr;
                    if !(1e-300..=1e300).contains(&q) {
                        let sigma = sigma_delay_from_snr(model.beta2, snr);
                        if !delay_sigma_ok(sigma) {
                            return Err(Error::InvalidSigma {
                                link: p,
                                value: sigma,
                            });
                        }
                    }
                    (info_per_snr * snr, Real::NAN)
                }
                MeasurementNoise::At(_) => {
                    let sigma = noise.sigma(model, p, r);
                    if !delay_sigma_ok(sigma) {
                        return Err(Error::InvalidSigma {
                            link: p,
                            value: sigma,
                        });
                    }
                    let s = SPEED_OF_LIGHT * sigma;
                    (1.0 / (s * s), sigma)
                }
            };
            if !(positive_finite(w)) {
                return Err(Error::InvalidSigma {
                    link: p,
                    value: match noise {
                        MeasurementNoise::AtPrediction => sigma_delay_from_snr(model.beta2, snr),
                        _ => sigma,
                    },
                });
            }
            let h = Vec4::new(g.range_gradient.x, g.range_gradient.y, 0.0, 0.0);
            let z = SPEED_OF_LIGHT * tau;
            row(
                p,
                Row {
                    rate: false,
                    z,
                    h,
                    w,
                    nu: z - g.range_m,
                },
            );
            used = true;
        }
        if let Some(rate) = rate {
            // `1/σ_ṙ²`; the CPI's (D5) without forming its square root, the rate skipped where
            // `σ_ṙ` is not finite and positive (no Doppler information).
            let w = match rates.noise {
                RateNoise::Cpi(c) => {
                    let f = c.doppler_information(snr);
                    let var = c.wavelength_m * c.wavelength_m / f + c.floor_mps * c.floor_mps;
                    (f > 0.0 && positive_finite(var)).then(|| 1.0 / var)
                }
                // Inline, not through `sigma`: a call there spills every live register of the
                // row loop (issue 42 §4).
                RateNoise::Fixed(s) => {
                    let s = s[p];
                    positive_finite(s).then(|| 1.0 / (s * s))
                }
                other => {
                    let s = other.sigma(model, p, &g);
                    positive_finite(s).then(|| 1.0 / (s * s))
                }
            };
            if let Some(w) = w {
                row(
                    p,
                    Row {
                        rate: true,
                        z: rate,
                        h: g.rate_row(),
                        w,
                        nu: rate - g.range_rate_mps,
                    },
                );
                used = true;
            }
        }
        links += usize::from(used);
    }
    Ok(links)
}

/// Whether a delay's σ from the link budget is one the delay-only update takes
/// ([`first_input_error`]: finite, `> 0`, finite information).
#[inline(always)]
fn delay_sigma_ok(sigma: Real) -> bool {
    positive_finite(sigma) && information_from_sigma(sigma).is_finite()
}
