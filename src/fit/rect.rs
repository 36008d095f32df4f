//! In the plane: the convex hull (Andrew's monotone chain) and the minimum-area enclosing
//! rectangle (rotating calipers, Toussaint 1983).
//!
//! The smallest rectangle around a convex polygon has a side on one of its edges (Freeman &
//! Shapira 1975), so it is enough to try each edge direction; the calipers keep the three
//! other extreme vertices and advance them monotonically, `O(m)` for `m` vertices. Rounding
//! in `f64` can only make the chosen direction slightly less than optimal: the fits measure
//! their extents again from every point.
//!
//! For a polytope's shadow, the same rectangle is also found without the 2D hull: from the
//! edges of its outline as candidate sides, measured in lanes ([`least_rectangle`]), which
//! costs less on the few dozen points of an outline.

use crate::num::sqrt;
use alloc::vec::Vec;
use glam::{DMat3, DVec2, DVec3};

/// The convex hull, counter-clockwise, without collinear vertices (any order of input),
/// sorting the points in place.
pub(crate) fn convex_hull_2d(points: &mut [DVec2]) -> Vec<DVec2> {
    // Unstable is enough: equal keys are equal points, taken once.
    points.sort_unstable_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    let distinct = || points.chunk_by(|a, b| a == b).map(|run| run[0]);
    // Adds `p` to the chain on top of `hull`, first popping every vertex above the first
    // `floor` where the chain would not turn left.
    let extend = |hull: &mut Vec<DVec2>, p: DVec2, floor: usize| {
        while hull.len() > floor {
            let (a, b) = (hull[hull.len() - 2], hull[hull.len() - 1]);
            if (b - a).perp_dot(p - a) > 0.0 {
                break;
            }
            hull.pop();
        }
        hull.push(p);
    };
    // The lower chain left to right, then the upper chain right to left on top of it; the
    // upper chain ends at the first point, which is dropped.
    let mut hull = Vec::with_capacity(points.len() + 1);
    for p in distinct() {
        extend(&mut hull, p, 1);
    }
    let lower = hull.len();
    for p in distinct().rev().skip(1) {
        extend(&mut hull, p, lower);
    }
    if hull.len() > 1 {
        hull.pop();
    }
    hull
}

/// Point sets of at most this many points are wrapped ([`wrapped_hull`]), not sorted.
const FEW: usize = 32;

/// The convex hull of at most [`FEW`] points, counter-clockwise from the least point in
/// `(x, y)` order, without collinear vertices, by gift wrapping (Jarvis 1973): `O(n·h)`
/// for `h` vertices, with no sort and no allocation, which costs less than the monotone
/// chain on a few points. Each step takes the point that no other lies to the right of
/// (the farthest of those on its line). Rounding near collinear points could keep the
/// wrap from closing: it stops after as many vertices as points.
fn wrapped_hull(points: &[DVec2], hull: &mut [DVec2; FEW]) -> usize {
    let Some(start) = points
        .iter()
        .copied()
        .min_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)))
    else {
        return 0;
    };
    let (mut at, mut m) = (start, 0);
    while m < points.len().min(FEW) {
        hull[m] = at;
        m += 1;
        let mut next = at;
        for &p in points {
            let turn = (next - at).perp_dot(p - at);
            let farther = || (p - at).length_squared() > (next - at).length_squared();
            if next == at || turn < 0.0 || (turn == 0.0 && farther()) {
                next = p;
            }
        }
        if next == start || next == at {
            break;
        }
        at = next;
    }
    m
}

/// The unit direction of one side of the minimum-area rectangle around `points`, and the
/// rectangle's area. For fewer than three hull vertices: the direction of the segment
/// (or `x`) and area 0.
pub(crate) fn min_area_rectangle(points: &mut [DVec2]) -> (DVec2, f64) {
    if points.len() <= FEW {
        let mut hull = [DVec2::ZERO; FEW];
        let m = wrapped_hull(points, &mut hull);
        return calipers(&hull[..m]);
    }
    calipers(&convex_hull_2d(points))
}

