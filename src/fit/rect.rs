//! In the plane: the convex hull (Andrew's monotone chain) and the minimum-area enclosing
//! rectangle (rotating calipers, Toussaint 1983).
//!
//! The smallest rectangle around a convex polygon has a side on one of its edges (Freeman &
//! Shapira 1975), so it is enough to try each edge direction; the calipers keep the three
//! other extreme vertices and advance them monotonically, `O(m)` for `m` vertices. Rounding
//! in `f64` can only make the chosen direction slightly less than optimal: the fits measure
//! their extents again from every point.

use alloc::vec::Vec;
use glam::DVec2;

/// The convex hull, counter-clockwise, without collinear vertices (any order of input).
pub(crate) fn convex_hull_2d(points: &[DVec2]) -> Vec<DVec2> {
    let mut sorted = points.to_vec();
    // Unstable is enough: equal keys are equal points, which `dedup` merges.
    sorted.sort_unstable_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    sorted.dedup();
    if sorted.len() < 3 {
        return sorted;
    }
    // Lower chain left to right, upper chain right to left; each drops its last point,
    // which starts the other.
    let mut hull = half_hull(sorted.iter());
    hull.pop();
    let mut upper = half_hull(sorted.iter().rev());
    upper.pop();
    hull.append(&mut upper);
    hull
}

/// One monotone chain: pops every vertex where the chain would not turn left.
fn half_hull<'a>(points: impl Iterator<Item = &'a DVec2>) -> Vec<DVec2> {
    let mut chain: Vec<DVec2> = Vec::new();
    for &p in points {
        while let [.., a, b] = chain[..] {
            if (b - a).perp_dot(p - a) > 0.0 {
                break;
            }
            chain.pop();
        }
        chain.push(p);
    }
    chain
}

/// The unit direction of one side of the minimum-area rectangle around `points`, and the
/// rectangle's area. For fewer than three hull vertices: the direction of the segment
/// (or `x`) and area 0.
pub(crate) fn min_area_rectangle(points: &[DVec2]) -> (DVec2, f64) {
    let hull = convex_hull_2d(points);
    let m = hull.len();
    if m < 3 {
        let along = match hull[..] {
            [a, b] => (b - a).normalize_or(DVec2::X),
            _ => DVec2::X,
        };
        return (along, 0.0);
    }
    let at = |i: usize| hull[i % m];
    // Advance `i` while the next vertex lies farther along `dir` (at most one lap).
    let advance = |mut i: usize, dir: DVec2| {
        for _ in 0..m {
            if (at(i + 1) - at(i)).dot(dir) > 0.0 {
                i += 1;
            } else {
                break;
            }
        }
        i
    };
    let (mut right, mut top, mut left) = (0, 0, 0);
    let mut best = (DVec2::X, f64::INFINITY);
    for i in 0..m {
        let u = (at(i + 1) - at(i)).normalize_or(DVec2::X);
        let v = u.perp();
        right = advance(right.max(i), u);
        top = advance(top.max(right), v);
        left = advance(left.max(top), -u);
        let width = (at(right) - at(left)).dot(u);
        let height = (at(top) - at(i)).dot(v);
        if width * height < best.1 {
            best = (u, width * height);
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

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
        assert_eq!(convex_hull_2d(&pts).len(), 4);
        let (dir, area) = min_area_rectangle(&pts);
        assert!((area - 4.0).abs() < 1e-12, "{area}");
        assert!(
            dir.perp_dot(r).abs() < 1e-12 || dir.dot(r).abs() < 1e-12,
            "{dir}"
        );
        let diamond: Vec<DVec2> = [(1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0)]
            .iter()
            .map(|&(x, y)| DVec2::new(x, y))
            .collect();
        assert!((min_area_rectangle(&diamond).1 - 2.0).abs() < 1e-12);
    }
}
