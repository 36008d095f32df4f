//! Local-frame AABB trees: two objects tested at any relative pose, with `|R|` and one
//! error pad computed once per query and reused at every node pair.
//!
//! Each object keeps a tree built once in its own frame ([`TriMesh`] over triangles,
//! [`AabbTree`] over bare boxes); nothing is rebuilt when an object moves. A [`Query`]
//! between `A` at `pa` and `B` at `pb` computes the relative pose ([`Relative`]) once and
//! descends both trees together: a node pair costs its centers and extents only, tested on
//! 6 axes (`A`'s box in `B`'s frame and `B`'s in `A`'s), the roots on all 15.
//!
//! ```
//! use bvkit::tree::TriMesh;
//! use bvkit::Rigid3;
//! use glam::{Quat, Vec3, Vec3A};
//!
//! let tetra = |s: f32| {
//!     let v = vec![Vec3::ZERO, Vec3::X * s, Vec3::Y * s, Vec3::Z * s];
//!     TriMesh::new(v, vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
//! };
//! let (a, b) = (tetra(1.0)?, tetra(1.0)?);
//! let pb = Rigid3::new(Quat::from_rotation_z(0.5), Vec3A::new(0.25, 0.25, 0.25));
//! assert!(a.intersects(Rigid3::IDENTITY, &b, pb)?);
//! let far = Rigid3::new(Quat::IDENTITY, Vec3A::X * 3.0);
//! assert!(!a.intersects(Rigid3::IDENTITY, &b, far)?);
//! // A pose that places nothing is an error, never "no contact".
//! let nan = Rigid3::new(Quat::IDENTITY, Vec3A::splat(f32::NAN));
//! assert!(a.intersects(Rigid3::IDENTITY, &b, nan).is_err());
//! # Ok::<(), Box<dyn core::error::Error>>(())
//! ```
//!
//! **Guarantees.** Box culling is conservative by proof (the pad's derivation is in
//! [`Relative`]); the leaf triangle test is exact ([`triangles_intersect`]), so
//! [`Query::intersects`] and [`Query::overlapping_triangles`] are exact for the geometry
//! [`Relative`] defines. A bad mesh is a [`MeshError`], a bad pose or tolerance a
//! [`QueryError`]; nothing panics, and no query answers "no contact" for input it cannot
//! decide. Meshes are accepted for every finite vertex, `±f32::MAX` included: the reach is
//! kept in `f64`, and past `2^126` the pad is infinite (nothing is culled, the exact leaf
//! test decides).

mod build;
mod mesh;
mod nodes;
mod query;
mod relative;
mod triangle;

pub use mesh::{AabbTree, MeshError, TriMesh};
pub use nodes::{Compact, Layout, Paired, Quantized};
pub use query::{Query, Shape, Stats};
pub use relative::{Object, QueryError, Relative};
pub use triangle::{triangles_distance_sq, triangles_intersect};
