//! The crate's one error type. Every bad input has a named variant that says which field or link
//! is wrong; numerical trouble inside a solver is a reported termination, not an error.

use alloc::string::String;
use core::fmt;

mod cancel;
pub mod limits;
mod show;

pub use cancel::{check_every, Cancel, CHECK_NS};
pub use show::{Clip, Num};

/// A named error. `Display` gives one line that names the offending field.
#[derive(Debug, Clone, PartialEq)]
pub enum Error {
    /// The scenario JSON could not be parsed (syntax, a missing or unknown field, a wrong type).
    Parse {
        /// serde_json's message (it names the field and the line/column).
        message: String,
    },
    /// A file parsed but its content does not fit (a missing alternative, a count or a length
    /// per link that is wrong): see [`crate::formats`].
    InvalidFile {
        /// Path of the field, e.g. `steps[3]`.
        field: String,
        /// What is wrong, in words.
        reason: String,
    },
    /// A number that must be finite is NaN or infinite.
    NonFinite {
        /// Path of the field, e.g. `receivers[2].position_m`.
        field: String,
    },
    /// A quantity that must be strictly positive is not (bandwidth, carrier, RCS, beamwidth, …).
    NotPositive {
        /// Path of the field.
        field: String,
        /// The value found.
        value: f64,
    },
    /// A quantity is outside its allowed range.
    OutOfRange {
        /// Path of the field.
        field: String,
        /// The value found.
        value: f64,
        /// What is allowed, in words.
        allowed: &'static str,
    },
    /// A node list that must not be empty is empty.
    EmptyNodeList {
        /// `transmitters` or `receivers`.
        field: &'static str,
    },
    /// The explicit link list is empty.
    EmptyLinkList,
    /// Two nodes share a name (names must be unique across transmitters and receivers).
    DuplicateName {
        /// The repeated name.
        name: String,
    },
    /// A link names a node that does not exist (or a receiver where a transmitter is expected).
    UnknownNode {
        /// Path of the field, e.g. `links[1][0]`.
        field: String,
        /// The unknown name.
        name: String,
    },
    /// The same (Tx, Rx) pair appears twice in the link list.
    DuplicateLink {
        /// Transmitter name.
        tx: String,
        /// Receiver name.
        rx: String,
    },
    /// An area whose minimum is not below its maximum.
    InvertedArea {
        /// `area_m.x` or `area_m.y`.
        field: &'static str,
        /// Lower bound given.
        min: f64,
        /// Upper bound given.
        max: f64,
    },
    /// Both `noise_figure_db` and `noise_power_dbm` were given.
    AmbiguousNoise,
    /// A vector has the wrong length (e.g. one delay per link expected).
    LengthMismatch {
        /// What was being read.
        field: &'static str,
        /// Expected length.
        expected: usize,
        /// Length found.
        found: usize,
    },
    /// Fewer links carry a measurement than the method needs (LM needs 3, spec §5).
    TooFewLinks {
        /// Links with a measurement.
        available: usize,
        /// Links needed.
        required: usize,
    },
    /// A measured delay is not a number in [`limits::DELAY_S`] (`0 < delay ≤ 1 s`): NaN,
    /// infinite, zero, negative or absurdly large.
    InvalidDelay {
        /// Index of the link in scenario link order.
        link: usize,
        /// The value found.
        value: f64,
    },
    /// A delay standard deviation is not a finite number > 0, or (when given by the user) not in
    /// [`limits::DELAY_SIGMA_S`].
    InvalidSigma {
        /// Index of the link in scenario link order.
        link: usize,
        /// The value found.
        value: f64,
    },
    /// A requested grid or Monte Carlo size exceeds the documented cap, or is zero.
    SizeLimit {
        /// What was requested (e.g. `nx`).
        field: &'static str,
        /// The requested value.
        value: usize,
        /// Smallest allowed value.
        min: usize,
        /// Largest allowed value.
        max: usize,
    },
    /// A name (a node's, the scenario's) longer than [`limits::MAX_NAME_BYTES`] (issue 24: a
    /// 100 MB name made every figure take minutes).
    NameTooLong {
        /// Path of the field, e.g. `transmitters[3].name`.
        field: String,
        /// Its length, bytes of UTF-8.
        bytes: usize,
        /// The cap, bytes.
        max: usize,
    },
    /// A covariance or information matrix that must be symmetric positive definite is not (or
    /// stopped being so during a filter update).
    NotPositiveDefinite {
        /// Which matrix, e.g. `initial_covariance` or `ekf.covariance`.
        field: String,
    },
    /// Multi-target localization (Algorithm 1) would evaluate more candidates than its work
    /// budget: the measurements are too ambiguous (too many ranges per TRP for the gate `T_e`
    /// and noise `cσ`) to be solved in bounded time and memory.
    WorkLimit {
        /// The input that drives the work, e.g. `ranges`.
        field: String,
        /// The budget, candidates.
        limit: usize,
    },
    /// A long computation was cancelled by its caller (Ctrl-C, a new drag in the page).
    Cancelled,
    /// Every run of one filter of a study failed (issue 24): the study keeps the other
    /// filters' results; this is the error when no filter has one.
    AllRunsFailed {
        /// The setting to change, e.g. `particles` (the particle filter), `ukf_alpha`.
        field: String,
        /// `ekf`, `ukf` or `pf`.
        filter: &'static str,
        /// Runs that failed (all of them).
        runs: usize,
        /// The first failed run's error, when this process ran it.
        cause: Option<String>,
    },
    /// Work predicted to take longer than the front end's cap (issue 24): a Monte Carlo study or
    /// a track refused before it starts (`crate::track::step_ns`, `crate::study::cost`).
    TooLong {
        /// The inputs that drive the work, e.g. `runs, noise_runs, steps, particles`.
        field: String,
        /// The predicted CPU time, s.
        predicted_s: f64,
        /// The cap, s.
        limit_s: f64,
    },
    /// A name that is not one of the known presets.
    UnknownPreset {
        /// The name asked for.
        name: String,
        /// The names there are (`scenario::presets::PRESET_NAMES`), listed by the message.
        known: &'static [&'static str],
    },
    /// An index past the end of a list (a node, a grid column or row).
    IndexOutOfRange {
        /// The list, e.g. `receivers`.
        field: &'static str,
        /// The index asked for.
        index: usize,
        /// The list's length.
        len: usize,
    },
    /// Removing this node would leave its list empty (at least one Tx and one Rx must remain).
    LastNode {
        /// `transmitters` or `receivers`.
        field: &'static str,
    },
    /// A trajectory name that is not known: not I, II or III (spec §9.4), or for front ends that
    /// also draw one, not `custom` either.
    UnknownTrajectory {
        /// Path of the field, e.g. `trajectory`.
        field: String,
        /// The name given.
        name: String,
        /// The names accepted there, e.g. `I, II, III`.
        known: &'static str,
    },
    /// A particle filter's weights degenerated: every log-weight is `−∞` or not a number (e.g.
    /// measurements infinitely unlikely under every particle). The filter is left unchanged.
    Degenerate {
        /// Which quantity, e.g. `pf.weights`.
        field: String,
    },
    /// A planning problem that no layout can satisfy, or that has nothing to optimise: no
    /// movable node, fixed nodes closer than the spacing, more nodes than the bounds can hold
    /// at that spacing, no feasible layout found within the budget.
    Infeasible {
        /// The input at fault, e.g. `move` or `min_spacing`.
        field: String,
        /// Why, in words.
        reason: String,
    },
    /// An antenna pattern kind that is not known (spec §9.3: `omni`, `parabolic`).
    UnknownPattern {
        /// Path of the field, e.g. `transmitters[0].pattern.kind`.
        field: String,
        /// The kind given.
        kind: String,
    },
    /// A tracker name that is not known (`ekf`, `ukf`, `pf`; issue 15).
    UnknownFilter {
        /// Path of the field, e.g. `filters[1]`.
        field: String,
        /// The name given.
        name: String,
    },
    /// A setting of a tracker that is not run (a particle count when the particle filter is not
    /// among the filters): an error, not silently ignored (issue 15, the Python package).
    UnusedSetting {
        /// The setting, e.g. `particles`, `ukf_alpha`, `bootstrap`.
        field: String,
        /// The filter it belongs to: `ukf` or `pf`.
        filter: &'static str,
        /// The front end's name of the filter list, e.g. `--filters` or `filters`.
        list: String,
    },
    /// A part file that does not fit its set (`merge` of a sharded study).
    InconsistentPart {
        /// The part's path.
        path: String,
        /// What does not fit.
        what: String,
    },
    /// The files given to `merge` are not one study's complete set of parts: not part files,
    /// foreign parts, shard counts that disagree, duplicate or missing shards (the message
    /// lists the files).
    PartSet {
        /// The whole message.
        what: String,
    },
}

