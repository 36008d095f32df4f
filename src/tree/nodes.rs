//! Node layouts: [`Compact`] (32 bytes per node), [`Quantized`] (20 bytes per node) and
//! [`Paired`] (32 bytes per node).
//!
//! All are "no-leaf" trees (Opcode's layout): a tree over `n` primitives has `n − 1` inner
//! nodes with two child references each, and a child is either another node or a
//! primitive. A compact or quantized node holds its own box, and primitive boxes are not
//! stored: a mesh derives them from its triangles at query time. A paired node holds its
//! two children's boxes instead, primitives' included, and the root's box is kept apart. So
//! a tree costs `32·(n − 1)`, `20·(n − 1)` or `32·(n − 1) + 24` bytes, under 32, 20 and 32
//! bytes per primitive.
//!
//! **Containment.** Every stored box contains, as an exact statement about real numbers,
//! the union of its primitives' boxes: a compact node (and a paired tree's root) stores
//! `center ± extent` with the extent rounded up past the exact distance to both faces
//! ([`outward`]); a quantized box (a quantized node's, or a paired node's child's) is
//! integers whose exact box `origin + step·(c ± e)` is checked to contain the exact one
//! ([`Quantized::quantize`]). Reading a box back rounds at most once per coordinate
//! (`origin + step·c`); the query pad covers that rounding.

use crate::num::{ceil, pow2, pow2_at_least, round, round_up, two_sum};
use alloc::vec::Vec;
use glam::{DVec3, Vec3A};

/// A primitive's box, exact `f32` faces.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PrimBox {
    pub min: [f32; 3],
    pub max: [f32; 3],
}

impl PrimBox {
    pub(crate) const EMPTY: PrimBox = PrimBox {
        min: [f32::INFINITY; 3],
        max: [f32::NEG_INFINITY; 3],
    };

    #[inline]
    pub(crate) fn union(&self, o: &PrimBox) -> PrimBox {
        PrimBox {
            min: core::array::from_fn(|k| self.min[k].min(o.min[k])),
            max: core::array::from_fn(|k| self.max[k].max(o.max[k])),
        }
    }
}

/// A child: a node index, or a primitive id with the top bit set.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Ref(pub u32);

/// The top bit of a [`Ref`]: set for a primitive.
pub(crate) const PRIMITIVE: u32 = 1 << 31;

impl Ref {
    #[inline(always)]
    pub(crate) fn node(index: u32) -> Self {
        Ref(index)
    }
    #[inline(always)]
    pub(crate) fn primitive(id: u32) -> Self {
        Ref(id | PRIMITIVE)
    }
    #[inline(always)]
    pub(crate) fn is_primitive(self) -> bool {
        self.0 & PRIMITIVE != 0
    }
    #[inline(always)]
    pub(crate) fn index(self) -> u32 {
        self.0 & !PRIMITIVE
    }
}

/// A compact node: `center ± extent` and two children (32 bytes).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct CompactNode {
    pub center: [f32; 3],
    pub extent: [f32; 3],
    pub children: [Ref; 2],
}

/// A quantized node: `origin + step·(center ± extent)` and two children (20 bytes).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct QNode {
    pub center: [i16; 3],
    pub extent: [u16; 3],
    pub children: [Ref; 2],
}

/// The smallest `f32` at least the exact distance `hi − lo` (`lo <= hi`, both finite).
///
/// TwoSum in `f64` gives the distance exactly as `d + err` (a difference of two `f32` values
/// cannot overflow `f64`). `round_up(d)` covers it unless it equals `d` and `err > 0`, when
/// the next `f32` does: an `f32` above `d` is at least one `f64` spacing above it, and
/// `|err|` is at most half of one.
fn distance_up(lo: f32, hi: f32) -> f32 {
    let (d, err) = two_sum(f64::from(hi), -f64::from(lo));
    let up = round_up(d);
    if f64::from(up) == d && err > 0.0 {
        up.next_up()
    } else {
        up
    }
}

