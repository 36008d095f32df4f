//! The broadphase update of many objects against its contract, in every form: `Active::All`,
//! `Indices` and `Mask` (well formed or not); per-object poses of every 3D class, `Swept`
//! pairs of them and `LargeWorld` of both pose types; AoS, AoSoA and SoA layouts; 2D fat
//! boxes; any backend, method, rounding and mode.
//!
//! Each update runs three times: from arbitrary fat boxes, again with the same poses (then
//! only an object whose input holds NaN may move), and with the next poses. After each,
//! every active object's fat box contains the exact image (of both poses when swept; with
//! Outward rounding) or is invalid where the input holds NaN; an inactive object is
//! untouched and not reported; a rewritten box is reported; and a bad margin or active set
//! is refused with nothing written.
#![no_main]

use bvkit::{
    Aabb2, Aabb3, Active, Backend, Batch, BatchError, Block8, LargeRigid3, Margin, Method, Moved,
    Rounding, Soa, Translation2, Translation3,
};
use bvkit::{LargeWorld, Swept};
use bvkit::{Transform2, Transform3};
use bvkit_fuzz::oracle::{Exact, Exactly, Expected, Problem, QuatProblem};
use bvkit_fuzz::{Floats, affine2, affine3, rigid2};
use glam::{DAffine3, DMat3, DVec3, Quat, Vec2, Vec3A};
use libfuzzer_sys::fuzz_target;

/// An active set as the fuzzer built it, possibly malformed.
enum ActiveSet {
    All,
    Indices(Vec<u32>),
    Mask(Vec<u64>),
}

impl ActiveSet {
    /// An active set over `n` objects; about one in eight is malformed.
    fn new(f: &mut Floats, n: usize) -> Self {
        let (kind, bad, how) = (f.byte() % 3, f.byte() % 8 == 0, f.byte());
        match kind {
            0 => ActiveSet::All,
            1 => {
                let mut ix: Vec<u32> = (0..n as u32).filter(|_| f.byte() % 2 == 0).collect();
                if bad {
                    match how % 3 {
                        0 => ix.push(n as u32 + u32::from(how / 3 % 4)),
                        1 if ix.len() >= 2 => ix.swap(0, 1),
                        _ => ix.insert(0, ix.first().copied().unwrap_or(0)),
                    }
                }
                ActiveSet::Indices(ix)
            }
            _ => {
                let mut words = vec![0u64; n.div_ceil(64)];
                for i in 0..n {
                    if f.byte() % 2 == 0 {
                        words[i / 64] |= 1 << (i % 64);
                    }
                }
                if bad {
                    match (how % 2, words.last_mut()) {
                        (0, Some(last)) if n % 64 != 0 => *last |= 1 << 63,
                        _ => words.push(u64::from(how)),
                    }
                }
                ActiveSet::Mask(words)
            }
        }
    }

    fn active(&self) -> Active<'_> {
        match self {
            ActiveSet::All => Active::All,
            ActiveSet::Indices(ix) => Active::Indices(ix),
            ActiveSet::Mask(words) => Active::Mask(words),
        }
    }

    /// The contract's rule, written independently of the crate's check.
    fn is_valid(&self, n: usize) -> bool {
        match self {
            ActiveSet::All => true,
            ActiveSet::Indices(ix) => {
                ix.windows(2).all(|w| w[0] < w[1]) && ix.iter().all(|&i| (i as usize) < n)
            }
            ActiveSet::Mask(words) => {
                words.len() == n.div_ceil(64)
                    && (0..64 * words.len()).all(|i| i < n || words[i / 64] >> (i % 64) & 1 == 0)
            }
        }
    }

    fn contains(&self, i: usize) -> bool {
        match self {
            ActiveSet::All => true,
            ActiveSet::Indices(ix) => ix.contains(&(i as u32)),
            ActiveSet::Mask(words) => words[i / 64] >> (i % 64) & 1 == 1,
        }
    }
}

/// Everything an update takes but the boxes and the poses.
struct Cx {
    batch: Batch,
    margin: Margin,
    set: ActiveSet,
    n: usize,
    /// 0: AoS, 1: AoSoA (then `n` is a multiple of 8), 2: SoA.
    layout: u8,
    /// True when the input is valid (margin and active set): the update must succeed.
    valid: bool,
}

