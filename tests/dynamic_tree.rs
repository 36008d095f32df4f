//! The broadphase's dynamic tree against a brute-force all-pairs reference: over many frames
//! of a dense random walk fed by `Batch::update`, with islands going to sleep and waking,
//! bodies removed and inserted and full rebuilds, the begun and ended pairs of every frame
//! are exactly the differences of the brute-force pair sets; and its refusals of bad input.

use std::collections::BTreeSet;

use bvkit::broadphase::{BroadphaseError, DynamicTree, Layers, Pairs};
use bvkit::{Aabb3, Aabb3x8, Active, Batch, Margin, Method, Moved, Rigid3, Rounding};
use glam::{Quat, Vec3A};
use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};

type Set = BTreeSet<(u32, u32)>;

/// Every pair of overlapping closed boxes among the members, by brute force.
fn brute_force(boxes: &[Aabb3], member: &[bool]) -> Set {
    let overlap = |a: &Aabb3, b: &Aabb3| a.min.cmple(b.max).all() && b.min.cmple(a.max).all();
    let mut set = Set::new();
    for i in 0..boxes.len() {
        for j in i + 1..boxes.len() {
            if member[i] && member[j] && overlap(&boxes[i], &boxes[j]) {
                set.insert((i as u32, j as u32));
            }
        }
    }
    set
}

/// The pairs as a set, with a check that none is listed twice or out of order.
fn as_set(pairs: &[(u32, u32)]) -> Set {
    let set: Set = pairs.iter().copied().collect();
    assert_eq!(set.len(), pairs.len(), "a pair is reported twice");
    assert!(
        pairs.iter().all(|(a, b)| a < b),
        "a pair is not (smaller, larger)"
    );
    set
}

/// Checks one frame's report against the reference: begun = now \ before, ended = before \ now.
fn check(frame: usize, pairs: &Pairs, before: &Set, now: &Set, tree: &DynamicTree) {
    let begun: Set = now.difference(before).copied().collect();
    let ended: Set = before.difference(now).copied().collect();
    assert_eq!(as_set(&pairs.begun), begun, "frame {frame}: begun pairs");
    assert_eq!(as_set(&pairs.ended), ended, "frame {frame}: ended pairs");
    let all: Set = tree.overlapping_pairs().into_iter().collect();
    assert_eq!(&all, now, "frame {frame}: all overlapping pairs");
}