/// `center ± extent` containing `[min, max]` exactly: the center is `min/2 + max/2` in
/// `f32` (so it lies in `[min, max]`), and the extent the smallest `f32` at least the exact
/// distance to the farther face ([`distance_up`]). That distance is at most
/// `max(|min|, |max|) <= f32::MAX`, so the extent is finite for every finite box: a box
/// reaching `±f32::MAX` is stored as it is, not as an infinite one.
pub(crate) fn outward(min: [f32; 3], max: [f32; 3]) -> ([f32; 3], [f32; 3]) {
    let mut center = [0.0; 3];
    let mut extent = [0.0; 3];
    for k in 0..3 {
        let c = min[k] * 0.5 + max[k] * 0.5;
        center[k] = c;
        extent[k] = distance_up(c, max[k]).max(distance_up(min[k], c));
    }
    (center, extent)
}

/// How a tree stores its inner nodes: [`Compact`] or [`Quantized`].
pub trait Layout: NodeAccess + Clone + core::fmt::Debug {}

/// The crate-private access every layout gives the builder and the queries.
pub(crate) trait NodeAccess {
    /// The layout over `children`, whose node `i` has the exact box `[min[i], max[i]]` and
    /// primitive `p` the exact box `prim(p)`.
    fn from_boxes(
        children: &[[Ref; 2]],
        min: &[[f32; 3]],
        max: &[[f32; 3]],
        prim: impl Fn(u32) -> PrimBox,
    ) -> Self;
    /// The two children of node `i` with their boxes `(center, extent)` as the queries read
    /// them; a primitive's box from `prim` where the layout does not store it.
    fn children_boxes(&self, i: u32, prim: impl Fn(u32) -> (Vec3A, Vec3A)) -> [ChildBox; 2];
    /// The box of the tree's root `root`, as the queries read it (`prim` as above).
    fn root_box(&self, root: Ref, prim: impl Fn(u32) -> (Vec3A, Vec3A)) -> (Vec3A, Vec3A);
    /// The largest `|coordinate|` of any box the layout stores, in `f64`: finite for every
    /// finite tree (the `f32` read-back of a quantized box may overflow where this does
    /// not), within two `f64` roundings of the exact value.
    fn stored_reach(&self) -> f64;
    /// The children of node `i`.
    fn children(&self, i: u32) -> [Ref; 2];
    /// The number of nodes.
    fn len(&self) -> usize;
    /// The bytes the layout stores: its nodes, and what it keeps beside them.
    fn bytes(&self) -> usize;
    /// True when the layout stores primitives' boxes (on its grid, so a little larger than
    /// the primitives' own).
    const STORES_PRIMITIVES: bool = false;
}

/// A child as the descent reads it: its reference and its box `center ± extent`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct ChildBox {
    pub r: Ref,
    pub center: Vec3A,
    pub extent: Vec3A,
}

/// The box of `r` in a layout where every node stores its own box (`node`), and
/// primitives' boxes come from `prim`.
#[inline(always)]
fn own_box(
    r: Ref,
    node: impl Fn(u32) -> (Vec3A, Vec3A),
    prim: impl Fn(u32) -> (Vec3A, Vec3A),
) -> (Vec3A, Vec3A) {
    if r.is_primitive() {
        prim(r.index())
    } else {
        node(r.index())
    }
}

/// The children of a node, and their boxes, in a layout where every node stores its own
/// box (as [`own_box`]).
#[inline(always)]
fn own_boxes(
    children: [Ref; 2],
    node: impl Fn(u32) -> (Vec3A, Vec3A),
    prim: impl Fn(u32) -> (Vec3A, Vec3A),
) -> [ChildBox; 2] {
    let child = |r: Ref| {
        let (center, extent) = own_box(r, &node, &prim);
        ChildBox { r, center, extent }
    };
    [child(children[0]), child(children[1])]
}

/// The largest `|c| + e` of `boxes`, in `f64`.
fn reach_of(boxes: impl Iterator<Item = (DVec3, DVec3)>) -> f64 {
    boxes.fold(0.0f64, |reach, (c, e)| {
        reach.max((c.abs() + e).max_element())
    })
}

/// Nodes of 32 bytes: an `f32` center and extent, two child references.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Compact {
    nodes: Vec<CompactNode>,
}

impl Layout for Compact {}

