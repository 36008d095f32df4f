//! The leaf test: do two closed triangles in 3D share a point? Exact, on `f64` vertices.
//!
//! Every decision is the sign of Shewchuk's adaptive `orient3d` or `orient2d` (the `robust`
//! crate), which is exact for `f64` inputs whose intermediate products neither overflow nor
//! underflow (coordinates within about `2^±300` of each other; any `f32` mesh at a pose with
//! a sane quaternion). Touching (a shared vertex, an edge on a face) counts as intersecting,
//! and degenerate triangles (segments, points) are normal input.
//!
//! **Why edges suffice.** Two closed triangles intersect iff an edge of one meets the other
//! triangle. Not coplanar: the intersection is an interval of the line where the planes
//! meet, and its end points lie on edges. Coplanar: if neither boundary met the other
//! triangle, a point of both interiors would force one triangle inside the other, whose
//! boundary would then meet it. Degenerate: the triangle is the union of its edges.
//!
//! **Why projections suffice.** Coplanar figures intersect iff their projections on all
//! three coordinate planes intersect: one of the three projections (along an axis the plane's
//! normal, or the common line's direction, does not lie across) is injective on them.

use super::relative::Relative;
use crate::num::pow2;
use glam::{DVec3, Vec3};
use robust::{Coord, Coord3D, orient2d, orient3d};

#[inline(always)]
fn c3(p: DVec3) -> Coord3D<f64> {
    Coord3D {
        x: p.x,
        y: p.y,
        z: p.z,
    }
}

