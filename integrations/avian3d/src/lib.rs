//! bvkit's [`DynamicTree`] as avian3d's broadphase: [`BvkitBroadPhasePlugin`] replaces
//! avian's `BvhBroadPhasePlugin` and adds the same pairs to the [`ContactGraph`], with the
//! same flags and filters.
//!
//! ```no_run
//! use avian3d::prelude::*;
//! use bevy::prelude::*;
//! use bvkit_avian3d::BvkitBroadPhasePlugin;
//!
//! App::new().add_plugins((
//!     MinimalPlugins,
//!     TransformPlugin,
//!     PhysicsPlugins::default()
//!         .build()
//!         .disable::<BvhBroadPhasePlugin>()
//!         .add(BvkitBroadPhasePlugin::<()>::default()),
//! ));
//! ```
//!
//! # What it keeps, and from where
//!
//! avian's `ColliderTreePlugin` stays: it computes each collider's [`EnlargedAabb`] (grown by
//! a margin and stretched along the velocity), lists the proxies whose enlarged box changed
//! in [`MovedProxies`], and keeps each proxy's collider, body, layers and flags in
//! [`ColliderTrees`]. The plugin mirrors those proxies in one [`DynamicTree`], each under a
//! dense id of its own:
//! - a proxy in [`MovedProxies`] is inserted (a new or re-keyed collider) or takes its new
//!   enlarged box, in one [`DynamicTree::write`] a step;
//! - a collider that is spawned, despawned, disabled or enabled again, re-parented, loses
//!   or replaces its collider, or changes its layers, its sensor marker or its body's kind
//!   is noted by an observer and compared with avian's proxy at the next step (inserted,
//!   removed, or given its new layers and kind), whatever avian's moved list says: avian
//!   clears that list at the end of each step, so a collider spawned after the broadphase
//!   would otherwise be lost.
//!
//! A step that inserts a quarter of the tree or more (a scene spawned) rebuilds the tree at
//! once rather than over the next steps' upkeep.
//!
//! Then one [`DynamicTree::report`] gives the pairs that began. Each is checked as avian's
//! own broadphase checks a pair (the same body, an existing contact edge, a joint that
//! disables collision, [`CollisionHooks::filter_pairs`]) and added with avian's flags:
//! contact events from either proxy, contacts modified when either asks, and no constraints
//! for a sensor or a disabled body. A pair refused by a joint or a hook is held and asked
//! again whenever one of its proxies moves, as avian asks again; pairs that end are left to
//! avian's narrow phase, which removes an edge once the enlarged boxes part. Where avian
//! removes a collider's edges while its boxes still overlap (a sensor marker added or
//! removed, a `RigidBody` inserted), the tree is queried for that collider's pairs again.
//!
//! [`BvkitSpatialQuery`] answers avian's spatial-query verbs from the same tree.
//!
//! # Kinds
//!
//! avian pairs a moved proxy with every tree but two static proxies, unless one is a sensor.
//! So the tree is told the kinds as [`BodyKind`] with every kind pair switched on: dynamic
//! and kinematic bodies as such, static bodies as [`BodyKind::Static`] (never paired with
//! each other, and costing nothing a step while they stay), and a static sensor or a
//! collider without a body as [`BodyKind::Kinematic`] (paired with everything). One
//! difference: avian pairs a static body with a static sensor only when the sensor is the
//! proxy that moved; this plugin pairs them whenever their boxes overlap.
//!
//! # Bad boxes
//!
//! A collider whose enlarged box turns NaN or infinite (a body given a NaN position) is
//! parked as [`DynamicTree::write`] parks a bad box: its pairs end, nothing panics, and it
//! comes back with its next good box.

mod spatial_query;

pub use spatial_query::BvkitSpatialQuery;

use core::marker::PhantomData;
use std::collections::BTreeMap;
use std::time::{Duration, Instant};

use avian3d::collider_tree::{
    ColliderTreeProxy, ColliderTreeProxyFlags, ColliderTreeProxyKey, ColliderTreeType,
    ColliderTrees, MovedProxies,
};
use avian3d::collision::CollisionDiagnostics;
use avian3d::collision::collider::EnlargedAabb;
use avian3d::collision::contact_types::ContactEdgeFlags;
use avian3d::data_structures::pair_key::PairKey;
use avian3d::dynamics::solver::joint_graph::JointGraph;
use avian3d::prelude::*;
use bevy::ecs::entity::EntityHashMap;
use bevy::ecs::entity_disabling::Disabled;
use bevy::ecs::system::{StaticSystemParam, SystemParamItem};
use bevy::prelude::*;
use bvkit::broadphase::{BodyKind, DynamicTree, KindPairs, Layers, Pairs};
use bvkit::glam::Vec3A;

