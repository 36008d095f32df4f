//! Numeric hygiene, checked through the MXCSR flags rather than timings: on normal-range
//! inputs no fast path reads a subnormal operand (DE) or produces a subnormal result (UE),
//! on any backend, in any layout, for any class, method and rounding, nor do the
//! broadphase update, the fitted volumes' world boxes and the tree queries.
//!
//! Intel cores take a microcode assist of a hundred cycles or more for each such operand or
//! result; AMD cores do not, but set the same architectural flags, so this test sees the
//! problem on either vendor.
//!
//! The inputs are a realistic scene: boxes of 0.01 to 10 units up to 1000 units from the
//! origin, random rotations (every entry zero or above `2^-32`), scales of 0.1 to 10,
//! plus the special cases a scene holds: identity and quarter-turn rotations (exact zero
//! and `6e-8` entries), zero-size boxes, a box at the origin, faces at zero.
#![cfg(target_arch = "x86_64")]

use bvkit_support::mxcsr;
use bvkit_support::trimesh;

use bvkit::LargeWorld;
use bvkit::tree::{AabbTree, Paired, Quantized, Query, TriMesh};
use bvkit::{
    Aabb2, Aabb3, Active, Backend, Batch, Block8, BoundingVolume, Capsule, Fit, LargeRigid3,
    Margin, Method, Moved, Obb3, Rigid2, Rigid3, Rounding, Similarity3, Soa, Sphere, Swept,
    Translation2, Translation3, Trs3,
};
use bvkit::{Transform2, Transform3};
use glam::{Affine2, Affine3A, DVec3, Mat2, Mat3, Mat4, Quat, Vec2, Vec3, Vec3A};
use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};

use mxcsr::{DE, UE};

const N: usize = 203;

/// Fails with the flags raised if `flags` holds DE or UE.
fn assert_clear(flags: u32, what: &str) {
    assert!(
        flags & (DE | UE) == 0,
        "{what}: raised {} on normal-range input (a subnormal operand or result on the fast path)",
        mxcsr::names(flags)
    );
}

fn signed(r: &mut StdRng, lo: f32, hi: f32) -> f32 {
    let x = r.random_range(lo..hi);
    if r.random_bool(0.5) { x } else { -x }
}

fn vec3(r: &mut StdRng, lo: f32, hi: f32) -> Vec3A {
    Vec3A::new(signed(r, lo, hi), signed(r, lo, hi), signed(r, lo, hi))
}

fn rotation(r: &mut StdRng, k: usize) -> Quat {
    match k {
        0 => Quat::IDENTITY,
        1 => Quat::from_rotation_z(core::f32::consts::FRAC_PI_2),
        2 => Quat::from_rotation_x(core::f32::consts::PI),
        _ => Quat::from_euler(
            glam::EulerRot::ZYX,
            r.random_range(-3.1..3.1),
            r.random_range(-1.5..1.5),
            r.random_range(-3.1..3.1),
        ),
    }
}

/// The scene: boxes and one transform of every 3D class per box.
struct Scene {
    boxes: Vec<Aabb3>,
    translations: Vec<Translation3>,
    rigids: Vec<Rigid3>,
    similarities: Vec<Similarity3>,
    trs: Vec<Trs3>,
    affines: Vec<Affine3A>,
    boxes2: Vec<Aabb2>,
    translations2: Vec<Translation2>,
    rigids2: Vec<Rigid2>,
    affines2: Vec<Affine2>,
}

