//! `track --out FIG.{svg,png} [--truth FILE]`: the track's figure. It shows the filter's own 1σ
//! position uncertainty `√(P_xx + P_yy)` over time. With a truth file (e.g. `simulate-walk`'s
//! `truth.json`) it adds the position error `‖r̂ − r‖`, and for raw steps the number of links
//! used (right-hand scale: every link on top, none at zero).

use plotters::coord::Shift;
use plotters::prelude::*;
use scatterloc::chart::{
    draw_curves, ChartError, CurveChartOptions, CurveSeries, LineKind, Marker,
};
use scatterloc::formats::Truth;

use super::flags::in_file;
use super::io::read_json_file;
use super::output::{write_figure, Figure, Format};
use crate::failure::CliError;

/// What the figure is drawn from.
pub struct TrackSeries<'a> {
    /// Times of the filter states, s.
    pub t_s: &'a [f64],
    /// Filter states `[x, y, vx, vy]`.
    pub states: &'a [[f64; 4]],
    /// Filter covariances.
    pub covariances: &'a [[[f64; 4]; 4]],
    /// Links used per step.
    pub links_used: &'a [usize],
    /// Number of links of the scenario.
    pub link_count: usize,
}

struct TrackFigure<'a> {
    series: Vec<CurveSeries<'a>>,
    opts: CurveChartOptions,
}

impl Figure for TrackFigure<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), ChartError> {
        draw_curves(root, &self.series, &self.opts)
    }
}

/// Reads `--truth` ([`Truth`]) and checks that its times are the track's.
pub fn read_truth(path: &str, t_s: &[f64]) -> Result<Truth, CliError> {
    let truth: Truth = read_json_file("truth", path)?;
    truth
        .check_times(t_s)
        .map_err(|e| in_file("truth", path, e))?;
    Ok(truth)
}

/// Writes the figure to `path` (format from its extension, checked by the caller).
pub fn write_track_figure(
    path: &str,
    format: Format,
    track: &TrackSeries,
    truth: Option<&Truth>,
    subtitle: String,
) -> Result<(), CliError> {
    let cm = |v: f64| 100.0 * v;
    let sigma: Vec<(f64, f64)> = track
        .t_s
        .iter()
        .zip(track.covariances)
        .map(|(t, p)| (*t, cm((p[0][0] + p[1][1]).max(0.0).sqrt())))
        .collect();
    let error: Vec<(f64, f64)> = truth.map_or_else(Vec::new, |tr| {
        track
            .t_s
            .iter()
            .zip(track.states.iter().zip(&tr.states))
            .map(|(t, (s, x))| (*t, cm((s[0] - x[0]).hypot(s[1] - x[1]))))
            .collect()
    });
    // The y range: the larger curve after the first tenth of the run (the start, from a wide
    // prior, would flatten the rest), at least 1 cm.
    let skip = track.t_s.len() / 10;
    let top = sigma
        .iter()
        .chain(&error)
        .skip(skip)
        .map(|p| p.1)
        .filter(|v| v.is_finite())
        .fold(1.0f64, f64::max)
        * 1.1;
    let links: Vec<(f64, f64)> = track
        .t_s
        .iter()
        .zip(track.links_used)
        .map(|(t, n)| (*t, top * *n as f64 / track.link_count.max(1) as f64))
        .collect();
    let mut series = vec![CurveSeries {
        label: "filter 1σ √(P_xx + P_yy)".into(),
        points: &sigma,
        colour: 0,
        line: LineKind::Solid,
        marker: Marker::None,
    }];
    if truth.is_some() {
        series.push(CurveSeries {
            label: "position error (estimate − truth)".into(),
            points: &error,
            colour: 1,
            line: LineKind::Solid,
            marker: Marker::None,
        });
    }
    series.push(CurveSeries {
        label: format!("links used (top = all {})", track.link_count),
        points: &links,
        colour: 2,
        line: LineKind::Dashed,
        marker: Marker::None,
    });
    let t_end = track.t_s.last().copied().unwrap_or(1.0).max(1e-9);
    let fig = TrackFigure {
        series,
        opts: CurveChartOptions {
            title: "EKF track".into(),
            subtitle: Some(subtitle),
            x_desc: "time t (s)".into(),
            y_desc: "position (cm)".into(),
            x_range: (0.0, t_end),
            y_range: (0.0, top * 1.05),
            legend: SeriesLabelPosition::UpperRight,
        },
    };
    write_figure("out", path, format, (1000, 620), &fig)
}