/// A replacement for avian's `BvhBroadPhasePlugin` that finds the pairs with bvkit's
/// [`DynamicTree`] (see the [crate docs](crate)). `H` are the [`CollisionHooks`] whose
/// `filter_pairs` the pairs pass, as with avian's plugin.
pub struct BvkitBroadPhasePlugin<H: CollisionHooks = ()> {
    /// Run the tree's pair search on the rayon pool ([`DynamicTree::report_par`]).
    pub parallel: bool,
    hooks: PhantomData<H>,
}

impl<H: CollisionHooks> Default for BvkitBroadPhasePlugin<H> {
    fn default() -> Self {
        Self {
            parallel: false,
            hooks: PhantomData,
        }
    }
}

impl<H: CollisionHooks> BvkitBroadPhasePlugin<H> {
    /// The plugin with its pair search on the rayon pool when `parallel`.
    #[must_use]
    pub fn with_parallel(parallel: bool) -> Self {
        Self {
            parallel,
            hooks: PhantomData,
        }
    }
}

impl<H: CollisionHooks + 'static> Plugin for BvkitBroadPhasePlugin<H>
where
    for<'w, 's> SystemParamItem<'w, 's, H>: CollisionHooks,
{
    fn build(&self, app: &mut App) {
        app.insert_resource(BvkitBroadPhase::new(self.parallel));
        // Each change that avian makes to a proxy without marking it moved, and each that it
        // marks moved: a collider spawned or re-enabled after this step's broadphase is
        // marked moved, but avian clears the moved list at the end of the step.
        app.add_observer(touch::<Remove, ColliderTreeProxyKey>)
            .add_observer(touch::<Insert, Collider>)
            .add_observer(touch::<Insert, ColliderOf>)
            .add_observer(touch::<Remove, ColliderOf>)
            .add_observer(touch::<Remove, ColliderDisabled>)
            .add_observer(touch::<Remove, Disabled>)
            .add_observer(touch::<Remove, Collider>)
            .add_observer(touch::<Add, ColliderDisabled>)
            .add_observer(touch::<Add, Disabled>)
            .add_observer(touch::<Insert, CollisionLayers>)
            .add_observer(touch::<Remove, CollisionLayers>)
            .add_observer(touch::<Add, Sensor>)
            .add_observer(touch::<Remove, Sensor>)
            .add_observer(touch_body::<Insert, RigidBody>);
        app.add_systems(
            PhysicsSchedule,
            collect_collision_pairs::<H>.in_set(BroadPhaseSystems::CollectCollisions),
        );
    }
}

/// Notes a collider whose proxy may have changed without moving, or whose contact edges
/// avian removed (a sensor marker added or removed).
fn touch<E: EntityEvent, B: Bundle>(trigger: On<E, B>, mut broad: ResMut<BvkitBroadPhase>) {
    broad.touched.push(trigger.event_target());
}

/// Notes the colliders of a body whose `RigidBody` was inserted: avian removes their contact
/// edges then, whether or not the kind changed.
fn touch_body<E: EntityEvent, B: Bundle>(
    trigger: On<E, B>,
    bodies: Query<&RigidBodyColliders>,
    mut broad: ResMut<BvkitBroadPhase>,
) {
    if let Ok(colliders) = bodies.get(trigger.event_target()) {
        broad.touched.extend(colliders.iter());
    }
}

/// Time spent in the plugin's stages, summed since the last [`BvkitTimings::take`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BvkitTimings {
    /// Proxies inserted, removed and refiltered; moved proxies' boxes written.
    pub write: Duration,
    /// The tree's upkeep and pair search ([`DynamicTree::maintain`], [`DynamicTree::report`]).
    pub report: Duration,
    /// Begun pairs checked and added to the contact graph, held pairs asked again.
    pub pairs: Duration,
    /// Steps timed.
    pub steps: u32,
    /// Proxies whose enlarged box was written, over those steps.
    pub moved: u64,
    /// Pairs the tree reported begun, over those steps.
    pub begun: u64,
}

