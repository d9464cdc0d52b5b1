#![cfg(not(target_arch = "wasm32"))]
//! One test per bad-input class: the named `scatterloc::Error` variant is returned (never a
//! panic) and its `Display` names the offending field. Degenerate-but-valid geometry (a receiver
//! on a transmitter) gives finite or unbounded outputs, never NaN.

use scatterloc::localize::{self, DelayMeasurements, LmConfig};
use scatterloc::localize::{crlb_at, crlb_map, Grid, MAX_GRID_CELLS, MAX_GRID_SIDE};
use scatterloc::math::{Real, Vec2};
use scatterloc::scenario::presets::{self, preset};
use scatterloc::scenario::{Area, LinkSpec, Pattern, Scenario};
use scatterloc::{Error, Model};

use crate::common;

use common::noise_free;

const NAN: Real = Real::NAN;
const INF: Real = Real::INFINITY;

fn l4() -> Scenario {
    presets::sensors2019()
}

/// The scenario JSON of the L4 preset as a mutable `serde_json::Value`.
fn l4_json() -> serde_json::Value {
    serde_json::from_str(&l4().to_json()).unwrap()
}

fn parse(v: &serde_json::Value) -> Result<Scenario, Error> {
    Scenario::from_json(&serde_json::to_string(v).unwrap())
}

/// Asserts the error's Display mentions `needle` (the field path or name).
#[track_caller]
fn names(e: &Error, needle: &str) {
    let msg = e.to_string();
    assert!(
        msg.contains(needle),
        "Display {msg:?} should name {needle:?}"
    );
}

#[track_caller]
fn validate_err(s: &Scenario) -> Error {
    let e = s.validate().expect_err("invalid scenario accepted");
    // Model::new validates as well and must give the same error.
    assert_eq!(Model::new(s).expect_err("Model::new accepted it"), e);
    e
}

// ------------------------------------------------------------------------- JSON parsing

#[test]
fn json_valid_preset_parses() {
    // Baseline for the JSON tests below: the unmodified document is accepted.
    assert_eq!(parse(&l4_json()), Ok(l4()));
}

#[test]
fn json_syntax_error() {
    let e = Scenario::from_json("{ \"name\": \"x\", ").unwrap_err();
    assert!(matches!(e, Error::Parse { .. }), "{e:?}");
    names(&e, "invalid JSON");
    names(&e, "line 1");
    let e = Scenario::from_json("").unwrap_err();
    assert!(matches!(e, Error::Parse { .. }), "{e:?}");
}

#[test]
fn json_missing_number_field() {
    let mut v = l4_json();
    v["radio"].as_object_mut().unwrap().remove("bandwidth_hz");
    let e = parse(&v).unwrap_err();
    assert!(matches!(e, Error::Parse { .. }), "{e:?}");
    names(&e, "bandwidth_hz");
    let mut v = l4_json();
    v["receivers"][1]
        .as_object_mut()
        .unwrap()
        .remove("gain_dbi");
    let e = parse(&v).unwrap_err();
    assert!(matches!(e, Error::Parse { .. }), "{e:?}");
    names(&e, "gain_dbi");
}

#[test]
fn json_unknown_field_typo() {
    let mut v = l4_json();
    let radio = v["radio"].as_object_mut().unwrap();
    let b = radio.remove("bandwidth_hz").unwrap();
    radio.insert("bandwith_hz".into(), b);
    let e = parse(&v).unwrap_err();
    assert!(matches!(e, Error::Parse { .. }), "{e:?}");
    names(&e, "bandwith_hz");
    // A typo at top level and inside a pattern too.
    let mut v = l4_json();
    v.as_object_mut()
        .unwrap()
        .insert("reciever".into(), serde_json::json!([]));
    let e = parse(&v).unwrap_err();
    names(&e, "reciever");
    let mut v = l4_json();
    v["transmitters"][0]["pattern"]
        .as_object_mut()
        .unwrap()
        .insert("beamwidth".into(), serde_json::json!(70.0));
    let e = parse(&v).unwrap_err();
    names(&e, "beamwidth");
}

