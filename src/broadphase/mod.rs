//! A dynamic tree of fat boxes that consumes an update's moved set and reports the pairs
//! whose overlap began (and, on request, ended) in each frame.
//!
//! [`DynamicTree`] holds one proxy per body, keyed by the body's index in the slices a
//! [`Batch::update`](crate::Batch::update) reads, with the body's fat box. Each frame the
//! engine hands it [`Moved::indices`](crate::Moved::indices) and the fat boxes, and
//! [`DynamicTree::update`] runs the frame's three steps (each also callable alone):
//! [`write`](DynamicTree::write) rewrites the moved proxies' boxes, enlarging the nodes
//! above each up to the first that already holds it; [`maintain`](DynamicTree::maintain)
//! builds a new hierarchy once enough has moved since the last build, a share in each
//! call, and swaps it in when done;
//! [`report`](DynamicTree::report) searches pairs only from the proxies changed since the
//! last report:
//!
//! ```
//! use bvkit::broadphase::{DynamicTree, Pairs};
//! use bvkit::{Aabb3, Active, Batch, Margin, Method, Moved, Rigid3, Rounding};
//! use glam::{Quat, Vec3A};
//!
//! let local = vec![Aabb3::new(Vec3A::splat(-0.5), Vec3A::splat(0.5)); 3];
//! let mut poses: Vec<Rigid3> = (0..3)
//!     .map(|i| Rigid3::new(Quat::IDENTITY, Vec3A::X * 3.0 * i as f32))
//!     .collect();
//! let batch = Batch::new(Method::AbsMatrix, Rounding::Outward);
//! let margin = Margin::new(0.1, 0.0);
//! let (mut fat, mut moved) = (vec![Aabb3::EMPTY; 3], Moved::new());
//! batch.update(margin, Active::All, &local, &poses, &mut fat, &mut moved)?;
//!
//! let mut tree = DynamicTree::from_boxes(&fat)?;
//! let mut pairs = Pairs::with_ended();
//! tree.update(moved.indices(), &fat, &mut pairs)?; // the first frame: no box overlaps
//! assert!(pairs.begun.is_empty());
//!
//! poses[1].translation.x = 1.0; // body 1 now overlaps body 0
//! batch.update(margin, Active::All, &local, &poses, &mut fat, &mut moved)?;
//! tree.update(moved.indices(), &fat, &mut pairs)?;
//! assert_eq!(pairs.begun, [(0, 1)]);
//!
//! poses[1].translation.x = 3.0;
//! batch.update(margin, Active::All, &local, &poses, &mut fat, &mut moved)?;
//! tree.update(moved.indices(), &fat, &mut pairs)?;
//! assert_eq!(pairs.ended, [(0, 1)]);
//! # Ok::<(), Box<dyn core::error::Error>>(())
//! ```
//!
//! **What a frame reports.** A report compares two snapshots: the pairs whose fat boxes
//! overlap now (closed boxes: touching counts) and those that overlapped at the last
//! report. A pair *begins* when it is in the first and not the second, and *ends* the other
//! way round; a proxy absent or parked at either moment has no box then. What happens in
//! between and is undone by the report is not seen: a remove and an insert of the same id
//! between two reports, with overlapping boxes, report nothing (an engine that reuses a
//! destroyed body's index for a new one in the same frame ends the old body's pairs
//! itself, or reports in between). This is exact: the tree loses no pair and invents none, whatever
//! moved, because a node's box always contains its children's (`min`/`max` round nothing)
//! and each pair's verdict compares the two boxes themselves; the tests and a fuzz target
//! check every report against all pairs by brute force.
//!
//! **Bad boxes.** A NaN, infinite or inverted box is refused: [`DynamicTree::insert`]
//! returns an error, and [`DynamicTree::write`] *parks* the proxy (it leaves the tree, its
//! pairs end, and its id is listed in [`Pairs::refused`]) until a later update gives it a
//! finite box. No such box ever reaches a node, so no later query or rebuild meets one.
//!
//! **Sleep.** Sleeping bodies need no call: they are not in the update's moved list, so
//! their proxies stay as they are, their pairs last, and a moved proxy finds them as any
//! other. (A second hierarchy for the sleeping proxies was measured and dropped: every
//! moved proxy must query both, which cost more than the smaller rebuilds saved.)

mod hierarchy;
mod partners;

use crate::aabb::Aabb3;
use crate::layout::BoxSource;
use alloc::vec::Vec;
use core::fmt;
use core::mem::take;
use glam::Vec3A;
use hierarchy::{Hierarchy, Places, Slot, overlap};
use partners::Partners;

