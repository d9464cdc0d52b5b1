//! The consistency of a channel track's reported covariance with its error (issue 38 §11),
//! shared by the CLI test (`tests/cli/cir.rs`) and the page's (`tests/e2e/page_nees.rs`): the
//! position NEES of TRACK.json against truth.json, and its mean's 95 % band with the samples'
//! autocorrelation taken into account.

use serde_json::Value;

/// One track's NEES against its truth.
#[derive(Debug, Clone, Copy)]
pub struct NeesSummary {
    /// Snapshots with a state within 2 m of the truth (the NEES samples).
    pub samples: usize,
    /// States farther than 2 m (a ghost: an association failure, not a covariance question).
    pub ghosts: usize,
    /// The mean position NEES (2 degrees of freedom: 2 is consistent).
    pub mean: f64,
    /// Independent samples `N/τ` (`τ` the series' integrated autocorrelation time).
    pub independent: f64,
    /// The mean's two-sided 95 % band `χ²_{2n}(0.025 | 0.975)/n`, n = `independent`.
    pub band: (f64, f64),
}

impl NeesSummary {
    /// Whether the mean lies in its band.
    pub fn inside(&self) -> bool {
        (self.band.0..=self.band.1).contains(&self.mean)
    }
}

/// The position NEES `eᵀP⁻¹e` of every state of `track` (TRACK.json: `states`, `covariances`)
/// against `truth` (truth.json: `states`), summarised. Panics (a test) on a covariance that is
/// not positive definite or a track with no state near the truth.
pub fn position_nees(track: &Value, truth: &Value) -> NeesSummary {
    let (mut nees, mut ghosts) = (Vec::new(), 0);
    let at = |v: &Value, i: usize| v[i].as_f64().unwrap();
    for (k, x) in track["states"].as_array().unwrap().iter().enumerate() {
        if x.is_null() {
            continue;
        }
        let truth_k = &truth["states"][k];
        let (dx, dy) = (at(x, 0) - at(truth_k, 0), at(x, 1) - at(truth_k, 1));
        if dx.hypot(dy) > 2.0 {
            ghosts += 1;
            continue;
        }
        let p = &track["covariances"][k];
        let (a, b, c, d) = (at(&p[0], 0), at(&p[0], 1), at(&p[1], 0), at(&p[1], 1));
        let det = a * d - b * c;
        assert!(
            a > 0.0 && det > 0.0,
            "snapshot {k}: position covariance not positive definite: {p}"
        );
        nees.push((d * dx * dx - (b + c) * dx * dy + a * dy * dy) / det);
    }
    assert!(!nees.is_empty(), "no state within 2 m of the truth");
    let mean = nees.iter().sum::<f64>() / nees.len() as f64;
    let independent = nees.len() as f64 / integrated_autocorrelation_time(&nees);
    let q = |z: f64| wilson_hilferty(2.0 * independent, z) / independent;
    NeesSummary {
        samples: nees.len(),
        ghosts,
        mean,
        independent,
        band: (q(-1.959_964), q(1.959_964)),
    }
}

/// The integrated autocorrelation time of `x` in samples (Sokal's self-consistent window
/// `M ≥ 5τ`), at least 1: `n/τ` of its samples count as independent.
pub fn integrated_autocorrelation_time(x: &[f64]) -> f64 {
    let n = x.len();
    let mean = x.iter().sum::<f64>() / n as f64;
    let var = x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n as f64;
    if var.is_nan() || var <= 0.0 {
        return 1.0;
    }
    let mut tau = 1.0;
    for lag in 1..n {
        let r: f64 = (0..n - lag)
            .map(|i| (x[i] - mean) * (x[i + lag] - mean))
            .sum::<f64>()
            / (n as f64 * var);
        tau += 2.0 * r;
        if lag as f64 >= 5.0 * tau {
            break;
        }
    }
    tau.max(1.0)
}

/// The `z` quantile of χ² with `k` degrees of freedom (Wilson–Hilferty; within 0.5 % for
/// k ≥ 20).
pub fn wilson_hilferty(k: f64, z: f64) -> f64 {
    k * (1.0 - 2.0 / (9.0 * k) + z * (2.0 / (9.0 * k)).sqrt()).powi(3)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// White samples: τ = 1; an AR(1) series with ρ = 0.9: τ near (1 + ρ)/(1 − ρ) = 19; the
    /// Wilson–Hilferty quantiles of χ²₁₀₀ against the tables (74.22, 129.56).
    #[test]
    fn autocorrelation_time_and_quantiles_against_closed_forms() {
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        let mut normal = move || {
            // Box–Muller on a xorshift stream.
            let mut u = || {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                (state >> 11) as f64 / (1u64 << 53) as f64
            };
            let (a, b) = (u().max(1e-300), u());
            (-2.0 * a.ln()).sqrt() * (2.0 * std::f64::consts::PI * b).cos()
        };
        let white: Vec<f64> = (0..20_000).map(|_| normal()).collect();
        let t = integrated_autocorrelation_time(&white);
        assert!((0.8..1.25).contains(&t), "white: τ = {t}");
        let mut x = 0.0;
        let ar: Vec<f64> = (0..200_000)
            .map(|_| {
                x = 0.9 * x + (1.0f64 - 0.81).sqrt() * normal();
                x
            })
            .collect();
        let t = integrated_autocorrelation_time(&ar);
        assert!((16.0..22.0).contains(&t), "AR(1) 0.9: τ = {t}");
        assert!((wilson_hilferty(100.0, -1.959_964) - 74.22).abs() < 0.1);
        assert!((wilson_hilferty(100.0, 1.959_964) - 129.56).abs() < 0.1);
    }
}
