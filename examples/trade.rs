//! The speed/accuracy trade of every kernel, measured: `cargo run --release --example trade`.
//!
//! For 3D affine, 2D affine and 2D rigid transforms, every method × rounding × layout
//! (single box, AoS, SoA, AoSoA) on the best backend of this CPU and on the scalar
//! backend, with the peers a user would otherwise write and the memory rooflines:
//!
//! - ns per box at an in-cache batch and a DRAM-sized batch (medians of repeated runs);
//! - against the exact oracle (`tests/oracle`), on a seeded sample over the finite
//!   extreme classes: the worst face error in units of `u·S`, the fraction of results
//!   that contain the exact box, and the mean volume overhead over the exact box;
//! - the ratio to the fastest kernel of the same transform class.
//!
//! It prints Markdown, with a recommendation per scene profile, and writes the same data
//! as CSV and an SVG plot to the paths it prints. Timings vary run to run; the accuracy
//! columns are identical for the fixed seed.

#[path = "../tests/cases/mod.rs"]
mod cases;
#[path = "../benches/common/mod.rs"]
mod common;
#[path = "../tests/oracle/mod.rs"]
mod oracle;

use std::fmt::Write as _;
use std::hint::black_box;
use std::path::PathBuf;
use std::time::Instant;

use bvkit::{
    Aabb2, Aabb3, Aabb3x8, AabbSoa, Affine3Soa, Affine3x8, Backend, Batch, Block8, Method, Rigid2,
    Rounding, Transform2, Transform3, Translation2, Translation3,
};
use glam::{Affine2, Affine3A, Vec2, Vec3A};

use cases::{Class, Scale, problem, quat_problem, rigid_problem, rng, translation_problem};
use oracle::{Bound, Exactly, Problem, QuatProblem, affine2, affine3, check, rigid2};

/// The seed of every random sample: the accuracy columns are identical run to run.
const SEED: u64 = 0xb0c5_2026;
/// Boxes of the in-cache batch (inputs and outputs fit in L2).
const CACHE: usize = 4096;
/// Boxes of the DRAM batch.
const DRAM: usize = 1 << 22;
/// Oracle cases per class.
const CASES: u64 = 1500;
/// The finite classes the accuracy columns are measured over.
const ACCURACY_CLASSES: [Class; 9] = [
    Class::Typical,
    Class::Far,
    Class::Subnormal,
    Class::ZeroSize,
    Class::Reflection,
    Class::Shear,
    Class::NearSingular,
    Class::Drifted,
    Class::QuarterTurn,
];

/// One measured kernel.
#[derive(Clone, Debug)]
struct Row {
    class: &'static str,
    kernel: String,
    method: Option<Method>,
    rounding: Option<Rounding>,
    layout: &'static str,
    backend: &'static str,
    ns_cache: f64,
    ns_dram: f64,
    accuracy: Option<Accuracy>,
    ratio: f64,
}

/// What the oracle measured of one kernel over the sample.
#[derive(Clone, Copy, Debug)]
struct Accuracy {
    worst_error_us: f64,
    contains: f64,
    overhead: f64,
}

/// The median ns per box of `reps` runs of `run` over `n` boxes.
fn ns_per_box(n: usize, reps: usize, mut run: impl FnMut()) -> f64 {
    run();
    let mut samples: Vec<f64> = (0..reps)
        .map(|_| {
            let start = Instant::now();
            run();
            start.elapsed().as_secs_f64() * 1e9 / n as f64
        })
        .collect();
    samples.sort_by(f64::total_cmp);
    samples[reps / 2]
}

/// Times `run(n)` at the in-cache and the DRAM size.
fn times(mut run: impl FnMut(usize)) -> (f64, f64) {
    (
        ns_per_box(CACHE, 301, || run(CACHE)),
        ns_per_box(DRAM, 5, || run(DRAM)),
    )
}

/// The seeded oracle sample.
fn sample<const N: usize>(
    make: impl Fn(Class, &mut rand::rngs::StdRng) -> Problem<N>,
) -> Vec<(Class, Problem<N>)> {
    let mut out = Vec::new();
    for class in ACCURACY_CLASSES {
        let r = &mut rng(SEED ^ (class as u64) << 40);
        out.extend((0..CASES).map(|_| (class, make(class, r))));
    }
    out
}

/// Checks `results` against the oracle (panics on a broken contract: the report must not
/// print figures of a kernel that is wrong) and summarises.
fn accuracy<const N: usize, P: Exactly<N>>(
    sample: &[(Class, P)],
    results: &[([f32; N], [f32; N])],
    bound: Bound,
) -> Accuracy {
    let (mut worst, mut contained, mut overhead_sum, mut overhead_count) =
        (0.0f64, 0usize, 0.0, 0usize);
    for ((class, p), (min, max)) in sample.iter().zip(results) {
        let m =
            check(p, *min, *max, bound).unwrap_or_else(|e| panic!("contract broken: {e}\n{p:?}"));
        worst = worst.max(m.worst_error_us);
        contained += usize::from(m.contains);
        if let (Class::Typical, Some(o)) = (class, m.overhead) {
            overhead_sum += o;
            overhead_count += 1;
        }
    }
    Accuracy {
        worst_error_us: worst,
        contains: contained as f64 / sample.len() as f64,
        overhead: overhead_sum / overhead_count as f64,
    }
}

fn flat3(b: &Aabb3) -> ([f32; 3], [f32; 3]) {
    (b.min.to_array(), b.max.to_array())
}

fn flat2(b: &Aabb2) -> ([f32; 2], [f32; 2]) {
    (b.min.to_array(), b.max.to_array())
}

