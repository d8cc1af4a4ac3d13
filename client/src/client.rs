//! The synchronous client.

use crate::connection::Connection;
use crate::error::{Error, Result};
use crate::goal::GoalSpec;
use crate::options::ConnectOptions;
use iceoryx2::config::Config;
use shm_schema::ipc::IpcSettings;
use shm_schema::{Answer, Command, Event, EventKind, GoalState, ReasonCode, Status, Verdict};
use std::collections::VecDeque;
use std::time::{Duration, Instant};

/// Events kept for [`Client::events`] when nobody reads them.
const EVENT_BACKLOG: usize = 4096;

/// Longest single block on the listener; bounds the effect of a lost
/// wake-up (a check runs at least this often while waiting).
const MAX_BLOCK: Duration = Duration::from_millis(100);

/// How a goal ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Outcome {
    /// The goal.
    pub goal_id: u64,
    /// Terminal state (Succeeded, Aborted, Canceled, Preempted, Rejected).
    pub state: GoalState,
    /// Why.
    pub reason: ReasonCode,
}

/// A goal sent to the daemon and its immediate answer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct GoalTicket {
    /// The goal id this client gave it.
    pub goal_id: u64,
    /// Accepted, or rejected with a reason.
    pub verdict: Verdict,
    /// The daemon tick that handled the goal (its status ticks count on
    /// from there).
    pub tick: u64,
}

/// A connection to a running gaitd. See the crate docs for an example.
#[derive(Debug)]
pub struct Client {
    opts: ConnectOptions,
    config: Config,
    settings: IpcSettings,
    conn: Connection,
    client_id: u64,
    next_request: u64,
    next_goal: u64,
    last_status: Option<Status>,
    events: VecDeque<Event>,
    answers: VecDeque<Answer>,
    /// (client_id, request_id) of requests still waiting for an answer.
    outstanding: VecDeque<(u64, u64)>,
    reconnects: u64,
    bad_samples: u64,
}

fn random_u64() -> u64 {
    let mut v = 0u64;
    // SAFETY: writes at most 8 bytes into v.
    let n = unsafe { libc::getrandom((&raw mut v).cast(), 8, 0) };
    if n != 8 {
        v = monotonic_ns() ^ (u64::from(std::process::id()) << 40);
    }
    v
}

/// CLOCK_MONOTONIC \[ns\] (the clock of the status time stamps).
pub fn monotonic_ns() -> u64 {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: valid out pointer.
    unsafe { libc::clock_gettime(libc::CLOCK_MONOTONIC, &mut ts) };
    ts.tv_sec as u64 * 1_000_000_000 + ts.tv_nsec as u64
}

impl Client {
    /// Connects to the daemon: opens its services and waits for a fresh
    /// status, within `opts.timeout`.
    ///
    /// Fails with [`Error::NoDaemon`] when nothing answers in time and with
    /// [`Error::SchemaMismatch`] when the daemon speaks another schema version.
    pub fn connect(opts: ConnectOptions) -> Result<Self> {
        let (config, settings) = opts.resolve()?;
        let deadline = Instant::now() + opts.timeout;
        let conn = Connection::open(&opts, &config, &settings, deadline)?;
        let mut c = Self {
            opts,
            config,
            settings,
            conn,
            client_id: random_u64() | 1,
            next_request: 1,
            next_goal: 1,
            last_status: None,
            events: VecDeque::new(),
            answers: VecDeque::new(),
            outstanding: VecDeque::new(),
            reconnects: 0,
            bad_samples: 0,
        };
        c.wait_fresh_status(deadline)?;
        Ok(c)
    }

    /// This client's id (random, non-zero, kept across reconnects).
    pub fn client_id(&self) -> u64 {
        self.client_id
    }

    /// The resolved IPC settings.
    pub fn settings(&self) -> &IpcSettings {
        &self.settings
    }

    /// The daemon instance id seen last (changes when the daemon restarts).
    pub fn daemon_instance(&self) -> u64 {
        self.last_status.map_or(0, |s| s.instance)
    }

    /// How many times this client reconnected.
    pub fn reconnects(&self) -> u64 {
        self.reconnects
    }

    /// Samples dropped because their codes did not decode.
    pub fn bad_samples(&self) -> u64 {
        self.bad_samples
    }

    fn fresh(&self, s: &Status) -> bool {
        let now = monotonic_ns();
        now.saturating_sub(s.publish_time_ns) <= self.opts.max_status_age.as_nanos() as u64
    }

