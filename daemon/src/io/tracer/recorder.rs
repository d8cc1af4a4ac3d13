//! The loop's side of the tracer: wait-free and allocation-free. One small
//! `Copy` message per tick goes into the pre-allocated ring, and only while
//! a goal is recorded; one slot is always kept free for the end marker, so
//! a trace is never left open by a full ring.

use super::{TraceCounters, TraceMsg};
use crate::sys::handoff::Producer;
use gait::executor::GoalTarget;
use gait::trace::Sample;
use shm_schema::{GoalState, ReasonCode};
use std::sync::Arc;
use std::sync::atomic::Ordering;

#[derive(Debug, Clone, Copy)]
struct Recording {
    /// The executor's goal id (the loop's own numbering).
    exec_goal: u64,
    /// Next sample's tick index.
    k: u64,
    dropped: u64,
}

/// The loop's end: wait-free, allocation-free (module docs).
#[derive(Debug)]
pub struct TraceRecorder {
    tx: Producer<TraceMsg>,
    active: Option<Recording>,
    counters: Arc<TraceCounters>,
}

impl TraceRecorder {
    /// A recorder sending into `tx`.
    pub fn new(tx: Producer<TraceMsg>, counters: Arc<TraceCounters>) -> Self {
        Self {
            tx,
            active: None,
            counters,
        }
    }

    /// The executor goal being recorded, if any.
    pub fn recording(&self) -> Option<u64> {
        self.active.map(|a| a.exec_goal)
    }

    /// Starts recording executor goal `exec_goal` (ends any other first).
    /// Needs room for the start and the end marker; otherwise the goal is
    /// not recorded and counted as missed.
    pub fn begin(
        &mut self,
        exec_goal: u64,
        client_id: u64,
        goal_id: u64,
        target: Option<GoalTarget>,
    ) {
        if self.active.is_some() {
            self.end(None);
        }
        if self.tx.free() < 2 {
            self.counters.missed.fetch_add(1, Ordering::Relaxed);
            return;
        }
        let m = TraceMsg::Begin {
            exec_goal,
            client_id,
            goal_id,
            target,
        };
        if self.tx.push(m).is_ok() {
            self.active = Some(Recording {
                exec_goal,
                k: 0,
                dropped: 0,
            });
        } else {
            self.counters.missed.fetch_add(1, Ordering::Relaxed);
        }
    }

    /// Records one tick of the goal being recorded (no-op otherwise).
    /// Dropped and counted if only the end marker's slot is left.
    pub fn record(&mut self, sample: &Sample) {
        let Some(a) = &mut self.active else { return };
        let k = a.k;
        a.k += 1;
        if self.tx.free() < 2 || self.tx.push(TraceMsg::Tick { k, sample: *sample }).is_err() {
            a.dropped += 1;
            self.counters.dropped.fetch_add(1, Ordering::Relaxed);
        }
    }

    /// Ends the recording with `outcome` (no-op when not recording).
    pub fn end(&mut self, outcome: Option<(GoalState, ReasonCode)>) {
        let Some(a) = self.active.take() else { return };
        // The slot kept free by `begin`/`record` guarantees room; should the
        // writer be gone the trace is lost anyway.
        let _ = self.tx.push(TraceMsg::End {
            outcome,
            dropped: a.dropped,
        });
    }
}
