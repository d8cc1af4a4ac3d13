//! The loop thread's receiving end of an external plant: it takes every
//! measurement queued since the last tick (keeping the newest) and, in
//! lockstep, waits for the plant's wake-up with a bounded timeout.
//!
//! Both run on the loop thread: an iceoryx2 `receive` and a listener wait
//! do not allocate in 0.10 once connected (the allocation test covers
//! them); publishing does, so commands go out through the writer thread.

use super::PlantSample;
use crate::io::ipc::PlantInPorts;
use crate::sys::clock::Nanos;
use std::time::Duration;

/// The loop's plant input.
#[derive(Debug)]
pub struct PlantInput {
    ports: PlantInPorts,
    /// Receive errors so far (reported by housekeeping as IPC errors).
    errors: u64,
}

impl PlantInput {
    /// Over the loop's plant ports.
    pub fn new(ports: PlantInPorts) -> Self {
        Self { ports, errors: 0 }
    }

    /// Every measurement queued since the last call; the newest is kept.
    /// `now` (wall clock) stamps its arrival.
    pub fn drain(&mut self, now: Nanos) -> PlantSample {
        let mut s = PlantSample::default();
        loop {
            match self.ports.measurements.receive() {
                Ok(Some(sample)) => {
                    s.newest = Some(*sample.payload());
                    s.received += 1;
                    s.received_at = now;
                }
                Ok(None) => break,
                Err(_) => {
                    self.errors += 1;
                    break;
                }
            }
        }
        s
    }

    /// Waits until the plant notifies a measurement or `timeout` passes;
    /// returns whether it notified. The notifications are consumed.
    pub fn wait(&mut self, timeout: Duration) -> bool {
        match self.ports.measured.timed_wait(|_| {}, timeout) {
            Ok(n) => n > 0,
            Err(_) => {
                self.errors += 1;
                // Never spin on a broken listener.
                std::thread::sleep(timeout);
                false
            }
        }
    }

    /// Receive and wait errors so far.
    pub fn errors(&self) -> u64 {
        self.errors
    }
}