    /// Reads everything that arrived (status, events, our answers).
    fn pump(&mut self) -> Result<()> {
        let ipc = |what| {
            move |e: iceoryx2::port::ReceiveError| Error::Ipc {
                what,
                why: format!("{e:?}"),
            }
        };
        while let Some(e) = self.conn.events.receive().map_err(ipc("event receive"))? {
            let e = *e.payload();
            if e.check().is_err() {
                self.bad_samples += 1;
                continue;
            }
            if self.events.len() == EVENT_BACKLOG {
                self.events.pop_front();
            }
            self.events.push_back(e);
        }
        while let Some(a) = self.conn.answers.receive().map_err(ipc("answer receive"))? {
            let a = *a.payload();
            // Answers to every client arrive here: keep ours.
            if self.outstanding.contains(&(a.client_id, a.request_id)) {
                self.answers.push_back(a);
            }
        }
        // Status last: a caller polling for the next status sees it as
        // soon as it is read, not after two more (empty) receives. One
        // receive is enough: the subscriber's buffer holds only the newest.
        if let Some(s) = self.conn.status.receive().map_err(ipc("status receive"))? {
            let s = *s.payload();
            match s.check() {
                Ok(()) => self.last_status = Some(s),
                Err(_) => self.bad_samples += 1,
            }
        }
        Ok(())
    }

    /// Blocks (on the daemon's notifications, not spinning) until `check`
    /// yields a value or `deadline` passes.
    fn wait_until<T>(
        &mut self,
        deadline: Instant,
        what: &'static str,
        waited: Duration,
        mut check: impl FnMut(&mut Self) -> Result<Option<T>>,
    ) -> Result<T> {
        loop {
            self.pump()?;
            if let Some(v) = check(self)? {
                return Ok(v);
            }
            let now = Instant::now();
            if now >= deadline {
                return Err(Error::Timeout { what, waited });
            }
            let block = (deadline - now).min(MAX_BLOCK);
            self.conn
                .listener
                .timed_wait(|_| {}, block)
                .map_err(|e| Error::Ipc {
                    what: "listener wait",
                    why: format!("{e:?}"),
                })?;
        }
    }

    fn wait_fresh_status(&mut self, deadline: Instant) -> Result<Status> {
        let waited = self.opts.timeout;
        self.wait_until(deadline, "a fresh status", waited, |c| {
            Ok(c.last_status.filter(|s| c.fresh(s)))
        })
        .map_err(|e| match e {
            Error::Timeout { .. } => Error::NoDaemon {
                prefix: self.settings.service_prefix.clone(),
                root: self.settings.root_path.clone(),
                waited,
            },
            other => other,
        })
    }

    /// Process id of the running daemon (its iceoryx2 node named `gaitd`
    /// in this namespace), if one is alive.
    pub fn daemon_pid(&self) -> Option<i32> {
        use iceoryx2::node::{NodeState, NodeView};
        use iceoryx2::prelude::{CallbackProgression, Node};
        let mut pid = None;
        let _ = Node::<crate::connection::Ipc>::list(&self.config, |state| {
            if let NodeState::Alive(v) = &state
                && let Some(d) = v.details()
                && d.name().as_str() == shm_schema::ipc::DAEMON_NODE_NAME
            {
                pid = Some(d.process_id().value());
                return CallbackProgression::Stop;
            }
            CallbackProgression::Continue
        });
        pid
    }

    /// Whether the daemon published a status recently.
    pub fn daemon_alive(&mut self) -> Result<bool> {
        self.pump()?;
        Ok(self.last_status.is_some_and(|s| self.fresh(&s)))
    }

    /// Drops the connection and connects again (e.g. after the daemon
    /// restarted), within `timeout`.
    pub fn reconnect(&mut self, timeout: Duration) -> Result<()> {
        let deadline = Instant::now() + timeout;
        // A new node: creating it cleans up the dead daemon's node and ports.
        let conn = Connection::open(&self.opts, &self.config, &self.settings, deadline)?;
        self.conn = conn;
        self.last_status = None;
        self.answers.clear();
        self.outstanding.clear();
        self.reconnects += 1;
        self.wait_fresh_status(deadline).map(|_| ())
    }

    /// Reconnects if the daemon looks gone; returns whether it did.
    pub fn ensure_connected(&mut self, timeout: Duration) -> Result<bool> {
        if self.daemon_alive()? {
            return Ok(false);
        }
        self.reconnect(timeout)?;
        Ok(true)
    }

    /// Sends a command as it is (only `request_id` is filled in) and
    /// returns its request id; does not wait. For well-formed commands use
    /// [`Client::reorient`], [`Client::cancel`], [`Client::hold`],
    /// [`Client::reset`]; this is for tools and tests that send anything.
    pub fn send_command(&mut self, mut cmd: Command) -> Result<u64> {
        cmd.request_id = self.next_request;
        self.next_request += 1;
        let sample = self.conn.commands.loan_uninit().map_err(|e| Error::Ipc {
            what: "command loan",
            why: format!("{e:?}"),
        })?;
        let delivered = sample.write_payload(cmd).send().map_err(|e| Error::Ipc {
            what: "command send",
            why: format!("{e:?}"),
        })?;
        if self.outstanding.len() == 256 {
            self.outstanding.pop_front();
        }
        self.outstanding.push_back((cmd.client_id, cmd.request_id));
        if delivered == 0 {
            // No daemon subscriber, or its queue for us is full.
            return Err(if self.daemon_alive()? {
                Error::Busy
            } else {
                Error::NoDaemon {
                    prefix: self.settings.service_prefix.clone(),
                    root: self.settings.root_path.clone(),
                    waited: Duration::ZERO,
                }
            });
        }
        Ok(cmd.request_id)
    }

