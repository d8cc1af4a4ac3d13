//! The writer thread: publishes what the loop produced (answers, events,
//! status) and wakes waiting clients.
//!
//! Why a thread: iceoryx2 0.10 allocates on every `Publisher::loan_uninit`
//! (an `Rc` per sample) and a notification is one syscall per listening
//! client; neither belongs on the real-time loop. The loop moves plain
//! `Copy` values into a pre-allocated ring ([`handoff`]) and marks the tick
//! done ([`Outbox::tick_done`]); this thread publishes them in order — a
//! tick's answers, then its events, then its status — and notifies: answers
//! and events at once, status every `status_notify_every` statuses and
//! always for the final one. `publish_time_ns` is stamped here, just before
//! the status is written into its sample and sent, so clients measure the
//! iceoryx2 hop itself. That hop is kept short by preparing it while the
//! loop computes the tick: the status's sample is loaned ahead and its
//! cache lines, and the publisher's, are touched (a send from a thread just
//! out of a millisecond's sleep took 2.2 µs on the development VM, 0.9 µs
//! prepared).
//!
//! How the writer wakes ([`WriterWake`]): by default on its own absolute
//! timer when the loop wakes (the loop's next deadline less its
//! `spin_us`; at the deadline when the two are pinned to disjoint CPUs),
//! then spinning (yielding) until the loop marks that tick
//! done — two atomic stores on the loop instead of a futex wake, which on
//! a VM cost the loop 5–20 µs per tick and most of its tail (an
//! inter-processor interrupt per wake). The spin ends `SPIN_WAIT` (100 µs) after
//! the deadline; a later tick is polled with short sleeps. With a mock
//! clock (tests) the loop unparks the writer instead.
//!
//! `main` raises the writer to SCHED_FIFO (`[rt] writer_priority`, below
//! the loop) once the loop itself runs SCHED_FIFO, so that normal threads
//! on its CPU — busy clients, builds — cannot hold back the status, the
//! answers and the planner's wake-up.
//!
//! If the ring is full (the writer starved for many periods) the loop drops
//! the message and counts it; it never waits.

pub use crate::config::WriterWake;
use crate::io::ipc::{IpcError, OutPorts, OutServices};
use crate::sys::clock::{Clock, MonotonicClock, Nanos, monotonic_now};
use crate::sys::doorbell::Doorbell;
use crate::sys::handoff::{self, Consumer, Producer};
use crate::sys::shared::Shared;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::update_connections::UpdateConnections;
use iceoryx2::prelude::*;
use iceoryx2::sample_mut_uninit::SampleMutUninit;
use shm_schema::{
    Answer, DaemonState, EVENT_ID_ANSWER, EVENT_ID_EVENT, EVENT_ID_STATUS, Event, PlantCommand,
    ServiceNames, Status,
};
use std::mem::MaybeUninit;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::thread::Thread;
use std::time::Duration;

/// Messages in the ring.
const CAPACITY: usize = 256;

/// Notification id on the plant wake-up services (shm_schema `PLANT-GUIDE.md`).
pub const PLANT_EVENT_ID: usize = 1;

/// One message from the loop to the writer.
#[derive(Debug, Clone, Copy)]
#[allow(clippy::large_enum_variant)] // stored inline on purpose: no boxing on the loop
pub enum Outbound {
    /// An answer to a command.
    Answer(Answer),
    /// An event.
    Event(Event),
    /// A status.
    Status(Status),
    /// A command for the external plant (published and notified first:
    /// the plant waits for it in lockstep).
    PlantCommand(PlantCommand),
}

/// The loop's end: wait-free, allocation-free.
#[derive(Debug)]
pub struct Outbox {
    tx: Producer<Outbound>,
    writer: Thread,
    shared: Arc<Shared>,
    wake: WriterWake,
    pushed: u64,
}

impl Outbox {
    /// Queues a message (dropped and counted if the ring is full).
    pub fn push(&mut self, m: Outbound) {
        if self.tx.push(m).is_err() {
            self.shared.outbox_dropped.fetch_add(1, Ordering::Relaxed);
        } else {
            self.pushed += 1;
        }
    }

    /// The tick of `deadline` queued everything it had; the next one is
    /// due at `next`. With [`WriterWake::Timer`] this is two atomic stores
    /// (the writer wakes on its own at `next`); with
    /// [`WriterWake::Unpark`] it also wakes the writer.
    pub fn tick_done(&self, deadline: Nanos, next: Nanos) {
        self.shared.queued.store(self.pushed, Ordering::Release);
        self.shared.next_deadline.store(next, Ordering::Release);
        self.shared.done_deadline.store(deadline, Ordering::Release);
        if self.wake == WriterWake::Unpark {
            self.writer.unpark();
        }
    }

    /// Wakes the writer now to publish what was queued (shutdown: the
    /// final status must not wait for a timer).
    pub fn flush(&self) {
        self.writer.unpark();
    }
}

/// Handle of the writer thread: `join` (or drop) publishes everything
/// still queued, then stops it.
pub type Writer = crate::sys::worker::StoppableThread;

