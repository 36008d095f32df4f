//! Fitted volumes through transforms, judged exactly: the world AABB of every volume
//! ([`BoundingVolume::transformed_aabb`]) under every 3D class × rounding over every extreme
//! class of inputs, the batch entry point against the single calls, and the images under
//! similarities ([`Obb3::transformed`], …). The exact judgement (rational corners, faces
//! `C + k·√N` compared exactly) is `support/src/volumes/world.rs`, shared with the fuzz targets.
#![allow(clippy::needless_range_loop)]

use bvkit_support::cases;
use bvkit_support::oracle;
use bvkit_support::volumes;

use bvkit::{
    Aabb3, BatchError, BoundingVolume, Capsule, Obb3, Rigid3, Rounding, Similarity3, Transform3,
    Translation3, Trs3,
};
use glam::{Affine3A, Mat3A, Quat, Vec3A};
use rand::RngExt;
use rand::rngs::StdRng;

use bvkit::Sphere;
use cases::{Class, Scale, problem, quat_problem, rng, translation_problem};
use oracle::{QuatProblem, affine3};
use volumes::world::*;

/// A volume built from a problem's box.
trait FromBox: Volume {
    fn from_box(lo: Vec3A, hi: Vec3A, r: &mut StdRng) -> Self;
}

fn random_rotation(r: &mut StdRng) -> Mat3A {
    let q = Quat::from_xyzw(
        r.random_range(-1.0..1.0),
        r.random_range(-1.0..1.0),
        r.random_range(-1.0..1.0),
        r.random_range(-1.0..1.0),
    );
    let q = if q.length_squared() > 1e-3 {
        q.normalize()
    } else {
        Quat::IDENTITY
    };
    Mat3A::from_quat(q)
}

impl FromBox for Obb3 {
    fn from_box(lo: Vec3A, hi: Vec3A, r: &mut StdRng) -> Self {
        let rotation = if r.random_range(0..4) == 0 {
            Mat3A::IDENTITY
        } else {
            random_rotation(r)
        };
        Obb3 {
            center: lo,
            half_extents: (hi - lo) * 0.5,
            rotation,
        }
    }
}

impl FromBox for Sphere {
    fn from_box(lo: Vec3A, hi: Vec3A, _: &mut StdRng) -> Self {
        Sphere {
            center: hi,
            radius: (hi.x - lo.x) * 0.5,
        }
    }
}

impl FromBox for Capsule {
    fn from_box(lo: Vec3A, hi: Vec3A, _: &mut StdRng) -> Self {
        Capsule {
            a: lo,
            b: hi,
            radius: (hi.y - lo.y) * 0.5,
        }
    }
}

// ---------------------------------------------------------------- classes

/// A transform class under test: a random problem of an extreme class, as bvkit's map
/// and the oracle's exact map (`None` when non-finite).
trait Case: Transform3 + Copy + core::fmt::Debug {
    const NAME: &'static str;
    /// The transform, its exact map, and a box of the class for the volume.
    fn make(class: Class, r: &mut StdRng) -> (Self, Option<XMap>, Vec3A, Vec3A);
}

fn quat_case(
    class: Class,
    scale: Scale,
    r: &mut StdRng,
) -> (QuatProblem, Option<XMap>, Vec3A, Vec3A) {
    let p = quat_problem(class, scale, r);
    let map = finite_map(&p);
    (p, map, Vec3A::from_array(p.lo), Vec3A::from_array(p.hi))
}

impl Case for Translation3 {
    const NAME: &'static str = "translation";
    fn make(class: Class, r: &mut StdRng) -> (Self, Option<XMap>, Vec3A, Vec3A) {
        let p = translation_problem::<3>(class, r);
        let xf = Translation3(Vec3A::from_array(p.t));
        (
            xf,
            finite_map(&p),
            Vec3A::from_array(p.lo),
            Vec3A::from_array(p.hi),
        )
    }
}

impl Case for Rigid3 {
    const NAME: &'static str = "rigid";
    fn make(class: Class, r: &mut StdRng) -> (Self, Option<XMap>, Vec3A, Vec3A) {
        let (p, map, lo, hi) = quat_case(class, Scale::Unit, r);
        (p.rigid3(), map, lo, hi)
    }
}

