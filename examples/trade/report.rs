//! The Markdown report and the CSV of every row.

use std::fmt::Write as _;

use bvkit::{Backend, Method, Rounding};

use crate::measure::{
    ACCURACY_CLASSES, Kind, Layout, Peer, Row, SCALAR, TransformClass, cache, cache_runs, cases,
    cases_per_kernel, dram, dram_runs,
};

/// "A few ulps is fine": the worst error, in `u·S`, a Nearest kernel may have to be
/// recommended.
pub const FEW_ULPS: f64 = 8.0;

/// The fastest row in cache.
fn fastest<'a>(rows: impl Iterator<Item = &'a Row>) -> Option<&'a Row> {
    rows.min_by(|a, b| a.ns_cache.total_cmp(&b.ns_cache))
}

/// The bvkit kernels of one class.
fn kernels(rows: &[Row], class: TransformClass) -> impl Iterator<Item = &Row> {
    rows.iter()
        .filter(move |r| r.class == class && r.kernel().is_some())
}

/// The fastest kernel of `class` that must contain: Outward rounding.
fn must_contain(rows: &[Row], class: TransformClass) -> Option<&Row> {
    fastest(kernels(rows, class).filter(|r| r.kernel().unwrap().1 == Rounding::Outward))
}

/// The fastest Nearest kernel of `class` whose worst error is at most [`FEW_ULPS`].
fn few_ulps(rows: &[Row], class: TransformClass) -> Option<&Row> {
    fastest(kernels(rows, class).filter(|r| {
        r.kernel().unwrap().1 == Rounding::Nearest
            && r.accuracy.is_some_and(|a| a.worst_error_us <= FEW_ULPS)
    }))
}

/// A batch size in words: "4096 boxes", "4M boxes".
fn boxes(n: usize) -> String {
    if n >= 1 << 20 && n.is_multiple_of(1 << 20) {
        format!("{}M boxes", n >> 20)
    } else {
        format!("{n} boxes")
    }
}

fn pct(x: f64) -> String {
    format!("{:.1}%", x * 100.0)
}

/// The code that runs `row`'s kernel, and the types of its local boxes and poses.
fn call(row: &Row, best: Backend) -> (String, String) {
    let (method, rounding) = row.kernel().expect("a bvkit kernel");
    let args = format!("Method::{method:?}, Rounding::{rounding:?}");
    let class = row.class;
    let (boxes, poses) = (class.box_type(), class.pose_type());
    if row.layout == Layout::Single {
        let function = if row.backend == SCALAR && !class.is_2d() {
            "transformed_scalar"
        } else {
            "transformed"
        };
        return (
            format!("`local.{function}(&pose, {args})`"),
            format!("one `{boxes}`, one `{poses}`"),
        );
    }
    let batch = match Backend::ALL.into_iter().find(|b| b.name() == row.backend) {
        Some(b) if b != best => format!("Batch::new({args}).on(Backend::{b:?})?"),
        _ => format!("Batch::new({args})"),
    };
    let (transform, types) = match row.layout {
        Layout::Soa => (
            ".transform(local.view(), poses.view(), world.view_mut())",
            format!("`Soa<{boxes}>`, `Soa<{poses}>`"),
        ),
        Layout::Aosoa => {
            let (b8, p8) = class.block_types();
            (
                ".transform(&local, &poses, &mut world)",
                format!("`&[{b8}]`, `&[{p8}]`"),
            )
        }
        _ => (
            ".transform(&local, &poses, &mut world)",
            format!("`&[{boxes}]`, `&[{poses}]`"),
        ),
    };
    (format!("`{batch}{transform}`"), types)
}

/// "abs-matrix outward, AoSoA, avx2".
fn kernel_name(row: &Row) -> String {
    format!("{}, {}, {}", row.name(), row.layout.name(), row.backend)
}