/// Why the tree refused an input.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BroadphaseError {
    /// A box with a NaN or infinite face, or a face below its opposite one.
    InvalidBox {
        /// The proxy.
        id: u32,
    },
    /// [`DynamicTree::insert`] of a proxy already in the tree.
    Duplicate {
        /// The proxy.
        id: u32,
    },
    /// An id of `2^31 − 2` or more (the tree packs ids in 31 bits).
    IdTooLarge {
        /// The id.
        id: u32,
    },
    /// The memory for ids up to this one could not be allocated (the tree keeps 16 bytes
    /// per id up to the largest): the tree is unchanged.
    OutOfMemory {
        /// The id.
        id: u32,
    },
    /// The moved list of [`DynamicTree::write`] (or `update`) is not strictly ascending.
    Unsorted,
    /// A moved id past the end of the fat boxes.
    MissingBox {
        /// The moved id.
        id: u32,
        /// The number of fat boxes.
        len: usize,
    },
    /// The fat boxes' layout is inconsistent (its columns disagree in length).
    Layout,
}

impl fmt::Display for BroadphaseError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::InvalidBox { id } => {
                write!(
                    f,
                    "proxy {id}: the box has a NaN or infinite face, or min > max"
                )
            }
            Self::Duplicate { id } => write!(f, "proxy {id} is already in the tree"),
            Self::IdTooLarge { id } => write!(f, "proxy id {id} is not below 2^31 - 2"),
            Self::OutOfMemory { id } => {
                write!(f, "proxy id {id}: no memory for the tree's per-id tables")
            }
            Self::Unsorted => write!(f, "the moved ids are not strictly ascending"),
            Self::MissingBox { id, len } => {
                write!(f, "moved id {id} is past the {len} fat boxes")
            }
            Self::Layout => write!(f, "the fat boxes' columns disagree in length"),
        }
    }
}

impl core::error::Error for BroadphaseError {}

/// What a frame of [`DynamicTree::update`] found. Each pair is `(smaller id, larger id)`,
/// once; the order of the pairs is deterministic but unspecified.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Pairs {
    /// The pairs whose fat boxes overlap now and did not at the last report.
    pub begun: Vec<(u32, u32)>,
    /// The pairs whose fat boxes overlapped at the last report and do not now (filled only
    /// when made by [`Pairs::with_ended`]).
    pub ended: Vec<(u32, u32)>,
    /// Moved proxies whose new box was refused (NaN, infinite or inverted) since the last
    /// report, once per refusal; each was parked then (a later good box or a remove may
    /// have changed that since).
    pub refused: Vec<u32>,
    ended_wanted: bool,
}

impl Pairs {
    /// Begun pairs only.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// Begun and ended pairs. The tree finds the ended ones in every report (it keeps each
    /// proxy's partners, the proxies whose boxes overlapped its own at the last report, and
    /// reads a changed proxy's), so asking for them costs only their list.
    #[must_use]
    pub fn with_ended() -> Self {
        Self {
            ended_wanted: true,
            ..Self::default()
        }
    }

    fn clear(&mut self) {
        self.begun.clear();
        self.ended.clear();
        self.refused.clear();
    }
}

/// A report traverses the tree against itself once at least one proxy in this many
/// changed, and queries each changed proxy's box otherwise (as rapier reinserts below a
/// sixteenth changed and updates in place above).
const TRAVERSE_FROM: usize = 16;

/// A write refits the slots above its proxies in one pass once at least one proxy in this
/// many moves ([`DynamicTree::write`]). With nearly every body leaving its fat box, that
/// took the frame from 8.7-10.9 to 7.5-9.8 ms at 100,000 bodies; with one in five moving,
/// at 1,000,000, the walks up were faster (AMD EPYC Zen 5, `docs/broadphase.md`).
const REFIT_FROM: usize = 2;

/// Where a proxy is: nowhere, parked, or a slot.
const ABSENT: u32 = u32::MAX;
const PARKED: u32 = u32::MAX - 1;
/// Ids stay below `2^31 − 2`: a child reference packs a proxy id in 31 bits beside the
/// leaf bit, where `2^31 − 1` would read as an empty child.
const MAX_ID: u32 = (1 << 31) - 2;

/// A proxy whose box changed since the last report, and its box then (the empty box when
/// it had none).
#[derive(Clone, Copy, Debug)]
struct Change {
    id: u32,
    /// The old box's `min` then `max` (28 bytes a change, not 48).
    old: [f32; 6],
}

impl Change {
    fn new(id: u32, old: &Aabb3) -> Self {
        let (min, max) = (old.min, old.max);
        Self {
            id,
            old: [min.x, min.y, min.z, max.x, max.y, max.z],
        }
    }

    #[inline(always)]
    fn old(&self) -> Aabb3 {
        let o = &self.old;
        Aabb3::new(Vec3A::new(o[0], o[1], o[2]), Vec3A::new(o[3], o[4], o[5]))
    }
}

/// Sends the hierarchy's proxy moves to the per-proxy places.
struct Placer<'a> {
    at: &'a mut [u32],
}

impl Places for Placer<'_> {
    #[inline(always)]
    fn place(&mut self, id: u32, slot: Slot) {
        self.at[id as usize] = slot.0;
    }
}

