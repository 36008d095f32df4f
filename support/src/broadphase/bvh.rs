//! Up to five broadphase pipelines on one scene, each on its own tree, frame by frame: C on
//! bvkit's `DynamicTree`, always, and those `Which` names: R, rapier3d 0.36.1's own
//! `BroadPhaseBvh` (`rapier.rs`: the peer itself), A and B on parry3d's `Bvh` (our models of
//! rapier's older pipeline, kept for what they show of bvkit's update feeding another
//! tree), and D on obvhs's `Bvh2` (the tree avian uses).
//!
//! - A, as rapier's pipeline ran it before its broadphase refitted only changed paths (a
//!   model, not the peer): every awake body's world box (`Aabb::transform_by`), each into
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
//!   (the pairs that began and ended, searched from the moved proxies: "pairs").
//! - D, obvhs: C's fat boxes and moved list (its box stage is C's) into `obvhs::ObvhsTree`
//!   (see `obvhs.rs` for the upkeep obvhs advises); its pairs are the begun ones.
//! - R, rapier's own: one `BroadPhaseBvh::update` a frame, every awake collider modified
//!   (its own boxes, leaves, upkeep and begun and ended pairs in one call: "frame").
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

use bvkit::broadphase::{BodyKind, DynamicTree, Layers, Pairs};
use bvkit::{Aabb3, Aabb3x8, Active, Batch, Margin, Method, Moved, Rigid3x8, Rounding};
use parry3d::bounding_volume::{Aabb, BoundingVolume};
use parry3d::math::Pose;
use parry3d::partitioning::{Bvh, BvhLeafUpdateStatus, BvhWorkspace};

pub use super::Frame;
use super::obvhs::ObvhsTree;
use super::rapier::Rapier;
use super::scene::Scene;
use super::{overlapping, parry_box};
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
    /// Static boxes C's tree holds beside the bodies (`Level`), none by default.
    pub level: Level,
    /// C's layers: 0 (the default) every proxy in every layer; `k` proxy `i` in layer
    /// `i % k` only, pairing with it only (so 1 puts every proxy in one layer, through the
    /// filter's checks).
    pub layers: u32,
    /// The backend of C's (and B's) update, where given; the widest this CPU runs
    /// otherwise (`Batch::new`).
    pub backend: Option<bvkit::Backend>,
}

/// A level of static boxes in C's tree, which the bodies move among.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Level {
    #[default]
    None,
    /// `n` boxes of the bodies' sizes at the bodies' density (1M per km³), in a cube
    /// centred on the scene (1 km wide for 1M): the bodies meet as many static boxes as
    /// bodies, and most static boxes are far from every body.
    Clutter(usize),
    /// `n` boxes as `Clutter`, in a cube 3 km away along x: the static proxies no body
    /// meets, what a level's far parts cost.
    Far(usize),
    /// A floor of `n` tiles (a square grid, 1 unit thick, with gaps of a tenth of a tile)
    /// under the scene, its top at the scene's bottom plus one unit: only the lowest
    /// bodies touch it.
    Floor(usize),
}

impl Level {
    /// The level's boxes, for a scene of `n` bodies.
    pub fn boxes(self, n: usize) -> Vec<Aabb3> {
        use glam::Vec3A;
        use rand::{RngExt, SeedableRng};
        let half = 500.0 * (n as f32 / 1e6).cbrt();
        let mut r = rand::rngs::StdRng::seed_from_u64(0x1e7e1);
        match self {
            Level::None => Vec::new(),
            Level::Clutter(m) | Level::Far(m) => {
                let side = 500.0 * (m as f32 / 1e6).cbrt();
                let away = Vec3A::X
                    * if matches!(self, Level::Far(_)) {
                        3000.0
                    } else {
                        0.0
                    };
                (0..m)
                    .map(|_| {
                        let e = Vec3A::new(
                            r.random_range(0.1..1.0),
                            r.random_range(0.1..1.0),
                            r.random_range(0.1..1.0),
                        );
                        let c = Vec3A::new(
                            r.random_range(-side..side),
                            r.random_range(-side..side),
                            r.random_range(-side..side),
                        );
                        Aabb3::new(away + c - e, away + c + e)
                    })
                    .collect()
            }
            Level::Floor(m) => {
                let k = (m as f64).sqrt().ceil() as usize;
                let pitch = 2.0 * half / k as f32;
                (0..m)
                    .map(|t| {
                        let (i, j) = ((t / k) as f32, (t % k) as f32);
                        let min = Vec3A::new(-half + i * pitch, -half, -half + j * pitch);
                        let size = Vec3A::new(0.9 * pitch, 1.0, 0.9 * pitch);
                        Aabb3::new(min, min + size)
                    })
                    .collect()
            }
        }
    }
}

