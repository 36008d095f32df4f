//! # bvkit
//!
//! SIMD-tuned bounding-volume kernels: the world-space AABB of a local AABB under a
//! transform, for one box or many, with a measured speed/accuracy trade.
//!
//! ```
//! use bvkit::{Aabb3, Method, Rounding};
//! use glam::{Affine3A, Quat, Vec3, Vec3A};
//!
//! let local = Aabb3::new(Vec3A::splat(-1.0), Vec3A::splat(1.0));
//! let pose = Affine3A::from_rotation_translation(Quat::from_rotation_z(0.3), Vec3::X * 10.0);
//! let world = local.transformed(&pose, Method::SignSelect, Rounding::Outward);
//! for corner in local.corners() {
//!     assert!(world.contains_point(pose.transform_point3a(corner)));
//! }
//! ```
//!
//! ## Methods
//! - [`Method::Naive`]: transform every corner, take min and max (the baseline).
//! - [`Method::AbsMatrix`]: Arvo's center/extent form, `M c + t ± |M| e`.
//! - [`Method::SignSelect`]: per matrix entry, pick the face by the sign of the entry;
//!   for [`Rigid2`] this is Eberly's four-case sign branch.
//!
//! ## The contract
//! - [`Rounding::Outward`] results contain the exact image of the box (exact arithmetic on
//!   the given `f32` inputs) and are tight: each face within twice the method's pad
//!   `k·u·S + TINY_PAD` of the exact face.
//! - [`Rounding::Nearest`] results are plain `f32` arithmetic, each face within
//!   `γ(n)·S + TINY_ERROR` of the exact face.
//! - `S_i = |t_i| + sum_j |m_ij|·max(|min_j|, |max_j|)`; the constants per method are in
//!   [`method`].
//! - Empty boxes map to `EMPTY`; NaN anywhere, or a non-finite matrix, to the invalid
//!   `NAN` box; unbounded faces to the exact unbounded result (a zero entry contributes
//!   exactly 0); finite inputs that overflow to `±inf`, never NaN. Nothing panics.
#![deny(missing_docs)]
#![deny(unsafe_code)]

mod aabb;
mod batch;
mod block;
mod error;
mod extended;
mod fit;
mod kernel;
mod lane;
pub mod method;
mod projective;
mod rigid2;
mod simd;
mod transform;

pub use aabb::{Aabb2, Aabb3};
pub use batch::{
    Aabb3x8, AabbSoa, AabbSoaMut, AabbSoaRef, Affine3Soa, Affine3SoaRef, Affine3x8, Batch,
    BatchError, transform_slice,
};
pub use error::TransformError;
pub use fit::{Capsule, Fit, FitError, Obb3, Sphere};
pub use method::{Method, Rounding};
pub use rigid2::Rigid2;
pub use simd::Backend;

pub use glam;
