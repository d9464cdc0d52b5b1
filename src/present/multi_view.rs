//! What a front end shows and exports of a several-people run (issue 41 §2; the page's "Several
//! people" document, the CLI's `track --targets auto --truth`): the document read back from its
//! JSON ([`people_doc_from_json`]: truth, track and score as the study's types), the map view at
//! one scan ([`people_map_view`]: every true path, every labelled track up to the scan in its own
//! colour — its place in the track's `tracks`, as the page's `linkColor(i)` of [`LINK_RGB`] —,
//! its label, position and 1σ ellipse), and the data file ([`people_data_text`]: CSV of the truth
//! and track rows, or JSON of the truth, track and score). Pure layout: no maths of its own
//! beyond [`position_ellipse`].
//!
//! [`LINK_RGB`]: crate::present::LINK_RGB

use alloc::format;
use alloc::string::{String, ToString};
use alloc::vec;
use alloc::vec::Vec;

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::math::{Mat4, Real, Vec4};
use crate::measure::Ellipse;
use crate::present::position_ellipse;
use crate::study::{
    LabelledTrack, MultiScoreDoc, MultiSettings, MultiTrackOutput, MultiTruth, TargetDoc,
};

/// A several-people run: the truth, the track and its score (the study's types).
#[derive(Debug, Clone, PartialEq)]
pub struct PeopleRun {
    /// The true people per scan.
    pub truth: MultiTruth,
    /// The tracker's document.
    pub track: MultiTrackOutput,
    /// GOSPA per scan and the run's scores.
    pub score: MultiScoreDoc,
}

#[derive(Deserialize)]
struct TargetIn {
    label: u64,
    state: [f64; 4],
    covariance: [[f64; 4]; 4],
    existence: f64,
}

#[derive(Deserialize)]
struct LifeIn {
    label: u64,
    first_scan: usize,
    last_scan: usize,
    scans: usize,
    start: String,
    end: String,
}

#[derive(Deserialize)]
struct TrackIn {
    method: String,
    settings: MultiSettings,
    t_s: Vec<f64>,
    targets: Vec<Vec<TargetIn>>,
    tracks: Vec<LifeIn>,
    static_removed: Vec<usize>,
}

/// JSON writes a non-finite number as `null`: read back as NaN.
fn nan_for_null(v: Vec<Option<f64>>) -> Vec<f64> {
    v.into_iter().map(|x| x.unwrap_or(f64::NAN)).collect()
}

#[derive(Deserialize)]
struct ScoreIn {
    c_m: f64,
    gospa_m: Vec<Option<f64>>,
    localisation_m2: Vec<Option<f64>>,
    missed_m2: Vec<Option<f64>>,
    false_m2: Vec<Option<f64>>,
    mean_gospa_m: Option<f64>,
    switches: usize,
    mean_cardinality_error: Option<f64>,
}

/// What is read of a document (other keys, e.g. the page's `ellipses`, ignored).
#[derive(Deserialize)]
struct DocIn {
    truth: MultiTruth,
    track: TrackIn,
    score: ScoreIn,
}

fn invalid(field: String, reason: &str) -> Error {
    Error::InvalidFile {
        field,
        reason: reason.to_string(),
    }
}

/// The 1σ position ellipse of every reported target of `track`, per scan in `track.targets`'
/// order (`None` where the covariance has none): the page's ellipses of a multi-target run, in
/// the tracking view and the channel view alike.
pub fn track_ellipses(track: &MultiTrackOutput) -> Vec<Vec<Option<crate::present::EllipseView>>> {
    track
        .targets
        .iter()
        .map(|scan| {
            scan.iter()
                .map(|t| {
                    let cov = Mat4::from_fn(|i, j| t.covariance[i][j]);
                    position_ellipse(&Vec4::from(t.state), &cov, 1.0)
                        .map(crate::present::EllipseView::from)
                })
                .collect()
        })
        .collect()
}

