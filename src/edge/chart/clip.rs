//! Clipping to the rectangle a figure shows, `[x0, x1, y0, y1]` (m), one home for every figure:
//! a segment (Liang–Barsky: the plan's paths), a polyline into the runs inside the view (the
//! overlays' ellipses and tracks, the scene's outlines), a polygon (Sutherland–Hodgman: the
//! scene's filled regions). Pure functions of the chart module; nothing here draws.
//!
//! `crate::mtl::polygon` keeps its own convex-by-convex clipper: it is the method's area
//! computation (inclusion–exclusion with reused buffers and a bitwise contract), not a figure's
//! view, and the figures' rectangle clips keep their own exact axis-aligned arithmetic.

use alloc::vec::Vec;

use crate::math::Real;

/// The part of the segment `a`–`b` inside the rectangle `[x0, x1, y0, y1]` (Liang–Barsky), or
/// `None` when it misses it.
pub(super) fn clip_segment(
    a: (Real, Real),
    b: (Real, Real),
    r: [Real; 4],
) -> Option<[(Real, Real); 2]> {
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let (mut t0, mut t1): (Real, Real) = (0.0, 1.0);
    for (p, q) in [
        (-dx, a.0 - r[0]),
        (dx, r[1] - a.0),
        (-dy, a.1 - r[2]),
        (dy, r[3] - a.1),
    ] {
        if p == 0.0 {
            if q < 0.0 {
                return None;
            }
        } else {
            let t = q / p;
            if p < 0.0 {
                t0 = t0.max(t);
            } else {
                t1 = t1.min(t);
            }
        }
    }
    (t0 <= t1).then_some([
        (a.0 + t0 * dx, a.1 + t0 * dy),
        (a.0 + t1 * dx, a.1 + t1 * dy),
    ])
}

/// The runs of the polyline `points` (closed back to its start when `closed`) inside the view
/// `[x0, x1, y0, y1]`: each segment is clipped, and a run breaks where the line leaves the view.
pub(super) fn clipped_runs(
    points: &[[Real; 2]],
    closed: bool,
    view: [Real; 4],
) -> Vec<Vec<(Real, Real)>> {
    let mut pts: Vec<(Real, Real)> = points
        .iter()
        .filter(|p| p[0].is_finite() && p[1].is_finite())
        .map(|p| (p[0], p[1]))
        .collect();
    if closed && pts.len() > 2 {
        pts.push(pts[0]);
    }
    let mut runs: Vec<Vec<(Real, Real)>> = Vec::new();
    let mut run: Vec<(Real, Real)> = Vec::new();
    for w in pts.windows(2) {
        match clip_segment(w[0], w[1], view) {
            Some([a, b]) => {
                if run.last() != Some(&a) {
                    if run.len() > 1 {
                        runs.push(core::mem::take(&mut run));
                    }
                    run.clear();
                    run.push(a);
                }
                run.push(b);
            }
            None => {
                if run.len() > 1 {
                    runs.push(core::mem::take(&mut run));
                }
                run.clear();
            }
        }
    }
    if run.len() > 1 {
        runs.push(run);
    }
    runs
}

/// The polygon `points` clipped to the rectangle `r` = `[x0, x1, y0, y1]` (Sutherland–Hodgman;
/// empty when it lies outside).
pub(super) fn clip_polygon(points: &[(Real, Real)], r: [Real; 4]) -> Vec<(Real, Real)> {
    let mut out = points.to_vec();
    for edge in 0..4 {
        let inside = |p: (Real, Real)| match edge {
            0 => p.0 >= r[0],
            1 => p.0 <= r[1],
            2 => p.1 >= r[2],
            _ => p.1 <= r[3],
        };
        let cut = |a: (Real, Real), b: (Real, Real)| {
            let t = match edge {
                0 => (r[0] - a.0) / (b.0 - a.0),
                1 => (r[1] - a.0) / (b.0 - a.0),
                2 => (r[2] - a.1) / (b.1 - a.1),
                _ => (r[3] - a.1) / (b.1 - a.1),
            };
            (a.0 + t * (b.0 - a.0), a.1 + t * (b.1 - a.1))
        };
        let input = core::mem::take(&mut out);
        for (i, &b) in input.iter().enumerate() {
            let a = input[(i + input.len() - 1) % input.len()];
            match (inside(a), inside(b)) {
                (true, true) => out.push(b),
                (true, false) => out.push(cut(a, b)),
                (false, true) => {
                    out.push(cut(a, b));
                    out.push(b);
                }
                (false, false) => {}
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::clip_segment;

    #[test]
    fn segments_are_clipped_to_the_view() {
        let r = [0.0, 10.0, 0.0, 10.0];
        assert_eq!(
            clip_segment((1.0, 1.0), (2.0, 3.0), r),
            Some([(1.0, 1.0), (2.0, 3.0)])
        );
        assert_eq!(
            clip_segment((5.0, 5.0), (15.0, 5.0), r),
            Some([(5.0, 5.0), (10.0, 5.0)])
        );
        assert_eq!(
            clip_segment((-5.0, -5.0), (15.0, 15.0), r),
            Some([(0.0, 0.0), (10.0, 10.0)])
        );
        // Touching a corner only.
        assert_eq!(
            clip_segment((-10.0, 0.0), (20.0, 30.0), r),
            Some([(0.0, 10.0), (0.0, 10.0)])
        );
        assert_eq!(clip_segment((20.0, 20.0), (30.0, 25.0), r), None);
        assert_eq!(clip_segment((-1.0, 5.0), (-1.0, 6.0), r), None);
    }
}
