//! The simple reference of spec C12 8, written here independently of the estimator under test:
//! background subtraction (the plain mean of the empty area's snapshots), a Hann-windowed,
//! zero-padded IFFT (this file's own radix-2), the three strongest peaks per link (parabolic
//! interpolation), and a gated EKF (its own: CV model, scalar range updates, a 3σ gate) started
//! at the true first position. Delays as path length, m.

use scatterloc::channel::Recording;
use scatterloc::math::{Complex, Mat4, Real, Vec4};
use scatterloc::Model;

/// Zero-padded transform length.
const L: usize = 4096;
/// Peaks per link.
const PEAKS: usize = 3;
/// Range measurement σ of the reference EKF, m (a person's extent and the peak's scatter).
const SIGMA_M: Real = 0.3;
/// Process-noise intensity, m²/s³ (the tracker's default).
const Q: Real = 1.0;
const C: Real = 299_792_458.0;

/// In-place iterative radix-2 FFT with `e^{+j2πkm/n}` (an inverse DFT, unscaled).
fn ifft(x: &mut [Complex]) {
    let n = x.len();
    let mut j = 0;
    for i in 1..n {
        let mut bit = n >> 1;
        while j & bit != 0 {
            j ^= bit;
            bit >>= 1;
        }
        j |= bit;
        if i < j {
            x.swap(i, j);
        }
    }
    let mut len = 2;
    while len <= n {
        let ang = 2.0 * std::f64::consts::PI / len as Real;
        let w = Complex::new(ang.cos(), ang.sin());
        for start in (0..n).step_by(len) {
            let mut wk = Complex::new(1.0, 0.0);
            for k in 0..len / 2 {
                let a = x[start + k];
                let b = x[start + k + len / 2] * wk;
                x[start + k] = a + b;
                x[start + k + len / 2] = a - b;
                wk *= w;
            }
        }
        len <<= 1;
    }
}

/// The three strongest peaks (path length, m) of link `p`'s residual in snapshot `s`.
fn peaks(rec: &Recording, bg: &[Complex], s: usize, p: usize, df: Real) -> Vec<Real> {
    let h = rec.response(s, p);
    let n = h.len();
    let mut x = vec![Complex::new(0.0, 0.0); L];
    for i in 0..n {
        let w = 0.5 - 0.5 * (2.0 * std::f64::consts::PI * i as Real / (n - 1) as Real).cos();
        x[i] = (h[i] - bg[i]) * w;
    }
    ifft(&mut x);
    let pw: Vec<Real> = x.iter().map(|v| v.norm_sqr()).collect();
    // Delay of cell k: k/(LΔf) (the phase origin at bin 0 only rotates the phase).
    let cell = C / (L as Real * df);
    let mut cand: Vec<(Real, Real)> = Vec::new();
    // Only the first half of the span: bistatic ranges of the area, not the wrapped tail.
    for k in 1..L / 2 {
        if pw[k] > pw[k - 1] && pw[k] >= pw[k + 1] {
            let (y0, y1, y2) = (pw[k - 1].sqrt(), pw[k].sqrt(), pw[k + 1].sqrt());
            let den = y0 - 2.0 * y1 + y2;
            let off = if den < 0.0 {
                0.5 * (y0 - y2) / den
            } else {
                0.0
            };
            cand.push((pw[k], (k as Real + off) * cell));
        }
    }
    cand.sort_by(|a, b| b.0.total_cmp(&a.0));
    cand.iter().take(PEAKS).map(|c| c.1).collect()
}

/// The reference's track: a state per snapshot (the first is the start).
pub fn track(model: &Model, rec: &Recording, empty: &Recording, x0: [Real; 2]) -> Vec<[Real; 2]> {
    let freq = match &rec.layout {
        scatterloc::channel::Layout::Cfr { freq_hz, .. } => freq_hz.clone(),
        _ => panic!("the corpus is in the cfr layout"),
    };
    let df = freq[1] - freq[0];
    let (links, n) = (rec.link_count(), freq.len());
    // Background: the plain mean of the empty area's snapshots.
    let bg: Vec<Vec<Complex>> = (0..links)
        .map(|p| {
            let mut m = vec![Complex::new(0.0, 0.0); n];
            for s in 0..empty.snapshot_count() {
                for (a, v) in m.iter_mut().zip(empty.response(s, p)) {
                    *a += v;
                }
            }
            m.iter()
                .map(|v| v / empty.snapshot_count() as Real)
                .collect()
        })
        .collect();
    let map = rec.link_map(model).unwrap();
    let net = &model.network;
    let mut x = Vec4::new(x0[0], x0[1], 0.0, 0.0);
    let mut pm = Mat4::from_diagonal(&Vec4::new(0.25, 0.25, 1.0, 1.0));
    let mut out = vec![[x[0], x[1]]];
    for s in 1..rec.snapshot_count() {
        let dt = rec.t_s[s] - rec.t_s[s - 1];
        let f = Mat4::new(
            1.0, 0.0, dt, 0.0, 0.0, 1.0, 0.0, dt, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0,
        );
        let (q3, q2, q1) = (Q * dt * dt * dt / 3.0, Q * dt * dt / 2.0, Q * dt);
        let qm = Mat4::new(
            q3, 0.0, q2, 0.0, 0.0, q3, 0.0, q2, q2, 0.0, q1, 0.0, 0.0, q2, 0.0, q1,
        );
        x = f * x;
        pm = f * pm * f.transpose() + qm;
        for (p, &li) in map.iter().enumerate() {
            let l = &net.links[li];
            let (t, r) = (net.transmitters[l.tx], net.receivers[l.rx]);
            let (dtx, dty) = (x[0] - t.x, x[1] - t.y);
            let (drx, dry) = (x[0] - r.x, x[1] - r.y);
            let (nt, nr) = (
                (dtx * dtx + dty * dty).sqrt(),
                (drx * drx + dry * dry).sqrt(),
            );
            let pred = nt + nr;
            let hrow = Vec4::new(dtx / nt + drx / nr, dty / nt + dry / nr, 0.0, 0.0);
            let sv = (hrow.transpose() * pm * hrow)[0] + SIGMA_M * SIGMA_M;
            let best = peaks(rec, &bg[p], s, p, df)
                .into_iter()
                .map(|z| (z - pred, ((z - pred) * (z - pred)) / sv))
                .filter(|v| v.1 <= 9.0)
                .min_by(|a, b| a.1.total_cmp(&b.1));
            if let Some((nu, _)) = best {
                let k = pm * hrow / sv;
                x += k * nu;
                let i_kh = Mat4::identity() - k * hrow.transpose();
                pm = i_kh * pm * i_kh.transpose() + k * k.transpose() * (SIGMA_M * SIGMA_M);
            }
        }
        out.push([x[0], x[1]]);
    }
    out
}
