//! The machine's own tail, measured beside the daemon's tick compute time
//! (`gaitctl bench`): a loop that sleeps to absolute deadlines at the
//! daemon's rate, like the control loop, and each period does a fixed
//! amount of work sized to the daemon's median tick. Its work never varies,
//! so whatever spread its timings show — preemption, interrupts, a
//! hypervisor stealing the CPU, caches cooled by the sleep — is the
//! platform's, and the daemon's tick cannot be expected to beat it.

use super::summary;
use std::hint::black_box;
use std::time::{Duration, Instant};

/// Cache lines walked per unit of work (32 KiB: a control tick's data
/// comes back cold after a sleep too).
const LINES: usize = 512;

/// One unit of work: arithmetic plus a walk over `buf`.
fn unit(buf: &mut [u64], x: f64) -> f64 {
    let mut y = x;
    for i in 0..64 {
        y = y.mul_add(1.000_000_1, 1e-9 * i as f64);
    }
    for line in buf.chunks_mut(8) {
        line[0] = line[0].wrapping_add(y.to_bits());
    }
    y
}

/// How many units take about `target` when run back to back.
fn calibrate(buf: &mut [u64], target: Duration) -> u32 {
    let t0 = Instant::now();
    let mut x = 1.0;
    for _ in 0..1000 {
        x = unit(black_box(buf), black_box(x));
    }
    black_box(x);
    let per_unit = t0.elapsed().as_secs_f64() / 1000.0;
    ((target.as_secs_f64() / per_unit.max(1e-12)).round() as u32).max(1)
}

/// Runs `n` periods of `period`, each doing about `work` of computation
/// (sized on a warm cache), on this thread pinned to `cpu` and, if
/// permitted, at SCHED_FIFO `priority` (the daemon's loop settings).
/// Returns the summary of the per-period compute times \[µs\] and whether
/// SCHED_FIFO was granted, or an error text if the thread cannot run.
pub fn reference_loop(
    n: usize,
    period: Duration,
    work: Duration,
    cpu: Option<u32>,
    priority: i32,
) -> Result<(serde_json::Value, bool), String> {
    let handle = std::thread::Builder::new()
        .name("gaitctl-noise".into())
        .spawn(move || {
            let _ = super::pin(cpu);
            let fifo = set_fifo(priority);
            let mut buf = vec![0u64; LINES * 8];
            let units = calibrate(&mut buf, work);
            let mut times = Vec::with_capacity(n);
            let mut x = 1.0;
            let start = Instant::now() + period;
            for k in 0..n as u32 {
                let deadline = start + period * k;
                std::thread::sleep(deadline.saturating_duration_since(Instant::now()));
                let t0 = Instant::now();
                for _ in 0..units {
                    x = unit(black_box(&mut buf), black_box(x));
                }
                times.push(t0.elapsed().as_secs_f64() * 1e6);
            }
            black_box(x);
            (summary(&mut times), fifo)
        })
        .map_err(|e| e.to_string())?;
    handle
        .join()
        .map_err(|_| "the reference loop panicked".to_string())
}

/// SCHED_FIFO at `priority` for the calling thread; false if not permitted
/// (or `priority` is 0).
fn set_fifo(priority: i32) -> bool {
    if priority <= 0 {
        return false;
    }
    let param = libc::sched_param {
        sched_priority: priority,
    };
    // SAFETY: plain syscall on the calling thread with a valid parameter.
    unsafe { libc::pthread_setschedparam(libc::pthread_self(), libc::SCHED_FIFO, &param) == 0 }
}
