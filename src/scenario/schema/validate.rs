//! Validation of a parsed [`Scenario`]: every field checked, the first problem returned as a
//! named [`Error`] with the path of its field.

use alloc::format;
use alloc::vec::Vec;

use super::{Area, Pattern, Scenario};
use crate::error::{check_finite, check_positive, Error, Result};

impl Scenario {
    /// Checks every field; the first problem found is returned as a named error.
    pub fn validate(&self) -> Result<()> {
        let r = &self.radio;
        check_positive("radio.carrier_hz", r.carrier_hz)?;
        check_positive("radio.bandwidth_hz", r.bandwidth_hz)?;
        if r.noise_figure_db.is_some() && r.noise_power_dbm.is_some() {
            return Err(Error::AmbiguousNoise);
        }
        if let Some(nf) = r.noise_figure_db {
            check_finite("radio.noise_figure_db", nf)?;
            if !(0.0..=100.0).contains(&nf) {
                return Err(Error::OutOfRange {
                    field: "radio.noise_figure_db".into(),
                    value: nf,
                    allowed: "0 to 100 dB",
                });
            }
        }
        if let Some(p) = r.noise_power_dbm {
            check_finite("radio.noise_power_dbm", p)?;
        }
        if let Some(g) = r.processing_gain_db {
            check_finite("radio.processing_gain_db", g)?;
            if g < 0.0 {
                return Err(Error::OutOfRange {
                    field: "radio.processing_gain_db".into(),
                    value: g,
                    allowed: ">= 0 dB",
                });
            }
        }
        if self.transmitters.is_empty() {
            return Err(Error::EmptyNodeList {
                field: "transmitters",
            });
        }
        if self.receivers.is_empty() {
            return Err(Error::EmptyNodeList { field: "receivers" });
        }
        let mut names: Vec<&str> = Vec::new();
        for (i, t) in self.transmitters.iter().enumerate() {
            unique_name(&mut names, &t.name)?;
            position(&format!("transmitters[{i}].position_m"), t.position_m)?;
            check_finite(&format!("transmitters[{i}].power_dbm"), t.power_dbm)?;
            check_finite(&format!("transmitters[{i}].gain_dbi"), t.gain_dbi)?;
            if let Pattern::Parabolic {
                boresight_deg,
                beamwidth_deg,
                floor_db,
            } = t.pattern
            {
                check_finite(
                    &format!("transmitters[{i}].pattern.boresight_deg"),
                    boresight_deg,
                )?;
                let bw = format!("transmitters[{i}].pattern.beamwidth_deg");
                check_finite(&bw, beamwidth_deg)?;
                if !(beamwidth_deg > 0.0 && beamwidth_deg <= 360.0) {
                    return Err(Error::OutOfRange {
                        field: bw,
                        value: beamwidth_deg,
                        allowed: "0 < beamwidth <= 360 degrees",
                    });
                }
                let fl = format!("transmitters[{i}].pattern.floor_db");
                check_finite(&fl, floor_db)?;
                if floor_db < 0.0 {
                    return Err(Error::OutOfRange {
                        field: fl,
                        value: floor_db,
                        allowed: ">= 0 dB",
                    });
                }
            }
        }
        for (i, rx) in self.receivers.iter().enumerate() {
            unique_name(&mut names, &rx.name)?;
            position(&format!("receivers[{i}].position_m"), rx.position_m)?;
            check_finite(&format!("receivers[{i}].gain_dbi"), rx.gain_dbi)?;
        }
        check_positive("target.rcs_m2", self.target.rcs_m2)?;
        area(&self.area_m)?;
        self.link_indices().map(|_| ())
    }
}

impl Area {
    /// Validates the rectangle (finite, min < max on both axes).
    pub fn validate(&self) -> Result<()> {
        area(self)
    }
}

fn position(field: &str, p: [f64; 2]) -> Result<()> {
    if p.iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(Error::NonFinite {
            field: field.into(),
        })
    }
}

fn unique_name<'a>(names: &mut Vec<&'a str>, name: &'a str) -> Result<()> {
    if names.contains(&name) {
        return Err(Error::DuplicateName { name: name.into() });
    }
    names.push(name);
    Ok(())
}

fn area(a: &Area) -> Result<()> {
    position("area_m.x", a.x)?;
    position("area_m.y", a.y)?;
    if a.x[0] >= a.x[1] {
        return Err(Error::InvertedArea {
            field: "area_m.x",
            min: a.x[0],
            max: a.x[1],
        });
    }
    if a.y[0] >= a.y[1] {
        return Err(Error::InvertedArea {
            field: "area_m.y",
            min: a.y[0],
            max: a.y[1],
        });
    }
    Ok(())
}
