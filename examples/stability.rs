//! Writes the extremes matrix to `docs/STABILITY.md`:
//! `cargo run --release --example stability`.

#[path = "../tests/cases/mod.rs"]
mod cases;
#[path = "../tests/matrix/mod.rs"]
mod matrix;
#[path = "../tests/oracle/mod.rs"]
mod oracle;

fn main() -> std::io::Result<()> {
    let cells = matrix::compute();
    let text = matrix::markdown(&cells);
    std::fs::create_dir_all("docs")?;
    std::fs::write("docs/STABILITY.md", &text)?;
    print!("{text}");
    let failures: usize = cells
        .iter()
        .flatten()
        .flatten()
        .map(|c| c.failures.len())
        .sum();
    eprintln!("wrote docs/STABILITY.md ({failures} contract failures)");
    if failures > 0 {
        std::process::exit(1);
    }
    Ok(())
}
