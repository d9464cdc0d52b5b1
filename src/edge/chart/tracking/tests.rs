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