impl BvkitTimings {
    /// The sum of the stages.
    #[must_use]
    pub fn total(&self) -> Duration {
        self.write + self.report + self.pairs
    }

    /// The timings so far, and zero in their place.
    pub fn take(&mut self) -> Self {
        core::mem::take(self)
    }
}

/// No proxy.
const NONE: u32 = u32::MAX;

/// One mirrored proxy: its collider and avian's key for it.
#[derive(Clone, Copy, Debug)]
struct Record {
    entity: Entity,
    key: ColliderTreeProxyKey,
}

/// The plugin's state: the tree, the mirror of avian's proxies, the held pairs.
#[derive(Resource)]
pub struct BvkitBroadPhase {
    tree: DynamicTree,
    /// Per id: the enlarged box, as the tree's writes read it.
    boxes: Vec<bvkit::Aabb3>,
    /// Per id: its collider and key, `None` when free.
    records: Vec<Option<Record>>,
    free: Vec<u32>,
    /// Per encoded avian key: the id, or [`NONE`].
    by_key: Vec<u32>,
    by_entity: EntityHashMap<u32>,
    /// Colliders noted by the observers since the last step.
    touched: Vec<Entity>,
    /// The proxies of the touched colliders, whose pairs are asserted again after the
    /// report: avian may have removed their edges while their boxes still overlap.
    reassert: Vec<u32>,
    /// Overlapping pairs a joint or a hook refused, with their colliders then; ordered, so
    /// that the edges they add come in the same order in every run.
    held: BTreeMap<(u32, u32), (Entity, Entity)>,
    pairs: Pairs,
    moved: Vec<u32>,
    /// Proxies inserted this step.
    inserted: usize,
    parallel: bool,
    /// The stages' times.
    pub timings: BvkitTimings,
}

impl BvkitBroadPhase {
    fn new(parallel: bool) -> Self {
        let mut tree = DynamicTree::new();
        // avian pairs kinematic bodies with everything; only static–static pairs are skipped.
        tree.set_kind_pairs(KindPairs {
            kinematic_kinematic: true,
            kinematic_static: true,
        });
        Self {
            tree,
            boxes: Vec::new(),
            records: Vec::new(),
            free: Vec::new(),
            by_key: Vec::new(),
            by_entity: EntityHashMap::default(),
            touched: Vec::new(),
            reassert: Vec::new(),
            held: BTreeMap::new(),
            pairs: Pairs::new(),
            moved: Vec::new(),
            inserted: 0,
            parallel,
            timings: BvkitTimings::default(),
        }
    }

    /// The tree, for queries and casts.
    #[must_use]
    pub fn tree(&self) -> &DynamicTree {
        &self.tree
    }

    /// The collider of tree proxy `id`.
    #[must_use]
    pub fn collider(&self, id: u32) -> Option<Entity> {
        self.records
            .get(id as usize)
            .copied()
            .flatten()
            .map(|r| r.entity)
    }

    /// Tree proxy `id`'s collider and avian key.
    fn record(&self, id: u32) -> Option<Record> {
        self.records.get(id as usize).copied().flatten()
    }

    /// The tree proxy of `collider`, if it has one.
    #[must_use]
    pub fn proxy(&self, collider: Entity) -> Option<u32> {
        self.by_entity.get(&collider).copied()
    }

    /// Gives `entity` (avian proxy `key`) an id and, when its box is good, a place in the tree.
    fn attach(
        &mut self,
        entity: Entity,
        key: ColliderTreeProxyKey,
        proxy: &ColliderTreeProxy,
        fat: bvkit::Aabb3,
    ) {
        let id = self.free.pop().unwrap_or(self.records.len() as u32);
        if id as usize == self.records.len() {
            self.records.push(None);
            self.boxes.push(fat);
        }
        self.records[id as usize] = Some(Record { entity, key });
        self.boxes[id as usize] = fat;
        let k = encode(key);
        if k >= self.by_key.len() {
            self.by_key.resize(k + 1, NONE);
        }
        self.by_key[k] = id;
        self.by_entity.insert(entity, id);
        // A bad box leaves it out of the tree until a good one comes (`sync_moved`).
        let _ = self
            .tree
            .insert_with(id, fat, kind_of(key, proxy), layers_of(proxy));
        self.inserted += 1;
    }

