//! [`ExactSum`]: an exact, order-independent sum of `f64` values (Shewchuk's non-overlapping
//! partials, the algorithm of Python's `math.fsum`), correctly rounded once at the end.

use alloc::vec::Vec;
use core::fmt;

/// The exact sum of the `f64` values added to it, kept as non-overlapping partials (Shewchuk,
/// "Adaptive precision floating-point arithmetic", 1997; Python's `math.fsum`), and
/// [`value`](ExactSum::value), the exact sum correctly rounded to the nearest `f64` (ties to
/// even).
///
/// Because nothing is rounded until [`value`](ExactSum::value), the value depends only on the
/// multiset of finite addends: not on the order of [`add`](ExactSum::add)s, nor on how they were
/// split between accumulators later combined with [`merge`](ExactSum::merge). This is what
/// makes a study's result independent of its thread count and of how it is split into shards.
///
/// Non-finite addends (`±∞`, NaN) are summed apart in plain floating point; if there was any,
/// the value is that sum (`∞`, `−∞` or NaN, `∞ + (−∞)` = NaN, whatever the order), as for a
/// plain sum.
///
/// Overflow: the partials are exact as long as every running sum stays below `f64::MAX` in
/// magnitude, which holds whenever the sum of the magnitudes of the finite addends does
/// (`≈ 1.8·10³⁰⁸`; our sums of squared errors, NEES and Fisher information stay many orders
/// below). Past that an intermediate overflow makes the value `±∞` (Python raises
/// `OverflowError` instead), and order independence is no longer guaranteed. A correctly
/// rounded value beyond `f64::MAX` is `±∞`.
///
/// Cost: an add touches every partial; there are rarely more than two or three (at most about
/// 40, one per 53 bits of the exponent range).
///
/// Serde: the partials as a JSON array of numbers (they round-trip exactly), or the string
/// `"inf"`, `"-inf"` or `"nan"` once a non-finite value was added. Deserialising adds the
/// numbers one by one, so any array of finite numbers is a valid accumulator of their sum.
#[derive(Clone, Default)]
pub struct ExactSum {
    /// Non-overlapping, non-zero, finite partials in increasing magnitude; their exact sum is
    /// the exact sum of the finite addends.
    partials: Vec<f64>,
    /// Plain sum of the non-finite addends (and of an overflowed running sum); `0.0` while
    /// there was none, else non-finite.
    special: f64,
}

impl ExactSum {
    /// An empty sum (value `0.0`).
    pub const fn new() -> ExactSum {
        ExactSum {
            partials: Vec::new(),
            special: 0.0,
        }
    }

    /// Adds `x` exactly.
    pub fn add(&mut self, x: f64) {
        if !x.is_finite() {
            self.special += x;
            return;
        }
        let mut x = x;
        let mut kept = 0;
        for j in 0..self.partials.len() {
            let mut y = self.partials[j];
            if x.abs() < y.abs() {
                core::mem::swap(&mut x, &mut y);
            }
            // Two-sum with |x| ≥ |y|: hi + lo == x + y exactly.
            let hi = x + y;
            let lo = y - (hi - x);
            if lo != 0.0 {
                self.partials[kept] = lo;
                kept += 1;
            }
            x = hi;
        }
        self.partials.truncate(kept);
        if x != 0.0 {
            if x.is_finite() {
                self.partials.push(x);
            } else {
                // Intermediate overflow (finite addends): the value becomes ±∞.
                self.special += x;
                self.partials.clear();
            }
        }
    }

    /// Adds every value of `other` exactly: afterwards `self` holds the exact sum of both sets
    /// of addends (the same value as adding them one by one, in any order).
    pub fn merge(&mut self, other: &ExactSum) {
        self.special += other.special;
        for &p in &other.partials {
            self.add(p);
        }
    }