/// How the writer thread runs.
#[derive(Debug, Clone)]
pub struct WriterSettings {
    /// Notify status listeners every this many statuses (≥ 1).
    pub status_notify_every: u64,
    /// How the writer learns that a tick is done.
    pub wake: WriterWake,
    /// The loop's period \[ns\] (bounds how long the writer waits for a tick).
    pub period: Nanos,
    /// How long before each deadline the writer wakes \[ns\]: the loop's
    /// busy-wait (`[rt] spin_us`) when they may share a CPU, so the
    /// writer's timer fires when the loop's does, not in the middle of its
    /// spin (where the interrupt would make the loop late); 0 on disjoint
    /// CPUs ([`DaemonConfig::writer_lead_ns`](crate::config::DaemonConfig::writer_lead_ns)).
    pub spin: Nanos,
    /// CPUs to pin the writer to (empty: any).
    pub cpus: Vec<u32>,
    /// Wake-ups the loop requested of other threads, delivered after every
    /// tick (so the loop itself makes no syscall for them).
    pub doorbells: Vec<Arc<Doorbell>>,
}

/// Starts the writer thread `gaitd-writer` on `services`; returns once its
/// ports exist (so `READY=1` after this means clients get data).
pub fn spawn(
    services: OutServices,
    names: ServiceNames,
    settings: WriterSettings,
    shared: Arc<Shared>,
) -> Result<(Outbox, Writer), IpcError> {
    let WriterSettings {
        status_notify_every,
        wake,
        period,
        spin,
        cpus,
        doorbells,
    } = settings;
    let (tx, rx) = handoff::channel::<Outbound>(CAPACITY);
    let stop = Arc::new(AtomicBool::new(false));
    let stop2 = stop.clone();
    let shared2 = shared.clone();
    let (ready_tx, ready_rx) = std::sync::mpsc::sync_channel::<Result<(), IpcError>>(1);
    let handle = std::thread::Builder::new()
        .name("gaitd-writer".into())
        .spawn(move || {
            if let Err(e) = crate::sys::rt::pin_current_thread(&cpus) {
                tracing::warn!(?cpus, error = %e, "cannot pin the writer thread");
            }
            if wake == WriterWake::Timer {
                crate::sys::rt::precise_timers();
            }
            let ports = match services.ports(&names) {
                Ok(p) => {
                    let _ = ready_tx.send(Ok(()));
                    p
                }
                Err(e) => {
                    let _ = ready_tx.send(Err(e));
                    return;
                }
            };
            let waiter = Waiter {
                wake,
                period,
                spin,
                shared: &shared2,
                stop: &stop2,
                last: std::cell::Cell::new(0),
            };
            run(ports, rx, status_notify_every.max(1), &waiter, &doorbells);
        })
        .map_err(|e| IpcError::Service {
            service: "writer thread".into(),
            why: e.to_string(),
        })?;
    let writer = handle.thread().clone();
    let guard = Writer::new(stop, handle);
    match ready_rx.recv() {
        Ok(Ok(())) => Ok((
            Outbox {
                tx,
                writer,
                shared,
                wake,
                pushed: 0,
            },
            guard,
        )),
        Ok(Err(e)) => Err(e),
        Err(_) => Err(IpcError::Service {
            service: "writer thread".into(),
            why: "exited during start-up".into(),
        }),
    }
}

fn send<T: std::fmt::Debug + ZeroCopySend + Copy>(
    p: &Publisher<ipc::Service, T, ()>,
    v: T,
) -> bool {
    match p.loan_uninit() {
        Ok(s) => s.write_payload(v).send().is_ok(),
        Err(_) => false,
    }
}

/// How long after the deadline the writer spins for a tick to finish
/// before it polls with sleeps \[ns\] (at most a tenth of the period):
/// above the loop's compute time (p99 ≈ 40 µs on the development VM), so
/// it only sleeps when the loop is late. Under SCHED_FIFO a spin (even
/// yielding) keeps normal threads off the writer's CPU.
const SPIN_WAIT: Nanos = 100_000;

/// The writer's sleep between polls of a late tick \[ns\].
const POLL_LATE: Nanos = 20_000;

/// A status sample loaned ahead of its tick.
type StatusLoan = SampleMutUninit<ipc::Service, MaybeUninit<Status>, ()>;

/// The writer's way of waiting for the next tick.
struct Waiter<'a> {
    wake: WriterWake,
    period: Nanos,
    spin: Nanos,
    shared: &'a Shared,
    stop: &'a AtomicBool,
    /// The deadline waited for last time.
    last: std::cell::Cell<Nanos>,
}

