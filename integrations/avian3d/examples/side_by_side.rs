//! avian3d's own broadphase and bvkit's, side by side in one run, on a pile of cubes and on a
//! static level with falling debris, on one thread and on every core.
//!
//! `cargo run --release -p bvkit-avian3d --example side_by_side [-- --quick]`
//!
//! Each thread count runs in a child process of its own (bevy makes its task pools once per
//! process); the one-thread run pins itself to one CPU.
//!
//! Per scene and thread count it builds one app per broadphase, lets it settle a few steps,
//! then times each step:
//! - **broadphase**: avian's collider-tree update (enlarged boxes, its trees' leaves and
//!   refits) and optimisation (its trees' rebuilds), plus the pair search (avian's
//!   `CollisionDiagnostics::broad_phase`, to which bvkit's plugin adds its own time);
//! - **step**: the app's whole update, one physics step.
//!
//! With bvkit's plugin, avian's trees no longer find pairs but still answer `SpatialQuery`;
//! their upkeep runs in two ways: as avian runs it, and with the optimisation (the rebuilds)
//! switched off. The enlarged boxes come from avian's update in both.

#[path = "../tests/scenes/mod.rs"]
mod scenes;

use std::time::{Duration, Instant};

use avian3d::collider_tree::{ColliderTreeDiagnostics, ColliderTreeSystems};
use avian3d::collision::CollisionDiagnostics;
use avian3d::collision::collider::EnlargedAabb;
use avian3d::prelude::*;
use bevy::prelude::*;
use bvkit_avian3d::BvkitBroadPhase;
use scenes::{Broad, app, level, pile};

/// One configuration of an app.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Setup {
    broad: Broad,
    /// avian's tree optimisation (rebuilds) left on.
    optimize: bool,
}

impl Setup {
    fn name(&self) -> &'static str {
        match (self.broad, self.optimize) {
            (Broad::Avian, _) => "avian",
            (Broad::Bvkit { .. }, true) => "bvkit",
            (Broad::Bvkit { .. }, false) => "bvkit, avian's rebuilds off",
        }
    }
}

/// A step's times, summed over the timed steps.
#[derive(Resource, Default, Clone, Copy, Debug)]
struct Sums {
    tree_update: Duration,
    tree_optimize: Duration,
    pair_search: Duration,
    steps: u32,
}

