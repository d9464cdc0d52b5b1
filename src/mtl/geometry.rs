//! Geometry primitives of the multi-target method (spec multi-target.md §5): the ellipse of a TRP
//! and a range (§5.1) and the ellipse–ellipse intersection (§5.2, at most four points, grazing
//! points dropped). No heap allocation.

use core::ops::Deref;

use crate::math::{cos, sin, sqrt, Real, Vec2, PI};
use crate::measure::{bistatic_range, iso_range_ellipse, range_gradient, Ellipse};
use crate::mtl::polygon::Rect;

/// Samples of `h(θ)` around ellipse 1 (§5.2).
pub const INTERSECTION_SAMPLES: usize = 720;
/// Tangency acceptance: a local minimum of `|h|` counts as a root below this times `ρ₂` (§5.2).
pub const TANGENCY_REL_TOL: Real = 1e-9;
/// Roots closer than this (m) are merged (§5.2).
pub const MERGE_DISTANCE_M: Real = 1e-6;
/// Points whose range-gradient matrix `G` has a condition number above this are grazing and
/// dropped (§5.2).
pub const MAX_GRADIENT_CONDITION: Real = 1e8;
/// Margin (m) by which the region is enlarged before points outside it are dropped (§5.2).
pub const REGION_MARGIN_M: Real = 1.0;

/// The ellipse `{x : ‖x − tx‖ + ‖x − rx‖ = ρ}` of one TRP (TX focus `tx`, RX focus `rx`) and one
/// measured range `ρ` (§5.1, (M1)).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RangeEllipse {
    /// TX position `u_{m_t}`, m.
    pub tx: Vec2,
    /// RX position `v_{m_r}`, m.
    pub rx: Vec2,
    /// Range `ρ`, m.
    pub range_m: Real,
    /// Centre, semi-axes and orientation (`a = ρ/2`, `b = √(a² − f²)`).
    pub ellipse: Ellipse,
}

impl RangeEllipse {
    /// The ellipse of foci `tx`, `rx` and range `range_m` (§5.1). `None` if a coordinate or the
    /// range is not finite or `ρ < 2f` (`f = ‖rx − tx‖/2`); degenerate (the segment, `b = 0`)
    /// when `ρ = 2f`.
    pub fn new(tx: Vec2, rx: Vec2, range_m: Real) -> Option<RangeEllipse> {
        if !(tx.x.is_finite() && tx.y.is_finite() && rx.x.is_finite() && rx.y.is_finite()) {
            return None;
        }
        let ellipse = iso_range_ellipse(tx, rx, range_m)?;
        Some(RangeEllipse {
            tx,
            rx,
            range_m,
            ellipse,
        })
    }

    /// Whether the ellipse is the focal segment (`ρ = 2f`, `b = 0`).
    pub fn is_degenerate(&self) -> bool {
        self.ellipse.semi_minor == 0.0
    }

    /// The TRP range `d(x) = ‖x − tx‖ + ‖x − rx‖` (M1), m.
    #[inline]
    pub fn range_at(&self, x: Vec2) -> Real {
        bistatic_range(self.tx, self.rx, x)
    }

    /// Residual `d(x) − ρ`, m.
    #[inline]
    pub fn residual(&self, x: Vec2) -> Real {
        self.range_at(x) - self.range_m
    }

    /// Gradient of `d` at `x`: the sum of the unit vectors from the foci (zero at a focus).
    #[inline]
    pub fn gradient(&self, x: Vec2) -> Vec2 {
        range_gradient(self.tx, self.rx, x)
    }

    /// Point at parameter `θ`: `c + a cos θ ê + b sin θ ê^⊥` (§5.2).
    #[inline]
    pub fn point(&self, theta: Real) -> Vec2 {
        self.ellipse.point(theta)
    }
}

/// At most four intersection points, without heap allocation. Dereferences to `[Vec2]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Intersections {
    points: [Vec2; 4],
    len: usize,
}

impl Intersections {
    /// No points.
    pub fn new() -> Intersections {
        Intersections {
            points: [Vec2::zeros(); 4],
            len: 0,
        }
    }

    /// The points as a slice.
    pub fn as_slice(&self) -> &[Vec2] {
        &self.points[..self.len]
    }

    fn push(&mut self, p: Vec2) {
        if self.len < 4 {
            self.points[self.len] = p;
            self.len += 1;
        }
    }
}

