use super::*;

fn labels(t: &[BarTick]) -> Vec<&str> {
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
    assert!(t.iter().all(|t| t.value_m >= 0.00105 && t.value_m <= 1.13));
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
