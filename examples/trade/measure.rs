//! The measurements: every kernel's speed (medians of repeated runs) and its accuracy
//! against the exact oracle, with the peers a user would otherwise write and the memory
//! rooflines.

use std::cell::Cell;
use std::hint::black_box;
use std::time::Instant;

use bvkit::{
    Aabb2, Aabb3, Aabb3x8, AabbSoa, Affine3Soa, Affine3x8, Backend, Batch, Block8, Method, Rigid2,
    Rigid3, Rounding, Transform2, Transform3, Translation2, Translation3,
};
use glam::{Affine2, Affine3A, Vec2, Vec3A};

use crate::cases::{self, Scale, problem, quat_problem, rigid_problem, rng, translation_problem};
use crate::common;
use crate::oracle::{Bound, Exactly, Problem, affine2, affine3, check, rigid2};

/// The seed of every random sample: the accuracy columns are identical run to run.
pub const SEED: u64 = 0xb0c5_2026;
pub use bvkit_support::timing::quick;
/// Boxes of the in-cache batch (inputs and outputs fit in L2).
pub fn cache() -> usize {
    if quick() { 256 } else { 4096 }
}
/// Timed runs of the in-cache batch; the median is reported.
pub fn cache_runs() -> usize {
    if quick() { 3 } else { 301 }
}
/// Boxes of the DRAM batch.
pub fn dram() -> usize {
    if quick() { 1 << 12 } else { 1 << 22 }
}
/// Timed runs of the DRAM batch; the median is reported.
pub fn dram_runs() -> usize {
    if quick() { 1 } else { 3 }
}
/// Oracle cases per extreme class.
pub fn cases() -> u64 {
    if quick() { 20 } else { 1500 }
}
/// The finite extreme classes the accuracy columns are measured over.
pub const ACCURACY_CLASSES: [cases::Class; 9] = [
    cases::Class::Typical,
    cases::Class::Far,
    cases::Class::Subnormal,
    cases::Class::ZeroSize,
    cases::Class::Reflection,
    cases::Class::Shear,
    cases::Class::NearSingular,
    cases::Class::Drifted,
    cases::Class::QuarterTurn,
];
/// The bound the peers are checked against: loose enough never to fail (they promise
/// nothing); the oracle only measures them.
const PEER_BOUND: Bound = Bound::Nearest {
    gamma_n: 1 << 20,
    tiny: 1e30,
};

/// The transform classes, in the order of the report and of the plot's panels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TransformClass {
    Translation3,
    Rigid3,
    Similarity3,
    Trs3,
    Affine3,
    Translation2,
    Rigid2,
    Affine2,
}

impl TransformClass {
    pub const ALL: [TransformClass; 8] = [
        TransformClass::Translation3,
        TransformClass::Rigid3,
        TransformClass::Similarity3,
        TransformClass::Trs3,
        TransformClass::Affine3,
        TransformClass::Translation2,
        TransformClass::Rigid2,
        TransformClass::Affine2,
    ];

    /// The class as the CSV and the tables name it.
    pub const fn name(self) -> &'static str {
        match self {
            TransformClass::Translation3 => "3D translation",
            TransformClass::Rigid3 => "3D rigid",
            TransformClass::Similarity3 => "3D similarity",
            TransformClass::Trs3 => "3D scale-rotation-translation",
            TransformClass::Affine3 => "3D affine",
            TransformClass::Translation2 => "2D translation",
            TransformClass::Rigid2 => "2D rigid",
            TransformClass::Affine2 => "2D affine",
        }
    }

    /// The scene profile the class serves.
    pub const fn profile(self) -> &'static str {
        match self {
            TransformClass::Translation3 => "Particles, spheres: 3D translation only",
            TransformClass::Rigid3 => "Rigid bodies: 3D quaternion + position",
            TransformClass::Similarity3 => "Uniformly scaled props (3D)",
            TransformClass::Trs3 => "Scaled props: bevy `Transform` (3D TRS)",
            TransformClass::Affine3 => "Sheared or skinned (3D affine)",
            TransformClass::Translation2 => "2D sprites, moved only",
            TransformClass::Rigid2 => "2D sprites: rotation + translation",
            TransformClass::Affine2 => "2D sprites with scale or shear",
        }
    }

    /// The box type.
    pub const fn box_type(self) -> &'static str {
        if self.is_2d() { "Aabb2" } else { "Aabb3" }
    }

    /// The pose type of one box.
    pub const fn pose_type(self) -> &'static str {
        match self {
            TransformClass::Translation3 => "Translation3",
            TransformClass::Rigid3 => "Rigid3",
            TransformClass::Similarity3 => "Similarity3",
            TransformClass::Trs3 => "Trs3",
            TransformClass::Affine3 => "Affine3A",
            TransformClass::Translation2 => "Translation2",
            TransformClass::Rigid2 => "Rigid2",
            TransformClass::Affine2 => "Affine2",
        }
    }

    /// The AoSoA block types of the boxes and the poses.
    pub const fn block_types(self) -> (&'static str, &'static str) {
        match self {
            TransformClass::Translation3 => ("Aabb3x8", "Translation3x8"),
            TransformClass::Rigid3 => ("Aabb3x8", "Rigid3x8"),
            TransformClass::Similarity3 => ("Aabb3x8", "Similarity3x8"),
            TransformClass::Trs3 => ("Aabb3x8", "Trs3x8"),
            TransformClass::Affine3 => ("Aabb3x8", "Affine3x8"),
            TransformClass::Translation2 => ("Aabb2x8", "Translation2x8"),
            TransformClass::Rigid2 => ("Aabb2x8", "Rigid2x8"),
            TransformClass::Affine2 => ("Aabb2x8", "Affine2x8"),
        }
    }

    /// True for the 2D classes.
    pub const fn is_2d(self) -> bool {
        matches!(
            self,
            TransformClass::Translation2 | TransformClass::Rigid2 | TransformClass::Affine2
        )
    }
}

