//! Goal traces from the loop side: one fixed-size sample per tick into the
//! recorder's ring (the tracer thread formats and writes, SPEC §8).

use super::GaitController;
use crate::io::tracer::{Sample, TraceRecorder};
use gait::executor::{self, TickReport};

impl GaitController {
    /// Records every goal's execution through `recorder` (SPEC §8; see
    /// [`crate::io::tracer`]).
    pub fn set_trace(&mut self, recorder: TraceRecorder) {
        self.trace = Some(recorder);
    }

    /// The executor goal being traced, if any.
    pub(super) fn tracing(&self) -> Option<u64> {
        self.trace.as_ref().and_then(TraceRecorder::recording)
    }

    /// Feeds this tick to the trace recorder: a goal is recorded from the
    /// tick it is first reported `Executing` to the tick its terminal state
    /// is seen (that tick included). Copies one `Sample`; no allocation.
    pub(super) fn record_trace(&mut self, r: &TickReport) {
        let Some(rec) = &mut self.trace else { return };
        let sample = Sample::from_report(r);
        let starting = match r.goal {
            Some((id, executor::GoalStage::Executing, _)) if rec.recording() != Some(id) => {
                Some(id)
            }
            _ => None,
        };
        // This tick belongs to the goal being recorded unless another one
        // starts executing in it.
        if starting.is_none() {
            rec.record(&sample);
        }
        if let Some(end) = self.trace_end.take() {
            rec.end(Some(end));
        }
        if let Some(id) = starting {
            let (client, goal) = self.ids.wire(id);
            rec.begin(id, client, goal, self.ids.target(id));
            rec.record(&sample);
        }
    }
}
