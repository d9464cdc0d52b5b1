//! Results of `montecarlo` and `pcrlb`: the curves per trajectory as JSON (`--json`, or stdout
//! when no file is asked for), the [S] Fig. 3 figure (`--out`, spec §10) and the one-line stdout
//! summary with the values at the reporting times. Files are written atomically, only after
//! every run has finished.

use plotters::coord::Shift;
use plotters::prelude::*;
use serde::Serialize;

use scatterloc::chart::{
    draw_tracking_filters, tracking_size, ChartError, FilterCurve, FiltersPanel,
    TrackingChartOptions,
};
use scatterloc::study::{CurveDoc, TrackStudy as Study};

use super::io::{emit, emit_summary};
use super::output::{check_writable, Figure, Format, OutputSet};
use super::study::{at_report_times, AtTime};
use crate::failure::CliError;

/// The scalars and the values at the reporting times.
#[derive(Serialize)]
struct Summary<'a, M: Serialize> {
    #[serde(flatten)]
    meta: &'a M,
    at: Vec<AtTime>,
}

/// `{"scenarios": [...]}`.
#[derive(Serialize)]
struct Scenarios<'a, T: Serialize> {
    scenarios: &'a [T],
}

/// One object for one trajectory, else `{"scenarios": [...]}` (keys in declaration order).
#[derive(Serialize)]
#[serde(untagged)]
enum Body<'a, T: Serialize> {
    One(&'a T),
    Many(Scenarios<'a, T>),
}

impl<'a, T: Serialize> Body<'a, T> {
    fn of(all: &'a [T]) -> Body<'a, T> {
        match all {
            [one] => Body::One(one),
            _ => Body::Many(Scenarios { scenarios: all }),
        }
    }
}

/// The stdout summary line: the body, then the output paths.
#[derive(Serialize)]
struct Line<'a, T: Serialize> {
    #[serde(flatten)]
    body: Body<'a, T>,
    json: Option<&'a str>,
    out: Option<&'a str>,
}

fn encode<T: Serialize>(v: &T) -> Result<String, CliError> {
    serde_json::to_string(v).map_err(|e| CliError::output(format!("encoding JSON: {e}")))
}

/// The tracking figure ([S] Fig. 3; one or more trackers' labelled RMSE curves beside the
/// PCRLB) as a [`Figure`].
pub(super) struct FiltersFigure<'a> {
    pub(super) panels: Vec<FiltersPanel<'a>>,
    pub(super) opts: &'a TrackingChartOptions,
}

impl Figure for FiltersFigure<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), ChartError> {
        draw_tracking_filters(root, &self.panels, self.opts).map(|_| ())
    }
}

/// Where results go: a figure (`--out`, SVG or PNG) and the curves (`--json`).
pub struct Outputs {
    figure: Option<(String, Format)>,
    json: Option<String>,
}

impl Outputs {
    /// Checks `--out` and `--json` now, before any long run: formats, and that both can be
    /// written.
    pub fn parse(out: Option<&str>, json: Option<&str>) -> Result<Outputs, CliError> {
        let figure = match out {
            Some(p) => Some((
                p.to_string(),
                Format::of("out", p, &[Format::Svg, Format::Png])?,
            )),
            None => None,
        };
        let json = match json {
            Some(p) => Format::of("json", p, &[Format::Json]).map(|_| Some(p.to_string()))?,
            None => None,
        };
        if let Some((p, _)) = &figure {
            check_writable("out", p)?;
        }
        if let Some(p) = &json {
            check_writable("json", p)?;
        }
        Ok(Outputs { figure, json })
    }

    /// Writes the results of `study` (one doc per trajectory, in order): without `--json` and
    /// `--out` every curve goes to stdout; otherwise the files, then the summary line.
    pub fn finish<M: Serialize>(
        &self,
        study: &Study,
        docs: &[CurveDoc<M>],
        opts: &TrackingChartOptions,
    ) -> Result<(), CliError> {
        if self.json.is_none() && self.figure.is_none() {
            return emit(&encode(&Body::of(docs))?);
        }
        // The JSON and the figure are renamed into place together, or neither (issue 24).
        let mut files = OutputSet::new();
        if let Some(path) = &self.json {
            files.json("json", path, &Body::of(docs))?;
        }
        if let Some((path, format)) = &self.figure {
            let captions: Vec<String> = study
                .trajectories
                .iter()
                .zip(docs)
                .map(|(t, d)| match &d.caption_note {
                    Some(note) => format!("Scenario {} · {note}", t.name()),
                    None => format!("Scenario {}", t.name()),
                })
                .collect();
            let size = tracking_size(docs.len());
            let curves: Vec<Vec<FilterCurve>> = docs
                .iter()
                .map(|d| {
                    d.figure_curves
                        .iter()
                        .map(|(label, rmse)| FilterCurve {
                            label,
                            rmse_m: rmse,
                        })
                        .collect()
                })
                .collect();
            let panels = docs
                .iter()
                .zip(&captions)
                .zip(&curves)
                .map(|((d, title), curves)| FiltersPanel {
                    title,
                    t_s: &d.t_s,
                    curves,
                    rmse_pcrlb_m: &d.rmse_pcrlb_m,
                    legend_note: d.figure_note,
                })
                .collect();
            files.figure("out", path, *format, size, &FiltersFigure { panels, opts })?;
        }
        files.commit()?;
        let summaries: Vec<Summary<M>> = docs
            .iter()
            .map(|d| Summary {
                meta: &d.meta,
                at: at_report_times(
                    &d.t_s,
                    &d.rmse_pcrlb_m,
                    d.rmse_ekf_m.as_deref().zip(d.nees.as_deref()),
                ),
            })
            .collect();
        emit_summary(&encode(&Line {
            body: Body::of(&summaries),
            json: self.json.as_deref(),
            out: self.figure.as_ref().map(|f| f.0.as_str()),
        })?)
    }
}