/// [`min_area_rectangle`] of the convex polygon `hull` (counter-clockwise, no collinear
/// vertices), by rotating calipers. An edge `e` is not normalised: its rectangle's sides
/// are the ranges of `q·e` and `q·e⊥` over the vertices, and its area their product over
/// `|e|²`.
fn calipers(hull: &[DVec2]) -> (DVec2, f64) {
    let m = hull.len();
    if m < 3 {
        let along = match hull[..] {
            [a, b] => (b - a).normalize_or(DVec2::X),
            _ => DVec2::X,
        };
        return (along, 0.0);
    }
    // Indices run over two laps: `at(i)` for `i < 2m`.
    let at = |i: usize| hull[if i < m { i } else { i - m }];
    // Advance `i` while the next vertex lies farther along `dir` (at most one lap).
    let advance = |mut i: usize, dir: DVec2| {
        let end = (i + m).min(2 * m - 1);
        while i < end && (at(i + 1) - at(i)).dot(dir) > 0.0 {
            i += 1;
        }
        i
    };
    let (mut right, mut top, mut left) = (0, 0, 0);
    let mut best = (DVec2::X, f64::INFINITY);
    for i in 0..m {
        let u = at(i + 1) - at(i);
        let v = u.perp();
        right = advance(right.max(i), u);
        top = advance(top.max(right), v);
        left = advance(left.max(top), -u);
        let width = (at(right) - at(left)).dot(u);
        let height = (at(top) - at(i)).dot(v);
        let area = width * height / u.length_squared();
        if area < best.1 {
            best = (u, area);
        }
    }
    (best.0.normalize_or(DVec2::X), best.1)
}

/// The frame `(u, n × u, n)` where `u` is a side of the minimum-area rectangle of the
/// points projected on the plane orthogonal to the unit `normal`.
pub(crate) fn rectangle_frame(normal: DVec3, points: &[DVec3]) -> DMat3 {
    let (e1, e2) = normal.any_orthonormal_pair();
    let flat = |p: &DVec3| DVec2::new(p.dot(e1), p.dot(e2));
    let (side, _) = if points.len() <= FEW {
        let mut few = [DVec2::ZERO; FEW];
        for (q, p) in few.iter_mut().zip(points) {
            *q = flat(p);
        }
        min_area_rectangle(&mut few[..points.len()])
    } else {
        min_area_rectangle(&mut points.iter().map(flat).collect::<Vec<_>>())
    };
    frame(normal, e1 * side.x + e2 * side.y)
}

/// The frame `(u, n × u, n)` of a rectangle's unit side `u` on the plane orthogonal to the
/// unit `n`.
pub(crate) fn frame(n: DVec3, u: DVec3) -> DMat3 {
    DMat3::from_cols(u, n.cross(u), n)
}

/// Candidate sides per lane group of [`least_rectangle`].
const LANES: usize = 4;

