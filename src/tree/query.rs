//! Queries between two trees at two poses: one simultaneous descent of both trees, with the
//! relative pose, `|R|` and the pad of [`Relative`] computed once.

use alloc::vec::Vec;
use core::ops::ControlFlow;

use glam::{DVec3, Vec3A};

use super::mesh::{AabbTree, Bvh, TriMesh, triangle_box};
use super::nodes::{ChildBox, Layout, NodeAccess, Ref};
use super::relative::{AxesOf, Crosswise, Lanes, QueryError, Relative};
use super::triangle::{
    LANES, TriangleLanes, filter_batch, triangles_distance_sq, triangles_intersect,
};
use crate::transform::{Rigid3, Similarity3};

/// What a tree is built over: [`TriMesh`] or [`AabbTree`] (sealed).
pub trait Shape: Primitives {}

/// The crate-private access of the descent: the tree, and a primitive's box.
pub(crate) trait Primitives {
    type Nodes: Layout;
    fn hierarchy(&self) -> &Bvh<Self::Nodes>;
    /// Primitive `id`'s box as `(center, extent)` in the object's frame.
    fn primitive_box(&self, id: u32) -> (Vec3A, Vec3A);
}

impl<L: Layout> Shape for TriMesh<L> {}
impl<L: Layout> Primitives for TriMesh<L> {
    type Nodes = L;
    #[inline(always)]
    fn hierarchy(&self) -> &Bvh<L> {
        &self.tree
    }
    #[inline(always)]
    fn primitive_box(&self, id: u32) -> (Vec3A, Vec3A) {
        triangle_box(self.corners(id))
    }
}

impl<L: Layout> Shape for AabbTree<L> {}
impl<L: Layout> Primitives for AabbTree<L> {
    type Nodes = L;
    #[inline(always)]
    fn hierarchy(&self) -> &Bvh<L> {
        &self.tree
    }
    #[inline(always)]
    fn primitive_box(&self, id: u32) -> (Vec3A, Vec3A) {
        let b = &self.boxes()[id as usize];
        (b.center(), b.half_extents())
    }
}

/// The work of one query.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Stats {
    /// Box pairs tested (nodes and primitive boxes, the roots included).
    pub node_pairs: u64,
    /// Primitive pairs whose boxes overlapped (triangle tests, for meshes).
    pub leaf_pairs: u64,
}

/// One query between `A` at pose `pa` and `B` at pose `pb`: the relative pose, `|R|` and
/// the pad are computed here, once (see [`Relative`] for the geometry decided and the
/// proof that no overlapping pair is culled).
#[derive(Clone, Copy, Debug)]
pub struct Query<'a, A, B> {
    a: &'a A,
    b: &'a B,
    pa: Similarity3,
    pb: Similarity3,
    tolerance: f32,
    cross_near_leaves: bool,
    relative: Relative,
}

impl<'a, A: Shape, B: Shape> Query<'a, A, B> {
    /// The query between `a` at `pa` and `b` at `pb`, with no tolerance; a non-finite pose,
    /// or a relative pose out of range, is a [`QueryError`] (never a silent "no contact").
    pub fn new(a: &'a A, pa: Rigid3, b: &'a B, pb: Rigid3) -> Result<Self, QueryError> {
        Self::similarity(a, pa.into(), b, pb.into())
    }

    /// The query between `a` at `pa` and `b` at `pb`, poses with a uniform scale (see
    /// [`Relative::similarity`]; a zero scale is [`QueryError::ZeroScale`]).
    pub fn similarity(
        a: &'a A,
        pa: Similarity3,
        b: &'a B,
        pb: Similarity3,
    ) -> Result<Self, QueryError> {
        let relative =
            Relative::similarity(&pa, a.hierarchy().reach, &pb, b.hierarchy().reach, 0.0)?;
        Ok(Query {
            a,
            b,
            pa,
            pb,
            tolerance: 0.0,
            cross_near_leaves: false,
            relative,
        })
    }

