//! Worst-case timing next to criterion's statistics: every call timed on
//! its own, reported as median / p99 / max (criterion reports the median
//! of batched means, which hides the tail a control tick cares about).
#![allow(dead_code)]

use std::hint::black_box;
use std::time::Instant;

/// True when the bench binary runs as a smoke test: `cargo bench` passes
/// `--bench`, `cargo test --benches` does not (criterion uses the same rule).
pub fn quick() -> bool {
    !std::env::args().any(|a| a == "--bench")
}

/// Prints the machine once (CPU model, logical CPUs).
pub fn machine() {
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .map(|l| l.split(':').nth(1).unwrap_or("").trim().to_owned())
        })
        .unwrap_or_else(|| "unknown CPU".to_owned());
    let cpus = std::thread::available_parallelism().map_or(0, |n| n.get());
    println!("machine: {cpu}, {cpus} logical CPUs (shared; numbers are indicative)");
}

/// Times `runs` single calls of `f(i)`, after `runs / 10` warm-up calls,
/// and prints median, p99 and max in microseconds.
pub fn worst_case<T>(name: &str, runs: usize, mut f: impl FnMut(usize) -> T) {
    let runs = if quick() { runs.min(20) } else { runs };
    for i in 0..runs / 10 {
        black_box(f(i));
    }
    let mut ns: Vec<u64> = Vec::with_capacity(runs);
    for i in 0..runs {
        let t = Instant::now();
        black_box(f(i));
        ns.push(t.elapsed().as_nanos() as u64);
    }
    ns.sort_unstable();
    let at = |q: f64| ns[((ns.len() - 1) as f64 * q).round() as usize] as f64 / 1e3;
    println!(
        "worst-case {name:<44} runs {runs:>6}  median {:>9.3} µs  p99 {:>9.3} µs  max {:>9.3} µs",
        at(0.5),
        at(0.99),
        at(1.0)
    );
}