/// What a row measured: a bvkit kernel, a peer, or a memory roofline.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    Kernel(Method, Rounding),
    Peer(Peer),
    Roofline,
}

/// The loops a user would otherwise write.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Peer {
    /// parry3d's `Aabb::transform_by` over rigid poses. In the 3D affine class it runs on
    /// the rigid poses of that class's scene: a speed reference, no affine peer.
    Parry,
    /// glam: transform the 8 corners.
    GlamCorners,
    /// glam: center and half-extents through `|M|`.
    GlamAbsMatrix,
    /// glam on rigid poses: `Mat3A::from_quat`, then abs-matrix.
    GlamRigid,
}

impl Peer {
    /// The peer's name in `class`, as the CSV has it.
    pub const fn name(self, class: TransformClass) -> &'static str {
        match (self, class) {
            (Peer::Parry, TransformClass::Rigid3) => "parry3d Aabb::transform_by",
            (Peer::Parry, _) => "parry3d Aabb::transform_by (rigid)",
            (Peer::GlamCorners, _) => "glam 8-corner loop",
            (Peer::GlamAbsMatrix, _) => "glam abs-matrix loop",
            (Peer::GlamRigid, _) => "glam loop: Mat3A::from_quat + abs-matrix",
        }
    }
}

/// How the boxes and poses are laid out.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Layout {
    /// One box at a time (`Aabb3::transformed`).
    Single,
    /// Slices of boxes and poses.
    Aos,
    /// Columns (`AabbSoa`, `Affine3Soa`).
    Soa,
    /// Blocks of 8 (`Aabb3x8`, `Rigid3x8`, …).
    Aosoa,
}

impl Layout {
    pub const ALL: [Layout; 4] = [Layout::Single, Layout::Aos, Layout::Soa, Layout::Aosoa];

    /// The lower-case name of the CSV.
    pub const fn key(self) -> &'static str {
        match self {
            Layout::Single => "single",
            Layout::Aos => "aos",
            Layout::Soa => "soa",
            Layout::Aosoa => "aosoa",
        }
    }

    /// The name of tables and labels.
    pub const fn name(self) -> &'static str {
        match self {
            Layout::Single => "single",
            Layout::Aos => "AoS",
            Layout::Soa => "SoA",
            Layout::Aosoa => "AoSoA",
        }
    }
}

/// The backend of the single-box path on glam's SIMD types.
pub const GLAM_SIMD: &str = "glam simd";
/// The backend name of the single-box and batch paths in plain `f32`.
pub const SCALAR: &str = "scalar";

/// One measured kernel, peer or roofline.
#[derive(Clone, Debug)]
pub struct Row {
    pub class: TransformClass,
    pub kind: Kind,
    pub layout: Layout,
    /// A [`Backend::name`], [`GLAM_SIMD`], or "peer" / "roofline".
    pub backend: &'static str,
    pub ns_cache: f64,
    pub ns_dram: f64,
    /// None where the oracle cannot judge the row (rooflines, and parry3d on rigid poses:
    /// it rotates by `q v q*`, which is the oracle's `R(q)` only for unit quaternions).
    pub accuracy: Option<Accuracy>,
}

