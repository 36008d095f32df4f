//! The box types, the Mat4 entry points and the projective path.

use bvkit_support::oracle;

use bvkit::{Aabb2, Aabb3, Method, Rigid2, Rounding, TransformError};
use glam::{Affine2, Affine3A, Mat4, Quat, Vec2, Vec3, Vec3A};
use oracle::Exact;

fn unit_box() -> Aabb3 {
    Aabb3::new(Vec3A::new(-1.0, -2.0, -3.0), Vec3A::new(1.0, 2.0, 3.0))
}

#[test]
fn box_basics() {
    let b = unit_box();
    assert_eq!(b.center(), Vec3A::ZERO);
    assert_eq!(b.half_extents(), Vec3A::new(1.0, 2.0, 3.0));
    assert_eq!(b.volume(), 48.0);
    assert_eq!(
        Aabb3::from_center_half_extents(Vec3A::ZERO, Vec3A::new(1.0, 2.0, 3.0)),
        b
    );
    let corners = b.corners();
    assert_eq!(corners[0], b.min);
    assert_eq!(corners[7], b.max);
    assert_eq!(corners[1], Vec3A::new(1.0, -2.0, -3.0));
    assert_eq!(Aabb3::from_points(corners), b);
    assert!(corners.iter().all(|&c| b.contains_point(c)));
    assert!(!b.contains_point(Vec3A::new(0.0, 0.0, 3.5)));
    assert!(b.contains(&Aabb3::EMPTY));
    assert!(b.contains(&Aabb3::new(Vec3A::ZERO, Vec3A::ONE)));
    assert!(!b.contains(&Aabb3::new(Vec3A::ZERO, Vec3A::splat(2.0))));
    assert!(!b.contains(&Aabb3::NAN));
    assert_eq!(b.union(&Aabb3::EMPTY), b);
    assert_eq!(Aabb3::EMPTY.union(&b), b);
    assert_eq!(Aabb3::default(), Aabb3::EMPTY);
    assert_eq!(Aabb3::from_points([]), Aabb3::EMPTY);
    let far = Aabb3::new(Vec3A::splat(3e38), Vec3A::splat(3.2e38));
    assert!(far.center().is_finite(), "center must not overflow");
}

#[test]
fn emptiness_and_validity() {
    assert!(Aabb3::EMPTY.is_empty() && Aabb3::EMPTY.is_valid());
    assert_eq!(Aabb3::EMPTY.volume(), 0.0);
    assert!(!Aabb3::NAN.is_valid() && !Aabb3::NAN.is_empty());
    let inverted = Aabb3::new(Vec3A::new(0.0, 1.0, 0.0), Vec3A::new(1.0, 0.0, 1.0));
    assert!(inverted.is_empty());
    let at_infinity = Aabb3::new(
        Vec3A::new(f32::INFINITY, 0.0, 0.0),
        Vec3A::new(f32::INFINITY, 1.0, 1.0),
    );
    assert!(at_infinity.is_empty(), "no real point has x = +inf");
    let unbounded = Aabb3::new(Vec3A::NEG_INFINITY, Vec3A::INFINITY);
    assert!(!unbounded.is_empty() && unbounded.volume() == f32::INFINITY);
    let point = Aabb3::new(Vec3A::ONE, Vec3A::ONE);
    assert!(!point.is_empty() && point.volume() == 0.0);
    let flat = Aabb2::new(Vec2::ZERO, Vec2::new(2.0, 0.0));
    assert!(!flat.is_empty() && flat.area() == 0.0);
    assert_eq!(Aabb2::new(Vec2::ZERO, Vec2::new(2.0, 3.0)).area(), 6.0);
    assert_eq!(
        Aabb2::new(Vec2::ZERO, Vec2::ONE).corners()[2],
        Vec2::new(0.0, 1.0)
    );
}

#[test]
fn rigid2_matches_its_affine_form() {
    let r = Rigid2::from_angle_translation(0.7, Vec2::new(3.0, -4.0));
    let a = r.to_affine2();
    let p = Vec2::new(1.5, -2.5);
    assert!((r.transform_point(p) - a.transform_point2(p)).length() < 1e-5);
    assert_eq!(Rigid2::from_angle(0.0), Rigid2::IDENTITY);
    let b = Aabb2::new(Vec2::new(-1.0, -2.0), Vec2::new(1.0, 2.0));
    for method in Method::ALL {
        for rounding in Rounding::ALL {
            let rigid = b.transformed_rigid(&r, method, rounding);
            let affine = b.transformed(&a, method, rounding);
            assert!(
                (rigid.min - affine.min).abs().max_element() < 1e-5,
                "{method:?} {rounding:?}"
            );
            assert!(
                (rigid.max - affine.max).abs().max_element() < 1e-5,
                "{method:?} {rounding:?}"
            );
        }
    }
}