impl Compact {
    #[inline(always)]
    fn node_box(&self, i: u32) -> (Vec3A, Vec3A) {
        let n = &self.nodes[i as usize];
        (Vec3A::from_array(n.center), Vec3A::from_array(n.extent))
    }
}

impl NodeAccess for Compact {
    fn from_boxes(
        children: &[[Ref; 2]],
        min: &[[f32; 3]],
        max: &[[f32; 3]],
        _prim: impl Fn(u32) -> PrimBox,
    ) -> Self {
        let nodes = children
            .iter()
            .zip(min.iter().zip(max))
            .map(|(&children, (&lo, &hi))| {
                let (center, extent) = outward(lo, hi);
                CompactNode {
                    center,
                    extent,
                    children,
                }
            })
            .collect();
        Compact { nodes }
    }
    #[inline(always)]
    fn children_boxes(&self, i: u32, prim: impl Fn(u32) -> (Vec3A, Vec3A)) -> [ChildBox; 2] {
        own_boxes(self.children(i), |j| self.node_box(j), prim)
    }
    #[inline(always)]
    fn root_box(&self, root: Ref, prim: impl Fn(u32) -> (Vec3A, Vec3A)) -> (Vec3A, Vec3A) {
        own_box(root, |j| self.node_box(j), prim)
    }
    fn stored_reach(&self) -> f64 {
        reach_of((0..self.nodes.len() as u32).map(|i| {
            let (c, e) = self.node_box(i);
            (c.as_dvec3(), e.as_dvec3())
        }))
    }
    #[inline(always)]
    fn children(&self, i: u32) -> [Ref; 2] {
        self.nodes[i as usize].children
    }
    fn len(&self) -> usize {
        self.nodes.len()
    }
    fn bytes(&self) -> usize {
        self.nodes.len() * core::mem::size_of::<CompactNode>()
    }
}

/// Nodes of 20 bytes: 16-bit integer centers and extents on a per-tree grid (a power-of-two
/// step from an `f32` origin), rounded outward at build time, two child references.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Quantized {
    nodes: Vec<QNode>,
    origin: Vec3A,
    step: Vec3A,
}

impl Layout for Quantized {}

/// The largest grid coordinate used: `|c| + e` stays below `i16::MAX` with room for the
/// outward steps.
const GRID: f64 = 32_000.0;

impl Quantized {
    /// The grid of a tree whose root box is `[lo, hi]`: the origin its `f32` center, the
    /// step the smallest power of two with `extent / step <= GRID` that is also at least
    /// `2^-20·|origin|` (so that the `f64` error of the checks below, a few `2^-53·|origin|`,
    /// is far below one step) and at least `2^-126` (normal).
    fn grid(lo: [f32; 3], hi: [f32; 3]) -> (Vec3A, Vec3A) {
        let mut origin = [0.0f32; 3];
        let mut step = [0.0f32; 3];
        for k in 0..3 {
            let o = lo[k] * 0.5 + hi[k] * 0.5;
            let extent = (f64::from(hi[k]) - f64::from(o)).max(f64::from(o) - f64::from(lo[k]));
            let need = (extent / GRID)
                .max(f64::from(o).abs() * pow2(-20))
                .max(pow2(-126));
            // A power of two (exact in f32: at most 2^128 · 2^-15 for finite input).
            let s = pow2_at_least(need);
            origin[k] = o;
            step[k] = s as f32;
        }
        (Vec3A::from_array(origin), Vec3A::from_array(step))
    }

    /// One node on the grid: `c = round((center − origin)/step)`, and `e` the smallest
    /// number of steps past the farther face, plus one step that absorbs the `f64` rounding
    /// of the distances (each within a few `2^-53·(|origin| + extent)`, far below a step by
    /// the choice of the step). `origin + step·c` is exact in `f64` as a real number only
    /// up to that rounding, which the extra step covers.
    fn quantize(origin: Vec3A, step: Vec3A, lo: [f32; 3], hi: [f32; 3]) -> ([i16; 3], [u16; 3]) {
        let mut c = [0i16; 3];
        let mut e = [0u16; 3];
        for k in 0..3 {
            let (o, s) = (f64::from(origin[k]), f64::from(step[k]));
            let (l, h) = (f64::from(lo[k]), f64::from(hi[k]));
            let mid = (l * 0.5 + h * 0.5 - o) / s;
            let ck = round(mid).clamp(-GRID, GRID);
            let center = o + ck * s;
            let reach = ceil(((h - center).max(center - l) / s).max(0.0)) + 1.0;
            c[k] = ck as i16;
            e[k] = reach.min(f64::from(u16::MAX)) as u16;
        }
        (c, e)
    }
}