    /// The exact sum correctly rounded to `f64` (nearest, ties to even), or the non-finite sum
    /// if any non-finite value was added. A function of the exact sum only.
    pub fn value(&self) -> f64 {
        if self.special != 0.0 {
            return self.special;
        }
        let p = &self.partials;
        let Some((&top, _)) = p.split_last() else {
            return 0.0;
        };
        // Sum from the top down while the additions are exact (Python's fsum).
        let mut n = p.len() - 1;
        let mut hi = top;
        let mut lo = 0.0;
        while n > 0 {
            let x = hi;
            n -= 1;
            let y = p[n];
            hi = x + y;
            lo = y - (hi - x);
            if lo != 0.0 {
                break;
            }
        }
        // Round half to even across partials: when `lo` is exactly half an ulp of `hi` and the
        // partials below push the true sum past it, round away (fsum's correction).
        if n > 0 && ((lo < 0.0 && p[n - 1] < 0.0) || (lo > 0.0 && p[n - 1] > 0.0)) {
            let y = lo * 2.0;
            let x = hi + y;
            if y == x - hi {
                hi = x;
            }
        }
        hi
    }

    /// Whether nothing but zeros was added.
    pub fn is_zero(&self) -> bool {
        self.special == 0.0 && self.partials.is_empty()
    }

    /// The partials (non-overlapping, in increasing magnitude; empty for a zero or non-finite
    /// sum).
    pub fn partials(&self) -> &[f64] {
        &self.partials
    }
}

impl From<f64> for ExactSum {
    fn from(x: f64) -> ExactSum {
        let mut s = ExactSum::new();
        s.add(x);
        s
    }
}

impl FromIterator<f64> for ExactSum {
    fn from_iter<I: IntoIterator<Item = f64>>(iter: I) -> ExactSum {
        let mut s = ExactSum::new();
        iter.into_iter().for_each(|x| s.add(x));
        s
    }
}

impl PartialEq for ExactSum {
    /// Equal exact sums (whatever the partials), or both non-finite with the same value (NaN
    /// equals NaN here).
    fn eq(&self, other: &ExactSum) -> bool {
        match (self.special != 0.0, other.special != 0.0) {
            (false, false) => {
                let mut d = self.clone();
                other.partials.iter().for_each(|&p| d.add(-p));
                d.is_zero()
            }
            (true, true) => {
                self.special == other.special || (self.special.is_nan() && other.special.is_nan())
            }
            _ => false,
        }
    }
}

impl fmt::Debug for ExactSum {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.special != 0.0 {
            write!(f, "ExactSum({})", self.special)
        } else {
            write!(f, "ExactSum({:?} = {})", self.partials, self.value())
        }
    }
}

impl serde::Serialize for ExactSum {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeSeq;
        if self.special != 0.0 {
            let name = if self.special.is_nan() {
                "nan"
            } else if self.special > 0.0 {
                "inf"
            } else {
                "-inf"
            };
            return s.serialize_str(name);
        }
        let mut seq = s.serialize_seq(Some(self.partials.len()))?;
        for p in &self.partials {
            seq.serialize_element(p)?;
        }
        seq.end()
    }
}

impl<'de> serde::Deserialize<'de> for ExactSum {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<ExactSum, D::Error> {
        struct Visitor;
        impl<'de> serde::de::Visitor<'de> for Visitor {
            type Value = ExactSum;

            fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str(
                    "an array of finite numbers (partial sums), or \"inf\", \"-inf\", \"nan\"",
                )
            }

            fn visit_seq<A: serde::de::SeqAccess<'de>>(
                self,
                mut seq: A,
            ) -> Result<ExactSum, A::Error> {
                let mut s = ExactSum::new();
                while let Some(x) = seq.next_element::<f64>()? {
                    if !x.is_finite() {
                        return Err(serde::de::Error::custom("a partial sum is not finite"));
                    }
                    s.add(x);
                }
                Ok(s)
            }

            fn visit_str<E: serde::de::Error>(self, v: &str) -> Result<ExactSum, E> {
                let special = match v {
                    "inf" => f64::INFINITY,
                    "-inf" => f64::NEG_INFINITY,
                    "nan" => f64::NAN,
                    _ => return Err(E::invalid_value(serde::de::Unexpected::Str(v), &self)),
                };
                Ok(ExactSum {
                    partials: Vec::new(),
                    special,
                })
            }
        }
        d.deserialize_any(Visitor)
    }
}

#[cfg(test)]
mod tests;
