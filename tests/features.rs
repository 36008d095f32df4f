//! The optional features: `serde` round trips, `bytemuck` casts, and what the crate does
//! without `std`. Run with `--features rayon,serde,bytemuck` and `--no-default-features`
//! (`.ci/run` does); each part compiles only under its feature.

use bvkit::Backend;

/// Eight boxes and affine maps, for the casts and the unfused lanes.
#[cfg(any(feature = "bytemuck", not(feature = "std")))]
fn problem() -> (Vec<bvkit::Aabb3>, Vec<glam::Affine3A>) {
    use bvkit::Aabb3;
    use glam::{Affine3A, Quat, Vec3, Vec3A};
    let local = (0..8)
        .map(|k| {
            let k = k as f32;
            Aabb3::new(
                Vec3A::new(-1.0 - k, -2.0, -0.5 * k),
                Vec3A::new(1.0, 2.0 + k, 3.0),
            )
        })
        .collect();
    let maps = (0..8)
        .map(|k| {
            let k = k as f32;
            Affine3A::from_scale_rotation_translation(
                Vec3::new(1.0 + k, 0.5, 2.0),
                Quat::from_euler(glam::EulerRot::XYZ, 0.3 * k, -0.7, 1.1 + k),
                Vec3::new(1e3 * k, -7.0, 0.25),
            )
        })
        .collect();
    (local, maps)
}

#[cfg(feature = "serde")]
mod serde_round_trip {
    use bvkit::{
        Aabb2, Aabb3, Backend, Capsule, Fit, LargeRigid3, Margin, Method, Obb3, Rigid2, Rigid3,
        Rounding, Similarity3, Sphere, Translation2, Translation3, Trs3,
    };
    use glam::{DVec3, Mat3A, Quat, Vec2, Vec3A};
    use serde::{Serialize, de::DeserializeOwned};
    use std::fmt::Debug;

    /// `value` through MessagePack and back: the same bytes again (MessagePack stores an
    /// `f32` as its bits, so this is a bitwise round trip, NaN payloads included).
    fn bitwise<T: Serialize + DeserializeOwned + Debug + PartialEq>(value: T) {
        let bytes = rmp_serde::to_vec(&value).expect("serialises");
        let back: T = rmp_serde::from_slice(&bytes).expect("deserialises");
        assert_eq!(rmp_serde::to_vec(&back).unwrap(), bytes, "{value:?}");
        // Truncated input is an error, never a panic or a plausible value.
        assert!(rmp_serde::from_slice::<T>(&bytes[..bytes.len() - 1]).is_err());
    }

    /// `value` through JSON and back, equal, and its JSON text as written.
    fn json<T: Serialize + DeserializeOwned + Debug + PartialEq>(value: T, text: &str) {
        let written = serde_json::to_string(&value).expect("serialises");
        assert_eq!(written, text);
        let back: T = serde_json::from_str(&written).expect("deserialises");
        assert_eq!(back, value);
    }

    const AWKWARD: [f32; 6] = [
        f32::NAN,
        f32::INFINITY,
        -0.0,
        f32::MIN_POSITIVE / 8.0,
        f32::MAX,
        -1.5,
    ];