/// Runs the update with the boxes in layout `$l` (0: AoS, 1: AoSoA, 2: SoA) and the poses
/// `$poses` (any source): a macro, since the layouts' element bound is sealed.
macro_rules! update_in {
    (0, $cx:expr, $local:expr, $poses:expr, $fat:expr, $moved:expr) => {{
        let (cx, local, fat, moved): (&Cx, &[_], &mut Vec<_>, &mut Moved) =
            ($cx, $local, $fat, $moved);
        let (b, m, a) = (&cx.batch, cx.margin, cx.set.active());
        b.update(m, a, local, $poses, &mut fat[..], moved)
    }};
    (1, $cx:expr, $local:expr, $poses:expr, $fat:expr, $moved:expr) => {{
        let (cx, local, fat, moved): (&Cx, &[_], &mut Vec<_>, &mut Moved) =
            ($cx, $local, $fat, $moved);
        let (b, m, a) = (&cx.batch, cx.margin, cx.set.active());
        let (l, mut f) = (Block8::pack(local), Block8::pack(fat));
        let r = b.update(m, a, &l[..], $poses, &mut f[..], moved);
        *fat = Block8::unpack(&f, fat.len());
        r
    }};
    (2, $cx:expr, $local:expr, $poses:expr, $fat:expr, $moved:expr) => {{
        let (cx, local, fat, moved): (&Cx, &[_], &mut Vec<_>, &mut Moved) =
            ($cx, $local, $fat, $moved);
        let (b, m, a) = (&cx.batch, cx.margin, cx.set.active());
        let (l, mut f) = (Soa::from_slice(local), Soa::from_slice(fat));
        let r = b.update(m, a, &l, $poses, &mut f, moved);
        *fat = (0..fat.len()).map(|k| f.get(k)).collect();
        r
    }};
}

/// The three stages of a scene, its boxes in layout `$l`, its poses as `$mode`: `plain`
/// (the current poses, then the next), `swept` (both, each stage) or `large` (a
/// `LargeWorld` of AoS poses). Per-object poses take the boxes' layout.
macro_rules! run {
    ($l:tt large, $cx:expr, $s:expr, $faces:expr) => {{
        let (cx, s) = ($cx, &$s);
        let (a, b, origin) = (&s.now[..], &s.next[..], s.origin);
        let mut update = |stage: usize, fat: &mut Vec<_>, moved: &mut Moved| {
            let poses = if stage == 2 { b } else { a };
            update_in!($l, cx, &s.local, LargeWorld { poses, origin }, fat, moved)
        };
        stages(cx, s.fat0.clone(), $faces, &mut update, &|st, i| s.expect(false, st, i))
    }};
    (0 $mode:ident, $cx:expr, $s:expr, $faces:expr) => {{
        let s = &$s;
        run!(@$mode 0, $cx, s, &s.now[..], &s.next[..], $faces)
    }};
    (1 $mode:ident, $cx:expr, $s:expr, $faces:expr) => {{
        let s = &$s;
        let (a, b) = (Block8::pack(&s.now), Block8::pack(&s.next));
        run!(@$mode 1, $cx, s, &a[..], &b[..], $faces)
    }};
    (2 $mode:ident, $cx:expr, $s:expr, $faces:expr) => {{
        let s = &$s;
        let (a, b) = (Soa::from_slice(&s.now), Soa::from_slice(&s.next));
        run!(@$mode 2, $cx, s, &a, &b, $faces)
    }};
    (@plain $l:tt, $cx:expr, $s:expr, $a:expr, $b:expr, $faces:expr) => {{
        let (cx, s, a, b) = ($cx, $s, $a, $b);
        let mut update = |stage: usize, fat: &mut Vec<_>, moved: &mut Moved| {
            if stage == 2 {
                update_in!($l, cx, &s.local, b, fat, moved)
            } else {
                update_in!($l, cx, &s.local, a, fat, moved)
            }
        };
        stages(cx, s.fat0.clone(), $faces, &mut update, &|st, i| s.expect(false, st, i))
    }};
    (@swept $l:tt, $cx:expr, $s:expr, $a:expr, $b:expr, $faces:expr) => {{
        let (cx, s, a, b) = ($cx, $s, $a, $b);
        let mut update = |_: usize, fat: &mut Vec<_>, moved: &mut Moved| {
            let poses = Swept {
                current: a,
                predicted: b,
            };
            update_in!($l, cx, &s.local, poses, fat, moved)
        };
        stages(cx, s.fat0.clone(), $faces, &mut update, &|st, i| s.expect(true, st, i))
    }};
}