    /// Pairs at distance at most `tolerance` count as overlapping (NaN, infinite or
    /// negative: [`QueryError::InvalidTolerance`]). The boxes are culled conservatively for
    /// the exact distance; the leaf distance is computed in `f64` (relative error a few
    /// `2^-52`), so only a zero tolerance is an exact test.
    pub fn with_tolerance(mut self, tolerance: f32) -> Result<Self, QueryError> {
        self.relative = Relative::similarity(
            &self.pa,
            self.a.hierarchy().reach,
            &self.pb,
            self.b.hierarchy().reach,
            tolerance,
        )?;
        self.tolerance = tolerance;
        Ok(self)
    }

    /// Also test the 9 cross axes (in `f64`) on every pair of primitive boxes before the
    /// leaf is visited. Off by default: measured on the tori and spot scenes, it culls few
    /// pairs and costs more than it saves (measured in `docs/trees.md`).
    #[must_use]
    pub fn with_cross_axes_near_leaves(mut self, on: bool) -> Self {
        self.cross_near_leaves = on;
        self
    }

    /// The relative pose of this query.
    #[must_use]
    pub fn relative(&self) -> &Relative {
        &self.relative
    }

    /// Calls `leaf(i, j)` for every pair of primitives whose own boxes overlap by the
    /// conservative test (a superset of the pairs whose exact boxes overlap or lie within
    /// the tolerance), in descent order, until it breaks. The descent gathers pairs in
    /// batches, so it may run a few dozen box tests past the pair that breaks.
    pub fn visit_boxes(
        &self,
        mut leaf: impl FnMut(u32, u32) -> ControlFlow<()>,
    ) -> (ControlFlow<()>, Stats) {
        // A layout that stores primitives' boxes holds them on its grid, a little larger:
        // the pairs it passes are tested again on the primitives' own boxes.
        let stored = A::Nodes::STORES_PRIMITIVES || B::Nodes::STORES_PRIMITIVES;
        self.descend(LANES, &mut |pairs| {
            for &(i, j) in pairs {
                if stored {
                    let ((ca, ea), (cb, eb)) = (self.a.primitive_box(i), self.b.primitive_box(j));
                    if !self.relative.overlaps_ce(ca, ea, cb, eb) {
                        continue;
                    }
                }
                leaf(i, j)?;
            }
            ControlFlow::Continue(())
        })
    }

    /// The simultaneous descent: hands the pairs of primitives whose boxes overlap to
    /// `batch`, in descent order, in batches of at least `flush_at` pairs (the last one
    /// excepted) and at most [`LANES`], until it breaks.
    ///
    /// A step pops a pair and splits both nodes, testing the four pairs of a child of each
    /// at once in lanes; when one side is a primitive, it opens the other node two levels
    /// and tests up to four boxes against the primitive's (`Crosswise`). The pairs that
    /// pass go on the stack, and pairs of primitives leave it for the batch. The triangle
    /// tests then run on a whole batch at once (a lane filter first).
    ///
    /// `batch` is called through a reference to a trait object, once per batch: the
    /// descent is compiled once per pair of shapes and backend in the user's crate, not
    /// once more for every caller's closure (the IR of a call site with the closure generic
    /// is in `docs/speed.md` and `docs/trees.md`).
    fn descend(&self, flush_at: usize, batch: &mut OnBatch<'_>) -> (ControlFlow<()>, Stats) {
        // Compiled in the best backend's dispatch wrapper (three-operand vector
        // instructions, fewer spills of the query's 15 vectors); plain arithmetic, unfused.
        let (broke, stats) = crate::simd::plain(
            #[inline(always)]
            || {
                let (flow, stats) = self.descend_here(flush_at, batch);
                (flow.is_break(), stats)
            },
        );
        let flow = if broke {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        };
        (flow, stats)
    }