fn progress(what: &str) {
    eprintln!("  {what}");
}

/// Every 3D kernel, layout and backend, with peers and rooflines.
fn measure_3d(backends: &[Backend]) -> Vec<Row> {
    let mut rows = Vec::new();
    let (boxes, xfs, poses) = common::scene(DRAM, 0x3d);
    let (b8, x8) = (Aabb3x8::pack(&boxes), Affine3x8::pack(&xfs));
    let (bs, xs) = (AabbSoa::from_slice(&boxes), Affine3Soa::from_slice(&xfs));
    let mut out = vec![Aabb3::EMPTY; DRAM];
    let mut o8 = vec![Aabb3x8::default(); b8.len()];
    let mut os = AabbSoa::filled(DRAM, Aabb3::EMPTY);
    let sample = sample::<3>(problem);
    let (sb, sx): (Vec<Aabb3>, Vec<Affine3A>) = sample.iter().map(|(_, p)| affine3(p)).unzip();
    let row = |kernel: String,
               method,
               rounding,
               layout,
               backend: &'static str,
               (ns_cache, ns_dram),
               accuracy| Row {
        class: "3D affine",
        kernel,
        method,
        rounding,
        layout,
        backend,
        ns_cache,
        ns_dram,
        accuracy,
        ratio: 0.0,
    };

    progress("3D peers and rooflines");
    let (pb, pp) = common::parry_scene(&boxes, &poses);
    let mut op = pb.clone();
    let t = times(|n| {
        common::parry_transform_by(black_box(&pb[..n]), black_box(&pp[..n]), &mut op[..n])
    });
    rows.push(row(
        "parry3d Aabb::transform_by (rigid)".into(),
        None,
        None,
        "aos",
        "peer",
        t,
        None,
    ));
    let peer_accuracy = |f: fn(&[Aabb3], &[Affine3A], &mut [Aabb3])| {
        let mut o = vec![Aabb3::EMPTY; sb.len()];
        f(&sb, &sx, &mut o);
        let results: Vec<_> = o.iter().map(flat3).collect();
        Some(accuracy(
            &sample,
            &results,
            Bound::Nearest {
                gamma_n: 1 << 20,
                tiny: 1e30,
            },
        ))
    };
    let t = times(|n| {
        common::glam_corners(black_box(&boxes[..n]), black_box(&xfs[..n]), &mut out[..n])
    });
    rows.push(row(
        "glam 8-corner loop".into(),
        None,
        None,
        "aos",
        "peer",
        t,
        peer_accuracy(common::glam_corners),
    ));
    let t = times(|n| {
        common::glam_abs_matrix(black_box(&boxes[..n]), black_box(&xfs[..n]), &mut out[..n])
    });
    rows.push(row(
        "glam abs-matrix loop".into(),
        None,
        None,
        "aos",
        "peer",
        t,
        peer_accuracy(common::glam_abs_matrix),
    ));
    let (braw, xraw) = (
        common::raw(&b8, |b| b.fields),
        common::raw(&x8, |x| x.fields),
    );
    let mut oraw = braw.clone();
    let t = times(|n| {
        common::roofline_blocks(
            black_box(&braw[..n / 8]),
            black_box(&xraw[..n / 8]),
            &mut oraw[..n / 8],
        )
    });
    rows.push(row(
        "memory roofline".into(),
        None,
        None,
        "aosoa",
        "roofline",
        t,
        None,
    ));
    let small = |n: usize| {
        let b = AabbSoa::from_columns(bs.columns.clone().map(|c| c[..n].to_vec()));
        let x = Affine3Soa::from_columns(xs.columns.clone().map(|c| c[..n].to_vec()));
        (b, x, AabbSoa::filled(n, Aabb3::EMPTY))
    };
    let (cb, cx, mut co) = small(CACHE);
    let t = (
        ns_per_box(CACHE, 301, || {
            common::roofline_soa(black_box(&cb), black_box(&cx), &mut co)
        }),
        ns_per_box(DRAM, 5, || {
            common::roofline_soa(black_box(&bs), black_box(&xs), &mut os)
        }),
    );
    rows.push(row(
        "memory roofline".into(),
        None,
        None,
        "soa",
        "roofline",
        t,
        None,
    ));
    let t = times(|n| {
        common::roofline_aos(black_box(&boxes[..n]), black_box(&xfs[..n]), &mut out[..n])
    });
    rows.push(row(
        "memory roofline".into(),
        None,
        None,
        "aos",
        "roofline",
        t,
        None,
    ));

    for method in Method::ALL {
        for rounding in Rounding::ALL {
            let kernel = format!("{} {}", method.name(), rounding.name());
            let b3 = Bound::documented(method, rounding, 3);
            progress(&format!("3D {kernel}"));
            let t = times(|n| {
                for ((b, xf), o) in black_box(&boxes[..n])
                    .iter()
                    .zip(&xfs[..n])
                    .zip(&mut out[..n])
                {
                    *o = b.transformed(xf, method, rounding);
                }
            });
            let results: Vec<_> = sb
                .iter()
                .zip(&sx)
                .map(|(b, x)| flat3(&b.transformed(x, method, rounding)))
                .collect();
            rows.push(row(
                kernel.clone(),
                Some(method),
                Some(rounding),
                "single",
                "glam simd",
                t,
                Some(accuracy(&sample, &results, b3)),
            ));
            let t = times(|n| {
                for ((b, xf), o) in black_box(&boxes[..n])
                    .iter()
                    .zip(&xfs[..n])
                    .zip(&mut out[..n])
                {
                    *o = b.transformed_scalar(xf, method, rounding);
                }
            });
            let results: Vec<_> = sb
                .iter()
                .zip(&sx)
                .map(|(b, x)| flat3(&b.transformed_scalar(x, method, rounding)))
                .collect();
            rows.push(row(
                kernel.clone(),
                Some(method),
                Some(rounding),
                "single",
                "scalar",
                t,
                Some(accuracy(&sample, &results, b3)),
            ));

            for &backend in backends {
                let batch = Batch::new(method, rounding).on(backend).expect("supported");
                let name = backend.name();
                let mut o = vec![Aabb3::EMPTY; sb.len()];
                let t = times(|n| {
                    batch
                        .transform(black_box(&boxes[..n]), black_box(&xfs[..n]), &mut out[..n])
                        .unwrap()
                });
                batch.transform(&sb, &sx, &mut o).unwrap();
                let results: Vec<_> = o.iter().map(flat3).collect();
                rows.push(row(
                    kernel.clone(),
                    Some(method),
                    Some(rounding),
                    "aos",
                    name,
                    t,
                    Some(accuracy(&sample, &results, b3)),
                ));

                let (cb, cx, mut co) = small(CACHE);
                let t = (
                    ns_per_box(CACHE, 301, || {
                        batch
                            .transform(black_box(cb.view()), cx.view(), co.view_mut())
                            .unwrap()
                    }),
                    ns_per_box(DRAM, 5, || {
                        batch
                            .transform(black_box(bs.view()), xs.view(), os.view_mut())
                            .unwrap()
                    }),
                );
                let (ssb, ssx) = (AabbSoa::from_slice(&sb), Affine3Soa::from_slice(&sx));
                let mut sso = AabbSoa::filled(sb.len(), Aabb3::EMPTY);
                batch
                    .transform(ssb.view(), ssx.view(), sso.view_mut())
                    .unwrap();
                let results: Vec<_> = (0..sb.len()).map(|k| flat3(&sso.get(k))).collect();
                rows.push(row(
                    kernel.clone(),
                    Some(method),
                    Some(rounding),
                    "soa",
                    name,
                    t,
                    Some(accuracy(&sample, &results, b3)),
                ));

                let t = times(|n| {
                    batch
                        .transform(
                            black_box(&b8[..n / 8]),
                            black_box(&x8[..n / 8]),
                            &mut o8[..n / 8],
                        )
                        .unwrap()
                });
                let (s8, x8s) = (Aabb3x8::pack(&sb), Affine3x8::pack(&sx));
                let mut so8 = vec![Aabb3x8::default(); s8.len()];
                batch.transform(&s8, &x8s, &mut so8).unwrap();
                let results: Vec<_> = Aabb3x8::unpack(&so8, sb.len()).iter().map(flat3).collect();
                rows.push(row(
                    kernel.clone(),
                    Some(method),
                    Some(rounding),
                    "aosoa",
                    name,
                    t,
                    Some(accuracy(&sample, &results, b3)),
                ));
            }
        }
    }
    rows
}

