//! The objects a tree is built over: [`TriMesh`] (triangles, boxes derived from vertices)
//! and [`AabbTree`] (bare primitive boxes), each with its [`Bvh`].

use alloc::vec::Vec;
use core::fmt;

use glam::{DVec3, Vec3, Vec3A};

use super::build;
use super::nodes::{Compact, Layout, PRIMITIVE, PrimBox, Ref};
use super::triangle::Soup;
use crate::aabb::Aabb3;

/// Why a mesh or a tree could not be built or refitted.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MeshError {
    /// No triangles (or no boxes) were given.
    Empty,
    /// More primitives than a tree can index (`2^31 − 1`).
    TooMany {
        /// How many were given.
        count: usize,
    },
    /// A triangle refers to a vertex that does not exist.
    IndexOutOfRange {
        /// The triangle.
        triangle: usize,
        /// The index it holds.
        index: u32,
        /// The number of vertices.
        vertices: usize,
    },
    /// A vertex has a NaN or infinite coordinate.
    NonFiniteVertex {
        /// The vertex.
        vertex: usize,
        /// Its coordinates.
        point: [f32; 3],
    },
    /// A box has a NaN or infinite face, or `min > max` on an axis.
    InvalidBox {
        /// The box.
        index: usize,
    },
    /// A refit was given a different number of vertices (or boxes) than the build.
    CountMismatch {
        /// The number the tree was built with.
        expected: usize,
        /// The number given.
        found: usize,
    },
}

impl fmt::Display for MeshError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Self::Empty => write!(f, "no primitives: a tree needs at least one"),
            Self::TooMany { count } => {
                write!(f, "{count} primitives: a tree indexes at most 2^31 - 1")
            }
            Self::IndexOutOfRange {
                triangle,
                index,
                vertices,
            } => write!(
                f,
                "triangle {triangle} refers to vertex {index}, but there are {vertices} vertices"
            ),
            Self::NonFiniteVertex { vertex, point } => {
                write!(f, "vertex {vertex} is not finite: {point:?}")
            }
            Self::InvalidBox { index } => {
                write!(f, "box {index} has a NaN or infinite face, or min > max")
            }
            Self::CountMismatch { expected, found } => write!(
                f,
                "refit with {found} items, but the tree was built over {expected}"
            ),
        }
    }
}

impl core::error::Error for MeshError {}

/// A tree over primitives: the nodes in a [`Layout`], the root and the reach.
#[derive(Clone, Debug)]
pub(crate) struct Bvh<L> {
    pub layout: L,
    pub root: Ref,
    /// Every box of the tree (primitives', and every box as stored) lies within `±reach` on
    /// every axis, to within `2^-52` relative ([`Bvh::measure`]).
    pub reach: f64,
}

impl<L: Layout> Bvh<L> {
    fn new(boxes: &[PrimBox]) -> Self {
        let topology = build::build(boxes);
        let mut h = Bvh {
            layout: build::layout(&topology.children, |i| boxes[i as usize]),
            root: topology.root,
            reach: 0.0,
        };
        h.reach = h.measure(boxes);
        h
    }

    /// The children of every node, read back from the nodes.
    fn children(&self) -> Vec<[Ref; 2]> {
        (0..self.layout.len() as u32)
            .map(|i| self.layout.children(i))
            .collect()
    }

    fn refit(&mut self, boxes: &[PrimBox]) {
        self.layout = build::layout(&self.children(), |i| boxes[i as usize]);
        self.reach = self.measure(boxes);
    }

    /// The largest `|coordinate|` of any box (primitive, or node as stored), in `f64`: finite
    /// for every finite tree (nodes reaching `±f32::MAX` included, whose `f32` read-back may
    /// overflow), within two `f64` roundings (`2^-52` relative) of the exact value, which the
    /// pad's factor `1 + 2^-18` on the reach absorbs ([`super::Relative`]).
    fn measure(&self, boxes: &[PrimBox]) -> f64 {
        let mut reach = self.layout.stored_reach();
        for b in boxes {
            for k in 0..3 {
                reach = reach.max(f64::from(b.min[k]).abs().max(f64::from(b.max[k]).abs()));
            }
        }
        reach
    }

    /// The tree's bytes: the nodes, child references included.
    pub fn node_bytes(&self) -> usize {
        self.layout.bytes()
    }
}

