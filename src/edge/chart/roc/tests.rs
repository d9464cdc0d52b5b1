use super::*;

#[test]
fn segments_skip_non_finite_points() {
    let p = [(0.0, 0.1), (0.2, Real::NAN), (0.3, 0.4), (0.5, 0.6)];
    let parts = segments(p.iter().copied(), |x, y| x.is_finite() && y.is_finite());
    assert_eq!(
        parts,
        [alloc::vec![(0.0, 0.1)], alloc::vec![(0.3, 0.4), (0.5, 0.6)]]
    );
}

#[test]
fn draws_an_svg_with_legend_and_rejects_empty_ranges() {
    let a = [(0.0, 0.0), (0.1, 0.5), (0.3, 0.9)];
    let series = [
        CurveSeries {
            label: "size rule".into(),
            points: &a,
            colour: 0,
            line: LineKind::Solid,
            marker: Marker::Dot,
        },
        CurveSeries {
            label: "Bayesian".into(),
            points: &a,
            colour: 0,
            line: LineKind::None,
            marker: Marker::Ring,
        },
        CurveSeries {
            label: "genie".into(),
            points: &a,
            colour: 7,
            line: LineKind::Dashed,
            marker: Marker::Square,
        },
    ];
    let opts = CurveChartOptions::roc("ROC".into(), Some("test".into()));
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (600, 480)).into_drawing_area();
        draw_curves(&root, &series, &opts).unwrap();
        root.present().unwrap();
    }
    assert!(svg.contains("size rule") && svg.contains("Bayesian") && svg.contains("genie"));
    assert!(svg.contains("P_FA") && svg.contains("<circle"));
    let bad = CurveChartOptions {
        x_range: (1.0, 1.0),
        ..opts
    };
    let mut svg = String::new();
    let root = SVGBackend::with_string(&mut svg, (600, 480)).into_drawing_area();
    assert!(draw_curves(&root, &series, &bad).is_err());
}
