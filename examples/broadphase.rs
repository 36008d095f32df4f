//! The per-frame broadphase update on a random walk: N bodies (default 1M) move for T
//! frames (default 30), a fraction of them asleep (default 0.5), in islands of 256
//! consecutive bodies that sleep together (as engines put a resting pile to sleep; a
//! fourth argument sets the island size, 1 for bodies asleep one by one at random). Each
//! frame prints the
//! update's cost, the fraction of awake bodies whose fat box moved and the fat boxes
//! rewritten, next to the naive path that recomputes and rewrites every box every frame.
//!
//! `cargo run --release --example broadphase [N] [T] [asleep] [island]`
//!
//! After every frame it checks what the update promises in each layout: every fat box
//! contains its body's tight box.

use std::time::Instant;

use bvkit::{Aabb3, Aabb3x8, Active, Batch, Margin, Method, Moved, Rigid3, Rigid3x8, Rounding};
use glam::{Quat, Vec3A};
use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};

fn main() {
    let mut args = std::env::args().skip(1);
    let mut arg = |default: f64| {
        args.next()
            .map_or(default, |a| a.parse().expect("a number"))
    };
    let n = arg(1e6) as usize;
    let frames = arg(30.0) as usize;
    let asleep = arg(0.5);
    let island = (arg(256.0) as usize).max(1);
    let mut r = StdRng::seed_from_u64(0xb0d1e5);

    // Bodies: boxes of 0.2 to 2 units in a 1 km cube, a random velocity of up to 2 m/s,
    // a random spin; `asleep` of the islands never move (their bits are clear in the mask).
    let local: Vec<Aabb3> = (0..n)
        .map(|_| {
            let e = Vec3A::new(
                r.random_range(0.1..1.0),
                r.random_range(0.1..1.0),
                r.random_range(0.1..1.0),
            );
            Aabb3::new(-e, e)
        })
        .collect();
    let mut poses: Vec<Rigid3> = (0..n)
        .map(|_| {
            let axis = Vec3A::new(r.random(), r.random(), r.random()).normalize_or(Vec3A::Y);
            let rotation = Quat::from_axis_angle(axis.into(), r.random_range(0.0..6.3));
            let position = Vec3A::new(
                r.random_range(-500.0..500.0),
                r.random_range(-500.0..500.0),
                r.random_range(-500.0..500.0),
            );
            Rigid3::new(rotation, position)
        })
        .collect();
    let velocity: Vec<Vec3A> = (0..n)
        .map(|_| Vec3A::new(r.random(), r.random(), r.random()) * 4.0 - 2.0)
        .collect();
    let spin = Quat::from_rotation_y(0.02);
    let mut mask = vec![0u64; n.div_ceil(64)];
    let mut awake = 0;
    for start in (0..n).step_by(island) {
        if r.random::<f64>() >= asleep {
            for i in start..(start + island).min(n) {
                mask[i / 64] |= 1 << (i % 64);
                awake += 1;
            }
        }
    }

    let batch = Batch::new(Method::AbsMatrix, Rounding::Outward);
    let margin = Margin::new(0.05, 0.1);
    let mut fat = vec![Aabb3::EMPTY; n];
    let mut world = vec![Aabb3::EMPTY; n];
    let mut moved = Moved::new();
    batch
        .update(margin, Active::All, &local, &poses, &mut fat, &mut moved)
        .expect("lengths agree");
    // The same scene in AoSoA blocks (the mask's length counts the padded blocks), its fat
    // boxes from its own first update.
    let local8 = Aabb3x8::pack(&local);
    let mut fat8 = Aabb3x8::pack(&vec![Aabb3::EMPTY; n]);
    let mut world8 = fat8.clone();
    let mut mask8 = mask.clone();
    mask8.resize((8 * local8.len()).div_ceil(64), 0);
    let mut moved8 = Moved::new();
    let poses8 = Rigid3x8::pack(&poses);
    batch
        .update(
            margin,
            Active::All,
            &local8[..],
            &poses8[..],
            &mut fat8[..],
            &mut moved8,
        )
        .expect("lengths agree");
    println!(
        "{n} bodies, {awake} awake ({:.0}% asleep, in islands of {island}), margin {margin:?}, \
         {:?} on {:?}, 60 Hz",
        asleep * 100.0,
        batch.method,
        batch.backend()
    );
    println!(
        "{:>5} | {:>9} {:>12} {:>9} {:>9} | {:>9} {:>9} | {:>10} {:>9} | {:>9}",
        "frame",
        "AoS ms",
        "ns per awake",
        "moved %",
        "rewritten",
        "naive ms",
        "speed-up",
        "AoSoA ms",
        "naive ms",
        "speed-up"
    );
    let (mut total_update, mut total_naive, mut total_moved) = (0.0, 0.0, 0);
    let (mut total_update8, mut total_naive8) = (0.0, 0.0);
    let dt = 1.0 / 60.0;
    for frame in 0..frames {
        // The simulation step: awake bodies move and spin.
        for (w, &word) in mask.iter().enumerate() {
            let mut bits = word;
            while bits != 0 {
                let i = 64 * w + bits.trailing_zeros() as usize;
                bits &= bits - 1;
                let p = &mut poses[i];
                p.translation += velocity[i] * dt;
                p.rotation = spin * p.rotation;
            }
        }
        let start = Instant::now();
        batch
            .update(
                margin,
                Active::Mask(&mask),
                &local,
                &poses,
                &mut fat,
                &mut moved,
            )
            .expect("lengths agree");
        let update = start.elapsed().as_secs_f64();
        let start = Instant::now();
        batch
            .transform(&local, &poses, &mut world)
            .expect("lengths agree");
        let naive = start.elapsed().as_secs_f64();
        // AoSoA: the poses packed outside the timing (a packed engine simulates in place).
        let poses8 = Rigid3x8::pack(&poses);
        let start = Instant::now();
        batch
            .update(
                margin,
                Active::Mask(&mask8),
                &local8[..],
                &poses8[..],
                &mut fat8[..],
                &mut moved8,
            )
            .expect("lengths agree");
        let update8 = start.elapsed().as_secs_f64();
        let start = Instant::now();
        batch
            .transform(&local8[..], &poses8[..], &mut world8[..])
            .expect("lengths agree");
        let naive8 = start.elapsed().as_secs_f64();
        // What the update promises, in each layout: every fat box contains the tight box of
        // its body (Outward, so the exact box too). The two layouts need not move the same
        // bodies: the AoS path and the AoSoA lanes may differ in the last bits (fused or
        // not), so a body on the edge of its fat box can move in one and not the other.
        let (fat_8, world_8) = (Aabb3x8::unpack(&fat8, n), Aabb3x8::unpack(&world8, n));
        for i in 0..n {
            assert!(
                fat[i].contains(&world[i]),
                "AoS: body {i} outside its fat box"
            );
            assert!(
                fat_8[i].contains(&world_8[i]),
                "AoSoA: body {i} outside its fat box"
            );
        }
        total_update += update;
        total_naive += naive;
        total_update8 += update8;
        total_naive8 += naive8;
        total_moved += moved.len();
        println!(
            "{frame:>5} | {:>9.3} {:>12.2} {:>9.2} {:>9} | {:>9.3} {:>8.1}× | {:>10.3} {:>9.3} | {:>8.1}×",
            update * 1e3,
            update * 1e9 / awake.max(1) as f64,
            100.0 * moved.len() as f64 / awake.max(1) as f64,
            moved.len(),
            naive * 1e3,
            naive / update,
            update8 * 1e3,
            naive8 * 1e3,
            naive8 / update8
        );
    }
    let frames = frames.max(1) as f64;
    println!(
        "mean: {:.2}% of awake bodies moved per frame, {:.0} fat boxes rewritten per frame \
         instead of {n}",
        100.0 * total_moved as f64 / frames / awake.max(1) as f64,
        total_moved as f64 / frames
    );
    println!(
        "mean: AoS update {:.3} ms against naive {:.3} ms ({:.1}×); AoSoA update {:.3} ms \
         against naive {:.3} ms ({:.1}×)",
        total_update * 1e3 / frames,
        total_naive * 1e3 / frames,
        total_naive / total_update,
        total_update8 * 1e3 / frames,
        total_naive8 * 1e3 / frames,
        total_naive8 / total_update8
    );
}