fn scene(seed: u64) -> Scene {
    let r = &mut StdRng::seed_from_u64(seed);
    let boxes: Vec<Aabb3> = (0..N)
        .map(|k| match k {
            0 => Aabb3::new(Vec3A::ZERO, Vec3A::ZERO),
            1 => Aabb3::new(Vec3A::ZERO, Vec3A::ONE),
            2 => Aabb3::new(Vec3A::splat(-1.0), Vec3A::splat(1.0)),
            3 => Aabb3::new(Vec3A::new(5.0, 0.0, -2.0), Vec3A::new(5.0, 0.0, -2.0)),
            _ => {
                let c = vec3(r, 0.0, 1000.0);
                let e = Vec3A::new(
                    r.random_range(0.01..10.0),
                    r.random_range(0.01..10.0),
                    r.random_range(0.01..10.0),
                );
                Aabb3::new(c - e, c + e)
            }
        })
        .collect();
    let position = |r: &mut StdRng, k: usize| {
        if k < 4 {
            Vec3A::ZERO
        } else {
            vec3(r, 0.0, 1000.0)
        }
    };
    let rigids: Vec<Rigid3> = (0..N)
        .map(|k| Rigid3::new(rotation(r, k % 6), position(r, k)))
        .collect();
    let similarities = rigids
        .iter()
        .map(|p| Similarity3::new(r.random_range(0.1..10.0), p.rotation, p.translation))
        .collect();
    let trs = rigids
        .iter()
        .map(|p| {
            let s = Vec3A::new(
                r.random_range(0.1..10.0),
                r.random_range(0.1..10.0),
                r.random_range(0.1..10.0),
            );
            Trs3::new(s, p.rotation, p.translation)
        })
        .collect();
    let affines = (0..N)
        .map(|k| {
            let m = Mat3::from_quat(rotation(r, k % 6))
                * Mat3::from_diagonal(vec3(r, 0.1, 10.0).into());
            let shear = Mat3::from_cols(
                Vec3::X,
                Vec3::new(r.random_range(0.0..0.5), 1.0, 0.0),
                Vec3::Z,
            );
            Affine3A::from_mat3_translation(m * shear, position(r, k).into())
        })
        .collect();
    let translations = rigids.iter().map(|p| Translation3(p.translation)).collect();
    let boxes2: Vec<Aabb2> = boxes
        .iter()
        .map(|b| Aabb2::new(b.min.truncate(), b.max.truncate()))
        .collect();
    let rigids2: Vec<Rigid2> = (0..N)
        .map(|k| {
            let t = position(r, k).truncate();
            match k % 6 {
                0 => Rigid2::new(1.0, 0.0, t),
                1 => Rigid2::from_angle_translation(core::f32::consts::FRAC_PI_2, t),
                _ => Rigid2::from_angle_translation(r.random_range(-3.1..3.1), t),
            }
        })
        .collect();
    let affines2 = rigids2
        .iter()
        .map(|p| {
            let s = Vec2::new(r.random_range(0.1..10.0), r.random_range(0.1..10.0));
            Affine2::from_mat2_translation(
                Mat2::from_cols(Vec2::new(p.cos, p.sin), Vec2::new(-p.sin, p.cos))
                    * Mat2::from_diagonal(s),
                p.translation,
            )
        })
        .collect();
    let translations2 = rigids2
        .iter()
        .map(|p| Translation2(p.translation))
        .collect();
    Scene {
        boxes,
        translations,
        rigids,
        similarities,
        trs,
        affines,
        boxes2,
        translations2,
        rigids2,
        affines2,
    }
}

/// Every (method, rounding) pair.
fn modes() -> impl Iterator<Item = (Method, Rounding)> {
    Method::ALL
        .into_iter()
        .flat_map(|m| Rounding::ALL.into_iter().map(move |r| (m, r)))
}

/// Every supported backend, in its default and its deterministic mode.
fn batches(method: Method, rounding: Rounding) -> Vec<(String, Batch)> {
    Backend::supported()
        .into_iter()
        .flat_map(|backend| {
            let batch = Batch::new(method, rounding).on(backend).unwrap();
            [
                (format!("{backend:?}"), batch),
                (format!("{backend:?} deterministic"), batch.deterministic()),
            ]
        })
        .collect()
}

