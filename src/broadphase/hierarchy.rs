//! One wide hierarchy: nodes of eight children whose boxes are stored in the parent as
//! columns (eight `min.x`, then eight `min.y`, …), so that one query tests all eight
//! children at once; a child is another node or a proxy (a leaf).
//!
//! **Containment.** A proxy's slot holds its box, and a node's slot in its parent contains
//! the union of the node's slots: boxes are combined with `min` and `max` only, which
//! round nothing. A new box enlarges the slots above it up to the first that already
//! contains it ([`Hierarchy::set`], Box2D's early exit), and a remove recomputes the unions
//! above it while they change. Where most proxies move at once, each new box only marks its
//! path ([`Hierarchy::set_leaf`]), and one pass then recomputes the marked slots from their
//! children ([`Hierarchy::refit_marked`]). So a query visits every proxy whose box it
//! overlaps. A build or a refit makes slots exact; moves leave slots loose, never short.

use super::slab::Sweep;
use crate::aabb::Aabb3;
use crate::num::round_down;
use alloc::vec::Vec;
use core::mem::take;
use glam::Vec3A;
use wide::f32x8;

/// Children per node.
pub(crate) const WIDTH: usize = 8;
/// No child, no parent.
pub(crate) const NONE: u32 = u32::MAX;
/// The bit of a child reference that marks a proxy.
const LEAF: u32 = 1 << 31;

/// A slot: node `index >> 3`, child `index & 7`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Slot(pub u32);

impl Slot {
    fn new(node: u32, child: usize) -> Self {
        Slot(node << 3 | child as u32)
    }
    pub(crate) fn node(self) -> u32 {
        self.0 >> 3
    }
    pub(crate) fn child(self) -> usize {
        (self.0 & 7) as usize
    }
}

/// Eight children: their boxes as columns, their references, and where this node sits in
/// its parent. An empty slot holds the empty box (`+∞` below `−∞`), which overlaps nothing.
#[derive(Clone, Debug)]
#[repr(C, align(64))]
pub(crate) struct Node {
    min: [[f32; WIDTH]; 3],
    max: [[f32; WIDTH]; 3],
    child: [u32; WIDTH],
    parent: Slot,
    /// The marks' epoch: `dirty` holds marks only while it equals the hierarchy's
    /// [`Hierarchy::epoch`], so that one increment clears every mark.
    epoch: u32,
    /// Bit `k` set when child `k` is a changed proxy or holds one
    /// ([`Hierarchy::mark_changed`], [`Hierarchy::set`]), read by a report's traversal
    /// ([`Hierarchy::changed_frontier`]). With the epoch it fits in the padding of the
    /// node's four lines.
    dirty: u8,
}

impl Node {
    fn new(parent: Slot) -> Self {
        Self {
            min: [[f32::INFINITY; WIDTH]; 3],
            max: [[f32::NEG_INFINITY; WIDTH]; 3],
            child: [NONE; WIDTH],
            parent,
            epoch: 0,
            dirty: 0,
        }
    }

    /// The marks of this node in `epoch`.
    #[inline(always)]
    fn marks(&self, epoch: u32) -> u8 {
        if self.epoch == epoch { self.dirty } else { 0 }
    }

    /// Marks child `k` in `epoch`; true when the node had no mark before (so its own slot
    /// above is not marked yet).
    #[inline(always)]
    fn mark(&mut self, k: usize, epoch: u32) -> bool {
        let before = self.marks(epoch);
        self.epoch = epoch;
        self.dirty = before | 1 << k;
        before == 0
    }

    /// Child `k`'s box.
    #[inline(always)]
    pub(crate) fn get(&self, k: usize) -> Aabb3 {
        Aabb3::new(
            Vec3A::new(self.min[0][k], self.min[1][k], self.min[2][k]),
            Vec3A::new(self.max[0][k], self.max[1][k], self.max[2][k]),
        )
    }

    #[inline(always)]
    fn set(&mut self, k: usize, b: &Aabb3) {
        for a in 0..3 {
            self.min[a][k] = b.min[a];
            self.max[a][k] = b.max[a];
        }
    }

    /// The union of the eight slots (empty slots add nothing).
    #[inline(always)]
    fn union(&self) -> Aabb3 {
        let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
        for a in 0..3 {
            for k in 0..WIDTH {
                lo[a] = lo[a].min(self.min[a][k]);
                hi[a] = hi[a].max(self.max[a][k]);
            }
        }
        Aabb3::new(Vec3A::from_array(lo), Vec3A::from_array(hi))
    }

    /// Bit `k` set when child `k`'s box overlaps the query's (closed boxes): six 8-lane
    /// compares (twelve SSE compares on a baseline x86-64 build).
    #[inline(always)]
    fn overlaps(&self, q: &QueryBox) -> u32 {
        let mut hit = f32x8::splat(0.0).simd_le(f32x8::splat(0.0));
        for a in 0..3 {
            hit &= q.min[a].simd_le(f32x8::new(self.max[a]));
            hit &= f32x8::new(self.min[a]).simd_le(q.max[a]);
        }
        hit.to_bitmask()
    }

    fn free_child(&self) -> Option<usize> {
        self.child.iter().position(|&c| c == NONE)
    }
}

/// A query box, each face splat across the lanes.
pub(crate) struct QueryBox {
    min: [f32x8; 3],
    max: [f32x8; 3],
}

