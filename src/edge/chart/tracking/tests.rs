use super::*;

static EKF_LABEL: std::sync::LazyLock<String> =
    std::sync::LazyLock::new(|| crate::study::curve_label("ekf", true));

#[test]
fn range_and_gaps() {
    let t = [0.0, 1.0, 2.0, 3.0];
    let ekf = [0.447, 0.02, Real::NAN, 0.004];
    let pcrlb = [Some(0.447), None, Some(0.01), Some(0.0022)];
    let curves = [FilterCurve {
        label: EKF_LABEL.as_str(),
        rmse_m: &ekf,
    }];
    let p = FiltersPanel {
        title: "I",
        t_s: &t,
        curves: &curves,
        rmse_pcrlb_m: &pcrlb,
        legend_note: None,
    };
    let (lo, hi) = y_range(&[p]);
    // 2.2 mm is within 15 % of 2 mm: one more 1-2-5 step below; 0.447 m fits under 0.5 m.
    assert_eq!((lo, hi), (0.001, 0.5));
    let drawable = |t: Real, v: Real| t.is_finite() && v.is_finite() && v > 0.0;
    let parts = segments(t.iter().copied().zip(ekf.iter().copied()), drawable);
    assert_eq!(parts.len(), 2);
    assert_eq!(parts[1], [(3.0, 0.004)]);
    let bound = pcrlb.iter().map(|v| v.unwrap_or(Real::NAN));
    assert_eq!(segments(t.iter().copied().zip(bound), drawable).len(), 2);
    assert_eq!(y_range(&[]), (1e-3, 1.0));
}

/// The SVG of `draw` on a 1000 × 620 canvas.
fn svg_of(
    draw: impl FnOnce(&DrawingArea<SVGBackend, Shift>) -> Result<(Real, Real), ChartError>,
) -> String {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (1000, 620)).into_drawing_area();
        draw(&root).unwrap();
        root.present().unwrap();
    }
    svg
}

#[test]
fn tracking_figure_of_one_and_of_two_filters() {
    let t = [0.0, 1.0, 2.0, 3.0];
    let ekf = [0.447, 0.02, 0.01, 0.004];
    let ukf = [0.447, 0.03, 0.012, 0.005];
    let pcrlb = [Some(0.447), Some(0.015), Some(0.01), Some(0.0022)];
    let opts = TrackingChartOptions {
        title: "t".into(),
        subtitle: None,
    };
    let one = [FilterCurve {
        label: EKF_LABEL.as_str(),
        rmse_m: &ekf,
    }];
    let panel = |curves| FiltersPanel {
        title: "I",
        t_s: &t,
        curves,
        rmse_pcrlb_m: &pcrlb,
        legend_note: None,
    };
    let single = svg_of(|root| draw_tracking_filters(root, &[panel(&one)], &opts));
    assert!(single.contains("EKF RMSE  ε_EKF"), "{single}");
    let two = [
        one[0],
        FilterCurve {
            label: "UKF RMSE",
            rmse_m: &ukf,
        },
    ];
    let both = svg_of(|root| draw_tracking_filters(root, &[panel(&two)], &opts));
    // The UKF curve takes the palette's third colour.
    let c = crate::chart::CURVE_PALETTE[2];
    let ukf_rgb = format!("#{:02X}{:02X}{:02X}", c.0, c.1, c.2);
    assert!(
        both.contains("UKF RMSE") && both.contains(&ukf_rgb),
        "{both}"
    );
    let short = [FilterCurve {
        label: "PF RMSE",
        rmse_m: &ukf[..2],
    }];
    let mut svg = String::new();
    let root = SVGBackend::with_string(&mut svg, (1000, 620)).into_drawing_area();
    let e = draw_tracking_filters(&root, &[panel(&short)], &opts).unwrap_err();
    assert!(e.0.contains("PF RMSE"), "{}", e.0);
}

