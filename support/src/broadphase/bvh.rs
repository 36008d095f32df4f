//! Four broadphase pipelines on one scene, each on its own tree, frame by frame: A and B on
//! parry3d's `Bvh`, C on bvkit's `DynamicTree`, D on obvhs's `Bvh2` (the tree avian uses).
//!
//! - A, as rapier runs it: every awake body's world box (`Aabb::transform_by`), each into
//!   the tree with `insert_or_update_partially(box, body, margin)` (a leaf changes only when
//!   the box leaves its enlarged box), then `optimize_incremental`, `refit` (in rapier's
//!   order: refitted before the optimisation, the tree lost pairs in `tests/pipeline.rs`)
//!   and the new pairs (`traverse_bvtt_single_tree::<true>`).
//! - B, with bvkit: `Batch::update` (Outward, AoSoA blocks) of the fat boxes of the awake bodies, then only
//!   the moved ones into the tree, then the same three steps. The fat box already holds the
//!   margin, so the tree adds none; parry marks a leaf changed only under a positive margin,
//!   so B passes the smallest normal `f32`, which moves a face by at most `2^-126` (and not
//!   at all where `|face| >= 2^-102`).
//!
//! - C, bvkit's own: the same update (into its own fat boxes and moved set), then
//!   `DynamicTree::write` of the moved proxies (the leaves, their paths enlarged: the
//!   "leaves" column), `maintain` (a rebuild once enough has moved: "optim") and `report`
//!   (the pairs that began, searched from the moved proxies: "pairs").
//! - D, obvhs: C's fat boxes and moved list (its box stage is C's) into `obvhs::ObvhsTree`
//!   (see `obvhs.rs` for the upkeep obvhs advises); its pairs are the begun ones too.
//!
//! Two options of B's (`Tuning`) test what bvkit can take off the tree's work:
//! - `--relative R`: B's fat boxes also grow each face by `R` times the box's half-extent
//!   along it (`Margin`'s relative part, which parry's absolute margin cannot express), so
//!   fewer leaves change and the change-detection traversal visits less; the boxes are
//!   fatter, so B reports more pairs.
//! - `--partial K`: B optimises and refits the whole tree only every K-th frame, and in
//!   between refits only the paths above the leaves that changed (`refit_partial`, which
//!   parry allows only with no optimisation since the last refit), from the moved list
//!   bvkit returns: the one stage that costs the same whatever moved becomes
//!   `O(moved × height)`.
//!
//! Both trees start from the same first frame, and one frame runs unmeasured before the
//! measured ones. A leaf's box depends on when it was last rewritten, so neither
//! pipeline's pair set contains the other's by construction; what
//! both promise is that every pair of bodies whose world boxes overlap is a pair of
//! overlapping leaves. On scenes of up to 20 000 bodies every frame checks that against a
//! sweep over the bodies' Outward world boxes, which contain the exact images (A's leaves
//! contain them too: the margin is far wider than the rounding of `transform_by`).

use std::collections::HashSet;
use std::time::Instant;

use bvkit::broadphase::{DynamicTree, Pairs};
use bvkit::{Aabb3, Aabb3x8, Active, Batch, Margin, Method, Moved, Rigid3x8, Rounding};
use parry3d::bounding_volume::{Aabb, BoundingVolume};
use parry3d::math::Pose;
use parry3d::partitioning::{Bvh, BvhLeafUpdateStatus, BvhWorkspace};

use super::obvhs::ObvhsTree;
use super::scene::Scene;
use crate::common::cpu;

/// The margin both pipelines give a box when its leaf is rewritten (B's relative part is
/// zero, so that its fat boxes are A's enlarged boxes at the same instant).
const MARGIN: f32 = 0.05;

/// One pipeline's tree, its workspace, the pairs it found in the last frame, and the leaves
/// whose change flag the last refit set (every leaf after the first).
struct Tree {
    bvh: Bvh,
    workspace: BvhWorkspace,
    pairs: Vec<(u32, u32)>,
    changed: Vec<u32>,
}

/// What B does beyond A's pipeline (module docs), and C's upkeep settings; the default is
/// A's tree work exactly for B, and the tree's own defaults for C.
#[derive(Clone, Copy, Debug, Default)]
pub struct Tuning {
    /// The relative part of B's margin.
    pub relative: f32,
    /// Optimise and refit the whole tree every this many frames, and refit only the changed
    /// paths in between (0: the whole tree every frame, as A).
    pub partial: usize,
    /// C's `DynamicTree::set_rebuild_after`, where given.
    pub rebuild_after: Option<f32>,
    /// C's `DynamicTree::set_rebuild_frames`, where given.
    pub rebuild_frames: Option<u32>,
}