/// Every 2D kernel (affine and rigid), single and AoS, on each backend.
fn measure_2d(backends: &[Backend]) -> Vec<Row> {
    let mut rows = Vec::new();
    let (boxes3, _, poses) = common::scene(DRAM, 0x2d);
    let boxes: Vec<Aabb2> = boxes3
        .iter()
        .map(|b| Aabb2::new(b.min.truncate(), b.max.truncate()))
        .collect();
    let rigid: Vec<Rigid2> = poses
        .iter()
        .map(|(q, t)| Rigid2::from_angle_translation(q.to_axis_angle().1, Vec2::new(t.x, t.y)))
        .collect();
    let affine: Vec<Affine2> = rigid.iter().map(Rigid2::to_affine2).collect();
    let translation: Vec<Translation2> =
        rigid.iter().map(|r| Translation2(r.translation)).collect();
    let translation_sample = sample::<2>(translation_problem::<2>);
    let (tb, tx): (Vec<Aabb2>, Vec<Translation2>) = translation_sample
        .iter()
        .map(|(_, p)| (affine2(p).0, Translation2(Vec2::from_array(p.t))))
        .unzip();
    let mut out = vec![Aabb2::EMPTY; DRAM];
    let affine_sample = sample::<2>(problem);
    let rigid_sample = sample::<2>(rigid_problem);
    let (ab, ax): (Vec<Aabb2>, Vec<Affine2>) =
        affine_sample.iter().map(|(_, p)| affine2(p)).unzip();
    let (rb, rx): (Vec<Aabb2>, Vec<Rigid2>) = rigid_sample.iter().map(|(_, p)| rigid2(p)).unzip();
    let row = |class,
               kernel: String,
               method,
               rounding,
               layout,
               backend,
               (ns_cache, ns_dram),
               accuracy| Row {
        class,
        kernel,
        method: Some(method),
        rounding: Some(rounding),
        layout,
        backend,
        ns_cache,
        ns_dram,
        accuracy: Some(accuracy),
        ratio: 0.0,
    };
    for method in Method::ALL {
        for rounding in Rounding::ALL {
            let kernel = format!("{} {}", method.name(), rounding.name());
            let b2 = Bound::documented(method, rounding, 2);
            progress(&format!("2D {kernel}"));
            let t = times(|n| {
                for ((b, xf), o) in black_box(&boxes[..n])
                    .iter()
                    .zip(&rigid[..n])
                    .zip(&mut out[..n])
                {
                    *o = b.transformed_rigid(xf, method, rounding);
                }
            });
            let results: Vec<_> = rb
                .iter()
                .zip(&rx)
                .map(|(b, x)| flat2(&b.transformed_rigid(x, method, rounding)))
                .collect();
            rows.push(row(
                "2D rigid",
                kernel.clone(),
                method,
                rounding,
                "single",
                "scalar",
                t,
                accuracy(&rigid_sample, &results, b2),
            ));
            let t = times(|n| {
                for ((b, xf), o) in black_box(&boxes[..n])
                    .iter()
                    .zip(&affine[..n])
                    .zip(&mut out[..n])
                {
                    *o = b.transformed(xf, method, rounding);
                }
            });
            let results: Vec<_> = ab
                .iter()
                .zip(&ax)
                .map(|(b, x)| flat2(&b.transformed(x, method, rounding)))
                .collect();
            rows.push(row(
                "2D affine",
                kernel.clone(),
                method,
                rounding,
                "single",
                "scalar",
                t,
                accuracy(&affine_sample, &results, b2),
            ));
            let bt = Bound::of_order(Translation2::nearest_gamma(method), rounding);
            let t = times(|n| {
                for ((b, xf), o) in black_box(&boxes[..n])
                    .iter()
                    .zip(&translation[..n])
                    .zip(&mut out[..n])
                {
                    *o = b.transformed(xf, method, rounding);
                }
            });
            let results: Vec<_> = tb
                .iter()
                .zip(&tx)
                .map(|(b, x)| flat2(&b.transformed(x, method, rounding)))
                .collect();
            let single = accuracy(&translation_sample, &results, bt);
            rows.push(row(
                TRANSLATION2,
                kernel.clone(),
                method,
                rounding,
                "single",
                "scalar",
                t,
                single,
            ));
            let batch = Batch::new(method, rounding)
                .on(backends[0])
                .expect("supported");
            let t = times(|n| {
                batch
                    .transform(
                        black_box(&boxes[..n]),
                        black_box(&translation[..n]),
                        &mut out[..n],
                    )
                    .unwrap()
            });
            let mut o = vec![Aabb2::EMPTY; tb.len()];
            batch.transform(&tb, &tx, &mut o).unwrap();
            let results: Vec<_> = o.iter().map(flat2).collect();
            let acc = accuracy(&translation_sample, &results, bt);
            rows.push(row(
                TRANSLATION2,
                kernel.clone(),
                method,
                rounding,
                "aos",
                backends[0].name(),
                t,
                acc,
            ));
            for &backend in backends {
                let batch = Batch::new(method, rounding).on(backend).expect("supported");
                let t = times(|n| {
                    batch
                        .transform(
                            black_box(&boxes[..n]),
                            black_box(&rigid[..n]),
                            &mut out[..n],
                        )
                        .unwrap()
                });
                let mut o = vec![Aabb2::EMPTY; rb.len()];
                batch.transform(&rb, &rx, &mut o).unwrap();
                let results: Vec<_> = o.iter().map(flat2).collect();
                rows.push(row(
                    "2D rigid",
                    kernel.clone(),
                    method,
                    rounding,
                    "aos",
                    backend.name(),
                    t,
                    accuracy(&rigid_sample, &results, b2),
                ));
                let t = times(|n| {
                    batch
                        .transform(
                            black_box(&boxes[..n]),
                            black_box(&affine[..n]),
                            &mut out[..n],
                        )
                        .unwrap()
                });
                batch.transform(&ab, &ax, &mut o).unwrap();
                let results: Vec<_> = o.iter().map(flat2).collect();
                rows.push(row(
                    "2D affine",
                    kernel.clone(),
                    method,
                    rounding,
                    "aos",
                    backend.name(),
                    t,
                    accuracy(&affine_sample, &results, b2),
                ));
            }
        }
    }
    rows
}

