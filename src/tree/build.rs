//! The build: binned SAH over primitive centroids, deterministic, `O(n log n)`, no
//! recursion (an explicit work stack, so that no input can overflow the call stack).
//!
//! Nodes come out in depth-first pre-order: every node's descendants follow it, so a
//! bottom-up pass (refit) is a reverse scan, and the left child of a node that is not a
//! primitive is the next node.

use super::nodes::{NodeAccess, PrimBox, Ref};
use alloc::vec;
use alloc::vec::Vec;

/// Bins per axis.
const BINS: usize = 16;

impl PrimBox {
    /// Half the surface area, in `f64` (no overflow).
    fn half_area(&self) -> f64 {
        let d: [f64; 3] =
            core::array::from_fn(|k| (f64::from(self.max[k]) - f64::from(self.min[k])).max(0.0));
        d[0] * d[1] + d[1] * d[2] + d[2] * d[0]
    }

    fn centroid(&self, k: usize) -> f64 {
        0.5 * (f64::from(self.min[k]) + f64::from(self.max[k]))
    }
}

/// The topology of a tree: the children of each node in pre-order, and the root.
pub(crate) struct Topology {
    pub children: Vec<[Ref; 2]>,
    pub root: Ref,
}

/// Builds the topology over `boxes` (at least one, fewer than `2^31`).
pub(crate) fn build(boxes: &[PrimBox]) -> Topology {
    let n = boxes.len();
    let mut ids: Vec<u32> = (0..n as u32).collect();
    let mut children: Vec<[Ref; 2]> = Vec::with_capacity(n.saturating_sub(1));
    let mut root = Ref::primitive(0);
    // (start, end, link, depth): the range to place, where its reference goes, and its
    // depth.
    #[derive(Clone, Copy)]
    enum ParentLink {
        Root,
        Child(usize, usize),
    }
    // Past this depth every split is a median split: SAH alone can peel one primitive per
    // level off adversarial input (O(n²)); with the guard the depth, and so the work per
    // primitive, stays O(log n).
    let max_depth = 2 * (usize::BITS - n.leading_zeros()) as usize + 16;
    let mut work = vec![(0usize, n, ParentLink::Root, 0usize)];
    while let Some((start, end, link, depth)) = work.pop() {
        let r = if end - start == 1 {
            Ref::primitive(ids[start])
        } else {
            let index = children.len();
            children.push([Ref::primitive(0); 2]);
            let range = &mut ids[start..end];
            let mid = if depth < max_depth {
                split(boxes, range)
            } else {
                median(boxes, range)
            } + start;
            // Right first, so that the left range is placed next (pre-order).
            work.push((mid, end, ParentLink::Child(index, 1), depth + 1));
            work.push((start, mid, ParentLink::Child(index, 0), depth + 1));
            Ref::node(index as u32)
        };
        match link {
            ParentLink::Root => root = r,
            ParentLink::Child(parent, side) => children[parent][side] = r,
        }
    }
    Topology { children, root }
}

/// Partitions `ids` (at least two) at the SAH-best bin boundary and returns the size of
/// the left part (in `1..len`); the median by index when no boundary separates them.
fn split(boxes: &[PrimBox], ids: &mut [u32]) -> usize {
    let len = ids.len();
    let mut best: Option<(f64, usize, f64, f64)> = None; // cost, axis, lo, scale
    let mut best_bin = 0;
    for axis in 0..3 {
        let (lo, hi) = ids
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &i| {
                let c = boxes[i as usize].centroid(axis);
                (l.min(c), h.max(c))
            });
        if hi <= lo {
            continue;
        }
        let scale = BINS as f64 / (hi - lo);
        let mut bins = [(PrimBox::EMPTY, 0usize); BINS];
        for &i in ids.iter() {
            let b = bin(boxes[i as usize].centroid(axis), lo, scale);
            bins[b].0 = bins[b].0.union(&boxes[i as usize]);
            bins[b].1 += 1;
        }
        // Sweep from the right for suffix areas, then from the left.
        let mut right = [(0.0, 0usize); BINS];
        let (mut acc, mut count) = (PrimBox::EMPTY, 0);
        for b in (1..BINS).rev() {
            acc = acc.union(&bins[b].0);
            count += bins[b].1;
            right[b] = (acc.half_area(), count);
        }
        let (mut acc, mut count) = (PrimBox::EMPTY, 0);
        for b in 0..BINS - 1 {
            acc = acc.union(&bins[b].0);
            count += bins[b].1;
            let (area_r, count_r) = right[b + 1];
            if count == 0 || count_r == 0 {
                continue;
            }
            let cost = acc.half_area() * count as f64 + area_r * count_r as f64;
            if best.is_none_or(|(c, ..)| cost < c) {
                best = Some((cost, axis, lo, scale));
                best_bin = b;
            }
        }
    }
    let Some((_, axis, lo, scale)) = best else {
        return len / 2;
    };
    // In-place partition: ids whose bin is at most best_bin go left.
    let mut left = 0;
    for k in 0..len {
        if bin(boxes[ids[k] as usize].centroid(axis), lo, scale) <= best_bin {
            ids.swap(left, k);
            left += 1;
        }
    }
    if left == 0 || left == len {
        len / 2
    } else {
        left
    }
}

/// Partitions `ids` (at least two) at the median centroid of the widest centroid axis (ties
/// by id, so deterministic) and returns the size of the left half.
fn median(boxes: &[PrimBox], ids: &mut [u32]) -> usize {
    let spread = |k: usize| {
        let (lo, hi) = ids
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &i| {
                let c = boxes[i as usize].centroid(k);
                (l.min(c), h.max(c))
            });
        hi - lo
    };
    let axis = (0..3).fold(0, |best, k| if spread(k) > spread(best) { k } else { best });
    let mid = ids.len() / 2;
    ids.select_nth_unstable_by(mid, |&a, &b| {
        let (ca, cb) = (
            boxes[a as usize].centroid(axis),
            boxes[b as usize].centroid(axis),
        );
        ca.total_cmp(&cb).then(a.cmp(&b))
    });
    mid
}

#[inline]
fn bin(c: f64, lo: f64, scale: f64) -> usize {
    (((c - lo) * scale) as usize).min(BINS - 1)
}

/// The exact box of every node (the union of its primitives' boxes), by one reverse scan
/// of the pre-order: children follow their parent.
pub(crate) fn node_boxes(
    children: &[[Ref; 2]],
    prim: impl Fn(u32) -> PrimBox,
) -> (Vec<[f32; 3]>, Vec<[f32; 3]>) {
    let mut boxes = vec![PrimBox::EMPTY; children.len()];
    for i in (0..children.len()).rev() {
        let get = |r: Ref, boxes: &[PrimBox]| {
            if r.is_primitive() {
                prim(r.index())
            } else {
                boxes[r.index() as usize]
            }
        };
        let [a, b] = children[i];
        boxes[i] = get(a, &boxes).union(&get(b, &boxes));
    }
    boxes.iter().map(|b| (b.min, b.max)).unzip()
}

/// A layout over a topology whose primitive `i` has the box `prim(i)`.
pub(crate) fn layout<L: NodeAccess>(children: &[[Ref; 2]], prim: impl Fn(u32) -> PrimBox) -> L {
    let (min, max) = node_boxes(children, &prim);
    L::from_boxes(children, &min, &max, prim)
}
