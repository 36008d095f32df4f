//! A peer broadphase tree on obvhs's `Bvh2` (the BVH avian's collider trees are built on),
//! fed the same fat boxes and moved lists as pipeline C, frame by frame.
//!
//! The upkeep is the one obvhs's own docs advise for moving leaves, by the share of the
//! proxies that moved. `PlocBuilder::partial_rebuild` (`ploc/rebuild.rs`):
//!
//! > If the set of leaves is a small enough proportion of the total this can be faster since
//! > there may be large portions of the BVH that don't need to be updated. If the proportion
//! > is very high it can be faster to build from scratch instead, avoiding the overhead of
//! > doing a partial rebuild. If only a few nodes need to be updated it might be faster and
//! > produce a better BVH to selectively reinsert them.
//!
//! and `Bvh2::refit_all`: "If the leaves have moved very much the BVH can quickly become
//! degenerate [...]. Consider rebuilding the BVH from scratch or running a bit of reinsertion
//! after refit." obvhs gives no shares; the thresholds are the defaults of avian's
//! `TreeOptimizationMode::Adaptive` (reinsertion below 15% moved, partial rebuild below 45%,
//! full rebuild above), which is this same three-way choice. Per frame:
//!
//! - under 15% moved, as obvhs's `physics` example (`parallel_reinsert`) and avian's
//!   `Reinsert`: leaves (`ms[1]`) by `Bvh2::resize_node` on each moved leaf (through
//!   `primitives_to_nodes`), which writes the box and refits the path above it (so, as C's,
//!   the refit is in the leaves and `ms[3]` is zero); then optimise (`ms[2]`) by
//!   reinserting the moved leaves (`ReinsertionOptimizer::run_with_candidates`, one pass).
//! - under 45%: leaves (`ms[1]`) by `Bvh2Node::set_aabb` alone (its docs ask for no refit
//!   before it), then optimise (`ms[2]`) by `PlocBuilder::partial_rebuild` over the paths
//!   above the moved leaves (`compute_rebuild_path_flags`).
//! - otherwise: leaves (`ms[1]`) by `set_aabb`, then optimise (`ms[2]`) by
//!   `PlocBuilder::full_rebuild` from the current leaves.
//!
//! Before a rebuild the leaves' stage also grows the root's box over the new boxes: the
//! rebuilds scale their Morton codes by the root's box, which must hold every leaf.
//!
//! Then pairs (`ms[4]`): each moved proxy's new box queries the tree (`aabb_traverse`,
//! which tests closed boxes); a pair is reported when the two boxes overlap now and did not
//! at the last frame (closed boxes, each box against its own last box), once: a pair of
//! two moved proxies from the larger id.
//!
//! The build and the rebuilds use PLOC's cheapest settings, as avian's and the `physics`
//! example's rebuilds do: `PlocSearchDistance::Minimum`, `SortPrecision::U64`, no
//! search-depth threshold. `ms[0]` (the boxes' update) is the caller's.
//!
//! One guard outside the timings. obvhs's traversals keep their stack in a fixed array
//! sized by `Bvh2::max_depth` (95 entries up to 96, 191 up to 192), and a push past it
//! overwrites the top entry silently: a tree deeper than `max_depth` allows loses subtrees
//! from its queries, so pairs. A PLOC build sets `max_depth` from its passes, but a partial
//! rebuild counts only the passes over the rebuilt part (not the subtrees it keeps) and a
//! reinsertion does not update it. So after every rebuild, and after reinsertions once their
//! count could have deepened the tree past what `max_depth` allows, the tree's height is
//! measured (a walk of every node) and `max_depth` raised if it is short
//! ([`ObvhsTree::depth_guard`] counts both).
//!
//! obvhs assumes finite boxes (NaN and infinite faces break its Morton codes, surface areas
//! and overlap tests: a NaN box overlaps everything), so a non-finite box panics here.

use std::time::Instant;

