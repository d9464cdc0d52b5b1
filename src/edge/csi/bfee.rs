//! The Intel 5300's beamforming-feedback (bfee) CSI payload, shared by the Linux 802.11n CSI
//! Tool's `.dat` records (code `0xBB`) and PicoScenes' IWL5300 `CSI` segment, which carries the
//! same bytes (PicoScenes' `parseIWL5300CSIData`, csiread's `parseCSI5300`).
//!
//! The payload (Halperin et al., `read_bfee.c`) is a bit stream, 30 subcarriers one after the
//! other; each subcarrier starts with 3 bits of padding, then per receive chain `r` and per
//! space-time stream `t` (`t` fastest) the real and the imaginary part as two's-complement
//! 8-bit integers, unaligned (bit `index` of the stream is bit `index mod 8` of byte
//! `index / 8`): `30·(3 + 16·Nrx·Ntx)` bits, stored in `60·Nrx·Ntx + 12` bytes (the `len`
//! field, `calc_len = (30·(16·Nrx·Ntx + 3) + 7) / 8`).
//!
//! The 30 subcarriers are the 802.11n grouping `Ng = 2` at 20 MHz and `Ng = 4` at 40 MHz
//! (IEEE 802.11n-2016 table 9-54; Halperin's and csiread's `scidx`).

use alloc::vec;
use alloc::vec::Vec;

use crate::math::Complex;

/// Subcarriers per bfee matrix set.
pub(super) const TONES: usize = 30;

/// The payload length, bytes, for `n_rx·n_tx` matrices (`read_bfee.c`'s `calc_len`), or
/// `None` if it overflows.
pub(super) fn payload_len(n_rx: usize, n_tx: usize) -> Option<usize> {
    n_rx.checked_mul(n_tx)?.checked_mul(60)?.checked_add(12)
}

/// The subcarrier indices: 20 MHz `-28, -26, …, -2, -1, 1, 3, …, 27, 28`; 40 MHz
/// `-58, -54, …, -2, 2, 6, …, 58`.
pub(super) fn subcarriers(bw40: bool) -> Vec<i32> {
    let (a, b, step) = if bw40 { (58, 2, 4) } else { (28, 1, 2) };
    let mut k: Vec<i32> = (0..14).map(|i| -a + step * i).collect();
    k.push(-b);
    k.extend((0..14).map(|i| b + step * i));
    k.push(a);
    k
}

/// The HT pilots among [`subcarriers`]: `7, 21` at 20 MHz (±7, ±21 are the pilots; only the
/// positive ones fall on the odd indices of the grouping), none at 40 MHz (±11, ±25, ±53 are
/// odd; the grouping reports `≡ 2 mod 4`).
pub(super) fn pilots(bw40: bool) -> Vec<i32> {
    if bw40 {
        Vec::new()
    } else {
        vec![7, 21]
    }
}

/// Decodes the payload of `n_rx × n_tx` matrices into `30·n_rx·n_tx` values in the capture's
/// order `[(r·n_tx + t)·30 + k]`. `perm[r]`: the row receive chain `r` of the stream goes to
/// (the antenna permutation of `antenna_sel`; `None`: as stored). `None` if the payload is
/// shorter than [`payload_len`] or a `perm` entry is out of range.
pub(super) fn decode(
    payload: &[u8],
    n_rx: usize,
    n_tx: usize,
    perm: Option<&[usize]>,
) -> Option<Vec<Complex>> {
    if payload.len() < payload_len(n_rx, n_tx)? {
        return None;
    }
    let mut out = vec![Complex::new(0.0, 0.0); TONES * n_rx * n_tx];
    let byte = |i: usize| payload.get(i).copied().map(u16::from);
    // One signed 8-bit value from bit `bit` on.
    let value = |bit: usize| -> Option<f64> {
        let (i, shift) = (bit / 8, bit % 8);
        let v = (byte(i)? >> shift) | (byte(i + 1)? << (8 - shift));
        Some(f64::from(v as u8 as i8))
    };
    let mut bit = 0usize;
    for k in 0..TONES {
        bit += 3;
        for r in 0..n_rx {
            let row = match perm {
                Some(p) => *p.get(r)?,
                None => r,
            };
            if row >= n_rx {
                return None;
            }
            for t in 0..n_tx {
                let z = Complex::new(value(bit)?, value(bit + 8)?);
                *out.get_mut((row * n_tx + t) * TONES + k)? = z;
                bit += 16;
            }
        }
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn indices_are_the_grouping_of_halperin_and_csiread() {
        let k20 = subcarriers(false);
        assert_eq!(k20.len(), 30);
        assert_eq!(&k20[..3], &[-28, -26, -24]);
        assert_eq!(&k20[13..17], &[-2, -1, 1, 3]);
        assert_eq!(&k20[28..], &[27, 28]);
        let k40 = subcarriers(true);
        assert_eq!(k40.len(), 30);
        assert_eq!(&k40[..2], &[-58, -54]);
        assert_eq!(&k40[13..16], &[-6, -2, 2]);
        assert_eq!(&k40[28..], &[54, 58]);
        for p in pilots(false) {
            assert!(k20.contains(&p));
        }
    }

    #[test]
    fn payload_length_is_calc_len() {
        for n in 1..=9 {
            assert_eq!(payload_len(n, 1), Some((30 * (16 * n + 3)).div_ceil(8)));
        }
        assert_eq!(payload_len(usize::MAX, 2), None);
    }

    #[test]
    fn short_payload_or_bad_perm_is_none() {
        let p = vec![0u8; 72];
        assert!(decode(&p, 1, 1, None).is_some());
        assert!(decode(&p[..71], 1, 1, None).is_none());
        assert!(decode(&p, 1, 1, Some(&[1])).is_none());
        assert!(decode(&p, 1, 1, Some(&[])).is_none());
    }
}
