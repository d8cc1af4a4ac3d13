//! The real-time loop (SPEC §6.1, §7.2), in copper-rs phases (`cu29_runtime`'s `CuTask`):
//!
//! 1. **preprocess** — record the wake-up (jitter, missed periods), drain at
//!    most `max_commands_per_tick` commands: validate, decide, answer;
//! 2. **process** — one [`Controller::tick`];
//! 3. **postprocess** — hand the tick's answers, events and status (every
//!    `status_every` ticks) to the writer thread (`outbox`; by default the
//!    writer wakes on its own timer, so this is atomic stores, no syscall),
//!    feed the systemd watchdog;
//! 4. **stats** — record the compute time.
//!
//! With a lockstep plant the ticks follow its measurements instead of the
//! clock ([`lockstep`](super::lockstep)).
//!
//! Contract: after construction nothing here allocates, frees, blocks or
//! logs (proven by `tests/loop_allocations.rs` with a counting allocator,
//! real iceoryx2 ports and the mock clock). The loop's only iceoryx2 call
//! is receiving commands, which is allocation-free in 0.10 except when the
//! set of connected clients changes (iceoryx2 then rebuilds its connection
//! list on the calling thread). Failures are counted in [`Shared`] for
//! housekeeping to report.
//!
//! Shutdown (dora `shutdown.rs` style, the order matters): stop accepting
//! commands → ask the controller for a safe hold → keep ticking until it is
//! at rest or `shutdown_timeout_ms` has passed (bounds how long a stop may
//! take) → queue `DaemonStopping` and a final status with
//! `daemon_state = Stopped` → return; the caller then joins the writer,
//! which publishes them, and drops the ports.

use crate::config::DaemonConfig;
use crate::control::controller::{
    ControlOutput, Controller, FingerOutput, GoalReport, TickContext,
};
use crate::control::convert::fill_status;
use crate::control::tick_events::TickEvents;
use crate::io::ipc::Ipc;
use crate::io::outbox::{Outbound, Outbox};
use crate::plant::PlantSample;
use crate::plant::contract::ContractWatch;
use crate::plant::ports::PlantInput;
use crate::realtime::intake::Intake;
use crate::realtime::lockstep::{Lockstep, Pass};
use crate::realtime::stats::LoopStats;
use crate::realtime::ticker::{Ticker, Wake};
use crate::sys::clock::{Clock, Nanos};
use crate::sys::sd_notify;
use crate::sys::shared::Shared;
use gait::HandState;
use iceoryx2::port::subscriber::Subscriber;
use nalgebra::Vector3;
use shm_schema::{
    Answer, Command, DaemonState, Event, EventKind, FaultCode, FingerPhase, GraspState, Phase,
    Status,
};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

/// The loop's settings, from the config.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LoopSettings {
    /// Period \[ns\].
    pub period: Nanos,
    /// Status every N ticks.
    pub status_every: u64,
    /// Commands per tick at most.
    pub max_commands_per_tick: u32,
    /// How long a shutdown may wait for the controller to come to rest \[ns\].
    pub shutdown_timeout: Nanos,
    /// Object radius R \[m\] (for contact points in the status).
    pub object_radius: f64,
    /// This run's instance id.
    pub instance: u64,
    /// Busy-wait before each tick \[ns\] (`[rt] spin_us`).
    pub spin: Nanos,
}

impl LoopSettings {
    /// Settings from a validated config.
    pub fn from_config(cfg: &DaemonConfig, instance: u64) -> Self {
        Self {
            period: cfg.period_ns(),
            status_every: cfg.daemon.status_every.into(),
            max_commands_per_tick: cfg.daemon.max_commands_per_tick,
            shutdown_timeout: u64::from(cfg.daemon.shutdown_timeout_ms) * 1_000_000,
            object_radius: cfg.model.object_radius,
            instance,
            spin: cfg.spin_ns(),
        }
    }
}

