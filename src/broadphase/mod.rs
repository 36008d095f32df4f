//! A dynamic tree of fat boxes that consumes an update's moved set and reports the pairs
//! whose overlap began (and, on request, ended) in each frame.
//!
//! [`DynamicTree`] holds one proxy per body, keyed by the body's index in the slices a
//! [`Batch::update`](crate::Batch::update) reads, with the body's fat box. Each frame the
//! engine hands it [`Moved::indices`](crate::Moved::indices) and the fat boxes, and
//! [`DynamicTree::update`] runs the frame's three steps (each also callable alone):
//! [`write`](DynamicTree::write) rewrites the moved proxies' boxes, enlarging the nodes
//! above each up to the first that already holds it (once half of the moving proxies or
//! more move, marking their paths and refitting the marked nodes in one pass instead);
//! [`maintain`](DynamicTree::maintain) builds a new hierarchy once enough has moved since
//! the last build, a share in each call, and swaps it in when done;
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
//! **Kinds and layers.** Each proxy is [`BodyKind::Dynamic`] (the default),
//! [`BodyKind::Kinematic`] or [`BodyKind::Static`], and has [`Layers`] (32-bit memberships
//! and filters; [`Layers::ALL`] by default), set at insert ([`DynamicTree::insert_with`],
//! [`DynamicTree::from_boxes_with`]) and changeable ([`DynamicTree::set_kind`],
//! [`DynamicTree::set_layers`]). A pair is reported only when its boxes overlap, one proxy
//! is dynamic (or the tree's [`KindPairs`] admit the kinematic pair; two static proxies
//! never pair), and each proxy's memberships meet the other's filters. The check is made
//! in the search, before a pair is stored, and skipped while no proxy is kinematic and all
//! share the layers of the first one. A change of kind or layers begins and ends pairs at
//! the next report exactly as a move does. Static proxies live in a hierarchy of their own,
//! which no frame rebuilds or writes unless a static proxy moves: the report searches the
//! moving hierarchy against itself and against the static one, from the changed proxies.
//!
//! **Queries and casts.** The same tree answers box and point queries
//! ([`DynamicTree::query`], [`DynamicTree::query_point`]), ray casts and casts of a moving
//! box ([`DynamicTree::cast_ray`], [`DynamicTree::cast_box`], and many rays at once,
//! [`DynamicTree::cast_rays`]), over every kind, each with a layer filter and no heap
//! allocation. A cast's callback goes on, clips the cast ([`CastControl::Clip`]: the
//! closest hit) or stops it. Casts are conservative by proof: never a missed box, never
//! an entry beyond the exact one, under FTZ and DAZ too (the proof is in `slab.rs`, beside
//! the test).
//!
//! **Sleep.** Sleeping bodies need no call: they are not in the update's moved list, so
//! their proxies stay as they are, their pairs last, and a moved proxy finds them as any
//! other. (A second hierarchy for the sleeping proxies was measured and dropped: every
//! moved proxy must query both, which cost more than the smaller rebuilds saved.)

mod cast;
mod edit;
mod error;
mod filter;
mod hierarchy;
mod pairs;
mod partners;
mod query;
mod ray;
mod rebuild;
mod report;
mod slab;
mod write;

pub use error::BroadphaseError;
pub use filter::{BodyKind, KindPairs, Layers};
pub use pairs::Pairs;
pub use ray::{CastControl, Ray};

use crate::aabb::Aabb3;
use alloc::vec::Vec;
use filter::{Proxy, Tier};
use glam::Vec3A;
use hierarchy::{Hierarchy, Places, Slot};
use partners::Partners;

/// A report traverses the tree against itself once at least one proxy in this many
/// changed, and queries each changed proxy's box otherwise (as rapier reinserts below a
/// sixteenth changed and updates in place above).
const TRAVERSE_FROM: usize = 16;

/// A write refits the slots above its proxies in one pass once at least one moving proxy
/// in this many moves ([`DynamicTree::write`]; `docs/broadphase.md` has the measurements).
const REFIT_FROM: usize = 2;

/// Ids stay below `2^31 − 2`: a child reference packs a proxy id in 31 bits beside the
/// leaf bit, where `2^31 − 1` would read as an empty child.
const MAX_ID: u32 = (1 << 31) - 2;

/// The most nodes a hierarchy may hold: a [`Place`] keeps a slot in 31 bits. (That is
/// 64 GiB of nodes: an insert that would pass it is refused as out of memory.)
const MAX_NODES: usize = (1 << 28) - 1;

/// Where a proxy is: absent, parked, or a slot of the moving hierarchy or (top bit set) of
/// the fixed one.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(transparent)]
struct Place(u32);

impl Place {
    const ABSENT: Self = Self(u32::MAX);
    const PARKED: Self = Self(u32::MAX - 1);
    /// The bit of a slot of the fixed hierarchy.
    const FIXED: u32 = 1 << 31;