/// Proxy `id`'s layers under `Tuning::layers`.
fn layers_of(id: u32, layers: u32) -> Layers {
    match layers {
        0 => Layers::ALL,
        k => Layers::new(1 << (id % k), 1 << (id % k)),
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
    /// The level's static boxes, proxies `8 * fat.len()` on.
    statics: Vec<Aabb3>,
    /// The frame last checked and the pairs of the tree's boxes then (the reference's).
    checked: Option<(usize, HashSet<(u32, u32)>)>,
}

fn ms(start: Instant) -> f64 {
    start.elapsed().as_secs_f64() * 1e3
}

/// Which pipelines run beside C (bvkit's own, which always runs).
#[derive(Clone, Copy, Debug)]
pub struct Which {
    /// A and B, the models on parry3d's `Bvh`.
    pub models: bool,
    /// D, obvhs's `Bvh2`.
    pub obvhs: bool,
    /// R, rapier's own `BroadPhaseBvh`.
    pub rapier: bool,
}

impl Which {
    /// Every pipeline.
    pub const ALL: Self = Self {
        models: true,
        obvhs: true,
        rapier: true,
    };
}

/// The pipelines' state over one scene.
pub struct Pipelines {
    /// A's state: the local boxes, poses and world boxes in parry's form, and the tree.
    a: Option<ModelA>,
    batch: Batch,
    margin: Margin,
    /// The bodies in AoSoA blocks (the update's fastest layout; an engine that keeps its
    /// poses packed simulates in place, so the packing is outside the timing), and the
    /// awake mask padded to whole blocks.
    local8: Vec<Aabb3x8>,
    poses8: Vec<Rigid3x8>,
    mask8: Vec<u64>,
    /// B: its fat boxes, moved set and tree.
    b: Option<ModelB>,
    /// C: bvkit's update (its own fat boxes and moved set) into bvkit's tree.
    c: Dynamic,
    /// D: the same update's fat boxes and moved list (C's) into obvhs's `Bvh2`.
    d: Option<ObvhsTree>,
    /// R: rapier's own broadphase.
    r: Option<Rapier>,
    tuning: Tuning,
    /// Frames run.
    frames: usize,
}

/// Pipeline A's state.
struct ModelA {
    local: Vec<Aabb>,
    /// A's poses, in parry's form (the engine's own, converted outside the timing).
    poses: Vec<Pose>,
    world: Vec<Aabb>,
    tree: Tree,
    /// The leaves rewritten in this frame.
    rewritten: Vec<u32>,
}

/// Pipeline B's state.
struct ModelB {
    fat: Vec<Aabb3x8>,
    moved: Moved,
    tree: Tree,
}

fn pose(p: &bvkit::Rigid3) -> Pose {
    Pose::from_parts(p.translation.into(), p.rotation)
}

impl Pipelines {
    /// The trees over the scene's first frame: every body's box.
    pub fn new(scene: &Scene, tuning: Tuning, which: Which) -> Self {
        let n = scene.local.len();
        let a = which.models.then(|| {
            let local: Vec<Aabb> = scene.local.iter().map(parry_box).collect();
            let poses: Vec<Pose> = scene.poses.iter().map(pose).collect();
            let world: Vec<Aabb> = local
                .iter()
                .zip(&poses)
                .map(|(b, p)| b.transform_by(p))
                .collect();
            let tree = Tree::new(world.iter().copied(), MARGIN);
            ModelA {
                local,
                poses,
                world,
                tree,
                rewritten: Vec::new(),
            }
        });
        let batch = Batch::new(Method::AbsMatrix, Rounding::Outward);
        let batch = match tuning.backend {
            Some(backend) => batch.on(backend).expect("a backend this CPU runs"),
            None => batch,
        };
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
        let b = which.models.then(|| ModelB {
            fat: fat.clone(),
            moved: Moved::new(),
            tree: Tree::new(
                Aabb3x8::unpack(&fat, n).iter().map(parry_box),
                f32::MIN_POSITIVE,
            ),
        });
        let mut mask8 = scene.mask.clone();
        mask8.resize((8 * local8.len()).div_ceil(64), 0);
        // The level's static proxies after the bodies' blocks, both hierarchies built.
        let statics = tuning.level.boxes(n);
        let first_static = 8 * fat.len();
        let mut all = Aabb3x8::unpack(&fat, first_static);
        all.extend_from_slice(&statics);
        let mut tree = DynamicTree::from_boxes_with(&all[..], |id| {
            let kind = match id as usize >= first_static {
                true => BodyKind::Static,
                false => BodyKind::Dynamic,
            };
            (kind, layers_of(id, tuning.layers))
        })
        .expect("finite fat boxes");
        if let Some(after) = tuning.rebuild_after {
            tree.set_rebuild_after(after);
        }
        if let Some(frames) = tuning.rebuild_frames {
            tree.set_rebuild_frames(frames);
        }
        let mut pairs = Pairs::with_ended();
        // The first report: every overlapping pair begins.
        tree.report(&mut pairs);
        let d = which
            .obvhs
            .then(|| ObvhsTree::new(&Aabb3x8::unpack(&fat, n)));
        let c = Dynamic {
            fat,
            moved,
            tree,
            pairs,
            statics,
            checked: None,
        };
        let r = which.rapier.then(|| Rapier::new(scene));
        Self {
            a,
            batch,
            margin,
            local8,
            poses8,
            mask8,
            b,
            c,
            d,
            r,
            tuning,
            frames: 0,
        }
    }

    /// One frame of each pipeline (A, B, C, D, R; those not run are zero) on the scene's
    /// current poses.
    pub fn frame(&mut self, scene: &Scene) -> [Frame; 5] {
        for i in scene.awake() {
            self.poses8[i / 8].set(i % 8, scene.poses[i]);
        }
        let mut fa = Frame::default();
        if let Some(a) = &mut self.a {
            for i in scene.awake() {
                a.poses[i] = pose(&scene.poses[i]);
            }
            let start = Instant::now();
            for i in scene.awake() {
                a.world[i] = a.local[i].transform_by(&a.poses[i]);
            }
            fa.ms[0] = ms(start);
            let start = Instant::now();
            a.rewritten.clear();
            for i in scene.awake() {
                let status = a
                    .tree
                    .bvh
                    .insert_or_update_partially(a.world[i], i as u32, MARGIN);
                if status != BvhLeafUpdateStatus::Unchanged {
                    a.rewritten.push(i as u32);
                }
            }
            fa.rewritten = a.rewritten.len();
            fa.ms[1] = ms(start);
            a.tree.finish(true, &a.rewritten, &mut fa);
        }

        self.frames += 1;
        let mut fb = Frame::default();
        if let Some(b) = &mut self.b {
            let start = Instant::now();
            self.batch
                .update(
                    self.margin,
                    Active::Mask(&self.mask8),
                    &self.local8[..],
                    &self.poses8[..],
                    &mut b.fat[..],
                    &mut b.moved,
                )
                .expect("lengths agree");
            fb.ms[0] = ms(start);
            let start = Instant::now();
            for &i in b.moved.indices() {
                let (block, lane) = (i as usize / 8, i as usize % 8);
                let fat = parry_box(&b.fat[block].get(lane));
                b.tree
                    .bvh
                    .insert_or_update_partially(fat, i, f32::MIN_POSITIVE);
            }
            fb.rewritten = b.moved.len();
            fb.ms[1] = ms(start);
            let partial = self.tuning.partial;
            let whole = partial == 0 || self.frames.is_multiple_of(partial);
            b.tree.finish(whole, b.moved.indices(), &mut fb);
        }

        let mut fc = Frame::default();
        let c = &mut self.c;
        let start = Instant::now();
        #[cfg(feature = "parallel")]
        let update = Batch::update_par;
        #[cfg(not(feature = "parallel"))]
        let update = Batch::update;
        update(
            &self.batch,
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
        #[cfg(feature = "parallel")]
        c.tree.report_par(&mut c.pairs);
        #[cfg(not(feature = "parallel"))]
        c.tree.report(&mut c.pairs);
        fc.ms[4] = ms(start);
        fc.rewritten = c.moved.len();
        fc.pairs = c.pairs.begun.len();
        fc.ended = c.pairs.ended.len();

        // D reads C's update (the same call would do the same work), so its box stage is
        // C's.
        let mut fd = Frame::default();
        if let Some(d) = &mut self.d {
            fd.ms[0] = fc.ms[0];
            let fat = &c.fat;
            d.frame(
                c.moved.indices(),
                |i| fat[i as usize / 8].get(i as usize % 8),
                &mut fd,
            );
        }

        // R: rapier's update does every stage in one call (its own boxes included).
        let mut fr = Frame::default();
        if let Some(r) = &mut self.r {
            let f = r.frame(scene);
            fr.ms[4] = f.ms;
            fr.pairs = f.begun;
            fr.ended = f.ended;
        }
        [fa, fb, fc, fd, fr]
    }

    /// C's tree, B's parry3d tree and D's obvhs tree (the pipelines must have run B and
    /// D), and C's fat boxes by proxy (`n` bodies).
    ///
    /// # Panics
    /// When B or D did not run.
    pub fn trees(&self, n: usize) -> (&DynamicTree, &Bvh, &::obvhs::bvh2::Bvh2, Vec<Aabb3>) {
        let b = self.b.as_ref().expect("B ran");
        let d = self.d.as_ref().expect("D ran");
        (
            &self.c.tree,
            &b.tree.bvh,
            d.bvh(),
            Aabb3x8::unpack(&self.c.fat, n),
        )
    }

    /// Checks C's last report against a sweep over its fat boxes, when the last check was
    /// the frame before: the pairs that began are the pairs that overlap now and did not
    /// then, and the pairs that ended the other way round. Returns the pairs missing from
    /// the report and the pairs it has wrongly (both zero when there is nothing to compare
    /// with), and keeps this frame's pairs for the next check.
    pub fn check_c(&mut self, n: usize) -> (usize, usize) {
        let c = &mut self.c;
        let layers = self.tuning.layers;
        let now = if c.statics.is_empty() && layers == 0 {
            let boxes: Vec<Aabb> = Aabb3x8::unpack(&c.fat, n).iter().map(parry_box).collect();
            overlapping(&boxes)
        } else {
            let bodies = Aabb3x8::unpack(&c.fat, 8 * c.fat.len());
            let admit = |a: u32, b: u32| layers_of(a, layers).interacts_with(layers_of(b, layers));
            pairs_with_level(&bodies, &c.statics)
                .into_iter()
                .filter(|&(a, b)| admit(a, b))
                .collect()
        };
        let now = (self.frames, now);
        let Some((then, before)) = c.checked.replace(now) else {
            return (0, 0);
        };
        if then + 1 != self.frames {
            return (0, 0);
        }
        let now = &c.checked.as_ref().expect("just set").1;
        let set = |pairs: &[(u32, u32)]| -> HashSet<(u32, u32)> { pairs.iter().copied().collect() };
        let (begun, ended) = (set(&c.pairs.begun), set(&c.pairs.ended));
        let expected_begun: HashSet<(u32, u32)> = now.difference(&before).copied().collect();
        let expected_ended: HashSet<(u32, u32)> = before.difference(now).copied().collect();
        (
            expected_begun.difference(&begun).count() + expected_ended.difference(&ended).count(),
            begun.difference(&expected_begun).count() + ended.difference(&expected_ended).count(),
        )
    }
}

/// Every pair of overlapping boxes (closed) among `bodies` (proxies `0..`) and between them
/// and `statics` (proxies `bodies.len()..`), never two static ones: by a grid of cells of 2
/// units, each box listed in every cell it meets.
fn pairs_with_level(bodies: &[Aabb3], statics: &[Aabb3]) -> HashSet<(u32, u32)> {
    use std::collections::HashMap;
    const CELL: f32 = 2.0;
    let cells = |b: &Aabb3| {
        let (lo, hi) = ((b.min / CELL).floor(), (b.max / CELL).floor());
        let (lo, hi) = (lo.as_ivec3(), hi.as_ivec3());
        (lo.x..=hi.x).flat_map(move |x| {
            (lo.y..=hi.y).flat_map(move |y| (lo.z..=hi.z).map(move |z| (x, y, z)))
        })
    };
    let all = |id: usize| match id.checked_sub(bodies.len()) {
        None => &bodies[id],
        Some(s) => &statics[s],
    };
    let mut grid: HashMap<(i32, i32, i32), Vec<u32>> = HashMap::new();
    for id in 0..bodies.len() + statics.len() {
        let b = all(id);
        if b.min.x <= b.max.x {
            for cell in cells(b) {
                grid.entry(cell).or_default().push(id as u32);
            }
        }
    }
    let overlap = |a: &Aabb3, b: &Aabb3| a.min.cmple(b.max).all() && b.min.cmple(a.max).all();
    let mut pairs = HashSet::new();
    for (id, b) in bodies.iter().enumerate() {
        if b.min.x > b.max.x {
            continue;
        }
        for cell in cells(b) {
            for &other in &grid[&cell] {
                if other as usize != id && overlap(b, all(other as usize)) {
                    let id = id as u32;
                    pairs.insert((id.min(other), id.max(other)));
                }
            }
        }
    }
    pairs
}

/// What a run measured: the mean frame of each pipeline (ms; A, B, C, D, R, zero for those
/// not run), C's mean moved proxies a frame, and, over the frames checked, the pairs C's
/// reports missed and had wrongly and the overlapping pairs R did not hold.
pub struct Summary {
    pub frame: [f64; 5],
    pub moved: f64,
    pub missing: usize,
    pub wrong: usize,
    pub rapier_missing: usize,
    pub checked: usize,
}

/// How often a run checks C's reports (each check is a sweep over every fat box, outside
/// the timings): never, every frame, or every `k`-th frame (with the frame before it, whose
/// pairs the check compares with).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Check {
    Never,
    Every,
    Sampled(usize),
}

impl Check {
    /// True when frame `f` (counted from 0) is checked, or is the one before a checked one.
    fn runs(self, f: usize) -> bool {
        match self {
            Check::Never => false,
            Check::Every => true,
            Check::Sampled(k) => (f + 1).is_multiple_of(k) || f.is_multiple_of(k),
        }
    }
}

/// How C's report and R's update run (the `parallel` feature of this crate).
#[cfg(feature = "parallel")]
const THREADS: &str = "C's update and report, and R, on the rayon pool";
#[cfg(not(feature = "parallel"))]
const THREADS: &str = "single-threaded";

/// The labels of the pipelines, in `Pipelines::frame`'s order.
const NAMES: [&str; 5] = ["A", "B", "C", "D", "R"];

/// Runs the scene through the pipelines of `which` (and C) and prints every frame. `check`
/// compares C's begun and ended pairs with a sweep over its fat boxes, and checks that R
/// holds every pair of overlapping world boxes, on the frames it names; up to 20K bodies,
/// every frame also checks that A's and B's trees keep every overlapping pair.
pub fn run(scene: Scene, frames: usize, tuning: Tuning, which: Which, check: Check) -> Summary {
    let mut scene = scene;
    let n = scene.local.len();
    let mut pipelines = Pipelines::new(&scene, tuning, which);
    // One frame before the measured ones: the first optimisation of a fresh tree costs
    // several frames' worth, once.
    scene.step();
    pipelines.frame(&scene);
    let verify = n <= 20_000 && which.models;
    let batch = pipelines.batch;
    let run = [which.models, which.models, true, which.obvhs, which.rapier];
    println!(
        "{n} bodies, {} awake, margin {MARGIN}; bvkit {:?} {:?} on {:?}; B's {tuning:?}; \
         pipelines {}; {THREADS}; CPU {}",
        scene.awake,
        batch.method,
        batch.rounding,
        batch.backend(),
        NAMES
            .iter()
            .zip(run)
            .filter(|(_, r)| *r)
            .map(|(n, _)| *n)
            .collect::<Vec<_>>()
            .join(" "),
        cpu()
    );
    let mut header = format!("{:>5}", "frame");
    for (k, name) in NAMES.iter().enumerate() {
        if run[k] {
            header += &format!(" | {}", columns(k, name));
        }
    }
    let baseline = if which.rapier { 4 } else { 0 };
    if run[baseline] {
        header += &format!(" | C/{}", NAMES[baseline]);
    }
    println!("{header}");
    let mut sum = [Frame::default(); 5];
    // Over the checked frames: overlapping world boxes, and leaf pairs of one tree only.
    let (mut overlaps, mut only_a, mut only_b) = (0, 0, 0);
    let (mut missing, mut wrong, mut rapier_missing, mut checked) = (0, 0, 0, 0);
    // C's slowest upkeep and slowest frame.
    let (mut slowest_upkeep, mut slowest_frame) = (0.0f64, 0.0f64);
    for frame in 0..frames {
        scene.step();
        let f = pipelines.frame(&scene);
        if check.runs(frame) {
            let (m, w) = pipelines.check_c(n);
            missing += m;
            wrong += w;
            let mut tight = vec![Aabb3::EMPTY; n];
            batch
                .transform(&scene.local, &scene.poses, &mut tight)
                .expect("lengths agree");
            if let Some(r) = &pipelines.r {
                rapier_missing += r.missing(&tight);
            }
            checked += 1;
            if verify {
                let tight: Vec<Aabb> = tight.iter().map(parry_box).collect();
                let exact = overlapping(&tight);
                let (a, b) = (pipelines.a.as_mut(), pipelines.b.as_mut());
                let (all_a, all_b) = (
                    a.expect("models").tree.all_pairs(),
                    b.expect("models").tree.all_pairs(),
                );
                assert!(exact.is_subset(&all_a), "A misses an overlapping pair");
                assert!(exact.is_subset(&all_b), "B misses an overlapping pair");
                overlaps += exact.len();
                only_a += all_a.difference(&all_b).count();
                only_b += all_b.difference(&all_a).count();
            }
        }
        print_frame(&frame.to_string(), &f, run, baseline);
        slowest_upkeep = slowest_upkeep.max(f[2].ms[2]);
        slowest_frame = slowest_frame.max(f[2].total());
        for (total, f) in sum.iter_mut().zip(&f) {
            for k in 0..5 {
                total.ms[k] += f.ms[k];
            }
            total.rewritten += f.rewritten;
            total.pairs += f.pairs;
            total.ended += f.ended;
        }
    }
    let mean = sum.map(|s| {
        let f = frames.max(1) as f64;
        Frame {
            ms: s.ms.map(|x| x / f),
            rewritten: (s.rewritten as f64 / f).round() as usize,
            pairs: (s.pairs as f64 / f).round() as usize,
            ended: (s.ended as f64 / f).round() as usize,
        }
    });
    print_frame("mean", &mean, run, baseline);
    // What the narrow phase inherits: every pair of overlapping leaves, new or not.
    print!("overlapping leaf pairs after the last frame: C {}", {
        pipelines.c.tree.overlapping_pairs().len()
    });
    if let (Some(a), Some(b)) = (pipelines.a.as_mut(), pipelines.b.as_mut()) {
        print!(
            ", A {}, B {}",
            a.tree.all_pairs().len(),
            b.tree.all_pairs().len()
        );
    }
    if let Some(r) = &pipelines.r {
        print!(", R {}", r.pairs().len());
    }
    println!();
    if verify {
        println!(
            "checked {checked} frames: each pair of overlapping world boxes ({:.0} per frame) \
             is a leaf pair of both trees; leaf pairs of A's tree only {:.0}, of B's only {:.0} \
             per frame",
            overlaps as f64 / checked.max(1) as f64,
            only_a as f64 / checked.max(1) as f64,
            only_b as f64 / checked.max(1) as f64
        );
    }
    println!(
        "C's slowest frame {slowest_frame:.1} ms; its upkeep (maintain) {:.2} ms per frame on \
         average, {slowest_upkeep:.1} ms in the slowest",
        mean[2].ms[2]
    );
    if check != Check::Never {
        println!(
            "checked on {checked} of {frames} frames ({check:?}): C's begun and ended pairs \
             against a sweep over its fat boxes: {missing} missing, {wrong} wrong; pairs of \
             overlapping world boxes that R does not hold: {rapier_missing}"
        );
    }
    Summary {
        frame: mean.map(|m| m.total()),
        moved: mean[2].rewritten as f64,
        missing,
        wrong,
        rapier_missing,
        checked,
    }
}

/// The column heads of pipeline `k`: its stages in `Frame::ms` order and its totals (the
/// pairs that began, or for A, B and D the pairs their traversal found from the changed
/// leaves, and for C and R those that ended); R's update is one call, its frame only.
fn columns(k: usize, name: &str) -> String {
    let heads: &[&str] = match k {
        4 => &["frame", "begun", "ended"],
        2 => &[
            "boxes", "leaves", "optim", "refit", "pairs", "total", "rewrit", "begun", "ended",
        ],
        _ => &[
            "boxes", "leaves", "optim", "refit", "pairs", "total", "rewrit", "new",
        ],
    };
    let mut c: Vec<String> = heads.iter().map(|h| format!("{h:>8}")).collect();
    c[0] = format!("{:>8}", format!("{name} {}", heads[0]));
    c.join(" ")
}

fn print_frame(label: &str, f: &[Frame; 5], run: [bool; 5], baseline: usize) {
    let cells = |k: usize, x: &Frame| {
        let mut c: Vec<String> = Vec::new();
        if k != 4 {
            c.extend(x.ms.iter().map(|v| format!("{v:>8.3}")));
        }
        c.push(format!("{:>8.3}", x.total()));
        if k != 4 {
            c.push(format!("{:>8}", x.rewritten));
        }
        c.push(format!("{:>8}", x.pairs));
        if k == 2 || k == 4 {
            c.push(format!("{:>8}", x.ended));
        }
        c.join(" ")
    };
    let mut line = format!("{label:>5}");
    for k in 0..5 {
        if run[k] {
            line += &format!(" | {}", cells(k, &f[k]));
        }
    }
    if run[baseline] {
        line += &format!(" | {:>5.2}×", f[2].total() / f[baseline].total());
    }
    println!("{line}");
}