/// What a finished run did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Summary {
    /// Ticks run.
    pub ticks: u64,
    /// Missed periods.
    pub overruns: u64,
    /// Whether the controller reached rest before the final status.
    pub at_rest: bool,
    /// Lockstep: ticks held for a plan ([`Controller::awaits_plan`]).
    pub plan_waits: u64,
    /// Lockstep: the longest of those holds (wall clock) \[ns\].
    pub plan_wait_max: Nanos,
}

struct Watchdog {
    notifier: sd_notify::Notifier,
    interval: Nanos,
    next: Nanos,
}

/// The loop: controller + clock + ports + statistics.
pub struct Runtime<C: Controller, K: Clock> {
    clock: K,
    ticker: Ticker,
    controller: C,
    commands: Subscriber<Ipc, Command, ()>,
    outbox: Outbox,
    intake: Intake,
    stats: LoopStats,
    events: TickEvents,
    out: ControlOutput,
    status: Status,
    settings: LoopSettings,
    tick: u64,
    event_seq: u64,
    last_cleaned: u64,
    watchdog: Option<Watchdog>,
    shared: Arc<Shared>,
    /// An external plant's input (`[plant] kind = "shm"`).
    plant: Option<PlantInput>,
    /// Lockstep: the plant paces the loop ([`lockstep`](super::lockstep)).
    lockstep: Option<Lockstep>,
    /// Time of the last tick (`Wake::now`: in lockstep the plant's).
    last_time: Nanos,
    /// The timing contract with an external plant (counted from its first
    /// measurement).
    contract: ContractWatch,
}

impl ControlOutput {
    /// A still hand at `hand`, before the controller's first tick.
    pub fn initial(hand: HandState) -> Self {
        Self {
            hand,
            object_omega: Vector3::zeros(),
            measured: None,
            phase: Phase::Hold,
            fault: FaultCode::None,
            goal: GoalReport::default(),
            fingers: [FingerOutput::bare(FingerPhase::Grasping); gait::FINGERS],
            chains: false,
            grasp: GraspState::Unknown,
            grasp_margin: 0.0,
            load_grip: 0.0,
            load_margin: 0.0,
            plant_command: None,
        }
    }
}

impl<C: Controller, K: Clock> Runtime<C, K> {
    /// A loop whose first deadline is one period after `clock.now()`,
    /// reading commands from `commands` and publishing through `outbox`.
    pub fn new(
        commands: Subscriber<Ipc, Command, ()>,
        outbox: Outbox,
        controller: C,
        clock: K,
        cfg: &DaemonConfig,
        instance: u64,
        shared: Arc<Shared>,
    ) -> Self {
        let settings = LoopSettings::from_config(cfg, instance);
        let ticker = Ticker::new(clock.now(), settings.period).with_spin(settings.spin);
        Self {
            clock,
            ticker,
            controller,
            commands,
            outbox,
            intake: Intake::new(cfg.daemon.goal_id_memory as usize, cfg.limits),
            stats: LoopStats::new(settings.period),
            events: TickEvents::new(),
            out: ControlOutput::initial(HandState::paper_start(&cfg.hand())),
            status: Status::default(),
            settings,
            tick: 0,
            event_seq: 0,
            last_cleaned: 0,
            watchdog: None,
            shared,
            plant: None,
            lockstep: cfg.plant.lockstep().then(|| {
                Lockstep::new(
                    u64::from(cfg.plant.lockstep_timeout_ms) * 1_000_000,
                    u64::from(cfg.plant.connect_timeout_ms) * 1_000_000,
                    settings.period,
                )
            }),
            last_time: 0,
            contract: ContractWatch::new(cfg.plant.misses_in_row_limit()),
        }
    }

    /// Reads an external plant through `input` every tick (and, in
    /// lockstep, is paced by it: see [`Runtime::run`]).
    pub fn set_plant(&mut self, input: PlantInput) {
        self.out.fault = FaultCode::PlantWaiting;
        self.out.phase = Phase::SafeHold;
        self.plant = Some(input);
    }

