//! Goal traces on request (SPEC §8, §10): with `[daemon] trace_dir` set,
//! every goal's execution — from the tick it starts executing to the tick
//! it ends, whatever the outcome — is written to
//! `<trace_dir>/gaitd-<instance>-client-<client>-goal-<goal>.jsonl` in
//! `gait-trajectory/1`, formatted by `gait::trace` exactly as
//! `gaitctl plan` does.
//!
//! Split like the outbox: the loop ([`TraceRecorder`]) copies one small
//! `Copy` [`Sample`] per tick into a pre-allocated SPSC ring ([`handoff`]),
//! and only while a goal is being recorded; the `gaitd-trace` thread
//! ([`spawn`]) drains it on its own timer (the loop never wakes it, so no
//! syscall on the loop), formats and writes through a `BufWriter`.
//!
//! The header is written last: the lines go to a hidden `.part` file and,
//! when the goal ends, the final file gets the header (with the outcome,
//! the tick count and whether samples were lost) followed by those lines.
//! Readers therefore never see a half-written trace under the final name,
//! and the outcome can live in the header where every reader looks.
//!
//! Overflow: if the writer falls behind by the ring's capacity, the loop
//! drops samples (never waits) and counts them; the trace's header then
//! says `"incomplete":true,"dropped_ticks":N` and the writer logs a WARN —
//! never a silent gap. `t` stays tick × dt of the goal's own ticks, so the
//! gap is visible as a larger step. One slot is always kept free for the
//! end marker, so a trace is never left open by a full ring; a goal whose
//! start marker finds no room is not recorded and is counted
//! ([`TraceCounters::missed`]) and logged.
//!
//! Files: `recorder` (the loop's side), `writer` (the trace thread),
//! `format` (file names, header keys), `retention` (keep the newest
//! `trace_keep` traces).

mod format;
pub mod plan_notes;
mod recorder;
mod retention;
mod writer;

pub use gait::trace::Sample;
pub use recorder::TraceRecorder;
pub use writer::TraceSink;

use crate::sys::handoff;
use gait::HandConfig;
use gait::executor::GoalTarget;
pub use plan_notes::{PlanNote, PlanNotes};
use shm_schema::{GoalState, ReasonCode};
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU64};

/// Samples the ring holds: 4 s at 1 kHz (about 1.3 MB), far more than the
/// writer's poll period, so only a stalled disk makes it overflow.
pub const DEFAULT_CAPACITY: usize = 4096;

/// One message from the loop to the trace thread.
#[derive(Debug, Clone, Copy)]
#[allow(clippy::large_enum_variant)] // stored inline on purpose: no boxing on the loop
pub enum TraceMsg {
    /// A goal started executing.
    Begin {
        /// The executor's goal id (the planner's notes are by it).
        exec_goal: u64,
        /// Sending client.
        client_id: u64,
        /// The client's goal id.
        goal_id: u64,
        /// The goal's target, if known.
        target: Option<GoalTarget>,
    },
    /// One tick of the goal being recorded.
    Tick {
        /// Ticks since the goal started executing (0 = first).
        k: u64,
        /// What the hand did.
        sample: Sample,
    },
    /// The goal ended.
    End {
        /// Terminal state and reason (None: unknown, e.g. the recorder
        /// saw another goal start without the end of this one).
        outcome: Option<(GoalState, ReasonCode)>,
        /// Samples the loop dropped because the ring was full.
        dropped: u64,
    },
}

/// Counters the loop and the trace thread share (atomics only).
#[derive(Debug, Default)]
pub struct TraceCounters {
    /// Goals not recorded because the ring had no room for their start.
    pub missed: AtomicU64,
    /// Samples dropped so far, all traces.
    pub dropped: AtomicU64,
    /// Traces written so far.
    pub written: AtomicU64,
    /// Old traces removed to keep at most `TraceSettings::keep`.
    pub pruned: AtomicU64,
}

/// Why the trace thread could not start.
#[derive(Debug, thiserror::Error)]
pub enum TraceError {
    /// The thread could not be spawned.
    #[error("cannot start the trace thread: {0}")]
    Spawn(std::io::Error),
}

