use super::*;
use crate::error::Error;
use crate::scenario::presets::{iclgnss2019, sensors2019};

#[test]
fn edits_recompile_the_model_and_rejected_ones_change_nothing() {
    let mut s = Session::new(sensors2019()).unwrap();
    assert_eq!(s.edit(|sc| sc.add_receiver([3.0, 4.0])), Ok(4));
    assert_eq!(s.model().link_count(), 5);
    assert_eq!(s.model(), &Model::new(s.scenario()).unwrap());
    let before = s.clone();
    assert!(matches!(
        s.edit(|sc| sc.set_bandwidth_hz(0.0)),
        Err(Error::OutOfRange { .. })
    ));
    assert!(s.edit(|sc| sc.remove_transmitter(0)).is_err());
    let mut bad = iclgnss2019();
    bad.target.rcs_m2 = -1.0;
    assert!(s.replace(bad).is_err());
    assert_eq!(s, before);
    s.replace(iclgnss2019()).unwrap();
    assert_eq!(s.model().link_count(), 3);
}

/// Edits reuse compiled patterns (`Model::recompile`); every model must still equal a fresh
/// compile of its scenario, through moves, pattern and gain changes, added and removed
/// transmitters (indices shift) and replacements.
#[test]
fn reused_patterns_give_the_model_of_a_fresh_compile() {
    use crate::scenario::Pattern;
    let mut s = Session::new(sensors2019()).unwrap();
    let fresh = |s: &Session| Model::new(s.scenario()).unwrap();
    let beam = |b: f64| Pattern::Parabolic {
        boresight_deg: b,
        beamwidth_deg: 30.0,
        floor_db: 25.0,
    };
    s.edit(|sc| sc.move_receiver(1, [3.5, 7.25])).unwrap();
    assert_eq!(s.model(), &fresh(&s));
    s.edit(|sc| sc.add_transmitter([1.0, 2.0]).map(|_| ()))
        .unwrap();
    s.edit(|sc| sc.set_tx_pattern(1, beam(70.0))).unwrap();
    assert_eq!(s.model(), &fresh(&s));
    // Only the boresight turns: the pattern is turned, not refitted, and equals a fresh one.
    for b in [71.5, -123.25, 359.9, 0.0] {
        s.edit(|sc| sc.set_tx_pattern(1, beam(b))).unwrap();
        assert_eq!(s.model(), &fresh(&s), "boresight {b}");
    }
    s.edit(|sc| sc.move_transmitter(0, [4.0, -1.0])).unwrap();
    s.edit(|sc| sc.set_tx_gain_dbi(0, 3.0)).unwrap();
    assert_eq!(s.model(), &fresh(&s));
    s.edit(|sc| sc.remove_transmitter(0)).unwrap();
    assert_eq!(s.model(), &fresh(&s));
    assert_eq!(s.model().patterns.len(), 1);
    s.edit(|sc| sc.set_tx_pattern(0, Pattern::Omni)).unwrap();
    assert_eq!(s.model(), &fresh(&s));
    s.replace(sensors2019()).unwrap();
    assert_eq!(s.model(), &fresh(&s));
    s.replace(iclgnss2019()).unwrap();
    assert_eq!(s.model(), &fresh(&s));
}
