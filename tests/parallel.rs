//! `Batch::transform_par` (feature `rayon`) against `Batch::transform`: bit-identical on
//! every supported backend, in both modes, for every layout (and a swept pair of poses),
//! method and rounding, with
//! extreme inputs mixed in and lengths that leave short last parts and lane tails.
//! `Batch::update_par` against `Batch::update`: the same fat boxes and moved sets, for every
//! kind of active set, in AoS and AoSoA. And `DynamicTree::update_par` against
//! `DynamicTree::update`: the same pairs in the same order on 1 to 4 threads.
#![cfg(feature = "rayon")]

use bvkit_support::cases;
use bvkit_support::oracle;

use bvkit::{Aabb3, Aabb3x8, Backend, Batch, Block8, Method, Rigid3, Rounding, Soa};
use glam::Affine3A;
use rand::RngExt;

use cases::{Class, Scale, problem, quat_problem, rng};
use oracle::affine3;

/// Mostly typical problems, one in ten from any extreme class.
fn class_of(r: &mut rand::rngs::StdRng) -> Class {
    if r.random_bool(0.9) {
        Class::Typical
    } else {
        Class::ALL[r.random_range(0..Class::ALL.len())]
    }
}

fn bits(boxes: &[Aabb3]) -> Vec<[u32; 6]> {
    boxes
        .iter()
        .map(|b| {
            let (lo, hi) = (b.min.to_array(), b.max.to_array());
            [lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]].map(f32::to_bits)
        })
        .collect()
}

/// Every layout of one class, serial against parallel.
fn same_bits<T>(local: &[Aabb3], xfs: &[T])
where
    T: bvkit::Transform3 + Sync,
{
    let n = local.len();
    let (lb, xb) = (Block8::pack(local), Block8::pack(xfs));
    let (ls, xs) = (Soa::from_slice(local), Soa::from_slice(xfs));
    let modes = Backend::supported()
        .into_iter()
        .flat_map(|b| [(b, false), (b, true)]);
    for (backend, deterministic) in modes {
        for method in Method::ALL {
            for rounding in Rounding::ALL {
                let mut batch = Batch::new(method, rounding).on(backend).unwrap();
                if deterministic {
                    batch = batch.deterministic();
                }
                let name =
                    format!("{backend:?} deterministic {deterministic} {method:?} {rounding:?}");

                let (mut serial, mut parallel) = (vec![Aabb3::NAN; n], vec![Aabb3::EMPTY; n]);
                batch.transform(local, xfs, &mut serial[..]).unwrap();
                batch.transform_par(local, xfs, &mut parallel[..]).unwrap();
                assert_eq!(bits(&serial), bits(&parallel), "AoS {name}");

                let (mut serial, mut parallel) = (vec![Aabb3::NAN; n], vec![Aabb3::EMPTY; n]);
                batch.transform(local, &xfs[0], &mut serial).unwrap();
                batch.transform_par(local, &xfs[0], &mut parallel).unwrap();
                assert_eq!(bits(&serial), bits(&parallel), "AoS shared {name}");

                // A swept pair of poses (the update's pose sources work here too).
                let swept = bvkit::Swept {
                    current: xfs,
                    predicted: &xfs[0],
                };
                let (mut serial, mut parallel) = (vec![Aabb3::NAN; n], vec![Aabb3::EMPTY; n]);
                batch.transform(local, swept, &mut serial[..]).unwrap();
                batch
                    .transform_par(local, swept, &mut parallel[..])
                    .unwrap();
                assert_eq!(bits(&serial), bits(&parallel), "AoS swept {name}");

                let mut serial = vec![Aabb3x8::default(); lb.len()];
                let mut parallel = vec![Aabb3x8::default(); lb.len()];
                let m = lb.len() * 8;
                if m == xb.len() * 8 {
                    batch.transform(&lb, &xb, &mut serial).unwrap();
                    batch.transform_par(&lb, &xb, &mut parallel).unwrap();
                    assert_eq!(
                        bits(&Block8::unpack(&serial, n)),
                        bits(&Block8::unpack(&parallel, n)),
                        "AoSoA {name}"
                    );
                }

                let mut serial = Soa::filled(n, Aabb3::NAN);
                let mut parallel = Soa::filled(n, Aabb3::EMPTY);
                batch.transform(&ls, &xs, &mut serial).unwrap();
                batch.transform_par(&ls, &xs, &mut parallel).unwrap();
                let (s, p): (Vec<Aabb3>, Vec<Aabb3>) =
                    (0..n).map(|k| (serial.get(k), parallel.get(k))).unzip();
                assert_eq!(bits(&s), bits(&p), "SoA {name}");
            }
        }
    }
}