/// Reads a several-people document — JSON text with `truth` (the CLI's truth.json), `track`
/// (`track --targets auto`'s document) and `score` (its score), other keys ignored, as the
/// page's `track_people` returns — and checks its shape: one entry of `t_s` per scan of the
/// truth and of the track, the score's series no longer than the scans, each track's
/// `first_scan ≤ last_scan <` scans. Malformed JSON is [`Error::Parse`], a shape that does not
/// fit [`Error::InvalidFile`] or [`Error::LengthMismatch`] naming the field.
pub fn people_doc_from_json(text: &str) -> Result<PeopleRun> {
    let d: DocIn = serde_json::from_str(text).map_err(|e| Error::Parse {
        message: e.to_string(),
    })?;
    if d.truth.targets.len() != d.truth.t_s.len() {
        return Err(Error::LengthMismatch {
            field: "truth.targets (one list per truth.t_s)",
            expected: d.truth.t_s.len(),
            found: d.truth.targets.len(),
        });
    }
    let t = d.track;
    let n = t.t_s.len();
    if t.targets.len() != n {
        return Err(Error::LengthMismatch {
            field: "track.targets (one list per track.t_s)",
            expected: n,
            found: t.targets.len(),
        });
    }
    for (i, l) in t.tracks.iter().enumerate() {
        if l.first_scan > l.last_scan || l.last_scan >= n {
            return Err(invalid(
                format!("track.tracks[{i}]"),
                "first_scan ≤ last_scan < the number of scans is required",
            ));
        }
    }
    let s = d.score;
    for (field, v) in [
        ("score.gospa_m", &s.gospa_m),
        ("score.localisation_m2", &s.localisation_m2),
        ("score.missed_m2", &s.missed_m2),
        ("score.false_m2", &s.false_m2),
    ] {
        if v.len() > n {
            return Err(invalid(field.to_string(), "more entries than scans"));
        }
    }
    let track = MultiTrackOutput {
        method: t.method,
        settings: t.settings,
        t_s: t.t_s,
        targets: t
            .targets
            .into_iter()
            .map(|scan| {
                scan.into_iter()
                    .map(|x| TargetDoc {
                        label: x.label,
                        state: x.state,
                        covariance: x.covariance,
                        existence: x.existence,
                    })
                    .collect()
            })
            .collect(),
        tracks: t
            .tracks
            .into_iter()
            .map(|l| LabelledTrack {
                label: l.label,
                first_scan: l.first_scan,
                last_scan: l.last_scan,
                scans: l.scans,
                start: l.start,
                end: l.end,
            })
            .collect(),
        static_removed: t.static_removed,
    };
    let score = MultiScoreDoc {
        c_m: s.c_m,
        gospa_m: nan_for_null(s.gospa_m),
        localisation_m2: nan_for_null(s.localisation_m2),
        missed_m2: nan_for_null(s.missed_m2),
        false_m2: nan_for_null(s.false_m2),
        mean_gospa_m: s.mean_gospa_m.unwrap_or(f64::NAN),
        switches: s.switches,
        mean_cardinality_error: s.mean_cardinality_error.unwrap_or(f64::NAN),
    };
    Ok(PeopleRun {
        truth: d.truth,
        track,
        score,
    })
}

/// One labelled track on the map at a scan.
#[derive(Debug, Clone, PartialEq)]
pub struct PeopleTrackView {
    /// Its label.
    pub label: u64,
    /// Its colour: its place in the track's `tracks` (an index into
    /// [`LINK_RGB`](crate::present::LINK_RGB), modulo its length; the page's `linkColor(i)`).
    pub colour: usize,
    /// Its estimates `[x, y]` (m) from its first scan up to the scan shown, split where it was
    /// not reported.
    pub runs: Vec<Vec<[Real; 2]>>,
    /// Its position at the scan shown, m, if reported there.
    pub position: Option<[Real; 2]>,
    /// Its 1σ position ellipse at the scan shown (true scale), if reported there.
    pub ellipse: Option<Ellipse>,
}

/// The map layer of a several-people run at one scan, as the page's tracking view draws it.
#[derive(Debug, Clone, PartialEq)]
pub struct PeopleMapView {
    /// The scan shown (the scan asked for, at most the last).
    pub step: usize,
    /// Its time, s.
    pub t_s: Real,
    /// Every true path `[x, y]` (m) over the whole run, one per person in the order they first
    /// appear.
    pub truth: Vec<Vec<[Real; 2]>>,
    /// Every track started by the scan shown, in the track's `tracks` order.
    pub tracks: Vec<PeopleTrackView>,
}

