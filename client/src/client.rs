//! The synchronous client.

use crate::connection::Connection;
use crate::error::{Error, Result};
use crate::goal::GoalSpec;
use crate::options::ConnectOptions;
use crate::remote::RemoteError;
use crate::remote::inflight::InFlight;
#[cfg(feature = "remote")]
use crate::remote::transport::RemoteConnection;
#[cfg(feature = "remote")]
use remote_side::lost;

#[cfg(feature = "remote")]
mod remote_side;
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

/// How a [`Client`] reaches the daemon.
// One per client, built once: the size difference costs nothing.
#[allow(clippy::large_enum_variant)]
#[derive(Debug)]
enum Transport {
    /// iceoryx2 shared memory, same host.
    Local(Connection),
    /// Zenoh through gaitd-bridge.
    #[cfg(feature = "remote")]
    Remote(RemoteConnection),
}

/// A connection to a running gaitd. See the crate docs for an example.
#[derive(Debug)]
pub struct Client {
    opts: ConnectOptions,
    config: Config,
    settings: IpcSettings,
    conn: Transport,
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
    /// Remote: requests that ended without an answer, and why.
    failures: VecDeque<(u64, RemoteError)>,
    /// Remote: the requests in flight, and which to send again after a
    /// dropped link.
    inflight: InFlight,
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
    ///
    /// With [`ConnectOptions::remote`], connects to gaitd-bridge instead
    /// and fails with [`Error::Remote`] saying what to check (endpoint,
    /// certificate, access control, no daemon behind the bridge).
    pub fn connect(opts: ConnectOptions) -> Result<Self> {
        if opts.remote.is_some() {
            return Self::connect_remote(opts);
        }
        let (config, settings) = opts.resolve()?;
        let deadline = Instant::now() + opts.timeout;
        let conn = Transport::Local(Connection::open(&opts, &config, &settings, deadline)?);
        let mut c = Self::with_transport(opts, config, settings, conn, random_u64() | 1);
        c.wait_fresh_status(deadline)?;
        Ok(c)
    }

    fn with_transport(
        opts: ConnectOptions,
        config: Config,
        settings: IpcSettings,
        conn: Transport,
        client_id: u64,
    ) -> Self {
        // Remote: every session of an identity shares its client id, and the
        // bridge recognises a request sent again by its id: sessions must
        // not reuse one another's (random start; local ones start at 1).
        let next_request = if opts.remote.is_some() {
            (random_u64() >> 2).max(1)
        } else {
            1
        };
        Self {
            opts,
            config,
            settings,
            conn,
            client_id,
            next_request,
            next_goal: 1,
            last_status: None,
            events: VecDeque::new(),
            answers: VecDeque::new(),
            outstanding: VecDeque::new(),
            reconnects: 0,
            bad_samples: 0,
            failures: VecDeque::new(),
            inflight: InFlight::default(),
        }
    }

    #[cfg(not(feature = "remote"))]
    fn connect_remote(_opts: ConnectOptions) -> Result<Self> {
        Err(Error::Remote(RemoteError::NotBuilt))
    }

    /// The key prefix of a remote connection: explicit, `GAITD_PREFIX`,
    /// or the default.
    #[cfg(feature = "remote")]
    fn remote_prefix(opts: &ConnectOptions) -> String {
        opts.ipc
            .service_prefix
            .clone()
            .or_else(|| std::env::var(shm_schema::ipc::ENV_PREFIX).ok())
            .filter(|p| !p.is_empty())
            .unwrap_or_else(|| crate::remote::protocol::DEFAULT_KEY_PREFIX.to_owned())
    }

    #[cfg(feature = "remote")]
    fn connect_remote(opts: ConnectOptions) -> Result<Self> {
        let Some(remote) = opts.remote.clone() else {
            return Err(Error::Invalid("not a remote connection"));
        };
        let prefix = Self::remote_prefix(&opts);
        let deadline = Instant::now() + opts.timeout;
        let conn = RemoteConnection::open(&remote, &prefix, opts.timeout, deadline)?;
        let client_id = crate::remote::protocol::client_id_for(&conn.identity);
        let settings = IpcSettings {
            service_prefix: prefix,
            root_path: String::new(),
            file_prefix: String::new(),
        };
        let mut c = Self::with_transport(
            opts,
            Config::default(),
            settings,
            Transport::Remote(conn),
            client_id,
        );
        // Goal ids are unique per client, and every session of an identity
        // shares its client id: start somewhere no earlier session did.
        c.next_goal = (random_u64() >> 33) + 1;
        c.wait_fresh_status(deadline)?;
        Ok(c)
    }