const TRANSLATION3: &str = "3D translation";
const RIGID3: &str = "3D rigid";
const SIMILARITY3: &str = "3D similarity";
const TRS3: &str = "3D scale-rotation-translation";
const TRANSLATION2: &str = "2D translation";

/// What the class table shows of one class: its bytes per box (AoSoA, read and written)
/// and its roofline row's times.
struct ClassBytes {
    class: &'static str,
    type_name: &'static str,
    bytes: usize,
}

/// Every kernel of one 3D class: AoSoA and AoS on the best backend, single boxes, and the
/// memory roofline that moves the class's bytes, with the oracle's accuracy over a sample
/// of the class's own problems.
#[allow(clippy::too_many_arguments)]
fn measure_class<T: Transform3, P: Exactly<3>, const F: usize>(
    class: &'static str,
    best: Backend,
    boxes: &[Aabb3],
    xfs: &[T],
    raw: impl Fn(&Block8<T>) -> [[f32; 8]; F],
    sample: &[(Class, P)],
    inputs: impl Fn(&P) -> (Aabb3, T),
) -> Vec<Row> {
    progress(class);
    let mut rows = Vec::new();
    let (b8, x8) = (Aabb3x8::pack(boxes), Block8::pack(xfs));
    let (braw, xraw) = (common::raw(&b8, |b| b.fields), common::raw(&x8, raw));
    let (mut oraw, mut o8) = (braw.clone(), vec![Aabb3x8::default(); b8.len()]);
    let mut out = vec![Aabb3::EMPTY; boxes.len()];
    let (sb, sx): (Vec<Aabb3>, Vec<T>) = sample.iter().map(|(_, p)| inputs(p)).unzip();
    let row =
        |kernel: String, method, rounding, layout, backend, (ns_cache, ns_dram), accuracy| Row {
            class,
            kernel,
            method,
            rounding,
            layout,
            backend,
            ns_cache,
            ns_dram,
            accuracy,
            ratio: 0.0,
        };
    let t = times(|n| {
        common::roofline_blocks(
            black_box(&braw[..n / 8]),
            black_box(&xraw[..n / 8]),
            &mut oraw[..n / 8],
        )
    });
    rows.push(row(
        "memory roofline".into(),
        None,
        None,
        "aosoa",
        "roofline",
        t,
        None,
    ));
    for method in Method::ALL {
        for rounding in Rounding::ALL {
            let kernel = format!("{} {}", method.name(), rounding.name());
            let bound = Bound::of_order(T::nearest_gamma(method), rounding);
            let batch = Batch::new(method, rounding).on(best).expect("detected");
            let mut so = vec![Aabb3::EMPTY; sb.len()];
            batch.transform(&sb, &sx, &mut so).expect("lengths");
            let results: Vec<_> = so.iter().map(flat3).collect();
            let batch_accuracy = Some(accuracy(sample, &results, bound));
            let t = times(|n| {
                batch
                    .transform(
                        black_box(&b8[..n / 8]),
                        black_box(&x8[..n / 8]),
                        &mut o8[..n / 8],
                    )
                    .expect("lengths")
            });
            let (m, r) = (Some(method), Some(rounding));
            rows.push(row(
                kernel.clone(),
                m,
                r,
                "aosoa",
                best.name(),
                t,
                batch_accuracy,
            ));
            let t = times(|n| {
                batch
                    .transform(black_box(&boxes[..n]), black_box(&xfs[..n]), &mut out[..n])
                    .expect("lengths")
            });
            rows.push(row(
                kernel.clone(),
                m,
                r,
                "aos",
                best.name(),
                t,
                batch_accuracy,
            ));
            let results: Vec<_> = sb
                .iter()
                .zip(&sx)
                .map(|(b, x)| flat3(&b.transformed(x, method, rounding)))
                .collect();
            let single_accuracy = Some(accuracy(sample, &results, bound));
            let t = times(|n| {
                for ((b, x), o) in boxes[..n].iter().zip(&xfs[..n]).zip(&mut out[..n]) {
                    *o = black_box(b).transformed(x, method, rounding);
                }
            });
            rows.push(row(kernel, m, r, "single", "glam simd", t, single_accuracy));
        }
    }
    rows
}