#[test]
fn json_number_overflow_is_a_parse_error() {
    // JSON cannot carry NaN/∞; an out-of-range literal is rejected by the parser.
    let text = l4().to_json().replace("120000000.0", "1e999");
    assert_ne!(text, l4().to_json());
    let e = Scenario::from_json(&text).unwrap_err();
    assert!(matches!(e, Error::Parse { .. }), "{e:?}");
    names(&e, "line");
}

// ------------------------------------------------------------------------- non-finite numbers

#[test]
fn non_finite_numbers_name_the_field() {
    type Edit = fn(&mut Scenario);
    let cases: Vec<(&str, Edit)> = vec![
        ("radio.carrier_hz", |s| s.radio.carrier_hz = NAN),
        ("radio.bandwidth_hz", |s| s.radio.bandwidth_hz = INF),
        ("radio.noise_figure_db", |s| {
            s.radio.noise_figure_db = Some(NAN)
        }),
        ("radio.noise_power_dbm", |s| {
            s.radio.noise_figure_db = None;
            s.radio.noise_power_dbm = Some(-INF);
        }),
        ("radio.processing_gain_db", |s| {
            s.radio.processing_gain_db = Some(INF)
        }),
        ("transmitters[0].position_m", |s| {
            s.transmitters[0].position_m[1] = NAN
        }),
        ("transmitters[0].power_dbm", |s| {
            s.transmitters[0].power_dbm = INF
        }),
        ("transmitters[0].gain_dbi", |s| {
            s.transmitters[0].gain_dbi = NAN
        }),
        ("transmitters[0].pattern.boresight_deg", |s| {
            s.transmitters[0].pattern = Pattern::Parabolic {
                boresight_deg: NAN,
                beamwidth_deg: 70.0,
                floor_db: 20.0,
            }
        }),
        ("transmitters[0].pattern.beamwidth_deg", |s| {
            s.transmitters[0].pattern = Pattern::Parabolic {
                boresight_deg: 10.0,
                beamwidth_deg: INF,
                floor_db: 20.0,
            }
        }),
        ("transmitters[0].pattern.floor_db", |s| {
            s.transmitters[0].pattern = Pattern::Parabolic {
                boresight_deg: 10.0,
                beamwidth_deg: 70.0,
                floor_db: NAN,
            }
        }),
        ("receivers[2].position_m", |s| {
            s.receivers[2].position_m[0] = -INF
        }),
        ("receivers[3].gain_dbi", |s| s.receivers[3].gain_dbi = NAN),
        ("target.rcs_m2", |s| s.target.rcs_m2 = NAN),
        ("area_m.x", |s| s.area_m.x[1] = INF),
        ("area_m.y", |s| s.area_m.y[0] = NAN),
    ];
    for (field, edit) in cases {
        let mut s = l4();
        edit(&mut s);
        let e = validate_err(&s);
        assert_eq!(
            e,
            Error::NonFinite {
                field: field.into()
            },
            "{field}"
        );
        names(&e, field);
    }
}

// ------------------------------------------------------------------------- structure

#[test]
fn empty_transmitters() {
    let mut s = l4();
    s.transmitters.clear();
    let e = validate_err(&s);
    assert_eq!(
        e,
        Error::EmptyNodeList {
            field: "transmitters"
        }
    );
    names(&e, "transmitters");
}

#[test]
fn empty_receivers() {
    let mut s = l4();
    s.receivers.clear();
    let e = validate_err(&s);
    assert_eq!(e, Error::EmptyNodeList { field: "receivers" });
    names(&e, "receivers");
}

#[test]
fn duplicate_names() {
    let mut s = l4();
    s.receivers[3].name = "Rx1".into();
    let e = validate_err(&s);
    assert_eq!(e, Error::DuplicateName { name: "Rx1".into() });
    names(&e, "\"Rx1\"");
    // Names are unique across transmitters and receivers.
    let mut s = l4();
    s.receivers[0].name = "Tx".into();
    let e = validate_err(&s);
    assert_eq!(e, Error::DuplicateName { name: "Tx".into() });
    names(&e, "\"Tx\"");
}