    /// Frees `id`: out of the tree, its pairs ending at the next report.
    fn detach(&mut self, id: u32) {
        let Some(record) = self.records[id as usize].take() else {
            return;
        };
        self.tree.remove(id);
        let k = encode(record.key);
        if self.by_key.get(k) == Some(&id) {
            self.by_key[k] = NONE;
        }
        if self.by_entity.get(&record.entity) == Some(&id) {
            self.by_entity.remove(&record.entity);
        }
        self.free.push(id);
    }

    /// The id avian's proxy `key` of collider `entity` has, if it is mirrored as that.
    fn id_of(&self, key: ColliderTreeProxyKey, entity: Entity) -> Option<u32> {
        let id = *self.by_key.get(encode(key))?;
        let record = self.records.get(id as usize).copied().flatten()?;
        (record.entity == entity && record.key == key).then_some(id)
    }
}

/// avian's key as one number (its id above the tree type's two bits).
fn encode(key: ColliderTreeProxyKey) -> usize {
    ((key.id().id() as usize) << 2) | key.tree_type() as usize
}

/// The kind the tree gives a proxy: see the crate docs.
fn kind_of(key: ColliderTreeProxyKey, proxy: &ColliderTreeProxy) -> BodyKind {
    match key.tree_type() {
        ColliderTreeType::Dynamic => BodyKind::Dynamic,
        ColliderTreeType::Static if !proxy.is_sensor() => BodyKind::Static,
        _ => BodyKind::Kinematic,
    }
}

/// avian's layers as the tree's (the same rule: each side's memberships meet the other's
/// filters).
fn layers_of(proxy: &ColliderTreeProxy) -> Layers {
    Layers::new(proxy.layers.memberships.0, proxy.layers.filters.0)
}

/// An enlarged box at the plugin's edge: avian's glam 0.32 vectors copied into bvkit's.
fn fat_of(aabb: &EnlargedAabb) -> bvkit::Aabb3 {
    let b = aabb.get();
    bvkit::Aabb3::new(
        Vec3A::from_array(b.min.to_array()),
        Vec3A::from_array(b.max.to_array()),
    )
}

/// avian's proxy for `key`.
fn proxy_of(trees: &ColliderTrees, key: ColliderTreeProxyKey) -> Option<&ColliderTreeProxy> {
    trees.tree_for_type(key.tree_type()).get_proxy(key.id())
}

/// What becomes of an overlapping pair.
enum Verdict {
    /// Into the contact graph.
    Add,
    /// Refused for now by a joint or a hook: asked again when one of them moves.
    Hold,
    /// Never while it overlaps (the same body), or already an edge.
    Drop,
}

/// The pair's checks beyond boxes, kinds and layers, as avian's broadphase makes them.
fn judge(
    p1: &ColliderTreeProxy,
    p2: &ColliderTreeProxy,
    contact_graph: &ContactGraph,
    joint_graph: &JointGraph,
    hooks: &impl CollisionHooks,
    commands: &mut Commands,
) -> Verdict {
    // Colliders of one body never pair (nor two colliders without a body, as in avian).
    if p1.body == p2.body {
        return Verdict::Drop;
    }
    if contact_graph.contains_key(&PairKey::new(
        p1.collider.index_u32(),
        p2.collider.index_u32(),
    )) {
        return Verdict::Drop;
    }
    if let (Some(b1), Some(b2)) = (p1.body, p2.body)
        && joint_graph
            .joints_between(b1, b2)
            .any(|edge| edge.collision_disabled)
    {
        return Verdict::Hold;
    }
    if p1
        .flags
        .union(p2.flags)
        .contains(ColliderTreeProxyFlags::CUSTOM_FILTER)
        && !hooks.filter_pairs(p1.collider, p2.collider, commands)
    {
        return Verdict::Hold;
    }
    Verdict::Add
}

