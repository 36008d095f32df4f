//! A lower bound on the volume of every capsule that holds a point set, over all axis
//! directions: a proof that no capsule much smaller than a fitted one exists.
//!
//! **Per direction.** A capsule with unit axis `d`, radius `r` and segment length `L` holds
//! the points only if `r >= r(d)`, the radius of the smallest circle around their
//! projection on the plane orthogonal to `d`, and `L + 2r >= E(d)`, their extent along
//! `d`. So its volume `πr²L + 4/3·πr³` is at least `h(r(d), E(d))` with
//! `h(r, E) = πr²·max(0, E − 2r) + 4/3·πr³`, which grows with `r` (its derivative is
//! `2πr(E − r) >= 0` for `r <= E/2`, and `4πr² > 0` beyond) and with `E`.
//!
//! **Pairs of points.** The caps add length only near the axis: a point at distance `ρ_p`
//! from the axis and height `t_p` along it lies in the capsule only if `t_p` is within
//! `√(r² − ρ_p²)` of the segment, so `L >= t_p − t_q − √(r² − ρ_p²) − √(r² − ρ_q²)` for any
//! two points. The distance `s` between their projections on the plane is at most
//! `ρ_p + ρ_q`, and `√(r² − x²)` is concave and decreasing, so the two roots are at most
//! `2·√(r² − s²/4)`: `L >= L(r) = max_pairs (t_p − t_q − 2·√(r² − s²/4))`, which falls as
//! `r` grows. On `r` in `[a, b]` the volume is then at least `πa²·max(0, L(b)) + 4/3·πa³`;
//! the bound is the least of these over a geometric ladder of `r` from `r(d)` up to where
//! `L` reaches 0 (beyond it, `4/3·πr³` only grows), and at least `h(r(d), E(d))`. The pairs
//! are those of the points highest and lowest along `d` (any subset of pairs gives a
//! bound): this is what decides capsules whose ends are corners or rims.
//!
//! **Near a direction.** Let `c` be any point and `ρ` the largest `|p − c|`. For a unit
//! `d'` at chord distance `δ` from `d`: every projection on `d'` moves by at most `ρδ`, so
//! `E(d') >= E(d) − 2ρδ`; and the axis of the best cylinder along `d'`, moved to direction
//! `d` about the foot of `c`, moves each point's nearest axis point by at most `ρδ`, so
//! `r(d') >= r(d) − ρδ`. Hence every capsule with its axis within chord `δ` of `d` has
//! volume at least `h(r(d) − ρδ, E(d) − 2ρδ)` (clamped at 0). Likewise a pair's height
//! difference and projected distance each move by at most `2ρδ`, so the pair bounds hold
//! with `t_p − t_q − 2ρδ` and `max(0, s − 2ρδ)`.
//!
//! **All directions.** `d` and `−d` give the same capsules, and every direction or its
//! opposite lies on one of the faces `+x`, `+y`, `+z` of the cube, seen from its center.
//! Each face is cut into squares; a square's directions lie within the largest chord from
//! its center's direction to its corners' (the square is a geodesic quadrilateral, and a
//! cap around the center that holds its corners holds it). Branch and bound: the square of
//! least bound gets its pairs' bound if it has none, and is split in four otherwise, until
//! the work budget is spent and the least square has its pairs' bound; the least bound
//! over all squares is a lower bound on every capsule's volume. Everything is `f64` on the `f32`
//! inputs; its rounding (about `10^-15` relative) is far below the four digits reported.

use bvkit_support::parry3d;
use glam::{DVec2, DVec3, Vec3};
use std::collections::BinaryHeap;