fn with_links(pairs: &[[&str; 2]]) -> Scenario {
    let mut s = l4();
    s.links = LinkSpec::List(
        pairs
            .iter()
            .map(|[t, r]| [t.to_string(), r.to_string()])
            .collect(),
    );
    s
}

#[test]
fn link_names_unknown_node() {
    let e = validate_err(&with_links(&[["Tx", "Rx1"], ["Tx", "Rx9"]]));
    assert_eq!(
        e,
        Error::UnknownNode {
            field: "links[1][1]".into(),
            name: "Rx9".into()
        }
    );
    names(&e, "links[1][1]");
    names(&e, "Rx9");
    // A receiver where a transmitter is expected is unknown as a transmitter.
    let e = validate_err(&with_links(&[["Rx2", "Rx1"]]));
    assert_eq!(
        e,
        Error::UnknownNode {
            field: "links[0][0]".into(),
            name: "Rx2".into()
        }
    );
    names(&e, "links[0][0]");
}

#[test]
fn duplicate_link() {
    let e = validate_err(&with_links(&[["Tx", "Rx1"], ["Tx", "Rx2"], ["Tx", "Rx1"]]));
    assert_eq!(
        e,
        Error::DuplicateLink {
            tx: "Tx".into(),
            rx: "Rx1".into()
        }
    );
    names(&e, "links");
    names(&e, "Rx1");
}

#[test]
fn empty_link_list() {
    let e = validate_err(&with_links(&[]));
    assert_eq!(e, Error::EmptyLinkList);
    names(&e, "links");
    // Same from JSON.
    let mut v = l4_json();
    v["links"] = serde_json::json!([]);
    assert_eq!(parse(&v), Err(Error::EmptyLinkList));
    // A links string other than "all" is a parse error naming the accepted forms.
    v["links"] = serde_json::json!("none");
    let e = parse(&v).unwrap_err();
    assert!(matches!(e, Error::Parse { .. }), "{e:?}");
    names(&e, "all");
}

// ------------------------------------------------------------------------- ranges

#[track_caller]
/// A value outside its documented range ([`scatterloc::error::limits`]) is named with that range.
fn not_positive(field: &str, value: Real, edit: impl Fn(&mut Scenario)) {
    let mut s = l4();
    edit(&mut s);
    let e = validate_err(&s);
    assert!(
        matches!(&e, Error::OutOfRange { field: f, value: v, .. } if f == field && *v == value),
        "{e:?}"
    );
    names(&e, field);
}

#[test]
fn bandwidth_not_positive() {
    not_positive("radio.bandwidth_hz", 0.0, |s| s.radio.bandwidth_hz = 0.0);
    not_positive("radio.bandwidth_hz", -1e6, |s| s.radio.bandwidth_hz = -1e6);
}

#[test]
fn rcs_not_positive() {
    not_positive("target.rcs_m2", 0.0, |s| s.target.rcs_m2 = 0.0);
    not_positive("target.rcs_m2", -1.0, |s| s.target.rcs_m2 = -1.0);
}

#[test]
fn carrier_not_positive() {
    not_positive("radio.carrier_hz", 0.0, |s| s.radio.carrier_hz = 0.0);
    not_positive("radio.carrier_hz", -5.2e9, |s| s.radio.carrier_hz = -5.2e9);
    // From JSON too.
    let mut v = l4_json();
    v["radio"]["carrier_hz"] = serde_json::json!(-1.0);
    let e = parse(&v).unwrap_err();
    assert!(matches!(e, Error::OutOfRange { .. }), "{e:?}");
    names(&e, "radio.carrier_hz");
}

#[test]
fn inverted_area() {
    let mut s = l4();
    s.area_m.x = [5.0, 5.0]; // min == max is inverted too (min must be below max)
    let e = validate_err(&s);
    assert_eq!(
        e,
        Error::InvertedArea {
            field: "area_m.x",
            min: 5.0,
            max: 5.0
        }
    );
    names(&e, "area_m.x");
    let mut s = l4();
    s.area_m.y = [3.0, -3.0];
    let e = validate_err(&s);
    assert_eq!(
        e,
        Error::InvertedArea {
            field: "area_m.y",
            min: 3.0,
            max: -3.0
        }
    );
    names(&e, "area_m.y");
}

