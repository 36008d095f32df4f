//! The broadphase update against the exact oracle and a brute-force reference: fat boxes,
//! the moved set, active subsets, swept boxes and large worlds, on every supported
//! backend and layout; and its refusals.
#![allow(clippy::needless_range_loop)]

use bvkit_support::cases;
use bvkit_support::oracle;

use bvkit::{
    Aabb2, Aabb3, Active, Backend, Batch, BatchError, Block8, LargeRigid3, Margin, Method, Moved,
    Rigid2, Rigid3, Rounding, Soa, Swept,
};
use bvkit::{LargePose, LargeWorld};
use glam::{Affine3A, DAffine3, DMat3, DVec3, Quat, Vec2, Vec3A};
use rand::RngExt;
use rand::rngs::StdRng;

use cases::{Class, Scale, problem, quat_problem, rng};
use oracle::{Exact, Exactly, Expected, Problem, QuatProblem, affine3};

const METHODS: [Method; 3] = [Method::Naive, Method::AbsMatrix, Method::SignSelect];
const ROUNDINGS: [Rounding; 2] = [Rounding::Nearest, Rounding::Outward];
const U: f64 = 1.0 / 16_777_216.0;

/// Bitwise box equality (NaN boxes included).
fn same3(a: &Aabb3, b: &Aabb3) -> bool {
    let bits = |x: &Aabb3| [x.min.to_array(), x.max.to_array()].map(|v| v.map(f32::to_bits));
    bits(a) == bits(b)
}

fn inside3(tight: &Aabb3, fat: &Aabb3) -> bool {
    (0..3).all(|a| fat.min[a] <= tight.min[a] && tight.max[a] <= fat.max[a])
}

/// The growth `g` of one axis, as documented on [`Margin`].
fn growth(margin: Margin, min: f32, max: f32) -> f32 {
    let rel = (max * 0.5 - min * 0.5) * margin.relative;
    if rel > margin.absolute {
        rel
    } else {
        margin.absolute
    }
}

/// `face <= exact` (a lower face) or `face >= exact`, decided exactly.
fn holds(face: f32, exact: &Exact, lower: bool) -> bool {
    if face.is_nan() {
        return false;
    }
    let f = Exact::of(face);
    if lower { f <= *exact } else { f >= *exact }
}

// ---------------------------------------------------------------------------------------
// Fat boxes.

#[test]
fn fat_boxes_contain_the_exact_grown_box_and_are_tight() {
    let mut r = rng(0xfa7);
    let margins = [
        Margin::ZERO,
        Margin::new(0.1, 0.0),
        Margin::new(0.0, 0.25),
        Margin::new(1e-30, 1e-7),
        Margin::new(3e38, 0.0),
        Margin::new(0.5, 1e30),
    ];
    let mut checked = 0;
    for class in Class::ALL {
        for _ in 0..300 {
            let p: Problem<3> = problem(class, &mut r);
            let tight = Aabb3::new(p.lo.into(), p.hi.into());
            let margin = margins[r.random_range(0..margins.len())];
            let fat = tight.fattened(margin);
            if !tight.is_valid() {
                assert!(!fat.is_valid(), "{tight:?} {margin:?} -> {fat:?}");
                continue;
            }
            if tight.is_empty() {
                // An empty box grows into an empty box (EMPTY stays EMPTY).
                assert!(fat.is_empty() || fat.is_valid(), "{tight:?} -> {fat:?}");
                if tight == Aabb3::EMPTY {
                    assert!(same3(&fat, &Aabb3::EMPTY), "{fat:?}");
                }
                continue;
            }
            assert!(inside3(&tight, &fat), "{tight:?} {margin:?} -> {fat:?}");
            for a in 0..3 {
                let (min, max) = (tight.min[a], tight.max[a]);
                let g = growth(margin, min, max);
                for (face, edge, lower) in [(fat.min[a], min, true), (fat.max[a], max, false)] {
                    if edge.is_infinite() || g.is_infinite() {
                        continue;
                    }
                    let exact = if lower {
                        Exact::of(edge).add(&Exact::of(g).neg())
                    } else {
                        Exact::of(edge).add(&Exact::of(g))
                    };
                    assert!(
                        holds(face, &exact, lower),
                        "axis {a}: {face} does not contain {edge} ∓ {g} ({margin:?})"
                    );
                    if face.is_finite() {
                        let slack = (f64::from(face) - exact.to_f64()).abs();
                        let allowed = 7.0 * U * f64::from(face).abs() + 2f64.powi(-149);
                        assert!(
                            slack <= allowed,
                            "axis {a}: {face} is {slack} from {exact:?}"
                        );
                    }
                    checked += 1;
                }
            }
        }
    }
    assert!(checked > 10_000, "only {checked} faces checked");
}

#[test]
fn fat_box_growth_is_the_documented_margin() {
    let b = Aabb3::new(Vec3A::new(0.0, -2.0, 10.0), Vec3A::new(4.0, 2.0, 10.0));
    let fat = b.fattened(Margin::new(0.5, 0.5));
    // x: half 2 → growth 1; y: half 2 → 1; z: half 0 → the absolute 0.5.
    for (got, want) in [
        (fat.min, Vec3A::new(-1.0, -3.0, 9.5)),
        (fat.max, Vec3A::new(5.0, 3.0, 10.5)),
    ] {
        assert!((got - want).abs().max_element() < 1e-5, "{got} vs {want}");
        assert!(got.cmpne(want).any(), "rounded outward, not to nearest");
    }
    let b2 = Aabb2::new(Vec2::ZERO, Vec2::ONE).fattened(Margin::new(1.0, 0.0));
    assert!(b2.min.x <= -1.0 && b2.max.y >= 2.0 && b2.max.y < 2.0001);
}

