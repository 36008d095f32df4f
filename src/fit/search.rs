//! Local minimisation without derivatives: compass (pattern) search.
//!
//! From `x`, try `x ± step·e_i` along each coordinate and move to the first improvement;
//! when no move improves, halve the step. It needs only function values, so it suits the
//! piecewise-smooth volumes of the fits (a box's extent is a maximum of linear forms), and
//! it stops after `max_evals` evaluations or once the step is below `min_step`.

/// Minimises `f` locally from the origin; returns the best point and its value.
pub(crate) fn compass_search<const N: usize>(
    mut f: impl FnMut([f64; N]) -> f64,
    mut step: f64,
    min_step: f64,
    max_evals: usize,
) -> ([f64; N], f64) {
    let mut x = [0.0; N];
    let mut best = f(x);
    let mut evals = 1;
    while step >= min_step && evals < max_evals {
        let mut improved = false;
        for i in 0..N {
            for sign in [1.0, -1.0] {
                let mut y = x;
                y[i] += sign * step;
                let value = f(y);
                evals += 1;
                if value < best {
                    (x, best, improved) = (y, value, true);
                    break;
                }
            }
        }
        if !improved {
            step *= 0.5;
        }
    }
    (x, best)
}

/// Minimises `f` locally from the origin by the Nelder–Mead simplex method; returns the
/// best point and its value.
///
/// The simplex starts at the origin and `step` along each coordinate. Each iteration
/// reflects the worst vertex through the centroid of the others, expands the reflection
/// when it is the best so far, contracts it toward the centroid when it is no better than
/// the second worst, and shrinks the simplex toward the best vertex when even the
/// contraction fails. Unlike the compass search it moves along diagonals, so it follows
/// the ridges where two terms of a maximum trade off (a capsule's cap against its radius).
/// It stops after `max_evals` evaluations or once the values of the simplex agree within
/// `tolerance` of the best. A NaN value counts as `+∞`, so it never wins (`total_cmp` would
/// put the negative NaN of x86 arithmetic first).
pub(crate) fn nelder_mead<const N: usize>(
    mut f: impl FnMut([f64; N]) -> f64,
    step: f64,
    tolerance: f64,
    max_evals: usize,
) -> ([f64; N], f64) {
    let mut f = |x| {
        let value = f(x);
        if value.is_nan() { f64::INFINITY } else { value }
    };
    let mut points: alloc::vec::Vec<([f64; N], f64)> = (0..=N)
        .map(|i| {
            let mut x = [0.0; N];
            if i > 0 {
                x[i - 1] = step;
            }
            (x, f(x))
        })
        .collect();
    let mut evals = N + 1;
    let along = |from: &[f64; N], to: &[f64; N], t: f64| -> [f64; N] {
        core::array::from_fn(|k| from[k] + t * (to[k] - from[k]))
    };
    while evals < max_evals {
        points.sort_by(|a, b| a.1.total_cmp(&b.1));
        let (best, worst) = (points[0].1, points[N].1);
        if worst - best <= tolerance * best.abs() {
            break;
        }
        // The centroid of all but the worst.
        let centroid: [f64; N] =
            core::array::from_fn(|k| points[..N].iter().map(|p| p.0[k]).sum::<f64>() / N as f64);
        let far = points[N].0;
        let reflected = along(&centroid, &far, -1.0);
        let value = f(reflected);
        evals += 1;
        if value < best {
            let expanded = along(&centroid, &far, -2.0);
            let grown = f(expanded);
            evals += 1;
            points[N] = if grown < value {
                (expanded, grown)
            } else {
                (reflected, value)
            };
        } else if value < points[N - 1].1 {
            points[N] = (reflected, value);
        } else {
            let contracted = along(&centroid, &far, 0.5);
            let value = f(contracted);
            evals += 1;
            if value < worst {
                points[N] = (contracted, value);
            } else {
                let anchor = points[0].0;
                for p in &mut points[1..] {
                    p.0 = along(&anchor, &p.0, 0.5);
                    p.1 = f(p.0);
                }
                evals += N;
            }
        }
    }
    points
        .into_iter()
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .unwrap_or(([0.0; N], f64::INFINITY))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A ridge along the diagonal, its minimum at `(0.5, 0.5)`: no move along one
    /// coordinate improves on the origin, so the compass search stays there, and the simplex
    /// finds the minimum.
    #[test]
    fn the_simplex_follows_a_diagonal_ridge() {
        let ridge = |x: [f64; 2]| 10.0 * (x[0] - x[1]).abs() + (x[0] + x[1] - 1.0).powi(2);
        let (stuck, _) = compass_search(ridge, 0.1, 1e-9, 10_000);
        assert_eq!(stuck, [0.0, 0.0]);
        let (x, value) = nelder_mead(ridge, 0.1, 1e-15, 10_000);
        assert!(value < 1e-9, "{x:?} {value}");
        assert!(
            (x[0] - 0.5).abs() < 1e-4 && (x[1] - 0.5).abs() < 1e-4,
            "{x:?}"
        );
    }

    /// A NaN value, even the negative NaN that `total_cmp` orders first, never wins.
    #[test]
    fn the_simplex_never_returns_nan() {
        let walled = |x: [f64; 2]| {
            if x[0] + x[1] > 0.5 {
                f64::NAN.copysign(-1.0)
            } else {
                (x[0] - 1.0).powi(2) + (x[1] - 1.0).powi(2)
            }
        };
        let (x, value) = nelder_mead(walled, 0.1, 1e-12, 10_000);
        assert!(value.is_finite() && value <= 2.0, "{x:?} {value}");
        assert!(x[0] + x[1] <= 0.5, "{x:?}");
    }
}
