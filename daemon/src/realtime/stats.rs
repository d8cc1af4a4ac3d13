//! Loop statistics (SPEC §7.2, §11): compute time and wake-up jitter in
//! fixed-size histograms, missed periods; summarised into the status's
//! [`Timing`] block. Percentiles are recomputed every
//! [`TIMING_REFRESH_TICKS`] ticks (a bucket scan), the rest every tick.

use crate::realtime::histogram::Histogram;
use crate::sys::clock::Nanos;
use shm_schema::Timing;
use shm_schema::status::{JITTER_BUCKETS, TIMING_REFRESH_TICKS, jitter_bucket};

/// Statistics of the running loop.
#[derive(Debug, Clone)]
pub struct LoopStats {
    /// Compute time per tick (wake-up to end of work) \[ns\].
    pub compute: Histogram,
    /// Wake-up jitter per tick \[ns\].
    pub jitter: Histogram,
    coarse_jitter: [u64; JITTER_BUCKETS],
    overruns: u64,
    last_compute: Nanos,
    last_jitter: Nanos,
    compute_p50: Nanos,
    compute_p99: Nanos,
    jitter_p99: Nanos,
    period: Nanos,
    plan_waits: u64,
    plan_wait_max: Nanos,
}

impl LoopStats {
    /// Empty statistics for a loop of `period` ns.
    pub fn new(period: Nanos) -> Self {
        Self {
            compute: Histogram::new(),
            jitter: Histogram::new(),
            coarse_jitter: [0; JITTER_BUCKETS],
            overruns: 0,
            last_compute: 0,
            last_jitter: 0,
            compute_p50: 0,
            compute_p99: 0,
            jitter_p99: 0,
            period,
            plan_waits: 0,
            plan_wait_max: 0,
        }
    }

    /// Records a lockstep tick held for `waited` ns for a plan (outside
    /// the tick: never part of its compute time).
    pub fn record_plan_wait(&mut self, waited: Nanos) {
        self.plan_waits += 1;
        self.plan_wait_max = self.plan_wait_max.max(waited);
    }

    /// Lockstep ticks held for a plan so far.
    pub fn plan_waits(&self) -> u64 {
        self.plan_waits
    }

    /// The longest hold for a plan so far \[ns\].
    pub fn plan_wait_max(&self) -> Nanos {
        self.plan_wait_max
    }

    /// Records a wake-up: its jitter and the periods missed before it.
    pub fn record_wake(&mut self, jitter: Nanos, missed: u64) {
        self.jitter.record(jitter);
        self.coarse_jitter[jitter_bucket(jitter)] += 1;
        self.last_jitter = jitter;
        self.overruns += missed;
    }

    /// Records the compute time of a finished tick.
    pub fn record_compute(&mut self, compute: Nanos, tick: u64) {
        self.compute.record(compute);
        self.last_compute = compute;
        if tick.is_multiple_of(TIMING_REFRESH_TICKS) {
            self.refresh();
        }
    }

    /// Recomputes the percentiles now.
    pub fn refresh(&mut self) {
        self.compute_p50 = self.compute.quantile(0.5);
        self.compute_p99 = self.compute.quantile(0.99);
        self.jitter_p99 = self.jitter.quantile(0.99);
    }

    /// Missed periods since start.
    pub fn overruns(&self) -> u64 {
        self.overruns
    }

    /// The status's timing block.
    pub fn timing(&self) -> Timing {
        Timing {
            period_ns: self.period,
            compute_last_ns: self.last_compute,
            compute_p50_ns: self.compute_p50,
            compute_p99_ns: self.compute_p99,
            compute_max_ns: self.compute.max(),
            jitter_last_ns: self.last_jitter,
            jitter_p99_ns: self.jitter_p99,
            jitter_max_ns: self.jitter.max(),
            overruns: self.overruns,
            jitter_hist: self.coarse_jitter,
            ..Timing::default()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn timing_summarises_the_records() {
        let mut s = LoopStats::new(1_000_000);
        for t in 1..=200u64 {
            s.record_wake(t * 10, u64::from(t == 50) * 2);
            s.record_compute(t * 100, t);
        }
        let tm = s.timing();
        assert_eq!(tm.period_ns, 1_000_000);
        assert_eq!(tm.compute_last_ns, 20_000);
        assert_eq!(tm.compute_max_ns, 20_000);
        assert_eq!(tm.jitter_max_ns, 2000);
        assert_eq!(tm.overruns, 2);
        assert_eq!(tm.jitter_hist.iter().sum::<u64>(), 200);
        assert!(tm.compute_p50_ns >= 10_000 && tm.compute_p50_ns <= 10_400);
        assert!(tm.compute_p99_ns >= 19_800 && tm.compute_p99_ns <= 20_000);
    }
}
