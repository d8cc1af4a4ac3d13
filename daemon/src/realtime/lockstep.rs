//! Lockstep pacing (`[plant] timing = "lockstep"`, PLANT-GUIDE.md): the
//! plant, not the clock, paces the loop. A tick runs only on a new plant
//! measurement, with now = its plant time. While none comes the loop waits
//! (at most a period at a time, so the stop flag and a heartbeat status —
//! the last one, published again — keep going); after
//! `plant.lockstep_timeout_ms` without one, one tick runs to fault
//! (`PlantLost`) and the wait goes on. Commands are handled on the plant's
//! ticks; while the plant is absent (lost, or no first measurement within
//! `plant.connect_timeout_ms`) the loop answers them itself every period,
//! at the last plant time and tick: time stays the plant's.
//!
//! While the controller awaits a plan ([`Controller::awaits_plan`]) a new
//! measurement is held and the loop beats instead, for at most
//! [`PLAN_WAIT`] (then the tick runs without the plan, which arrives at a
//! later tick, as in real time).
//!
//! [`Lockstep`] decides what each pass of the loop does ([`Pass`]);
//! [`Runtime::lockstep_once`](super::runtime::Runtime::lockstep_once)
//! waits for the plant, reads it and carries the decision out. Plain
//! state, no allocation: it runs on the loop thread.
//!
//! [`Controller::awaits_plan`]: crate::control::controller::Controller::awaits_plan

use crate::plant::PlantSample;
use crate::sys::clock::Nanos;

/// How long a lockstep tick is held for a plan before it runs without it
/// \[ns\].
pub const PLAN_WAIT: Nanos = 10_000_000_000;

/// What one pass of the lockstep loop does.
#[derive(Debug, Clone, Copy, PartialEq)]
#[allow(clippy::large_enum_variant)] // returned by value: no boxing on the loop
pub enum Pass {
    /// Nothing: wait again.
    Wait,
    /// No tick: publish a heartbeat status; with `answer` (the plant is
    /// absent) first answer the commands that came, at the last plant
    /// time.
    Beat {
        /// Answer waiting commands before the heartbeat.
        answer: bool,
    },
    /// A tick on the plant's measurement `sample`, at its plant time; then
    /// [`Lockstep::ticked`].
    Tick {
        /// What the plant sent (its newest measurement and how many came).
        sample: PlantSample,
        /// How long the measurement was held for a plan, if it was \[ns\].
        plan_wait: Option<Nanos>,
    },
    /// The plant timed out: one tick on a timed-out sample, a period after
    /// the last tick, to fault.
    Lost,
}

/// A measurement held for a plan.
#[derive(Debug, Clone, Copy)]
struct Held {
    sample: PlantSample,
    /// When it was first held (wall clock).
    since: Nanos,
    /// Passes that waited on it.
    passes: u64,
}

/// The lockstep loop's state between passes.
#[derive(Debug, Clone, Copy)]
pub struct Lockstep {
    /// How long the plant may make no progress before a tick runs to
    /// fault \[ns\].
    timeout: Nanos,
    /// How long commands wait for the plant's first measurement before the
    /// loop answers them itself \[ns\].
    connect_timeout: Nanos,
    /// The loop's period: the longest wait, the heartbeat interval \[ns\].
    period: Nanos,
    /// Sequence number of the last plant measurement taken (0: none yet).
    plant_seq: u64,
    /// When the lockstep loop started (wall clock).
    started: Nanos,
    /// When the plant last made progress (wall clock).
    last_progress: Nanos,
    /// When the next heartbeat is due (wall clock).
    next_beat: Nanos,
    /// Whether the plant's timeout was reported.
    timed_out: bool,
    /// A measurement held while the controller waits for a plan.
    held: Option<Held>,
}

impl Lockstep {
    /// Pacing with the plant's `timeout`, its `connect_timeout` and the
    /// loop's `period` \[ns\], started at time 0.
    pub fn new(timeout: Nanos, connect_timeout: Nanos, period: Nanos) -> Self {
        Self {
            timeout,
            connect_timeout,
            period,
            plant_seq: 0,
            started: 0,
            last_progress: 0,
            next_beat: 0,
            timed_out: false,
            held: None,
        }
    }

    /// The lockstep loop starts at `now` (wall clock): timeouts count from
    /// here, the first heartbeat is a period later.
    pub fn start(&mut self, now: Nanos) {
        *self = Self {
            started: now,
            last_progress: now,
            next_beat: now + self.period,
            timed_out: false,
            held: None,
            ..*self
        };
    }