/// The sign of `orient3d(a, b, c, d)`: `0` for coplanar (and, conservatively, for NaN).
#[inline(always)]
fn o3(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> i8 {
    sign(orient3d(c3(a), c3(b), c3(c), c3(d)))
}

#[inline(always)]
fn sign(x: f64) -> i8 {
    (x > 0.0) as i8 - (x < 0.0) as i8
}

/// A point projected on the coordinate plane that drops `axis`.
#[inline(always)]
fn project(p: DVec3, axis: usize) -> Coord<f64> {
    let (x, y) = match axis {
        0 => (p.y, p.z),
        1 => (p.z, p.x),
        _ => (p.x, p.y),
    };
    Coord { x, y }
}

#[inline(always)]
fn o2(a: Coord<f64>, b: Coord<f64>, c: Coord<f64>) -> i8 {
    sign(orient2d(a, b, c))
}

/// `p` on the segment `[a, b]`, given that the three are collinear (exact comparisons).
#[inline(always)]
fn within(a: Coord<f64>, b: Coord<f64>, p: Coord<f64>) -> bool {
    a.x.min(b.x) <= p.x && p.x <= a.x.max(b.x) && a.y.min(b.y) <= p.y && p.y <= a.y.max(b.y)
}

/// Closed segments in the plane (either may be a point).
fn segments_2d(p: Coord<f64>, q: Coord<f64>, a: Coord<f64>, b: Coord<f64>) -> bool {
    let (d1, d2) = (o2(a, b, p), o2(a, b, q));
    let (d3, d4) = (o2(p, q, a), o2(p, q, b));
    if d1 * d2 < 0 && d3 * d4 < 0 {
        return true;
    }
    (d1 == 0 && within(a, b, p))
        || (d2 == 0 && within(a, b, q))
        || (d3 == 0 && within(p, q, a))
        || (d4 == 0 && within(p, q, b))
}

/// A closed segment and a closed triangle in the plane (the triangle may be degenerate).
fn segment_triangle_2d(
    p: Coord<f64>,
    q: Coord<f64>,
    a: Coord<f64>,
    b: Coord<f64>,
    c: Coord<f64>,
) -> bool {
    let edges = segments_2d(p, q, a, b) || segments_2d(p, q, b, c) || segments_2d(p, q, c, a);
    if edges || o2(a, b, c) == 0 {
        return edges;
    }
    // A proper triangle that no edge crosses: the segment is inside iff an end point is.
    let inside = |x: Coord<f64>| {
        let s = [o2(a, b, x), o2(b, c, x), o2(c, a, x)];
        !(s.contains(&1) && s.contains(&-1))
    };
    inside(p)
}

/// True when `a`, `b`, `c` lie on one line: `(b − a) × (c − a) = 0`, whose components are
/// the orientations of the three projections.
fn collinear(a: DVec3, b: DVec3, c: DVec3) -> bool {
    (0..3).all(|k| o2(project(a, k), project(b, k), project(c, k)) == 0)
}

/// Closed segments in 3D: coplanar, and intersecting in all three projections.
fn segments(p: DVec3, q: DVec3, a: DVec3, b: DVec3) -> bool {
    o3(p, q, a, b) == 0
        && (0..3).all(|k| segments_2d(project(p, k), project(q, k), project(a, k), project(b, k)))
}

/// A closed segment `[p, q]` and the closed triangle `abc` in 3D.
fn segment_triangle(p: DVec3, q: DVec3, a: DVec3, b: DVec3, c: DVec3) -> bool {
    if collinear(a, b, c) {
        return segments(p, q, a, b) || segments(p, q, b, c) || segments(p, q, c, a);
    }
    let (sp, sq) = (o3(a, b, c, p), o3(a, b, c, q));
    if sp * sq > 0 {
        return false; // both strictly on one side
    }
    if sp == 0 && sq == 0 {
        return (0..3).all(|k| {
            let pr = |x: DVec3| project(x, k);
            segment_triangle_2d(pr(p), pr(q), pr(a), pr(b), pr(c))
        });
    }
    // The line pq crosses the plane at one point, which the segment reaches; it lies in
    // the closed triangle iff pq turns the same way (or not at all) around each edge.
    let s = [o3(p, q, a, b), o3(p, q, b, c), o3(p, q, c, a)];
    !(s.contains(&1) && s.contains(&-1))
}

/// The filter's relative error bound and the bottom of its range (see [`orientation`]).
const TWO_POW_M48: f64 = pow2(-48);
const TWO_POW_M900: f64 = pow2(-900);

/// The signs of `u`'s vertices against the plane of `t` ([`orientation`] of each), or
/// `None` when one of them is not certain.
#[inline(always)]
fn plane_signs(t: &[DVec3; 3], u: &[DVec3; 3]) -> Option<[i8; 3]> {
    let [t0, t1, t2] = t.map(|v| v.to_array());
    let mut signs = [0i8; 3];
    for (sign, p) in signs.iter_mut().zip(u) {
        *sign = orientation(t0, t1, t2, p.to_array()).of();
        if *sign == 0 {
            return None;
        }
    }
    Some(signs)
}

/// Triangle pairs per batch of the lane filter ([`filter_batch`]).
pub(crate) const LANES: usize = 32;

/// Triangles in lanes: coordinate `c` of corner `k` of the triangle in lane `l` at
/// `[k][c][l]`.
pub(crate) type TriangleLanes = [[[f64; LANES]; 3]; 3];

/// What the lane filter proved about each pair of a batch: `apart[l]` that the triangles of
/// lane `l` do not meet, `meet[l]` that they do; neither, and the exact test decides.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Verdicts {
    pub apart: [bool; LANES],
    pub meet: [bool; LANES],
}

/// The filtered opening of [`triangles_intersect`] on a batch of pairs `(i, j)`, triangle
/// `i` of `a` and triangle `j` of `b` placed in `A`'s frame by `rel`, loaded into `lanes`
/// (lanes past the batch keep earlier triangles): the plane-side rejection of
/// [`plane_signs`] both ways, then, where every sign is certain and both triangles cross
/// the other's plane, Guigue and Devillers' two orientations of [`crossing`] by the same
/// filter. Each decision is the one the scalar test makes from the same signs, taken only
/// where the filter proves the sign of the exact determinant. Plain array code, run with
/// the loads and the placement in the best backend's dispatch wrapper so that it
/// vectorises; compiled once, in the library, whatever the meshes' layouts.
pub(crate) fn filter_batch(
    a: Soup<'_>,
    b: Soup<'_>,
    rel: &Relative,
    batch: &[(u32, u32)],
    lanes: &mut (TriangleLanes, TriangleLanes),
) -> Verdicts {
    crate::simd::plain(
        #[inline(always)]
        move || {
            let (la, lb) = lanes;
            for (l, &(i, j)) in (0..LANES).zip(batch) {
                let (ta, tb) = (a.corners(i), b.corners(j));
                for k in 0..3 {
                    for c in 0..3 {
                        la[k][c][l] = f64::from(ta[k][c]);
                        lb[k][c][l] = f64::from(tb[k][c]);
                    }
                }
            }
            // `B`'s corners placed in `A`'s frame, all lanes at once.
            for corner in lb.iter_mut() {
                rel.place_lanes(corner);
            }
            verdicts(la, lb)
        },
    )
}