impl Row {
    /// The kernel's method and rounding, when the row is a bvkit kernel.
    pub fn kernel(&self) -> Option<(Method, Rounding)> {
        match self.kind {
            Kind::Kernel(m, r) => Some((m, r)),
            _ => None,
        }
    }

    /// The kernel's, peer's or roofline's name, as the CSV has it.
    pub fn name(&self) -> String {
        match self.kind {
            Kind::Kernel(m, r) => format!("{} {}", m.name(), r.name()),
            Kind::Peer(peer) => peer.name(self.class).into(),
            Kind::Roofline => "memory roofline".into(),
        }
    }
}

/// What the oracle measured of one kernel over the sample.
#[derive(Clone, Copy, Debug)]
pub struct Accuracy {
    /// The largest face error, in units of `u·S`.
    pub worst_error_us: f64,
    /// The fraction of results that contain the exact box.
    pub contains: f64,
    /// The mean `volume(result) / volume(exact) − 1` over the Typical class.
    pub overhead: f64,
}

/// Progress on stderr: one numbered line per stage with the time since the start, the
/// kernels of the stage appended as they are measured.
pub struct Progress {
    total: usize,
    done: Cell<usize>,
    items: Cell<usize>,
    started: Instant,
}

impl Progress {
    pub fn new(total: usize) -> Self {
        Self {
            total,
            done: Cell::new(0),
            items: Cell::new(0),
            started: Instant::now(),
        }
    }

    /// Starts the next stage.
    pub fn stage(&self, what: &str) {
        let k = self.done.get() + 1;
        self.done.set(k);
        self.items.set(0);
        let newline = if k > 1 { "\n" } else { "" };
        eprint!(
            "{newline}[{k}/{}] {:5.1} s  {what}",
            self.total,
            self.started.elapsed().as_secs_f64()
        );
    }

    /// Reports one measured item of the current stage.
    fn item(&self, what: &str) {
        let sep = if self.items.get() == 0 { ": " } else { ", " };
        self.items.set(self.items.get() + 1);
        eprint!("{sep}{what}");
    }

    /// Ends the last stage; returns the seconds since the start.
    pub fn finish(&self) -> f64 {
        debug_assert_eq!(self.done.get(), self.total, "the stage count is stale");
        let seconds = self.started.elapsed().as_secs_f64();
        eprintln!("\ndone in {seconds:.0} s");
        seconds
    }
}

/// Collects the rows of one transform class and reports each on the progress line.
struct Meter<'a> {
    class: TransformClass,
    rows: Vec<Row>,
    progress: &'a Progress,
}

impl<'a> Meter<'a> {
    fn new(class: TransformClass, progress: &'a Progress) -> Self {
        Self {
            class,
            rows: Vec::new(),
            progress,
        }
    }

    fn push(
        &mut self,
        kind: Kind,
        layout: Layout,
        backend: &'static str,
        (ns_cache, ns_dram): (f64, f64),
        accuracy: Option<Accuracy>,
    ) {
        // The 2D classes share their stages: their items name the class.
        let item = match kind {
            Kind::Kernel(..) if self.class.is_2d() => {
                format!("{} {} {backend}", self.class.name(), layout.name())
            }
            Kind::Kernel(..) => format!("{} {backend}", layout.name()),
            Kind::Peer(peer) => peer.name(self.class).into(),
            Kind::Roofline => format!("roofline {}", layout.name()),
        };
        self.progress.item(&item);
        self.rows.push(Row {
            class: self.class,
            kind,
            layout,
            backend,
            ns_cache,
            ns_dram,
            accuracy,
        });
    }

    fn kernel(
        &mut self,
        (method, rounding): (Method, Rounding),
        layout: Layout,
        backend: &'static str,
        times: (f64, f64),
        accuracy: Accuracy,
    ) {
        let kind = Kind::Kernel(method, rounding);
        self.push(kind, layout, backend, times, Some(accuracy));
    }

    fn peer(&mut self, peer: Peer, times: (f64, f64), accuracy: Option<Accuracy>) {
        self.push(Kind::Peer(peer), Layout::Aos, "peer", times, accuracy);
    }

    fn roofline(&mut self, layout: Layout, times: (f64, f64)) {
        self.push(Kind::Roofline, layout, "roofline", times, None);
    }
}

/// Every method × rounding, in the order of the tables.
fn kernels() -> impl Iterator<Item = (Method, Rounding)> {
    Method::ALL
        .into_iter()
        .flat_map(|m| Rounding::ALL.map(|r| (m, r)))
}

