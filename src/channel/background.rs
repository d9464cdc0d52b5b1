//! The static channel at the signal level (C9): a link's background `H̄` (the coherent mean of
//! an empty-area recording, or a recursive mean learnt from the walk itself), each snapshot's
//! alignment to it (timing offset `δ` and complex gain `g`) and the residual the snapshot
//! estimator (C5) then runs on.
//!
//! Model (C9): `H^{(s)}[n] = g^{(s)} e^{−j2πf_nδ^{(s)}} H̄[n] + D^{(s)}[n] + w[n]`.
//!
//! - **Alignment** (C9 step 2): `δ̂` maximises `J(δ) = |ρ(δ)|²`, `ρ(δ) = Σ_n H̄*[n] H[n]
//!   e^{j2πf_nδ}` — Newton from 0 (at most [`limits::NEWTON_ITERATIONS`] steps of at most
//!   `1/(4B)`: a synchronised sounder's drift), or, for receivers without a common clock (C10),
//!   from the peak of `|ρ|²` on the grid of one zero-padded FFT over the whole unambiguous span
//!   (a parabola through the peak cell first); then `ĝ = ρ(δ̂)/Σ|H̄|²` (least squares).
//! - **Joint alignment** (C9 step 2 with the dynamic part, C10): `δ`, `g` and the strongest
//!   dynamic paths refined together by Levenberg–Marquardt ([`LinkBackground::joint_align`]):
//!   the separate alignment leaves the residual as the dynamic part minus its projection on the
//!   background.
//! - **Residual** (C9 step 3), in the background's time base and gain: `r[n] = H[n]
//!   e^{j2πf_nδ̂}/ĝ − H̄[n]`, so the residual's delays are those of the background (an empty-area
//!   recording's timing) and its amplitudes are relative to the background's gain (AGC steps
//!   and the carrier phase drop out). Its noise variance is `σ²/|ĝ|² + σ̄²`, `σ̄²` the
//!   background's own (`σ²/S_bg` for the mean of `S_bg` snapshots: C9's `σ²(1 + 1/S_bg)`).
//! - **From an empty-area recording** (C9 step 1): every snapshot aligned to the first and
//!   averaged, then every snapshot aligned again to that mean and averaged (two passes: the
//!   second reference is `S_bg` times less noisy).
//! - **Recursive** (no empty-area recording, C9 step 1 **[choice]**): `H̄₀ = H₀`, then
//!   `H̄ ← (1 − λ_k)H̄ + λ_k·H_aligned` with `λ_k = max(Δt/τ_bg, 1/(k+1))` — the plain mean of the
//!   first `τ_bg/Δt` snapshots, then exponential forgetting with time constant `τ_bg` (default
//!   [`DEFAULT_BACKGROUND_TIME_S`]). Every snapshot updates it: a person walks through a
//!   resolution cell (`c/B` of path length) in about a second, so a moving echo enters the mean
//!   at about `Δt_cell/τ_bg` of its amplitude (−20 dB at 10 s) and the echo of the start position
//!   fades as `1/k`; a person standing still is absorbed after about `τ_bg`. Spec C9 updates only
//!   over snapshots without a dynamic path; with a walker present from the first snapshot that
//!   rule never updates, so this module does not apply it (stated in docs/reproduction.md).

// `!(x > 0.0)` is meant: a NaN must fail these checks as well.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use alloc::vec;
use alloc::vec::Vec;

use crate::channel::band::cis;
use crate::channel::fft::PaddedFft;
use crate::channel::Band;
use crate::error::{limits, Error, Result};
use crate::math::{Complex, Real, PI};

/// Default time constant `τ_bg` of the recursive background, s.
pub const DEFAULT_BACKGROUND_TIME_S: Real = 10.0;

