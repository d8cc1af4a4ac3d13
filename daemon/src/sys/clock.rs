//! Injected time (as copper-rs's `cu29_clock`): the loop reads time
//! and sleeps only through [`Clock`], so tests drive it with a
//! [`MockClock`] that advances exactly, with scripted wake-up delays.

use std::cell::Cell;
use std::rc::Rc;

/// Nanoseconds on CLOCK_MONOTONIC (or the mock clock's time line).
pub type Nanos = u64;

/// A monotonic clock the loop can sleep on until an absolute deadline.
pub trait Clock {
    /// The current time.
    fn now(&self) -> Nanos;
    /// Sleeps until `deadline` (absolute); returns at once if it has passed.
    /// May return early on a signal; the caller re-checks the time.
    fn sleep_until(&mut self, deadline: Nanos);
    /// Busy-waits until `deadline` (the last stretch before a tick: no
    /// wake-up latency, the CPU never idles).
    fn spin_until(&mut self, deadline: Nanos) {
        while self.now() < deadline {
            core::hint::spin_loop();
        }
    }
}

/// CLOCK_MONOTONIC; sleeps with `clock_nanosleep(TIMER_ABSTIME)` so a late
/// wake-up never shifts the following deadlines (SPEC §7.2).
#[derive(Debug, Default, Clone, Copy)]
pub struct MonotonicClock;

/// CLOCK_MONOTONIC now \[ns\] (also used off the loop, e.g. for latency stamps).
pub fn monotonic_now() -> Nanos {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: valid pointer to a timespec; CLOCK_MONOTONIC always exists on Linux.
    unsafe { libc::clock_gettime(libc::CLOCK_MONOTONIC, &mut ts) };
    ts.tv_sec as u64 * 1_000_000_000 + ts.tv_nsec as u64
}

impl Clock for MonotonicClock {
    fn now(&self) -> Nanos {
        monotonic_now()
    }

    fn sleep_until(&mut self, deadline: Nanos) {
        let ts = libc::timespec {
            tv_sec: (deadline / 1_000_000_000) as libc::time_t,
            tv_nsec: (deadline % 1_000_000_000) as libc::c_long,
        };
        // SAFETY: valid timespec; a null remainder is allowed with TIMER_ABSTIME.
        // EINTR (a signal) returns early: the loop then checks its stop flag.
        unsafe {
            libc::clock_nanosleep(
                libc::CLOCK_MONOTONIC,
                libc::TIMER_ABSTIME,
                &ts,
                std::ptr::null_mut(),
            )
        };
    }
}

/// A clock for tests: time only moves when the loop sleeps (to exactly the
/// deadline plus a scripted delay) or when the test advances it.
#[derive(Debug, Clone, Default)]
pub struct MockClock {
    now: Rc<Cell<Nanos>>,
    delay: Rc<Cell<Nanos>>,
}

impl MockClock {
    /// A mock clock at time `start`.
    pub fn new(start: Nanos) -> Self {
        Self {
            now: Rc::new(Cell::new(start)),
            delay: Rc::new(Cell::new(0)),
        }
    }

    /// Moves time forward by `dt` (e.g. to model a tick's compute time).
    pub fn advance(&self, dt: Nanos) {
        self.now.set(self.now.get() + dt);
    }

    /// The next wake-ups happen `delay` after their deadline (late wake-up).
    pub fn set_wake_delay(&self, delay: Nanos) {
        self.delay.set(delay);
    }
}

impl Clock for MockClock {
    fn now(&self) -> Nanos {
        self.now.get()
    }

    fn sleep_until(&mut self, deadline: Nanos) {
        if deadline > self.now.get() {
            self.now.set(deadline + self.delay.get());
        } else {
            self.now.set(self.now.get() + self.delay.get());
        }
    }

    /// Time does not pass by itself: spinning jumps to the deadline.
    fn spin_until(&mut self, deadline: Nanos) {
        self.now.set(self.now.get().max(deadline));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mock_clock_jumps_to_the_deadline() {
        let mut c = MockClock::new(100);
        let probe = c.clone();
        c.sleep_until(1000);
        assert_eq!(probe.now(), 1000);
        probe.set_wake_delay(7);
        c.sleep_until(2000);
        assert_eq!(c.now(), 2007);
        c.sleep_until(10); // in the past: no jump back
        assert_eq!(c.now(), 2014);
    }

    #[test]
    fn monotonic_clock_sleeps_until_the_deadline() {
        let mut c = MonotonicClock;
        let t0 = c.now();
        c.sleep_until(t0 + 2_000_000);
        assert!(c.now() >= t0 + 2_000_000);
    }
}