/// The smallest circle around `points` (Welzl's algorithm, iteratively, on a fixed-seed
/// shuffle): its radius.
fn circle_radius(points: &mut [DVec2]) -> f64 {
    // A fixed-seed shuffle (xorshift64*), so that the expected time is linear.
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    for i in (1..points.len()).rev() {
        state ^= state >> 12;
        state ^= state << 25;
        state ^= state >> 27;
        let j = (state.wrapping_mul(0x2545_f491_4f6c_dd1d) % (i as u64 + 1)) as usize;
        points.swap(i, j);
    }
    let inside = |c: DVec2, r2: f64, p: DVec2| c.distance_squared(p) <= r2 * (1.0 + 1e-12);
    let (mut c, mut r2) = (points[0], 0.0);
    for i in 1..points.len() {
        if inside(c, r2, points[i]) {
            continue;
        }
        (c, r2) = (points[i], 0.0);
        for j in 0..i {
            if inside(c, r2, points[j]) {
                continue;
            }
            c = (points[i] + points[j]) * 0.5;
            r2 = c.distance_squared(points[i]);
            for k in 0..j {
                if inside(c, r2, points[k]) {
                    continue;
                }
                let three = [points[i], points[j], points[k]];
                // Collinear: the circle on the farthest pair.
                c = circumcenter(three[0], three[1], three[2]).unwrap_or_else(|| {
                    let pairs = [(0, 1), (1, 2), (0, 2)];
                    let (a, b) = pairs
                        .into_iter()
                        .max_by(|x, y| {
                            let d = |(a, b): (usize, usize)| three[a].distance_squared(three[b]);
                            d(*x).total_cmp(&d(*y))
                        })
                        .unwrap_or((0, 1));
                    (three[a] + three[b]) * 0.5
                });
                r2 = three
                    .iter()
                    .map(|p| c.distance_squared(*p))
                    .fold(0.0, f64::max);
            }
        }
    }
    r2.sqrt()
}

/// The center of the circle through three points (none when they are collinear).
fn circumcenter(a: DVec2, b: DVec2, c: DVec2) -> Option<DVec2> {
    let (ab, ac) = (b - a, c - a);
    let d = 2.0 * ab.perp_dot(ac);
    if d == 0.0 {
        return None;
    }
    let (lb, lc) = (ab.length_squared(), ac.length_squared());
    Some(a + DVec2::new(ac.y * lb - ab.y * lc, ab.x * lc - ac.x * lb) / d)
}

/// `h(r, E)`: the least volume of a capsule of radius `r` whose extent along its axis is
/// at least `E`.
fn least_volume(r: f64, extent: f64) -> f64 {
    let pi = std::f64::consts::PI;
    pi * r * r * (extent - 2.0 * r).max(0.0) + 4.0 / 3.0 * pi * r.powi(3)
}

/// How many of the highest and of the lowest points along a direction pair up.
const PAIRED: usize = 48;
/// The ratio of the ladder of radii.
const LADDER: f64 = 1.005;

/// The least volume of a capsule of radius at least `r0` (and extent at least `extent`)
/// whose pairs of points need lengths `L(r) >= height − 2·√(r² − reach)` for each
/// `(height, reach)` in `pairs` (see the module's doc): a lower bound from a ladder of
/// radii, never below `h(r0, extent)`; and how many rungs it took.
fn pair_volume(r0: f64, extent: f64, pairs: &[(f64, f64)]) -> (f64, usize) {
    let pi = std::f64::consts::PI;
    let length = |r: f64| {
        pairs
            .iter()
            .map(|&(height, reach)| height - 2.0 * (r * r - reach).max(0.0).sqrt())
            .fold(0.0, f64::max)
    };
    let plain = least_volume(r0, extent);
    if r0 <= 0.0 {
        return (plain, 0);
    }
    let (mut least, mut rungs) = (f64::INFINITY, 0);
    let mut a = r0;
    loop {
        let b = a * LADDER;
        let l = length(b);
        rungs += 1;
        least = least.min(pi * a * a * l + 4.0 / 3.0 * pi * a.powi(3));
        if l <= 0.0 || 4.0 / 3.0 * pi * a.powi(3) >= least {
            break;
        }
        a = b;
    }
    (least.max(plain), rungs)
}

/// The direction of point `(u, v)` of cube face `axis` (`+x`, `+y`, `+z`).
fn direction(axis: usize, u: f64, v: f64) -> DVec3 {
    let mut d = [0.0; 3];
    d[axis] = 1.0;
    d[(axis + 1) % 3] = u;
    d[(axis + 2) % 3] = v;
    DVec3::from_array(d).normalize()
}

/// A square `[u, u + side] × [v, v + side]` of a cube face, with its lower bound.
#[derive(Clone, Copy, PartialEq)]
struct Square {
    bound: f64,
    axis: usize,
    u: f64,
    v: f64,
    side: f64,
    /// Whether the bound includes the pairs' ladder.
    paired: bool,
}

