//! Band validation, β_N² (C4) and the C1/C2 views of a recording.

use alloc::vec;
use alloc::vec::Vec;

use rand::SeedableRng as _;
use rand_distr::{Distribution, StandardNormal};
use rand_pcg::Pcg64;

use super::*;
use crate::channel::Pulse;
use crate::math::{sin, sqrt};

fn one() -> Complex {
    Complex::new(1.0, 0.0)
}

#[test]
fn validation_errors() {
    assert!(matches!(
        Band::new(vec![0.0], vec![one()]),
        Err(Error::SizeLimit { .. })
    ));
    assert!(matches!(
        Band::new(vec![0.0, 1.0, 2.0], vec![one(); 2]),
        Err(Error::LengthMismatch {
            field: "system_response",
            ..
        })
    ));
    assert!(matches!(
        Band::new(vec![0.0, 1.0, 2.5, 3.0], vec![one(); 4]),
        Err(Error::InvalidFile { .. })
    ));
    assert!(matches!(
        Band::new(vec![2.0, 1.0, 0.0], vec![one(); 3]),
        Err(Error::InvalidFile { .. })
    ));
    assert!(matches!(
        Band::new(vec![0.0, Real::NAN, 2.0], vec![one(); 3]),
        Err(Error::NonFinite { .. })
    ));
    assert!(matches!(
        Band::new(
            vec![0.0, 1.0],
            vec![one(), Complex::new(Real::INFINITY, 0.0)]
        ),
        Err(Error::NonFinite { .. })
    ));
    assert!(Band::new(vec![0.0, 1.0], vec![Complex::new(0.0, 0.0); 2]).is_err());
    assert!(Band::flat(5, 0.0).is_err());
}

/// β_N² = Δf²(N²−1)/12 for a flat band; a tapered P lowers it.
#[test]
fn beta_sq_closed_form() {
    let b = Band::flat(11, 2.0).unwrap();
    assert!((b.beta_sq() - 4.0 * 120.0 / 12.0).abs() < 1e-12);
    assert!(b.mean_freq_hz().abs() < 1e-12);
    let mut t = b.clone();
    t.response = (0..11)
        .map(|i| Complex::new(1.0 - (i as Real - 5.0).abs() / 6.0, 0.0))
        .collect();
    assert!(t.beta_sq() < b.beta_sq());
}

fn cir_rec(taps: Vec<Complex>, pulse: Option<Pulse>) -> Recording {
    Recording {
        t_s: vec![0.0],
        links: vec![[0, 0]],
        layout: Layout::Cir {
            tap0_s: 0.0,
            tap_spacing_s: 1.0 / 240e6,
            pulse,
        },
        samples: taps,
        noise_var: None,
        synchronized: None,
    }
}

/// CIR noise only: the out-of-band estimate and the in-band bins' mean |H|² both equal
/// `(BΔt)²·M·σ_v²` (to 4 standard errors), for a power-of-two and a direct-DFT tap count.
#[test]
fn cir_noise_estimate() {
    for m in [512usize, 500] {
        let mut rng = Pcg64::seed_from_u64(m as u64);
        let sv2 = 3.0;
        let mut oob = 0.0;
        let mut inb = 0.0;
        let reps = 40;
        let mut nb = 0;
        for _ in 0..reps {
            let taps: Vec<Complex> = (0..m)
                .map(|_| {
                    let a: Real = StandardNormal.sample(&mut rng);
                    let b: Real = StandardNormal.sample(&mut rng);
                    Complex::new(a, b) * sqrt(sv2 / 2.0)
                })
                .collect();
            let rec = cir_rec(taps, None);
            let (band, map) = Band::of_recording(&rec, 120e6).unwrap();
            let mut h = Vec::new();
            oob += map.fill(&rec, 0, 0, &mut h).unwrap().unwrap() / reps as Real;
            inb += h.iter().map(|v| v.norm_sqr()).sum::<Real>() / (h.len() * reps) as Real;
            nb = band.len();
            let want = map.noise_var_of_taps(sv2);
            assert!((want - 0.25 * m as Real * sv2).abs() < 1e-9);
        }
        let want = 0.25 * m as Real * sv2;
        std::println!("M {m}: N {nb}, oob σ̂² {oob:.2}, in-band mean {inb:.2}, want {want:.2}");
        // in-band mean over 40·N exponentials: relative SE 1/√(40N); median-based: ≈ 1.1/√(40·N_oob)
        assert!((inb / want - 1.0).abs() < 4.0 / sqrt((40 * nb) as Real));
        assert!((oob / want - 1.0).abs() < 4.0 * 1.2 / sqrt((40 * nb) as Real) + 0.01);
    }
}

/// A measured pulse equal to the sampled sinc gives P ≈ 1 in band (away from the edges).
#[test]
fn measured_sinc_pulse_is_flat() {
    let b = 120e6;
    let sp = 1.0 / (4.0 * b);
    let k = 2001;
    let samples = (0..k)
        .map(|i| {
            let t = (i as Real - 1000.0) * sp;
            let x = PI * b * t;
            Complex::new(if i == 1000 { 1.0 } else { sin(x) / x }, 0.0)
        })
        .collect();
    let rec = cir_rec(
        vec![Complex::new(0.0, 0.0); 256],
        Some(Pulse {
            samples,
            spacing_s: sp,
        }),
    );
    let (band, _) = Band::of_recording(&rec, b).unwrap();
    for (f, p) in band.freq_hz.iter().zip(&band.response) {
        if f.abs() < 0.4 * b {
            assert!((p - Complex::new(1.0, 0.0)).norm_sqr() < 1e-3, "{f}: {p}");
        }
    }
}

#[test]
fn recording_errors() {
    let mut rec = cir_rec(vec![Complex::new(0.0, 0.0); 64], None);
    assert!(Band::of_recording(&rec, 0.0).is_err());
    assert!(Band::of_recording(&rec, 480e6).is_err()); // Δt > 1/B
    rec.t_s.push(1.0); // 2 snapshots of 32 taps, but a CIR of 1 bin pair: the DFT has < 2 in-band bins
    rec.layout = Layout::Cir {
        tap0_s: 0.0,
        tap_spacing_s: 1.0 / 120e6,
        pulse: None,
    };
    rec.samples.truncate(4);
    assert!(Band::of_recording(&rec, 120e6).is_err());
    let cfr = Recording {
        t_s: vec![0.0, 1.0],
        links: vec![[0, 0]],
        layout: Layout::Cfr {
            freq_hz: vec![0.0, 1.0, 2.0],
            system_response: None,
        },
        samples: vec![one(); 6],
        noise_var: None,
        synchronized: None,
    };
    let (band, map) = Band::of_recording(&cfr, 1.0).unwrap();
    assert_eq!(band.response, vec![one(); 3]);
    let mut h = Vec::new();
    assert_eq!(map.fill(&cfr, 1, 0, &mut h).unwrap(), None);
    assert_eq!(h.len(), 3);
    assert!(map.fill(&cfr, 2, 0, &mut h).is_err());
    assert!(map.fill(&cfr, 0, 1, &mut h).is_err());
}
