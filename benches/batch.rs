//! Batch kernels at L1, L2 and DRAM sizes, per layout and backend, with peers and the memory
//! roofline in the same run. `cargo bench --features peers --bench batch`.

use bvkit_support::common;

use std::hint::black_box;

use bvkit::{Aabb3, Aabb3x8, AabbSoa, Affine3Soa, Affine3x8, Backend, Batch, Method, Rounding};
use bvkit_support::criterion;
use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};

use common::*;

const SIZES: [(usize, &str); 3] = [(1 << 10, "1K"), (1 << 16, "64K"), (1 << 22, "4M")];

fn kernels() -> Vec<(Method, Rounding)> {
    vec![
        (Method::AbsMatrix, Rounding::Nearest),
        (Method::AbsMatrix, Rounding::Outward),
        (Method::SignSelect, Rounding::Nearest),
        (Method::SignSelect, Rounding::Outward),
    ]
}

fn bench(c: &mut Criterion) {
    announce("batch");
    let best = Backend::detect();
    for (n, size) in SIZES {
        let (boxes, xfs, poses) = scene(n, 0x5eed);
        let (b8, x8) = (Aabb3x8::pack(&boxes), Affine3x8::pack(&xfs));
        let (bs, xs) = (AabbSoa::from_slice(&boxes), Affine3Soa::from_slice(&xfs));
        let (pb, pp) = parry_scene(&boxes, &poses);
        let mut o8 = vec![Aabb3x8::default(); b8.len()];
        let (braw, xraw) = (raw(&b8, |b| b.fields), raw(&x8, |x| x.fields));
        let mut oraw = braw.clone();
        let mut os = AabbSoa::filled(n, Aabb3::EMPTY);
        let mut oa = vec![Aabb3::EMPTY; n];
        let mut op = pb.clone();

        let mut g = c.benchmark_group(format!("batch/{size}"));
        g.throughput(Throughput::Elements(n as u64));
        configure(&mut g, n);

        g.bench_function("roofline/aosoa", |b| {
            b.iter(|| roofline_blocks(black_box(&braw), black_box(&xraw), &mut oraw))
        });
        g.bench_function("roofline/soa", |b| {
            b.iter(|| roofline_soa(black_box(&bs), black_box(&xs), &mut os))
        });
        g.bench_function("roofline/aos", |b| {
            b.iter(|| roofline_aos(black_box(&boxes), black_box(&xfs), &mut oa))
        });
        g.bench_function("peer/parry3d-transform_by", |b| {
            b.iter(|| parry_transform_by(black_box(&pb), black_box(&pp), &mut op))
        });
        g.bench_function("peer/glam-8-corner", |b| {
            b.iter(|| glam_corners(black_box(&boxes), black_box(&xfs), &mut oa))
        });
        g.bench_function("peer/glam-abs-matrix", |b| {
            b.iter(|| glam_abs_matrix(black_box(&boxes), black_box(&xfs), &mut oa))
        });

        for (method, rounding) in kernels() {
            let kernel = format!("{}/{}", method.name(), rounding.name());
            for backend in Backend::supported() {
                let batch = Batch::new(method, rounding).on(backend).unwrap();
                g.bench_function(
                    BenchmarkId::new(format!("aosoa/{}", backend.name()), &kernel),
                    |b| {
                        b.iter(|| {
                            batch
                                .transform(black_box(&b8), black_box(&x8), &mut o8)
                                .unwrap()
                        })
                    },
                );
            }
            for backend in [Backend::Scalar, best] {
                let batch = Batch::new(method, rounding).on(backend).unwrap();
                g.bench_function(
                    BenchmarkId::new(format!("soa/{}", backend.name()), &kernel),
                    |b| {
                        b.iter(|| {
                            batch
                                .transform(
                                    black_box(bs.view()),
                                    black_box(xs.view()),
                                    os.view_mut(),
                                )
                                .unwrap()
                        })
                    },
                );
                g.bench_function(
                    BenchmarkId::new(format!("aos/{}", backend.name()), &kernel),
                    |b| {
                        b.iter(|| {
                            batch
                                .transform(black_box(&boxes), black_box(&xfs), &mut oa)
                                .unwrap()
                        })
                    },
                );
            }
        }
        for rounding in Rounding::ALL {
            let batch = Batch::new(Method::Naive, rounding);
            g.bench_function(
                BenchmarkId::new(
                    format!("aosoa/{}", best.name()),
                    format!("naive/{}", rounding.name()),
                ),
                |b| {
                    b.iter(|| {
                        batch
                            .transform(black_box(&b8), black_box(&x8), &mut o8)
                            .unwrap()
                    })
                },
            );
        }
        g.finish();
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