    #[inline(always)]
    fn descend_here(&self, flush_at: usize, batch: &mut OnBatch<'_>) -> (ControlFlow<()>, Stats) {
        let mut stats = Stats::default();
        let rel = &self.relative;
        let (ha, hb) = (self.a.hierarchy(), self.b.hierarchy());
        let (la, lb) = (&ha.layout, &hb.layout);
        let prim_a = |i| self.a.primitive_box(i);
        let prim_b = |i| self.b.primitive_box(i);
        let margin = rel.cross_margin(ha.reach, hb.reach);
        // The roots: 6 axes in f32, then the 9 cross axes in f64.
        let ((ca, ea), (cb, eb)) = (la.root_box(ha.root, prim_a), lb.root_box(hb.root, prim_b));
        stats.node_pairs += 1;
        if !rel.overlaps_ce(ca, ea, cb, eb) || rel.roots_separated(ca, ea, cb, eb, margin) {
            return (ControlFlow::Continue(()), stats);
        }
        if ha.root.is_primitive() && hb.root.is_primitive() {
            stats.leaf_pairs += 1;
            return (batch(&[(ha.root.index(), hb.root.index())]), stats);
        }
        let cross = rel.crosswise();
        let cross_near_leaves = self.cross_near_leaves;
        // Each pair on the stack passed its box test; the stack's top is the next pair in
        // descent order, leaves included, so pairs of primitives leave in that order.
        let mut stack = Pending::default();
        stack.put((ha.root, hb.root), [ca, ea, cb, eb], true);
        let mut leaves = [(0u32, 0u32); LANES];
        let mut found = 0;
        let flush_at = flush_at.clamp(1, LANES);
        while let Some(i) = stack.pop() {
            let ((ra, rb), [ca, ea, cb, eb]) = (stack.pairs[i], stack.boxes[i]);
            // A pair of primitives goes to the batch.
            if ra.is_primitive() && rb.is_primitive() {
                // `found` is below `flush_at <= LANES` here: the mask spares the check.
                leaves[found & (LANES - 1)] = (ra.index(), rb.index());
                found += 1;
                if found >= flush_at {
                    stats.leaf_pairs += found as u64;
                    let flow = batch(&leaves[..found]);
                    found = 0;
                    if flow.is_break() {
                        return (flow, stats);
                    }
                }
                continue;
            }
            // One side is a primitive: up to four boxes below the other side's node
            // (`Below`), placed on the primitive's tree's axes, against its box.
            if ra.is_primitive() {
                let below = Below::new(lb, rb.index(), prim_b);
                let keep = self.keep_against(&cross, &below, AxesOf::A, (ca, ea), margin);
                stats.node_pairs += u64::from(below.valid.count_ones());
                stack.push_kept(keep, |l| {
                    let k = below.kids[l];
                    ((ra, k.r), [ca, ea, k.center, k.extent])
                });
                continue;
            }
            if rb.is_primitive() {
                let below = Below::new(la, ra.index(), prim_a);
                let keep = self.keep_against(&cross, &below, AxesOf::B, (cb, eb), margin);
                stats.node_pairs += u64::from(below.valid.count_ones());
                stack.push_kept(keep, |l| {
                    let k = below.kids[l];
                    ((k.r, rb), [k.center, k.extent, cb, eb])
                });
                continue;
            }
            // Both nodes split: two children of `A` in lanes 0 and 1, two of `B` in lanes 2
            // and 3, each placed on the other tree's axes, and the four pairs of a child of
            // each tested at once, each kept by a count.
            let kids_a = la.children_boxes(ra.index(), prim_a);
            let kids_b = lb.children_boxes(rb.index(), prim_b);
            let x = Lanes::new(
                [
                    kids_a[0].center,
                    kids_a[1].center,
                    kids_b[0].center,
                    kids_b[1].center,
                ],
                [
                    kids_a[0].extent,
                    kids_a[1].extent,
                    kids_b[0].extent,
                    kids_b[1].extent,
                ],
            );
            let apart = cross.apart_pairs(&x, &cross.place(&x));
            stats.node_pairs += 4;
            // Pair `2i + j` holds `A`'s child `i` and `B`'s child `j`.
            let mut keep = !apart;
            if cross_near_leaves {
                let leaf = pairs_of(primitives(&kids_a), primitives(&kids_b));
                for l in 0..4 {
                    let (a, b) = (kids_a[l >> 1], kids_b[l & 1]);
                    if leaf >> l & 1 != 0
                        && rel.roots_separated(a.center, a.extent, b.center, b.extent, margin)
                    {
                        keep &= !(1 << l);
                    }
                }
            }
            stack.push_kept(keep, |l| {
                let (a, b) = (kids_a[l >> 1], kids_b[l & 1]);
                ((a.r, b.r), [a.center, a.extent, b.center, b.extent])
            });
        }
        stats.leaf_pairs += found as u64;
        (batch(&leaves[..found]), stats)
    }
}