#[test]
fn fattened_refuses_the_margins_update_refuses() {
    let b = Aabb3::new(Vec3A::new(0.0, -2.0, 10.0), Vec3A::new(4.0, 2.0, 10.0));
    let b2 = Aabb2::new(Vec2::ZERO, Vec2::ONE);
    for bad in [-1.0, -f32::MIN_POSITIVE, f32::INFINITY, f32::NAN] {
        for margin in [Margin::new(bad, 0.0), Margin::new(0.0, bad)] {
            // A negative margin would shrink the box below the tight one, silently.
            assert!(!b.fattened(margin).is_valid(), "{margin:?}");
            assert!(!b2.fattened(margin).is_valid(), "{margin:?}");
        }
    }
}

// ---------------------------------------------------------------------------------------
// The update against a brute-force reference.

#[derive(Clone, Copy, Debug)]
enum Layout {
    Aos,
    Aosoa,
    Soa,
}

/// Runs the update on `layout`, with the fat boxes converted there and back.
macro_rules! update_on {
    ($layout:expr, $batch:expr, $margin:expr, $active:expr, $local:expr, $poses:expr, $fat:expr, $moved:expr) => {{
        let (local, poses, fat): (&[Aabb3], &[_], &mut Vec<Aabb3>) = ($local, $poses, $fat);
        match $layout {
            Layout::Aos => $batch.update($margin, $active, local, poses, &mut fat[..], $moved),
            Layout::Aosoa => {
                let (l, p) = (Block8::pack(local), Block8::pack(poses));
                let mut f = Block8::pack(fat);
                let result = $batch.update($margin, $active, &l[..], &p[..], &mut f[..], $moved);
                *fat = Block8::unpack(&f, fat.len());
                result
            }
            Layout::Soa => {
                let (l, p) = (Soa::from_slice(local), Soa::from_slice(poses));
                let mut f = Soa::from_slice(fat);
                let result = $batch.update($margin, $active, &l, &p, &mut f, $moved);
                *fat = (0..fat.len()).map(|k| f.get(k)).collect();
                result
            }
        }
    }};
}

/// The reference: every active object's tight box from the scalar path, the fat logic
/// written out, and the moved indices collected in order.
fn reference(
    tight: impl Fn(usize) -> Aabb3,
    active: &[usize],
    margin: Margin,
    fat: &mut [Aabb3],
) -> Vec<u32> {
    let mut moved = Vec::new();
    for &i in active {
        let t = tight(i);
        let inside = t.is_valid() && fat[i].is_valid() && inside3(&t, &fat[i]);
        if !inside {
            fat[i] = t.fattened(margin);
            moved.push(i as u32);
        }
    }
    moved
}

/// A random walk of poses: most objects drift a little, some jump, a few go NaN and come
/// back, and a few local boxes are empty or unbounded.
struct Scene<T> {
    local: Vec<Aabb3>,
    poses: Vec<T>,
}

fn rigid_scene(n: usize, r: &mut StdRng) -> Scene<Rigid3> {
    let local = (0..n)
        .map(|k| match k % 29 {
            5 => Aabb3::EMPTY,
            11 => Aabb3::new(Vec3A::new(f32::NEG_INFINITY, 0.0, 0.0), Vec3A::ONE),
            _ => {
                let e = Vec3A::new(r.random_range(0.1..2.0), 0.5, r.random_range(0.0..1.0));
                Aabb3::new(-e, e)
            }
        })
        .collect();
    let poses = (0..n)
        .map(|_| {
            let q = Quat::from_euler(
                glam::EulerRot::XYZ,
                r.random_range(-3.0..3.0),
                r.random_range(-3.0..3.0),
                0.0,
            );
            Rigid3::new(q, Vec3A::new(r.random_range(-100.0..100.0), 0.0, 5.0))
        })
        .collect();
    Scene { local, poses }
}

/// The active objects of a frame: all of them on every third frame, else about two
/// thirds at random; as a list, as `u32` indices and as a mask.
fn active_set(n: usize, frame: usize, r: &mut StdRng) -> (Vec<usize>, Vec<u32>, Vec<u64>) {
    // On the mask's frames, every object of its second word: a whole span that does not
    // start at object 0.
    let whole = |i: usize| frame % 3 == 2 && (64..128).contains(&i);
    // Two thirds of the objects, or on frame 4 one in 32: a list that sparse runs an entry
    // at a time on the lane layouts, a dense one as a mask.
    let mut listed = || match frame {
        4 => r.random_range(0..32) == 0,
        _ => r.random_range(0..3) != 0,
    };
    let subset: Vec<usize> = match frame % 3 {
        0 => (0..n).collect(),
        _ => (0..n).filter(|&i| whole(i) || listed()).collect(),
    };
    let indices = subset.iter().map(|&i| i as u32).collect();
    let mut mask = vec![0u64; n.div_ceil(64)];
    subset.iter().for_each(|&i| mask[i / 64] |= 1 << (i % 64));
    (subset, indices, mask)
}

fn step(poses: &mut [Rigid3], frame: usize, r: &mut StdRng) {
    for (k, p) in poses.iter_mut().enumerate() {
        let roll = r.random_range(0..100);
        if p.translation.is_nan() {
            p.translation = Vec3A::ZERO;
        } else if roll < 60 {
            p.translation.x += r.random_range(-0.02..0.02);
        } else if roll < 70 {
            p.translation.y += r.random_range(-3.0..3.0);
            p.rotation = (p.rotation * Quat::from_rotation_z(0.7)).normalize();
        } else if roll < 71 || (k == 3 && frame % 2 == 1) {
            p.translation.z = f32::NAN;
        }
    }
}

