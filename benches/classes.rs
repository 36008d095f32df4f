//! Per transform class: ns per box in cache (4K boxes) and from DRAM (4M boxes), AoSoA and
//! AoS on the best backend, against a memory roofline that moves that class's bytes, with
//! the peers on the same poses in the same run. `cargo bench --features peers --bench classes`.
//!
//! Bytes per box (AoSoA, read + written): box 24 + output 24 + the class's fields:
//! translation 12 (60), rigid 28 (76), similarity 32 (80), scale-rotation-translation 40
//! (88), affine 48 (96).

use bvkit_support::common;

use std::hint::black_box;

use bvkit::{Aabb3, Aabb3x8, Batch, Block8, Method, Rounding, Transform3};
use bvkit_support::criterion;
use criterion::{BenchmarkGroup, Criterion, Throughput, criterion_group, criterion_main};

use common::*;

const SIZES: [(usize, &str); 2] = [(1 << 12, "4K"), (1 << 22, "4M")];

/// The kernels measured per class.
const KERNELS: [(Method, Rounding); 2] = [
    (Method::AbsMatrix, Rounding::Nearest),
    (Method::SignSelect, Rounding::Outward),
];

fn class<T: Transform3, const F: usize>(
    g: &mut BenchmarkGroup<'_, criterion::measurement::WallTime>,
    name: &str,
    boxes: &[Aabb3],
    xfs: &[T],
    fields: impl Fn(&Block8<T>) -> [[f32; 8]; F],
) {
    let (b8, x8) = (Aabb3x8::pack(boxes), Block8::pack(xfs));
    let (braw, xraw) = (common::raw(&b8, |b| b.fields), common::raw(&x8, fields));
    let mut oraw = braw.clone();
    let mut o8 = vec![Aabb3x8::default(); b8.len()];
    let mut out = vec![Aabb3::EMPTY; boxes.len()];
    g.bench_function(format!("roofline/{name}"), |b| {
        b.iter(|| roofline_blocks(black_box(&braw), black_box(&xraw), &mut oraw))
    });
    for (method, rounding) in KERNELS {
        let batch = Batch::new(method, rounding);
        let kernel = format!("{}/{}", method.name(), rounding.name());
        g.bench_function(format!("aosoa/{name}/{kernel}"), |b| {
            b.iter(|| {
                batch
                    .transform(black_box(&b8), black_box(&x8), &mut o8)
                    .unwrap()
            })
        });
        g.bench_function(format!("aos/{name}/{kernel}"), |b| {
            b.iter(|| {
                batch
                    .transform(black_box(boxes), black_box(xfs), &mut out[..])
                    .unwrap()
            })
        });
    }
}

fn bench(c: &mut Criterion) {
    announce("classes");
    for (n, size) in SIZES {
        let s = class_scene(n, 0xc1a55);
        let (pb, pp) = parry_scene(&s.boxes, &s.poses);
        let mut op = pb.clone();
        let mut out = vec![Aabb3::EMPTY; n];

        let mut g = c.benchmark_group(format!("classes/{size}"));
        g.throughput(Throughput::Elements(n as u64));
        configure(&mut g, n);
        g.bench_function("peer/parry3d-transform_by", |b| {
            b.iter(|| parry_transform_by(black_box(&pb), black_box(&pp), &mut op))
        });
        g.bench_function("peer/glam-abs-matrix-affine", |b| {
            b.iter(|| glam_abs_matrix(black_box(&s.boxes), black_box(&s.affine), &mut out))
        });
        g.bench_function("peer/glam-abs-matrix-rigid", |b| {
            b.iter(|| glam_rigid_abs_matrix(black_box(&s.boxes), black_box(&s.rigid), &mut out))
        });
        class(&mut g, "translation3", &s.boxes, &s.translation, |b| {
            b.fields
        });
        class(&mut g, "rigid3", &s.boxes, &s.rigid, |b| b.fields);
        class(&mut g, "similarity3", &s.boxes, &s.similarity, |b| b.fields);
        class(&mut g, "trs3", &s.boxes, &s.trs, |b| b.fields);
        class(&mut g, "affine3", &s.boxes, &s.affine, |b| b.fields);
        g.finish();
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
