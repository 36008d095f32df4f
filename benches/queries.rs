//! Queries from a broadphase's tree, side by side in one run: closest-hit ray casts and box
//! queries on bvkit's `DynamicTree`, parry3d's `Bvh` and obvhs (its `CwBvh`, built for rays,
//! for the casts; its `Bvh2` for the boxes), each tree as its pipeline keeps it after 60
//! frames of the broadphase example's walk (`support/src/broadphase/queries.rs`), over the
//! same fat boxes, every leaf test the box's alone. At 100K bodies all awake and at 1M
//! with half asleep; 1024 rays (from random points in the scene, random directions, as long
//! as the scene is wide) or 1024 boxes (4-unit cubes) per iteration, on one core and on
//! every core (rayon). `cargo bench --features peers --bench queries`: criterion's
//! throughput is rays (or boxes) per second.
//!
//! Before timing, the three trees' answers are compared: the same closest box (or a box
//! entered within `1e-4` relative of it), unless bvkit's is a near miss that its widened
//! test lets through (checked exactly, and counted), and the same box counts.

use bvkit_support::broadphase::queries::Trees;
use bvkit_support::broadphase::scene::Scene;
use bvkit_support::common::cpu;
use bvkit_support::referee::{exact_entry, near_miss};

use std::hint::black_box;

use bvkit::broadphase::{CastControl, Layers};
use bvkit_support::criterion;
use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use rayon::prelude::*;

const RAYS: usize = 1024;

/// Checks that the three trees answer alike, and prints what they found.
fn agree(label: &str, trees: &Trees, rays: &[bvkit::broadphase::Ray], boxes: &[bvkit::Aabb3]) {
    let (mut hits, mut grazes) = (0, 0);
    for ray in rays {
        let (a, b, c) = (
            trees.closest_bvkit(ray),
            trees.closest_parry(ray),
            trees.closest_obvhs(ray),
        );
        let near = |x: Option<(u32, f32)>, y: Option<(u32, f32)>| match (x, y) {
            (None, None) => true,
            (Some((i, s)), Some((j, t))) => i == j || (s - t).abs() <= 1e-4 * s.abs().max(1.0),
            _ => false,
        };
        // bvkit's closest may be a box the exact ray just misses (conservative by proof).
        let grazed = a.is_some_and(|(id, t)| {
            let b = &trees.fat[id as usize];
            let (o, d) = (ray.origin, ray.direction);
            exact_entry(o, o, d, ray.max, b).is_none()
                && near_miss(o, o, d, ray.max, b)
                && c.is_none_or(|(_, s)| t <= s)
        });
        grazes += usize::from(grazed);
        assert!(
            grazed || (near(a, b) && near(a, c)),
            "{ray:?}: bvkit {a:?}, parry {b:?}, obvhs {c:?}"
        );
        hits += usize::from(a.is_some());
    }
    let mut found = 0;
    for b in boxes {
        let n = trees.query_bvkit(b);
        assert_eq!(n, trees.query_parry(b), "{b:?}");
        assert_eq!(n, trees.query_obvhs(b), "{b:?}");
        found += n;
    }
    println!(
        "queries/{label}: {} boxes, CPU {}; of {RAYS} rays {hits} hit a box ({grazes} of them, \
         for bvkit, a box the exact ray just misses); {RAYS} boxes found {found}; obvhs's \
         CwBvh conversion {:.1} ms (not timed below); {} threads",
        trees.fat.len(),
        cpu(),
        trees.cwbvh_ms,
        rayon::current_num_threads(),
    );
}

fn queries(c: &mut Criterion) {
    for (n, asleep, label) in [
        (100_000, 0.0, "100K-awake"),
        (1_000_000, 0.5, "1M-half-asleep"),
    ] {
        let trees = Trees::after(Scene::new(n, asleep, 256), 60);
        let rays = trees.rays(RAYS, 2.0 * trees.half, 1);
        let boxes = trees.boxes(RAYS, 4.0, 2);
        agree(label, &trees, &rays, &boxes);

        let mut g = c.benchmark_group(format!("rays/{label}"));
        g.throughput(Throughput::Elements(RAYS as u64));
        g.bench_function("bvkit", |b| {
            b.iter(|| {
                rays.iter()
                    .map(|r| trees.closest_bvkit(r))
                    .filter(Option::is_some)
                    .count()
            })
        });
        g.bench_function("parry3d", |b| {
            b.iter(|| {
                rays.iter()
                    .map(|r| trees.closest_parry(r))
                    .filter(Option::is_some)
                    .count()
            })
        });
        g.bench_function("obvhs-cwbvh", |b| {
            b.iter(|| {
                rays.iter()
                    .map(|r| trees.closest_obvhs(r))
                    .filter(Option::is_some)
                    .count()
            })
        });
        // Every core: bvkit's own batch, the peers' casts in a rayon loop.
        let mut out = vec![f32::INFINITY; RAYS];
        g.bench_function("bvkit-every-core", |b| {
            b.iter(|| {
                out.fill(f32::INFINITY);
                trees
                    .bvkit
                    .cast_rays_par(&rays, Layers::ALL, &mut out, |_, _, t, best| {
                        *best = best.min(t);
                        CastControl::Clip(t)
                    })
                    .expect("valid rays");
                black_box(&out);
            })
        });
        g.bench_function("parry3d-every-core", |b| {
            b.iter(|| {
                rays.par_iter()
                    .map(|r| trees.closest_parry(r))
                    .filter(Option::is_some)
                    .count()
            })
        });
        g.bench_function("obvhs-cwbvh-every-core", |b| {
            b.iter(|| {
                rays.par_iter()
                    .map(|r| trees.closest_obvhs(r))
                    .filter(Option::is_some)
                    .count()
            })
        });
        g.finish();

        let mut g = c.benchmark_group(format!("boxes/{label}"));
        g.throughput(Throughput::Elements(RAYS as u64));
        g.bench_function("bvkit", |b| {
            b.iter(|| boxes.iter().map(|q| trees.query_bvkit(q)).sum::<usize>())
        });
        g.bench_function("parry3d", |b| {
            b.iter(|| boxes.iter().map(|q| trees.query_parry(q)).sum::<usize>())
        });
        g.bench_function("obvhs-bvh2", |b| {
            b.iter(|| boxes.iter().map(|q| trees.query_obvhs(q)).sum::<usize>())
        });
        g.finish();
    }
}

criterion_group!(benches, queries);
criterion_main!(benches);