impl QueryBox {
    #[inline(always)]
    fn new(b: &Aabb3) -> Self {
        Self {
            min: [0, 1, 2].map(|a| f32x8::splat(b.min[a])),
            max: [0, 1, 2].map(|a| f32x8::splat(b.max[a])),
        }
    }
}

/// A reference to a child: a node, or a proxy.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Child {
    Node(u32),
    Proxy(u32),
}

impl Child {
    fn encode(self) -> u32 {
        match self {
            Child::Node(n) => n,
            Child::Proxy(id) => id | LEAF,
        }
    }
    fn decode(c: u32) -> Option<Self> {
        match c {
            NONE => None,
            c if c & LEAF != 0 => Some(Child::Proxy(c & !LEAF)),
            c => Some(Child::Node(c)),
        }
    }
}

/// A descent's stack: on the caller's stack up to [`STACK_INLINE`] entries (a depth-first
/// descent holds at most seven a level and one, so a tree of 9 levels, 134M proxies when
/// built), on the heap beyond, so that no tree, however deep its inserts made it, loses a
/// hit.
pub(crate) struct Stack<T> {
    inline: [T; STACK_INLINE],
    len: usize,
    spill: Vec<T>,
}

/// The entries a [`Stack`] holds on the caller's stack.
const STACK_INLINE: usize = 64;

impl<T: Copy + Default> Stack<T> {
    #[inline(always)]
    pub(crate) fn new() -> Self {
        Self {
            inline: [T::default(); STACK_INLINE],
            len: 0,
            spill: Vec::new(),
        }
    }

    #[inline(always)]
    pub(crate) fn push(&mut self, x: T) {
        if self.len < STACK_INLINE {
            self.inline[self.len] = x;
            self.len += 1;
        } else {
            self.spill.push(x);
        }
    }

    #[inline(always)]
    pub(crate) fn pop(&mut self) -> Option<T> {
        if let Some(x) = self.spill.pop() {
            return Some(x);
        }
        self.len = self.len.checked_sub(1)?;
        Some(self.inline[self.len])
    }
}

/// The traversal's tasks before it runs depth first: enough to share among threads.
const FRONTIER: usize = 256;

/// The task of the pairs within node `n`.
fn task_within(n: u32) -> u64 {
    u64::from(n) << 32 | u64::from(NONE)
}

/// The task of the pairs across slots `x` and `y`.
fn task_across(x: Slot, y: Slot) -> u64 {
    u64::from(x.0) << 32 | u64::from(y.0)
}

/// The half surface area of a box: the cost of visiting it, up to a constant.
#[inline(always)]
pub(crate) fn area(b: &Aabb3) -> f32 {
    let d = b.max - b.min;
    d.x * d.y + d.y * d.z + d.z * d.x
}

/// True when the closed boxes share a point.
#[inline(always)]
pub(crate) fn overlap(a: &Aabb3, b: &Aabb3) -> bool {
    a.min.cmple(b.max).all() && b.min.cmple(a.max).all()
}

/// A wide hierarchy; node 0 is the root and always exists.
#[derive(Clone, Debug)]
pub(crate) struct Hierarchy {
    nodes: Vec<Node>,
    free: Vec<u32>,
    /// A build's centres and unfinished nodes, kept so that a rebuild does not fault its
    /// pages in again.
    centres: Vec<Centre>,
    tasks: Vec<Task>,
    /// The epoch of the marks in use: a node's marks count only in it ([`Node::epoch`]).
    epoch: u32,
}

impl Default for Hierarchy {
    fn default() -> Self {
        Self {
            nodes: alloc::vec![Node::new(Slot(NONE))],
            free: Vec::new(),
            centres: Vec::new(),
            tasks: Vec::new(),
            epoch: 1,
        }
    }
}

/// Where a hierarchy's changes send each proxy: `place(id, slot)` after every move.
pub(crate) trait Places {
    fn place(&mut self, id: u32, slot: Slot);
}

impl Hierarchy {
    /// The box of the proxy in `slot`.
    pub(crate) fn get(&self, slot: Slot) -> Aabb3 {
        self.nodes[slot.node() as usize].get(slot.child())
    }

    /// Asks for the cache lines of `slot`'s node (all four: the box columns, the children
    /// and the parent).
    #[inline(always)]
    pub(crate) fn prefetch(&self, slot: Slot) {
        self.prefetch_node(slot.node());
    }

    /// Asks for the cache lines of node `n` (all four).
    #[inline(always)]
    fn prefetch_node(&self, n: u32) {
        if let Some(node) = self.nodes.get(n as usize) {
            crate::simd::prefetch(&node.min[0]);
            crate::simd::prefetch(&node.min[2]);
            crate::simd::prefetch(&node.max[1]);
            crate::simd::prefetch(&node.child);
        }
    }

    /// Asks for the cache lines of the parent of `slot`'s node (reading the node's parent
    /// field, so best once the node itself was asked for).
    #[inline(always)]
    pub(crate) fn prefetch_parent(&self, slot: Slot) {
        if let Some(node) = self.nodes.get(slot.node() as usize)
            && node.parent.0 != NONE
        {
            self.prefetch(node.parent);
        }
    }

    /// The number of nodes in use.
    pub(crate) fn nodes(&self) -> usize {
        self.nodes.len() - self.free.len()
    }

    /// True when the hierarchy holds no proxy (its root has no child).
    pub(crate) fn is_empty(&self) -> bool {
        self.nodes[0].child.iter().all(|&c| c == NONE)
    }

