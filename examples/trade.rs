//! The speed/accuracy trade of every kernel, measured: `cargo run --release --example trade`.
//!
//! For each kernel it measures the median time per box, and against the exact oracle
//! (`tests/oracle`) the worst face error in units of `u·S`, the fraction of cases whose
//! result contains the exact box, and the mean volume overhead over the exact box. It
//! prints a Markdown table and writes the same data as CSV and an SVG plot.

#[path = "../tests/cases/mod.rs"]
mod cases;
#[path = "../tests/oracle/mod.rs"]
mod oracle;

use std::fmt::Write as _;
use std::hint::black_box;
use std::path::PathBuf;
use std::time::Instant;

use bvkit::method::{TINY_ERROR, TINY_PAD};
use bvkit::{Aabb2, Aabb3, Method, Rigid2, Rounding};
use glam::{Affine3A, Mat3A, Vec2, Vec3A};

use cases::{Class, problem, rigid_problem, rng};
use oracle::{Bound, Measured, Problem, check};

/// The seed of every random sample: the accuracy columns are identical run to run.
const SEED: u64 = 0xb0c5_2026;
/// Boxes per timed loop (in L1 with their transforms).
const LOOP: usize = 1024;
/// Timed repetitions; the median is reported.
const REPS: usize = 201;
/// Oracle cases per kernel and class.
const CASES: u64 = 4000;
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
struct Row {
    kernel: String,
    method: Method,
    rounding: Rounding,
    ns_per_box: f64,
    worst_error_us: f64,
    contains: f64,
    overhead: f64,
}

fn bound(method: Method, rounding: Rounding, dims: u32) -> Bound {
    match rounding {
        Rounding::Nearest => Bound::Nearest {
            gamma_n: method.nearest_gamma(dims),
            tiny: f64::from(TINY_ERROR),
        },
        Rounding::Outward => Bound::Outward {
            k: method.outward_pad(dims),
            tiny: f64::from(TINY_PAD),
        },
    }
}

/// The median of `REPS` timings of `run` over a loop of `LOOP` boxes, in ns per box.
fn median_ns_per_box(mut run: impl FnMut()) -> f64 {
    for _ in 0..10 {
        run();
    }
    let mut samples: Vec<f64> = (0..REPS)
        .map(|_| {
            let start = Instant::now();
            run();
            start.elapsed().as_secs_f64() * 1e9 / LOOP as f64
        })
        .collect();
    samples.sort_by(f64::total_cmp);
    samples[REPS / 2]
}

/// Worst error, containment fraction and mean overhead of `kernel` over the accuracy
/// classes (overhead over the Typical class only, where the exact volume is meaningful).
fn accuracy<const N: usize>(
    make: impl Fn(Class, u64) -> Problem<N>,
    kernel: impl Fn(&Problem<N>) -> ([f32; N], [f32; N]),
    bound: Bound,
) -> (f64, f64, f64) {
    let (mut worst, mut contained, mut total) = (0.0f64, 0u64, 0u64);
    let (mut overhead_sum, mut overhead_count) = (0.0, 0u64);
    for class in ACCURACY_CLASSES {
        for seed in 0..CASES {
            let p = make(class, SEED ^ seed ^ (class as u64) << 40);
            let (min, max) = kernel(&p);
            let m: Measured = check(&p, min, max, bound)
                .unwrap_or_else(|e| panic!("contract broken: {e}\n{p:?}"));
            worst = worst.max(m.worst_error_us);
            contained += u64::from(m.contains);
            total += 1;
            if let (Class::Typical, Some(o)) = (class, m.overhead) {
                overhead_sum += o;
                overhead_count += 1;
            }
        }
    }
    (
        worst,
        contained as f64 / total as f64,
        overhead_sum / overhead_count as f64,
    )
}

fn affine3(p: &Problem<3>) -> (Aabb3, Affine3A) {
    let [x, y, z] = p.cols.map(Vec3A::from_array);
    let xf = Affine3A {
        matrix3: Mat3A::from_cols(x, y, z),
        translation: Vec3A::from_array(p.t),
    };
    (
        Aabb3::new(Vec3A::from_array(p.lo), Vec3A::from_array(p.hi)),
        xf,
    )
}

