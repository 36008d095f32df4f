//! Headless avian3d apps and the scenes the parity tests and the example share.
#![allow(dead_code)]

use std::time::Duration;

use avian3d::prelude::*;
use bevy::app::{TaskPoolOptions, TaskPoolPlugin};
use bevy::ecs::system::SystemParamItem;
use bevy::prelude::*;
use bevy::time::TimeUpdateStrategy;
use bvkit_avian3d::BvkitBroadPhasePlugin;

/// Which broadphase an app runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Broad {
    /// avian's own `BvhBroadPhasePlugin`.
    Avian,
    /// bvkit's plugin, its pair search serial or on the rayon pool.
    Bvkit { parallel: bool },
}

/// A headless app (no window, no render), its compute pool of `threads` threads (bevy's
/// pools are made once per process: the first app's count holds for the others), one
/// physics step per update.
pub fn app(broad: Broad, threads: usize) -> App {
    app_with::<()>(broad, threads)
}

/// [`app`] with collision hooks `H`, in avian's narrow phase and in the broadphase.
pub fn app_with<H: CollisionHooks + 'static>(broad: Broad, threads: usize) -> App
where
    for<'w, 's> SystemParamItem<'w, 's, H>: CollisionHooks,
{
    let mut app = App::new();
    // bevy's compute pool takes what its I/O and async pools leave, at least one thread:
    // asked for `threads` threads it would get fewer, so its share is set.
    let mut pools = TaskPoolOptions::with_num_threads(threads);
    pools.compute.min_threads = threads;
    app.add_plugins(MinimalPlugins.set(TaskPoolPlugin {
        task_pool_options: pools,
    }))
    .add_plugins(TransformPlugin);
    let physics = PhysicsPlugins::default()
        .with_collision_hooks::<H>()
        .build();
    match broad {
        Broad::Avian => app.add_plugins(physics),
        Broad::Bvkit { parallel } => app.add_plugins(
            physics
                .disable::<BvhBroadPhasePlugin<H>>()
                .add(BvkitBroadPhasePlugin::<H>::with_parallel(parallel)),
        ),
    };
    // One fixed step per update: the fixed clock and the update clock agree.
    let step = Duration::from_secs_f64(1.0 / 64.0);
    app.insert_resource(Time::<Fixed>::from_duration(step))
        .insert_resource(TimeUpdateStrategy::ManualDuration(step));
    app.finish();
    app.cleanup();
    app
}

/// A static ground, its top at `y = 0`, `size` wide.
pub fn ground(world: &mut World, size: f32) -> Entity {
    world
        .spawn((
            RigidBody::Static,
            Collider::cuboid(size, 1.0, size),
            Transform::from_xyz(0.0, -0.5, 0.0),
        ))
        .id()
}

/// A pile: `side × side` columns of `height` unit cubes on a ground, each column a
/// little off the one below so that they topple onto each other.
pub fn pile(world: &mut World, side: usize, height: usize) -> Vec<Entity> {
    ground(world, 4.0 * side as f32 + 20.0);
    let mut cubes = Vec::new();
    for layer in 0..height {
        for i in 0..side {
            for k in 0..side {
                let jitter = 0.05 * ((i * 7 + k * 3 + layer * 5) % 5) as f32;
                let x = (i as f32 - side as f32 / 2.0) * 1.02 + jitter;
                let z = (k as f32 - side as f32 / 2.0) * 1.02 - jitter;
                let y = 0.5 + layer as f32 * 1.01;
                cubes.push(
                    world
                        .spawn((
                            RigidBody::Dynamic,
                            Collider::cuboid(1.0, 1.0, 1.0),
                            Transform::from_xyz(x, y, z),
                        ))
                        .id(),
                );
            }
        }
    }
    cubes
}

/// A level: a `side × side` grid of static boxes of varied heights, and `debris`
/// dynamic boxes falling onto it from a few rows above.
pub fn level(world: &mut World, side: usize, debris: usize) -> Vec<Entity> {
    let spacing = 2.0;
    let half = side as f32 * spacing / 2.0;
    for i in 0..side {
        for k in 0..side {
            let h = 1.0 + ((i * 13 + k * 7) % 4) as f32 * 0.5;
            world.spawn((
                RigidBody::Static,
                Collider::cuboid(spacing * 0.9, h, spacing * 0.9),
                Transform::from_xyz(
                    i as f32 * spacing - half,
                    h / 2.0,
                    k as f32 * spacing - half,
                ),
            ));
        }
    }
    let per_row = (debris as f32).sqrt().ceil() as usize;
    let pitch = (2.0 * half / per_row as f32).max(0.6);
    (0..debris)
        .map(|n| {
            let (i, k) = (n % per_row, n / per_row);
            let size = 0.3 + 0.1 * (n % 4) as f32;
            world
                .spawn((
                    RigidBody::Dynamic,
                    Collider::cuboid(size, size, size),
                    Transform::from_xyz(
                        i as f32 * pitch - half + 0.3,
                        3.0 + 0.7 * (n % 3) as f32,
                        (k % per_row) as f32 * pitch - half + 0.3,
                    ),
                ))
                .id()
        })
        .collect()
}

/// Runs `steps` updates (a physics step each).
pub fn run(app: &mut App, steps: usize) {
    for _ in 0..steps {
        app.update();
    }
}