    fn alloc(&mut self, parent: Slot) -> u32 {
        let node = Node::new(parent);
        match self.free.pop() {
            Some(n) => {
                self.nodes[n as usize] = node;
                n
            }
            None => {
                self.nodes.push(node);
                (self.nodes.len() - 1) as u32
            }
        }
    }

    /// Recomputes the unions above node `n` while a parent's slot changes.
    fn refit_up(&mut self, mut n: u32) {
        loop {
            let node = &self.nodes[n as usize];
            let parent = node.parent;
            if parent.0 == NONE {
                return;
            }
            let b = node.union();
            let p = &mut self.nodes[parent.node() as usize];
            if p.get(parent.child()) == b {
                return;
            }
            p.set(parent.child(), &b);
            n = parent.node();
        }
    }

    /// Writes the box of the proxy in `slot`, and enlarges the slots above it until one
    /// already contains the box (Box2D's early exit): a slot then still contains its node's
    /// union, with room left where a child shrank or left, until the next build. The slot
    /// is marked changed as [`Hierarchy::mark_changed`] marks it, on the same walk up, while
    /// the nodes are in the cache.
    #[inline(always)]
    pub(crate) fn set(&mut self, slot: Slot, b: &Aabb3) {
        let node = &mut self.nodes[slot.node() as usize];
        node.set(slot.child(), b);
        let mark = node.mark(slot.child(), self.epoch);
        self.enlarge_above(slot.node(), b, mark);
    }

    /// Writes the box of the proxy in `slot` and marks its path as
    /// [`Hierarchy::mark_changed`] does, leaving the slots above it short until
    /// [`Hierarchy::refit_marked`].
    #[inline(always)]
    pub(crate) fn set_leaf(&mut self, slot: Slot, b: &Aabb3) {
        self.nodes[slot.node() as usize].set(slot.child(), b);
        self.mark_changed(slot);
    }

    /// Makes the slot of every marked node the union of its children's slots, children
    /// first (depth first, each node after its marked child nodes), with `stack` as
    /// scratch. Every proxy whose slot changed since the last clear must have its path
    /// marked ([`Hierarchy::set_leaf`], [`Hierarchy::set`]): then every slot contains its
    /// node's union again, exactly on the marked paths, and loose as before elsewhere.
    pub(crate) fn refit_marked(&mut self, stack: &mut Vec<u64>) {
        /// The low bit of a stack entry: the node's marked children are done.
        const DONE: u64 = 1;
        stack.clear();
        stack.push(0);
        while let Some(entry) = stack.pop() {
            let n = (entry >> 1) as u32;
            let node = &self.nodes[n as usize];
            if entry & DONE == 0 {
                stack.push(entry | DONE);
                let mut marks = node.marks(self.epoch);
                while marks != 0 {
                    let k = marks.trailing_zeros() as usize;
                    marks &= marks - 1;
                    let c = node.child[k];
                    if c != NONE && c & LEAF == 0 {
                        self.prefetch_node(c);
                        stack.push(u64::from(c) << 1);
                    }
                }
            } else if node.parent.0 != NONE {
                let (parent, union) = (node.parent, node.union());
                self.nodes[parent.node() as usize].set(parent.child(), &union);
            }
        }
    }

    /// Enlarges the slots above node `n` to contain `b`, up to the first that does, and
    /// when `mark` (node `n` took its first mark) marks them, up to the first node already
    /// marked: one walk up for both.
    #[inline(always)]
    fn enlarge_above(&mut self, mut n: u32, b: &Aabb3, mut mark: bool) {
        let epoch = self.epoch;
        let mut enlarge = true;
        while enlarge || mark {
            let parent = self.nodes[n as usize].parent;
            if parent.0 == NONE {
                return;
            }
            let p = &mut self.nodes[parent.node() as usize];
            if enlarge {
                let old = p.get(parent.child());
                enlarge = !(old.min.cmple(b.min).all() && b.max.cmple(old.max).all());
                if enlarge {
                    p.set(parent.child(), &old.union(b));
                }
            }
            if mark {
                mark = p.mark(parent.child(), epoch);
            }
            n = parent.node();
        }
    }

    /// Adds proxy `id` with box `b`: down from the root, into the first node with a free
    /// slot, else into the child whose box grows least in area (a proxy there becomes a
    /// node of two). Returns its slot.
    pub(crate) fn insert(&mut self, id: u32, b: &Aabb3, places: &mut impl Places) -> Slot {
        let mut n = 0u32;
        loop {
            let node = &self.nodes[n as usize];
            if let Some(k) = node.free_child() {
                let node = &mut self.nodes[n as usize];
                node.set(k, b);
                node.child[k] = Child::Proxy(id).encode();
                self.enlarge_above(n, b, false);
                let slot = Slot::new(n, k);
                places.place(id, slot);
                return slot;
            }
            let mut best = (f32::INFINITY, f32::INFINITY, 0);
            for k in 0..WIDTH {
                let c = node.get(k);
                let grown = area(&c.union(b)) - area(&c);
                let key = (grown, area(&c), k);
                if key.0 < best.0 || (key.0 == best.0 && key.1 < best.1) {
                    best = key;
                }
            }
            // An area of ±∞ or NaN (boxes near `f32::MAX`) compares false: child 0.
            let k = best.2;
            match Child::decode(node.child[k]) {
                Some(Child::Node(c)) => n = c,
                Some(Child::Proxy(other)) => {
                    let old = node.get(k);
                    let m = self.alloc(Slot::new(n, k));
                    let node = &mut self.nodes[m as usize];
                    node.set(0, &old);
                    node.child[0] = Child::Proxy(other).encode();
                    self.nodes[n as usize].child[k] = Child::Node(m).encode();
                    places.place(other, Slot::new(m, 0));
                    n = m;
                }
                None => unreachable!("a node without a free slot has eight children"),
            }
        }
    }

