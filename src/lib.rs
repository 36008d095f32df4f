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
//! # Which call to make
//!
//! Three choices, in this order. The figures are ns per box on one AVX2 core (the
//! criterion run of `docs/speed.md`, 1K boxes in cache); `cargo run --release --example
//! trade` measures every combination on your machine in under two minutes.
//!
//! ## 1. The transform class: what your poses hold
//!
//! Pick the narrowest class that holds your poses: each has its own kernel and moves only
//! its own bytes (AoSoA, box read + pose read + box written).
//!
//! | your poses hold | class | bytes per box |
//! |---|---|---:|
//! | a position only (particles, spheres) | [`Translation3`], [`Translation2`] | 60 |
//! | a rotation and a position (rigid bodies) | [`Rigid3`], [`Rigid2`] | 76 |
//! | …and a uniform scale | [`Similarity3`] | 80 |
//! | …and a per-axis scale (bevy's `Transform`) | [`Trs3`] | 88 |
//! | any affine map (shear, skinning) | `glam::Affine3A`, `glam::Affine2`; a `Mat4` through [`Aabb3::try_transformed_mat4`] | 96 |
//!
//! ## 2. The rounding, then the method: must the box contain?
//!
//! - **It must contain** (a broadphase, culling, continuous collision: anything a box too
//!   small would make miss): [`Rounding::Outward`]. The result provably contains the exact
//!   image of the box. In cache it costs more than Nearest; once memory bound the two cost
//!   the same (`docs/speed.md` and `docs/trade.md` measure both, per CPU).
//! - **A few ulps are fine** (debug drawing, level of detail, sorting): [`Rounding::Nearest`],
//!   each face within `γ(n)·S` of the exact face, on either side.
//! - **The method**: [`Method::AbsMatrix`] on AoSoA blocks, the fastest kernel there for
//!   every 3D class and both roundings in the trade report; [`Method::SignSelect`] in 2D,
//!   and for one box or slices of the scaled and affine classes, where it measured fastest
//!   with Outward and its pad is two `u·S` narrower; [`Method::Naive`] only as the baseline.
//!
//! ## 3. The layout: how your data is stored
//!
//! [`Batch::transform`] takes every layout through one entry point; only the speed differs.
//! The lane layouts (AoSoA blocks and columns) are the fastest; `docs/speed.md` measures
//! every layout on the CPU it names.
//!
//! | you hold | pass |
//! |---|---|
//! | one box and its pose | [`Aabb3::transformed`] |
//! | `Vec<Aabb3>` and `Vec<Rigid3>` | `&local`, `&poses` |
//! | AoSoA blocks of eight ([`Aabb3x8`], [`Rigid3x8`]) | `&local8`, `&poses8` |
//! | columns ([`AabbSoa`], [`Rigid3Soa`]) | `&local`, `&poses` |
//! | one pose for many boxes | `&pose` |
//!
//! A broadphase calls [`Batch::update`] instead: the same kernels, and only the fat boxes
//! whose object left them are rewritten.
//!
//! ## Features
//!
//! - `std` (default): run-time CPU detection. Without it the crate is `no_std` (with
//!   `alloc`), takes its float functions from libm, and runs the backends the build's
//!   target features guarantee (`-C target-cpu=…`), never fusing the batch lanes.
//! - `rayon`: `Batch::transform_par` and `Batch::update_par`, bit-identical to
//!   [`Batch::transform`] and [`Batch::update`] on the same backend; the broadphase tree's
//!   `update_par`, `report_par` and `cast_rays_par`, the same results in the same order on
//!   any number of threads.
//! - `serde`: `Serialize`/`Deserialize` on the boxes, the transform classes, [`Obb3`],
//!   [`Sphere`], [`Capsule`], [`LargeRigid3`], [`Margin`], [`Method`], [`Rounding`],
//!   [`Fit`] and [`Backend`].
//! - `bytemuck`: `Pod` on the AoSoA blocks, [`Aabb2`], [`Translation2`], [`Rigid2`] and
//!   [`Margin`]; `AnyBitPattern` (read from bytes) on the types holding a `Vec3A`, whose
//!   fourth lane glam does not promise is initialised.
//! - `bevy`: `From`/`Into` between [`Aabb3`], [`Aabb2`] and bevy_math 0.19's
//!   `bounding::Aabb3d`, `Aabb2d`, and between [`Rigid3`], [`Rigid2`] and its `Isometry3d`,
//!   `Isometry2d` (bevy 0.19 and avian 0.7 use glam 0.32: the floats are copied bit for bit).
//!   A NaN or inverted bevy box converts as it is and is refused where bvkit refuses any bad
//!   box.
//!
//! # The crate
//!
//! ## Transform classes
//! Model only what the scene requires: every entry point takes any class of
//! [`Transform3`], each with the cheapest kernel that is exact for it and its own bytes per
//! box: [`Translation3`] (spheres, particles: 12 bytes), [`Rigid3`] (quaternion +
//! position: 28), [`Similarity3`] (plus a uniform scale: 32), [`Trs3`] (bevy's
//! `Transform`: 40) and `glam::Affine3A` (48 useful bytes); in 2D [`Translation2`],
//! [`Rigid2`] and `glam::Affine2`.
//!
//! ```
//! use bvkit::{Aabb3, Batch, Method, Rigid3, Rounding};
//! use glam::{Quat, Vec3, Vec3A};
//!
//! let local = vec![Aabb3::new(Vec3A::splat(-1.0), Vec3A::splat(1.0)); 64];
//! let poses: Vec<Rigid3> = (0..64)
//!     .map(|k| (Quat::from_rotation_y(k as f32), Vec3::X * k as f32).into())
//!     .collect();
//! let mut world = vec![Aabb3::EMPTY; 64];
//! // One generic entry point: any box layout, any transform class, any transform layout.
//! Batch::new(Method::AbsMatrix, Rounding::Outward).transform(&local, &poses, &mut world)?;
//! let pose = glam::Affine3A::from(poses[3]);
//! assert!(local[3].corners().iter().all(|&c| world[3].contains_point(pose.transform_point3a(c))));
//! # Ok::<(), bvkit::BatchError>(())
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
//!   [`Method`].
//! - Empty boxes map to `EMPTY`; NaN anywhere, or a non-finite matrix, to the invalid
//!   `NAN` box; unbounded faces to the exact unbounded result (a zero entry contributes
//!   exactly 0); finite inputs that overflow to `±inf`, never NaN. No kernel panics,
//!   whatever the input (the element accessors [`Soa::get`], [`Block8::get`] and
//!   [`Block8::set`] panic on an index out of range, as slice indexing does).
//!
//! ## Broadphase
//! [`Batch::update`] rewrites only the fat boxes whose object left them and
//! returns the [`Moved`] set, over [`Active`] subsets, with [`Swept`] pose pairs and
//! large-world poses (`f64` positions, boxes relative to an `f64` origin, proven to contain
//! the exact image). Both verbs take the same [`PoseSource`], so [`Batch::transform`] also
//! gives swept boxes and large-world boxes outright.
//!
//! ## Trees
//! [`tree`] keeps an AABB tree per object in its own frame ([`tree::TriMesh`],
//! [`tree::AabbTree`]) and tests two objects at any pair of poses with one simultaneous
//! descent: the relative pose, `|R|` and one derived error pad are computed once per query,
//! and no node pair that truly overlaps is culled. The leaf triangle test is exact.
#![no_std]
#![deny(missing_docs)]
#![deny(unsafe_code)]
// The public traits (`Transform3`, `BoxSource`, …) are sealed: their machinery (lane types,
// kernels) is crate-private by design and reachable only through the sealed supertraits.
#![allow(private_interfaces, private_bounds)]