    /// Sends `WATCHDOG=1` through `notifier` every `interval` ns.
    pub fn set_watchdog(&mut self, notifier: sd_notify::Notifier, interval: Nanos) {
        self.watchdog = Some(Watchdog {
            notifier,
            interval,
            next: self.clock.now(),
        });
    }

    /// Loop statistics so far.
    pub fn stats(&self) -> &LoopStats {
        &self.stats
    }

    /// The controller.
    pub fn controller(&self) -> &C {
        &self.controller
    }

    /// The controller, mutably (tests inject plant faults through it).
    pub fn controller_mut(&mut self) -> &mut C {
        &mut self.controller
    }

    /// Waits for the next deadline and runs one tick.
    pub fn run_once(&mut self) -> Wake {
        let w = self.ticker.wait(&mut self.clock);
        self.step(w);
        w
    }

    /// Runs until `stop` is set, then shuts down (see module docs).
    pub fn run(&mut self, stop: &AtomicBool) -> Summary {
        // Deadlines start now, not at construction (set-up in between must
        // not count as missed periods).
        self.ticker =
            Ticker::new(self.clock.now(), self.settings.period).with_spin(self.settings.spin);
        self.events.push(Event::new(EventKind::DaemonStarted));
        if self.lockstep.is_some() && self.plant.is_some() {
            self.run_lockstep(stop);
            return self.shutdown();
        }
        while !stop.load(Ordering::Acquire) {
            let stopping = || stop.load(Ordering::Acquire);
            match self.ticker.wait_or_stop(&mut self.clock, stopping) {
                Some(w) => self.step(w),
                None => break,
            }
        }
        self.shutdown()
    }

    /// Safe hold, final status (see module docs). In lockstep the plant
    /// keeps pacing the ticks and its time stamps the last events and
    /// status (one clock per run); a plant that is gone leaves the hand
    /// where it is.
    pub fn shutdown(&mut self) -> Summary {
        self.intake.begin_shutdown();
        let lockstep = self.lockstep.is_some() && self.plant.is_some();
        let now = if lockstep {
            self.last_time
        } else {
            self.clock.now()
        };
        let mut ctx = TickContext {
            now,
            tick: self.tick,
            events: &mut self.events,
        };
        self.controller.begin_safe_hold(&mut ctx);
        let give_up = self.clock.now() + self.settings.shutdown_timeout;
        while !self.controller.at_rest() && self.clock.now() < give_up {
            if lockstep {
                self.lockstep_once();
            } else {
                self.run_once();
            }
        }
        let at_rest = self.controller.at_rest();
        let now = if lockstep {
            self.last_time
        } else {
            self.clock.now()
        };
        self.events.push(Event::new(EventKind::DaemonStopping));
        self.publish_events(now);
        self.publish_status(now, DaemonState::Stopped);
        self.outbox.flush();
        Summary {
            ticks: self.tick,
            overruns: self.stats.overruns(),
            at_rest,
            plan_waits: self.stats.plan_waits(),
            plan_wait_max: self.stats.plan_wait_max(),
        }
    }

    /// The lockstep loop ([`lockstep`](super::lockstep)): passes of
    /// [`Runtime::lockstep_once`] until `stop` is set.
    fn run_lockstep(&mut self, stop: &AtomicBool) {
        let now = self.clock.now();
        if let Some(l) = self.lockstep.as_mut() {
            l.start(now);
        }
        while !stop.load(Ordering::Acquire) {
            self.lockstep_once();
        }
    }

