//! Fitted volumes through transforms against the exact oracle: an `Obb3`, `Sphere` or
//! `Capsule` from raw fields (any values: NaN, infinite, empty, singular or drifted axes)
//! under a transform of any 3D class; `transformed_aabb` in both roundings holds the exact
//! image (Outward) and stays within the documented allowance, or gives the documented
//! special box; `transformed_aabbs` equals the single calls bitwise, per volume and shared,
//! and refuses wrong lengths with the output untouched; under the similarity classes,
//! `transformed` holds the exact images of the volume's extreme points.
#![no_main]

use bvkit::Transform3;
use bvkit::{Aabb3, BatchError, Capsule, Obb3, Rounding, Similarity3, Sphere, Translation3};
use bvkit_fuzz::Floats;
use bvkit_fuzz::affine3;
use bvkit_fuzz::volumes::world::{
    Volume, XMap, check_expected, check_images, finite_map, unit_directions,
};
use glam::Vec3A;
use libfuzzer_sys::fuzz_target;

fn bits(b: &Aabb3) -> [u32; 6] {
    let (l, h) = (b.min.to_array(), b.max.to_array());
    [l[0], l[1], l[2], h[0], h[1], h[2]].map(f32::to_bits)
}

/// The world boxes of `v` under `xf`, single and batched, against the contract.
fn world<V: Volume, T: Transform3 + Copy + core::fmt::Debug>(v: V, xf: T, map: Option<&XMap>) {
    let sentinel = Aabb3::new(Vec3A::splat(7.0), Vec3A::splat(-7.0));
    let expected = v.expected(map);
    for rounding in Rounding::ALL {
        let result = v.transformed_aabb(&xf, rounding);
        if let Err(e) = check_expected(&expected, result, rounding) {
            panic!("{rounding:?}: {e}\n  volume {v:?}\n  map {xf:?}\n  result {result:?}");
        }
        let (volumes, xfs) = ([v; 3], [xf; 3]);
        let mut out = [sentinel; 3];
        V::transformed_aabbs(&volumes, &xfs[..], &mut out, rounding).unwrap();
        let mut shared = [sentinel; 3];
        V::transformed_aabbs(&volumes, &xf, &mut shared, rounding).unwrap();
        for b in out.iter().chain(&shared) {
            assert_eq!(bits(b), bits(&result), "{v:?} {xf:?}");
        }
        let mut short = [sentinel; 2];
        assert!(matches!(
            V::transformed_aabbs(&volumes, &xfs[..], &mut short, rounding),
            Err(BatchError::LengthMismatch { .. })
        ));
        let mut untouched = [sentinel; 3];
        assert!(matches!(
            V::transformed_aabbs(&volumes, &xfs[1..], &mut untouched, rounding),
            Err(BatchError::LengthMismatch { .. })
        ));
        assert!(
            short
                .iter()
                .chain(&untouched)
                .all(|b| bits(b) == bits(&sentinel))
        );
    }
}

/// Every volume type under one transform.
fn all_volumes<T: Transform3 + Copy + core::fmt::Debug>(
    f: &mut Floats,
    kind: u8,
    xf: T,
    map: Option<&XMap>,
) {
    match kind % 3 {
        0 => world(f.obb(), xf, map),
        1 => world(f.sphere(), xf, map),
        _ => world(f.capsule(), xf, map),
    }
}

fuzz_target!(|data: &[u8]| {
    let mut f = Floats::new(data);
    let (class, kind) = (f.byte(), f.byte());
    match class % 6 {
        0 => {
            let p = f.translation_problem::<3>();
            let xf = Translation3(Vec3A::from_array(p.t));
            all_volumes(&mut f, kind, xf, finite_map(&p).as_ref());
        }
        1 => {
            let p = f.quat_problem(None);
            all_volumes(&mut f, kind, p.rigid3(), finite_map(&p).as_ref());
        }
        2 => {
            let p = f.quat_problem(Some(true));
            all_volumes(&mut f, kind, p.similarity3(), finite_map(&p).as_ref());
        }
        3 => {
            let p = f.quat_problem(Some(false));
            all_volumes(&mut f, kind, p.trs3(), finite_map(&p).as_ref());
        }
        4 => {
            let p = f.problem::<3>();
            let (_, xf) = affine3(&p);
            all_volumes(&mut f, kind, xf, finite_map(&p).as_ref());
        }
        _ => {
            // Images under a similarity (rigid when the kind byte is even).
            let rigid = kind % 2 == 0;
            let p = f.quat_problem(if rigid { None } else { Some(true) });
            let xf: Similarity3 = if rigid {
                p.rigid3().into()
            } else {
                p.similarity3()
            };
            let map = finite_map(&p);
            let (obb, sphere, capsule): (Obb3, Sphere, Capsule) =
                (f.obb(), f.sphere(), f.capsule());
            // The 6 axes and every fourth other direction: a sample, as in the tests.
            let dirs: Vec<_> = unit_directions()
                .into_iter()
                .enumerate()
                .filter(|(i, _)| *i < 6 || i % 4 == 0)
                .map(|(_, d)| d)
                .collect();
            check_images(
                xf,
                map.as_ref(),
                &obb,
                &sphere,
                &capsule,
                &dirs,
                &format!("{xf:?}"),
            );
        }
    }
});
