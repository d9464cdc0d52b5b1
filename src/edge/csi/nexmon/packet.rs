//! One pcap record: the link, IPv4 and UDP layers down to the Nexmon payload, its 18-byte
//! header, the chip, the chanspec and the CSI words (the layouts are in the module doc).

use alloc::format;
use alloc::string::String;

use crate::error::{Error, Result};
use crate::math::Real;

/// The UDP port nexmon_csi sends to.
pub(super) const CSI_PORT: u16 = 5500;
/// Bytes of the Nexmon header before the CSI words.
pub(super) const HEADER_BYTES: usize = 18;

/// pcap link types this reader unwraps.
pub(super) const LINKTYPE_ETHERNET: u32 = 1;
/// Linux "cooked" capture (`tcpdump -i any`).
pub(super) const LINKTYPE_LINUX_SLL: u32 = 113;

/// The two layouts of the Nexmon header's first four bytes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum HeaderVersion {
    /// Magic `0x11111111` (nexmon_csi before its RSSI change, 2020-06): no RSSI, no frame
    /// control, the CSI words untouched.
    Magic4,
    /// Magic `0x1111`, RSSI (i8), frame control (u8) (nexmon_csi pull requests 46/256): the
    /// firmware writes 3 words of PHY status over FFT bins `o..o+3` (`o` = 28 at 20 MHz, else 0).
    Rssi,
}

/// The sample format of a chip's CSI words.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Sample {
    /// Two int16 (low half, high half of each little-endian word).
    Int16,
    /// Packed float: sign + `m − 1`-bit magnitude for real and imaginary parts, an `e`-bit
    /// two's-complement exponent (csiread's and nexmon's `unpack_float`, `M`, `E`).
    Float { m: u32, e: u32 },
}

/// A chip nexmon_csi extracts CSI on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct Chip {
    /// The header's chip-version field (nexmon `firmware_version.h`).
    pub version: u16,
    /// Name for [`super::super::CsiCapture::device`].
    pub name: &'static str,
    /// How its CSI words are packed.
    pub sample: Sample,
}

/// The chips whose CSI format nexmon_csi documents (README, `csi_extractor.c`).
pub(super) const CHIPS: [Chip; 4] = [
    Chip {
        version: 1,
        name: "BCM4339",
        sample: Sample::Int16,
    },
    Chip {
        version: 3,
        name: "BCM4358",
        sample: Sample::Float { m: 9, e: 5 },
    },
    Chip {
        version: 101,
        name: "BCM43455c0",
        sample: Sample::Int16,
    },
    Chip {
        version: 106,
        name: "BCM4366c0",
        sample: Sample::Float { m: 12, e: 6 },
    },
];

/// The chip of a chip-version field; an error naming the frame otherwise.
pub(super) fn chip(version: u16, frame: usize) -> Result<Chip> {
    if let Some(c) = CHIPS.iter().find(|c| c.version == version) {
        return Ok(*c);
    }
    let known = CHIPS
        .iter()
        .map(|c| format!("{} ({})", c.version, c.name))
        .collect::<alloc::vec::Vec<_>>()
        .join(", ");
    let extra = match version {
        105 => " — 105 is the BCM4375b1, whose CSI format nexmon_csi does not document",
        _ => "",
    };
    Err(Error::InvalidFile {
        field: format!("frame {frame}: chip version"),
        reason: format!(
            "{version} (0x{version:04x}) is not a chip this reader decodes{extra}; known: {known} \
             (captures from before nexmon_csi's chip field, 2019-10, hold other values)"
        ),
    })
}

/// What a (d11ac) chanspec says: bandwidth, FFT size, carrier.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Chanspec {
    /// The raw field.
    pub raw: u16,
    /// Bandwidth, MHz (20, 40 or 80).
    pub bw_mhz: u32,
    /// FFT size: 3.2 × the bandwidth in MHz.
    pub nfft: usize,
    /// The centre frequency, Hz, where the band is 2.4 or 5 GHz.
    pub center_hz: Option<Real>,
}