impl Default for Intersections {
    fn default() -> Self {
        Intersections::new()
    }
}

impl Deref for Intersections {
    type Target = [Vec2];
    fn deref(&self) -> &[Vec2] {
        self.as_slice()
    }
}

/// Condition number `σ_max/σ_min` of the 2×2 matrix with rows `g1`, `g2` (∞ when singular).
pub fn condition_number(g1: Vec2, g2: Vec2) -> Real {
    let det = (g1.x * g2.y - g1.y * g2.x).abs();
    let fro2 = g1.norm_squared() + g2.norm_squared();
    if det == 0.0 || !det.is_finite() {
        return Real::INFINITY;
    }
    // σ_max² + σ_min² = ‖G‖_F², σ_max σ_min = |det G|.
    let disc = sqrt((fro2 * fro2 - 4.0 * det * det).max(0.0));
    let smax2 = 0.5 * (fro2 + disc);
    smax2 / det
}

fn same_point(p: Vec2, q: Vec2, scale: Real) -> bool {
    (p - q).norm() <= 1e-12 * scale
}

/// Brent's root finder on `[a, b]` with `f(a)`, `f(b)` of opposite signs (or one zero).
fn brent<F: Fn(Real) -> Real>(f: &F, mut a: Real, mut b: Real, mut fa: Real, mut fb: Real) -> Real {
    if fa == 0.0 {
        return a;
    }
    if fb == 0.0 {
        return b;
    }
    let (mut c, mut fc) = (a, fa);
    let mut d = b - a;
    let mut e = d;
    for _ in 0..200 {
        if (fb > 0.0) == (fc > 0.0) {
            c = a;
            fc = fa;
            d = b - a;
            e = d;
        }
        if fc.abs() < fb.abs() {
            a = b;
            b = c;
            c = a;
            fa = fb;
            fb = fc;
            fc = fa;
        }
        let tol = 2.0 * Real::EPSILON * b.abs() + 1e-16;
        let m = 0.5 * (c - b);
        if m.abs() <= tol || fb == 0.0 {
            return b;
        }
        if e.abs() < tol || fa.abs() <= fb.abs() {
            d = m;
            e = m;
        } else {
            let s = fb / fa;
            let (mut p, mut q);
            if a == c {
                p = 2.0 * m * s;
                q = 1.0 - s;
            } else {
                let q0 = fa / fc;
                let r = fb / fc;
                p = s * (2.0 * m * q0 * (q0 - r) - (b - a) * (r - 1.0));
                q = (q0 - 1.0) * (r - 1.0) * (s - 1.0);
            }
            if p > 0.0 {
                q = -q;
            } else {
                p = -p;
            }
            if 2.0 * p < (3.0 * m * q - (tol * q).abs()).min((e * q).abs()) {
                e = d;
                d = p / q;
            } else {
                d = m;
                e = m;
            }
        }
        a = b;
        fa = fb;
        b += if d.abs() > tol {
            d
        } else if m > 0.0 {
            tol
        } else {
            -tol
        };
        fb = f(b);
    }
    b
}

/// Golden-section minimisation of `g` on `[lo, hi]`; returns the abscissa of the minimum found.
fn golden_min<F: Fn(Real) -> Real>(g: &F, mut lo: Real, mut hi: Real) -> Real {
    const R: Real = 0.618_033_988_749_894_8;
    let mut x1 = hi - R * (hi - lo);
    let mut x2 = lo + R * (hi - lo);
    let (mut g1, mut g2) = (g(x1), g(x2));
    for _ in 0..80 {
        if g1 < g2 {
            hi = x2;
            x2 = x1;
            g2 = g1;
            x1 = hi - R * (hi - lo);
            g1 = g(x1);
        } else {
            lo = x1;
            x1 = x2;
            g1 = g2;
            x2 = lo + R * (hi - lo);
            g2 = g(x2);
        }
    }
    if g1 < g2 {
        x1
    } else {
        x2
    }
}

/// Whether `cur` (non-zero) is a local minimum of `|·|` among three neighbouring samples of one
/// sign (a tangency candidate of §5.2).
fn same_sign_local_min(prev: Real, cur: Real, next: Real) -> bool {
    cur != 0.0
        && cur.abs() <= prev.abs()
        && cur.abs() <= next.abs()
        && (prev > 0.0) == (cur > 0.0)
        && (next > 0.0) == (cur > 0.0)
}

