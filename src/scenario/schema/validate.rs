//! Validation of a parsed [`Scenario`]: every field checked, the first problem returned as a
//! named [`Error`] with the path of its field.

use alloc::collections::BTreeSet;
use alloc::format;

use super::{Area, LinkSpec, Pattern, Scenario};
use crate::error::{check_finite, limits, Error, Result};

impl Scenario {
    /// Checks every field against its documented range ([`crate::error::limits`]) and the size
    /// caps ([`limits::MAX_NODES`], [`limits::MAX_LINKS`]); the first problem found is returned
    /// as a named error.
    pub fn validate(&self) -> Result<()> {
        let r = &self.radio;
        limits::CARRIER_HZ.check("radio.carrier_hz", r.carrier_hz)?;
        limits::BANDWIDTH_HZ.check("radio.bandwidth_hz", r.bandwidth_hz)?;
        if r.noise_figure_db.is_some() && r.noise_power_dbm.is_some() {
            return Err(Error::AmbiguousNoise);
        }
        if let Some(nf) = r.noise_figure_db {
            limits::NOISE_FIGURE_DB.check("radio.noise_figure_db", nf)?;
        }
        if let Some(p) = r.noise_power_dbm {
            limits::NOISE_POWER_DBM.check("radio.noise_power_dbm", p)?;
        }
        if let Some(g) = r.processing_gain_db {
            limits::PROCESSING_GAIN_DB.check("radio.processing_gain_db", g)?;
        }
        limits::check_name("name", &self.name)?;
        node_count("transmitters", self.transmitters.len())?;
        node_count("receivers", self.receivers.len())?;
        let mut names: BTreeSet<&str> = BTreeSet::new();
        for (i, t) in self.transmitters.iter().enumerate() {
            limits::check_name(&format!("transmitters[{i}].name"), &t.name)?;
            unique_name(&mut names, &t.name)?;
            position(&format!("transmitters[{i}].position_m"), t.position_m)?;
            height(&format!("transmitters[{i}].height_m"), t.height_m)?;
            limits::POWER_DBM.check(&format!("transmitters[{i}].power_dbm"), t.power_dbm)?;
            limits::GAIN_DBI.check(&format!("transmitters[{i}].gain_dbi"), t.gain_dbi)?;
            if let Pattern::Parabolic {
                boresight_deg,
                beamwidth_deg,
                floor_db,
            } = t.pattern
            {
                limits::BORESIGHT_DEG.check(
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
                limits::PATTERN_FLOOR_DB
                    .check(&format!("transmitters[{i}].pattern.floor_db"), floor_db)?;
            }
        }
        for (i, rx) in self.receivers.iter().enumerate() {
            limits::check_name(&format!("receivers[{i}].name"), &rx.name)?;
            unique_name(&mut names, &rx.name)?;
            position(&format!("receivers[{i}].position_m"), rx.position_m)?;
            height(&format!("receivers[{i}].height_m"), rx.height_m)?;
            limits::GAIN_DBI.check(&format!("receivers[{i}].gain_dbi"), rx.gain_dbi)?;
        }
        limits::RCS_M2.check("target.rcs_m2", self.target.rcs_m2)?;
        height("target.height_m", self.target.height_m)?;
        self.area_m.validate()?;
        if let LinkSpec::List(pairs) = &self.links {
            for (i, [t, r]) in pairs.iter().enumerate() {
                limits::check_name(&format!("links[{i}][0]"), t)?;
                limits::check_name(&format!("links[{i}][1]"), r)?;
            }
        }
        let links = self.link_indices()?.len();
        if links > limits::MAX_LINKS {
            return Err(Error::SizeLimit {
                field: "links",
                value: links,
                min: 1,
                max: limits::MAX_LINKS,
            });
        }
        Ok(())
    }
}

impl Area {
    /// Validates the rectangle: finite, within [`limits::COORDINATE_M`], min < max and a span of at
    /// least [`limits::MIN_AREA_SPAN_M`] on both axes.
    pub fn validate(&self) -> Result<()> {
        self.validate_as(["area_m.x", "area_m.y"])
    }

    /// [`Area::validate`] for a rectangle of another name: errors name `fields` (x, y), e.g.
    /// `["roi.x", "roi.y"]`.
    pub fn validate_as(&self, fields: [&'static str; 2]) -> Result<()> {
        area(self, fields)
    }
}

/// A position: both coordinates finite and within [`limits::COORDINATE_M`].
fn position(field: &str, p: [f64; 2]) -> Result<()> {
    for v in p {
        check_finite(field, v)?;
    }
    for v in p {
        limits::COORDINATE_M.check(field, v)?;
    }
    Ok(())
}

/// A height: finite and within [`limits::COORDINATE_M`] (the limits of a coordinate).
fn height(field: &str, h: f64) -> Result<()> {
    check_finite(field, h)?;
    limits::COORDINATE_M.check(field, h)
}

fn node_count(field: &'static str, n: usize) -> Result<()> {
    if n == 0 {
        return Err(Error::EmptyNodeList { field });
    }
    if n > limits::MAX_NODES {
        return Err(Error::SizeLimit {
            field,
            value: n,
            min: 1,
            max: limits::MAX_NODES,
        });
    }
    Ok(())
}

fn unique_name<'a>(names: &mut BTreeSet<&'a str>, name: &'a str) -> Result<()> {
    if !names.insert(name) {
        return Err(Error::DuplicateName { name: name.into() });
    }
    Ok(())
}

fn area(a: &Area, [fx, fy]: [&'static str; 2]) -> Result<()> {
    position(fx, a.x)?;
    position(fy, a.y)?;
    if a.x[0] >= a.x[1] {
        return Err(Error::InvertedArea {
            field: fx,
            min: a.x[0],
            max: a.x[1],
        });
    }
    if a.y[0] >= a.y[1] {
        return Err(Error::InvertedArea {
            field: fy,
            min: a.y[0],
            max: a.y[1],
        });
    }
    for (field, [lo, hi]) in [(fx, a.x), (fy, a.y)] {
        if hi - lo < limits::MIN_AREA_SPAN_M {
            return Err(Error::OutOfRange {
                field: field.into(),
                value: hi - lo,
                allowed: "a span of at least 1e-3 m",
            });
        }
    }
    Ok(())
}