#[test]
fn mat4_affine_matches_affine3a() {
    let xf = Affine3A::from_scale_rotation_translation(
        Vec3::new(2.0, 0.5, 3.0),
        Quat::from_euler(glam::EulerRot::XYZ, 0.3, -1.1, 2.0),
        Vec3::new(10.0, -20.0, 30.0),
    );
    let m = Mat4::from(xf);
    for method in Method::ALL {
        for rounding in Rounding::ALL {
            let expected = unit_box().transformed(&xf, method, rounding);
            assert_eq!(
                unit_box().try_transformed_mat4(&m, method, rounding),
                Ok(expected)
            );
        }
    }
}

#[test]
fn mat4_rejects_projective_and_non_finite() {
    let projective = glam::camera::rh::proj::directx::perspective(1.0, 1.5, 0.1, 100.0);
    let err = unit_box().try_transformed_mat4(&projective, Method::SignSelect, Rounding::Outward);
    assert_eq!(
        err,
        Err(TransformError::NotAffine {
            last_row: [0.0, 0.0, -1.0, 0.0]
        })
    );
    let mut nan = Mat4::IDENTITY;
    nan.y_axis.x = f32::NAN;
    assert_eq!(
        unit_box().try_transformed_mat4(&nan, Method::Naive, Rounding::Nearest),
        Err(TransformError::NonFiniteMatrix)
    );
    let mut inf = Mat4::IDENTITY;
    inf.w_axis.z = f32::INFINITY;
    assert_eq!(
        unit_box().transformed_projective(&inf),
        Err(TransformError::NonFiniteMatrix)
    );
    assert!(!err.unwrap_err().to_string().is_empty());
}

/// The projective result contains every exactly projected corner, and is within two f32
/// ulps of the extreme corners.
#[test]
fn projective_contains_exact_corners() {
    let view = glam::camera::rh::view::look_at_mat4(Vec3::new(3.0, 4.0, 20.0), Vec3::ZERO, Vec3::Y);
    let m = glam::camera::rh::proj::directx::perspective(1.0, 1.5, 0.1, 100.0) * view;
    let mut rng_state = 0x2545_f491_u32;
    let mut next = || {
        rng_state ^= rng_state << 13;
        rng_state ^= rng_state >> 17;
        rng_state ^= rng_state << 5;
        (rng_state as f32 / u32::MAX as f32) * 2.0 - 1.0
    };
    for _ in 0..500 {
        let c = Vec3A::new(next(), next(), next()) * 5.0;
        let e = Vec3A::new(next(), next(), next()).abs() * 3.0;
        let b = Aabb3::from_center_half_extents(c, e);
        let out = b.transformed_projective(&m).expect("in front of the eye");
        let rows: [[f32; 4]; 4] = core::array::from_fn(|i| m.row(i).to_array());
        let mut closest_lo = [f64::INFINITY; 3];
        let mut closest_hi = [f64::NEG_INFINITY; 3];
        for corner in b.corners() {
            let p = [corner.x, corner.y, corner.z, 1.0];
            let w = Exact::dot(&rows[3], &p);
            for i in 0..3 {
                let n = Exact::dot(&rows[i], &p);
                assert!(Exact::face_le_ratio(out.min[i], &n, &w));
                assert!(
                    !Exact::face_le_ratio(out.max[i], &n, &w)
                        || Exact::face_ge_ratio(out.max[i], &n, &w)
                );
                let q = n.to_f64() / w.to_f64();
                closest_lo[i] = closest_lo[i].min(q);
                closest_hi[i] = closest_hi[i].max(q);
            }
        }
        for i in 0..3 {
            let ulp = |x: f64| f64::from((x as f32).abs().next_up() - (x as f32).abs());
            assert!(f64::from(out.min[i]) >= closest_lo[i] - 2.0 * ulp(closest_lo[i]));
            assert!(f64::from(out.max[i]) <= closest_hi[i] + 2.0 * ulp(closest_hi[i]));
        }
    }
}