#[test]
fn both_noise_figure_and_noise_power() {
    let mut s = l4();
    s.radio.noise_figure_db = Some(10.0);
    s.radio.noise_power_dbm = Some(-83.0);
    let e = validate_err(&s);
    assert_eq!(e, Error::AmbiguousNoise);
    names(&e, "noise_figure_db");
    names(&e, "noise_power_dbm");
}

#[test]
fn beamwidth_out_of_range() {
    let field = "transmitters[0].pattern.beamwidth_deg";
    for bw in [0.0, -5.0, 360.5, 1000.0] {
        let mut s = l4();
        s.transmitters[0].pattern = Pattern::Parabolic {
            boresight_deg: 10.0,
            beamwidth_deg: bw,
            floor_db: 20.0,
        };
        let e = validate_err(&s);
        assert!(
            matches!(&e, Error::OutOfRange { field: f, value, .. } if f == field && *value == bw),
            "{e:?}"
        );
        names(&e, field);
    }
    // The limits themselves are allowed: 360° is valid.
    let mut s = l4();
    s.transmitters[0].pattern = Pattern::Parabolic {
        boresight_deg: 10.0,
        beamwidth_deg: 360.0,
        floor_db: 20.0,
    };
    assert_eq!(s.validate(), Ok(()));
}

#[test]
fn other_out_of_range_fields() {
    let mut s = l4();
    s.transmitters[0].pattern = Pattern::Parabolic {
        boresight_deg: 10.0,
        beamwidth_deg: 70.0,
        floor_db: -1.0,
    };
    let e = validate_err(&s);
    assert!(matches!(&e, Error::OutOfRange { .. }), "{e:?}");
    names(&e, "transmitters[0].pattern.floor_db");
    let mut s = l4();
    s.radio.noise_figure_db = Some(-3.0);
    let e = validate_err(&s);
    assert!(matches!(&e, Error::OutOfRange { .. }), "{e:?}");
    names(&e, "radio.noise_figure_db");
    let mut s = l4();
    s.radio.processing_gain_db = Some(-1.0);
    let e = validate_err(&s);
    assert!(matches!(&e, Error::OutOfRange { .. }), "{e:?}");
    names(&e, "radio.processing_gain_db");
}

// ------------------------------------------------------------------------- LM input

struct Fixture {
    model: Model,
    area: Area,
    delays: Vec<Option<Real>>,
    sigmas: Vec<Real>,
}

fn lm_fixture() -> Fixture {
    let s = l4();
    let model = Model::new(&s).unwrap();
    let truth = Vec2::new(4.0, 1.0);
    let (delays, sigmas) = noise_free(&model, truth);
    Fixture {
        model,
        area: s.area_m,
        delays,
        sigmas,
    }
}

impl Fixture {
    fn locate(&self, initial: Option<Vec2>) -> Result<localize::LmReport, Error> {
        let m = DelayMeasurements {
            delays_s: &self.delays,
            sigmas_s: &self.sigmas,
        };
        localize::locate(
            &self.model.network,
            &m,
            &LmConfig::default(),
            initial,
            &self.area,
        )
    }
}

#[test]
fn lm_fixture_is_valid() {
    // Baseline for the LM tests: the unmodified fixture gives a converged fix.
    let f = lm_fixture();
    let rep = f.locate(Some(Vec2::new(5.0, 2.0))).unwrap();
    assert!(rep.termination.converged());
    assert!((rep.position - Vec2::new(4.0, 1.0)).norm() < 1e-6);
}

#[test]
fn lm_fewer_than_three_links() {
    let mut f = lm_fixture();
    f.delays[0] = None;
    // Three left: still fine (spec §5 needs ≥ 3).
    assert!(f.locate(Some(Vec2::new(4.0, 1.0))).is_ok());
    f.delays[2] = None;
    let e = f.locate(Some(Vec2::new(4.0, 1.0))).unwrap_err();
    assert_eq!(
        e,
        Error::TooFewLinks {
            available: 2,
            required: 3
        }
    );
    names(&e, "delays_s");
    f.delays = vec![None; 4];
    let e = f.locate(None).unwrap_err();
    assert_eq!(
        e,
        Error::TooFewLinks {
            available: 0,
            required: 3
        }
    );
}