#[test]
fn every_frame_reports_exactly_the_pairs_that_began_and_ended() {
    const N: usize = 400;
    const ISLAND: usize = 16;
    let mut r = StdRng::seed_from_u64(47);
    // Boxes of 0.2 to 1 unit in a cube of 12 units: about six overlaps per body.
    let local: Vec<Aabb3> = (0..N)
        .map(|_| {
            let e = Vec3A::new(
                r.random_range(0.1..0.5),
                r.random_range(0.1..0.5),
                r.random_range(0.1..0.5),
            );
            Aabb3::new(-e, e)
        })
        .collect();
    let mut poses: Vec<Rigid3> = (0..N)
        .map(|_| {
            let p = Vec3A::new(
                r.random_range(-6.0..6.0),
                r.random_range(-6.0..6.0),
                r.random_range(-6.0..6.0),
            );
            Rigid3::new(Quat::from_rotation_x(r.random_range(0.0..6.0)), p)
        })
        .collect();
    let velocity: Vec<Vec3A> = (0..N)
        .map(|_| Vec3A::new(r.random(), r.random(), r.random()) * 0.6 - 0.3)
        .collect();
    let batch = Batch::new(Method::AbsMatrix, Rounding::Outward);
    let margin = Margin::new(0.05, 0.1);
    let (mut fat, mut moved) = (vec![Aabb3::EMPTY; N], Moved::new());
    batch
        .update(margin, Active::All, &local, &poses, &mut fat, &mut moved)
        .unwrap();
    let mut tree = DynamicTree::from_boxes(&fat).unwrap();
    // Rebuilt by its upkeep every few frames (two moves per proxy, each rebuild spread over
    // three frames, so that moves, removes and inserts meet rebuilds under way), besides
    // the explicit rebuilds below.
    tree.set_rebuild_after(2.0);
    tree.set_rebuild_frames(3);
    let mut maintained = 0;
    let mut member = vec![true; N];
    let mut awake = vec![true; N];
    let mut before = Set::new();
    let mut pairs = Pairs::with_ended();
    let (mut begun, mut ended, mut slept, mut removed) = (0, 0, 0, 0);
    for frame in 0..120 {
        // Islands fall asleep and wake: the update skips the sleeping bodies (the tree
        // needs no call), whose pairs must last.
        for start in (0..N).step_by(ISLAND) {
            if r.random_bool(0.1) {
                let sleep = awake[start];
                slept += usize::from(sleep);
                awake[start..start + ISLAND].fill(!sleep);
            }
        }
        // Bodies leave and come back between updates.
        for _ in 0..3 {
            let i = r.random_range(0..N);
            if member[i] {
                assert!(tree.remove(i as u32));
                removed += 1;
            } else {
                tree.insert(i as u32, fat[i]).unwrap();
            }
            member[i] = !member[i];
        }
        for i in 0..N {
            if awake[i] {
                poses[i].translation += velocity[i];
                // Keep the walk dense: bounce off the cube's walls.
                let t = poses[i].translation;
                poses[i].translation = t.clamp(Vec3A::splat(-6.0), Vec3A::splat(6.0));
                poses[i].rotation = Quat::from_rotation_y(0.1) * poses[i].rotation;
            }
        }
        let mut mask = vec![0u64; N.div_ceil(64)];
        for i in 0..N {
            if awake[i] {
                mask[i / 64] |= 1 << (i % 64);
            }
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
        if frame % 25 == 24 {
            tree.rebuild();
        }
        tree.write(moved.indices(), &fat).unwrap();
        maintained += usize::from(tree.maintain());
        tree.report(&mut pairs);
        let now = brute_force(&fat, &member);
        check(frame, &pairs, &before, &now, &tree);
        assert!(pairs.refused.is_empty());
        for i in 0..N {
            assert_eq!(
                tree.get(i as u32),
                member[i].then_some(fat[i]),
                "frame {frame}"
            );
        }
        begun += pairs.begun.len();
        ended += pairs.ended.len();
        before = now;
    }
    // The walk exercised what it claims to.
    assert!(begun > 1000 && ended > 1000, "begun {begun}, ended {ended}");
    assert!(
        slept > 10 && removed > 50,
        "slept {slept}, removed {removed}"
    );
    assert!(before.len() > 300, "{} pairs at the end", before.len());
    assert!(maintained > 10, "{maintained} rebuilds by the upkeep");
}

#[test]
fn a_rebuild_spread_over_frames_misses_no_change_made_meanwhile() {
    // A rebuild under way, spread over many frames, while proxies move, leave, come back,
    // are parked by a bad box and unparked: every frame's pairs and boxes are exact, and
    // the rebuilds finish.
    const N: usize = 300;
    let mut r = StdRng::seed_from_u64(47);
    let random_box = |r: &mut StdRng| {
        let c = Vec3A::new(
            r.random_range(-5.0..5.0),
            r.random_range(-5.0..5.0),
            r.random_range(-5.0..5.0),
        );
        let e = Vec3A::splat(r.random_range(0.2..0.8));
        Aabb3::new(c - e, c + e)
    };
    let mut fat: Vec<Aabb3> = (0..N).map(|_| random_box(&mut r)).collect();
    let mut tree = DynamicTree::from_boxes(&fat).unwrap();
    tree.set_rebuild_after(0.5);
    tree.set_rebuild_frames(6);
    let mut member = vec![true; N];
    let mut parked = vec![false; N];
    let mut pairs = Pairs::with_ended();
    let mut before = Set::new();
    let (mut finished, mut refused) = (0, 0);
    for frame in 0..200 {
        for _ in 0..4 {
            let i = r.random_range(0..N);
            if member[i] {
                assert!(tree.remove(i as u32));
            } else {
                fat[i] = random_box(&mut r);
                tree.insert(i as u32, fat[i]).unwrap();
                parked[i] = false;
            }
            member[i] = !member[i];
        }
        let mut moved = Vec::new();
        for i in 0..N {
            if r.random_bool(0.2) {
                moved.push(i as u32);
                let bad = r.random_bool(0.03);
                fat[i] = if bad { Aabb3::NAN } else { random_box(&mut r) };
                parked[i] = member[i] && bad;
            }
        }
        tree.write(&moved, &fat).unwrap();
        finished += usize::from(tree.maintain());
        tree.report(&mut pairs);
        refused += pairs.refused.len();
        let placed: Vec<bool> = (0..N).map(|i| member[i] && !parked[i]).collect();
        let now = brute_force(&fat, &placed);
        check(frame, &pairs, &before, &now, &tree);
        for i in 0..N {
            assert_eq!(tree.contains(i as u32), member[i], "frame {frame}");
            assert_eq!(tree.is_parked(i as u32), member[i] && parked[i]);
            assert_eq!(tree.get(i as u32), placed[i].then_some(fat[i]));
        }
        before = now;
    }
    assert!(finished > 10, "{finished} rebuilds finished");
    assert!(refused > 50, "{refused} boxes refused");
}

/// The frame (counted from 1) in which the upkeep's first rebuild takes over, when each
/// frame writes `per_frame` of 1000 proxies (in turn) and calls `maintain`, with the default
/// trigger (16 moves per proxy) and spread (32 calls).
fn first_takeover(per_frame: usize) -> Option<usize> {
    let fat: Vec<Aabb3> = (0..1000)
        .map(|i| {
            let c = Vec3A::new((i % 10) as f32, (i / 10 % 10) as f32, (i / 100) as f32);
            Aabb3::new(c, c + 0.6)
        })
        .collect();
    let mut tree = DynamicTree::from_boxes(&fat).unwrap();
    let mut next = 0;
    (1..=20_000).find(|_| {
        let mut moved: Vec<u32> = (next..next + per_frame)
            .map(|i| (i % 1000) as u32)
            .collect();
        moved.sort_unstable();
        next += per_frame;
        tree.write(&moved, &fat).unwrap();
        tree.maintain()
    })
}

#[test]
fn where_most_proxies_move_a_rebuild_takes_over_before_they_moved_a_quarter_of_its_trigger() {
    // Every proxy moves every frame: the rebuild starts in frame 17 (past 16 moves each) and
    // must take over once they have moved 4 times more each, in frame 20 (it would take
    // about 32 calls at its spread's own pace).
    let fast = first_takeover(1000);
    assert_eq!(fast, Some(20), "took over in frame {fast:?}");
    // One proxy in a hundred moves each frame: the rebuild starts in frame 1601 and keeps to
    // its spread, about 32 calls.
    let slow = first_takeover(10);
    assert!(
        matches!(slow, Some(1625..=1641)),
        "took over in frame {slow:?}"
    );
}

#[test]
fn a_rebuild_takes_over_after_about_as_many_calls_as_it_is_spread_over() {
    let fat: Vec<Aabb3> = (0..1000)
        .map(|i| {
            let c = Vec3A::new((i % 10) as f32, (i / 10 % 10) as f32, (i / 100) as f32);
            Aabb3::new(c, c + 0.6)
        })
        .collect();
    let moved: Vec<u32> = (0..1000).collect();
    let mut tree = DynamicTree::from_boxes(&fat).unwrap();
    tree.set_rebuild_after(0.5);
    // Over one call: the new hierarchy takes over in the call that starts it.
    tree.set_rebuild_frames(1);
    tree.write(&moved, &fat).unwrap();
    assert!(tree.maintain());
    assert!(!tree.maintain(), "nothing moved since");
    // Over four: a few calls, never the first.
    tree.set_rebuild_frames(4);
    tree.write(&moved, &fat).unwrap();
    let calls = (1..=20).find(|_| tree.maintain());
    assert!(
        matches!(calls, Some(2..=6)),
        "took over after {calls:?} calls"
    );
    let mut pairs = Pairs::new();
    tree.report(&mut pairs);
    assert_eq!(
        tree.overlapping_pairs(),
        brute_force(&fat, &[true; 1000])
            .into_iter()
            .collect::<Vec<_>>()
    );
}

#[test]
fn begun_pairs_alone_match_the_reference() {
    // Without the ended pairs (the default), the begun ones are the same.
    let boxes = |shift: f32| -> Vec<Aabb3> {
        (0..64)
            .map(|i| {
                let c = Vec3A::new((i % 8) as f32, (i / 8) as f32, 0.0) + Vec3A::X * shift;
                Aabb3::new(c - 0.3, c + 0.3)
            })
            .collect()
    };
    let start = boxes(0.0);
    let mut tree = DynamicTree::from_boxes(&start).unwrap();
    let mut pairs = Pairs::new();
    let member = vec![true; 64];
    tree.update(&[], &start, &mut pairs).unwrap();
    assert!(pairs.begun.is_empty() && pairs.ended.is_empty());
    // Every odd body moves half a unit along x: it now touches its neighbours.
    let mut next = start.clone();
    let odd: Vec<u32> = (1..64).step_by(2).collect();
    for &i in &odd {
        next[i as usize] = boxes(0.5)[i as usize];
    }
    tree.update(&odd, &next, &mut pairs).unwrap();
    let now = brute_force(&next, &member);
    assert!(!now.is_empty());
    assert_eq!(as_set(&pairs.begun), now);
    // And back: every pair ends, which a begun-only report leaves out.
    tree.update(&odd, &start, &mut pairs).unwrap();
    assert!(pairs.begun.is_empty() && pairs.ended.is_empty());
    assert!(tree.overlapping_pairs().is_empty());
}

#[test]
fn a_tower_that_comes_apart_ends_every_pair() {
    // A stack of 64 boxes along z, each touching the next two. Then the odd ones slide out, alternately to +x and −x: every
    // pair with an odd box ends, those of two moved odd boxes included, and only the even
    // boxes' pairs stay.
    let tower = |shift: f32| -> Vec<Aabb3> {
        (0..64)
            .map(|i| {
                let x = match i % 4 {
                    1 => shift,
                    3 => -shift,
                    _ => 0.0,
                };
                let c = Vec3A::new(x, 0.0, i as f32);
                Aabb3::new(c - Vec3A::new(0.5, 0.5, 1.0), c + Vec3A::new(0.5, 0.5, 1.0))
            })
            .collect()
    };
    let member = vec![true; 64];
    let start = tower(0.0);
    let mut tree = DynamicTree::from_boxes(&start).unwrap();
    let mut pairs = Pairs::with_ended();
    tree.update(&[], &start, &mut pairs).unwrap();
    let before = brute_force(&start, &member);
    assert_eq!(as_set(&pairs.begun), before);
    let moved: Vec<u32> = (1..64).step_by(2).collect();
    let next = tower(5.0);
    tree.update(&moved, &next, &mut pairs).unwrap();
    let now = brute_force(&next, &member);
    assert!(now.iter().all(|&(a, b)| a % 2 == 0 && b % 2 == 0));
    assert!(before.contains(&(1, 3)) && !now.contains(&(1, 3)));
    assert!(pairs.begun.is_empty());
    assert_eq!(as_set(&pairs.ended), &before - &now);
}

/// A crowd of `n` boxes of half-extents 0.2 to 0.8 with centres in a cube of `side` units.
struct Crowd {
    extent: Vec<Vec3A>,
    centre: Vec<Vec3A>,
}

impl Crowd {
    fn new(r: &mut StdRng, n: usize, side: f32) -> Self {
        let extent = (0..n)
            .map(|_| Vec3A::new(r.random(), r.random(), r.random()) * 0.6 + 0.2)
            .collect();
        let centre = (0..n)
            .map(|_| Vec3A::new(r.random(), r.random(), r.random()) * side)
            .collect();
        Self { extent, centre }
    }

    fn boxes(&self) -> Vec<Aabb3> {
        self.centre
            .iter()
            .zip(&self.extent)
            .map(|(&c, &e)| Aabb3::new(c - e, c + e))
            .collect()
    }
}

#[test]
fn most_bodies_leaving_every_frame_end_exactly_their_pairs() {
    // A dense crowd where about nine in ten bodies jump every frame (the regime where the
    // ended pairs once cost a sweep that grew with the square of the movers): each frame's
    // begun and ended pairs are the differences of the brute-force pair sets. Every third
    // report asks for the begun pairs alone, and the next must still end exactly the pairs
    // that overlapped at that report: the tree follows the pairs whether or not they are
    // wanted.
    const N: usize = 600;
    let mut r = StdRng::seed_from_u64(68);
    let mut crowd = Crowd::new(&mut r, N, 10.0);
    let member = vec![true; N];
    let mut fat = crowd.boxes();
    let mut tree = DynamicTree::from_boxes(&fat).unwrap();
    let mut pairs = Pairs::with_ended();
    tree.update(&[], &fat, &mut pairs).unwrap();
    let mut before = brute_force(&fat, &member);
    assert_eq!(as_set(&pairs.begun), before);
    let (mut begun, mut ended, mut moved_total) = (0, 0, 0);
    for frame in 0..40 {
        let moved: Vec<u32> = (0..N as u32).filter(|_| r.random::<f64>() < 0.9).collect();
        for &i in &moved {
            let step = Vec3A::new(r.random(), r.random(), r.random()) * 1.2 - 0.6;
            let c = &mut crowd.centre[i as usize];
            *c = (*c + step).clamp(Vec3A::ZERO, Vec3A::splat(10.0));
        }
        fat = crowd.boxes();
        let mut pairs = if frame % 3 == 2 {
            Pairs::new()
        } else {
            Pairs::with_ended()
        };
        tree.update(&moved, &fat, &mut pairs).unwrap();
        let now = brute_force(&fat, &member);
        if frame % 3 == 2 {
            assert!(pairs.ended.is_empty());
            let expected: Set = now.difference(&before).copied().collect();
            assert_eq!(as_set(&pairs.begun), expected, "frame {frame}: begun pairs");
        } else {
            check(frame, &pairs, &before, &now, &tree);
            ended += pairs.ended.len();
        }
        begun += pairs.begun.len();
        moved_total += moved.len();
        before = now;
    }
    assert!(
        moved_total > 30 * N && begun > 2000 && ended > 2000,
        "moved {moved_total}, begun {begun}, ended {ended}"
    );
}

#[test]
fn most_bodies_moving_while_some_park_come_back_and_leave_miss_no_pair() {
    // Half of the proxies or more moving in one write take the one-pass refit of the slots
    // above them. Meanwhile some movers get a NaN box (parked, which takes them out of the
    // hierarchy), parked ones come back with a good box (inserted again), bodies are removed
    // and inserted between frames, and the upkeep rebuilds the tree every few frames:
    // every report must still be the differences of the brute-force pair sets.
    const N: usize = 600;
    let mut r = StdRng::seed_from_u64(81);
    let mut crowd = Crowd::new(&mut r, N, 10.0);
    let mut member = vec![true; N];
    let mut fat = crowd.boxes();
    let mut tree = DynamicTree::from_boxes(&fat).unwrap();
    tree.set_rebuild_after(3.0);
    tree.set_rebuild_frames(2);
    let mut pairs = Pairs::with_ended();
    tree.update(&[], &fat, &mut pairs).unwrap();
    let present = |fat: &[Aabb3], member: &[bool]| -> Vec<bool> {
        (0..N)
            .map(|i| member[i] && !fat[i].min.x.is_nan())
            .collect()
    };
    let mut before = brute_force(&fat, &present(&fat, &member));
    let (mut parked, mut unparked, mut refused) = (0, 0, 0);
    for frame in 0..40 {
        for _ in 0..4 {
            let i = r.random_range(0..N);
            if member[i] {
                assert!(tree.remove(i as u32));
            } else {
                if fat[i].min.x.is_nan() {
                    fat[i] = crowd.boxes()[i];
                }
                tree.insert(i as u32, fat[i]).unwrap();
            }
            member[i] = !member[i];
        }
        let moved: Vec<u32> = (0..N as u32).filter(|_| r.random::<f64>() < 0.8).collect();
        for &i in &moved {
            let i = i as usize;
            let step = Vec3A::new(r.random(), r.random(), r.random()) * 1.2 - 0.6;
            crowd.centre[i] = (crowd.centre[i] + step).clamp(Vec3A::ZERO, Vec3A::splat(10.0));
            let was_parked = fat[i].min.x.is_nan();
            fat[i] = if r.random::<f64>() < 0.03 {
                Aabb3::NAN
            } else {
                Aabb3::new(
                    crowd.centre[i] - crowd.extent[i],
                    crowd.centre[i] + crowd.extent[i],
                )
            };
            if member[i] {
                parked += usize::from(!was_parked && fat[i].min.x.is_nan());
                unparked += usize::from(was_parked && !fat[i].min.x.is_nan());
            }
        }
        tree.update(&moved, &fat, &mut pairs).unwrap();
        refused += pairs.refused.len();
        let now = brute_force(&fat, &present(&fat, &member));
        check(frame, &pairs, &before, &now, &tree);
        before = now;
    }
    assert!(
        parked > 100 && unparked > 100 && refused > 100,
        "parked {parked}, unparked {unparked}, refused {refused}"
    );
}

#[test]
fn few_movers_among_many_take_the_queries_and_agree_with_brute_force() {
    // Under a sixteenth of the proxies changing, a report queries each changed proxy's box
    // rather than traversing the tree against itself: 2000 boxes, 40 of them jumping each
    // frame, every report against brute force.
    const N: usize = 2000;
    let mut r = StdRng::seed_from_u64(16);
    let mut crowd = Crowd::new(&mut r, N, 16.0);
    let member = vec![true; N];
    let mut fat = crowd.boxes();
    let mut tree = DynamicTree::from_boxes(&fat).unwrap();
    let mut pairs = Pairs::with_ended();
    tree.update(&[], &fat, &mut pairs).unwrap();
    let mut before = brute_force(&fat, &member);
    let (mut begun, mut ended) = (0, 0);
    for frame in 0..60 {
        let mut moved: Vec<u32> = (0..40).map(|_| r.random_range(0..N as u32)).collect();
        moved.sort_unstable();
        moved.dedup();
        for &i in &moved {
            crowd.centre[i as usize] += Vec3A::new(r.random(), r.random(), r.random()) * 3.0 - 1.5;
        }
        fat = crowd.boxes();
        tree.update(&moved, &fat, &mut pairs).unwrap();
        let now = brute_force(&fat, &member);
        check(frame, &pairs, &before, &now, &tree);
        begun += pairs.begun.len();
        ended += pairs.ended.len();
        before = now;
    }
    assert!(begun > 300 && ended > 300, "begun {begun}, ended {ended}");
}

#[test]
fn a_build_fills_its_nodes() {
    // A full tree of eight children per node over n proxies has ⌈n/8⌉ bottom nodes, ⌈n/64⌉
    // above them, and so on up to the root: a build takes no more, whatever the counts
    // (including those one past a power of eight) and the boxes' layout.
    let mut rng = StdRng::seed_from_u64(48);
    for n in [1usize, 2, 8, 9, 63, 64, 65, 511, 512, 513, 4097, 30_000] {
        let boxes: Vec<Aabb3> = (0..n)
            .map(|_| {
                let c = Vec3A::new(
                    rng.random_range(-50.0..50.0),
                    rng.random_range(-50.0..50.0),
                    rng.random_range(-2.0..2.0),
                );
                Aabb3::new(c - 0.5, c + 0.5)
            })
            .collect();
        let mut full = 0;
        let mut level = n;
        loop {
            level = level.div_ceil(8);
            full += level;
            if level == 1 {
                break;
            }
        }
        let mut tree = DynamicTree::from_boxes(&boxes).unwrap();
        assert!(
            tree.nodes() <= full,
            "{n} proxies: {} nodes, a full tree has {full}",
            tree.nodes()
        );
        tree.rebuild();
        assert!(
            tree.nodes() <= full,
            "{n} proxies rebuilt: {} nodes",
            tree.nodes()
        );
        // And every proxy is still found by its own box.
        for (i, b) in boxes.iter().enumerate() {
            let mut found = false;
            tree.query(b, Layers::ALL, |id| found |= id == i as u32)
                .unwrap();
            assert!(found, "{n} proxies: proxy {i} lost");
        }
    }
}

#[test]
fn empty_boxes_stay_out_and_queries_see_only_proxies() {
    // 1001 bodies in AoSoA blocks: the last block's padding lanes hold the empty box, and
    // so does body 5 (no geometry). Neither enters the tree.
    let mut boxes: Vec<Aabb3> = (0..1001)
        .map(|i| {
            let c = Vec3A::new(i as f32 * 2.0, 0.0, 0.0);
            Aabb3::new(c - 0.5, c + 0.5)
        })
        .collect();
    boxes[5] = Aabb3::EMPTY;
    let blocks = Aabb3x8::pack(&boxes);
    assert_eq!(blocks.len() * 8, 1008);
    let tree = DynamicTree::from_boxes(&blocks[..]).unwrap();
    assert_eq!(tree.len(), 1000);
    assert!(!tree.contains(5) && !tree.contains(1001) && tree.contains(1000));
    // A query reaching everything, infinite faces included, finds exactly the proxies.
    let everything = Aabb3::new(Vec3A::NEG_INFINITY, Vec3A::INFINITY);
    let mut hits = vec![];
    tree.query(&everything, Layers::ALL, |id| hits.push(id))
        .unwrap();
    hits.sort();
    let expected: Vec<u32> = (0..1001).filter(|&i| i != 5).collect();
    assert_eq!(hits, expected);
    let mut none = vec![];
    DynamicTree::new()
        .query(&everything, Layers::ALL, |id| none.push(id))
        .unwrap();
    assert!(none.is_empty());
}

#[test]
fn the_first_update_begins_every_overlapping_pair() {
    let b = |x: f32| Aabb3::new(Vec3A::new(x, 0.0, 0.0), Vec3A::new(x + 1.0, 1.0, 1.0));
    let fat = vec![b(0.0), b(1.0), b(2.0), b(10.0)];
    let mut tree = DynamicTree::from_boxes(&fat).unwrap();
    let mut pairs = Pairs::with_ended();
    tree.update(&[], &fat, &mut pairs).unwrap();
    // Touching faces overlap (closed boxes).
    assert_eq!(as_set(&pairs.begun), Set::from([(0, 1), (1, 2)]));
    tree.update(&[], &fat, &mut pairs).unwrap();
    assert!(pairs.begun.is_empty() && pairs.ended.is_empty());
}

#[test]
fn bad_boxes_are_refused_at_insert() {
    let good = Aabb3::new(Vec3A::ZERO, Vec3A::ONE);
    let mut tree = DynamicTree::new();
    tree.insert(0, good).unwrap();
    for bad in [
        Aabb3::NAN,
        Aabb3::EMPTY,
        Aabb3::new(Vec3A::ZERO, Vec3A::new(1.0, f32::NAN, 1.0)),
        Aabb3::new(Vec3A::ZERO, Vec3A::new(f32::INFINITY, 1.0, 1.0)),
        Aabb3::new(Vec3A::ONE, Vec3A::ZERO),
    ] {
        assert_eq!(
            tree.insert(1, bad),
            Err(BroadphaseError::InvalidBox { id: 1 })
        );
        assert!(!tree.contains(1));
        // `from_boxes` leaves the empty box out (the padding of AoSoA blocks), and refuses
        // the others.
        let built = DynamicTree::from_boxes(&[good, bad][..]);
        if bad == Aabb3::EMPTY {
            assert!(built.is_ok_and(|t| t.len() == 1 && !t.contains(1)));
        } else {
            assert_eq!(built.err(), Some(BroadphaseError::InvalidBox { id: 1 }));
        }
    }
    assert_eq!(
        tree.insert(0, good),
        Err(BroadphaseError::Duplicate { id: 0 })
    );
    for id in [u32::MAX, (1 << 31) - 2] {
        assert_eq!(
            tree.insert(id, good),
            Err(BroadphaseError::IdTooLarge { id })
        );
    }
    assert_eq!(tree.len(), 1);
    // Nothing reached the tree: it still answers.
    let mut pairs = Pairs::with_ended();
    tree.update(&[], &[good][..], &mut pairs).unwrap();
    assert!(pairs.begun.is_empty() && pairs.refused.is_empty());
}

#[test]
fn a_bad_box_at_update_parks_its_proxy_until_a_good_one_comes() {
    let b = |x: f32| Aabb3::new(Vec3A::new(x, 0.0, 0.0), Vec3A::new(x + 1.0, 1.0, 1.0));
    let mut fat = vec![b(0.0), b(0.5), b(5.0)];
    let mut tree = DynamicTree::from_boxes(&fat).unwrap();
    let mut pairs = Pairs::with_ended();
    tree.update(&[], &fat, &mut pairs).unwrap();
    assert_eq!(pairs.begun, [(0, 1)]);
    for bad in [
        Aabb3::NAN,
        Aabb3::new(Vec3A::splat(f32::NEG_INFINITY), Vec3A::ONE),
    ] {
        fat[1] = bad;
        tree.update(&[1], &fat, &mut pairs).unwrap();
        // Refused and reported; its pair ends; it is out of every query.
        assert_eq!(pairs.refused, [1]);
        assert_eq!(pairs.ended, [(0, 1)]);
        assert!(tree.is_parked(1) && tree.contains(1) && tree.get(1).is_none());
        let mut hits = vec![];
        let all = Aabb3::new(Vec3A::splat(-1e30), Vec3A::splat(1e30));
        tree.query(&all, Layers::ALL, |id| hits.push(id)).unwrap();
        hits.sort();
        assert_eq!(hits, [0, 2]);
        // A rebuild and another bad box change nothing.
        tree.rebuild();
        tree.update(&[1], &fat, &mut pairs).unwrap();
        assert_eq!(pairs.refused, [1]);
        assert!(pairs.begun.is_empty() && pairs.ended.is_empty());
        // A good box brings it back, and its pair begins again.
        fat[1] = b(0.5);
        tree.update(&[1], &fat, &mut pairs).unwrap();
        assert!(pairs.refused.is_empty());
        assert_eq!(pairs.begun, [(0, 1)]);
        assert_eq!(tree.get(1), Some(b(0.5)));
    }
    // A parked proxy can be removed.
    fat[2] = Aabb3::NAN;
    tree.update(&[2], &fat, &mut pairs).unwrap();
    assert!(tree.remove(2) && !tree.contains(2));
    assert_eq!(tree.len(), 2);
}

#[test]
fn bad_moved_lists_are_errors_before_any_change() {
    let b = Aabb3::new(Vec3A::ZERO, Vec3A::ONE);
    let fat = vec![b; 3];
    let mut tree = DynamicTree::from_boxes(&fat).unwrap();
    let mut pairs = Pairs::new();
    assert_eq!(
        tree.update(&[1, 0], &fat, &mut pairs),
        Err(BroadphaseError::Unsorted)
    );
    assert_eq!(
        tree.update(&[1, 1], &fat, &mut pairs),
        Err(BroadphaseError::Unsorted)
    );
    assert_eq!(
        tree.update(&[3], &fat, &mut pairs),
        Err(BroadphaseError::MissingBox { id: 3, len: 3 })
    );
    // The pending first frame is still there.
    tree.update(&[], &fat, &mut pairs).unwrap();
    assert_eq!(as_set(&pairs.begun), Set::from([(0, 1), (0, 2), (1, 2)]));
}

/// Kinds, layers, box and point queries and every other operation (inserts of any kind,
/// removes, writes with any boxes, changes of kind, layers and kind pairs, rebuilds whole
/// and spread) against the brute-force referee, over random sequences: every report's
/// begun and ended pairs, every query's hits, every proxy's state, kind and layers, and
/// every pair after every operation.
#[test]
fn kinds_layers_and_queries_agree_with_brute_force_over_random_sequences() {
    use bvkit_support::referee::{Check, Op};
    let (mut begun, mut ended, mut reports) = (0, 0, 0);
    for seed in 0..96 {
        let mut r = StdRng::seed_from_u64(seed);
        let mut byte = || r.random::<u8>();
        let mut check = Check::new(40);
        for _ in 0..300 {
            let op = Op::decode(&mut byte, 40);
            check.apply(&op, true);
        }
        check.apply(&Op::Report, true);
        (begun, ended, reports) = (
            begun + check.begun,
            ended + check.ended,
            reports + check.reports,
        );
    }
    // Not vacuous: many reports, with pairs beginning and ending.
    assert!(
        reports > 2000 && begun > 2000 && ended > 2000,
        "{reports} {begun} {ended}"
    );
}

/// The same over long sequences whose boxes are all well formed and which report after
/// every few operations, with kinds and layers in play: few parked proxies, many pairs.
#[test]
fn long_sequences_of_kinds_and_layers_agree_with_brute_force() {
    use bvkit_support::referee::{Check, Op};
    let mut r = StdRng::seed_from_u64(85);
    let mut check = Check::new(40);
    let mut byte = || r.random::<u8>();
    for step in 0..6000 {
        let op = match Op::decode(&mut byte, 40) {
            // Only well-formed boxes here.
            Op::Insert { fat, .. } | Op::Query(fat, _) if !fat.min.cmple(fat.max).all() => {
                continue;
            }
            op => op,
        };
        check.apply(&op, step % 16 == 0);
        if step % 5 == 0 {
            check.apply(&Op::Report, false);
        }
    }
    check.check_state();
    assert!(check.begun > 1000 && check.ended > 1000);
}

/// A level: 1,500 static boxes, 500 dynamic and 50 kinematic ones among them, in three
/// layers, moving for 60 frames (a few movers in some frames, so that the report queries
/// each changed proxy, and most in others, so that it traverses the hierarchies, deep
/// enough to run the traversals' depth-first tasks), with statics teleported, kinds and
/// layers changed and the kind pairs switched on the way: every report against brute
/// force.
#[test]
fn a_level_with_moving_bodies_in_layers_agrees_with_brute_force() {
    use bvkit::broadphase::{BodyKind, KindPairs};
    use bvkit_support::referee::{Check, Op};
    const N: u32 = 2050;
    let mut r = StdRng::seed_from_u64(86);
    let mut check = Check::new(N as usize);
    let mut boxes: Vec<Aabb3> = (0..N)
        .map(|_| {
            let c = Vec3A::new(
                r.random_range(0.0..40.0),
                r.random_range(0.0..40.0),
                r.random_range(0.0..4.0),
            );
            let e = Vec3A::new(
                r.random_range(0.2..1.0),
                r.random_range(0.2..1.0),
                r.random_range(0.2..1.0),
            );
            Aabb3::new(c - e, c + e)
        })
        .collect();
    let kind = |id: u32| match id {
        0..1500 => BodyKind::Static,
        1500..2000 => BodyKind::Dynamic,
        _ => BodyKind::Kinematic,
    };
    for id in 0..N {
        let layers = Layers::new(1 << (id % 3), if id % 7 == 0 { 0b011 } else { 0b111 });
        let op = Op::Insert {
            id,
            fat: boxes[id as usize],
            kind: kind(id),
            layers,
        };
        check.apply(&op, false);
    }
    check.apply(&Op::Report, true);
    for frame in 0..60 {
        let share = if frame % 3 == 0 { 0.01 } else { 0.8 };
        let mut moved = Vec::new();
        for id in 0..N {
            let moves = match kind(id) {
                BodyKind::Static => r.random_bool(0.002),
                _ => r.random_bool(share),
            };
            if moves {
                let step = Vec3A::new(
                    r.random_range(-0.6..0.6),
                    r.random_range(-0.6..0.6),
                    r.random_range(-0.3..0.3),
                );
                let b = &mut boxes[id as usize];
                *b = Aabb3::new(b.min + step, b.max + step);
                moved.push((id, *b));
            }
        }
        check.apply(&Op::Write(moved), false);
        match frame % 10 {
            2 => check.apply(&Op::SetKind(r.random_range(0..N), BodyKind::Dynamic), false),
            4 => check.apply(
                &Op::SetKind(r.random_range(1500..N), BodyKind::Static),
                false,
            ),
            5 => check.apply(
                &Op::SetLayers(r.random_range(0..N), Layers::new(2, 2)),
                false,
            ),
            7 => check.apply(
                &Op::SetKindPairs(KindPairs {
                    kinematic_kinematic: frame % 20 == 7,
                    kinematic_static: true,
                }),
                false,
            ),
            _ => {}
        }
        check.apply(&Op::Maintain(4), false);
        check.apply(&Op::Report, frame % 10 == 9);
    }
    assert!(
        check.begun > 5000 && check.ended > 5000,
        "{} {}",
        check.begun,
        check.ended
    );
}

/// Every proxy in the same layers, with no check of each pair (the tree's common layers):
/// layers that meet themselves pair as `Layers::ALL` does, layers that do not (debris that
/// ignores debris) never pair, until a proxy in other layers comes, which pairs as its
/// layers say; and queries see the common layers' answer.
#[test]
fn proxies_all_in_one_layer_pair_as_that_layer_says() {
    let mut r = StdRng::seed_from_u64(9);
    let boxes: Vec<Aabb3> = (0..2000)
        .map(|_| {
            let c = Vec3A::new(r.random(), r.random(), r.random()) * 30.0;
            Aabb3::new(c - 0.7, c + 0.7)
        })
        .collect();
    let all = DynamicTree::from_boxes(&boxes).unwrap().overlapping_pairs();
    assert!(all.len() > 500);
    for (layers, pairs) in [
        (Layers::new(1, 1), all.clone()),
        (Layers::new(1, 2), Vec::new()),
    ] {
        let mut tree = DynamicTree::from_boxes_with(&boxes, |_| {
            (bvkit::broadphase::BodyKind::Dynamic, layers)
        })
        .unwrap();
        let mut report = Pairs::new();
        tree.report(&mut report);
        let mut begun = report.begun.clone();
        begun.sort_unstable();
        assert_eq!(begun, pairs, "{layers:?}");
        assert_eq!(tree.overlapping_pairs(), pairs, "{layers:?}");
        let everything = Aabb3::new(Vec3A::splat(-1e3), Vec3A::splat(1e3));
        for (filter, seen) in [(Layers::new(2, 1), 2000), (Layers::new(1, 1), 0)] {
            let mut n = 0;
            tree.query(&everything, filter, |_| n += 1).unwrap();
            let expected = if layers.interacts_with(filter) {
                2000
            } else {
                0
            };
            assert_eq!(n, expected, "{layers:?} {filter:?} ({seen})");
        }
        // One proxy in other layers: it pairs as they say, the others as before.
        tree.set_layers(0, Layers::ALL).unwrap();
        tree.report(&mut report);
        let with_zero: Vec<(u32, u32)> = all
            .iter()
            .copied()
            .filter(|&(a, b)| {
                pairs.contains(&(a, b))
                    || (a == 0 && layers.interacts_with(Layers::ALL))
                    || (b == 0 && layers.interacts_with(Layers::ALL))
            })
            .collect();
        assert_eq!(tree.overlapping_pairs(), with_zero, "{layers:?}");
    }
}

/// A proxy removed and inserted again between two reports, with other layers or another
/// kind: the report compares the pairs then and now, so a pair its old layers or kind did
/// not admit and its new ones do begins, and the other way round ends.
#[test]
fn a_proxy_inserted_again_with_other_layers_or_kind_begins_and_ends_its_pairs() {
    use bvkit::broadphase::BodyKind;
    let b = Aabb3::new(Vec3A::ZERO, Vec3A::ONE);
    let mut tree = DynamicTree::new();
    tree.insert_with(7, b, BodyKind::Dynamic, Layers::new(1, 1))
        .unwrap();
    tree.insert_with(5, b, BodyKind::Dynamic, Layers::new(2, 2))
        .unwrap();
    let mut pairs = Pairs::with_ended();
    tree.report(&mut pairs);
    assert!(pairs.begun.is_empty());
    // Back in layer 1: the pair begins.
    assert!(tree.remove(5));
    tree.insert_with(5, b, BodyKind::Dynamic, Layers::new(1, 1))
        .unwrap();
    tree.report(&mut pairs);
    assert_eq!(pairs.begun, [(5, 7)]);
    // Back as a static proxy beside a static one: the pair ends.
    tree.set_kind(7, BodyKind::Static).unwrap();
    tree.report(&mut pairs);
    assert!(pairs.begun.is_empty() && pairs.ended.is_empty());
    assert!(tree.remove(5));
    tree.insert_with(5, b, BodyKind::Static, Layers::new(1, 1))
        .unwrap();
    tree.report(&mut pairs);
    assert_eq!((pairs.begun.len(), pairs.ended.clone()), (0, vec![(5, 7)]));
    // And dynamic again: it begins.
    assert!(tree.remove(5));
    tree.insert_with(5, b, BodyKind::Dynamic, Layers::new(1, 1))
        .unwrap();
    tree.report(&mut pairs);
    assert_eq!((pairs.begun.clone(), pairs.ended.len()), (vec![(5, 7)], 0));
}
