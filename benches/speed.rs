//! Where users call bvkit, in one process: a hand-written glam loop and a parry3d loop,
//! single-box calls, AoS, SoA and AoSoA batches on the best backend, and the memory
//! rooflines, at 256 (L1), 1K, 64K and 4M boxes, for affine maps and rigid poses; and in
//! cache (256, 1K) the translation class in every layout against a glam translation loop,
//! and the 2D classes as AoS slices. The CPU and the backend are printed first.
//! `cargo bench --features peers --bench speed`; `scripts/bench_report.py speed` tabulates a run.

use bvkit_support::common;

use std::hint::black_box;

use bvkit::{
    Aabb2, Aabb3, Aabb3x8, AabbSoa, Affine3Soa, Affine3x8, Batch, Block8, Method, Rigid2, Rigid3,
    Rigid3x8, Rounding, Soa, Translation2, Translation3,
};
use bvkit_support::criterion;
use criterion::measurement::WallTime;
use criterion::{
    BenchmarkGroup, BenchmarkId, Criterion, Throughput, criterion_group, criterion_main,
};
use glam::{Affine2, Mat2};

use common::*;

const SIZES: [(usize, &str); 4] = [
    (1 << 8, "256"),
    (1 << 10, "1K"),
    (1 << 16, "64K"),
    (1 << 22, "4M"),
];

const KERNELS: [(Method, Rounding); 4] = [
    (Method::AbsMatrix, Rounding::Nearest),
    (Method::AbsMatrix, Rounding::Outward),
    (Method::SignSelect, Rounding::Nearest),
    (Method::SignSelect, Rounding::Outward),
];

fn bench(c: &mut Criterion) {
    announce("speed");
    for (n, size) in SIZES {
        let s = class_scene(n, 0x5eed);
        let boxes = &s.boxes;
        let (b8, x8, r8) = (
            Aabb3x8::pack(boxes),
            Affine3x8::pack(&s.affine),
            Rigid3x8::pack(&s.rigid),
        );
        let (bs, xs, rs) = (
            AabbSoa::from_slice(boxes),
            Affine3Soa::from_slice(&s.affine),
            Soa::<Rigid3>::from_slice(&s.rigid),
        );
        let (pb, pp) = parry_scene(boxes, &s.poses);
        let (braw, xraw, rraw) = (
            raw(&b8, |b| b.fields),
            raw(&x8, |x| x.fields),
            raw(&r8, |x| x.fields),
        );
        let mut oraw = braw.clone();
        let mut o8 = vec![Aabb3x8::default(); b8.len()];
        let mut os = AabbSoa::filled(n, Aabb3::EMPTY);
        let mut oa = vec![Aabb3::EMPTY; n];
        let mut op = pb.clone();

        let mut g = c.benchmark_group(format!("speed/{size}"));
        g.throughput(Throughput::Elements(n as u64));
        configure(&mut g, n);

        g.bench_function("roofline/aos", |b| {
            b.iter(|| roofline_aos(black_box(boxes), black_box(&s.affine), &mut oa))
        });
        g.bench_function("roofline/soa", |b| {
            b.iter(|| roofline_soa(black_box(&bs), black_box(&xs), &mut os))
        });
        g.bench_function("roofline/aosoa", |b| {
            b.iter(|| roofline_blocks(black_box(&braw), black_box(&xraw), &mut oraw))
        });
        g.bench_function("roofline/aosoa-rigid", |b| {
            b.iter(|| roofline_blocks(black_box(&braw), black_box(&rraw), &mut oraw))
        });
        // Non-temporal stores (issue 9): kept in bvkit only if this beats the plain roofline.
        #[cfg(target_arch = "x86_64")]
        g.bench_function("roofline/aosoa-stream", |b| {
            b.iter(|| roofline_blocks_streaming(black_box(&braw), black_box(&xraw), &mut o8))
        });
        g.bench_function("peer/glam-abs-matrix", |b| {
            b.iter(|| glam_abs_matrix(black_box(boxes), black_box(&s.affine), &mut oa))
        });
        g.bench_function("peer/glam-rigid-abs-matrix", |b| {
            b.iter(|| glam_rigid_abs_matrix(black_box(boxes), black_box(&s.rigid), &mut oa))
        });
        g.bench_function("peer/parry3d-transform_by", |b| {
            b.iter(|| parry_transform_by(black_box(&pb), black_box(&pp), &mut op))
        });

        for (method, rounding) in KERNELS {
            let kernel = format!("{}/{}", method.name(), rounding.name());
            let batch = Batch::new(method, rounding);
            g.bench_function(BenchmarkId::new("single", &kernel), |b| {
                b.iter(|| single_loop(black_box(boxes), &s.affine, &mut oa, method, rounding))
            });
            g.bench_function(BenchmarkId::new("single-rigid", &kernel), |b| {
                b.iter(|| single_loop(black_box(boxes), &s.rigid, &mut oa, method, rounding))
            });
            g.bench_function(BenchmarkId::new("aos", &kernel), |b| {
                b.iter(|| batch.transform(black_box(boxes), black_box(&s.affine), &mut oa))
            });
            g.bench_function(BenchmarkId::new("aos-rigid", &kernel), |b| {
                b.iter(|| batch.transform(black_box(boxes), black_box(&s.rigid), &mut oa))
            });
            g.bench_function(BenchmarkId::new("soa", &kernel), |b| {
                b.iter(|| batch.transform(black_box(&bs), black_box(&xs), &mut os))
            });
            g.bench_function(BenchmarkId::new("soa-rigid", &kernel), |b| {
                b.iter(|| batch.transform(black_box(&bs), black_box(&rs), &mut os))
            });
            g.bench_function(BenchmarkId::new("aosoa", &kernel), |b| {
                b.iter(|| batch.transform(black_box(&b8), black_box(&x8), &mut o8))
            });
            g.bench_function(BenchmarkId::new("aosoa-rigid", &kernel), |b| {
                b.iter(|| batch.transform(black_box(&b8), black_box(&r8), &mut o8))
            });
        }
        if n <= 1 << 10 {
            classes_in_cache(&mut g, &s);
        }
        g.finish();
    }
}

