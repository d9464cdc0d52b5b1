//! How errors show what the user gave: numbers in a readable form (`1e300`, not 301 digits) and
//! long strings clipped, so a message stays one short line whatever the input.

use core::fmt;

/// Shows an `f64` as Rust's `Display` does for ordinary magnitudes and in scientific form for
/// `|v| ≥ 10¹⁶` or `0 < |v| < 10⁻⁵` (where `Display` would print hundreds of digits).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Num(pub f64);

impl fmt::Display for Num {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let a = self.0.abs();
        if a.is_finite() && (a >= 1e16 || (a > 0.0 && a < 1e-5)) {
            write!(f, "{:e}", self.0)
        } else {
            write!(f, "{}", self.0)
        }
    }
}

/// Shows a string on one line: control characters escaped, and clipped to its first
/// [`Clip::HEAD`] and last [`Clip::TAIL`] characters with the number left out in between when it
/// is longer than [`Clip::MAX`] characters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Clip<'a>(pub &'a str);

impl Clip<'_> {
    /// Longest string shown whole, characters.
    pub const MAX: usize = 200;
    /// Characters kept from the start of a longer string.
    pub const HEAD: usize = 120;
    /// Characters kept from its end (where serde puts "at line L column C").
    pub const TAIL: usize = 60;
}

impl fmt::Display for Clip<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let s = self.0;
        let n = s.chars().count();
        if n <= Self::MAX {
            return write_escaped(f, s);
        }
        let head_end = s.char_indices().nth(Self::HEAD).map_or(s.len(), |(i, _)| i);
        let tail_start = s
            .char_indices()
            .nth(n - Self::TAIL)
            .map_or(s.len(), |(i, _)| i);
        let left_out = n - Self::HEAD - Self::TAIL;
        write_escaped(f, &s[..head_end])?;
        write!(f, "…[{left_out} characters left out]…")?;
        write_escaped(f, &s[tail_start..])
    }
}

/// `s` with control characters escaped (`\n`, `\u{7}`), so a message stays one line.
fn write_escaped(f: &mut fmt::Formatter<'_>, s: &str) -> fmt::Result {
    for c in s.chars() {
        if c.is_control() {
            write!(f, "{}", c.escape_default())?;
        } else {
            fmt::Write::write_char(f, c)?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use alloc::string::{String, ToString};

    #[test]
    fn huge_and_tiny_numbers_are_shown_in_scientific_form() {
        assert_eq!(Num(1e300).to_string(), "1e300");
        assert_eq!(Num(-1e308).to_string(), "-1e308");
        assert_eq!(Num(5e-324).to_string(), "5e-324");
        assert_eq!(Num(1e-200).to_string(), "1e-200");
        assert_eq!(Num(0.5).to_string(), "0.5");
        assert_eq!(Num(-3.25).to_string(), "-3.25");
        assert_eq!(Num(1e15).to_string(), "1000000000000000");
        assert_eq!(Num(0.0).to_string(), "0");
        assert_eq!(Num(f64::INFINITY).to_string(), "inf");
    }

    #[test]
    fn long_strings_are_clipped_and_keep_both_ends() {
        let short = "a".repeat(Clip::MAX);
        assert_eq!(Clip(&short).to_string(), short);
        let long: String = "é".repeat(1_000_000) + " at line 1 column 9";
        let shown = Clip(&long).to_string();
        assert!(shown.chars().count() < 260, "{}", shown.len());
        assert!(shown.starts_with(&"é".repeat(Clip::HEAD)));
        assert!(shown.ends_with(" at line 1 column 9"));
        let left_out = 1_000_019 - Clip::HEAD - Clip::TAIL;
        assert!(shown.contains(&alloc::format!("[{left_out} characters left out]")));
    }

    /// Fuzz (issue 12): a model kind of "\n" made a two-line error message.
    #[test]
    fn control_characters_are_escaped() {
        assert_eq!(Clip("a\nb\r\u{7}").to_string(), "a\\nb\\r\\u{7}");
        let long = "\n".repeat(1000);
        assert!(!Clip(&long).to_string().contains('\n'));
    }
}
