//! `read_recording`: a `.npz` in memory → a validated [`Recording`].

use std::collections::BTreeMap;
use std::io::{Cursor, Read};

use alloc::format;
use alloc::vec::Vec;

use super::npy::{self, invalid, Npy};
use super::ARRAYS;
use crate::channel::{Layout, Pulse, Recording};
use crate::error::limits::{MAX_RECORDING_BYTES, MAX_RECORDING_SAMPLES};
use crate::error::{Error, Result};
use crate::math::Complex;

fn too_big(field: &'static str, value: u64, cap: u64) -> Error {
    Error::SizeLimit {
        field,
        value: value.min(usize::MAX as u64) as usize,
        min: 0,
        max: cap.min(usize::MAX as u64) as usize,
    }
}

/// Reads the members of the archive: each `NAME.npy` must be one of [`ARRAYS`], declared and
/// inflated within `cap` bytes (each member and all together). A member is read
/// through `take(min(declared, remaining) + 1)`, so a member that inflates past its declared size
/// is refused after at most one byte more than it declared.
fn members(bytes: &[u8], cap: u64) -> Result<BTreeMap<&'static str, Npy>> {
    if bytes.len() as u64 > cap {
        return Err(too_big("npz", bytes.len() as u64, cap));
    }
    let mut zip = zip::ZipArchive::new(Cursor::new(bytes))
        .map_err(|e| invalid("npz", format!("not a zip archive (.npz): {e}")))?;
    refuse_duplicates(bytes, zip.offset() + zip.central_directory_start())?;
    let mut out = BTreeMap::new();
    let mut budget = cap;
    for k in 0..zip.len() {
        let mut f = zip
            .by_index(k)
            .map_err(|e| invalid("npz", format!("member {k}: {e}")))?;
        let file_name = f.name().to_owned();
        let stem = file_name.strip_suffix(".npy").unwrap_or(&file_name);
        let Some(&name) = ARRAYS.iter().find(|a| **a == stem) else {
            return Err(invalid(
                &crate::error::Clip(&file_name).to_string(),
                format!("unknown array (known: {})", ARRAYS.join(", ")),
            ));
        };
        if out.contains_key(name) {
            return Err(invalid(name, "the array appears twice".into()));
        }
        let declared = f.size();
        if declared > budget {
            return Err(too_big(name, declared, cap));
        }
        // Grown with what actually inflates (a 2 KB file may declare gigabytes: reserving
        // them up front aborts under an address-space limit).
        let mut data = Vec::with_capacity(declared.min(INITIAL_RESERVE) as usize);
        (&mut f)
            .take(declared + 1)
            .read_to_end(&mut data)
            .map_err(|e| invalid(name, format!("cannot inflate: {e}")))?;
        if data.len() as u64 > declared {
            return Err(invalid(
                name,
                format!(
                    "the member inflates to more than its declared {declared} bytes (a zip \
                     bomb?)"
                ),
            ));
        }
        if (data.len() as u64) < declared {
            return Err(invalid(
                name,
                format!(
                    "the member inflates to {} bytes, fewer than its declared {declared} (a \
                     truncated or corrupt archive)",
                    data.len()
                ),
            ));
        }
        budget -= data.len() as u64;
        out.insert(name, npy::parse(name, data)?);
    }
    Ok(out)
}

/// The most a member's buffer reserves before inflating (1 MiB); it grows from there.
const INITIAL_RESERVE: u64 = 1 << 20;

/// Refuses an archive whose central directory (from `start`) names a member twice: the zip
/// reader keys members by name and would keep one of them silently. The walk reads the
/// fixed 46-byte headers (`PK\x01\x02`, name, extra and comment lengths at 28, 30, 32) and
/// advances at least 46 bytes per record, so it ends within `bytes.len()/46` records.
fn refuse_duplicates(bytes: &[u8], start: u64) -> Result<()> {
    let u16_at = |p: usize| u16::from_le_bytes([bytes[p], bytes[p + 1]]) as usize;
    let mut names: Vec<&[u8]> = Vec::new();
    let mut p = usize::try_from(start).unwrap_or(usize::MAX);
    while p.checked_add(46).is_some_and(|e| e <= bytes.len())
        && bytes[p..p + 4] == [0x50, 0x4b, 0x01, 0x02]
    {
        let (n, m, k) = (u16_at(p + 28), u16_at(p + 30), u16_at(p + 32));
        let Some(name) = bytes.get(p + 46..p + 46 + n) else {
            break;
        };
        if names.contains(&name) {
            let text = alloc::string::String::from_utf8_lossy(name);
            return Err(invalid(
                &crate::error::Clip(&text).to_string(),
                "the member appears twice in the archive".into(),
            ));
        }
        names.push(name);
        p += 46 + n + m + k;
    }
    Ok(())
}

