//! A lower bound on the volume of every capsule that holds a point set, over all axis
//! directions: a proof that no capsule much smaller than a fitted one exists.
//!
//! **One direction.** Take a unit axis direction `d`, and write each point as its height
//! `t_p = p·d` and its foot `q_p`, its projection on the plane across `d`. A capsule along
//! `d` with radius `r`, whose axis crosses the plane at `c`, holds `p` only if
//! `|q_p − c| <= r` and the segment reaches within `√(r² − |q_p − c|²)` of `t_p`. So its
//! segment reaches up to `T = max_p (t_p − √(r² − |q_p − c|²))` and down to
//! `B = min_p (t_p + √(r² − |q_p − c|²))`, its length is at least `T − B`, and its volume
//! `πr²L + 4/3·πr³` is at least `πr²·max(0, T − B) + 4/3·πr³`. The thinnest such capsule
//! has `r >= r(d)`, the radius of the smallest circle around the feet; and its extent
//! `L + 2r` is at least `E(d)`, the points' extent along `d`, so its volume is at least
//! `h(r(d), E(d))` with `h(r, E) = πr²·max(0, E − 2r) + 4/3·πr³`, which grows with `r` and
//! `E`.
//!
//! **Nodes.** For a box `C` of axis crossings and an interval `[a, b]` of radii, every
//! capsule in it has `|q_p − c| >= g_p`, the distance from `q_p` to the box, so each root
//! is at most `√(b² − g_p²)`: its volume is at least `πa²·max(0, T' − B') + 4/3·πa³` with
//! `T' = max_p (t_p − √(b² − g_p²))` and `B' = min_p (t_p + √(b² − g_p²))`. A box with a
//! point farther than `b` from all of it holds no capsule of the interval, and neither
//! does one farther than `√(b² − r(d)²)` from the smallest circle's center `c0`: `c0` lies
//! in the hull of the feet that define the circle, all at distance `r(d)` from it, so for
//! any `c` one of them, `s`, has `(s − c0)·(c − c0) <= 0`, whence
//! `|c − s|² >= r(d)² + |c − c0|²`. Branch and bound
//! on the box and the interval (split in four, or the interval at its geometric mean) raises
//! the least node's bound toward the exact least capsule along `d`.
//!
//! **Near a direction.** Let the points be centered on their centroid, `A` the largest
//! `|t_p|` and `W` the largest `|q_p|`. For a unit `d'` at chord distance `δ` from `d`:
//! - every height moves by at most `τ = A·δ²/2 + W·δ` (`d' − d` has `−δ²/2·d` along `d`
//!   and at most `δ` across it);
//! - a capsule along `d'` whose axis passes at the foot `f` of the centroid, turned to
//!   `d` about `f`, moves each point's nearest axis point by `|(p − f)·d'|·δ <= σ` with
//!   `σ = δ·(A + W·δ)`: the turned axis holds every point within `r + σ`, and each point's
//!   distance from the capsule's own axis is at least its distance from the turned one
//!   minus `σ`.
//!
//! So every capsule with its axis within chord `δ` of `d` has `r >= r(d) − σ`, an extent of
//! at least `E(d) − 2τ`, and, in a node, a volume of at least the node's bound with each
//! `g_p` lowered by `σ`, the reach `b` raised by `σ` for the emptiness test, and `T' − B'`
//! lowered by `2τ`.
//!
//! **All directions.** `d` and `−d` give the same capsules, and every direction or its
//! opposite lies on one of the faces `+x`, `+y`, `+z` of the cube, seen from its center.
//! Each face is cut into squares; a square's directions lie within the largest chord from
//! its center's direction to its corners' (the square is a geodesic quadrilateral, and a
//! cap around the center that holds its corners holds it). Branch and bound: the square of
//! least bound gets its nodes' bound if it has only `h`, and is split in four otherwise,
//! until the work budget is spent; the least bound over all squares is then a lower bound
//! on every capsule's volume. The nodes of a square are refined until they are as fine as
//! its directions allow (`σ`), and at most `NODES` times.
//!
//! **Points.** A capsule that holds the points holds any subset of them, so the bound may
//! use fewer: the hull's vertices, and on a hull of more than `DIRECTIONS` vertices, only
//! those extreme along `DIRECTIONS` directions spread over the sphere.
//!
//! Everything is `f64` on the `f32` inputs. `r(d)` is taken no larger than the smallest
//! circle around the two or three feet that define the computed one. The rounding (about
//! `10^-15` relative) is far below the four digits reported.

