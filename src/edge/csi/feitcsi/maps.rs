//! The subcarrier maps of the PHY formats and widths (module doc of `feitcsi`) and the rate
//! flags' format and width.

use alloc::format;
use alloc::string::String;
use alloc::vec::Vec;

/// The PHY formats with a subcarrier map.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Phy {
    Legacy,
    Ht,
    Vht,
    He,
}

impl Phy {
    pub(super) fn name(self) -> &'static str {
        match self {
            Phy::Legacy => "legacy",
            Phy::Ht => "HT",
            Phy::Vht => "VHT",
            // FeitCSI's injector and capture modes are NOHT, HT, VHT and HESU.
            Phy::He => "HE-SU",
        }
    }
}

/// A subcarrier map: the occupied tones as inclusive ranges, the pilots' positive indices
/// (mirrored), and the padding entries of the 160 MHz firmware bug `(raw K, first, end)`.
#[derive(Debug, Clone, Copy)]
pub(super) struct Map {
    pub(super) ranges: &'static [(i32, i32)],
    pub(super) pilots: &'static [i32],
    pub(super) bug: Option<(usize, usize, usize)>,
}

pub(super) fn map(phy: Phy, width_mhz: u32) -> Option<Map> {
    let m = |ranges, pilots| {
        Some(Map {
            ranges,
            pilots,
            bug: None,
        })
    };
    const P20: &[i32] = &[7, 21];
    const P40: &[i32] = &[11, 25, 53];
    match (phy, width_mhz) {
        (Phy::Legacy, 20) => m(&[(-26, -1), (1, 26)], P20),
        (Phy::Ht | Phy::Vht, 20) => m(&[(-28, -1), (1, 28)], P20),
        (Phy::Ht | Phy::Vht, 40) => m(&[(-58, -2), (2, 58)], P40),
        (Phy::Vht, 80) => m(&[(-122, -2), (2, 122)], &[11, 39, 75, 103]),
        (Phy::Vht, 160) => Some(Map {
            ranges: &[(-250, -130), (-126, -6), (6, 126), (130, 250)],
            pilots: &[25, 53, 89, 117, 139, 167, 203, 231],
            bug: Some((498, 242, 256)),
        }),
        (Phy::He, 20) => m(&[(-122, -2), (2, 122)], &[22, 48, 90, 116]),
        (Phy::He, 40) => m(
            &[(-244, -3), (3, 244)],
            &[10, 36, 78, 104, 144, 170, 212, 238],
        ),
        (Phy::He, 80) => m(
            &[(-500, -3), (3, 500)],
            &[24, 92, 158, 226, 266, 334, 400, 468],
        ),
        (Phy::He, 160) => Some(Map {
            ranges: &[(-1012, -515), (-509, -12), (12, 509), (515, 1012)],
            // The HE 80 pilots around ±512.
            pilots: &[
                44, 112, 178, 246, 286, 354, 420, 488, 536, 604, 670, 738, 778, 846, 912, 980,
            ],
            bug: Some((2020, 996, 1024)),
        }),
        _ => None,
    }
}

impl Map {
    /// Every occupied tone, in index order.
    pub(super) fn tones(&self) -> Vec<i32> {
        self.ranges.iter().flat_map(|&(a, b)| a..=b).collect()
    }

    pub(super) fn is_pilot(&self, k: i32) -> bool {
        self.pilots.contains(&k.abs())
    }
}

/// The PHY format and width of `rate_flags` (`Err`: the reason no map applies).
pub(super) fn rate(flags: u32) -> core::result::Result<(Phy, u32), String> {
    let phy = match (flags >> 8) & 7 {
        1 => Phy::Legacy,
        2 => Phy::Ht,
        3 => Phy::Vht,
        4 => Phy::He,
        0 => return Err("a CCK frame (no OFDM subcarrier map)".into()),
        5 => return Err("an EHT frame (no subcarrier map here)".into()),
        f => return Err(format!("rate format {f} is not one FeitCSI defines")),
    };
    let width = match (flags >> 11) & 7 {
        0 => 20,
        1 => 40,
        2 => 80,
        3 => 160,
        w => {
            return Err(format!(
                "channel width code {w} (320 MHz or unknown) has no map here"
            ))
        }
    };
    Ok((phy, width))
}
