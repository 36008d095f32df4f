//! The broadphase tree's casts against the exact referee (`bvkit_support::referee`, rational
//! arithmetic on the given `f32` values): a ray or a moving box never misses a box it meets
//! within its length, never reports an entry beyond the exact one (and stays within two
//! `f32` steps of it), on random trees and rays and on the cases where a float slab test
//! goes wrong: grazing and axis-parallel rays, rays through corners and along edges, origins
//! inside boxes and on their faces, coordinates near `1e30` and near zero (subnormal
//! included). The callback's controls (clip, stop) and the refusals of bad input.

use bvkit::Aabb3;
use bvkit::broadphase::{BodyKind, BroadphaseError, CastControl, DynamicTree, Layers, Ray};
use bvkit_support::referee::{Check, Op, Referee, State, check_cast, exact_entry};
use glam::Vec3A;
use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};

/// Random trees and casts of every kind: the casts come from the same decoder as the fuzz
/// target's, among inserts, moves and kind and layer changes.
#[test]
fn random_casts_meet_every_box_the_exact_cast_meets() {
    let (mut hits, mut extra) = (0, 0);
    for seed in 0..256 {
        let mut r = StdRng::seed_from_u64(seed);
        let mut byte = || r.random::<u8>();
        let mut check = Check::new(40);
        for _ in 0..400 {
            let op = Op::decode(&mut byte, 40);
            check.apply(&op, false);
        }
        hits += check.hits;
        extra += check.extra_hits;
    }
    // Not vacuous; every hit the exact cast does not meet was a near miss (checked in
    // `check_cast`), and they are few.
    assert!(hits > 3000, "{hits} hits");
    println!("{hits} hits, {extra} near misses");
    assert!(
        extra * 100 <= hits,
        "{extra} of {hits} hits are near misses"
    );
}

/// A tree of the referee's proxies: unit cubes `[k, k + 1]·s` along the diagonal at scale
/// `s`, and a few around them.
fn cubes(s: f32) -> (DynamicTree, Referee) {
    let mut tree = DynamicTree::new();
    let mut referee = Referee::new(12);
    let corners = [
        Vec3A::ZERO,
        Vec3A::splat(2.0),
        Vec3A::new(4.0, 0.0, 0.0),
        Vec3A::new(0.0, 4.0, 0.0),
        Vec3A::new(0.0, 0.0, 4.0),
        Vec3A::new(2.0, 2.0, 4.0),
        Vec3A::new(-3.0, 1.0, 1.0),
        Vec3A::new(1.0, -3.0, 1.0),
    ];
    for (id, c) in corners.iter().enumerate() {
        let b = Aabb3::new(*c * s, (*c + 1.0) * s);
        let kind = if id % 3 == 0 {
            BodyKind::Static
        } else {
            BodyKind::Dynamic
        };
        tree.insert_with(id as u32, b, kind, Layers::ALL).unwrap();
        referee.proxies[id].state = State::Placed(b);
        referee.proxies[id].kind = kind;
    }
    (tree, referee)
}

/// Every hit of a cast, all taken.
fn all_hits(tree: &DynamicTree, ray: &Ray) -> Vec<(u32, f32)> {
    let mut hits = Vec::new();
    tree.cast_ray(ray, Layers::ALL, |id, entry| {
        hits.push((id, entry));
        CastControl::Continue
    })
    .unwrap();
    hits
}

