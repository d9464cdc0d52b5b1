//! The `CSI` segment of a PicoScenes RXS frame: its header (versions 1–4) and the CSI values in
//! the layout of the device type (module doc of `picoscenes`).

use alloc::format;
use alloc::string::String;
use alloc::vec;
use alloc::vec::Vec;

use super::super::bfee;
use super::frame::Cursor;
use crate::error::limits::{MAX_BINS_PER_LINK, MAX_LINKS};
use crate::error::{Error, Result};
use crate::math::Complex;

/// `PicoScenesDeviceType` values.
const IWL5300: u16 = 0x5300;
const QCA9300: u16 = 0x9300;
const AX200: u16 = 0x2000;
const AX210: u16 = 0x2100;
const USRP: u16 = 0x1234;
const VIRTUAL_SDR: u16 = 0x1000;

/// What one frame's CSI segment holds.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Csi {
    /// `DeviceType`.
    pub device: u16,
    /// `PacketFormat` (0 non-HT, 1 HT, 2 VHT, 3 HE-SU, 4 HE-MU).
    pub format: i8,
    /// `CBW`, MHz.
    pub cbw: u16,
    /// `CarrierFreq`, Hz.
    pub carrier_hz: u64,
    /// `SubcarrierBandwidth`, Hz.
    pub spacing_hz: u32,
    /// Receive chains.
    pub n_rx: usize,
    /// Streams measured (`NumTx + NumESS`, as the buffer holds them).
    pub n_tx: usize,
    /// Subcarrier indices (strictly increasing).
    pub subcarriers: Vec<i32>,
    /// The values, `[(r·n_tx + t)·K + k]`.
    pub values: Vec<Complex>,
}

/// The device's name for [`super::super::CsiCapture::device`].
pub(super) fn device_name(device: u16) -> String {
    match device {
        IWL5300 => "Intel 5300".into(),
        QCA9300 => "Qualcomm Atheros QCA9300".into(),
        AX200 => "Intel AX200".into(),
        AX210 => "Intel AX210".into(),
        USRP => "USRP".into(),
        VIRTUAL_SDR => "PicoScenes virtual SDR".into(),
        d => format!("PicoScenes device {d:#06x}"),
    }
}

/// The frame format's name.
pub(super) fn format_name(format: i8) -> &'static str {
    match format {
        0 => "legacy",
        1 => "HT",
        2 => "VHT",
        3 => "HE-SU",
        4 => "HE-MU",
        _ => "unknown",
    }
}

/// The pilots of a format and bandwidth (IEEE 802.11-2016/802.11ax); the caller keeps those
/// among the reported subcarriers.
pub(super) fn pilots(format: i8, cbw: u16) -> Vec<i32> {
    let half: &[i32] = match (format, cbw) {
        (0..=2, 20) => &[7, 21],
        (1 | 2, 40) => &[11, 25, 53],
        (2, 80) => &[11, 39, 75, 103],
        (2, 160) => &[25, 53, 89, 117, 139, 167, 203, 231],
        (3 | 4, 20) => &[22, 48, 90, 116],
        (3 | 4, 40) => &[10, 36, 78, 104, 144, 170, 212, 238],
        (3 | 4, 80) => &[24, 92, 158, 226, 266, 334, 400, 468],
        _ => &[],
    };
    let mut p: Vec<i32> = half
        .iter()
        .rev()
        .map(|k| -k)
        .chain(half.iter().copied())
        .collect();
    p.sort_unstable();
    p
}