    /// One pass of the lockstep loop ([`lockstep`](super::lockstep)):
    /// waits at most a period for the plant, then runs a tick on a new
    /// measurement (or on the timeout, once, to fault), or publishes a
    /// heartbeat. While the controller awaits a plan
    /// ([`Controller::awaits_plan`]) the new measurement is held and the
    /// loop beats instead, for at most [`PLAN_WAIT`](super::lockstep::PLAN_WAIT)
    /// (then the tick runs without the plan). Returns whether a tick ran
    /// (never without lockstep).
    pub fn lockstep_once(&mut self) -> bool {
        if self.lockstep.is_none() {
            return false;
        }
        let period = self.settings.period;
        if let Some(p) = self.plant.as_mut() {
            p.wait(std::time::Duration::from_nanos(period));
        }
        let now = self.clock.now();
        let sample = self
            .plant
            .as_mut()
            .map(|p| p.drain(now))
            .unwrap_or_default();
        let awaits_plan = self.controller.awaits_plan();
        let Some(pace) = self.lockstep.as_mut() else {
            return false;
        };
        match pace.pass(now, sample, awaits_plan) {
            Pass::Wait => false,
            Pass::Beat { answer } => {
                if answer {
                    // No plant to tick with: commands are answered at the
                    // last plant time (the controller is in its fault).
                    self.drain_commands(self.last_time);
                    self.publish_events(self.last_time);
                }
                self.heartbeat(now);
                false
            }
            Pass::Tick { sample, plan_wait } => {
                if let Some(waited) = plan_wait {
                    self.stats.record_plan_wait(waited);
                }
                // The plant's clock is the daemon's clock.
                let t = sample
                    .newest
                    .map_or(self.status.time_ns + period, |m| m.time_ns);
                self.step_with(t, &sample);
                let end = self.clock.now();
                if let Some(l) = self.lockstep.as_mut() {
                    l.ticked(end);
                }
                true
            }
            Pass::Lost => {
                let lost = PlantSample {
                    timed_out: true,
                    ..PlantSample::default()
                };
                self.step_with(self.last_time + period, &lost);
                true
            }
        }
    }

    /// A lockstep tick at plant time `now` with `sample`.
    fn step_with(&mut self, now: Nanos, sample: &PlantSample) {
        let mut sample = *sample;
        self.contract.measured(&sample);
        sample.contract_broken = self.contract.take_broken();
        self.controller.feed_plant(&sample, now);
        self.step(Wake {
            deadline: now,
            now,
            missed: 0,
        });
    }

    /// While a lockstep loop waits for its plant: the last status again
    /// (its publish time tells clients the daemon is alive).
    fn heartbeat(&mut self, now: Nanos) {
        if self.tick == 0 {
            // No plant time yet.
            self.publish_status(0, DaemonState::Running);
        } else {
            // The controller's part is the last tick's; the counters are
            // current (commands may have been answered meanwhile).
            let s = &mut self.status;
            s.commands = self.intake.received();
            s.rejected = self.intake.rejected();
            s.clients = self.shared.clients.load(Ordering::Relaxed);
            s.publish_time_ns = 0;
            self.outbox.push(Outbound::Status(self.status));
        }
        self.outbox.tick_done(now, now + self.settings.period);
        // The loop is alive: a missing plant is a fault, not a hang.
        self.feed_watchdog(now);
    }

