//! The extended-range path: every box the fast kernels do not answer.
//!
//! It runs in `f64`, where the product of two `f32` values is exact and no sum of four of
//! them can overflow or underflow, so the only error is the rounding of three `f64`
//! additions (`3·2^-53` relative to the magnitude of the terms) and the final rounding
//! to `f32`. It decides the documented values:
//!
//! - NaN anywhere in the input: the NaN box (`is_valid() == false`);
//! - a non-finite matrix entry or translation: the NaN box (no finite image exists);
//! - an empty box (no real point: `min > max`, `min = +inf` or `max = -inf`): `EMPTY`;
//! - an unbounded face: the exact unbounded result, a zero matrix entry contributing 0;
//! - a face beyond the `f32` range: `±inf` for Nearest, the outermost finite or infinite
//!   value that still contains the exact face for Outward; never NaN.

use crate::method::Rounding;

/// Relative bound for the `f64` sum of at most four exact products, with room for the
/// rounding of the pad itself: `8·2^-53`.
const F64_SUM_PAD: f64 = 8.0 / 9_007_199_254_740_992.0;

/// The box `[lo, hi]` through `x ↦ M x + t` in extended range; `cols[j][i] = m_ij`.
#[cold]
#[inline(never)]
pub(crate) fn transform<const N: usize>(
    cols: [[f32; N]; N],
    t: [f32; N],
    lo: [f32; N],
    hi: [f32; N],
    rounding: Rounding,
) -> ([f32; N], [f32; N]) {
    let matrix = cols.iter().flatten().chain(&t);
    let any_nan = matrix.clone().chain(&lo).chain(&hi).any(|x| x.is_nan());
    if any_nan || !matrix.clone().all(|x| x.is_finite()) {
        return ([f32::NAN; N], [f32::NAN; N]);
    }
    let empty =
        (0..N).any(|j| lo[j] > hi[j] || lo[j] == f32::INFINITY || hi[j] == f32::NEG_INFINITY);
    if empty {
        return ([f32::INFINITY; N], [f32::NEG_INFINITY; N]);
    }
    let mut min = [0.0; N];
    let mut max = [0.0; N];
    for i in 0..N {
        let ti = f64::from(t[i]);
        let (mut lo_i, mut hi_i) = (ti, ti);
        // Magnitudes of the terms summed into each face: their f64 rounding error bound.
        let (mut lo_mag, mut hi_mag) = (ti.abs(), ti.abs());
        // Whether every f64 addition was exact: then no pad is needed.
        let mut exact = true;
        for j in 0..N {
            let m = f64::from(cols[j][i]);
            if m == 0.0 {
                continue; // exactly 0, even against an infinite face
            }
            let (a, b) = (m * f64::from(lo[j]), m * f64::from(hi[j]));
            let (low, high) = if a <= b { (a, b) } else { (b, a) };
            exact &= is_exact_sum(lo_i, low) && is_exact_sum(hi_i, high);
            lo_i += low;
            hi_i += high;
            lo_mag += low.abs();
            hi_mag += high.abs();
        }
        // A face has real points on every axis, so no lower term is +inf and no upper
        // term is -inf: the sums are never NaN.
        (min[i], max[i]) = match rounding {
            Rounding::Nearest => (lo_i as f32, hi_i as f32),
            Rounding::Outward if exact => (round_down(lo_i), round_up(hi_i)),
            Rounding::Outward => (
                round_down(lo_i - lo_mag * F64_SUM_PAD),
                round_up(hi_i + hi_mag * F64_SUM_PAD),
            ),
        };
    }
    (min, max)
}

/// True when `a + b` is exact in `f64` (Knuth's TwoSum error term is zero), or infinite.
#[inline]
fn is_exact_sum(a: f64, b: f64) -> bool {
    let s = a + b;
    if !s.is_finite() {
        return true; // an infinite face is exact: no finite term changes it
    }
    let b_virtual = s - a;
    let a_virtual = s - b_virtual;
    (a - a_virtual) + (b - b_virtual) == 0.0
}

/// The largest `f32` not above `x` (`-inf` below the range).
#[inline]
pub(crate) fn round_down(x: f64) -> f32 {
    let y = x as f32;
    if f64::from(y) > x { y.next_down() } else { y }
}

/// The smallest `f32` not below `x` (`+inf` above the range).
#[inline]
pub(crate) fn round_up(x: f64) -> f32 {
    let y = x as f32;
    if f64::from(y) < x { y.next_up() } else { y }
}
