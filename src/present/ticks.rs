//! Presentation helpers shared by every front end (the page, figures): 1-2-5 "nice" numbers,
//! linear and logarithmic axis ticks with clean labels, and length labels in µm/mm/cm/m/km.
//! Pure functions, so the page's JavaScript only places text where these say.

use alloc::format;
use alloc::string::{String, ToString};
use alloc::vec::Vec;

use crate::math::{log10, round, Real};

/// A tick: its value and its label.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Tick {
    /// Value, in the axis unit (m for lengths).
    pub value: Real,
    /// Text to print.
    pub label: String,
}

/// The double nearest to `mantissa · 10^exp10` (decimal parse, so `3 · 10^-1` is exactly `0.3`).
pub fn decimal(mantissa: i64, exp10: i32) -> Real {
    format!("{mantissa}e{exp10}").parse().unwrap_or(Real::NAN)
}

/// `⌊log10 x⌋` for finite `x > 0`, robust to rounding at exact powers of ten.
fn decade(x: Real) -> i32 {
    let mut k = libm::floor(log10(x)) as i32;
    if decimal(1, k + 1) <= x {
        k += 1;
    } else if decimal(1, k) > x {
        k -= 1;
    }
    k
}

/// The largest `m · 10^k` with `m ∈ {1, 2, 5}` that is `≤ x`, as `(m, k)`; `None` unless
/// `x` is finite and > 0.
pub fn nice_below(x: Real) -> Option<(i64, i32)> {
    if !(x.is_finite() && x > 0.0) {
        return None;
    }
    let k = decade(x);
    let m = [5, 2, 1]
        .into_iter()
        .find(|&m| decimal(m, k) <= x)
        .unwrap_or(1);
    Some((m, k))
}

/// The smallest `m · 10^k` with `m ∈ {1, 2, 5}` that is `≥ x`, as `(m, k)`.
fn nice_above(x: Real) -> Option<(i64, i32)> {
    let (m, k) = nice_below(x)?;
    if decimal(m, k) >= x {
        return Some((m, k));
    }
    Some(match m {
        1 => (2, k),
        2 => (5, k),
        _ => (1, k + 1),
    })
}

/// Longest label written without an exponent, digits: past it `mantissa · 10^exp10` is written
/// as `2.5e12` (spans like ±1e300 would otherwise give 301-digit labels).
const MAX_PLAIN_DIGITS: usize = 12;

/// Formats `mantissa · 10^exp10` exactly (`-25, -1` → `"−2.5"`), without exponent unless that
/// would take more than [`MAX_PLAIN_DIGITS`] digits (`25, 20` → `"2.5e21"`).
fn decimal_label(mantissa: i64, exp10: i32) -> String {
    let neg = mantissa < 0;
    let digits = mantissa.unsigned_abs().to_string();
    let plain_digits = if exp10 >= 0 {
        digits.len() + exp10 as usize
    } else {
        digits.len().max(exp10.unsigned_abs() as usize + 1)
    };
    let body = if digits != "0" && plain_digits > MAX_PLAIN_DIGITS {
        let (lead, rest) = digits.split_at(1);
        let rest = rest.trim_end_matches('0');
        let e = exp10 + digits.len() as i32 - 1;
        if rest.is_empty() {
            format!("{lead}e{e}")
        } else {
            format!("{lead}.{rest}e{e}")
        }
    } else if exp10 >= 0 {
        let mut s = digits;
        if s != "0" {
            s.extend(core::iter::repeat_n('0', exp10 as usize));
        }
        s
    } else {
        let frac = (-exp10) as usize;
        let padded = if digits.len() <= frac {
            let mut p: String = core::iter::repeat_n('0', frac + 1 - digits.len()).collect();
            p.push_str(&digits);
            p
        } else {
            digits
        };
        let (int, fr) = padded.split_at(padded.len() - frac);
        let fr = fr.trim_end_matches('0');
        if fr.is_empty() {
            int.to_string()
        } else {
            format!("{int}.{fr}")
        }
    };
    if neg && body != "0" {
        format!("\u{2212}{body}")
    } else {
        body
    }
}

/// Ticks at multiples of a 1-2-5 step over `[lo, hi]`, at most about `max_count` of them, with
/// exact decimal labels (`"−2.5"`, `"10"`). Empty when the range is not finite or not increasing.
pub fn linear_ticks(lo: Real, hi: Real, max_count: usize) -> Vec<Tick> {
    if !(lo.is_finite() && hi.is_finite() && hi > lo) {
        return Vec::new();
    }
    let Some((m, k)) = nice_above((hi - lo) / max_count.max(1) as Real) else {
        return Vec::new();
    };
    let step = decimal(m, k);
    let (first, last) = (libm::ceil(lo / step), libm::floor(hi / step));
    // Tick indices times the mantissa must be exact integers: past 2⁵³/5 (a span that is tiny
    // against its distance from 0, e.g. [1e3, 1e3 + 1e-13]) no 1-2-5 step can be labelled
    // apart, so the axis gets its two ends.
    const EXACT: Real = 1.8e15;
    if !(first.abs() <= EXACT && last.abs() <= EXACT) {
        return [lo, hi]
            .into_iter()
            .map(|v| Tick {
                value: v,
                label: typographic_minus(crate::error::Num(v).to_string()),
            })
            .collect();
    }
    (first as i64..=last as i64)
        .take(1000)
        .map(|i| Tick {
            value: decimal(i * m, k),
            label: decimal_label(i * m, k),
        })
        .collect()
}

