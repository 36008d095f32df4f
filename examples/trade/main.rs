//! The speed/accuracy trade of every kernel, measured: `cargo run --release --example trade`
//! (add `--features peers` for the parry3d loop, which builds parry3d). With `--quick` it
//! runs on small sizes with few runs, to check that it runs (CI).
//!
//! For every transform class (3D translation, rigid, similarity, TRS and affine; 2D
//! translation, rigid and affine), every method × rounding × layout (single box, AoS, SoA,
//! AoSoA) on the best backend of this CPU and on the scalar backend, with the peers a user
//! would otherwise write (the glam loops, the parry3d loop) and the memory rooflines:
//!
//! - ns per box at an in-cache batch and a DRAM-sized batch (medians of repeated runs);
//! - against the exact oracle (`support/src/oracle.rs`), on a seeded sample over the finite
//!   extreme classes: the worst face error in units of `u·S`, the fraction of results
//!   that contain the exact box, and the mean volume overhead over the exact box.
//!
//! It prints Markdown that opens with the answer (per scene profile, the kernel to use when
//! the box must contain the exact one and when a few ulps are fine), then a summary per
//! class × rounding × layout and the targets; every row goes to a CSV, and an SVG
//! plots speed against worst error per class with the Pareto fronts labelled. Progress
//! goes to stderr. Timings vary run to run; the accuracy columns are identical for the
//! fixed seed.

use bvkit_support::cases;
use bvkit_support::common;
mod measure;
use bvkit_support::oracle;
mod plot;
mod report;

use std::path::PathBuf;

use bvkit::Backend;

use measure::{AFFINE3_STAGES, CLASSES2_STAGES, CLASSES3_STAGES, Progress};

fn main() -> std::io::Result<()> {
    let best = Backend::detect();
    let backends: Vec<Backend> = if best == Backend::Scalar {
        vec![best]
    } else {
        vec![best, Backend::Scalar]
    };
    // The measuring stages, and one that writes the files.
    let progress = Progress::new(AFFINE3_STAGES + CLASSES3_STAGES + CLASSES2_STAGES + 1);
    eprintln!(
        "bvkit trade report: CPU {}; best backend {best:?}; {} oracle cases per kernel",
        common::cpu(),
        measure::cases_per_kernel()
    );
    let mut rows = measure::affine3d(&backends, &progress);
    rows.extend(measure::classes3(best, &progress));
    rows.extend(measure::classes2(&backends, &progress));

    progress.stage("writing the CSV and the SVG");
    let dir =
        PathBuf::from(std::env::var_os("CARGO_TARGET_DIR").unwrap_or_else(|| "target".into()))
            .join("trade");
    std::fs::create_dir_all(&dir)?;
    let (csv_path, svg_path) = (dir.join("trade.csv"), dir.join("trade.svg"));
    std::fs::write(&csv_path, report::csv(&rows))?;
    let (svg, unplaced) = plot::svg(&rows, best.name());
    std::fs::write(&svg_path, svg)?;
    if unplaced > 0 {
        eprint!(" ({unplaced} plot labels overlap something)");
    }
    let seconds = progress.finish();

    println!("# bvkit: which kernel, and what it costs\n");
    println!("{}", report::which_kernel(&rows, best));
    println!("{}", report::summary(&rows));
    println!("{}", report::targets(&rows, best));
    println!("{}", report::method(best, &rows));
    println!(
        "Full table: `{}`. Plot: `{}`. Measured in {seconds:.0} s.",
        csv_path.display(),
        svg_path.display()
    );

    Ok(())
}
