//! The broadphase example's scene and its two pipelines on parry3d's `Bvh`, shared with
//! the broadphase bench, a peer tree on obvhs's `Bvh2`, and rapier's own broadphase.

pub mod bvh;
pub mod obvhs;
pub mod rapier;
pub mod scene;
