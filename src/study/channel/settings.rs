//! The settings of a [`ChannelRequest`] that a front end shows, as data (issue 39):
//! [`channel_settings`] lists each one's JSON key, kind, default and range, taken from the
//! request's own default, the filters' defaults and the very limits [`ChannelRequest::check`]
//! applies, so the page reads them from the core instead of repeating them (a unit test walks the
//! table against `check`). A new setting of the channel view is added here once.

use alloc::format;
use alloc::string::String;
use alloc::vec::Vec;

use serde::Serialize;
use serde_json::Value;

use super::request::{ChannelRequest, DelayReference, StaticMode, DEFAULT_SEED};
use crate::error::limits::{self, OpenRange, Range};
use crate::measure::MAX_CPI_SNAPSHOTS;
use crate::track::{FilterKind, PfConfig, UkfParams, MAX_PARTICLES};

/// One setting of a [`ChannelRequest`] (JSON: `{key, kind, …the kind's fields, default,
/// filter?}`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ChannelSetting {
    /// The request's JSON key (its serde name).
    pub key: &'static str,
    /// What it takes: `number`, `integer` (each with its [`Bounds`]) or `choice` (its values).
    #[serde(flatten)]
    pub kind: SettingKind,
    /// The value taken when the setting is not given (`null`: none; `delay_reference`'s is the
    /// recording's own `synchronized` flag).
    pub default: Value,
    /// The one filter the setting belongs to (`pf` for `particles` and `seed`: given with any
    /// other filter, [`ChannelRequest::check`] refuses it), else absent.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub filter: Option<&'static str>,
}

/// The kind of a [`ChannelSetting`] (JSON: the `kind` tag beside the kind's fields).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum SettingKind {
    /// A real number within its bounds.
    Number(Bounds),
    /// A whole number within its bounds.
    Integer(Bounds),
    /// One of these names.
    Choice {
        /// The allowed names.
        values: Vec<&'static str>,
    },
}

/// The range of a number setting, as [`ChannelRequest::check`] applies it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Bounds {
    /// The lower end.
    pub min: f64,
    /// The upper end.
    pub max: f64,
    /// Whether `min` and `max` themselves are refused. An open end at 0 of a
    /// [`limits::Range`] whose `min` is `f64::MIN_POSITIVE` (the core's "> 0") also refuses the
    /// subnormal numbers below that.
    pub open: [bool; 2],
    /// The range in the words of the core's error.
    pub allowed: String,
    /// The unit (`""`: none).
    pub unit: &'static str,
    /// The quantity's symbol (spec), for a range with an open end (`0 < q ≤ 1e6`).
    pub symbol: &'static str,
}

impl Bounds {
    /// The bounds of a closed [`Range`]; a `min` of `f64::MIN_POSITIVE` is "> 0".
    fn closed(r: Range, unit: &'static str, symbol: &'static str) -> Bounds {
        let positive = r.min == f64::MIN_POSITIVE;
        Bounds {
            min: if positive { 0.0 } else { r.min },
            max: r.max,
            open: [positive, false],
            allowed: r.allowed.into(),
            unit,
            symbol,
        }
    }

    /// The bounds of an [`OpenRange`].
    fn open(r: OpenRange, symbol: &'static str) -> Bounds {
        Bounds {
            min: r.min,
            max: r.max,
            open: [true, true],
            allowed: r.allowed.into(),
            unit: "",
            symbol,
        }
    }

    /// The bounds of a count `min..=max` (the words of [`crate::Error::SizeLimit`]).
    fn count(min: u64, max: u64, symbol: &'static str) -> Bounds {
        Bounds {
            min: min as f64,
            max: max as f64,
            open: [false, false],
            allowed: format!("{min}..={max}"),
            unit: "",
            symbol,
        }
    }
}