/// Intersection points of two TRP ellipses (§5.2, a \[P\] choice): ellipse 1 is parametrized, `h(θ) =
/// d₂(p(θ)) − ρ₂` sampled at [`INTERSECTION_SAMPLES`] points, every sign change Brent-refined,
/// tangencies (local minima of `|h|` below [`TANGENCY_REL_TOL`]`·ρ₂`) added, roots closer than
/// [`MERGE_DISTANCE_M`] merged, at most four kept. Points where the matrix `G` of the two range
/// gradients has `cond(G) >` [`MAX_GRADIENT_CONDITION`] (grazing) are dropped, and, when `region`
/// is given, points outside it enlarged by [`REGION_MARGIN_M`]. Identical or confocal ellipses
/// give no points.
pub fn intersect(e1: &RangeEllipse, e2: &RangeEllipse, region: Option<&Rect>) -> Intersections {
    intersect_with(e1, e2, region, &SampleTable::new())
}

/// `cos θ_k`, `sin θ_k` of the §5.2 sample angles `θ_k = 2πk/n`, `n =`
/// [`INTERSECTION_SAMPLES`]: computed once and shared by many intersections (the sampling loop
/// then needs no trigonometry; the values are bitwise those of `cos`/`sin` at `θ_k`).
#[derive(Debug, Clone)]
pub struct SampleTable {
    cos: [Real; INTERSECTION_SAMPLES],
    sin: [Real; INTERSECTION_SAMPLES],
}

impl SampleTable {
    /// The table.
    pub fn new() -> SampleTable {
        let step = 2.0 * PI / INTERSECTION_SAMPLES as Real;
        let mut t = SampleTable {
            cos: [0.0; INTERSECTION_SAMPLES],
            sin: [0.0; INTERSECTION_SAMPLES],
        };
        for k in 0..INTERSECTION_SAMPLES {
            let theta = step * k as Real;
            t.cos[k] = cos(theta);
            t.sin[k] = sin(theta);
        }
        t
    }
}

impl Default for SampleTable {
    fn default() -> Self {
        SampleTable::new()
    }
}

/// Axis-aligned bounding box `(min, max)` of an ellipse, padded by `pad`.
fn bounding_box(e: &RangeEllipse, pad: Real) -> (Vec2, Vec2) {
    let el = &e.ellipse;
    let (ca, sa) = (cos(el.angle_rad), sin(el.angle_rad));
    let (a, b) = (el.semi_major, el.semi_minor);
    let hx = sqrt(a * a * ca * ca + b * b * sa * sa) + pad;
    let hy = sqrt(a * a * sa * sa + b * b * ca * ca) + pad;
    let h = Vec2::new(hx, hy);
    (el.center - h, el.center + h)
}

fn boxes_overlap(p: (Vec2, Vec2), q: (Vec2, Vec2)) -> bool {
    p.0.x <= q.1.x && q.0.x <= p.1.x && p.0.y <= q.1.y && q.0.y <= p.1.y
}