/// The stage name of one kernel of a class.
fn kernel_stage(class: &str, (method, rounding): (Method, Rounding)) -> String {
    format!("{class}, {} {}", method.name(), rounding.name())
}

/// The median ns per box of `runs` timed runs of `run` over `n` boxes, after one warm-up.
fn ns_per_box(n: usize, runs: usize, mut run: impl FnMut()) -> f64 {
    run();
    let mut samples: Vec<f64> = (0..runs)
        .map(|_| {
            let start = Instant::now();
            run();
            start.elapsed().as_secs_f64() * 1e9 / n as f64
        })
        .collect();
    samples.sort_by(f64::total_cmp);
    samples[runs / 2]
}

/// Times `run(n)` at the in-cache and the dram() size.
fn times(mut run: impl FnMut(usize)) -> (f64, f64) {
    (
        ns_per_box(cache(), cache_runs(), || run(cache())),
        ns_per_box(dram(), dram_runs(), || run(dram())),
    )
}

/// The seeded oracle sample: [`cases`] problems of each of the [`ACCURACY_CLASSES`].
fn sample<P>(
    salt: u64,
    make: impl Fn(cases::Class, &mut rand::rngs::StdRng) -> P,
) -> Vec<(cases::Class, P)> {
    let mut out = Vec::new();
    for class in ACCURACY_CLASSES {
        let r = &mut rng(SEED ^ (class as u64) << 40 ^ salt);
        out.extend((0..cases()).map(|_| (class, make(class, r))));
    }
    out
}

/// Checks `results` against the oracle (panics on a broken contract: the report must not
/// print figures of a kernel that is wrong) and summarises.
fn accuracy<const N: usize, P: Exactly<N>>(
    sample: &[(cases::Class, P)],
    results: &[([f32; N], [f32; N])],
    bound: Bound,
) -> Accuracy {
    let (mut worst, mut contained, mut overhead_sum, mut overhead_count) =
        (0.0f64, 0usize, 0.0, 0usize);
    for ((class, p), (min, max)) in sample.iter().zip(results) {
        let m =
            check(p, *min, *max, bound).unwrap_or_else(|e| panic!("contract broken: {e}\n{p:?}"));
        worst = worst.max(m.worst_error_us);
        contained += usize::from(m.contains);
        if let (cases::Class::Typical, Some(o)) = (class, m.overhead) {
            overhead_sum += o;
            overhead_count += 1;
        }
    }
    Accuracy {
        worst_error_us: worst,
        contains: contained as f64 / sample.len() as f64,
        overhead: overhead_sum / overhead_count as f64,
    }
}

fn flat3(b: &Aabb3) -> ([f32; 3], [f32; 3]) {
    (b.min.to_array(), b.max.to_array())
}

fn flat2(b: &Aabb2) -> ([f32; 2], [f32; 2]) {
    (b.min.to_array(), b.max.to_array())
}

/// The faces of a box as the oracle reads them.
trait Faces<const N: usize>: Copy {
    fn faces(&self) -> ([f32; N], [f32; N]);
}

impl Faces<3> for Aabb3 {
    fn faces(&self) -> ([f32; 3], [f32; 3]) {
        flat3(self)
    }
}

impl Faces<2> for Aabb2 {
    fn faces(&self) -> ([f32; 2], [f32; 2]) {
        flat2(self)
    }
}

/// One kernel on slices, `apply(boxes, poses, out)`: timed over the scene's boxes and poses
/// (in cache and in DRAM) and judged by the oracle on the sample's.
fn on_slices<B: Faces<N>, X, const N: usize, P: Exactly<N>>(
    (boxes, xfs, out): (&[B], &[X], &mut [B]),
    (sample, sb, sx): (&[(cases::Class, P)], &[B], &[X]),
    bound: Bound,
    mut apply: impl FnMut(&[B], &[X], &mut [B]),
) -> ((f64, f64), Accuracy) {
    let t = times(|n| apply(black_box(&boxes[..n]), black_box(&xfs[..n]), &mut out[..n]));
    let mut so = sb.to_vec();
    apply(sb, sx, &mut so);
    let results: Vec<_> = so.iter().map(Faces::faces).collect();
    (t, accuracy(sample, &results, bound))
}

/// `apply` one box at a time over slices, as a user's loop does.
fn each<B, X>(f: impl Fn(&B, &X) -> B) -> impl FnMut(&[B], &[X], &mut [B]) {
    move |boxes, xfs, out| {
        for ((b, x), o) in boxes.iter().zip(xfs).zip(out) {
            *o = f(b, x);
        }
    }
}