/// The tests of [`filter_batch`] on triangles already in lanes, `b`'s placed.
#[inline(always)]
fn verdicts(a: &TriangleLanes, b: &TriangleLanes) -> Verdicts {
    // The signs of `b`'s corners against `a`'s plane, and of `a`'s against `b`'s,
    // in straight-line loops over the lanes (they vectorise).
    let (sb, sa) = (plane_sides(a, b), plane_sides(b, a));
    let mut v = Verdicts::default();
    let mut crossing_lanes = [false; LANES];
    for l in 0..LANES {
        let aside = |s: &[[Sign; LANES]; 3]| {
            (s[0][l].above & s[1][l].above & s[2][l].above)
                | (s[0][l].below & s[1][l].below & s[2][l].below)
        };
        let certain = |s: &[[Sign; LANES]; 3]| (0..3).all(|k| s[k][l].above | s[k][l].below);
        v.apart[l] = aside(&sb) | aside(&sa);
        crossing_lanes[l] = !v.apart[l] & certain(&sa) & certain(&sb);
    }
    // Both cross strictly: `crossing`'s rotation and swaps, then its two signs.
    for l in 0..LANES {
        if !crossing_lanes[l] {
            continue;
        }
        let corner = |t: &TriangleLanes, k: usize| [t[k][0][l], t[k][1][l], t[k][2][l]];
        let ta = [corner(a, 0), corner(a, 1), corner(a, 2)];
        let tb = [corner(b, 0), corner(b, 1), corner(b, 2)];
        let signs = |s: &[[Sign; LANES]; 3]| [s[0][l].of(), s[1][l].of(), s[2][l].of()];
        let (sa, sb) = (signs(&sa), signs(&sb));
        let [[a0, a1, a2, a3], [b0, b1, b2, b3]] = crossing_corners(ta, tb, sa, sb);
        let (o1, o2) = (orientation(a0, a1, a2, a3), orientation(b0, b1, b2, b3));
        v.apart[l] = o1.above | o2.above;
        v.meet[l] = o1.below & o2.below;
    }
    v
}

/// [`verdicts`] in the dispatch wrapper, as [`filter_batch`] runs it.
#[cfg(test)]
fn filter(a: &TriangleLanes, b: &TriangleLanes) -> Verdicts {
    crate::simd::plain(
        #[inline(always)]
        || verdicts(a, b),
    )
}

/// A mesh's triangles as a batch reads them: its vertices, and each triangle's three
/// vertex indices (checked when the mesh was built).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Soup<'a> {
    pub vertices: &'a [Vec3],
    pub triangles: &'a [[u32; 3]],
}

impl Soup<'_> {
    /// The corners of triangle `i`.
    #[inline(always)]
    pub(crate) fn corners(&self, i: u32) -> [Vec3; 3] {
        self.triangles[i as usize].map(|v| self.vertices[v as usize])
    }
}

/// Per corner `k` of `u` and lane `l`, the sign of `O(t₀, t₁, t₂, u_k)` where the filter
/// proves it ([`orientation`]).
#[inline(always)]
fn plane_sides(t: &TriangleLanes, u: &TriangleLanes) -> [[Sign; LANES]; 3] {
    let mut sides = [[Sign::default(); LANES]; 3];
    for l in 0..LANES {
        let corner = |t: &TriangleLanes, k: usize| [t[k][0][l], t[k][1][l], t[k][2][l]];
        let (t0, t1, t2) = (corner(t, 0), corner(t, 1), corner(t, 2));
        for (k, side) in sides.iter_mut().enumerate() {
            side[l] = orientation(t0, t1, t2, corner(u, k));
        }
    }
    sides
}

/// The sign of an orientation where the filter proves it: `above` when certainly positive,
/// `below` when certainly negative, neither when the exact predicate must decide.
#[derive(Clone, Copy, Default)]
struct Sign {
    above: bool,
    below: bool,
}

impl Sign {
    /// As `-1`, `0` or `1` (`0`: not certain).
    #[inline(always)]
    fn of(self) -> i8 {
        i8::from(self.above) - i8::from(self.below)
    }
}