impl Case for Similarity3 {
    const NAME: &'static str = "similarity";
    fn make(class: Class, r: &mut StdRng) -> (Self, Option<XMap>, Vec3A, Vec3A) {
        let (p, map, lo, hi) = quat_case(class, Scale::Uniform, r);
        (p.similarity3(), map, lo, hi)
    }
}

impl Case for Trs3 {
    const NAME: &'static str = "trs";
    fn make(class: Class, r: &mut StdRng) -> (Self, Option<XMap>, Vec3A, Vec3A) {
        let (p, map, lo, hi) = quat_case(class, Scale::PerAxis, r);
        (p.trs3(), map, lo, hi)
    }
}

impl Case for Affine3A {
    const NAME: &'static str = "affine";
    fn make(class: Class, r: &mut StdRng) -> (Self, Option<XMap>, Vec3A, Vec3A) {
        let p = problem::<3>(class, r);
        let (b, xf) = affine3(&p);
        (xf, finite_map(&p), b.min, b.max)
    }
}

const CASES_PER_CLASS: usize = 12;

/// Every extreme class × rounding for one volume type and one transform class.
fn world_aabbs_hold<V: FromBox, T: Case>(seed: u64) {
    let mut r = rng(seed);
    for class in Class::ALL {
        for n in 0..CASES_PER_CLASS {
            let (xf, map, lo, hi) = T::make(class, &mut r);
            let v = V::from_box(lo, hi, &mut r);
            for rounding in Rounding::ALL {
                let result = v.transformed_aabb(&xf, rounding);
                if let Err(e) = check(&v, map.as_ref(), result, rounding) {
                    panic!(
                        "{} {class:?} #{n} {rounding:?}: {e}\n  volume {v:?}\n  map {xf:?}\n  result {result:?}",
                        T::NAME
                    );
                }
            }
        }
    }
}

macro_rules! world_tests {
    ($($name:ident: $v:ty, $t:ty, $seed:expr;)*) => {$(
        #[test]
        fn $name() {
            world_aabbs_hold::<$v, $t>($seed);
        }
    )*};
}

world_tests! {
    obb_translation: Obb3, Translation3, 1;
    obb_rigid: Obb3, Rigid3, 2;
    obb_similarity: Obb3, Similarity3, 3;
    obb_trs: Obb3, Trs3, 4;
    obb_affine: Obb3, Affine3A, 5;
    sphere_translation: Sphere, Translation3, 6;
    sphere_rigid: Sphere, Rigid3, 7;
    sphere_similarity: Sphere, Similarity3, 8;
    sphere_trs: Sphere, Trs3, 9;
    sphere_affine: Sphere, Affine3A, 10;
    capsule_translation: Capsule, Translation3, 11;
    capsule_rigid: Capsule, Rigid3, 12;
    capsule_similarity: Capsule, Similarity3, 13;
    capsule_trs: Capsule, Trs3, 14;
    capsule_affine: Capsule, Affine3A, 15;
}

// ---------------------------------------------------------------- batches and bad input

/// Bit patterns of a box, so that NaN results compare too.
fn bits(b: &Aabb3) -> [u32; 6] {
    let (l, h) = (b.min.to_array(), b.max.to_array());
    [l[0], l[1], l[2], h[0], h[1], h[2]].map(f32::to_bits)
}