use bvkit_support::parry3d;
use glam::{DVec2, DVec3, Vec3};
use std::collections::BinaryHeap;

/// The smallest circle around `points` (Welzl's algorithm, iteratively, on a fixed-seed
/// shuffle), given as the smallest circle around the two or three points that define it:
/// its radius is no larger than the exact smallest circle's, and its center lies in the
/// hull of the defining points on it (see `nodes_bound`).
fn smallest_circle(points: &mut [DVec2]) -> (DVec2, f64) {
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
    let mut defining = vec![points[0]];
    for i in 1..points.len() {
        if inside(c, r2, points[i]) {
            continue;
        }
        (c, r2, defining) = (points[i], 0.0, vec![points[i]]);
        for j in 0..i {
            if inside(c, r2, points[j]) {
                continue;
            }
            c = (points[i] + points[j]) * 0.5;
            r2 = c.distance_squared(points[i]);
            defining = vec![points[i], points[j]];
            for k in 0..j {
                if inside(c, r2, points[k]) {
                    continue;
                }
                let three = [points[i], points[j], points[k]];
                // Collinear: the circle on the farthest pair.
                c = circumcenter(three[0], three[1], three[2]).unwrap_or_else(|| {
                    let (a, b) = farthest_pair(&three);
                    (a + b) * 0.5
                });
                r2 = three
                    .iter()
                    .map(|p| c.distance_squared(*p))
                    .fold(0.0, f64::max);
                defining = three.to_vec();
            }
        }
    }
    enclosing(&defining)
}

/// The two farthest apart of three points.
fn farthest_pair(three: &[DVec2; 3]) -> (DVec2, DVec2) {
    [(0, 1), (1, 2), (0, 2)]
        .into_iter()
        .map(|(a, b)| (three[a], three[b]))
        .max_by(|x, y| {
            x.0.distance_squared(x.1)
                .total_cmp(&y.0.distance_squared(y.1))
        })
        .unwrap_or((three[0], three[1]))
}

/// The smallest circle around one, two or three points (center and radius): on the
/// longest side when a triangle is not acute, its circumcircle when it is.
fn enclosing(points: &[DVec2]) -> (DVec2, f64) {
    match *points {
        [a, b] => ((a + b) * 0.5, a.distance(b) / 2.0),
        [a, b, c] => {
            let (p, q) = farthest_pair(&[a, b, c]);
            let (m, half) = ((p + q) * 0.5, p.distance(q) / 2.0);
            match circumcenter(a, b, c) {
                Some(o) if [a, b, c].iter().any(|x| x.distance(m) > half) => {
                    (o, o.distance(a).min(o.distance(b)).min(o.distance(c)))
                }
                _ => (m, half),
            }
        }
        _ => (points.first().copied().unwrap_or(DVec2::ZERO), 0.0),
    }
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
    /// Whether the bound includes the nodes'.
    refined: bool,
}

/// Orders a heap entry with a `bound` field so that a max-heap pops the least bound first.
macro_rules! least_bound_first {
    ($entry:ty) => {
        impl Eq for $entry {}

        impl Ord for $entry {
            fn cmp(&self, other: &Self) -> std::cmp::Ordering {
                other.bound.total_cmp(&self.bound)
            }
        }

        impl PartialOrd for $entry {
            fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
                Some(self.cmp(other))
            }
        }
    };
}

least_bound_first!(Square);

/// How many directions pick the points of a large hull (see the module's doc).
const DIRECTIONS: usize = 1024;
/// A node is fine enough when its box's side is below `CENTERS` of its least radius and its
/// interval's ratio below `1 + RADII`, or below what the square's directions allow.
const CENTERS: f64 = 0.01;
/// See `CENTERS`.
const RADII: f64 = 0.002;
/// The most nodes a square splits.
const NODES: usize = 300;