#[test]
fn affine3_parallel_is_serial() {
    let r = &mut rng(31);
    // Five parts of 4096 and a short last one with a lane tail.
    let (local, xfs): (Vec<Aabb3>, Vec<Affine3A>) = (0..4 * 4096 + 2003)
        .map(|_| affine3(&problem::<3>(class_of(r), r)))
        .unzip();
    same_bits(&local, &xfs);
}

#[test]
fn rigid3_parallel_is_serial() {
    let r = &mut rng(32);
    let (local, xfs): (Vec<Aabb3>, Vec<Rigid3>) = (0..2 * 4096 + 1001)
        .map(|_| {
            let p = quat_problem(class_of(r), Scale::Unit, r);
            (p.aabb(), p.rigid3())
        })
        .unzip();
    same_bits(&local, &xfs);
}

#[test]
fn parallel_length_mismatch_writes_nothing() {
    let local = vec![Aabb3::new(glam::Vec3A::ZERO, glam::Vec3A::ONE); 10_000];
    let xfs = vec![Affine3A::IDENTITY; 9_999];
    let mut out = vec![Aabb3::NAN; 10_000];
    let batch = Batch::new(Method::AbsMatrix, Rounding::Outward);
    let result = batch.transform_par(&local, &xfs, &mut out);
    assert!(result.is_err());
    assert!(out.iter().all(|b| b.min.x.is_nan()));
}

/// A dense crowd where a share of the bodies jump every frame, a few of them to a NaN box
/// (parked) and back, run through one tree with `update` and through others with
/// `update_par` on pools of 1 to 4 threads: every frame's begun, ended and refused lists
/// are the same, in the same order. Half of 12K moving takes the report's traversals of the
/// moving hierarchy against itself and against the static one (hundreds of tasks, eight a
/// part); a twentieth of 20K, its queries (a thousand, 512 a part). A fifth of the proxies
/// are static and a tenth kinematic (paired with statics), in two layers.
#[test]
fn the_tree_reports_the_same_pairs_in_the_same_order_on_any_number_of_threads() {
    same_pairs_on_any_number_of_threads(12_000, 0.5);
    same_pairs_on_any_number_of_threads(20_000, 0.05);
}

fn same_pairs_on_any_number_of_threads(n: usize, share: f64) {
    use bvkit::broadphase::{BodyKind, DynamicTree, KindPairs, Layers, Pairs};
    use glam::Vec3A;
    let mut r = rng(68);
    let extent: Vec<Vec3A> = (0..n)
        .map(|_| Vec3A::new(r.random(), r.random(), r.random()) * 0.6 + 0.2)
        .collect();
    let mut centre: Vec<Vec3A> = (0..n)
        .map(|_| {
            Vec3A::new(r.random(), r.random(), r.random()) * 40.0 * (n as f32 / 12_000.0).cbrt()
        })
        .collect();
    let boxes = |centre: &[Vec3A]| -> Vec<Aabb3> {
        centre
            .iter()
            .zip(&extent)
            .map(|(&c, &e)| Aabb3::new(c - e, c + e))
            .collect()
    };
    let mut fat = boxes(&centre);
    let pools = pools(4);
    let mut serial = DynamicTree::from_boxes_with(&fat, |id| {
        let kind = match id % 10 {
            0 | 5 => BodyKind::Static,
            3 => BodyKind::Kinematic,
            _ => BodyKind::Dynamic,
        };
        (
            kind,
            Layers::new(1 << (id % 2), if id % 7 == 0 { 1 } else { 3 }),
        )
    })
    .unwrap();
    serial.set_kind_pairs(KindPairs {
        kinematic_kinematic: false,
        kinematic_static: true,
    });
    let mut parallel: Vec<DynamicTree> = pools.iter().map(|_| serial.clone()).collect();
    let (mut begun, mut ended) = (0, 0);
    for frame in 0..12 {
        let moved: Vec<u32> = if frame == 0 {
            Vec::new()
        } else {
            (0..n as u32).filter(|_| r.random_bool(share)).collect()
        };
        for &i in &moved {
            let step = Vec3A::new(r.random(), r.random(), r.random()) * 1.6 - 0.8;
            centre[i as usize] += step;
        }
        fat = boxes(&centre);
        for &i in moved.iter().filter(|&&i| i % 97 == frame) {
            fat[i as usize].min.x = f32::NAN;
        }
        let mut want = Pairs::with_ended();
        serial.update(&moved, &fat, &mut want).unwrap();
        for (tree, pool) in parallel.iter_mut().zip(&pools) {
            let mut got = Pairs::with_ended();
            pool.install(|| tree.update_par(&moved, &fat, &mut got))
                .unwrap();
            assert_eq!(
                got,
                want,
                "{n} boxes, frame {frame}, {} threads",
                pool.current_num_threads()
            );
        }
        begun += want.begun.len();
        ended += want.ended.len();
    }
    assert!(
        begun > 10_000 && ended > 5_000,
        "begun {begun}, ended {ended}"
    );
}

