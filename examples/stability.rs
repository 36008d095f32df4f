//! Writes the extremes matrix to `target/stability.md` (or to the path given):
//! `cargo run --release --example stability [PATH]`; `python3 scripts/docs.py stability`
//! puts it in `docs/stability.md`. Exits with an error on any contract failure.

use bvkit_support::matrix;

fn main() -> std::io::Result<()> {
    let cells = matrix::compute();
    let text = matrix::markdown(&cells);
    let path = std::path::PathBuf::from(
        std::env::args()
            .nth(1)
            .unwrap_or_else(|| "target/stability.md".into()),
    );
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)?;
    }
    std::fs::write(&path, &text)?;
    print!("{text}");
    let failures: usize = cells
        .iter()
        .flatten()
        .flatten()
        .map(|c| c.failures.len())
        .sum();
    eprintln!("wrote {} ({failures} contract failures)", path.display());
    if failures > 0 {
        std::process::exit(1);
    }
    Ok(())
}