/// A box the tree accepts: every face finite, `min <= max`.
fn accepts(b: &Aabb3) -> bool {
    b.min.is_finite() && b.max.is_finite() && b.min.cmple(b.max).all()
}

/// A dynamic tree of fat boxes, fed by the moved set (see the [module docs](self)).
#[derive(Clone, Debug)]
pub struct DynamicTree {
    hierarchy: Hierarchy,
    /// Per id: [`ABSENT`], [`PARKED`], or a slot.
    at: Vec<u32>,
    /// Per id: 1 + its index in `pending`, 0 when it has not changed since the last report.
    mark: Vec<u32>,
    /// Proxies written, inserted, removed or parked since the last report, each with its
    /// box then.
    pending: Vec<Change>,
    /// Proxies refused since the last report.
    refused: Vec<u32>,
    /// True while every change in `pending` has its path marked in `hierarchy` (each write
    /// marks its own): no insert, remove, park or unpark since the last report, and no
    /// rebuild taking over, which move proxies between slots.
    paths_marked: bool,
    /// The pairs that overlapped at the last report, as each proxy's partners.
    partners: Partners,
    len: usize,
    /// The moves and inserts since the last build.
    moves: u64,
    /// [`DynamicTree::set_rebuild_after`].
    rebuild_after: f32,
    /// The hierarchy a rebuild fills, and the proxies' slots in it; kept between rebuilds
    /// for their memory.
    spare: Hierarchy,
    spare_at: Vec<u32>,
    /// The budget of each step of the rebuild under way, if one is.
    rebuilding: Option<usize>,
    /// The proxies inserted, removed, parked or unparked since the rebuild under way began.
    replay: Vec<u32>,
    /// [`DynamicTree::set_rebuild_frames`].
    rebuild_frames: u32,
    /// Scratch: the order of the changes, the query stack, the traversal's tasks.
    order: Vec<u64>,
    stack: Vec<u64>,
    tasks: Vec<u64>,
}

impl Default for DynamicTree {
    fn default() -> Self {
        Self {
            hierarchy: Hierarchy::default(),
            at: Vec::new(),
            mark: Vec::new(),
            pending: Vec::new(),
            refused: Vec::new(),
            paths_marked: true,
            partners: Partners::default(),
            len: 0,
            moves: 0,
            rebuild_after: 16.0,
            spare: Hierarchy::default(),
            spare_at: Vec::new(),
            rebuilding: None,
            replay: Vec::new(),
            rebuild_frames: 32,
            order: Vec::new(),
            stack: Vec::new(),
            tasks: Vec::new(),
        }
    }
}

impl DynamicTree {
    /// An empty tree.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// A tree whose proxy `i` has box `i` of `fat`, built balanced (as
    /// [`DynamicTree::rebuild`]); every pair that overlaps begins at the first report. A box
    /// equal to [`Aabb3::EMPTY`] (as in the padding lanes of the last AoSoA block, or for a
    /// body with no geometry) leaves its id out of the tree.
    ///
    /// # Errors
    /// [`BroadphaseError::InvalidBox`] for the first other NaN, infinite or inverted box,
    /// [`BroadphaseError::IdTooLarge`] for more than `2^31 − 2` boxes,
    /// [`BroadphaseError::OutOfMemory`] when the per-id tables cannot be allocated, and
    /// [`BroadphaseError::Layout`] for inconsistent columns.
    pub fn from_boxes(fat: impl BoxSource<3>) -> Result<Self, BroadphaseError> {
        let len = fat.len().map_err(|_| BroadphaseError::Layout)?;
        if len > MAX_ID as usize {
            return Err(BroadphaseError::IdTooLarge { id: MAX_ID });
        }
        let mut items = Vec::with_capacity(len);
        for i in 0..len {
            let (min, max) = fat.get(i);
            let b = Aabb3::new(min.into(), max.into());
            if b == Aabb3::EMPTY {
                continue;
            }
            if !accepts(&b) {
                return Err(BroadphaseError::InvalidBox { id: i as u32 });
            }
            items.push((i as u32, b));
        }
        let mut mark = alloc::vec![0; len];
        for (k, (id, _)) in items.iter().enumerate() {
            mark[*id as usize] = k as u32 + 1;
        }
        let mut partners = Partners::default();
        partners
            .grow(len)
            .map_err(|_| BroadphaseError::OutOfMemory {
                id: (len as u32).saturating_sub(1),
            })?;
        let mut tree = Self {
            at: alloc::vec![ABSENT; len],
            partners,
            mark,
            pending: items
                .iter()
                .map(|(id, _)| Change::new(*id, &Aabb3::EMPTY))
                .collect(),
            // Every proxy is a change, its path not marked.
            paths_marked: false,
            len: items.len(),
            ..Self::default()
        };
        tree.hierarchy.begin(items);
        let mut places = Placer { at: &mut tree.at };
        tree.hierarchy.step(
            usize::MAX,
            |id| {
                let (min, max) = fat.get(id as usize);
                Some(Aabb3::new(min.into(), max.into()))
            },
            &mut places,
        );
        Ok(tree)
    }

