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