impl<A: Shape, B: Shape> Query<'_, A, B> {
    /// The boxes of `below` (one tree's) that pass the box test against the box `one` of
    /// the other tree (a primitive), as a lane mask; `axes` are the primitive's tree's.
    /// With the cross axes near leaves, a pair of primitives must pass them too.
    #[inline(always)]
    fn keep_against(
        &self,
        cross: &Crosswise,
        below: &Below,
        axes: AxesOf,
        one: (Vec3A, Vec3A),
        margin: f64,
    ) -> u32 {
        let rel = &self.relative;
        let (placed, one_placed) = if axes == AxesOf::A {
            (
                cross.place_on(AxesOf::A, &below.lanes),
                rel.on_b(one.0, one.1),
            )
        } else {
            (
                cross.place_on(AxesOf::B, &below.lanes),
                rel.on_a(one.0, one.1),
            )
        };
        let mut keep = below.valid & !cross.apart_from(&below.lanes, &placed, one, &one_placed);
        if self.cross_near_leaves {
            for (l, kid) in below.kids.iter().enumerate() {
                let kid_box = (kid.center, kid.extent);
                let ((ca, ea), (cb, eb)) = if axes == AxesOf::A {
                    (one, kid_box)
                } else {
                    (kid_box, one)
                };
                if kid.r.is_primitive() && rel.roots_separated(ca, ea, cb, eb, margin) {
                    keep &= !(1 << l);
                }
            }
        }
        keep
    }
}

/// The boxes a step against a primitive tests: a node's children, each child that is a
/// node replaced by its own two children (the step skips that level: a box test skipped
/// only culls less). Up to four, in descent order, in lanes; `valid` marks the lanes used.
struct Below {
    kids: [ChildBox; 4],
    valid: u32,
    lanes: Lanes,
}

impl Below {
    #[inline(always)]
    fn new<L: NodeAccess>(layout: &L, i: u32, prim: impl Fn(u32) -> (Vec3A, Vec3A) + Copy) -> Self {
        let open = |c: ChildBox| {
            if c.r.is_primitive() {
                ([c, c], 0b01)
            } else {
                (layout.children_boxes(c.r.index(), prim), 0b11)
            }
        };
        let [c0, c1] = layout.children_boxes(i, prim);
        let ([k0, k1], v0) = open(c0);
        let ([k2, k3], v1) = open(c1);
        Below {
            lanes: Lanes::new(
                [k0.center, k1.center, k2.center, k3.center],
                [k0.extent, k1.extent, k2.extent, k3.extent],
            ),
            kids: [k0, k1, k2, k3],
            valid: v0 | v1 << 2,
        }
    }
}

/// Bit `l` set for the children that are primitives.
#[inline(always)]
fn primitives(kids: &[ChildBox; 2]) -> u32 {
    kids[0].r.0 >> 31 | (kids[1].r.0 >> 31) << 1
}

/// The pairs `2i + j` whose child `i` of `A` is in `a` and child `j` of `B` in `b` (two
/// masks of two bits).
#[inline(always)]
fn pairs_of(a: u32, b: u32) -> u32 {
    (b * (a & 1)) | ((b << 2) * (a >> 1))
}

/// The descent's consumer: called once per batch of pairs of primitives whose boxes
/// overlap, it may stop the descent.
type OnBatch<'f> = dyn FnMut(&[(u32, u32)]) -> ControlFlow<()> + 'f;

/// The pairs of the descent whose boxes overlap, each with both boxes (`A`'s center and
/// extent, then `B`'s): a node's children and their boxes come from the node, a primitive's
/// box from here. Pairs of two primitives are leaves.
///
/// Two arrays (the pairs, the boxes), each read back at the width it was written. An entry
/// is written at the top whether it is kept or not, and kept by moving the top: no
/// branch.
#[derive(Default)]
struct Pending {
    pairs: Vec<(Ref, Ref)>,
    boxes: Vec<[Vec3A; 4]>,
    top: usize,
}

