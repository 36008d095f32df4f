//! The tree's upkeep: a new hierarchy built beside the one in use, a share of the work a
//! frame, which takes over when done.

use super::{DynamicTree, Place, Placer, Rebuild, Tier};
use crate::broadphase::hierarchy::{Hierarchy, Slot};
use core::mem::take;

/// The fixed hierarchy is rebuilt once it has taken this many times fewer moves and inserts
/// per proxy than the moving one: static proxies rarely move, but a level inserted one by
/// one leaves their hierarchy unbalanced until a build.
const FIXED_PATIENCE: f32 = 32.0;

/// A spread rebuild takes over before its proxies have taken this share of the moves each
/// that started it: it builds from the boxes of its start, so where most proxies move every
/// frame a rebuild spread over many frames is stale when it takes over
/// (`docs/decisions.md`, "A spread rebuild's deadline where proxies move fast").
const STALE_SHARE: f32 = 0.25;

impl DynamicTree {
    /// Rebuilds both hierarchies from their proxies, balanced (near-median splits of the
    /// widest spread of centres, every node full but those on one path from the root).
    /// Boxes and pairs do not change; queries get faster where moves have left node boxes
    /// loose or mixed distant proxies under one node.
    pub fn rebuild(&mut self) {
        for tier in [Tier::Moving, Tier::Fixed] {
            self.begin_rebuild(tier, usize::MAX, usize::MAX);
            self.continue_rebuild();
        }
    }

    /// Sets when [`DynamicTree::maintain`] starts a rebuild: once the tree has taken this
    /// many moves and inserts per moving proxy since its last build (default 16;
    /// `f32::INFINITY` never, leaving [`DynamicTree::rebuild`] to the caller). The static
    /// proxies' hierarchy is rebuilt after a thirty-second of that per static proxy (half a
    /// move or insert each, by default).
    pub fn set_rebuild_after(&mut self, moves_per_proxy: f32) {
        self.rebuild_after = moves_per_proxy;
    }

    /// Sets over about how many [`DynamicTree::maintain`] calls a rebuild is spread (default
    /// 32; 1 rebuilds at once, in the call that starts it). Fewer frames give each a larger
    /// share of the work; more leave the old hierarchy in use longer.
    pub fn set_rebuild_frames(&mut self, frames: u32) {
        self.rebuild_frames = frames.max(1);
    }

    /// The tree's upkeep, between [`DynamicTree::write`] and [`DynamicTree::report`].
    ///
    /// Moves leave node boxes loose and mix distant proxies under one node, so once a
    /// hierarchy has taken enough moves since its last build
    /// ([`DynamicTree::set_rebuild_after`]) a new one is built beside it, a share of the
    /// work in each call ([`DynamicTree::set_rebuild_frames`]), while the old one serves
    /// the frames: no frame pays for a whole rebuild. Where proxies move fast, each call
    /// takes a larger share, so that the new hierarchy takes over before its proxies have
    /// taken a quarter of that many moves each since it began (at the rate of the last
    /// frame), since a rebuild starts from the boxes of its first frame. Until the new
    /// hierarchy takes over, each write goes to both, and proxies inserted or removed
    /// meanwhile are brought up to date in it when its build is done. Returns true when a new hierarchy took over.
    /// Boxes and pairs do not change; the rebuild needs a second hierarchy's memory, kept
    /// between rebuilds (its nodes, 256 bytes per about 7 proxies after a build, the
    /// centres it sorts, 16 bytes per proxy, and the proxies' slots in it, 4 bytes per id).
    /// One hierarchy is rebuilt at a time, the static proxies' first when both are due.
    pub fn maintain(&mut self) -> bool {
        if self.rebuilding.is_none() {
            let due = |tier: Tier| self.moves[tier as usize] > self.trigger(tier);
            let tier = if due(Tier::Fixed) {
                Tier::Fixed
            } else if due(Tier::Moving) {
                Tier::Moving
            } else {
                return false;
            };
            let work = Hierarchy::build_work(self.tier_len[tier as usize]);
            let budget = match self.rebuild_frames {
                1 => usize::MAX,
                frames => work.div_ceil(frames as usize).max(1),
            };
            self.begin_rebuild(tier, budget, work);
        }
        self.continue_rebuild()
    }

