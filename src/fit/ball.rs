//! The smallest enclosing ball of points in `D` dimensions (circle for `D = 2`, sphere for
//! `D = 3`): Welzl's randomised algorithm, in `f64`.
//!
//! `ball(P, R)` is the smallest ball holding `P` with the support points `R` on its
//! boundary. If the last point `p` of `P` lies in `ball(P − p, R)`, that ball is the answer;
//! otherwise `p` lies on the boundary of the answer, which is `ball(P − p, R + p)`
//! (Welzl 1991). With `|R| = D + 1` the ball is the circumball of `R`. On points in random
//! order the expected work is linear; the callers shuffle (see [`super::cloud::shuffle`]).
//!
//! Rounding may call a point outside that lies on the boundary, or make a support set
//! affinely dependent; the containment test has a relative tolerance of `2^-40` and a
//! dependent support point is dropped from the circumball. Neither can break containment:
//! the fits re-derive the radius of the rounded center from every point
//! ([`super::bound`]). Recursion depth is at most `D + 1`.

use crate::num::sqrt;
use alloc::vec;
use alloc::vec::Vec;

/// A ball `|x − center|² <= radius2`; `radius2 < 0` is the empty ball.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Ball<const D: usize> {
    pub center: [f64; D],
    pub radius2: f64,
}

/// The relative tolerance of the in-ball test.
const TOLERANCE: f64 = crate::num::pow2(-40);

fn sub<const D: usize>(a: &[f64; D], b: &[f64; D]) -> [f64; D] {
    core::array::from_fn(|i| a[i] - b[i])
}

fn dot<const D: usize>(a: &[f64; D], b: &[f64; D]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

impl<const D: usize> Ball<D> {
    /// The empty ball, which holds no point.
    const EMPTY: Self = Self {
        center: [0.0; D],
        radius2: -1.0,
    };

    /// The radius.
    pub fn radius(&self) -> f64 {
        sqrt(self.radius2.max(0.0))
    }

    /// True when `p` is inside, up to the relative tolerance.
    fn holds(&self, p: &[f64; D]) -> bool {
        let d = sub(p, &self.center);
        dot(&d, &d) <= self.radius2 * (1.0 + TOLERANCE)
    }

    /// The smallest ball with every support point on its boundary: center
    /// `c = s0 + Σ λ_i (s_i − s0)` in their affine hull, where equal distances to `s0` and
    /// `s_i` read `(c − s0)·(s_i − s0) = |s_i − s0|²/2`, a Gram system `G λ = b` solved by
    /// Gaussian elimination with partial pivoting. A pivot below `2^-40` of the Gram diagonal
    /// marks a (numerically) dependent point, whose `λ` is set to 0.
    fn circumball(support: &[[f64; D]]) -> Self {
        let Some(s0) = support.first() else {
            return Self::EMPTY;
        };
        let edges: Vec<[f64; D]> = support[1..].iter().map(|s| sub(s, s0)).collect();
        let k = edges.len();
        let mut g: Vec<Vec<f64>> = (0..k)
            .map(|i| {
                let mut row: Vec<f64> = (0..k).map(|j| dot(&edges[i], &edges[j])).collect();
                row.push(dot(&edges[i], &edges[i]) / 2.0);
                row
            })
            .collect();
        let lambda = solve(&mut g);
        let center = core::array::from_fn(|d| {
            s0[d]
                + edges
                    .iter()
                    .zip(&lambda)
                    .map(|(e, l)| l * e[d])
                    .sum::<f64>()
        });
        let radius2 = support
            .iter()
            .map(|s| {
                let v = sub(s, &center);
                dot(&v, &v)
            })
            .fold(0.0, f64::max);
        Self { center, radius2 }
    }
}

/// Solves the augmented system `[G | b]` (k × (k+1)) by elimination with partial pivoting;
/// unknowns with a negligible pivot are set to 0.
fn solve(g: &mut [Vec<f64>]) -> Vec<f64> {
    let k = g.len();
    let scale = (0..k).map(|i| g[i][i]).fold(0.0, f64::max);
    let mut pivot_of = vec![None; k];
    let mut used = vec![false; k];
    for col in 0..k {
        let best = (0..k)
            .filter(|&r| !used[r])
            .max_by(|&a, &b| g[a][col].abs().total_cmp(&g[b][col].abs()));
        let Some(r) = best.filter(|&r| g[r][col].abs() > scale * TOLERANCE) else {
            continue;
        };
        used[r] = true;
        pivot_of[col] = Some(r);
        let pivot = g[r].clone();
        for (_, row) in g.iter_mut().enumerate().filter(|(other, _)| *other != r) {
            let f = row[col] / pivot[col];
            for (x, p) in row[col..].iter_mut().zip(&pivot[col..]) {
                *x -= f * p;
            }
        }
    }
    pivot_of
        .iter()
        .enumerate()
        .map(|(col, r)| r.map_or(0.0, |r| g[r][k] / g[r][col]))
        .collect()
}

/// The smallest ball holding `points` with every point of `support` on its boundary.
fn ball_with<const D: usize>(points: &[[f64; D]], support: &mut Vec<[f64; D]>) -> Ball<D> {
    let mut ball = Ball::circumball(support);
    if support.len() == D + 1 {
        return ball;
    }
    for (i, p) in points.iter().enumerate() {
        if !ball.holds(p) {
            support.push(*p);
            ball = ball_with(&points[..i], support);
            support.pop();
        }
    }
    ball
}

/// The smallest enclosing ball of `points` (in the given order; shuffle first).
pub(crate) fn smallest_ball<const D: usize>(points: &[[f64; D]]) -> Ball<D> {
    ball_with(points, &mut Vec::with_capacity(D + 1))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn known_balls() {
        let square = [[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0], [1.0, 1.0]];
        let b = smallest_ball(&square);
        assert!((b.center[0] - 1.0).abs() < 1e-12 && (b.radius2 - 2.0).abs() < 1e-12);
        let line = [
            [0.0, 0.0, 0.0],
            [1.0, 1.0, 1.0],
            [3.0, 3.0, 3.0],
            [2.0, 2.0, 2.0],
        ];
        let b = smallest_ball(&line);
        assert!((b.radius2 - 6.75).abs() < 1e-12, "{b:?}");
        let one = [[5.0, -1.0, 2.0]];
        assert_eq!(smallest_ball(&one).radius2, 0.0);
        let cube: Vec<[f64; 3]> = (0..8)
            .map(|k| [(k & 1) as f64, (k >> 1 & 1) as f64, (k >> 2 & 1) as f64])
            .collect();
        assert!((smallest_ball(&cube).radius2 - 0.75).abs() < 1e-12);
    }
}