    /// Waits for the answer to request `request_id`.
    pub fn wait_answer(&mut self, request_id: u64, timeout: Duration) -> Result<Answer> {
        let deadline = Instant::now() + timeout;
        let found = self.wait_until(deadline, "the daemon's answer", timeout, |c| {
            Ok(c.answers
                .iter()
                .position(|a| a.request_id == request_id)
                .and_then(|i| c.answers.remove(i)))
        });
        self.outstanding.retain(|&(_, r)| r != request_id);
        found
    }

    /// Sends a command and waits for its answer, reconnecting once if the
    /// daemon restarted.
    pub fn command(&mut self, cmd: Command, timeout: Duration) -> Result<Answer> {
        let start = Instant::now();
        self.ensure_connected(timeout)?;
        let req = match self.send_command(cmd) {
            Err(Error::NoDaemon { .. }) => {
                self.reconnect(timeout.saturating_sub(start.elapsed()))?;
                self.send_command(cmd)?
            }
            other => other?,
        };
        // Keep at most a small backlog of unclaimed answers.
        while self.answers.len() > 64 {
            self.answers.pop_front();
        }
        self.wait_answer(req, timeout.saturating_sub(start.elapsed()))
    }

    /// Sends a reorientation goal (a new goal id) and waits for its answer.
    pub fn reorient(&mut self, goal: &GoalSpec, timeout: Duration) -> Result<GoalTicket> {
        let goal_id = self.next_goal;
        self.next_goal += 1;
        let a = self.command(goal.to_command(self.client_id, goal_id), timeout)?;
        Ok(GoalTicket {
            goal_id,
            verdict: a.verdict()?,
            tick: a.tick,
        })
    }

    /// Cancels `goal_id` (None: whichever goal is active).
    pub fn cancel(&mut self, goal_id: Option<u64>, timeout: Duration) -> Result<Verdict> {
        let cmd = Command::cancel(self.client_id, goal_id.unwrap_or(0));
        Ok(self.command(cmd, timeout)?.verdict()?)
    }

    /// Stops any motion and holds the grasp.
    pub fn hold(&mut self, timeout: Duration) -> Result<Verdict> {
        Ok(self
            .command(Command::hold(self.client_id), timeout)?
            .verdict()?)
    }

    /// Clears a fault.
    pub fn reset(&mut self, timeout: Duration) -> Result<Verdict> {
        Ok(self
            .command(Command::reset(self.client_id), timeout)?
            .verdict()?)
    }

    /// Waits until goal `goal_id` of this client reaches a terminal state
    /// (from its events, or the status if events were missed).
    pub fn wait_outcome(&mut self, goal_id: u64, timeout: Duration) -> Result<Outcome> {
        let deadline = Instant::now() + timeout;
        let me = self.client_id;
        self.wait_until(deadline, "the goal's outcome", timeout, |c| {
            for e in &c.events {
                if e.kind() == Ok(EventKind::GoalTransition)
                    && (e.client_id, e.goal_id) == (me, goal_id)
                    && e.state()?.is_terminal()
                {
                    return Ok(Some(Outcome {
                        goal_id,
                        state: e.state()?,
                        reason: e.reason()?,
                    }));
                }
            }
            if let Some(s) = c.last_status
                && (s.goal.client_id, s.goal.goal_id) == (me, goal_id)
                && s.goal_state()?.is_terminal()
            {
                return Ok(Some(Outcome {
                    goal_id,
                    state: s.goal_state()?,
                    reason: s.goal_reason()?,
                }));
            }
            Ok(None)
        })
    }

    /// The newest status received so far, without waiting.
    pub fn latest_status(&mut self) -> Result<Option<Status>> {
        self.pump()?;
        Ok(self.last_status)
    }

    /// Waits for a status newer than the one seen last: a later tick, or
    /// the same one published again (a lockstep daemon waiting for its
    /// plant repeats its last status as a heartbeat).
    pub fn wait_status(&mut self, timeout: Duration) -> Result<Status> {
        let deadline = Instant::now() + timeout;
        self.pump()?;
        let key = |s: &Status| (s.instance, s.tick, s.publish_time_ns);
        let seen = self.last_status.as_ref().map(key);
        self.wait_until(deadline, "a new status", timeout, |c| {
            Ok(c.last_status.filter(|s| Some(key(s)) != seen))
        })
    }

    /// Takes every event received so far (oldest first), without waiting.
    pub fn events(&mut self) -> Result<impl Iterator<Item = Event> + '_> {
        self.pump()?;
        Ok(self.events.drain(..))
    }

    /// Waits for the next event.
    pub fn next_event(&mut self, timeout: Duration) -> Result<Option<Event>> {
        let deadline = Instant::now() + timeout;
        match self.wait_until(deadline, "an event", timeout, |c| Ok(c.events.pop_front())) {
            Ok(e) => Ok(Some(e)),
            Err(Error::Timeout { .. }) => Ok(None),
            Err(e) => Err(e),
        }
    }
}
