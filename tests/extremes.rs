//! Named extreme inputs with their documented values, for every method, rounding and path.

use bvkit::{Aabb2, Aabb3, Method, Rigid2, Rounding};
use glam::{Affine2, Affine3A, Mat3, Quat, Vec2, Vec3, Vec3A, Vec3Swizzles};

/// Every (method, rounding, path) result of one 3D box.
fn all3(b: Aabb3, xf: &Affine3A) -> Vec<(String, Aabb3)> {
    let mut out = Vec::new();
    for method in Method::ALL {
        for rounding in Rounding::ALL {
            out.push((
                format!("{method:?} {rounding:?} simd"),
                b.transformed(xf, method, rounding),
            ));
            out.push((
                format!("{method:?} {rounding:?} scalar"),
                b.transformed_scalar(xf, method, rounding),
            ));
        }
    }
    out
}

/// Every (method, rounding, transform kind) result of one 2D box.
fn all2(b: Aabb2, xf: &Rigid2) -> Vec<(String, Aabb2)> {
    let mut out = Vec::new();
    for method in Method::ALL {
        for rounding in Rounding::ALL {
            out.push((
                format!("{method:?} {rounding:?} rigid"),
                b.transformed_rigid(xf, method, rounding),
            ));
            out.push((
                format!("{method:?} {rounding:?} affine"),
                b.transformed(&xf.to_affine2(), method, rounding),
            ));
        }
    }
    out
}

fn pose() -> Affine3A {
    Affine3A::from_rotation_translation(
        Quat::from_euler(glam::EulerRot::ZYX, 0.4, 0.5, 0.6),
        Vec3::new(1.0, 2.0, 3.0),
    )
}

#[test]
fn empty_in_gives_empty_out() {
    let inverted = Aabb3::new(Vec3A::new(0.0, 1.0, 0.0), Vec3A::new(1.0, 0.0, 1.0));
    let at_infinity = Aabb3::new(Vec3A::new(0.0, f32::INFINITY, 0.0), Vec3A::INFINITY);
    for b in [Aabb3::EMPTY, inverted, at_infinity] {
        for (name, out) in all3(b, &pose()) {
            assert_eq!(out, Aabb3::EMPTY, "{name} for {b:?}");
        }
    }
    for (name, out) in all2(Aabb2::EMPTY, &Rigid2::from_angle(1.0)) {
        assert_eq!(out, Aabb2::EMPTY, "{name}");
    }
}

#[test]
fn nan_anywhere_gives_an_invalid_box() {
    let b = Aabb3::new(Vec3A::ZERO, Vec3A::ONE);
    let nan_box = Aabb3::new(Vec3A::new(0.0, f32::NAN, 0.0), Vec3A::ONE);
    let mut nan_pose = pose();
    nan_pose.matrix3.z_axis.y = f32::NAN;
    let mut nan_translation = pose();
    nan_translation.translation.x = f32::NAN;
    for (b, xf) in [
        (nan_box, pose()),
        (b, nan_pose),
        (b, nan_translation),
        (Aabb3::EMPTY, nan_pose),
    ] {
        for (name, out) in all3(b, &xf) {
            assert!(!out.is_valid(), "{name} gave {out:?}");
        }
    }
    let r = Rigid2::new(f32::NAN, 0.0, Vec2::ZERO);
    for (name, out) in all2(Aabb2::new(Vec2::ZERO, Vec2::ONE), &r) {
        assert!(!out.is_valid(), "{name} gave {out:?}");
    }
}

#[test]
fn infinite_matrix_entries_give_an_invalid_box() {
    let mut xf = pose();
    xf.matrix3.x_axis.x = f32::INFINITY;
    for (name, out) in all3(Aabb3::new(Vec3A::ZERO, Vec3A::ONE), &xf) {
        assert!(!out.is_valid(), "{name} gave {out:?}");
    }
}

