//! `Batch::transform_par` (feature `rayon`) against `Batch::transform`: bit-identical on
//! every supported backend, in both modes, for every layout (and a swept pair of poses),
//! method and rounding, with
//! extreme inputs mixed in and lengths that leave short last parts and lane tails. And
//! `DynamicTree::update_par` against `DynamicTree::update`: the same pairs in the same order
//! on 1 to 4 threads.
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

/// A dense crowd where about half the bodies jump every frame, a few of them to a NaN box
/// (parked) and back, run through one tree with `update` and through others with
/// `update_par` on pools of 1 to 4 threads: every frame's begun, ended and refused lists
/// are the same, in the same order, and each frame's parts are many (thousands of changed
/// proxies, 512 a part).
#[test]
fn the_tree_reports_the_same_pairs_in_the_same_order_on_any_number_of_threads() {
    use bvkit::broadphase::{DynamicTree, Pairs};
    use glam::Vec3A;
    const N: usize = 12_000;
    let mut r = rng(68);
    let extent: Vec<Vec3A> = (0..N)
        .map(|_| Vec3A::new(r.random(), r.random(), r.random()) * 0.6 + 0.2)
        .collect();
    let mut centre: Vec<Vec3A> = (0..N)
        .map(|_| Vec3A::new(r.random(), r.random(), r.random()) * 40.0)
        .collect();
    let boxes = |centre: &[Vec3A]| -> Vec<Aabb3> {
        centre
            .iter()
            .zip(&extent)
            .map(|(&c, &e)| Aabb3::new(c - e, c + e))
            .collect()
    };
    let mut fat = boxes(&centre);
    let pools: Vec<rayon::ThreadPool> = (1..=4)
        .map(|threads| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
        })
        .collect();
    let mut serial = DynamicTree::from_boxes(&fat).unwrap();
    let mut parallel: Vec<DynamicTree> = pools.iter().map(|_| serial.clone()).collect();
    let (mut begun, mut ended) = (0, 0);
    for frame in 0..12 {
        let moved: Vec<u32> = if frame == 0 {
            Vec::new()
        } else {
            (0..N as u32).filter(|_| r.random_bool(0.5)).collect()
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
                "frame {frame}, {} threads",
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