/// The stages [`affine3d`] reports.
pub const AFFINE3_STAGES: usize = 2 + Method::ALL.len() * Rounding::ALL.len();

/// 3D affine: every kernel, layout (single, AoS, SoA, AoSoA) and backend, with the peers
/// (parry3d on the rigid poses of the scene, the glam loops) and the rooflines.
pub fn affine3d(backends: &[Backend], progress: &Progress) -> Vec<Row> {
    progress.stage("3D affine: scene and oracle sample");
    let (boxes, xfs, poses) = common::scene(dram(), 0x3d);
    #[cfg(not(feature = "peers"))]
    let _ = poses; // for the parry3d loop
    let (b8, x8) = (Aabb3x8::pack(&boxes), Affine3x8::pack(&xfs));
    let (bs, xs) = (AabbSoa::from_slice(&boxes), Affine3Soa::from_slice(&xfs));
    let (cb, cx) = (
        AabbSoa::from_slice(&boxes[..cache()]),
        Affine3Soa::from_slice(&xfs[..cache()]),
    );
    let mut out = vec![Aabb3::EMPTY; dram()];
    let mut o8 = vec![Aabb3x8::default(); b8.len()];
    let mut os = AabbSoa::filled(dram(), Aabb3::EMPTY);
    let mut co = AabbSoa::filled(cache(), Aabb3::EMPTY);
    let sample = sample::<Problem<3>>(0, problem);
    let (sb, sx): (Vec<Aabb3>, Vec<Affine3A>) = sample.iter().map(|(_, p)| affine3(p)).unzip();
    let (ssb, ssx) = (AabbSoa::from_slice(&sb), Affine3Soa::from_slice(&sx));
    let (s8, sx8) = (Aabb3x8::pack(&sb), Affine3x8::pack(&sx));
    let mut m = Meter::new(TransformClass::Affine3, progress);

    progress.stage("3D affine: peers and rooflines");
    #[cfg(feature = "peers")]
    {
        let (pb, pp) = common::parry_scene(&boxes, &poses);
        let mut op = pb.clone();
        let t = times(|n| {
            common::parry_transform_by(black_box(&pb[..n]), black_box(&pp[..n]), &mut op[..n])
        });
        m.peer(Peer::Parry, t, None);
    }
    let peer_accuracy = |f: fn(&[Aabb3], &[Affine3A], &mut [Aabb3])| {
        let mut o = vec![Aabb3::EMPTY; sb.len()];
        f(&sb, &sx, &mut o);
        let results: Vec<_> = o.iter().map(flat3).collect();
        Some(accuracy(&sample, &results, PEER_BOUND))
    };
    let t = times(|n| {
        common::glam_corners(black_box(&boxes[..n]), black_box(&xfs[..n]), &mut out[..n])
    });
    m.peer(Peer::GlamCorners, t, peer_accuracy(common::glam_corners));
    let t = times(|n| {
        common::glam_abs_matrix(black_box(&boxes[..n]), black_box(&xfs[..n]), &mut out[..n])
    });
    m.peer(
        Peer::GlamAbsMatrix,
        t,
        peer_accuracy(common::glam_abs_matrix),
    );
    let (braw, xraw) = (
        common::raw(&b8, |b| b.fields),
        common::raw(&x8, |x| x.fields),
    );
    let mut oraw = braw.clone();
    let t = times(|n| {
        common::roofline_blocks(
            black_box(&braw[..n / 8]),
            black_box(&xraw[..n / 8]),
            &mut oraw[..n / 8],
        )
    });
    m.roofline(Layout::Aosoa, t);
    let t = (
        ns_per_box(cache(), cache_runs(), || {
            common::roofline_soa(black_box(&cb), black_box(&cx), &mut co)
        }),
        ns_per_box(dram(), dram_runs(), || {
            common::roofline_soa(black_box(&bs), black_box(&xs), &mut os)
        }),
    );
    m.roofline(Layout::Soa, t);
    let t = times(|n| {
        common::roofline_aos(black_box(&boxes[..n]), black_box(&xfs[..n]), &mut out[..n])
    });
    m.roofline(Layout::Aos, t);

    for k @ (method, rounding) in kernels() {
        progress.stage(&kernel_stage("3D affine", k));
        let bound = Bound::documented(method, rounding, 3);
        let (scene, judged) = (
            (&boxes[..], &xfs[..], &mut out[..]),
            (&sample[..], &sb[..], &sx[..]),
        );
        let (t, a) = on_slices(
            scene,
            judged,
            bound,
            each(|b: &Aabb3, x| b.transformed(x, method, rounding)),
        );
        m.kernel(k, Layout::Single, GLAM_SIMD, t, a);
        let (scene, judged) = (
            (&boxes[..], &xfs[..], &mut out[..]),
            (&sample[..], &sb[..], &sx[..]),
        );
        let (t, a) = on_slices(
            scene,
            judged,
            bound,
            each(|b: &Aabb3, x| b.transformed_scalar(x, method, rounding)),
        );
        m.kernel(k, Layout::Single, SCALAR, t, a);

        for &backend in backends {
            let batch = Batch::new(method, rounding).on(backend).expect("supported");
            let name = backend.name();

            let (scene, judged) = (
                (&boxes[..], &xfs[..], &mut out[..]),
                (&sample[..], &sb[..], &sx[..]),
            );
            let (t, a) = on_slices(scene, judged, bound, |b, x, o| {
                batch.transform(b, x, o).unwrap()
            });
            m.kernel(k, Layout::Aos, name, t, a);

            let t = (
                ns_per_box(cache(), cache_runs(), || {
                    batch
                        .transform(black_box(cb.view()), cx.view(), co.view_mut())
                        .unwrap()
                }),
                ns_per_box(dram(), dram_runs(), || {
                    batch
                        .transform(black_box(bs.view()), xs.view(), os.view_mut())
                        .unwrap()
                }),
            );
            let mut sso = AabbSoa::filled(sb.len(), Aabb3::EMPTY);
            batch
                .transform(ssb.view(), ssx.view(), sso.view_mut())
                .unwrap();
            let results: Vec<_> = (0..sb.len()).map(|k| flat3(&sso.get(k))).collect();
            m.kernel(k, Layout::Soa, name, t, accuracy(&sample, &results, bound));

            let t = times(|n| {
                batch
                    .transform(
                        black_box(&b8[..n / 8]),
                        black_box(&x8[..n / 8]),
                        &mut o8[..n / 8],
                    )
                    .unwrap()
            });
            let mut so8 = vec![Aabb3x8::default(); s8.len()];
            batch.transform(&s8, &sx8, &mut so8).unwrap();
            let results: Vec<_> = Aabb3x8::unpack(&so8, sb.len()).iter().map(flat3).collect();
            m.kernel(
                k,
                Layout::Aosoa,
                name,
                t,
                accuracy(&sample, &results, bound),
            );
        }
    }
    m.rows
}