/// The answer: per scene profile, the kernel to use when the box must contain the exact
/// one, and when a few ulps either way are fine.
pub fn which_kernel(rows: &[Row], best: Backend) -> String {
    let mut s = format!(
        "## Which kernel to use\n\nPer scene profile, the fastest kernel in cache that must contain the exact box (Outward), and the fastest Nearest kernel whose worst error is at most {FEW_ULPS} u·S. `local`, `poses` and `world` are the types named, `world` the same layout as `local`; ns/box are medians, errors and containment are against the exact oracle over {} cases per kernel.\n",
        cases_per_kernel()
    );
    for class in TransformClass::ALL {
        writeln!(
            s,
            "\n### {} — `{}`\n\n| need | kernel | call | local, poses | ns/box in cache | ns/box, {} | worst error (u·S) | contains exact |\n|---|---|---|---|---:|---:|---:|---:|",
            class.profile(),
            class.pose_type(),
            boxes(dram())
        )
        .unwrap();
        for (need, row) in [
            ("must contain", must_contain(rows, class)),
            ("a few ulps is fine", few_ulps(rows, class)),
        ] {
            let Some(row) = row else {
                writeln!(s, "| {need} | none measured | | | | | | |").unwrap();
                continue;
            };
            let a = row.accuracy.expect("kernels carry accuracy");
            let (code, types) = call(row, best);
            writeln!(
                s,
                "| {need} | {} | {code} | {types} | {:.2} | {:.2} | {:.2} | {} |",
                kernel_name(row),
                row.ns_cache,
                row.ns_dram,
                a.worst_error_us,
                pct(a.contains)
            )
            .unwrap();
        }
    }
    s
}

/// The compact summary: the fastest kernel in cache per class × rounding × layout.
pub fn summary(rows: &[Row]) -> String {
    let mut s = format!(
        "## Summary\n\nThe fastest kernel in cache per class, rounding and layout (any backend): method, ns/box in cache / at {}, worst error. Every kernel, peer and roofline is in the CSV.\n\n| class | rounding |",
        boxes(dram())
    );
    for layout in Layout::ALL {
        write!(s, " {} |", layout.name()).unwrap();
    }
    s.push_str("\n|---|---|---|---|---|---|\n");
    for class in TransformClass::ALL {
        for rounding in Rounding::ALL {
            write!(s, "| {} | {} |", class.name(), rounding.name()).unwrap();
            for layout in Layout::ALL {
                let best = fastest(
                    kernels(rows, class)
                        .filter(|r| r.layout == layout && r.kernel().unwrap().1 == rounding),
                );
                let cell = best.map_or("–".into(), |r| {
                    let backend = if r.backend == SCALAR { " (scalar)" } else { "" };
                    format!(
                        "{}{backend} {:.2} / {:.2} ns, {:.2} u·S",
                        r.kernel().unwrap().0.name(),
                        r.ns_cache,
                        r.ns_dram,
                        r.accuracy.expect("kernels carry accuracy").worst_error_us
                    )
                });
                write!(s, " {cell} |").unwrap();
            }
            s.push('\n');
        }
    }
    s
}

/// The speed targets, measured in this run (the rows that are missing are left
/// out, e.g. on a CPU without SIMD).
pub fn targets(rows: &[Row], best: Backend) -> String {
    let find = |class: TransformClass, kind: Kind, layout: Layout, backend: &str| {
        rows.iter().find(|r| {
            r.class == class && r.kind == kind && r.layout == layout && r.backend == backend
        })
    };
    let b = best.name();
    let abs = |rounding| Kind::Kernel(Method::AbsMatrix, rounding);
    let parry = |class| find(class, Kind::Peer(Peer::Parry), Layout::Aos, "peer");
    let nearest = |class| find(class, abs(Rounding::Nearest), Layout::Aosoa, b);
    let roofline = |class| find(class, Kind::Roofline, Layout::Aosoa, "roofline");
    use TransformClass::{Affine3, Rigid3, Translation3};
    let figures = [
        (
            format!("abs-matrix nearest AoSoA ({b}), in cache"),
            nearest(Affine3).map(|n| format!("{:.2} ns/box", n.ns_cache)),
            "<= 0.5 ns/box",
        ),
        (
            "speed-up over the parry3d loop, in cache".into(),
            parry(Affine3)
                .zip(nearest(Affine3))
                .map(|(p, n)| format!("{:.1}x", p.ns_cache / n.ns_cache)),
            ">= 10x",
        ),
        (
            "Outward / Nearest (abs-matrix AoSoA), in cache".into(),
            find(Affine3, abs(Rounding::Outward), Layout::Aosoa, b)
                .zip(nearest(Affine3))
                .map(|(o, n)| format!("{:.2}x", o.ns_cache / n.ns_cache)),
            "<= 1.2x",
        ),
        (
            format!(
                "abs-matrix nearest AoSoA / memory roofline, {}",
                boxes(dram())
            ),
            nearest(Affine3)
                .zip(roofline(Affine3))
                .map(|(n, r)| format!("{:.2}x", n.ns_dram / r.ns_dram)),
            "<= 1.15x",
        ),
        (
            format!("affine AoSoA / rigid AoSoA, {}", boxes(dram())),
            nearest(Affine3)
                .zip(nearest(Rigid3))
                .map(|(a, r)| format!("{:.2}x", a.ns_dram / r.ns_dram)),
            ">= 1.25x",
        ),
        (
            format!("rigid AoSoA / its roofline, {}", boxes(dram())),
            nearest(Rigid3)
                .zip(roofline(Rigid3))
                .map(|(n, r)| format!("{:.2}x", n.ns_dram / r.ns_dram)),
            "<= 1.15x",
        ),
        (
            format!("affine AoSoA / translation AoSoA, {}", boxes(dram())),
            nearest(Affine3)
                .zip(nearest(Translation3))
                .map(|(a, t)| format!("{:.2}x", a.ns_dram / t.ns_dram)),
            ">= 1.6x",
        ),
        (
            "parry3d loop / rigid AoS (`&[Rigid3]`), in cache".into(),
            parry(Rigid3)
                .zip(find(Rigid3, abs(Rounding::Nearest), Layout::Aos, b))
                .map(|(p, r)| format!("{:.2}x", p.ns_cache / r.ns_cache)),
            ">= 8x",
        ),
    ];
    let mut s = String::from(
        "## Issue targets, measured in this run\n\n| figure | measured | target |\n|---|---:|---:|\n",
    );
    for (figure, measured, target) in figures {
        if let Some(measured) = measured {
            writeln!(s, "| {figure} | {measured} | {target} |").unwrap();
        }
    }
    s
}

