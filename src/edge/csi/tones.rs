//! The subcarrier maps of the 802.11 OFDM formats and widths as the Intel AX200/AX210 firmware
//! ("IWLMVM") reports them, shared by the FeitCSI reader and the PicoScenes reader's MVM layout
//! (one home; the same tables as PicoScenes' `rxs_parsing_core` `CSI::fromIWLMVM`: NonHT20 52,
//! HT/VHT20 56, HT/VHT40 114, VHT80 242, VHT160 484, HE20 242, HE40 484, HE80 996, HE160 1992).
//! Every table holds its pilot tones (listed apart, mirrored); the missing indices are DC, the
//! guards and the 160 MHz middle gaps.

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
    /// The format's name (FeitCSI's injector and capture modes are NOHT, HT, VHT and HESU).
    pub(super) fn name(self) -> &'static str {
        match self {
            Phy::Legacy => "legacy",
            Phy::Ht => "HT",
            Phy::Vht => "VHT",
            Phy::He => "HE-SU",
        }
    }
}

/// A subcarrier map: the occupied tones as inclusive ranges, the pilots' positive indices
/// (mirrored), and the padding entries of the firmware's raw 160 MHz report `(raw K, first,
/// end)` (FeitCSI passes them on; PicoScenes records the table's count).
#[derive(Debug, Clone, Copy)]
pub(super) struct Map {
    pub(super) ranges: &'static [(i32, i32)],
    pub(super) pilots: &'static [i32],
    pub(super) bug: Option<(usize, usize, usize)>,
}

/// The map of a format and width (IEEE 802.11-2016 §19.3.7, §21.3.7; 802.11ax §27.3.11), `None`
/// where the firmware has none.
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

    /// The pilots, both signs, in index order.
    pub(super) fn all_pilots(&self) -> Vec<i32> {
        let neg = self.pilots.iter().rev().map(|k| -k);
        neg.chain(self.pilots.iter().copied()).collect()
    }
}