/// The batch entry point equals the single calls bitwise, per transform and shared, and
/// checks its lengths before writing anything.
fn batch_matches<V: FromBox, T: Case>(seed: u64) {
    let mut r = rng(seed);
    let (mut volumes, mut xfs) = (Vec::new(), Vec::new());
    for class in Class::ALL {
        for _ in 0..3 {
            let (xf, _, lo, hi) = T::make(class, &mut r);
            volumes.push(V::from_box(lo, hi, &mut r));
            xfs.push(xf);
        }
    }
    let n = volumes.len();
    let sentinel = Aabb3::new(Vec3A::splat(7.0), Vec3A::splat(-7.0));
    for rounding in Rounding::ALL {
        let mut out = vec![sentinel; n];
        V::transformed_aabbs(&volumes, &xfs[..], &mut out, rounding).unwrap();
        let mut shared = vec![sentinel; n];
        V::transformed_aabbs(&volumes, &xfs[5], &mut shared, rounding).unwrap();
        for k in 0..n {
            assert_eq!(
                bits(&out[k]),
                bits(&volumes[k].transformed_aabb(&xfs[k], rounding))
            );
            assert_eq!(
                bits(&shared[k]),
                bits(&volumes[k].transformed_aabb(&xfs[5], rounding))
            );
        }
        let mut short = vec![sentinel; n - 1];
        assert_eq!(
            V::transformed_aabbs(&volumes, &xfs[..], &mut short, rounding),
            Err(BatchError::LengthMismatch {
                what: "output",
                expected: n,
                found: n - 1
            })
        );
        let mut untouched = vec![sentinel; n];
        assert_eq!(
            V::transformed_aabbs(&volumes, &xfs[1..], &mut untouched, rounding),
            Err(BatchError::LengthMismatch {
                what: "transforms",
                expected: n,
                found: n - 1
            })
        );
        assert!(short.iter().chain(&untouched).all(|b| *b == sentinel));
    }
}

#[test]
fn batches_equal_single_calls() {
    batch_matches::<Obb3, Rigid3>(21);
    batch_matches::<Obb3, Affine3A>(22);
    batch_matches::<Sphere, Translation3>(23);
    batch_matches::<Sphere, Similarity3>(24);
    batch_matches::<Capsule, Trs3>(25);
    batch_matches::<Capsule, Affine3A>(26);
}

#[test]
fn bad_input_follows_the_contract() {
    let pose = Rigid3::new(Quat::from_rotation_z(0.5), Vec3A::new(1.0, 2.0, 3.0));
    let obb = Obb3 {
        center: Vec3A::ONE,
        half_extents: Vec3A::new(1.0, 2.0, 3.0),
        rotation: Mat3A::from_rotation_x(0.3),
    };
    let sphere = Sphere {
        center: Vec3A::ONE,
        radius: 2.0,
    };
    let capsule = Capsule {
        a: Vec3A::ZERO,
        b: Vec3A::X,
        radius: 1.0,
    };
    let everywhere = Aabb3::new(Vec3A::NEG_INFINITY, Vec3A::INFINITY);
    let nan_pose = Rigid3::new(Quat::from_xyzw(f32::NAN, 0.0, 0.0, 1.0), Vec3A::ZERO);
    let inf_pose = Affine3A::from_translation(glam::Vec3::new(f32::INFINITY, 0.0, 0.0));
    for rounding in Rounding::ALL {
        {
            let v = obb;
            assert!(!v.transformed_aabb(&nan_pose, rounding).is_valid());
            assert!(!v.transformed_aabb(&inf_pose, rounding).is_valid());
            let nan = Obb3 {
                center: Vec3A::new(0.0, f32::NAN, 0.0),
                ..v
            };
            assert!(!nan.transformed_aabb(&pose, rounding).is_valid());
            let empty = Obb3 {
                half_extents: Vec3A::new(1.0, -1.0, 1.0),
                ..v
            };
            assert_eq!(empty.transformed_aabb(&pose, rounding), Aabb3::EMPTY);
            let unbounded = Obb3 {
                half_extents: Vec3A::new(1.0, f32::INFINITY, 1.0),
                ..v
            };
            assert_eq!(unbounded.transformed_aabb(&pose, rounding), everywhere);
            let singular = Obb3 {
                rotation: Mat3A::ZERO,
                ..v
            };
            assert_eq!(singular.transformed_aabb(&pose, rounding), everywhere);
        }
        {
            let v = sphere;
            assert!(!v.transformed_aabb(&nan_pose, rounding).is_valid());
            assert!(!v.transformed_aabb(&inf_pose, rounding).is_valid());
            let nan = Sphere {
                radius: f32::NAN,
                ..v
            };
            assert!(!nan.transformed_aabb(&pose, rounding).is_valid());
            let empty = Sphere { radius: -1.0, ..v };
            assert_eq!(empty.transformed_aabb(&pose, rounding), Aabb3::EMPTY);
            let far = Sphere {
                center: Vec3A::splat(3e38),
                radius: 1e38,
            };
            // Faces at 2e39 and 4e39: +inf, or f32::MAX for an Outward lower face.
            let big = Similarity3::new(10.0, Quat::IDENTITY, Vec3A::ZERO);
            let b = far.transformed_aabb(&big, rounding);
            assert_eq!(b.max, Vec3A::INFINITY);
            assert!(b.min.cmpge(Vec3A::splat(f32::MAX)).all(), "{b:?}");
        }
        {
            let v = capsule;
            assert!(!v.transformed_aabb(&nan_pose, rounding).is_valid());
            let nan = Capsule { b: Vec3A::NAN, ..v };
            assert!(!nan.transformed_aabb(&pose, rounding).is_valid());
            let empty = Capsule { radius: -0.5, ..v };
            assert_eq!(empty.transformed_aabb(&pose, rounding), Aabb3::EMPTY);
            let unbounded = Capsule {
                a: Vec3A::NEG_INFINITY,
                ..v
            };
            assert_eq!(unbounded.transformed_aabb(&pose, rounding), everywhere);
        }
    }
}