/// Every kernel of one dedicated 3D class: AoSoA and AoS on the best backend, single
/// boxes, and the memory roofline that moves the class's bytes, with the oracle's accuracy
/// over a sample of the class's own problems.
#[allow(clippy::too_many_arguments)]
fn class3<T: Transform3, P: Exactly<3>, const F: usize>(
    m: &mut Meter,
    best: Backend,
    boxes: &[Aabb3],
    xfs: &[T],
    raw: impl Fn(&Block8<T>) -> [[f32; 8]; F],
    sample: &[(cases::Class, P)],
    inputs: impl Fn(&P) -> (Aabb3, T),
) {
    let class = m.class.name();
    m.progress.stage(class);
    let (b8, x8) = (Aabb3x8::pack(boxes), Block8::pack(xfs));
    let (braw, xraw) = (common::raw(&b8, |b| b.fields), common::raw(&x8, raw));
    let (mut oraw, mut o8) = (braw.clone(), vec![Aabb3x8::default(); b8.len()]);
    let mut out = vec![Aabb3::EMPTY; boxes.len()];
    let (sb, sx): (Vec<Aabb3>, Vec<T>) = sample.iter().map(|(_, p)| inputs(p)).unzip();
    let t = times(|n| {
        common::roofline_blocks(
            black_box(&braw[..n / 8]),
            black_box(&xraw[..n / 8]),
            &mut oraw[..n / 8],
        )
    });
    m.roofline(Layout::Aosoa, t);
    for k @ (method, rounding) in kernels() {
        m.progress.stage(&kernel_stage(class, k));
        let bound = Bound::of_order(T::nearest_order(method), rounding);
        let batch = Batch::new(method, rounding).on(best).expect("detected");
        let mut so = vec![Aabb3::EMPTY; sb.len()];
        batch.transform(&sb, &sx, &mut so).expect("lengths");
        let results: Vec<_> = so.iter().map(flat3).collect();
        let batch_accuracy = accuracy(sample, &results, bound);
        let t = times(|n| {
            batch
                .transform(
                    black_box(&b8[..n / 8]),
                    black_box(&x8[..n / 8]),
                    &mut o8[..n / 8],
                )
                .expect("lengths")
        });
        m.kernel(k, Layout::Aosoa, best.name(), t, batch_accuracy);
        let (t, a) = on_slices(
            (boxes, xfs, &mut out),
            (sample, &sb, &sx),
            bound,
            |b, x, o| batch.transform(b, x, o).expect("lengths"),
        );
        m.kernel(k, Layout::Aos, best.name(), t, a);
        let (t, a) = on_slices(
            (boxes, xfs, &mut out),
            (sample, &sb, &sx),
            bound,
            each(|b: &Aabb3, x| b.transformed(x, method, rounding)),
        );
        m.kernel(k, Layout::Single, GLAM_SIMD, t, a);
    }
}

