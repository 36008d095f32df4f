//! Single-box transforms: the public entry points for one box at a time.
//!
//! Every entry point runs the chosen kernel on the fast path (finite, non-empty box; the
//! result is checked finite) and hands every other box to the extended-range path, which
//! gives the documented value: `EMPTY` for an empty box, the NaN box for NaN input or a
//! non-finite map, exact unbounded faces for unbounded boxes, `±inf` (never NaN) when
//! finite inputs overflow.

use glam::{Affine3A, Mat4, Vec2, Vec3A};

use crate::aabb::{Aabb2, Aabb3};
use crate::error::TransformError;
use crate::extended;
use crate::fields::MAX_FIELDS;
use crate::kernel::{self, MapKernel};
use crate::lane::Vector;
use crate::method::{Method, Rounding};
use crate::transform::{Class, Rigid2, Transform2, Transform3};

/// True where glam's `Vec3A` is a SIMD register; elsewhere the scalar path is used.
const GLAM_SIMD: bool = cfg!(any(
    target_feature = "sse2",
    all(target_arch = "aarch64", target_feature = "neon"),
    target_feature = "simd128"
));

/// The box `[lo, hi]` through `xf` on the scalar path: the class's lanes with one lane.
#[inline(always)]
fn transform_scalar<const N: usize, T: Class<N>>(
    xf: &T,
    lo: [f32; N],
    hi: [f32; N],
    method: Method,
    rounding: Rounding,
) -> ([f32; N], [f32; N]) {
    let fields: [f32; MAX_FIELDS] = xf.to_fields();
    let map = T::lanes::<f32>(&fields);
    let outward = rounding == Rounding::Outward;
    match kernel::transform_checked(&map, Vector(lo), Vector(hi), method, outward) {
        (min, max, 0.0) => (min.0, max.0),
        _ => extended::transform(&xf.extended(), lo, hi, rounding),
    }
}

impl Aabb3 {
    /// The box through `xf`, any 3D [transform class](crate::Transform3), by `method`,
    /// with the guarantee `rounding` gives.
    ///
    /// - [`Rounding::Outward`]: contains the exact image of every real point of `self`;
    ///   each face within `2·(k·u·S_i + τ·TINY_PAD)` of the exact face, `k` being
    ///   [`Transform3::nearest_order`]`(method) + 2`.
    /// - [`Rounding::Nearest`]: each face within `γ(n)·S_i + τ·TINY_ERROR` of the exact
    ///   face, `n` being [`Transform3::nearest_order`]`(method)`.
    ///
    /// For an affine map `S_i = |t_i| + sum_j |m_ij|·max(|min_j|, |max_j|)` and `τ = 1`;
    /// the other classes are listed on [`Transform3`]. Empty in gives [`Aabb3::EMPTY`];
    /// NaN anywhere, or a non-finite map, gives [`Aabb3::NAN`]. Runs on glam's SIMD
    /// `Vec3A` where it has one, else on [`Aabb3::transformed_scalar`].
    #[inline(always)]
    #[must_use]
    pub fn transformed<T: Transform3>(&self, xf: &T, method: Method, rounding: Rounding) -> Aabb3 {
        if !GLAM_SIMD {
            return self.transformed_scalar(xf, method, rounding);
        }
        let outward = rounding == Rounding::Outward;
        let (mut min, mut max) = xf.simd().transform(self.min, self.max, method, outward);
        // One mask, one branch. The input is non-empty and NaN-free (`min <= max`), and
        // the result finite: every kernel gives `min <= max` for such input, so
        // `max − min <= f32::MAX` fails exactly when a face is infinite or NaN (or, rarely,
        // when the finite box is wider than `f32::MAX`, which the extended path handles).
        let ok = (max - min).cmple(Vec3A::splat(f32::MAX)) & self.min.cmple(self.max);
        if !ok.all() {
            // Assigned rather than returned, so the fast path keeps its faces in registers.
            Aabb3 { min, max } = self.transformed_extended(xf, rounding);
        }
        Aabb3 { min, max }
    }

    /// [`Aabb3::transformed`] computed in plain `f32`, one component at a time: the
    /// scalar reference every SIMD path is tested against. Same contract. A test hook, not
    /// part of the documented surface.
    #[doc(hidden)]
    #[inline]
    #[must_use]
    pub fn transformed_scalar<T: Transform3>(
        &self,
        xf: &T,
        method: Method,
        rounding: Rounding,
    ) -> Aabb3 {
        let (lo, hi) = (self.min.to_array(), self.max.to_array());
        let (min, max) = transform_scalar(xf, lo, hi, method, rounding);
        Aabb3::new(Vec3A::from_array(min), Vec3A::from_array(max))
    }

    #[cold]
    fn transformed_extended<T: Transform3>(&self, xf: &T, rounding: Rounding) -> Aabb3 {
        let (lo, hi) = (self.min.to_array(), self.max.to_array());
        let (min, max) = extended::transform(&xf.extended(), lo, hi, rounding);
        Aabb3::new(Vec3A::from_array(min), Vec3A::from_array(max))
    }

    /// [`Aabb3::transformed`] by an affine `Mat4`.
    ///
    /// # Errors
    /// [`TransformError::NonFiniteMatrix`] when an entry is NaN or infinite, and
    /// [`TransformError::NotAffine`] when the last row is not `(0, 0, 0, 1)`; use
    /// [`Aabb3::transformed_projective`] for projective matrices.
    #[inline]
    pub fn try_transformed_mat4(
        &self,
        m: &Mat4,
        method: Method,
        rounding: Rounding,
    ) -> Result<Aabb3, TransformError> {
        if !m.is_finite() {
            return Err(TransformError::NonFiniteMatrix);
        }
        let last_row = m.row(3).to_array();
        if last_row != [0.0, 0.0, 0.0, 1.0] {
            return Err(TransformError::NotAffine { last_row });
        }
        Ok(self.transformed(&Affine3A::from_mat4(*m), method, rounding))
    }
}

impl Aabb2 {
    /// The box through `xf`, any 2D [transform class](crate::Transform2), by `method`,
    /// with the guarantee `rounding` gives.
    ///
    /// The bounds of [`Aabb3::transformed`] with `dims = 2` and the order `n` of
    /// [`Transform2::nearest_order`]. glam's `Vec2` has no SIMD form, so this is the
    /// scalar path.
    #[inline]
    #[must_use]
    pub fn transformed<T: Transform2>(&self, xf: &T, method: Method, rounding: Rounding) -> Aabb2 {
        let (lo, hi) = (self.min.to_array(), self.max.to_array());
        let (min, max) = transform_scalar(xf, lo, hi, method, rounding);
        Aabb2::new(Vec2::from_array(min), Vec2::from_array(max))
    }

    /// The box through a rigid transform: [`Aabb2::transformed`] on a [`Rigid2`], where
    /// [`Method::SignSelect`] is Eberly's four-case sign branch on `(cos >= 0, sin >= 0)`:
    /// 8 multiplications, 8 additions, 2 comparisons. A test hook (the same as
    /// [`Aabb2::transformed`]), not part of the documented surface.
    #[doc(hidden)]
    #[inline]
    #[must_use]
    pub fn transformed_rigid(&self, xf: &Rigid2, method: Method, rounding: Rounding) -> Aabb2 {
        self.transformed(xf, method, rounding)
    }
}