/// The dedicated 3D classes on one scene, with the peers on the same poses.
fn measure_classes(best: Backend) -> (Vec<Row>, Vec<ClassBytes>) {
    let s = common::class_scene(DRAM, 0xc1a55);
    let mut rows = Vec::new();
    let quats = |scale| -> Vec<(Class, QuatProblem)> {
        let mut out = Vec::new();
        for class in ACCURACY_CLASSES {
            let r = &mut rng(SEED ^ (class as u64) << 40 ^ 0x51);
            out.extend((0..CASES).map(|_| (class, quat_problem(class, scale, r))));
        }
        out
    };
    let translations = sample::<3>(translation_problem::<3>);
    rows.extend(measure_class(
        TRANSLATION3,
        best,
        &s.boxes,
        &s.translation,
        |b| b.fields,
        &translations,
        |p| (affine3(p).0, Translation3(Vec3A::from_array(p.t))),
    ));
    rows.extend(measure_class(
        RIGID3,
        best,
        &s.boxes,
        &s.rigid,
        |b| b.fields,
        &quats(Scale::Unit),
        |p| (p.aabb(), p.rigid3()),
    ));
    rows.extend(measure_class(
        SIMILARITY3,
        best,
        &s.boxes,
        &s.similarity,
        |b| b.fields,
        &quats(Scale::Uniform),
        |p| (p.aabb(), p.similarity3()),
    ));
    rows.extend(measure_class(
        TRS3,
        best,
        &s.boxes,
        &s.trs,
        |b| b.fields,
        &quats(Scale::PerAxis),
        |p| (p.aabb(), p.trs3()),
    ));
    // The peers, on the rigid poses of the same scene.
    let (pb, pp) = common::parry_scene(&s.boxes, &s.poses);
    let mut op = pb.clone();
    let mut out = vec![Aabb3::EMPTY; DRAM];
    let peer = |kernel: &str, t: (f64, f64)| Row {
        class: RIGID3,
        kernel: kernel.into(),
        method: None,
        rounding: None,
        layout: "aos",
        backend: "peer",
        ns_cache: t.0,
        ns_dram: t.1,
        accuracy: None,
        ratio: 0.0,
    };
    let t = times(|n| {
        common::parry_transform_by(black_box(&pb[..n]), black_box(&pp[..n]), &mut op[..n])
    });
    rows.push(peer("parry3d Aabb::transform_by", t));
    let t = times(|n| {
        common::glam_rigid_abs_matrix(
            black_box(&s.boxes[..n]),
            black_box(&s.rigid[..n]),
            &mut out[..n],
        )
    });
    rows.push(peer("glam loop: Mat3A::from_quat + abs-matrix", t));
    let bytes = [
        (TRANSLATION3, "Translation3", 3),
        (RIGID3, "Rigid3", 7),
        (SIMILARITY3, "Similarity3", 8),
        (TRS3, "Trs3", 10),
        ("3D affine", "Affine3A", 12),
    ]
    .map(|(class, type_name, fields)| ClassBytes {
        class,
        type_name,
        bytes: 48 + 4 * fields,
    });
    (rows, bytes.into())
}

