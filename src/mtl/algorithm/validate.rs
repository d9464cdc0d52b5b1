//! Input validation of Algorithm 1: every bad input is a named [`Error`].

use alloc::vec::Vec;

use crate::error::{check_finite, check_len, check_non_negative, limits, Error, Result};
use crate::math::Real;
use crate::mtl::algorithm::{Measurements, MtlConfig, MAX_CANDIDATES};
use crate::mtl::blocking::BlockingModel;

/// Check `input`, `model` and `cfg`; returns the TRP order `π`.
///
/// Errors: [`Error::EmptyNodeList`] (`transmitters` / `receivers`); [`Error::LengthMismatch`]
/// (`transmitters`, `receivers`, `ranges`, `order`) against the model's TRP map;
/// [`Error::NonFinite`] (`transmitters[j]`, `receivers[j]`, `ranges[m][i]`, `t_e`, `t_b`,
/// `c_sigma_m`); [`Error::OutOfRange`] (`c_sigma_m` outside [`limits::C_SIGMA_M`]); [`Error::OutOfRange`] (`t_e`, `t_b` when
/// negative; `order` when not a permutation); [`Error::SizeLimit`] (`max_candidates` outside
/// 1..=[`MAX_CANDIDATES`]; `b_max`, `merge_shared_pairs`
/// when 0).
pub fn validate<B: BlockingModel + ?Sized>(
    input: &Measurements,
    model: &B,
    cfg: &MtlConfig,
) -> Result<Vec<usize>> {
    use alloc::format;
    let map = model.trp_map();
    if input.tx.is_empty() {
        return Err(Error::EmptyNodeList {
            field: "transmitters",
        });
    }
    if input.rx.is_empty() {
        return Err(Error::EmptyNodeList { field: "receivers" });
    }
    for (field, len, want) in [
        ("transmitters", input.tx.len(), map.n_tx()),
        ("receivers", input.rx.len(), map.n_rx()),
        ("ranges", input.ranges.len(), map.n_trps()),
    ] {
        if len != want {
            return Err(Error::LengthMismatch {
                field,
                expected: want,
                found: len,
            });
        }
    }
    let nodes = input.tx.iter().map(|p| ("transmitters", p));
    let nodes = nodes.chain(input.rx.iter().map(|p| ("receivers", p)));
    for (k, (field, p)) in nodes.enumerate() {
        if !(p.x.is_finite() && p.y.is_finite()) {
            let j = if field == "transmitters" {
                k
            } else {
                k - input.tx.len()
            };
            return Err(Error::NonFinite {
                field: format!("{field}[{j}]"),
            });
        }
    }
    for (m, rs) in input.ranges.iter().enumerate() {
        // Measured ranges with noise may dip below 0 (cσ up to 1 km); only their size is bounded.
        for (i, &r) in rs.iter().enumerate() {
            check_finite(&format!("ranges[{m}][{i}]"), r)?;
            if r.abs() > limits::RANGE_M.max {
                return Err(Error::OutOfRange {
                    field: format!("ranges[{m}][{i}]"),
                    value: r,
                    allowed: "|range| <= 1e8 m",
                });
            }
        }
    }
    check_non_negative("t_e", cfg.t_e, false, "a threshold ≥ 0")?;
    check_non_negative("t_b", cfg.t_b, true, "a threshold ≥ 0")?;
    check_non_negative(
        "merge_radius_m",
        cfg.merge_radius_m,
        true,
        "a threshold ≥ 0",
    )?;
    limits::C_SIGMA_M.check("c_sigma_m", input.c_sigma_m)?;
    for (field, v) in [
        ("b_max", cfg.b_max),
        ("merge_shared_pairs", cfg.merge_shared_pairs),
    ] {
        if v == 0 {
            return Err(Error::SizeLimit {
                field,
                value: 0,
                min: 1,
                max: usize::MAX,
            });
        }
    }
    if !(1..=MAX_CANDIDATES).contains(&cfg.max_candidates) {
        return Err(Error::SizeLimit {
            field: "max_candidates",
            value: cfg.max_candidates,
            min: 1,
            max: MAX_CANDIDATES,
        });
    }
    let m = map.n_trps();
    let order: Vec<usize> = cfg.order.clone().unwrap_or_else(|| (0..m).collect());
    check_len("order", m, order.len())?;
    let mut seen = 0u64;
    for &t in &order {
        if t >= m || seen >> t & 1 == 1 {
            return Err(Error::OutOfRange {
                field: "order".into(),
                value: t as Real,
                allowed: "a permutation of the TRPs 0..M",
            });
        }
        seen |= 1 << t;
    }
    Ok(order)
}