/// The hard cases at scales from subnormal to `2^100`: each cast against the exact
/// referee (a hit the exact cast misses must be a near miss, checked there).
#[test]
fn grazing_axis_parallel_and_corner_rays_at_every_scale() {
    let scales = [
        1.0,
        2f32.powi(100),
        1e30,
        2f32.powi(-100),
        1e-30,
        2f32.powi(-140),
    ];
    for s in scales {
        let (tree, referee) = cubes(s);
        let p = |x: f32, y: f32, z: f32| Vec3A::new(x, y, z) * s;
        let rays = [
            // Axis-parallel, through the middle of cube 0.
            (p(-1.0, 0.5, 0.5), Vec3A::X),
            // Grazing: in the plane of a face (y = 1), along it.
            (p(-1.0, 1.0, 0.5), Vec3A::X),
            // Along an edge (y = 1, z = 1).
            (p(-1.0, 1.0, 1.0), Vec3A::X),
            // Along an edge, from the other side.
            (p(3.0, 0.0, 0.0), Vec3A::NEG_X),
            // Touching the corner (0, 0, 0) only, at t = s.
            (p(-1.0, 1.0, 0.0), Vec3A::new(1.0, -1.0, 0.0)),
            // Through the corners of cubes 0 and 1 and the diagonal between them.
            (p(-1.0, -1.0, -1.0), Vec3A::ONE),
            // Origin inside cube 0, on its face, on its edge, on its corner.
            (p(0.5, 0.5, 0.5), Vec3A::new(0.3, -0.2, 0.1)),
            (p(1.0, 0.5, 0.5), Vec3A::X),
            (p(1.0, 1.0, 0.5), Vec3A::new(1.0, 1.0, 0.0)),
            (p(1.0, 1.0, 1.0), Vec3A::ONE),
            // Just missing the face plane by one step.
            (
                p(-1.0, 1.0, 0.5) + Vec3A::new(0.0, (s * 1.0).next_up() - s, 0.0),
                Vec3A::X,
            ),
            // Directions with a tiny and a huge component.
            (p(-1.0, 0.5, 0.5), Vec3A::new(1.0, 1e-38, -1e-45)),
            (p(-1.0, 0.5, 0.5), Vec3A::new(1e30, 1.0, 0.0)),
            // Away from everything.
            (p(-1.0, -1.0, -1.0), Vec3A::NEG_ONE),
        ];
        for (origin, direction) in rays {
            for max in [f32::INFINITY, 2.0 * s, s, 0.0] {
                let ray = Ray::new(origin, direction, max);
                let hits = all_hits(&tree, &ray);
                let cast = (origin, origin, direction, max);
                check_cast(&referee, cast, Layers::ALL, &hits);
            }
        }
        // The corner-touching ray meets cube 0 at exactly t = s.
        let ray = Ray::new(p(-1.0, 1.0, 0.0), Vec3A::new(1.0, -1.0, 0.0), f32::INFINITY);
        let b = Aabb3::new(Vec3A::ZERO, Vec3A::splat(s));
        let exact = exact_entry(ray.origin, ray.origin, ray.direction, ray.max, &b);
        assert!(exact.is_some(), "scale {s}: the corner ray meets cube 0");
        assert!(all_hits(&tree, &ray).iter().any(|h| h.0 == 0));
    }
}

/// A box moving along a vector: the same checks, with boxes that slide along faces, meet at
/// corners and start overlapping.
#[test]
fn moving_boxes_meet_every_box_they_touch() {
    for s in [1.0, 2f32.powi(100), 2f32.powi(-140)] {
        let (tree, referee) = cubes(s);
        let b = |x: f32, y: f32, z: f32, e: f32| {
            let c = Vec3A::new(x, y, z) * s;
            Aabb3::new(c - e * s, c + e * s)
        };
        let casts = [
            (b(-2.0, 0.5, 0.5, 0.5), Vec3A::X),
            (b(-2.0, 1.5, 0.5, 0.5), Vec3A::X),
            (b(-2.0, 1.5, 1.5, 0.5), Vec3A::X),
            (b(-1.0, 2.0, 0.5, 1.0), Vec3A::new(1.0, -1.0, 0.0)),
            (b(0.5, 0.5, 0.5, 0.1), Vec3A::ZERO),
            (b(0.5, 0.5, 0.5, 0.25), Vec3A::ONE),
            (b(-3.0, -3.0, -3.0, 0.5), Vec3A::ONE),
        ];
        for (moving, motion) in casts {
            for max in [f32::INFINITY, s, 0.0] {
                let mut hits = Vec::new();
                tree.cast_box(&moving, motion, max, Layers::ALL, |id, entry| {
                    hits.push((id, entry));
                    CastControl::Continue
                })
                .unwrap();
                let cast = (moving.min, moving.max, motion, max);
                check_cast(&referee, cast, Layers::ALL, &hits);
            }
        }
    }
}