/// The points the bound is computed on (see the module's doc), centered on their centroid.
fn support(points: &[Vec3]) -> Vec<DVec3> {
    let (hull, _) = parry3d::transformation::convex_hull(points);
    let mut hull: Vec<DVec3> = hull.iter().map(|p| p.as_dvec3()).collect();
    if hull.len() > DIRECTIONS {
        // A Fibonacci spiral of directions.
        let mut kept = vec![false; hull.len()];
        let turn = std::f64::consts::PI * (3.0 - 5f64.sqrt());
        for i in 0..DIRECTIONS {
            let z = 1.0 - 2.0 * (i as f64 + 0.5) / DIRECTIONS as f64;
            let (sin, cos) = (turn * i as f64).sin_cos();
            let d = DVec3::new(cos, sin, 0.0) * (1.0 - z * z).sqrt() + DVec3::Z * z;
            let extreme =
                (0..hull.len()).max_by(|&a, &b| hull[a].dot(d).total_cmp(&hull[b].dot(d)));
            kept[extreme.unwrap_or(0)] = true;
        }
        hull = hull
            .into_iter()
            .zip(kept)
            .filter_map(|(p, k)| k.then_some(p))
            .collect();
    }
    let centroid = hull.iter().sum::<DVec3>() / hull.len() as f64;
    hull.iter().map(|p| *p - centroid).collect()
}

/// The points seen along the center direction of a square: each `(t_p, q_p)` (see the
/// module's doc), and the square's slacks.
struct View {
    points: Vec<(f64, DVec2)>,
    /// The extent along the center direction.
    extent: f64,
    /// The smallest circle around the feet: its center `c0` and radius `r0`.
    circle: (DVec2, f64),
    /// How far a point's distance from the axis may move within the square.
    sigma: f64,
    /// How far a height may move within the square.
    tau: f64,
}

impl View {
    /// The view of square `[u, u + side] × [v, v + side]` of face `axis`.
    fn new(points: &[DVec3], axis: usize, u: f64, v: f64, side: f64) -> Self {
        let d = direction(axis, u + side / 2.0, v + side / 2.0);
        let delta = [(0.0, 0.0), (side, 0.0), (0.0, side), (side, side)]
            .iter()
            .map(|&(du, dv)| direction(axis, u + du, v + dv).distance(d))
            .fold(0.0, f64::max);
        let (e1, e2) = d.any_orthonormal_pair();
        let points: Vec<(f64, DVec2)> = points
            .iter()
            .map(|p| (p.dot(d), DVec2::new(p.dot(e1), p.dot(e2))))
            .collect();
        let (lo, hi) = points
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &(t, _)| {
                (lo.min(t), hi.max(t))
            });
        let along = lo.abs().max(hi.abs());
        let across = points.iter().map(|(_, q)| q.length()).fold(0.0, f64::max);
        let mut feet: Vec<DVec2> = points.iter().map(|&(_, q)| q).collect();
        Self {
            circle: smallest_circle(&mut feet),
            points,
            extent: hi - lo,
            sigma: delta * (along + across * delta),
            tau: along * delta * delta / 2.0 + across * delta,
        }
    }

    /// The radius of the disk around `c0` that holds the (turned) axis crossing of every
    /// capsule of radius at most `b` (see the module's doc), with a margin for rounding.
    fn disk(&self, b: f64) -> f64 {
        let (_, r0) = self.circle;
        ((b + self.sigma).powi(2) - r0 * r0).max(0.0).sqrt() * (1.0 + 1e-9) + 1e-6 * r0
    }

    /// The least volume of a capsule along the square's directions with its radius in
    /// `[a, b]` and its (turned) axis crossing the plane in the box `[x0, x0 + side] ×
    /// [y0, y0 + side]`; infinite when none holds the points.
    fn node_bound(&self, x0: f64, y0: f64, side: f64, a: f64, b: f64) -> f64 {
        let half = side / 2.0;
        let center = DVec2::new(x0 + half, y0 + half);
        let gap = |q: DVec2| {
            ((q - center).abs() - DVec2::splat(half))
                .max(DVec2::ZERO)
                .length()
        };
        if gap(self.circle.0) > self.disk(b) {
            return f64::INFINITY;
        }
        let (mut top, mut bottom) = (f64::NEG_INFINITY, f64::NEG_INFINITY);
        for &(t, q) in &self.points {
            let gap = gap(q);
            if gap > b + self.sigma {
                return f64::INFINITY;
            }
            let g = (gap - self.sigma).max(0.0);
            let root = (b * b - g * g).max(0.0).sqrt();
            top = top.max(t - root);
            bottom = bottom.max(-t - root);
        }
        let pi = std::f64::consts::PI;
        pi * a * a * (top + bottom - 2.0 * self.tau).max(0.0) + 4.0 / 3.0 * pi * a.powi(3)
    }
}

/// A box of axis crossings and an interval of radii, with its lower bound.
#[derive(Clone, Copy, PartialEq)]
struct Node {
    bound: f64,
    x0: f64,
    y0: f64,
    side: f64,
    a: f64,
    b: f64,
}