/// The sign of `O(t₀, t₁, t₂, p) = n·(p − t₀)` with `n = (t₁ − t₀) × (t₂ − t₀)`, in `f64`,
/// where a filter proves it.
///
/// The filter: each of the six products `±e₁·e₂·w` of the determinant carries at most 9
/// roundings (three differences, the cross product's products and difference, the dot
/// product's products and sums), so the computed value errs by at most
/// `γ(9)·perm < 2^-49.7·perm` with `perm` the sum of their absolute values; `perm` is itself
/// computed with at most 6 roundings, so `2^-48·perm` bounds the error. A sign is certain when
/// the value exceeds that bound. Near the ends of the range (`perm` below `2^-900`, where
/// products could underflow, or not finite) nothing is certain and the exact predicate
/// decides.
#[inline(always)]
fn orientation(t0: [f64; 3], t1: [f64; 3], t2: [f64; 3], p: [f64; 3]) -> Sign {
    let e1 = [t1[0] - t0[0], t1[1] - t0[1], t1[2] - t0[2]];
    let e2 = [t2[0] - t0[0], t2[1] - t0[1], t2[2] - t0[2]];
    // `DVec3::cross` and the filter's permanent, term by term.
    let n = [
        e1[1] * e2[2] - e2[1] * e1[2],
        e1[2] * e2[0] - e2[2] * e1[0],
        e1[0] * e2[1] - e2[0] * e1[1],
    ];
    let na = [
        (e1[1] * e2[2]).abs() + (e1[2] * e2[1]).abs(),
        (e1[2] * e2[0]).abs() + (e1[0] * e2[2]).abs(),
        (e1[0] * e2[1]).abs() + (e1[1] * e2[0]).abs(),
    ];
    let w = [p[0] - t0[0], p[1] - t0[1], p[2] - t0[2]];
    let value = n[0] * w[0] + n[1] * w[1] + n[2] * w[2];
    let perm = na[0] * w[0].abs() + na[1] * w[1].abs() + na[2] * w[2].abs();
    let certain = (TWO_POW_M900..f64::INFINITY).contains(&perm);
    let bound = perm * TWO_POW_M48;
    Sign {
        above: certain & (value > bound),
        below: certain & (value < -bound),
    }
}