/// The least-area rectangle around the points `outline` (coordinate columns of one length)
/// projected on the plane orthogonal to the unit `n`, among those with a side along the
/// projection of one of the `edges` (index pairs into `points`): its area and that side
/// (in the plane, not normalised); `None` when no candidate gives a finite area (every edge
/// along `n`).
///
/// For the outline of a convex polytope along `n` and the edges that bound its triangles
/// facing `n` (with those of its edge-on triangles), the least rectangle around the shadow
/// is among these: it has a side along a side of the shadow's polygon (Freeman & Shapira
/// 1975), which is the projection of such an edge. Each candidate side is
/// `d = w − n·(n·w)` with `e = n × d`, and its area the product of the ranges of `p·d` and
/// `p·e` over the outline, over `|d|·|e|`. Extra candidates cost only time: each area is
/// that of a rectangle holding the shadow. The candidates are measured four at a time, in
/// lanes, inside the best backend; `O(edges · points)`, which beats a sort and the calipers
/// on the few dozen points of an outline. Rounding can only make the chosen side slightly
/// less than optimal: the fits measure their boxes again on every point.
pub(crate) fn least_rectangle<I: Copy + Into<usize>>(
    n: DVec3,
    points: &[DVec3],
    edges: &[[I; 2]],
    outline: [&[f64]; 3],
) -> Option<(f64, DVec3)> {
    let [xs, ys, zs] = outline;
    let least = crate::simd::plain(
        #[inline(always)]
        || {
            let mut least = (f64::INFINITY, DVec3::ZERO);
            for group in edges.chunks(LANES) {
                // The candidate sides `d` and `e = n × d`, a lane each, padded with the first.
                let mut d = [[0.0; LANES]; 3];
                let mut e = [[0.0; LANES]; 3];
                for j in 0..LANES {
                    let [u, v] = group[if j < group.len() { j } else { 0 }];
                    let w = points[v.into()] - points[u.into()];
                    let side = w - n * n.dot(w);
                    let across = n.cross(side);
                    for k in 0..3 {
                        (d[k][j], e[k][j]) = (side[k], across[k]);
                    }
                }
                let (mut d_lo, mut d_hi) = ([f64::INFINITY; LANES], [f64::NEG_INFINITY; LANES]);
                let (mut e_lo, mut e_hi) = (d_lo, d_hi);
                for ((&x, &y), &z) in xs.iter().zip(ys).zip(zs) {
                    for j in 0..LANES {
                        let p = d[0][j] * x + d[1][j] * y + d[2][j] * z;
                        let q = e[0][j] * x + e[1][j] * y + e[2][j] * z;
                        d_lo[j] = if p < d_lo[j] { p } else { d_lo[j] };
                        d_hi[j] = if p > d_hi[j] { p } else { d_hi[j] };
                        e_lo[j] = if q < e_lo[j] { q } else { e_lo[j] };
                        e_hi[j] = if q > e_hi[j] { q } else { e_hi[j] };
                    }
                }
                for j in 0..LANES {
                    let norms = (d[0][j] * d[0][j] + d[1][j] * d[1][j] + d[2][j] * d[2][j])
                        * (e[0][j] * e[0][j] + e[1][j] * e[1][j] + e[2][j] * e[2][j]);
                    let area = (d_hi[j] - d_lo[j]) * (e_hi[j] - e_lo[j]) / sqrt(norms);
                    // A candidate of no length gives NaN, which never wins.
                    if area < least.0 {
                        least = (area, DVec3::new(d[0][j], d[1][j], d[2][j]));
                    }
                }
            }
            least
        },
    );
    least.0.is_finite().then_some(least)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// On small-integer points (exact arithmetic, with many collinear and repeated points)
    /// the wrap gives the monotone chain's polygon, vertex for vertex, and so the same
    /// rectangle.
    #[test]
    fn the_wrap_is_the_monotone_chain_on_few_points() {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = |n: u64| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state % n) as f64
        };
        for trial in 0..2000 {
            let len = 1 + trial % FEW;
            let side = [3, 5, 9, 100][trial % 4];
            let mut points: Vec<DVec2> = (0..len)
                .map(|_| DVec2::new(next(side), next(side)))
                .collect();
            let mut wrapped = [DVec2::ZERO; FEW];
            let m = wrapped_hull(&points, &mut wrapped);
            let (wrap_side, wrap_area) = calipers(&wrapped[..m]);
            let chain = convex_hull_2d(&mut points);
            assert_eq!(&wrapped[..m], &chain[..], "trial {trial}");
            assert_eq!(calipers(&chain), (wrap_side, wrap_area));
        }
    }

    #[test]
    fn rotated_rectangle_and_square() {
        let r = DVec2::from_angle(0.3);
        let corners = [
            (0.0, 0.0),
            (4.0, 0.0),
            (4.0, 1.0),
            (0.0, 1.0),
            (2.0, 0.5),
            (1.0, 0.0),
        ];
        let pts: Vec<DVec2> = corners
            .iter()
            .map(|&(x, y)| r.rotate(DVec2::new(x, y)))
            .collect();
        let mut pts = pts;
        assert_eq!(convex_hull_2d(&mut pts).len(), 4);
        let (dir, area) = min_area_rectangle(&mut pts);
        assert!((area - 4.0).abs() < 1e-12, "{area}");
        assert!(
            dir.perp_dot(r).abs() < 1e-12 || dir.dot(r).abs() < 1e-12,
            "{dir}"
        );
        let mut diamond: Vec<DVec2> = [(1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0)]
            .iter()
            .map(|&(x, y)| DVec2::new(x, y))
            .collect();
        assert!((min_area_rectangle(&mut diamond).1 - 2.0).abs() < 1e-12);
    }

    /// Repeated and collinear points: one point, the two ends of a segment, and a
    /// triangle whose edges hold repeated points, each vertex once and counter-clockwise.
    #[test]
    fn hulls_of_repeated_and_collinear_points() {
        let p = |x: f64, y: f64| DVec2::new(x, y);
        assert_eq!(convex_hull_2d(&mut [p(1.0, 2.0); 3]), [p(1.0, 2.0)]);
        let mut segment = [
            p(2.0, 2.0),
            p(0.0, 0.0),
            p(1.0, 1.0),
            p(2.0, 2.0),
            p(0.0, 0.0),
        ];
        assert_eq!(convex_hull_2d(&mut segment), [p(0.0, 0.0), p(2.0, 2.0)]);
        let mut triangle = [
            p(0.0, 0.0),
            p(4.0, 0.0),
            p(2.0, 0.0),
            p(0.0, 4.0),
            p(2.0, 2.0),
            p(0.0, 2.0),
            p(4.0, 0.0),
            p(0.0, 0.0),
            p(1.0, 1.0),
        ];
        assert_eq!(
            convex_hull_2d(&mut triangle),
            [p(0.0, 0.0), p(4.0, 0.0), p(0.0, 4.0)]
        );
    }
}