#[test]
fn update_matches_the_brute_force_reference_on_every_backend_and_layout() {
    let n = 203; // whole blocks of 8 and 16, and a tail
    let margin = Margin::new(0.05, 0.1);
    for backend in Backend::supported() {
        for layout in [Layout::Aos, Layout::Aosoa, Layout::Soa] {
            for method in METHODS {
                for rounding in ROUNDINGS {
                    let batch = Batch::new(method, rounding)
                        .deterministic()
                        .on(backend)
                        .unwrap();
                    let mut r = rng(0x5eed + method as u64);
                    let mut scene = rigid_scene(n, &mut r);
                    let mut fat = vec![Aabb3::EMPTY; n];
                    let mut want = fat.clone();
                    let mut moved = Moved::new();
                    let mut total = 0;
                    for frame in 0..6 {
                        let before = fat.clone();
                        // Alternate the whole scene with active lists and masks.
                        // The whole scene, then an index list, then a mask.
                        let (subset, indices, mask) = active_set(n, frame, &mut r);
                        let active = [Active::All, Active::Indices(&indices), Active::Mask(&mask)]
                            [frame % 3];
                        let (local, poses) = (&scene.local, &scene.poses);
                        update_on!(
                            layout, batch, margin, active, local, poses, &mut fat, &mut moved
                        )
                        .unwrap();
                        let tight = |i: usize| {
                            scene.local[i].transformed_scalar(&scene.poses[i], method, rounding)
                        };
                        let expected = reference(tight, &subset, margin, &mut want);
                        let what =
                            format!("{backend:?} {layout:?} {method:?} {rounding:?} frame {frame}");
                        assert_eq!(moved.indices(), &expected[..], "{what}");
                        for i in 0..n {
                            assert_eq!(
                                moved.contains(i),
                                expected.contains(&(i as u32)),
                                "{what} bit {i}"
                            );
                            assert!(
                                same3(&fat[i], &want[i]),
                                "{what} box {i}: {:?} vs {:?}",
                                fat[i],
                                want[i]
                            );
                            if !subset.contains(&i) {
                                assert!(
                                    same3(&fat[i], &before[i]),
                                    "{what}: inactive {i} was written"
                                );
                            }
                        }
                        // A NaN pose is always moved and never hidden in a fat box.
                        for i in 0..n {
                            if subset.contains(&i)
                                && scene.poses[i].translation.is_nan()
                                && !scene.local[i].is_empty()
                            {
                                assert!(
                                    moved.contains(i) && !fat[i].is_valid(),
                                    "{what}: NaN pose {i}"
                                );
                            }
                        }
                        total += moved.len();
                        step(&mut scene.poses, frame, &mut r);
                    }
                    assert!(total > n, "too few moves to test anything: {total}");
                }
            }
        }
    }
}

#[test]
fn aos_update_matches_single_box_calls_on_the_simd_backends() {
    // In the default mode, AoS boxes run the single-box kernel: the reference is
    // `Aabb3::transformed` itself, bit for bit, with every kind of active set.
    let n = 203;
    let margin = Margin::new(0.05, 0.1);
    let simd = [Backend::Baseline, Backend::Avx2, Backend::Avx512];
    for backend in Backend::supported()
        .into_iter()
        .filter(|b| simd.contains(b))
    {
        for method in METHODS {
            for rounding in ROUNDINGS {
                let batch = Batch::new(method, rounding).on(backend).unwrap();
                let mut r = rng(0xa05 + method as u64);
                let mut scene = rigid_scene(n, &mut r);
                let (mut fat, mut want, mut moved) =
                    (vec![Aabb3::EMPTY; n], vec![Aabb3::EMPTY; n], Moved::new());
                for frame in 0..6 {
                    let (subset, indices, mask) = active_set(n, frame, &mut r);
                    let active =
                        [Active::All, Active::Indices(&indices), Active::Mask(&mask)][frame % 3];
                    batch
                        .update(
                            margin,
                            active,
                            &scene.local,
                            &scene.poses,
                            &mut fat,
                            &mut moved,
                        )
                        .unwrap();
                    let tight =
                        |i: usize| scene.local[i].transformed(&scene.poses[i], method, rounding);
                    let expected = reference(tight, &subset, margin, &mut want);
                    let what = format!("{backend:?} {method:?} {rounding:?} frame {frame}");
                    assert_eq!(moved.indices(), &expected[..], "{what}");
                    assert!(fat.iter().zip(&want).all(|(a, b)| same3(a, b)), "{what}");
                    step(&mut scene.poses, frame, &mut r);
                }
            }
        }
    }
}

#[test]
fn default_mode_keeps_the_contract_on_every_backend() {
    // Not bitwise: the default fuses multiply-adds. Outward fat boxes contain the exact
    // image of every object the update visits, for affine maps from every extreme class.
    let mut r = rng(0xaff);
    let problems: Vec<Problem<3>> = Class::ALL
        .iter()
        .flat_map(|&c| (0..40).map(move |_| c))
        .map(|c| problem(c, &mut r))
        .collect();
    let (local, poses): (Vec<Aabb3>, Vec<Affine3A>) = problems.iter().map(affine3).unzip();
    let n = local.len();
    for backend in Backend::supported() {
        for layout in [Layout::Aos, Layout::Aosoa, Layout::Soa] {
            for method in METHODS {
                let batch = Batch::new(method, Rounding::Outward).on(backend).unwrap();
                let mut fat = vec![Aabb3::EMPTY; n];
                let mut moved = Moved::new();
                let margin = Margin::new(0.0, 0.01);
                update_on!(
                    layout,
                    batch,
                    margin,
                    Active::All,
                    &local,
                    &poses,
                    &mut fat,
                    &mut moved
                )
                .unwrap();
                for (i, p) in problems.iter().enumerate() {
                    let what =
                        format!("{backend:?} {layout:?} {method:?} #{i} {p:?}: {:?}", fat[i]);
                    match p.expected() {
                        Expected::Invalid => {
                            assert!(!fat[i].is_valid() && moved.contains(i), "{what}")
                        }
                        Expected::Empty => assert!(!moved.contains(i), "{what}"),
                        Expected::Faces { lo, hi, .. } => {
                            assert!(moved.contains(i), "{what}");
                            for a in 0..3 {
                                assert!(holds(fat[i].min[a], &lo[a], true), "{what} min {a}");
                                assert!(holds(fat[i].max[a], &hi[a], false), "{what} max {a}");
                            }
                        }
                    }
                }
                // Nothing moved since: a second update rewrites nothing but the NaN boxes.
                let before = fat.clone();
                update_on!(
                    layout,
                    batch,
                    margin,
                    Active::All,
                    &local,
                    &poses,
                    &mut fat,
                    &mut moved
                )
                .unwrap();
                for i in 0..n {
                    assert_eq!(
                        moved.contains(i),
                        !before[i].is_valid(),
                        "{backend:?} {layout:?} #{i}"
                    );
                    assert!(same3(&fat[i], &before[i]));
                }
            }
        }
    }
}

