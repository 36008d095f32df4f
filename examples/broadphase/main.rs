//! The broadphase on a seeded random walk of N bodies (default 1M) over T frames (default
//! 30), a fraction of them asleep (default 0.5) in islands of 256 consecutive bodies that
//! sleep together (as engines put a resting pile to sleep; a fourth argument sets the island
//! size, 1 for bodies asleep one by one at random). Three modes:
//!
//! - `cargo run --release --features peers --example broadphase [N] [T] [asleep] [island]`:
//!   the fat-box update against the naive path that recomputes and rewrites every box every
//!   frame, in AoS and AoSoA; each frame prints the update's cost, the fraction of awake
//!   bodies whose fat box moved and the fat boxes rewritten. After every frame it checks
//!   what the update promises in each layout: every fat box contains its body's tight box.
//! - `cargo run --release --features peers --example broadphase bvh [N] [T] [asleep] [island]`:
//!   whole broadphase pipelines (see `support/src/broadphase/bvh.rs`), stage by stage: C,
//!   bvkit's update into its own `broadphase::DynamicTree` (begun and ended pairs), beside R,
//!   rapier3d 0.36.1's own `BroadPhaseBvh::update` (`rapier.rs`), and A and B, our models of
//!   rapier's older pipeline on parry3d's `Bvh` (A as rapier ran it, B fed by bvkit's
//!   update). Up to 20K bodies it checks every frame (C's begun and ended pairs against a
//!   sweep, R's pairs and A's and B's trees against the exact boxes) and fails on any error;
//!   above, every fifth frame.
//! - `cargo run --release --features peers --example broadphase tree [T]`: C against R on
//!   six scenes, T frames each (default 60, so that the trees reach their steady state
//!   under motion): 1M bodies half asleep, 100K all awake, 100K all awake moving 8 times as
//!   fast, where most bodies leave their fat box every frame, the 1M half asleep as fast,
//!   and the 100K packed six times closer (a pile: several overlapping pairs a body, where
//!   the sparse scenes have far under one) at both speeds; checked every fifth frame. The
//!   last line reads `frame_vs_rapier_1m=R1 frame_vs_rapier_100k=R2
//!   frame_vs_rapier_most_move=R3 frame_vs_rapier_1m_most_move=R4 frame_vs_rapier_pile=R5
//!   frame_vs_rapier_pile_most_move=R6 missing_pairs=M`.
//!
//! Options of the `bvh` and `tree` modes: `--speed S` multiplies every velocity and
//! `--packed F` packs the bodies F times closer along each axis (`bvh`),
//! `--obvhs` adds D, obvhs's `Bvh2` fed by C's update (the tree avian uses; about 0.4 s a
//! frame at 1M), `--models` adds A and B to `tree` (`--no-models` leaves them out of `bvh`), `--no-rapier`
//! leaves R out, `--avx2` runs C's update on the AVX2 backend (the widest this CPU runs
//! otherwise), `--check-all` checks every frame and `--no-check` none (for profiling), `--relative R` and `--partial K` tune B, and `--rebuild-after M` and
//! `--rebuild-frames F` tune C's upkeep; `--level M` adds M static boxes to C's tree at the bodies'
//! density around the scene, `--floor M` a floor of M static tiles under it, `--far M` M
//! static boxes 3 km away, and `--layers K`
//! puts C's proxy `i` in layer `i % K` alone (1: every proxy in one layer, through the filter).

use bvkit_support::broadphase::{bvh, scene};
use bvkit_support::common;

use std::time::Instant;

use bvkit::{Aabb3, Aabb3x8, Active, Batch, Margin, Method, Moved, Rigid3x8, Rounding};

use bvh::{Check, Which};
use scene::Scene;

fn main() {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let mode = args
        .first()
        .filter(|a| *a == "bvh" || *a == "tree")
        .cloned();
    if mode.is_some() {
        args.remove(0);
    }
    // `--name value`, taken out of the positional arguments.
    let mut option = |name: &str| {
        let k = args.iter().position(|a| a == name)?;
        let value = args.get(k + 1).expect("a value after the option").clone();
        args.drain(k..k + 2);
        Some(value.parse::<f64>().expect("a number"))
    };
    let tuning = bvh::Tuning {
        relative: option("--relative").unwrap_or(0.0) as f32,
        partial: option("--partial").unwrap_or(0.0) as usize,
        rebuild_after: option("--rebuild-after").map(|x| x as f32),
        rebuild_frames: option("--rebuild-frames").map(|x| x as u32),
        level: match (option("--level"), option("--floor"), option("--far")) {
            (Some(m), _, _) => bvh::Level::Clutter(m as usize),
            (None, Some(m), _) => bvh::Level::Floor(m as usize),
            (None, None, Some(m)) => bvh::Level::Far(m as usize),
            (None, None, None) => bvh::Level::None,
        },
        layers: option("--layers").unwrap_or(0.0) as u32,
        backend: None,
    };
    let speed = option("--speed").unwrap_or(1.0) as f32;
    let packed = option("--packed").unwrap_or(1.0) as f32;
    // `--name`, taken out of the positional arguments.
    let mut flag = |name: &str| {
        let k = args.iter().position(|a| a == name);
        k.map(|k| args.remove(k)).is_some()
    };
    let obvhs = flag("--obvhs");
    let models = flag("--models");
    let no_models = flag("--no-models");
    let rapier = !flag("--no-rapier");
    let check_all = flag("--check-all");
    let no_check = flag("--no-check");
    let tuning = bvh::Tuning {
        backend: flag("--avx2").then_some(bvkit::Backend::Avx2),
        ..tuning
    };
    let arg = |k: usize, default: f64| {
        args.get(k)
            .map_or(default, |a| a.parse().expect("a number"))
    };
    let (n, frames, asleep) = (arg(0, 1e6) as usize, arg(1, 30.0) as usize, arg(2, 0.5));
    let island = (arg(3, 256.0) as usize).max(1);
    match mode.as_deref() {
        Some("tree") => {
            let which = Which {
                models,
                obvhs,
                rapier,
            };
            let check = match (check_all, no_check) {
                (true, _) => Check::Every,
                (_, true) => Check::Never,
                _ => Check::Sampled(5),
            };
            tree(arg(0, 60.0) as usize, tuning, which, check);
        }
        Some(_) => {
            let which = Which {
                models: !no_models,
                obvhs,
                rapier,
            };
            let check = match (check_all || n <= 20_000, no_check) {
                (_, true) => Check::Never,
                (true, _) => Check::Every,
                _ => Check::Sampled(5),
            };
            let scene = Scene::new(n, asleep, island).packed(packed).fast(speed);
            let summary = bvh::run(scene, frames, tuning, which, check);
            assert_eq!(
                summary.missing + summary.wrong + summary.rapier_missing,
                0,
                "C's pairs differ from the sweep's, or R misses a pair"
            );
        }
        None => update_against_naive(n, frames, asleep, island),
    }
}

