//! Convex polygons for the PPP blocking model (multi-target spec §6.2): shoelace areas,
//! Sutherland–Hodgman clipping of a convex polygon by a convex polygon, the width-`D` rectangle
//! `A_n` around a segment `[x, node]`, the axis-aligned region `R`, and union areas by
//! inclusion–exclusion over intersections obtained by successive convex clipping.
//!
//! Polygons are vertex lists (either orientation, no repeated closing vertex). An empty list or
//! one with fewer than three vertices has area 0.

use alloc::vec::Vec;

use crate::error::{check_len, limits, Error, Result};
use crate::math::{Real, Vec2};

/// An axis-aligned rectangle `[min.x, max.x] × [min.y, max.y]` (the region `R` of §6.2/§7).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rect {
    /// Lower-left corner, m.
    pub min: Vec2,
    /// Upper-right corner, m.
    pub max: Vec2,
}

impl Rect {
    /// A rectangle from its corners, named `region` in errors (see [`Rect::named`]).
    pub fn new(min: Vec2, max: Vec2) -> Result<Rect> {
        Rect::named(["region", "region.x", "region.y"], min, max)
    }

    /// A rectangle from its corners; errors name `fields` = `[whole, x side, y side]`:
    /// [`Error::NonFinite`] (whole) for a non-finite coordinate, [`Error::OutOfRange`] (whole)
    /// for one outside [`limits::COORDINATE_M`], and [`Error::InvertedArea`] (side) when a
    /// minimum is not below its maximum.
    pub fn named(fields: [&'static str; 3], min: Vec2, max: Vec2) -> Result<Rect> {
        for v in [min.x, min.y, max.x, max.y] {
            limits::COORDINATE_M.check(fields[0], v)?;
        }
        if min.x >= max.x {
            return Err(Error::InvertedArea {
                field: fields[1],
                min: min.x,
                max: max.x,
            });
        }
        if min.y >= max.y {
            return Err(Error::InvertedArea {
                field: fields[2],
                min: min.y,
                max: max.y,
            });
        }
        Ok(Rect { min, max })
    }

    /// Whether `p` lies in the closed rectangle.
    pub fn contains(&self, p: Vec2) -> bool {
        p.x >= self.min.x && p.x <= self.max.x && p.y >= self.min.y && p.y <= self.max.y
    }

    /// The rectangle grown by `margin` m on every side.
    pub fn enlarged(&self, margin: Real) -> Rect {
        Rect {
            min: self.min - Vec2::new(margin, margin),
            max: self.max + Vec2::new(margin, margin),
        }
    }

    /// Its four corners, counter-clockwise from `min`.
    pub fn polygon(&self) -> [Vec2; 4] {
        [
            self.min,
            Vec2::new(self.max.x, self.min.y),
            self.max,
            Vec2::new(self.min.x, self.max.y),
        ]
    }

    /// Area, m².
    pub fn area(&self) -> Real {
        (self.max.x - self.min.x) * (self.max.y - self.min.y)
    }
}

/// Signed shoelace area, m² (> 0 for counter-clockwise vertices).
pub fn signed_area(poly: &[Vec2]) -> Real {
    if poly.len() < 3 {
        return 0.0;
    }
    let mut s = 0.0;
    let n = poly.len();
    for i in 0..n {
        let (p, q) = (poly[i], poly[if i + 1 < n { i + 1 } else { 0 }]);
        s += p.x * q.y - q.x * p.y;
    }
    0.5 * s
}

/// Area of a simple polygon (shoelace formula), m².
pub fn area(poly: &[Vec2]) -> Real {
    signed_area(poly).abs()
}

/// Sutherland–Hodgman clipping of `subject` by the convex polygon `clip` (either orientation):
/// the vertices of `subject ∩ clip`. Empty when the intersection has no area (or either input has
/// fewer than three vertices). `subject` must be convex for the result to be one polygon.
pub fn clip_convex(subject: &[Vec2], clip: &[Vec2]) -> Vec<Vec2> {
    let mut clipper = Clipper::default();
    if clipper.clip(subject, clip, orientation(clip)) == 0.0 {
        return Vec::new();
    }
    clipper.out
}

/// `±1`: the orientation of `poly` as a clipper; 0 when it has no area or < 3 vertices.
fn orientation(poly: &[Vec2]) -> Real {
    let a = signed_area(poly);
    if poly.len() < 3 || a == 0.0 {
        0.0
    } else {
        a.signum()
    }
}

/// Sutherland–Hodgman scratch, reused across calls (no allocation once its buffers have grown).
#[derive(Debug, Default)]
struct Clipper {
    /// The result of the last [`Clipper::clip`].
    out: Vec<Vec2>,
    tmp: Vec<Vec2>,
    /// Signed distances (× edge length) of the current vertices to the current clip edge.
    sides: Vec<Real>,
    /// Whether the last [`Clipper::clip`] left the subject as it was (every vertex inside).
    unchanged: bool,
}

impl Clipper {
    /// A clipper whose buffers hold `n` vertices before they grow.
    fn with_capacity(n: usize) -> Self {
        Clipper {
            out: Vec::with_capacity(n),
            tmp: Vec::with_capacity(n),
            sides: Vec::with_capacity(n),
            unchanged: false,
        }
    }

