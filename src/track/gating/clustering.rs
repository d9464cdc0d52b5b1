//! The skeleton both calibration clusterers share (spec §4, C7): the size caps of a link's
//! calibration, the estimates read and sorted by delay, split where consecutive delays differ by
//! more than the gap (and, for C7, each delay group again where consecutive amplitudes differ by
//! more than the amplitude gap), the clusters seen in fewer than `min_fraction` of the snapshots
//! dropped (a snapshot counts once), each kept one's delay mean and sample σ (floored) and, for
//! C7, amplitude mean and σ in dB; and the same per network, one list per link. The delay-only
//! clusterer (`calibration.rs`) reads delays, the delay-and-amplitude one
//! (`amplitude_clusters.rs`) reads [`DelayEstimate`](crate::channel::DelayEstimate)s.

use alloc::vec::Vec;
use core::cmp::Ordering;
use core::ops::Range;

use crate::error::{Error, Result};
use crate::math::{sqrt, Real};
use crate::track::gating::{
    Calibration, ClusterConfig, LinkCalibration, StaticCluster, MAX_CALIBRATION_DELAYS,
    MAX_CALIBRATION_SNAPSHOTS,
};

/// One calibration estimate of a link: its delay, its snapshot and (C7) its amplitude in dB.
#[derive(Debug, Clone, Copy)]
pub(super) struct Entry {
    pub(super) delay_s: Real,
    pub(super) snapshot: usize,
    pub(super) amplitude_db: Option<Real>,
}

impl Entry {
    /// By delay, then snapshot, then amplitude.
    fn by_delay(&self, b: &Entry) -> Ordering {
        self.delay_s
            .total_cmp(&b.delay_s)
            .then(self.snapshot.cmp(&b.snapshot))
            .then(self.amplitude().total_cmp(&b.amplitude()))
    }

    fn amplitude(&self) -> Real {
        self.amplitude_db.unwrap_or(0.0)
    }
}

/// The static clusters of one link from its calibration lists (`lists` = the link's list in
/// each snapshot; `cfg` checked by the caller). `read(k, i, item)` checks item `i` of snapshot
/// `k` (its error names it) and gives its entry, or `None` to skip it. With `amplitude_gap_db`
/// each delay group is split again by amplitude (every entry then has one) and the clusters
/// carry their amplitude statistics. Errors: no snapshots or too many, too many estimates
/// ([`Error::SizeLimit`]), and `read`'s.
pub(super) fn cluster_link<'s, T: 's>(
    lists: impl ExactSizeIterator<Item = &'s [T]> + Clone,
    cfg: &ClusterConfig,
    amplitude_gap_db: Option<Real>,
    read: impl Fn(usize, usize, &T) -> Result<Option<Entry>>,
) -> Result<LinkCalibration> {
    let count = lists.len();
    let total: usize = lists.clone().map(<[T]>::len).sum();
    check_sizes(count, total)?;
    let mut entries = Vec::with_capacity(total);
    for (k, list) in lists.enumerate() {
        for (i, item) in list.iter().enumerate() {
            if let Some(e) = read(k, i, item)? {
                entries.push(e);
            }
        }
    }
    entries.sort_by(Entry::by_delay);
    let needed = cfg.min_fraction * count as Real;
    let mut clusters = Vec::new();
    let mut seen = Vec::new();
    for group in gap_groups(&entries, |e| e.delay_s, cfg.gap_s) {
        let group = &mut entries[group];
        let subs = match amplitude_gap_db {
            Some(gap) => {
                group.sort_by(|a, b| a.amplitude().total_cmp(&b.amplitude()).then(a.by_delay(b)));
                gap_groups(group, Entry::amplitude, gap)
            }
            None => alloc::vec![0..group.len()],
        };
        for sub in subs {
            let members = &group[sub];
            let snapshots = distinct_snapshots(members.iter().map(|e| e.snapshot), &mut seen);
            if snapshots as Real >= needed {
                clusters.push(cluster_of(members, snapshots, cfg.sigma_floor_s));
            }
        }
    }
    clusters.sort_by(|a, b| a.mean_s.total_cmp(&b.mean_s));
    Ok(LinkCalibration { clusters })
}