fn single3<T: Transform3>(name: &str, boxes: &[Aabb3], xfs: &[T]) {
    for (method, rounding) in modes() {
        let ((), flags) = mxcsr::run(0, (boxes, xfs), |(boxes, xfs)| {
            for (b, xf) in boxes.iter().zip(xfs) {
                core::hint::black_box(b.transformed(xf, method, rounding));
                core::hint::black_box(b.transformed_scalar(xf, method, rounding));
            }
        });
        assert_clear(flags, &format!("one box, {name} {method:?} {rounding:?}"));
    }
}

fn single2<T: Transform2>(name: &str, boxes: &[Aabb2], xfs: &[T]) {
    for (method, rounding) in modes() {
        let ((), flags) = mxcsr::run(0, (boxes, xfs), |(boxes, xfs)| {
            for (b, xf) in boxes.iter().zip(xfs) {
                core::hint::black_box(b.transformed(xf, method, rounding));
            }
        });
        assert_clear(flags, &format!("one box, {name} {method:?} {rounding:?}"));
    }
}

#[test]
fn one_box_of_every_class_raises_no_subnormal_flag() {
    let s = scene(1);
    single3("Translation3", &s.boxes, &s.translations);
    single3("Rigid3", &s.boxes, &s.rigids);
    single3("Similarity3", &s.boxes, &s.similarities);
    single3("Trs3", &s.boxes, &s.trs);
    single3("Affine3A", &s.boxes, &s.affines);
    single2("Translation2", &s.boxes2, &s.translations2);
    single2("Rigid2", &s.boxes2, &s.rigids2);
    single2("Affine2", &s.boxes2, &s.affines2);
    for (method, rounding) in modes() {
        let ((), flags) = mxcsr::run(0, &s, |s| {
            for (b, xf) in s.boxes2.iter().zip(&s.rigids2) {
                core::hint::black_box(b.transformed_rigid(xf, method, rounding));
            }
            for (b, xf) in s.boxes.iter().zip(&s.affines) {
                let m = Mat4::from(*xf);
                core::hint::black_box(b.try_transformed_mat4(&m, method, rounding).unwrap());
            }
        });
        assert_clear(
            flags,
            &format!("one box, Rigid2 and Mat4, {method:?} {rounding:?}"),
        );
    }
}

/// Every layout of the batch entry point, for one class, on every backend.
macro_rules! every_layout {
    ($name:expr, $boxes:expr, $xfs:expr, $empty:expr) => {{
        let (boxes, xfs) = (&$boxes[..], &$xfs[..]);
        let (bb, xb) = (Block8::pack(boxes), Block8::pack(xfs));
        let (bs, xs) = (Soa::from_slice(boxes), Soa::from_slice(xfs));
        for (method, rounding) in modes() {
            for (backend, batch) in batches(method, rounding) {
                let mut out = vec![$empty; boxes.len()];
                let mut ob = vec![Block8::splat($empty); bb.len()];
                let mut os = Soa::filled(boxes.len(), $empty);
                let ((), flags) = mxcsr::run(0, (), |()| {
                    batch.transform(boxes, xfs, &mut out[..]).unwrap();
                    batch.transform(&bb[..], &xb[..], &mut ob[..]).unwrap();
                    batch.transform(&bs, &xs, &mut os).unwrap();
                    batch.transform(boxes, &xfs[5], &mut out[..]).unwrap();
                    batch.transform(&bb[..], &xfs[5], &mut ob[..]).unwrap();
                });
                let what = format!("batch, {} {backend} {method:?} {rounding:?}", $name);
                assert_clear(flags, &what);
            }
        }
    }};
}

#[test]
fn batches_of_every_class_layout_and_backend_raise_no_subnormal_flag() {
    let s = scene(2);
    every_layout!("Translation3", s.boxes, s.translations, Aabb3::EMPTY);
    every_layout!("Rigid3", s.boxes, s.rigids, Aabb3::EMPTY);
    every_layout!("Similarity3", s.boxes, s.similarities, Aabb3::EMPTY);
    every_layout!("Trs3", s.boxes, s.trs, Aabb3::EMPTY);
    every_layout!("Affine3A", s.boxes, s.affines, Aabb3::EMPTY);
    every_layout!("Translation2", s.boxes2, s.translations2, Aabb2::EMPTY);
    every_layout!("Rigid2", s.boxes2, s.rigids2, Aabb2::EMPTY);
    every_layout!("Affine2", s.boxes2, s.affines2, Aabb2::EMPTY);
}

