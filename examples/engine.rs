//! bvkit as an engine's broadphase: a static level (a floor of tiles and a few pillars),
//! kinematic platforms moving on paths, dynamic bodies in two layers (debris that does not
//! collide with debris, and characters that collide with everything), a door (static)
//! teleported once, a body whose pose turns NaN and comes back, and a ray cast each frame.
//!
//! `cargo run --release --example engine [FRAMES]` (default 120). Each frame: the bodies'
//! fat boxes from their poses (`Batch::update`, which lists the ones that left their fat
//! box), the tree's frame (`DynamicTree::update`: writes, upkeep, the pairs that began and
//! ended), a closest-hit ray cast from a camera that sees only characters and the level.
//! Every tenth frame, and at the end, the tree's pairs are checked against a brute force
//! over its boxes with the same kind and layer rules; a mismatch exits with an error.

use bvkit::broadphase::{BodyKind, CastControl, DynamicTree, KindPairs, Layers, Pairs, Ray};
use bvkit::{Aabb3, Active, Batch, Margin, Method, Moved, Rigid3, Rounding};
use glam::{Quat, Vec3A};

/// Collision layers, as an engine names them.
const LEVEL: u32 = 1;
const DEBRIS: u32 = 2;
const CHARACTER: u32 = 4;
const PLATFORM: u32 = 8;

