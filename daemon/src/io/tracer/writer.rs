//! The `gaitd-trace` thread's side: drains the ring on its own timer (the
//! loop never wakes it), formats each sample as a `gait-trajectory/1` line
//! into a hidden `.part` file, and when the goal ends writes the final
//! file — header first — under a staged name, then renames it into place.

use super::format::{HeaderFacts, header_extra, part_path, trace_path};
use super::{TraceCounters, TraceMsg, TraceSettings, retention};
use crate::sys::handoff::Consumer;
use gait::executor::GoalTarget;
use shm_schema::{GoalState, ReasonCode};
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

/// How often the trace thread looks at the ring. The loop never wakes it.
const POLL: Duration = Duration::from_millis(10);

/// The thread's body: drain every `POLL` until `stop`, then close what is
/// left.
pub(super) fn run(
    settings: TraceSettings,
    counters: Arc<TraceCounters>,
    mut rx: Consumer<TraceMsg>,
    stop: &AtomicBool,
) {
    if let Err(e) = crate::sys::rt::pin_current_thread(&settings.cpus) {
        tracing::warn!(cpus = ?settings.cpus, error = %e, "cannot pin the trace thread");
    }
    let mut sink = TraceSink::new(settings, counters);
    loop {
        let stopping = stop.load(Ordering::Acquire);
        sink.drain(&mut rx);
        if stopping {
            break;
        }
        std::thread::park_timeout(POLL);
    }
    sink.close_unfinished();
}

/// The trace being written.
struct Open {
    exec_goal: u64,
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
        trace_path(&self.settings, client_id, goal_id)
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
                exec_goal,
                client_id,
                goal_id,
                target,
            } => self.begin(exec_goal, client_id, goal_id, target),
            TraceMsg::Tick { k, sample } => self.tick(k, &sample),
            TraceMsg::End { outcome, dropped } => self.finish(outcome, dropped),
        }
    }

    fn begin(&mut self, exec_goal: u64, client_id: u64, goal_id: u64, target: Option<GoalTarget>) {
        if self.open.is_some() {
            self.finish(None, 0);
        }
        let part = part_path(&self.settings, client_id, goal_id);
        let out = match File::create(&part) {
            Ok(f) => Some(BufWriter::with_capacity(64 * 1024, f)),
            Err(e) => {
                tracing::warn!(path = %part.display(), error = %e, "trace: cannot create file; goal not recorded");
                None
            }
        };
        self.open = Some(Open {
            exec_goal,
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

    fn tick(&mut self, k: u64, sample: &gait::trace::Sample) {
        let Some(o) = &mut self.open else { return };
        if k != o.next_k {
            o.gaps += k.saturating_sub(o.next_k);
        }
        o.next_k = k + 1;
        o.ticks += 1;
        let Some(out) = &mut o.out else { return };
        self.line.clear();
        gait::trace::sample_line(&mut self.line, k as f64 * self.settings.dt, sample);
        if let Err(e) = out.write_all(self.line.as_bytes()) {
            tracing::warn!(path = %o.part.display(), error = %e, "trace: write failed; goal not recorded");
            o.out = None;
            let _ = std::fs::remove_file(&o.part);
        }
    }

    /// Closes a trace the loop did not end (shutdown) as incomplete.
    pub fn close_unfinished(&mut self) {
        if self.open.is_some() {
            self.finish(None, 0);
        }
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
        let plan = self
            .settings
            .plan_notes
            .as_ref()
            .and_then(|n| n.take(o.exec_goal));
        let facts = HeaderFacts {
            plan,
            client_id: o.client_id,
            goal_id: o.goal_id,
            target: o.target,
            outcome,
            ticks: o.ticks,
            dropped,
            hand_description: self.settings.hand_description.clone(),
        };
        let mut header = String::new();
        gait::trace::header(
            &mut header,
            &self.settings.hand,
            self.settings.dt,
            &header_extra(self.settings.instance, &facts),
        );
        match write_final(out, &o.part, &path, &header) {
            Ok(()) => {
                self.counters.written.fetch_add(1, Ordering::Relaxed);
                log_written(&path, &facts);
                let removed = retention::prune(&self.settings.dir, self.settings.keep);
                self.counters.pruned.fetch_add(removed, Ordering::Relaxed);
            }
            Err(e) => {
                tracing::warn!(path = %path.display(), error = %e, "trace: cannot write; goal not recorded");
                let _ = std::fs::remove_file(&o.part);
                let _ = std::fs::remove_file(&path);
            }
        }
    }
}

/// One log line per trace: WARN when it is incomplete.
fn log_written(path: &Path, facts: &HeaderFacts) {
    let outcome = facts.outcome.map_or("unknown", |(s, _)| s.name());
    let (ticks, dropped) = (facts.ticks, facts.dropped);
    if dropped > 0 || outcome == "unknown" {
        tracing::warn!(
            path = %path.display(),
            ticks,
            dropped,
            outcome,
            "trace written INCOMPLETE (samples dropped: the trace writer fell behind, or the goal did not end)"
        );
    } else {
        tracing::info!(path = %path.display(), ticks, outcome, "trace written");
    }
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