#[test]
fn broadphase_updates_raise_no_subnormal_flag() {
    let s = scene(3);
    let next = scene(4);
    let n = s.boxes.len();
    let margin = Margin::new(0.1, 0.05);
    let indices: Vec<u32> = (0..n as u32).step_by(3).collect();
    let mask: Vec<u64> = (0..n.div_ceil(64))
        .map(|w| 0x5555_5555_5555_5555u64 >> (w % 2))
        .collect();
    let mask = {
        let mut m = mask;
        let last = n.div_ceil(64) - 1;
        m[last] &= (1u64 << (n - 64 * last)) - 1;
        m
    };
    let large: Vec<LargeRigid3> = s
        .rigids
        .iter()
        .map(|p| LargeRigid3::new(p.rotation, p.translation.as_dvec3() + DVec3::splat(1e6)))
        .collect();
    for (method, rounding) in modes() {
        for (backend, batch) in batches(method, rounding) {
            for active in [Active::All, Active::Indices(&indices), Active::Mask(&mask)] {
                let mut moved = Moved::new();
                let mut fat = vec![Aabb3::EMPTY; n];
                let mut fat_b = Block8::pack(&fat);
                let mut fat_s = Soa::from_slice(&fat);
                let mut fat2 = vec![Aabb2::EMPTY; n];
                let (bb, pb) = (Block8::pack(&s.boxes), Block8::pack(&s.rigids));
                let (bs, ps) = (Soa::from_slice(&s.boxes), Soa::from_slice(&s.rigids));
                let swept = Swept {
                    current: &s.rigids[..],
                    predicted: &next.rigids[..],
                };
                let world = LargeWorld {
                    poses: &large,
                    origin: DVec3::splat(1e6),
                };
                let ((), flags) = mxcsr::run(0, (), |()| {
                    // Twice: the first writes every box, the second tests containment.
                    for poses in [&s.rigids, &next.rigids] {
                        let (l, f) = (&s.boxes[..], &mut fat[..]);
                        batch
                            .update(margin, active, l, &poses[..], f, &mut moved)
                            .unwrap();
                    }
                    batch
                        .update(margin, active, &bb[..], &pb[..], &mut fat_b[..], &mut moved)
                        .unwrap();
                    batch
                        .update(margin, active, &bs, &ps, &mut fat_s, &mut moved)
                        .unwrap();
                    let (l, f) = (&s.boxes[..], &mut fat[..]);
                    batch
                        .update(margin, active, l, &s.affines[..], f, &mut moved)
                        .unwrap();
                    batch
                        .update(margin, active, l, swept, &mut fat[..], &mut moved)
                        .unwrap();
                    batch
                        .update(margin, active, l, world, &mut fat[..], &mut moved)
                        .unwrap();
                    let (l2, f2) = (&s.boxes2[..], &mut fat2[..]);
                    batch
                        .update(margin, active, l2, &s.rigids2[..], f2, &mut moved)
                        .unwrap();
                });
                let what = format!("update, {backend} {method:?} {rounding:?} {active:?}");
                assert_clear(flags, &what);
            }
        }
    }
}