#[test]
fn two_dimensional_update_follows_the_same_logic() {
    let n = 77;
    let mut r = rng(0x2d);
    let local: Vec<Aabb2> = (0..n)
        .map(|_| Aabb2::new(Vec2::splat(-1.0), Vec2::splat(1.0)))
        .collect();
    let mut poses: Vec<Rigid2> = (0..n)
        .map(|_| {
            Rigid2::from_angle_translation(
                r.random_range(-3.0..3.0),
                Vec2::new(r.random_range(-9.0..9.0), 0.0),
            )
        })
        .collect();
    let mut fat = vec![Aabb2::EMPTY; n];
    let mut moved = Moved::new();
    let batch = Batch::new(Method::SignSelect, Rounding::Outward);
    let margin = Margin::new(0.5, 0.0);
    batch
        .update(margin, Active::All, &local, &poses, &mut fat, &mut moved)
        .unwrap();
    assert_eq!(moved.len(), n);
    poses[10].translation.x += 0.1;
    poses[40].translation.x += 5.0;
    batch
        .update(margin, Active::All, &local, &poses, &mut fat, &mut moved)
        .unwrap();
    assert_eq!(moved.indices(), &[40]);
    assert_eq!(moved.words(), &[1 << 40, 0]);
}

// ---------------------------------------------------------------------------------------
// Swept boxes.

#[test]
fn swept_boxes_contain_the_exact_image_at_both_poses() {
    let mut r = rng(0x5e7);
    let pairs: Vec<(QuatProblem, QuatProblem)> = Class::ALL
        .iter()
        .flat_map(|&c| (0..30).map(move |_| c))
        .map(|c| {
            let a = quat_problem(c, Scale::Unit, &mut r);
            let mut b = quat_problem(Class::Typical, Scale::Unit, &mut r);
            (b.lo, b.hi) = (a.lo, a.hi);
            if r.random_range(0..10) == 0 {
                b.t[1] = f32::NAN;
            }
            (a, b)
        })
        .collect();
    let local: Vec<Aabb3> = pairs.iter().map(|(a, _)| a.aabb()).collect();
    let current: Vec<Rigid3> = pairs.iter().map(|(a, _)| a.rigid3()).collect();
    let predicted: Vec<Rigid3> = pairs.iter().map(|(_, b)| b.rigid3()).collect();
    let n = local.len();
    for backend in Backend::supported() {
        for method in METHODS {
            let batch = Batch::new(method, Rounding::Outward).on(backend).unwrap();
            let mut fat = vec![Aabb3::EMPTY; n];
            let mut moved = Moved::new();
            let swept = Swept {
                current: &current,
                predicted: &predicted,
            };
            batch
                .update(
                    Margin::ZERO,
                    Active::All,
                    &local,
                    swept,
                    &mut fat,
                    &mut moved,
                )
                .unwrap();
            let mut both = 0;
            for (i, (a, b)) in pairs.iter().enumerate() {
                let what = format!("{backend:?} {method:?} #{i} {a:?} {b:?}: {:?}", fat[i]);
                match (a.expected(), b.expected()) {
                    (Expected::Invalid, _) | (_, Expected::Invalid) => {
                        assert!(!fat[i].is_valid() && moved.contains(i), "{what}")
                    }
                    (
                        Expected::Faces { lo, hi, .. },
                        Expected::Faces {
                            lo: lo2, hi: hi2, ..
                        },
                    ) => {
                        for a in 0..3 {
                            for (l, h) in [(&lo[a], &hi[a]), (&lo2[a], &hi2[a])] {
                                assert!(holds(fat[i].min[a], l, true), "{what} min {a}");
                                assert!(holds(fat[i].max[a], h, false), "{what} max {a}");
                            }
                        }
                        both += 1;
                    }
                    _ => {}
                }
            }
            assert!(both > 300, "only {both} swept boxes checked");
            // In deterministic mode, the swept box is the union of the two tight boxes of
            // the batch transform, fattened by zero, bit for bit.
            let batch = batch.deterministic();
            let (mut t0, mut t1) = (vec![Aabb3::EMPTY; n], vec![Aabb3::EMPTY; n]);
            batch.transform(&local, &current, &mut t0).unwrap();
            batch.transform(&local, &predicted, &mut t1).unwrap();
            let swept = Swept {
                current: &current,
                predicted: &predicted,
            };
            fat.fill(Aabb3::EMPTY);
            batch
                .update(
                    Margin::ZERO,
                    Active::All,
                    &local,
                    swept,
                    &mut fat,
                    &mut moved,
                )
                .unwrap();
            for i in 0..n {
                // AoS boxes with AoS poses: every input, the extended path's too (in other
                // layouts, where either pose needs it both are recomputed there).
                if t0[i].is_valid() && t1[i].is_valid() {
                    let want = t0[i].union(&t1[i]).fattened(Margin::ZERO);
                    assert!(
                        same3(&want, &fat[i]),
                        "{backend:?} {method:?} {i}: {want:?} vs {:?}",
                        fat[i]
                    );
                }
            }
        }
    }
}