impl Error {
    /// The variant's name (`OutOfRange`, `InvalidDelay`, …): what a front end that exposes
    /// errors as values (the Python package's `ScatterlocError.kind`) tells them apart by.
    pub fn kind(&self) -> &'static str {
        match self {
            Error::Parse { .. } => "Parse",
            Error::InvalidFile { .. } => "InvalidFile",
            Error::NonFinite { .. } => "NonFinite",
            Error::NotPositive { .. } => "NotPositive",
            Error::OutOfRange { .. } => "OutOfRange",
            Error::EmptyNodeList { .. } => "EmptyNodeList",
            Error::EmptyLinkList => "EmptyLinkList",
            Error::DuplicateName { .. } => "DuplicateName",
            Error::UnknownNode { .. } => "UnknownNode",
            Error::DuplicateLink { .. } => "DuplicateLink",
            Error::InvertedArea { .. } => "InvertedArea",
            Error::AmbiguousNoise => "AmbiguousNoise",
            Error::LengthMismatch { .. } => "LengthMismatch",
            Error::TooFewLinks { .. } => "TooFewLinks",
            Error::InvalidDelay { .. } => "InvalidDelay",
            Error::InvalidSigma { .. } => "InvalidSigma",
            Error::SizeLimit { .. } => "SizeLimit",
            Error::NameTooLong { .. } => "NameTooLong",
            Error::NotPositiveDefinite { .. } => "NotPositiveDefinite",
            Error::WorkLimit { .. } => "WorkLimit",
            Error::Cancelled => "Cancelled",
            Error::AllRunsFailed { .. } => "AllRunsFailed",
            Error::TooLong { .. } => "TooLong",
            Error::UnknownPreset { .. } => "UnknownPreset",
            Error::IndexOutOfRange { .. } => "IndexOutOfRange",
            Error::LastNode { .. } => "LastNode",
            Error::UnknownTrajectory { .. } => "UnknownTrajectory",
            Error::Degenerate { .. } => "Degenerate",
            Error::Infeasible { .. } => "Infeasible",
            Error::UnknownPattern { .. } => "UnknownPattern",
            Error::UnknownFilter { .. } => "UnknownFilter",
            Error::UnusedSetting { .. } => "UnusedSetting",
            Error::InconsistentPart { .. } => "InconsistentPart",
            Error::PartSet { .. } => "PartSet",
        }
    }

    /// The input field the error names, when it names one (`runs`, `receivers[2].position_m`,
    /// `filters[1]`, …): what a front end maps to its own flag or form control. `Display` starts
    /// with it for every variant that has one.
    pub fn field(&self) -> Option<&str> {
        match self {
            Error::NonFinite { field }
            | Error::NotPositive { field, .. }
            | Error::OutOfRange { field, .. }
            | Error::UnknownNode { field, .. }
            | Error::NotPositiveDefinite { field }
            | Error::WorkLimit { field, .. }
            | Error::AllRunsFailed { field, .. }
            | Error::TooLong { field, .. }
            | Error::UnknownTrajectory { field, .. }
            | Error::Degenerate { field }
            | Error::Infeasible { field, .. }
            | Error::UnknownPattern { field, .. }
            | Error::UnknownFilter { field, .. }
            | Error::UnusedSetting { field, .. }
            | Error::NameTooLong { field, .. }
            | Error::InvalidFile { field, .. } => Some(field),
            Error::EmptyNodeList { field }
            | Error::InvertedArea { field, .. }
            | Error::LengthMismatch { field, .. }
            | Error::SizeLimit { field, .. }
            | Error::IndexOutOfRange { field, .. }
            | Error::LastNode { field } => Some(field),
            _ => None,
        }
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::Parse { message } => write!(f, "invalid JSON: {}", Clip(message)),
            Error::InvalidFile { field, reason } => write!(f, "{field}: {reason}"),
            Error::NonFinite { field } => write!(f, "{field}: not a finite number"),
            Error::NotPositive { field, value } => {
                write!(f, "{field}: must be > 0 (got {})", Num(*value))
            }
            Error::OutOfRange {
                field,
                value,
                allowed,
            } => {
                write!(f, "{field}: {} is out of range ({allowed})", Num(*value))
            }
            Error::EmptyNodeList { field } => write!(f, "{field}: at least one node is required"),
            Error::EmptyLinkList => write!(f, "links: the link list is empty"),
            Error::DuplicateName { name } => write!(f, "duplicate node name \"{}\"", Clip(name)),
            Error::UnknownNode { field, name } => {
                write!(f, "{field}: unknown node \"{}\"", Clip(name))
            }
            Error::DuplicateLink { tx, rx } => {
                write!(
                    f,
                    "links: the link [\"{}\", \"{}\"] appears twice",
                    Clip(tx),
                    Clip(rx)
                )
            }
            Error::InvertedArea { field, min, max } => {
                write!(
                    f,
                    "{field}: the minimum {} must be below the maximum {}",
                    Num(*min),
                    Num(*max)
                )
            }
            Error::AmbiguousNoise => write!(
                f,
                "radio: give either noise_figure_db or noise_power_dbm, not both"
            ),
            Error::LengthMismatch {
                field,
                expected,
                found,
            } => {
                write!(
                    f,
                    "{field}: expected {expected} values (one per link), found {found}"
                )
            }
            Error::TooFewLinks {
                available,
                required,
            } => write!(
                f,
                "delays_s: {available} link(s) carry a measurement, at least {required} are needed"
            ),
            Error::InvalidDelay { link, value } if !value.is_finite() => {
                write!(f, "delays_s[{link}]: not a finite number")
            }
            Error::InvalidDelay { link, value } => write!(
                f,
                "delays_s[{link}]: {} is out of range ({})",
                Num(*value),
                limits::DELAY_S.allowed
            ),
            Error::InvalidSigma { link, value } if value.is_finite() && *value > 0.0 => write!(
                f,
                "sigma_s[{link}]: {} is out of range ({})",
                Num(*value),
                limits::DELAY_SIGMA_S.allowed
            ),
            Error::InvalidSigma { link, value } => {
                write!(
                    f,
                    "sigma_s[{link}]: must be a finite number > 0 (got {})",
                    Num(*value)
                )
            }
            Error::SizeLimit {
                field,
                value,
                min,
                max,
            } => {
                write!(
                    f,
                    "{field}: {value} is outside the allowed range {min}..={max}"
                )
            }
            Error::NameTooLong { field, bytes, max } => {
                write!(f, "{field}: {bytes} bytes long, at most {max} are allowed")
            }
            Error::NotPositiveDefinite { field } => {
                write!(f, "{field}: not a symmetric positive-definite matrix")
            }
            Error::WorkLimit { field, limit } => write!(
                f,
                "{field}: more than {limit} candidates to evaluate (the work budget of \
                 multi-target localization); give fewer ranges per TRP, or lower T_e or c_sigma_m"
            ),
            Error::Cancelled => write!(f, "cancelled"),
            Error::AllRunsFailed {
                field,
                filter,
                runs,
                cause,
            } => {
                let name = filter.to_uppercase();
                write!(
                    f,
                    "{field}: every run of the {name} failed ({runs} of {runs})"
                )?;
                match cause {
                    Some(c) => write!(f, "; the first: {}", Clip(c)),
                    None => Ok(()),
                }
            }
            Error::TooLong {
                field,
                predicted_s,
                limit_s,
            } => write!(
                f,
                "{field}: the work is predicted to take {} s of CPU time, over the cap of {} s; \
                 make it smaller",
                Num(crate::math::round(*predicted_s)),
                Num(*limit_s)
            ),
            Error::Degenerate { field } => write!(
                f,
                "{field}: degenerate (every particle's likelihood is zero or not a number)"
            ),
            Error::Infeasible { field, reason } => write!(f, "{field}: {}", Clip(reason)),
            Error::UnknownPreset { name, known } => write!(
                f,
                "unknown preset \"{}\" (known: {})",
                Clip(name),
                known.join(", ")
            ),
            Error::IndexOutOfRange { field, index, len } => {
                write!(f, "{field}[{index}]: no such entry (there are {len})")
            }
            Error::LastNode { field } => write!(
                f,
                "{field}: the last one cannot be removed (at least one is required)"
            ),
            Error::UnknownTrajectory { field, name, known } => {
                write!(
                    f,
                    "{field}: unknown trajectory \"{}\" (known: {known})",
                    Clip(name)
                )
            }
            Error::UnknownPattern { field, kind } => write!(
                f,
                "{field}: unknown pattern \"{}\" (known: omni, parabolic)",
                Clip(kind)
            ),
            Error::UnusedSetting {
                field,
                filter,
                list,
            } => write!(
                f,
                "{field}: only for the {filter} filter ({list} does not include {filter})"
            ),
            Error::UnknownFilter { field, name } => write!(
                f,
                "{field}: unknown filter \"{}\" (known: ekf, ukf, pf)",
                Clip(name)
            ),
            Error::InconsistentPart { path, what } => {
                write!(f, "merge: inconsistent part {path}: {what}")
            }
            Error::PartSet { what } => write!(f, "{what}"),
        }
    }
}

