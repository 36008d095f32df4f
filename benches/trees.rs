//! Trees: bvkit's simultaneous descent against parry3d 0.31 in the same run, on two tori
//! (5k and 20k triangles) and two copies of spot, each at 200 seeded poses. One iteration
//! runs all 200 queries: divide by 200 for the time per query. Node pairs per query and
//! bytes per triangle are printed once before the timings (`examples/trees.rs` prints the
//! full comparison). `cargo bench --features peers --bench trees`.

use bvkit_support::common;
use bvkit_support::parry3d;
use bvkit_support::trimesh;

use std::hint::black_box;
use std::ops::ControlFlow;
use std::time::Duration;

use bvkit::Rigid3;
use bvkit::tree::{Paired, Quantized, TriMesh};
use bvkit_support::criterion;
use criterion::{Criterion, criterion_group, criterion_main};
use parry3d::bounding_volume::BoundingVolume;
use parry3d::math::Pose;
use parry3d::query;
use parry3d::shape::TriMesh as ParryMesh;

type Mesh = (Vec<glam::Vec3>, Vec<[u32; 3]>);

fn parry_pose(p: &Rigid3) -> Pose {
    Pose::from_parts(p.translation.into(), p.rotation)
}

fn parry_intersects(a: &ParryMesh, b: &ParryMesh, poses: &[Rigid3]) -> usize {
    poses
        .iter()
        .filter(|&p| {
            query::intersection_test(&Pose::IDENTITY, a, &parry_pose(p), b)
                .map(|r| r.intersecting)
                .unwrap_or(false)
        })
        .count()
}

fn parry_pairs(a: &ParryMesh, b: &ParryMesh, poses: &[Rigid3]) -> usize {
    poses
        .iter()
        .map(|p| {
            let pos12 = parry_pose(p);
            a.bvh()
                .leaf_pairs(b.bvh(), |n1, n2| {
                    n1.aabb().intersects(&n2.aabb().transform_by(&pos12))
                })
                .filter(|&(i, j)| {
                    let (t1, t2) = (a.triangle(i), b.triangle(j).transformed(&pos12));
                    query::intersection_test(&Pose::IDENTITY, &t1, &Pose::IDENTITY, &t2)
                        .map(|r| r.intersecting)
                        .unwrap_or(false)
                })
                .count()
        })
        .sum()
}

fn scene(c: &mut Criterion, name: &str, ma: Mesh, mb: Mesh, poses: Vec<Rigid3>) {
    let a = TriMesh::new(ma.0.clone(), ma.1.clone()).unwrap();
    let b = TriMesh::new(mb.0.clone(), mb.1.clone()).unwrap();
    let (aq, bq) = (a.with_layout::<Quantized>(), b.with_layout::<Quantized>());
    let (aw, bw) = (a.with_layout::<Paired>(), b.with_layout::<Paired>());
    let pa = ParryMesh::new(ma.0, ma.1).unwrap();
    let pb = ParryMesh::new(mb.0, mb.1).unwrap();
    let id = Rigid3::IDENTITY;
    let n = poses.len() as f64;
    let (mut first, mut all) = (0u64, 0u64);
    for &p in &poses {
        first += a.query(id, &b, p).unwrap().first_contact().1.node_pairs;
        all += a
            .query(id, &b, p)
            .unwrap()
            .visit(|_, _| ControlFlow::Continue(()))
            .1
            .node_pairs;
    }
    let tris = b.triangles().len() as f64;
    println!(
        "{name}: node pairs/query first contact {:.0}, all pairs {:.0}; B/tri compact {:.1}, quantized {:.1}, paired {:.1}, parry {:.1}",
        first as f64 / n,
        all as f64 / n,
        b.tree_bytes() as f64 / tris,
        bq.tree_bytes() as f64 / tris,
        bw.tree_bytes() as f64 / tris,
        pb.bvh().total_memory_size() as f64 / tris,
    );
    let mut g = c.benchmark_group(format!("trees/{name}"));
    g.sample_size(10)
        .measurement_time(Duration::from_secs(2))
        .warm_up_time(Duration::from_millis(300));
    g.bench_function("intersects/bvkit", |it| {
        it.iter(|| {
            poses
                .iter()
                .filter(|&&p| a.intersects(id, black_box(&b), p).unwrap())
                .count()
        })
    });
    g.bench_function("intersects/bvkit-quantized", |it| {
        it.iter(|| {
            poses
                .iter()
                .filter(|&&p| aq.intersects(id, black_box(&bq), p).unwrap())
                .count()
        })
    });
    g.bench_function("intersects/bvkit-paired", |it| {
        it.iter(|| {
            poses
                .iter()
                .filter(|&&p| aw.intersects(id, black_box(&bw), p).unwrap())
                .count()
        })
    });
    g.bench_function("intersects/parry3d", |it| {
        it.iter(|| parry_intersects(&pa, black_box(&pb), &poses))
    });
    g.bench_function("pairs/bvkit", |it| {
        it.iter(|| {
            poses
                .iter()
                .map(|&p| a.overlapping_triangles(id, black_box(&b), p).unwrap().len())
                .sum::<usize>()
        })
    });
    g.bench_function("pairs/bvkit-quantized", |it| {
        it.iter(|| {
            poses
                .iter()
                .map(|&p| {
                    aq.overlapping_triangles(id, black_box(&bq), p)
                        .unwrap()
                        .len()
                })
                .sum::<usize>()
        })
    });
    g.bench_function("pairs/bvkit-paired", |it| {
        it.iter(|| {
            poses
                .iter()
                .map(|&p| {
                    aw.overlapping_triangles(id, black_box(&bw), p)
                        .unwrap()
                        .len()
                })
                .sum::<usize>()
        })
    });
    g.bench_function("pairs/parry3d", |it| {
        it.iter(|| parry_pairs(&pa, black_box(&pb), &poses))
    });
    g.finish();
}

fn bench(c: &mut Criterion) {
    common::announce("trees");
    scene(
        c,
        "tori",
        trimesh::torus(1.0, 0.3, 50, 50),
        trimesh::torus(1.0, 0.3, 100, 100),
        trimesh::poses(200, 0.9, 11),
    );
    scene(
        c,
        "spot",
        trimesh::spot(),
        trimesh::spot(),
        trimesh::poses(200, 0.5, 12),
    );
}

criterion_group!(benches, bench);
criterion_main!(benches);
