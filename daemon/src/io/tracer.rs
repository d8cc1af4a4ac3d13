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

use crate::control::handoff::{self, Consumer, Producer};
use gait::HandConfig;
use gait::executor::GoalTarget;
pub use gait::trace::Sample;
use shm_schema::{GoalState, ReasonCode};
use std::fmt::Write as _;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::Duration;

/// Samples the ring holds: 4 s at 1 kHz (about 1.3 MB), far more than the
/// writer's poll period, so only a stalled disk makes it overflow.
pub const DEFAULT_CAPACITY: usize = 4096;

/// How often the trace thread looks at the ring. The loop never wakes it.
const POLL: Duration = Duration::from_millis(10);

/// One message from the loop to the trace thread.
#[derive(Debug, Clone, Copy)]
#[allow(clippy::large_enum_variant)] // stored inline on purpose: no boxing on the loop
pub enum TraceMsg {
    /// A goal started executing.
    Begin {
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
}

/// Handle of the trace thread: `join` (or drop) writes everything still
/// queued (an unfinished trace is closed as incomplete), then stops it.
pub type TraceWriter = crate::io::worker::StoppableThread;

/// Starts the `gaitd-trace` thread with a ring of `capacity` samples.
pub fn spawn(
    settings: TraceSettings,
    capacity: usize,
) -> Result<(TraceRecorder, TraceWriter), TraceError> {
    let (tx, mut rx) = handoff::channel::<TraceMsg>(capacity);
    let counters = Arc::new(TraceCounters::default());
    let stop = Arc::new(AtomicBool::new(false));
    let stop2 = stop.clone();
    let counters2 = counters.clone();
    let handle = std::thread::Builder::new()
        .name("gaitd-trace".into())
        .spawn(move || {
            if let Err(e) = crate::process::rt::pin_current_thread(&settings.cpus) {
                tracing::warn!(cpus = ?settings.cpus, error = %e, "cannot pin the trace thread");
            }
            let mut sink = TraceSink::new(settings, counters2);
            loop {
                let stopping = stop2.load(Ordering::Acquire);
                sink.drain(&mut rx);
                if stopping {
                    break;
                }
                std::thread::park_timeout(POLL);
            }
            sink.close_unfinished();
        })
        .map_err(TraceError::Spawn)?;
    Ok((
        TraceRecorder::new(tx, counters),
        TraceWriter::new(stop, handle),
    ))
}

/// The trace being written.
struct Open {
    client_id: u64,
    goal_id: u64,
    target: Option<GoalTarget>,
    part: PathBuf,
    /// None once an I/O error made the trace unusable.
    out: Option<BufWriter<File>>,
    ticks: u64,
    /// Next expected tick index (a jump is a gap).
    next_k: u64,
    gaps: u64,
}

/// The trace thread's side: formats and writes (module docs).
pub struct TraceSink {
    settings: TraceSettings,
    counters: Arc<TraceCounters>,
    open: Option<Open>,
    line: String,
    missed_seen: u64,
}

impl std::fmt::Debug for TraceSink {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("TraceSink")
            .field("dir", &self.settings.dir)
            .finish()
    }
}

impl TraceSink {
    /// A sink writing into `settings.dir`.
    pub fn new(settings: TraceSettings, counters: Arc<TraceCounters>) -> Self {
        Self {
            settings,
            counters,
            open: None,
            line: String::with_capacity(2048),
            missed_seen: 0,
        }
    }

    /// The final path of a goal's trace.
    pub fn path_for(&self, client_id: u64, goal_id: u64) -> PathBuf {
        self.settings.dir.join(format!(
            "gaitd-{:016x}-client-{client_id:016x}-goal-{goal_id}.jsonl",
            self.settings.instance
        ))
    }

    /// Handles everything in the ring.
    pub fn drain(&mut self, rx: &mut Consumer<TraceMsg>) {
        while let Some(m) = rx.pop() {
            self.handle(m);
        }
        let missed = self.counters.missed.load(Ordering::Relaxed);
        if missed != self.missed_seen {
            tracing::warn!(
                goals = missed - self.missed_seen,
                "trace: goals not recorded (the trace ring was full: the trace writer is too slow)"
            );
            self.missed_seen = missed;
        }
    }