    /// Takes the proxy in `slot` out; a node left empty leaves its parent, and the unions
    /// above are recomputed.
    pub(crate) fn remove(&mut self, slot: Slot) {
        let (mut n, mut k) = (slot.node(), slot.child());
        loop {
            let node = &mut self.nodes[n as usize];
            node.child[k] = NONE;
            node.set(k, &Aabb3::EMPTY);
            if n == 0 || node.child.iter().any(|&c| c != NONE) {
                self.refit_up(n);
                return;
            }
            let parent = node.parent;
            self.free.push(n);
            (n, k) = (parent.node(), parent.child());
        }
    }

    /// Calls `hit(id, box)` for every proxy whose box overlaps `q`, with a stack of its own
    /// (no heap allocation unless the tree is deeper than a [`Stack`] holds inline).
    #[inline(always)]
    pub(crate) fn query_one(&self, q: &Aabb3, mut hit: impl FnMut(u32, &Aabb3)) {
        let splat = QueryBox::new(q);
        let mut stack = Stack::<u32>::new();
        stack.push(0);
        while let Some(n) = stack.pop() {
            let node = &self.nodes[n as usize];
            let mut bits = node.overlaps(&splat);
            while bits != 0 {
                let k = bits.trailing_zeros() as usize;
                bits &= bits - 1;
                match node.child[k] {
                    // An empty slot (+∞ below −∞) meets only a query reaching both.
                    NONE => {}
                    c if c & LEAF != 0 => hit(c & !LEAF, &node.get(k)),
                    c => stack.push(c),
                }
            }
        }
    }

    /// Runs a cast ([`Sweep`]) through the hierarchy: calls `hit(id, entry, limit)` for
    /// every proxy whose box it may meet within `*limit` (every one the exact cast meets),
    /// with a bound on its entry never beyond the exact entry; `hit` may lower `*limit`
    /// (a clip), and returns false to stop the cast. The children of a node are taken
    /// nearest entry first, and any whose entry has passed the limit by then are skipped.
    /// Returns false when `hit` stopped it. `tame`: no box of the hierarchy has a coordinate
    /// beyond [`F32_REACH`](super::slab::F32_REACH), so the `f32` test may take the cast.
    #[inline(always)]
    pub(crate) fn cast(
        &self,
        sweep: &Sweep,
        tame: bool,
        limit: &mut f32,
        hit: impl FnMut(u32, f32, &mut f32) -> bool,
    ) -> bool {
        // The tests inlined into the caller's target features (out of line, the lanes
        // would run one at a time).
        if sweep.fits_f32(tame) {
            self.descend(
                limit,
                #[inline(always)]
                |node, l| sweep.test_f32(&node.min, &node.max, l),
                hit,
            )
        } else {
            self.descend(
                limit,
                #[inline(always)]
                |node, l| {
                    // The entries of the children met rounded down to `f32`: still never
                    // beyond the exact ones.
                    let (enter, bits) = sweep.test(&node.min, &node.max, f64::from(l));
                    let (mut down, mut met) = ([0.0; WIDTH], bits);
                    while met != 0 {
                        let k = met.trailing_zeros() as usize;
                        met &= met - 1;
                        down[k] = round_down(enter[k]);
                    }
                    (down, bits)
                },
                hit,
            )
        }
    }

    /// The descent of [`Hierarchy::cast`], with the slab test `test(node, limit)` (the
    /// children's entry bounds and the bits of those met).
    #[inline(always)]
    fn descend(
        &self,
        limit: &mut f32,
        test: impl Fn(&Node, f32) -> ([f32; WIDTH], u32),
        mut hit: impl FnMut(u32, f32, &mut f32) -> bool,
    ) -> bool {
        let mut stack = Stack::<(f32, u32)>::new();
        stack.push((0.0, 0));
        while let Some((entry, c)) = stack.pop() {
            if entry > *limit {
                continue;
            }
            if c & LEAF != 0 {
                if !hit(c & !LEAF, entry, limit) {
                    return false;
                }
                continue;
            }
            let node = &self.nodes[c as usize];
            let (enter, mut bits) = test(node, *limit);
            // The children met, by entry (insertion into at most eight).
            let (mut order, mut len) = ([0usize; WIDTH], 0);
            while bits != 0 {
                let k = bits.trailing_zeros() as usize;
                bits &= bits - 1;
                if node.child[k] == NONE {
                    continue;
                }
                let mut i = len;
                while i > 0 && enter[order[i - 1]] > enter[k] {
                    order[i] = order[i - 1];
                    i -= 1;
                }
                order[i] = k;
                len += 1;
            }
            // Farthest pushed first, so that the nearest is taken next.
            for &k in order[..len].iter().rev() {
                let c = node.child[k];
                if c & LEAF == 0 {
                    self.prefetch_node(c);
                }
                stack.push((enter[k], c));
            }
        }
        true
    }

