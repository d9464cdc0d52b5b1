//! `write_recording`: a [`Recording`] → the bytes of a `.npz` (stored members, as
//! `numpy.savez` writes them).

use std::io::{Cursor, Write};

use alloc::format;
use alloc::vec::Vec;

use super::npy;
use crate::channel::{Layout, Recording};
use crate::error::{Error, Result};
use crate::math::{Complex, Real};

fn f64_bytes(v: &[Real]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}

fn c128_bytes(v: &[Complex]) -> Vec<u8> {
    v.iter()
        .flat_map(|z| z.re.to_le_bytes().into_iter().chain(z.im.to_le_bytes()))
        .collect()
}

/// Writes `rec` (validated first) as a `.npz` that `numpy.load` reads: `t_s`, `freq_hz`,
/// `tap0_s`, `tap_spacing_s`, `pulse_spacing_s`, `noise_var` as float64, `links` as int64
/// `(P, 2)`, `cfr`/`cir`, `system_response` and `pulse` as complex128, little-endian, C order.
pub fn write_recording(rec: &Recording) -> Result<Vec<u8>> {
    rec.validate()?;
    let (s, p, l) = (
        rec.snapshot_count(),
        rec.link_count(),
        rec.samples_per_link(),
    );
    let mut members: Vec<(&str, Vec<u8>)> = Vec::new();
    members.push(("t_s", npy::write("<f8", &[s], &f64_bytes(&rec.t_s))));
    let links: Vec<u8> = rec
        .links
        .iter()
        .flat_map(|&[a, b]| {
            (a as i64)
                .to_le_bytes()
                .into_iter()
                .chain((b as i64).to_le_bytes())
        })
        .collect();
    members.push(("links", npy::write("<i8", &[p, 2], &links)));
    let samples = npy::write("<c16", &[s, p, l], &c128_bytes(&rec.samples));
    match &rec.layout {
        Layout::Cfr {
            freq_hz,
            system_response,
        } => {
            members.push(("cfr", samples));
            members.push(("freq_hz", npy::write("<f8", &[l], &f64_bytes(freq_hz))));
            if let Some(r) = system_response {
                members.push(("system_response", npy::write("<c16", &[l], &c128_bytes(r))));
            }
        }
        Layout::Cir {
            tap0_s,
            tap_spacing_s,
            pulse,
        } => {
            members.push(("cir", samples));
            members.push(("tap0_s", npy::write("<f8", &[], &tap0_s.to_le_bytes())));
            members.push((
                "tap_spacing_s",
                npy::write("<f8", &[], &tap_spacing_s.to_le_bytes()),
            ));
            if let Some(pl) = pulse {
                let k = pl.samples.len();
                members.push(("pulse", npy::write("<c16", &[k], &c128_bytes(&pl.samples))));
                members.push((
                    "pulse_spacing_s",
                    npy::write("<f8", &[], &pl.spacing_s.to_le_bytes()),
                ));
            }
        }
    }
    if let Some(sync) = rec.synchronized {
        members.push(("synchronized", npy::write("|b1", &[], &[u8::from(sync)])));
    }
    if let Some(nv) = &rec.noise_var {
        members.push(("noise_var", npy::write("<f8", &[p], &f64_bytes(nv))));
    }
    let fail = |e: &dyn core::fmt::Display| Error::InvalidFile {
        field: "npz".into(),
        reason: format!("cannot write the archive: {e}"),
    };
    let mut zip = zip::ZipWriter::new(Cursor::new(Vec::new()));
    let opts = zip::write::SimpleFileOptions::default()
        .compression_method(zip::CompressionMethod::Stored)
        .large_file(true);
    for (name, data) in members {
        zip.start_file(format!("{name}.npy"), opts)
            .map_err(|e| fail(&e))?;
        zip.write_all(&data).map_err(|e| fail(&e))?;
    }
    Ok(zip.finish().map_err(|e| fail(&e))?.into_inner())
}