/// Parses the body of a `CSI` segment of `version` (1–4).
pub(super) fn parse(c: &mut Cursor<'_>, version: u16) -> Result<Csi> {
    if !(1..=4).contains(&version) {
        return Err(c.bad(
            "version",
            format!("{version}: unsupported (versions 1 to 4 are read)"),
        ));
    }
    let device = c.u16("DeviceType")?;
    if version >= 4 {
        c.u8("FirmwareVersion")?;
    }
    let format = c.u8("PacketFormat")? as i8;
    let cbw = c.u16("CBW")?;
    let carrier_hz = c.u64("CarrierFreq")?;
    c.u64("SamplingRate")?;
    let spacing_hz = c.u32("SubcarrierBandwidth")?;
    let tones = usize::from(c.u16("NumTones")?);
    c.u8("NumTx")?;
    let n_rx = usize::from(c.u8("NumRx")?);
    c.u8("NumESS")?;
    if version >= 3 {
        let n = c.u16("NumCSI")?;
        if n != 1 {
            return Err(c.bad("NumCSI", format!("{n}: only one CSI per frame is read")));
        }
    }
    c.u8("ANTSEL")?;
    let offset = if version >= 2 {
        i32::from(c.u16("SubcarrierOffset")? as i16)
    } else {
        0
    };
    let len = c.u32("CSIBufferLength")? as usize;
    let buf = c.take("CSI buffer", len)?;
    if n_rx == 0 || tones == 0 || tones > MAX_BINS_PER_LINK {
        let (f, v) = if n_rx == 0 {
            ("NumRx", n_rx)
        } else {
            ("NumTones", tones)
        };
        return Err(c.bad(f, format!("{v}: impossible")));
    }
    let (n_tx, mut subcarriers, values) = match device {
        IWL5300 => iwl5300(c, buf, tones, n_rx, cbw)?,
        QCA9300 => qca9300(c, buf, tones, n_rx, cbw)?,
        USRP | VIRTUAL_SDR => signal_matrix(c, buf, tones, n_rx)?,
        _ => {
            return Err(c.bad(
                "DeviceType",
                format!(
                    "{} ({device:#06x}): CSI layout unsupported (IWL5300, QCA9300 and the SDR \
                     layout with explicit subcarrier indices are read)",
                    device_name(device)
                ),
            ))
        }
    };
    for k in &mut subcarriers {
        *k += offset;
    }
    if subcarriers.windows(2).any(|w| w[1] <= w[0]) {
        return Err(c.bad("subcarrier indices", "not strictly increasing".into()));
    }
    Ok(Csi {
        device,
        format,
        cbw,
        carrier_hz,
        spacing_hz,
        n_rx,
        n_tx,
        subcarriers,
        values,
    })
}

type Layout = (usize, Vec<i32>, Vec<Complex>);

/// The Intel 5300's bfee payload: `60·NumRx·N + 12` bytes for `N` streams per chain.
fn iwl5300(c: &Cursor<'_>, buf: &[u8], tones: usize, n_rx: usize, cbw: u16) -> Result<Layout> {
    if tones != bfee::TONES {
        return Err(c.bad("NumTones", format!("{tones}: the IWL5300 reports 30")));
    }
    if !(1..=3).contains(&n_rx) {
        return Err(c.bad("NumRx", format!("{n_rx}: the IWL5300 has 1 to 3 chains")));
    }
    let bw40 = match cbw {
        20 => false,
        40 => true,
        _ => return Err(c.bad("CBW", format!("{cbw} MHz: the IWL5300 has 20 or 40"))),
    };
    let n = buf
        .len()
        .checked_sub(12)
        .filter(|n| n % (60 * n_rx) == 0)
        .map(|n| n / (60 * n_rx));
    let n_tx = match n {
        Some(n @ 1..=3) => n,
        _ => {
            return Err(c.bad(
                "CSIBufferLength",
                format!(
                    "{}: not 60·NumRx·N + 12 with NumRx = {n_rx}, N = 1 to 3",
                    buf.len()
                ),
            ))
        }
    };
    let values = bfee::decode(buf, n_rx, n_tx, None)
        .ok_or_else(|| c.bad("CSI buffer", "bfee bit stream too short".into()))?;
    Ok((n_tx, bfee::subcarriers(bw40), values))
}

/// The QCA9300's 10-bit packed values: per stream and chain 56 (20 MHz) or 114 (40 MHz)
/// tones, 4 numbers in 5 bytes, imaginary part first; value `v` is chain `v mod NumRx`,
/// stream `(v / NumRx) mod N`, tone `v / (NumRx·N)` (PicoScenes' `parseQCA9300CSIData`).
fn qca9300(c: &Cursor<'_>, buf: &[u8], tones: usize, n_rx: usize, cbw: u16) -> Result<Layout> {
    let (a, b, per) = match cbw {
        20 => (28, 1, 140),
        40 => (58, 2, 285),
        _ => return Err(c.bad("CBW", format!("{cbw} MHz: the QCA9300 has 20 or 40"))),
    };
    let subcarriers: Vec<i32> = (-a..=-b).chain(b..=a).collect();
    if tones != subcarriers.len() {
        return Err(c.bad(
            "NumTones",
            format!("{tones}: {} at {cbw} MHz", subcarriers.len()),
        ));
    }
    let n_tx = buf.len() / per / n_rx;
    if n_tx == 0 || n_tx * n_rx > MAX_LINKS {
        return Err(c.bad("CSIBufferLength", format!("{}: no whole stream", buf.len())));
    }
    let count = tones * n_tx * n_rx;
    let num = |i: usize| -> f64 {
        let bit = i * 10;
        let lo = u16::from(buf.get(bit / 8).copied().unwrap_or(0));
        let hi = u16::from(buf.get(bit / 8 + 1).copied().unwrap_or(0));
        let v = ((lo | hi << 8) >> (bit % 8)) & 0x3FF;
        f64::from(if v & 0x200 != 0 {
            v as i16 - 0x400
        } else {
            v as i16
        })
    };
    let mut values = vec![Complex::new(0.0, 0.0); count];
    for v in 0..count {
        let (r, t, k) = (v % n_rx, (v / n_rx) % n_tx, v / (n_rx * n_tx));
        values[(r * n_tx + t) * tones + k] = Complex::new(num(2 * v + 1), num(2 * v));
    }
    Ok((n_tx, subcarriers, values))
}

