//! A block of boxes in lanes through a map: the fast kernel for the whole block, and the
//! mask of the lanes whose result stands. The others go to the extended-range path.

use crate::kernel::{self, AffineLanes};
use crate::lane::{Lane, Vector};
use crate::method::Method;
use crate::simd::LaneArray;

/// A map `x ↦ M x + t` per lane, in a form a kernel runs on.
pub(crate) trait MapLanes<L: LaneArray, const N: usize> {
    /// The fast kernel on every lane.
    fn transform(
        &self,
        lo: Vector<L, N>,
        hi: Vector<L, N>,
        method: Method,
        outward: bool,
    ) -> (Vector<L, N>, Vector<L, N>);
}

impl<L: LaneArray, const N: usize> MapLanes<L, N> for AffineLanes<Vector<L, N>, N> {
    #[inline(always)]
    fn transform(
        &self,
        lo: Vector<L, N>,
        hi: Vector<L, N>,
        method: Method,
        outward: bool,
    ) -> (Vector<L, N>, Vector<L, N>) {
        kernel::transform(self, lo, hi, method, outward)
    }
}

/// Rigid 2D maps `[[cos, −sin], [sin, cos]]`, `t` per lane.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Rigid2Lanes<L> {
    pub cos: L,
    pub sin: L,
    pub t: [L; 2],
}

impl<L: LaneArray> MapLanes<L, 2> for Rigid2Lanes<L> {
    #[inline(always)]
    fn transform(
        &self,
        lo: Vector<L, 2>,
        hi: Vector<L, 2>,
        method: Method,
        outward: bool,
    ) -> (Vector<L, 2>, Vector<L, 2>) {
        let (min, max) =
            kernel::transform_rigid2(self.cos, self.sin, self.t, lo.0, hi.0, method, outward);
        (Vector(min), Vector(max))
    }
}

/// The boxes `[lo, hi]` through `map` on the fast path, with a lane value that says where
/// the result stands: 0 where the box is non-empty with no NaN (`hi − lo >= 0` on every
/// axis) and the result finite (`x·0` is exactly 0 for finite `x`), NaN elsewhere. Those
/// lanes must be recomputed by [`crate::extended`]. One float per lane tests a whole block
/// with a single compare.
#[inline(always)]
pub(crate) fn transform<L: LaneArray, const N: usize, M: MapLanes<L, N>>(
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

/// All lanes equal to `x`: a map shared by the whole batch.
#[inline(always)]
pub(crate) fn splat<L: LaneArray>(x: f32) -> L {
    <L as Lane>::splat(x)
}
