//! `scatterloc track`: the EKF of spec §6 (S16, S17) over a measurement file — step `n` predicts
//! by `dt_s` with the CV model (E7), then updates with `steps[n−1]` (missing links skipped, none =
//! predict only), `R` fixed from `sigma_s` or from the link budget (E8) at the predicted position.

use std::ffi::OsString;

use serde::{Deserialize, Serialize};

use scatterloc::ekf::{Ekf, MeasurementNoise};
use scatterloc::math::{Mat4, Vec4};
use scatterloc::montecarlo::MAX_STEPS;
use scatterloc::motion::ConstantVelocity;
use scatterloc::Error;

use crate::commands::{emit, model_of, parse_args, read_json_file, read_scenario, Sigma};
use crate::CliError;

/// The `--measurements` file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct MeasurementsFile {
    /// Step `T`, s.
    dt_s: f64,
    /// Process-noise intensity `q̃`, m²/s³.
    process_noise: f64,
    /// `x̂(t₀) = [x, y, vx, vy]`, m and m/s.
    initial_state: [f64; 4],
    /// `P(t₀)`, row-major.
    initial_covariance: [[f64; 4]; 4],
    /// Fixed delay σ (one or per link), s; absent: the link budget at the prediction.
    #[serde(default)]
    sigma_s: Option<Sigma>,
    /// Per step, one delay per link in scenario link order (`null` = missing), s.
    steps: Vec<Vec<Option<f64>>>,
}

/// Output of `track`: one entry per step (after its update).
#[derive(Serialize)]
struct TrackOut {
    t_s: Vec<f64>,
    states: Vec<[f64; 4]>,
    covariances: Vec<[[f64; 4]; 4]>,
    /// NIS `νᵀS⁻¹ν` of the step; `null` when no link was used.
    nis: Vec<Option<f64>>,
    links_used: Vec<usize>,
}

/// `scatterloc track --scenario S --measurements M`.
pub fn track(argv: &[OsString]) -> Result<(), CliError> {
    let Some(args) = parse_args(argv, "track", &["scenario", "measurements"], &[])? else {
        return Ok(());
    };
    args.expect_positional("track", 0, "")?;
    let mpath = args.required("measurements")?;
    let scenario = read_scenario(&args)?;
    let m: MeasurementsFile = read_json_file("measurements", mpath)?;
    let bad = |e: &dyn std::fmt::Display| CliError::usage(format!("--measurements {mpath}: {e}"));
    let model = model_of(&scenario)?;
    let n = model.link_count();
    let motion = ConstantVelocity::validated(m.dt_s, m.process_noise).map_err(|e| bad(&e))?;
    let p0 = Mat4::from_fn(|i, j| m.initial_covariance[i][j]);
    let mut ekf = Ekf::new(Vec4::from(m.initial_state), p0).map_err(|e| bad(&e))?;
    let sigmas = match m.sigma_s {
        Some(s) => Some(s.per_link(n).map_err(|e| bad(&e))?),
        None => None,
    };
    let noise = match &sigmas {
        Some(s) => MeasurementNoise::Fixed(s),
        None => MeasurementNoise::AtPrediction,
    };
    if m.steps.len() > MAX_STEPS {
        return Err(bad(&format!(
            "steps: {} steps, at most {MAX_STEPS} are allowed",
            m.steps.len()
        )));
    }
    let mut out = TrackOut {
        t_s: Vec::with_capacity(m.steps.len()),
        states: Vec::with_capacity(m.steps.len()),
        covariances: Vec::with_capacity(m.steps.len()),
        nis: Vec::with_capacity(m.steps.len()),
        links_used: Vec::with_capacity(m.steps.len()),
    };
    for (k, z) in m.steps.iter().enumerate() {
        let field = format!("steps[{k}]");
        if z.len() != n {
            return Err(bad(&format!(
                "{field}: expected {n} delays (one per link, null = missing), found {}",
                z.len()
            )));
        }
        ekf.predict(&motion);
        let summary = ekf.update(&model, z, noise, None).map_err(|e| match e {
            Error::NonFiniteDelay { link } => bad(&format!("{field}[{link}]: not a finite number")),
            other => bad(&format!("{field}: {other}")),
        })?;
        let p = &ekf.covariance;
        out.t_s.push((k + 1) as f64 * m.dt_s);
        out.states.push(ekf.state.into());
        out.covariances
            .push(std::array::from_fn(|i| std::array::from_fn(|j| p[(i, j)])));
        out.nis
            .push((summary.links_used > 0).then_some(summary.nis));
        out.links_used.push(summary.links_used);
    }
    let text =
        serde_json::to_string(&out).map_err(|e| CliError::output(format!("encoding JSON: {e}")))?;
    emit(&text)
}