// ---------------------------------------------------------------- images under similarities

/// A similarity (`Rigid3` when `rigid`) of an extreme class, its exact map (`None` when
/// non-finite), `|σ|` and a box of the class.
fn similarity(
    class: Class,
    rigid: bool,
    r: &mut StdRng,
) -> (Similarity3, Option<XMap>, Vec3A, Vec3A) {
    let scale = if rigid { Scale::Unit } else { Scale::Uniform };
    let (p, map, lo, hi) = quat_case(class, scale, r);
    let xf = if rigid {
        p.rigid3().into()
    } else {
        p.similarity3()
    };
    (xf, map, lo, hi)
}

/// Every image holds the exact images of the volume's extreme points (the box's corners,
/// points of the balls' spheres), over every extreme class, rigid and similar.
#[test]
fn images_hold_the_exact_images() {
    let mut r = rng(31);
    let dirs = unit_directions();
    let mut checked = 0;
    for class in Class::ALL {
        for n in 0..CASES_PER_CLASS {
            for rigid in [true, false] {
                let (xf, map, lo, hi) = similarity(class, rigid, &mut r);
                let (obb, sphere, capsule) = (
                    Obb3::from_box(lo, hi, &mut r),
                    Sphere::from_box(lo, hi, &mut r),
                    Capsule::from_box(lo, hi, &mut r),
                );
                let context = format!("{class:?} #{n} rigid {rigid}: {xf:?}");
                checked += check_images(xf, map.as_ref(), &obb, &sphere, &capsule, &dirs, &context);
            }
        }
    }
    assert!(checked > 600, "only {checked} finite images checked");
}

/// For unit quaternions and orthonormal axes the images are tight: the half-extents and
/// radii exceed `|σ|` times the old ones by about the rounding of the moved center.
#[test]
fn images_are_tight() {
    let mut r = rng(32);
    for class in [
        Class::Typical,
        Class::Far,
        Class::Reflection,
        Class::ZeroSize,
    ] {
        for _ in 0..50 {
            let (xf, _, lo, hi) = similarity(class, false, &mut r);
            let sigma = xf.scale.abs();
            let slack = |c: Vec3A, size: f32| {
                2f32.powi(-18) * (c.abs().element_sum() + sigma * size) + 1e-30
            };
            let obb = Obb3::from_box(lo, hi, &mut r);
            let o = obb.transformed(xf);
            for k in 0..3 {
                let bound =
                    sigma * obb.half_extents[k] + slack(o.center, obb.half_extents.element_sum());
                assert!(o.half_extents[k] <= bound, "{obb:?} -> {o:?} under {xf:?}");
            }
            let sphere = Sphere::from_box(lo, hi, &mut r);
            let s = sphere.transformed(xf);
            assert!(
                s.radius <= sigma * sphere.radius + slack(s.center, sphere.radius),
                "{s:?}"
            );
            let capsule = Capsule::from_box(lo, hi, &mut r);
            let c = capsule.transformed(xf);
            let reach = c.a.abs().max(c.b.abs());
            assert!(
                c.radius <= sigma * capsule.radius + slack(reach, capsule.radius),
                "{c:?}"
            );
        }
    }
}