/// What a scene's update runs on: the local boxes, the current and next poses, the fat
/// boxes before the first stage, and the exact images at the current and next poses.
struct Scene<B, T, const N: usize> {
    local: Vec<B>,
    now: Vec<T>,
    next: Vec<T>,
    fat0: Vec<B>,
    images: Vec<[Expected<N>; 2]>,
    /// The world origin of a `LargeWorld` scene (zero otherwise).
    origin: DVec3,
}

impl<B, T, const N: usize> Scene<B, T, N> {
    /// What object `i`'s fat box must hold after `stage`: both images when swept, else
    /// the current one, or the next one at stage 2.
    fn expect(&self, swept: bool, stage: usize, i: usize) -> Vec<Expected<N>> {
        let [now, next] = &self.images[i];
        match (swept, stage) {
            (true, _) => vec![now.clone(), next.clone()],
            (false, 2) => vec![next.clone()],
            _ => vec![now.clone()],
        }
    }
}

/// Three updates from `fat`, each verified: stage 0 and 1 with the current poses, stage 2
/// with the next ones. `expect(stage, i)` is what object `i`'s fat box must hold.
fn stages<const N: usize, B: Copy + core::fmt::Debug>(
    cx: &Cx,
    mut fat: Vec<B>,
    faces: fn(&B) -> [[f32; N]; 2],
    update: &mut dyn FnMut(usize, &mut Vec<B>, &mut Moved) -> Result<(), BatchError>,
    expect: &dyn Fn(usize, usize) -> Vec<Expected<N>>,
) {
    let bits = |b: &B| faces(b).map(|f| f.map(f32::to_bits));
    let mut moved = Moved::new();
    for stage in 0..3 {
        let (before, moved_before) = (fat.clone(), moved.clone());
        let result = update(stage, &mut fat, &mut moved);
        let what = format!("stage {stage} {:?} layout {}", cx.batch, cx.layout);
        if !cx.valid {
            assert!(result.is_err(), "{what}: bad input accepted");
            assert!(
                before.iter().zip(&fat).all(|(a, b)| bits(a) == bits(b)),
                "{what}: written"
            );
            assert_eq!(moved, moved_before, "{what}: moved written on an error");
            return;
        }
        result.unwrap_or_else(|e| panic!("{what}: {e}"));
        let ix = moved.indices();
        assert!(ix.windows(2).all(|w| w[0] < w[1]), "{what}: {ix:?}");
        assert!(ix.iter().all(|&i| (i as usize) < cx.n), "{what}: {ix:?}");
        for i in 0..cx.n {
            let (old, new) = (faces(&before[i]), faces(&fat[i]));
            let changed = bits(&before[i]) != bits(&fat[i]);
            if !cx.set.contains(i) {
                assert!(
                    !changed && !moved.contains(i),
                    "{what}: inactive {i} touched"
                );
                continue;
            }
            assert!(
                moved.contains(i) || !changed,
                "{what}: {i} rewritten, not reported"
            );
            let wants = expect(stage, i);
            let invalid = wants.iter().any(|e| matches!(e, Expected::Invalid));
            if invalid {
                let nan = new.iter().flatten().any(|x| x.is_nan());
                assert!(
                    nan && moved.contains(i),
                    "{what}: {i} NaN input hidden in {new:?}"
                );
                continue;
            }
            // Again with the same poses: every valid tight box is inside its fat box.
            assert!(
                stage != 1 || !changed,
                "{what}: {i} moved again: {old:?} -> {new:?}"
            );
            if cx.batch.rounding != Rounding::Outward {
                continue;
            }
            for want in wants {
                if let Expected::Faces { lo, hi, .. } = want {
                    for a in 0..N {
                        let [min, max] = [new[0][a], new[1][a]];
                        assert!(
                            !min.is_nan() && Exact::of(min) <= lo[a],
                            "{what}: {i} min {a} {min} misses {}",
                            lo[a].to_f64()
                        );
                        assert!(
                            !max.is_nan() && Exact::of(max) >= hi[a],
                            "{what}: {i} max {a} {max} misses {}",
                            hi[a].to_f64()
                        );
                    }
                }
            }
        }
    }
}