    /// The number of proxies, parked ones included.
    #[must_use]
    pub fn len(&self) -> usize {
        self.len
    }

    /// True when the tree holds no proxy.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Proxy `id`'s fat box, or `None` when it is absent or parked.
    #[must_use]
    pub fn get(&self, id: u32) -> Option<Aabb3> {
        let at = *self.at.get(id as usize)?;
        match at {
            ABSENT | PARKED => None,
            at => Some(self.hierarchy.get(Slot(at))),
        }
    }

    /// True when proxy `id` is in the tree (placed or parked).
    #[must_use]
    pub fn contains(&self, id: u32) -> bool {
        self.at.get(id as usize).is_some_and(|&at| at != ABSENT)
    }

    /// True when proxy `id` is parked: its last box was refused.
    #[must_use]
    pub fn is_parked(&self, id: u32) -> bool {
        self.at.get(id as usize) == Some(&PARKED)
    }

    /// The tree's nodes (8 children each, 256 bytes).
    #[must_use]
    pub fn nodes(&self) -> usize {
        self.hierarchy.nodes()
    }

    fn grow(&mut self, id: u32) -> Result<(), BroadphaseError> {
        if id >= MAX_ID {
            return Err(BroadphaseError::IdTooLarge { id });
        }
        let len = id as usize + 1;
        if self.at.len() < len {
            // Reserved first, so that a refused id changes nothing; the spare's table too,
            // which a rebuild later grows to this length where it cannot fail.
            let more = |v: &Vec<u32>| len.saturating_sub(v.len());
            self.at
                .try_reserve_exact(more(&self.at))
                .and_then(|()| self.mark.try_reserve_exact(more(&self.mark)))
                .and_then(|()| self.spare_at.try_reserve_exact(more(&self.spare_at)))
                .and_then(|()| self.partners.grow(len))
                .map_err(|_| BroadphaseError::OutOfMemory { id })?;
            self.at.resize(len, ABSENT);
            self.mark.resize(len, 0);
        }
        Ok(())
    }

    /// The box proxy `id` has now, or the empty box.
    fn current(&self, id: u32) -> Aabb3 {
        self.get(id).unwrap_or(Aabb3::EMPTY)
    }

    /// Notes that `id`'s box is about to change (its box at the last report is the one it
    /// has now, unless it already changed since).
    fn note(&mut self, id: u32) {
        if self.mark[id as usize] == 0 {
            let old = self.current(id);
            self.pending.push(Change::new(id, &old));
            self.mark[id as usize] = self.pending.len() as u32;
        }
    }

    /// The hierarchy, and where its proxy moves go.
    fn parts(&mut self) -> (&mut Hierarchy, Placer<'_>) {
        (&mut self.hierarchy, Placer { at: &mut self.at })
    }

    /// Takes placed proxy `id` out of the hierarchy.
    fn take_out(&mut self, id: u32) {
        self.hierarchy.remove(Slot(self.at[id as usize]));
    }

    fn place(&mut self, id: u32, b: &Aabb3) {
        let (h, mut places) = self.parts();
        h.insert(id, b, &mut places);
        self.moves += 1;
    }

    /// Adds proxy `id` with fat box `fat`; its pairs begin at the next report (if it still
    /// has a box then: see the module docs on what a report compares). The tree's memory
    /// grows with the largest id (16 bytes per id up to it).
    ///
    /// # Errors
    /// [`BroadphaseError::InvalidBox`] for a NaN, infinite or inverted box,
    /// [`BroadphaseError::Duplicate`] when `id` is in the tree,
    /// [`BroadphaseError::IdTooLarge`] from `2^31 − 2` on, [`BroadphaseError::OutOfMemory`]
    /// when the per-id tables cannot grow to `id`; the tree is then unchanged.
    pub fn insert(&mut self, id: u32, fat: Aabb3) -> Result<(), BroadphaseError> {
        if !accepts(&fat) {
            return Err(BroadphaseError::InvalidBox { id });
        }
        self.grow(id)?;
        if self.at[id as usize] != ABSENT {
            return Err(BroadphaseError::Duplicate { id });
        }
        self.note(id);
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
        if !self.is_parked(id) {
            self.take_out(id);
        }
        self.at[id as usize] = ABSENT;
        self.len -= 1;
        true
    }

    /// Rebuilds the tree from its proxies, balanced (near-median splits of the widest spread
    /// of centres, every node full but those on one path from the root). Boxes and pairs do
    /// not change; queries get faster where moves have left node boxes loose or mixed
    /// distant proxies under one node.
    pub fn rebuild(&mut self) {
        self.begin_rebuild(usize::MAX);
        self.continue_rebuild();
    }