    /// Handles one message.
    pub fn handle(&mut self, m: TraceMsg) {
        match m {
            TraceMsg::Begin {
                client_id,
                goal_id,
                target,
            } => {
                if self.open.is_some() {
                    self.finish(None, 0);
                }
                let part = self.settings.dir.join(format!(
                    ".gaitd-{:016x}-client-{client_id:016x}-goal-{goal_id}.jsonl.part",
                    self.settings.instance
                ));
                let out = match File::create(&part) {
                    Ok(f) => Some(BufWriter::with_capacity(64 * 1024, f)),
                    Err(e) => {
                        tracing::warn!(path = %part.display(), error = %e, "trace: cannot create file; goal not recorded");
                        None
                    }
                };
                self.open = Some(Open {
                    client_id,
                    goal_id,
                    target,
                    part,
                    out,
                    ticks: 0,
                    next_k: 0,
                    gaps: 0,
                });
            }
            TraceMsg::Tick { k, sample } => {
                let Some(o) = &mut self.open else { return };
                if k != o.next_k {
                    o.gaps += k.saturating_sub(o.next_k);
                }
                o.next_k = k + 1;
                o.ticks += 1;
                let Some(out) = &mut o.out else { return };
                self.line.clear();
                gait::trace::sample_line(&mut self.line, k as f64 * self.settings.dt, &sample);
                if let Err(e) = out.write_all(self.line.as_bytes()) {
                    tracing::warn!(path = %o.part.display(), error = %e, "trace: write failed; goal not recorded");
                    o.out = None;
                    let _ = std::fs::remove_file(&o.part);
                }
            }
            TraceMsg::End { outcome, dropped } => self.finish(outcome, dropped),
        }
    }

    /// Closes a trace the loop did not end (shutdown) as incomplete.
    pub fn close_unfinished(&mut self) {
        if self.open.is_some() {
            self.finish(None, 0);
        }
    }

    fn header_extra(
        &self,
        o: &Open,
        outcome: Option<(GoalState, ReasonCode)>,
        dropped: u64,
    ) -> String {
        let mut x = String::new();
        let _ = write!(
            x,
            "\"source\":\"gaitd\",\"instance\":\"{:016x}\",\"client_id\":{},\"goal_id\":{}",
            self.settings.instance, o.client_id, o.goal_id
        );
        match o.target {
            Some(GoalTarget::Orientation(q)) => {
                let q = q.quaternion();
                let _ = write!(x, ",\"target_q\":[{},{},{},{}]", q.w, q.i, q.j, q.k);
            }
            Some(GoalTarget::Rotation { axis, angle }) => {
                let _ = write!(
                    x,
                    ",\"target_axis\":[{},{},{}],\"target_angle\":{angle}",
                    axis.x, axis.y, axis.z
                );
            }
            None => {}
        }
        let (state, reason) = outcome.map_or(("unknown", "unknown"), |(s, r)| (s.name(), r.name()));
        let _ = write!(
            x,
            ",\"outcome\":\"{state}\",\"reason\":\"{reason}\",\"ticks\":{},\"dropped_ticks\":{dropped},\"incomplete\":{}",
            o.ticks,
            dropped > 0 || outcome.is_none()
        );
        x
    }

    fn finish(&mut self, outcome: Option<(GoalState, ReasonCode)>, dropped: u64) {
        let Some(mut o) = self.open.take() else {
            return;
        };
        // The loop's count is the truth; the gap count covers a lost end
        // marker (never expected).
        let dropped = dropped.max(o.gaps);
        let Some(out) = o.out.take() else { return };
        let path = self.path_for(o.client_id, o.goal_id);
        let mut header = String::new();
        gait::trace::header(
            &mut header,
            &self.settings.hand,
            self.settings.dt,
            &self.header_extra(&o, outcome, dropped),
        );
        match write_final(out, &o.part, &path, &header) {
            Ok(()) => {
                self.counters.written.fetch_add(1, Ordering::Relaxed);
                let outcome = outcome.map_or("unknown", |(s, _)| s.name());
                if dropped > 0 || outcome == "unknown" {
                    tracing::warn!(
                        path = %path.display(),
                        ticks = o.ticks,
                        dropped,
                        outcome,
                        "trace written INCOMPLETE (samples dropped: the trace writer fell behind, or the goal did not end)"
                    );
                } else {
                    tracing::info!(path = %path.display(), ticks = o.ticks, outcome, "trace written");
                }
                self.prune();
            }
            Err(e) => {
                tracing::warn!(path = %path.display(), error = %e, "trace: cannot write; goal not recorded");
                let _ = std::fs::remove_file(&o.part);
                let _ = std::fs::remove_file(&path);
            }
        }
    }
}

