//! The Intel AX200/AX210 ("IWLMVM", `DeviceType` `0x2000`/`0x2100`) layout of a PicoScenes `CSI`
//! segment (PicoScenes' `rxs_parsing_core`, `CSI::fromIWLMVM` and `parseIWLMVMCSIDataCore`).
//!
//! The buffer is exactly `NumTx·NumRx·NumTones·4` bytes: per value an i16 real then an i16
//! imaginary part, little-endian; value `i` is element `i` of the column-major
//! `{NumTones, NumTx, NumRx}` matrix — tone fastest, then stream, then chain: tone `i mod K`,
//! stream `(i / K) mod NumTx`, chain `i / (K·NumTx)`, the order FeitCSI writes the same
//! firmware report in (rx, then tx, then subcarrier). `NumESS` is not part of the buffer.
//! The subcarrier indices are the firmware's table of the format and width
//! ([`super::super::tones`]), shifted by `SubcarrierOffset`; `NumTones` must be its count.
//! Every table holds its pilot tones, where the firmware writes 0 (FeitCSI's files, module doc
//! of `feitcsi`): they are left out, as the FeitCSI reader does (csiread 1.4.1 also drops
//! pilots, at positions shifted by one per pilot already removed, and orders chain before
//! stream; the tests keep to the tones and the 1-stream case where it agrees). HE-MU frames
//! (format 4) have no table (PicoScenes' parser leaves their indices empty).

use alloc::format;
use alloc::vec::Vec;

use super::super::tones::{map, Phy};
use super::cursor::Cursor;
use crate::error::limits::MAX_LINKS;
use crate::error::Result;
use crate::math::Complex;

/// The streams, the reported (non-pilot) subcarrier indices before `SubcarrierOffset`, and the
/// values `[(r·n_tx + t)·K + k]` of an MVM buffer of `num_tx` streams and `n_rx` chains.
pub(super) fn read(
    c: &Cursor<'_>,
    buf: &[u8],
    format: i8,
    cbw: u16,
    tones: usize,
    num_tx: usize,
    n_rx: usize,
) -> Result<(usize, Vec<i32>, Vec<Complex>)> {
    let phy = match format {
        0 => Phy::Legacy,
        1 => Phy::Ht,
        2 => Phy::Vht,
        3 => Phy::He,
        f => {
            return Err(c.bad(
                "PacketFormat",
                format!(
                    "{f}: no Intel MVM subcarrier table (0 non-HT, 1 HT, 2 VHT and 3 HE-SU have \
                     one; 4 HE-MU has none)"
                ),
            ))
        }
    };
    let Some(m) = map(phy, u32::from(cbw)) else {
        return Err(c.bad(
            "CBW",
            format!(
                "{cbw} MHz: no Intel MVM subcarrier table for {} (non-HT 20; HT 20/40; \
                 VHT 20/40/80/160; HE-SU 20/40/80/160 MHz)",
                phy.name()
            ),
        ));
    };
    let table = m.tones();
    if tones != table.len() {
        return Err(c.bad(
            "NumTones",
            format!(
                "{tones}: the Intel MVM table of {} {cbw} MHz has {}",
                phy.name(),
                table.len()
            ),
        ));
    }
    if num_tx == 0 || num_tx * n_rx > MAX_LINKS {
        return Err(c.bad("NumTx", format!("{num_tx}: impossible with NumRx = {n_rx}")));
    }
    let want = 4 * tones * num_tx * n_rx;
    if buf.len() != want {
        return Err(c.bad(
            "CSIBufferLength",
            format!(
                "{}: NumTx·NumRx·NumTones·4 = {num_tx}·{n_rx}·{tones}·4 = {want} expected",
                buf.len()
            ),
        ));
    }
    let kept: Vec<i32> = table.iter().copied().filter(|&k| !m.is_pilot(k)).collect();
    let mut values = Vec::with_capacity(kept.len() * num_tx * n_rx);
    for block in buf.chunks_exact(4 * tones) {
        for (&k, v) in table.iter().zip(block.chunks_exact(4)) {
            if !m.is_pilot(k) {
                let re = i16::from_le_bytes([v[0], v[1]]);
                let im = i16::from_le_bytes([v[2], v[3]]);
                values.push(Complex::new(re.into(), im.into()));
            }
        }
    }
    Ok((num_tx, kept, values))
}
