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
