//! The `.npz` recording format of docs/recording.md end to end: the documented numpy snippet is
//! run with Debian's `/usr/bin/python3` (python3-numpy, installed by scripts/setup.sh), both files
//! it writes (`np.savez` and `np.savez_compressed`, with the optional `synchronized` flag) are
//! read with `npz::read_recording`, and the committed int16 I/Q CIR fixture
//! (scripts/make-recording-fixture.py) is read back value by value.

use std::path::PathBuf;
use std::process::Command;

use scatterloc::channel::{Layout, Recording};
use scatterloc::math::{cos, sin, Complex, Real};
use scatterloc::npz::read_recording;
use scatterloc::scenario::presets;
use scatterloc::Model;

const DOC: &str = include_str!("../../docs/recording.md");
const PYTHON: &str = "/usr/bin/python3";

/// The Python between the snippet markers, without its ```python fence.
fn snippet() -> String {
    let start = DOC
        .find("<!-- recording-snippet:start -->")
        .expect("docs/recording.md has the snippet start marker");
    let end = DOC
        .find("<!-- recording-snippet:end -->")
        .expect("docs/recording.md has the snippet end marker");
    let block = &DOC[start..end];
    let open = block.find("```python\n").expect("a ```python block") + "```python\n".len();
    let close = block[open..].find("```").expect("the block is closed") + open;
    block[open..close].to_owned()
}