impl Quantized {
    #[inline(always)]
    fn node_box(&self, i: u32) -> (Vec3A, Vec3A) {
        let n = &self.nodes[i as usize];
        grid_box(self.origin, self.step, n.center, n.extent)
    }

    /// The grid of `from_boxes`: the root's box is node 0's.
    fn grid_of(min: &[[f32; 3]], max: &[[f32; 3]]) -> (Vec3A, Vec3A) {
        match (min.first(), max.first()) {
            (Some(&lo), Some(&hi)) => Self::grid(lo, hi),
            _ => (Vec3A::ZERO, Vec3A::ONE),
        }
    }
}

/// A grid box read back: `step·c` and `step·e` are exact (a power of two times a 16-bit
/// integer); the sum rounds once (relative u), which the query pad's box-rounding term
/// covers.
#[inline(always)]
fn grid_box(origin: Vec3A, step: Vec3A, c: [i16; 3], e: [u16; 3]) -> (Vec3A, Vec3A) {
    let c = Vec3A::new(f32::from(c[0]), f32::from(c[1]), f32::from(c[2]));
    let e = Vec3A::new(f32::from(e[0]), f32::from(e[1]), f32::from(e[2]));
    (origin + step * c, step * e)
}

/// A grid box in `f64`: `step·c` and `step·e` exact (at most 2^113 · 2^16), the sum
/// rounded once.
fn grid_box_f64(origin: Vec3A, step: Vec3A, c: [i16; 3], e: [u16; 3]) -> (DVec3, DVec3) {
    let c = DVec3::from_array(c.map(f64::from));
    let e = DVec3::from_array(e.map(f64::from));
    let step = step.as_dvec3();
    (origin.as_dvec3() + step * c, step * e)
}

impl NodeAccess for Quantized {
    fn from_boxes(
        children: &[[Ref; 2]],
        min: &[[f32; 3]],
        max: &[[f32; 3]],
        _prim: impl Fn(u32) -> PrimBox,
    ) -> Self {
        let (origin, step) = Self::grid_of(min, max);
        let nodes = children
            .iter()
            .zip(min.iter().zip(max))
            .map(|(&children, (&lo, &hi))| {
                let (center, extent) = Self::quantize(origin, step, lo, hi);
                QNode {
                    center,
                    extent,
                    children,
                }
            })
            .collect();
        Quantized {
            nodes,
            origin,
            step,
        }
    }
    #[inline(always)]
    fn children_boxes(&self, i: u32, prim: impl Fn(u32) -> (Vec3A, Vec3A)) -> [ChildBox; 2] {
        own_boxes(self.children(i), |j| self.node_box(j), prim)
    }
    #[inline(always)]
    fn root_box(&self, root: Ref, prim: impl Fn(u32) -> (Vec3A, Vec3A)) -> (Vec3A, Vec3A) {
        own_box(root, |j| self.node_box(j), prim)
    }
    fn stored_reach(&self) -> f64 {
        reach_of(
            self.nodes
                .iter()
                .map(|n| grid_box_f64(self.origin, self.step, n.center, n.extent)),
        )
    }
    #[inline(always)]
    fn children(&self, i: u32) -> [Ref; 2] {
        self.nodes[i as usize].children
    }
    fn len(&self) -> usize {
        self.nodes.len()
    }
    fn bytes(&self) -> usize {
        self.nodes.len() * core::mem::size_of::<QNode>()
    }
}

/// A paired node: both children's boxes on the tree's grid, `[c₀, e₀, c₁, e₁]` (the
/// centers' `i16` bits, the extents' `u16`), and the two children (32 bytes).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct PNode {
    pub grid: [u16; 12],
    pub children: [Ref; 2],
}