impl Eq for Square {}

impl Ord for Square {
    /// The least bound first, in a max-heap.
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        other.bound.total_cmp(&self.bound)
    }
}

impl PartialOrd for Square {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

/// A lower bound on the volume of every capsule that holds `points`, from squares of
/// directions until about `work` steps are spent (a square costs a pass over the hull
/// vertices and its pairs on each rung of its ladder; at least the 192 first squares are
/// measured).
pub fn capsule_lower_bound(points: &[Vec3], work: usize) -> f64 {
    let (hull, _) = parry3d::transformation::convex_hull(points);
    let hull: Vec<DVec3> = hull.iter().map(|p| p.as_dvec3()).collect();
    let c = hull.iter().sum::<DVec3>() / hull.len() as f64;
    let rho = hull.iter().map(|p| p.distance(c)).fold(0.0, f64::max);
    let mut flat = Vec::with_capacity(hull.len());
    let mut heights: Vec<(f64, DVec2)> = Vec::with_capacity(hull.len());
    // Work spent: hull vertices visited, and pairs evaluated per rung.
    let spent = std::cell::Cell::new(0);
    // A square's bound: `h(r(d), E(d))` near its center `d`, and with `paired` the pairs'
    // ladder too (it costs more, so only squares that come up as the least get it).
    let mut bound = |axis: usize, u: f64, v: f64, side: f64, paired: bool| {
        let d = direction(axis, u + side / 2.0, v + side / 2.0);
        let delta = [(0.0, 0.0), (side, 0.0), (0.0, side), (side, side)]
            .iter()
            .map(|&(du, dv)| direction(axis, u + du, v + dv).distance(d))
            .fold(0.0, f64::max);
        let (e1, e2) = d.any_orthonormal_pair();
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        flat.clear();
        heights.clear();
        for p in &hull {
            let q = p.dot(d);
            (lo, hi) = (lo.min(q), hi.max(q));
            let at = DVec2::new(p.dot(e1), p.dot(e2));
            flat.push(at);
            heights.push((q, at));
        }
        // The highest and the lowest points, paired (before the circle shuffles `flat`).
        let m = if paired {
            PAIRED.min(heights.len() / 2).max(1).min(heights.len())
        } else {
            0
        };
        heights.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
        let slack = 2.0 * rho * delta;
        let (bottom, top) = (&heights[..m], &heights[heights.len() - m..]);
        let pairs: Vec<(f64, f64)> = top
            .iter()
            .flat_map(|&(tp, pp)| {
                bottom.iter().map(move |&(tq, pq)| {
                    let s = (pp.distance(pq) - slack).max(0.0);
                    (tp - tq - slack, s * s / 4.0)
                })
            })
            .collect();
        let r = circle_radius(&mut flat);
        let (bound, rungs) = pair_volume(
            (r - rho * delta).max(0.0),
            (hi - lo - slack).max(0.0),
            &pairs,
        );
        spent.set(spent.get() + hull.len() + pairs.len() * rungs);
        Square {
            bound,
            axis,
            u,
            v,
            side,
            paired,
        }
    };
    let mut heap = BinaryHeap::new();
    const START: usize = 8;
    let side = 2.0 / START as f64;
    for axis in 0..3 {
        for i in 0..START {
            for j in 0..START {
                heap.push(bound(
                    axis,
                    -1.0 + side * i as f64,
                    -1.0 + side * j as f64,
                    side,
                    false,
                ));
            }
        }
    }
    // The least square gets its pairs' bound, or is split while work is left; so the
    // least bound at the end is a paired one.
    while let Some(s) = heap.pop() {
        if !s.paired {
            heap.push(bound(s.axis, s.u, s.v, s.side, true));
            continue;
        }
        if spent.get() >= work {
            heap.push(s);
            break;
        }
        let half = s.side / 2.0;
        for (du, dv) in [(0.0, 0.0), (half, 0.0), (0.0, half), (half, half)] {
            heap.push(bound(s.axis, s.u + du, s.v + dv, half, false));
        }
    }
    heap.peek().map_or(0.0, |s| s.bound)
}