/// The stages [`classes3`] reports.
pub const CLASSES3_STAGES: usize = 2 + 4 * (1 + Method::ALL.len() * Rounding::ALL.len());

/// The dedicated 3D classes (translation, rigid, similarity, TRS) on one scene, with the
/// peers on its rigid poses.
pub fn classes3(best: Backend, progress: &Progress) -> Vec<Row> {
    progress.stage("3D classes: scene and oracle samples");
    let s = common::class_scene(dram(), 0xc1a55);
    let quats = |scale| sample(0x51, |class, r| quat_problem(class, scale, r));
    let translations = sample::<Problem<3>>(0, translation_problem::<3>);
    let rigid = quats(Scale::Unit);
    let (similarity, trs) = (quats(Scale::Uniform), quats(Scale::PerAxis));
    let mut rows = Vec::new();

    let mut m = Meter::new(TransformClass::Translation3, progress);
    class3(
        &mut m,
        best,
        &s.boxes,
        &s.translation,
        |b| b.fields,
        &translations,
        |p| (affine3(p).0, Translation3(Vec3A::from_array(p.t))),
    );
    rows.append(&mut m.rows);

    let mut m = Meter::new(TransformClass::Rigid3, progress);
    class3(
        &mut m,
        best,
        &s.boxes,
        &s.rigid,
        |b| b.fields,
        &rigid,
        |p| (p.aabb(), p.rigid3()),
    );
    progress.stage("3D rigid: peers");
    #[cfg(feature = "peers")]
    {
        let (pb, pp) = common::parry_scene(&s.boxes, &s.poses);
        let mut op = pb.clone();
        let t = times(|n| {
            common::parry_transform_by(black_box(&pb[..n]), black_box(&pp[..n]), &mut op[..n])
        });
        m.peer(Peer::Parry, t, None);
    }
    let mut out = vec![Aabb3::EMPTY; dram()];
    let t = times(|n| {
        common::glam_rigid_abs_matrix(
            black_box(&s.boxes[..n]),
            black_box(&s.rigid[..n]),
            &mut out[..n],
        )
    });
    let (sb, sx): (Vec<Aabb3>, Vec<Rigid3>) =
        rigid.iter().map(|(_, p)| (p.aabb(), p.rigid3())).unzip();
    let mut so = vec![Aabb3::EMPTY; sb.len()];
    common::glam_rigid_abs_matrix(&sb, &sx, &mut so);
    let results: Vec<_> = so.iter().map(flat3).collect();
    m.peer(
        Peer::GlamRigid,
        t,
        Some(accuracy(&rigid, &results, PEER_BOUND)),
    );
    rows.append(&mut m.rows);

    let mut m = Meter::new(TransformClass::Similarity3, progress);
    class3(
        &mut m,
        best,
        &s.boxes,
        &s.similarity,
        |b| b.fields,
        &similarity,
        |p| (p.aabb(), p.similarity3()),
    );
    rows.append(&mut m.rows);

    let mut m = Meter::new(TransformClass::Trs3, progress);
    class3(
        &mut m,
        best,
        &s.boxes,
        &s.trs,
        |b| b.fields,
        &trs,
        |p| (p.aabb(), p.trs3()),
    );
    rows.append(&mut m.rows);
    rows
}

/// The stages [`classes2`] reports.
pub const CLASSES2_STAGES: usize = 1 + Method::ALL.len() * Rounding::ALL.len();

