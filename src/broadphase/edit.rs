//! Building a tree, and adding, removing and refiltering its proxies.

use super::{
    BodyKind, BroadphaseError, Change, DynamicTree, KindPairs, Layers, MAX_ID, MAX_NODES, Partners,
    Place, Proxy, Tier, accepts, tame,
};
use crate::aabb::Aabb3;
use crate::layout::BoxSource;
use alloc::vec::Vec;

impl DynamicTree {
    /// A tree whose proxy `i` has box `i` of `fat`, every proxy dynamic and in every layer,
    /// built balanced (as [`DynamicTree::rebuild`]); every pair that overlaps begins at the
    /// first report. A box equal to [`Aabb3::EMPTY`] (as in the padding lanes of the last
    /// AoSoA block, or for a body with no geometry) leaves its id out of the tree.
    ///
    /// # Errors
    /// [`BroadphaseError::InvalidBox`] for the first other NaN, infinite or inverted box,
    /// [`BroadphaseError::IdTooLarge`] for more than `2^31 − 2` boxes,
    /// [`BroadphaseError::OutOfMemory`] when the per-id tables cannot be allocated, and
    /// [`BroadphaseError::Layout`] for inconsistent columns.
    pub fn from_boxes(fat: impl BoxSource<3>) -> Result<Self, BroadphaseError> {
        Self::from_boxes_with(fat, |_| (BodyKind::Dynamic, Layers::ALL))
    }

    /// [`DynamicTree::from_boxes`] with proxy `i` of kind and layers `proxy(i)`: how a
    /// level's static boxes go in at once, each hierarchy built balanced.
    ///
    /// # Errors
    /// As [`DynamicTree::from_boxes`].
    pub fn from_boxes_with(
        fat: impl BoxSource<3>,
        mut proxy: impl FnMut(u32) -> (BodyKind, Layers),
    ) -> Result<Self, BroadphaseError> {
        let len = fat.len().map_err(|_| BroadphaseError::Layout)?;
        if len > MAX_ID as usize {
            return Err(BroadphaseError::IdTooLarge { id: MAX_ID });
        }
        let mut items = [Vec::new(), Vec::new()];
        let mut proxies = Vec::new();
        let mut tree = Self::default();
        proxies
            .try_reserve_exact(len)
            .map_err(|_| BroadphaseError::OutOfMemory {
                id: (len as u32).saturating_sub(1),
            })?;
        let mut common = None;
        for i in 0..len {
            let (min, max) = fat.get(i);
            let b = Aabb3::new(min.into(), max.into());
            let (kind, layers) = proxy(i as u32);
            proxies.push(Proxy { layers, kind });
            if b == Aabb3::EMPTY {
                continue;
            }
            if !accepts(&b) {
                return Err(BroadphaseError::InvalidBox { id: i as u32 });
            }
            tree.wild |= !tame(&b);
            items[kind.tier() as usize].push((i as u32, b));
            tree.tier_len[kind.tier() as usize] += 1;
            let common = *common.get_or_insert(layers);
            tree.unplain += usize::from(!proxies[i].is_plain(common));
        }
        tree.common = common.unwrap_or(Layers::ALL);
        let mut partners = Partners::default();
        partners
            .grow(len)
            .map_err(|_| BroadphaseError::OutOfMemory {
                id: (len as u32).saturating_sub(1),
            })?;
        tree.at = alloc::vec![Place::ABSENT; len];
        tree.mark = alloc::vec![0; len];
        tree.proxies = proxies;
        tree.partners = partners;
        tree.len = items[0].len() + items[1].len();
        // Every proxy is a change, its path not marked.
        tree.paths_marked = false;
        for (id, _) in items.iter().flatten() {
            tree.pending.push(Change::new(*id, &Aabb3::EMPTY));
            tree.mark[*id as usize] = tree.pending.len() as u32;
        }
        for (tier, items) in [Tier::Moving, Tier::Fixed].into_iter().zip(items) {
            let (h, mut places) = tree.tier_mut(tier);
            h.begin(items);
            h.step(
                usize::MAX,
                |id| {
                    let (min, max) = fat.get(id as usize);
                    Some(Aabb3::new(min.into(), max.into()))
                },
                &mut places,
            );
        }
        Ok(tree)
    }

