//! `BvkitSpatialQuery` against avian's own `SpatialQuery` on the same world: the same
//! closest hit (distance bit for bit), the same ray hits, box and point intersections.

mod scenes;

use std::collections::BTreeSet;

use avian3d::prelude::*;
use bevy::ecs::system::SystemState;
use bevy::prelude::*;
use bvkit_avian3d::BvkitSpatialQuery;
use scenes::{Broad, app, level, run};

/// A small deterministic generator (xorshift).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }

    fn in_range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.next()
    }

    fn point(&mut self) -> Vec3 {
        Vec3::new(
            self.in_range(-10.0, 10.0),
            self.in_range(-1.0, 6.0),
            self.in_range(-10.0, 10.0),
        )
    }
}

fn set<T: Ord>(items: impl IntoIterator<Item = T>) -> BTreeSet<T> {
    items.into_iter().collect()
}

#[test]
fn bvkit_answers_as_avian_does() {
    let mut app = app(Broad::Bvkit { parallel: false }, 2);
    let debris = level(app.world_mut(), 8, 60);
    // Some debris in a second layer, and one left out by the filter below.
    for &e in debris.iter().step_by(4) {
        app.world_mut()
            .entity_mut(e)
            .insert(CollisionLayers::new(0b10, 0b11));
    }
    run(&mut app, 60);
    let excluded = debris[1];
    let filters = [
        SpatialQueryFilter::default(),
        SpatialQueryFilter::from_mask(0b10),
        SpatialQueryFilter::default().with_excluded_entities([excluded]),
    ];
    let mut state: SystemState<(SpatialQuery, BvkitSpatialQuery)> =
        SystemState::new(app.world_mut());
    let (avian, bvkit) = state.get(app.world()).expect("the queries run");
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let (mut closest, mut hits, mut boxes, mut points) = (0, 0, 0, 0);
    for k in 0..600 {
        let filter = &filters[k % filters.len()];
        let origin = rng.point() + Vec3::Y * 4.0;
        let target = rng.point();
        let Ok(direction) = Dir3::new(target - origin) else {
            continue;
        };
        let max = rng.in_range(1.0, 40.0);
        let solid = k % 2 == 0;

        let a = avian.cast_ray(origin, direction, max, solid, filter);
        let b = bvkit.cast_ray(origin, direction, max, solid, filter);
        match (a, b) {
            (None, None) => {}
            (Some(a), Some(b)) => {
                closest += 1;
                assert_eq!(a.distance.to_bits(), b.distance.to_bits(), "ray {k}");
                if a.entity != b.entity {
                    // Two colliders at the same distance: either is the closest.
                    let again = bvkit.ray_hits(origin, direction, max, u32::MAX, solid, filter);
                    assert!(
                        again
                            .iter()
                            .any(|h| h.entity == a.entity && h.distance == a.distance)
                    );
                }
            }
            (a, b) => panic!("ray {k}: avian {a:?}, bvkit {b:?}"),
        }

        let a = avian.ray_hits(origin, direction, max, u32::MAX, solid, filter);
        let b = bvkit.ray_hits(origin, direction, max, u32::MAX, solid, filter);
        hits += a.len();
        assert_eq!(
            set(a.iter().map(|h| (h.entity, h.distance.to_bits()))),
            set(b.iter().map(|h| (h.entity, h.distance.to_bits()))),
            "ray hits {k}"
        );
        assert!(
            b.len() == set(b.iter().map(|h| h.entity)).len(),
            "a collider hit twice"
        );
        let capped = bvkit.ray_hits(origin, direction, max, 1, solid, filter);
        assert_eq!(capped.len(), a.len().min(1));

        let half = Vec3::new(rng.next(), rng.next(), rng.next()) * 2.0;
        let centre = rng.point();
        let aabb = ColliderAabb::new(centre, half);
        let a = set(avian.aabb_intersections_with_aabb(aabb));
        let b = set(bvkit.aabb_intersections_with_aabb(aabb));
        boxes += a.len();
        assert_eq!(a, b, "box {k}");

        let point = rng.point();
        let a = set(avian.point_intersections(point, filter));
        let b = set(bvkit.point_intersections(point, filter));
        points += a.len();
        assert_eq!(a, b, "point {k}");
    }
    // The scene gives every verb answers to compare, not only empty ones.
    assert!(
        closest > 100 && hits > 150 && boxes > 100 && points > 10,
        "{closest} {hits} {boxes} {points}"
    );
}