impl TraceSink {
    /// Removes the oldest traces beyond `keep` (by modification time, then
    /// name). Only finished traces of the daemon's naming pattern count;
    /// other files in the directory are never touched.
    fn prune(&mut self) {
        if self.settings.keep == 0 {
            return;
        }
        let Ok(dir) = std::fs::read_dir(&self.settings.dir) else {
            return;
        };
        let mut traces: Vec<(std::time::SystemTime, PathBuf)> = dir
            .flatten()
            .filter(|e| is_trace_name(&e.file_name().to_string_lossy()))
            .filter_map(|e| {
                let m = e.metadata().ok()?;
                m.is_file()
                    .then(|| (m.modified().unwrap_or(std::time::UNIX_EPOCH), e.path()))
            })
            .collect();
        if traces.len() <= self.settings.keep {
            return;
        }
        traces.sort();
        let excess = traces.len() - self.settings.keep;
        let mut removed = 0usize;
        for (_, path) in traces.into_iter().take(excess) {
            match std::fs::remove_file(&path) {
                Ok(()) => removed += 1,
                Err(e) => {
                    tracing::warn!(path = %path.display(), error = %e, "trace: cannot remove an old trace")
                }
            }
        }
        self.counters
            .pruned
            .fetch_add(removed as u64, Ordering::Relaxed);
    }
}

/// Whether `name` is a finished trace's file name
/// (`gaitd-<instance>-client-<client>-goal-<goal>.jsonl`).
fn is_trace_name(name: &str) -> bool {
    name.starts_with("gaitd-") && name.ends_with(".jsonl") && name.contains("-goal-")
}

/// Header, then the lines from `part`, into `path`; removes `part`. The
/// file appears under its final name only when complete (written under a
/// hidden name, then renamed), so whoever watches the directory never
/// reads half a trace.
fn write_final(
    out: BufWriter<File>,
    part: &Path,
    path: &Path,
    header: &str,
) -> std::io::Result<()> {
    out.into_inner().map_err(|e| e.into_error())?;
    let name = path
        .file_name()
        .map_or_else(Default::default, |n| n.to_string_lossy());
    let staged = path.with_file_name(format!(".{name}.tmp"));
    let write = || -> std::io::Result<()> {
        let mut dst = BufWriter::with_capacity(64 * 1024, File::create(&staged)?);
        dst.write_all(header.as_bytes())?;
        std::io::copy(&mut File::open(part)?, &mut dst)?;
        dst.into_inner().map_err(|e| e.into_error())?;
        std::fs::rename(&staged, path)
    };
    if let Err(e) = write() {
        let _ = std::fs::remove_file(&staged);
        return Err(e);
    }
    std::fs::remove_file(part)
}

#[cfg(test)]
mod tests {
    use super::*;
    use gait::HandState;

    fn settings(dir: &Path) -> TraceSettings {
        TraceSettings {
            dir: dir.to_path_buf(),
            instance: 0xabc,
            hand: HandConfig::default(),
            dt: 1e-3,
            cpus: Vec::new(),
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
        });
        Sample {
            object_q: s.object,
            phase: "hold",
            fingers,
            fc: true,
            fc_margin: 0.1,
            remaining_angle: 0.0,
            gaits: 0,
            estimate_epoch: 0,
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
        let d = std::env::temp_dir().join(format!("gaitd-tracer-{}-{tag}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
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