    /// What the pass at `now` (wall clock) does, given what the plant sent
    /// since the last pass and whether the controller awaits a plan.
    pub fn pass(&mut self, now: Nanos, sample: PlantSample, awaits_plan: bool) -> Pass {
        if let Some(m) = sample.newest.filter(|m| m.seq != self.plant_seq) {
            self.plant_seq = m.seq;
            self.last_progress = now;
            self.timed_out = false;
            self.held = Some(match self.held {
                // (A plant that sent again meanwhile: its newest counts.)
                Some(h) => Held {
                    sample: PlantSample {
                        received: h.sample.received.saturating_add(sample.received),
                        ..sample
                    },
                    ..h
                },
                None => Held {
                    sample,
                    since: now,
                    passes: 0,
                },
            });
        }
        if let Some(held) = self.held.as_mut() {
            let waited = now.saturating_sub(held.since);
            if awaits_plan && waited < PLAN_WAIT {
                // Waiting for the planner, not for the plant.
                held.passes += 1;
                self.last_progress = now;
                return self.beat_due(now, false);
            }
            let held = *held;
            self.held = None;
            Pass::Tick {
                sample: held.sample,
                plan_wait: (held.passes > 0).then_some(waited),
            }
        } else if self.plant_seq != 0
            && !self.timed_out
            && now.saturating_sub(self.last_progress) > self.timeout
        {
            self.timed_out = true;
            self.next_beat = now + self.period;
            Pass::Lost
        } else {
            let absent = if self.plant_seq == 0 {
                now.saturating_sub(self.started) > self.connect_timeout
            } else {
                self.timed_out
            };
            self.beat_due(now, absent)
        }
    }

    /// A tick on the plant's measurement ended at `now` (wall clock): the
    /// next heartbeat is due a period later.
    pub fn ticked(&mut self, now: Nanos) {
        self.next_beat = now + self.period;
    }

    /// A heartbeat if one is due at `now`, else nothing.
    fn beat_due(&mut self, now: Nanos, answer: bool) -> Pass {
        if now >= self.next_beat {
            self.next_beat = now + self.period;
            Pass::Beat { answer }
        } else {
            Pass::Wait
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use shm_schema::PlantMeasurement;

    const MS: Nanos = 1_000_000;

    fn measured(seq: u64) -> PlantSample {
        PlantSample {
            newest: Some(PlantMeasurement {
                seq,
                ..PlantMeasurement::default()
            }),
            received: 1,
            ..PlantSample::default()
        }
    }

    fn started() -> Lockstep {
        let mut l = Lockstep::new(50 * MS, 200 * MS, MS);
        l.start(1000 * MS);
        l
    }

    #[test]
    fn a_new_measurement_ticks_and_a_repeated_one_does_not() {
        let mut l = started();
        let t = 1000 * MS + 100;
        assert_eq!(
            l.pass(t, measured(1), false),
            Pass::Tick {
                sample: measured(1),
                plan_wait: None
            }
        );
        l.ticked(t);
        assert_eq!(l.pass(t + 10, measured(1), false), Pass::Wait);
        assert_eq!(
            l.pass(t + MS, measured(1), false),
            Pass::Beat { answer: false }
        );
    }

    #[test]
    fn a_silent_plant_is_lost_once_and_then_answered_for() {
        let mut l = started();
        let t = 1000 * MS;
        assert!(matches!(l.pass(t, measured(1), false), Pass::Tick { .. }));
        l.ticked(t);
        assert_eq!(
            l.pass(t + 50 * MS, PlantSample::default(), false),
            Pass::Beat { answer: false }
        );
        assert_eq!(
            l.pass(t + 51 * MS, PlantSample::default(), false),
            Pass::Lost
        );
        assert_eq!(
            l.pass(t + 52 * MS, PlantSample::default(), false),
            Pass::Beat { answer: true }
        );
        // It comes back: ticks again, commands wait for its ticks.
        assert!(matches!(
            l.pass(t + 53 * MS, measured(2), false),
            Pass::Tick { .. }
        ));
        l.ticked(t + 53 * MS);
        assert_eq!(
            l.pass(t + 54 * MS, PlantSample::default(), false),
            Pass::Beat { answer: false }
        );
    }

    #[test]
    fn commands_are_answered_when_no_plant_connects() {
        let mut l = started();
        let t = 1000 * MS;
        assert_eq!(
            l.pass(t + 100 * MS, PlantSample::default(), false),
            Pass::Beat { answer: false }
        );
        assert_eq!(
            l.pass(t + 201 * MS, PlantSample::default(), false),
            Pass::Beat { answer: true }
        );
    }

    #[test]
    fn a_measurement_is_held_for_a_plan_at_most_the_plan_wait() {
        let mut l = started();
        let t = 1000 * MS;
        assert_eq!(l.pass(t, measured(1), true), Pass::Wait);
        // Held, not lost: the wait is the planner's.
        assert_eq!(
            l.pass(t + 60 * MS, measured(2), true),
            Pass::Beat { answer: false }
        );
        let mut twice = measured(2);
        twice.received = 2;
        assert_eq!(
            l.pass(t + 70 * MS, PlantSample::default(), false),
            Pass::Tick {
                sample: twice,
                plan_wait: Some(70 * MS)
            }
        );
        assert_eq!(
            l.pass(t + 80 * MS, measured(3), true),
            Pass::Beat { answer: false }
        );
        assert!(matches!(
            l.pass(t + 80 * MS + PLAN_WAIT, PlantSample::default(), true),
            Pass::Tick {
                plan_wait: Some(PLAN_WAIT),
                ..
            }
        ));
    }
}