    /// Calls `hit(i, id, box)` for every query `qs[i]` and every proxy whose box overlaps
    /// it, with `stack` as scratch: the same calls as one [`Hierarchy::query_one`] per box (in
    /// another order), but the queries descend together, so a node that several of them
    /// reach is read once. Each stack entry carries the queries that reached it (a node,
    /// then a byte of them); at most [`WIDTH`] queries (more would spill into the node's
    /// bits: checked).
    #[inline(always)]
    pub(crate) fn query_group(
        &self,
        qs: &[Aabb3],
        stack: &mut Vec<u64>,
        mut hit: impl FnMut(usize, u32, &Aabb3),
    ) {
        assert!(
            qs.len() <= WIDTH,
            "at most {WIDTH} queries descend together"
        );
        let mut splat = [const { None }; WIDTH];
        for (s, q) in splat.iter_mut().zip(qs) {
            *s = Some(QueryBox::new(q));
        }
        stack.clear();
        stack.push((1u64 << qs.len()) - 1);
        while let Some(entry) = stack.pop() {
            let node = &self.nodes[(entry >> 8) as usize];
            // Per child, the queries that go down into it.
            let mut down = [0u8; WIDTH];
            let mut any = 0u32;
            let mut active = entry as u8;
            while active != 0 {
                let i = active.trailing_zeros() as usize;
                active &= active - 1;
                let Some(q) = &splat[i] else { continue };
                let mut bits = node.overlaps(q);
                while bits != 0 {
                    let k = bits.trailing_zeros() as usize;
                    bits &= bits - 1;
                    let c = node.child[k];
                    if c == NONE {
                        // An empty slot (+∞ below −∞) meets only a query reaching both.
                        continue;
                    }
                    if c & LEAF != 0 {
                        hit(i, c & !LEAF, &node.get(k));
                    } else {
                        down[k] |= 1 << i;
                        any |= 1 << k;
                    }
                }
            }
            while any != 0 {
                let k = any.trailing_zeros() as usize;
                any &= any - 1;
                let c = node.child[k];
                self.prefetch_node(c);
                stack.push(u64::from(c) << 8 | u64::from(down[k]));
            }
        }
    }

    /// Marks the slots from `slot` (a changed proxy's) up to the root as holding a changed
    /// proxy, up to the first node already marked (whose slot above is).
    pub(crate) fn mark_changed(&mut self, mut slot: Slot) {
        while slot.0 != NONE {
            let node = &mut self.nodes[slot.node() as usize];
            if !node.mark(slot.child(), self.epoch) {
                return;
            }
            slot = node.parent;
        }
    }

    /// Clears every mark at once: a new epoch. When the epoch wraps, every node's is reset
    /// first, so that no old mark can count again.
    pub(crate) fn clear_marks(&mut self) {
        self.epoch = self.epoch.wrapping_add(1);
        if self.epoch == 0 {
            for node in &mut self.nodes {
                node.epoch = 0;
            }
            self.epoch = 1;
        }
    }

    /// The marks of node `n`.
    #[inline(always)]
    fn marks(&self, n: u32) -> u8 {
        self.nodes[n as usize].marks(self.epoch)
    }

    /// True when `slot` is marked.
    #[inline(always)]
    fn is_changed(&self, slot: Slot) -> bool {
        self.marks(slot.node()) >> slot.child() & 1 != 0
    }

    /// The traversal's first tasks: the root's own pairs, expanded breadth first (their
    /// pairs of proxies handed to `pair` on the way) until there are at least
    /// [`FRONTIER`] tasks or none; each task is then run depth first by
    /// [`Hierarchy::changed_pairs_from`], in order, on one thread or in ordered parts on
    /// several: the pairs come in the same order either way.
    pub(crate) fn changed_frontier(
        &self,
        tasks: &mut Vec<u64>,
        pair: impl FnMut(u32, &Aabb3, u32, &Aabb3),
    ) {
        tasks.clear();
        tasks.push(task_within(0));
        self.frontier(self, tasks, pair);
    }

    /// [`Hierarchy::changed_frontier`] of the traversal of this hierarchy against `other`:
    /// the pairs of a proxy of each with a changed one, each reached once, from the pair of
    /// the two roots' slots that hold them (then `x` is of this hierarchy, `y` of
    /// `other`). Run with [`Hierarchy::changed_pairs_from`] with the same `other`.
    pub(crate) fn changed_frontier_with(
        &self,
        other: &Hierarchy,
        tasks: &mut Vec<u64>,
        pair: impl FnMut(u32, &Aabb3, u32, &Aabb3),
    ) {
        tasks.clear();
        let (a, b) = (&self.nodes[0], &other.nodes[0]);
        let (marks_a, marks_b) = (
            u32::from(a.marks(self.epoch)),
            u32::from(b.marks(other.epoch)),
        );
        for i in 0..WIDTH {
            if a.child[i] == NONE {
                continue;
            }
            let mut bits = b.overlaps(&QueryBox::new(&a.get(i)));
            if marks_a >> i & 1 == 0 {
                bits &= marks_b;
            }
            while bits != 0 {
                let j = bits.trailing_zeros() as usize;
                bits &= bits - 1;
                if b.child[j] != NONE {
                    tasks.push(task_across(Slot::new(0, i), Slot::new(0, j)));
                }
            }
        }
        self.frontier(other, tasks, pair);
    }

    /// Expands `tasks` breadth first until there are at least [`FRONTIER`] or none.
    fn frontier(
        &self,
        other: &Hierarchy,
        tasks: &mut Vec<u64>,
        mut pair: impl FnMut(u32, &Aabb3, u32, &Aabb3),
    ) {
        let mut first = 0;
        while first < tasks.len() && tasks.len() - first < FRONTIER {
            let task = tasks[first];
            first += 1;
            self.expand(other, task, &mut pair, |t| tasks.push(t));
        }
        tasks.drain(..first);
    }