/// The milliseconds of a frame's stages, and what they did.
#[derive(Default, Clone, Copy)]
pub struct Frame {
    /// World or fat boxes, tree leaves, optimisation, refit, pairs. C writes its leaves
    /// and enlarges their paths in one step (its "leaves"), optimises by rebuilding when
    /// `DynamicTree::maintain` says so, and reports the pairs that began.
    pub ms: [f64; 5],
    pub rewritten: usize,
    pub pairs: usize,
}

impl Frame {
    pub fn total(&self) -> f64 {
        self.ms.iter().sum()
    }
}

impl Tree {
    /// A tree over `boxes` enlarged by `margin` (parry inserts a new leaf as given, and
    /// enlarges only a box that leaves its leaf), refitted.
    fn new(boxes: impl Iterator<Item = Aabb>, margin: f32) -> Self {
        let mut tree = Self {
            bvh: Bvh::new(),
            workspace: BvhWorkspace::default(),
            pairs: Vec::new(),
            changed: Vec::new(),
        };
        for (i, b) in boxes.enumerate() {
            tree.bvh
                .insert_or_update_partially(b.loosened(margin), i as u32, margin);
            tree.changed.push(i as u32);
        }
        tree.bvh.refit(&mut tree.workspace);
        tree
    }

    /// The three stages after the leaves, whose leaves `changed` were rewritten: the
    /// optimisation and the refit of the whole tree, or (`whole` false) the refit of the
    /// paths above the leaves changed in this frame and the last; then the new pairs.
    fn finish(&mut self, whole: bool, changed: &[u32], frame: &mut Frame) {
        let start = Instant::now();
        if whole {
            self.bvh.optimize_incremental(&mut self.workspace);
        }
        frame.ms[2] = ms(start);
        let start = Instant::now();
        if whole {
            self.bvh.refit(&mut self.workspace);
        } else {
            self.bvh.refit_partial(&self.changed, changed);
        }
        self.changed.clear();
        self.changed.extend_from_slice(changed);
        frame.ms[3] = ms(start);
        let start = Instant::now();
        self.pairs.clear();
        let pairs = &mut self.pairs;
        self.bvh
            .traverse_bvtt_single_tree::<true>(&mut self.workspace, &mut |a, b| {
                pairs.push((a.min(b), a.max(b)))
            });
        frame.ms[4] = ms(start);
        frame.pairs = self.pairs.len();
    }

    /// Every pair of overlapping leaves.
    fn all_pairs(&mut self) -> HashSet<(u32, u32)> {
        let mut all = HashSet::new();
        self.bvh
            .traverse_bvtt_single_tree::<false>(&mut self.workspace, &mut |a, b| {
                all.insert((a.min(b), a.max(b)));
            });
        all
    }
}

/// Pipeline C's state: the fat boxes and moved set of its update, and the tree.
struct Dynamic {
    fat: Vec<Aabb3x8>,
    moved: Moved,
    tree: DynamicTree,
    pairs: Pairs,
    /// The pairs of the tree's boxes at the last frame checked (the reference's).
    checked: Option<HashSet<(u32, u32)>>,
}

fn ms(start: Instant) -> f64 {
    start.elapsed().as_secs_f64() * 1e3
}

fn parry_box(b: &Aabb3) -> Aabb {
    Aabb::new(b.min.into(), b.max.into())
}

/// Every pair of boxes that overlap (closed boxes), by a sweep along x.
fn overlapping(boxes: &[Aabb]) -> HashSet<(u32, u32)> {
    let mut order: Vec<u32> = (0..boxes.len() as u32).collect();
    order.sort_by(|&a, &b| {
        boxes[a as usize]
            .mins
            .x
            .total_cmp(&boxes[b as usize].mins.x)
    });
    let mut pairs = HashSet::new();
    for (k, &a) in order.iter().enumerate() {
        let ba = &boxes[a as usize];
        for &b in &order[k + 1..] {
            let bb = &boxes[b as usize];
            if bb.mins.x > ba.maxs.x {
                break;
            }
            if ba.intersects(bb) {
                pairs.insert((a.min(b), a.max(b)));
            }
        }
    }
    pairs
}