    /// The iceoryx2 configuration the connection was opened with.
    pub(crate) fn iceoryx2_config(&self) -> &Config {
        &self.config
    }

    /// A remote connection's plan paths.
    #[cfg(feature = "remote")]
    pub(crate) fn remote_plans(&self) -> Option<crate::remote::transport::RemotePlans> {
        match &self.conn {
            Transport::Remote(r) => Some(r.plans()),
            _ => None,
        }
    }

    /// Whether this client talks to gaitd through a bridge.
    pub fn is_remote(&self) -> bool {
        !matches!(self.conn, Transport::Local(_))
    }

    /// Remote: events of the daemon's current sequence that never arrived
    /// here — holes in (`instance`, `seq`) that no later event filled (a
    /// restarted bridge's cache fills what it holds), or Zenoh's count of
    /// missed samples if more; always 0 for a local client.
    pub fn missed_events(&self) -> u64 {
        match &self.conn {
            Transport::Local(_) => 0,
            #[cfg(feature = "remote")]
            Transport::Remote(r) => r.missed_events(),
        }
    }

    /// Remote: the holes in the events received, oldest first: (daemon
    /// instance, first seq, last seq) of events that never arrived; empty
    /// for a local client (iceoryx2 delivers in order).
    pub fn event_holes(&self) -> Vec<(u64, u64, u64)> {
        match &self.conn {
            Transport::Local(_) => Vec::new(),
            #[cfg(feature = "remote")]
            Transport::Remote(r) => r.event_holes(),
        }
    }

