//! [`BvkitSpatialQuery`]: avian's `SpatialQuery` verbs answered from bvkit's tree.

use avian3d::collider_tree::ColliderTrees;
use avian3d::prelude::*;
use bevy::ecs::system::SystemParam;
use bevy::prelude::*;
use bvkit::broadphase::{CastControl, Layers, Ray};
use bvkit::glam::Vec3A;

use crate::BvkitBroadPhase;

/// A system parameter with avian's `SpatialQuery` verbs, answered from the plugin's tree
/// rather than avian's `ColliderTrees`: the tree's proven-conservative cast or box query
/// over the enlarged boxes finds the candidates, then each collider's own shape (its
/// `Collider::cast_ray`) or tight `ColliderAabb` decides, as avian decides after its trees.
/// The answers are avian's (`tests/spatial_query.rs` checks them against `SpatialQuery`);
/// they see the world as of the last physics step's broadphase.
#[derive(SystemParam)]
pub struct BvkitSpatialQuery<'w, 's> {
    colliders: Query<'w, 's, (&'static Position, &'static Rotation, &'static Collider)>,
    aabbs: Query<'w, 's, &'static ColliderAabb>,
    trees: Res<'w, ColliderTrees>,
    broad: Res<'w, BvkitBroadPhase>,
}

impl BvkitSpatialQuery<'_, '_> {
    /// The collider of tree proxy `id`, if `filter` lets it through (its layers as avian's
    /// proxy holds them).
    fn admitted(&self, id: u32, filter: &SpatialQueryFilter) -> Option<Entity> {
        let record = self.broad.record(id)?;
        let proxy = self
            .trees
            .tree_for_type(record.key.tree_type())
            .get_proxy(record.key.id())?;
        filter
            .test(proxy.collider, proxy.layers)
            .then_some(proxy.collider)
    }

    /// The ray's hit on `collider`'s shape, if any within `max_distance`.
    fn hit(
        &self,
        collider: Entity,
        origin: Vec3,
        direction: Dir3,
        max_distance: f32,
        solid: bool,
    ) -> Option<RayHitData> {
        let (position, rotation, shape) = self.colliders.get(collider).ok()?;
        let (distance, normal) = shape.cast_ray(
            position.0,
            *rotation,
            origin,
            *direction,
            max_distance,
            solid,
        )?;
        Some(RayHitData {
            entity: collider,
            distance,
            normal,
        })
    }

    /// The closest hit of a ray with a collider's shape (avian's `SpatialQuery::cast_ray`).
    #[must_use]
    pub fn cast_ray(
        &self,
        origin: Vec3,
        direction: Dir3,
        max_distance: f32,
        solid: bool,
        filter: &SpatialQueryFilter,
    ) -> Option<RayHitData> {
        let mut closest: Option<RayHitData> = None;
        let ray = Ray::new(
            Vec3A::from_array(origin.to_array()),
            Vec3A::from_array(direction.to_array()),
            max_distance,
        );
        // Layers are checked by avian's filter on each candidate.
        let _ = self.broad.tree().cast_ray(&ray, Layers::ALL, |id, _entry| {
            let Some(collider) = self.admitted(id, filter) else {
                return CastControl::Continue;
            };
            let best = closest.map_or(max_distance, |c| c.distance);
            match self.hit(collider, origin, direction, best, solid) {
                Some(hit) if closest.is_none_or(|c| hit.distance < c.distance) => {
                    closest = Some(hit);
                    // No box entered beyond this hit can hold a closer one.
                    CastControl::Clip(hit.distance)
                }
                _ => CastControl::Continue,
            }
        });
        closest
    }

    /// Up to `max_hits` hits of a ray with colliders' shapes, in no particular order
    /// (avian's `SpatialQuery::ray_hits`).
    #[must_use]
    pub fn ray_hits(
        &self,
        origin: Vec3,
        direction: Dir3,
        max_distance: f32,
        max_hits: u32,
        solid: bool,
        filter: &SpatialQueryFilter,
    ) -> Vec<RayHitData> {
        let mut hits = Vec::new();
        if max_hits == 0 {
            return hits;
        }
        let ray = Ray::new(
            Vec3A::from_array(origin.to_array()),
            Vec3A::from_array(direction.to_array()),
            max_distance,
        );
        let _ = self.broad.tree().cast_ray(&ray, Layers::ALL, |id, _entry| {
            if let Some(collider) = self.admitted(id, filter)
                && let Some(hit) = self.hit(collider, origin, direction, max_distance, solid)
            {
                hits.push(hit);
                if hits.len() >= max_hits as usize {
                    return CastControl::Stop;
                }
            }
            CastControl::Continue
        });
        hits
    }

    /// The colliders whose `ColliderAabb` shares a point with `aabb` (avian's
    /// `SpatialQuery::aabb_intersections_with_aabb`). A NaN or inverted `aabb` finds none.
    #[must_use]
    pub fn aabb_intersections_with_aabb(&self, aabb: ColliderAabb) -> Vec<Entity> {
        let mut found = Vec::new();
        let query = bvkit::Aabb3::new(
            Vec3A::from_array(aabb.min.to_array()),
            Vec3A::from_array(aabb.max.to_array()),
        );
        let _ = self.broad.tree().query(&query, Layers::ALL, |id| {
            let Some(collider) = self.broad.collider(id) else {
                return;
            };
            // The tree holds the enlarged boxes: the collider's own box decides.
            if self.aabbs.get(collider).is_ok_and(|b| b.intersects(&aabb)) {
                found.push(collider);
            }
        });
        found
    }

    /// The colliders whose shape contains `point` (avian's
    /// `SpatialQuery::point_intersections`).
    #[must_use]
    pub fn point_intersections(&self, point: Vec3, filter: &SpatialQueryFilter) -> Vec<Entity> {
        let mut found = Vec::new();
        let _ =
            self.broad
                .tree()
                .query_point(Vec3A::from_array(point.to_array()), Layers::ALL, |id| {
                    if let Some(collider) = self.admitted(id, filter)
                        && let Ok((position, rotation, shape)) = self.colliders.get(collider)
                        && shape.contains_point(position.0, *rotation, point)
                    {
                        found.push(collider);
                    }
                });
        found
    }
}
