//! The daemon's tick as `gaitctl bench` sees it: compute time while the
//! hand moves (the status window of [`super::latency`] is at rest), the
//! fixed-work reference loop at the same rate (`noise`: the platform's own
//! tail), and the wake-up jitter histogram of the bench window.

use crate::common::us;
use gaitd_client::{Client, GoalSpec, Status, Verdict};
use serde_json::json;
use shm_schema::status::{JITTER_BUCKETS, jitter_bucket_upper_ns};
use std::time::{Duration, Instant};

/// Tick compute time \[µs\] of every status of `turns` half turns about z
/// (rolling, rotations and gaits), each planned and executed to its end.
pub fn compute_while_moving(
    c: &mut Client,
    turns: usize,
    timeout: Duration,
) -> gaitd_client::Result<Vec<f64>> {
    let mut compute = Vec::new();
    for _ in 0..turns {
        let t = c.reorient(
            &GoalSpec::turn([0.0, 0.0, 1.0], std::f64::consts::PI)?,
            timeout,
        )?;
        if t.verdict != Verdict::Accepted {
            continue;
        }
        let (mut last_tick, mut started) = (0, false);
        let deadline = Instant::now() + Duration::from_secs(60);
        while Instant::now() < deadline {
            // Blocking on the daemon's wake-up, not spinning: a reader
            // spinning beside the loop (2 CPUs) slows the very ticks it
            // measures.
            let s = c.wait_status(timeout)?;
            if s.tick == last_tick || s.goal.goal_id != t.goal_id {
                continue;
            }
            last_tick = s.tick;
            let moving = s.phase != shm_schema::Phase::Hold.code();
            if moving {
                started = true;
                compute.push(us(s.timing.compute_last_ns));
            } else if started {
                break;
            }
        }
    }
    Ok(compute)
}

/// Settings of the fixed-work reference loop.
#[derive(Debug, Clone, Copy)]
pub struct Reference {
    /// Periods to run (0: skip).
    pub periods: usize,
    /// Its CPU.
    pub cpu: Option<u32>,
    /// Its SCHED_FIFO priority if permitted (0: normal scheduling).
    pub priority: i32,
}

/// The reference loop at the daemon's period doing the daemon's median
/// tick work (`work_us`, 5 µs if unknown), as the report's JSON.
pub fn reference_loop(r: Reference, period_us: u64, work_us: Option<f64>) -> serde_json::Value {
    if r.periods == 0 {
        return json!(null);
    }
    let work = work_us.unwrap_or(5.0);
    match super::noise::reference_loop(
        r.periods,
        Duration::from_micros(period_us),
        Duration::from_secs_f64(work * 1e-6),
        r.cpu,
        r.priority,
    ) {
        Ok((s, fifo)) => json!({"compute_us": s, "fifo": fifo, "work_us": work}),
        Err(e) => json!({"error": e}),
    }
}

/// The wake-up jitter histogram between two statuses, bucket by bucket.
pub fn jitter_histogram(start: &Status, end: &Status) -> Vec<serde_json::Value> {
    (0..JITTER_BUCKETS)
        .map(|i| {
            let n = end.timing.jitter_hist[i] - start.timing.jitter_hist[i];
            let below = (i + 1 < JITTER_BUCKETS).then(|| jitter_bucket_upper_ns(i) / 1000);
            json!({"below_us": below, "count": n})
        })
        .collect()
}
