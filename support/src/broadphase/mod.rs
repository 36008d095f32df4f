//! The broadphase example's scene and its two pipelines on parry3d's `Bvh`, shared with
//! the broadphase bench, a peer tree on obvhs's `Bvh2`, and rapier's own broadphase.

pub mod bvh;
pub mod obvhs;
pub mod queries;
pub mod rapier;
pub mod scene;

use std::collections::HashSet;

use bvkit::Aabb3;
use parry3d::bounding_volume::{Aabb, BoundingVolume};

/// The milliseconds of a frame's stages, and what they did.
#[derive(Default, Clone, Copy)]
pub struct Frame {
    /// World or fat boxes, tree leaves, optimisation, refit, pairs. C writes its leaves
    /// and enlarges their paths in one step (its "leaves"), optimises by rebuilding when
    /// `DynamicTree::maintain` says so, and reports the pairs that began.
    pub ms: [f64; 5],
    pub rewritten: usize,
    /// The pairs that began, and those that ended (C and R report both).
    pub pairs: usize,
    pub ended: usize,
}

impl Frame {
    pub fn total(&self) -> f64 {
        self.ms.iter().sum()
    }
}

/// A parry3d box from ours.
pub(crate) fn parry_box(b: &Aabb3) -> Aabb {
    Aabb::new(b.min.into(), b.max.into())
}

/// Every pair of boxes that overlap (closed boxes), by a sweep along x.
pub(crate) fn overlapping(boxes: &[Aabb]) -> HashSet<(u32, u32)> {
    let mut order: Vec<u32> = (0..boxes.len() as u32).collect();
    order.sort_by(|&a, &b| {
        boxes[a as usize]
            .mins
            .x
            .total_cmp(&boxes[b as usize].mins.x)
    });
    let mut pairs = HashSet::new();
    for (k, &a) in order.iter().enumerate() {
        let ba = &boxes[a as usize];
        for &b in &order[k + 1..] {
            let bb = &boxes[b as usize];
            if bb.mins.x > ba.maxs.x {
                break;
            }
            if ba.intersects(bb) {
                pairs.insert((a.min(b), a.max(b)));
            }
        }
    }
    pairs
}