impl Waiter<'_> {
    /// Returns when the next tick's output is queued (or a bound passed);
    /// `warm` runs once awake, while the loop is still computing.
    fn wait(&self, warm: &mut dyn FnMut()) {
        let next = self.shared.next_deadline.load(Ordering::Acquire);
        if self.wake == WriterWake::Unpark || next == 0 {
            // Woken by the loop (or the loop has not ticked yet); the
            // timeout only bounds a lost wake-up.
            std::thread::park_timeout(Duration::from_millis(50));
            warm();
            return;
        }
        if next == self.last.get() {
            // The loop has not finished that tick in half a period (late,
            // stopped or shutting down): poll gently instead of spinning;
            // `Outbox::flush` cuts the wait short.
            std::thread::park_timeout(Duration::from_nanos(self.period / 4));
            return;
        }
        self.last.set(next);
        MonotonicClock.sleep_until(next.saturating_sub(self.spin));
        warm();
        // The loop woke for the same deadline: wait for it to finish that
        // tick (its compute time, typically µs), at most half a period.
        // Spinning is bounded by SPIN_WAIT: a SCHED_FIFO writer that spun
        // through a late tick would starve the normal threads of its CPU.
        let give_up = next + self.period / 2;
        // Counted from the deadline: with `spin_us` the writer wakes while
        // the loop still busy-waits for it.
        let stop_spinning = monotonic_now().max(next) + SPIN_WAIT.min(self.period / 10);
        let mut spins = 0u32;
        while self.shared.done_deadline.load(Ordering::Acquire) < next
            && !self.stop.load(Ordering::Acquire)
        {
            spins += 1;
            if spins < 256 {
                std::hint::spin_loop();
                continue;
            }
            let now = monotonic_now();
            if now > give_up {
                break;
            } else if now < stop_spinning {
                std::thread::yield_now();
            } else {
                std::thread::sleep(Duration::from_nanos(POLL_LATE));
            }
        }
    }
}

fn run(
    ports: OutPorts,
    mut rx: Consumer<Outbound>,
    status_notify_every: u64,
    w: &Waiter<'_>,
    doorbells: &[Arc<Doorbell>],
) {
    let (shared, stop) = (w.shared, w.stop);
    let (mut statuses, mut published) = (0u64, 0u64);
    let mut status_loan: Option<StatusLoan> = None;
    let mut last_status = Status::default();
    loop {
        // Read the stop flag before draining: whatever the loop queued
        // before setting it is published below.
        let stopping = stop.load(Ordering::Acquire);
        let (mut answers, mut events, mut wake_status) = (false, false, false);
        let mut errors = 0;
        while let Some(m) = rx.pop() {
            published += 1;
            let ok = match m {
                Outbound::PlantCommand(c) => match &ports.plant {
                    // Notified at once: a lockstep plant waits for it.
                    Some(p) => {
                        send(&p.command, c)
                            && p.commanded
                                .notify_with_custom_event_id(EventId::new(PLANT_EVENT_ID))
                                .is_ok()
                    }
                    None => false,
                },
                Outbound::Answer(a) => {
                    answers = true;
                    send(&ports.answers, a)
                }
                Outbound::Event(e) => {
                    events = true;
                    send(&ports.events, e)
                }
                Outbound::Status(mut s) => {
                    statuses += 1;
                    wake_status |= statuses.is_multiple_of(status_notify_every)
                        || s.daemon_state == DaemonState::Stopped.code();
                    match status_loan
                        .take()
                        .map_or_else(|| ports.status.loan_uninit(), Ok)
                    {
                        Ok(sample) => {
                            last_status = s;
                            s.publish_time_ns = monotonic_now();
                            sample.write_payload(s).send().is_ok()
                        }
                        Err(_) => false,
                    }
                }
            };
            errors += u64::from(!ok);
        }
        for (flag, id) in [
            (answers, EVENT_ID_ANSWER),
            (events, EVENT_ID_EVENT),
            (wake_status, EVENT_ID_STATUS),
        ] {
            if flag
                && ports
                    .notifier
                    .notify_with_custom_event_id(EventId::new(id))
                    .is_err()
            {
                errors += 1;
            }
        }
        // A publisher connects new subscribers (and hands them the event
        // history) only when it sends or is told to; events are rare, so
        // connect late joiners here instead of at the next event.
        if ports.events.update_connections().is_err() {
            errors += 1;
        }
        if errors > 0 {
            shared.ipc_errors.fetch_add(errors, Ordering::Relaxed);
        }
        shared.published.store(published, Ordering::Release);
        for d in doorbells {
            d.deliver();
        }
        if stopping {
            break;
        }
        w.wait(&mut || {
            // Off the latency path, while the loop computes: loan the next
            // status's sample (a loan allocates in iceoryx2 0.10 and walks
            // the data segment's free list), write the last status into it
            // (its cache lines become ours) and look for new subscribers.
            // After a millisecond's sleep all of that is cold; done in the
            // publish it doubled the status's latency (measured).
            if status_loan.is_none() {
                status_loan = ports.status.loan_uninit().ok();
            }
            if let Some(sample) = status_loan.as_mut() {
                sample.payload_mut().write(last_status);
            }
            if ports.status.update_connections().is_err() {
                shared.ipc_errors.fetch_add(1, Ordering::Relaxed);
            }
        });
    }
}