    /// One tick for wake-up `w` (all four phases). With an external plant
    /// in real time, the measurements that arrived are read first.
    pub fn step(&mut self, w: Wake) {
        if self.lockstep.is_none()
            && let Some(p) = self.plant.as_mut()
        {
            let now = self.clock.now();
            let mut sample = p.drain(now);
            self.contract.measured(&sample);
            sample.contract_broken = self.contract.take_broken();
            self.controller.feed_plant(&sample, now);
        }
        let wall_start = self.clock.now();
        self.tick += 1;
        self.last_time = w.now;
        // 1. preprocess
        self.stats.record_wake(w.jitter(), w.missed);
        if w.missed > 0 {
            let mut e = Event::new(EventKind::Overrun);
            e.count = w.missed;
            self.events.push(e);
            self.shared.overruns.fetch_add(w.missed, Ordering::Relaxed);
        }
        let cleaned = self.shared.cleaned.load(Ordering::Acquire);
        if cleaned != self.last_cleaned {
            let mut e = Event::new(EventKind::ClientsCleaned);
            e.count = cleaned.wrapping_sub(self.last_cleaned);
            self.events.push(e);
            self.last_cleaned = cleaned;
        }
        self.drain_commands(w.now);
        // 2. process
        let mut ctx = TickContext {
            now: w.now,
            tick: self.tick,
            events: &mut self.events,
        };
        self.out.plant_command = None;
        self.controller.tick(&mut ctx, &mut self.out);
        // 3. postprocess: the plant's command first (it may be waiting).
        if let Some(c) = self.out.plant_command.take() {
            self.outbox.push(Outbound::PlantCommand(c));
        }
        self.publish_events(w.now);
        if self.tick.is_multiple_of(self.settings.status_every) {
            self.publish_status(w.now, DaemonState::Running);
        }
        self.outbox
            .tick_done(w.deadline, self.ticker.next_deadline());
        self.shared.ticks.store(self.tick, Ordering::Relaxed);
        // 4. stats (wall clock: in lockstep `w.now` is the plant's time)
        let end = self.clock.now();
        if self.plant.is_some() {
            // In real time this tick's command is late if it went out after
            // the next deadline, and every skipped period had none; in
            // lockstep the plant waits for it.
            let late = if self.lockstep.is_some() {
                0
            } else {
                w.missed + u64::from(end > w.deadline + self.settings.period)
            };
            self.contract.ticked(late);
        }
        // (Wall clock too: the watchdog's deadlines are, whatever the plant's time.)
        self.feed_watchdog(end);
        let start = if self.lockstep.is_some() {
            wall_start
        } else {
            w.now
        };
        self.stats
            .record_compute(end.saturating_sub(start), self.tick);
    }

    fn drain_commands(&mut self, now: Nanos) {
        for _ in 0..self.settings.max_commands_per_tick {
            let cmd = match self.commands.receive() {
                Ok(Some(sample)) => *sample.payload(),
                Ok(None) => break,
                Err(_) => {
                    self.shared.ipc_errors.fetch_add(1, Ordering::Relaxed);
                    break;
                }
            };
            let mut ctx = TickContext {
                now,
                tick: self.tick,
                events: &mut self.events,
            };
            let verdict = self.intake.handle(&cmd, &mut self.controller, &mut ctx);
            let answer = Answer::new(&cmd, verdict, self.tick, self.settings.instance);
            self.outbox.push(Outbound::Answer(answer));
        }
    }

    fn publish_events(&mut self, now: Nanos) {
        let n = self.events.as_slice().len();
        for i in 0..n {
            self.event_seq += 1;
            let mut e = self.events.as_slice()[i];
            e.seq = self.event_seq;
            e.tick = self.tick;
            e.time_ns = now;
            e.instance = self.settings.instance;
            self.outbox.push(Outbound::Event(e));
        }
        self.events.clear();
        self.shared
            .events_dropped
            .store(self.events.dropped(), Ordering::Relaxed);
    }

    fn publish_status(&mut self, now: Nanos, state: DaemonState) {
        let s = &mut self.status;
        fill_status(&self.out, self.settings.object_radius, s);
        s.tick = self.tick;
        s.time_ns = now;
        s.instance = self.settings.instance;
        s.daemon_state = state.code();
        s.timing = self.stats.timing();
        self.contract.fill(&mut s.timing);
        s.commands = self.intake.received();
        s.rejected = self.intake.rejected();
        s.clients = self.shared.clients.load(Ordering::Relaxed);
        // Stamped by the writer just before it publishes.
        s.publish_time_ns = 0;
        self.outbox.push(Outbound::Status(self.status));
    }

    fn feed_watchdog(&mut self, now: Nanos) {
        if let Some(w) = &mut self.watchdog
            && now >= w.next
        {
            w.next = now + w.interval;
            if w.notifier.watchdog().is_err() {
                self.shared.ipc_errors.fetch_add(1, Ordering::Relaxed);
            }
        }
    }
}