/// The union of an object's boxes at two poses, invalid where either has a NaN face.
fn swept_union(a: Aabb3, b: Aabb3) -> Aabb3 {
    let nan = |x: &Aabb3| x.min.is_nan() || x.max.is_nan();
    if nan(&a) || nan(&b) {
        Aabb3::NAN
    } else {
        a.union(&b)
    }
}

#[test]
fn swept_aos_update_is_the_union_of_two_single_box_calls() {
    // AoS boxes with a swept pair of AoS or shared poses, of any classes, run the AoS loop
    // at each pose: the tight box is the union of the single-box kernel's two boxes, bit
    // for bit, on every backend, in both modes, with every kind of active set. 700 objects:
    // whole blocks of the swept run (256) and a tail, and a sparse mask on frame 4.
    let n = 700;
    let margin = Margin::new(0.05, 0.1);
    for backend in Backend::supported() {
        for method in METHODS {
            for rounding in ROUNDINGS {
                for deterministic in [false, true] {
                    let mut batch = Batch::new(method, rounding).on(backend).unwrap();
                    if deterministic {
                        batch = batch.deterministic();
                    }
                    let mut r = rng(0x5a1 + method as u64);
                    let mut scene = rigid_scene(n, &mut r);
                    let (mut fat, mut want, mut moved) =
                        (vec![Aabb3::EMPTY; n], vec![Aabb3::EMPTY; n], Moved::new());
                    let shared = Affine3A::from_rotation_z(0.3);
                    for frame in 0..8 {
                        let mut next = scene.poses.clone();
                        step(&mut next, frame + 100, &mut r);
                        let (subset, indices, mask) = active_set(n, frame, &mut r);
                        let active = match frame % 3 {
                            0 => Active::All,
                            1 if frame != 4 => Active::Indices(&indices),
                            _ => Active::Mask(&mask),
                        };
                        let before = fat.clone();
                        let local = &scene.local[..];
                        let at =
                            |i: usize, pose: &Rigid3| local[i].transformed(pose, method, rounding);
                        let what = format!(
                            "{backend:?} {method:?} {rounding:?} deterministic {deterministic} \
                             frame {frame}"
                        );
                        if frame % 2 == 0 {
                            let swept = Swept {
                                current: &scene.poses[..],
                                predicted: &next[..],
                            };
                            batch.update(margin, active, local, swept, &mut fat, &mut moved)
                        } else {
                            let swept = Swept {
                                current: &scene.poses[..],
                                predicted: &shared,
                            };
                            batch.update(margin, active, local, swept, &mut fat, &mut moved)
                        }
                        .unwrap();
                        let tight = |i: usize| {
                            let other = if frame % 2 == 0 {
                                at(i, &next[i])
                            } else {
                                local[i].transformed(&shared, method, rounding)
                            };
                            swept_union(at(i, &scene.poses[i]), other)
                        };
                        let expected = reference(tight, &subset, margin, &mut want);
                        assert_eq!(moved.indices(), &expected[..], "{what}");
                        for i in 0..n {
                            assert!(same3(&fat[i], &want[i]), "{what} {i}");
                            if !subset.contains(&i) {
                                assert!(same3(&fat[i], &before[i]), "{what}: {i} written");
                            }
                        }
                        // The transform takes the same route: the union, bit for bit.
                        if frame == 0 {
                            let swept = Swept {
                                current: &scene.poses[..],
                                predicted: &next[..],
                            };
                            let mut out = vec![Aabb3::EMPTY; n];
                            batch.transform(local, swept, &mut out).unwrap();
                            for (i, o) in out.iter().enumerate() {
                                assert!(same3(o, &tight(i)), "{what} transform {i}");
                            }
                        }
                        scene.poses = next;
                    }
                }
            }
        }
    }
}

// ---------------------------------------------------------------------------------------
// Large worlds.

/// A random `f64` position at `distance` from the origin, with every bit of its
/// significand used.
fn far_point(distance: f64, r: &mut StdRng) -> DVec3 {
    let dir = DVec3::new(
        r.random_range(-1.0..1.0),
        r.random_range(-1.0..1.0),
        r.random_range(-1.0..1.0),
    )
    .normalize_or(DVec3::X);
    dir * distance * r.random_range(0.5..1.0)
}

/// The exact box of `M·x + t − origin` over the corners of `local`, as exact faces.
fn exact_relative(
    cols: &[[Exact; 3]; 3],
    local: &Aabb3,
    t: DVec3,
    origin: DVec3,
) -> [[Exact; 3]; 2] {
    let mut lo: [Exact; 3] = core::array::from_fn(|_| Exact::PosInf);
    let mut hi: [Exact; 3] = core::array::from_fn(|_| Exact::NegInf);
    for c in local.corners() {
        for i in 0..3 {
            let mut v = Exact::of_f64(t[i]).add(&Exact::of_f64(origin[i]).neg());
            for j in 0..3 {
                v = v.add(&match &cols[j][i] {
                    Exact::Finite(_) => cols[j][i].mul_f32(c[j]),
                    _ => unreachable!(),
                });
            }
            if v < lo[i] {
                lo[i] = v.clone();
            }
            if v > hi[i] {
                hi[i] = v;
            }
        }
    }
    [lo, hi]
}