    #[inline(always)]
    fn new(tier: Tier, slot: Slot) -> Self {
        match tier {
            Tier::Moving => Self(slot.0),
            Tier::Fixed => Self(slot.0 | Self::FIXED),
        }
    }

    /// The hierarchy and slot of a placed proxy; `None` for an absent or parked one.
    #[inline(always)]
    fn slot(self) -> Option<(Tier, Slot)> {
        match self {
            Self::ABSENT | Self::PARKED => None,
            Self(p) if p & Self::FIXED != 0 => Some((Tier::Fixed, Slot(p & !Self::FIXED))),
            Self(p) => Some((Tier::Moving, Slot(p))),
        }
    }

    /// The slot of a proxy placed in `tier`.
    #[inline(always)]
    fn slot_in(self, tier: Tier) -> Option<Slot> {
        self.slot().filter(|&(t, _)| t == tier).map(|(_, s)| s)
    }

    #[inline(always)]
    fn is_placed(self) -> bool {
        self != Self::ABSENT && self != Self::PARKED
    }
}

/// A proxy whose box, kind or layers changed since the last report, and its box then (the
/// empty box when it had none).
#[derive(Clone, Copy, Debug)]
struct Change {
    /// The id, and [`Change::REFILTERED`] when its kind or layers changed.
    tagged: u32,
    /// The old box's `min` then `max` (28 bytes a change, not 48).
    old: [f32; 6],
}

impl Change {
    /// The bit of `tagged` that says the proxy's kind or layers changed: whether its pairs
    /// were reported then is read from its partners, not from its old box.
    const REFILTERED: u32 = 1 << 31;

    fn new(id: u32, old: &Aabb3) -> Self {
        let (min, max) = (old.min, old.max);
        Self {
            tagged: id,
            old: [min.x, min.y, min.z, max.x, max.y, max.z],
        }
    }

    #[inline(always)]
    fn id(&self) -> u32 {
        self.tagged & !Self::REFILTERED
    }

    #[inline(always)]
    fn refiltered(&self) -> bool {
        self.tagged & Self::REFILTERED != 0
    }

    #[inline(always)]
    fn old(&self) -> Aabb3 {
        let o = &self.old;
        Aabb3::new(Vec3A::new(o[0], o[1], o[2]), Vec3A::new(o[3], o[4], o[5]))
    }
}

/// Sends a hierarchy's proxy moves to the per-proxy places.
struct Placer<'a> {
    at: &'a mut [Place],
    tier: Tier,
}

impl Places for Placer<'_> {
    #[inline(always)]
    fn place(&mut self, id: u32, slot: Slot) {
        self.at[id as usize] = Place::new(self.tier, slot);
    }
}

/// A spread rebuild under way (`rebuild.rs`): its tier, the least work of each step, the
/// work left, and its tier's moves at its last step.
#[derive(Clone, Copy, Debug)]
struct Rebuild {
    tier: Tier,
    budget: usize,
    left: usize,
    seen: u64,
}

/// A box the tree accepts: every face finite, `min <= max`.
fn accepts(b: &Aabb3) -> bool {
    b.min.is_finite() && b.max.is_finite() && b.min.cmple(b.max).all()
}

/// True when a box's coordinates are within the casts' `f32` reach.
#[inline(always)]
fn tame(b: &Aabb3) -> bool {
    b.min.abs().max(b.max.abs()).max_element() <= slab::F32_REACH
}

