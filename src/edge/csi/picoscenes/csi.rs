//! The `CSI` segment of a PicoScenes RXS frame: its header (versions 1–4) and the CSI values in
//! the layout of the device type (module doc of `picoscenes`).

use alloc::format;
use alloc::string::String;
use alloc::vec;
use alloc::vec::Vec;

use super::super::bfee;
use super::super::tones::{map, Phy};
use super::cursor::Cursor;
use super::mvm;
use crate::error::limits::{MAX_BINS_PER_LINK, MAX_LINKS};
use crate::error::Result;
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
    /// `SubcarrierOffset` (added to the indices; the pilots shift with them).
    pub offset: i32,
    /// Receive chains.
    pub n_rx: usize,
    /// Streams measured (as the buffer holds them: IWL5300/QCA9300 `NumTx + NumESS`, from its
    /// length; AX200/AX210 `NumTx`; the SDRs the `SignalMatrix`'s).
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

/// The unit of `RxSBasic.tstamp`, ticks per second: ns for the SDRs (the host's clock since
/// the Unix epoch), µs for the NICs (their hardware clock).
pub(super) fn ticks_per_second(device: u16) -> f64 {
    match device {
        USRP | VIRTUAL_SDR => 1e9,
        _ => 1e6,
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

/// The pilots of a format and bandwidth (IEEE 802.11-2016/802.11ax, the subcarrier maps of
/// `csi::tones`; HE-MU as HE-SU), in index order; the caller keeps those among the reported
/// subcarriers.
pub(super) fn pilots(format: i8, cbw: u16) -> Vec<i32> {
    let phy = match format {
        0 => Phy::Legacy,
        1 => Phy::Ht,
        2 => Phy::Vht,
        3 | 4 => Phy::He,
        _ => return Vec::new(),
    };
    map(phy, u32::from(cbw)).map_or_else(Vec::new, |m| m.all_pilots())
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
    let num_tx = usize::from(c.u8("NumTx")?);
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
        AX200 | AX210 => mvm::read(c, buf, format, cbw, tones, num_tx, n_rx)?,
        USRP | VIRTUAL_SDR => signal_matrix(c, buf, tones, n_rx)?,
        _ => {
            return Err(c.bad(
                "DeviceType",
                format!(
                    "{} ({device:#06x}): CSI layout unsupported (IWL5300, QCA9300, AX200/AX210 \
                     and the SDR layout with explicit subcarrier indices are read)",
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
        offset,
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A version-2 CSI segment body.
    fn body(device: u16, cbw: u16, tones: u16, n_rx: u8, offset: i16, buf: &[u8]) -> Vec<u8> {
        let mut b = device.to_le_bytes().to_vec();
        b.push(1); // HT
        b.extend(cbw.to_le_bytes());
        b.extend(5_180_000_000u64.to_le_bytes());
        b.extend(20_000_000u64.to_le_bytes());
        b.extend(312_500u32.to_le_bytes());
        b.extend(tones.to_le_bytes());
        b.extend([1, n_rx, 0, 0]);
        b.extend(offset.to_le_bytes());
        b.extend((buf.len() as u32).to_le_bytes());
        b.extend(buf);
        b
    }

    fn parse_v2(b: &[u8]) -> Result<Csi> {
        parse(&mut Cursor::new(b, 7, "CSI"), 2)
    }

    #[test]
    fn qca9300_ten_bit_values_imaginary_first() {
        // 2 chains × 1 stream × 56 tones; value v: chain v mod 2, tone v / 2.
        let z = |v: i32| ((v % 50) - 25, 3 - (v % 37));
        let mut nums = Vec::new();
        for v in 0..112 {
            let (re, im) = z(v);
            nums.extend([im, re]);
        }
        let mut buf = vec![0u8; 280];
        for (i, &n) in nums.iter().enumerate() {
            let bits = (n as u32) & 0x3FF;
            for j in 0..10 {
                if bits >> j & 1 == 1 {
                    buf[(i * 10 + j) / 8] |= 1 << ((i * 10 + j) % 8);
                }
            }
        }
        let c = parse_v2(&body(QCA9300, 20, 56, 2, 0, &buf)).unwrap();
        assert_eq!((c.n_rx, c.n_tx, c.subcarriers.len()), (2, 1, 56));
        assert_eq!((c.subcarriers[27], c.subcarriers[28]), (-1, 1));
        for v in 0..112usize {
            let (re, im) = z(v as i32);
            let got = c.values[(v % 2) * 56 + v / 2];
            assert_eq!(got, Complex::new(re.into(), im.into()), "value {v}");
        }
        let e = parse_v2(&body(QCA9300, 20, 30, 2, 0, &buf))
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("frame 7: CSI.NumTones"), "{e}");
        let e = parse_v2(&body(QCA9300, 20, 56, 3, 0, &buf))
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("frame 7: CSI.CSIBufferLength"), "{e}");
    }

    fn matrix(version: u8, dims: &[u64], kind: &[u8; 4], values: &[u8]) -> Vec<u8> {
        let mut m = vec![b'B', b'B', b'v', b'0' + version, dims.len() as u8];
        for &d in dims {
            if version == 1 {
                m.extend((d as u32).to_le_bytes());
            } else {
                m.extend(d.to_le_bytes());
            }
        }
        m.extend(kind);
        m.extend(values);
        m
    }

    #[test]
    fn sdr_layout_with_explicit_indices() {
        let mut buf: Vec<u8> = [-2i16, 1, 3].iter().flat_map(|k| k.to_le_bytes()).collect();
        // Column-major [3 tones, 1 stream, 2 chains] of complex int16: value i = (i+1, -(i+1)).
        let vals: Vec<u8> = (1..=6i16)
            .flat_map(|i| [i, -i])
            .flat_map(|x| x.to_le_bytes())
            .collect();
        buf.extend(matrix(1, &[3, 1, 2], b"CI\x10C", &vals));
        let c = parse_v2(&body(USRP, 20, 3, 2, 10, &buf)).unwrap();
        assert_eq!(c.subcarriers, [8, 11, 13]);
        assert_eq!((c.n_rx, c.n_tx), (2, 1));
        // Chain 1, tone 2 is element 2 + 3·1 = 5: (6, -6).
        assert_eq!(c.values[3 + 2], Complex::new(6.0, -6.0));
        assert_eq!(c.values[1], Complex::new(2.0, -2.0));
        // Row-major complex float32, BBv2: element i is tone i / 2, chain i mod 2.
        let mut buf: Vec<u8> = [-2i16, 1, 3].iter().flat_map(|k| k.to_le_bytes()).collect();
        let vals: Vec<u8> = (1..=6)
            .flat_map(|i| [i as f32, 0.5])
            .flat_map(|x| x.to_le_bytes())
            .collect();
        buf.extend(matrix(2, &[3, 1, 2], b"CF\x20R", &vals));
        let c = parse_v2(&body(VIRTUAL_SDR, 20, 3, 2, 0, &buf)).unwrap();
        assert_eq!(c.values[3 + 2], Complex::new(6.0, 0.5));
        assert_eq!(c.values[1], Complex::new(3.0, 0.5));
        // Wrong dimensions, a bad header, a short buffer.
        let mut bad = buf.clone();
        bad[6] = b'X';
        let e = parse_v2(&body(USRP, 20, 3, 2, 0, &bad))
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("frame 7: CSI.SignalMatrix"), "{e}");
        let e = parse_v2(&body(USRP, 20, 3, 1, 0, &buf))
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("frame 7: CSI.SignalMatrix dimensions"), "{e}");
        let e = parse_v2(&body(USRP, 20, 3, 2, 0, &buf[..buf.len() - 1]))
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("frame 7: CSI.SignalMatrix values"), "{e}");
        // Indices must increase.
        let mut swap = buf.clone();
        swap[..2].copy_from_slice(&5i16.to_le_bytes());
        let e = parse_v2(&body(USRP, 20, 3, 2, 0, &swap))
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("frame 7: CSI.subcarrier indices"), "{e}");
        // Huge dimensions: an error, no allocation.
        let mut buf: Vec<u8> = [-2i16, 1, 3].iter().flat_map(|k| k.to_le_bytes()).collect();
        buf.extend(matrix(2, &[3, u64::MAX, 2], b"CD\x40C", &[]));
        assert!(parse_v2(&body(USRP, 20, 3, 2, 0, &buf)).is_err());
    }

    #[test]
    fn other_devices_and_versions_are_named_unsupported() {
        for dev in [0x0802, 0x3000] {
            let e = parse_v2(&body(dev, 20, 56, 1, 0, &[0; 224]))
                .unwrap_err()
                .to_string();
            assert!(
                e.starts_with("frame 7: CSI.DeviceType") && e.contains("unsupported"),
                "{e}"
            );
        }
        let e = parse(&mut Cursor::new(&[0; 64], 7, "CSI"), 5)
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("frame 7: CSI.version"), "{e}");
        assert_eq!(pilots(2, 80), [-103, -75, -39, -11, 11, 39, 75, 103]);
        // HE 160: the HE 80 pilots around ±512 (802.11ax §27.3.11.13), 32 in all.
        let he160 = pilots(3, 160);
        assert_eq!(
            (he160.len(), he160[0], he160[15], he160[16]),
            (32, -980, -44, 44)
        );
        assert_eq!(ticks_per_second(USRP), 1e9);
        assert_eq!(ticks_per_second(IWL5300), 1e6);
    }

    /// A version-3 CSI segment body (csiread's version; `NumCSI` 1, `NumESS` 1, ignored by the
    /// MVM layout) of `format`.
    #[allow(clippy::too_many_arguments)]
    fn mvm_body(
        device: u16,
        format: u8,
        cbw: u16,
        tones: u16,
        n_tx: u8,
        n_rx: u8,
        offset: i16,
        buf: &[u8],
    ) -> Vec<u8> {
        let mut b = device.to_le_bytes().to_vec();
        b.push(format);
        b.extend(cbw.to_le_bytes());
        b.extend(5_500_000_000u64.to_le_bytes());
        b.extend((u64::from(cbw) * 1_000_000).to_le_bytes());
        b.extend(if format == 3 { 78_125u32 } else { 312_500 }.to_le_bytes());
        b.extend(tones.to_le_bytes());
        b.extend([n_tx, n_rx, 1]);
        b.extend(1u16.to_le_bytes());
        b.push(0);
        b.extend(offset.to_le_bytes());
        b.extend((buf.len() as u32).to_le_bytes());
        b.extend(buf);
        b
    }

    /// The raw value `i` of the pattern: both parts sweep the whole i16 range.
    fn raw(i: usize) -> (i16, i16) {
        let re = (i as u32).wrapping_mul(40_503) as u16 as i16;
        (re, !re)
    }

    /// The tables of PicoScenes' `CSISegment.cxx` (`*_Subcarriers_Indices`, as ranges) and the
    /// pilots of IEEE 802.11-2016 §19.3.11.10, §21.3.10.10 and 802.11ax §27.3.11.13 (positive
    /// halves), written out here as the independent reference.
    #[allow(clippy::type_complexity)]
    const TABLES: [(u8, u16, usize, &[(i32, i32)], &[i32]); 11] = [
        (0, 20, 52, &[(-26, -1), (1, 26)], &[7, 21]),
        (1, 20, 56, &[(-28, -1), (1, 28)], &[7, 21]),
        (2, 20, 56, &[(-28, -1), (1, 28)], &[7, 21]),
        (1, 40, 114, &[(-58, -2), (2, 58)], &[11, 25, 53]),
        (2, 40, 114, &[(-58, -2), (2, 58)], &[11, 25, 53]),
        (2, 80, 242, &[(-122, -2), (2, 122)], &[11, 39, 75, 103]),
        (
            2,
            160,
            484,
            &[(-250, -130), (-126, -6), (6, 126), (130, 250)],
            &[25, 53, 89, 117, 139, 167, 203, 231],
        ),
        (3, 20, 242, &[(-122, -2), (2, 122)], &[22, 48, 90, 116]),
        (
            3,
            40,
            484,
            &[(-244, -3), (3, 244)],
            &[10, 36, 78, 104, 144, 170, 212, 238],
        ),
        (
            3,
            80,
            996,
            &[(-500, -3), (3, 500)],
            &[24, 92, 158, 226, 266, 334, 400, 468],
        ),
        (
            3,
            160,
            1992,
            &[(-1012, -515), (-509, -12), (12, 509), (515, 1012)],
            &[
                44, 112, 178, 246, 286, 354, 420, 488, 536, 604, 670, 738, 778, 846, 912, 980,
            ],
        ),
    ];

    #[test]
    fn mvm_every_table_with_its_values_in_tone_stream_chain_order() {
        for (format, cbw, k_raw, ranges, half) in TABLES {
            let table: Vec<i32> = ranges.iter().flat_map(|&(a, b)| a..=b).collect();
            assert_eq!(table.len(), k_raw);
            for (device, n_tx, n_rx, offset) in [(AX200, 1u8, 2u8, 0i16), (AX210, 2, 2, -3)] {
                let (nt, nr) = (usize::from(n_tx), usize::from(n_rx));
                let buf: Vec<u8> = (0..k_raw * nt * nr)
                    .flat_map(|i| {
                        let (re, im) = raw(i);
                        [re.to_le_bytes(), im.to_le_bytes()]
                    })
                    .flatten()
                    .collect();
                assert_eq!(buf.len(), nt * nr * k_raw * 4);
                let b = mvm_body(device, format, cbw, k_raw as u16, n_tx, n_rx, offset, &buf);
                let c = parse(&mut Cursor::new(&b, 7, "CSI"), 3).unwrap();
                let kept: Vec<usize> = (0..k_raw)
                    .filter(|&j| !half.contains(&table[j].abs()))
                    .collect();
                assert_eq!(kept.len(), k_raw - 2 * half.len(), "{format} {cbw}");
                let want: Vec<i32> = kept.iter().map(|&j| table[j] + i32::from(offset)).collect();
                assert_eq!(c.subcarriers, want, "{format} {cbw}");
                assert_eq!((c.device, c.format, c.cbw), (device, format as i8, cbw));
                assert_eq!((c.n_rx, c.n_tx, c.carrier_hz), (nr, nt, 5_500_000_000));
                let k = kept.len();
                assert_eq!(c.values.len(), k * nt * nr);
                for r in 0..nr {
                    for t in 0..nt {
                        for (n, &j) in kept.iter().enumerate() {
                            // Column-major {NumTones, NumTx, NumRx}: i = j + K·(t + NumTx·r).
                            let (re, im) = raw(j + k_raw * (t + nt * r));
                            let got = c.values[(r * nt + t) * k + n];
                            assert_eq!(got, Complex::new(re.into(), im.into()));
                        }
                    }
                }
            }
        }
        // The v4 header (with FirmwareVersion) reads the same layout.
        let mut b = mvm_body(AX210, 1, 20, 56, 1, 1, 0, &[1; 224]);
        b.insert(2, 9);
        let c = parse(&mut Cursor::new(&b, 7, "CSI"), 4).unwrap();
        assert_eq!(
            (c.subcarriers.len(), c.values[0]),
            (52, Complex::new(257.0, 257.0))
        );
    }

    #[test]
    fn mvm_wrong_sizes_and_pairs_without_a_table_are_named() {
        let v3 = |b: Vec<u8>| {
            parse(&mut Cursor::new(&b, 7, "CSI"), 3)
                .unwrap_err()
                .to_string()
        };
        let cases: [(u8, u16, u16, u8, usize, &str); 9] = [
            (2, 80, 242, 1, 242 * 8 - 4, "frame 7: CSI.CSIBufferLength"),
            (2, 80, 242, 1, 242 * 8 + 4, "frame 7: CSI.CSIBufferLength"),
            (2, 80, 242, 2, 242 * 8, "frame 7: CSI.CSIBufferLength"),
            (2, 80, 242, 0, 0, "frame 7: CSI.NumTx"),
            (2, 160, 498, 1, 498 * 8, "frame 7: CSI.NumTones"),
            (3, 20, 56, 1, 56 * 8, "frame 7: CSI.NumTones"),
            (1, 80, 242, 1, 242 * 8, "frame 7: CSI.CBW"),
            (0, 40, 114, 1, 114 * 8, "frame 7: CSI.CBW"),
            (4, 20, 242, 1, 242 * 8, "frame 7: CSI.PacketFormat"),
        ];
        for (format, cbw, tones, n_tx, len, want) in cases {
            let e = v3(mvm_body(
                AX200,
                format,
                cbw,
                tones,
                n_tx,
                2,
                0,
                &vec![0; len],
            ));
            assert!(e.starts_with(want), "{want}: {e}");
        }
        let e = v3(mvm_body(AX200, 2, 80, 242, 1, 2, 0, &[0; 100]));
        assert!(
            e.contains("100: NumTx·NumRx·NumTones·4 = 1·2·242·4 = 1936"),
            "{e}"
        );
    }
}
