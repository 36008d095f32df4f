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
    Aabb2, Aabb3, Aabb3x8, AabbSoa, Affine3Soa, Affine3x8, Backend, Batch, Method, Rigid2, Rounding,
};
use glam::{Affine2, Affine3A, Vec2};

use cases::{Class, problem, rigid_problem, rng};
use oracle::{Bound, Problem, affine2, affine3, check, rigid2};

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
fn accuracy<const N: usize>(
    sample: &[(Class, Problem<N>)],
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
    let (bs, xs) = (AabbSoa::from_boxes(&boxes), Affine3Soa::from_affines(&xfs));
    let mut out = vec![Aabb3::EMPTY; DRAM];
    let mut o8 = vec![Aabb3x8::EMPTY; b8.len()];
    let mut os = AabbSoa::empty(DRAM);
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
    let t = times(|n| {
        common::roofline_aosoa(
            black_box(&b8[..n / 8]),
            black_box(&x8[..n / 8]),
            &mut o8[..n / 8],
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
        let b = AabbSoa {
            min: bs.min.clone().map(|c| c[..n].to_vec()),
            max: bs.max.clone().map(|c| c[..n].to_vec()),
        };
        let x = Affine3Soa {
            cols: xs.cols.clone().map(|c| c.map(|v| v[..n].to_vec())),
            translation: xs.translation.clone().map(|c| c[..n].to_vec()),
        };
        (b, x, AabbSoa::empty(n))
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
                        .aos(black_box(&boxes[..n]), black_box(&xfs[..n]), &mut out[..n])
                        .unwrap()
                });
                batch.aos(&sb, &sx, &mut o).unwrap();
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
                            .soa(black_box(cb.view()), cx.view(), co.view_mut())
                            .unwrap()
                    }),
                    ns_per_box(DRAM, 5, || {
                        batch
                            .soa(black_box(bs.view()), xs.view(), os.view_mut())
                            .unwrap()
                    }),
                );
                let (ssb, ssx) = (AabbSoa::from_boxes(&sb), Affine3Soa::from_affines(&sx));
                let mut sso = AabbSoa::empty(sb.len());
                batch.soa(ssb.view(), ssx.view(), sso.view_mut()).unwrap();
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
                        .aosoa(
                            black_box(&b8[..n / 8]),
                            black_box(&x8[..n / 8]),
                            &mut o8[..n / 8],
                        )
                        .unwrap()
                });
                let (s8, x8s) = (Aabb3x8::pack(&sb), Affine3x8::pack(&sx));
                let mut so8 = vec![Aabb3x8::EMPTY; s8.len()];
                batch.aosoa(&s8, &x8s, &mut so8).unwrap();
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
            for &backend in backends {
                let batch = Batch::new(method, rounding).on(backend).expect("supported");
                let t = times(|n| {
                    batch
                        .aos_rigid2(
                            black_box(&boxes[..n]),
                            black_box(&rigid[..n]),
                            &mut out[..n],
                        )
                        .unwrap()
                });
                let mut o = vec![Aabb2::EMPTY; rb.len()];
                batch.aos_rigid2(&rb, &rx, &mut o).unwrap();
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
                        .aos2(
                            black_box(&boxes[..n]),
                            black_box(&affine[..n]),
                            &mut out[..n],
                        )
                        .unwrap()
                });
                batch.aos2(&ab, &ax, &mut o).unwrap();
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

/// Each row's in-cache time over the fastest kernel of its transform class.
fn set_ratios(rows: &mut [Row]) {
    for class in ["3D affine", "2D affine", "2D rigid"] {
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
        ("2D sprites (rotation + translation)", "2D rigid"),
        ("2D sprites with scale or shear", "2D affine"),
        ("rigid bodies (3D)", "3D affine"),
        ("scaled props (3D)", "3D affine"),
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
    s.push_str("\nThe 3D profiles share the affine kernels: bvkit has no dedicated 3D rigid or scale-only kernel yet, so they get the same figures; the sample covers rotations, reflections, scale, shear and drift alike.\n");
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
    rows.extend(measure_2d(&backends));
    set_ratios(&mut rows);

    println!("## Speed and accuracy of every kernel\n");
    println!(
        "Best backend: {best:?}. In-cache batch: {CACHE} boxes; DRAM batch: {DRAM} boxes. Accuracy over {} seeded cases per kernel from the classes {:?} (peers: error against the same exact oracle; they make no containment promise). Volume overhead over the Typical class. × fastest: in-cache time over the fastest kernel of the same transform class.\n",
        CASES * ACCURACY_CLASSES.len() as u64,
        ACCURACY_CLASSES
    );
    println!("{}", table(&rows));
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
