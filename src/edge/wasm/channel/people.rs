//! Several people in the channel view's run (issue 41 §2): after the estimation, the job's
//! estimates tracked by the multi-target tracker exactly as `scatterloc cir track --targets auto`
//! does with its defaults ([`cir_track_multi`] with [`recording_multi_settings`] of the model's
//! links, the extent [`RECORDING_EXTENT_SIGMA_M`], the request's process noise and the statics'
//! clusters), scored against a truth with further walkers (`cir simulate`'s `others`, read by
//! [`walkers_truth`] as the CLI's `--truth` reads it) with the CLI's GOSPA `c` of 1 m. The
//! document [`PeopleDoc`] is what `ChannelJob.people_json()` returns.

use alloc::string::String;
use alloc::vec::Vec;

use serde::{Deserialize, Serialize};

use crate::error::{Cancel, Error, Result};
use crate::formats::Truth;
use crate::present::{track_ellipses, EllipseView};
use crate::scenario::Area;
use crate::study::{
    cir_track_multi, recording_multi_settings, score_multi, walkers_truth, ChannelRequest,
    ChannelStatics, FrontEndConfig, MultiScoreDoc, MultiTrackOutput, MultiTruth,
    RecordingEstimates, RECORDING_EXTENT_SIGMA_M,
};
use crate::Model;

/// GOSPA's cut-off `c`, m, of the score (the CLI's `cir track --gospa-c` default).
pub const CHANNEL_PEOPLE_GOSPA_C_M: f64 = 1.0;

/// How many people a channel run tracks: `"one"` (the single-target `cir track`, the default)
/// or `"auto"` (also `cir track --targets auto`). Anything else is [`Error::InvalidFile`]
/// `targets`.
pub(super) fn parse_targets(text: &str) -> Result<bool> {
    match text {
        "one" => Ok(false),
        "auto" => Ok(true),
        other => Err(Error::InvalidFile {
            field: "targets".into(),
            reason: alloc::format!(
                "\"{}\" is not one of one, auto",
                other.chars().take(40).collect::<String>()
            ),
        }),
    }
}

/// The further walkers of a truth file (`cir simulate`'s `others`: per walker one `[x, y, vx,
/// vy]` per snapshot; absent: none). Other keys are the [`Truth`]'s and are ignored here.
#[derive(Deserialize)]
struct Others {
    #[serde(default)]
    others: Vec<Vec<[f64; 4]>>,
}

/// The further walkers of the truth file's text (its `others`); a malformed `others` is
/// [`Error::InvalidFile`] naming it.
pub(super) fn truth_others(text: &str) -> Result<Vec<Vec<[f64; 4]>>> {
    serde_json::from_str::<Others>(text)
        .map(|o| o.others)
        .map_err(|e| Error::InvalidFile {
            field: "others".into(),
            reason: alloc::format!("{e}"),
        })
}

/// The people document of a channel run (`ChannelJob.people_json()`).
#[derive(Serialize)]
pub(super) struct PeopleDoc {
    /// The labelled tracks: the document `cir track --targets auto` writes, without its
    /// additions below.
    track: MultiTrackOutput,
    /// The extent that widened each estimate's σ̂, m (the CLI's `extent_sigma_m`).
    extent_sigma_m: f64,
    /// The statics' handling (the CLI's `statics`).
    statics: &'static str,
    /// The delays' reference (the CLI's `delay_reference`).
    delay_reference: &'static str,
    /// Per scan, per reported target in `track.targets`' order, the 1σ position ellipse.
    ellipses: Vec<Vec<Option<EllipseView>>>,
    /// The walkers' truth (label 0 the truth file's `states`, `i + 1` its `others[i]`), with a
    /// truth file.
    truth: Option<MultiTruth>,
    /// The score against it (GOSPA `c` = [`CHANNEL_PEOPLE_GOSPA_C_M`]), with a truth file.
    score: Option<MultiScoreDoc>,
}

/// The people of a run (module docs): the estimates `est` with the statics `st` tracked as
/// `cir track --targets auto` does with its defaults, and, with a `truth` (its times already
/// checked against the recording's) and its further walkers `others`, the score.
///
/// Errors: [`cir_track_multi`]'s (`Err(("track", e))`), a truth whose walkers are not one
/// state per snapshot or whose score fails (`Err(("truth", e))`).
#[allow(clippy::too_many_arguments)]
pub(super) fn people_doc(
    model: &Model,
    area: &Area,
    st: &ChannelStatics,
    est: &RecordingEstimates,
    req: &ChannelRequest,
    cfg: &FrontEndConfig,
    truth: Option<(&Truth, &[Vec<[f64; 4]>])>,
) -> core::result::Result<PeopleDoc, (&'static str, Error)> {
    let settings = recording_multi_settings(model.link_count());
    let track = cir_track_multi(
        model,
        area,
        &st.calibration,
        est,
        &settings,
        req.process_noise,
        RECORDING_EXTENT_SIGMA_M,
        Cancel::NEVER,
    )
    .map_err(|e| ("track", e))?;
    let (truth, score) = match truth {
        Some((t, others)) => {
            let walkers = walkers_truth(&t.t_s, &t.states, others).map_err(|e| ("truth", e))?;
            let score = score_multi(&track, &walkers, CHANNEL_PEOPLE_GOSPA_C_M)
                .map_err(|e| ("truth", e))?;
            (Some(walkers), Some(score))
        }
        None => (None, None),
    };
    Ok(PeopleDoc {
        ellipses: track_ellipses(&track),
        track,
        extent_sigma_m: RECORDING_EXTENT_SIGMA_M,
        statics: cfg.statics.name(),
        delay_reference: cfg.delay_reference.name(),
        truth,
        score,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// "one" and "auto" only; anything else names `targets`.
    #[test]
    fn targets_are_one_or_auto() {
        assert!(!parse_targets("one").unwrap());
        assert!(parse_targets("auto").unwrap());
        for bad in ["", "several", "Auto", "2"] {
            assert_eq!(parse_targets(bad).unwrap_err().field(), Some("targets"));
        }
    }

    /// `others` absent is none; present, every walker's states; malformed, named.
    #[test]
    fn others_are_read_or_named() {
        assert!(truth_others(r#"{"t_s": [0], "states": [[0, 0, 0, 0]]}"#)
            .unwrap()
            .is_empty());
        let o = truth_others(r#"{"others": [[[1, 2, 3, 4]], [[5, 6, 7, 8]]]}"#).unwrap();
        assert_eq!(
            o,
            alloc::vec![
                alloc::vec![[1.0, 2.0, 3.0, 4.0]],
                alloc::vec![[5.0, 6.0, 7.0, 8.0]]
            ]
        );
        let e = truth_others(r#"{"others": [[[1, 2]]]}"#).unwrap_err();
        assert_eq!(e.field(), Some("others"));
    }
}