/// Decodes a d11ac chanspec (bits 0–7 channel — the centre channel of a 40/80 MHz channel —,
/// 8–10 control sideband, 11–13 bandwidth 2/3/4 = 20/40/80 MHz, 14–15 band 0 = 2.4 GHz,
/// 3 = 5 GHz). Other bandwidths are an error naming the frame.
pub(super) fn chanspec(raw: u16, frame: usize) -> Result<Chanspec> {
    let bw_mhz = match (raw >> 11) & 7 {
        2 => 20,
        3 => 40,
        4 => 80,
        code => {
            let what = [
                "5 MHz",
                "10 MHz",
                "",
                "",
                "",
                "160 MHz",
                "80+80 MHz",
                "reserved",
            ][code as usize];
            return Err(Error::InvalidFile {
                field: format!("frame {frame}: chanspec"),
                reason: format!(
                    "0x{raw:04x}: bandwidth code {code} ({what}, bits 11–13) — nexmon_csi \
                     reports 20, 40 or 80 MHz (codes 2, 3, 4)"
                ),
            });
        }
    };
    let channel = Real::from(raw & 0xff);
    let center_mhz = match raw >> 14 {
        0 if raw & 0xff == 14 => Some(2484.0),
        0 => Some(2407.0 + 5.0 * channel),
        3 => Some(5000.0 + 5.0 * channel),
        _ => None,
    };
    Ok(Chanspec {
        raw,
        bw_mhz,
        nfft: bw_mhz as usize * 16 / 5,
        center_hz: center_mhz.map(|f| f * 1e6),
    })
}

/// The Nexmon header of one CSI packet and its CSI bytes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Packet<'a> {
    pub version: HeaderVersion,
    pub seq: u16,
    pub core: u8,
    pub stream: u8,
    pub chanspec: u16,
    pub chip_version: u16,
    /// The bytes after the header (the CSI words, possibly followed by extra bytes).
    pub csi: &'a [u8],
}

fn u16_be(b: &[u8], at: usize) -> Option<u16> {
    Some(u16::from_be_bytes([*b.get(at)?, *b.get(at + 1)?]))
}

fn u16_le(b: &[u8], at: usize) -> Option<u16> {
    Some(u16::from_le_bytes([*b.get(at)?, *b.get(at + 1)?]))
}

/// The UDP payload to port 5500 of a record, or why the record is not one (a skip reason).
pub(super) fn udp_payload(link: u32, data: &[u8]) -> core::result::Result<&[u8], String> {
    let (ethertype, ip) = match link {
        LINKTYPE_ETHERNET => {
            let mut at = 12;
            let mut ty = u16_be(data, at);
            if ty == Some(0x8100) {
                at += 4;
                ty = u16_be(data, at);
            }
            (ty, data.get(at + 2..))
        }
        _ => (u16_be(data, 14), data.get(16..)),
    };
    let (Some(ethertype), Some(ip)) = (ethertype, ip) else {
        return Err(format!(
            "{} bytes: shorter than its link-layer header",
            data.len()
        ));
    };
    if ethertype != 0x0800 {
        return Err(format!("EtherType 0x{ethertype:04x}, not IPv4"));
    }
    let (Some(&vihl), Some(total), Some(frag), Some(&proto)) =
        (ip.first(), u16_be(ip, 2), u16_be(ip, 6), ip.get(9))
    else {
        return Err("IPv4 header truncated".into());
    };
    let ihl = usize::from(vihl & 0x0f) * 4;
    if vihl >> 4 != 4 || ihl < 20 || usize::from(total) < ihl {
        return Err(format!(
            "not an IPv4 header (version/IHL 0x{vihl:02x}, length {total})"
        ));
    }
    if proto != 17 {
        return Err(format!("IP protocol {proto}, not UDP"));
    }
    if frag & 0x3fff != 0 {
        return Err("an IPv4 fragment".into());
    }
    let ip = ip.get(..usize::from(total).min(ip.len())).unwrap_or(ip);
    let Some(udp) = ip.get(ihl..) else {
        return Err("IPv4 header truncated".into());
    };
    let (Some(port), Some(udp_len)) = (u16_be(udp, 2), u16_be(udp, 4)) else {
        return Err("UDP header truncated".into());
    };
    if port != CSI_PORT {
        return Err(format!("UDP to port {port}, not {CSI_PORT}"));
    }
    let end = usize::from(udp_len).min(udp.len());
    match udp.get(8..end) {
        Some(p) if udp_len >= 8 => Ok(p),
        _ => Err(format!("UDP length {udp_len}: shorter than its header")),
    }
}