/// Five frames of a walk where some bodies jump out of their fat boxes (one in fifty to a
/// NaN pose), through `update` and through `update_par` on pools of 1 to 3 threads: the same
/// fat boxes (bit for bit) and the same moved sets, for every kind of active set, in AoS
/// and in AoSoA blocks, over a length that leaves a short last part and a lane tail.
#[test]
fn the_update_gives_the_same_fat_boxes_and_moved_set_on_any_number_of_threads() {
    use bvkit::{Active, Margin, Moved, Rigid3x8};
    use glam::{Quat, Vec3A};
    const N: usize = 20_003;
    let mut r = rng(69);
    let local: Vec<Aabb3> = (0..N)
        .map(|_| {
            let e = Vec3A::new(r.random(), r.random(), r.random()) + 0.1;
            Aabb3::new(-e, e)
        })
        .collect();
    let mut poses: Vec<Rigid3> = (0..N)
        .map(|_| {
            let t = Vec3A::new(r.random(), r.random(), r.random()) * 100.0;
            Rigid3::new(Quat::from_rotation_y(r.random()), t)
        })
        .collect();
    let list: Vec<u32> = (0..N as u32).filter(|_| r.random_bool(0.3)).collect();
    let mut mask = vec![0u64; N.div_ceil(64)];
    for &i in &list {
        mask[i as usize / 64] |= 1 << (i % 64);
    }
    let mut mask8 = mask.clone();
    mask8.resize(N.next_multiple_of(8).div_ceil(64), 0);
    let local8 = Aabb3x8::pack(&local);
    let pools = pools(3);
    let batch = Batch::new(Method::AbsMatrix, Rounding::Outward);
    let margin = Margin::new(0.05, 0.1);
    for kind in 0..3 {
        let (active, active8) = match kind {
            0 => (Active::All, Active::All),
            1 => (Active::Indices(&list), Active::Indices(&list)),
            _ => (Active::Mask(&mask), Active::Mask(&mask8)),
        };
        let mut want = (vec![Aabb3::EMPTY; N], Moved::new());
        let mut want8 = (Aabb3x8::pack(&want.0), Moved::new());
        let mut got: Vec<_> = pools.iter().map(|_| want.clone()).collect();
        let mut got8: Vec<_> = pools.iter().map(|_| want8.clone()).collect();
        for frame in 0..5 {
            if frame > 0 {
                for (i, p) in poses.iter_mut().enumerate() {
                    if r.random_bool(0.2) {
                        p.translation.x += if i % 50 == frame { f32::NAN } else { 1.0 };
                    }
                }
            }
            let poses8 = Rigid3x8::pack(&poses);
            batch
                .update(margin, active, &local, &poses, &mut want.0, &mut want.1)
                .unwrap();
            batch
                .update(
                    margin,
                    active8,
                    &local8[..],
                    &poses8[..],
                    &mut want8.0[..],
                    &mut want8.1,
                )
                .unwrap();
            for ((pool, g), g8) in pools.iter().zip(&mut got).zip(&mut got8) {
                pool.install(|| {
                    batch.update_par(margin, active, &local, &poses, &mut g.0, &mut g.1)
                })
                .unwrap();
                pool.install(|| {
                    batch.update_par(
                        margin,
                        active8,
                        &local8[..],
                        &poses8[..],
                        &mut g8.0[..],
                        &mut g8.1,
                    )
                })
                .unwrap();
                let threads = pool.current_num_threads();
                assert_eq!(bits(&g.0), bits(&want.0), "AoS, {kind}, {frame}, {threads}");
                assert_eq!(g.1, want.1, "AoS moved, {kind}, {frame}, {threads}");
                let (a, b) = (Aabb3x8::unpack(&g8.0, N), Aabb3x8::unpack(&want8.0, N));
                assert_eq!(bits(&a), bits(&b), "AoSoA, {kind}, {frame}, {threads}");
                assert_eq!(g8.1, want8.1, "AoSoA moved, {kind}, {frame}, {threads}");
            }
            assert!(want.1.len() > 500, "frame {frame}: {} moved", want.1.len());
        }
    }
}

