//! The Monte Carlo study's part-file configuration rebuilds the study and refuses an edited one.

use alloc::vec;

use super::*;
use crate::scenario::presets;
use crate::track::{ConstantVelocity, FilterKind, PfConfig, TrackScenario};

const PF: FilterKind = FilterKind::Pf(PfConfig {
    particles: 40,
    roughening: None,
    regularized: true,
});

#[test]
fn monte_carlo_config_rebuilds_the_study_and_refuses_an_edited_one() {
    let track = TrackStudy::new(
        "sensors2019".into(),
        presets::preset("sensors2019").unwrap(),
        vec![TrackScenario::I, TrackScenario::III],
        ConstantVelocity::validated(0.1, 1.0).unwrap(),
        5,
    )
    .unwrap();
    let kinds = [FilterKind::Ekf, PF];
    let study = MonteCarloStudy::new(track, 20, 2, 11, false, &kinds).unwrap();
    let doc = serde_json::to_value(study.config_doc().unwrap()).unwrap();
    assert_eq!(doc["filters"]["names"], serde_json::json!(["ekf", "pf"]));
    assert_eq!(doc["filters"]["particles"], 40);
    let again = MonteCarloStudy::from_config(&doc).unwrap();
    assert_eq!(again.configs, study.configs);
    assert_eq!(again.filters, study.filters);
    let mut edited = doc.clone();
    edited["noise_runs"] = serde_json::json!(3);
    let ok = MonteCarloStudy::from_config(&edited).unwrap();
    assert_eq!(ok.noise_runs, 3);
    edited["filters"]["ukf"] = serde_json::json!([1.0, 2.0, 0.0]);
    let e = MonteCarloStudy::from_config(&edited)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("config is not as this scatterloc writes it (filters.ukf"),
        "{e}"
    );
    // The EKF alone records no filters.
    let ekf =
        MonteCarloStudy::new(study.track.clone(), 20, 2, 11, false, &[FilterKind::Ekf]).unwrap();
    assert!(ekf.config_doc().unwrap().filters.is_none());
}