/// A crowd of boxes and many rays: closest hit by clipping finds the least entry of all
/// hits, any hit by stopping calls back once, and a layer filter hides exactly the boxes
/// outside it.
#[test]
fn clip_stop_and_layers_do_what_they_say() {
    let mut r = StdRng::seed_from_u64(7);
    let mut tree = DynamicTree::new();
    for id in 0..3000u32 {
        let c = Vec3A::new(
            r.random_range(-50.0..50.0),
            r.random_range(-50.0..50.0),
            r.random_range(-50.0..50.0),
        );
        let e = Vec3A::splat(r.random_range(0.2..2.0));
        let layers = Layers::new(1 << (id % 4), u32::MAX);
        let kind = [BodyKind::Static, BodyKind::Kinematic, BodyKind::Dynamic][id as usize % 3];
        tree.insert_with(id, Aabb3::new(c - e, c + e), kind, layers)
            .unwrap();
    }
    let (mut some, mut clipped_sooner) = (0, 0);
    for _ in 0..500 {
        let origin = Vec3A::new(
            r.random_range(-60.0..60.0),
            r.random_range(-60.0..60.0),
            r.random_range(-60.0..60.0),
        );
        let direction = Vec3A::new(r.random(), r.random(), r.random()) * 2.0 - 1.0;
        let ray = Ray::new(origin, direction, r.random_range(10.0..200.0));
        let all = all_hits(&tree, &ray);
        // Closest: clip at each hit's entry.
        let (mut best, mut calls) = (f32::INFINITY, 0);
        tree.cast_ray(&ray, Layers::ALL, |_, entry| {
            calls += 1;
            best = best.min(entry);
            CastControl::Clip(entry)
        })
        .unwrap();
        let least = all.iter().map(|h| h.1).fold(f32::INFINITY, f32::min);
        assert_eq!(best, least);
        assert!(calls <= all.len());
        clipped_sooner += usize::from(calls < all.len());
        // Any: one call.
        let mut calls = 0;
        tree.cast_ray(&ray, Layers::ALL, |_, _| {
            calls += 1;
            CastControl::Stop
        })
        .unwrap();
        assert_eq!(calls, usize::from(!all.is_empty()));
        some += usize::from(!all.is_empty());
        // Layers: only the proxies in layer 2 (their filters are all set).
        let mut layered: Vec<u32> = Vec::new();
        tree.cast_ray(&ray, Layers::new(u32::MAX, 1 << 2), |id, _| {
            layered.push(id);
            CastControl::Continue
        })
        .unwrap();
        layered.sort_unstable();
        let mut expected: Vec<u32> = all.iter().map(|h| h.0).filter(|id| id % 4 == 2).collect();
        expected.sort_unstable();
        assert_eq!(layered, expected);
    }
    assert!(some > 100 && clipped_sooner > 20, "{some} {clipped_sooner}");
}