    /// Runs each of `tasks` depth first (see [`Hierarchy::changed_frontier`]; `other` is
    /// this hierarchy for its traversal against itself), with `stack` as scratch.
    #[inline(always)]
    pub(crate) fn changed_pairs_from(
        &self,
        other: &Hierarchy,
        tasks: &[u64],
        stack: &mut Vec<u64>,
        mut pair: impl FnMut(u32, &Aabb3, u32, &Aabb3),
    ) {
        for &task in tasks {
            stack.clear();
            stack.push(task);
            while let Some(task) = stack.pop() {
                self.expand(other, task, &mut pair, |t| stack.push(t));
            }
        }
    }

    /// One step of the traversal of pairs with a changed proxy: a task is a node whose
    /// children's pairs are wanted ([`task_within`], only in a traversal of a hierarchy
    /// against itself), or two slots, `x` of this hierarchy and `y` of `other`, whose boxes
    /// overlap and one of which is marked ([`task_across`]). Each pair of proxies is
    /// reached once, from their lowest common node (or the roots' slots that hold them):
    /// within a node, each pair of its children whose boxes overlap and one of which is
    /// marked; across two slots, the children of the one that is a node (the larger, when
    /// both are) against the other, those that overlap it and are marked or meet a marked
    /// one. Node boxes contain their children's, so no pair of overlapping proxies is
    /// missed.
    #[inline(always)]
    fn expand(
        &self,
        other: &Hierarchy,
        task: u64,
        pair: &mut impl FnMut(u32, &Aabb3, u32, &Aabb3),
        mut push: impl FnMut(u64),
    ) {
        let (x, y) = ((task >> 32) as u32, task as u32);
        if y == NONE {
            let node = &self.nodes[x as usize];
            let dirty = node.marks(self.epoch);
            for i in 0..WIDTH {
                let c = node.child[i];
                if c == NONE {
                    continue;
                }
                let mut bits = node.overlaps(&QueryBox::new(&node.get(i))) & (0xfe << i) & 0xff;
                if dirty >> i & 1 == 0 {
                    bits &= u32::from(dirty);
                }
                while bits != 0 {
                    let j = bits.trailing_zeros() as usize;
                    bits &= bits - 1;
                    push(task_across(Slot::new(x, i), Slot::new(x, j)));
                }
                if c & LEAF == 0 && dirty >> i & 1 != 0 {
                    self.prefetch_node(c);
                    push(task_within(c));
                }
            }
            return;
        }
        let (sx, sy) = (Slot(x), Slot(y));
        let (cx, cy) = (
            self.nodes[sx.node() as usize].child[sx.child()],
            other.nodes[sy.node() as usize].child[sy.child()],
        );
        let (bx, by) = (self.get(sx), other.get(sy));
        if cx & LEAF != 0 && cy & LEAF != 0 {
            pair(cx & !LEAF, &bx, cy & !LEAF, &by);
            return;
        }
        // Descend the node side: x when y is a proxy or x is the larger node.
        let x_down = cy & LEAF != 0 || (cx & LEAF == 0 && area(&bx) >= area(&by));
        let (tree, down, rest, rest_box, rest_changed) = if x_down {
            (self, cx, sy, by, other.is_changed(sy))
        } else {
            (other, cy, sx, bx, self.is_changed(sx))
        };
        let node = &tree.nodes[down as usize];
        let mut bits = node.overlaps(&QueryBox::new(&rest_box));
        if !rest_changed {
            bits &= u32::from(node.marks(tree.epoch));
        }
        while bits != 0 {
            let j = bits.trailing_zeros() as usize;
            bits &= bits - 1;
            if node.child[j] == NONE {
                continue;
            }
            let s = Slot::new(down, j);
            push(if x_down {
                task_across(s, rest)
            } else {
                task_across(rest, s)
            });
        }
    }

    /// Every proxy and its box, depth first, into `out`.
    fn collect(&self, out: &mut Vec<(u32, Aabb3)>) {
        let mut stack = alloc::vec![0u32];
        while let Some(n) = stack.pop() {
            let node = &self.nodes[n as usize];
            for k in (0..WIDTH).rev() {
                match Child::decode(node.child[k]) {
                    Some(Child::Proxy(id)) => out.push((id, node.get(k))),
                    Some(Child::Node(c)) => stack.push(c),
                    None => {}
                }
            }
        }
    }

    /// Every proxy and its box, depth first.
    pub(crate) fn proxies(&self) -> Vec<(u32, Aabb3)> {
        let mut out = Vec::new();
        self.collect(&mut out);
        out
    }

    /// Starts a build over `boxes` (ids and boxes): see [`Hierarchy::step`]. The tree is
    /// empty until the build finishes.
    pub(crate) fn begin(&mut self, boxes: impl IntoIterator<Item = (u32, Aabb3)>) {
        let mut centres = take(&mut self.centres);
        centres.clear();
        centres.extend(boxes.into_iter().map(|(id, b)| Centre::of(id, &b)));
        self.begin_with(centres);
    }

