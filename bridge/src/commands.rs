//! remote clients → daemon: the command queryable (`P/cmd/*/*`), the rate
//! limit, and the policy for clients that vanish.
//!
//! Zenoh calls the queryable and the liveliness subscriber on its own
//! threads. The queryable's callback applies the per-identity rate limit
//! first (`RateLimited` at once: a burst beyond it never occupies the
//! queue), then hands the query to this module's thread through a bounded
//! channel (a full channel answers `DaemonBusy` at once: more commands
//! within their identities' limits than the queue holds). This thread owns
//! its own `gaitd_client::Client` and handles one command at a time: check
//! ([`crate::checks`]), forward, reply.

use crate::answered::Answered;
use crate::checks::{self, Check};
use crate::config::{Config, Role};
use crate::forward::local_options;
use crate::presence::{self, Presence};
use crate::rate::RateLimiter;
use gaitd_client::remote::protocol::{self as proto, Refusal, RefusalCode};
use gaitd_client::{Answer, Client, Error};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, mpsc};
use std::time::{Duration, Instant};
use zenoh::Wait;
use zenoh::bytes::Encoding;
use zenoh::query::Query;
use zenoh::sample::SampleKind;

/// Work waiting for the command thread.
enum Work {
    Query(Query),
    Token {
        key: String,
        present: bool,
    },
    /// A client's beat (a put on its own `P/clients/<identity>/<session>`).
    Beat {
        key: String,
    },
}

/// Commands waiting at most (beyond, the bridge answers `DaemonBusy`).
const QUEUE: usize = 64;

fn refuse(q: &Query, r: &Refusal) {
    let res = q
        .reply_err(r.to_bytes())
        .encoding(Encoding::from(proto::encoding_of(proto::REFUSAL_SCHEMA)))
        .wait();
    if let Err(e) = res {
        tracing::debug!("refusal reply: {e}");
    }
}

fn answer(q: &Query, a: &Answer) {
    let res = q
        .reply(q.key_expr().clone(), a.to_bytes().to_vec())
        .encoding(Encoding::from(proto::encoding_of(proto::ANSWER_SCHEMA)))
        .wait();
    if let Err(e) = res {
        tracing::debug!("answer reply: {e}");
    }
}

/// The command side's Zenoh declarations and the channel their callbacks
/// feed (dropping it undeclares them).
pub struct Declared {
    _queryable: zenoh::query::Queryable<()>,
    _clients: zenoh::pubsub::Subscriber<()>,
    _beats: zenoh::pubsub::Subscriber<()>,
    rx: mpsc::Receiver<Work>,
}

/// The command side: declared on `session`, runs until `stop`.
pub struct Commands<'a> {
    cfg: &'a Config,
    daemon: Option<Client>,
    presence: Presence,
    answered: Answered,
    timeout: Duration,
    /// How long an operator may be gone before the policy applies.
    grace: Duration,
    /// A session silent this long is gone.
    beat_timeout: Duration,
}

impl<'a> Commands<'a> {
    /// A command side for `cfg`.
    pub fn new(cfg: &'a Config) -> Self {
        Self {
            cfg,
            daemon: None,
            presence: Presence::default(),
            answered: Answered::default(),
            timeout: Duration::from_millis(cfg.bridge.command_timeout_ms),
            grace: Duration::from_millis(cfg.bridge.client_lost_grace_ms),
            beat_timeout: Duration::from_millis(cfg.bridge.client_beat_timeout_ms),
        }
    }

