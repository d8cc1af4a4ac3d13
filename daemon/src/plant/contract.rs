//! The timing contract with an external plant (PLANT-GUIDE.md, "Timing
//! contract"), counted as TriFinger's `robot_interfaces` counts action
//! repetitions and libfranka counts lost packets: every tick may miss it in four ways —
//!
//! - its command went out late: in real time, handed out after the next
//!   tick's deadline, or a period skipped with no command at all;
//! - the plant repeated a command: two consecutive measurements echo the
//!   same `applied` command (the plant stepped again before the next
//!   command reached it, and held the last one);
//! - its measurement came late: the tick found no new measurement (it
//!   holds the last one);
//! - a measurement came twice: one with a sequence number already taken.
//!
//! Each is counted since start; a run of `plant.max_misses_in_row` ticks in
//! a row (default: [`DEFAULT_MAX_MISSES_IN_ROW`]) that each missed in some
//! way is a fault (`PlantTiming`), reported
//! through the plant link like a lost plant. Counting starts with the
//! plant's first measurement (a plant that has not started misses
//! nothing). Plain counters, no allocation: it runs on the loop thread.
//!
//! [`DEFAULT_MAX_MISSES_IN_ROW`]: crate::config::plant::DEFAULT_MAX_MISSES_IN_ROW

use super::PlantSample;
use shm_schema::Timing;

/// The counters and the run of misses (module docs).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ContractWatch {
    /// Fault at this many misses in a row (0: never).
    limit: u64,
    /// The plant has sent a measurement.
    started: bool,
    /// Sequence number and echoed command of the last measurement taken.
    last_seq: u64,
    last_applied: u64,
    /// This tick's measurement missed (late or repeated, or it showed a
    /// repeated command).
    tick_missed: bool,
    commands_late: u64,
    commands_repeated: u64,
    measurements_late: u64,
    measurements_repeated: u64,
    in_row: u64,
    in_row_max: u64,
    /// The fault is due (reported once per run of misses).
    broken: bool,
}

impl ContractWatch {
    /// A watch that faults at `limit` misses in a row (0: never).
    pub fn new(limit: u32) -> Self {
        Self {
            limit: u64::from(limit),
            ..Self::default()
        }
    }

    /// What this tick received from the plant (before the tick runs).
    pub fn measured(&mut self, sample: &PlantSample) {
        self.tick_missed = false;
        let Some(m) = &sample.newest else {
            if self.started || sample.timed_out {
                self.measurements_late += 1;
                self.tick_missed = true;
            }
            return;
        };
        if self.started && m.seq == self.last_seq {
            self.measurements_repeated += 1;
            self.tick_missed = true;
            return;
        }
        if self.started
            && m.seq == self.last_seq + 1
            && m.applied != 0
            && m.applied == self.last_applied
        {
            self.commands_repeated += 1;
            self.tick_missed = true;
        }
        self.started = true;
        self.last_seq = m.seq;
        self.last_applied = m.applied;
    }

    /// The tick's end: `late` commands went out late (its own, and any
    /// periods skipped before it). Returns whether the run of misses just
    /// reached the limit.
    pub fn ticked(&mut self, late: u64) -> bool {
        if !self.started {
            return false;
        }
        self.commands_late += late;
        if self.tick_missed || late > 0 {
            self.in_row += 1;
            self.in_row_max = self.in_row_max.max(self.in_row);
        } else {
            self.in_row = 0;
        }
        let due = self.limit > 0 && self.in_row == self.limit;
        self.broken |= due;
        due
    }

    /// Whether the fault is due; clears it (reported once).
    pub fn take_broken(&mut self) -> bool {
        std::mem::take(&mut self.broken)
    }

    /// Writes the counters into the status's timing block.
    pub fn fill(&self, t: &mut Timing) {
        t.plant_commands_late = self.commands_late;
        t.plant_commands_repeated = self.commands_repeated;
        t.plant_measurements_late = self.measurements_late;
        t.plant_measurements_repeated = self.measurements_repeated;
        t.plant_misses_in_row = self.in_row;
        t.plant_misses_in_row_max = self.in_row_max;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use shm_schema::PlantMeasurement;

    fn m(seq: u64, applied: u64) -> PlantSample {
        PlantSample {
            newest: Some(PlantMeasurement {
                seq,
                applied,
                ..PlantMeasurement::default()
            }),
            received: 1,
            ..PlantSample::default()
        }
    }

    #[test]
    fn each_miss_is_counted_and_a_run_of_them_is_due_once() {
        let mut w = ContractWatch::new(3);
        // Nothing before the plant's first measurement.
        w.measured(&PlantSample::default());
        assert!(!w.ticked(0));
        w.measured(&m(1, 0));
        assert!(!w.ticked(0));
        w.measured(&m(2, 1));
        assert!(!w.ticked(0));
        // The plant repeated command 1, then a tick without measurement,
        // then one measurement twice: three in a row.
        w.measured(&m(3, 1));
        assert!(!w.ticked(0));
        w.measured(&PlantSample::default());
        assert!(!w.ticked(0));
        w.measured(&m(3, 1));
        assert!(w.ticked(0));
        assert!(w.take_broken() && !w.take_broken());
        // A command late keeps the run going; a clean tick ends it.
        w.measured(&m(4, 3));
        assert!(!w.ticked(1));
        w.measured(&m(5, 4));
        assert!(!w.ticked(0));
        let mut t = Timing::default();
        w.fill(&mut t);
        assert_eq!(
            (
                t.plant_commands_late,
                t.plant_commands_repeated,
                t.plant_measurements_late,
                t.plant_measurements_repeated,
                t.plant_misses_in_row,
                t.plant_misses_in_row_max
            ),
            (1, 1, 1, 1, 0, 4)
        );
    }
}