use ::obvhs::aabb::Aabb;
use ::obvhs::bvh2::Bvh2;
use ::obvhs::bvh2::reinsertion::ReinsertionOptimizer;
use ::obvhs::ploc::rebuild::compute_rebuild_path_flags;
use ::obvhs::ploc::{PlocBuilder, PlocSearchDistance, SortPrecision};
use bvkit::Aabb3;

use super::Frame;

/// Below this share of the proxies moved, the moved leaves are reinserted (avian's default).
const REINSERT_BELOW: f64 = 0.15;
/// Below this share (and not below [`REINSERT_BELOW`]), the paths above the moved leaves are
/// rebuilt; above it, the whole tree (avian's default).
const PARTIAL_BELOW: f64 = 0.45;

/// A proxy that did not move this frame, in [`ObvhsTree::place`].
const UNMOVED: u32 = u32::MAX;

/// How a frame kept the tree up (module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Upkeep {
    /// Each moved leaf resized with its path refitted, then the moved leaves reinserted.
    Reinsert,
    /// The paths above the moved leaves rebuilt by PLOC.
    PartialRebuild,
    /// The whole tree rebuilt by PLOC from its leaves.
    FullRebuild,
}

/// obvhs's `Bvh2` over one box per proxy (proxy `i` is primitive `i`), kept up frame by
/// frame as its docs advise, with the pairs that began.
pub struct ObvhsTree {
    bvh: Bvh2,
    builder: PlocBuilder,
    optimizer: ReinsertionOptimizer,
    /// Each proxy's box at the last frame (its leaf's box until this frame's writes).
    last: Vec<Aabb3>,
    /// Per proxy, its place in `moved` this frame, or [`UNMOVED`].
    place: Vec<u32>,
    /// This frame's moved proxies (without repeats), their new boxes, and their leaves.
    moved: Vec<u32>,
    new: Vec<Aabb3>,
    leaves: Vec<u32>,
    /// The partial rebuild's flags (`compute_rebuild_path_flags`).
    flags: Vec<bool>,
    /// An upper bound on the tree's height (edges from the root to its deepest leaf), and
    /// the guard's stack.
    height: usize,
    walk: Vec<(u32, u32)>,
    upkeep: Upkeep,
    /// Heights measured, and `max_depth` raises (module docs).
    checks: usize,
    raises: usize,
}

impl ObvhsTree {
    /// The tree.
    pub fn bvh(&self) -> &Bvh2 {
        &self.bvh
    }

    /// A tree over `boxes` (proxy `i` has box `i`), built by PLOC.
    ///
    /// # Panics
    /// If a box has a non-finite face.
    pub fn new(boxes: &[Aabb3]) -> Self {
        let n = boxes.len();
        assert!(
            u32::try_from(n).is_ok_and(|n| n < UNMOVED),
            "{n} proxies: ids must fit a u32"
        );
        let aabbs: Vec<Aabb> = boxes
            .iter()
            .enumerate()
            .map(|(i, b)| to_obvhs(i as u32, b))
            .collect();
        let mut builder = PlocBuilder::with_capacity(n);
        let mut bvh = builder.build(
            PlocSearchDistance::Minimum,
            &aabbs,
            (0..n as u32).collect(),
            SortPrecision::U64,
            0,
        );
        // Both maps are kept valid by every later operation once they exist.
        bvh.init_primitives_to_nodes_if_uninit();
        bvh.init_parents_if_uninit();
        let mut tree = Self {
            bvh,
            builder,
            optimizer: ReinsertionOptimizer::default(),
            last: boxes.to_vec(),
            place: vec![UNMOVED; n],
            moved: Vec::new(),
            new: Vec::new(),
            leaves: Vec::new(),
            flags: Vec::new(),
            height: 0,
            walk: Vec::new(),
            upkeep: Upkeep::FullRebuild,
            checks: 0,
            raises: 0,
        };
        tree.guard_depth(true);
        tree
    }