/// Checks containment exactly and tightness against a bound of the documented form.
fn check_large(
    b: &Aabb3,
    exact: &[[Exact; 3]; 2],
    local_magnitude: f64,
    offset: DVec3,
    what: &str,
) {
    for a in 0..3 {
        for (face, e, lower) in [
            (b.min[a], &exact[0][a], true),
            (b.max[a], &exact[1][a], false),
        ] {
            assert!(
                holds(face, e, lower),
                "{what}: axis {a} face {face} misses {}",
                e.to_f64()
            );
            let ulp = |x: f64| (x.abs() as f32).next_up() as f64 - x.abs() as f32 as f64;
            let allowed =
                16.0 * U * local_magnitude + ulp(offset[a]) + 2.0 * ulp(f64::from(face)) + 1e-37;
            let slack = (f64::from(face) - e.to_f64()).abs();
            assert!(
                slack <= allowed,
                "{what}: axis {a} face {face} is {slack} > {allowed} from the exact face"
            );
        }
    }
}

#[test]
fn large_world_boxes_contain_the_exact_image_from_1e6_to_1e12() {
    let mut r = rng(0x1a2e);
    let mut checked = 0;
    for distance in [1e6, 1e8, 1e10, 1e12] {
        for k in 0..150 {
            let class = [
                Class::Typical,
                Class::Drifted,
                Class::ZeroSize,
                Class::SignedZero,
            ][k % 4];
            let mut p = quat_problem(class, Scale::Unit, &mut r);
            p.t = [0.0; 3];
            let local = p.aabb();
            if !local.is_valid() || local.is_empty() || !p.all_finite() {
                continue;
            }
            let position = far_point(distance, &mut r);
            // The origin near the object (a region's center) or at the world origin.
            let origin = if k % 3 == 0 {
                DVec3::ZERO
            } else {
                position + far_point(500.0, &mut r)
            };
            let magnitude = p.rho()
                * (0..3)
                    .map(|j| f64::from(p.lo[j].abs().max(p.hi[j].abs())))
                    .sum::<f64>();
            let exact = exact_relative(&p.exact_cols(), &local, position, origin);
            let rigid = LargeRigid3::new(Quat::from_array(p.q), position);
            for method in METHODS {
                let what = format!("rigid at {distance:e} {method:?} {p:?} {position} {origin}");
                let b = rigid.relative_aabb(&local, origin, method);
                check_large(&b, &exact, magnitude, position - origin, &what);
                checked += 1;
            }
            // An affine pose with an f64 matrix that f32 cannot hold.
            let m = DMat3::from_cols_array(&core::array::from_fn(|i| {
                let c = p.exact_cols()[i / 3][i % 3].to_f64();
                c * (1.0 + r.random_range(-1e-9..1e-9))
            }));
            let affine = DAffine3::from_mat3_translation(m, position);
            let exact = exact_affine(m, &local, position, origin);
            let magnitude = (0..3)
                .map(|j| {
                    m.col(j).abs().max_element()
                        * f64::from(local.min[j].abs().max(local.max[j].abs()))
                })
                .sum::<f64>();
            for method in METHODS {
                let what =
                    format!("affine at {distance:e} {method:?} {m} {local:?} {position} {origin}");
                let b = affine.relative_aabb(&local, origin, method);
                check_large(&b, &exact, magnitude, position - origin, &what);
                checked += 1;
            }
        }
    }
    assert!(checked > 3000, "only {checked} large-world boxes checked");
}

/// The exact faces of an `f64` matrix times the corners (products of `f64` and `f32`).
fn exact_affine(m: DMat3, local: &Aabb3, t: DVec3, origin: DVec3) -> [[Exact; 3]; 2] {
    let mut lo: [Exact; 3] = core::array::from_fn(|_| Exact::PosInf);
    let mut hi: [Exact; 3] = core::array::from_fn(|_| Exact::NegInf);
    for c in local.corners() {
        for i in 0..3 {
            let mut v = Exact::of_f64(t[i]).add(&Exact::of_f64(origin[i]).neg());
            for j in 0..3 {
                v = v.add(&Exact::product_f64(m.col(j)[i], c[j]));
            }
            if v < lo[i] {
                lo[i] = v.clone();
            }
            if v > hi[i] {
                hi[i] = v;
            }
        }
    }
    [lo, hi]
}

#[test]
fn large_world_update_fattens_the_relative_box() {
    let mut r = rng(0x1a2f);
    let n = 50;
    let local: Vec<Aabb3> = (0..n)
        .map(|_| Aabb3::new(Vec3A::splat(-1.0), Vec3A::splat(1.0)))
        .collect();
    let mut poses: Vec<LargeRigid3> = (0..n)
        .map(|_| {
            LargeRigid3::new(
                Quat::from_rotation_y(r.random_range(-3.0..3.0)),
                far_point(1e11, &mut r),
            )
        })
        .collect();
    poses[7].position.x = f64::NAN;
    let origin = poses[0].position;
    let margin = Margin::new(0.25, 0.0);
    let mut fat = vec![Aabb3::EMPTY; n];
    let mut moved = Moved::new();
    for rounding in ROUNDINGS {
        let batch = Batch::new(Method::AbsMatrix, rounding);
        fat.fill(Aabb3::EMPTY);
        let world = LargeWorld {
            poses: &poses,
            origin,
        };
        batch
            .update(margin, Active::All, &local, world, &mut fat, &mut moved)
            .unwrap();
        assert_eq!(moved.len(), n);
        for i in 0..n {
            let tight = poses[i].relative_aabb(&local[i], origin, Method::AbsMatrix);
            assert!(
                same3(&fat[i], &tight.fattened(margin)),
                "{i}: {:?} {tight:?}",
                fat[i]
            );
            assert_eq!(fat[i].is_valid(), i != 7);
        }
        // A small step stays inside; the NaN pose is reported again.
        poses[3].position.y += 0.1;
        let world = LargeWorld {
            poses: &poses,
            origin,
        };
        batch
            .update(margin, Active::All, &local, world, &mut fat, &mut moved)
            .unwrap();
        assert_eq!(moved.indices(), &[7]);
    }
}

