//! Fat boxes: a tight box grown by a margin and rounded outward, the test that a tight
//! box still lies inside one, and the set of objects whose fat box an update rewrote
//! (`moved`).

mod moved;

pub use moved::Moved;

use crate::aabb::{Aabb2, Aabb3};
use crate::lane::{Lane, Vector};
use crate::num::pow2;
use glam::Vec3A;

/// How much a fat box exceeds the tight box it was made from, per axis:
/// `max(absolute, relative × half-extent)`, in world units.
///
/// A larger margin rewrites fewer fat boxes per frame and makes the broadphase report more
/// pairs; Box2D uses an absolute margin of 0.1 m, Jolt and rapier a fraction of the size.
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "bytemuck", derive(bytemuck::Pod, bytemuck::Zeroable))]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C)]
pub struct Margin {
    /// The least growth of every face, in world units.
    pub absolute: f32,
    /// The growth as a fraction of the tight box's half-extent on the same axis.
    pub relative: f32,
}

impl Margin {
    /// No growth: the fat box is the tight box, rounded outward.
    pub const ZERO: Self = Self::new(0.0, 0.0);

    /// A margin of `max(absolute, relative × half-extent)` per axis.
    #[must_use]
    pub const fn new(absolute: f32, relative: f32) -> Self {
        Self { absolute, relative }
    }

    /// True when both fields are finite and non-negative (otherwise the broadphase refuses
    /// the margin with [`crate::BatchError::InvalidMargin`]).
    pub(crate) fn is_valid(self) -> bool {
        let ok = |x: f32| x.is_finite() && x >= 0.0;
        ok(self.absolute) && ok(self.relative)
    }

    /// The fat box of the tight boxes `[min, max]`, in lanes.
    ///
    /// The growth is `g = max(absolute, relative·h)` with `h = max/2 − min/2` (no overflow
    /// for finite faces; a NaN product, `0·inf`, gives `absolute`, since the compare-select
    /// `max` returns its second operand). The faces `x = min − g` and `y = max + g` are
    /// rounded to nearest, then moved out by `s = min(|x|·2^-22, MAX)`, which proves
    /// `RN(x − s) <= min − g` exactly:
    /// - if `x` is subnormal or zero, `min − g` was exact and `RN(x − s) <= x`;
    /// - if `x` is normal, `min − g >= x − u|x|` (`u = 2^-24`), and `s >= 4u|x| − 2^-150`
    ///   (the product may be subnormal), so `RN(x − s) <= x − s + u|x − s|`
    ///   `<= x − 3u|x| + 2^-150 + 5u²|x| < x − u|x|` since `|x| >= 2^-126`;
    /// - `x = −inf` stays; `x = +inf` (an empty axis) stays, since `inf − MAX = inf`.
    ///
    /// So the fat box contains the exact `[min − g, max + g]`, and each face lies within
    /// `7u·|face| + 2^-149` of it (`u|x|` for the first rounding, `4u|x|` for the step,
    /// `u|x − s|` for the second rounding). A NaN face stays NaN: an invalid tight box gives an
    /// invalid fat box.
    #[inline(always)]
    pub(crate) fn grow<L: Lane, const N: usize>(
        self,
        min: Vector<L, N>,
        max: Vector<L, N>,
    ) -> (Vector<L, N>, Vector<L, N>) {
        let splat = Vector::<L, N>::splat;
        let half = max * splat(0.5) - min * splat(0.5);
        let g = (half * splat(self.relative)).max(splat(self.absolute));
        let (x, y) = (min - g, max + g);
        (x - step(x), y + step(y))
    }
}

/// The outward step of [`Margin::grow`] at faces `v`: `min(|v|·2^-22, MAX)`. A function,
/// not a closure: a closure is not inlined into the dispatcher's target features, and was
/// called out of line, its lane operations with it.
#[inline(always)]
fn step<L: Lane, const N: usize>(v: Vector<L, N>) -> Vector<L, N> {
    let splat = Vector::<L, N>::splat;
    (v.abs() * splat(pow2(-22) as f32)).min(splat(f32::MAX))
}

/// Lane value 0 where the tight boxes `[min, max]` lie inside the fat boxes, nonzero
/// where they leave them or a fat face is NaN. For finite tight faces only: a difference
/// of a finite face and any fat face has the sign of the comparison (`±inf` included),
/// and NaN where a fat face is NaN.
#[inline(always)]
pub(crate) fn outside<L: Lane, const N: usize>(
    min: Vector<L, N>,
    max: Vector<L, N>,
    fat_min: Vector<L, N>,
    fat_max: Vector<L, N>,
) -> L {
    let (zero, one) = (L::splat(0.0), L::splat(1.0));
    let mut out = zero;
    for a in 0..N {
        out = out
            + (min.0[a] - fat_min.0[a]).select_nonneg(zero, one)
            + (fat_max.0[a] - max.0[a]).select_nonneg(zero, one);
    }
    out
}

/// True when the box `[min, max]` lies inside `[fat_min, fat_max]`, for any faces: an
/// empty box lies inside every valid box, and nothing lies inside or around a NaN.
#[inline]
pub(crate) fn inside<const N: usize>(
    [min, max]: [[f32; N]; 2],
    [fat_min, fat_max]: [[f32; N]; 2],
) -> bool {
    (0..N).all(|a| fat_min[a] <= min[a] && max[a] <= fat_max[a])
}

/// [`inside`] on glam's `Vec3A`: two compares and one mask (false for a NaN face).
#[inline(always)]
pub(crate) fn inside_aabb3(tight: &Aabb3, fat: &Aabb3) -> bool {
    (fat.min.cmple(tight.min) & tight.max.cmple(fat.max)).all()
}

impl Aabb3 {
    /// The fat box of this tight box: grown by `margin` on every axis and rounded outward,
    /// so that it contains the exact grown box (see [`Batch::update`](crate::Batch::update)).
    /// A margin that [`Batch::update`](crate::Batch::update) refuses (a field negative,
    /// infinite or NaN) gives [`Aabb3::NAN`], whose `is_valid()` is false.
    #[inline]
    #[must_use]
    pub fn fattened(&self, margin: Margin) -> Aabb3 {
        if !margin.is_valid() {
            return Aabb3::NAN;
        }
        // On `Vec3A` lanes: per axis the same operations, so the same bits, as in any lanes.
        let (min, max) = margin.grow::<Vec3A, 1>(Vector([self.min]), Vector([self.max]));
        Aabb3::new(min.0[0], max.0[0])
    }
}

impl Aabb2 {
    /// The fat box of this tight box: grown by `margin` on every axis and rounded outward.
    /// A margin that [`Batch::update`](crate::Batch::update) refuses gives [`Aabb2::NAN`].
    #[must_use]
    pub fn fattened(&self, margin: Margin) -> Aabb2 {
        if !margin.is_valid() {
            return Aabb2::NAN;
        }
        let (min, max) =
            margin.grow::<f32, 2>(Vector(self.min.to_array()), Vector(self.max.to_array()));
        Aabb2::new(min.0.into(), max.0.into())
    }
}
