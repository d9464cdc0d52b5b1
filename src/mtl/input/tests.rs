use super::*;
use crate::mtl::algorithm::locate;

fn hexagon() -> NetworkInput {
    let at = |deg: Real| {
        let a = deg.to_radians();
        [5.0 + 5.0 * a.cos(), 5.0 + 5.0 * a.sin()]
    };
    NetworkInput {
        tx: [90.0, 210.0, 330.0].map(at).to_vec(),
        rx: [30.0, 150.0, 270.0].map(at).to_vec(),
        region: Some(RegionInput {
            min_m: [0.0, 0.0],
            max_m: [10.0, 10.0],
        }),
        c_sigma_m: 0.1,
    }
}

fn exact_ranges(net: &Network, targets: &[Vec2]) -> RangesInput {
    RangesInput {
        ranges_m: (0..net.map.n_trps())
            .map(|m| {
                targets
                    .iter()
                    .map(|x| net.map.range(m, x, &net.tx, &net.rx))
                    .collect()
            })
            .collect(),
    }
}

#[test]
fn json_round_trip_and_defaults() {
    let net = hexagon();
    let text = serde_json::to_string(&net).unwrap();
    assert_eq!(from_json::<NetworkInput>(&text).unwrap(), net);
    let short: NetworkInput = from_json(r#"{"tx": [[0, 0]], "rx": [[1, 0]]}"#).unwrap();
    assert_eq!((short.c_sigma_m, short.region), (0.1, None));
    for spec in [
        ModelSpec::Icb {
            p_u: Some(0.3),
            p_d: None,
            p_los: None,
        },
        ModelSpec::Ppp {
            lambda: 0.03,
            diameter_m: 0.2,
            p_d: 0.9,
            exact: true,
        },
        ModelSpec::Empirical {
            p_d: 0.9,
            table: None,
            training: Some(TrainingSpec::default()),
        },
    ] {
        let text = serde_json::to_string(&spec).unwrap();
        assert_eq!(from_json::<ModelSpec>(&text).unwrap(), spec, "{text}");
    }
    let ppp: ModelSpec = from_json(r#"{"kind": "ppp"}"#).unwrap();
    assert_eq!(
        ppp,
        ModelSpec::Ppp {
            lambda: 0.03,
            diameter_m: 0.6,
            p_d: 0.9,
            exact: false
        }
    );
    let r = RangesInput {
        ranges_m: alloc::vec![alloc::vec![1.0, 2.5], alloc::vec![]],
    };
    let text = serde_json::to_string(&r).unwrap();
    assert_eq!(from_json::<RangesInput>(&text).unwrap(), r);
}

#[test]
fn parse_errors_name_the_field() {
    let e = from_json::<NetworkInput>(r#"{"tx": [[0, 0]], "rx": [[1, 0]], "cs": 1}"#);
    assert!(matches!(e, Err(Error::Parse { ref message }) if message.contains("cs")));
    let e = from_json::<NetworkInput>(r#"{"tx": [[0, "a"]], "rx": [[1, 0]]}"#);
    assert!(matches!(e, Err(Error::Parse { ref message }) if message.contains("tx[0]")));
    let e = from_json::<ModelSpec>(r#"{"kind": "magic"}"#);
    assert!(matches!(e, Err(Error::Parse { ref message }) if message.contains("magic")));
}

#[test]
fn bad_networks_and_ranges_are_named_errors() {
    let mut net = hexagon();
    net.tx.clear();
    assert_eq!(net.validate(), Err(Error::EmptyNodeList { field: "tx" }));
    let mut net = hexagon();
    net.rx[2][1] = Real::NAN;
    assert!(matches!(net.validate(), Err(Error::NonFinite { field }) if field == "rx[2]"));
    let mut net = hexagon();
    net.c_sigma_m = 0.0;
    assert!(matches!(
        net.validate(),
        Err(Error::OutOfRange { field, .. }) if field == "c_sigma_m"
    ));
    let mut net = hexagon();
    net.region = Some(RegionInput {
        min_m: [0.0, 5.0],
        max_m: [10.0, 5.0],
    });
    assert!(matches!(
        net.validate(),
        Err(Error::InvertedArea {
            field: "region.y",
            ..
        })
    ));
    let mut net = hexagon();
    net.tx = alloc::vec![[0.0, 0.0]; 9];
    net.rx = alloc::vec![[1.0, 0.0]; 9];
    assert!(matches!(net.validate(), Err(Error::SizeLimit { .. })));

    let net = hexagon().validate().unwrap();
    let mut r = exact_ranges(&net, &[Vec2::new(4.0, 5.0)]);
    r.ranges_m.pop();
    assert!(matches!(
        r.validate(&net),
        Err(Error::LengthMismatch {
            field: "ranges_m",
            expected: 9,
            found: 8
        })
    ));
    let mut r = exact_ranges(&net, &[Vec2::new(4.0, 5.0)]);
    r.ranges_m[3][0] = Real::NAN;
    assert!(
        matches!(r.validate(&net), Err(Error::NonFinite { field }) if field == "ranges_m[3][0]")
    );
    r.ranges_m[3][0] = -1.0;
    assert!(matches!(
        r.validate(&net),
        Err(Error::OutOfRange { field, .. }) if field == "ranges_m[3][0]"
    ));
    r.ranges_m[3] = alloc::vec![1.0; MAX_RANGES_PER_TRP + 1];
    assert!(matches!(r.validate(&net), Err(Error::SizeLimit { .. })));
}

#[test]
fn bad_models_are_named_errors() {
    let net = hexagon().validate().unwrap();
    let err = |s: ModelSpec| s.build(&net).err().unwrap();
    assert!(matches!(
        err(ModelSpec::Icb { p_u: Some(0.2), p_d: Some(0.9), p_los: None }),
        Error::OutOfRange { field, .. } if field == "p_u"
    ));
    assert!(matches!(
        err(ModelSpec::Icb { p_u: None, p_d: None, p_los: Some(1.5) }),
        Error::OutOfRange { field, .. } if field == "p_los"
    ));
    assert!(matches!(
        err(ModelSpec::Ppp { lambda: -1.0, diameter_m: 0.6, p_d: 0.9, exact: false }),
        Error::OutOfRange { field, .. } if field == "lambda"
    ));
    assert!(matches!(
        err(ModelSpec::Ppp { lambda: 0.03, diameter_m: 0.6, p_d: 2.0, exact: false }),
        Error::OutOfRange { field, .. } if field == "p_d"
    ));
    assert!(matches!(
        err(ModelSpec::Empirical { p_d: 0.9, table: None, training: None }),
        Error::OutOfRange { field, .. } if field == "table"
    ));
    let region = net.region.unwrap();
    let table = EmpiricalTable::new(&region, 2, 2, 2, 3).unwrap();
    assert!(matches!(
        err(ModelSpec::Empirical {
            p_d: 0.9,
            table: Some(table),
            training: None
        }),
        Error::LengthMismatch {
            field: "table.n_tx",
            ..
        }
    ));
    let training = TrainingSpec {
        scenes: usize::MAX,
        ..TrainingSpec::default()
    };
    assert!(matches!(
        err(ModelSpec::Empirical {
            p_d: 0.9,
            table: None,
            training: Some(training)
        }),
        Error::SizeLimit {
            field: "scenes",
            ..
        }
    ));
}

/// Two targets in the V-A hexagon with exact ranges: every model finds both.
#[test]
fn every_model_finds_two_exact_targets() {
    let net = hexagon().validate().unwrap();
    let truth = [Vec2::new(3.0, 4.0), Vec2::new(6.5, 6.0)];
    let ranges = exact_ranges(&net, &truth);
    ranges.validate(&net).unwrap();
    let training = TrainingSpec {
        cells: 10,
        scenes: 20,
        ..TrainingSpec::default()
    };
    for spec in [
        ModelSpec::Icb {
            p_u: None,
            p_d: None,
            p_los: None,
        },
        ModelSpec::Ppp {
            lambda: 0.03,
            diameter_m: 0.2,
            p_d: 0.9,
            exact: false,
        },
        ModelSpec::Empirical {
            p_d: 0.9,
            table: None,
            training: Some(training),
        },
    ] {
        let built = spec.build(&net).unwrap();
        assert_eq!(built.consistency, spec.name() != "icb");
        let cfg = net.config(&MtlConfig::default(), &built);
        let out = locate(&net.measurements(&ranges.ranges_m), &*built.model, &cfg).unwrap();
        let reports = target_reports(&net.map, &out.targets);
        assert_eq!(reports.len(), 2, "{}", spec.name());
        for x in truth {
            assert!(
                reports.iter().any(|r| {
                    (r.position_m[0] - x.x).abs() < 1e-6 && (r.position_m[1] - x.y).abs() < 1e-6
                }),
                "{}: {x:?} not found",
                spec.name()
            );
        }
        assert!(reports
            .iter()
            .all(|r| r.g == [1; 9] && r.matching.len() == 9));
    }
}
