//! Unit tests of [`crate::scenario`]: unique names, rollback, the last node, link lists, setters.

use alloc::string::ToString;
use alloc::vec::Vec;
use alloc::{format, vec};

use super::*;
use crate::scenario::presets::sensors2019;

fn names(s: &Scenario) -> Vec<&str> {
    let tx = s.transmitters.iter().map(|t| t.name.as_str());
    tx.chain(s.receivers.iter().map(|r| r.name.as_str()))
        .collect()
}

/// A sensors2019 copy with an explicit link list: Tx to Rx1 and Rx3 only.
fn listed() -> Scenario {
    let mut s = sensors2019();
    s.links = LinkSpec::List(vec![
        ["Tx".into(), "Rx1".into()],
        ["Tx".into(), "Rx3".into()],
    ]);
    s.validate().unwrap();
    s
}

#[test]
fn added_nodes_get_fresh_unique_names() {
    let mut s = sensors2019();
    assert_eq!(s.add_transmitter([1.0, 2.0]), Ok(1));
    assert_eq!(s.add_transmitter([3.0, 2.0]), Ok(2));
    assert_eq!(s.add_receiver([0.0, 5.0]), Ok(4));
    assert_eq!(names(&s)[1..3], ["Tx1", "Tx2"]);
    assert_eq!(s.receivers[4].name, "Rx5");
    let n = names(&s);
    assert!(
        n.iter().enumerate().all(|(i, a)| !n[..i].contains(a)),
        "{n:?}"
    );
    // The new transmitter copies the last one's radio settings.
    assert_eq!(s.transmitters[1].power_dbm, s.transmitters[0].power_dbm);
    assert_eq!(s.transmitters[1].position_m, [1.0, 2.0]);
    // The smallest free name is reused.
    s.remove_receiver(0).unwrap();
    assert_eq!(s.add_receiver([0.0, 0.5]), Ok(4));
    assert_eq!(s.receivers[4].name, "Rx1");
    s.validate().unwrap();
}

#[test]
fn rejected_edits_leave_the_scenario_bit_identical() {
    let mut s = listed();
    let before = s.clone();
    let json = s.to_json();
    let errors = [
        s.set_bandwidth_hz(-1.0).unwrap_err(),
        s.set_carrier_hz(f64::NAN).unwrap_err(),
        s.set_rcs_m2(0.0).unwrap_err(),
        s.set_noise_figure_db(500.0).unwrap_err(),
        s.set_tx_pattern_kind(0, "parabolic", 0.0, -3.0, 20.0)
            .unwrap_err(),
        s.set_tx_pattern_kind(0, "cardioid", 0.0, 70.0, 20.0)
            .unwrap_err(),
        s.move_transmitter(0, [f64::INFINITY, 1.0]).unwrap_err(),
        s.add_receiver([f64::NAN, 0.0]).unwrap_err(),
        s.set_area(Area {
            x: [1.0, 0.0],
            y: [0.0, 1.0],
        })
        .unwrap_err(),
        s.move_receiver(9, [1.0, 1.0]).unwrap_err(),
    ];
    let fields = [
        "radio.bandwidth_hz",
        "radio.carrier_hz",
        "target.rcs_m2",
        "radio.noise_figure_db",
        "transmitters[0].pattern.beamwidth_deg",
        "transmitters[0].pattern.kind",
        "transmitters[0].position_m",
        "receivers[4].position_m",
        "area_m.x",
        "receivers[9]",
    ];
    for (e, field) in errors.iter().zip(fields) {
        assert!(e.to_string().starts_with(field), "{e} should name {field}");
    }
    assert_eq!(s, before);
    assert_eq!(s.to_json(), json);
}