/// The settings of a [`ChannelRequest`] the page's channel view shows, in its panel's order:
/// `filter`, `particles`, `seed`, `process_noise`, `pfa`, `max_paths`, `extent_sigma_m`,
/// `statics`, `delay_reference`, `background_time_s`, `cpi_snapshots`, `range_rate_floor_mps`
/// (the request's other fields — the UKF's
/// parameters, roughening, bootstrap, association, sigma — are the CLI's and Python's only).
pub fn channel_settings() -> Vec<ChannelSetting> {
    let d = ChannelRequest::default();
    let filters = [
        FilterKind::Ekf,
        FilterKind::Ukf(UkfParams::default()),
        FilterKind::Pf(PfConfig::default()),
    ];
    let setting = |key, kind, default, filter| ChannelSetting {
        key,
        kind,
        default,
        filter,
    };
    let choice = |values: &[&'static str]| SettingKind::Choice {
        values: values.to_vec(),
    };
    Vec::from([
        setting(
            "filter",
            choice(&filters.map(|k| k.name())),
            Value::from(d.filter.as_str()),
            None,
        ),
        setting(
            "particles",
            SettingKind::Integer(Bounds::count(1, MAX_PARTICLES as u64, "N")),
            Value::from(PfConfig::default().particles),
            Some("pf"),
        ),
        setting(
            "seed",
            SettingKind::Integer(Bounds::count(0, u64::MAX, "seed")),
            Value::from(DEFAULT_SEED),
            Some("pf"),
        ),
        setting(
            "process_noise",
            SettingKind::Number(Bounds::closed(limits::PROCESS_NOISE, "m²/s³", "q")),
            Value::from(d.process_noise),
            None,
        ),
        setting(
            "pfa",
            SettingKind::Number(Bounds::open(limits::FALSE_ALARM_PROBABILITY, "P_fa")),
            Value::from(d.pfa),
            None,
        ),
        setting(
            "max_paths",
            SettingKind::Integer(Bounds::count(1, limits::MAX_PATHS as u64, "M_max")),
            Value::from(d.max_paths),
            None,
        ),
        setting(
            "extent_sigma_m",
            SettingKind::Number(Bounds::closed(limits::PERSON_EXTENT_M, "m", "σ_e")),
            Value::from(d.extent_sigma_m),
            None,
        ),
        setting(
            "statics",
            choice(&[StaticMode::Background, StaticMode::Clusters].map(StaticMode::name)),
            Value::from(d.statics.name()),
            None,
        ),
        setting(
            "delay_reference",
            choice(&[DelayReference::Absolute, DelayReference::Los].map(DelayReference::name)),
            d.delay_reference
                .map_or(Value::Null, |r| Value::from(r.name())),
            None,
        ),
        setting(
            "background_time_s",
            SettingKind::Number(Bounds::closed(limits::BACKGROUND_TIME_S, "s", "τ_bg")),
            Value::from(d.background_time_s),
            None,
        ),
        // 1 (or none) is no CPI; 2 … MAX_CPI_SNAPSHOTS are checked by `FrontEndCpi::validate`
        // (whose error names the range 2 …, the off value 1 aside).
        setting(
            "cpi_snapshots",
            SettingKind::Integer(Bounds::count(1, MAX_CPI_SNAPSHOTS as u64, "N")),
            d.cpi_snapshots.map_or(Value::Null, Value::from),
            None,
        ),
        // Checked with a CPI on (`FrontEndCpi::validate`): finite and ≥ 0, no upper end.
        setting(
            "range_rate_floor_mps",
            SettingKind::Number(Bounds {
                min: 0.0,
                max: f64::MAX,
                open: [false, false],
                allowed: "a finite floor ≥ 0 m/s".into(),
                unit: "m/s",
                symbol: "σ_floor",
            }),
            Value::from(d.range_rate_floor_mps),
            None,
        ),
    ])
}

/// [`channel_settings`] as JSON text (an array of [`ChannelSetting`]).
pub fn channel_settings_json() -> String {
    serde_json::to_string(&channel_settings()).expect("the settings table serialises")
}