    /// Declares the queryable and the client-token subscriber on
    /// `session`. Called before the bridge's liveliness token, so that a
    /// client that sees the bridge finds its queryable too.
    pub fn declare(session: &zenoh::Session, cfg: &Config) -> anyhow::Result<Declared> {
        let prefix = cfg.zenoh.key_prefix.clone();
        let (tx, rx) = mpsc::sync_channel::<Work>(QUEUE);
        let qtx = tx.clone();
        let r = &cfg.rate_limit;
        let limiter = Arc::new(Mutex::new(RateLimiter::new(r.commands_per_second, r.burst)));
        let limit_text = format!(
            "sends more than {} commands/s (burst {})",
            r.commands_per_second, r.burst
        );
        let qprefix = prefix.clone();
        let queryable = session
            .declare_queryable(format!("{prefix}/cmd/*/*"))
            .callback(move |q| {
                let key = q.key_expr().as_str();
                tracing::debug!(key, "command query");
                // (Access control lets an operator query its own keys only:
                // the key names the identity.)
                let identity = proto::parse_command_key(&qprefix, key).map_or("", |(i, _)| i);
                let allowed = limiter
                    .lock()
                    .map(|mut l| l.allow(identity, Instant::now()))
                    .unwrap_or(true);
                if !allowed {
                    let why = format!("identity `{identity}` {limit_text}");
                    refuse(&q, &Refusal::new(RefusalCode::RateLimited, why));
                    return;
                }
                if let Err(mpsc::TrySendError::Full(Work::Query(q))) = qtx.try_send(Work::Query(q))
                {
                    refuse(
                        &q,
                        &Refusal::new(
                            RefusalCode::DaemonBusy,
                            format!(
                                "the bridge's command queue is full ({QUEUE} commands waiting \
                                 for the daemon, within their identities' rate limits)"
                            ),
                        ),
                    );
                }
            })
            .wait()
            .map_err(|e| {
                anyhow::anyhow!(
                    "declaring the command queryable: {}",
                    gaitd_client::remote::zenoh_text(e)
                )
            })?;
        let btx = tx.clone();
        let beats = session
            .declare_subscriber(proto::client_tokens(&prefix))
            .callback(move |s| {
                // (A full queue drops a beat: the next one comes soon.)
                let _ = btx.try_send(Work::Beat {
                    key: s.key_expr().as_str().to_owned(),
                });
            })
            .wait()
            .map_err(|e| {
                anyhow::anyhow!(
                    "declaring the client-beat subscriber: {}",
                    gaitd_client::remote::zenoh_text(e)
                )
            })?;
        let clients = session
            .liveliness()
            .declare_subscriber(proto::client_tokens(&prefix))
            .history(true)
            .callback(move |s| {
                let present = s.kind() == SampleKind::Put;
                // Blocking here only delays Zenoh's delivery of tokens; a
                // vanished client must not be forgotten.
                let _ = tx.send(Work::Token {
                    key: s.key_expr().as_str().to_owned(),
                    present,
                });
            })
            .wait()
            .map_err(|e| {
                anyhow::anyhow!(
                    "declaring the client-token subscriber: {}",
                    gaitd_client::remote::zenoh_text(e)
                )
            })?;
        Ok(Declared {
            _queryable: queryable,
            _clients: clients,
            _beats: beats,
            rx,
        })
    }

    /// Handles the work of `declared` until `stop` is set.
    pub fn run(mut self, declared: Declared, stop: &AtomicBool) -> anyhow::Result<()> {
        // Just (re)started: no session known yet. Every operator has the
        // reconnect wait to come back; then one whose goal still runs (the
        // daemon's status says whose) falls under the policy.
        let back_by = Instant::now() + Duration::from_millis(self.cfg.bridge.reconnect_wait_ms);
        for id in &self.cfg.identities {
            if id.role == Role::Operator {
                self.presence.expect(&id.name, back_by);
            }
        }
        while !stop.load(Ordering::Acquire) {
            match declared.rx.recv_timeout(self.idle()) {
                Ok(Work::Query(q)) => self.handle(&q),
                Ok(Work::Token { key, present }) => self.token(&key, present),
                Ok(Work::Beat { key }) => self.beat(&key),
                Err(mpsc::RecvTimeoutError::Timeout) => {}
                Err(mpsc::RecvTimeoutError::Disconnected) => break,
            }
            self.presence
                .expire_silent(Instant::now(), self.beat_timeout);
            self.expire();
        }
        Ok(())
    }

    fn beat(&mut self, key: &str) {
        if let Some((identity, session)) =
            proto::parse_client_token(&self.cfg.zenoh.key_prefix, key)
            && self.presence.beat(identity, session, Instant::now())
        {
            tracing::info!(identity, "remote client back within the grace period");
        }
    }

    /// The connection to gaitd, opened on first use (and again after a loss).
    fn daemon(&mut self) -> Option<&mut Client> {
        if self.daemon.is_none() {
            match Client::connect(local_options(self.cfg, "gaitd-bridge-cmd")) {
                Ok(c) => self.daemon = Some(c),
                Err(e) => tracing::debug!("gaitd for commands: {e}"),
            }
        }
        self.daemon.as_mut()
    }

    fn handle(&mut self, q: &Query) {
        let t0 = Instant::now();
        self.handle_query(q);
        tracing::debug!(
            key = q.key_expr().as_str(),
            us = t0.elapsed().as_micros() as u64,
            "command handled"
        );
    }

