//! Writes the extremes matrix to `docs/STABILITY.md` (or to the path given):
//! `cargo run --release --example stability [PATH]`. Exits with an error on any contract
//! failure.

#[path = "../tests/cases/mod.rs"]
mod cases;
#[path = "../tests/matrix/mod.rs"]
mod matrix;
#[path = "../tests/oracle/mod.rs"]
mod oracle;

fn main() -> std::io::Result<()> {
    let cells = matrix::compute();
    let text = matrix::markdown(&cells);
    let path = std::path::PathBuf::from(
        std::env::args()
            .nth(1)
            .unwrap_or_else(|| "docs/STABILITY.md".into()),
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
