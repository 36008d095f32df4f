//! The broadphase example's scene and its two pipelines on parry3d's `Bvh`, shared with
//! the broadphase bench, and a peer tree on obvhs's `Bvh2`.

pub mod bvh;
pub mod obvhs;
pub mod scene;