/// Any box: empty, NaN, whole space or two fuzzed corners.
fn fat_faces<const N: usize>(f: &mut Floats) -> [[f32; N]; 2] {
    match f.byte() % 4 {
        0 => [[f32::INFINITY; N], [f32::NEG_INFINITY; N]],
        1 => [[f32::NAN; N]; 2],
        2 => [[f32::NEG_INFINITY; N], [f32::INFINITY; N]],
        _ => [f.array(), f.array()],
    }
}

fn faces3(b: &Aabb3) -> [[f32; 3]; 2] {
    [b.min.to_array(), b.max.to_array()]
}

fn faces2(b: &Aabb2) -> [[f32; 2]; 2] {
    [b.min.to_array(), b.max.to_array()]
}

fn fat3(f: &mut Floats, n: usize) -> Vec<Aabb3> {
    (0..n)
        .map(|_| {
            let [min, max] = fat_faces::<3>(f);
            Aabb3::new(Vec3A::from_array(min), Vec3A::from_array(max))
        })
        .collect()
}

/// A 3D scene of per-object poses: each object's next pose keeps its box.
fn scene3<T: Transform3, P: Exactly<3>>(
    cx: &Cx,
    f: &mut Floats,
    make: impl Fn(&mut Floats) -> P,
    map: impl Fn(&P) -> (Aabb3, T),
) -> Scene<Aabb3, T, 3> {
    let ps: Vec<P> = (0..cx.n).map(|_| make(f)).collect();
    let qs: Vec<P> = ps
        .iter()
        .map(|p| make(f).with_box(p.lo(), p.hi()))
        .collect();
    Scene {
        local: ps.iter().map(|p| map(p).0).collect(),
        now: ps.iter().map(|p| map(p).1).collect(),
        next: qs.iter().map(|q| map(q).1).collect(),
        fat0: fat3(f, cx.n),
        images: ps
            .iter()
            .zip(&qs)
            .map(|(p, q)| [p.expected(), q.expected()])
            .collect(),
        origin: DVec3::ZERO,
    }
}

/// A 2D scene, as [`scene3`].
fn scene2<T: Transform2>(
    cx: &Cx,
    f: &mut Floats,
    map: impl Fn(&Problem<2>) -> (Problem<2>, Aabb2, T),
) -> Scene<Aabb2, T, 2> {
    let ps: Vec<_> = (0..cx.n).map(|_| map(&f.problem::<2>())).collect();
    let qs: Vec<_> = ps
        .iter()
        .map(|(p, _, _)| map(&f.problem::<2>().with_box(p.lo, p.hi)))
        .collect();
    let fat0 = (0..cx.n)
        .map(|_| {
            let [min, max] = fat_faces::<2>(f);
            Aabb2::new(Vec2::from_array(min), Vec2::from_array(max))
        })
        .collect();
    Scene {
        local: ps.iter().map(|p| p.1).collect(),
        now: ps.iter().map(|p| p.2).collect(),
        next: qs.iter().map(|q| q.2).collect(),
        fat0,
        images: ps
            .iter()
            .zip(&qs)
            .map(|(p, q)| [p.0.expected(), q.0.expected()])
            .collect(),
        origin: DVec3::ZERO,
    }
}

/// An `f64` from a fuzzed `f32`, scaled by a power of two (within the oracle's range).
fn wide(f: &mut Floats) -> f64 {
    let x = f64::from(f.next());
    x * 2f64.powi(i32::from(f.byte() % 49) - 8)
}

/// The exact faces of `x ↦ M·x + t − origin` over `[lo, hi]`, with `term(i, j, x)` the exact
/// `m_ij · x` (`0 · ±inf = 0`); `invalid` where the pose is not finite.
fn large_expected(
    lo: [f32; 3],
    hi: [f32; 3],
    invalid: bool,
    t: DVec3,
    origin: DVec3,
    term: impl Fn(usize, usize, f32) -> Exact,
) -> Expected<3> {
    let nan = lo.iter().chain(&hi).any(|x| x.is_nan());
    if invalid || nan || !t.is_finite() || !origin.is_finite() {
        return Expected::Invalid;
    }
    if (0..3).any(|j| lo[j] > hi[j] || lo[j] == f32::INFINITY || hi[j] == f32::NEG_INFINITY) {
        return Expected::Empty;
    }
    let face = |i: usize| {
        let base = Exact::of_f64(t[i]).add(&Exact::of_f64(origin[i]).neg());
        let (mut l, mut h) = (base.clone(), base);
        for j in 0..3 {
            let (a, b) = (term(i, j, lo[j]), term(i, j, hi[j]));
            let (low, high) = if a <= b { (a, b) } else { (b, a) };
            (l, h) = (l.add(&low), h.add(&high));
        }
        (l, h)
    };
    let [x, y, z] = [0, 1, 2].map(face);
    Expected::Faces {
        lo: [x.0, y.0, z.0],
        hi: [x.1, y.1, z.1],
        magnitude: [0.0; 3],
    }
}

