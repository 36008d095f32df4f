//! A block of boxes in lanes through a map: the fast kernel for the whole block, and the
//! mask of the lanes whose result stands. The others go to the extended-range path.

use crate::lane::{Lane, Vector};
use crate::method::Method;
use crate::transform::MapKernel;

/// The boxes `[lo, hi]` through `map` on the fast path, with a lane value that says where
/// the result stands: 0 where the box is non-empty with no NaN (`hi − lo >= 0` on every
/// axis) and the result finite (`x·0` is exactly 0 for finite `x`), NaN elsewhere. Those
/// lanes must be recomputed by [`crate::extended`]. One float per lane tests a whole block
/// with a single compare.
#[inline(always)]
pub(crate) fn transform<L: Lane, const N: usize, M: MapKernel<Vector<L, N>>>(
    map: &M,
    lo: Vector<L, N>,
    hi: Vector<L, N>,
    method: Method,
    outward: bool,
) -> (Vector<L, N>, Vector<L, N>, L) {
    let (min, max) = map.transform(lo, hi, method, outward);
    let (zero, nan) = (L::splat(0.0), L::splat(f32::NAN));
    let mut stands = zero;
    for i in 0..N {
        let finite = min.0[i] * zero + max.0[i] * zero;
        stands = stands + (hi.0[i] - lo.0[i]).select_nonneg(finite, nan);
    }
    (min, max, stands)
}