/// Both pipelines' state over one scene.
pub struct Pipelines {
    local: Vec<Aabb>,
    /// A's poses, in parry's form (the engine's own, converted outside the timing).
    poses: Vec<Pose>,
    world: Vec<Aabb>,
    a: Tree,
    batch: Batch,
    margin: Margin,
    /// B's bodies in AoSoA blocks (the update's fastest layout; an engine that keeps its
    /// poses packed simulates in place, so the packing is outside the timing), the awake
    /// mask padded to whole blocks, and the fat boxes.
    local8: Vec<Aabb3x8>,
    poses8: Vec<Rigid3x8>,
    mask8: Vec<u64>,
    fat: Vec<Aabb3x8>,
    moved: Moved,
    b: Tree,
    /// C: bvkit's update (its own fat boxes and moved set, as B's) into bvkit's tree.
    c: Dynamic,
    /// D: the same update's fat boxes and moved list (C's) into obvhs's `Bvh2`.
    d: ObvhsTree,
    tuning: Tuning,
    /// Frames run, and A's rewritten leaves in this one.
    frames: usize,
    rewritten: Vec<u32>,
}

fn pose(p: &bvkit::Rigid3) -> Pose {
    Pose::from_parts(p.translation.into(), p.rotation)
}

impl Pipelines {
    /// Both trees over the scene's first frame: every body's box.
    pub fn new(scene: &Scene, tuning: Tuning) -> Self {
        let n = scene.local.len();
        let local: Vec<Aabb> = scene.local.iter().map(parry_box).collect();
        let poses: Vec<Pose> = scene.poses.iter().map(pose).collect();
        let world: Vec<Aabb> = local
            .iter()
            .zip(&poses)
            .map(|(b, p)| b.transform_by(p))
            .collect();
        let a = Tree::new(world.iter().copied(), MARGIN);
        let batch = Batch::new(Method::AbsMatrix, Rounding::Outward);
        let margin = Margin::new(MARGIN, tuning.relative);
        let local8 = Aabb3x8::pack(&scene.local);
        let poses8 = Rigid3x8::pack(&scene.poses);
        let mut fat = Aabb3x8::pack(&vec![Aabb3::EMPTY; n]);
        let mut moved = Moved::new();
        batch
            .update(
                margin,
                Active::All,
                &local8[..],
                &poses8[..],
                &mut fat[..],
                &mut moved,
            )
            .expect("lengths agree");
        let b = Tree::new(
            Aabb3x8::unpack(&fat, n).iter().map(parry_box),
            f32::MIN_POSITIVE,
        );
        let mut mask8 = scene.mask.clone();
        mask8.resize((8 * local8.len()).div_ceil(64), 0);
        let mut tree = DynamicTree::from_boxes(&fat[..]).expect("finite fat boxes");
        if let Some(after) = tuning.rebuild_after {
            tree.set_rebuild_after(after);
        }
        if let Some(frames) = tuning.rebuild_frames {
            tree.set_rebuild_frames(frames);
        }
        let mut pairs = Pairs::new();
        // The first report: every overlapping pair begins.
        tree.report(&mut pairs);
        let d = ObvhsTree::new(&Aabb3x8::unpack(&fat, n));
        let c = Dynamic {
            fat: fat.clone(),
            moved: Moved::new(),
            tree,
            pairs,
            checked: None,
        };
        Self {
            local,
            poses,
            world,
            a,
            batch,
            margin,
            local8,
            poses8,
            mask8,
            fat,
            moved,
            b,
            c,
            d,
            tuning,
            frames: 0,
            rewritten: Vec::new(),
        }
    }