    #[test]
    fn every_value_type_round_trips_bitwise() {
        let v = |k: usize| Vec3A::new(AWKWARD[k % 6], AWKWARD[(k + 1) % 6], AWKWARD[(k + 2) % 6]);
        let q = Quat::from_xyzw(0.5, -0.5, f32::NAN, 0.5);
        for k in 0..6 {
            bitwise(Aabb3::new(v(k), v(k + 3)));
            bitwise(Aabb2::new(v(k).truncate(), v(k + 1).truncate()));
            bitwise(Translation3(v(k)));
            bitwise(Translation2(v(k).truncate()));
            bitwise(Rigid2::new(
                AWKWARD[k],
                AWKWARD[(k + 1) % 6],
                Vec2::new(3.0, -4.0),
            ));
            bitwise(Rigid3 {
                rotation: q,
                translation: v(k),
            });
            bitwise(Similarity3 {
                scale: AWKWARD[k],
                rotation: q,
                translation: v(k),
            });
            bitwise(Trs3 {
                scale: v(k + 1),
                rotation: q,
                translation: v(k),
            });
            bitwise(Obb3 {
                center: v(k),
                half_extents: v(k + 2),
                rotation: Mat3A::from_cols(v(k), v(k + 1), v(k + 4)),
            });
            bitwise(Sphere {
                center: v(k),
                radius: AWKWARD[k],
            });
            bitwise(Capsule {
                a: v(k),
                b: v(k + 5),
                radius: AWKWARD[k],
            });
            bitwise(Margin::new(AWKWARD[k], AWKWARD[(k + 3) % 6]));
            bitwise(LargeRigid3 {
                rotation: q,
                position: DVec3::new(1e12, f64::NAN, -0.0),
            });
        }
        bitwise(Aabb3::EMPTY);
        bitwise(Aabb3::NAN);
        for m in Method::ALL {
            bitwise(m);
        }
        for r in Rounding::ALL {
            bitwise(r);
        }
        for f in [Fit::Pca, Fit::Fast, Fit::Tight] {
            bitwise(f);
        }
        for b in Backend::ALL {
            bitwise(b);
        }
    }

