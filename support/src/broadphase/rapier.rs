//! Pipeline R: rapier3d 0.36.1's own broadphase, `BroadPhaseBvh`, driven as rapier's
//! pipelines drive it, on the scene's bodies, so that bvkit's broadphase is measured against
//! the real peer rather than against our reading of it (pipeline A of `bvh.rs`).
//!
//! # How the colliders move
//!
//! One collider per body, a cuboid of the body's half extents, with no parent: it is placed
//! with `Collider::set_position`, which is how rapier moves a parentless collider, and which
//! marks it `POSITION` (so `needs_broad_phase_update()` holds) and puts it in the set's
//! modified list. A collider on a rigid body would have its world pose written only by the
//! pipeline's body-to-collider propagation, which `BroadPhaseBvh::update` alone does not
//! run (`compute_broad_phase_aabb` reads the collider's own pose), so parentless colliders
//! are the direct way to drive `update` without a pipeline step per frame.
//!
//! A parentless collider counts as attached to a fixed body, and the pair filter of
//! `update` drops fixed–fixed pairs under the default `ActiveCollisionTypes`, so every
//! collider takes `ActiveCollisionTypes::all()` (as rapier's own test of the
//! `CollisionPipeline` does); collision groups are left at their default (all).
//!
//! # Change flags
//!
//! A collider's change flags are crate-private and only rapier's pipelines clear them.
//! Insertion sets all of them, and `update` removes and re-inserts every modified leaf whose
//! flags hold `PARENT`, `PARENT_EFFECTIVE_DOMINANCE` or `GROUPS` (the forced-reinsertion
//! pre-pass of `broad_phase_bvh/update.rs`), and then refits the whole tree. So `new` runs
//! one `CollisionPipeline::step` over the colliders, on a throwaway broadphase and narrow
//! phase, whose `clear_modified_colliders` empties every collider's flags; from then on
//! the only flag a frame sets is `POSITION` (with `IN_MODIFIED_SET`, which keeps the set's
//! modified list at one entry per collider since nothing consumes it). `update` then takes
//! the path of rapier's own steady steps: for each modified collider the broad-phase box,
//! and the leaf left alone while that box stays inside the leaf's fat box
//! (`Unchanged`), else refattened in place (`update_partially_if_present`) or, when fewer
//! than a sixteenth of the leaves changed at the last update and are modified at this one,
//! removed and re-inserted by SAH descent (`reinsert_or_update_if_present`); then the
//! optimiser on its own schedule, a partial or full refit, the pair traversal from the
//! changed leaves and the stale pairs. (Left as inserted, every awake leaf would instead be
//! stored back unfattened each frame: the re-insertion adds no skin.)
//!
//! The tree the frames run on is a fresh `BroadPhaseBvh`, whose first update (in `new`)
//! takes every collider, reset to `POSITION` alone by setting its pose again, as modified:
//! every leaf is inserted, as at a pipeline's first step, and every initial pair reported.
//!
//! # The allowance
//!
//! With `IntegrationParameters::default()` (`length_unit` 1, `normalized_prediction_distance`
//! 0.02) and the collider's default `contact_skin` of 0, `compute_broad_phase_aabb` is the
//! shape's world box grown by `contact_skin + prediction_distance / 2 = 0.01` on every face,
//! and `change_detection_skin` (not adaptive by default) is `0.04 × length_unit`: a leaf
//! that changes stores that box grown by 0.04 more, so 0.05 beyond the tight box on every
//! face, and is left alone until the 0.01-grown box leaves it. A leaf first inserted is not
//! fattened (`insert_new_unchecked` of the 0.01-grown box) until its first change. So a
//! leaf is rewritten once the tight box moves 0.04 beyond where it was (the slack of
//! `Margin::new(0.04, 0)`), but the leaf, which the pair traversal and the stale-pair test
//! compare, is the tight box grown by 0.05 (`Margin::new(0.05, 0)`'s fat box): pairs begin
//! up to 0.1 apart where 0.04 fat boxes begin them up to 0.08 apart.
//!
//! # Timing
//!
//! `frame` times the `update` call alone: the poses are copied before it (bvkit's side gets
//! its poses for free too) and the pair set of [`Rapier::pairs`] is kept after it. Driven
//! without a pipeline, an optimisation pass an update defers (rapier's pipeline would run
//! it alongside the narrow phase) runs at the start of the next update, so inside its time.

use std::collections::HashSet;
use std::time::Instant;

use bvkit::Aabb3;
use parry3d::math::Pose;
use rapier3d::dynamics::{IntegrationParameters, IslandManager, RigidBodySet};
use rapier3d::geometry::{
    ActiveCollisionTypes, BroadPhaseBvh, BroadPhasePairEvent, ColliderBuilder, ColliderHandle,
    ColliderSet, NarrowPhase,
};
use rapier3d::pipeline::CollisionPipeline;

use super::scene::Scene;

/// Pipeline R: rapier3d's own `BroadPhaseBvh`, driven as rapier's pipeline drives it.
pub struct Rapier {
    params: IntegrationParameters,
    /// Empty: the colliders have no parent, but `update` takes the set.
    bodies: RigidBodySet,
    colliders: ColliderSet,
    /// The collider of body `i`; its arena index is `i` (inserted in order into an empty set).
    handles: Vec<ColliderHandle>,
    broad_phase: BroadPhaseBvh,
    /// The awake colliders of the frame, the `modified_colliders` of `update`.
    modified: Vec<ColliderHandle>,
    /// The events of the last update, kept to reuse their buffer.
    events: Vec<BroadPhasePairEvent>,
    pairs: HashSet<(u32, u32)>,
}