impl Pending {
    /// Room for `n` more entries past the top.
    #[inline(always)]
    fn reserve(&mut self, n: usize) {
        if self.pairs.len() < self.top + n {
            let len = (self.top + n).max(2 * self.pairs.len()).max(64);
            self.pairs.resize(len, (Ref(0), Ref(0)));
            self.boxes.resize(len, [Vec3A::ZERO; 4]);
        }
    }

    /// Writes a pair and its boxes at the top, and keeps it when `keep` (the root).
    #[inline(always)]
    fn put(&mut self, pair: (Ref, Ref), boxes: [Vec3A; 4], keep: bool) {
        self.reserve(1);
        self.pairs[self.top] = pair;
        self.boxes[self.top] = boxes;
        self.top += usize::from(keep);
    }

    /// Writes a step's four entries `entry(3)`, …, `entry(0)` at the top, in that order
    /// (`entry(0)` ends on top), each kept when its bit of `keep` is set. Every entry is
    /// written, and kept by moving the top: no branch, and one bounds check for the four.
    #[inline(always)]
    fn push_kept(&mut self, keep: u32, entry: impl Fn(usize) -> ((Ref, Ref), [Vec3A; 4])) {
        self.reserve(4);
        let top = self.top;
        let (Some(pairs), Some(boxes)) = (
            self.pairs[top..].first_chunk_mut::<4>(),
            self.boxes[top..].first_chunk_mut::<4>(),
        ) else {
            unreachable!("four entries were reserved past the top");
        };
        let mut kept = 0;
        for l in (0..4).rev() {
            let (pair, b) = entry(l);
            // `kept` is at most 3 here: the mask only spares the bounds check.
            pairs[kept & 3] = pair;
            boxes[kept & 3] = b;
            kept += (keep >> l & 1) as usize;
        }
        self.top = top + kept;
    }

    /// Pops the top pair: its entry's index (read it before the next write).
    #[inline(always)]
    fn pop(&mut self) -> Option<usize> {
        self.top = self.top.checked_sub(1)?;
        Some(self.top)
    }
}

impl<'a, LA: Layout, LB: Layout> Query<'a, TriMesh<LA>, TriMesh<LB>> {
    /// True when triangle `i` of `A` and `j` of `B` intersect (exactly, touching counts)
    /// or, with a tolerance, lie within it (`f64` distance).
    #[inline]
    fn triangles_meet(&self, i: u32, j: u32) -> bool {
        let ta = self.a.triangle_f64(i);
        let tb: [DVec3; 3] = self.b.corners(j).map(|v| self.relative.place(v));
        if self.tolerance > 0.0 {
            let d = f64::from(self.tolerance);
            triangles_distance_sq(&ta, &tb) <= d * d
        } else {
            triangles_intersect(&ta, &tb)
        }
    }

    /// Calls `f(i, j)` for every pair of triangles that intersect (or lie within the
    /// tolerance), in descent order, until it breaks. The triangle tests run in batches of
    /// box-overlapping pairs, so the descent may run a few dozen box tests past the pair
    /// that breaks (see [`Query::first_contact`]).
    pub fn visit(
        &self,
        mut f: impl FnMut(u32, u32) -> ControlFlow<()>,
    ) -> (ControlFlow<()>, Stats) {
        // The lanes are written over batch after batch: zeroed once per query, not once per
        // batch (lanes past a short batch hold an earlier batch's triangles, never read).
        let mut lanes = ([[[0.0; LANES]; 3]; 3], [[[0.0; LANES]; 3]; 3]);
        self.descend(LANES, &mut |pairs| {
            self.meet_each(pairs, &mut lanes, &mut f)
        })
    }

    /// Calls `f` on the pairs of `batch` whose triangles meet, in order, until it breaks.
    fn meet_each(
        &self,
        batch: &[(u32, u32)],
        lanes: &mut (TriangleLanes, TriangleLanes),
        f: &mut impl FnMut(u32, u32) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        if self.tolerance > 0.0 || batch.len() < 4 {
            return self.meet_one_by_one(batch, f);
        }
        let verdicts = filter_batch(self.a.soup(), self.b.soup(), &self.relative, batch, lanes);
        let (a, b) = lanes;
        let corners = |t: &TriangleLanes, l: usize| {
            [0, 1, 2].map(|k| DVec3::new(t[k][0][l], t[k][1][l], t[k][2][l]))
        };
        for (l, &(i, j)) in (0..LANES).zip(batch) {
            let meet = verdicts.meet[l]
                || !verdicts.apart[l] && triangles_intersect(&corners(a, l), &corners(b, l));
            if meet {
                f(i, j)?;
            }
        }
        ControlFlow::Continue(())
    }

