//! The [S] Fig. 4 view of a recording (issue 25 §4): per link the delay profile of the
//! responses as an image, the front end's estimates coloured by amplitude, the static clusters
//! of the calibration (E4 bands) and the person's true path length when a truth is known —
//! assembled once here for the CLI's `--delays-figure` and the page's channel view.

use alloc::format;
use alloc::string::String;
use alloc::vec;
use alloc::vec::Vec;

use crate::channel::{Band, Recording, ResponseMap};
use crate::error::limits::MAX_DELAY_IMAGE_COLS;
use crate::error::Result;
use crate::math::{Complex, Real, Vec2, SPEED_OF_LIGHT};
use crate::measure::Model;
use crate::present::{
    delay_image, delay_points, static_bands, suggest_range_m, DelayFigure, ImageConfig, LinkDelays,
    TruthCurve,
};
use crate::study::RecordingEstimates;
use crate::track::gating::Calibration;

/// The delay figure of `rec` on `model`'s links: `names[p]` labels link `p`; `truth` the true
/// states per snapshot of `rec` (any file with `t_s` and `states`), drawn as the person's
/// bistatic path length `c·τ_p(r(t))` (E1). At most [`MAX_DELAY_IMAGE_COLS`] snapshots are
/// imaged (evenly spread); every estimate is drawn. [`delay_figure_link`] link by link.
pub fn delay_figure(
    model: &Model,
    rec: &Recording,
    band_map: &(Band, ResponseMap),
    estimates: &RecordingEstimates,
    calibration: Option<&Calibration>,
    truth: Option<&[[Real; 4]]>,
    names: &[String],
) -> Result<DelayFigure> {
    let links = (0..model.link_count())
        .map(|p| {
            delay_figure_link(
                model,
                rec,
                band_map,
                estimates,
                calibration,
                truth,
                names,
                p,
            )
        })
        .collect::<Result<Vec<_>>>()?;
    Ok(DelayFigure::new(&rec.t_s, links))
}

/// The panel of model link `p` of [`delay_figure`] (the page's worker makes them one at a
/// time, reporting its progress between two). `DelayFigure::new(&rec.t_s, panels)` assembles
/// the figure.
#[allow(clippy::too_many_arguments)]
pub fn delay_figure_link(
    model: &Model,
    rec: &Recording,
    (band, map): &(Band, ResponseMap),
    estimates: &RecordingEstimates,
    calibration: Option<&Calibration>,
    truth: Option<&[[Real; 4]]>,
    names: &[String],
    p: usize,
) -> Result<LinkDelays> {
    let lmap = rec.link_map(model)?;
    let s = rec.t_s.len();
    let cols = s.min(MAX_DELAY_IMAGE_COLS);
    let shown: Vec<usize> = (0..cols)
        .map(|i| ((2 * i + 1) * s / (2 * cols.max(1))).min(s.saturating_sub(1)))
        .collect();
    let t_shown: Vec<Real> = shown.iter().map(|&k| rec.t_s[k]).collect();
    let unambiguous_m = SPEED_OF_LIGHT * band.unambiguous_s();
    let mut h = Vec::new();
    let lists: Vec<_> = (0..estimates.len())
        .map(|k| {
            estimates.paths[k][p]
                .iter()
                .map(|t| t.estimate)
                .collect::<Vec<_>>()
        })
        .collect();
    let points = delay_points(&estimates.t_s, &lists);
    let statics = calibration
        .and_then(|c| c.links.get(p))
        .map(static_bands)
        .unwrap_or_default();
    let truth_curves = match truth {
        Some(states) => vec![TruthCurve {
            kind: String::from("person"),
            primary: true,
            points: rec
                .t_s
                .iter()
                .zip(states)
                .map(|(&t, x)| {
                    (
                        t,
                        SPEED_OF_LIGHT * model.network.delay(p, Vec2::new(x[0], x[1])),
                    )
                })
                .collect(),
        }],
        None => Vec::new(),
    };
    let range_m = suggest_range_m(&points, &statics, &truth_curves, unambiguous_m);
    let image = match lmap.iter().position(|&m| m == p) {
        Some(r) if cols > 0 => {
            let mut hs: Vec<Vec<Complex>> = Vec::with_capacity(cols);
            for &k in &shown {
                map.fill(rec, k, r, &mut h)?;
                hs.push(h.clone());
            }
            Some(delay_image(
                &band.freq_hz,
                &t_shown,
                |i| hs[i].as_slice(),
                &ImageConfig::new(range_m),
            )?)
        }
        _ => None,
    };
    Ok(LinkDelays {
        name: names.get(p).cloned().unwrap_or_else(|| format!("link {p}")),
        range_m,
        image,
        estimates: points,
        statics,
        truth: truth_curves,
    })
}