/// The scenes through C and R (and the pipelines of `which`), checked as `check`
/// says; the last line gives C's frame against R's in each and the pairs missed.
fn tree(frames: usize, tuning: bvh::Tuning, which: Which, check: Check) {
    let scenes = [
        ("1m", Scene::new(1_000_000, 0.5, 256)),
        ("100k", Scene::new(100_000, 0.0, 256)),
        ("most_move", Scene::new(100_000, 0.0, 256).fast(8.0)),
        ("1m_most_move", Scene::new(1_000_000, 0.5, 256).fast(8.0)),
        ("pile", Scene::new(100_000, 0.0, 256).packed(6.0)),
        (
            "pile_most_move",
            Scene::new(100_000, 0.0, 256).packed(6.0).fast(8.0),
        ),
    ];
    let mut line = Vec::new();
    let mut missing = 0;
    for (label, scene) in scenes {
        let start = Instant::now();
        let summary = bvh::run(scene, frames, tuning, which, check);
        println!(
            "scene {label}: C moved {:.0} proxies a frame; C's frame {:.3} µs per moved body \
             ({:.0} s for the scene with its checks)",
            summary.moved,
            summary.frame[2] * 1e3 / summary.moved.max(1.0),
            start.elapsed().as_secs_f64()
        );
        println!();
        assert_eq!(
            summary.wrong, 0,
            "C reported a pair that did not begin or end"
        );
        missing += summary.missing + summary.rapier_missing;
        if which.rapier {
            line.push(format!(
                "frame_vs_rapier_{label}={:.2}",
                summary.frame[2] / summary.frame[4]
            ));
        }
    }
    line.push(format!("missing_pairs={missing}"));
    println!("{}", line.join(" "));
}

/// The fat-box update against the naive pass, in AoS and AoSoA.
fn update_against_naive(n: usize, frames: usize, asleep: f64, island: usize) {
    let mut scene = Scene::new(n, asleep, island);
    let (awake, mask, local) = (scene.awake, scene.mask.clone(), scene.local.clone());
    let batch = Batch::new(Method::AbsMatrix, Rounding::Outward);
    let margin = Margin::new(0.05, 0.1);
    let mut fat = vec![Aabb3::EMPTY; n];
    let mut world = vec![Aabb3::EMPTY; n];
    let mut moved = Moved::new();
    batch
        .update(
            margin,
            Active::All,
            &local,
            &scene.poses,
            &mut fat,
            &mut moved,
        )
        .expect("lengths agree");
    // The same scene in AoSoA blocks (the mask's length counts the padded blocks), its fat
    // boxes from its own first update.
    let local8 = Aabb3x8::pack(&local);
    let mut fat8 = Aabb3x8::pack(&vec![Aabb3::EMPTY; n]);
    let mut world8 = fat8.clone();
    let mut mask8 = mask.clone();
    mask8.resize((8 * local8.len()).div_ceil(64), 0);
    let mut moved8 = Moved::new();
    let poses8 = Rigid3x8::pack(&scene.poses);
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
         {:?} on {:?}, 60 Hz; CPU {}",
        asleep * 100.0,
        batch.method,
        batch.backend(),
        common::cpu()
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
    for frame in 0..frames {
        scene.step();
        let poses = &scene.poses;
        let start = Instant::now();
        batch
            .update(
                margin,
                Active::Mask(&mask),
                &local,
                poses,
                &mut fat,
                &mut moved,
            )
            .expect("lengths agree");
        let update = start.elapsed().as_secs_f64();
        let start = Instant::now();
        batch
            .transform(&local, poses, &mut world)
            .expect("lengths agree");
        let naive = start.elapsed().as_secs_f64();
        // AoSoA: the poses packed outside the timing (a packed engine simulates in place).
        let poses8 = Rigid3x8::pack(poses);
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
