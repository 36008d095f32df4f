//! Timing for the report examples: the `--quick` flag and the fastest of repeated calls.

use std::hint::black_box;
use std::time::{Duration, Instant};

/// True with `--quick`: small inputs and one timed run each, to check that a report runs
/// (CI); its timings mean nothing.
pub fn quick() -> bool {
    std::env::args().any(|a| a == "--quick")
}

/// The fastest of repeated calls of `f`: at least 3 of them, for at least `min_total` in
/// all; one with `--quick`.
pub fn fastest<T>(min_total: Duration, mut f: impl FnMut() -> T) -> Duration {
    let (mut best, mut total, mut runs) = (Duration::MAX, Duration::ZERO, 0);
    let (min_runs, min_total) = if quick() {
        (1, Duration::ZERO)
    } else {
        (3, min_total)
    };
    while runs < min_runs || total < min_total {
        let start = Instant::now();
        black_box(f());
        let took = start.elapsed();
        (best, total, runs) = (best.min(took), total + took, runs + 1);
    }
    best
}