/// The failed counts in the labels and the legend's last row saying what "failed" means (issue
/// 26): both in the SVG's text, the note after every curve's label.
#[test]
fn legend_names_failed_runs_and_what_failed_means() {
    let t = [0.0, 1.0, 2.0];
    let pf = [0.4, 0.02, 0.01];
    let pcrlb = [Some(0.4), Some(0.015), Some(0.008)];
    let label = crate::study::failed_label("pf", 3, 192);
    assert_eq!(label, "PF RMSE (3/192 failed)");
    let curves = [FilterCurve {
        label: &label,
        rmse_m: &pf,
    }];
    let panel = FiltersPanel {
        title: "Scenario I",
        t_s: &t,
        curves: &curves,
        rmse_pcrlb_m: &pcrlb,
        legend_note: Some(crate::study::FAILED_NOTE),
    };
    let opts = TrackingChartOptions {
        title: "t".into(),
        subtitle: None,
    };
    let svg = svg_of(|root| draw_tracking_filters(root, &[panel], &opts));
    let at = |s: &str| svg.find(s).unwrap_or_else(|| panic!("{s} not in {svg}"));
    assert!(at("PF RMSE (3/192 failed)") < at("failed = filter broke down"));
    assert!(at("posterior CRLB") < at("failed = filter broke down"));
}

/// Issue 38 §8: the filters' curves differ in line style as well as colour (EKF one solid
/// polyline, UKF and PF many dashes of different lengths), their legend samples too, and a title
/// wider than the figure is drawn smaller to fit.
#[test]
fn curves_differ_in_dash_pattern_and_long_titles_fit() {
    let t: Vec<Real> = (0..=50).map(|k| k as Real * 0.2).collect();
    let ekf: Vec<Real> = t.iter().map(|t| 0.4 / (1.0 + t)).collect();
    let ukf: Vec<Real> = ekf.iter().map(|v| v * 1.1).collect();
    let pf: Vec<Real> = ekf.iter().map(|v| v * 1.3).collect();
    let pcrlb: Vec<Option<Real>> = ekf.iter().map(|v| Some(v * 0.8)).collect();
    let curves = [
        FilterCurve {
            label: "EKF RMSE",
            rmse_m: &ekf,
        },
        FilterCurve {
            label: "UKF RMSE",
            rmse_m: &ukf,
        },
        FilterCurve {
            label: "PF RMSE",
            rmse_m: &pf,
        },
    ];
    let panel = FiltersPanel {
        title: "Scenario I",
        t_s: &t,
        curves: &curves,
        rmse_pcrlb_m: &pcrlb,
        legend_note: None,
    };
    let title = "Position RMSE: EKF, UKF, PF vs posterior CRLB (partial: EKF 200 of 200, UKF 200 of 200, PF 16 of 192 runs)";
    let opts = TrackingChartOptions {
        title: title.into(),
        subtitle: None,
    };
    let svg = svg_of(|root| draw_tracking_filters(root, &[panel], &opts));
    // Polylines per curve colour, and their mean number of points.
    let lines = |c: RGBColor| {
        let rgb = format!("stroke=\"#{:02X}{:02X}{:02X}\"", c.0, c.1, c.2);
        svg.lines()
            .filter(|l| l.contains("<polyline") && l.contains(&rgb))
            .count()
    };
    let (e, u, p) = (
        lines(CURVE_RGB[0]),
        lines(CURVE_RGB[1]),
        lines(CURVE_RGB[2]),
    );
    // EKF: the curve and its legend sample; UKF (dotted) more dashes than PF (long dashes).
    assert_eq!(e, 2, "{svg}");
    assert!(u > p && p > 5, "UKF {u}, PF {p} dashes");
    // The title at 32 px would be ~1500 px wide: drawn smaller than 32 px.
    let lines: Vec<&str> = svg.lines().collect();
    let at = lines
        .iter()
        .position(|l| l.contains("partial: EKF"))
        .expect("the title");
    let size = lines[at - 1]
        .split("font-size=\"")
        .nth(1)
        .and_then(|s| s.split('"').next())
        .and_then(|s| s.parse::<f64>().ok())
        .unwrap_or_else(|| panic!("title font size in {}", lines[at - 1]));
    assert!(size < 30.0, "title font {size}");
}