/// One frame of pipeline R.
#[derive(Clone, Copy, Debug, Default)]
pub struct RapierFrame {
    /// The milliseconds of the `BroadPhaseBvh::update` call.
    pub ms: f64,
    /// The pairs that began (`AddPair` events).
    pub begun: usize,
    /// The pairs that ended (`DeletePair` events).
    pub ended: usize,
}

/// A body's pose in rapier's form (rapier's math is parry's).
fn pose(p: &bvkit::Rigid3) -> Pose {
    Pose::from_parts(p.translation.into(), p.rotation)
}

impl Rapier {
    /// One collider per scene body: a cuboid with the body's local half extents (the scene's
    /// local boxes are centred), at the body's pose. Clears the colliders' change flags
    /// through one `CollisionPipeline::step` (module docs), then runs the first update, in
    /// which every initial pair is reported.
    pub fn new(scene: &Scene) -> Self {
        let params = IntegrationParameters::default();
        let mut bodies = RigidBodySet::new();
        let mut colliders = ColliderSet::new();
        let handles: Vec<ColliderHandle> = scene
            .local
            .iter()
            .zip(&scene.poses)
            .enumerate()
            .map(|(i, (b, p))| {
                // A cuboid is centred on its collider's origin, so the body's box must be too
                // for the collider's pose to be the body's.
                assert_eq!(b.min, -b.max, "body {i}: local box not centred");
                let collider = ColliderBuilder::cuboid(b.max.x, b.max.y, b.max.z)
                    .position(pose(p))
                    .active_collision_types(ActiveCollisionTypes::all())
                    .build();
                let handle = colliders.insert(collider);
                // `pairs` maps a handle back to its body by the arena index.
                assert_eq!(handle.into_raw_parts().0, i as u32);
                handle
            })
            .collect();

        // The one pipeline step that clears the flags insertion set, on a broadphase and a
        // narrow phase of its own: its pairs are not the frames' (module docs).
        CollisionPipeline::new().step(
            params.prediction_distance(),
            &mut IslandManager::new(),
            &mut BroadPhaseBvh::new(),
            &mut NarrowPhase::new(),
            &mut bodies,
            &mut colliders,
            &(),
            &(),
        );

        // Every collider marked `POSITION` (at the same pose), so the first update inserts
        // them all.
        for (h, p) in handles.iter().zip(&scene.poses) {
            colliders
                .get_mut(*h)
                .expect("inserted above")
                .set_position(pose(p));
        }
        let mut rapier = Self {
            params,
            bodies,
            colliders,
            handles: handles.clone(),
            broad_phase: BroadPhaseBvh::new(),
            modified: handles,
            events: Vec::new(),
            pairs: HashSet::new(),
        };
        rapier.update();
        rapier
    }

    /// One frame: copies the awake bodies' poses from `scene` (untimed), then times
    /// `BroadPhaseBvh::update` with the awake colliders as the modified ones and none
    /// removed, and applies its pair events to [`Self::pairs`] (untimed).
    pub fn frame(&mut self, scene: &Scene) -> RapierFrame {
        self.modified.clear();
        for i in scene.awake() {
            let h = self.handles[i];
            self.colliders
                .get_mut(h)
                .expect("one collider per body")
                .set_position(pose(&scene.poses[i]));
            self.modified.push(h);
        }
        self.update()
    }

    /// The update over the colliders of `modified`, timed, then its events applied.
    fn update(&mut self) -> RapierFrame {
        self.events.clear();
        let start = Instant::now();
        self.broad_phase.update(
            &self.params,
            &self.colliders,
            &self.bodies,
            &self.modified,
            &[],
            &mut self.events,
        );
        let ms = start.elapsed().as_secs_f64() * 1e3;
        let mut frame = RapierFrame {
            ms,
            ..RapierFrame::default()
        };
        for event in &self.events {
            match event {
                BroadPhasePairEvent::AddPair(p) => {
                    frame.begun += 1;
                    self.pairs.insert(body_pair(p.collider1, p.collider2));
                }
                BroadPhasePairEvent::DeletePair(p) => {
                    frame.ended += 1;
                    self.pairs.remove(&body_pair(p.collider1, p.collider2));
                }
            }
        }
        frame
    }

    /// The set of pairs rapier considers current (every `AddPair` since the start, less
    /// every `DeletePair`), as (smaller body index, larger body index).
    pub fn pairs(&self) -> &HashSet<(u32, u32)> {
        &self.pairs
    }

    /// Checks that every pair of bodies whose world boxes overlap (closed boxes, one box per
    /// body, e.g. the Outward tight boxes) is in [`Self::pairs`]; returns the number missing.
    pub fn missing(&self, world: &[Aabb3]) -> usize {
        let boxes: Vec<_> = world.iter().map(super::parry_box).collect();
        super::overlapping(&boxes)
            .iter()
            .filter(|pair| !self.pairs.contains(pair))
            .count()
    }
}

/// The bodies of a pair of colliders, smaller first.
fn body_pair(a: ColliderHandle, b: ColliderHandle) -> (u32, u32) {
    let (a, b) = (a.into_raw_parts().0, b.into_raw_parts().0);
    (a.min(b), a.max(b))
}