    /// Clips `subject` by the convex `clip` of orientation `sign` ([`orientation`]) into
    /// `self.out`; returns the area of the result (0 when it has none).
    ///
    /// Each vertex's side of an edge is evaluated once; an edge with every vertex inside leaves the
    /// polygon as it is and one with none inside ends the clip. The output is bitwise that of the
    /// textbook loop (same edges, same vertex order, same arithmetic).
    fn clip(&mut self, subject: &[Vec2], clip: &[Vec2], sign: Real) -> Real {
        let Clipper {
            out,
            tmp,
            sides,
            unchanged,
        } = self;
        out.clear();
        *unchanged = false;
        if subject.len() < 3 || sign == 0.0 {
            return 0.0;
        }
        out.extend_from_slice(subject);
        *unchanged = true;
        let m = clip.len();
        for i in 0..m {
            let a = clip[i];
            let b = clip[if i + 1 < m { i + 1 } else { 0 }];
            let (ex, ey) = (b.x - a.x, b.y - a.y);
            sides.clear();
            let mut inside = 0usize;
            for p in out.iter() {
                let sp = sign * (ex * (p.y - a.y) - ey * (p.x - a.x));
                inside += usize::from(sp >= 0.0);
                sides.push(sp);
            }
            let n = out.len();
            if inside == n {
                continue;
            }
            if inside == 0 {
                out.clear();
                *unchanged = false;
                return 0.0;
            }
            *unchanged = false;
            core::mem::swap(out, tmp);
            out.clear();
            for j in 0..n {
                let k = if j + 1 < n { j + 1 } else { 0 };
                let (p, q, sp, sq) = (tmp[j], tmp[k], sides[j], sides[k]);
                if sp >= 0.0 {
                    out.push(p);
                }
                if (sp >= 0.0) != (sq >= 0.0) {
                    let t = sp / (sp - sq);
                    out.push(p + (q - p) * t);
                }
            }
        }
        if out.len() < 3 {
            *unchanged = false;
            return 0.0;
        }
        area(out)
    }
}

/// The rectangle of width `width` around the segment `[x, node]` (the `A_n` of §6.2, length
/// `‖node − x‖`), counter-clockwise. Degenerate (zero area) when `x = node`.
pub fn segment_rectangle(x: Vec2, node: Vec2, width: Real) -> [Vec2; 4] {
    let d = node - x;
    let len = d.norm();
    let n = if len > 0.0 {
        Vec2::new(-d.y, d.x) * (0.5 * width / len)
    } else {
        Vec2::zeros()
    };
    [x - n, node - n, node + n, x + n]
}

/// The rectangle `A_n` of §6.2, clipped to `region` when one is given.
pub fn node_rectangle(x: Vec2, node: Vec2, width: Real, region: Option<&Rect>) -> Vec<Vec2> {
    rectangle_in_region(&segment_rectangle(x, node, width), region)
}

/// `rect` clipped to `region` when one is given, else as it is; empty when it has no area.
pub fn rectangle_in_region(rect: &[Vec2; 4], region: Option<&Rect>) -> Vec<Vec2> {
    match region {
        // Inside the region: what the clip would return (the rectangle as it is).
        Some(r) if !rect.iter().all(|p| r.contains(*p)) => clip_convex(rect, &r.polygon()),
        _ if area(rect) > 0.0 => rect.to_vec(),
        _ => Vec::new(),
    }
}

/// Area of the intersection of convex polygons by successive clipping, m² (0 for an empty list).
pub fn intersection_area(polys: &[&[Vec2]]) -> Real {
    let Some((first, rest)) = polys.split_first() else {
        return 0.0;
    };
    let mut cur: Vec<Vec2> = first.to_vec();
    for p in rest {
        cur = clip_convex(&cur, p);
        if cur.is_empty() {
            return 0.0;
        }
    }
    area(&cur)
}

/// The areas `|∩_{i∈T} A_i|` of every subset `T` of `polys` (convex), indexed by the bit mask of
/// `T` (entry 0, the empty set, is 0). Subsets whose intersection is already empty are not
/// extended. At most 24 polygons ([`Error::SizeLimit`] otherwise).
pub fn subset_intersection_areas<P: AsRef<[Vec2]>>(polys: &[P]) -> Result<Vec<Real>> {
    subset_intersection_areas_clipped(polys, polys)
}

/// [`subset_intersection_areas`] of `polys[i] = clippers[i] ∩ C` for one convex `C` (e.g. the
/// rectangles `A_n` clipped to the region `R`): each subset's intersection starts from its first
/// `polys[i]` (inside `C`) and is clipped by the other members' `clippers[j]` (a rectangle has 4
/// edges where the clipped polygon may have 8; `∩_T polys = polys[i₀] ∩ ⋂_{T∖i₀} clippers`).
/// `clippers` must have one convex polygon per entry of `polys` ([`Error::LengthMismatch`]).
pub fn subset_intersection_areas_clipped<P: AsRef<[Vec2]>, Q: AsRef<[Vec2]>>(
    polys: &[P],
    clippers: &[Q],
) -> Result<Vec<Real>> {
    let n = polys.len();
    check_len("clippers", n, clippers.len())?;
    if n > 24 {
        return Err(Error::SizeLimit {
            field: "polygons",
            value: n,
            min: 0,
            max: 24,
        });
    }
    let mut out = alloc::vec![0.0; 1usize << n];
    let signs: Vec<Real> = clippers.iter().map(|p| orientation(p.as_ref())).collect();
    // Depth-first over subsets in increasing index order, carrying the running intersection.
    // Polygons live in one arena: the top stack entry's polygon is always the arena's tail.
    let mut stack: Vec<(usize, usize, usize, usize)> = Vec::with_capacity(n * (n + 1) / 2 + 1);
    let mut arena: Vec<Vec2> = Vec::with_capacity(16 * (n * (n + 1) / 2 + 1));
    for (i, p) in polys.iter().enumerate() {
        let p = p.as_ref();
        let a = area(p);
        if p.len() >= 3 && a > 0.0 {
            out[1 << i] = a;
            stack.push((1 << i, i, arena.len(), p.len()));
            arena.extend_from_slice(p);
        }
    }
    // `same_as[m] = m'` (≠ 0): `∩_m` is `∩_{m'}`, filled in after the search.
    let mut same_as = alloc::vec![0usize; 1usize << n];
    let mut cur = Vec::with_capacity(32);
    let mut clipper = Clipper::with_capacity(32);
    while let Some((mask, last, start, len)) = stack.pop() {
        cur.clear();
        cur.extend_from_slice(&arena[start..start + len]);
        arena.truncate(start);
        for (j, q) in clippers.iter().enumerate().skip(last + 1) {
            let a = clipper.clip(&cur, q.as_ref(), signs[j]);
            if a == 0.0 {
                continue;
            }
            let m = mask | (1 << j);
            if clipper.unchanged {
                // `∩_mask ⊆ A_j`: for every `T` above `j`, `∩_{m∪T} = ∩_{mask∪T}`, which the
                // search reaches through `mask` (bitwise the same clips), so it is not repeated.
                let above = ((1usize << n) - 1) & !((1usize << (j + 1)) - 1);
                let mut t = above;
                loop {
                    same_as[m | t] = mask | t;
                    if t == 0 {
                        break;
                    }
                    t = (t - 1) & above;
                }
                continue;
            }
            out[m] = a;
            stack.push((m, j, arena.len(), clipper.out.len()));
            arena.extend_from_slice(&clipper.out);
        }
    }
    // Increasing order: a source mask is smaller than its target, so it is final by then.
    for m in 1..out.len() {
        if same_as[m] != 0 {
            out[m] = out[same_as[m]];
        }
    }
    Ok(out)
}

/// `|∪_{i∈S} A_i|` from the subset intersection areas of [`subset_intersection_areas`], by
/// inclusion–exclusion `Σ_{∅≠T⊆S} (−1)^{|T|+1} |∩_{i∈T} A_i|`.
pub fn union_area_from_table(table: &[Real], set: usize) -> Real {
    let mut sum = 0.0;
    let mut t = set;
    while t != 0 {
        let v = table[t];
        if v != 0.0 {
            if t.count_ones() % 2 == 1 {
                sum += v;
            } else {
                sum -= v;
            }
        }
        t = (t - 1) & set;
    }
    sum
}

/// Area of the union of convex polygons by inclusion–exclusion over their intersections, m².
pub fn union_area<P: AsRef<[Vec2]>>(polys: &[P]) -> Result<Real> {
    let table = subset_intersection_areas(polys)?;
    Ok(union_area_from_table(&table, (1usize << polys.len()) - 1))
}

#[cfg(test)]
mod tests;