/// Adds the edge of a pair, its flags from the two proxies' as avian sets them.
fn add_edge(contact_graph: &mut ContactGraph, p1: &ColliderTreeProxy, p2: &ColliderTreeProxy) {
    let mut edge = ContactEdge::new(p1.collider, p2.collider);
    edge.body1 = p1.body;
    edge.body2 = p2.body;
    let flags = p1.flags.union(p2.flags);
    edge.flags.set(
        ContactEdgeFlags::CONTACT_EVENTS,
        flags.contains(ColliderTreeProxyFlags::CONTACT_EVENTS),
    );
    contact_graph.add_edge_with(edge, |pair| {
        pair.body1 = p1.body;
        pair.body2 = p2.body;
        pair.flags.set(
            ContactPairFlags::MODIFY_CONTACTS,
            flags.contains(ColliderTreeProxyFlags::MODIFY_CONTACTS),
        );
        pair.flags.set(
            ContactPairFlags::GENERATE_CONSTRAINTS,
            !flags
                .intersects(ColliderTreeProxyFlags::BODY_DISABLED | ColliderTreeProxyFlags::SENSOR),
        );
    });
}

/// The broadphase's step: the mirror brought up to date, one report, the begun pairs
/// checked and added.
#[allow(clippy::too_many_arguments)]
fn collect_collision_pairs<H: CollisionHooks>(
    mut broad: ResMut<BvkitBroadPhase>,
    trees: Res<ColliderTrees>,
    moved_proxies: Res<MovedProxies>,
    keys: Query<&ColliderTreeProxyKey, Allow<Disabled>>,
    aabbs: Query<&EnlargedAabb, Allow<Disabled>>,
    hooks: StaticSystemParam<H>,
    mut commands: Commands,
    mut contact_graph: ResMut<ContactGraph>,
    joint_graph: Res<JointGraph>,
    mut diagnostics: ResMut<CollisionDiagnostics>,
) where
    for<'w, 's> SystemParamItem<'w, 's, H>: CollisionHooks,
{
    let start = Instant::now();
    let broad = &mut *broad;
    sync_touched(broad, &trees, &keys, &aabbs);
    sync_moved(broad, &trees, &moved_proxies, &aabbs);
    // A step that inserted a quarter of the tree or more loaded a scene: its proxies went in
    // one by one, each down the greedy path, so the tree is built afresh at once rather than
    // over the next steps' upkeep.
    if broad.inserted >= 64 && broad.inserted * 4 >= broad.tree.len() {
        broad.tree.rebuild();
    }
    broad.inserted = 0;
    let written = Instant::now();

    broad.tree.maintain();
    if broad.parallel {
        broad.tree.report_par(&mut broad.pairs);
    } else {
        broad.tree.report(&mut broad.pairs);
    }
    let reported = Instant::now();

    let hooks = hooks.into_inner();
    let BvkitBroadPhase {
        pairs,
        held,
        records,
        reassert,
        tree,
        ..
    } = broad;
    let proxies = |a: u32, b: u32| {
        let r1 = records[a as usize]?;
        let r2 = records[b as usize]?;
        Some((r1, proxy_of(&trees, r1.key)?, r2, proxy_of(&trees, r2.key)?))
    };
    for pair in &pairs.ended {
        held.remove(pair);
    }
    // Held pairs first: a pair refused before is asked again when one of its proxies moved.
    held.retain(|&(a, b), &mut (e1, e2)| {
        let Some((r1, p1, r2, p2)) = proxies(a, b) else {
            return false;
        };
        if (r1.entity, r2.entity) != (e1, e2) {
            return false;
        }
        if !moved_proxies.contains(r1.key) && !moved_proxies.contains(r2.key) {
            return true;
        }
        match judge(p1, p2, &contact_graph, &joint_graph, &hooks, &mut commands) {
            Verdict::Add => {
                add_edge(&mut contact_graph, p1, p2);
                false
            }
            Verdict::Hold => true,
            Verdict::Drop => false,
        }
    });
    // The touched proxies' overlapping pairs, whose edges avian may have removed, are
    // settled with the begun ones.
    reassert.sort_unstable();
    reassert.dedup();
    let mut found = Vec::new();
    for &id in reassert.iter() {
        let (Some(kind), Some(layers), Some(fat)) = (tree.kind(id), tree.layers(id), tree.get(id))
        else {
            continue;
        };
        let _ = tree.query(&fat, layers, |other| {
            let static_pair =
                kind == BodyKind::Static && tree.kind(other) == Some(BodyKind::Static);
            if other != id && !static_pair {
                found.push((id.min(other), id.max(other)));
            }
        });
    }
    for &(a, b) in pairs.begun.iter().chain(&found) {
        let Some((r1, p1, r2, p2)) = proxies(a, b) else {
            continue;
        };
        match judge(p1, p2, &contact_graph, &joint_graph, &hooks, &mut commands) {
            Verdict::Add => add_edge(&mut contact_graph, p1, p2),
            Verdict::Hold => {
                held.insert((a, b), (r1.entity, r2.entity));
            }
            Verdict::Drop => {}
        }
    }
    let end = Instant::now();
    let t = &mut broad.timings;
    t.write += written - start;
    t.report += reported - written;
    t.pairs += end - reported;
    t.steps += 1;
    t.moved += broad.moved.len() as u64;
    t.begun += broad.pairs.begun.len() as u64;
    diagnostics.broad_phase += end - start;
}