    #[test]
    fn json_reads_as_written() {
        json(
            Aabb3::new(Vec3A::new(-1.0, -2.0, -3.0), Vec3A::new(1.0, 2.0, 3.5)),
            r#"{"min":[-1.0,-2.0,-3.0],"max":[1.0,2.0,3.5]}"#,
        );
        json(
            Rigid3 {
                rotation: Quat::IDENTITY,
                translation: Vec3A::new(10.0, 0.0, -2.0),
            },
            r#"{"rotation":[0.0,0.0,0.0,1.0],"translation":[10.0,0.0,-2.0]}"#,
        );
        json(
            Margin::new(0.1, 0.25),
            r#"{"absolute":0.1,"relative":0.25}"#,
        );
        json(Method::SignSelect, r#""SignSelect""#);
        json(Rounding::Outward, r#""Outward""#);
        json(
            Sphere {
                center: Vec3A::ZERO,
                radius: 2.0,
            },
            r#"{"center":[0.0,0.0,0.0],"radius":2.0}"#,
        );
        // An unknown variant or a missing field is an error.
        assert!(serde_json::from_str::<Method>(r#""Exact""#).is_err());
        assert!(serde_json::from_str::<Aabb3>(r#"{"min":[0.0,0.0,0.0]}"#).is_err());
    }
}

#[cfg(feature = "bytemuck")]
mod bytemuck_casts {
    use super::problem;
    use bvkit::{Aabb2, Aabb3, Aabb3x8, Affine3x8, Batch, Margin, Method, Rigid2x8, Rounding};
    use glam::{Vec2, Vec3A};

    /// AoSoA blocks go to bytes (a GPU upload) and come back as the same blocks; the bytes
    /// are the fields in order, eight lanes each.
    #[test]
    fn blocks_cast_to_bytes_and_back() {
        let (local, maps) = problem();
        let local8 = Aabb3x8::pack(&local);
        let maps8 = Affine3x8::pack(&maps);
        let mut world8 = vec![Aabb3x8::default(); 1];
        // Deterministic: the AoSoA and the AoS paths give the same bits.
        let batch = Batch::new(Method::AbsMatrix, Rounding::Outward).deterministic();
        batch.transform(&local8, &maps8, &mut world8).unwrap();
        let bytes: &[u8] = bytemuck::cast_slice(&world8);
        assert_eq!(bytes.len(), 6 * 8 * 4);
        let floats: &[f32] = bytemuck::cast_slice(bytes);
        let mut expected = vec![Aabb3::EMPTY; 8];
        batch.transform(&local, &maps, &mut expected).unwrap();
        for (k, b) in expected.iter().enumerate() {
            let fields = [b.min.x, b.min.y, b.min.z, b.max.x, b.max.y, b.max.z];
            for (n, f) in fields.into_iter().enumerate() {
                assert_eq!(
                    floats[8 * n + k].to_bits(),
                    f.to_bits(),
                    "box {k} field {n}"
                );
            }
        }
        // Back from bytes (aligned as a block): the same blocks.
        let back: &[Aabb3x8] = bytemuck::cast_slice(bytes);
        assert_eq!(back, &world8[..]);
        // A misaligned or short byte slice is refused, not reinterpreted.
        let raw = bytemuck::cast_slice::<Aabb3x8, u8>(&world8).to_vec();
        assert!(bytemuck::try_cast_slice::<u8, Rigid2x8>(&raw[..raw.len() - 4]).is_err());
    }

    /// The plain-data types: Pod ones to bytes and back, `Aabb3` (its `Vec3A` padding lane
    /// is not guaranteed initialised, so only `AnyBitPattern`) read from bytes.
    #[test]
    fn plain_types_cast() {
        let boxes = [
            Aabb2::new(Vec2::new(-1.0, -2.0), Vec2::new(3.0, 4.0)),
            Aabb2::EMPTY,
        ];
        let floats: &[f32] = bytemuck::cast_slice(&boxes);
        assert_eq!(floats[..4], [-1.0, -2.0, 3.0, 4.0]);
        assert_eq!(bytemuck::cast_slice::<f32, Aabb2>(floats), &boxes);
        let margin = Margin::new(0.1, 0.5);
        assert_eq!(bytemuck::cast::<Margin, [f32; 2]>(margin), [0.1, 0.5]);
        let padded: [f32; 8] = [-1.0, -2.0, -3.0, 0.0, 1.0, 2.0, 3.0, 0.0];
        let read: Aabb3 = bytemuck::cast(padded);
        assert_eq!(
            read,
            Aabb3::new(Vec3A::new(-1.0, -2.0, -3.0), Vec3A::new(1.0, 2.0, 3.0))
        );
        let zero: Aabb3 = bytemuck::Zeroable::zeroed();
        assert_eq!(zero, Aabb3::new(Vec3A::ZERO, Vec3A::ZERO));
    }
}

/// Without `std` there is no run-time CPU detection: a backend is supported exactly when
/// the build's target features guarantee it.
#[test]
fn backend_support_follows_the_build() {
    for backend in Backend::ALL {
        let guaranteed = match backend {
            Backend::Scalar | Backend::Baseline | Backend::Wide => true,
            Backend::Avx2 => cfg!(all(target_feature = "avx2", target_feature = "fma")),
            Backend::Avx512 => cfg!(all(target_feature = "avx512f", target_feature = "fma")),
        };
        if cfg!(feature = "std") {
            // Detection finds at least what the build guarantees.
            assert!(!guaranteed || backend.is_supported(), "{backend:?}");
        } else {
            assert_eq!(backend.is_supported(), guaranteed, "{backend:?}");
        }
    }
    assert!(Backend::detect().is_supported());
}

/// Without `std` the lane backends never fuse, so the default mode already gives the
/// deterministic bits (with `std` the fused backends differ in the last bits).
#[cfg(not(feature = "std"))]
#[test]
fn without_std_lanes_are_unfused() {
    use bvkit::{Batch, Method, Rounding};
    let (local, maps) = problem();
    let local8 = bvkit::Aabb3x8::pack(&local);
    let maps8 = bvkit::Affine3x8::pack(&maps);
    for backend in Backend::supported() {
        for method in Method::ALL {
            let batch = Batch::new(method, Rounding::Nearest).on(backend).unwrap();
            let mut fast = vec![bvkit::Aabb3x8::default(); 1];
            let mut exact = fast.clone();
            batch.transform(&local8, &maps8, &mut fast).unwrap();
            batch
                .deterministic()
                .transform(&local8, &maps8, &mut exact)
                .unwrap();
            assert_eq!(fast, exact, "{backend:?} {method:?}");
        }
    }
}