/// Adds the step's diagnostics (reset by avian at each step's start) to the sums.
fn sum(
    trees: Res<ColliderTreeDiagnostics>,
    collision: Res<CollisionDiagnostics>,
    mut sums: ResMut<Sums>,
) {
    sums.tree_update += trees.update;
    sums.tree_optimize += trees.optimize;
    sums.pair_search += collision.broad_phase;
    sums.steps += 1;
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Scene {
    Pile,
    Level,
}

/// One app: built, settled `warm` steps, then `timed` steps measured.
struct Measured {
    /// Per step, in milliseconds: broadphase stage, whole update, pair search alone.
    broadphase: f64,
    step: f64,
    pairs: f64,
    /// The edges in the contact graph at the end.
    edges: usize,
    colliders: usize,
    /// bvkit's stages per step, in milliseconds (mirror and writes, report, pairs), and its
    /// proxies moved and pairs begun per step.
    split: Option<(f64, f64, f64, u64, u64)>,
    /// bvkit's copies of the moved boxes at the edge (glam 0.32 to 0.33), per step, in
    /// milliseconds, timed apart.
    copies: Option<f64>,
}

fn measure(
    scene: Scene,
    n: usize,
    threads: usize,
    setup: Setup,
    warm: usize,
    timed: usize,
) -> Measured {
    let mut app = app(setup.broad, threads);
    if !setup.optimize {
        let never = || false;
        app.configure_sets(
            PhysicsSchedule,
            (
                ColliderTreeSystems::BeginOptimize.run_if(never),
                ColliderTreeSystems::EndOptimize.run_if(never),
            ),
        );
    }
    app.init_resource::<Sums>()
        .add_systems(PhysicsSchedule, sum.in_set(PhysicsStepSystems::Last));
    match scene {
        Scene::Pile => {
            // Columns of 20 cubes.
            let side = ((n / 20) as f64).sqrt().round() as usize;
            pile(app.world_mut(), side, 20);
        }
        Scene::Level => {
            // Half static boxes, half debris.
            let side = ((n / 2) as f64).sqrt().round() as usize;
            level(app.world_mut(), side, n - side * side);
        }
    }
    for _ in 0..warm {
        app.update();
    }
    *app.world_mut().resource_mut::<Sums>() = Sums::default();
    if let Some(mut b) = app.world_mut().get_resource_mut::<BvkitBroadPhase>() {
        b.timings.take();
    }
    let mut step = Duration::ZERO;
    for _ in 0..timed {
        let start = Instant::now();
        app.update();
        step += start.elapsed();
    }
    let sums = *app.world().resource::<Sums>();
    let steps = f64::from(sums.steps.max(1));
    let ms = |d: Duration| d.as_secs_f64() * 1e3 / steps;
    let colliders = app
        .world_mut()
        .query::<&Collider>()
        .iter(app.world())
        .count();
    let edges = {
        let graph = app.world().resource::<ContactGraph>();
        graph.active_pairs().len() + graph.sleeping_pairs().len()
    };
    let split = app.world().get_resource::<BvkitBroadPhase>().map(|b| {
        let t = b.timings;
        let per_step = |n: u64| n / u64::from(t.steps.max(1));
        (
            ms(t.write),
            ms(t.report),
            ms(t.pairs),
            per_step(t.moved),
            per_step(t.begun),
        )
    });
    let is_bvkit = split.is_some();
    let copies = is_bvkit.then(|| {
        // The plugin copies each moved proxy's box once a step: time as many copies.
        let boxes: Vec<EnlargedAabb> = app
            .world_mut()
            .query::<&EnlargedAabb>()
            .iter(app.world())
            .copied()
            .collect();
        let start = Instant::now();
        let mut sink = bvkit::Aabb3::new(bvkit::glam::Vec3A::ZERO, bvkit::glam::Vec3A::ZERO);
        for b in &boxes {
            let b = b.get();
            let c = bvkit::Aabb3::new(
                bvkit::glam::Vec3A::from_array(b.min.to_array()),
                bvkit::glam::Vec3A::from_array(b.max.to_array()),
            );
            sink = std::hint::black_box(c);
        }
        std::hint::black_box(sink);
        start.elapsed().as_secs_f64() * 1e3
    });
    Measured {
        broadphase: ms(sums.tree_update + sums.tree_optimize + sums.pair_search),
        step: step.as_secs_f64() * 1e3 / timed as f64,
        pairs: ms(sums.pair_search),
        edges,
        colliders,
        split,
        copies,
    }
}

/// Pins this process to one CPU, so that every thread bevy or rayon starts runs on it.
fn pin_to_one_cpu() -> bool {
    // SAFETY: `set` is a plain bit set on the stack, zeroed then given one CPU, and
    // `sched_setaffinity` reads exactly `size_of::<cpu_set_t>()` bytes of it.
    unsafe {
        let mut set: libc::cpu_set_t = std::mem::zeroed();
        libc::CPU_SET(0, &mut set);
        libc::sched_setaffinity(0, std::mem::size_of::<libc::cpu_set_t>(), &set) == 0
    }
}

/// One thread count's rows, in this process: every scene and size, or those of `only`
/// (`--scene pile|level --size N`, for a profiler).
fn rows(threads: usize, quick: bool, only: Option<(Scene, usize)>) {
    // Where the system refuses the pinning (a sandbox), the run goes on and says so.
    let label = if threads == 1 && !pin_to_one_cpu() {
        "1 (not pinned)".to_string()
    } else {
        threads.to_string()
    };
    let (sizes, warm, timed): (&[usize], usize, usize) = if quick {
        (&[2_000], 3, 5)
    } else {
        (&[10_000, 100_000], 5, 15)
    };
    let sizes = match only {
        Some((_, n)) => &[n][..],
        None => sizes,
    };
    for scene in [Scene::Pile, Scene::Level] {
        for &n in sizes {
            if only.is_some_and(|o| o != (scene, n)) {
                continue;
            }
            let setups = [
                Setup {
                    broad: Broad::Avian,
                    optimize: true,
                },
                Setup {
                    broad: Broad::Bvkit {
                        parallel: threads > 1,
                    },
                    optimize: true,
                },
                Setup {
                    broad: Broad::Bvkit {
                        parallel: threads > 1,
                    },
                    optimize: false,
                },
            ];
            let mut base: Option<Measured> = None;
            for setup in setups {
                let m = measure(scene, n, threads, setup, warm, timed);
                let (b, s) = base.as_ref().map_or((1.0, 1.0), |a| {
                    (m.broadphase / a.broadphase, m.step / a.step)
                });
                let split = m
                    .split
                    .map_or(" | | ".to_string(), |(w, r, p, moved, begun)| {
                        format!("{w:.2}, {r:.2}, {p:.2} | {moved} | {begun}")
                    });
                let copies = m.copies.map_or(String::new(), |c| format!("{c:.3}"));
                println!(
                    "| {scene:?} | {} | {label} | {} | {:.2} | {:.2} | {:.2} | {b:.2}× | {s:.2}× | {} | {split} | {copies} |",
                    m.colliders,
                    setup.name(),
                    m.broadphase,
                    m.pairs,
                    m.step,
                    m.edges
                );
                if base.is_none() {
                    base = Some(m);
                }
            }
        }
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let quick = args.iter().any(|a| a == "--quick");
    if let Some(k) = args.iter().position(|a| a == "--threads") {
        let threads = args.get(k + 1).and_then(|t| t.parse().ok()).unwrap_or(1);
        let arg = |name: &str| {
            let k = args.iter().position(|a| a == name)?;
            args.get(k + 1).cloned()
        };
        let scene = arg("--scene").map(|s| {
            if s == "pile" {
                Scene::Pile
            } else {
                Scene::Level
            }
        });
        let size = arg("--size").and_then(|n| n.parse().ok());
        rows(threads, quick, scene.zip(size));
        return;
    }
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .map(|l| l.split(':').nth(1).unwrap_or("").trim().to_string())
        })
        .unwrap_or_else(|| "unknown CPU".into());
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let (warm, timed) = if quick { (3, 5) } else { (5, 15) };
    println!("# avian3d 0.7: its own broadphase and bvkit's, side by side");
    println!();
    println!(
        "{cpu}, {cores} cores; {warm} steps to settle, then the mean of {timed} steps. One thread: \
         the process pinned to one CPU; every core: bevy's compute pool and bvkit's pair search \
         (rayon) on all of them."
    );
    println!();
    println!(
        "| scene | colliders | threads | broadphase | broadphase ms | of it, pair search ms | step ms | broadphase / avian's | step / avian's | edges | bvkit: mirror, report, pairs ms | moved a step | begun a step | copies at the edge ms |"
    );
    println!("|---|---:|---:|---|---:|---:|---:|---:|---:|---:|---|---:|---:|---:|");
    // bevy's task pools are made once per process: a process per thread count.
    let exe = std::env::current_exe().expect("the example's own path");
    for threads in [1, cores] {
        let mut child = std::process::Command::new(&exe);
        child.args(["--threads", &threads.to_string()]);
        if quick {
            child.arg("--quick");
        }
        let status = child.status().expect("the example runs itself");
        assert!(status.success(), "the {threads}-thread run failed");
    }
    println!();
    println!(
        "The copies at the edge: every collider's enlarged box copied from glam 0.32 to 0.33 \
         once, timed apart; the plugin copies only the moved ones, once a step."
    );
}