    /// Starts a build over the proxies of `from` (their boxes now), reading its nodes in
    /// memory order.
    pub(crate) fn begin_from(&mut self, from: &Hierarchy) {
        let mut centres = take(&mut self.centres);
        centres.clear();
        for node in &from.nodes {
            for k in 0..WIDTH {
                let c = node.child[k];
                // A freed node has no children left.
                if c != NONE && c & LEAF != 0 {
                    centres.push(Centre::of(c & !LEAF, &node.get(k)));
                }
            }
        }
        // Room for the nodes of a full tree over this many proxies, the most a build takes
        // (see [`Task`]), so that no step of a spread build moves the nodes to a larger
        // allocation (`docs/decisions.md`, "A spread build's nodes reserved at its start").
        self.nodes.clear();
        self.nodes.reserve(full_tree_nodes(centres.len()));
        self.begin_with(centres);
    }

    fn begin_with(&mut self, centres: Vec<Centre>) {
        self.nodes.clear();
        self.free.clear();
        self.nodes.push(Node::new(Slot(NONE)));
        self.tasks.clear();
        if !centres.is_empty() {
            self.tasks.push(Task::new(0, centres.len()));
        }
        self.centres = centres;
    }

    /// The work of a build over `n` proxies, in the units of [`Hierarchy::step`]'s budget:
    /// `log2(n)` levels of splits, and the placing of each proxy.
    pub(crate) fn build_work(n: usize) -> usize {
        n * ((usize::BITS - n.leading_zeros()) as usize + PLACE_WORK)
    }

    /// Runs the build begun by [`Hierarchy::begin`] or [`Hierarchy::begin_from`] for about
    /// `budget` units of work (a split of `m` centres costs `m`, placing a proxy
    /// [`PLACE_WORK`]; a split is never cut short), placing each proxy with the box
    /// `box_of(id)` gives when it is placed (`None`: the proxy left, and its slot
    /// stays empty). Returns true when the build is done and the unions are set.
    ///
    /// The build splits top-down near the median of the widest spread of centres until every
    /// group of a node fits a subtree one level shallower (at most eight groups, see
    /// [`Task`]): balanced, so it has `⌈log8 n⌉` levels (one for `n <= 8`) whatever the
    /// distribution. Every placed proxy's slot goes to `places`.
    pub(crate) fn step(
        &mut self,
        mut budget: usize,
        mut box_of: impl FnMut(u32) -> Option<Aabb3>,
        places: &mut impl Places,
    ) -> bool {
        while let Some(mut task) = self.tasks.pop() {
            if budget == 0 {
                self.tasks.push(task);
                return false;
            }
            // Up to eight groups, each the split of the largest one near its median, at a
            // whole number of units.
            let (g, (start, end)) = task.largest();
            let unit = task.unit as usize;
            if usize::from(task.count) < WIDTH && end - start > unit {
                let mid = start + (end - start).div_ceil(unit) / 2 * unit;
                split_at_median(&mut self.centres[start..end], mid - start);
                task.groups[g] = (start as u32, mid as u32);
                task.groups[usize::from(task.count)] = (mid as u32, end as u32);
                task.count += 1;
                budget = budget.saturating_sub(end - start);
                self.tasks.push(task);
                continue;
            }
            let n = task.node;
            for k in 0..usize::from(task.count) {
                let (start, end) = task.group(k);
                let child = if end - start == 1 {
                    budget = budget.saturating_sub(PLACE_WORK);
                    let id = self.centres[start].1;
                    let Some(b) = box_of(id) else { continue };
                    self.nodes[n as usize].set(k, &b);
                    places.place(id, Slot::new(n, k));
                    Child::Proxy(id)
                } else {
                    let m = self.alloc(Slot::new(n, k));
                    let mut sub = Task::new(start, end);
                    sub.node = m;
                    self.tasks.push(sub);
                    Child::Node(m)
                };
                self.nodes[n as usize].child[k] = child.encode();
            }
        }
        // Every node was allocated after its parent: one pass from the last sets the
        // unions bottom-up, and takes out the nodes left without children (all their
        // proxies left before they were placed), so that no empty node stays linked.
        for n in (1..self.nodes.len()).rev() {
            let node = &self.nodes[n];
            let (parent, b) = (node.parent, node.union());
            let empty = node.child.iter().all(|&c| c == NONE);
            let p = &mut self.nodes[parent.node() as usize];
            p.set(parent.child(), &b);
            if empty {
                p.child[parent.child()] = NONE;
                self.free.push(n as u32);
            }
        }
        true
    }

    /// Writes the box of the placed proxy in `slot` during a build, before the unions are
    /// set (so nothing above it changes).
    pub(crate) fn set_during_build(&mut self, slot: Slot, b: &Aabb3) {
        self.nodes[slot.node() as usize].set(slot.child(), b);
    }
}

/// What placing a proxy costs a build, against one centre of a split: a read of the proxy's
/// box in the old hierarchy, scattered, and a node write. A rough weight
/// (`docs/decisions.md`, "A build's weight for placing a proxy").
const PLACE_WORK: usize = 16;

/// A node of a build being filled: its groups of centres, the largest split until every
/// group fits one unit (then there are at most eight).
///
/// Each group but one holds a whole number of units, the most proxies a subtree one level
/// shallower can hold (`8^(⌈log8 n⌉ − 1)` for `n` centres), so that every node of the tree
/// is full but those on one path from the root: at most [`full_tree_nodes`], about `n / 7`,
/// in `⌈log8 n⌉` levels. (Splits at the plain median left bottom nodes of two or three proxies:
/// 37,449 nodes for 100K proxies, against 14,288 now.)
#[derive(Clone, Copy, Debug)]
struct Task {
    node: u32,
    groups: [(u32, u32); WIDTH],
    count: u8,
    unit: u32,
}