#[cfg(feature = "std")]
impl std::error::Error for Error {}

/// Result with the crate's [`Error`].
pub type Result<T> = core::result::Result<T, Error>;

/// `index` if it is below `len`, else [`Error::IndexOutOfRange`] naming `field`.
pub fn checked_index(field: &'static str, index: usize, len: usize) -> Result<usize> {
    if index < len {
        Ok(index)
    } else {
        Err(Error::IndexOutOfRange { field, index, len })
    }
}

/// `Ok` when `found == expected`, else [`Error::LengthMismatch`] naming `field`.
pub(crate) fn check_len(field: &'static str, expected: usize, found: usize) -> Result<()> {
    if found == expected {
        Ok(())
    } else {
        Err(Error::LengthMismatch {
            field,
            expected,
            found,
        })
    }
}

/// `v` if finite, else [`Error::NonFinite`] naming `field`.
pub(crate) fn check_finite(field: &str, v: f64) -> Result<()> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(Error::NonFinite {
            field: field.into(),
        })
    }
}

/// `v > 0`: [`Error::NonFinite`] when not finite, else [`Error::NotPositive`], naming `field`.
pub(crate) fn check_positive(field: &str, v: f64) -> Result<()> {
    check_finite(field, v)?;
    if v > 0.0 {
        Ok(())
    } else {
        Err(Error::NotPositive {
            field: field.into(),
            value: v,
        })
    }
}

/// `v ≥ 0`: [`Error::NonFinite`] for NaN (and `±∞` unless `allow_inf`), else
/// [`Error::OutOfRange`] with `allowed`, naming `field`.
pub(crate) fn check_non_negative(
    field: &str,
    v: f64,
    allow_inf: bool,
    allowed: &'static str,
) -> Result<()> {
    if v.is_nan() || (!allow_inf && v.is_infinite()) {
        return Err(Error::NonFinite {
            field: field.into(),
        });
    }
    if v < 0.0 {
        return Err(Error::OutOfRange {
            field: field.into(),
            value: v,
            allowed,
        });
    }
    Ok(())
}
