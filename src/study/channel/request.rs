//! What a channel run is asked to do: [`ChannelRequest`], the one home of every setting of the
//! chain from a recording to a track and of its default. The CLI's flags, the page's settings
//! object (this type's JSON, field for field) and the Python keywords all fill it; its
//! [`ChannelRequest::check`] names the field at fault. The settings the page shows, with their
//! defaults and `check`'s ranges, are listed as data by `settings.rs`
//! ([`super::channel_settings`]).

use alloc::borrow::Cow;
use alloc::string::{String, ToString};

use serde::{Deserialize, Serialize};

use crate::channel::{
    AlignMode, EstimatorConfig, PathTrackerConfig, Recording, DEFAULT_BACKGROUND_TIME_S,
};
use crate::error::{limits, Error, Result};
use crate::math::Real;
use crate::track::gating::{AssociationRule, SegmentConfig};
use crate::track::{ConstantVelocity, FilterKind, FilterSettings};

/// Default process-noise intensity `q̃` of a recording's track, m²/s³: a person at 1–2 m/s
/// turning on 2–3 m radii accelerates by up to v²/r ≈ 1–2 m/s².
pub const DEFAULT_PROCESS_NOISE: Real = 1.0;

/// Default spread of the scatterer's own extent, as path length (m): a person's body radius is
/// about 0.2 m ([`ChannelRequest::extent_sigma_m`]).
pub const EXTENT_SIGMA_M: Real = 0.2;

/// Default seed of the particle filter of a channel run ([`ChannelRequest::seed`]).
pub const DEFAULT_SEED: u64 = 1;

/// How static paths are kept from the tracker (spec C9, C7).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StaticMode {
    /// C9: the background (the empty area's coherent mean, or a recursive mean of the walk) is
    /// subtracted at the signal level and the estimator runs on the residual; static clusters
    /// from the background's own paths gate what is left of them (shadowing). The default: it
    /// wins on every recording of the ray-traced corpus (docs/reproduction.md).
    #[default]
    Background,
    /// C7 alone: every snapshot's full response is estimated and its static paths gated by
    /// the clusters of the empty area's estimates ([S]'s way; the path budget goes to static
    /// multipath on dense recordings).
    Clusters,
}

impl StaticMode {
    /// `background` or `clusters`.
    pub fn name(self) -> &'static str {
        match self {
            StaticMode::Background => "background",
            StaticMode::Clusters => "clusters",
        }
    }

    /// The mode named `name`, else [`Error::InvalidFile`] of `field`.
    pub fn named(field: &str, name: &str) -> Result<StaticMode> {
        match name {
            "background" => Ok(StaticMode::Background),
            "clusters" => Ok(StaticMode::Clusters),
            _ => Err(not_one_of(field, name, "background, clusters")),
        }
    }
}

/// Which delays the tracker reads (spec C10).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DelayReference {
    /// Absolute propagation delays: a sounder with a common clock.
    #[default]
    Absolute,
    /// Delays relative to each link's direct path, plus the baseline `‖t − r‖/c` (C10): Wi-Fi
    /// CSI and free-running UWB anchors. Each snapshot is aligned to the background over the
    /// whole unambiguous span, so timing offsets and carrier phases of any size drop out.
    Los,
}

impl DelayReference {
    /// `absolute` or `los`.
    pub fn name(self) -> &'static str {
        match self {
            DelayReference::Absolute => "absolute",
            DelayReference::Los => "los",
        }
    }

    /// The reference named `name`, else [`Error::InvalidFile`] of `field`.
    pub fn named(field: &str, name: &str) -> Result<DelayReference> {
        match name {
            "absolute" => Ok(DelayReference::Absolute),
            "los" => Ok(DelayReference::Los),
            _ => Err(not_one_of(field, name, "absolute, los")),
        }
    }
}

/// How a recording's track weights each delay.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum DelaySigma {
    /// The estimator's own σ̂_τ (C4 at the fitted SNR): the default for recordings.
    #[default]
    #[serde(rename = "estimator")]
    Estimator,
    /// The link budget's σ at the prediction (E8: needs the scenario's RCS and radio).
    #[serde(rename = "budget")]
    LinkBudget,
}