/// The glam loop a user writes for translations.
fn glam_translation(boxes: &[Aabb3], xfs: &[Translation3], out: &mut [Aabb3]) {
    for ((b, t), o) in boxes.iter().zip(xfs).zip(out) {
        *o = Aabb3::new(b.min + t.0, b.max + t.0);
    }
}

/// The translation class in every layout, and the 2D classes as AoS slices, in cache:
/// rows of the subnormal issue's table (Outward against Nearest, and the glam loop).
fn classes_in_cache(g: &mut BenchmarkGroup<'_, WallTime>, s: &ClassScene) {
    let boxes = &s.boxes;
    let n = boxes.len();
    let (b8, t8) = (Aabb3x8::pack(boxes), Block8::pack(&s.translation));
    let (bs, ts) = (AabbSoa::from_slice(boxes), Soa::from_slice(&s.translation));
    let mut o8 = vec![Aabb3x8::default(); b8.len()];
    let mut os = AabbSoa::filled(n, Aabb3::EMPTY);
    let mut oa = vec![Aabb3::EMPTY; n];
    let boxes2: Vec<Aabb2> = boxes
        .iter()
        .map(|b| Aabb2::new(b.min.truncate(), b.max.truncate()))
        .collect();
    let rigid2: Vec<Rigid2> = s
        .rigid
        .iter()
        .map(|p| {
            let (axis, angle) = p.rotation.to_axis_angle();
            Rigid2::from_angle_translation(angle * axis.z.signum(), p.translation.truncate())
        })
        .collect();
    let translation2: Vec<Translation2> =
        rigid2.iter().map(|p| Translation2(p.translation)).collect();
    let affine2: Vec<Affine2> = rigid2
        .iter()
        .zip(&s.trs)
        .map(|(p, t)| Affine2::from_mat2(Mat2::from_diagonal(t.scale.truncate())) * p.to_affine2())
        .collect();
    let mut o2 = vec![Aabb2::EMPTY; n];

    g.bench_function("peer/glam-translation", |b| {
        b.iter(|| glam_translation(black_box(boxes), black_box(&s.translation), &mut oa))
    });
    for rounding in Rounding::ALL {
        let batch = Batch::new(Method::AbsMatrix, rounding);
        let r = rounding.name();
        g.bench_function(BenchmarkId::new("single-translation", r), |b| {
            b.iter(|| {
                single_loop(
                    black_box(boxes),
                    &s.translation,
                    &mut oa,
                    Method::AbsMatrix,
                    rounding,
                )
            })
        });
        g.bench_function(BenchmarkId::new("aos-translation", r), |b| {
            b.iter(|| batch.transform(black_box(boxes), black_box(&s.translation), &mut oa))
        });
        g.bench_function(BenchmarkId::new("soa-translation", r), |b| {
            b.iter(|| batch.transform(black_box(&bs), black_box(&ts), &mut os))
        });
        g.bench_function(BenchmarkId::new("aosoa-translation", r), |b| {
            b.iter(|| batch.transform(black_box(&b8), black_box(&t8), &mut o8))
        });
        g.bench_function(BenchmarkId::new("aos2-translation", r), |b| {
            b.iter(|| batch.transform(black_box(&boxes2), black_box(&translation2), &mut o2))
        });
    }
    for (method, rounding) in KERNELS {
        let kernel = format!("{}/{}", method.name(), rounding.name());
        let batch = Batch::new(method, rounding);
        g.bench_function(BenchmarkId::new("aos2-rigid", &kernel), |b| {
            b.iter(|| batch.transform(black_box(&boxes2), black_box(&rigid2), &mut o2))
        });
        g.bench_function(BenchmarkId::new("aos2-affine", &kernel), |b| {
            b.iter(|| batch.transform(black_box(&boxes2), black_box(&affine2), &mut o2))
        });
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