/// The Nexmon header of a UDP payload, or why it is not one (a skip reason).
pub(super) fn nexmon_header(payload: &[u8]) -> core::result::Result<Packet<'_>, String> {
    let Some(csi) = payload.get(HEADER_BYTES..) else {
        return Err(format!(
            "UDP payload {} bytes: shorter than the {HEADER_BYTES}-byte Nexmon header",
            payload.len()
        ));
    };
    let word = |at| u16_le(payload, at).unwrap_or(0);
    let version = match payload.get(..4) {
        Some([0x11, 0x11, 0x11, 0x11]) => HeaderVersion::Magic4,
        Some([0x11, 0x11, _, _]) => HeaderVersion::Rssi,
        _ => {
            return Err(format!(
                "magic 0x{:04x}, not 0x1111 (not Nexmon CSI)",
                word(0)
            ));
        }
    };
    let conf = word(12);
    Ok(Packet {
        version,
        seq: word(10),
        core: (conf & 7) as u8,
        stream: ((conf >> 3) & 7) as u8,
        chanspec: word(14),
        chip_version: word(16),
        csi,
    })
}

/// One CSI word's two parts before scaling: magnitudes, signs and exponent (floats), or the
/// two int16 (integers; exponent 0).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct Word {
    pub re: i32,
    pub im: i32,
    pub exp: i32,
}

/// Unpacks word `h` as csiread's/nexmon's `unpack_float` does: magnitudes
/// `(h >> (E+M)) & (2^(M−1)−1)` and `(h >> E) & (2^(M−1)−1)`, signs at bits `E+2M−1` and
/// `E+M−1`, exponent the low `E` bits in two's complement.
pub(super) fn unpack_float(h: u32, m: u32, e: u32) -> Word {
    let mag = (1u32 << (m - 1)) - 1;
    let sign = |bit: u32| if h & (1 << bit) != 0 { -1 } else { 1 };
    let e_p = 1i32 << (e - 1);
    let mut exp = (h & ((1 << e) - 1)) as i32;
    if exp >= e_p {
        exp -= e_p << 1;
    }
    Word {
        re: sign(e + 2 * m - 1) * ((h >> (e + m)) & mag) as i32,
        im: sign(e + m - 1) * ((h >> e) & mag) as i32,
        exp,
    }
}

/// The autoscale exponent of a word: its exponent plus the position of the highest set bit of
/// `|re| | |im|` (`None` for a zero word), as `unpack_float`'s `maxbit` search.
pub(super) fn top_bit(w: Word) -> Option<i32> {
    let x = w.re.unsigned_abs() | w.im.unsigned_abs();
    (x != 0).then(|| w.exp + (31 - x.leading_zeros()) as i32)
}

/// One part scaled as `unpack_float` does with shift `shft` (`e = exp + shft`): `0` below
/// `−M`, a right shift (truncating the magnitude) for `e < 0`, a left shift otherwise.
pub(super) fn scale(v: i32, exp: i32, shft: i32, m: u32) -> Real {
    let e = exp + shft;
    let mag = v.unsigned_abs();
    let out = if mag == 0 || e < -(m as i32) {
        0.0
    } else if e < 0 {
        Real::from(mag >> e.unsigned_abs())
    } else {
        Real::from(mag) * libm::exp2(Real::from(e))
    };
    if v < 0 && out != 0.0 {
        -out
    } else {
        out
    }
}

/// The int16 pair of a word: `(low, high)` halves of the little-endian word.
pub(super) fn int16_pair(h: u32) -> (i16, i16) {
    ((h & 0xffff) as u16 as i16, (h >> 16) as u16 as i16)
}