    /// [`Query::meet_each`] one pair at a time (no lanes).
    fn meet_one_by_one(
        &self,
        batch: &[(u32, u32)],
        f: &mut impl FnMut(u32, u32) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        for &(i, j) in batch {
            if self.triangles_meet(i, j) {
                f(i, j)?;
            }
        }
        ControlFlow::Continue(())
    }

    /// True when some triangle of `A` meets some triangle of `B` (stops at the first).
    #[must_use]
    pub fn intersects(&self) -> bool {
        self.first_contact().0.is_some()
    }

    /// The first pair `(i, j)` of triangles that meet, in descent order, or `None`, with
    /// the work done: the descent stops at once, where [`Query::visit`] may run ahead by a
    /// batch of box tests.
    #[must_use]
    pub fn first_contact(&self) -> (Option<(u32, u32)>, Stats) {
        let mut first = None;
        // Batches of one: each triangle test runs alone.
        let (_, stats) = self.descend(1, &mut |pairs| {
            self.meet_one_by_one(pairs, &mut |i, j| {
                first = Some((i, j));
                ControlFlow::Break(())
            })
        });
        (first, stats)
    }

    /// Every pair `(i, j)` of triangle ids that meet, in descent order.
    #[must_use]
    pub fn overlapping_triangles(&self) -> Vec<(u32, u32)> {
        let mut pairs = Vec::new();
        let _ = self.visit(|i, j| {
            pairs.push((i, j));
            ControlFlow::Continue(())
        });
        pairs
    }
}

impl<'a, LA: Layout, LB: Layout> Query<'a, AabbTree<LA>, AabbTree<LB>> {
    /// Every pair `(i, j)` of primitive ids whose boxes overlap by the conservative test
    /// (every pair whose exact boxes overlap is among them).
    #[must_use]
    pub fn leaf_pairs(&self) -> Vec<(u32, u32)> {
        let mut pairs = Vec::new();
        let _ = self.visit_boxes(|i, j| {
            pairs.push((i, j));
            ControlFlow::Continue(())
        });
        pairs
    }
}

impl<L: Layout> TriMesh<L> {
    /// The query between this mesh at `pose` and `other` at `other_pose` (see
    /// [`Query::new`] for the errors).
    pub fn query<'a, M: Layout>(
        &'a self,
        pose: Rigid3,
        other: &'a TriMesh<M>,
        other_pose: Rigid3,
    ) -> Result<Query<'a, Self, TriMesh<M>>, QueryError> {
        Query::new(self, pose, other, other_pose)
    }

    /// True when this mesh at `pose` meets `other` at `other_pose` (first contact); a bad
    /// pose is a [`QueryError`].
    pub fn intersects<M: Layout>(
        &self,
        pose: Rigid3,
        other: &TriMesh<M>,
        other_pose: Rigid3,
    ) -> Result<bool, QueryError> {
        Ok(self.query(pose, other, other_pose)?.intersects())
    }

    /// Every pair of triangle ids (this mesh's, `other`'s) that meet at these poses; a bad
    /// pose is a [`QueryError`].
    pub fn overlapping_triangles<M: Layout>(
        &self,
        pose: Rigid3,
        other: &TriMesh<M>,
        other_pose: Rigid3,
    ) -> Result<Vec<(u32, u32)>, QueryError> {
        Ok(self.query(pose, other, other_pose)?.overlapping_triangles())
    }
}

impl<L: Layout> AabbTree<L> {
    /// The query between this tree at `pose` and `other` at `other_pose` (see
    /// [`Query::new`] for the errors).
    pub fn query<'a, M: Layout>(
        &'a self,
        pose: Rigid3,
        other: &'a AabbTree<M>,
        other_pose: Rigid3,
    ) -> Result<Query<'a, Self, AabbTree<M>>, QueryError> {
        Query::new(self, pose, other, other_pose)
    }
}