fn temp_dir() -> PathBuf {
    let d = std::env::temp_dir().join(format!("scatterloc-recording-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Fails (not skips) without Debian's python3 with numpy.
fn require_numpy() {
    let ok = Command::new(PYTHON)
        .args(["-c", "import numpy"])
        .status()
        .map(|s| s.success())
        .unwrap_or(false);
    assert!(
        ok,
        "{PYTHON} with numpy is missing: run scripts/setup.sh (python3-numpy)"
    );
}

/// `|Σ_n H[n] e^{+j2π f_n τ}|`: the periodogram of one CFR at delay `tau`.
fn periodogram(h: &[Complex], f: &[Real], tau: Real) -> Real {
    let mut acc = Complex::new(0.0, 0.0);
    for (z, &fn_) in h.iter().zip(f) {
        let ph = 2.0 * core::f64::consts::PI * fn_ * tau;
        acc += z * Complex::new(cos(ph), sin(ph));
    }
    (acc.re * acc.re + acc.im * acc.im).sqrt()
}

/// The delay of the periodogram's maximum on 0 … 200 ns: a 0.5 ns grid, then ± 1 ns around its
/// best point at 0.01 ns.
fn peak_delay(h: &[Complex], f: &[Real]) -> Real {
    let best = |taus: &mut dyn Iterator<Item = Real>| {
        taus.map(|t| (t, periodogram(h, f, t)))
            .fold((0.0, -1.0), |a, b| if b.1 > a.1 { b } else { a })
            .0
    };
    let coarse = best(&mut (0..=400).map(|k| k as Real * 0.5e-9));
    best(&mut (0..=200).map(|k| coarse - 1e-9 + k as Real * 0.01e-9))
}

#[test]
fn documented_numpy_snippet_writes_a_valid_recording() {
    require_numpy();
    let dir = temp_dir();
    let script = dir.join("snippet.py");
    std::fs::write(&script, snippet()).unwrap();
    let (plain, packed) = (dir.join("rec.npz"), dir.join("rec-compressed.npz"));
    let out = Command::new(PYTHON)
        .arg(&script)
        .arg(&plain)
        .arg(&packed)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "the snippet failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let read = |p: &PathBuf| read_recording(&std::fs::read(p).unwrap()).unwrap();
    let (a, b): (Recording, Recording) = (read(&plain), read(&packed));
    std::fs::remove_dir_all(&dir).ok();
    assert_eq!(
        a, b,
        "np.savez and np.savez_compressed give the same recording"
    );
    a.validate().unwrap();
    assert_eq!(a.snapshot_count(), 100);
    assert_eq!(a.link_count(), 4);
    assert_eq!(a.samples_per_link(), 241);
    assert_eq!(a.samples.len(), 100 * 4 * 241);
    assert_eq!(a.t_s[99], 99.0 * 2.048e-3);
    assert_eq!(a.noise_var, Some(vec![1e-14; 4]));
    // `synchronized=np.bool_(True)`: numpy's bool scalar, read as a common clock.
    assert_eq!(a.synchronized, Some(true));
    let model = Model::new(&presets::sensors2019()).unwrap();
    assert_eq!(a.link_map(&model).unwrap(), vec![0, 1, 2, 3]);
    let Layout::Cfr {
        freq_hz,
        system_response,
    } = &a.layout
    else {
        panic!("the snippet writes cfr");
    };
    assert!(system_response.is_none());
    // f_n = (n − 120)·B/N with B = 120 MHz, N = 241.
    let df = 120e6 / 241.0;
    assert!((freq_hz[0] + 120.0 * df).abs() < 1e-6);
    assert!((freq_hz[240] - 120.0 * df).abs() < 1e-6);
    // The strongest path's delay per link (the snippet's first column of tau): the periodogram's
    // peak. The second path is 35–45 ns away (≥ 4.2/B) and the noise 40 dB below the first path
    // per sample (64 dB over 241 bins); measured worst over the 400 link-snapshots 0.19 ns
    // (sidelobe of the second path, 0.01 ns grid). The bound 0.5 ns is 6 % of the resolution 1/B.
    let first = [40e-9, 55e-9, 70e-9, 85e-9];
    let mut worst: Real = 0.0;
    for s in 0..a.snapshot_count() {
        for (p, &tau) in first.iter().enumerate() {
            let d = peak_delay(a.response(s, p), freq_hz);
            worst = worst.max((d - tau).abs());
            assert!(
                (d - tau).abs() < 0.5e-9,
                "snapshot {s} link {p}: peak at {d:e} s, the first path at {tau:e} s"
            );
        }
    }
    eprintln!("largest |periodogram peak − first path delay|: {worst:e} s");
}

/// The committed fixture of scripts/make-recording-fixture.py: int16 I/Q CIR, 3 snapshots × 4
/// links × 64 taps, tap m of link p in snapshot s = (100s + 10p + m − 500) + j(7m − 3p − 200 + s).
#[test]
fn int16_cir_fixture_reads_the_values_numpy_wrote() {
    let bytes = include_bytes!("../data/recording-cir-int16.npz");
    let r = read_recording(bytes).unwrap();
    assert_eq!(
        (r.snapshot_count(), r.link_count(), r.samples_per_link()),
        (3, 4, 64)
    );
    assert_eq!(r.t_s, vec![0.0, 2.048e-3, 4.096e-3]);
    assert_eq!(r.links, vec![[0, 0], [0, 1], [0, 2], [0, 3]]);
    assert_eq!(
        r.layout,
        Layout::Cir {
            tap0_s: -10e-9,
            tap_spacing_s: 1.0 / 240e6,
            pulse: None
        }
    );
    assert_eq!(r.noise_var, None);
    for s in 0..3 {
        for p in 0..4 {
            for (m, z) in r.response(s, p).iter().enumerate() {
                let (s, p, m) = (s as Real, p as Real, m as Real);
                let want = Complex::new(
                    100.0 * s + 10.0 * p + m - 500.0,
                    7.0 * m - 3.0 * p - 200.0 + s,
                );
                assert_eq!(*z, want, "[{s}, {p}, {m}]");
            }
        }
    }
    // Two taps spelled out: [0, 0, 0] = −500 − 200j, [2, 3, 63] = −207 + 234j.
    assert_eq!(r.response(0, 0)[0], Complex::new(-500.0, -200.0));
    assert_eq!(r.response(2, 3)[63], Complex::new(-207.0, 234.0));
    let model = Model::new(&presets::sensors2019()).unwrap();
    assert_eq!(r.link_map(&model).unwrap(), vec![0, 1, 2, 3]);
}