/// Bad input: a clear error, and nothing searched.
#[test]
fn bad_casts_and_queries_are_refused() {
    let (tree, _) = cubes(1.0);
    let never = |_: u32, _: f32| -> CastControl { panic!("nothing is cast") };
    let o = Vec3A::splat(-1.0);
    let bad_rays = [
        Ray::new(Vec3A::new(f32::NAN, 0.0, 0.0), Vec3A::X, 1.0),
        Ray::new(Vec3A::new(f32::INFINITY, 0.0, 0.0), Vec3A::X, 1.0),
        Ray::new(o, Vec3A::new(0.0, f32::NAN, 0.0), 1.0),
        Ray::new(o, Vec3A::new(0.0, f32::NEG_INFINITY, 0.0), 1.0),
        Ray::new(o, Vec3A::ZERO, 1.0),
        Ray::new(o, -Vec3A::ZERO, 1.0),
        Ray::new(o, Vec3A::X, -1.0),
        Ray::new(o, Vec3A::X, f32::NAN),
        Ray::new(o, Vec3A::X, f32::NEG_INFINITY),
    ];
    for ray in bad_rays {
        assert!(!ray.is_valid());
        let got = tree.cast_ray(&ray, Layers::ALL, never);
        assert_eq!(got, Err(BroadphaseError::InvalidCast), "{ray:?}");
    }
    let b = Aabb3::new(Vec3A::ZERO, Vec3A::ONE);
    let bad_boxes = [
        Aabb3::new(Vec3A::new(f32::NAN, 0.0, 0.0), Vec3A::ONE),
        Aabb3::new(Vec3A::ONE, Vec3A::ZERO),
        Aabb3::EMPTY,
        Aabb3::new(Vec3A::NEG_INFINITY, Vec3A::ONE),
    ];
    for bad in bad_boxes {
        let got = tree.cast_box(&bad, Vec3A::X, 1.0, Layers::ALL, never);
        assert_eq!(got, Err(BroadphaseError::InvalidCast), "{bad:?}");
    }
    for (motion, max) in [(Vec3A::NAN, 1.0), (Vec3A::INFINITY, 1.0), (Vec3A::X, -0.5)] {
        let got = tree.cast_box(&b, motion, max, Layers::ALL, never);
        assert_eq!(got, Err(BroadphaseError::InvalidCast));
    }
    let never = |_: u32| panic!("nothing is searched");
    for bad in [bad_boxes[0], bad_boxes[1], bad_boxes[2]] {
        assert_eq!(
            tree.query(&bad, Layers::ALL, never),
            Err(BroadphaseError::InvalidQuery)
        );
    }
    assert_eq!(
        tree.query_point(Vec3A::new(0.0, f32::NAN, 0.0), Layers::ALL, never),
        Err(BroadphaseError::InvalidQuery)
    );
    // Infinite query faces are fine.
    let mut n = 0;
    tree.query(&bad_boxes[3], Layers::ALL, |_| n += 1).unwrap();
    assert!(n > 0);
    // Batches: a bad ray or a short output refuses the whole batch.
    let rays = [Ray::new(o, Vec3A::X, 10.0), bad_rays[0]];
    let mut out = [0u32; 2];
    let got = tree.cast_rays(&rays, Layers::ALL, &mut out, |_, _, _, _| panic!("none"));
    assert_eq!(got, Err(BroadphaseError::InvalidCast));
    let got = tree.cast_rays(&rays[..1], Layers::ALL, &mut out, |_, _, _, _| {
        panic!("none")
    });
    assert_eq!(got, Err(BroadphaseError::OutputLength { rays: 1, len: 2 }));
    // Unknown ids.
    let mut tree = tree;
    assert_eq!(
        tree.set_kind(99, BodyKind::Static),
        Err(BroadphaseError::UnknownId { id: 99 })
    );
    assert_eq!(
        tree.set_layers(99, Layers::NONE),
        Err(BroadphaseError::UnknownId { id: 99 })
    );
}

/// Under flush-to-zero and denormals-are-zero, as engines run: casts among boxes whose
/// coordinates are tiny normal numbers (near `2^-125`, where differences and products
/// underflow and are flushed) and at unit scale, with directions from `2^-20` to `2^19`, keep
/// the guarantee, checked outside the modes against the exact referee.
#[cfg(target_arch = "x86_64")]
#[test]
fn casts_keep_their_guarantee_under_ftz_and_daz() {
    use bvkit_support::mxcsr;
    let mut r = StdRng::seed_from_u64(126);
    for scale in [2f32.powi(-125), 2f32.powi(-110), 1.0] {
        let mut tree = DynamicTree::new();
        let mut referee = Referee::new(32);
        // Corners on a grid of steps of scale/8 above scale: normal, with differences that
        // are subnormal at the smallest scale.
        let at = |r: &mut StdRng| scale * (1.0 + f32::from(r.random_range(0u8..16)) / 8.0);
        for id in 0..32u32 {
            let min = Vec3A::new(at(&mut r), at(&mut r), at(&mut r));
            let b = Aabb3::new(min, min + Vec3A::splat(scale / 4.0));
            tree.insert(id, b).unwrap();
            referee.proxies[id as usize].state = State::Placed(b);
        }
        let directions = [
            Vec3A::new(2f32.powi(-20), 2f32.powi(-20), 0.0),
            Vec3A::new(1.0, 0.5, -0.25),
            Vec3A::new(2f32.powi(19), 1.0, 0.0),
            Vec3A::X,
        ];
        for _ in 0..200 {
            let origin = Vec3A::new(at(&mut r), at(&mut r), at(&mut r)) - scale / 2.0;
            let direction = directions[r.random_range(0..directions.len())];
            let ray = Ray::new(origin, direction, f32::INFINITY);
            let (hits, _) = mxcsr::run(mxcsr::FTZ | mxcsr::DAZ, &tree, |tree| all_hits(tree, &ray));
            check_cast(
                &referee,
                (origin, origin, direction, ray.max),
                Layers::ALL,
                &hits,
            );
        }
    }
}