fn rigid2(p: &Problem<2>) -> (Aabb2, Rigid2) {
    let b = Aabb2::new(Vec2::from_array(p.lo), Vec2::from_array(p.hi));
    (
        b,
        Rigid2::new(p.cols[0][0], p.cols[0][1], Vec2::from_array(p.t)),
    )
}

fn measure_single() -> Vec<Row> {
    let mut rows = Vec::new();
    let r = &mut rng(SEED);
    let inputs3: Vec<(Aabb3, Affine3A)> = (0..LOOP)
        .map(|_| affine3(&problem::<3>(Class::Typical, r)))
        .collect();
    let inputs2: Vec<(Aabb2, Rigid2)> = (0..LOOP)
        .map(|_| rigid2(&rigid_problem(Class::Typical, r)))
        .collect();
    let mut out3 = vec![Aabb3::EMPTY; LOOP];
    let mut out2 = vec![Aabb2::EMPTY; LOOP];
    for method in Method::ALL {
        for rounding in Rounding::ALL {
            eprintln!("  single 3D affine {} {}", method.name(), rounding.name());
            let ns = median_ns_per_box(|| {
                for ((b, xf), o) in black_box(&inputs3).iter().zip(&mut out3) {
                    *o = b.transformed(xf, method, rounding);
                }
                black_box(&out3);
            });
            let (worst, contains, overhead) = accuracy(
                |c, s| problem::<3>(c, &mut rng(s)),
                |p| {
                    let (b, xf) = affine3(p);
                    let o = b.transformed(&xf, method, rounding);
                    (o.min.to_array(), o.max.to_array())
                },
                bound(method, rounding, 3),
            );
            rows.push(Row {
                kernel: "single 3D affine".into(),
                method,
                rounding,
                ns_per_box: ns,
                worst_error_us: worst,
                contains,
                overhead,
            });

            eprintln!("  single 2D rigid {} {}", method.name(), rounding.name());
            let ns = median_ns_per_box(|| {
                for ((b, xf), o) in black_box(&inputs2).iter().zip(&mut out2) {
                    *o = b.transformed_rigid(xf, method, rounding);
                }
                black_box(&out2);
            });
            let (worst, contains, overhead) = accuracy(
                |c, s| rigid_problem(c, &mut rng(s)),
                |p| {
                    let (b, xf) = rigid2(p);
                    let o = b.transformed_rigid(&xf, method, rounding);
                    (o.min.to_array(), o.max.to_array())
                },
                bound(method, rounding, 2),
            );
            rows.push(Row {
                kernel: "single 2D rigid".into(),
                method,
                rounding,
                ns_per_box: ns,
                worst_error_us: worst,
                contains,
                overhead,
            });
        }
    }
    rows
}

fn table(rows: &[Row]) -> String {
    let mut s = String::new();
    writeln!(s, "| kernel | method | rounding | ns/box (median) | worst error (u·S) | contains exact | mean volume overhead |").unwrap();
    writeln!(s, "|---|---|---|---:|---:|---:|---:|").unwrap();
    for r in rows {
        writeln!(
            s,
            "| {} | {} | {} | {:.2} | {:.3} | {:.1}% | {:.2e} |",
            r.kernel,
            r.method.name(),
            r.rounding.name(),
            r.ns_per_box,
            r.worst_error_us,
            r.contains * 100.0,
            r.overhead
        )
        .unwrap();
    }
    s
}

fn csv(rows: &[Row]) -> String {
    let mut s = String::from(
        "kernel,method,rounding,ns_per_box,worst_error_us,contains_fraction,mean_volume_overhead\n",
    );
    for r in rows {
        writeln!(
            s,
            "{},{},{},{:.4},{:.6},{:.6},{:.6e}",
            r.kernel,
            r.method.name(),
            r.rounding.name(),
            r.ns_per_box,
            r.worst_error_us,
            r.contains,
            r.overhead
        )
        .unwrap();
    }
    s
}