impl Task {
    fn new(start: usize, end: usize) -> Self {
        let mut groups = [(0, 0); WIDTH];
        groups[0] = (start as u32, end as u32);
        let mut unit = 1;
        while unit < (end - start).div_ceil(WIDTH) {
            unit *= WIDTH;
        }
        Self {
            node: 0,
            groups,
            count: 1,
            unit: unit as u32,
        }
    }

    fn group(&self, k: usize) -> (usize, usize) {
        let (s, e) = self.groups[k];
        (s as usize, e as usize)
    }

    /// The largest group and its range.
    fn largest(&self) -> (usize, (usize, usize)) {
        (0..usize::from(self.count))
            .map(|k| (k, self.group(k)))
            .max_by_key(|(_, (s, e))| e - s)
            .unwrap_or((0, (0, 0)))
    }
}

/// The nodes of a full tree over `n` proxies: `⌈n/8⌉` above the proxies, `⌈n/64⌉` above
/// those, and so on up to the root.
fn full_tree_nodes(n: usize) -> usize {
    let (mut level, mut nodes) = (n, 0);
    loop {
        level = level.div_ceil(WIDTH);
        nodes += level;
        if level <= 1 {
            return nodes.max(1);
        }
    }
}

/// A box's centre (`min/2 + max/2`, which cannot overflow) and its proxy: 16 bytes, what a
/// build moves.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Centre([f32; 3], u32);

impl Centre {
    fn of(id: u32, b: &Aabb3) -> Self {
        let c = b.min * 0.5 + b.max * 0.5;
        Centre([c.x, c.y, c.z], id)
    }
}

/// Reorders `centres` so that the first `mid` are the smallest along the axis where they
/// spread widest.
fn split_at_median(centres: &mut [Centre], mid: usize) {
    let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
    for c in centres.iter() {
        for a in 0..3 {
            lo[a] = lo[a].min(c.0[a]);
            hi[a] = hi[a].max(c.0[a]);
        }
    }
    let axis = widest_axis(lo, hi);
    centres.select_nth_unstable_by(mid, |a, b| a.0[axis].total_cmp(&b.0[axis]));
}

/// The axis along which `lo..hi` spreads widest (spreads in `f64`, where they cannot
/// overflow): what a build splits along.
fn widest_axis(lo: [f32; 3], hi: [f32; 3]) -> usize {
    let spread = [0, 1, 2].map(|a| f64::from(hi[a]) - f64::from(lo[a]));
    if spread[0] >= spread[1] && spread[0] >= spread[2] {
        0
    } else if spread[1] >= spread[2] {
        1
    } else {
        2
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each proxy's slot, as the hierarchy moves it.
    struct Slots(Vec<u32>);

    impl Places for Slots {
        fn place(&mut self, id: u32, slot: Slot) {
            self.0[id as usize] = slot.0;
        }
    }

    /// A stack gives its entries back last in, first out, past its inline part too.
    #[test]
    fn a_stack_spills_to_the_heap_and_loses_nothing() {
        let mut stack = Stack::<u32>::new();
        for round in 0..2 {
            for x in 0..1000 {
                stack.push(x);
            }
            for x in (0..1000).rev() {
                assert_eq!(stack.pop(), Some(x), "round {round}");
            }
            assert_eq!(stack.pop(), None);
        }
    }

    /// True when `slot` and every slot above it are marked.
    fn path_marked(h: &Hierarchy, mut slot: Slot) -> bool {
        while slot.0 != NONE {
            if !h.is_changed(slot) {
                return false;
            }
            slot = h.nodes[slot.node() as usize].parent;
        }
        true
    }

    fn any_mark(h: &Hierarchy) -> bool {
        (0..h.nodes.len() as u32).any(|n| h.marks(n) != 0)
    }

    /// A write marks its path up to the root; a clear drops every mark at once; and when the
    /// epoch wraps, a mark left from the epoch it wraps to does not count again.
    #[test]
    fn writes_mark_their_paths_and_a_clear_drops_every_mark_even_when_the_epoch_wraps() {
        let mut h = Hierarchy::default();
        let mut slots = Slots(alloc::vec![NONE; 100]);
        let b = |x: f32| Aabb3::new(Vec3A::splat(x), Vec3A::splat(x + 1.0));
        for id in 0..100 {
            h.insert(id, &b(id as f32 * 0.5), &mut slots);
        }
        let slot = |id: usize| Slot(slots.0[id]);
        assert!(h.nodes.len() > 8 && !any_mark(&h));
        // A box far away: the write enlarges every slot above it, and marks them.
        h.set(slot(5), &b(500.0));
        assert!(path_marked(&h, slot(5)) && !h.is_changed(slot(6)));
        h.clear_marks();
        assert!(!any_mark(&h));
        // A mark made in epoch 1, then left (at a proxy whose node is not on proxy 7's
        // path): the epoch counts up to the last before it wraps, where proxy 7's path is
        // marked; the clear that wraps it back to 1 must drop both.
        assert_ne!(slot(90).node(), slot(7).node());
        h.epoch = 1;
        h.set(slot(90), &b(44.0));
        h.epoch = u32::MAX;
        h.mark_changed(slot(7));
        assert!(path_marked(&h, slot(7)) && !h.is_changed(slot(90)));
        h.clear_marks();
        assert_eq!(h.epoch, 1);
        assert!(!any_mark(&h));
        h.set(slot(90), &b(44.5));
        assert!(path_marked(&h, slot(90)) && !h.is_changed(slot(7)));
    }
}