    /// This client's id (random, non-zero, kept across reconnects; remote:
    /// the bridge's id for this client's identity).
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
        match &self.conn {
            Transport::Local(_) => {
                let now = monotonic_ns();
                now.saturating_sub(s.publish_time_ns) <= self.opts.max_status_age.as_nanos() as u64
            }
            // The daemon's clock is another host's: judge by arrival.
            #[cfg(feature = "remote")]
            Transport::Remote(r) => r
                .status_age()
                .is_some_and(|a| a <= self.opts.max_status_age),
        }
    }

    /// Reads everything that arrived (status, events, our answers).
    fn pump(&mut self) -> Result<()> {
        #[cfg(feature = "remote")]
        if let Transport::Remote(_) = self.conn {
            self.pump_remote();
            return Ok(());
        }
        #[allow(irrefutable_let_patterns)] // without the `remote` feature
        let Transport::Local(conn) = &mut self.conn else {
            unreachable!("remote handled above");
        };
        let ipc = |what| {
            move |e: iceoryx2::port::ReceiveError| Error::Ipc {
                what,
                why: format!("{e:?}"),
            }
        };
        while let Some(e) = conn.events.receive().map_err(ipc("event receive"))? {
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
        while let Some(a) = conn.answers.receive().map_err(ipc("answer receive"))? {
            let a = *a.payload();
            // Answers to every client arrive here: keep ours.
            if self.outstanding.contains(&(a.client_id, a.request_id)) {
                self.answers.push_back(a);
            }
        }
        // Status last: a caller polling for the next status sees it as
        // soon as it is read, not after two more (empty) receives. One
        // receive is enough: the subscriber's buffer holds only the newest.
        if let Some(s) = conn.status.receive().map_err(ipc("status receive"))? {
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
            match &self.conn {
                Transport::Local(conn) => {
                    conn.listener
                        .timed_wait(|_| {}, block)
                        .map_err(|e| Error::Ipc {
                            what: "listener wait",
                            why: format!("{e:?}"),
                        })?;
                }
                #[cfg(feature = "remote")]
                Transport::Remote(r) => r.wait(block),
            }
        }
    }

    fn wait_fresh_status(&mut self, deadline: Instant) -> Result<Status> {
        let waited = self.opts.timeout;
        self.wait_until(deadline, "a fresh status", waited, |c| {
            Ok(c.last_status.filter(|s| c.fresh(s)))
        })
        .map_err(|e| match e {
            #[cfg(feature = "remote")]
            Error::Timeout { .. } if self.is_remote() => self.remote_silence(waited),
            Error::Timeout { .. } => Error::NoDaemon {
                prefix: self.settings.service_prefix.clone(),
                root: self.settings.root_path.clone(),
                waited,
            },
            other => other,
        })
    }

    /// Process id of the running daemon (its iceoryx2 node named `gaitd`
    /// in this namespace), if one is alive; `None` for a remote daemon.
    pub fn daemon_pid(&self) -> Option<i32> {
        if self.is_remote() {
            return None;
        }
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
        self.conn = match &self.opts.remote {
            // A new node: creating it cleans up the dead daemon's node and ports.
            None => Transport::Local(Connection::open(
                &self.opts,
                &self.config,
                &self.settings,
                deadline,
            )?),
            #[cfg(feature = "remote")]
            // The old session stays until the new one is open (it may be
            // reconnecting by itself meanwhile).
            Some(remote) => Transport::Remote(RemoteConnection::open(
                remote,
                &self.settings.service_prefix,
                self.opts.timeout,
                deadline,
            )?),
            #[cfg(not(feature = "remote"))]
            Some(_) => return Err(Error::Remote(RemoteError::NotBuilt)),
        };
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
    ///
    /// Remote: the command goes to the key of its kind (an unknown kind to
    /// `reorient`); the bridge replaces `client_id` with this identity's.
    pub fn send_command(&mut self, mut cmd: Command) -> Result<u64> {
        cmd.request_id = self.next_request;
        self.next_request += 1;
        #[cfg(feature = "remote")]
        if let Transport::Remote(r) = &self.conn {
            use crate::remote::protocol as proto;
            let name =
                shm_schema::CommandKind::try_from(cmd.kind).map_or("reorient", proto::command_name);
            r.send(
                name,
                cmd.to_bytes().to_vec(),
                proto::COMMAND_SCHEMA,
                cmd.request_id,
            )?;
            if self.outstanding.len() == 256 {
                self.outstanding.pop_front();
            }
            self.outstanding.push_back((cmd.client_id, cmd.request_id));
            self.inflight
                .sent(cmd.request_id, name, cmd, Instant::now());
            return Ok(cmd.request_id);
        }
        #[allow(irrefutable_let_patterns)] // without the `remote` feature
        let Transport::Local(conn) = &self.conn else {
            unreachable!("remote handled above");
        };
        let sample = conn.commands.loan_uninit().map_err(|e| Error::Ipc {
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
            if let Some(i) = c.failures.iter().position(|(r, _)| *r == request_id) {
                let (_, why) = c.failures.remove(i).expect("found");
                return Err(Error::Remote(c.name_failure(request_id, why)));
            }
            Ok(c.answers
                .iter()
                .position(|a| a.request_id == request_id)
                .and_then(|i| c.answers.remove(i)))
        });
        #[cfg(feature = "remote")]
        let found = match (found, &self.conn) {
            // Still waiting for the bridge to come back.
            (Err(Error::Timeout { .. }), Transport::Remote(r))
                if self.inflight.hit_by_a_drop(request_id) =>
            {
                Err(Error::Remote(lost(&r.endpoint)))
            }
            (Err(Error::Timeout { waited, .. }), _) if self.is_remote() => {
                let no = RemoteError::NoAnswer {
                    command: String::new(),
                    identity: String::new(),
                    waited,
                };
                Err(Error::Remote(self.name_failure(request_id, no)))
            }
            (other, _) => other,
        };
        self.outstanding.retain(|&(_, r)| r != request_id);
        self.inflight.done(request_id);
        found
    }

    /// Fills in the command name and identity of a [`RemoteError::NoAnswer`].
    fn name_failure(&self, request_id: u64, why: RemoteError) -> RemoteError {
        match why {
            RemoteError::NoAnswer { waited, .. } => RemoteError::NoAnswer {
                command: self
                    .inflight
                    .name(request_id)
                    .unwrap_or("command")
                    .to_owned(),
                identity: self.identity().unwrap_or_default().to_owned(),
                waited,
            },
            other => other,
        }
    }

    /// The identity of a remote client (its certificate's common name);
    /// `None` for a local one.
    pub fn identity(&self) -> Option<&str> {
        match &self.conn {
            Transport::Local(_) => None,
            #[cfg(feature = "remote")]
            Transport::Remote(r) => Some(&r.identity),
        }
    }

    /// Remote only: sends `payload` as it is to command key `name`
    /// (`reorient`, `cancel`, `hold`, `reset`, or anything) with encoding
    /// schema `schema`, and waits for the reply. For tools and tests that
    /// check what the bridge does with bad bytes.
    #[cfg(feature = "remote")]
    pub fn send_raw(
        &mut self,
        name: &str,
        payload: &[u8],
        schema: &str,
        timeout: Duration,
    ) -> Result<crate::remote::RawReply> {
        match &self.conn {
            Transport::Remote(r) => Ok(r.send_raw(name, payload, schema, timeout)?),
            Transport::Local(_) => Err(Error::Invalid("send_raw needs a remote connection")),
        }
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
