use super::*;

#[test]
fn lengths() {
    assert_eq!(format_length_m(0.00426, 3), "4.26 mm");
    assert_eq!(format_length_m(0.0792, 3), "7.92 cm");
    assert_eq!(format_length_m(0.01, 3), "1 cm");
    assert_eq!(format_length_m(2.0, 3), "2 m");
    assert_eq!(format_length_m(5e-7, 3), "0.5 \u{b5}m");
    assert_eq!(format_length_m(Real::INFINITY, 3), "\u{221e}");
    assert_eq!(format_length_m(0.1769, 4), "17.69 cm");
}

#[test]
fn linear() {
    let t = linear_ticks(-7.5, 30.0, 8);
    let labels: Vec<_> = t.iter().map(|t| t.label.as_str()).collect();
    assert_eq!(
        labels,
        ["\u{2212}5", "0", "5", "10", "15", "20", "25", "30"]
    );
    let t = linear_ticks(0.0, 1.0, 4);
    assert_eq!(t[1].value, 0.5); // step 0.5: 0, 0.5, 1
    assert_eq!(t[1].label, "0.5");
    assert!(linear_ticks(1.0, 1.0, 5).is_empty());
}

#[test]
fn logs() {
    let t = log_length_ticks(0.003, 0.5);
    let labels: Vec<_> = t.iter().map(|t| t.label.as_str()).collect();
    assert_eq!(
        labels,
        ["5 mm", "1 cm", "2 cm", "5 cm", "10 cm", "20 cm", "50 cm"]
    );
    let t = log_length_ticks(1e-4, 10.0);
    assert_eq!(t.len(), 6);
    assert_eq!(log_length_ticks(1e-9, 1e3).len(), 7);
    assert_eq!(log_length_ticks(0.0042, 0.0043).len(), 2);
}

#[test]
fn bars() {
    assert_eq!(scale_bar(0.0073).unwrap().label, "5 mm");
    assert_eq!(scale_bar(0.02).unwrap().value, 0.02);
    assert!(scale_bar(0.0).is_none());
}

fn labels(t: &[Tick]) -> Vec<&str> {
    t.iter()
        .filter(|t| !t.label.is_empty())
        .map(|t| t.label.as_str())
        .collect()
}

#[test]
fn decades_with_minor_ticks() {
    let t = colorbar_ticks(0.00105, 1.13, 4);
    assert_eq!(labels(&t), ["1 cm", "10 cm", "1 m"]);
    assert!(t.iter().filter(|t| t.label.is_empty()).count() >= 20);
    assert!(t.iter().all(|t| t.value >= 0.00105 && t.value <= 1.13));
    let t = colorbar_ticks(0.00105, 1.13, 12);
    let l = labels(&t);
    assert!((3..=12).contains(&l.len()), "{l:?}");
    assert!(
        ["1 cm", "10 cm", "1 m"].iter().all(|x| l.contains(x)),
        "{l:?}"
    );
}

#[test]
fn thinned_to_fit() {
    let t = colorbar_ticks(1e-6, 1e3, 3);
    let n = labels(&t).len();
    assert!((2..=3).contains(&n), "{n}");
}

#[test]
fn flat_map_keeps_two_labels() {
    let t = colorbar_ticks(0.0079, 0.0081, 8);
    assert!(labels(&t).len() >= 2, "{t:?}");
}

/// Issue 12, item 6: spans like ±1e300 gave labels of 301 digits or, once the tick index
/// overflowed `i64`, ±9223372036854775808; a tiny span far from 0 overflowed (a debug panic).
#[test]
fn extreme_spans_give_short_exact_labels() {
    let t = linear_ticks(-1e300, 1e300, 3);
    assert_eq!(labels(&t), ["\u{2212}1e300", "0", "1e300"]);
    assert_eq!(t[2].value, 1e300);
    let t = linear_ticks(0.0, 2.5e13, 5);
    assert_eq!(
        labels(&t),
        ["0", "5e12", "1e13", "1.5e13", "2e13", "2.5e13"]
    );
    // Twelve digits are still written out.
    assert_eq!(labels(&linear_ticks(0.0, 2e11, 2))[2], "200000000000");
    assert_eq!(labels(&linear_ticks(0.0, 2e-12, 2))[1], "1e-12");
    assert_eq!(labels(&linear_ticks(0.0, 2e-11, 2))[1], "0.00000000001");
    assert_eq!(labels(&linear_ticks(0.0, 2e-10, 2))[1], "0.0000000001");
    // No 1-2-5 step fits: the two ends.
    let t = linear_ticks(1e3, 1e3 + 1e-13, 1000);
    assert_eq!(t.len(), 2);
    assert_eq!((t[0].value, t[1].value), (1e3, 1e3 + 1e-13));
    let t = linear_ticks(-1e300, -1e300 + 1e285, 3);
    assert!(t.iter().all(|t| t.label.len() < 30), "{t:?}");
    for t in log_length_ticks(5e-324, 1.7e308) {
        assert!(t.label.chars().count() < 16, "{t:?}");
    }
    assert_eq!(format_length_m(1.5e12, 3), "1.5e9 km");
    assert_eq!(format_length_m(-2e300, 3), "\u{2212}2e297 km");
    assert_eq!(format_length_m(5e-324, 3), "4.94e-318 \u{b5}m");
    assert_eq!(format_length_m(9.99e8, 3), "999000 km");
}