/// The colliders the observers noted: each one's proxy compared with avian's, and removed,
/// re-keyed or refiltered to match.
fn sync_touched(
    broad: &mut BvkitBroadPhase,
    trees: &ColliderTrees,
    keys: &Query<&ColliderTreeProxyKey, Allow<Disabled>>,
    aabbs: &Query<&EnlargedAabb, Allow<Disabled>>,
) {
    let mut touched = core::mem::take(&mut broad.touched);
    // A collider is often noted twice (a spawn inserts `Collider` and `ColliderOf`).
    touched.sort_unstable();
    touched.dedup();
    broad.reassert.clear();
    for &entity in &touched {
        let now = keys
            .get(entity)
            .ok()
            .copied()
            .filter(|&k| k != ColliderTreeProxyKey::PLACEHOLDER)
            .and_then(|k| Some((k, proxy_of(trees, k)?)))
            .filter(|(_, p)| p.collider == entity);
        let mine = broad.by_entity.get(&entity).copied();
        match (mine, now) {
            (Some(id), Some((key, proxy)))
                if broad.records[id as usize].map(|r| r.key) == Some(key) =>
            {
                if broad.tree.contains(id) {
                    let _ = broad.tree.set_kind(id, kind_of(key, proxy));
                    let _ = broad.tree.set_layers(id, layers_of(proxy));
                    broad.reassert.push(id);
                }
            }
            (mine, now) => {
                if let Some(id) = mine {
                    broad.detach(id);
                }
                if let Some((key, proxy)) = now
                    && let Ok(aabb) = aabbs.get(entity)
                {
                    if let Some(&stale) = broad.by_key.get(encode(key))
                        && stale != NONE
                    {
                        broad.detach(stale);
                    }
                    broad.attach(entity, key, proxy, fat_of(aabb));
                }
            }
        }
    }
    touched.clear();
    broad.touched = touched;
}

/// The proxies avian marked moved: new ones attached, the others' enlarged boxes written.
fn sync_moved(
    broad: &mut BvkitBroadPhase,
    trees: &ColliderTrees,
    moved_proxies: &MovedProxies,
    aabbs: &Query<&EnlargedAabb, Allow<Disabled>>,
) {
    let mut moved = core::mem::take(&mut broad.moved);
    moved.clear();
    for &key in moved_proxies.proxies() {
        let Some(proxy) = proxy_of(trees, key) else {
            continue;
        };
        let entity = proxy.collider;
        let Ok(aabb) = aabbs.get(entity) else {
            continue;
        };
        let fat = fat_of(aabb);
        match broad.id_of(key, entity) {
            Some(id) if broad.tree.contains(id) => {
                broad.boxes[id as usize] = fat;
                moved.push(id);
            }
            Some(id) => {
                // Refused at insert (a bad box): in with its first good one.
                broad.boxes[id as usize] = fat;
                let _ = broad
                    .tree
                    .insert_with(id, fat, kind_of(key, proxy), layers_of(proxy));
            }
            None => {
                // A new proxy, or a collider under a new key: whatever held either is freed.
                if let Some(&stale) = broad.by_key.get(encode(key))
                    && stale != NONE
                {
                    broad.detach(stale);
                }
                if let Some(&old) = broad.by_entity.get(&entity) {
                    broad.detach(old);
                }
                broad.attach(entity, key, proxy, fat);
            }
        }
    }
    moved.sort_unstable();
    moved.dedup();
    // Sorted and in range, so the write cannot fail; a bad box parks its proxy.
    let _ = broad.tree.write(&moved, &broad.boxes);
    broad.moved = moved;
}