/// How the figures were measured.
pub fn method(best: Backend, rows: &[Row]) -> String {
    let (kernels, peers, rooflines) = counts(rows);
    let (cache_runs, dram_runs, cases) = (cache_runs(), dram_runs(), cases());
    let parry = if rows.iter().any(|r| r.kind == Kind::Peer(Peer::Parry)) {
        "The parry3d loop rotates by `q v q*`, the oracle's `R(q)` only for unit quaternions, so its error is not measured (the plot draws it as a dashed line at its speed, in the 3D rigid panel)."
    } else {
        "The parry3d loop is not in this run: `cargo run --release --example trade --features peers` adds it (and builds parry3d)."
    };
    format!(
        "## How this was measured\n\nCPU: {}. Figures differ by vendor: subnormal operands cost an Intel core a microcode assist and an AMD core nothing, and bvkit's kernels form none on normal-range input. Best backend: {best:?} (of {:?}); the 3D affine, 2D rigid and 2D affine batch kernels also run on the scalar backend. ns/box: the median of {cache_runs} runs over {} (inputs and outputs in cache) and of {dram_runs} runs over {}, each after a warm-up run. Accuracy: every kernel's results against the exact oracle on {} seeded cases ({cases} from each of the classes {ACCURACY_CLASSES:?}), in units of `u·S` (see `bvkit::method`); the peers against the same oracle (they make no containment promise). {parry} The CSV has every row: {kernels} kernel × layout × backend rows, {peers} peers and {rooflines} memory rooflines.\n",
        crate::common::cpu(),
        Backend::supported(),
        boxes(cache()),
        boxes(dram()),
        cases_per_kernel(),
    )
}

/// Every row as CSV, with its in-cache time over the fastest kernel of its class.
pub fn csv(rows: &[Row]) -> String {
    let mut s = String::from(
        "class,kernel,layout,backend,ns_per_box_cache,ns_per_box_dram,worst_error_us,contains_fraction,mean_volume_overhead,ratio_to_fastest\n",
    );
    for r in rows {
        let fastest = fastest(kernels(rows, r.class)).map_or(f64::NAN, |f| f.ns_cache);
        let a = r.accuracy.map_or(",,".to_string(), |a| {
            format!(
                "{:.6},{:.6},{:.6e}",
                a.worst_error_us, a.contains, a.overhead
            )
        });
        writeln!(
            s,
            "{},{},{},{},{:.4},{:.4},{},{:.4}",
            r.class.name(),
            r.name(),
            r.layout.key(),
            r.backend,
            r.ns_cache,
            r.ns_dram,
            a,
            r.ns_cache / fastest
        )
        .unwrap();
    }
    s
}

/// How many kernel, peer and roofline rows there are.
fn counts(rows: &[Row]) -> (usize, usize, usize) {
    let count = |f: fn(&Kind) -> bool| rows.iter().filter(|r| f(&r.kind)).count();
    (
        count(|k| matches!(k, Kind::Kernel(..))),
        count(|k| matches!(k, Kind::Peer(_))),
        count(|k| matches!(k, Kind::Roofline)),
    )
}
