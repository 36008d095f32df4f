//! The `bevy` feature's conversions: bevy_math 0.19's boxes and isometries to bvkit's and
//! back, bit for bit; a bad bevy box refused where bvkit refuses any bad box.

use bevy_math::bounding::{Aabb2d, Aabb3d};
use bevy_math::{Isometry2d, Isometry3d, Rot2};
use bvkit::broadphase::{BroadphaseError, DynamicTree, Layers};
use bvkit::{Aabb2, Aabb3, Method, Rigid2, Rigid3, Rounding};
use glam::{Quat, Vec2, Vec3A};

/// Floats a copy must keep bit for bit: signed zeros, subnormals, extremes, a NaN with a
/// payload.
const EDGES: [f32; 8] = [
    0.0,
    -0.0,
    1.0e-45,
    -3.4e38,
    f32::MAX,
    f32::INFINITY,
    1.5,
    f32::from_bits(0x7fc0_1234),
];

fn bits3(v: [f32; 3]) -> [u32; 3] {
    v.map(f32::to_bits)
}

fn bits2(v: [f32; 2]) -> [u32; 2] {
    v.map(f32::to_bits)
}

#[test]
fn boxes_convert_both_ways_bit_for_bit() {
    for (k, &a) in EDGES.iter().enumerate() {
        let b = EDGES[(k + 3) % EDGES.len()];
        let c = EDGES[(k + 5) % EDGES.len()];
        let bevy3 = Aabb3d {
            min: bevy_math::Vec3A::new(a, b, c),
            max: bevy_math::Vec3A::new(c, a, b),
        };
        let ours = Aabb3::from(bevy3);
        assert_eq!(bits3(ours.min.to_array()), bits3([a, b, c]));
        assert_eq!(bits3(ours.max.to_array()), bits3([c, a, b]));
        let back = Aabb3d::from(ours);
        assert_eq!(bits3(back.min.to_array()), bits3(bevy3.min.to_array()));
        assert_eq!(bits3(back.max.to_array()), bits3(bevy3.max.to_array()));

        let bevy2 = Aabb2d {
            min: bevy_math::Vec2::new(a, b),
            max: bevy_math::Vec2::new(c, a),
        };
        let ours = Aabb2::from(bevy2);
        assert_eq!(bits2(ours.min.to_array()), bits2([a, b]));
        assert_eq!(bits2(ours.max.to_array()), bits2([c, a]));
        let back = Aabb2d::from(ours);
        assert_eq!(bits2(back.min.to_array()), bits2(bevy2.min.to_array()));
        assert_eq!(bits2(back.max.to_array()), bits2(bevy2.max.to_array()));
    }
}

#[test]
fn isometries_convert_to_the_same_poses() {
    let local = Aabb3::new(Vec3A::new(-1.0, -2.0, -0.5), Vec3A::new(3.0, 1.0, 0.25));
    for k in 0..64 {
        let t = k as f32 * 0.37;
        let rotation = Quat::from_euler(glam::EulerRot::XYZ, t, 1.3 * t, -0.7 * t);
        let translation = Vec3A::new(t * 100.0, -t, 1.0e6 / (1.0 + t));
        let direct = Rigid3 {
            rotation,
            translation,
        };
        let bevy = Isometry3d {
            rotation: bevy_math::Quat::from_array(rotation.to_array()),
            translation: bevy_math::Vec3A::from_array(translation.to_array()),
        };
        let converted = Rigid3::from(bevy);
        assert_eq!(converted, direct);
        let back = Isometry3d::from(converted);
        assert_eq!(back.rotation.to_array(), bevy.rotation.to_array());
        assert_eq!(back.translation.to_array(), bevy.translation.to_array());
        // The same pose, so the same box, bit for bit.
        for method in [Method::Naive, Method::AbsMatrix, Method::SignSelect] {
            for rounding in [Rounding::Outward, Rounding::Nearest] {
                let a = local.transformed(&converted, method, rounding);
                let b = local.transformed(&direct, method, rounding);
                assert_eq!(bits3(a.min.to_array()), bits3(b.min.to_array()));
                assert_eq!(bits3(a.max.to_array()), bits3(b.max.to_array()));
            }
        }

        let angle = t - 3.0;
        let rot = Rot2::radians(angle);
        let bevy2 = Isometry2d {
            rotation: rot,
            translation: bevy_math::Vec2::new(t, -2.0 * t),
        };
        let ours = Rigid2::from(bevy2);
        assert_eq!(ours.cos.to_bits(), rot.cos.to_bits());
        assert_eq!(ours.sin.to_bits(), rot.sin.to_bits());
        assert_eq!(ours.translation, Vec2::new(t, -2.0 * t));
        let back = Isometry2d::from(ours);
        assert_eq!(back.rotation.cos.to_bits(), rot.cos.to_bits());
        assert_eq!(back.rotation.sin.to_bits(), rot.sin.to_bits());
        assert_eq!(back.translation.to_array(), bevy2.translation.to_array());
    }
}

#[test]
fn a_nan_or_inverted_bevy_box_is_refused_as_any_bad_box() {
    let good = Aabb3d {
        min: bevy_math::Vec3A::splat(-1.0),
        max: bevy_math::Vec3A::splat(1.0),
    };
    let nan = Aabb3d {
        min: bevy_math::Vec3A::new(f32::NAN, 0.0, 0.0),
        max: bevy_math::Vec3A::splat(1.0),
    };
    let inverted = Aabb3d {
        min: bevy_math::Vec3A::splat(1.0),
        max: bevy_math::Vec3A::new(2.0, 0.0, 2.0),
    };
    let mut tree = DynamicTree::new();
    tree.insert(0, good.into()).unwrap();
    for (k, bad) in [nan, inverted].into_iter().enumerate() {
        let id = 1 + k as u32;
        assert_eq!(
            tree.insert(id, bad.into()),
            Err(BroadphaseError::InvalidBox { id })
        );
        assert_eq!(
            tree.move_proxy(0, bad.into()),
            Err(BroadphaseError::InvalidBox { id: 0 })
        );
        assert_eq!(
            tree.query(&bad.into(), Layers::ALL, |_| {}),
            Err(BroadphaseError::InvalidQuery)
        );
        // Nothing changed.
        assert_eq!(tree.len(), 1);
        assert_eq!(tree.get(0), Some(Aabb3::from(good)));
    }
}