impl PNode {
    /// Child `k`'s box on the grid, as stored.
    fn integers(&self, k: usize) -> ([i16; 3], [u16; 3]) {
        let q = &self.grid[6 * k..6 * k + 6];
        ([q[0] as i16, q[1] as i16, q[2] as i16], [q[3], q[4], q[5]])
    }
}

/// Nodes of 32 bytes that hold their two children's boxes, primitives' included, on a
/// per-tree grid as [`Quantized`] does; the root's box is kept apart as a [`Compact`] node's.
///
/// A descent step reads one node for both children's boxes, and never derives a
/// primitive's box from its vertices; a tree over `n` primitives costs `32·(n − 1)` bytes
/// plus the root's box. A primitive's box on the grid is a little larger than its own, so
/// [`super::Query::visit_boxes`] tests the pairs it reports again on their own boxes (a
/// mesh's pairs go to the exact triangle test anyway).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Paired {
    nodes: Vec<PNode>,
    /// The root's `center ± extent`, rounded outward ([`outward`]).
    root: ([f32; 3], [f32; 3]),
    origin: Vec3A,
    step: Vec3A,
}

impl Layout for Paired {}

impl NodeAccess for Paired {
    const STORES_PRIMITIVES: bool = true;

    fn from_boxes(
        children: &[[Ref; 2]],
        min: &[[f32; 3]],
        max: &[[f32; 3]],
        prim: impl Fn(u32) -> PrimBox,
    ) -> Self {
        let (origin, step) = Quantized::grid_of(min, max);
        let boxed = |r: Ref| {
            let b = if r.is_primitive() {
                prim(r.index())
            } else {
                PrimBox {
                    min: min[r.index() as usize],
                    max: max[r.index() as usize],
                }
            };
            Quantized::quantize(origin, step, b.min, b.max)
        };
        let nodes = children
            .iter()
            .map(|&children| {
                let mut grid = [0u16; 12];
                for (k, &r) in children.iter().enumerate() {
                    let (c, e) = boxed(r);
                    for a in 0..3 {
                        grid[6 * k + a] = c[a] as u16;
                        grid[6 * k + 3 + a] = e[a];
                    }
                }
                PNode { grid, children }
            })
            .collect();
        let root = match (min.first(), max.first()) {
            (Some(&lo), Some(&hi)) => outward(lo, hi),
            _ => {
                let b = prim(0);
                outward(b.min, b.max)
            }
        };
        Paired {
            nodes,
            root,
            origin,
            step,
        }
    }
    #[inline(always)]
    fn children_boxes(&self, i: u32, _prim: impl Fn(u32) -> (Vec3A, Vec3A)) -> [ChildBox; 2] {
        let n = &self.nodes[i as usize];
        let [(c0, e0), (c1, e1)] = crate::simd::grid_pair(&n.grid);
        // As `grid_box`: `step·c` and `step·e` exact, the sum rounded once.
        let child = |r: Ref, c: Vec3A, e: Vec3A| ChildBox {
            r,
            center: self.origin + self.step * c,
            extent: self.step * e,
        };
        [child(n.children[0], c0, e0), child(n.children[1], c1, e1)]
    }
    #[inline(always)]
    fn root_box(&self, _root: Ref, _prim: impl Fn(u32) -> (Vec3A, Vec3A)) -> (Vec3A, Vec3A) {
        (
            Vec3A::from_array(self.root.0),
            Vec3A::from_array(self.root.1),
        )
    }
    fn stored_reach(&self) -> f64 {
        let (c, e) = self.root;
        let root = (
            Vec3A::from_array(c).as_dvec3(),
            Vec3A::from_array(e).as_dvec3(),
        );
        reach_of(
            self.nodes
                .iter()
                .flat_map(|n| {
                    [0, 1].map(|k| {
                        let (c, e) = n.integers(k);
                        grid_box_f64(self.origin, self.step, c, e)
                    })
                })
                .chain([root]),
        )
    }
    #[inline(always)]
    fn children(&self, i: u32) -> [Ref; 2] {
        self.nodes[i as usize].children
    }
    fn len(&self) -> usize {
        self.nodes.len()
    }
    fn bytes(&self) -> usize {
        self.nodes.len() * core::mem::size_of::<PNode>() + core::mem::size_of_val(&self.root)
    }
}