#[test]
fn the_last_node_cannot_be_removed() {
    let mut s = sensors2019();
    assert_eq!(
        s.remove_transmitter(0),
        Err(Error::LastNode {
            field: "transmitters"
        })
    );
    for _ in 0..3 {
        s.remove_receiver(0).unwrap();
    }
    let before = s.clone();
    let e = s.remove_receiver(0).unwrap_err();
    assert_eq!(e, Error::LastNode { field: "receivers" });
    assert!(e.to_string().starts_with("receivers:"), "{e}");
    assert_eq!(s, before);
    assert_eq!(
        s.remove_receiver(3),
        Err(Error::IndexOutOfRange {
            field: "receivers",
            index: 3,
            len: 1
        })
    );
}

#[test]
fn explicit_link_lists_follow_added_and_removed_nodes() {
    let pairs = |s: &Scenario| match &s.links {
        LinkSpec::List(l) => l.iter().map(|[t, r]| format!("{t}-{r}")).collect(),
        LinkSpec::All => Vec::new(),
    };
    let mut s = listed();
    s.add_receiver([2.0, 2.0]).unwrap();
    assert_eq!(pairs(&s), ["Tx-Rx1", "Tx-Rx3", "Tx-Rx5"]);
    s.add_transmitter([0.0, 3.0]).unwrap();
    assert_eq!(
        pairs(&s),
        ["Tx-Rx1", "Tx-Rx3", "Tx-Rx5", "Tx1-Rx1", "Tx1-Rx2", "Tx1-Rx3", "Tx1-Rx4", "Tx1-Rx5"]
    );
    s.remove_receiver(0).unwrap();
    assert_eq!(
        pairs(&s),
        ["Tx-Rx3", "Tx-Rx5", "Tx1-Rx2", "Tx1-Rx3", "Tx1-Rx4", "Tx1-Rx5"]
    );
    s.remove_transmitter(0).unwrap();
    assert_eq!(pairs(&s), ["Tx1-Rx2", "Tx1-Rx3", "Tx1-Rx4", "Tx1-Rx5"]);
    assert_eq!(s.link_indices().unwrap().len(), 4);
    // "all" stays "all".
    let mut all = sensors2019();
    all.add_receiver([1.0, 1.0]).unwrap();
    assert_eq!(all.links, LinkSpec::All);
    // A removal that would empty the list is rejected as a whole.
    let mut one = listed();
    one.links = LinkSpec::List(vec![["Tx".into(), "Rx2".into()]]);
    let before = one.clone();
    assert_eq!(one.remove_receiver(1), Err(Error::EmptyLinkList));
    assert_eq!(one, before);
}

#[test]
fn setters_land_in_the_scenario() {
    let mut s = sensors2019();
    s.radio.noise_figure_db = None;
    s.radio.noise_power_dbm = Some(-90.0);
    s.set_noise_figure_db(7.0).unwrap();
    assert_eq!(
        (s.radio.noise_figure_db, s.radio.noise_power_dbm),
        (Some(7.0), None)
    );
    s.set_carrier_hz(2.4e9).unwrap();
    s.set_bandwidth_hz(2e7).unwrap();
    s.set_rcs_m2(2.5).unwrap();
    s.set_tx_power_dbm(0, 30.0).unwrap();
    s.set_tx_gain_dbi(0, 6.0).unwrap();
    s.set_rx_gain_dbi(3, 2.0).unwrap();
    s.set_tx_pattern_kind(0, "omni", f64::NAN, f64::NAN, f64::NAN)
        .unwrap();
    s.move_receiver(1, [1.5, -2.25]).unwrap();
    let area = Area {
        x: [-1.0, 1.0],
        y: [-2.0, 2.0],
    };
    s.set_area(area).unwrap();
    assert_eq!((s.radio.carrier_hz, s.radio.bandwidth_hz), (2.4e9, 2e7));
    assert_eq!((s.target.rcs_m2, s.transmitters[0].power_dbm), (2.5, 30.0));
    assert_eq!(
        (s.transmitters[0].gain_dbi, s.receivers[3].gain_dbi),
        (6.0, 2.0)
    );
    assert_eq!(s.transmitters[0].pattern, Pattern::Omni);
    assert_eq!((s.receivers[1].position_m, s.area_m), ([1.5, -2.25], area));
}