/// The sign of `O(a, b, c, d) = ((b − a) × (c − a))·(d − a)`, exact (Shewchuk's `orient3d`
/// is `−O`).
#[inline(always)]
fn orient(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> i8 {
    -o3(a, b, c, d)
}

/// The signs of `O(t₀, t₁, t₂, u_k)`: filtered, exact where the filter is unsure.
#[inline(always)]
fn signs(t: &[DVec3; 3], u: &[DVec3; 3]) -> [i8; 3] {
    plane_signs(t, u).unwrap_or_else(|| u.map(|p| orient(t[0], t[1], t[2], p)))
}

/// True when all three signs are the same and not zero.
#[inline(always)]
fn aside(s: [i8; 3]) -> bool {
    s == [1, 1, 1] || s == [-1, -1, -1]
}

/// True when the closed triangles `a` and `b` share a point (exact; touching counts).
#[must_use]
pub fn triangles_intersect(a: &[DVec3; 3], b: &[DVec3; 3]) -> bool {
    // The common rejection first (a filtered, then exact, plane-side test): one triangle
    // strictly on one side of the other's plane.
    let sb = signs(a, b);
    if aside(sb) {
        return false;
    }
    let sa = signs(b, a);
    if aside(sa) {
        return false;
    }
    if !sa.contains(&0) && !sb.contains(&0) {
        return crossing(a, b, sa, sb);
    }
    // Some vertex on the other plane, coplanar or degenerate: the edge tests.
    let edges = [(0, 1), (1, 2), (2, 0)];
    edges
        .iter()
        .any(|&(i, j)| segment_triangle(a[i], a[j], b[0], b[1], b[2]))
        || edges
            .iter()
            .any(|&(i, j)| segment_triangle(b[i], b[j], a[0], a[1], a[2]))
}

/// The corner alone on its side of the other triangle's plane (no sign zero, not all equal).
#[inline(always)]
fn lone(s: [i8; 3]) -> usize {
    if s[0] == s[1] {
        2
    } else if s[0] == s[2] {
        1
    } else {
        0
    }
}

/// Guigue and Devillers' test for triangles that each cross the other's plane strictly (no
/// vertex on the other plane; `sa`, `sb` the signs of `a`'s vertices against `b`'s plane
/// and of `b`'s against `a`'s, none zero).
///
/// Each triangle has one vertex alone on its side; rotating the vertices (which keeps the
/// orientation) puts it first, as `p₁` and `p₂`, and swapping the other two of the other
/// triangle puts `p₁` on the positive side of `π₂` and `p₂` on the positive side of `π₁`.
/// The planes then cut `a` in `[i, j]` (`i` on `p₁q₁`, `j` on `p₁r₁`) and `b` in `[k, l]`,
/// on the line where the planes meet, and the two intervals overlap iff `k` is not past `j`
/// and `i` not past `l`, which are the signs of `O(p₁, q₁, p₂, q₂)` and
/// `O(p₁, r₁, r₂, p₂)` (both `<= 0`); zero is touching, which counts. (The opposite sign
/// convention fails the exact reference of `tests/trees.rs` at once.)
fn crossing(a: &[DVec3; 3], b: &[DVec3; 3], sa: [i8; 3], sb: [i8; 3]) -> bool {
    let [[a0, a1, a2, a3], [b0, b1, b2, b3]] = crossing_corners(*a, *b, sa, sb);
    orient(a0, a1, a2, a3) <= 0 && orient(b0, b1, b2, b3) <= 0
}

/// The arguments of [`crossing`]'s two orientations, `(p₁, q₁, p₂, q₂)` and
/// `(p₁, r₁, r₂, p₂)`: each triangle rotated to put its lone corner first, and the other
/// two swapped by the lone corner's side. The one home of that rule, for points of any
/// type (the scalar test and the lane filter).
#[inline(always)]
fn crossing_corners<P: Copy>(a: [P; 3], b: [P; 3], sa: [i8; 3], sb: [i8; 3]) -> [[P; 4]; 2] {
    let (i, j) = (lone(sa), lone(sb));
    let (p1, mut q1, mut r1) = (a[i], a[(i + 1) % 3], a[(i + 2) % 3]);
    let (p2, mut q2, mut r2) = (b[j], b[(j + 1) % 3], b[(j + 2) % 3]);
    if sa[i] < 0 {
        core::mem::swap(&mut q2, &mut r2);
    }
    if sb[j] < 0 {
        core::mem::swap(&mut q1, &mut r1);
    }
    [[p1, q1, p2, q2], [p1, r1, r2, p2]]
}

/// The squared distance from `p` to the segment `[a, b]` (`f64`, not exact).
fn point_segment_sq(p: DVec3, a: DVec3, b: DVec3) -> f64 {
    let ab = b - a;
    let len = ab.length_squared();
    let s = if len > 0.0 {
        ((p - a).dot(ab) / len).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (a + ab * s - p).length_squared()
}

/// The squared distance between segments `[p, q]` and `[a, b]` (`f64`, not exact).
fn segment_segment_sq(p: DVec3, q: DVec3, a: DVec3, b: DVec3) -> f64 {
    let ends = point_segment_sq(p, a, b)
        .min(point_segment_sq(q, a, b))
        .min(point_segment_sq(a, p, q))
        .min(point_segment_sq(b, p, q));
    // The interior minimum, where it exists (the end points cover every other case).
    let (d1, d2, r) = (q - p, b - a, p - a);
    let (aa, ee, bb) = (d1.length_squared(), d2.length_squared(), d1.dot(d2));
    let denom = aa * ee - bb * bb;
    if denom > 0.0 {
        let (c, f) = (d1.dot(r), d2.dot(r));
        let s = (bb * f - c * ee) / denom;
        let t = (aa * f - bb * c) / denom;
        if (0.0..=1.0).contains(&s) && (0.0..=1.0).contains(&t) {
            return ends.min((p + d1 * s - (a + d2 * t)).length_squared());
        }
    }
    ends
}

/// The squared distance from `p` to the triangle `abc` (`f64`, not exact).
fn point_triangle_sq(p: DVec3, t: &[DVec3; 3]) -> f64 {
    let edges = point_segment_sq(p, t[0], t[1])
        .min(point_segment_sq(p, t[1], t[2]))
        .min(point_segment_sq(p, t[2], t[0]));
    let n = (t[1] - t[0]).cross(t[2] - t[0]);
    let nn = n.length_squared();
    if nn > 0.0 {
        let h = (p - t[0]).dot(n);
        let foot = p - n * (h / nn);
        let inside = (0..3).all(|i| {
            let (u, v) = (t[i], t[(i + 1) % 3]);
            (v - u).cross(foot - u).dot(n) >= 0.0
        });
        if inside {
            return edges.min(h * h / nn);
        }
    }
    edges
}

/// The squared distance between two triangles in `f64`: zero when they intersect (decided
/// exactly), otherwise the least of the 9 edge–edge and 6 vertex–triangle distances, each
/// rounded (relative error a few `2^-52`).
#[must_use]
pub fn triangles_distance_sq(a: &[DVec3; 3], b: &[DVec3; 3]) -> f64 {
    if triangles_intersect(a, b) {
        return 0.0;
    }
    let mut best = f64::INFINITY;
    for i in 0..3 {
        best = best
            .min(point_triangle_sq(a[i], b))
            .min(point_triangle_sq(b[i], a));
        for j in 0..3 {
            best = best.min(segment_segment_sq(
                a[i],
                a[(i + 1) % 3],
                b[j],
                b[(j + 1) % 3],
            ));
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The lane filter decides only what the exact test decides: a pair it proves apart
    /// does not meet, a pair it proves meeting does, and it rejects at least every pair the
    /// scalar plane filter rejects. Random pairs, pairs sharing a corner, coplanar pairs and
    /// pairs a hair apart, and empty lanes.
    #[test]
    fn the_lane_filter_agrees_with_the_exact_test() {
        let mut next = crate::num::uniform(0x9e37_79b9_7f4a_7c15);
        let one_sided = |s: Option<[i8; 3]>| s.is_some_and(aside);
        let (mut rejected, mut met, mut unsure) = (0, 0, 0);
        for round in 0..64 {
            let mut a: TriangleLanes = [[[0.0; LANES]; 3]; 3];
            let mut b: TriangleLanes = [[[0.0; LANES]; 3]; 3];
            let mut pairs = [[[DVec3::ZERO; 3]; 2]; LANES];
            // The last lanes of the last round stay empty (all zero).
            let used = if round == 63 { LANES - 5 } else { LANES };
            for (l, pair) in pairs.iter_mut().enumerate().take(used) {
                let mut point = || DVec3::new(next(), next(), next());
                let ta = [point(), point(), point()];
                let mut tb = [point(), point(), point()];
                match l % 4 {
                    1 => tb[0] = ta[1],
                    2 => {
                        // Coplanar with `ta`.
                        tb = tb.map(|p| ta[0] + (ta[1] - ta[0]) * p.x + (ta[2] - ta[0]) * p.y)
                    }
                    3 => {
                        // A hair above `ta`'s plane.
                        let n = (ta[1] - ta[0]).cross(ta[2] - ta[0]);
                        let lift = n * (1e-15 * (1.0 + next().abs()));
                        tb = tb.map(|p| {
                            ta[0] + (ta[1] - ta[0]) * p.x.abs() + (ta[2] - ta[0]) * p.y.abs() + lift
                        })
                    }
                    _ => {}
                }
                *pair = [ta, tb];
                for k in 0..3 {
                    for c in 0..3 {
                        a[k][c][l] = ta[k][c];
                        b[k][c][l] = tb[k][c];
                    }
                }
            }
            let v = filter(&a, &b);
            for (l, [ta, tb]) in pairs.iter().enumerate() {
                let exact = triangles_intersect(ta, tb);
                let scalar = one_sided(plane_signs(ta, tb)) || one_sided(plane_signs(tb, ta));
                let what = alloc::format!("round {round}, lane {l}: {ta:?} {tb:?}");
                assert!(!(v.apart[l] && v.meet[l]), "{what}");
                assert!(!v.apart[l] || !exact, "{what}");
                assert!(!v.meet[l] || exact, "{what}");
                assert!(!scalar || v.apart[l], "{what}");
                match (v.apart[l], v.meet[l]) {
                    (true, _) => rejected += 1,
                    (_, true) => met += 1,
                    _ => unsure += 1,
                }
            }
        }
        // Every outcome is exercised.
        assert!(
            rejected > 200 && met > 50 && unsure > 50,
            "rejected {rejected}, met {met}, unsure {unsure}"
        );
    }
}