/// The map view of `track` and `truth` at scan `step` (past the end: the last scan). A track
/// with no scan is [`Error::InvalidFile`] (`track.t_s`).
pub fn people_map_view(
    track: &MultiTrackOutput,
    truth: &MultiTruth,
    step: usize,
) -> Result<PeopleMapView> {
    let n = track.t_s.len().min(track.targets.len());
    if n == 0 {
        return Err(invalid("track.t_s".to_string(), "the track has no scan"));
    }
    let step = step.min(n - 1);
    let mut labels: Vec<u64> = Vec::new();
    let mut paths: Vec<Vec<[Real; 2]>> = Vec::new();
    for scan in &truth.targets {
        for t in scan {
            let i = match labels.iter().position(|&l| l == t.label) {
                Some(i) => i,
                None => {
                    labels.push(t.label);
                    paths.push(Vec::new());
                    labels.len() - 1
                }
            };
            paths[i].push([t.state[0], t.state[1]]);
        }
    }
    let mut tracks = Vec::new();
    for (colour, life) in track.tracks.iter().enumerate() {
        if life.first_scan > step {
            continue;
        }
        let find = |k: usize| track.targets[k].iter().find(|x| x.label == life.label);
        let mut runs: Vec<Vec<[Real; 2]>> = vec![Vec::new()];
        for k in life.first_scan..=step.min(life.last_scan) {
            match find(k) {
                Some(t) => runs.last_mut().unwrap().push([t.state[0], t.state[1]]),
                None if !runs.last().unwrap().is_empty() => runs.push(Vec::new()),
                None => {}
            }
        }
        runs.retain(|r| !r.is_empty());
        let now = find(step);
        tracks.push(PeopleTrackView {
            label: life.label,
            colour,
            runs,
            position: now.map(|t| [t.state[0], t.state[1]]),
            ellipse: now.and_then(|t| {
                let cov = Mat4::from_fn(|i, j| t.covariance[i][j]);
                position_ellipse(&Vec4::from(t.state), &cov, 1.0)
            }),
        });
    }
    Ok(PeopleMapView {
        step,
        t_s: track.t_s[step],
        truth: paths,
        tracks,
    })
}

/// A number of a CSV file: Rust's shortest text that reads back as the same `f64`; empty for a
/// non-finite value.
fn csv_num(v: f64) -> String {
    if v.is_finite() {
        format!("{v}")
    } else {
        String::new()
    }
}

/// The state names of the CSV columns.
const STATE: [&str; 4] = ["x_m", "y_m", "vx_mps", "vy_mps"];

/// The header of [`people_data_text`]'s CSV.
pub fn people_csv_header() -> String {
    let mut head: Vec<String> = ["scan", "t_s", "kind", "label"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    head.extend(STATE.iter().map(|s| s.to_string()));
    head.push("existence".into());
    head.extend((0..16).map(|k| format!("P_{}_{}", k / 4, k % 4)));
    head.join(",")
}

/// The JSON of [`people_data_text`].
#[derive(Serialize)]
struct PeopleDataJs<'a> {
    units: &'static str,
    truth: &'a MultiTruth,
    track: &'a MultiTrackOutput,
    score: &'a MultiScoreDoc,
}

/// A several-people run as a data file. `format` `"csv"`: the long table — header
/// [`people_csv_header`] (`scan, t_s, kind, label, x_m, y_m, vx_mps, vy_mps, existence, P_0_0,
/// …, P_3_3`), per scan first the true people (`kind` `truth`, the truth's `t_s`, existence and
/// covariance empty) then the reported targets (`kind` `track`, the track's `t_s`, existence and
/// the covariance row-major over x, y, vx, vy); `"json"`: `{units, truth, track, score}` (the
/// study's documents, GOSPA and its parts per scan in `score`). Every number is the run's,
/// written to read back as the same `f64` (a non-finite one: empty in CSV, `null` in JSON).
/// Another format is [`Error::Parse`] naming it.
pub fn people_data_text(run: &PeopleRun, format: &str) -> Result<String> {
    match format {
        "csv" => {}
        "json" => {
            let doc = PeopleDataJs {
                units: "m, m/s, s; covariance row-major over (x, y, vx, vy); GOSPA parts m²",
                truth: &run.truth,
                track: &run.track,
                score: &run.score,
            };
            return serde_json::to_string(&doc).map_err(|e| Error::Parse {
                message: e.to_string(),
            });
        }
        other => {
            return Err(Error::Parse {
                message: format!("format: \"{other}\" is not csv or json"),
            })
        }
    }
    let mut out = people_csv_header();
    out.push('\n');
    let scans = run.truth.t_s.len().max(run.track.t_s.len());
    for k in 0..scans {
        if let (Some(t_s), Some(scan)) = (run.truth.t_s.get(k), run.truth.targets.get(k)) {
            for t in scan {
                let mut row = vec![
                    k.to_string(),
                    csv_num(*t_s),
                    "truth".into(),
                    t.label.to_string(),
                ];
                row.extend(t.state.map(csv_num));
                row.extend(core::iter::repeat_n(String::new(), 17));
                out.push_str(&row.join(","));
                out.push('\n');
            }
        }
        if let (Some(t_s), Some(scan)) = (run.track.t_s.get(k), run.track.targets.get(k)) {
            for t in scan {
                let mut row = vec![
                    k.to_string(),
                    csv_num(*t_s),
                    "track".into(),
                    t.label.to_string(),
                ];
                row.extend(t.state.map(csv_num));
                row.push(csv_num(t.existence));
                row.extend(t.covariance.iter().flatten().map(|&v| csv_num(v)));
                out.push_str(&row.join(","));
                out.push('\n');
            }
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests;