    /// Room in the per-id tables for `id`.
    fn grow(&mut self, id: u32) -> Result<(), BroadphaseError> {
        if id >= MAX_ID {
            return Err(BroadphaseError::IdTooLarge { id });
        }
        let len = id as usize + 1;
        if self.at.len() < len {
            // Reserved first, so that a refused id changes nothing; the spare's table too,
            // which a rebuild later grows to this length where it cannot fail.
            let more = len - self.at.len();
            self.at
                .try_reserve_exact(more)
                .and_then(|()| self.mark.try_reserve_exact(more))
                .and_then(|()| self.proxies.try_reserve_exact(more))
                .and_then(|()| {
                    self.spare_at
                        .try_reserve_exact(len.saturating_sub(self.spare_at.len()))
                })
                .and_then(|()| self.partners.grow(len))
                .map_err(|_| BroadphaseError::OutOfMemory { id })?;
            self.at.resize(len, Place::ABSENT);
            self.mark.resize(len, 0);
            self.proxies.resize(len, Proxy::default());
        }
        Ok(())
    }

    /// Notes that `id`'s box is about to change (its box at the last report is the one it
    /// has now, unless it already changed since).
    pub(super) fn note(&mut self, id: u32) {
        if self.mark[id as usize] == 0 {
            let old = self.current(id);
            self.pending.push(Change::new(id, &old));
            self.mark[id as usize] = self.pending.len() as u32;
        }
    }

    /// Notes that `id`'s kind or layers are about to change: whether its pairs held at the
    /// last report is then read from its partners.
    fn note_refiltered(&mut self, id: u32) {
        self.note(id);
        self.tag_refiltered(id);
        // Its path must be marked for the report's traversal, as a write marks it.
        if let Some((tier, slot)) = self.at[id as usize].slot() {
            match tier {
                Tier::Moving => self.moving.mark_changed(slot),
                Tier::Fixed => self.fixed.mark_changed(slot),
            }
        }
    }

    /// Tags `id`'s pending change as refiltered: its pairs at the last report are read from
    /// its partners.
    fn tag_refiltered(&mut self, id: u32) {
        let m = self.mark[id as usize] as usize;
        self.pending[m - 1].tagged |= Change::REFILTERED;
        self.refiltered = true;
    }

    /// Takes placed proxy `id` out of its hierarchy.
    pub(super) fn take_out(&mut self, id: u32) {
        if let Some((tier, slot)) = self.at[id as usize].slot() {
            self.tier_mut(tier).0.remove(slot);
        }
    }

    /// Places proxy `id` with box `b` in its kind's hierarchy.
    pub(super) fn place(&mut self, id: u32, b: &Aabb3) {
        let tier = self.proxies[id as usize].kind.tier();
        let (h, mut places) = self.tier_mut(tier);
        h.insert(id, b, &mut places);
        self.moves[tier as usize] += 1;
    }

    /// Sets proxy `id`'s kind and layers, keeping the counts.
    fn set_proxy(&mut self, id: u32, proxy: Proxy) {
        let old = self.proxies[id as usize];
        self.tier_len[old.kind.tier() as usize] -= 1;
        self.unplain -= usize::from(!old.is_plain(self.common));
        self.tier_len[proxy.kind.tier() as usize] += 1;
        self.unplain += usize::from(!proxy.is_plain(self.common));
        self.proxies[id as usize] = proxy;
    }

    /// Adds proxy `id` with fat box `fat`, dynamic and in every layer; its pairs begin at
    /// the next report (if it still has a box then: see the module docs on what a report
    /// compares). The tree's memory grows with the largest id (28 bytes per id up to it).
    ///
    /// # Errors
    /// [`BroadphaseError::InvalidBox`] for a NaN, infinite or inverted box,
    /// [`BroadphaseError::Duplicate`] when `id` is in the tree,
    /// [`BroadphaseError::IdTooLarge`] from `2^31 − 2` on, [`BroadphaseError::OutOfMemory`]
    /// when the per-id tables cannot grow to `id`; the tree is then unchanged.
    pub fn insert(&mut self, id: u32, fat: Aabb3) -> Result<(), BroadphaseError> {
        self.insert_with(id, fat, BodyKind::Dynamic, Layers::ALL)
    }

