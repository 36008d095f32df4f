//! The broadphase's dynamic tree on any number of threads: one tree runs each frame with
//! `DynamicTree::update`, and copies of it with `DynamicTree::update_par` on rayon pools of
//! 1, 2 and 3 threads; every frame's begun, ended and refused lists must be the same, in
//! the same order, bit for bit. The fuzzer picks the scene: up to 4,000 proxies (enough for
//! the report's parts of 512 changed proxies and its traversals' tasks to split across
//! threads) in a cube from a pile's density to sparse, their kinds and layers, the kind pairs, the share
//! that moves each frame and how far, boxes refused (NaN, infinite, inverted) and restored,
//! and the upkeep's trigger and spread, so that the writes' three regimes (enlarge, refit,
//! and a rebuild under way or taking over), the report's queries and its traversals all
//! run. The pairs themselves are checked against a brute force by the `dynamic_tree`
//! target; this one checks that threads change nothing.
#![no_main]

use std::sync::OnceLock;

use bvkit::Aabb3;
use bvkit::broadphase::{BodyKind, DynamicTree, KindPairs, Layers, Pairs};
use bvkit_fuzz::Floats;
use glam::Vec3A;
use libfuzzer_sys::fuzz_target;

/// Pools of 1, 2 and 3 threads, built once.
fn pools() -> &'static [rayon::ThreadPool] {
    static POOLS: OnceLock<Vec<rayon::ThreadPool>> = OnceLock::new();
    POOLS.get_or_init(|| {
        (1..=3)
            .map(|threads| {
                rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()
                    .expect("a thread pool")
            })
            .collect()
    })
}

/// A small seeded generator (xorshift64*), so that a few fuzz bytes drive thousands of
/// boxes.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }

    /// A float in `[0, 1)`.
    fn unit(&mut self) -> f32 {
        (self.next() >> 40) as f32 / (1u64 << 24) as f32
    }
}

fuzz_target!(|data: &[u8]| {
    let mut f = Floats::new(data);
    let n = 1 + usize::from(u16::from_le_bytes([f.byte(), f.byte()])) % 4000;
    let seed = u64::from_le_bytes(core::array::from_fn(|_| f.byte()));
    let mut r = Rng(seed | 1);
    // The scene's side: from one proxy per unit cube (a pile: about eight pairs a proxy) to
    // sparse.
    let side = (n as f32).cbrt() * (1.0 + f32::from(f.byte()) * 0.1);
    let mut centre: Vec<Vec3A> = (0..n)
        .map(|_| Vec3A::new(r.unit(), r.unit(), r.unit()) * side)
        .collect();
    let extent: Vec<Vec3A> = (0..n)
        .map(|_| Vec3A::new(r.unit(), r.unit(), r.unit()) * 0.8 + 0.1)
        .collect();
    let boxes = |centre: &[Vec3A]| -> Vec<Aabb3> {
        centre
            .iter()
            .zip(&extent)
            .map(|(&c, &e)| Aabb3::new(c - e, c + e))
            .collect()
    };
    let (kinds, layers) = (f.byte(), f.byte());
    let mut fat = boxes(&centre);
    let Ok(mut serial) = DynamicTree::from_boxes_with(&fat, |id| {
        let kind = match (id as u8).wrapping_add(kinds) % 8 {
            0 if kinds & 1 != 0 => BodyKind::Static,
            1 if kinds & 2 != 0 => BodyKind::Kinematic,
            _ => BodyKind::Dynamic,
        };
        let layer = match layers % 3 {
            0 => Layers::ALL,
            1 => Layers::new(1 << (id % 2), 3),
            _ => Layers::new(1 << (id % 3), if id % 5 == 0 { 1 } else { 6 }),
        };
        (kind, layer)
    }) else {
        panic!("finite boxes refused");
    };
    let flags = f.byte();
    serial.set_kind_pairs(KindPairs {
        kinematic_kinematic: flags & 1 != 0,
        kinematic_static: flags & 2 != 0,
    });
    serial.set_rebuild_after(0.25 * f32::from(1 + f.byte() % 32));
    serial.set_rebuild_frames(1 + u32::from(f.byte() % 8));
    let mut parallel: Vec<DynamicTree> = pools().iter().map(|_| serial.clone()).collect();
    let frames = 1 + f.byte() % 8;
    for frame in 0..frames {
        // A share of the proxies moves (from none to all), each by up to `reach`.
        let (share, reach) = (f.byte(), 0.1 + f32::from(f.byte()) * 0.02);
        let moved: Vec<u32> = (0..n as u32)
            .filter(|_| (r.next() & 0xff) < u64::from(share))
            .collect();
        for &i in &moved {
            let step = (Vec3A::new(r.unit(), r.unit(), r.unit()) * 2.0 - 1.0) * reach;
            centre[i as usize] += step;
        }
        fat = boxes(&centre);
        // A few moved boxes are refused (their proxies park) and come back later.
        let bad = f.byte();
        if bad % 4 == 0 {
            for &i in moved.iter().filter(|&&i| i % 61 == u32::from(bad) % 61) {
                let b = &mut fat[i as usize];
                match bad % 3 {
                    0 => b.min.x = f32::NAN,
                    1 => b.max.y = f32::INFINITY,
                    _ => core::mem::swap(&mut b.min.z, &mut b.max.z),
                }
            }
        }
        let mut want = Pairs::with_ended();
        serial
            .update(&moved, &fat, &mut want)
            .expect("a sorted moved list with a box each");
        for (tree, pool) in parallel.iter_mut().zip(pools()) {
            let mut got = Pairs::with_ended();
            pool.install(|| tree.update_par(&moved, &fat, &mut got))
                .expect("a sorted moved list with a box each");
            assert_eq!(
                got,
                want,
                "{n} proxies, frame {frame}, {} threads",
                pool.current_num_threads()
            );
        }
    }
    // The trees agree after the frames too.
    for tree in &parallel {
        assert_eq!(tree.overlapping_pairs(), serial.overlapping_pairs());
    }
});