least_bound_first!(Node);

/// The nodes' bound of a view: the least volume of a capsule along its square's
/// directions, from a branch and bound over axis crossings and radii from `r_lo`; and how
/// many nodes it measured.
fn nodes_bound(view: &View, r_lo: f64) -> (f64, usize) {
    let pi = std::f64::consts::PI;
    let (center, r0) = view.circle;
    // The capsule on the smallest circle along the center direction holds the points:
    // beyond the radius of a ball of its volume, every capsule is bigger.
    let (mut top, mut bottom) = (f64::NEG_INFINITY, f64::INFINITY);
    for &(t, q) in &view.points {
        let root = (r0 * r0 - q.distance_squared(center)).max(0.0).sqrt();
        (top, bottom) = (top.max(t - root), bottom.min(t + root));
    }
    let feasible = pi * r0 * r0 * (top - bottom).max(0.0) + 4.0 / 3.0 * pi * r0.powi(3);
    let r_hi = (feasible * 3.0 / (4.0 * pi)).cbrt().max(r_lo);
    let beyond = 4.0 / 3.0 * pi * r_hi.powi(3);
    // Every axis crossing within reach of every point.
    let reach = r_hi + view.sigma;
    let disk = view.disk(r_hi);
    let (lo, hi) = view
        .points
        .iter()
        .fold((center - disk, center + disk), |(lo, hi), &(_, q)| {
            (lo.max(q - reach), hi.min(q + reach))
        });
    let side = (hi - lo).max_element();
    let mut nodes = BinaryHeap::new();
    let root = view.node_bound(lo.x, lo.y, side, r_lo, r_hi);
    nodes.push(Node {
        bound: root,
        x0: lo.x,
        y0: lo.y,
        side,
        a: r_lo,
        b: r_hi,
    });
    let mut measured = 1;
    // As fine as the square's directions allow.
    let (centers, radii) = (
        CENTERS.max(2.0 * view.sigma / r0),
        RADII.max(view.sigma / r0),
    );
    let least = loop {
        let Some(node) = nodes.pop() else {
            break beyond;
        };
        if node.bound >= beyond {
            break beyond;
        }
        let (fine_c, fine_r) = (node.side / node.a, node.b / node.a - 1.0);
        if (fine_c < centers && fine_r < radii) || measured >= NODES {
            break node.bound;
        }
        let children: Vec<Node> = if fine_c / centers > fine_r / radii {
            let half = node.side / 2.0;
            [(0.0, 0.0), (half, 0.0), (0.0, half), (half, half)]
                .map(|(dx, dy)| Node {
                    x0: node.x0 + dx,
                    y0: node.y0 + dy,
                    side: half,
                    ..node
                })
                .to_vec()
        } else {
            let mid = (node.a * node.b).sqrt();
            vec![Node { b: mid, ..node }, Node { a: mid, ..node }]
        };
        for mut child in children {
            child.bound = view.node_bound(child.x0, child.y0, child.side, child.a, child.b);
            measured += 1;
            if child.bound.is_finite() {
                nodes.push(child);
            }
        }
    };
    (least, measured)
}

/// A lower bound on the volume of every capsule that holds `points`, from squares of
/// directions until about `work` steps are spent (a square costs a pass over the points,
/// and each of its nodes one more; at least the 192 first squares are measured).
pub fn capsule_lower_bound(points: &[Vec3], work: usize) -> f64 {
    let points = support(points);
    let spent = std::cell::Cell::new(0);
    // A square's bound: `h(r(d), E(d))` less its slacks, and with `nodes` the nodes' bound
    // too (it costs more, so only squares that come up as the least get it).
    let bound = |axis: usize, u: f64, v: f64, side: f64, nodes: bool| {
        let view = View::new(&points, axis, u, v, side);
        let r_lo = (view.circle.1 - view.sigma).max(0.0);
        let plain = least_volume(r_lo, (view.extent - 2.0 * view.tau).max(0.0));
        spent.set(spent.get() + points.len());
        let mut bound = plain;
        if nodes && r_lo > 0.0 {
            let (least, measured) = nodes_bound(&view, r_lo);
            spent.set(spent.get() + points.len() * measured);
            bound = bound.max(least);
        }
        Square {
            bound,
            axis,
            u,
            v,
            side,
            refined: nodes,
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
    // The least square gets its nodes' bound, or is split while work is left; so the
    // least bound at the end is a refined one.
    while let Some(s) = heap.pop() {
        if !s.refined {
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