/// Many rays cast with `cast_rays_par` on pools of 1 to 4 threads, their closest hits and
/// every hit in call order: the same as `cast_rays` and as one `cast_ray` at a time.
#[test]
fn many_rays_give_the_same_hits_in_the_same_order_on_any_number_of_threads() {
    use bvkit::broadphase::{BodyKind, CastControl, DynamicTree, Layers, Ray};
    use glam::Vec3A;
    let mut r = rng(85);
    let fat: Vec<Aabb3> = (0..20_000)
        .map(|_| {
            let c = Vec3A::new(r.random(), r.random(), r.random()) * 100.0;
            Aabb3::new(c - 0.8, c + 0.8)
        })
        .collect();
    let tree = DynamicTree::from_boxes_with(&fat, |id| {
        let kind = [BodyKind::Static, BodyKind::Dynamic][id as usize % 2];
        (kind, Layers::new(1 << (id % 3), u32::MAX))
    })
    .unwrap();
    let rays: Vec<Ray> = (0..3000)
        .map(|_| {
            let origin = Vec3A::new(r.random(), r.random(), r.random()) * 100.0;
            let direction = Vec3A::new(r.random(), r.random(), r.random()) - 0.5;
            Ray::new(origin, direction, 150.0)
        })
        .collect();
    let layers = Layers::new(u32::MAX, 0b101);
    // Each ray's hits in call order, clipping to the nearest entry so far.
    type Hits = Vec<(u32, u32)>;
    let record = |_: usize, id: u32, t: f32, out: &mut Hits| {
        out.push((id, t.to_bits()));
        let nearest = out.iter().map(|h| f32::from_bits(h.1)).fold(t, f32::min);
        CastControl::Clip(nearest + 5.0)
    };
    let mut one_by_one: Vec<Hits> = vec![Vec::new(); rays.len()];
    for (i, ray) in rays.iter().enumerate() {
        let out = &mut one_by_one[i];
        tree.cast_ray(ray, layers, |id, t| record(i, id, t, out))
            .unwrap();
    }
    let mut serial: Vec<Hits> = vec![Vec::new(); rays.len()];
    tree.cast_rays(&rays, layers, &mut serial, record).unwrap();
    assert_eq!(serial, one_by_one);
    for pool in pools(4) {
        let mut got: Vec<Hits> = vec![Vec::new(); rays.len()];
        pool.install(|| tree.cast_rays_par(&rays, layers, &mut got, record))
            .unwrap();
        assert_eq!(got, serial, "{} threads", pool.current_num_threads());
    }
    let hits: usize = serial.iter().map(Vec::len).sum();
    assert!(hits > 3000, "{hits} hits");
}

/// Thread pools of 1 to `most` threads.
fn pools(most: usize) -> Vec<rayon::ThreadPool> {
    (1..=most)
        .map(|threads| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
        })
        .collect()
}
