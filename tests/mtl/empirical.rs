//! The empirical blocking model of spec `multi-target.md` §6.3: smoothing, lookup, named
//! errors, and agreement of a table trained on the disc process with the PPP model (M11).

use scatterloc::math::{Real, Vec2};
use scatterloc::mtl::blocking::NodePatternModel;
use scatterloc::mtl::empirical::{EmpiricalNodeModel, EmpiricalTable};
use scatterloc::mtl::polygon::Rect;
use scatterloc::Error;

use scatterloc::measure::rng;
use scatterloc::mtl::ppp::{PppBlocking, PppNodeModel};

fn v(x: Real, y: Real) -> Vec2 {
    Vec2::new(x, y)
}

fn region() -> Rect {
    Rect::new(v(0.0, 0.0), v(10.0, 10.0)).unwrap()
}

#[test]
fn smoothed_cells_sum_to_one_and_empty_cells_are_uniform() {
    let mut t = EmpiricalTable::new(&region(), 4, 4, 2, 1).unwrap();
    t.record(&v(1.0, 1.0), 0b11, 0b1).unwrap();
    t.record(&v(1.2, 1.0), 0b01, 0b1).unwrap();
    let m = EmpiricalNodeModel::new(t.clone()).unwrap();
    let c = t.cell_of(&v(1.0, 1.0)).unwrap();
    let p = t.cell_probabilities(c);
    assert!((p.iter().sum::<Real>() - 1.0).abs() < 1e-15);
    // (1 + 0.5) / (2 + 0.5·8)
    assert!((p[0b111] - 1.5 / 6.0).abs() < 1e-15);
    assert_eq!(
        m.node_pattern_probability(&v(1.0, 1.0), 0b11, 0b1),
        p[0b111]
    );
    let empty = t.cell_probabilities(t.cell_of(&v(9.0, 9.0)).unwrap());
    assert!(empty.iter().all(|&q| (q - 1.0 / 8.0).abs() < 1e-15));
    // Outside the region: nearest cell; NaN: probability 0 (L_b = ∞, never NaN).
    assert_eq!(t.cell_of(&v(-5.0, 0.5)), Some(0));
    assert_eq!(t.cell_of(&v(50.0, 50.0)), Some(15));
    assert_eq!(m.node_pattern_probability(&v(Real::NAN, 1.0), 0, 0), 0.0);
}

#[test]
fn bad_tables_are_named_errors() {
    let r = region();
    assert!(matches!(
        EmpiricalTable::new(&r, 0, 4, 3, 3),
        Err(Error::SizeLimit { field: "nx", .. })
    ));
    assert!(matches!(
        EmpiricalTable::new(&r, 4, 4, 0, 3),
        Err(Error::EmptyNodeList { field: "n_tx" })
    ));
    assert!(matches!(
        EmpiricalTable::new(&r, 4096, 4096, 3, 3),
        Err(Error::SizeLimit {
            field: "nx*ny*patterns",
            ..
        })
    ));
    let mut t = EmpiricalTable::new(&r, 2, 2, 1, 1).unwrap();
    t.counts.pop();
    assert!(matches!(
        t.validate(),
        Err(Error::LengthMismatch {
            field: "counts",
            ..
        })
    ));
    let mut t = EmpiricalTable::new(&r, 2, 2, 1, 1).unwrap();
    t.pseudo_count = 0.0;
    assert!(matches!(t.validate(), Err(Error::OutOfRange { .. })));
    t.pseudo_count = Real::NAN;
    assert!(matches!(t.validate(), Err(Error::OutOfRange { .. })));
    let mut t = EmpiricalTable::new(&r, 2, 2, 1, 1).unwrap();
    assert!(matches!(
        t.record(&v(1.0, 1.0), 0b10, 0),
        Err(Error::IndexOutOfRange { .. })
    ));
    assert!(matches!(
        t.train_discs(&[v(1.0, 1.0)], &[], 0.03, 0.6, 10, &mut rng(1, 1)),
        Err(Error::LengthMismatch { field: "rx", .. })
    ));
    assert!(matches!(
        t.train_discs(
            &[v(1.0, 1.0)],
            &[v(2.0, 2.0)],
            -1.0,
            0.6,
            10,
            &mut rng(1, 1)
        ),
        Err(Error::OutOfRange { .. })
    ));
}

/// Trained on the disc process, the per-cell frequencies approach the PPP model where its
/// rectangle approximation is good (far from the nodes): all-LoS within a few percent.
#[test]
fn trained_table_agrees_with_the_ppp_model_away_from_nodes() {
    let tx = [v(1.0, 1.0), v(9.0, 2.0), v(2.0, 8.0)];
    let rx = [v(8.0, 8.5), v(5.0, 0.5), v(0.5, 5.0)];
    let mut t = EmpiricalTable::new(&region(), 10, 10, 3, 3).unwrap();
    t.train_discs(&tx, &rx, 0.03, 0.6, 4000, &mut rng(7, 0))
        .unwrap();
    let x = v(5.5, 5.5); // cell (5, 5) spans [5, 6]²
    let cell = t.cell_of(&x).unwrap();
    assert!(t.observations(cell) > 3800);
    let p = t.cell_probabilities(cell);
    let ppp = PppNodeModel::new(
        PppBlocking::new(0.03, 0.6, Some(region()), true).unwrap(),
        tx.to_vec(),
        rx.to_vec(),
    )
    .unwrap();
    let q = ppp.pattern_probabilities(x).unwrap();
    let all = (1 << 6) - 1;
    // Binomial standard error at n = 4000 and p ≈ 0.6 is 0.008; the PPP rectangle ignores
    // the node exclusion zones (more LoS in the simulation), so allow 0.04.
    assert!((p[all] - q[all]).abs() < 0.04, "{} vs {}", p[all], q[all]);
    assert!(p[all] >= q[all] - 0.02);
}