/// What the trace files say about the run.
#[derive(Debug, Clone)]
pub struct TraceSettings {
    /// Directory the traces go to (validated by the config).
    pub dir: PathBuf,
    /// This daemon run's instance id (part of the file name).
    pub instance: u64,
    /// The model (header echo).
    pub hand: HandConfig,
    /// Control period \[s\].
    pub dt: f64,
    /// CPUs to pin the thread to (empty: any).
    pub cpus: Vec<u32>,
    /// Most finished traces kept in `dir` (0: all): after each trace is
    /// written the oldest `gaitd-*.jsonl` beyond this many are removed.
    pub keep: usize,
    /// The planner's notes on its plans (route, effort), if it keeps them.
    pub plan_notes: Option<Arc<PlanNotes>>,
    /// A chain hand's description file (header `hand_description`).
    pub hand_description: Option<String>,
}

/// Handle of the trace thread: `join` (or drop) writes everything still
/// queued (an unfinished trace is closed as incomplete), then stops it.
pub type TraceWriter = crate::sys::worker::StoppableThread;

/// Starts the `gaitd-trace` thread with a ring of `capacity` samples.
pub fn spawn(
    settings: TraceSettings,
    capacity: usize,
) -> Result<(TraceRecorder, TraceWriter), TraceError> {
    let (tx, rx) = handoff::channel::<TraceMsg>(capacity);
    let counters = Arc::new(TraceCounters::default());
    let stop = Arc::new(AtomicBool::new(false));
    let stop2 = stop.clone();
    let counters2 = counters.clone();
    let handle = std::thread::Builder::new()
        .name("gaitd-trace".into())
        .spawn(move || writer::run(settings, counters2, rx, &stop2))
        .map_err(TraceError::Spawn)?;
    Ok((
        TraceRecorder::new(tx, counters),
        TraceWriter::new(stop, handle),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sys::handoff::Consumer;
    use gait::HandState;
    use std::path::Path;
    use std::sync::atomic::Ordering;
    use std::time::Duration;

    fn settings(dir: &Path) -> TraceSettings {
        TraceSettings {
            dir: dir.to_path_buf(),
            instance: 0xabc,
            hand: HandConfig::default(),
            dt: 1e-3,
            cpus: Vec::new(),
            plan_notes: None,
            hand_description: None,
            keep: 0,
        }
    }

    fn sample() -> Sample {
        let hand = HandConfig::default();
        let s = HandState::paper_start(&hand);
        let fingers = core::array::from_fn(|k| gait::trace::FingerSample {
            p: s.fingers[k].center,
            q: s.fingers[k].orientation,
            contact: true,
            grip_force: 1.0,
            roll: 0.0,
            joints: None,
        });
        Sample {
            object_q: s.object,
            phase: "hold",
            fingers,
            fc: true,
            fc_margin: 0.1,
            load_margin: 10.0,
            remaining_angle: 0.0,
            gaits: 0,
            estimate_epoch: 0,
            joint_margin: None,
        }
    }

    fn read(path: &Path) -> Vec<String> {
        std::fs::read_to_string(path)
            .unwrap()
            .lines()
            .map(str::to_owned)
            .collect()
    }

    fn tmp(tag: &str) -> PathBuf {
        test_support::scratch_dir(&format!("tracer-{tag}"))
    }

    /// A recorder and a sink on one ring of `capacity`, sharing counters.
    fn rig(
        settings: TraceSettings,
        capacity: usize,
    ) -> (
        Arc<TraceCounters>,
        TraceRecorder,
        Consumer<TraceMsg>,
        TraceSink,
    ) {
        let counters = Arc::new(TraceCounters::default());
        let (tx, rx) = handoff::channel(capacity);
        let rec = TraceRecorder::new(tx, counters.clone());
        let sink = TraceSink::new(settings, counters.clone());
        (counters, rec, rx, sink)
    }

    #[test]
    fn a_complete_trace_has_its_outcome_in_the_header() {
        let dir = tmp("ok");
        let (counters, mut rec, mut rx, mut sink) = rig(settings(&dir), 64);
        rec.begin(1, 7, 9, None);
        for _ in 0..10 {
            rec.record(&sample());
            sink.drain(&mut rx);
        }
        rec.end(Some((GoalState::Succeeded, ReasonCode::Reached)));
        sink.drain(&mut rx);
        let lines = read(&sink.path_for(7, 9));
        assert_eq!(lines.len(), 11);
        assert!(lines[0].starts_with("{\"format\":\"gait-trajectory/1\""));
        for key in [
            "\"goal_id\":9",
            "\"client_id\":7",
            "\"outcome\":\"Succeeded\"",
            "\"reason\":\"Reached\"",
            "\"ticks\":10",
            "\"dropped_ticks\":0",
            "\"incomplete\":false",
        ] {
            assert!(lines[0].contains(key), "{key} in {}", lines[0]);
        }
        assert!(lines[1].starts_with("{\"t\":0,"), "{}", lines[1]);
        assert!(
            lines[10].starts_with("{\"t\":0.009000000000000001,"),
            "{}",
            lines[10]
        );
        // Nothing else left behind (the .part file is gone).
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1);
        assert_eq!(counters.written.load(Ordering::Relaxed), 1);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// With `keep = 3`, five goals leave the newest three traces; files
    /// that are not finished traces are never removed.
    #[test]
    fn old_traces_beyond_keep_are_removed() {
        let dir = tmp("keep");
        std::fs::write(dir.join("notes.txt"), "mine").unwrap();
        std::fs::write(dir.join("gaitd-other.json"), "mine").unwrap();
        let (counters, mut rec, mut rx, mut sink) = rig(
            TraceSettings {
                plan_notes: None,
                hand_description: None,
                keep: 3,
                ..settings(&dir)
            },
            64,
        );
        for goal in 1..=5u64 {
            rec.begin(goal, 7, goal, None);
            rec.record(&sample());
            rec.end(Some((GoalState::Succeeded, ReasonCode::Reached)));
            sink.drain(&mut rx);
            // Distinct modification times: the oldest go first.
            std::thread::sleep(Duration::from_millis(20));
        }
        let names: Vec<String> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        for p in (3..=5).map(|g| sink.path_for(7, g)) {
            assert!(p.exists(), "{} kept", p.display());
        }
        assert!(!sink.path_for(7, 1).exists() && !sink.path_for(7, 2).exists());
        assert_eq!(names.len(), 5, "{names:?}");
        assert!(names.contains(&"notes.txt".into()) && names.contains(&"gaitd-other.json".into()));
        assert_eq!(counters.written.load(Ordering::Relaxed), 5);
        assert_eq!(counters.pruned.load(Ordering::Relaxed), 2);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// The writer does not drain while the loop records 20 ticks into a
    /// ring of 8: 6 samples fit (one slot stays free for the end marker),
    /// 14 are dropped, and the trace says so.
    #[test]
    fn an_overflowing_ring_marks_the_trace_incomplete() {
        let dir = tmp("overflow");
        let (counters, mut rec, mut rx, mut sink) = rig(settings(&dir), 8);
        rec.begin(1, 7, 10, None);
        for _ in 0..20 {
            rec.record(&sample());
        }
        rec.end(Some((GoalState::Succeeded, ReasonCode::Reached)));
        assert_eq!(counters.dropped.load(Ordering::Relaxed), 14);
        sink.drain(&mut rx);
        let lines = read(&sink.path_for(7, 10));
        assert_eq!(lines.len(), 7);
        assert!(lines[0].contains("\"incomplete\":true"), "{}", lines[0]);
        assert!(lines[0].contains("\"dropped_ticks\":14"), "{}", lines[0]);
        assert!(lines[0].contains("\"ticks\":6"), "{}", lines[0]);
        // A ring with no room for start + end: the goal is not recorded.
        let (tx, _rx) = handoff::channel(1);
        let mut rec = TraceRecorder::new(tx, counters.clone());
        rec.begin(2, 7, 11, None);
        assert_eq!(rec.recording(), None);
        assert_eq!(counters.missed.load(Ordering::Relaxed), 1);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn an_unfinished_trace_is_closed_as_incomplete() {
        let dir = tmp("unfinished");
        let (_, mut rec, mut rx, mut sink) = rig(settings(&dir), 64);
        rec.begin(1, 7, 12, None);
        rec.record(&sample());
        sink.drain(&mut rx);
        sink.close_unfinished();
        let lines = read(&sink.path_for(7, 12));
        assert_eq!(lines.len(), 2);
        assert!(lines[0].contains("\"outcome\":\"unknown\""), "{}", lines[0]);
        assert!(lines[0].contains("\"incomplete\":true"), "{}", lines[0]);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