impl DelaySigma {
    /// The name in `TRACK.json` and on the CLI: `estimator`, `budget`.
    pub fn name(self) -> &'static str {
        match self {
            DelaySigma::Estimator => "estimator",
            DelaySigma::LinkBudget => "budget",
        }
    }

    /// The source named `name`, else [`Error::InvalidFile`] of `field`.
    pub fn named(field: &str, name: &str) -> Result<DelaySigma> {
        match name {
            "estimator" => Ok(DelaySigma::Estimator),
            "budget" => Ok(DelaySigma::LinkBudget),
            _ => Err(not_one_of(field, name, "estimator, budget")),
        }
    }
}

fn not_one_of(field: &str, name: &str, allowed: &str) -> Error {
    Error::InvalidFile {
        field: field.into(),
        reason: alloc::format!("\"{}\" is not one of {allowed}", crate::error::Clip(name)),
    }
}

/// The front end's settings (derived from a [`ChannelRequest`]): the snapshot estimator (C5),
/// the per-link path tracker (C6), the static channel (C9/C7) and the delay reference (C10).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrontEndConfig {
    /// The snapshot estimator.
    pub estimator: EstimatorConfig,
    /// The per-link path tracker.
    pub paths: PathTrackerConfig,
    /// How static paths are removed.
    pub statics: StaticMode,
    /// The recursive background's time constant `τ_bg`, s (without an empty-area recording).
    pub background_time_s: Real,
    /// Which delays come out.
    pub delay_reference: DelayReference,
    /// Each scan a CPI of consecutive snapshots whose paths' range rates are read (issue 42
    /// §2; `None`: every snapshot a scan, no Doppler).
    pub cpi: Option<FrontEndCpi>,
}

/// The front end's coherent processing interval (issue 42 §2): every `snapshots` consecutive
/// snapshots of a recording are one scan; the paths are estimated in its middle snapshot
/// (index `snapshots / 2`, whose time is the scan's), their amplitudes fitted at those delays
/// in every snapshot of it, and each path's range rate read from their phase progression
/// (`channel::path_rate`, D9), its σ with the floor `floor_mps` (D5).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrontEndCpi {
    /// Snapshots per scan, `N` (2 … [`measure::MAX_CPI_SNAPSHOTS`](crate::measure::MAX_CPI_SNAPSHOTS)).
    pub snapshots: usize,
    /// The floor on each range rate's σ, m/s.
    pub floor_mps: Real,
}

impl FrontEndCpi {
    /// Checks the fields (`cpi_snapshots` in 2 … `MAX_CPI_SNAPSHOTS`, `range_rate_floor_mps`
    /// finite and ≥ 0).
    pub fn validate(&self) -> Result<()> {
        if !(2..=crate::measure::MAX_CPI_SNAPSHOTS).contains(&self.snapshots) {
            return Err(Error::SizeLimit {
                field: "cpi_snapshots",
                value: self.snapshots,
                min: 2,
                max: crate::measure::MAX_CPI_SNAPSHOTS,
            });
        }
        if !(self.floor_mps.is_finite() && self.floor_mps >= 0.0) {
            return Err(Error::OutOfRange {
                field: "range_rate_floor_mps".into(),
                value: self.floor_mps,
                allowed: "a finite floor ≥ 0 m/s",
            });
        }
        Ok(())
    }

    /// Snapshots per scan of an optional CPI (1 without one).
    pub fn per_scan(cpi: Option<FrontEndCpi>) -> usize {
        cpi.map_or(1, |c| c.snapshots)
    }
}

impl Default for FrontEndConfig {
    fn default() -> Self {
        FrontEndConfig {
            estimator: EstimatorConfig::default(),
            paths: PathTrackerConfig::default(),
            statics: StaticMode::default(),
            background_time_s: DEFAULT_BACKGROUND_TIME_S,
            delay_reference: DelayReference::default(),
            cpi: None,
        }
    }
}

impl FrontEndConfig {
    /// The alignment to the background its delay reference needs: none for absolute delays
    /// (a synchronised sounder; an alignment estimated with the walker present is biased), a
    /// search over the whole span for delays relative to the direct path.
    pub fn align(&self) -> AlignMode {
        match self.delay_reference {
            DelayReference::Absolute => AlignMode::Off,
            DelayReference::Los => AlignMode::Coarse,
        }
    }

    /// Checks every part (the estimator's and path tracker's named errors;
    /// `background_time_s` in [`limits::BACKGROUND_TIME_S`]).
    pub fn validate(&self) -> Result<()> {
        self.estimator.validate()?;
        self.paths.validate()?;
        if let Some(c) = &self.cpi {
            c.validate()?;
        }
        limits::BACKGROUND_TIME_S.check("background_time_s", self.background_time_s)
    }
}