/// The calibration of a network of `links` links, `link(p)` clustering link `p`. Errors: a
/// snapshot without one list per link ([`Error::LengthMismatch`]), and `link`'s.
pub(super) fn cluster_network<L>(
    snapshots: &[Vec<L>],
    links: usize,
    link: impl Fn(usize) -> Result<LinkCalibration>,
) -> Result<Calibration> {
    if let Some(s) = snapshots.iter().find(|s| s.len() != links) {
        return Err(Error::LengthMismatch {
            field: "calibration snapshot",
            expected: links,
            found: s.len(),
        });
    }
    let links = (0..links).map(link).collect::<Result<Vec<_>>>()?;
    Ok(Calibration { links })
}

/// The snapshot-count and total-size caps of one link's calibration: `1 ≤ count ≤`
/// [`MAX_CALIBRATION_SNAPSHOTS`] snapshots, at most [`MAX_CALIBRATION_DELAYS`] delays.
fn check_sizes(count: usize, total: usize) -> Result<()> {
    if count == 0 || count > MAX_CALIBRATION_SNAPSHOTS {
        return Err(Error::SizeLimit {
            field: "calibration snapshots per link",
            value: count,
            min: 1,
            max: MAX_CALIBRATION_SNAPSHOTS,
        });
    }
    if total > MAX_CALIBRATION_DELAYS {
        return Err(Error::SizeLimit {
            field: "calibration delays per link",
            value: total,
            min: 0,
            max: MAX_CALIBRATION_DELAYS,
        });
    }
    Ok(())
}

/// The index ranges of `sorted` (ascending in `key`) split where consecutive keys differ by
/// more than `gap`.
fn gap_groups<T>(sorted: &[T], key: impl Fn(&T) -> Real, gap: Real) -> Vec<Range<usize>> {
    let mut groups = Vec::new();
    let mut start = 0;
    for end in 1..=sorted.len() {
        if end == sorted.len() || key(&sorted[end]) - key(&sorted[end - 1]) > gap {
            groups.push(start..end);
            start = end;
        }
    }
    groups
}

/// Number of distinct snapshot indices in `ids` (`scratch` is reused storage).
fn distinct_snapshots(ids: impl Iterator<Item = usize>, scratch: &mut Vec<usize>) -> usize {
    scratch.clear();
    scratch.extend(ids);
    scratch.sort_unstable();
    scratch.dedup();
    scratch.len()
}

/// Mean and sample standard deviation (`n − 1`; 0 for one value) of `values` (non-empty).
fn mean_sigma(values: impl Iterator<Item = Real> + Clone) -> (Real, Real) {
    let n = values.clone().count() as Real;
    let mean = values.clone().sum::<Real>() / n;
    let ss: Real = values.map(|v| (v - mean) * (v - mean)).sum();
    let sigma = if n > 1.0 { sqrt(ss / (n - 1.0)) } else { 0.0 };
    (mean, sigma)
}

/// The cluster of `members` seen in `snapshots` distinct snapshots: the delay's mean and sample
/// standard deviation (`n − 1`; 0 for one member) floored at `floor`, and the amplitude's mean
/// and sample σ in dB when the members have amplitudes.
fn cluster_of(members: &[Entry], snapshots: usize, floor: Real) -> StaticCluster {
    let (mean, sigma) = mean_sigma(members.iter().map(|m| m.delay_s));
    let amplitude = members
        .iter()
        .all(|m| m.amplitude_db.is_some())
        .then(|| mean_sigma(members.iter().map(Entry::amplitude)));
    StaticCluster {
        mean_s: mean,
        sigma_s: sigma.max(floor),
        count: members.len(),
        snapshots,
        amplitude_db_mean: amplitude.map(|a| a.0),
        amplitude_db_sigma: amplitude.map(|a| a.1),
    }
}