/// A `LargeWorld` scene of `LargeRigid3` poses.
fn large_rigid(cx: &Cx, f: &mut Floats) -> Scene<Aabb3, LargeRigid3, 3> {
    large(cx, f, |_, p, t, origin| {
        let rigid = LargeRigid3::new(Quat::from_array(p.q), t);
        let finite_q = p.q.iter().all(|x| x.is_finite());
        let cols = finite_q.then(|| p.exact_cols());
        let e = large_expected(p.lo, p.hi, !finite_q, t, origin, |i, j, x| {
            cols.as_ref().expect("finite")[j][i].mul_f32(x)
        });
        (rigid, e)
    })
}

/// A `LargeWorld` scene of `DAffine3` poses: `f64` matrices near fuzzed `f32` entries,
/// usually off the `f32` grid.
fn large_affine(cx: &Cx, f: &mut Floats) -> Scene<Aabb3, DAffine3, 3> {
    large(cx, f, |f, p, t, origin| {
        let m = DMat3::from_cols_array(&core::array::from_fn(|_| {
            f64::from(f.next()) * (1.0 + f64::from(f.byte() as i8) * 2f64.powi(-40))
        }));
        let e = large_expected(p.lo, p.hi, !m.is_finite(), t, origin, |i, j, x| {
            Exact::product_f64(m.col(j)[i], x)
        });
        (DAffine3::from_mat3_translation(m, t), e)
    })
}

/// A `LargeWorld` scene: `pose(f, problem, t, origin)` makes a pose and its exact image.
fn large<T>(
    cx: &Cx,
    f: &mut Floats,
    mut pose: impl FnMut(&mut Floats, &QuatProblem, DVec3, DVec3) -> (T, Expected<3>),
) -> Scene<Aabb3, T, 3> {
    let origin = DVec3::new(wide(f), wide(f), wide(f));
    let ps: Vec<QuatProblem> = (0..cx.n).map(|_| f.quat_problem(None)).collect();
    let mut poses = |f: &mut Floats| -> Vec<(T, Expected<3>)> {
        ps.iter()
            .map(|p| {
                let t = DVec3::new(wide(f), wide(f), wide(f));
                pose(f, p, t, origin)
            })
            .collect()
    };
    let (now, images_now): (Vec<T>, Vec<_>) = poses(f).into_iter().unzip();
    let (next, images_next): (Vec<T>, Vec<_>) = poses(f).into_iter().unzip();
    Scene {
        local: ps.iter().map(QuatProblem::aabb).collect(),
        now,
        next,
        fat0: fat3(f, cx.n),
        images: images_now
            .into_iter()
            .zip(images_next)
            .map(|(a, b)| [a, b])
            .collect(),
        origin,
    }
}

fn translation3(p: &Problem<3>) -> (Aabb3, Translation3) {
    (affine3(p).0, Translation3(Vec3A::from_array(p.t)))
}

fn affine2_scene(p: &Problem<2>) -> (Problem<2>, Aabb2, glam::Affine2) {
    let (b, x) = affine2(p);
    (*p, b, x)
}

fn translation2(p: &Problem<2>) -> (Problem<2>, Aabb2, Translation2) {
    let mut q = *p;
    q.cols = [[1.0, 0.0], [0.0, 1.0]];
    (q, affine2(&q).0, Translation2(Vec2::from_array(q.t)))
}

/// The scenes this target runs, each a class in one box layout (0: AoS, 1: AoSoA, 2:
/// SoA) with its poses plain, swept or large. Not the whole cross product: each update
/// instantiates the kernels of every backend, method and rounding, and all 60
/// combinations took the instrumented build past ten minutes. The transform kernels of
/// every class and layout are the `batch` target's; here every layout runs plain and
/// swept affine scenes, and every class runs in at least two layouts and both modes.
macro_rules! scenes {
    ($cx:ident, $f:ident; $($l:tt $mode:ident $faces:ident => $scene:expr),* $(,)?) => {
        /// Each scene's box layout.
        const LAYOUTS: &[u8] = &[$($l),*];

        /// Builds scene `k` from the input and runs its three stages.
        fn run_scene(k: usize, $cx: &Cx, $f: &mut Floats) {
            let mut i = 0;
            $(
                if k == i {
                    return run!($l $mode, $cx, $scene, $faces);
                }
                i += 1;
            )*
            let _ = i;
        }
    };
}