fn missing(name: &str, why: &str) -> Error {
    invalid(name, format!("missing array ({why})"))
}

fn scalar(m: &BTreeMap<&'static str, Npy>, name: &'static str) -> Result<f64> {
    let a = m
        .get(name)
        .ok_or_else(|| missing(name, "required with cir"))?;
    let v = a.f64s()?;
    a.expect_shape(&[], "a scalar")?;
    Ok(v[0])
}

fn samples_cap(name: &str, count: usize) -> Result<()> {
    if count > MAX_RECORDING_SAMPLES {
        return Err(invalid(
            name,
            format!("{count} complex samples, at most {MAX_RECORDING_SAMPLES} are allowed"),
        ));
    }
    Ok(())
}

/// Reads a recording from the bytes of a `.npz` file (docs/recording.md) and validates it
/// ([`Recording::validate`]); the pulse is normalised to `p(0) = 1`. Every malformed file is a
/// named [`Error`] naming the array (missing, unknown, wrong dtype or shape, non-finite,
/// non-increasing `t_s`, non-uniform `freq_hz`, over a cap, not a zip, not an npy, a zip bomb).
/// The file and its inflated members are capped at [`MAX_RECORDING_BYTES`].
pub fn read_recording(bytes: &[u8]) -> Result<Recording> {
    read_recording_within(bytes, MAX_RECORDING_BYTES)
}