#[test]
fn projective_rejects_points_behind_the_eye() {
    let m = glam::camera::rh::proj::directx::perspective(1.0, 1.5, 0.1, 100.0);
    // Eye at the origin looking down -z: a box reaching z > 0 has corners with w <= 0.
    let b = Aabb3::new(Vec3A::new(-1.0, -1.0, -5.0), Vec3A::new(1.0, 1.0, 1.0));
    assert!(matches!(
        b.transformed_projective(&m),
        Err(TransformError::NonPositiveW { .. })
    ));
    let on_plane = Aabb3::new(Vec3A::new(-1.0, -1.0, -5.0), Vec3A::new(1.0, 1.0, 0.0));
    assert!(matches!(
        on_plane.transformed_projective(&m),
        Err(TransformError::NonPositiveW { .. })
    ));
    assert_eq!(Aabb3::EMPTY.transformed_projective(&m), Ok(Aabb3::EMPTY));
    assert!(!Aabb3::NAN.transformed_projective(&m).unwrap().is_valid());
    let unbounded = Aabb3::new(
        Vec3A::new(-1.0, -1.0, f32::NEG_INFINITY),
        Vec3A::new(1.0, 1.0, -1.0),
    );
    assert_eq!(
        unbounded.transformed_projective(&m),
        Err(TransformError::UnboundedProjective)
    );
    // An affine Mat4 is a projective map with w = 1.
    let affine = Mat4::from_translation(Vec3::new(1.0, 2.0, 3.0));
    let moved = unit_box().transformed_projective(&affine).unwrap();
    let exact = Aabb3::new(Vec3A::new(0.0, 0.0, 0.0), Vec3A::new(2.0, 4.0, 6.0));
    assert!(moved.contains(&exact));
    // Outward by at most one f32 ulp (plus the f64 interval's width below zero).
    assert!((moved.max - exact.max).max_element() <= 6.0 * f32::EPSILON);
    assert!((exact.min - moved.min).max_element() <= 1e-14);
}

#[test]
fn affine2_entry_point() {
    let xf = Affine2::from_angle_translation(core::f32::consts::FRAC_PI_2, Vec2::new(5.0, 0.0));
    let b = Aabb2::new(Vec2::new(0.0, 0.0), Vec2::new(2.0, 1.0));
    let out = b.transformed(&xf, Method::SignSelect, Rounding::Outward);
    assert!(out.contains(&Aabb2::new(Vec2::new(4.0, 0.0), Vec2::new(5.0, 2.0))));
    assert!((out.min - Vec2::new(4.0, 0.0)).abs().max_element() < 1e-5);
}

#[test]
fn rigid3_columns_read_like_the_slice() {
    use bvkit::{Batch, Rigid3, Rigid3Soa, Rigid3SoaRef};
    let local: Vec<Aabb3> = (0..11)
        .map(|i| Aabb3::new(Vec3A::splat(-1.0 - i as f32), Vec3A::splat(0.5 + i as f32)))
        .collect();
    let poses: Vec<Rigid3> = (0..11)
        .map(|i| {
            let q = Quat::from_rotation_y(0.3 * i as f32);
            Rigid3::new(q, Vec3A::new(i as f32, -2.0, 0.5))
        })
        .collect();
    // Deterministic: every layout gives the scalar reference's bits (by default the AoS
    // path runs the single-box kernel, the columns the lanes, which may fuse).
    let batch = Batch::new(Method::AbsMatrix, Rounding::Outward).deterministic();
    let mut from_slice = vec![Aabb3::EMPTY; local.len()];
    batch.transform(&local, &poses, &mut from_slice).unwrap();
    let columns: Rigid3Soa = Rigid3Soa::from_slice(&poses);
    let view: Rigid3SoaRef<'_> = columns.view();
    let mut from_columns = vec![Aabb3::EMPTY; local.len()];
    batch.transform(&local, view, &mut from_columns).unwrap();
    assert_eq!(from_columns, from_slice);
    assert!(from_slice.iter().all(|b| b.is_valid() && !b.is_empty()));
}

/// The README, the guide and the crate docs say exactly which calls panic: the element
/// accessors on an index out of range, as slice indexing does, and nothing else.
#[test]
fn the_docs_name_every_panic_of_the_api() {
    use bvkit::{Aabb3x8, Block8, Soa};
    use std::panic::{AssertUnwindSafe, catch_unwind};
    let panics = |f: &mut dyn FnMut()| catch_unwind(AssertUnwindSafe(f)).is_err();
    let mut block: Aabb3x8 = Block8::splat(unit_box());
    let soa = Soa::from_slice(&[unit_box(); 3]);
    let soa_get = panics(&mut || {
        let _ = soa.get(3);
    });
    let block_get = panics(&mut || {
        let _ = block.get(8);
    });
    let block_set = panics(&mut || block.set(8, unit_box()));
    let accessors = [
        ("Soa::get", soa_get),
        ("Block8::get", block_get),
        ("Block8::set", block_set),
    ];
    assert!(!panics(&mut || {
        let _ = (soa.get(2), block.get(7));
    }));
    let docs = [
        ("README.md", include_str!("../README.md")),
        ("docs/guide.md", include_str!("../docs/guide.md")),
        ("src/lib.rs", include_str!("../src/lib.rs")),
    ];
    for (name, text) in docs {
        let text = text
            .replace("//!", "")
            .split_whitespace()
            .collect::<Vec<_>>()
            .join(" ");
        assert!(
            !text.contains("Nothing panics"),
            "{name} says nothing panics"
        );
        for (accessor, panicked) in accessors {
            assert!(panicked, "{accessor} out of range did not panic");
            assert!(
                text.contains(accessor),
                "{name} does not name the panic of {accessor}"
            );
        }
    }
}