    /// One frame of each pipeline (A, B, C, D) on the scene's current poses.
    pub fn frame(&mut self, scene: &Scene) -> [Frame; 4] {
        for i in scene.awake() {
            self.poses[i] = pose(&scene.poses[i]);
            self.poses8[i / 8].set(i % 8, scene.poses[i]);
        }
        let mut fa = Frame::default();
        let start = Instant::now();
        for i in scene.awake() {
            self.world[i] = self.local[i].transform_by(&self.poses[i]);
        }
        fa.ms[0] = ms(start);
        let start = Instant::now();
        self.rewritten.clear();
        for i in scene.awake() {
            let status = self
                .a
                .bvh
                .insert_or_update_partially(self.world[i], i as u32, MARGIN);
            if status != BvhLeafUpdateStatus::Unchanged {
                self.rewritten.push(i as u32);
            }
        }
        fa.rewritten = self.rewritten.len();
        fa.ms[1] = ms(start);
        self.a.finish(true, &self.rewritten, &mut fa);

        let mut fb = Frame::default();
        let start = Instant::now();
        self.batch
            .update(
                self.margin,
                Active::Mask(&self.mask8),
                &self.local8[..],
                &self.poses8[..],
                &mut self.fat[..],
                &mut self.moved,
            )
            .expect("lengths agree");
        fb.ms[0] = ms(start);
        let start = Instant::now();
        for &i in self.moved.indices() {
            let (block, lane) = (i as usize / 8, i as usize % 8);
            let fat = parry_box(&self.fat[block].get(lane));
            self.b
                .bvh
                .insert_or_update_partially(fat, i, f32::MIN_POSITIVE);
        }
        fb.rewritten = self.moved.len();
        fb.ms[1] = ms(start);
        self.frames += 1;
        let partial = self.tuning.partial;
        let whole = partial == 0 || self.frames.is_multiple_of(partial);
        self.b.finish(whole, self.moved.indices(), &mut fb);

        let mut fc = Frame::default();
        let c = &mut self.c;
        let start = Instant::now();
        self.batch
            .update(
                self.margin,
                Active::Mask(&self.mask8),
                &self.local8[..],
                &self.poses8[..],
                &mut c.fat[..],
                &mut c.moved,
            )
            .expect("lengths agree");
        fc.ms[0] = ms(start);
        let start = Instant::now();
        c.tree
            .write(c.moved.indices(), &c.fat[..])
            .expect("a sorted moved list");
        fc.ms[1] = ms(start);
        let start = Instant::now();
        c.tree.maintain();
        fc.ms[2] = ms(start);
        let start = Instant::now();
        c.tree.report(&mut c.pairs);
        fc.ms[4] = ms(start);
        fc.rewritten = c.moved.len();
        fc.pairs = c.pairs.begun.len();

        // D reads C's update (the same call would do the same work), so its box stage is
        // C's.
        let mut fd = Frame::default();
        fd.ms[0] = fc.ms[0];
        let fat = &c.fat;
        self.d.frame(
            c.moved.indices(),
            |i| fat[i as usize / 8].get(i as usize % 8),
            &mut fd,
        );
        [fa, fb, fc, fd]
    }

    /// Checks C's last report against a sweep over its fat boxes: the pairs that began are
    /// the pairs that overlap now and did not at the last check (which must be the last
    /// frame). Returns the pairs missing from the report and the pairs it has wrongly.
    pub fn check_c(&mut self, n: usize) -> (usize, usize) {
        let c = &mut self.c;
        let boxes: Vec<Aabb> = Aabb3x8::unpack(&c.fat, n).iter().map(parry_box).collect();
        let now = overlapping(&boxes);
        let Some(before) = c.checked.replace(now) else {
            return (0, 0);
        };
        let now = c.checked.as_ref().expect("just set");
        let begun: HashSet<(u32, u32)> = c.pairs.begun.iter().copied().collect();
        let expected: HashSet<(u32, u32)> = now.difference(&before).copied().collect();
        (
            expected.difference(&begun).count(),
            begun.difference(&expected).count(),
        )
    }
}

/// What a run measured: the mean frame of each pipeline (ms) and, over the frames checked,
/// the pairs C's reports missed and had wrongly.
pub struct Summary {
    pub frame: [f64; 4],
    pub missing: usize,
    pub wrong: usize,
    pub checked: usize,
}