    /// One frame: the proxies `moved` (ids below the proxy count, in any order; a repeat
    /// counts once) have the new boxes `fat(id)`. Writes them, keeps the tree up, and
    /// counts the pairs that began; fills `frame.ms[1..5]`, `frame.rewritten` (the moved
    /// proxies) and `frame.pairs` (the pairs that began).
    ///
    /// # Panics
    /// If an id is out of range or a new box has a non-finite face.
    pub fn frame(&mut self, moved: &[u32], fat: impl Fn(u32) -> Aabb3, frame: &mut Frame) {
        let n = self.last.len();

        // Leaves: the new boxes into their leaves (and, before a rebuild, into the root).
        let start = Instant::now();
        self.moved.clear();
        self.new.clear();
        self.leaves.clear();
        for &id in moved {
            assert!(
                (id as usize) < n,
                "moved proxy {id} out of range: the tree has {n} proxies"
            );
            if self.place[id as usize] != UNMOVED {
                continue;
            }
            self.place[id as usize] = self.moved.len() as u32;
            self.moved.push(id);
            self.new.push(fat(id));
        }
        let share = if n == 0 {
            0.0
        } else {
            self.moved.len() as f64 / n as f64
        };
        let upkeep = if share < REINSERT_BELOW {
            Upkeep::Reinsert
        } else if share < PARTIAL_BELOW {
            Upkeep::PartialRebuild
        } else {
            Upkeep::FullRebuild
        };
        if upkeep == Upkeep::Reinsert {
            // Each leaf resized and its path refitted before the next: `refit_from_fast`
            // stops at the second unchanged ancestor, which is exact only when one leaf
            // changed since the tree was last tight (it asserts so in debug builds).
            for (&id, b) in self.moved.iter().zip(&self.new) {
                let leaf = self.bvh.primitives_to_nodes[id as usize];
                self.bvh.resize_node(leaf as usize, to_obvhs(id, b));
                self.leaves.push(leaf);
            }
        } else {
            let mut grown = Aabb::empty();
            for (&id, b) in self.moved.iter().zip(&self.new) {
                let b = to_obvhs(id, b);
                let leaf = self.bvh.primitives_to_nodes[id as usize];
                self.bvh.nodes[leaf as usize].set_aabb(b);
                self.leaves.push(leaf);
                grown = grown.union(&b);
            }
            // The rebuilds scale their Morton codes by the root's box: it must hold every
            // leaf. (A lone leaf is the root itself and already has its box.)
            if self.bvh.nodes.len() > 1 {
                let root = self.bvh.nodes[0].aabb().union(&grown);
                self.bvh.nodes[0].set_aabb(root);
            }
        }
        frame.ms[1] = ms(start);

        // Optimise (the refit was the leaves' own, or the rebuild's).
        frame.ms[3] = 0.0;
        match upkeep {
            Upkeep::Reinsert => {
                let start = Instant::now();
                if !self.leaves.is_empty() {
                    self.optimizer
                        .run_with_candidates(&mut self.bvh, &self.leaves, 1);
                }
                frame.ms[2] = ms(start);
                // Each reinsertion deepens the tree by at most one.
                self.height = self.height.saturating_add(self.leaves.len());
            }
            Upkeep::PartialRebuild => {
                let start = Instant::now();
                let Self {
                    bvh,
                    builder,
                    flags,
                    leaves,
                    ..
                } = self;
                compute_rebuild_path_flags(bvh, leaves.iter(), flags);
                builder.partial_rebuild(
                    bvh,
                    |node| flags[node],
                    PlocSearchDistance::Minimum,
                    SortPrecision::U64,
                    0,
                );
                frame.ms[2] = ms(start);
            }
            Upkeep::FullRebuild => {
                let start = Instant::now();
                self.builder.full_rebuild(
                    &mut self.bvh,
                    PlocSearchDistance::Minimum,
                    SortPrecision::U64,
                    0,
                );
                frame.ms[2] = ms(start);
            }
        }
        self.upkeep = upkeep;
        self.guard_depth(upkeep != Upkeep::Reinsert);

        // Pairs: each moved proxy's new box against the tree.
        let start = Instant::now();
        let mut begun = 0;
        let (last, place, new) = (&self.last, &self.place, &self.new);
        for (&a, now_a) in self.moved.iter().zip(new) {
            let last_a = &last[a as usize];
            // (Checked finite when written.)
            self.bvh.aabb_traverse(convert(now_a), |bvh, node| {
                let node = &bvh.nodes[node as usize];
                for k in node.first_index..node.first_index + node.prim_count {
                    let b = bvh.primitive_indices[k as usize];
                    let at = place[b as usize];
                    // A pair of two moved proxies is counted from the larger id.
                    if b == a || (at != UNMOVED && b > a) {
                        continue;
                    }
                    let now_b = if at == UNMOVED {
                        &last[b as usize]
                    } else {
                        &new[at as usize]
                    };
                    if overlap(now_a, now_b) && !overlap(last_a, &last[b as usize]) {
                        begun += 1;
                    }
                }
                true
            });
        }
        frame.ms[4] = ms(start);

        // This frame's boxes become the last ones.
        for (&id, b) in self.moved.iter().zip(&self.new) {
            self.last[id as usize] = *b;
            self.place[id as usize] = UNMOVED;
        }
        frame.rewritten = self.moved.len();
        frame.pairs = begun;
    }