/// A scatter plot: ns per box (log x) against worst error in u·S (y), one point a kernel.
fn svg(rows: &[Row]) -> String {
    let (w, h, left, right, top, bottom) = (900.0, 560.0, 80.0, 250.0, 40.0, 60.0);
    let (pw, ph) = (w - left - right, h - top - bottom);
    let lx = |ns: f64| ns.max(1e-3).log10();
    let (x0, x1) = rows.iter().fold((f64::MAX, f64::MIN), |(a, b), r| {
        (a.min(lx(r.ns_per_box)), b.max(lx(r.ns_per_box)))
    });
    let (x0, x1) = (x0.floor(), x1.ceil().max(x0.floor() + 1.0));
    let y1 = rows.iter().map(|r| r.worst_error_us).fold(1.0, f64::max) * 1.1;
    let px = |ns: f64| left + (lx(ns) - x0) / (x1 - x0) * pw;
    let py = |e: f64| top + ph - e / y1 * ph;
    let mut s = format!(
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" font-family="sans-serif" font-size="12">"#
    );
    write!(s, r#"<rect width="{w}" height="{h}" fill="white"/>"#).unwrap();
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
    write!(
        s,
        r#"<text x="{}" y="{}" text-anchor="middle">ns per box (median, log scale)</text>"#,
        left + pw / 2.0,
        h - 15.0
    )
    .unwrap();
    write!(s, r#"<text x="18" y="{}" transform="rotate(-90 18 {})" text-anchor="middle">worst face error (u·S)</text>"#, top + ph / 2.0, top + ph / 2.0).unwrap();
    let color = |m: Method| match m {
        Method::Naive => "#d62728",
        Method::AbsMatrix => "#1f77b4",
        Method::SignSelect => "#2ca02c",
    };
    for (i, r) in rows.iter().enumerate() {
        let (x, y) = (px(r.ns_per_box), py(r.worst_error_us));
        let c = color(r.method);
        match r.rounding {
            Rounding::Nearest => write!(s, r#"<circle cx="{x:.1}" cy="{y:.1}" r="5" fill="{c}"/>"#),
            Rounding::Outward => write!(s, r#"<rect x="{:.1}" y="{:.1}" width="10" height="10" fill="none" stroke="{c}" stroke-width="2"/>"#, x - 5.0, y - 5.0),
        }
        .unwrap();
        let ly = top + 14.0 + 16.0 * i as f64;
        write!(
            s,
            r#"<text x="{}" y="{ly}" fill="{c}">{}: {} {} ({:.2} ns, {:.2} u·S)</text>"#,
            left + pw + 10.0,
            i + 1,
            r.kernel,
            format_args!("{} {}", r.method.name(), r.rounding.name()),
            r.ns_per_box,
            r.worst_error_us
        )
        .unwrap();
        write!(
            s,
            r#"<text x="{:.1}" y="{:.1}" font-size="10">{}</text>"#,
            x + 7.0,
            y - 6.0,
            i + 1
        )
        .unwrap();
    }
    s.push_str("</svg>\n");
    s
}

fn main() -> std::io::Result<()> {
    eprintln!(
        "bvkit trade report: timing {LOOP}-box loops ({REPS} reps, median) and checking {} oracle cases per kernel",
        CASES * ACCURACY_CLASSES.len() as u64
    );
    let rows = measure_single();
    println!("## Single boxes\n");
    println!("{}", table(&rows));
    println!(
        "Accuracy over {} seeded cases per kernel from the classes {:?}; volume overhead over the Typical class.",
        CASES * ACCURACY_CLASSES.len() as u64,
        ACCURACY_CLASSES
    );
    let dir =
        PathBuf::from(std::env::var_os("CARGO_TARGET_DIR").unwrap_or_else(|| "target".into()))
            .join("trade");
    std::fs::create_dir_all(&dir)?;
    let (csv_path, svg_path) = (dir.join("trade.csv"), dir.join("trade.svg"));
    std::fs::write(&csv_path, csv(&rows))?;
    std::fs::write(&svg_path, svg(&rows))?;
    println!(
        "\nwrote {}\nwrote {}",
        csv_path.display(),
        svg_path.display()
    );
    Ok(())
}