/// Runs the scene through the three pipelines and prints every frame. `check` compares C's
/// reports with a sweep over its fat boxes every frame (outside the timings); up to 20K
/// bodies, every frame also checks that A's and B's trees keep every overlapping pair.
pub fn run(
    n: usize,
    frames: usize,
    asleep: f64,
    island: usize,
    tuning: Tuning,
    check: bool,
) -> Summary {
    let mut scene = Scene::new(n, asleep, island);
    let mut pipelines = Pipelines::new(&scene, tuning);
    // One frame before the measured ones: the first optimisation of a fresh tree costs
    // several frames' worth, once.
    scene.step();
    pipelines.frame(&scene);
    if check {
        pipelines.check_c(n);
    }
    let verify = n <= 20_000;
    let batch = pipelines.batch;
    println!(
        "{n} bodies, {} awake ({:.0}% asleep, in islands of {island}), margin {MARGIN}; \
         bvkit {:?} {:?} on {:?}; B's {tuning:?}; CPU {}",
        scene.awake,
        asleep * 100.0,
        batch.method,
        batch.rounding,
        batch.backend(),
        cpu()
    );
    // The columns of each pipeline: its stages in `Frame::ms` order, then the totals.
    let columns = |first: &str| {
        [
            first, "leaves", "optim", "refit", "pairs", "total", "rewrit", "new",
        ]
        .map(|c| format!("{c:>8}"))
        .join(" ")
    };
    println!(
        "{:>5} | {} | {} | {} | {} | {:>6} {:>6} {:>6}",
        "frame",
        columns("A boxes"),
        columns("B update"),
        columns("C update"),
        columns("D update"),
        "B/A",
        "C/A",
        "D/A"
    );
    let mut sum = [Frame::default(); 4];
    // Over the checked frames: overlapping world boxes, and leaf pairs of one tree only.
    let (mut overlaps, mut only_a, mut only_b) = (0, 0, 0);
    let (mut missing, mut wrong) = (0, 0);
    // C's slowest upkeep and slowest frame.
    let (mut slowest_upkeep, mut slowest_frame) = (0.0f64, 0.0f64);
    for frame in 0..frames {
        scene.step();
        let f = pipelines.frame(&scene);
        if check {
            let (m, w) = pipelines.check_c(n);
            missing += m;
            wrong += w;
        }
        if verify {
            let mut tight = vec![Aabb3::EMPTY; n];
            batch
                .transform(&scene.local, &scene.poses, &mut tight)
                .expect("lengths agree");
            let tight: Vec<Aabb> = tight.iter().map(parry_box).collect();
            let exact = overlapping(&tight);
            let (all_a, all_b) = (pipelines.a.all_pairs(), pipelines.b.all_pairs());
            assert!(exact.is_subset(&all_a), "A misses an overlapping pair");
            assert!(exact.is_subset(&all_b), "B misses an overlapping pair");
            overlaps += exact.len();
            only_a += all_a.difference(&all_b).count();
            only_b += all_b.difference(&all_a).count();
        }
        print_frame(&frame.to_string(), &f);
        slowest_upkeep = slowest_upkeep.max(f[2].ms[2]);
        slowest_frame = slowest_frame.max(f[2].total());
        for (total, f) in sum.iter_mut().zip(&f) {
            for k in 0..5 {
                total.ms[k] += f.ms[k];
            }
            total.rewritten += f.rewritten;
            total.pairs += f.pairs;
        }
    }
    let mean = sum.map(|s| {
        let f = frames.max(1) as f64;
        Frame {
            ms: s.ms.map(|x| x / f),
            rewritten: (s.rewritten as f64 / f).round() as usize,
            pairs: (s.pairs as f64 / f).round() as usize,
        }
    });
    print_frame("mean", &mean);
    // What the narrow phase inherits: every pair of overlapping leaves, new or not.
    println!(
        "overlapping leaf pairs after the last frame: A {}, B {}, C {}",
        pipelines.a.all_pairs().len(),
        pipelines.b.all_pairs().len(),
        pipelines.c.tree.overlapping_pairs().len()
    );
    if verify {
        let f = frames.max(1) as f64;
        println!(
            "checked every frame: each pair of overlapping world boxes ({:.0} per frame) is a \
             leaf pair of both trees; leaf pairs of A's tree only {:.0}, of B's only {:.0} per \
             frame",
            overlaps as f64 / f,
            only_a as f64 / f,
            only_b as f64 / f
        );
    }
    println!(
        "C's slowest frame {slowest_frame:.1} ms; its upkeep (maintain) {:.2} ms per frame on \
         average, {slowest_upkeep:.1} ms in the slowest",
        mean[2].ms[2]
    );
    if check {
        println!(
            "C's begun pairs against a sweep over its fat boxes, every frame: {missing} \
             missing, {wrong} wrong"
        );
    }
    Summary {
        frame: mean.map(|m| m.total()),
        missing,
        wrong,
        checked: if check { frames } else { 0 },
    }
}

fn print_frame(label: &str, f: &[Frame; 4]) {
    let cells = |x: &Frame| {
        let mut c: Vec<String> = x.ms.iter().map(|v| format!("{v:>8.3}")).collect();
        c.push(format!("{:>8.3}", x.total()));
        c.push(format!("{:>8}", x.rewritten));
        c.push(format!("{:>8}", x.pairs));
        c.join(" ")
    };
    println!(
        "{label:>5} | {} | {} | {} | {} | {:>5.2}× {:>5.2}× {:>5.2}×",
        cells(&f[0]),
        cells(&f[1]),
        cells(&f[2]),
        cells(&f[3]),
        f[1].total() / f[0].total(),
        f[2].total() / f[0].total(),
        f[3].total() / f[0].total()
    );
}