/// The class table: per class, its bytes, the fastest AoSoA kernel against its roofline and
/// against the affine class at the DRAM size.
fn class_table(rows: &[Row], classes: &[ClassBytes], best: &str) -> String {
    let find = |class: &str, kernel: &str, layout: &str, backend: &str| {
        rows.iter().find(|r| {
            r.class == class && r.kernel == kernel && r.layout == layout && r.backend == backend
        })
    };
    let affine = find("3D affine", "abs-matrix nearest", "aosoa", best);
    let mut s = String::from(
        "| class | type | bytes/box (AoSoA) | abs-matrix nearest AoSoA ns/box cache | DRAM | roofline DRAM | × roofline (DRAM) | affine / this (DRAM) | sign-select outward AoSoA DRAM | AoS abs-matrix nearest, cache |\n|---|---|---:|---:|---:|---:|---:|---:|---:|---:|\n",
    );
    for c in classes {
        let (Some(k), Some(o), Some(rl), Some(aos)) = (
            find(c.class, "abs-matrix nearest", "aosoa", best),
            find(c.class, "sign-select outward", "aosoa", best),
            find(c.class, "memory roofline", "aosoa", "roofline"),
            find(c.class, "abs-matrix nearest", "aos", best),
        ) else {
            continue;
        };
        let vs_affine = affine.map_or(String::new(), |a| format!("{:.2}x", a.ns_dram / k.ns_dram));
        writeln!(
            s,
            "| {} | `{}` | {} | {:.2} | {:.2} | {:.2} | {:.2}x | {} | {:.2} | {:.2} |",
            c.class,
            c.type_name,
            c.bytes,
            k.ns_cache,
            k.ns_dram,
            rl.ns_dram,
            k.ns_dram / rl.ns_dram,
            vs_affine,
            o.ns_dram,
            aos.ns_cache
        )
        .unwrap();
    }
    s
}

/// Each row's in-cache time over the fastest kernel of its transform class.
fn set_ratios(rows: &mut [Row]) {
    for class in [
        "3D affine",
        "2D affine",
        "2D rigid",
        TRANSLATION3,
        RIGID3,
        SIMILARITY3,
        TRS3,
        TRANSLATION2,
    ] {
        let fastest = rows
            .iter()
            .filter(|r| r.class == class && r.method.is_some())
            .map(|r| r.ns_cache)
            .fold(f64::INFINITY, f64::min);
        rows.iter_mut()
            .filter(|r| r.class == class)
            .for_each(|r| r.ratio = r.ns_cache / fastest);
    }
}

fn pct(x: f64) -> String {
    format!("{:.1}%", x * 100.0)
}

fn table(rows: &[Row]) -> String {
    let mut s = String::new();
    s.push_str("| class | kernel | layout | backend | ns/box in cache | ns/box DRAM | worst error (u·S) | contains exact | volume overhead | × fastest |\n");
    s.push_str("|---|---|---|---|---:|---:|---:|---:|---:|---:|\n");
    for r in rows {
        let (worst, contains, overhead) = match r.accuracy {
            Some(a) => (
                format!("{:.2}", a.worst_error_us),
                pct(a.contains),
                format!("{:.2e}", a.overhead),
            ),
            None => ("".into(), "".into(), "".into()),
        };
        let worst = if r.backend == "peer" && !worst.is_empty() {
            format!("{worst} (unbounded)")
        } else {
            worst
        };
        writeln!(
            s,
            "| {} | {} | {} | {} | {:.2} | {:.2} | {} | {} | {} | {:.2} |",
            r.class,
            r.kernel,
            r.layout,
            r.backend,
            r.ns_cache,
            r.ns_dram,
            worst,
            contains,
            overhead,
            r.ratio
        )
        .unwrap();
    }
    s
}

fn csv(rows: &[Row]) -> String {
    let mut s = String::from(
        "class,kernel,layout,backend,ns_per_box_cache,ns_per_box_dram,worst_error_us,contains_fraction,mean_volume_overhead,ratio_to_fastest\n",
    );
    for r in rows {
        let a = r.accuracy.map_or(",,".to_string(), |a| {
            format!(
                "{:.6},{:.6},{:.6e}",
                a.worst_error_us, a.contains, a.overhead
            )
        });
        writeln!(
            s,
            "{},{},{},{},{:.4},{:.4},{},{:.4}",
            r.class, r.kernel, r.layout, r.backend, r.ns_cache, r.ns_dram, a, r.ratio
        )
        .unwrap();
    }
    s
}

/// Scene profiles and, for each, the fastest kernel that must contain and the fastest that
/// may miss by a few ulps, from the measured rows (in cache, where compute decides).
fn recommendations(rows: &[Row]) -> String {
    let profiles = [
        ("2D sprites, moved only", TRANSLATION2),
        ("2D sprites (rotation + translation)", "2D rigid"),
        ("2D sprites with scale or shear", "2D affine"),
        ("spheres, particles (3D translation only)", TRANSLATION3),
        ("rigid bodies (3D, quaternion + position)", RIGID3),
        ("uniformly scaled props (3D)", SIMILARITY3),
        ("scaled props (3D, bevy Transform)", TRS3),
        ("sheared / skinned (3D)", "3D affine"),
    ];
    let mut s = String::from(
        "| scene profile | must contain (fastest Outward) | a few ulps is fine (fastest Nearest within 8 u·S) |\n|---|---|---|\n",
    );
    let describe = |r: &Row| {
        let a = r.accuracy.expect("kernel rows carry accuracy");
        format!(
            "{} {} {} — {:.2} ns/box cache, {:.2} DRAM; worst {:.2} u·S, contains {}",
            r.kernel,
            r.layout,
            r.backend,
            r.ns_cache,
            r.ns_dram,
            a.worst_error_us,
            pct(a.contains)
        )
    };
    for (profile, class) in profiles {
        let kernels = || {
            rows.iter()
                .filter(move |r| r.class == class && r.accuracy.is_some() && r.method.is_some())
        };
        let fastest = |it: &mut dyn Iterator<Item = &Row>| {
            it.min_by(|a, b| a.ns_cache.total_cmp(&b.ns_cache))
                .map(describe)
                .unwrap_or_default()
        };
        let must = fastest(&mut kernels().filter(|r| r.accuracy.unwrap().contains == 1.0));
        let ulps = fastest(&mut kernels().filter(|r| {
            r.rounding == Some(Rounding::Nearest) && r.accuracy.unwrap().worst_error_us <= 8.0
        }));
        writeln!(s, "| {profile} | {must} | {ulps} |").unwrap();
    }
    s.push_str("\nEach profile uses its dedicated transform class (the class's own kernel and its own bytes per box); the accuracy is against the exact image of that class's map, in units of its own `u·S` (see `bvkit::transform`).\n");
    s
}