#[test]
fn lm_non_finite_delay() {
    // Also zero, negative and absurd delays (issue 12, item 7: `locate` reported `converged` at
    // (0, 0) with cost 3e7 for negative delays).
    for bad in [NAN, INF, -INF, 0.0, -1e-7, 2.0, 1e308] {
        let mut f = lm_fixture();
        f.delays[1] = Some(bad);
        let e = f.locate(Some(Vec2::new(4.0, 1.0))).unwrap_err();
        assert!(
            matches!(e, Error::InvalidDelay { link: 1, value } if value.to_bits() == bad.to_bits()),
            "{bad}: {e:?}"
        );
        names(&e, "delays_s[1]");
    }
}

#[test]
fn lm_invalid_sigma() {
    // Outside 1e-15 ..= 1e-3 s too (issue 12, item 7: 1e308 gave `exact_fit` at the start).
    for bad in [0.0, -1e-11, NAN, INF, 1e308, 2e-3, 1e-16] {
        let mut f = lm_fixture();
        f.sigmas[2] = bad;
        let e = f.locate(Some(Vec2::new(4.0, 1.0))).unwrap_err();
        assert!(
            matches!(e, Error::InvalidSigma { link: 2, value } if value.to_bits() == bad.to_bits()),
            "{e:?}"
        );
        names(&e, "sigma_s[2]");
    }
    // The σ of a link without a measurement is ignored.
    let mut f = lm_fixture();
    f.delays[2] = None;
    f.sigmas[2] = NAN;
    assert!(f.locate(Some(Vec2::new(4.0, 1.0))).is_ok());
}

#[test]
fn lm_length_mismatch() {
    let mut f = lm_fixture();
    f.delays.pop();
    let e = f.locate(None).unwrap_err();
    assert_eq!(
        e,
        Error::LengthMismatch {
            field: "delays_s",
            expected: 4,
            found: 3
        }
    );
    names(&e, "delays_s");
    let mut f = lm_fixture();
    f.sigmas.push(1e-11);
    let e = f.locate(None).unwrap_err();
    assert_eq!(
        e,
        Error::LengthMismatch {
            field: "sigma_s",
            expected: 4,
            found: 5
        }
    );
    names(&e, "sigma_s");
}

#[test]
fn lm_non_finite_initial_point() {
    let f = lm_fixture();
    for start in [Vec2::new(NAN, 1.0), Vec2::new(0.0, INF)] {
        let e = f.locate(Some(start)).unwrap_err();
        assert_eq!(
            e,
            Error::NonFinite {
                field: "initial_m".into()
            }
        );
        names(&e, "initial_m");
    }
    // Grid-search start over an invalid area is a named error as well.
    let mut f = lm_fixture();
    f.area.x = [10.0, -10.0];
    let e = f.locate(None).unwrap_err();
    assert!(
        matches!(
            e,
            Error::InvertedArea {
                field: "area_m.x",
                ..
            }
        ),
        "{e:?}"
    );
}

// ------------------------------------------------------------------------- grid caps

#[test]
fn grid_size_limits() {
    let area = l4().area_m;
    for (nx, ny, field, value) in [
        (0, 10, "nx", 0),
        (1, 10, "nx", 1),
        (10, 1, "ny", 1),
        (5000, 10, "nx", 5000),
        (10, MAX_GRID_SIDE + 1, "ny", MAX_GRID_SIDE + 1),
    ] {
        let e = Grid::new(area, nx, ny).unwrap_err();
        assert_eq!(
            e,
            Error::SizeLimit {
                field,
                value,
                min: 2,
                max: MAX_GRID_SIDE
            }
        );
        names(&e, field);
    }
    // Each side within limits but too many cells.
    let e = Grid::new(area, MAX_GRID_SIDE, MAX_GRID_SIDE).unwrap_err();
    assert!(
        matches!(e, Error::SizeLimit { field: "nx*ny", value, max, .. }
            if value == MAX_GRID_SIDE * MAX_GRID_SIDE && max == MAX_GRID_CELLS),
        "{e:?}"
    );
    names(&e, "nx*ny");
    // Limits are inclusive: 2×2 and exactly MAX_GRID_CELLS are fine.
    assert!(Grid::new(area, 2, 2).is_ok());
    assert!(Grid::new(area, MAX_GRID_SIDE, MAX_GRID_CELLS / MAX_GRID_SIDE).is_ok());
    // An inverted area is rejected by the grid too.
    let bad = Area {
        x: [1.0, 0.0],
        y: [0.0, 1.0],
    };
    assert!(matches!(
        Grid::new(bad, 4, 4),
        Err(Error::InvertedArea {
            field: "area_m.x",
            ..
        })
    ));
}

