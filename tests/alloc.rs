//! No heap allocation per query or cast of the broadphase tree: a counting allocator around
//! the system's counts the allocations of this thread while box and point queries, ray
//! casts (all hits, closest, any), box casts and a batch of rays run on a tree of 20,000
//! proxies of every kind, after 60 frames of motion.
#![allow(unsafe_code)]

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

use bvkit::Aabb3;
use bvkit::broadphase::{BodyKind, CastControl, DynamicTree, Layers, Pairs, Ray};
use glam::Vec3A;
use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};

thread_local! {
    /// The allocations made on this thread.
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

/// The system allocator, counting.
struct Counting;

// SAFETY: every call is forwarded unchanged to the system allocator, which upholds
// `GlobalAlloc`'s contract; the count is a thread-local `Cell` with a constant initialiser,
// which neither allocates nor unwinds.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.with(|n| n.set(n.get() + 1));
        // SAFETY: the caller's guarantees for `layout` are the system allocator's.
        unsafe { System.alloc(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: `ptr` came from `System.alloc` with this `layout` (through `alloc`).
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCATIONS.with(|n| n.set(n.get() + 1));
        // SAFETY: as for `dealloc`, and `new_size` is the caller's to guarantee.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static COUNTING: Counting = Counting;

fn allocations() -> usize {
    ALLOCATIONS.with(Cell::get)
}

#[test]
fn queries_and_casts_allocate_nothing() {
    const N: u32 = 20_000;
    let mut r = StdRng::seed_from_u64(3);
    let half = 500.0 * (N as f32 / 1e6).cbrt();
    let mut centres: Vec<Vec3A> = (0..N)
        .map(|_| Vec3A::new(r.random(), r.random(), r.random()) * 2.0 * half - half)
        .collect();
    let boxed = |c: Vec3A| Aabb3::new(c - 0.6, c + 0.6);
    let fat: Vec<Aabb3> = centres.iter().map(|&c| boxed(c)).collect();
    let kind =
        |id: u32| [BodyKind::Dynamic, BodyKind::Kinematic, BodyKind::Static][id as usize % 3];
    let mut tree = DynamicTree::from_boxes_with(&fat[..], |id| {
        (kind(id), Layers::new(1 << (id % 2), u32::MAX))
    })
    .unwrap();
    let mut pairs = Pairs::with_ended();
    let mut fat = fat;
    for _ in 0..60 {
        let moved: Vec<u32> = (0..N).filter(|&id| kind(id) != BodyKind::Static).collect();
        for &id in &moved {
            centres[id as usize] += Vec3A::new(r.random(), r.random(), r.random()) - 0.5;
            fat[id as usize] = boxed(centres[id as usize]);
        }
        tree.update(&moved, &fat[..], &mut pairs).unwrap();
    }
    let rays: Vec<Ray> = (0..256)
        .map(|_| {
            let origin = Vec3A::new(r.random(), r.random(), r.random()) * 2.0 * half - half;
            let direction = Vec3A::new(r.random(), r.random(), r.random()) - 0.5;
            Ray::new(origin, direction, 2.0 * half)
        })
        .collect();
    let mut out = vec![f32::INFINITY; rays.len()];
    let (mut found, mut cast) = (0usize, 0usize);

    let before = allocations();
    for (k, ray) in rays.iter().enumerate() {
        let b = Aabb3::new(ray.origin - 3.0, ray.origin + 3.0);
        tree.query(&b, Layers::ALL, |_| found += 1).unwrap();
        tree.query_point(ray.origin, Layers::new(1, 1), |_| found += 1)
            .unwrap();
        let mut all = |_: u32, _: f32| {
            cast += 1;
            CastControl::Continue
        };
        tree.cast_ray(ray, Layers::ALL, &mut all).unwrap();
        tree.cast_ray(ray, Layers::ALL, |_, t| CastControl::Clip(t))
            .unwrap();
        tree.cast_ray(ray, Layers::new(2, 2), |_, _| CastControl::Stop)
            .unwrap();
        tree.cast_box(&b, ray.direction, 10.0, Layers::ALL, |_, t| {
            cast += usize::from(k % 2 == 0);
            CastControl::Clip(t)
        })
        .unwrap();
    }
    tree.cast_rays(&rays, Layers::ALL, &mut out, |_, _, t, best| {
        *best = best.min(t);
        CastControl::Clip(t)
    })
    .unwrap();
    let during = allocations() - before;

    assert_eq!(during, 0, "allocations during the queries and casts");
    // Not vacuous: the queries and casts found things.
    assert!(found > 50 && cast > 100, "{found} {cast}");
    assert!(out.iter().filter(|t| t.is_finite()).count() > 32);
    // And the counter counts: a vector allocates.
    let before = allocations();
    let v: Vec<u64> = Vec::with_capacity(8);
    assert!(allocations() > before && v.capacity() >= 8);
}