/// A scatter plot: ns per box in cache (log x) against worst error in u·S (y), one point a
/// kernel (best backend and scalar), coloured by method, filled for Nearest, hollow for
/// Outward; peers as grey crosses.
fn svg(rows: &[Row]) -> String {
    let points: Vec<&Row> = rows
        .iter()
        .filter(|r| r.accuracy.is_some() && r.backend != "peer")
        .collect();
    let (w, h, left, right, top, bottom) = (960.0, 600.0, 80.0, 40.0, 50.0, 70.0);
    let (pw, ph) = (w - left - right, h - top - bottom);
    let lx = |ns: f64| ns.max(1e-3).log10();
    let (x0, x1) = points.iter().fold((f64::MAX, f64::MIN), |(a, b), r| {
        (a.min(lx(r.ns_cache)), b.max(lx(r.ns_cache)))
    });
    let (x0, x1) = (x0.floor(), x1.ceil().max(x0.floor() + 1.0));
    let y1 = points
        .iter()
        .map(|r| r.accuracy.unwrap().worst_error_us)
        .fold(1.0, f64::max)
        * 1.1;
    let px = |ns: f64| left + (lx(ns) - x0) / (x1 - x0) * pw;
    let py = |e: f64| top + ph - e / y1 * ph;
    let mut s = format!(
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" font-family="sans-serif" font-size="12">"#
    );
    write!(s, r#"<rect width="{w}" height="{h}" fill="white"/><text x="{left}" y="28" font-size="15">bvkit: speed against worst error, every kernel, layout and backend (in-cache batch)</text>"#).unwrap();
    write!(
        s,
        r#"<rect x="{left}" y="{top}" width="{pw}" height="{ph}" fill="none" stroke="black"/>"#
    )
    .unwrap();
    let mut decade = x0;
    while decade <= x1 {
        let x = left + (decade - x0) / (x1 - x0) * pw;
        write!(s, r#"<line x1="{x}" y1="{top}" x2="{x}" y2="{}" stroke="lightgray"/><text x="{x}" y="{}" text-anchor="middle">{}</text>"#, top + ph, top + ph + 18.0, 10f64.powf(decade)).unwrap();
        decade += 1.0;
    }
    for k in 0..=5 {
        let e = y1 * f64::from(k) / 5.0;
        write!(
            s,
            r#"<text x="{}" y="{}" text-anchor="end">{e:.1}</text>"#,
            left - 6.0,
            py(e) + 4.0
        )
        .unwrap();
    }
    write!(s, r#"<text x="{}" y="{}" text-anchor="middle">ns per box, in cache (median, log scale)</text>"#, left + pw / 2.0, h - 30.0).unwrap();
    write!(s, r#"<text x="18" y="{0}" transform="rotate(-90 18 {0})" text-anchor="middle">worst face error (u·S)</text>"#, top + ph / 2.0).unwrap();
    let color = |m: Option<Method>| match m {
        Some(Method::Naive) => "#d62728",
        Some(Method::AbsMatrix) => "#1f77b4",
        Some(Method::SignSelect) => "#2ca02c",
        None => "gray",
    };
    for r in &points {
        let (x, y) = (px(r.ns_cache), py(r.accuracy.unwrap().worst_error_us));
        let c = color(r.method);
        let shape = match r.class {
            "3D affine" => format!(r#"<circle cx="{x:.1}" cy="{y:.1}" r="5""#),
            "2D rigid" => format!(
                r#"<rect x="{:.1}" y="{:.1}" width="9" height="9""#,
                x - 4.5,
                y - 4.5
            ),
            _ => format!(
                r#"<polygon points="{:.1},{:.1} {:.1},{:.1} {:.1},{:.1}""#,
                x,
                y - 6.0,
                x - 5.5,
                y + 4.0,
                x + 5.5,
                y + 4.0
            ),
        };
        let paint = if r.rounding == Some(Rounding::Nearest) {
            format!(r#"fill="{c}""#)
        } else {
            format!(r#"fill="none" stroke="{c}" stroke-width="2""#)
        };
        write!(
            s,
            r#"{shape} {paint}><title>{} {} {} {}: {:.2} ns, {:.2} u·S</title></{}>"#,
            r.class,
            r.kernel,
            r.layout,
            r.backend,
            r.ns_cache,
            r.accuracy.unwrap().worst_error_us,
            if r.class == "3D affine" {
                "circle"
            } else if r.class == "2D rigid" {
                "rect"
            } else {
                "polygon"
            }
        )
        .unwrap();
    }
    let legend = [
        ("naive", "#d62728"),
        ("abs-matrix", "#1f77b4"),
        ("sign-select", "#2ca02c"),
    ];
    for (i, (name, c)) in legend.iter().enumerate() {
        write!(
            s,
            r#"<circle cx="{}" cy="{}" r="5" fill="{c}"/><text x="{}" y="{}">{name}</text>"#,
            left + 15.0,
            top + 18.0 + 18.0 * i as f64,
            left + 25.0,
            top + 22.0 + 18.0 * i as f64
        )
        .unwrap();
    }
    write!(s, r#"<text x="{}" y="{}">filled: Nearest · hollow: Outward · circle: 3D affine · square: 2D rigid · triangle: 2D affine</text>"#, left + 15.0, top + 22.0 + 18.0 * 3.0).unwrap();
    s.push_str("</svg>\n");
    s
}

fn main() -> std::io::Result<()> {
    let started = Instant::now();
    let best = Backend::detect();
    let backends: Vec<Backend> = if best == Backend::Scalar {
        vec![best]
    } else {
        vec![best, Backend::Scalar]
    };
    eprintln!(
        "bvkit trade report: best backend {best:?} (supported: {:?}); {CACHE}-box and {DRAM}-box batches; {} oracle cases per kernel",
        Backend::supported(),
        CASES * ACCURACY_CLASSES.len() as u64
    );
    let mut rows = measure_3d(&backends);
    let (class_rows, class_bytes) = measure_classes(best);
    rows.extend(class_rows);
    rows.extend(measure_2d(&backends));
    set_ratios(&mut rows);

    println!("## Speed and accuracy of every kernel\n");
    println!(
        "Best backend: {best:?}. In-cache batch: {CACHE} boxes; DRAM batch: {DRAM} boxes. Accuracy over {} seeded cases per kernel from the classes {:?} (peers: error against the same exact oracle; they make no containment promise). Volume overhead over the Typical class. × fastest: in-cache time over the fastest kernel of the same transform class.\n",
        CASES * ACCURACY_CLASSES.len() as u64,
        ACCURACY_CLASSES
    );
    println!("{}", table(&rows));
    println!("## Transform classes: bytes, rooflines and the affine class\n");
    println!(
        "Every class on the same {DRAM} boxes (and poses that differ only in what each class holds), on the best backend. The roofline moves the class's bytes with one addition per float.\n"
    );
    println!("{}", class_table(&rows, &class_bytes, best.name()));
    println!("## Recommendations\n");
    println!("{}", recommendations(&rows));
    let key = |class: &str, kernel: &str, layout: &str, backend: &str| {
        rows.iter().find(|r| {
            r.class == class && r.kernel == kernel && r.layout == layout && r.backend == backend
        })
    };
    let b = best.name();
    if let (Some(n), Some(o), Some(p), Some(rl)) = (
        key("3D affine", "abs-matrix nearest", "aosoa", b),
        key("3D affine", "abs-matrix outward", "aosoa", b),
        key(
            "3D affine",
            "parry3d Aabb::transform_by (rigid)",
            "aos",
            "peer",
        ),
        key("3D affine", "memory roofline", "aosoa", "roofline"),
    ) {
        println!("## Issue targets, measured in this run\n");
        println!("| figure | measured | target |\n|---|---:|---:|");
        println!(
            "| abs-matrix nearest AoSoA ({b}), in cache | {:.2} ns/box | <= 0.5 ns/box |",
            n.ns_cache
        );
        println!(
            "| speed-up over the parry3d loop, in cache | {:.1}x | >= 10x |",
            p.ns_cache / n.ns_cache
        );
        println!(
            "| Outward / Nearest (abs-matrix AoSoA), in cache | {:.2}x | <= 1.2x |",
            o.ns_cache / n.ns_cache
        );
        println!(
            "| abs-matrix nearest AoSoA / memory roofline, DRAM | {:.2}x | <= 1.15x |",
            n.ns_dram / rl.ns_dram
        );
        println!();
    }
    if let (
        Some(rigid),
        Some(affine),
        Some(translation),
        Some(rigid_roof),
        Some(rigid_aos),
        Some(parry),
    ) = (
        key(RIGID3, "abs-matrix nearest", "aosoa", b),
        key("3D affine", "abs-matrix nearest", "aosoa", b),
        key(TRANSLATION3, "abs-matrix nearest", "aosoa", b),
        key(RIGID3, "memory roofline", "aosoa", "roofline"),
        key(RIGID3, "abs-matrix nearest", "aos", b),
        key(RIGID3, "parry3d Aabb::transform_by", "aos", "peer"),
    ) {
        println!("## Transform-class targets, measured in this run\n");
        println!("| figure | measured | target |\n|---|---:|---:|");
        println!(
            "| affine AoSoA / rigid AoSoA, 4M boxes | {:.2}x | >= 1.25x |",
            affine.ns_dram / rigid.ns_dram
        );
        println!(
            "| rigid AoSoA / its roofline, 4M boxes | {:.2}x | <= 1.15x |",
            rigid.ns_dram / rigid_roof.ns_dram
        );
        println!(
            "| affine AoSoA / translation AoSoA, 4M boxes | {:.2}x | >= 1.6x |",
            affine.ns_dram / translation.ns_dram
        );
        println!(
            "| parry3d loop / rigid AoS (`&[Rigid3]`), in cache | {:.2}x | >= 8x |",
            parry.ns_cache / rigid_aos.ns_cache
        );
        println!();
    }
    let dir =
        PathBuf::from(std::env::var_os("CARGO_TARGET_DIR").unwrap_or_else(|| "target".into()))
            .join("trade");
    std::fs::create_dir_all(&dir)?;
    let (csv_path, svg_path) = (dir.join("trade.csv"), dir.join("trade.svg"));
    std::fs::write(&csv_path, csv(&rows))?;
    std::fs::write(&svg_path, svg(&rows))?;
    println!("wrote {}\nwrote {}", csv_path.display(), svg_path.display());
    eprintln!("done in {:.0} s", started.elapsed().as_secs_f64());
    Ok(())
}