/// How a snapshot is aligned to the background (C9 step 2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum AlignMode {
    /// No alignment (`δ = 0`, `g = 1`): a synchronised sounder without AGC. An alignment
    /// estimated with the walker present is biased by about `‖D‖/‖H̄‖` and leaks every static
    /// path into the residual at that level below its own strength (tested), so a sounder
    /// that needs none is best served without.
    #[default]
    Off,
    /// Newton from `δ = 0` (a synchronised sounder's drift of a fraction of `1/B`).
    Fine,
    /// The peak of `|ρ(δ)|²` over the whole unambiguous span first (one FFT), then Newton:
    /// receivers without a common clock (C10), timing offsets of any size.
    Coarse,
}

/// One snapshot's alignment to the background (C9 step 2).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Alignment {
    /// `δ̂`, s: the snapshot's timing offset against the background (in `[−1/(2Δf), 1/(2Δf))`).
    pub delay_s: Real,
    /// `ĝ`: its complex gain against the background (AGC, carrier phase).
    pub gain: Complex,
}

impl Alignment {
    /// No offset, unit gain.
    pub const NONE: Alignment = Alignment {
        delay_s: 0.0,
        gain: Complex::new(1.0, 0.0),
    };
}

/// The background of one link (C9): `H̄` on a band's bins and its noise variance.
#[derive(Debug, Clone, PartialEq)]
pub struct LinkBackground {
    mean: Vec<Complex>,
    /// `Σ|H̄|²`.
    energy: Real,
    /// Noise variance of `H̄` per bin, W (0 when unknown).
    noise_var: Real,
    /// Snapshots averaged into it (for the recursive mean: updates so far).
    count: usize,
    align: AlignMode,
    /// `f_n − f_c`, Hz, and the spacing.
    fc: Vec<Real>,
    df: Real,
    fft: PaddedFft,
    scratch: Vec<Complex>,
    tmp: Vec<Complex>,
    /// The band's system response `P[n]` (a path's column is `P[n]e^{−j2πf_nτ}`).
    response: Vec<Complex>,
}

/// A snapshot's alignment refined jointly with its strongest dynamic paths
/// ([`LinkBackground::joint_align`]).
#[derive(Debug, Clone, PartialEq)]
pub struct JointAlignment {
    /// The refined alignment.
    pub alignment: Alignment,
    /// The refined paths `(τ, α)`, in the background's time base and gain.
    pub paths: Vec<(Real, Complex)>,
    /// Levenberg–Marquardt iterations made.
    pub iterations: usize,
    /// Whether the fit converged before [`limits::JOINT_ALIGN_ITERATIONS`] (or the bound given).
    pub converged: bool,
}

impl LinkBackground {
    /// A background of `band` from a first response `h0` (a recursive mean's start, or the
    /// reference of [`LinkBackground::from_snapshots`]); `noise_var` the per-bin noise of `h0`
    /// when known (0: unknown). Errors: `h0` of the wrong length or non-finite.
    pub fn new(band: &Band, h0: &[Complex], noise_var: Real, align: AlignMode) -> Result<Self> {
        check_response(band, h0)?;
        let n = band.len();
        let fcen = 0.5 * (band.freq_hz[0] + band.freq_hz[n - 1]);
        let l = (4 * n).next_power_of_two();
        let mut bg = LinkBackground {
            mean: h0.to_vec(),
            energy: 0.0,
            noise_var: noise_var.max(0.0),
            count: 1,
            align,
            fc: band.freq_hz.iter().map(|f| f - fcen).collect(),
            df: band.spacing_hz(),
            fft: PaddedFft::new(n, l),
            scratch: vec![Complex::new(0.0, 0.0); l],
            tmp: vec![Complex::new(0.0, 0.0); n],
            response: band.response.clone(),
        };
        bg.energy = bg.mean.iter().map(|v| v.norm_sqr()).sum();
        Ok(bg)
    }