/// Every 2D kernel: translation (single and AoS on the best backend), rigid and affine
/// (single, and AoS on each backend).
pub fn classes2(backends: &[Backend], progress: &Progress) -> Vec<Row> {
    progress.stage("2D: scene and oracle samples");
    let (boxes3, _, poses) = common::scene(dram(), 0x2d);
    let boxes: Vec<Aabb2> = boxes3
        .iter()
        .map(|b| Aabb2::new(b.min.truncate(), b.max.truncate()))
        .collect();
    let rigid: Vec<Rigid2> = poses
        .iter()
        .map(|(q, t)| Rigid2::from_angle_translation(q.to_axis_angle().1, Vec2::new(t.x, t.y)))
        .collect();
    let affine: Vec<Affine2> = rigid.iter().map(Rigid2::to_affine2).collect();
    let translation: Vec<Translation2> =
        rigid.iter().map(|r| Translation2(r.translation)).collect();
    let translation_sample = sample::<Problem<2>>(0, translation_problem::<2>);
    let (tb, tx): (Vec<Aabb2>, Vec<Translation2>) = translation_sample
        .iter()
        .map(|(_, p)| (affine2(p).0, Translation2(Vec2::from_array(p.t))))
        .unzip();
    let affine_sample = sample::<Problem<2>>(0, problem);
    let rigid_sample = sample::<Problem<2>>(0, rigid_problem);
    let (ab, ax): (Vec<Aabb2>, Vec<Affine2>) =
        affine_sample.iter().map(|(_, p)| affine2(p)).unzip();
    let (rb, rx): (Vec<Aabb2>, Vec<Rigid2>) = rigid_sample.iter().map(|(_, p)| rigid2(p)).unzip();
    let mut out = vec![Aabb2::EMPTY; dram()];
    let mut mt = Meter::new(TransformClass::Translation2, progress);
    let mut mr = Meter::new(TransformClass::Rigid2, progress);
    let mut ma = Meter::new(TransformClass::Affine2, progress);
    for k @ (method, rounding) in kernels() {
        progress.stage(&kernel_stage("2D", k));
        let b2 = Bound::documented(method, rounding, 2);
        let bt = Bound::of_order(Translation2::nearest_order(method), rounding);
        let (rigid_judged, affine_judged, translation_judged) = (
            (&rigid_sample[..], &rb[..], &rx[..]),
            (&affine_sample[..], &ab[..], &ax[..]),
            (&translation_sample[..], &tb[..], &tx[..]),
        );
        let single = each(|b: &Aabb2, x: &Rigid2| b.transformed_rigid(x, method, rounding));
        let (t, a) = on_slices(
            (&boxes[..], &rigid[..], &mut out[..]),
            rigid_judged,
            b2,
            single,
        );
        mr.kernel(k, Layout::Single, SCALAR, t, a);
        let single = each(|b: &Aabb2, x: &Affine2| b.transformed(x, method, rounding));
        let (t, a) = on_slices(
            (&boxes[..], &affine[..], &mut out[..]),
            affine_judged,
            b2,
            single,
        );
        ma.kernel(k, Layout::Single, SCALAR, t, a);
        let single = each(|b: &Aabb2, x: &Translation2| b.transformed(x, method, rounding));
        let (t, a) = on_slices(
            (&boxes[..], &translation[..], &mut out[..]),
            translation_judged,
            bt,
            single,
        );
        mt.kernel(k, Layout::Single, SCALAR, t, a);
        for (i, &backend) in backends.iter().enumerate() {
            let batch = Batch::new(method, rounding).on(backend).expect("supported");
            if i == 0 {
                let (t, a) = on_slices(
                    (&boxes[..], &translation[..], &mut out[..]),
                    translation_judged,
                    bt,
                    |b, x, o| batch.transform(b, x, o).unwrap(),
                );
                mt.kernel(k, Layout::Aos, backend.name(), t, a);
            }
            let (t, a) = on_slices(
                (&boxes[..], &rigid[..], &mut out[..]),
                rigid_judged,
                b2,
                |b, x, o| batch.transform(b, x, o).unwrap(),
            );
            mr.kernel(k, Layout::Aos, backend.name(), t, a);
            let (t, a) = on_slices(
                (&boxes[..], &affine[..], &mut out[..]),
                affine_judged,
                b2,
                |b, x, o| batch.transform(b, x, o).unwrap(),
            );
            ma.kernel(k, Layout::Aos, backend.name(), t, a);
        }
    }
    [mt.rows, mr.rows, ma.rows].concat()
}

/// The samples' case count, for the report.
pub fn cases_per_kernel() -> u64 {
    cases() * ACCURACY_CLASSES.len() as u64
}