    /// Starts a rebuild into the spare hierarchy from the proxies as they are, to advance by
    /// `budget` units of work per [`DynamicTree::continue_rebuild`]. A rebuild under way is
    /// dropped.
    fn begin_rebuild(&mut self, budget: usize) {
        self.spare.begin_from(&self.hierarchy);
        // Placed proxies are absent until the build places them; absent and parked ones
        // stay so.
        self.spare_at.clear();
        self.spare_at.extend(
            self.at
                .iter()
                .map(|&at| if at == PARKED { PARKED } else { ABSENT }),
        );
        self.replay.clear();
        self.rebuilding = Some(budget);
        self.moves = 0;
    }

    /// Advances the rebuild under way by its budget; once its build is done, brings the
    /// proxies inserted, removed, parked or unparked meanwhile up to date in it and makes it
    /// the tree. Returns true then.
    fn continue_rebuild(&mut self) -> bool {
        let Some(budget) = self.rebuilding else {
            return false;
        };
        let (hierarchy, at) = (&self.hierarchy, &self.at);
        let mut places = Placer {
            at: &mut self.spare_at,
        };
        // A proxy is placed with the box it has now, if it is still placed; a later write
        // goes to both hierarchies (`DynamicTree::set`).
        let box_of = |id: u32| match at[id as usize] {
            ABSENT | PARKED => None,
            slot => Some(hierarchy.get(Slot(slot))),
        };
        if !self.spare.step(budget, box_of, &mut places) {
            return false;
        }
        let replay = take(&mut self.replay);
        self.spare_at.resize(self.at.len(), ABSENT);
        for &id in &replay {
            let (now, then) = (self.at[id as usize], self.spare_at[id as usize]);
            let placed = |at: u32| at != ABSENT && at != PARKED;
            let mut places = Placer {
                at: &mut self.spare_at,
            };
            match (placed(now), placed(then)) {
                (true, true) => self.spare.set(Slot(then), &self.hierarchy.get(Slot(now))),
                (true, false) => {
                    let b = self.hierarchy.get(Slot(now));
                    self.spare.insert(id, &b, &mut places);
                }
                (false, true) => {
                    self.spare.remove(Slot(then));
                    places.at[id as usize] = now;
                }
                (false, false) => places.at[id as usize] = now,
            }
        }
        core::mem::swap(&mut self.hierarchy, &mut self.spare);
        core::mem::swap(&mut self.at, &mut self.spare_at);
        self.paths_marked = false;
        self.replay = replay;
        self.rebuilding = None;
        true
    }

    /// Proxy `id`'s slot in the hierarchy a rebuild under way fills, once placed there.
    #[inline(always)]
    fn spare_slot(&self, id: u32) -> Option<Slot> {
        self.rebuilding?;
        let then = *self.spare_at.get(id as usize)?;
        (then != ABSENT && then != PARKED).then_some(Slot(then))
    }

    /// Notes that proxy `id` is inserted, removed, parked or unparked: proxies may have
    /// moved between slots, so the report marks the changed paths again, and the rebuild
    /// under way brings such proxies up to date when its build is done.
    fn restructured(&mut self, id: u32) {
        self.paths_marked = false;
        if self.rebuilding.is_some() {
            self.replay.push(id);
        }
    }

    /// Calls `hit(id)` for every placed proxy whose fat box overlaps `b` (closed boxes).
    pub fn query(&self, b: &Aabb3, mut hit: impl FnMut(u32)) {
        self.hierarchy.query(b, &mut Vec::new(), |id, _| hit(id));
    }

    /// Every pair of placed proxies whose fat boxes overlap, as `(smaller, larger)`,
    /// ascending: what a narrow phase starts from.
    #[must_use]
    pub fn overlapping_pairs(&self) -> Vec<(u32, u32)> {
        let mut out = Vec::new();
        let mut stack = Vec::new();
        for (id, b) in self.hierarchy.proxies() {
            self.hierarchy.query(&b, &mut stack, |other, _| {
                if other > id {
                    out.push((id, other));
                }
            });
        }
        out.sort_unstable();
        out
    }

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

    /// Sets when [`DynamicTree::maintain`] starts a rebuild: once the tree has taken this
    /// many moves and inserts per proxy since its last build (default 16; `f32::INFINITY`
    /// never, leaving [`DynamicTree::rebuild`] to the caller).
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
    /// Moves leave node boxes loose and mix distant proxies under one node, so once the
    /// tree has taken enough moves since its last build ([`DynamicTree::set_rebuild_after`])
    /// a new hierarchy is built beside it, a share of the work in each call
    /// ([`DynamicTree::set_rebuild_frames`]), while the old one serves the frames: no frame
    /// pays for a whole rebuild. Until the new hierarchy takes over, each write goes to
    /// both, and proxies inserted or removed meanwhile are brought up to date in it when its
    /// build is done. Returns true when a new hierarchy took over. Boxes and pairs do not
    /// change; the rebuild needs a second hierarchy's memory, kept between rebuilds (its
    /// nodes, 256 bytes per about 7 proxies after a build, the centres it sorts, 16 bytes
    /// per proxy, and the proxies' slots in it, 4 bytes per id).
    pub fn maintain(&mut self) -> bool {
        if self.rebuilding.is_none() {
            let proxies = self.len.max(1) as f32;
            if self.moves as f32 <= self.rebuild_after * proxies {
                return false;
            }
            let budget = match self.rebuild_frames {
                1 => usize::MAX,
                frames => Hierarchy::build_work(self.len)
                    .div_ceil(frames as usize)
                    .max(1),
            };
            self.begin_rebuild(budget);
        }
        self.continue_rebuild()
    }