scenes! { cx, f;
    0 plain faces3 => scene3(cx, f, |f| f.problem::<3>(), affine3),
    1 plain faces3 => scene3(cx, f, |f| f.problem::<3>(), affine3),
    2 plain faces3 => scene3(cx, f, |f| f.problem::<3>(), affine3),
    0 swept faces3 => scene3(cx, f, |f| f.problem::<3>(), affine3),
    1 swept faces3 => scene3(cx, f, |f| f.problem::<3>(), affine3),
    2 swept faces3 => scene3(cx, f, |f| f.problem::<3>(), affine3),
    0 plain faces3 => scene3(cx, f, |f| f.quat_problem(None), |p| (p.aabb(), p.rigid3())),
    1 plain faces3 => scene3(cx, f, |f| f.quat_problem(None), |p| (p.aabb(), p.rigid3())),
    2 swept faces3 => scene3(cx, f, |f| f.quat_problem(None), |p| (p.aabb(), p.rigid3())),
    0 swept faces3 => scene3(cx, f, |f| f.translation_problem::<3>(), translation3),
    1 plain faces3 => scene3(cx, f, |f| f.translation_problem::<3>(), translation3),
    2 plain faces3 => scene3(cx, f, |f| f.translation_problem::<3>(), translation3),
    0 plain faces3 => scene3(cx, f, |f| f.quat_problem(Some(true)), |p| (p.aabb(), p.similarity3())),
    1 swept faces3 => scene3(cx, f, |f| f.quat_problem(Some(true)), |p| (p.aabb(), p.similarity3())),
    0 swept faces3 => scene3(cx, f, |f| f.quat_problem(Some(false)), |p| (p.aabb(), p.trs3())),
    2 plain faces3 => scene3(cx, f, |f| f.quat_problem(Some(false)), |p| (p.aabb(), p.trs3())),
    0 large faces3 => large_rigid(cx, f),
    1 large faces3 => large_rigid(cx, f),
    0 large faces3 => large_affine(cx, f),
    2 large faces3 => large_affine(cx, f),
    0 plain faces2 => scene2(cx, f, affine2_scene),
    1 swept faces2 => scene2(cx, f, affine2_scene),
    2 plain faces2 => scene2(cx, f, affine2_scene),
    0 swept faces2 => scene2(cx, f, rigid2),
    2 plain faces2 => scene2(cx, f, rigid2),
    0 plain faces2 => scene2(cx, f, translation2),
    1 swept faces2 => scene2(cx, f, translation2),
}

fuzz_target!(|data: &[u8]| {
    let mut f = Floats::new(data);
    let supported = Backend::supported();
    let backend = supported[usize::from(f.byte()) % supported.len()];
    let method = Method::ALL[usize::from(f.byte()) % 3];
    let rounding = Rounding::ALL[usize::from(f.byte()) % 2];
    let mut batch = Batch::new(method, rounding).on(backend).unwrap();
    if f.byte() % 2 == 1 {
        batch = batch.deterministic();
    }
    let scene = usize::from(f.byte()) % LAYOUTS.len();
    let layout = LAYOUTS[scene];
    let mut n = usize::from(f.byte() % 20);
    if layout == 1 {
        n = n.div_ceil(8) * 8;
    }
    // Mostly a sound margin, sometimes any two floats.
    let margin = if f.byte() % 8 == 0 {
        Margin::new(f.next(), f.next())
    } else {
        let m = |x: f32| if x.is_finite() { x.abs() } else { 0.5 };
        Margin::new(m(f.next()), m(f.next()))
    };
    let set = ActiveSet::new(&mut f, n);
    let ok = |x: f32| x.is_finite() && x >= 0.0;
    let valid = set.is_valid(n) && ok(margin.absolute) && ok(margin.relative);
    let cx = Cx {
        batch,
        margin,
        set,
        n,
        layout,
        valid,
    };
    run_scene(scene, &cx, &mut f);
});
