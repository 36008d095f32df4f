//! The queries a tree answers beside its frames: the proxies whose boxes overlap a box or
//! contain a point, and every pair of overlapping proxies.

use super::{BroadphaseError, DynamicTree, Layers, Tier};
use crate::aabb::Aabb3;
use alloc::vec::Vec;
use glam::Vec3A;

impl DynamicTree {
    /// Calls `hit(id)` for every placed proxy, of any kind, whose fat box overlaps `b`
    /// (closed boxes: touching counts) and whose layers interact with `layers`
    /// ([`Layers::interacts_with`]; [`Layers::ALL`] finds every proxy with a membership and
    /// a filter). Each proxy is found once, in an unspecified order. No heap allocation
    /// (unless the tree is deeper than 9 levels, which inserts alone can make it).
    ///
    /// # Errors
    /// [`BroadphaseError::InvalidQuery`] for a box with a NaN face or a face below its
    /// opposite one (infinite faces are fine); nothing is searched then.
    pub fn query(
        &self,
        b: &Aabb3,
        layers: Layers,
        mut hit: impl FnMut(u32),
    ) -> Result<(), BroadphaseError> {
        if !b.min.cmple(b.max).all() {
            // A NaN face compares false too.
            return Err(BroadphaseError::InvalidQuery);
        }
        // While every proxy is in the common layers, one check answers for all.
        let every = self.unplain == 0;
        if every && !layers.interacts_with(self.common) {
            return Ok(());
        }
        let proxies = &self.proxies;
        for tier in [Tier::Moving, Tier::Fixed] {
            self.tier(tier).query_one(b, |id, _| {
                if every || proxies[id as usize].layers.interacts_with(layers) {
                    hit(id);
                }
            });
        }
        Ok(())
    }

    /// Calls `hit(id)` for every placed proxy whose fat box contains `p` (closed boxes) and
    /// whose layers interact with `layers`: [`DynamicTree::query`] with the box of `p`
    /// alone.
    ///
    /// # Errors
    /// [`BroadphaseError::InvalidQuery`] for a NaN coordinate; nothing is searched then.
    pub fn query_point(
        &self,
        p: Vec3A,
        layers: Layers,
        hit: impl FnMut(u32),
    ) -> Result<(), BroadphaseError> {
        self.query(&Aabb3::new(p, p), layers, hit)
    }

    /// Every pair of placed proxies whose fat boxes overlap and whose kinds and layers admit
    /// the pair, as `(smaller, larger)`, ascending: what a narrow phase starts from.
    #[must_use]
    pub fn overlapping_pairs(&self) -> Vec<(u32, u32)> {
        let mut out = Vec::new();
        let admits = |a: u32, b: u32| {
            let (pa, pb) = (self.proxies[a as usize], self.proxies[b as usize]);
            self.kind_pairs.admit(pa.kind, pb.kind) && pa.layers.interacts_with(pb.layers)
        };
        for (tier, h) in [(Tier::Moving, &self.moving), (Tier::Fixed, &self.fixed)] {
            for (id, b) in h.proxies() {
                // A moving proxy meets both hierarchies, a static one the moving proxies.
                let mut meet = |other: u32, _: &Aabb3| {
                    if other > id && admits(id, other) {
                        out.push((id, other));
                    }
                };
                self.moving.query_one(&b, &mut meet);
                if tier == Tier::Moving {
                    self.fixed.query_one(&b, &mut meet);
                }
            }
        }
        out.sort_unstable();
        out
    }
}