/// Ticks of a logarithmic axis over `[min, max]` (both > 0): 1-2-5 per decade while that gives
/// at most ten, else every decade (every other one beyond eight); never fewer than the two ends. Labels are lengths
/// ([`format_length_m`]).
pub fn log_length_ticks(min: Real, max: Real) -> Vec<Tick> {
    if !(min.is_finite() && max.is_finite() && min > 0.0 && max >= min) {
        return Vec::new();
    }
    let (lo, hi) = (min * (1.0 - 1e-9), max * (1.0 + 1e-9));
    let (k0, k1) = (decade(min), decade(max) + 1);
    let pick = |mantissas: &[i64]| -> Vec<Real> {
        let mut v = Vec::new();
        for k in k0..=k1 {
            for &m in mantissas {
                let x = decimal(m, k);
                if x >= lo && x <= hi {
                    v.push(x);
                }
            }
        }
        v
    };
    let mut values = pick(&[1, 2, 5]);
    if values.len() > 10 {
        values = pick(&[1]);
        if values.len() > 8 {
            values = values.into_iter().step_by(2).collect();
        }
    }
    if values.len() < 2 {
        values = alloc::vec![min, max];
    }
    values
        .into_iter()
        .map(|value| Tick {
            value,
            label: format_length_m(value, 3),
        })
        .collect()
}

/// Ticks of a logarithmic colour bar over `[min, max]` m — the one algorithm of the page's bar
/// and the figures' bars: the labelled [`log_length_ticks`], thinned to at most `max_labels`
/// (≥ 2; powers of ten first, then every other one), plus unlabelled minor ticks (empty label)
/// at the other integer multiples of each decade when the labels are at most a decade apart.
pub fn colorbar_ticks(min: Real, max: Real, max_labels: usize) -> Vec<Tick> {
    let max_labels = max_labels.max(2);
    let mut major = log_length_ticks(min, max);
    if major.len() > max_labels {
        // Too many for the bar: keep the powers of ten, then every other one.
        let decades: Vec<_> = major
            .iter()
            .filter(|t| (log10(t.value) - round(log10(t.value))).abs() < 1e-9)
            .cloned()
            .collect();
        if decades.len() >= 2 {
            major = decades;
        }
    }
    while major.len() > max_labels {
        major = major.into_iter().step_by(2).collect();
    }
    let mut out = major.clone();
    // Minor ticks only when the labels are at most a decade apart (not for thinned decades or the
    // bare end points of a flat map).
    let dense = major.len() >= 2 && major.windows(2).all(|w| w[1].value <= 10.0001 * w[0].value);
    if dense && min > 0.0 && max > min {
        let (k0, k1) = (decade(min), decade(max) + 1);
        for k in k0..=k1 {
            for m in 1..=9 {
                let v = decimal(m, k);
                let inside = v >= min * (1.0 - 1e-9) && v <= max * (1.0 + 1e-9);
                let taken = major.iter().any(|t| (t.value - v).abs() <= 1e-9 * v);
                if inside && !taken {
                    out.push(Tick {
                        value: v,
                        label: String::new(),
                    });
                }
            }
        }
    }
    out
}

/// A length in metres as text with a readable unit (µm, mm, cm, m, km) and `significant`
/// significant digits, trailing zeros dropped: `0.00426 → "4.26 mm"`, `0.0792 → "7.92 cm"`.
/// Infinite → `"∞"` (unbounded), NaN → `"–"`.
pub fn format_length_m(v: Real, significant: usize) -> String {
    if v.is_nan() {
        return "\u{2013}".into();
    }
    if v.is_infinite() {
        return if v > 0.0 {
            "\u{221e}"
        } else {
            "\u{2212}\u{221e}"
        }
        .into();
    }
    let a = v.abs();
    let (scale, unit) = if a == 0.0 {
        (1.0, "m")
    } else if a < 1e-3 {
        (1e-6, "\u{b5}m")
    } else if a < 1e-2 {
        (1e-3, "mm")
    } else if a < 1.0 {
        (1e-2, "cm")
    } else if a < 1e3 {
        (1.0, "m")
    } else {
        (1e3, "km")
    };
    let u = v / scale;
    let sig = significant.clamp(1, 17) as i32;
    let s = if u != 0.0 && !(1e-3..1e6).contains(&u.abs()) {
        // Below 1 nm or beyond 10⁶ km: a mantissa and an exponent, not hundreds of digits.
        let p = (sig - 1) as usize;
        let s = format!("{u:.p$e}");
        let (mant, exp) = s.split_once('e').unwrap_or((&s, "0"));
        format!("{}e{exp}", trim_fraction(mant))
    } else {
        let decimals = if u == 0.0 {
            0
        } else {
            (sig - 1 - decade(u.abs())).max(0) as usize
        };
        trim_fraction(&format!("{u:.decimals$}")).to_string()
    };
    format!("{} {unit}", typographic_minus(s))
}

/// `s` without trailing zeros of its fraction (and without a bare `.`).
fn trim_fraction(s: &str) -> &str {
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.')
    } else {
        s
    }
}

/// `s` with a leading ASCII `-` written as the minus sign `−` (U+2212).
fn typographic_minus(s: String) -> String {
    match s.strip_prefix('-') {
        Some(rest) => format!("\u{2212}{rest}"),
        None => s,
    }
}

/// A scale bar: the longest 1-2-5 length `≤ max_len_m`, with its label; `None` unless
/// `max_len_m` is finite and > 0.
pub fn scale_bar(max_len_m: Real) -> Option<Tick> {
    let (m, k) = nice_below(max_len_m)?;
    let value = decimal(m, k);
    Some(Tick {
        value,
        label: format_length_m(value, 3),
    })
}

#[cfg(test)]
mod tests;