    fn handle_query(&mut self, q: &Query) {
        let key = q.key_expr().as_str().to_owned();
        let encoding = q.encoding().map(|e| e.to_string());
        let payload = q
            .payload()
            .map(|p| p.to_bytes().into_owned())
            .unwrap_or_default();
        let checked = match checks::check(self.cfg, &key, encoding.as_deref(), &payload) {
            Check::Forward(c) => c,
            Check::Reject(mut a) => {
                tracing::info!(
                    key,
                    reason = a.reason,
                    "invalid command rejected at the bridge"
                );
                a.instance = self.daemon.as_ref().map_or(0, Client::daemon_instance);
                answer(q, &a);
                return;
            }
            Check::Refuse(r) => {
                tracing::info!(key, code = %r.code, "command refused: {}", r.message);
                refuse(q, &r);
                return;
            }
        };
        let identity = proto::parse_command_key(&self.cfg.zenoh.key_prefix, &key)
            .map_or("", |(i, _)| i)
            .to_owned();
        // A request sent again (its reply lost with a dropped link): the
        // same answer, and the daemon does not get it twice.
        if let Some(a) = self.answered.get(&identity, &checked.command) {
            tracing::info!(
                identity,
                request_id = checked.request_id,
                "request sent again: answered as before, not forwarded"
            );
            answer(q, &a);
            return;
        }
        let timeout = self.timeout;
        let Some(c) = self.daemon() else {
            refuse(
                q,
                &Refusal::new(
                    RefusalCode::NoDaemon,
                    "no gaitd is running behind the bridge",
                ),
            );
            return;
        };
        match c.command(checked.command, timeout) {
            Ok(a) => {
                let a = Answer {
                    request_id: checked.request_id,
                    ..a
                };
                self.answered.insert(&identity, &checked.command, a);
                answer(q, &a);
            }
            Err(e) => {
                let (code, msg) = match &e {
                    Error::Busy => (RefusalCode::DaemonBusy, e.to_string()),
                    Error::Timeout { .. } => (
                        RefusalCode::DaemonTimeout,
                        format!("gaitd did not answer within {timeout:?}"),
                    ),
                    _ => (
                        RefusalCode::NoDaemon,
                        format!("gaitd is not reachable: {e}"),
                    ),
                };
                if code == RefusalCode::NoDaemon {
                    self.daemon = None;
                }
                refuse(q, &Refusal::new(code, msg));
            }
        }
    }

    fn token(&mut self, key: &str, present: bool) {
        let Some((identity, session)) = proto::parse_client_token(&self.cfg.zenoh.key_prefix, key)
        else {
            return;
        };
        let identity = identity.to_owned();
        tracing::info!(identity, session, present, "remote client");
        if self
            .presence
            .update(&identity, session, present, Instant::now())
        {
            tracing::info!(identity, "remote client back within the grace period");
        }
    }

    /// Applies the client-lost policy to identities gone for the grace period.
    fn expire(&mut self) {
        for lost in self.presence.lost(Instant::now(), self.grace) {
            self.lost(&lost);
        }
    }

    /// How long the thread may wait for work before [`Self::expire`] is due.
    fn idle(&self) -> Duration {
        let poll = Duration::from_millis(200);
        self.presence.next_due(self.grace).map_or(poll, |t| {
            t.saturating_duration_since(Instant::now()).min(poll)
        })
    }

    fn lost(&mut self, lost: &str) {
        tracing::info!(
            identity = lost,
            grace_ms = self.grace.as_millis() as u64,
            "remote client lost"
        );
        if self.cfg.role(lost) != Some(Role::Operator) {
            return;
        }
        let policy = self.cfg.bridge.on_client_lost;
        let timeout = self.timeout;
        let Some(c) = self.daemon() else {
            return;
        };
        let status = c.latest_status().ok().flatten();
        let Some(cmd) = presence::on_lost(policy, lost, status.as_ref()) else {
            return;
        };
        tracing::warn!(
            identity = lost,
            ?policy,
            goal = cmd.goal_id,
            "operator vanished with its goal running"
        );
        match c.command(cmd, timeout) {
            Ok(a) => tracing::info!(verdict = ?a.verdict(), "client-lost policy applied"),
            Err(e) => tracing::warn!("client-lost policy: {e}"),
        }
    }
}