/// Every setting of a channel run, with its default (`ChannelRequest::default()`; JSON: this
/// object with any subset of its fields, unknown fields refused). The recording, the empty
/// area's recording and the truth are the run's inputs, not settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ChannelRequest {
    /// Most paths per snapshot `M_max` of the estimator (C5; default 12).
    pub max_paths: usize,
    /// The estimator's false-alarm probability per snapshot (C5; default 10⁻³).
    pub pfa: Real,
    /// How static paths are removed (default `background`).
    pub statics: StaticMode,
    /// Which delays the tracker reads (`None`: the recording's own `synchronized` flag, absolute
    /// when it has none).
    pub delay_reference: Option<DelayReference>,
    /// The recursive background's time constant, s, used without an empty-area recording
    /// (default 10).
    pub background_time_s: Real,
    /// Without a recording of the empty area: the snapshots of the recording with
    /// `t0 ≤ t ≤ t1` are the empty area.
    pub calibration_range_s: Option<[Real; 2]>,
    /// The segment filter: `ekf` (default), `ukf` or `pf`.
    pub filter: String,
    /// UKF α (`ukf` only).
    pub ukf_alpha: Option<Real>,
    /// UKF β (`ukf` only).
    pub ukf_beta: Option<Real>,
    /// UKF κ (`ukf` only).
    pub ukf_kappa: Option<Real>,
    /// Particles (`pf` only; default 1000).
    pub particles: Option<usize>,
    /// Roughening constant (`pf` only).
    pub roughening: Option<Real>,
    /// The plain bootstrap particle filter (`pf` only).
    pub bootstrap: bool,
    /// The particle filter's seed (`pf` only; default 1).
    pub seed: Option<u64>,
    /// Process-noise intensity `q̃` of the CV model (E7), m²/s³ (default 1).
    pub process_noise: Real,
    /// How a link's candidates are associated: `gated` (default) or `spec`.
    pub association: AssociationRule,
    /// How each delay is weighted: `estimator` (default) or `budget`.
    pub sigma: DelaySigma,
    /// With `sigma = estimator`: the scatterer's extent as path length (m), added in
    /// quadrature to each estimate's σ̂ (default 0.2).
    pub extent_sigma_m: Real,
    /// Snapshots per scan: each scan a coherent processing interval whose paths' range rates
    /// the front end reads (issue 42 §2; `None` or 1: no Doppler).
    pub cpi_snapshots: Option<usize>,
    /// The floor on each range rate's σ, m/s (default 0.1, D5).
    pub range_rate_floor_mps: Real,
    /// Start, loss and restart (C11; not settable from the page or the CLI yet).
    #[serde(skip)]
    pub segments: SegmentConfig,
}

impl Default for ChannelRequest {
    fn default() -> Self {
        ChannelRequest {
            max_paths: EstimatorConfig::default().max_paths,
            pfa: EstimatorConfig::default().p_fa,
            statics: StaticMode::default(),
            delay_reference: None,
            background_time_s: DEFAULT_BACKGROUND_TIME_S,
            calibration_range_s: None,
            filter: "ekf".to_string(),
            ukf_alpha: None,
            ukf_beta: None,
            ukf_kappa: None,
            particles: None,
            roughening: None,
            bootstrap: false,
            seed: None,
            process_noise: DEFAULT_PROCESS_NOISE,
            association: AssociationRule::Gated,
            sigma: DelaySigma::Estimator,
            extent_sigma_m: EXTENT_SIGMA_M,
            cpi_snapshots: None,
            range_rate_floor_mps: crate::measure::DEFAULT_RANGE_RATE_FLOOR_MPS,
            segments: SegmentConfig::default(),
        }
    }
}

impl ChannelRequest {
    /// The request of a JSON object (the page's settings; `""` = every default). Errors:
    /// [`Error::Parse`] (an unknown field, a wrong type), then [`ChannelRequest::check`]'s.
    pub fn from_json(text: &str) -> Result<ChannelRequest> {
        let req: ChannelRequest = if text.trim().is_empty() {
            ChannelRequest::default()
        } else {
            crate::scenario::parse_json(text)?
        };
        req.check()?;
        Ok(req)
    }

