//! Random multipath snapshots for the estimator's termination checks (spec C12 7): up to 64
//! paths, spacings down to 0.1/B, amplitudes over 60 dB, from noise-free to 0 dB SNR — the one
//! generator of `library/bounds.rs` (a fixed sweep) and `fuzz.rs` (a proptest strategy), and the
//! check of one snapshot's result against the stated bounds.

use scatterloc::channel::{Band, Estimator, EstimatorConfig, SnapshotEstimate};
use scatterloc::error::limits;
use scatterloc::math::{Complex, Real};

/// N = 241 bins over 120 MHz (the sensors2019 sounder).
pub const N: usize = 241;
/// The bandwidth, Hz.
pub const B: Real = 120e6;

/// One drawn snapshot: the paths `(delay s, amplitude)` and the noise variance per bin (0:
/// noise-free).
#[derive(Debug, Clone)]
pub struct Draw {
    pub paths: Vec<(Real, Complex)>,
    pub noise_var: Real,
    /// Whether the estimator is told the noise variance.
    pub given: bool,
}

/// The band of [`N`] bins over [`B`].
pub fn band() -> Band {
    Band::flat(N, B / N as Real).unwrap()
}

/// A snapshot from unit-interval draws `u` (a splitmix stream of `seed`): `k` paths (1 … 64),
/// clustered so that spacings reach 0.1/B, amplitudes spread over `dr_db` (≤ 60 dB), the
/// strongest path's SNR from 0 dB to 60 dB, or noise-free (one in four), or `noise_var = 1e-40`.
pub fn draw(seed: u64) -> Draw {
    let mut s = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ 0xD1B5_4A32_D192_ED03;
    let mut u = move || {
        s = s.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = s;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as Real / (1u64 << 53) as Real
    };
    let k = 1 + (u() * u() * 64.0) as usize;
    let k = k.min(64);
    let dr_db = 60.0 * u();
    let mut paths = Vec::with_capacity(k);
    let mut t = 20e-9 + 200e-9 * u();
    for _ in 0..k {
        // Spacing: often within 0.1 … 1.5 of 1/B, sometimes far.
        let gap = if u() < 0.7 {
            (0.1 + 1.4 * u()) / B
        } else {
            40e-9 * u()
        };
        t += gap;
        let amp = 10f64.powf(-dr_db * u() / 20.0) * 1e-5;
        let ph = 2.0 * std::f64::consts::PI * u();
        paths.push((t % 1.9e-6, Complex::new(amp * ph.cos(), amp * ph.sin())));
    }
    let strongest = paths.iter().map(|p| p.1.norm_sqr()).fold(0.0, Real::max);
    let kind = u();
    let (noise_var, given) = if kind < 0.25 {
        (0.0, false)
    } else if kind < 0.3 {
        (1e-40, true)
    } else {
        let snr_db = 60.0 * u();
        (N as Real * strongest / 10f64.powf(snr_db / 10.0), u() < 0.5)
    };
    Draw {
        paths,
        noise_var,
        given,
    }
}

/// The response of `d` on `b` (noise from `seed`).
pub fn response(b: &Band, d: &Draw, seed: u64) -> Vec<Complex> {
    use rand::SeedableRng as _;
    use rand_distr::{Distribution, StandardNormal};
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
    b.freq_hz
        .iter()
        .map(|&f| {
            let mut h = Complex::new(0.0, 0.0);
            for &(t, a) in &d.paths {
                let x = -2.0 * std::f64::consts::PI * f * t;
                h += a * Complex::new(x.cos(), x.sin());
            }
            if d.noise_var > 0.0 {
                let s = (d.noise_var / 2.0).sqrt();
                let (x, y): (Real, Real) = (
                    StandardNormal.sample(&mut rng),
                    StandardNormal.sample(&mut rng),
                );
                h += Complex::new(x * s, y * s);
            }
            h
        })
        .collect()
}

/// What one snapshot did against the bounds: `Err` names the broken bound or the non-finite
/// output.
pub fn check(e: &SnapshotEstimate, cfg: &EstimatorConfig, span: Real) -> Result<(), String> {
    let w = &e.work;
    let passes = 2 * cfg.max_paths + 2;
    if w.passes > passes {
        return Err(format!("{} passes > {passes}", w.passes));
    }
    if w.sweeps > limits::ESTIMATOR_SWEEPS {
        return Err(format!(
            "{} sweeps > {}",
            w.sweeps,
            limits::ESTIMATOR_SWEEPS
        ));
    }
    if w.newton > limits::NEWTON_ITERATIONS {
        return Err(format!("{} Newton iterations", w.newton));
    }
    if e.paths.len() > cfg.max_paths {
        return Err(format!("{} paths > max_paths", e.paths.len()));
    }
    if !(e.noise_var.is_finite() && e.noise_var >= 0.0) {
        return Err(format!("noise_var {}", e.noise_var));
    }
    for p in &e.paths {
        let ok = p.delay_s.is_finite()
            && p.delay_s >= 0.0
            && p.delay_s <= span
            && p.alpha.re.is_finite()
            && p.alpha.im.is_finite()
            && p.sigma_s.is_finite()
            && p.sigma_s >= 0.0
            && p.snr.is_finite();
        if !ok {
            return Err(format!("non-finite or out-of-window path {p:?}"));
        }
    }
    Ok(())
}

/// Estimates draw `seed` with `cfg` and checks it ([`check`]).
pub fn run(est: &mut Estimator, b: &Band, seed: u64) -> Result<SnapshotEstimate, String> {
    let d = draw(seed);
    let h = response(b, &d, seed ^ 0x5555);
    let nv = d.given.then_some(d.noise_var);
    let e = est
        .estimate(&h, nv, &[])
        .map_err(|e| format!("seed {seed}: error {e}"))?;
    let cfg = *est.config();
    check(&e, &cfg, b.unambiguous_s()).map_err(|m| format!("seed {seed}: {m} ({d:?})"))?;
    Ok(e)
}

/// An estimator of the band with `max_paths` (the rest default).
pub fn estimator(b: &Band, max_paths: usize) -> Estimator {
    Estimator::new(
        b.clone(),
        EstimatorConfig {
            max_paths,
            ..EstimatorConfig::default()
        },
    )
    .unwrap()
}