#[test]
fn fitted_volumes_world_boxes_raise_no_subnormal_flag() {
    let s = scene(5);
    let (vertices, _) = trimesh::spot();
    let fits = [Fit::Pca, Fit::Fast, Fit::Tight];
    let obbs: Vec<Obb3> = fits
        .iter()
        .map(|&f| Obb3::fit(&vertices, f).unwrap())
        .collect();
    let spheres: Vec<Sphere> = fits
        .iter()
        .map(|&f| Sphere::fit(&vertices, f).unwrap())
        .collect();
    let capsules: Vec<Capsule> = fits
        .iter()
        .map(|&f| Capsule::fit(&vertices, f).unwrap())
        .collect();
    for rounding in Rounding::ALL {
        let ((), flags) = mxcsr::run(0, (), |()| {
            let mut out = vec![Aabb3::EMPTY; 3];
            for k in 0..N {
                for o in &obbs {
                    core::hint::black_box(o.transformed_aabb(&s.rigids[k], rounding));
                    core::hint::black_box(o.transformed_aabb(&s.trs[k], rounding));
                    core::hint::black_box(o.transformed_aabb(&s.affines[k], rounding));
                    core::hint::black_box(o.transformed_aabb(&s.translations[k], rounding));
                    core::hint::black_box(o.transformed(s.similarities[k]));
                }
                for c in &spheres {
                    core::hint::black_box(c.transformed_aabb(&s.similarities[k], rounding));
                    core::hint::black_box(c.transformed_aabb(&s.affines[k], rounding));
                    core::hint::black_box(c.transformed(s.rigids[k]));
                }
                for c in &capsules {
                    core::hint::black_box(c.transformed_aabb(&s.rigids[k], rounding));
                    core::hint::black_box(c.transformed_aabb(&s.trs[k], rounding));
                    core::hint::black_box(c.transformed(s.similarities[k]));
                }
            }
            Obb3::transformed_aabbs(&obbs, &s.rigids[..3], &mut out, rounding).unwrap();
            Sphere::transformed_aabbs(&spheres, &s.affines[7], &mut out, rounding).unwrap();
            Capsule::transformed_aabbs(&capsules, &s.trs[..3], &mut out, rounding).unwrap();
        });
        assert_clear(flags, &format!("fitted volumes' world boxes, {rounding:?}"));
    }
}

#[test]
fn tree_queries_raise_no_subnormal_flag() {
    let (va, ia) = trimesh::torus(1.0, 0.3, 24, 12);
    let (vb, ib) = trimesh::spot();
    let a = TriMesh::new(va, ia).unwrap();
    let b = TriMesh::new(vb, ib).unwrap();
    let (aq, bq) = (a.with_layout::<Quantized>(), b.with_layout::<Quantized>());
    let (aw, bw) = (a.with_layout::<Paired>(), b.with_layout::<Paired>());
    let boxes: Vec<Aabb3> = scene(6)
        .boxes
        .iter()
        .map(|b| b.fattened(Margin::new(0.0, 0.0)))
        .collect();
    let tree = AabbTree::new(&boxes).unwrap();
    let poses_a = trimesh::poses(16, 0.8, 1);
    let poses_b = trimesh::poses(16, 0.8, 2);
    let ((), flags) = mxcsr::run(0, (), |()| {
        for (k, (&pa, &pb)) in poses_a.iter().zip(&poses_b).enumerate() {
            let pb = if k % 4 == 0 { Rigid3::IDENTITY } else { pb };
            let q = Query::new(&a, pa, &b, pb)
                .and_then(|q| q.with_tolerance(if k % 2 == 0 { 0.0 } else { 0.01 }))
                .unwrap();
            core::hint::black_box(q.intersects());
            core::hint::black_box(q.overlapping_triangles());
            let q = Query::new(&aq, pa, &bq, pb).unwrap();
            core::hint::black_box(q.overlapping_triangles());
            let q = Query::new(&aw, pa, &bw, pb).unwrap();
            core::hint::black_box(q.intersects());
            core::hint::black_box(q.overlapping_triangles());
            let (sa, sb) = (Similarity3::from(pa), Similarity3::from(pb));
            let q = Query::similarity(&a, sa, &b, Similarity3 { scale: 1.5, ..sb }).unwrap();
            core::hint::black_box(q.overlapping_triangles());
            let q = Query::new(&tree, pa, &tree, pb).unwrap();
            core::hint::black_box(q.leaf_pairs());
        }
    });
    assert_clear(flags, "tree queries");
}