/// A tiny deterministic generator, so that the example needs no dependency.
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let frames: usize = std::env::args().nth(1).map_or(Ok(120), |a| a.parse())?;
    let mut rng = Lcg(85);

    // The moving bodies: ids 0..BODIES, their local boxes and poses (the engine's own).
    const BODIES: usize = 6_000;
    const PLATFORMS: usize = 40;
    let mut local = Vec::with_capacity(BODIES);
    let mut poses = Vec::with_capacity(BODIES);
    let mut velocity = Vec::with_capacity(BODIES);
    for i in 0..BODIES {
        let half = if i < PLATFORMS {
            Vec3A::new(3.0, 0.25, 3.0)
        } else {
            Vec3A::new(rng.next(), rng.next(), rng.next()) * 0.4 + 0.1
        };
        local.push(Aabb3::new(-half, half));
        let at = Vec3A::new(
            rng.next() * 100.0,
            rng.next() * 20.0 + 0.5,
            rng.next() * 100.0,
        );
        poses.push(Rigid3::new(Quat::IDENTITY, at));
        velocity.push((Vec3A::new(rng.next(), rng.next(), rng.next()) - 0.5) * 4.0);
    }
    let kind = |i: usize| {
        if i < PLATFORMS {
            BodyKind::Kinematic
        } else {
            BodyKind::Dynamic
        }
    };
    let layers = |i: usize| match (kind(i), i % 3) {
        (BodyKind::Kinematic, _) => Layers::new(PLATFORM, DEBRIS | CHARACTER),
        (_, 0) => Layers::new(CHARACTER, u32::MAX),
        _ => Layers::new(DEBRIS, LEVEL | CHARACTER | PLATFORM),
    };

    // The fat boxes: a margin of 5 cm, so that a body at rest leaves its fat box rarely.
    let batch = Batch::new(Method::AbsMatrix, Rounding::Outward);
    let margin = Margin::new(0.05, 0.0);
    let (mut fat, mut moved) = (vec![Aabb3::EMPTY; BODIES], Moved::new());
    batch.update(margin, Active::All, &local, &poses, &mut fat, &mut moved)?;

    // The tree: the bodies, then the level's static boxes after them (ids BODIES..).
    let mut tree =
        DynamicTree::from_boxes_with(&fat[..], |i| (kind(i as usize), layers(i as usize)))?;
    let level = Layers::new(LEVEL, u32::MAX);
    let mut statics = Vec::new();
    for x in 0..50 {
        for z in 0..50 {
            let min = Vec3A::new(x as f32 * 2.0, -1.0, z as f32 * 2.0);
            statics.push(Aabb3::new(min, min + Vec3A::new(2.0, 1.0, 2.0)));
        }
    }
    for _ in 0..200 {
        let at = Vec3A::new(rng.next() * 100.0, 0.0, rng.next() * 100.0);
        statics.push(Aabb3::new(at, at + Vec3A::new(1.0, 8.0, 1.0)));
    }
    let door = (BODIES + statics.len()) as u32;
    statics.push(Aabb3::new(
        Vec3A::new(49.0, 0.0, 49.0),
        Vec3A::new(51.0, 3.0, 49.5),
    ));
    for (k, b) in statics.iter().enumerate() {
        tree.insert_with((BODIES + k) as u32, *b, BodyKind::Static, level)?;
    }
    // Platforms carry characters and push debris; they also stop at the level's walls.
    tree.set_kind_pairs(KindPairs {
        kinematic_kinematic: false,
        kinematic_static: true,
    });

    let mut pairs = Pairs::with_ended();
    let mut live = 0i64;
    let camera = Ray::new(
        Vec3A::new(-10.0, 10.0, -10.0),
        Vec3A::new(1.0, -0.15, 1.0),
        200.0,
    );
    let sees = Layers::new(u32::MAX, CHARACTER | LEVEL);
    println!(
        "{BODIES} bodies ({PLATFORMS} kinematic platforms), {} static boxes, {} nodes; backend {:?}",
        statics.len(),
        tree.nodes(),
        batch.backend()
    );
    for frame in 0..frames {
        // The simulation's step: bodies fly about and bounce inside the level; platforms
        // follow circles.
        let t = frame as f32 / 60.0;
        for (i, pose) in poses.iter_mut().enumerate() {
            if i < PLATFORMS {
                let phase = i as f32;
                pose.translation += Vec3A::new((t + phase).cos(), 0.0, (t + phase).sin()) * 0.2;
                continue;
            }
            let v = &mut velocity[i];
            let p = &mut pose.translation;
            *p += *v / 60.0;
            for a in 0..3 {
                let top = if a == 1 { 20.0 } else { 100.0 };
                if p[a] < 0.5 || p[a] > top {
                    v[a] = -v[a];
                }
            }
        }
        // A body whose pose turns NaN for a few frames (a solver blow-up): its proxy is
        // parked, its pairs end, and it comes back when its pose does.
        let broken = PLATFORMS + 7;
        let saved = poses[broken].translation;
        if (30..33).contains(&frame) {
            poses[broken].translation.x = f32::NAN;
        }
        batch.update(margin, Active::All, &local, &poses, &mut fat, &mut moved)?;
        poses[broken].translation = saved;

        // The door is teleported once: one proxy's move in the static hierarchy.
        if frame == 60 {
            tree.move_proxy(
                door,
                Aabb3::new(Vec3A::new(49.0, 0.0, 60.0), Vec3A::new(51.0, 3.0, 60.5)),
            )?;
        }
        tree.update(moved.indices(), &fat[..], &mut pairs)?;
        live += pairs.begun.len() as i64 - pairs.ended.len() as i64;

        // The camera's ray: the closest character or level box.
        let mut closest: Option<(u32, f32)> = None;
        tree.cast_ray(&camera, sees, |id, t| {
            if closest.is_none_or(|(_, best)| t < best) {
                closest = Some((id, t));
            }
            CastControl::Clip(t)
        })?;

        if frame % 10 == 0 || frame + 1 == frames {
            let all = tree.overlapping_pairs();
            let brute = brute_force(&tree, BODIES + statics.len());
            if all != brute || all.len() as i64 != live {
                return Err(format!(
                    "frame {frame}: the tree holds {} pairs, brute force {}, begun minus ended {live}",
                    all.len(),
                    brute.len()
                )
                .into());
            }
            println!(
                "frame {frame:>3}: {:>5} moved, {:>4} begun, {:>4} ended, {:>5} pairs (checked), \
                 refused {:?}, camera sees {:?}",
                moved.len(),
                pairs.begun.len(),
                pairs.ended.len(),
                all.len(),
                pairs.refused,
                closest
            );
        }
    }
    Ok(())
}

/// Every pair the tree should hold, by brute force over its boxes, kinds and layers.
fn brute_force(tree: &DynamicTree, ids: usize) -> Vec<(u32, u32)> {
    let rule = tree.kind_pairs();
    let proxies: Vec<(u32, Aabb3, BodyKind, Layers)> = (0..ids as u32)
        .filter_map(|id| Some((id, tree.get(id)?, tree.kind(id)?, tree.layers(id)?)))
        .collect();
    let overlap = |a: &Aabb3, b: &Aabb3| a.min.cmple(b.max).all() && b.min.cmple(a.max).all();
    let kinds = |a: BodyKind, b: BodyKind| match (a, b) {
        (BodyKind::Dynamic, _) | (_, BodyKind::Dynamic) => true,
        (BodyKind::Kinematic, BodyKind::Kinematic) => rule.kinematic_kinematic,
        (BodyKind::Static, BodyKind::Static) => false,
        _ => rule.kinematic_static,
    };
    let mut out = Vec::new();
    for (i, a) in proxies.iter().enumerate() {
        for b in &proxies[i + 1..] {
            if overlap(&a.1, &b.1) && kinds(a.2, b.2) && a.3.interacts_with(b.3) {
                out.push((a.0, b.0));
            }
        }
    }
    out
}
