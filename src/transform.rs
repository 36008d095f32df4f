//! Single-box transforms: the public entry points for one box at a time.
//!
//! Every entry point runs the chosen kernel on the fast path (finite, non-empty box; the
//! result is checked finite) and hands every other box to the extended-range path, which
//! gives the documented value: `EMPTY` for an empty box, the NaN box for NaN input or a
//! non-finite matrix, exact unbounded faces for unbounded boxes, `±inf` (never NaN) when
//! finite inputs overflow.

use glam::{Affine2, Affine3A, Mat4, Vec2, Vec3A};

use crate::aabb::{Aabb2, Aabb3};
use crate::block::{self, Rigid2Lanes};
use crate::error::TransformError;
use crate::extended;
use crate::kernel::{self, AffineLanes};
use crate::lane::Vector;
use crate::method::{Method, Rounding};
use crate::rigid2::Rigid2;

/// True where glam's `Vec3A` is a SIMD register; elsewhere the scalar path is used.
const GLAM_SIMD: bool = cfg!(any(
    target_feature = "sse2",
    all(target_arch = "aarch64", target_feature = "neon"),
    target_feature = "simd128"
));

/// The box `[lo, hi]` through `x ↦ M x + t` on the scalar path (`cols[j][i] = m_ij`).
#[inline(always)]
fn transform_scalar<const N: usize>(
    cols: [[f32; N]; N],
    t: [f32; N],
    lo: [f32; N],
    hi: [f32; N],
    method: Method,
    rounding: Rounding,
) -> ([f32; N], [f32; N]) {
    let a = AffineLanes {
        cols: cols.map(Vector),
        t: Vector(t),
    };
    let outward = rounding == Rounding::Outward;
    match block::transform::<f32, N, _>(&a, Vector(lo), Vector(hi), method, outward) {
        (min, max, 0.0) => (min.0, max.0),
        _ => extended::transform(cols, t, lo, hi, rounding),
    }
}

fn affine3_cols(xf: &Affine3A) -> [[f32; 3]; 3] {
    [
        xf.matrix3.x_axis.to_array(),
        xf.matrix3.y_axis.to_array(),
        xf.matrix3.z_axis.to_array(),
    ]
}

impl Aabb3 {
    /// The box through `xf` by `method`, with the guarantee `rounding` gives.
    ///
    /// - [`Rounding::Outward`]: contains the exact image of every real point of `self`;
    ///   each face within `2·(k·u·S_i + TINY_PAD)` of the exact face, `k` being
    ///   [`Method::outward_pad`]`(3)`.
    /// - [`Rounding::Nearest`]: each face within `γ(n)·S_i + TINY_ERROR` of the exact face,
    ///   `n` being [`Method::nearest_gamma`]`(3)`.
    ///
    /// `S_i = |t_i| + sum_j |m_ij|·max(|min_j|, |max_j|)`; see [`crate::method`].
    /// Empty in gives [`Aabb3::EMPTY`]; NaN anywhere, or a non-finite matrix, gives
    /// [`Aabb3::NAN`]. Runs on glam's SIMD `Vec3A` where it has one, else on
    /// [`Aabb3::transformed_scalar`].
    #[inline]
    #[must_use]
    pub fn transformed(&self, xf: &Affine3A, method: Method, rounding: Rounding) -> Aabb3 {
        if !GLAM_SIMD {
            return self.transformed_scalar(xf, method, rounding);
        }
        let m = &xf.matrix3;
        let a = AffineLanes {
            cols: [m.x_axis, m.y_axis, m.z_axis],
            t: xf.translation,
        };
        let outward = rounding == Rounding::Outward;
        let (min, max) = kernel::transform(&a, self.min, self.max, method, outward);
        // One mask, one branch: non-empty, NaN-free input, and a finite result (`x·0` is
        // 0 for finite `x`, NaN for `±inf` and NaN).
        let finite = (min * 0.0 + max * 0.0).cmpeq(Vec3A::ZERO);
        if (self.min.cmple(self.max) & finite).all() {
            Aabb3 { min, max }
        } else {
            self.transformed_extended(xf, rounding)
        }
    }

    /// [`Aabb3::transformed`] computed in plain `f32`, one component at a time: the
    /// scalar reference every SIMD path is tested against. Same contract.
    #[inline]
    #[must_use]
    pub fn transformed_scalar(&self, xf: &Affine3A, method: Method, rounding: Rounding) -> Aabb3 {
        let (min, max) = transform_scalar(
            affine3_cols(xf),
            xf.translation.to_array(),
            self.min.to_array(),
            self.max.to_array(),
            method,
            rounding,
        );
        Aabb3::new(Vec3A::from_array(min), Vec3A::from_array(max))
    }

    #[cold]
    fn transformed_extended(&self, xf: &Affine3A, rounding: Rounding) -> Aabb3 {
        let (min, max) = extended::transform(
            affine3_cols(xf),
            xf.translation.to_array(),
            self.min.to_array(),
            self.max.to_array(),
            rounding,
        );
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

fn rigid2_cols(xf: &Rigid2) -> [[f32; 2]; 2] {
    [[xf.cos, xf.sin], [-xf.sin, xf.cos]]
}

fn affine2_cols(xf: &Affine2) -> [[f32; 2]; 2] {
    [xf.matrix2.x_axis.to_array(), xf.matrix2.y_axis.to_array()]
}

impl Aabb2 {
    /// The box through `xf` by `method`, with the guarantee `rounding` gives.
    ///
    /// The bounds of [`Aabb3::transformed`] with `dims = 2`: Nearest within
    /// `γ(n)·S_i + TINY_ERROR`, Outward containing the exact image and within
    /// `2·(k·u·S_i + TINY_PAD)`. glam's `Vec2` has no SIMD form, so this is the scalar path.
    #[inline]
    #[must_use]
    pub fn transformed(&self, xf: &Affine2, method: Method, rounding: Rounding) -> Aabb2 {
        let (min, max) = transform_scalar(
            affine2_cols(xf),
            xf.translation.to_array(),
            self.min.to_array(),
            self.max.to_array(),
            method,
            rounding,
        );
        Aabb2::new(Vec2::from_array(min), Vec2::from_array(max))
    }

    /// The box through a rigid transform. [`Method::SignSelect`] is Eberly's four-case
    /// sign branch on `(cos >= 0, sin >= 0)`: 8 multiplications, 8 additions, 2 comparisons.
    ///
    /// Bounds as [`Aabb2::transformed`] for the matrix `[[cos, -sin], [sin, cos]]`.
    #[inline]
    #[must_use]
    pub fn transformed_rigid(&self, xf: &Rigid2, method: Method, rounding: Rounding) -> Aabb2 {
        let map = Rigid2Lanes {
            cos: xf.cos,
            sin: xf.sin,
            t: xf.translation.to_array(),
        };
        let (lo, hi) = (self.min.to_array(), self.max.to_array());
        let outward = rounding == Rounding::Outward;
        let (min, max) = match block::transform(&map, Vector(lo), Vector(hi), method, outward) {
            (min, max, 0.0) => (min.0, max.0),
            _ => extended::transform(rigid2_cols(xf), map.t, lo, hi, rounding),
        };
        Aabb2::new(Vec2::from_array(min), Vec2::from_array(max))
    }
}