    /// The tree's half of a frame: the proxies in `moved` (strictly ascending ids, as
    /// [`Moved::indices`](crate::Moved::indices)) take their boxes from `fat` (indexed by id,
    /// in any box layout the batch writes), and each enlarges the boxes above it up to the
    /// first that already contains it (once half of the proxies or more move, one pass
    /// recomputes the boxes above them instead). Moved ids not in the tree are ignored; a
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
        let refit = moved.len().saturating_mul(REFIT_FROM) >= self.len;
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
            self.hierarchy.refit_marked(&mut self.stack);
        }
        Ok(())
    }

    /// Asks for the cache lines of proxy `id`'s node, or of its parent.
    #[inline(always)]
    fn prefetch(&self, id: u32, parent: bool) {
        if let Some(&at) = self.at.get(id as usize)
            && at != ABSENT
            && at != PARKED
        {
            if parent {
                self.hierarchy.prefetch_parent(Slot(at));
            } else {
                self.hierarchy.prefetch(Slot(at));
                // A rebuild under way takes the write too.
                if let Some(slot) = self.spare_slot(id) {
                    self.spare.prefetch(slot);
                }
            }
        }
    }

    /// Gives proxy `id` (in the tree) box `b`, or parks it when `b` is refused; with
    /// `refit`, the slots above it wait for [`Hierarchy::refit_marked`].
    fn set(&mut self, id: u32, b: &Aabb3, refit: bool) {
        self.note(id);
        let at = self.at[id as usize];
        if accepts(b) {
            if at == PARKED {
                self.restructured(id);
                self.place(id, b);
            } else {
                if refit {
                    self.hierarchy.set_leaf(Slot(at), b);
                } else {
                    self.hierarchy.set(Slot(at), b);
                }
                self.moves += 1;
                if let Some(slot) = self.spare_slot(id) {
                    self.spare.set_during_build(slot, b);
                }
            }
        } else {
            self.refused.push(id);
            if at != PARKED {
                self.restructured(id);
                self.take_out(id);
                self.at[id as usize] = PARKED;
            }
        }
    }

    /// The pairs' half of a frame: `pairs` receives the pairs that began (and ended) since
    /// the last report, searched from the proxies written, inserted, removed or parked
    /// since, and the proxies refused since.
    pub fn report(&mut self, pairs: &mut Pairs) {
        self.report_on(pairs, false);
    }

    /// [`DynamicTree::report`] on the rayon pool (feature `rayon`): the changed proxies'
    /// searches in ordered parts, whose pairs are joined in part order, so that `pairs` is
    /// the same, in the same order, as [`DynamicTree::report`] gives, on any number of
    /// threads. Parts are at least 512 changed proxies, so a small report runs on the
    /// calling thread.
    #[cfg(feature = "rayon")]
    pub fn report_par(&mut self, pairs: &mut Pairs) {
        self.report_on(pairs, true);
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

    /// The report, its searches on the rayon pool when `parallel` (and the feature) say so.
    fn report_on(&mut self, pairs: &mut Pairs, parallel: bool) {
        pairs.clear();
        core::mem::swap(&mut pairs.refused, &mut self.refused);
        let mut changes = take(&mut self.pending);
        // Once a sixteenth of the proxies or more changed, one traversal of the tree against
        // itself, restricted to the changed proxies' paths, shares the descents that their
        // queries would each repeat; it needs those paths marked, in any order. The writes
        // marked theirs, unless proxies moved between slots since.
        let traverse = changes.len() * TRAVERSE_FROM >= self.len;
        let placed = |at: u32| at != ABSENT && at != PARKED;
        let mut order = take(&mut self.order);
        order.clear();
        if traverse {
            if !self.paths_marked {
                self.hierarchy.clear_marks();
                for c in &changes {
                    let at = self.at[c.id as usize];
                    if placed(at) {
                        self.hierarchy.mark_changed(Slot(at));
                    }
                }
            }
        } else {
            // Queries in slot order: neighbours in the tree share their paths in the
            // caches. The absent and parked proxies (places `PARKED` and `ABSENT`, the
            // largest) come last, and have no box to query with: they are cut off.
            for (i, c) in changes.iter().enumerate() {
                order.push(u64::from(self.at[c.id as usize]) << 32 | i as u64);
            }
            order.sort_unstable();
            let queried = order.partition_point(|&key| placed((key >> 32) as u32));
            order.truncate(queried);
        }
        let mut tasks = take(&mut self.tasks);
        let (begun, ended) = (&mut pairs.begun, &mut pairs.ended);
        let view = View {
            hierarchy: &self.hierarchy,
            at: &self.at,
            mark: &self.mark,
        };
        let partners = &self.partners;
        // The ended pairs are found in every report, wanted or not: the partners must
        // follow every change.
        if traverse {
            view.hierarchy.changed_frontier(&mut tasks, |a, ba, b, bb| {
                view.begun(&changes, (a, ba), (b, bb), begun)
            });
        }
        #[cfg(feature = "rayon")]
        if parallel {
            use rayon::prelude::*;
            // Whole groups of queries per part, so that each part forms the serial search's
            // groups (whose hits come in the order of their shared descent); the traversal's
            // tasks in parts of eight.
            const PART: usize = 64 * hierarchy::WIDTH;
            let found: Vec<Vec<(u32, u32)>> = if traverse {
                tasks
                    .par_chunks(8)
                    .map(|part| {
                        let (mut stack, mut found) = (Vec::new(), Vec::new());
                        crate::simd::plain(
                            #[inline(always)]
                            || view.changed_pairs(&changes, part, &mut stack, &mut found),
                        );
                        found
                    })
                    .collect()
            } else {
                order
                    .par_chunks(PART)
                    .map(|part| {
                        let (mut stack, mut found) = (Vec::new(), Vec::new());
                        crate::simd::plain(
                            #[inline(always)]
                            || search(&changes, part, &view, &mut stack, &mut found),
                        );
                        found
                    })
                    .collect()
            };
            begun.extend(found.into_iter().flatten());
            let found: Vec<Vec<(u32, u32)>> = changes
                .par_chunks(PART)
                .map(|part| {
                    let mut found = Vec::new();
                    search_ended(part, &view, partners, &mut found);
                    found
                })
                .collect();
            ended.extend(found.into_iter().flatten());
        }
        if !parallel {
            let stack = &mut self.stack;
            if traverse {
                crate::simd::plain(
                    #[inline(always)]
                    || view.changed_pairs(&changes, &tasks, stack, begun),
                );
            } else {
                crate::simd::plain(
                    #[inline(always)]
                    || search(&changes, &order, &view, stack, begun),
                );
            }
            search_ended(&changes, &view, partners, ended);
        }
        self.hierarchy.clear_marks();
        self.paths_marked = true;
        self.tasks = tasks;
        for &(a, b) in ended.iter() {
            self.partners.remove(a, b);
        }
        for &(a, b) in begun.iter() {
            self.partners.add(a, b);
        }
        if !pairs.ended_wanted {
            ended.clear();
        }
        for c in &changes {
            self.mark[c.id as usize] = 0;
        }
        changes.clear();
        (self.pending, self.order) = (changes, order);
    }
}