/// A dynamic tree of fat boxes, fed by the moved set (see the [module docs](self)).
#[derive(Clone, Debug)]
pub struct DynamicTree {
    /// The dynamic and kinematic proxies.
    moving: Hierarchy,
    /// The static proxies.
    fixed: Hierarchy,
    /// Per id: where it is.
    at: Vec<Place>,
    /// Per id: its kind and layers.
    proxies: Vec<Proxy>,
    /// Per id: 1 + its index in `pending`, 0 when it has not changed since the last report.
    mark: Vec<u32>,
    /// Proxies written, inserted, removed, parked or refiltered since the last report, each
    /// with its box then.
    pending: Vec<Change>,
    /// Proxies refused since the last report.
    refused: Vec<u32>,
    /// True while every change in `pending` has its path marked in its hierarchy (each
    /// write marks its own): no insert, remove, park, unpark or change of kind since the
    /// last report, and no rebuild taking over, which move proxies between slots.
    paths_marked: bool,
    /// The pairs that overlapped (and were admitted) at the last report, as each proxy's
    /// partners.
    partners: Partners,
    /// The proxies, parked ones included: in all, and of each tier's kinds.
    len: usize,
    tier_len: [usize; 2],
    /// The layers of the first proxy of an empty tree: most proxies' layers, as a rule.
    common: Layers,
    /// The proxies that are kinematic or not in the `common` layers: while there are none
    /// (and the common layers interact with themselves), no pair takes a check beyond its
    /// boxes, and no query a check of each proxy's layers.
    unplain: usize,
    /// True when a proxy's kind or layers (or the kind pairs) changed since the last report.
    refiltered: bool,
    /// True once a box with a coordinate beyond the casts' `f32` reach entered the tree:
    /// casts then take the `f64` test (`slab.rs`).
    wild: bool,
    /// [`DynamicTree::set_kind_pairs`].
    kind_pairs: KindPairs,
    /// Per tier: the moves and inserts since its last build.
    moves: [u64; 2],
    /// [`DynamicTree::set_rebuild_after`].
    rebuild_after: f32,
    /// The hierarchy a rebuild fills, and the proxies' places in it; kept between rebuilds
    /// for their memory.
    spare: Hierarchy,
    spare_at: Vec<Place>,
    /// The rebuild under way.
    rebuilding: Option<Rebuild>,
    /// The proxies inserted, removed, parked, unparked or moved between tiers since the
    /// rebuild under way began.
    replay: Vec<u32>,
    /// [`DynamicTree::set_rebuild_frames`].
    rebuild_frames: u32,
    /// Scratch: the order of the changes, the search stack, the traversals' tasks.
    order: Vec<u64>,
    stack: Vec<u64>,
    tasks: Vec<u64>,
    cross: Vec<u64>,
}

impl Default for DynamicTree {
    fn default() -> Self {
        Self {
            moving: Hierarchy::default(),
            fixed: Hierarchy::default(),
            at: Vec::new(),
            proxies: Vec::new(),
            mark: Vec::new(),
            pending: Vec::new(),
            refused: Vec::new(),
            paths_marked: true,
            partners: Partners::default(),
            len: 0,
            tier_len: [0; 2],
            common: Layers::ALL,
            unplain: 0,
            refiltered: false,
            wild: false,
            kind_pairs: KindPairs::default(),
            moves: [0; 2],
            rebuild_after: 16.0,
            spare: Hierarchy::default(),
            spare_at: Vec::new(),
            rebuilding: None,
            replay: Vec::new(),
            rebuild_frames: 32,
            order: Vec::new(),
            stack: Vec::new(),
            tasks: Vec::new(),
            cross: Vec::new(),
        }
    }
}

impl DynamicTree {
    /// An empty tree.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
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
        let (tier, slot) = self.at.get(id as usize)?.slot()?;
        Some(self.tier(tier).get(slot))
    }

    /// True when proxy `id` is in the tree (placed or parked).
    #[must_use]
    pub fn contains(&self, id: u32) -> bool {
        self.at
            .get(id as usize)
            .is_some_and(|&at| at != Place::ABSENT)
    }

    /// True when proxy `id` is parked: its last box was refused.
    #[must_use]
    pub fn is_parked(&self, id: u32) -> bool {
        self.at.get(id as usize) == Some(&Place::PARKED)
    }

    /// Proxy `id`'s kind, or `None` when it is not in the tree.
    #[must_use]
    pub fn kind(&self, id: u32) -> Option<BodyKind> {
        self.contains(id).then(|| self.proxies[id as usize].kind)
    }

    /// Proxy `id`'s layers, or `None` when it is not in the tree.
    #[must_use]
    pub fn layers(&self, id: u32) -> Option<Layers> {
        self.contains(id).then(|| self.proxies[id as usize].layers)
    }

    /// The pairs of non-dynamic proxies the tree reports.
    #[must_use]
    pub fn kind_pairs(&self) -> KindPairs {
        self.kind_pairs
    }

    /// The tree's nodes (8 children each, 256 bytes): the moving proxies' hierarchy's,
    /// and the static proxies' once it holds one.
    #[must_use]
    pub fn nodes(&self) -> usize {
        self.moving.nodes() + self.fixed.nodes() - usize::from(self.fixed.is_empty())
    }

    /// The hierarchy of `tier`.
    #[inline(always)]
    fn tier(&self, tier: Tier) -> &Hierarchy {
        match tier {
            Tier::Moving => &self.moving,
            Tier::Fixed => &self.fixed,
        }
    }

    /// The hierarchy of `tier`, and where its proxy moves go.
    #[inline(always)]
    fn tier_mut(&mut self, tier: Tier) -> (&mut Hierarchy, Placer<'_>) {
        let h = match tier {
            Tier::Moving => &mut self.moving,
            Tier::Fixed => &mut self.fixed,
        };
        (
            h,
            Placer {
                at: &mut self.at,
                tier,
            },
        )
    }

    /// The box proxy `id` has now, or the empty box.
    fn current(&self, id: u32) -> Aabb3 {
        self.get(id).unwrap_or(Aabb3::EMPTY)
    }
}