/// The SDR layout: `NumTones` i16 subcarrier indices, then a PicoScenes `SignalMatrix`
/// (`"BBv1"`/`"BBv2"`, u8 ndim, dimensions u32 (v1) or u64 (v2) `[tones, streams, chains,
/// CSIs]`, `'C'` complex, type `'D'`/`'F'`/`'I'`, bits, majority `'C'`/`'R'`, values).
fn signal_matrix(c: &Cursor<'_>, buf: &[u8], tones: usize, n_rx: usize) -> Result<Layout> {
    let mut m = Cursor::new(buf, c.frame, "CSI");
    let mut subcarriers = Vec::with_capacity(tones.min(buf.len() / 2));
    for _ in 0..tones {
        subcarriers.push(i32::from(m.u16("subcarrier indices")? as i16));
    }
    let magic = m.take("SignalMatrix", 4)?;
    let wide = match magic {
        b"BBv1" => false,
        b"BBv2" => true,
        _ => return Err(m.bad("SignalMatrix", "no BBv1/BBv2 header".into())),
    };
    let ndim = usize::from(m.u8("SignalMatrix ndim")?);
    if !(1..=4).contains(&ndim) {
        return Err(m.bad("SignalMatrix ndim", format!("{ndim}: 1 to 4 expected")));
    }
    let mut dims = [1usize; 4];
    for d in dims.iter_mut().take(ndim) {
        *d = if wide {
            usize::try_from(m.u64("SignalMatrix dimensions")?).unwrap_or(usize::MAX)
        } else {
            m.u32("SignalMatrix dimensions")? as usize
        };
    }
    let [k, n_tx, r, n_csi] = dims;
    if k != tones || r != n_rx || n_tx == 0 || n_tx > MAX_LINKS || n_csi != 1 {
        return Err(m.bad(
            "SignalMatrix dimensions",
            format!("{dims:?}: [NumTones {tones}, streams, NumRx {n_rx}, 1] expected"),
        ));
    }
    let complex = m.u8("SignalMatrix complexity")?;
    let kind = m.u8("SignalMatrix type")?;
    let bits = m.u8("SignalMatrix bits")?;
    let column = match m.u8("SignalMatrix majority")? {
        b'C' => true,
        b'R' => false,
        x => return Err(m.bad("SignalMatrix majority", format!("{:?}: C or R", x as char))),
    };
    let size = match (complex, kind, bits) {
        (b'C', b'D', 64) | (b'C', b'F', 32) | (b'C', b'I', 8 | 16 | 32) => usize::from(bits / 8),
        _ => {
            return Err(m.bad(
                "SignalMatrix type",
                format!(
                    "{}{}{bits}: complex D64, F32 or I8/16/32",
                    complex as char, kind as char
                ),
            ))
        }
    };
    let count = k.checked_mul(n_tx).and_then(|v| v.checked_mul(r));
    let bytes = count.and_then(|v| v.checked_mul(2 * size));
    let (Some(count), Some(bytes)) = (count, bytes) else {
        return Err(m.bad("SignalMatrix dimensions", format!("{dims:?}: too large")));
    };
    let data = m.take("SignalMatrix values", bytes)?;
    let part = |i: usize| -> f64 {
        let b = data.get(i * size..(i + 1) * size).unwrap_or_default();
        match (kind, size) {
            (b'D', _) => <[u8; 8]>::try_from(b).map_or(0.0, f64::from_le_bytes),
            (b'F', _) => <[u8; 4]>::try_from(b).map_or(0.0, |a| f64::from(f32::from_le_bytes(a))),
            (_, 1) => b.first().map_or(0.0, |&x| f64::from(x as i8)),
            (_, 2) => <[u8; 2]>::try_from(b).map_or(0.0, |a| f64::from(i16::from_le_bytes(a))),
            _ => <[u8; 4]>::try_from(b).map_or(0.0, |a| f64::from(i32::from_le_bytes(a))),
        }
    };
    let mut values = vec![Complex::new(0.0, 0.0); count];
    for i in 0..count {
        let (kk, t, rr) = if column {
            (i % k, (i / k) % n_tx, i / (k * n_tx))
        } else {
            (i / (n_tx * r), (i / r) % n_tx, i % r)
        };
        values[(rr * n_tx + t) * k + kk] = Complex::new(part(2 * i), part(2 * i + 1));
    }
    Ok((n_tx, subcarriers, values))
}