extern crate alloc;
#[cfg(feature = "std")]
extern crate std;

mod aabb;
mod batch;
// From/Into with bevy_math's boxes and isometries (feature `bevy`).
#[cfg(feature = "bevy")]
mod bevy;
// The broadphase's dynamic tree, fed by the moved set (issue 47).
pub mod broadphase;
mod engine;
mod error;
mod extended;
mod fat;
mod fields;
mod fit;
mod kernel;
mod lane;
mod layout;
mod method;
mod num;
mod projective;
mod simd;
mod single;
mod transform;
// Local-frame AABB trees (issue 11).
pub mod tree;

pub use aabb::{Aabb2, Aabb3};
pub use batch::{Batch, LargePose, LargeRigid3, LargeWorld, Swept};
pub use engine::{Active, PoseSource};
pub use error::{BatchError, TransformError};
pub use fat::{Margin, Moved};
pub use fit::{BoundingVolume, Capsule, Fit, FitError, Obb3, Sphere};
pub use layout::{
    Aabb2Soa, Aabb2SoaMut, Aabb2SoaRef, Aabb2x8, Aabb3x8, AabbSoa, AabbSoaMut, AabbSoaRef,
    Affine2x8, Affine3Soa, Affine3SoaRef, Affine3x8, Block8, BoxSink, BoxSource, Rigid2x8,
    Rigid3Soa, Rigid3SoaRef, Rigid3x8, Similarity3x8, Soa, SoaMut, SoaRef, TransformSource,
    Translation2x8, Translation3x8, Trs3x8,
};
pub use method::{Method, Rounding, TINY_ERROR, TINY_PAD, UNIT_ROUNDOFF, gamma};
pub use simd::Backend;
pub use transform::{
    Rigid2, Rigid3, Similarity3, Transform2, Transform3, Translation2, Translation3, Trs3,
};

pub use glam;

// Every Rust block of the README and of the guide is compiled and run as a doctest.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;

#[cfg(doctest)]
#[doc = include_str!("../docs/guide.md")]
struct GuideDoctests;