    /// How the last frame (or the build) kept the tree up.
    pub fn upkeep(&self) -> Upkeep {
        self.upkeep
    }

    /// The untimed depth guard (module docs): how many times it measured the tree's height,
    /// and how many times `max_depth` was short of it and had to be raised (each of which
    /// obvhs's traversals would have answered wrongly).
    pub fn depth_guard(&self) -> (usize, usize) {
        (self.checks, self.raises)
    }

    /// Measures the height when `rebuilt` or when the bound on it could exceed what the
    /// traversal stack holds, and raises `max_depth` if the stack is short.
    fn guard_depth(&mut self, rebuilt: bool) {
        if !rebuilt && self.height < stack_capacity(self.bvh.max_depth) {
            return;
        }
        self.checks += 1;
        self.height = height(&self.bvh, &mut self.walk);
        // A query's stack holds at most one pending pair per level, two at the deepest.
        if stack_capacity(self.bvh.max_depth) < self.height + 1 {
            self.bvh.max_depth = self.height + 2;
            self.raises += 1;
        }
    }
}

/// The entries a traversal stack of obvhs holds for `max_depth` before it overwrites its
/// top (`fast_stack!(u32, (96, 192), max_depth, ..)`: a `StackStack<_, 96>` or
/// `StackStack<_, 192>`, whose last slot is never popped, else a `HeapStack` of
/// `max_depth`, which panics when full).
fn stack_capacity(max_depth: usize) -> usize {
    match max_depth {
        0..=96 => 95,
        97..=192 => 191,
        m => m,
    }
}

/// The tree's height: the edges from the root to its deepest leaf.
fn height(bvh: &Bvh2, walk: &mut Vec<(u32, u32)>) -> usize {
    if bvh.nodes.is_empty() {
        return 0;
    }
    let mut height = 0;
    walk.clear();
    walk.push((0, 0));
    while let Some((node, depth)) = walk.pop() {
        let node = &bvh.nodes[node as usize];
        if node.is_leaf() {
            height = height.max(depth);
        } else {
            walk.push((node.first_index, depth + 1));
            walk.push((node.first_index + 1, depth + 1));
        }
    }
    height as usize
}

/// Whether two closed boxes overlap: `min <= other.max` on every axis, both ways.
fn overlap(a: &Aabb3, b: &Aabb3) -> bool {
    a.min.cmple(b.max).all() && b.min.cmple(a.max).all()
}

/// Proxy `id`'s box as obvhs's, checked.
///
/// # Panics
/// If a face is not finite.
fn to_obvhs(id: u32, b: &Aabb3) -> Aabb {
    assert!(
        b.min.is_finite() && b.max.is_finite(),
        "proxy {id}: obvhs needs finite boxes, got {b:?}"
    );
    convert(b)
}

/// A box as obvhs's (through arrays, whichever glam obvhs resolves to).
fn convert(b: &Aabb3) -> Aabb {
    Aabb::new(b.min.to_array().into(), b.max.to_array().into())
}

fn ms(start: Instant) -> f64 {
    start.elapsed().as_secs_f64() * 1e3
}
