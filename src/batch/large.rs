//! Large worlds: poses with an `f64` translation, boxes relative to an `f64` origin (see
//! [`LargePose`]).

use crate::num::{pow2, round_up, two_sum};
use glam::{Affine3A, DAffine3, DVec3, Quat, Vec3A};

use crate::aabb::Aabb3;
use crate::method::{Method, Rounding};
use crate::transform::Rigid3;

/// A rigid pose for large worlds: an `f32` rotation and an `f64` position, `x ↦ R(q)·x + p`.
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "bytemuck", derive(bytemuck::AnyBitPattern))]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C)]
pub struct LargeRigid3 {
    /// The rotation; the exact map uses `R(q)` as [`Rigid3`] does, with no normalisation.
    pub rotation: Quat,
    /// The position, in world units.
    pub position: DVec3,
}

impl LargeRigid3 {
    /// A pose from a rotation and a position.
    #[must_use]
    pub const fn new(rotation: Quat, position: DVec3) -> Self {
        Self { rotation, position }
    }
}

/// A pose with an `f64` translation: [`LargeRigid3`] and glam's `DAffine3`.
///
/// Engines that keep positions in `f64` (Jolt's double build, Box2D's large-world build,
/// Unreal) add the position to the local box in `f64` with round-to-nearest and only then
/// round to `f32` outward, so the double rounding can leave the box. Here nothing is
/// rounded to nearest on the way: the rotated box comes from the `f32` Outward kernel, and
/// every `f64` step is exact (an error-free sum) before one directed rounding to `f32`.
///
/// **Bound.** Per face, the result exceeds the exact face by at most twice the Outward pad
/// of the rotation (`(n + 2)·u·S + τ·TINY_PAD` with `S` the local magnitude, see
/// [`crate::Transform3`]), plus one `f32` ulp of `t − origin` and two of the face; for
/// `DAffine3`, plus `2u·Σ_j |m_ij|·max(|lo_j|, |hi_j|)` for the rounding of the matrix to
/// `f32`. At `10^12` from an origin near the object that is a few ulps of the local size,
/// where an `f32` world position would be off by `2^16`.
pub trait LargePose: sealed::Sealed + Copy + Send + Sync {
    /// The box of `pose(x) − origin` over the points `x` of `local`, in `f32`, rounded
    /// outward: it contains the exact image (see the [trait docs](LargePose) for the bound).
    /// An empty box gives `EMPTY`; NaN anywhere, or an infinity in the pose or the origin,
    /// gives a box whose `is_valid()` is false; an unbounded local box gives the unbounded
    /// result.
    fn relative_aabb(&self, local: &Aabb3, origin: DVec3, method: Method) -> Aabb3;
}

mod sealed {
    pub trait Sealed {}
    impl Sealed for super::LargeRigid3 {}
    impl Sealed for glam::DAffine3 {}
}

impl LargePose for LargeRigid3 {
    fn relative_aabb(&self, local: &Aabb3, origin: DVec3, method: Method) -> Aabb3 {
        let rotation = Rigid3::new(self.rotation, Vec3A::ZERO);
        let rotated = local.transformed(&rotation, method, Rounding::Outward);
        offset(rotated, self.position, origin, DVec3::ZERO)
    }
}

impl LargePose for DAffine3 {
    /// The matrix is rounded to `f32`, `M = M_f + Δ` with `Δ` exact in `f64`; the box
    /// through `M_f` comes from the Outward kernel and is widened by
    /// `w_i >= Σ_j |Δ_ij|·max(|lo_j|, |hi_j|)`, which bounds `Δ·x` for every `x` of the box
    /// (the proof is beside `residual`). A matrix entry beyond `f32::MAX` gives the whole
    /// space.
    fn relative_aabb(&self, local: &Aabb3, origin: DVec3, method: Method) -> Aabb3 {
        let m = self.matrix3;
        if !local.is_valid() || !m.is_finite() {
            return Aabb3::NAN;
        }
        let linear = m.as_mat3();
        if !linear.is_finite() {
            return offset(
                Aabb3::new(Vec3A::NEG_INFINITY, Vec3A::INFINITY),
                self.translation,
                origin,
                DVec3::ZERO,
            );
        }
        let rounded = Affine3A::from_mat3(linear);
        let box_f = local.transformed(&rounded, method, Rounding::Outward);
        let reach = local.min.abs().max(local.max.abs()).as_dvec3();
        let residual = |i: usize| residual(m.row(i), linear.row(i).as_dvec3(), reach);
        let widen = DVec3::new(residual(0), residual(1), residual(2));
        offset(box_f, self.translation, origin, widen)
    }
}

/// An upper bound of `Σ_j |Δ_j|·r_j`, `Δ = row − rounded` (exact in `f64`: `rounded` is
/// `row` rounded to `f32`), for `r >= 0`.
///
/// A term with `Δ_j = 0` or `r_j = 0` is exactly 0, even where the other factor is infinite.
/// Otherwise the product is rounded to nearest: with a normal result its relative error is
/// at most `2^-53`, but it may underflow (a `Δ_j` below the `f32` range, times a tiny
/// `r_j`) and lose everything, so each term is at least `f64::MIN_POSITIVE`, which exceeds
/// any product that rounds below it. The sum of three normal terms is rounded twice, so
/// `(1 + 2^-53)^3 < 1 + 2^-50` covers the three roundings.
fn residual(row: DVec3, rounded: DVec3, r: DVec3) -> f64 {
    (0..3)
        .map(|j| {
            let delta = row[j] - rounded[j];
            if delta == 0.0 || r[j] == 0.0 {
                0.0
            } else {
                (delta.abs() * r[j]).max(f64::MIN_POSITIVE)
            }
        })
        .sum::<f64>()
        * (1.0 + pow2(-50))
}

