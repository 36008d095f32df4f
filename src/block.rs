//! A block of boxes in lanes through a map: the fast kernel for the whole block, and the
//! mask of the lanes whose result stands. The others go to the extended-range path.

use crate::lane::{Lane, Vector};
use crate::method::Method;
use crate::transform::MapKernel;

/// The boxes `[lo, hi]` through `map` on the fast path, with a lane value that says where
/// the result stands: 0 where the box is non-empty with no NaN and the result finite,
/// non-zero (negative or NaN) elsewhere. Those lanes must be recomputed by
/// [`crate::extended`]. One float per lane tests a whole block with a single compare.
///
/// Per axis, `min(0, hi − lo)` is 0 for a non-empty axis and negative or NaN otherwise
/// (the compare-select `min` returns its second operand on NaN), and `(max − min)·0` is 0
/// for finite faces and NaN for an infinite or NaN one (every kernel gives `min <= max`
/// for a non-empty box; a finite box wider than `f32::MAX` also gives NaN and merely takes
/// the extended path). A sum of zeros, negatives and NaN is 0 only if every term is.
#[inline(always)]
pub(crate) fn transform<L: Lane, const N: usize, M: MapKernel<Vector<L, N>>>(
    map: &M,
    lo: Vector<L, N>,
    hi: Vector<L, N>,
    method: Method,
    outward: bool,
) -> (Vector<L, N>, Vector<L, N>, L) {
    let (min, max) = map.transform(lo, hi, method, outward);
    let zero = L::splat(0.0);
    let mut stands = zero;
    for i in 0..N {
        let empty = zero.min(hi.0[i] - lo.0[i]);
        let unbounded = (max.0[i] - min.0[i]) * zero;
        stands = stands + empty + unbounded;
    }
    (min, max, stands)
}