    /// The front end's settings with the delay reference resolved against the recording's
    /// `synchronized` flag (`None`: unknown).
    pub fn front_end(&self, synchronized: Option<bool>) -> FrontEndConfig {
        let reference = self.delay_reference.unwrap_or(match synchronized {
            Some(false) => DelayReference::Los,
            _ => DelayReference::Absolute,
        });
        FrontEndConfig {
            estimator: EstimatorConfig {
                max_paths: self.max_paths,
                p_fa: self.pfa,
                ..EstimatorConfig::default()
            },
            paths: PathTrackerConfig::default(),
            statics: self.statics,
            background_time_s: self.background_time_s,
            delay_reference: reference,
            cpi: match self.cpi_snapshots {
                None | Some(1) => None,
                Some(snapshots) => Some(FrontEndCpi {
                    snapshots,
                    floor_mps: self.range_rate_floor_mps,
                }),
            },
        }
    }

    /// The segment filter with its settings ([`FilterSettings::kinds`]: a setting of another
    /// filter is [`Error::UnusedSetting`]; an unknown name [`Error::UnknownFilter`] of
    /// `filter`). `seed` is refused unless the filter is `pf`.
    pub fn filter_kind(&self) -> Result<FilterKind> {
        let settings = FilterSettings {
            ukf_alpha: self.ukf_alpha,
            ukf_beta: self.ukf_beta,
            ukf_kappa: self.ukf_kappa,
            particles: self.particles,
            roughening: self.roughening,
            bootstrap: self.bootstrap,
        };
        let kinds = settings.kinds(&[self.filter.as_str()], "filter", |_| "filter".into())?;
        if self.seed.is_some() && self.filter != "pf" {
            return Err(Error::UnusedSetting {
                field: "seed".into(),
                filter: "pf",
                list: "filter".into(),
            });
        }
        Ok(kinds[0])
    }

    /// The recording of the empty area: `file` (a calibration recording), or the snapshots of
    /// `rec` in [`ChannelRequest::calibration_range_s`], or neither (`None`: a recursive
    /// background). Errors: both given ([`Error::InvalidFile`] of `calibration_range_s`), a
    /// range with no snapshot in it.
    pub fn empty_area<'a>(
        &self,
        file: Option<&'a Recording>,
        rec: &Recording,
    ) -> Result<Option<Cow<'a, Recording>>> {
        match (file, self.calibration_range_s) {
            (Some(_), Some(_)) => Err(Error::InvalidFile {
                field: "calibration_range_s".into(),
                reason: "give a calibration recording or a time range of the recording, not both"
                    .into(),
            }),
            (Some(f), None) => Ok(Some(Cow::Borrowed(f))),
            (None, Some([a, b])) => rec
                .between("calibration_range_s", a, b)
                .map(|r| Some(Cow::Owned(r))),
            (None, None) => Ok(None),
        }
    }

    /// The particle filter's seed (default [`DEFAULT_SEED`]).
    pub fn seed(&self) -> u64 {
        self.seed.unwrap_or(DEFAULT_SEED)
    }

    /// Checks every setting, naming the field at fault: `pfa`
    /// ([`limits::FALSE_ALARM_PROBABILITY`]), the front end's ([`FrontEndConfig::validate`]:
    /// `max_paths`, `background_time_s`), the filter's ([`ChannelRequest::filter_kind`]),
    /// `process_noise` (E7's range), `extent_sigma_m` ([`limits::PERSON_EXTENT_M`]),
    /// `calibration_range_s` (finite, `t0 ≤ t1`), the segments'. The ranges are the ones
    /// [`super::channel_settings`] lists for the page.
    pub fn check(&self) -> Result<()> {
        limits::FALSE_ALARM_PROBABILITY.check("pfa", self.pfa)?;
        // The floor is checked with or without a CPI (as the CLI's flag is).
        FrontEndCpi {
            snapshots: 2,
            floor_mps: self.range_rate_floor_mps,
        }
        .validate()?;
        self.front_end(None).validate()?;
        self.filter_kind()?;
        ConstantVelocity::validated(1.0, self.process_noise)?;
        if !limits::PERSON_EXTENT_M.contains(self.extent_sigma_m) {
            return Err(Error::OutOfRange {
                field: "extent_sigma_m".into(),
                value: self.extent_sigma_m,
                allowed: limits::PERSON_EXTENT_M.allowed,
            });
        }
        if let Some([a, b]) = self.calibration_range_s {
            for v in [a, b] {
                if !v.is_finite() {
                    return Err(Error::OutOfRange {
                        field: "calibration_range_s".into(),
                        value: v,
                        allowed: "finite times, s",
                    });
                }
            }
            if b < a {
                return Err(Error::OutOfRange {
                    field: "calibration_range_s".into(),
                    value: b,
                    allowed: "t1 >= t0",
                });
            }
        }
        self.segments.validate()
    }
}
