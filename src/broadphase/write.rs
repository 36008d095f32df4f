//! A frame's first half: the moved proxies' new boxes written into their hierarchies.

use super::{BroadphaseError, DynamicTree, Pairs, Place, REFIT_FROM, Tier, accepts, tame};
use crate::aabb::Aabb3;
use crate::layout::BoxSource;

impl DynamicTree {
    /// One frame: [`DynamicTree::write`], [`DynamicTree::maintain`], then
    /// [`DynamicTree::report`].
    ///
    /// # Errors
    /// As [`DynamicTree::write`], before anything changes.
    pub fn update(
        &mut self,
        moved: &[u32],
        fat: impl BoxSource<3>,
        pairs: &mut Pairs,
    ) -> Result<(), BroadphaseError> {
        self.update_on(moved, fat, pairs, false)
    }

    /// A frame, its report on the rayon pool when `parallel` (and the feature) say so.
    fn update_on(
        &mut self,
        moved: &[u32],
        fat: impl BoxSource<3>,
        pairs: &mut Pairs,
        parallel: bool,
    ) -> Result<(), BroadphaseError> {
        self.write(moved, fat)?;
        self.maintain();
        self.report_on(pairs, parallel);
        Ok(())
    }

    /// [`DynamicTree::update`] with [`DynamicTree::report_par`] (feature `rayon`).
    ///
    /// # Errors
    /// As [`DynamicTree::write`], before anything changes.
    #[cfg(feature = "rayon")]
    pub fn update_par(
        &mut self,
        moved: &[u32],
        fat: impl BoxSource<3>,
        pairs: &mut Pairs,
    ) -> Result<(), BroadphaseError> {
        self.update_on(moved, fat, pairs, true)
    }

    /// The tree's half of a frame: the proxies in `moved` (strictly ascending ids, as
    /// [`Moved::indices`](crate::Moved::indices)) take their boxes from `fat` (indexed by id,
    /// in any box layout the batch writes), and each enlarges the boxes above it up to the
    /// first that already contains it (once half of the proxies or more move, one pass
    /// recomputes the boxes above them instead). A static proxy moves as any other, in its own
    /// hierarchy (a teleported door: one write, and its pairs with the moving proxies at the
    /// next report). Moved ids not in the tree are ignored; a
    /// refused box parks its proxy (module docs). The pairs wait for [`DynamicTree::report`].
    ///
    /// # Errors
    /// [`BroadphaseError::Unsorted`], [`BroadphaseError::MissingBox`] or
    /// [`BroadphaseError::Layout`], before anything changes.
    pub fn write(&mut self, moved: &[u32], fat: impl BoxSource<3>) -> Result<(), BroadphaseError> {
        if !moved.is_sorted_by(|a, b| a < b) {
            return Err(BroadphaseError::Unsorted);
        }
        let len = fat.len().map_err(|_| BroadphaseError::Layout)?;
        if let Some(&id) = moved.last()
            && id as usize >= len
        {
            return Err(BroadphaseError::MissingBox { id, len });
        }
        // In id order, which reads `fat`, `at` and `mark` as streams; the nodes, scattered,
        // are asked for a few proxies ahead so that their cache misses overlap.
        // Two stages: a proxy's node sixteen ahead, its parent (which the first write
        // of the path above reads) eight ahead, once the node's parent field is in.
        const AHEAD: usize = 8;
        // Once half of the proxies or more move, each write only sets its proxy's slot and
        // marks its path, and one pass then recomputes the slots of the marked nodes from
        // their children, children first: a visit per marked node rather than a walk up per
        // proxy, and exact slots for the report, whose traversal then visits nearly every
        // node (rapier updates its leaves in place and refits above them in this regime
        // too). A park or an unpark meanwhile keeps its own path's slots containing, as
        // always; the marked paths stay whole, since a node keeps its parent until it is
        // freed, and a node allocated anew starts unmarked below a marked slot.
        let refit = moved.len().saturating_mul(REFIT_FROM) >= self.tier_len[Tier::Moving as usize];
        for (k, &id) in moved.iter().enumerate() {
            if let Some(&next) = moved.get(k + 2 * AHEAD) {
                self.prefetch(next, false);
            }
            if let Some(&next) = moved.get(k + AHEAD) {
                self.prefetch(next, true);
            }
            if self.contains(id) {
                let (min, max) = fat.get(id as usize);
                self.set(id, &Aabb3::new(min.into(), max.into()), refit);
            }
        }
        if refit {
            self.moving.refit_marked(&mut self.stack);
        }
        Ok(())
    }

    /// Asks for the cache lines of proxy `id`'s node, or of its parent.
    #[inline(always)]
    fn prefetch(&self, id: u32, parent: bool) {
        if let Some((tier, slot)) = self.at.get(id as usize).and_then(|at| at.slot()) {
            let h = self.tier(tier);
            if parent {
                h.prefetch_parent(slot);
            } else {
                h.prefetch(slot);
                // A rebuild under way takes the write too.
                if let Some(slot) = self.spare_slot(id) {
                    self.spare.prefetch(slot);
                }
            }
        }
    }

    /// Gives proxy `id` (in the tree) box `b`, or parks it when `b` is refused; with
    /// `refit`, the slots above a moving proxy wait for `Hierarchy::refit_marked`.
    pub(super) fn set(&mut self, id: u32, b: &Aabb3, refit: bool) {
        self.note(id);
        let at = self.at[id as usize];
        if !accepts(b) {
            self.refused.push(id);
            if at != Place::PARKED {
                self.restructured(id);
                self.take_out(id);
                self.at[id as usize] = Place::PARKED;
            }
            return;
        }
        self.wild |= !tame(b);
        let Some((tier, slot)) = at.slot() else {
            self.restructured(id);
            self.place(id, b);
            return;
        };
        match tier {
            Tier::Moving if refit => self.moving.set_leaf(slot, b),
            Tier::Moving => self.moving.set(slot, b),
            Tier::Fixed => self.fixed.set(slot, b),
        }
        self.moves[tier as usize] += 1;
        if let Some(slot) = self.spare_slot(id) {
            self.spare.set_during_build(slot, b);
        }
    }
}