/// [`intersect`] with a shared [`SampleTable`] (same points). Ellipses whose bounding boxes do
/// not overlap, or (with `region`) one of which lies wholly outside the enlarged region, are
/// rejected before sampling.
pub fn intersect_with(
    e1: &RangeEllipse,
    e2: &RangeEllipse,
    region: Option<&Rect>,
    table: &SampleTable,
) -> Intersections {
    let mut out = Intersections::new();
    let scale = 1.0 + e1.range_m.abs() + e2.range_m.abs();
    let confocal = (same_point(e1.tx, e2.tx, scale) && same_point(e1.rx, e2.rx, scale))
        || (same_point(e1.tx, e2.rx, scale) && same_point(e1.rx, e2.tx, scale));
    if confocal {
        return out;
    }
    // Exact rejections: every intersection lies on both ellipses (so in both boxes) and, to be
    // kept, in the enlarged region.
    let pad = 1e-9 * scale;
    let (b1, b2) = (bounding_box(e1, pad), bounding_box(e2, pad));
    if !boxes_overlap(b1, b2) {
        return out;
    }
    if let Some(r) = region {
        let r = r.enlarged(REGION_MARGIN_M);
        let rb = (r.min, r.max);
        if !boxes_overlap(b1, rb) || !boxes_overlap(b2, rb) {
            return out;
        }
    }
    // p(θ) as Ellipse::point, with the axis rotation and the sample angles' cos/sin hoisted.
    let el = &e1.ellipse;
    let (ca, sa) = (cos(el.angle_rad), sin(el.angle_rad));
    let at = |ct: Real, st: Real| {
        let (u, v) = (el.semi_major * ct, el.semi_minor * st);
        el.center + Vec2::new(ca * u - sa * v, sa * u + ca * v)
    };
    let h = |t: Real| e2.residual(at(cos(t), sin(t)));
    let n = INTERSECTION_SAMPLES;
    let step = 2.0 * PI / n as Real;
    let theta = |k: usize| step * k as Real;
    // h at sample k (k = n is sample 0), evaluated only where the scan needs it.
    let h_at = |k: usize| {
        let k = if k >= n { k - n } else { k };
        e2.residual(at(table.cos[k], table.sin[k]))
    };
    // The scan: the sign of h(θ_k) is the sign of the implicit quadratic of ellipse 2,
    // q(θ) = u²/a₂² + v²/b₂² − 1 in its axes (inside ⇔ d₂ < ρ₂), affine in cos θ, sin θ: no
    // square roots. q is a trigonometric polynomial of degree 2, so |q'| ≤ L (its amplitudes):
    // a stretch of COARSE samples whose end values satisfy |q_a| + |q_b| > L·Δ + 2ε holds no
    // root and has |q| > ε throughout (no tangency either), and its inner samples are skipped.
    // A degenerate ellipse 2 (the focal segment, b₂ = 0) is scanned with h itself, in full.
    const COARSE: usize = 8;
    const STRETCHES: usize = INTERSECTION_SAMPLES / COARSE;
    let mut qv = [0.0; INTERSECTION_SAMPLES + 1];
    let mut active = [true; STRETCHES];
    let el2 = &e2.ellipse;
    // 1/b₂² overflows for a nearly degenerate ellipse: scan h itself then too.
    let implicit = el2.semi_minor > 0.0 && (1.0 / (el2.semi_minor * el2.semi_minor)).is_finite();
    if implicit {
        let (c2, s2) = (cos(el2.angle_rad), sin(el2.angle_rad));
        let (ax, ay) = (ca * el.semi_major, sa * el.semi_major);
        let (bx, by) = (-sa * el.semi_minor, ca * el.semi_minor);
        let d = el.center - el2.center;
        let (u0, u1, u2) = (c2 * d.x + s2 * d.y, c2 * ax + s2 * ay, c2 * bx + s2 * by);
        let (v0, v1, v2) = (c2 * d.y - s2 * d.x, c2 * ay - s2 * ax, c2 * by - s2 * bx);
        let (ia, ib) = (
            1.0 / (el2.semi_major * el2.semi_major),
            1.0 / (el2.semi_minor * el2.semi_minor),
        );
        let q_at = |k: usize| {
            let (ct, st) = (table.cos[k], table.sin[k]);
            let u = u0 + u1 * ct + u2 * st;
            let v = v0 + v1 * ct + v2 * st;
            u * u * ia + v * v * ib - 1.0
        };
        // q = K0 + K1 cos θ + K2 sin θ + K3 cos 2θ + K4 sin 2θ.
        let k0 = ia * (u0 * u0 + 0.5 * (u1 * u1 + u2 * u2))
            + ib * (v0 * v0 + 0.5 * (v1 * v1 + v2 * v2))
            - 1.0;
        let (k1, k2) = (
            2.0 * (ia * u0 * u1 + ib * v0 * v1),
            2.0 * (ia * u0 * u2 + ib * v0 * v2),
        );
        let (k3, k4) = (
            0.5 * (ia * (u1 * u1 - u2 * u2) + ib * (v1 * v1 - v2 * v2)),
            ia * u1 * u2 + ib * v1 * v2,
        );
        let (amp1, amp2) = (sqrt(k1 * k1 + k2 * k2), sqrt(k3 * k3 + k4 * k4));
        let lipschitz = amp1 + 2.0 * amp2;
        let eps = 1e-6 * (1.0 + k0.abs() + amp1 + amp2);
        let reach = lipschitz * step * COARSE as Real + 2.0 * eps;
        for i in 0..STRETCHES {
            qv[i * COARSE] = q_at(i * COARSE);
        }
        qv[n] = qv[0];
        for (i, live) in active.iter_mut().enumerate() {
            let (a, b) = (i * COARSE, (i + 1) * COARSE);
            // A bound that is not a number skips nothing.
            let ends = qv[a].abs() + qv[b].abs();
            *live = ends <= reach || ends.is_nan() || reach.is_nan();
            if *live {
                for (k, q) in qv.iter_mut().enumerate().take(b).skip(a + 1) {
                    *q = q_at(k);
                }
            }
        }
    } else {
        for (k, q) in qv.iter_mut().enumerate().take(n) {
            *q = h_at(k);
        }
        qv[n] = qv[0];
    }
    // Samples k of the active stretches (k = n is sample 0 again).
    let live_samples = || {
        active
            .iter()
            .enumerate()
            .filter(|(_, &live)| live)
            .flat_map(|(i, _)| i * COARSE..(i + 1) * COARSE)
    };
    // Candidate roots (θ), more than 4 only through numerical duplicates.
    let mut cand = [0.0; 16];
    let mut nc = 0;
    let mut add = |t: Real, nc: &mut usize| {
        if *nc < cand.len() {
            cand[*nc] = t;
            *nc += 1;
        }
    };
    // Every sign change (or zero) of the scan is bracketed with h itself, then Brent-refined.
    for k in live_samples() {
        let (q0, q1) = (qv[k], qv[k + 1]);
        if q0 != 0.0 && q1 != 0.0 && (q0 > 0.0) == (q1 > 0.0) {
            continue;
        }
        let (h0, h1) = (h_at(k), h_at(k + 1));
        if h0 == 0.0 {
            add(theta(k), &mut nc);
        } else if h1 != 0.0 && (h0 > 0.0) != (h1 > 0.0) {
            add(brent(&h, theta(k), theta(k + 1), h0, h1), &mut nc);
        }
    }
    // Tangencies: local minima of |h| between samples of one sign, looked for around the
    // same-sign local minima of |q| (the same sampled points unless |h| and |q| peak at
    // neighbouring samples, hence the three indices tested around each). Samples whose
    // neighbour lies in a skipped stretch are not candidates (|q| > ε there).
    let tang_tol = TANGENCY_REL_TOL * e2.range_m.abs();
    let live_at = |k: usize| active[(k % n) / COARSE];
    let mut tested = [usize::MAX; 16];
    let mut nt = 0;
    for k in live_samples() {
        let prev = (k + n - 1) % n;
        if !live_at(prev) || !same_sign_local_min(qv[prev], qv[k], qv[k + 1]) {
            continue;
        }
        for j in [k + n - 1, k, k + 1] {
            let j = j % n;
            if tested[..nt].contains(&j) {
                continue;
            }
            if nt < tested.len() {
                tested[nt] = j;
                nt += 1;
            }
            let cur = h_at(j);
            if !same_sign_local_min(h_at(j + n - 1), cur, h_at(j + 1)) {
                continue;
            }
            let s = if cur > 0.0 { 1.0 } else { -1.0 };
            let g = |t: Real| s * h(t);
            let t = golden_min(&g, theta(j) - step, theta(j) + step);
            if h(t).abs() < tang_tol {
                add(t, &mut nc);
            }
        }
    }
    // Points, merged and filtered.
    let mut pts = [Vec2::zeros(); 16];
    let mut np = 0;
    for &t in &cand[..nc] {
        let p = e1.point(t);
        if !(p.x.is_finite() && p.y.is_finite()) {
            continue;
        }
        if pts[..np].iter().any(|q| (p - *q).norm() < MERGE_DISTANCE_M) {
            continue;
        }
        if condition_number(e1.gradient(p), e2.gradient(p)) > MAX_GRADIENT_CONDITION {
            continue;
        }
        if let Some(r) = region {
            if !r.enlarged(REGION_MARGIN_M).contains(p) {
                continue;
            }
        }
        pts[np] = p;
        np += 1;
    }
    if np > 4 {
        // Keep the four best by total residual (only reachable through numerical noise).
        let res = |p: &Vec2| e1.residual(*p).abs() + e2.residual(*p).abs();
        pts[..np].sort_by(|a, b| res(a).total_cmp(&res(b)));
        np = 4;
    }
    for p in &pts[..np] {
        out.push(*p);
    }
    out
}

#[cfg(test)]
mod tests;
