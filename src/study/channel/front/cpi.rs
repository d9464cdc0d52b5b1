//! A scan's coherent processing interval (issue 42 §2, D9; [`FrontEndCpi`]): each path of the
//! scan's estimate gets its range rate from its amplitudes fitted at its delay in every snapshot
//! of the CPI.

use alloc::vec;
use alloc::vec::Vec;

use super::los_of;
use crate::channel::{path_rate, Estimator, Recording, ResponseMap, SnapshotEstimate};
use crate::error::Result;
use crate::math::{sqrt, Complex, Real};
use crate::study::channel::FrontEndCpi;

/// A scan's CPI: the recording, its map and the scan's first snapshot.
pub(super) struct Burst<'a> {
    pub(super) rec: &'a Recording,
    pub(super) map: &'a ResponseMap,
    pub(super) first: usize,
}

/// Each path of the scan's estimate `e` (delays in the estimator's time base) gets its range
/// rate over the CPI `burst` (issue 42 §2, [`FrontEndCpi`]): per snapshot of the burst its
/// response through `residual` (the background's residual, or the response itself), the paths'
/// amplitudes at their delays ([`Estimator::amplitudes_at`]) — with `per_snapshot` each
/// referred to the direct path's phase (a receiver without the transmitter's clock turns every
/// snapshot's carrier phase; the direct path does not move) — and [`path_rate`] at the path's
/// SNR.
#[allow(clippy::too_many_arguments)]
pub(super) fn rates(
    e: &mut SnapshotEstimate,
    burst: &Burst,
    cpi: FrontEndCpi,
    wavelength_m: Real,
    link: usize,
    mut residual: impl FnMut(&mut Vec<Complex>, &mut Vec<Complex>) -> Result<()>,
    estimator: &mut Estimator,
    per_snapshot: bool,
    span: Real,
) -> Result<()> {
    if e.paths.is_empty() {
        return Ok(());
    }
    let delays: Vec<Real> = e.paths.iter().map(|p| p.delay_s).collect();
    let los = if per_snapshot {
        los_of(&e.paths, span).and_then(|l| delays.iter().position(|d| *d == l.delay_s))
    } else {
        None
    };
    let n = cpi.snapshots;
    let mut alpha = vec![Vec::with_capacity(n); delays.len()];
    let mut t = Vec::with_capacity(n);
    let (mut h, mut r) = (Vec::new(), Vec::new());
    for s in burst.first..burst.first + n {
        burst.map.fill(burst.rec, s, link, &mut h)?;
        residual(&mut h, &mut r)?;
        let mut a = estimator.amplitudes_at(&r, &delays)?;
        if let Some(l) = los {
            let ref_phase = a[l];
            let m = sqrt(ref_phase.norm_sqr());
            if m > 0.0 {
                let rot = ref_phase.conj() / m;
                for v in a.iter_mut() {
                    *v *= rot;
                }
            }
        }
        for (list, v) in alpha.iter_mut().zip(a) {
            list.push(v);
        }
        t.push(burst.rec.t_s[s]);
    }
    for (p, a) in e.paths.iter_mut().zip(&alpha) {
        p.range_rate = path_rate(&t, a, p.snr, wavelength_m, cpi.floor_mps)?;
    }
    Ok(())
}