/// [`read_recording`] with the file and the total of its inflated members capped at
/// `max_bytes` (at most [`MAX_RECORDING_BYTES`]; the page reads with
/// [`crate::error::limits::MAX_PAGE_RECORDING_BYTES`]): a larger file, or a member that declares
/// or inflates to more, is an [`Error::SizeLimit`] or [`Error::InvalidFile`] naming it.
pub fn read_recording_within(bytes: &[u8], max_bytes: u64) -> Result<Recording> {
    let m = members(bytes, max_bytes.min(MAX_RECORDING_BYTES))?;
    let t = m.get("t_s").ok_or_else(|| missing("t_s", "required"))?;
    let t_s = t.f64s()?;
    if t.shape.len() != 1 {
        return Err(invalid(
            "t_s",
            format!("wrong shape {}, expected (S,)", npy::shape_text(&t.shape)),
        ));
    }
    let s = t_s.len();
    let l = m.get("links").ok_or_else(|| missing("links", "required"))?;
    let raw = l.ints(&[4, 8], "int64 (or int32)")?;
    if l.shape.len() != 2 || l.shape[1] != 2 {
        return Err(invalid(
            "links",
            format!("wrong shape {}, expected (P, 2)", npy::shape_text(&l.shape)),
        ));
    }
    let p = l.shape[0];
    let mut links = Vec::with_capacity(p);
    for (k, pair) in raw.chunks_exact(2).enumerate() {
        if pair[0] < 0 || pair[1] < 0 {
            return Err(invalid(
                "links",
                format!(
                    "links[{k}] = ({}, {}): indices must be >= 0",
                    pair[0], pair[1]
                ),
            ));
        }
        links.push([pair[0] as usize, pair[1] as usize]);
    }
    let (layout, samples) = match (m.get("cfr"), m.get("cir")) {
        (Some(_), Some(_)) => {
            return Err(invalid(
                "cfr",
                "both cfr and cir are present: give exactly one".into(),
            ))
        }
        (None, None) => return Err(missing("cfr", "give exactly one of cfr and cir")),
        (Some(c), None) => {
            for extra in ["tap0_s", "tap_spacing_s", "pulse", "pulse_spacing_s"] {
                if m.contains_key(extra) {
                    return Err(invalid(extra, "only with cir, not with cfr".into()));
                }
            }
            let f = m
                .get("freq_hz")
                .ok_or_else(|| missing("freq_hz", "required with cfr"))?;
            let freq_hz = f.f64s()?;
            f.expect_shape(&[freq_hz.len()], "(N,)")?;
            let n = freq_hz.len();
            if !c.is_complex() {
                c.complexes()?;
            }
            samples_cap("cfr", s.saturating_mul(p).saturating_mul(n))?;
            c.expect_shape(&[s, p, n], "(S, P, N)")?;
            let system_response = match m.get("system_response") {
                Some(a) => {
                    let v = a.complexes()?;
                    a.expect_shape(&[n], "(N,)")?;
                    Some(v)
                }
                None => None,
            };
            (
                Layout::Cfr {
                    freq_hz,
                    system_response,
                },
                c.complexes()?,
            )
        }
        (None, Some(c)) => {
            for extra in ["freq_hz", "system_response"] {
                if m.contains_key(extra) {
                    return Err(invalid(extra, "only with cfr, not with cir".into()));
                }
            }
            let tap0_s = scalar(&m, "tap0_s")?;
            let tap_spacing_s = scalar(&m, "tap_spacing_s")?;
            let pulse = match (m.get("pulse"), m.contains_key("pulse_spacing_s")) {
                (Some(a), _) => {
                    let samples = a.complexes()?;
                    if a.shape.len() != 1 {
                        return Err(invalid(
                            "pulse",
                            format!("wrong shape {}, expected (K,)", npy::shape_text(&a.shape)),
                        ));
                    }
                    let mut pl = Pulse {
                        samples,
                        spacing_s: scalar(&m, "pulse_spacing_s")
                            .map_err(|_| missing("pulse_spacing_s", "required with pulse"))?,
                    };
                    pl.normalise()?;
                    Some(pl)
                }
                (None, true) => return Err(invalid("pulse_spacing_s", "only with pulse".into())),
                (None, false) => None,
            };
            let layout = Layout::Cir {
                tap0_s,
                tap_spacing_s,
                pulse,
            };
            let mm = c.shape.get(2).copied().unwrap_or(0);
            samples_cap("cir", s.saturating_mul(p).saturating_mul(mm))?;
            if c.is_complex() {
                c.expect_shape(&[s, p, mm], "(S, P, M)")?;
                (layout, c.complexes()?)
            } else if c.dtype.kind == b'i' && (c.dtype.size == 2 || c.dtype.size == 4) {
                c.expect_shape(&[s, p, mm, 2], "(S, P, M, 2) (I, Q)")?;
                let iq = c.ints(&[2, 4], "int16 or int32")?;
                let v = iq
                    .chunks_exact(2)
                    .map(|q| Complex::new(q[0] as f64, q[1] as f64))
                    .collect();
                (layout, v)
            } else {
                return Err(invalid(
                    "cir",
                    format!(
                        "wrong dtype {}, expected complex64, complex128, or int16/int32 (I, Q)",
                        c.dtype.name()
                    ),
                ));
            }
        }
    };
    let noise_var = match m.get("noise_var") {
        Some(a) => {
            let v = a.f64s()?;
            a.expect_shape(&[p], "(P,)")?;
            Some(v)
        }
        None => None,
    };
    let synchronized = match m.get("synchronized") {
        Some(a) => {
            a.expect_shape(&[], "a scalar")?;
            Some(a.flag()?)
        }
        None => None,
    };
    if let Some(a) = m.get("cpi_snapshots") {
        a.expect_shape(&[], "a scalar")?;
        let n = a.ints(&[1, 2, 4, 8], "an integer")?[0];
        if n < 1 || t_s.len() % n as usize != 0 {
            return Err(invalid(
                "cpi_snapshots",
                format!("{n} does not divide the {} snapshots", t_s.len()),
            ));
        }
    }
    if let Some(a) = m.get("cpi_spacing_s") {
        a.expect_shape(&[], "a scalar")?;
        let v = a.f64s()?[0];
        if !(v.is_finite() && v > 0.0) {
            return Err(invalid(
                "cpi_spacing_s",
                format!("{v} is not a positive time"),
            ));
        }
    }
    let rec = Recording {
        t_s,
        links,
        layout,
        samples,
        noise_var,
        synchronized,
    };
    rec.validate()?;
    Ok(rec)
}
