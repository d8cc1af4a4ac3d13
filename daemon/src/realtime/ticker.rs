//! Periodic wake-ups on absolute deadlines (SPEC §7.2; as copper-rs's
//! `LoopRateLimiter`).
//!
//! Deadlines are `start + k·period`, never "now + period", so a late
//! wake-up does not shift the ones after it. When the loop wakes after one
//! or more whole deadlines have passed (a long tick, a preempted thread), it
//! runs once for the latest passed deadline and reports the skipped ones as
//! missed: it never runs a burst of ticks to catch up.

use crate::sys::clock::{Clock, Nanos};

/// One wake-up of the loop.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Wake {
    /// The deadline this tick belongs to.
    pub deadline: Nanos,
    /// When the loop actually woke.
    pub now: Nanos,
    /// Whole periods skipped since the previous tick (0 when on time).
    pub missed: u64,
}

impl Wake {
    /// Wake-up jitter: how late the loop woke for this tick's deadline \[ns\].
    pub fn jitter(&self) -> Nanos {
        self.now - self.deadline
    }
}

/// Absolute-deadline periodic timer over an injected [`Clock`].
#[derive(Debug, Clone)]
pub struct Ticker {
    period: Nanos,
    next: Nanos,
    spin: Nanos,
}

impl Ticker {
    /// First deadline one period after `start`.
    pub fn new(start: Nanos, period: Nanos) -> Self {
        assert!(period > 0, "period must be positive");
        Self {
            period,
            next: start + period,
            spin: 0,
        }
    }

    /// Sleeps only until `spin` before each deadline and busy-waits the
    /// rest (`[rt] spin_us`): trades that much CPU per period for a wake-up
    /// without timer and scheduler latency.
    pub fn with_spin(mut self, spin: Nanos) -> Self {
        self.spin = spin.min(self.period);
        self
    }

    /// Sleeps (then spins, see [`Ticker::with_spin`]) until `deadline`.
    fn sleep_until<C: Clock>(&self, clock: &mut C, deadline: Nanos) {
        if self.spin == 0 {
            clock.sleep_until(deadline);
        } else {
            if clock.now() < deadline.saturating_sub(self.spin) {
                clock.sleep_until(deadline - self.spin);
            }
            clock.spin_until(deadline);
        }
    }

    /// The period \[ns\].
    pub fn period(&self) -> Nanos {
        self.period
    }

    /// The next deadline.
    pub fn next_deadline(&self) -> Nanos {
        self.next
    }

    /// Sleeps until the next deadline (re-sleeping after early returns such
    /// as EINTR) and schedules the one after it.
    pub fn wait<C: Clock>(&mut self, clock: &mut C) -> Wake {
        let mut now = clock.now();
        while now < self.next {
            self.sleep_until(clock, self.next);
            now = clock.now();
        }
        self.wake_at(now)
    }

    /// Like [`Ticker::wait`] but returns early (None) when `stop()` turns
    /// true after an interrupted sleep, so a signal is seen promptly.
    pub fn wait_or_stop<C: Clock>(
        &mut self,
        clock: &mut C,
        stop: impl Fn() -> bool,
    ) -> Option<Wake> {
        let mut now = clock.now();
        while now < self.next {
            self.sleep_until(clock, self.next);
            now = clock.now();
            if now < self.next && stop() {
                return None;
            }
        }
        Some(self.wake_at(now))
    }

    fn wake_at(&mut self, now: Nanos) -> Wake {
        let missed = (now - self.next) / self.period;
        let deadline = self.next + missed * self.period;
        self.next = deadline + self.period;
        Wake {
            deadline,
            now,
            missed,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sys::clock::MockClock;
    use rand::{Rng, SeedableRng};

    #[test]
    fn on_time_ticks_hit_every_deadline() {
        let mut clock = MockClock::new(0);
        let mut t = Ticker::new(0, 1000);
        for k in 1..=100 {
            let w = t.wait(&mut clock);
            assert_eq!(w.deadline, k * 1000);
            assert_eq!((w.missed, w.jitter()), (0, 0));
        }
    }

    #[test]
    fn a_long_tick_skips_and_counts_missed_periods() {
        let mut clock = MockClock::new(0);
        let probe = clock.clone();
        let mut t = Ticker::new(0, 1000);
        assert_eq!(t.wait(&mut clock).deadline, 1000);
        probe.advance(3500); // the tick took 3.5 periods
        let w = t.wait(&mut clock);
        assert_eq!((w.deadline, w.now, w.missed), (4000, 4500, 2)); // 2000 and 3000 skipped
        // Next tick is the next deadline, not a burst of catch-up ticks.
        let w = t.wait(&mut clock);
        assert_eq!((w.deadline, w.missed), (5000, 0));
    }

    /// Seeded random compute times and wake-up delays: deadlines stay on
    /// the k·period grid, are strictly increasing, and every period is
    /// either ticked or counted as missed.
    #[test]
    fn deadlines_stay_on_the_grid_under_random_delays() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let period = 1_000_000;
        let mut clock = MockClock::new(123);
        let probe = clock.clone();
        let mut t = Ticker::new(123, period);
        let (mut last, mut ticks, mut missed) = (0, 0u64, 0u64);
        for _ in 0..50_000 {
            probe.set_wake_delay(if rng.random_bool(0.01) {
                rng.random_range(0..3 * period)
            } else {
                rng.random_range(0..20_000)
            });
            let w = t.wait(&mut clock);
            assert_eq!((w.deadline - 123) % period, 0);
            assert!(w.deadline > last);
            assert!(w.now >= w.deadline && w.jitter() < period);
            last = w.deadline;
            ticks += 1;
            missed += w.missed;
            probe.advance(rng.random_range(0..period / 2));
        }
        assert_eq!(ticks + missed, (last - 123) / period);
    }

    /// Records what the ticker asks of it; time advances only when told.
    struct Recording {
        now: Nanos,
        calls: Vec<(&'static str, Nanos)>,
    }

    impl Clock for Recording {
        fn now(&self) -> Nanos {
            self.now
        }
        fn sleep_until(&mut self, deadline: Nanos) {
            self.calls.push(("sleep", deadline));
            self.now = self.now.max(deadline);
        }
        fn spin_until(&mut self, deadline: Nanos) {
            self.calls.push(("spin", deadline));
            self.now = self.now.max(deadline);
        }
    }

    #[test]
    fn spinning_sleeps_to_the_spin_window_then_busy_waits_the_rest() {
        let mut clock = Recording {
            now: 0,
            calls: Vec::new(),
        };
        let mut t = Ticker::new(0, 1000).with_spin(100);
        let w = t.wait(&mut clock);
        assert_eq!(w.deadline, 1000);
        assert_eq!(clock.calls, [("sleep", 900), ("spin", 1000)]);
        // A tick that ran into the spin window only spins.
        clock.calls.clear();
        clock.now = 1950;
        let w = t.wait(&mut clock);
        assert_eq!((w.deadline, w.now), (2000, 2000));
        assert_eq!(clock.calls, [("spin", 2000)]);
        // Without spin: one plain sleep.
        let mut plain = Ticker::new(0, 1000);
        clock.calls.clear();
        clock.now = 0;
        plain.wait(&mut clock);
        assert_eq!(clock.calls, [("sleep", 1000)]);
        // A spin window longer than the period never sleeps.
        let mut always = Ticker::new(0, 1000).with_spin(5000);
        clock.calls.clear();
        clock.now = 10;
        always.wait(&mut clock);
        assert_eq!(clock.calls, [("spin", 1000)]);
    }
}
