//! Single-box kernels over a loop of 1024 boxes, with peers in the same group.
//! `cargo bench --features peers --bench single`.

use bvkit_support::common;

use std::hint::black_box;
use std::time::Duration;

use bvkit::{Aabb2, Aabb3, Method, Rigid2, Rounding};
use bvkit_support::criterion;
use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use glam::Vec2;

use common::*;

const LOOP: usize = 1024;

fn bench(c: &mut Criterion) {
    announce("single");
    let (boxes, xfs, poses) = scene(LOOP, 0x51e);
    let (pb, pp) = parry_scene(&boxes, &poses);
    let boxes2: Vec<Aabb2> = boxes
        .iter()
        .map(|b| Aabb2::new(b.min.truncate(), b.max.truncate()))
        .collect();
    let rigid: Vec<Rigid2> = poses
        .iter()
        .map(|(q, t)| Rigid2::from_angle_translation(q.to_axis_angle().1, Vec2::new(t.x, t.y)))
        .collect();
    let mut out = vec![Aabb3::EMPTY; LOOP];
    let mut out2 = vec![Aabb2::EMPTY; LOOP];
    let mut op = pb.clone();

    let mut g = c.benchmark_group("single");
    g.throughput(Throughput::Elements(LOOP as u64));
    g.sample_size(50)
        .measurement_time(Duration::from_secs(2))
        .warm_up_time(Duration::from_millis(300));
    g.bench_function("peer/parry3d-transform_by", |b| {
        b.iter(|| parry_transform_by(black_box(&pb), black_box(&pp), &mut op))
    });
    g.bench_function("peer/glam-8-corner", |b| {
        b.iter(|| glam_corners(black_box(&boxes), black_box(&xfs), &mut out))
    });
    g.bench_function("peer/glam-abs-matrix", |b| {
        b.iter(|| glam_abs_matrix(black_box(&boxes), black_box(&xfs), &mut out))
    });
    for method in Method::ALL {
        for rounding in Rounding::ALL {
            let kernel = format!("{}/{}", method.name(), rounding.name());
            g.bench_function(BenchmarkId::new("3d", &kernel), |b| {
                b.iter(|| {
                    for ((bx, xf), o) in black_box(&boxes).iter().zip(black_box(&xfs)).zip(&mut out)
                    {
                        *o = bx.transformed(xf, method, rounding);
                    }
                })
            });
            g.bench_function(BenchmarkId::new("3d-scalar", &kernel), |b| {
                b.iter(|| {
                    for ((bx, xf), o) in black_box(&boxes).iter().zip(black_box(&xfs)).zip(&mut out)
                    {
                        *o = bx.transformed_scalar(xf, method, rounding);
                    }
                })
            });
            g.bench_function(BenchmarkId::new("2d-rigid", &kernel), |b| {
                b.iter(|| {
                    for ((bx, xf), o) in black_box(&boxes2)
                        .iter()
                        .zip(black_box(&rigid))
                        .zip(&mut out2)
                    {
                        *o = bx.transformed_rigid(xf, method, rounding);
                    }
                })
            });
        }
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