#[test]
fn overflow_gives_infinities_never_nan() {
    let b = Aabb3::new(Vec3A::splat(1e38), Vec3A::splat(2e38));
    let scale = Affine3A::from_scale(Vec3::splat(10.0));
    for (name, out) in all3(b, &scale) {
        assert!(out.is_valid(), "{name}");
        assert_eq!(out.max, Vec3A::INFINITY, "{name}");
        if name.contains("Outward") {
            // The exact minimum, 1e39, is beyond the range: the largest f32 below it.
            assert_eq!(out.min, Vec3A::splat(f32::MAX), "{name}");
        } else {
            assert_eq!(out.min, Vec3A::INFINITY, "{name}");
        }
    }
    // A rotated huge box: products overflow with both signs, and inf - inf must not leak.
    let huge = Aabb3::new(Vec3A::splat(-3e38), Vec3A::splat(3e38));
    for (name, out) in all3(huge, &(Affine3A::from_scale(Vec3::splat(4.0)) * pose())) {
        assert!(out.is_valid() && !out.is_empty(), "{name} gave {out:?}");
        assert!(out.contains(&huge), "{name} gave {out:?}");
    }
}

#[test]
fn unbounded_faces_stay_exact_where_entries_are_zero() {
    // A quarter turn about x: x' = x, y' = -z, z' = y, with exact zeros elsewhere.
    let turn = Affine3A::from_mat3_translation(
        Mat3::from_cols(Vec3::X, Vec3::Z, -Vec3::Y),
        Vec3::new(0.0, 10.0, 20.0),
    );
    let b = Aabb3::new(
        Vec3A::new(f32::NEG_INFINITY, 1.0, 2.0),
        Vec3A::new(f32::INFINITY, 3.0, 5.0),
    );
    for (name, out) in all3(b, &turn) {
        assert_eq!(out.min.x, f32::NEG_INFINITY, "{name}");
        assert_eq!(out.max.x, f32::INFINITY, "{name}");
        let exact = Aabb3::new(Vec3A::new(0.0, 5.0, 21.0), Vec3A::new(0.0, 8.0, 23.0));
        assert!(
            out.min.y <= exact.min.y && out.max.y >= exact.max.y || name.contains("Nearest"),
            "{name}"
        );
        assert!(
            (out.min.yz() - exact.min.yz()).abs().max_element() < 1e-4,
            "{name} gave {out:?}"
        );
        assert!(
            (out.max.yz() - exact.max.yz()).abs().max_element() < 1e-4,
            "{name} gave {out:?}"
        );
    }
    let half_plane = Aabb2::new(Vec2::new(0.0, f32::NEG_INFINITY), Vec2::new(1.0, 0.0));
    for (name, out) in all2(half_plane, &Rigid2::new(0.0, 1.0, Vec2::ZERO)) {
        // x' = -y in [0, inf), y' = x in [0, 1].
        assert_eq!(
            (out.max.x, out.min.y, out.max.y),
            (f32::INFINITY, 0.0, 1.0),
            "{name} gave {out:?}"
        );
        assert!(
            out.min.x <= 0.0 && out.min.x > -1e-40,
            "{name} gave {out:?}"
        );
    }
}

#[test]
fn one_ulp_subnormal_box_survives_a_huge_scale() {
    let tiny = f32::from_bits(1); // 2^-149
    let b = Aabb3::new(Vec3A::splat(tiny), Vec3A::splat(3.0 * tiny));
    let scale = Affine3A::from_scale(Vec3::splat(2f32.powi(100)));
    for (name, out) in all3(b, &scale) {
        // Exactly [2^-49, 3·2^-49]; not flushed to a point, within the Outward pad.
        let (lo, hi) = (2f32.powi(-49), 3.0 * 2f32.powi(-49));
        assert!(
            (out.min.x - lo).abs() <= 16.0 * hi * f32::EPSILON,
            "{name} gave {out:?}"
        );
        assert!(
            (out.max.x - hi).abs() <= 16.0 * hi * f32::EPSILON,
            "{name} gave {out:?}"
        );
    }
}

#[test]
fn signed_zero_and_zero_size_boxes() {
    let point = Aabb3::new(Vec3A::new(-0.0, 0.0, -0.0), Vec3A::new(0.0, -0.0, 0.0));
    for (name, out) in all3(point, &pose()) {
        assert!(
            out.contains_point(Vec3A::new(1.0, 2.0, 3.0)),
            "{name} gave {out:?}"
        );
        assert!(
            (out.max - out.min).max_element() < 1e-5,
            "{name} gave {out:?}"
        );
    }
    let segment = Aabb2::new(Vec2::new(1.0, 2.0), Vec2::new(1.0, 2.0));
    let xf = Affine2::from_angle(0.3);
    let p = xf.transform_point2(Vec2::new(1.0, 2.0));
    for method in Method::ALL {
        let out = segment.transformed(&xf, method, Rounding::Outward);
        assert!(out.contains_point(p), "{method:?}");
    }
}
