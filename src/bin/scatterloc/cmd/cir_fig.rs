//! The figures of `cir track`: `--delays-figure` ([S] Fig. 4 per link, from
//! [`scatterloc::present::delay_figure`]) and `--figure` (the track on the map, the position
//! error over time and its CDF, [S] Figs. 5–6), drawn by `scatterloc::chart::channel` and staged
//! with the command's other files.

use plotters::coord::Shift;
use plotters::prelude::*;
use scatterloc::channel::{Band, Recording};
use scatterloc::chart::{
    delays_size, delays_svg, draw_delays, draw_track_errors, scenario_nodes, track_errors_size,
    ChannelChartOptions, ChartError,
};
use scatterloc::formats::Truth;
use scatterloc::present::{delay_figure, link_names, DelayFigure, TrackErrorView};
use scatterloc::study::{CirTrackOutput, RecordingEstimates};
use scatterloc::track::gating::Calibration;
use scatterloc::{Model, Scenario};

use super::flags::at_flag;
use super::output::{Figure, Format, OutputSet};
use crate::failure::CliError;

struct Delays {
    fig: DelayFigure,
    opts: ChannelChartOptions,
}

impl Figure for Delays {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), ChartError> {
        draw_delays(root, &self.fig, &self.opts)
    }

    /// The images as one PNG per panel inside the SVG (issue 37 item 11).
    fn svg(&self, size: (u32, u32)) -> Option<Result<String, ChartError>> {
        Some(delays_svg(size, &self.fig, &self.opts))
    }
}

struct Errors<'a> {
    view: TrackErrorView,
    scenario: &'a Scenario,
    opts: ChannelChartOptions,
}

impl Figure for Errors<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), ChartError> {
        let nodes = scenario_nodes(self.scenario);
        draw_track_errors(root, &self.view, &nodes, &self.scenario.area_m, &self.opts)
    }
}

/// Stages `--delays-figure`.
#[allow(clippy::too_many_arguments)]
pub fn stage_delays_figure(
    files: &mut OutputSet,
    path: &str,
    format: Format,
    scenario: &Scenario,
    model: &Model,
    rec: &Recording,
    est: &RecordingEstimates,
    calibration: &Calibration,
    truth: Option<&Truth>,
) -> Result<(), CliError> {
    let fail = |e: &dyn std::fmt::Display| at_flag("delays-figure", e);
    let band = Band::of_recording(rec, scenario.radio.bandwidth_hz).map_err(|e| fail(&e))?;
    let fig = delay_figure(
        model,
        rec,
        &band,
        est,
        Some(calibration),
        truth.map(|t| t.states.as_slice()),
        &link_names(scenario, model),
    )
    .map_err(|e| fail(&e))?;
    let size = delays_size(fig.links.len());
    let opts = ChannelChartOptions {
        title: "Delay estimates per link ([S] Fig. 4)".into(),
        subtitle: Some(format!(
            "{} · {} snapshots · grey: static clusters (±3σ, E4) · dashed: truth",
            scenario.name,
            rec.t_s.len()
        )),
    };
    files.figure("delays-figure", path, format, size, &Delays { fig, opts })
}

/// Stages `--figure`.
pub fn stage_track_figure(
    files: &mut OutputSet,
    path: &str,
    format: Format,
    scenario: &Scenario,
    track: &CirTrackOutput,
    view: TrackErrorView,
    filter: &str,
) -> Result<(), CliError> {
    let opts = ChannelChartOptions {
        title: format!("Track from channel recordings ({filter}; [S] Figs. 5–6)"),
        subtitle: Some(format!(
            "{} · {} snapshots · start {}",
            scenario.name,
            track.t_s.len(),
            track
                .start
                .as_ref()
                .map_or("none".to_string(), |s| format!("at {:.3} s", s.t_s))
        )),
    };
    files.figure(
        "figure",
        path,
        format,
        track_errors_size(),
        &Errors {
            view,
            scenario,
            opts,
        },
    )
}
