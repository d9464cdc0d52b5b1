//! Results of `montecarlo` and `pcrlb`: the curves per trajectory as JSON (`--json`, or stdout
//! when no file is asked for), the [S] Fig. 3 figure (`--out`, spec §10) and the one-line stdout
//! summary with the values at the reporting times. Files are written atomically, only after
//! every run has finished.

use plotters::coord::Shift;
use plotters::prelude::*;
use serde::Serialize;

use scatterloc::chart::{
    draw_tracking_filters, draw_tracking_rmse, tracking_size, ChartError, FilterCurve,
    FiltersPanel, TrackingChartOptions, TrackingPanel,
};

use super::io::emit;
use super::output::{check_writable, write_figure, write_json_file, Figure, Format};
use super::study::{at_report_times, AtTime, Study};
use crate::failure::CliError;

/// The curves of one trajectory and its scalars `M` (flattened after the curves).
#[derive(Serialize)]
pub struct CurveDoc<M: Serialize> {
    /// `t_n`, s.
    pub t_s: Vec<f64>,
    /// `ε_EKF(t_n)`, m (EKF studies only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rmse_ekf_m: Option<Vec<f64>>,
    /// `ε_PCRLB(t_n)`, m (`null` where singular).
    pub rmse_pcrlb_m: Vec<Option<f64>>,
    /// Average NEES (EKF studies only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub nees: Option<Vec<f64>>,
    /// Everything else.
    #[serde(flatten)]
    pub meta: M,
    /// Added to the panel caption of the figure (EKF studies: the failed runs, which
    /// `ε_EKF` leaves out); not part of the JSON.
    #[serde(skip)]
    pub caption_note: Option<String>,
    /// Several trackers (`montecarlo --filters`): the figure draws these labelled RMSE curves
    /// instead of `rmse_ekf_m`; not part of the JSON (the meta holds them).
    #[serde(skip)]
    pub figure_curves: Option<Vec<(String, Vec<f64>)>>,
}

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

/// The [S] Fig. 3 figure as a [`Figure`].
struct TrackingFigure<'a> {
    panels: Vec<TrackingPanel<'a>>,
    opts: &'a TrackingChartOptions,
}

impl Figure for TrackingFigure<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), ChartError> {
        draw_tracking_rmse(root, &self.panels, self.opts).map(|_| ())
    }
}

/// The figure of several trackers' curves as a [`Figure`].
struct FiltersFigure<'a> {
    panels: Vec<FiltersPanel<'a>>,
    opts: &'a TrackingChartOptions,
}

impl Figure for FiltersFigure<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), ChartError> {
        draw_tracking_filters(root, &self.panels, self.opts).map(|_| ())
    }
}

/// `{layout}, scenario II` or `{layout}, scenarios I, II, III` (figure titles).
pub fn which(study: &Study) -> String {
    let names: Vec<&str> = study.trajectories.iter().map(|t| t.name()).collect();
    let plural = if names.len() > 1 { "s" } else { "" };
    format!("{}, scenario{plural} {}", study.layout, names.join(", "))
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
        if let Some(path) = &self.json {
            write_json_file("json", path, &Body::of(docs))?;
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
            if docs.iter().any(|d| d.figure_curves.is_some()) {
                let curves: Vec<Vec<FilterCurve>> = docs
                    .iter()
                    .map(|d| {
                        d.figure_curves
                            .iter()
                            .flatten()
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
                    })
                    .collect();
                write_figure("out", path, *format, size, &FiltersFigure { panels, opts })?;
            } else {
                let panels = docs
                    .iter()
                    .zip(&captions)
                    .map(|(d, title)| TrackingPanel {
                        title,
                        t_s: &d.t_s,
                        rmse_ekf_m: d.rmse_ekf_m.as_deref().unwrap_or(&[]),
                        rmse_pcrlb_m: &d.rmse_pcrlb_m,
                    })
                    .collect();
                write_figure("out", path, *format, size, &TrackingFigure { panels, opts })?;
            }
        }
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
        emit(&encode(&Line {
            body: Body::of(&summaries),
            json: self.json.as_deref(),
            out: self.figure.as_ref().map(|f| f.0.as_str()),
        })?)
    }
}
