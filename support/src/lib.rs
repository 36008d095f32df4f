//! What bvkit's tests, benches, examples and fuzz targets share: the exact oracle, the input
//! classes, the meshes, the scenes and the peers. Not published.
// `Dy::cmp` and `Rng::next` were private to the tests that moved here; as public items
// clippy would have them implement `Ord` and `Iterator`, which they do not need.
#![allow(clippy::needless_range_loop, clippy::should_implement_trait)]

#[cfg(feature = "peers")]
pub mod broadphase;
pub mod cases;
pub mod common;
pub mod matrix;
pub mod meshes;
#[cfg(target_arch = "x86_64")]
pub mod mxcsr;
pub mod oracle;
pub mod referee;
pub mod sat;
pub mod timing;
pub mod trimesh;
pub mod volumes;

// The peers, for the benches, examples and tests that compare with them (`peers`).
#[cfg(feature = "peers")]
pub use criterion;
#[cfg(feature = "peers")]
pub use parry3d;
