//! The two case studies of spec §9 as ready scenarios.

use alloc::string::{String, ToString};
use alloc::vec;
use alloc::vec::Vec;

use crate::error::{Error, Result};
use crate::scenario::{Area, LinkSpec, Pattern, Radio, Receiver, Scenario, Target, Transmitter};

/// Names accepted by [`preset`].
pub const PRESET_NAMES: [&str; 2] = ["sensors2019", "iclgnss2019"];

/// A preset by name.
pub fn preset(name: &str) -> Result<Scenario> {
    match name {
        "sensors2019" => Ok(sensors2019()),
        "iclgnss2019" => Ok(iclgnss2019()),
        _ => Err(Error::UnknownPreset {
            name: name.to_string(),
            known: &PRESET_NAMES,
        }),
    }
}

fn receivers(positions: &[[f64; 2]], gain_dbi: f64) -> Vec<Receiver> {
    positions
        .iter()
        .enumerate()
        .map(|(i, p)| Receiver {
            name: alloc::format!("Rx{}", i + 1),
            height_m: 0.0,
            position_m: *p,
            gain_dbi,
        })
        .collect()
}

fn radio() -> Radio {
    Radio {
        carrier_hz: 5.2e9,
        bandwidth_hz: 1.2e8,
        noise_figure_db: Some(10.0),
        noise_power_dbm: None,
        processing_gain_db: None,
    }
}

/// \[S\] pedestrian tracking: layout L4 (§9.2), \[S\] Table 1, parabolic Tx pattern (§9.3),
/// RCS 1 m², area x ∈ [−7.5, 30], y ∈ [−10, 26] m (§9.1).
pub fn sensors2019() -> Scenario {
    Scenario {
        name: String::from("sensors2019"),
        radio: radio(),
        transmitters: vec![Transmitter {
            name: "Tx".into(),
            height_m: 0.0,
            position_m: [0.0, 0.0],
            power_dbm: 37.0,
            gain_dbi: 9.0,
            pattern: Pattern::Parabolic {
                boresight_deg: 10.0,
                beamwidth_deg: 70.0,
                floor_db: 20.0,
            },
        }],
        receivers: receivers(
            &[[-5.0, 12.0], [10.0, 10.0], [-6.0, -8.0], [12.0, -6.0]],
            8.0,
        ),
        links: LinkSpec::All,
        target: Target {
            rcs_m2: 1.0,
            height_m: 0.0,
        },
        area_m: Area {
            x: [-7.5, 30.0],
            y: [-10.0, 26.0],
        },
    }
}

/// \[I\] car localization: layout L3 (§9.2), \[I\] Table I, omni Tx 8 dBi, RCS 100 m²,
/// area x ∈ [−45, 30], y ∈ [−5, 15] m (§9.1).
pub fn iclgnss2019() -> Scenario {
    Scenario {
        name: String::from("iclgnss2019"),
        radio: radio(),
        transmitters: vec![Transmitter {
            name: "Tx".into(),
            height_m: 0.0,
            position_m: [0.0, 0.0],
            power_dbm: 36.0,
            gain_dbi: 8.0,
            pattern: Pattern::Omni,
        }],
        receivers: receivers(&[[-10.0, 0.0], [-10.0, 10.0], [0.0, 10.0]], 8.0),
        links: LinkSpec::All,
        target: Target {
            rcs_m2: 100.0,
            height_m: 0.0,
        },
        area_m: Area {
            x: [-45.0, 30.0],
            y: [-5.0, 15.0],
        },
    }
}