/// What a report reads: the hierarchy, the proxies' places and the change marks.
struct View<'a> {
    hierarchy: &'a Hierarchy,
    at: &'a [u32],
    mark: &'a [u32],
}

/// The changes in `order` (each key a change's place, then its index), with each change's
/// new box read from its place; the changes themselves, scattered in this order, are asked
/// for a few keys ahead.
#[inline(always)]
fn in_order<'c>(
    changes: &'c [Change],
    order: &'c [u64],
    view: &'c View<'_>,
) -> impl Iterator<Item = (&'c Change, Aabb3)> + 'c {
    const AHEAD: usize = 8;
    order.iter().enumerate().map(move |(k, &key)| {
        if let Some(&next) = order.get(k + 2 * AHEAD) {
            let at = (next >> 32) as u32;
            if at != ABSENT && at != PARKED {
                view.hierarchy.prefetch(Slot(at));
            }
        }
        if let Some(&next) = order.get(k + AHEAD) {
            crate::simd::prefetch(&changes[next as u32 as usize]);
            let at = (next >> 32) as u32;
            if at != ABSENT && at != PARKED {
                view.hierarchy.prefetch_parent(Slot(at));
            }
        }
        (&changes[key as u32 as usize], view.at((key >> 32) as u32))
    })
}

impl View<'_> {
    /// The box at place `at` (a slot, or the empty box for an absent or parked proxy).
    #[inline(always)]
    fn at(&self, at: u32) -> Aabb3 {
        match at {
            ABSENT | PARKED => Aabb3::EMPTY,
            at => self.hierarchy.get(Slot(at)),
        }
    }

    /// Proxy `id`'s box now, or the empty box.
    #[inline(always)]
    fn now(&self, id: u32) -> Aabb3 {
        self.at(self.at[id as usize])
    }

    /// Adds the pair of proxies `a` and `b` (with their boxes now, which overlap, and one
    /// of them changed) to `begun` when their boxes at the last report did not overlap: a
    /// changed proxy's then is its change's old box, an unchanged one's is its box now.
    #[inline(always)]
    fn begun(
        &self,
        changes: &[Change],
        (a, ba): (u32, &Aabb3),
        (b, bb): (u32, &Aabb3),
        begun: &mut Vec<(u32, u32)>,
    ) {
        let then = |id: u32, now: &Aabb3| match self.mark[id as usize] {
            0 => *now,
            m => changes[m as usize - 1].old(),
        };
        if !overlap(&then(a, ba), &then(b, bb)) {
            begun.push((a.min(b), a.max(b)));
        }
    }

    /// The traversal's `tasks` run depth first ([`Hierarchy::changed_pairs_from`]), their
    /// pairs that began into `begun`.
    #[inline(always)]
    fn changed_pairs(
        &self,
        changes: &[Change],
        tasks: &[u64],
        stack: &mut Vec<u64>,
        begun: &mut Vec<(u32, u32)>,
    ) {
        self.hierarchy
            .changed_pairs_from(tasks, stack, |a, ba, b, bb| {
                self.begun(changes, (a, ba), (b, bb), begun)
            });
    }
}