/// `(center, extent)` of the box of three points, one rounding each (the pad's `δ`).
#[inline(always)]
pub(crate) fn triangle_box(p: [Vec3; 3]) -> (Vec3A, Vec3A) {
    let (a, b, c) = (Vec3A::from(p[0]), Vec3A::from(p[1]), Vec3A::from(p[2]));
    let (lo, hi) = (a.min(b).min(c), a.max(b).max(c));
    (lo * 0.5 + hi * 0.5, hi * 0.5 - lo * 0.5)
}

fn count_ok(count: usize) -> Result<(), MeshError> {
    match count {
        0 => Err(MeshError::Empty),
        n if n >= PRIMITIVE as usize => Err(MeshError::TooMany { count: n }),
        _ => Ok(()),
    }
}

fn check_vertices(vertices: &[Vec3]) -> Result<(), MeshError> {
    match vertices.iter().position(|v| !v.is_finite()) {
        Some(vertex) => Err(MeshError::NonFiniteVertex {
            vertex,
            point: vertices[vertex].to_array(),
        }),
        None => Ok(()),
    }
}

/// Every triangle's box (indices checked).
fn prim_boxes(vertices: &[Vec3], triangles: &[[u32; 3]]) -> Vec<PrimBox> {
    triangles
        .iter()
        .map(|t| {
            let p = t.map(|v| vertices[v as usize]);
            PrimBox {
                min: p[0].min(p[1]).min(p[2]).to_array(),
                max: p[0].max(p[1]).max(p[2]).to_array(),
            }
        })
        .collect()
}

/// A triangle mesh in its own frame, with an AABB tree over its triangles.
///
/// Built once (binned SAH, deterministic); queried at any pair of poses without a rebuild
/// ([`TriMesh::query`]). The tree costs at most 32 bytes per triangle ([`Compact`]) or 20
/// ([`super::Quantized`]); the vertices and triangles are the caller's data.
#[derive(Clone, Debug)]
pub struct TriMesh<L: Layout = Compact> {
    vertices: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
    pub(crate) tree: Bvh<L>,
}

impl TriMesh<Compact> {
    /// The mesh and its tree with [`Compact`] nodes. Degenerate triangles are allowed;
    /// no triangles, an index out of range or a non-finite vertex is an error.
    pub fn new(vertices: Vec<Vec3>, triangles: Vec<[u32; 3]>) -> Result<Self, MeshError> {
        Self::build(vertices, triangles)
    }
}

impl<L: Layout> TriMesh<L> {
    /// The mesh and its tree in the layout `L` (as [`TriMesh::new`]).
    pub fn build(vertices: Vec<Vec3>, triangles: Vec<[u32; 3]>) -> Result<Self, MeshError> {
        count_ok(triangles.len())?;
        for (triangle, t) in triangles.iter().enumerate() {
            if let Some(&index) = t.iter().find(|&&i| i as usize >= vertices.len()) {
                return Err(MeshError::IndexOutOfRange {
                    triangle,
                    index,
                    vertices: vertices.len(),
                });
            }
        }
        check_vertices(&vertices)?;
        let tree = Bvh::new(&prim_boxes(&vertices, &triangles));
        Ok(TriMesh {
            vertices,
            triangles,
            tree,
        })
    }

    fn prim_boxes(&self) -> Vec<PrimBox> {
        prim_boxes(&self.vertices, &self.triangles)
    }

    /// The same mesh and tree topology, with nodes in another layout.
    #[must_use]
    pub fn with_layout<M: Layout>(&self) -> TriMesh<M> {
        let boxes = self.prim_boxes();
        TriMesh {
            vertices: self.vertices.clone(),
            triangles: self.triangles.clone(),
            tree: Bvh {
                layout: build::layout(&self.tree.children(), |i| boxes[i as usize]),
                root: self.tree.root,
                reach: 0.0,
            },
        }
        .measured(&boxes)
    }

    fn measured(mut self, boxes: &[PrimBox]) -> Self {
        self.tree.reach = self.tree.measure(boxes);
        self
    }

    /// Moves the vertices and refits every node box, keeping the topology (for deforming
    /// meshes). The count must match, and every vertex be finite.
    pub fn refit(&mut self, vertices: &[Vec3]) -> Result<(), MeshError> {
        if vertices.len() != self.vertices.len() {
            return Err(MeshError::CountMismatch {
                expected: self.vertices.len(),
                found: vertices.len(),
            });
        }
        check_vertices(vertices)?;
        self.vertices.copy_from_slice(vertices);
        let boxes = self.prim_boxes();
        self.tree.refit(&boxes);
        Ok(())
    }