/// Local boxes of every kind an update must take, one AoSoA block of them: plain boxes, an
/// empty one, an unbounded one, one whose image overflows `f32`, a point, a far one, and
/// one with a NaN face (the only kind reported moved at every update).
fn standing_boxes() -> Vec<Aabb3> {
    let big = f32::MAX * 0.9;
    vec![
        Aabb3::new(Vec3A::splat(-1.0), Vec3A::splat(1.0)),
        Aabb3::EMPTY,
        Aabb3::new(Vec3A::new(f32::NEG_INFINITY, -1.0, -1.0), Vec3A::ONE),
        Aabb3::new(Vec3A::splat(-big), Vec3A::splat(big)),
        Aabb3::new(Vec3A::new(f32::NAN, -1.0, -1.0), Vec3A::ONE),
        Aabb3::new(Vec3A::splat(2.0), Vec3A::splat(3.0)),
        Aabb3::new(Vec3A::splat(5.0), Vec3A::splat(5.0)),
        Aabb3::new(Vec3A::splat(1e30), Vec3A::splat(2e30)),
    ]
}

/// Updates twice with the same poses, on every backend, for AoS and AoSoA boxes: the first
/// call writes every object (the fat boxes start NaN), the second only the NaN one.
fn check_unchanged_poses_move_nothing(
    what: &str,
    update: impl Fn(&Batch, bool, &[Aabb3], &mut Vec<Aabb3>, &mut Moved),
) {
    let local = standing_boxes();
    let nan_box = 4;
    for backend in Backend::supported() {
        for method in METHODS {
            for rounding in ROUNDINGS {
                for aosoa in [false, true] {
                    let batch = Batch::new(method, rounding).on(backend).unwrap();
                    let mut fat = vec![Aabb3::NAN; local.len()];
                    let mut moved = Moved::new();
                    update(&batch, aosoa, &local, &mut fat, &mut moved);
                    assert_eq!(moved.len(), local.len(), "{what}: first update");
                    let first = fat.clone();
                    update(&batch, aosoa, &local, &mut fat, &mut moved);
                    let how = format!("{what} {backend:?} {method:?} {rounding:?} aosoa {aosoa}");
                    assert_eq!(moved.indices(), &[nan_box as u32], "{how}: second update");
                    for i in 0..local.len() {
                        assert!(
                            i == nan_box || same3(&fat[i], &first[i]),
                            "{how}: {i} rewritten"
                        );
                    }
                }
            }
        }
    }
}

/// [`Batch::update`] with AoS or AoSoA local and fat boxes.
fn update_layout(
    batch: &Batch,
    aosoa: bool,
    local: &[Aabb3],
    poses: impl bvkit::PoseSource<3>,
    fat: &mut Vec<Aabb3>,
    moved: &mut Moved,
) {
    let margin = Margin::new(0.1, 0.2);
    if aosoa {
        let (l, mut f) = (Block8::pack(local), Block8::pack(fat));
        batch
            .update(margin, Active::All, &l[..], poses, &mut f[..], moved)
            .unwrap();
        *fat = Block8::unpack(&f, fat.len());
    } else {
        batch
            .update(margin, Active::All, local, poses, &mut fat[..], moved)
            .unwrap();
    }
}

#[test]
fn unchanged_poses_move_nothing_after_the_first_update() {
    let n = standing_boxes().len();
    let rigid = vec![Rigid3::new(Quat::from_rotation_z(0.5), Vec3A::X); n];
    let large = vec![LargeRigid3::new(Quat::from_rotation_z(0.5), DVec3::new(1e9, 0.0, 0.0)); n];
    let daffine = vec![DAffine3::from_rotation_z(0.5); n];
    let origin = DVec3::new(1e9 - 3.0, 0.0, 0.0);
    let world = LargeWorld {
        poses: &large[..],
        origin,
    };
    let dworld = LargeWorld {
        poses: &daffine[..],
        origin,
    };
    check_unchanged_poses_move_nothing("rigid3", |b, s, l, f, m| {
        update_layout(b, s, l, &rigid[..], f, m)
    });
    check_unchanged_poses_move_nothing("large rigid3", |b, s, l, f, m| {
        update_layout(b, s, l, world, f, m)
    });
    check_unchanged_poses_move_nothing("large daffine3", |b, s, l, f, m| {
        update_layout(b, s, l, dworld, f, m)
    });
    check_unchanged_poses_move_nothing("swept rigid3", |b, s, l, f, m| {
        let swept = Swept {
            current: &rigid[..],
            predicted: &rigid[..],
        };
        update_layout(b, s, l, swept, f, m)
    });
    check_unchanged_poses_move_nothing("swept large", |b, s, l, f, m| {
        update_layout(
            b,
            s,
            l,
            Swept {
                current: world,
                predicted: dworld,
            },
            f,
            m,
        )
    });
}

// ---------------------------------------------------------------------------------------
// Refusals.

