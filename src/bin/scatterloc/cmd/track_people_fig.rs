//! `track --targets auto --figure F.{svg,png}`: the map of a several-people track at its last
//! scan — the page's "Several people" Save figure (`chart::draw_people_map` of
//! `present::people_map_view`: the nodes, every true path dashed, every labelled track in the
//! page's colour of its place with its label and its 1σ ellipse at true scale).

use plotters::coord::Shift;
use plotters::prelude::{DrawingArea, DrawingBackend};

use scatterloc::chart::{
    draw_people_map, people_titles, scenario_nodes, suggested_size, ChartError, PeopleChartOptions,
};
use scatterloc::present::{people_map_view, PeopleMapView};
use scatterloc::study::{MultiTrackOutput, MultiTruth};
use scatterloc::Scenario;

use super::output::{write_figure, Figure, Format};
use crate::failure::CliError;

/// The figure's width, px (the page's SVG width); the height fits the plot.
const WIDTH: u32 = 1000;

struct PeopleFigure<'a> {
    scenario: &'a Scenario,
    view: PeopleMapView,
    opts: PeopleChartOptions,
}

impl Figure for PeopleFigure<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), ChartError> {
        draw_people_map(root, &scenario_nodes(self.scenario), &self.view, &self.opts)
    }
}

/// Writes the map of `track` (against `truth`, if any) at its last scan to `path`.
pub fn write_people_figure(
    path: &str,
    format: Format,
    scenario: &Scenario,
    track: &MultiTrackOutput,
    truth: Option<&MultiTruth>,
) -> Result<(), CliError> {
    let none = MultiTruth {
        t_s: Vec::new(),
        targets: Vec::new(),
    };
    let truth = truth.unwrap_or(&none);
    let view = people_map_view(track, truth, usize::MAX)
        .map_err(|e| CliError::usage(format!("--figure: {e}")))?;
    let (title, subtitle) = people_titles(&scenario.name, track, truth, &view, 1.0);
    let area = scenario.area_m;
    let figure = PeopleFigure {
        scenario,
        view,
        opts: PeopleChartOptions {
            title,
            subtitle: Some(subtitle),
            window: area,
            magnify: 1.0,
        },
    };
    write_figure(
        "figure",
        path,
        format,
        suggested_size(&area, WIDTH),
        &figure,
    )
}