    /// The vertices.
    #[inline]
    #[must_use]
    pub fn vertices(&self) -> &[Vec3] {
        &self.vertices
    }

    /// The triangles, as vertex indices.
    #[inline]
    #[must_use]
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// The vertices of triangle `i`, if it exists.
    #[inline]
    #[must_use]
    pub fn triangle(&self, i: u32) -> Option<[Vec3; 3]> {
        let t = self.triangles.get(i as usize)?;
        Some(t.map(|v| self.vertices[v as usize]))
    }

    /// The vertices of triangle `i`, an id the tree holds (so it exists, and its indices
    /// were checked at the build).
    #[inline(always)]
    pub(crate) fn corners(&self, i: u32) -> [Vec3; 3] {
        self.soup().corners(i)
    }

    /// The vertices and triangles, as a batch of triangle tests reads them.
    #[inline(always)]
    pub(crate) fn soup(&self) -> Soup<'_> {
        Soup {
            vertices: &self.vertices,
            triangles: &self.triangles,
        }
    }

    /// The bytes of the tree's nodes (vertices and triangles not included).
    #[must_use]
    pub fn tree_bytes(&self) -> usize {
        self.tree.node_bytes()
    }

    /// Every box of the tree lies within `±reach()` on every axis (in `f64`, so finite for
    /// every finite tree; within `2^-52` relative of the exact bound).
    #[must_use]
    pub fn reach(&self) -> f64 {
        self.tree.reach
    }

    /// Triangle `i`'s vertices in `f64` (exact).
    #[inline(always)]
    pub(crate) fn triangle_f64(&self, i: u32) -> [DVec3; 3] {
        self.corners(i).map(|v| v.as_dvec3())
    }
}

/// An AABB tree over bare primitive boxes: leaf pairs whose boxes overlap at two poses.
#[derive(Clone, Debug)]
pub struct AabbTree<L: Layout = Compact> {
    boxes: Vec<Aabb3>,
    pub(crate) tree: Bvh<L>,
}

fn to_prims(boxes: &[Aabb3]) -> Result<Vec<PrimBox>, MeshError> {
    boxes
        .iter()
        .enumerate()
        .map(|(index, b)| {
            let finite = b.min.is_finite() && b.max.is_finite();
            if !finite || b.min.cmpgt(b.max).any() {
                return Err(MeshError::InvalidBox { index });
            }
            Ok(PrimBox {
                min: b.min.to_array(),
                max: b.max.to_array(),
            })
        })
        .collect()
}

impl AabbTree<Compact> {
    /// A tree with [`Compact`] nodes over `boxes` (finite, `min <= max`, at least one).
    pub fn new(boxes: &[Aabb3]) -> Result<Self, MeshError> {
        Self::build(boxes)
    }
}

impl<L: Layout> AabbTree<L> {
    /// A tree in the layout `L` over `boxes` (as [`AabbTree::new`]).
    pub fn build(boxes: &[Aabb3]) -> Result<Self, MeshError> {
        count_ok(boxes.len())?;
        let prims = to_prims(boxes)?;
        Ok(AabbTree {
            boxes: boxes.to_vec(),
            tree: Bvh::new(&prims),
        })
    }

    /// Replaces the boxes (same count) and refits every node.
    pub fn refit(&mut self, boxes: &[Aabb3]) -> Result<(), MeshError> {
        if boxes.len() != self.boxes.len() {
            return Err(MeshError::CountMismatch {
                expected: self.boxes.len(),
                found: boxes.len(),
            });
        }
        let prims = to_prims(boxes)?;
        self.boxes.copy_from_slice(boxes);
        self.tree.refit(&prims);
        Ok(())
    }

    /// The primitive boxes.
    #[inline]
    #[must_use]
    pub fn boxes(&self) -> &[Aabb3] {
        &self.boxes
    }

    /// The bytes of the tree's nodes (the primitive boxes not included).
    #[must_use]
    pub fn tree_bytes(&self) -> usize {
        self.tree.node_bytes()
    }

    /// Every box of the tree lies within `±reach()` on every axis (in `f64`, so finite for
    /// every finite tree; within `2^-52` relative of the exact bound).
    #[must_use]
    pub fn reach(&self) -> f64 {
        self.tree.reach
    }
}
