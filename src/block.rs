//! A block of boxes in lanes through a map: the fast kernel for the whole block, and the
//! mask of the lanes whose result stands. The others go to the extended-range path.

use crate::kernel::MapKernel;
use crate::lane::{Lane, Vector};
use crate::method::Method;

/// The boxes `[lo, hi]` through `map` on the fast path, with a lane value that says where
/// the result stands: 0 where the box is non-empty with no NaN and the result finite,
/// NaN elsewhere. Those lanes must be recomputed by
/// [`crate::extended`]. One float per lane tests a whole block with a single compare.
///
/// Per axis: `(hi − lo).select_nonneg(0, NaN)` is 0 for a non-empty axis (an overflowing
/// `hi − lo = +inf` included) and NaN for an empty or NaN one, and `(max − min)·0` is 0
/// for finite faces and NaN for an infinite or NaN one (every kernel gives `min <= max`
/// for a non-empty box; a finite box wider than `f32::MAX` also gives NaN and takes the
/// extended path, as on the single-box path, so that both agree bit for bit).
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
        let empty = (hi.0[i] - lo.0[i]).select_nonneg(zero, nan);
        let unbounded = (max.0[i] - min.0[i]) * zero;
        stands = stands + empty + unbounded;
    }
    (min, max, stands)
}
