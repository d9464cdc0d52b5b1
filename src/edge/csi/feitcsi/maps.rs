//! The rate flags' format and width; the subcarrier maps of the formats and widths are the
//! firmware's, shared with PicoScenes' AX200/AX210 layout (`csi::tones`, module doc of `feitcsi`).

use alloc::format;
use alloc::string::String;

pub(super) use super::super::tones::{map, Map, Phy};

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