#[test]
fn unknown_preset() {
    let e = preset("sensors2020").unwrap_err();
    assert_eq!(
        e,
        Error::UnknownPreset {
            name: "sensors2020".into(),
            known: &presets::PRESET_NAMES
        }
    );
    names(&e, "sensors2020");
    names(&e, "sensors2019"); // lists the known ones
    names(&e, "iclgnss2019");
    assert!(preset("").is_err());
    assert_eq!(preset("iclgnss2019"), Ok(presets::iclgnss2019()));
}

// ------------------------------------------------------------------------- degenerate geometry

#[test]
fn receiver_on_transmitter_gives_no_nan() {
    let mut s = l4();
    s.receivers[0].position_m = s.transmitters[0].position_m; // Rx1 on the Tx at (0,0)
    let m = Model::new(&s).expect("coincident nodes are valid input");
    let on_node = Vec2::new(0.0, 0.0);
    // LoS delay 0; the iso-delay "ellipse" is a circle around the node.
    assert_eq!(m.network.los_delay(0), 0.0);
    let e = m
        .network
        .iso_delay_ellipse(0, 20.0 / 299_792_458.0)
        .unwrap();
    assert!((e.semi_major - 10.0).abs() < 1e-9 && (e.semi_minor - 10.0).abs() < 1e-9);
    for r in [
        on_node,
        Vec2::new(1e-12, 0.0),
        Vec2::new(0.5, 0.5),
        Vec2::new(4.0, 1.0),
    ] {
        let row = m.network.jacobian_row(0, r);
        assert!(row.x.is_finite() && row.y.is_finite(), "J at {r:?}");
        assert!(m.network.delay(0, r).is_finite());
        assert!(m.snr(0, r).is_finite() && m.snr(0, r) > 0.0);
        let c = crlb_at(&m, r);
        assert!(c.fisher_per_m2.iter().all(|v| v.is_finite()), "F at {r:?}");
        if let Some(b) = c.bound {
            assert!(b.rmse_m.is_finite() && b.rmse_m > 0.0);
        }
    }
    // Map with a cell centre exactly on the coincident nodes (odd sizes, symmetric area).
    let grid = Grid::new(
        Area {
            x: [-5.0, 5.0],
            y: [-5.0, 5.0],
        },
        11,
        11,
    )
    .unwrap();
    assert_eq!((grid.x(5), grid.y(5)), (0.0, 0.0));
    let mut out = vec![0.0; grid.len()];
    crlb_map(&m, &grid, &mut out).unwrap();
    assert!(out.iter().all(|v| !v.is_nan() && *v > 0.0));
    // LM: noise-free fix still works, and starting exactly on the node does not panic.
    let truth = Vec2::new(4.0, 1.0);
    let (delays, sigmas) = noise_free(&m, truth);
    let meas = DelayMeasurements {
        delays_s: &delays,
        sigmas_s: &sigmas,
    };
    for start in [Some(truth + Vec2::new(1.0, -1.0)), Some(on_node), None] {
        let rep =
            localize::locate(&m.network, &meas, &LmConfig::default(), start, &s.area_m).unwrap();
        assert!(rep.position.x.is_finite() && rep.position.y.is_finite());
        assert!(rep.cost.is_finite());
        if start != Some(on_node) {
            assert!((rep.position - truth).norm() < 1e-6, "{rep:?}");
        }
    }
}
