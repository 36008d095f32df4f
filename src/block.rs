//! A block of boxes in lanes through a map: the fast kernel for the whole block, the
//! extended-range path for each lane outside the fast path's domain.

use crate::extended;
use crate::kernel::{self, AffineLanes};
use crate::lane::{Lane, Vector};
use crate::method::{Method, Rounding};
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
    /// Lane `k` as columns (`cols[j][i] = m_ij`) and translation.
    fn lane(&self, k: usize) -> ([[f32; N]; N], [f32; N]);
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
    fn lane(&self, k: usize) -> ([[f32; N]; N], [f32; N]) {
        (
            self.cols.map(|c| c.0.map(|x| x.get(k))),
            self.t.0.map(|x| x.get(k)),
        )
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
    fn lane(&self, k: usize) -> ([[f32; 2]; 2], [f32; 2]) {
        let (c, s) = (self.cos.get(k), self.sin.get(k));
        ([[c, s], [-s, c]], self.t.map(|x| x.get(k)))
    }
}

/// Bit `k` set where lane `k` stays on the fast path: its box is non-empty with no NaN
/// (`lo <= hi` on every axis) and its result is finite (`x·0` is 0 exactly for finite `x`).
#[inline(always)]
fn fast_lanes<L: LaneArray, const N: usize>(
    lo: &Vector<L, N>,
    hi: &Vector<L, N>,
    min: &Vector<L, N>,
    max: &Vector<L, N>,
) -> u32 {
    let zero = L::splat(0.0);
    (0..N).fold(u32::MAX, |bits, i| {
        let finite = min.0[i] * zero + max.0[i] * zero;
        bits & lo.0[i].le_bits(hi.0[i]) & finite.le_bits(zero)
    })
}

/// The boxes `[lo, hi]` through `map`, with the full contract: the fast kernel, then the
/// extended path for every lane outside its domain.
#[inline(always)]
pub(crate) fn transform<L: LaneArray, const N: usize, M: MapLanes<L, N>>(
    map: &M,
    lo: Vector<L, N>,
    hi: Vector<L, N>,
    method: Method,
    rounding: Rounding,
) -> (Vector<L, N>, Vector<L, N>) {
    let (mut min, mut max) = map.transform(lo, hi, method, rounding == Rounding::Outward);
    let all = u32::MAX >> (32 - L::WIDTH);
    let fast = fast_lanes(&lo, &hi, &min, &max) & all;
    if fast != all {
        redo_lanes(map, &lo, &hi, &mut min, &mut max, !fast & all, rounding);
    }
    (min, max)
}

/// Recomputes the lanes set in `lanes` on the extended-range path.
#[cold]
#[inline(never)]
fn redo_lanes<L: LaneArray, const N: usize, M: MapLanes<L, N>>(
    map: &M,
    lo: &Vector<L, N>,
    hi: &Vector<L, N>,
    min: &mut Vector<L, N>,
    max: &mut Vector<L, N>,
    lanes: u32,
    rounding: Rounding,
) {
    for k in (0..L::WIDTH).filter(|k| lanes >> k & 1 == 1) {
        let (cols, t) = map.lane(k);
        let lane = |v: &Vector<L, N>| v.0.map(|x| x.get(k));
        let (mn, mx) = extended::transform(cols, t, lane(lo), lane(hi), rounding);
        for i in 0..N {
            min.0[i].set(k, mn[i]);
            max.0[i].set(k, mx[i]);
        }
    }
}

/// Lanes `i..i + count` of a block from `f(index)`, zero beyond `count` (a zero box
/// through a zero map stays on the fast path).
#[inline(always)]
pub(crate) fn gather<L: LaneArray>(i: usize, count: usize, f: impl Fn(usize) -> f32) -> L {
    L::from_fn(|k| if k < count { f(i + k) } else { 0.0 })
}

/// All lanes equal to `x`: a map shared by the whole batch.
#[inline(always)]
pub(crate) fn splat<L: LaneArray>(x: f32) -> L {
    <L as Lane>::splat(x)
}
