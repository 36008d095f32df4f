//! bvkit feeding a real dynamic BVH (parry3d's `Bvh`), against the pipeline rapier runs on
//! it, over a few frames of a dense random walk: in both trees every pair of bodies whose
//! world boxes overlap is a pair of overlapping leaves, and was reported, by the first
//! frame's full traversal or by a change-detection traversal since (an engine keeps a pair
//! until its boxes separate).

use bvkit_support::parry3d;
use std::collections::HashSet;

use bvkit::{Aabb3, Active, Batch, Margin, Method, Moved, Rigid3, Rounding};
use glam::{Quat, Vec3A};
use parry3d::bounding_volume::{Aabb, BoundingVolume};
use parry3d::math::Pose;
use parry3d::partitioning::{Bvh, BvhWorkspace};
use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};

const MARGIN: f32 = 0.05;

fn parry_box(b: &Aabb3) -> Aabb {
    Aabb::new(b.min.into(), b.max.into())
}

/// Every pair of overlapping leaves.
fn leaf_pairs(bvh: &Bvh, workspace: &mut BvhWorkspace) -> HashSet<(u32, u32)> {
    let mut pairs = HashSet::new();
    bvh.traverse_bvtt_single_tree::<false>(workspace, &mut |a, b| {
        pairs.insert((a.min(b), a.max(b)));
    });
    pairs
}

/// The pairs a change-detection traversal reports.
fn new_pairs(bvh: &Bvh, workspace: &mut BvhWorkspace) -> HashSet<(u32, u32)> {
    let mut pairs = HashSet::new();
    bvh.traverse_bvtt_single_tree::<true>(workspace, &mut |a, b| {
        pairs.insert((a.min(b), a.max(b)));
    });
    pairs
}

/// Every pair of overlapping boxes, by brute force.
fn overlapping(boxes: &[Aabb]) -> HashSet<(u32, u32)> {
    let mut pairs = HashSet::new();
    for i in 0..boxes.len() {
        for j in i + 1..boxes.len() {
            if boxes[i].intersects(&boxes[j]) {
                pairs.insert((i as u32, j as u32));
            }
        }
    }
    pairs
}

#[test]
fn both_pipelines_keep_every_overlapping_pair() {
    let n: usize = 600;
    let mut r = StdRng::seed_from_u64(7);
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
            let position = Vec3A::new(
                r.random_range(-8.0..8.0),
                r.random_range(-8.0..8.0),
                r.random_range(-8.0..8.0),
            );
            Rigid3::new(Quat::from_rotation_x(r.random_range(0.0..6.3)), position)
        })
        .collect();
    // Two thirds awake (their mask bits set), moving up to 0.1 a frame.
    let mut mask = vec![0u64; n.div_ceil(64)];
    let awake: Vec<usize> = (0..n).filter(|_| r.random_range(0..3) != 0).collect();
    awake.iter().for_each(|&i| mask[i / 64] |= 1 << (i % 64));
    let velocity: Vec<Vec3A> = (0..n)
        .map(|_| Vec3A::new(r.random(), r.random(), r.random()) * 0.2 - 0.1)
        .collect();

    let batch = Batch::new(Method::AbsMatrix, Rounding::Outward);
    let margin = Margin::new(MARGIN, 0.1);
    let pose = |p: &Rigid3| Pose::from_parts(p.translation.into(), p.rotation);
    let parry_local: Vec<Aabb> = local.iter().map(parry_box).collect();

    // A: rapier's pipeline; B: bvkit's fat boxes, only the moved ones into the tree.
    let (mut a, mut wa) = (Bvh::new(), BvhWorkspace::default());
    let (mut b, mut wb) = (Bvh::new(), BvhWorkspace::default());
    let mut fat = vec![Aabb3::EMPTY; n];
    let mut moved = Moved::new();
    batch
        .update(margin, Active::All, &local, &poses, &mut fat, &mut moved)
        .unwrap();
    for i in 0..n {
        let world = parry_local[i].transform_by(&pose(&poses[i]));
        a.insert_or_update_partially(world.loosened(MARGIN), i as u32, MARGIN);
        b.insert_or_update_partially(parry_box(&fat[i]), i as u32, f32::MIN_POSITIVE);
    }
    a.refit(&mut wa);
    b.refit(&mut wb);
    let mut tight = vec![Aabb3::EMPTY; n];
    let (mut known_a, mut known_b) = (leaf_pairs(&a, &mut wa), leaf_pairs(&b, &mut wb));
    let (mut overlaps, mut new) = (0, 0);
    for frame in 0..8 {
        for &i in &awake {
            poses[i].translation += velocity[i];
            poses[i].rotation = Quat::from_rotation_y(0.05) * poses[i].rotation;
        }
        for &i in &awake {
            let world = parry_local[i].transform_by(&pose(&poses[i]));
            a.insert_or_update_partially(world, i as u32, MARGIN);
        }
        batch
            .update(
                margin,
                Active::Mask(&mask),
                &local,
                &poses,
                &mut fat,
                &mut moved,
            )
            .unwrap();
        for &i in moved.indices() {
            b.insert_or_update_partially(parry_box(&fat[i as usize]), i, f32::MIN_POSITIVE);
        }
        // rapier's order: the optimisation first, then the refit that makes every internal
        // node enclose its children again (refitting first, the traversal below missed
        // pairs under nodes the optimisation had restructured).
        for (bvh, workspace) in [(&mut a, &mut wa), (&mut b, &mut wb)] {
            bvh.optimize_incremental(workspace);
            bvh.refit(workspace);
        }
        let (new_a, new_b) = (new_pairs(&a, &mut wa), new_pairs(&b, &mut wb));
        new += new_a.len() + new_b.len();
        known_a.extend(new_a);
        known_b.extend(new_b);

        // The bodies' world boxes (Outward: they contain the exact images).
        batch.transform(&local, &poses, &mut tight).unwrap();
        let exact = overlapping(&tight.iter().map(parry_box).collect::<Vec<_>>());
        let (all_a, all_b) = (leaf_pairs(&a, &mut wa), leaf_pairs(&b, &mut wb));
        assert!(exact.is_subset(&all_a), "frame {frame}: A lost a pair");
        assert!(exact.is_subset(&all_b), "frame {frame}: B lost a pair");
        assert!(
            exact.is_subset(&known_a),
            "frame {frame}: A never reported a pair"
        );
        assert!(
            exact.is_subset(&known_b),
            "frame {frame}: B never reported a pair"
        );
        overlaps += exact.len();
    }
    // The scene is dense enough, and moves enough, that the checks above were exercised.
    assert!(overlaps > 400 && new > 100, "{overlaps} {new}");
}