    /// [`DynamicTree::insert`] of a proxy of kind `kind` in layers `layers`.
    ///
    /// # Errors
    /// As [`DynamicTree::insert`].
    pub fn insert_with(
        &mut self,
        id: u32,
        fat: Aabb3,
        kind: BodyKind,
        layers: Layers,
    ) -> Result<(), BroadphaseError> {
        if !accepts(&fat) {
            return Err(BroadphaseError::InvalidBox { id });
        }
        if self.tier(kind.tier()).nodes() >= MAX_NODES {
            return Err(BroadphaseError::OutOfMemory { id });
        }
        self.grow(id)?;
        if self.at[id as usize] != Place::ABSENT {
            return Err(BroadphaseError::Duplicate { id });
        }
        self.wild |= !tame(&fat);
        let proxy = Proxy { layers, kind };
        if self.len == 0 {
            // The first proxy of an empty tree sets the common layers.
            self.common = layers;
        }
        self.proxies[id as usize] = proxy;
        self.tier_len[kind.tier() as usize] += 1;
        self.unplain += usize::from(!proxy.is_plain(self.common));
        self.note(id);
        // Removed and inserted again since the last report, it may come back with another
        // kind or other layers: whether its pairs held then is read from its partners.
        self.tag_refiltered(id);
        self.restructured(id);
        self.place(id, &fat);
        self.len += 1;
        Ok(())
    }

    /// Removes proxy `id`; its pairs end at the next report (unless it is back with an
    /// overlapping box by then). Returns false when it was not in the tree.
    pub fn remove(&mut self, id: u32) -> bool {
        if !self.contains(id) {
            return false;
        }
        self.note(id);
        self.restructured(id);
        self.take_out(id);
        let proxy = self.proxies[id as usize];
        self.tier_len[proxy.kind.tier() as usize] -= 1;
        self.unplain -= usize::from(!proxy.is_plain(self.common));
        self.at[id as usize] = Place::ABSENT;
        self.len -= 1;
        true
    }

    /// Gives proxy `id`, of any kind, the fat box `fat`: one proxy's [`DynamicTree::write`]
    /// without a box array (a teleported door, a platform set in place). Its pairs begin and
    /// end at the next report. A static proxy's move is a write in its own hierarchy: one
    /// walk up from its slot, enlarging the boxes above it.
    ///
    /// # Errors
    /// [`BroadphaseError::UnknownId`] when `id` is not in the tree and
    /// [`BroadphaseError::InvalidBox`] for a NaN, infinite or inverted box (a `write` would
    /// park the proxy; here nothing changes).
    pub fn move_proxy(&mut self, id: u32, fat: Aabb3) -> Result<(), BroadphaseError> {
        if !self.contains(id) {
            return Err(BroadphaseError::UnknownId { id });
        }
        if !accepts(&fat) {
            return Err(BroadphaseError::InvalidBox { id });
        }
        self.set(id, &fat, false);
        Ok(())
    }

    /// Makes proxy `id` of kind `kind`. Its pairs begin and end at the next report as the
    /// kinds admit them, as a move's do; a change between static and moving kinds moves
    /// the proxy to the other hierarchy (an insert's cost).
    ///
    /// # Errors
    /// [`BroadphaseError::UnknownId`] when `id` is not in the tree; nothing changes then.
    pub fn set_kind(&mut self, id: u32, kind: BodyKind) -> Result<(), BroadphaseError> {
        if !self.contains(id) {
            return Err(BroadphaseError::UnknownId { id });
        }
        let old = self.proxies[id as usize];
        if old.kind == kind {
            return Ok(());
        }
        if old.kind.tier() != kind.tier() && self.tier(kind.tier()).nodes() >= MAX_NODES {
            return Err(BroadphaseError::OutOfMemory { id });
        }
        self.note_refiltered(id);
        self.set_proxy(id, Proxy { kind, ..old });
        if old.kind.tier() != kind.tier()
            && let Some(b) = self.get(id)
        {
            self.restructured(id);
            self.take_out(id);
            self.place(id, &b);
        }
        Ok(())
    }

    /// Gives proxy `id` layers `layers`. Its pairs begin and end at the next report as the
    /// layers admit them, as a move's do.
    ///
    /// # Errors
    /// [`BroadphaseError::UnknownId`] when `id` is not in the tree; nothing changes then.
    pub fn set_layers(&mut self, id: u32, layers: Layers) -> Result<(), BroadphaseError> {
        if !self.contains(id) {
            return Err(BroadphaseError::UnknownId { id });
        }
        let old = self.proxies[id as usize];
        if old.layers != layers {
            self.note_refiltered(id);
            self.set_proxy(id, Proxy { layers, ..old });
        }
        Ok(())
    }

    /// Sets which pairs of two non-dynamic proxies the tree reports (none by default). The
    /// pairs of every kinematic proxy begin and end at the next report as they now admit.
    pub fn set_kind_pairs(&mut self, kind_pairs: KindPairs) {
        if kind_pairs == self.kind_pairs {
            return;
        }
        self.kind_pairs = kind_pairs;
        for id in 0..self.at.len() as u32 {
            if self.contains(id) && self.proxies[id as usize].kind == BodyKind::Kinematic {
                self.note_refiltered(id);
            }
        }
    }
}