#[test]
fn bad_input_is_refused_and_nothing_is_written() {
    let local = vec![Aabb3::new(Vec3A::ZERO, Vec3A::ONE); 100];
    let poses = vec![Rigid3::IDENTITY; 100];
    let batch = Batch::new(Method::AbsMatrix, Rounding::Outward);
    let mut fat = vec![Aabb3::EMPTY; 100];
    let mut moved = Moved::new();
    batch
        .update(
            Margin::ZERO,
            Active::Indices(&[1, 5]),
            &local,
            &poses,
            &mut fat,
            &mut moved,
        )
        .unwrap();
    let (fat0, moved0) = (fat.clone(), moved.clone());
    assert_eq!(moved0.indices(), &[1, 5]);

    let mut stray = vec![0u64; 2];
    stray[1] = 1 << 40; // object 104 of 100
    let cases: Vec<(Margin, Active<'_>, usize, usize)> = vec![
        (Margin::new(-1.0, 0.0), Active::All, 100, 100),
        (Margin::new(0.0, f32::NAN), Active::All, 100, 100),
        (Margin::new(f32::INFINITY, 0.0), Active::All, 100, 100),
        (Margin::ZERO, Active::All, 99, 100),
        (Margin::ZERO, Active::All, 100, 101),
        (Margin::ZERO, Active::Indices(&[3, 2]), 100, 100),
        (Margin::ZERO, Active::Indices(&[3, 3]), 100, 100),
        (Margin::ZERO, Active::Indices(&[100]), 100, 100),
        (Margin::ZERO, Active::Mask(&[u64::MAX]), 100, 100),
        (Margin::ZERO, Active::Mask(&stray), 100, 100),
    ];
    for (margin, active, n_poses, n_fat) in cases {
        let mut f = fat0[..].to_vec();
        f.resize(n_fat, Aabb3::EMPTY);
        let before = f.clone();
        let err = batch
            .update(
                margin,
                active,
                &local,
                &vec![Rigid3::IDENTITY; n_poses],
                &mut f,
                &mut moved,
            )
            .unwrap_err();
        assert!(!err.to_string().is_empty());
        assert!(
            matches!(
                err,
                BatchError::InvalidMargin(_)
                    | BatchError::InvalidActive(_)
                    | BatchError::LengthMismatch { .. }
            ),
            "{err:?}"
        );
        assert!(
            f.iter().zip(&before).all(|(a, b)| same3(a, b)),
            "{margin:?} {active:?}: written"
        );
        assert_eq!(moved, moved0, "{margin:?} {active:?}: moved set changed");
    }
    assert!(fat.iter().zip(&fat0).all(|(a, b)| same3(a, b)));
}

// ---------------------------------------------------------------------------------------
// The same pose sources through `Batch::transform`.

#[test]
fn transform_takes_swept_and_large_world_poses_as_the_update_does() {
    // One pose trait for both verbs: a swept pair gives the union of the boxes at its two
    // poses, bit for bit in deterministic mode (where every path gives the reference's
    // bits); large-world poses give each pose's relative box. Every backend, method and
    // rounding, AoS and AoSoA boxes, lengths across span and chunk edges.
    let mut r = rng(45);
    for n in [0, 1, 7, 17, 70] {
        let local: Vec<Aabb3> = (0..n)
            .map(|_| {
                let c = Vec3A::new(r.random(), r.random(), r.random()) * 4.0 - 2.0;
                Aabb3::new(c - 0.5, c + Vec3A::new(0.3, 0.7, 0.1))
            })
            .collect();
        let pose = |r: &mut StdRng| {
            let q = Quat::from_rotation_arc(
                Vec3A::X.into(),
                Vec3A::new(r.random(), 1.0, 0.5).normalize().into(),
            );
            Rigid3::new(q, Vec3A::new(r.random(), r.random(), r.random()) * 100.0)
        };
        let a: Vec<Rigid3> = (0..n).map(|_| pose(&mut r)).collect();
        let b: Vec<Rigid3> = (0..n).map(|_| pose(&mut r)).collect();
        let origin = DVec3::new(1e7, -3e6, 2.5e5);
        let large: Vec<LargeRigid3> = a
            .iter()
            .map(|p| LargeRigid3::new(p.rotation, origin + p.translation.as_dvec3()))
            .collect();
        for backend in Backend::supported() {
            for method in [Method::AbsMatrix, Method::SignSelect] {
                for rounding in [Rounding::Nearest, Rounding::Outward] {
                    let batch = Batch::new(method, rounding)
                        .on(backend)
                        .unwrap()
                        .deterministic();
                    let mut wa = vec![Aabb3::EMPTY; n];
                    let mut wb = vec![Aabb3::EMPTY; n];
                    let mut ws = vec![Aabb3::EMPTY; n];
                    batch.transform(&local, &a, &mut wa).unwrap();
                    batch.transform(&local, &b, &mut wb).unwrap();
                    let swept = Swept {
                        current: &a[..],
                        predicted: &b[..],
                    };
                    batch.transform(&local, swept, &mut ws).unwrap();
                    let (a8, b8) = (bvkit::Rigid3x8::pack(&a), bvkit::Rigid3x8::pack(&b));
                    let swept8 = Swept {
                        current: &a8[..],
                        predicted: &b8[..],
                    };
                    let mut w8 = vec![bvkit::Aabb3x8::default(); n.div_ceil(8)];
                    batch
                        .transform(&bvkit::Aabb3x8::pack(&local)[..], swept8, &mut w8[..])
                        .unwrap();
                    for k in 0..n {
                        let union = Aabb3::new(wa[k].min.min(wb[k].min), wa[k].max.max(wb[k].max));
                        assert_eq!(ws[k], union, "{backend:?} {method:?} {rounding:?} {k}");
                        assert_eq!(w8[k / 8].get(k % 8), union);
                    }
                    let world = LargeWorld {
                        poses: &large[..],
                        origin,
                    };
                    let mut wl = vec![Aabb3::EMPTY; n];
                    batch.transform(&local, world, &mut wl).unwrap();
                    for k in 0..n {
                        assert_eq!(wl[k], large[k].relative_aabb(&local[k], origin, method));
                        assert!(wl[k].contains_point(wa[k].min * 0.5 + wa[k].max * 0.5));
                    }
                }
            }
        }
    }
}
