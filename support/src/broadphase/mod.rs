//! The broadphase example's scene and its two pipelines on parry3d's `Bvh`, shared with
//! the broadphase bench.

pub mod bvh;
pub mod scene;