/// Up to [`hierarchy::WIDTH`] changes, each with its query box and the box its hits are
/// compared with, taken in slot order, so that they are neighbours in the tree and their
/// queries descend together ([`Hierarchy::query_group`]).
struct Group<'c> {
    changes: [Option<(&'c Change, Aabb3)>; hierarchy::WIDTH],
    boxes: [Aabb3; hierarchy::WIDTH],
    len: usize,
}

impl<'c> Group<'c> {
    fn new() -> Self {
        Self {
            changes: [None; hierarchy::WIDTH],
            boxes: [Aabb3::EMPTY; hierarchy::WIDTH],
            len: 0,
        }
    }

    /// Adds a change, its query box and the box its hits are compared with; true when the
    /// group is full.
    #[inline(always)]
    fn push(&mut self, c: &'c Change, q: Aabb3, against: Aabb3) -> bool {
        self.changes[self.len] = Some((c, against));
        self.boxes[self.len] = q;
        self.len += 1;
        self.len == hierarchy::WIDTH
    }

    /// Calls `hit(change, against, other, box)` for every proxy whose box overlaps a
    /// change's query box, then empties the group.
    #[inline(always)]
    fn query(
        &mut self,
        view: &View<'_>,
        stack: &mut Vec<u64>,
        mut hit: impl FnMut(&'c Change, &Aabb3, u32, &Aabb3),
    ) {
        if self.len == 0 {
            return;
        }
        let changes = &self.changes;
        view.hierarchy
            .query_group(&self.boxes[..self.len], stack, |i, other, b| {
                if let Some((c, against)) = &changes[i] {
                    hit(c, against, other, b);
                }
            });
        self.len = 0;
    }
}

/// The begun pairs: each changed proxy's new box against the tree. A pair of two
/// changed proxies is taken from the larger id's query, and began when their old boxes did
/// not overlap; a pair with an unchanged proxy began when the changed one's old box did not
/// overlap the other's (unchanged) box.
#[inline(always)]
fn search(
    changes: &[Change],
    order: &[u64],
    view: &View<'_>,
    stack: &mut Vec<u64>,
    begun: &mut Vec<(u32, u32)>,
) {
    let mut hit = |c: &Change, old: &Aabb3, other: u32, b: &Aabb3| {
        if other == c.id {
            return;
        }
        let was = match view.mark[other as usize] {
            0 => overlap(old, b),
            m if other < c.id => overlap(old, &changes[m as usize - 1].old()),
            _ => return,
        };
        if !was {
            begun.push((c.id.min(other), c.id.max(other)));
        }
    };
    let mut group = Group::new();
    for (c, new) in in_order(changes, order, view) {
        if new.min.x <= new.max.x && group.push(c, new, c.old()) {
            group.query(view, stack, &mut hit);
        }
    }
    group.query(view, stack, &mut hit);
}

/// The ended pairs: the partners of each changed proxy (the proxies its box overlapped
/// at the last report) whose box no longer overlaps its own. A pair of two changed proxies
/// is taken from the smaller id's list. Each proxy's partners are read in change order, so
/// the list is deterministic.
fn search_ended(
    changes: &[Change],
    view: &View<'_>,
    partners: &Partners,
    ended: &mut Vec<(u32, u32)>,
) {
    for c in changes {
        if partners.is_alone(c.id) {
            continue;
        }
        let new = view.now(c.id);
        for other in partners.of(c.id) {
            if other < c.id && view.mark[other as usize] != 0 {
                continue;
            }
            if !overlap(&new, &view.now(other)) {
                ended.push((c.id.min(other), c.id.max(other)));
            }
        }
    }
}