    /// The coherent mean of `snapshots` (an empty-area recording of one link, ≥ 1 response)
    /// after aligning each to the first, then each again to that mean (C9 step 1); per-bin
    /// noise `noise_var` of one snapshot when known (0: unknown). Returns the background and
    /// each snapshot's alignment of the second pass. Errors: no snapshot, a response of the
    /// wrong length or non-finite.
    pub fn from_snapshots<'a>(
        band: &Band,
        snapshots: impl Iterator<Item = &'a [Complex]> + Clone,
        noise_var: Real,
        align: AlignMode,
    ) -> Result<(LinkBackground, Vec<Alignment>)> {
        let mut it = snapshots.clone();
        let first = it.next().ok_or(Error::SizeLimit {
            field: "background snapshots",
            value: 0,
            min: 1,
            max: limits::MAX_SNAPSHOTS,
        })?;
        let mut bg = LinkBackground::new(band, first, noise_var, align)?;
        let mut aligned = Vec::new();
        for _pass in 0..2 {
            let mut sum = vec![Complex::new(0.0, 0.0); band.len()];
            let mut nv = 0.0;
            aligned.clear();
            for h in snapshots.clone() {
                let a = bg.align(h)?;
                bg.rotate(h, &a);
                for (s, v) in sum.iter_mut().zip(&bg.tmp) {
                    *s += v;
                }
                nv += noise_var / a.gain.norm_sqr().max(Real::MIN_POSITIVE);
                aligned.push(a);
            }
            let k = aligned.len() as Real;
            for s in &mut sum {
                *s /= k;
            }
            bg.mean = sum;
            bg.energy = bg.mean.iter().map(|v| v.norm_sqr()).sum();
            bg.noise_var = if nv.is_finite() { nv / (k * k) } else { 0.0 };
            bg.count = aligned.len();
        }
        Ok((bg, aligned))
    }

    /// `H̄`.
    pub fn mean(&self) -> &[Complex] {
        &self.mean
    }

    /// The noise variance of `H̄` per bin, W (0 when unknown).
    pub fn noise_var(&self) -> Real {
        self.noise_var
    }

    /// The snapshots averaged into `H̄` (for the recursive mean: its updates so far plus one).
    pub fn count(&self) -> usize {
        self.count
    }

    /// The alignment of `h` to the background (C9 step 2; module docs). A background of zero
    /// energy aligns nothing ([`Alignment::NONE`]); so does a zero correlation.
    /// Errors: `h` of the wrong length or non-finite.
    pub fn align(&mut self, h: &[Complex]) -> Result<Alignment> {
        self.check(h)?;
        if !(self.energy > 0.0) {
            return Ok(Alignment::NONE);
        }
        for ((t, m), v) in self.tmp.iter_mut().zip(&self.mean).zip(h) {
            *t = m.conj() * v;
        }
        let span = 1.0 / self.df;
        let mut d = 0.0;
        if self.align == AlignMode::Off {
            return Ok(Alignment::NONE);
        }
        if self.align == AlignMode::Coarse {
            self.fft.run(&self.tmp, &mut self.scratch);
            let (mut best, mut slot) = (-1.0, 0usize);
            for (s, v) in self.scratch.iter().enumerate() {
                let p = v.norm_sqr();
                if p > best {
                    best = p;
                    slot = s;
                }
            }
            let l = self.fft.len();
            let k = self.fft.natural()[slot] as usize;
            let off = self.fft.parabola(&self.scratch, slot as u32);
            d = (k as Real + off) * span / l as Real;
            if d >= 0.5 * span {
                d -= span;
            }
        }
        Ok(self.newton_from(d))
    }

    /// The alignment of `h` refined **jointly** with its dynamic part (C9 step 2 with the
    /// model `h = e^{−j2πf_nδ}(g·H̄ + Σ_i β_i P e^{−j2πf_nτ_i}) + w`, C10): Levenberg–Marquardt
    /// over `δ`, `g`, and the delays `τ_i` and amplitudes `β_i = g·α_i` of the strongest
    /// [`limits::JOINT_ALIGN_PATHS`] of `paths` (`(τ, α)` in the background's time base and
    /// gain, e.g. the estimator's fit of the residual of `a`), from `a` and those paths, at
    /// most `max_iterations` iterations (each a damped Gauss–Newton step on the exact
    /// Jacobian, delay steps at most `1/(4B)`; within one, the damping grows tenfold per
    /// rejected step from at least 10⁻¹² to at most 10¹², so at most 25 tries), the linear
    /// parameters started by least squares at the first fit's delays.
    ///
    /// Why jointly: an alignment fitted to the whole background by least squares leaves the
    /// residual as the dynamic part *minus its projection on the background*, so where the
    /// echo overlaps a strong static path the residual holds a copy of that path at the echo's
    /// own level, the estimator fits it, and realigning with the fitted paths taken out and
    /// held fixed stays where it is (the copy and a shift of the snapshot explain the data
    /// alike, a valley that alternating steps do not leave: measured on the hangar walk with
    /// free-running receivers, C12 9's ratio over 12 seeds had a median of 1.43 that way, 1.12
    /// with the joint step). The joint step moves both at once.
    ///
    /// Returns `a` unchanged (no iterations) without paths, without background energy or
    /// with alignment off. Errors: `h` of the wrong length or non-finite.
    pub fn joint_align(
        &mut self,
        h: &[Complex],
        paths: &[(Real, Complex)],
        a: &Alignment,
        max_iterations: usize,
    ) -> Result<JointAlignment> {
        self.check(h)?;
        let mut ps: Vec<(Real, Complex)> = paths
            .iter()
            .copied()
            .filter(|p| p.0.is_finite() && p.1.re.is_finite() && p.1.im.is_finite())
            .collect();
        ps.sort_by(|x, y| y.1.norm_sqr().total_cmp(&x.1.norm_sqr()));
        ps.truncate(limits::JOINT_ALIGN_PATHS);
        let unchanged = JointAlignment {
            alignment: *a,
            paths: paths.to_vec(),
            iterations: 0,
            converged: true,
        };
        if ps.is_empty() || !(self.energy > 0.0) || self.align == AlignMode::Off {
            return Ok(unchanged);
        }
        let k = ps.len();
        let n = self.fc.len();
        let mut d = a.delay_s;
        let mut taus: Vec<Real> = ps.iter().map(|p| p.0).collect();
        // The linear parameters (g, β) by least squares at the starting delays.
        let Some(mut lin) = self.linear_fit(h, d, &taus) else {
            return Ok(unchanged);
        };
        let mut model = vec![Complex::new(0.0, 0.0); n];
        let mut trial = vec![Complex::new(0.0, 0.0); n];
        let mut cost = self.joint_cost(h, d, &taus, &lin, &mut model);
        // Parameters: δ, τ_1..τ_k, Re g, Im g, Re β_1, Im β_1, …
        let m = 3 + 3 * k;
        let max_step = 0.25 / (self.df * n as Real);
        let mut lambda = 1e-3;
        let mut cols = vec![Complex::new(0.0, 0.0); m * n];
        let mut iterations = 0;
        let mut converged = false;
        let tp = 2.0 * PI;
        let j = Complex::new(0.0, 1.0);
        while iterations < max_iterations {
            iterations += 1;
            // Columns (order δ, τ_1..τ_k, Re g, Im g, Re β_i, Im β_i …) at the current point;
            // `model` holds the model there.
            let (mut sh, ds, mut phs) = self.phasors(d, &taus);
            for i in 0..n {
                let f = self.fc[i];
                let w = Complex::new(0.0, -tp * f);
                cols[i] = w * model[i];
                let u = sh * self.mean[i];
                cols[(1 + k) * n + i] = u;
                cols[(2 + k) * n + i] = j * u;
                for (q, ph) in phs.iter_mut().enumerate() {
                    let v = sh * self.response[i] * ph.0;
                    cols[(1 + q) * n + i] = w * lin[1 + q] * v;
                    cols[(3 + k + 2 * q) * n + i] = v;
                    cols[(4 + k + 2 * q) * n + i] = j * v;
                    ph.0 *= ph.1;
                }
                sh *= ds;
            }
            let mut fim = vec![0.0; m * m];
            let mut grad = vec![0.0; m];
            for r in 0..m {
                let cr = &cols[r * n..(r + 1) * n];
                let mut gsum = Complex::new(0.0, 0.0);
                for (x, (hv, mv)) in cr.iter().zip(h.iter().zip(&model)) {
                    gsum += x.conj() * (hv - mv);
                }
                grad[r] = gsum.re;
                for c in r..m {
                    let cc = &cols[c * n..(c + 1) * n];
                    let v: Complex = cr.iter().zip(cc).map(|(x, y)| x.conj() * y).sum();
                    fim[r * m + c] = v.re;
                    fim[c * m + r] = v.re;
                }
            }
            let mut improved = false;
            while lambda <= 1e12 {
                let mut sys = fim.clone();
                for i in 0..m {
                    sys[i * m + i] *= 1.0 + lambda;
                }
                let Some(inv) = crate::channel::estimate::inverse_spd_scaled(sys, m) else {
                    lambda *= 10.0;
                    continue;
                };
                let step: Vec<Real> = (0..m)
                    .map(|r| (0..m).map(|c| inv[r * m + c] * grad[c]).sum())
                    .collect();
                let dd = step[0].clamp(-max_step, max_step);
                let tt: Vec<Real> = (0..k)
                    .map(|q| taus[q] + step[1 + q].clamp(-max_step, max_step))
                    .collect();
                let mut ll = lin.clone();
                ll[0] += Complex::new(step[1 + k], step[2 + k]);
                for q in 0..k {
                    ll[1 + q] += Complex::new(step[3 + k + 2 * q], step[4 + k + 2 * q]);
                }
                let c_new = self.joint_cost(h, d + dd, &tt, &ll, &mut trial);
                if c_new.is_finite() && c_new < cost {
                    let rel = (cost - c_new) / cost.max(Real::MIN_POSITIVE);
                    d += dd;
                    taus = tt;
                    lin = ll;
                    core::mem::swap(&mut model, &mut trial);
                    cost = c_new;
                    lambda = (lambda * 0.1).max(1e-12);
                    improved = true;
                    if rel < 1e-10 {
                        converged = true;
                    }
                    break;
                }
                lambda *= 10.0;
            }
            if !improved {
                // No step lowers the cost: a (local) minimum.
                converged = true;
            }
            if converged {
                break;
            }
        }
        let g = lin[0];
        if !(g.norm_sqr() > 0.0) || !d.is_finite() {
            return Ok(unchanged);
        }
        let span = 1.0 / self.df;
        let d_wrapped = d - span * crate::math::round(d / span);
        Ok(JointAlignment {
            alignment: Alignment {
                delay_s: d_wrapped,
                gain: g,
            },
            paths: taus
                .iter()
                .zip(&lin[1..])
                .map(|(&t, &b)| (t, b / g))
                .collect(),
            iterations,
            converged,
        })
    }

    /// `(g, β_1..β_k)` minimising `‖h − e^{−j2πfδ}(gH̄ + Σβ_i P e^{−j2πfτ_i})‖²`; `None` when
    /// the normal equations are singular.
    fn linear_fit(&self, h: &[Complex], d: Real, taus: &[Real]) -> Option<Vec<Complex>> {
        let k = taus.len() + 1;
        let n = self.fc.len();
        let mut cols = vec![Complex::new(0.0, 0.0); k * n];
        let (mut sh, ds, mut phs) = self.phasors(d, taus);
        for i in 0..n {
            cols[i] = sh * self.mean[i];
            for (q, ph) in phs.iter_mut().enumerate() {
                cols[(1 + q) * n + i] = sh * self.response[i] * ph.0;
                ph.0 *= ph.1;
            }
            sh *= ds;
        }
        let mut g = vec![Complex::new(0.0, 0.0); k * k];
        let mut b = vec![Complex::new(0.0, 0.0); k];
        for r in 0..k {
            let cr = &cols[r * n..(r + 1) * n];
            b[r] = cr.iter().zip(h).map(|(x, y)| x.conj() * y).sum();
            for c in 0..k {
                let cc = &cols[c * n..(c + 1) * n];
                g[r * k + c] = cr.iter().zip(cc).map(|(x, y)| x.conj() * y).sum();
            }
        }
        crate::channel::estimate::solve_complex(&mut g, &mut b, k)
    }

    /// The phasors of the joint model at the first bin and their steps per bin: the shift
    /// `e^{−j2πf_0δ}` and its step `e^{−j2πΔfδ}`, and per delay `τ_i` the pair
    /// `(e^{−j2πf_0τ_i}, e^{−j2πΔfτ_i})`.
    fn phasors(&self, d: Real, taus: &[Real]) -> (Complex, Complex, Vec<(Complex, Complex)>) {
        let tp = 2.0 * PI;
        let at = |t: Real| (cis(-tp * self.fc[0] * t), cis(-tp * self.df * t));
        let (sh, ds) = at(d);
        (sh, ds, taus.iter().map(|&t| at(t)).collect())
    }

    /// `‖h − model‖²` of the joint model at `(δ, τ, (g, β))`, the model written to `out`.
    fn joint_cost(
        &self,
        h: &[Complex],
        d: Real,
        taus: &[Real],
        lin: &[Complex],
        out: &mut [Complex],
    ) -> Real {
        let (mut sh, ds, mut phs) = self.phasors(d, taus);
        let mut cost = 0.0;
        for (i, o) in out.iter_mut().enumerate() {
            let mut v = lin[0] * self.mean[i];
            for (q, ph) in phs.iter_mut().enumerate() {
                v += lin[1 + q] * self.response[i] * ph.0;
                ph.0 *= ph.1;
            }
            *o = sh * v;
            cost += (h[i] - *o).norm_sqr();
            sh *= ds;
        }
        cost
    }

    /// Newton on `|ρ(δ)|²` over `tmp = H̄*·H` from `d` (at most [`limits::NEWTON_ITERATIONS`]
    /// steps of at most `1/(4B)`), then `ĝ`.
    fn newton_from(&self, mut d: Real) -> Alignment {
        let n = self.fc.len();
        let span = 1.0 / self.df;
        let max_step = 0.25 / (self.df * n as Real);
        let mut c0 = self.correlation(d).0;
        for _ in 0..limits::NEWTON_ITERATIONS {
            let (c, c1, c2) = self.correlation(d);
            c0 = c;
            let d1 = 2.0 * (c.conj() * c1).re;
            let d2 = 2.0 * (c1.norm_sqr() + (c.conj() * c2).re);
            let step = if d2 < 0.0 { -d1 / d2 } else { 0.0 };
            if !step.is_finite() || step == 0.0 {
                break;
            }
            let step = step.clamp(-max_step, max_step);
            d += step;
            if step.abs() < 1e-9 * max_step {
                c0 = self.correlation(d).0;
                break;
            }
        }
        let gain = c0 / self.energy;
        if !(gain.norm_sqr() > 0.0) || !(d.is_finite()) {
            return Alignment::NONE;
        }
        // Keep δ in [−span/2, span/2).
        let d = d - span * crate::math::round(d / span);
        Alignment { delay_s: d, gain }
    }

    /// `ρ(δ)` and its first two derivatives over `tmp = H̄*·H`.
    fn correlation(&self, d: Real) -> (Complex, Complex, Complex) {
        let mut ph = cis(2.0 * PI * self.fc[0] * d);
        let step = cis(2.0 * PI * self.df * d);
        let (mut c0, mut c1, mut c2) = (
            Complex::new(0.0, 0.0),
            Complex::new(0.0, 0.0),
            Complex::new(0.0, 0.0),
        );
        for (x, f) in self.tmp.iter().zip(&self.fc) {
            let y = x * ph;
            let w = 2.0 * PI * f;
            c0 += y;
            let yw = y * w;
            c1 += Complex::new(-yw.im, yw.re);
            c2 -= yw * w;
            ph *= step;
        }
        (c0, c1, c2)
    }

    /// `tmp` ← `h·e^{j2πf_nδ}/g` (the snapshot in the background's time base and gain).
    fn rotate(&mut self, h: &[Complex], a: &Alignment) {
        let mut ph = cis(2.0 * PI * self.fc[0] * a.delay_s) / a.gain;
        let step = cis(2.0 * PI * self.df * a.delay_s);
        for (t, v) in self.tmp.iter_mut().zip(h) {
            *t = v * ph;
            ph *= step;
        }
    }

    /// The residual of `h` aligned by `a` (C9 step 3): `out ← h·e^{j2πf_nδ}/g − H̄`, in the
    /// background's time base and gain.
    /// Errors: `h` of the wrong length or non-finite.
    pub fn residual(&mut self, h: &[Complex], a: &Alignment, out: &mut Vec<Complex>) -> Result<()> {
        self.check(h)?;
        self.rotate(h, a);
        out.clear();
        out.extend(self.tmp.iter().zip(&self.mean).map(|(v, m)| v - m));
        Ok(())
    }

    fn check(&self, h: &[Complex]) -> Result<()> {
        check_len_finite(self.mean.len(), h)
    }

    /// The residual's noise variance per bin for a snapshot of noise `noise_var` aligned by
    /// `a`: `σ²/|g|² + σ̄²`.
    pub fn residual_noise(&self, noise_var: Real, a: &Alignment) -> Real {
        noise_var / a.gain.norm_sqr().max(Real::MIN_POSITIVE) + self.noise_var
    }

    /// The recursive update with `h` aligned by `a` (the last [`LinkBackground::residual`]'s
    /// snapshot, whose rotated copy is kept): `H̄ ← (1 − λ)H̄ + λ·h_aligned`, `λ` in (0, 1];
    /// `noise_var` the snapshot's per-bin noise (0: unknown).
    pub fn update(&mut self, lambda: Real, noise_var: Real, a: &Alignment) {
        let l = lambda.clamp(0.0, 1.0);
        for (m, v) in self.mean.iter_mut().zip(&self.tmp) {
            *m = *m * (1.0 - l) + v * l;
        }
        self.energy = self.mean.iter().map(|v| v.norm_sqr()).sum();
        let nv = noise_var / a.gain.norm_sqr().max(Real::MIN_POSITIVE);
        self.noise_var = (1.0 - l) * (1.0 - l) * self.noise_var + l * l * nv;
        if !self.noise_var.is_finite() {
            self.noise_var = 0.0;
        }
        self.count += 1;
    }
}

/// `h` has the band's length and finite values.
fn check_response(band: &Band, h: &[Complex]) -> Result<()> {
    check_len_finite(band.len(), h)
}

/// `h` has `n` values, all finite.
fn check_len_finite(n: usize, h: &[Complex]) -> Result<()> {
    if h.len() != n {
        return Err(Error::LengthMismatch {
            field: "response",
            expected: n,
            found: h.len(),
        });
    }
    if h.iter().any(|v| !(v.re.is_finite() && v.im.is_finite())) {
        return Err(Error::NonFinite {
            field: "response".into(),
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests;