/// `b + (t − origin)` widened by `widen` on every face, rounded outward: every step exact
/// in `f64`, then one directed rounding to `f32` per face.
fn offset(b: Aabb3, t: DVec3, origin: DVec3, widen: DVec3) -> Aabb3 {
    if !(b.is_valid() && t.is_finite() && origin.is_finite()) || widen.is_nan() {
        return Aabb3::NAN;
    }
    if b.is_empty() {
        return Aabb3::EMPTY;
    }
    let face = |i: usize| {
        let (d_lo, d_hi) = difference(t[i], origin[i]);
        let w = round_up(widen[i]);
        let lo = add_down(add_down(b.min[i], -w), d_lo);
        let hi = add_up(add_up(b.max[i], w), d_hi);
        (lo, hi)
    };
    let [x, y, z] = [0, 1, 2].map(face);
    Aabb3::new(Vec3A::new(x.0, y.0, z.0), Vec3A::new(x.1, y.1, z.1))
}

/// `f32` bounds `lo <= t − o <= hi` of the exact difference of two finite `f64`s.
fn difference(t: f64, o: f64) -> (f32, f32) {
    let (s, e) = two_sum(t, -o);
    if s.is_infinite() {
        // The exact difference overflowed `f64`, so it is beyond `f32::MAX` too.
        return if s > 0.0 {
            (f32::MAX, f32::INFINITY)
        } else {
            (f32::NEG_INFINITY, f32::MIN)
        };
    }
    enclose(s, e)
}

/// `f32` bounds of the exact value `s + e`, where `s` is the rounded `f64` sum and `e` its
/// exact error (`|e| <= ulp(s)/2`).
///
/// `f = RN_f32(s)`, and `f − s` is exact in `f64` (Sterbenz: `f` is within a factor 2 of
/// `s`, or zero), so `f <= s + e` is decided exactly by `f − s <= e`; where it fails,
/// the next `f32` below is below `s + e`, since `|f − (s + e)| < ulp_f32`. Overflow to
/// `±inf` is handled by the same comparisons (`next_down(inf) = MAX`).
fn enclose(s: f64, e: f64) -> (f32, f32) {
    let f = s as f32;
    let d = f64::from(f) - s;
    let lo = if d <= e { f } else { f.next_down() };
    let hi = if d >= e { f } else { f.next_up() };
    (lo, hi)
}

/// The largest `f32` at or below the exact `a + b` (an infinite operand gives itself).
fn add_down(a: f32, b: f32) -> f32 {
    let (a, b) = (f64::from(a), f64::from(b));
    let s = a + b;
    if s.is_finite() {
        enclose(s, two_sum(a, b).1).0
    } else {
        s as f32
    }
}

/// The smallest `f32` at or above the exact `a + b`.
fn add_up(a: f32, b: f32) -> f32 {
    -add_down(-a, -b)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn directed_sums_bracket_the_exact_sum() {
        // 1 + 2^-30 is not an f32: the sum rounds to 1, up to the next f32 above.
        let tiny = crate::num::pow2(-30) as f32;
        assert_eq!(add_down(1.0, tiny), 1.0);
        assert_eq!(add_up(1.0, tiny), 1.0f32.next_up());
        assert_eq!(add_down(1.0, -tiny), 1.0f32.next_down());
        assert_eq!(add_up(2.0, 3.0), 5.0);
        assert_eq!(add_down(f32::MAX, f32::MAX), f32::MAX);
        assert_eq!(add_up(f32::MAX, f32::MAX), f32::INFINITY);
        assert_eq!(add_down(f32::NEG_INFINITY, 1.0), f32::NEG_INFINITY);
    }

    #[test]
    fn residual_bounds_a_product_that_underflows() {
        // Δ = 1e-300 (the entry rounds to 0 in `f32`) times r = 2^-149: the product is
        // below the `f64` range, but it is not 0.
        let tiny = DVec3::new(1e-300, 0.0, 0.0);
        let r = DVec3::splat(f64::from(f32::from_bits(1)));
        let w = residual(tiny, DVec3::ZERO, r);
        assert!(w > 0.0 && round_up(w) > 0.0, "{w}");
        // An exact entry or a zero reach adds nothing, even beside an infinity.
        let r = DVec3::new(f64::INFINITY, 0.0, 1.0);
        assert_eq!(
            residual(DVec3::new(1.0, 1e-300, 2.0), DVec3::new(1.0, 0.0, 2.0), r),
            0.0
        );
    }

    #[test]
    fn differences_bracket_the_exact_difference() {
        // 1e12 + 0.3 - 1e12: 0.3 is not an f64 near 1e12, but t − o is exact in f64 here,
        // and rounds to f32 around it.
        let (t, o) = (1e12 + 0.25, 1e12);
        assert_eq!(difference(t, o), (0.25, 0.25));
        let (lo, hi) = difference(0.1, 0.0);
        assert!(f64::from(lo) < 0.1 && 0.1 < f64::from(hi) && lo.next_up() == hi);
        assert_eq!(difference(1e300, -1e300), (f32::MAX, f32::INFINITY));
        assert_eq!(difference(f64::MAX, -f64::MAX), (f32::MAX, f32::INFINITY));
    }
}