    /// Starts a rebuild of `tier` into the spare hierarchy from its proxies as they are, of
    /// about `work` units, to advance by at least `budget` units per
    /// [`DynamicTree::continue_rebuild`]. A rebuild under way is dropped.
    fn begin_rebuild(&mut self, tier: Tier, budget: usize, work: usize) {
        let from = match tier {
            Tier::Moving => &self.moving,
            Tier::Fixed => &self.fixed,
        };
        self.spare.begin_from(from);
        // The tier's placed proxies are absent until the build places them; the others
        // keep their places (only the tier's are read back).
        self.spare_at.clear();
        self.spare_at
            .extend(self.at.iter().map(|&at| match at.slot_in(tier) {
                Some(_) => Place::ABSENT,
                None => at,
            }));
        self.replay.clear();
        self.rebuilding = Some(Rebuild {
            tier,
            budget,
            left: work,
            seen: 0,
        });
        self.moves[tier as usize] = 0;
    }

    /// Advances the rebuild under way by its budget; once its build is done, brings the
    /// proxies inserted, removed, parked, unparked or moved between tiers meanwhile up to
    /// date in it and makes it the tier's hierarchy. Returns true then.
    fn continue_rebuild(&mut self) -> bool {
        let Some(mut rebuild) = self.rebuilding else {
            return false;
        };
        let tier = rebuild.tier;
        // The frames left before the deadline, at the rate of moves since the last step,
        // share the work left.
        let deadline = (self.trigger(tier) as f32 * STALE_SHARE) as u64;
        let moves = self.moves[tier as usize];
        let rate = moves.saturating_sub(rebuild.seen);
        rebuild.seen = moves;
        let budget = match rate {
            0 => rebuild.budget,
            rate => {
                let frames = (deadline.saturating_sub(moves) / rate).max(1) as usize;
                rebuild.budget.max(rebuild.left.div_ceil(frames))
            }
        };
        rebuild.left = rebuild.left.saturating_sub(budget);
        self.rebuilding = Some(rebuild);
        let (hierarchy, at) = (
            match tier {
                Tier::Moving => &self.moving,
                Tier::Fixed => &self.fixed,
            },
            &self.at,
        );
        let mut places = Placer {
            at: &mut self.spare_at,
            tier,
        };
        // A proxy is placed with the box it has now, if it is still placed in the tier; a
        // later write goes to both hierarchies (`DynamicTree::set`).
        let box_of = |id: u32| at[id as usize].slot_in(tier).map(|s| hierarchy.get(s));
        if !self.spare.step(budget, box_of, &mut places) {
            return false;
        }
        let replay = take(&mut self.replay);
        self.spare_at.resize(self.at.len(), Place::ABSENT);
        for &id in &replay {
            let i = id as usize;
            let mut places = Placer {
                at: &mut self.spare_at,
                tier,
            };
            match (self.at[i].slot_in(tier), places.at[i].slot_in(tier)) {
                (Some(now), Some(then)) => self.spare.set(then, &hierarchy.get(now)),
                (Some(now), None) => {
                    self.spare.insert(id, &hierarchy.get(now), &mut places);
                }
                (None, Some(then)) => {
                    self.spare.remove(then);
                    places.at[i] = self.at[i];
                }
                (None, None) => places.at[i] = self.at[i],
            }
        }
        match tier {
            Tier::Moving => core::mem::swap(&mut self.moving, &mut self.spare),
            Tier::Fixed => core::mem::swap(&mut self.fixed, &mut self.spare),
        }
        // Every proxy placed in the tier is placed in the new hierarchy (the build placed
        // it, or the replay did).
        for (now, new) in self.at.iter_mut().zip(&self.spare_at) {
            if now.slot_in(tier).is_some() {
                *now = *new;
            }
        }
        self.paths_marked = false;
        self.replay = replay;
        self.rebuilding = None;
        true
    }

    /// The moves and inserts since its last build past which `tier` is rebuilt.
    fn trigger(&self, tier: Tier) -> u64 {
        let patience = match tier {
            Tier::Moving => 1.0,
            Tier::Fixed => FIXED_PATIENCE,
        };
        let proxies = self.tier_len[tier as usize].max(1) as f32;
        let moves = self.rebuild_after / patience * proxies;
        // An infinite or NaN trigger is never reached (the cast saturates, NaN would be 0).
        if moves.is_nan() {
            u64::MAX
        } else {
            moves as u64
        }
    }

    /// Proxy `id`'s slot in the hierarchy a rebuild under way fills, once placed there.
    #[inline(always)]
    pub(super) fn spare_slot(&self, id: u32) -> Option<Slot> {
        let tier = self.rebuilding?.tier;
        self.spare_at.get(id as usize)?.slot_in(tier)
    }

    /// Notes that proxy `id` is inserted, removed, parked, unparked or moved between
    /// tiers: proxies may have moved between slots, so the report marks the changed paths
    /// again, and the rebuild under way brings such proxies up to date when its build is
    /// done.
    pub(super) fn restructured(&mut self, id: u32) {
        self.paths_marked = false;
        if self.rebuilding.is_some() {
            self.replay.push(id);
        }
    }
}
