use super::*;
use crate::scenario::presets;

fn cfr(s: usize, p: usize, n: usize) -> Recording {
    Recording {
        t_s: (0..s).map(|k| k as Real * 2.048e-3).collect(),
        links: (0..p).map(|r| [0, r]).collect(),
        layout: Layout::Cfr {
            freq_hz: (0..n).map(|k| -60e6 + k as Real * 0.5e6).collect(),
            system_response: None,
        },
        samples: vec![Complex::new(1e-6, -2e-6); s * p * n],
        noise_var: Some(vec![1e-13; p]),
        synchronized: None,
    }
}

fn cir(m: usize) -> Recording {
    Recording {
        layout: Layout::Cir {
            tap0_s: -1e-8,
            tap_spacing_s: 1e-9,
            pulse: Some(Pulse {
                samples: vec![
                    Complex::new(0.5, 0.0),
                    Complex::new(1.0, 0.0),
                    Complex::new(0.5, 0.0),
                ],
                spacing_s: 1e-9,
            }),
        },
        ..cfr(3, 2, m)
    }
}

fn text(r: Result<()>) -> alloc::string::String {
    format!("{}", r.unwrap_err())
}

#[test]
fn valid_recordings_pass() {
    cfr(3, 4, 241).validate().unwrap();
    cir(64).validate().unwrap();
}

#[test]
fn t_s_must_increase_and_be_finite() {
    let mut r = cfr(3, 1, 4);
    r.t_s[2] = r.t_s[1];
    assert!(text(r.validate()).starts_with("t_s: not strictly increasing: t_s[2]"));
    r.t_s[2] = Real::NAN;
    assert!(text(r.validate()).starts_with("t_s: t_s[2] is not a finite"));
}

#[test]
fn freq_must_be_uniform_within_tolerance() {
    let mut r = cfr(1, 1, 5);
    if let Layout::Cfr { freq_hz, .. } = &mut r.layout {
        freq_hz[2] += 0.5e6 * 0.5e-6; // within 1e-6·Δf (the tolerance of FREQ_UNIFORM_TOL)
    }
    r.validate().unwrap();
    if let Layout::Cfr { freq_hz, .. } = &mut r.layout {
        freq_hz[2] += 0.5e6 * 2e-6;
    }
    let t = text(r.validate());
    assert!(
        t.starts_with("freq_hz: not uniformly spaced: freq_hz[2]"),
        "{t}"
    );
}

#[test]
fn non_finite_sample_named_by_index() {
    let mut r = cfr(3, 4, 5);
    // [s, p, i] = [2, 1, 3]
    r.samples[(2 * 4 + 1) * 5 + 3] = Complex::new(0.0, Real::INFINITY);
    assert_eq!(text(r.validate()), "cfr: sample [2, 1, 3] is not finite");
    let mut c = cir(8);
    c.samples[8 + 7] = Complex::new(Real::NAN, 0.0);
    assert_eq!(text(c.validate()), "cir: sample [0, 1, 7] is not finite");
}

#[test]
fn shapes_and_extras_are_checked() {
    let mut r = cfr(2, 2, 4);
    r.samples.pop();
    assert!(text(r.validate()).starts_with("cfr: 15 samples, expected S·P·N"));
    let mut r = cfr(2, 2, 4);
    r.noise_var = Some(vec![1.0, 0.0]);
    assert!(text(r.validate()).starts_with("noise_var: noise_var[1] = 0"));
    r.noise_var = Some(vec![1.0]);
    assert!(text(r.validate()).starts_with("noise_var: 1 values"));
    let mut r = cfr(2, 2, 4);
    r.layout = Layout::Cfr {
        freq_hz: vec![0.0, 1.0, 2.0, 3.0],
        system_response: Some(vec![Complex::new(1.0, 0.0); 3]),
    };
    assert!(text(r.validate()).starts_with("system_response: 3 values"));
    let mut c = cir(4);
    if let Layout::Cir { tap_spacing_s, .. } = &mut c.layout {
        *tap_spacing_s = 0.0;
    }
    assert!(text(c.validate()).starts_with("tap_spacing_s: must be > 0"));
    let mut c = cir(4);
    if let Layout::Cir { pulse: Some(p), .. } = &mut c.layout {
        p.samples[1] = Complex::new(2.0, 0.0);
    }
    assert!(text(c.validate()).starts_with("pulse: not normalised"));
    if let Layout::Cir { pulse: Some(p), .. } = &mut c.layout {
        p.normalise().unwrap();
        assert_eq!(p.samples[0], Complex::new(0.25, 0.0));
        p.spacing_s = -1.0;
    }
    assert!(text(c.validate()).starts_with("pulse_spacing_s: must be > 0"));
    let mut z = Pulse {
        samples: vec![
            Complex::new(1.0, 0.0),
            Complex::new(0.0, 0.0),
            Complex::new(1.0, 0.0),
        ],
        spacing_s: 1.0,
    };
    assert!(format!("{}", z.normalise().unwrap_err()).contains("p(0) is 0"));
}

#[test]
fn caps_are_enforced() {
    let r = cfr(1, 1, MAX_BINS_PER_LINK + 1);
    assert!(matches!(
        r.validate(),
        Err(Error::SizeLimit {
            field: "freq_hz",
            ..
        })
    ));
    // 256 snapshots × 4 links × 65 536 bins = 64 Mi + … over MAX_RECORDING_SAMPLES without
    // allocating them: the count is checked before the samples.
    let mut r = cfr(257, 4, 2);
    r.layout = Layout::Cfr {
        freq_hz: (0..65_536).map(|k| k as Real).collect(),
        system_response: None,
    };
    assert!(matches!(
        r.validate(),
        Err(Error::SizeLimit { field: "cfr", .. })
    ));
}

#[test]
fn link_map_follows_the_scenario_order() {
    let model = Model::new(&presets::preset("sensors2019").unwrap()).unwrap();
    let mut r = cfr(1, 4, 4);
    r.links = vec![[0, 3], [0, 1], [0, 0], [0, 2]];
    assert_eq!(r.link_map(&model).unwrap(), vec![3, 1, 0, 2]);
    r.links[1] = [0, 7];
    assert_eq!(
        format!("{}", r.link_map(&model).unwrap_err()),
        "links[1]: the link (transmitter 0, receiver 7) is not one of the scenario's 4 links"
    );
    r.links[1] = [0, 3];
    assert!(
        format!("{}", r.link_map(&model).unwrap_err()).contains("recorded twice (also links[0])")
    );
}
