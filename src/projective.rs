//! Projective transforms: boxes through a general `Mat4` with the divide by `w`.
//!
//! When `w > 0` at every corner, `w` (affine in the point) is positive on the whole box,
//! the perspective map is continuous there and maps segments to segments, so the image
//! is the convex hull of the projected corners and its bounding box is the box of the
//! corners. Each corner is evaluated in `f64` interval arithmetic (exact products, the
//! sums' rounding bounded), so the result is Outward: it contains the exact image.

use glam::{Mat4, Vec3A};

use crate::aabb::Aabb3;
use crate::error::TransformError;
use crate::num::{round_down, round_up};

/// Bound on the rounding of a sum of four exact `f64` products, relative to the sum of
/// their magnitudes: `3·2^-53`, rounded up to `4·2^-53`.
const F64_DOT_ERROR: f64 = 4.0 / 9_007_199_254_740_992.0;

/// An interval `[lo, hi]` holding the exact dot product of `row` and `p`.
fn dot_interval(row: [f64; 4], p: [f64; 4]) -> (f64, f64) {
    let mut sum = 0.0;
    let mut magnitude = 0.0;
    for k in 0..4 {
        let term = row[k] * p[k]; // exact: two f32 significands fit in 53 bits
        sum += term;
        magnitude += term.abs();
    }
    let error = magnitude * F64_DOT_ERROR;
    ((sum - error).next_down(), (sum + error).next_up())
}

impl Aabb3 {
    /// The box through the projective map `p ↦ (M p)_xyz / (M p)_w`, always Outward.
    ///
    /// The result contains the exact image of every real point of the box and is at most
    /// a few `f64` ulps wider before the final rounding to `f32`. Empty in gives
    /// [`Aabb3::EMPTY`], NaN in the box gives [`Aabb3::NAN`].
    ///
    /// # Errors
    /// [`TransformError::NonFiniteMatrix`] for a NaN or infinite entry,
    /// [`TransformError::UnboundedProjective`] for a box with an infinite face, and
    /// [`TransformError::NonPositiveW`] when a corner's `w` is not provably positive.
    pub fn transformed_projective(&self, m: &Mat4) -> Result<Aabb3, TransformError> {
        if !m.is_finite() {
            return Err(TransformError::NonFiniteMatrix);
        }
        if !self.is_valid() {
            return Ok(Aabb3::NAN);
        }
        if self.is_empty() {
            return Ok(Aabb3::EMPTY);
        }
        if !(self.min.is_finite() && self.max.is_finite()) {
            return Err(TransformError::UnboundedProjective);
        }
        let rows: [[f64; 4]; 4] = core::array::from_fn(|i| m.row(i).to_array().map(f64::from));
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for (corner, c) in self.corners().into_iter().enumerate() {
            let p = [c.x, c.y, c.z, 1.0].map(f64::from);
            let (w_lo, w_hi) = dot_interval(rows[3], p);
            if w_lo <= 0.0 {
                let w = (w_lo * 0.5 + w_hi * 0.5) as f32;
                return Err(TransformError::NonPositiveW { corner, w });
            }
            for i in 0..3 {
                let (n_lo, n_hi) = dot_interval(rows[i], p);
                // n / w over positive w: the smallest quotient divides by the largest w
                // when n >= 0, by the smallest when n < 0 (and the mirror for the largest).
                let q_lo = (n_lo / if n_lo >= 0.0 { w_hi } else { w_lo }).next_down();
                let q_hi = (n_hi / if n_hi >= 0.0 { w_lo } else { w_hi }).next_up();
                lo[i] = lo[i].min(q_lo);
                hi[i] = hi[i].max(q_hi);
            }
        }
        Ok(Aabb3::new(
            Vec3A::from_array(lo.map(round_down)),
            Vec3A::from_array(hi.map(round_up)),
        ))
    }
}
