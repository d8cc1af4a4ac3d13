//! The remote transport: a Zenoh session to `gaitd-bridge` in place of the
//! iceoryx2 ports (same [`Client`](crate::Client) API).
//!
//! Zenoh delivers samples and replies on its own threads; their callbacks
//! only decode, check and store into an [`Inbox`] (bounded: the newest
//! status, a backlog of events, the replies of outstanding commands) and
//! wake the client's thread, which waits on a condition variable instead of
//! the daemon's iceoryx2 notifications.
//!
//! Reconnection is Zenoh's: a client-mode session whose router (the
//! bridge) goes away retries the endpoint and re-declares its subscribers
//! and its liveliness token when the bridge is back.

use super::RemoteError;

/// What the transport's calls return: a remote failure, never a local one.
type Result<T> = std::result::Result<T, RemoteError>;
use super::protocol::{self as proto, Refusal};
use super::tls::{self, Endpoint};
use crate::remote_options::RemoteOptions;
use shm_schema::{Answer, Event, PlanPath, Status};
use std::collections::VecDeque;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Condvar, Mutex, MutexGuard};
use std::time::{Duration, Instant};
use zenoh::Wait;
use zenoh::bytes::{Encoding, ZBytes};
use zenoh::query::{ConsolidationMode, QueryTarget, Reply};
use zenoh::sample::{Sample, SampleKind};

/// Events kept when nobody reads them (as the local client).
const EVENT_BACKLOG: usize = 4096;
/// Replies kept for commands nobody waits for any more.
const REPLY_BACKLOG: usize = 256;
/// Events asked from the bridge's cache by a late joiner.
const HISTORY: usize = 256;
/// How long after subscribing the history is judged (see
/// `RemoteConnection::recheck_at`).
const HISTORY_RECHECK: Duration = Duration::from_secs(1);

/// What a command query came back with.
#[derive(Debug, Clone)]
pub(crate) enum ReplyOutcome {
    /// The daemon's answer (or the bridge's, `tick` 0, for invalid bytes).
    Answer(Answer),
    /// The bridge refused it.
    Refused(Refusal),
    /// A reply that does not decode.
    Bad(String),
    /// The query ended without a reply.
    NoReply,
}

#[derive(Debug, Default)]
struct InboxState {
    generation: u64,
    status: Option<Status>,
    status_new: bool,
    status_at: Option<Instant>,
    events: VecDeque<Event>,
    /// Which events of the daemon's sequence arrived: each is delivered
    /// once (a bridge's history repeats events), holes are counted.
    continuity: super::continuity::Continuity,
    /// The bridge returned since the events were last subscribed: the
    /// next drain subscribes again, which queries its cache.
    resubscribe: bool,
    replies: VecDeque<(u64, ReplyOutcome)>,
    bad_samples: u64,
    missed_events: u64,
    bridge: bool,
    /// The bridge's token was seen once (later appearances are returns).
    bridge_seen: bool,
    daemon: bool,
    bridge_returns: u64,
    /// The link to the bridge is up (Zenoh's transport events).
    linked: bool,
    /// Times it went down.
    link_drops: u64,
    /// The newest valid plan path the bridge forwarded.
    plan: Option<Box<PlanPath>>,
    /// Plan paths that did not decode or failed their check.
    plans_refused: u64,
}

/// Shared between Zenoh's callbacks and the client's thread.
#[derive(Debug, Default)]
struct Inbox {
    state: Mutex<InboxState>,
    cond: Condvar,
}

impl Inbox {
    fn lock(&self) -> MutexGuard<'_, InboxState> {
        // A panicking callback cannot leave the state half-written in a way
        // that matters (plain values): keep going.
        self.state.lock().unwrap_or_else(|p| p.into_inner())
    }

    fn update(&self, f: impl FnOnce(&mut InboxState)) {
        let mut s = self.lock();
        f(&mut s);
        s.generation += 1;
        drop(s);
        self.cond.notify_all();
    }
}

/// Bytes of a sample or reply if its encoding and size are those of `schema`.
fn payload_of<'a>(
    encoding: &Encoding,
    payload: &'a ZBytes,
    schema: &str,
    size: usize,
) -> std::result::Result<std::borrow::Cow<'a, [u8]>, String> {
    let enc = encoding.to_string();
    if enc != proto::encoding_of(schema) {
        return Err(format!("encoding `{enc}`, expected {schema}"));
    }
    let b = payload.to_bytes();
    if b.len() != size {
        return Err(format!("{} bytes, expected {size} for {schema}", b.len()));
    }
    Ok(b)
}

fn decode_plan(sample: &Sample) -> Option<PlanPath> {
    let b = payload_of(
        sample.encoding(),
        sample.payload(),
        proto::PLAN_SCHEMA,
        PlanPath::SIZE,
    )
    .ok()?;
    let p = PlanPath::from_bytes(b.as_ref().try_into().ok()?);
    p.checked().is_ok().then_some(p)
}

/// The plan paths a remote connection receives (the latest kept).
#[derive(Debug, Clone)]
pub(crate) struct RemotePlans(Arc<Inbox>);

impl RemotePlans {
    /// The newest valid path, and how many were refused.
    pub(crate) fn latest(&self) -> (Option<PlanPath>, u64) {
        let st = self.0.lock();
        (st.plan.as_deref().copied(), st.plans_refused)
    }
}

fn decode_status(sample: &Sample) -> Option<Status> {
    let b = payload_of(
        sample.encoding(),
        sample.payload(),
        proto::STATUS_SCHEMA,
        Status::SIZE,
    )
    .ok()?;
    let s = Status::from_bytes(b.as_ref().try_into().ok()?);
    s.check().is_ok().then_some(s)
}

fn decode_event(sample: &Sample) -> Option<Event> {
    let b = payload_of(
        sample.encoding(),
        sample.payload(),
        proto::EVENT_SCHEMA,
        Event::SIZE,
    )
    .ok()?;
    let e = Event::from_bytes(b.as_ref().try_into().ok()?);
    e.check().is_ok().then_some(e)
}

/// Decodes one reply to a command query.
pub(crate) fn decode_reply(reply: &Reply) -> ReplyOutcome {
    match reply.result() {
        Ok(sample) => {
            let b = match payload_of(
                sample.encoding(),
                sample.payload(),
                proto::ANSWER_SCHEMA,
                Answer::SIZE,
            ) {
                Ok(b) => b,
                Err(why) => return ReplyOutcome::Bad(why),
            };
            let Ok(arr) = b.as_ref().try_into() else {
                return ReplyOutcome::Bad("answer size".into());
            };
            let a = Answer::from_bytes(arr);
            match a.verdict() {
                Ok(_) => ReplyOutcome::Answer(a),
                Err(e) => ReplyOutcome::Bad(e.to_string()),
            }
        }
        Err(err) => {
            let enc = err.encoding().to_string();
            if enc != proto::encoding_of(proto::REFUSAL_SCHEMA) {
                return ReplyOutcome::Bad(format!("error reply with encoding `{enc}`"));
            }
            match Refusal::from_bytes(&err.payload().to_bytes()) {
                Some(r) => ReplyOutcome::Refused(r),
                None => ReplyOutcome::Bad("refusal does not decode".into()),
            }
        }
    }
}

/// What [`RemoteConnection::drain`] hands to the client.
#[derive(Debug, Default)]
pub(crate) struct Drained {
    pub status: Option<Status>,
    pub events: Vec<Event>,
    pub replies: Vec<(u64, ReplyOutcome)>,
    pub bad_samples: u64,
    pub bridge_returns: u64,
    /// Times the link to the bridge went down since the last drain.
    pub link_drops: u64,
}

/// A raw command query's result (see [`Client::send_raw`](crate::Client::send_raw)).
#[derive(Debug, Clone, PartialEq)]
pub enum RawReply {
    /// The daemon's answer (or the bridge's on its behalf).
    Answer(Answer),
    /// The bridge refused the bytes.
    Refused(Refusal),
    /// No reply before the query ended (access control dropped it, or no bridge).
    NoReply,
}

/// Marks a query finished when Zenoh drops its callback (after the final
/// reply or the timeout); records [`ReplyOutcome::NoReply`] if nothing came.
struct QueryEnd {
    inbox: Arc<Inbox>,
    request_id: u64,
    replied: AtomicBool,
}

impl Drop for QueryEnd {
    fn drop(&mut self) {
        if !self.replied.load(Ordering::Acquire) {
            let id = self.request_id;
            self.inbox
                .update(|s| push_reply(s, id, ReplyOutcome::NoReply));
        }
    }
}

fn push_reply(s: &mut InboxState, id: u64, r: ReplyOutcome) {
    if s.replies.len() == REPLY_BACKLOG {
        s.replies.pop_front();
    }
    s.replies.push_back((id, r));
}

/// The advanced subscriber of `P/events` and its miss listener.
struct EventSubscription {
    _events: zenoh_ext::AdvancedSubscriber<()>,
    _misses: zenoh_ext::SampleMissListener<()>,
}

impl EventSubscription {
    /// Subscribes, with the bridge's history (PROTOCOL.md, "Events").
    fn declare(session: &zenoh::Session, prefix: &str, inbox: &Arc<Inbox>) -> Result<Self> {
        use zenoh_ext::{AdvancedSubscriberBuilderExt, HistoryConfig, RecoveryConfig};
        let ib = inbox.clone();
        // History without late-publisher detection: with it, zenoh-ext
        // 1.10.2 queries the bridge's cache a second time and, should a
        // live event come between the end of the first query and the first
        // reply of the second, delivers that event first and drops the
        // whole history as older. A restarted bridge is subscribed to again
        // instead ([`RemoteConnection::drain`]), which queries its cache.
        let events = session
            .declare_subscriber(proto::events_key(prefix))
            .history(HistoryConfig::default().max_samples(HISTORY))
            .recovery(RecoveryConfig::default().heartbeat())
            .callback(move |sample| {
                let e = decode_event(&sample);
                ib.update(|st| match e {
                    Some(e) => {
                        if st.continuity.accept(e.instance, e.seq) {
                            if st.events.len() == EVENT_BACKLOG {
                                st.events.pop_front();
                            }
                            st.events.push_back(e);
                        }
                    }
                    None => st.bad_samples += 1,
                });
            })
            .wait()
            .map_err(zerr)?;
        let ib = inbox.clone();
        let misses = events
            .sample_miss_listener()
            .callback(move |m| ib.update(|st| st.missed_events += u64::from(m.nb())))
            .wait()
            .map_err(zerr)?;
        Ok(Self {
            _events: events,
            _misses: misses,
        })
    }
}

/// One session to the bridge and its declarations.
pub(crate) struct RemoteConnection {
    session: zenoh::Session,
    inbox: Arc<Inbox>,
    pub prefix: String,
    pub identity: String,
    pub endpoint: String,
    query_timeout: Duration,
    seen_generation: u64,
    _status: zenoh::pubsub::Subscriber<()>,
    events: EventSubscription,
    /// When the last subscription's history is judged: if by then the
    /// history owed has not come or holes remain, the events are
    /// subscribed to once more (a cache queried before the bridge had
    /// filled it, or a history query lost, answers the second one).
    recheck_at: Option<Instant>,
    _plan: zenoh_ext::AdvancedSubscriber<()>,
    _alive: zenoh::pubsub::Subscriber<()>,
    _transports: zenoh::session::TransportEventsListener<()>,
    _token: zenoh::liveliness::LivelinessToken,
    _beat: Beat,
}

/// The thread that beats for this session (PROTOCOL.md, "Lost clients"):
/// a put on the client's token key every [`proto::CLIENT_BEAT_MS`]; stopped
/// and joined on drop.
struct Beat {
    stop: Arc<AtomicBool>,
    thread: Option<std::thread::JoinHandle<()>>,
}

impl Beat {
    fn start(session: zenoh::Session, key: String) -> Result<Self> {
        let stop = Arc::new(AtomicBool::new(false));
        let flag = stop.clone();
        let thread = std::thread::Builder::new()
            .name("gaitd-remote-beat".into())
            .spawn(move || {
                let period = Duration::from_millis(proto::CLIENT_BEAT_MS);
                let mut next = Instant::now();
                while !flag.load(Ordering::Acquire) {
                    if Instant::now() >= next {
                        let _ = session.put(&key, Vec::<u8>::new()).wait();
                        next += period;
                    }
                    std::thread::sleep(Duration::from_millis(20).min(period));
                }
            })
            .map_err(|e| RemoteError::Zenoh(format!("starting the beat thread: {e}")))?;
        Ok(Self {
            stop,
            thread: Some(thread),
        })
    }
}

impl Drop for Beat {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Release);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

impl std::fmt::Debug for RemoteConnection {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RemoteConnection")
            .field("endpoint", &self.endpoint)
            .field("prefix", &self.prefix)
            .field("identity", &self.identity)
            .field("zid", &self.session.zid())
            .finish()
    }
}

/// Zenoh's message without the source location it appends (`… at /path/file.rs:N.`).
pub fn zenoh_text(e: impl std::fmt::Display) -> String {
    let t = e.to_string();
    match t.find(" at /") {
        Some(i) => t[..i].trim_end_matches(['.', ' ']).to_owned(),
        None => t,
    }
}

fn zerr(e: impl std::fmt::Display) -> RemoteError {
    RemoteError::Zenoh(zenoh_text(e))
}

/// Waits until `addr` accepts a TCP connection or `deadline` passes.
fn wait_reachable(ep: &Endpoint, deadline: Instant) -> Result<()> {
    use std::net::ToSocketAddrs;
    loop {
        let why = match ep.address.to_socket_addrs() {
            Ok(addrs) => {
                let mut last = String::from("no address");
                for a in addrs {
                    let left = deadline
                        .saturating_duration_since(Instant::now())
                        .max(Duration::from_millis(50));
                    match std::net::TcpStream::connect_timeout(&a, left) {
                        Ok(_) => return Ok(()),
                        Err(e) => last = e.to_string(),
                    }
                }
                last
            }
            Err(e) => {
                return Err(RemoteError::Unreachable {
                    endpoint: ep.locator.clone(),
                    why: format!("cannot resolve: {e}"),
                });
            }
        };
        if Instant::now() >= deadline {
            return Err(RemoteError::Unreachable {
                endpoint: ep.locator.clone(),
                why,
            });
        }
        std::thread::sleep(Duration::from_millis(100));
    }
}

impl RemoteConnection {
    /// Opens a session to the bridge and declares the subscriptions and
    /// this client's liveliness token, within `deadline` (waits for the
    /// bridge to come up until then). Does not wait for a status.
    pub fn open(
        opts: &RemoteOptions,
        prefix: &str,
        timeout: Duration,
        deadline: Instant,
    ) -> Result<Self> {
        let ep = tls::parse_endpoint(&opts.endpoint)?;
        let cn = tls::check_files(&opts.tls)?;
        let identity = opts.identity.clone().unwrap_or(cn);
        if !proto::identity_valid(&identity) {
            return Err(RemoteError::BadIdentity(identity));
        }
        if !proto::prefix_valid(prefix) {
            return Err(RemoteError::BadPrefix(prefix.to_owned()));
        }
        // A TCP connect tells an absent bridge from a refused certificate;
        // a QUIC endpoint has no such probe (Zenoh retries until the deadline).
        let tcp = ep.protocol == "tls";
        if tcp {
            wait_reachable(&ep, deadline)?;
        }
        let left = deadline.saturating_duration_since(Instant::now());
        let config = tls::client_config(&ep, opts, left.max(Duration::from_millis(500)))?;
        let session = zenoh::open(config).wait().map_err(|e| {
            let (endpoint, why) = (ep.locator.clone(), zenoh_text(e));
            if tcp {
                RemoteError::Handshake { endpoint, why }
            } else {
                RemoteError::NoSession { endpoint, why }
            }
        })?;
        let inbox = Arc::new(Inbox::default());

        let ib = inbox.clone();
        let status = session
            .declare_subscriber(proto::status_key(prefix))
            .callback(move |sample| {
                let s = decode_status(&sample);
                ib.update(|st| match s {
                    Some(s) => {
                        st.status = Some(s);
                        st.status_new = true;
                        st.status_at = Some(Instant::now());
                    }
                    None => st.bad_samples += 1,
                });
            })
            .wait()
            .map_err(zerr)?;

        let events = EventSubscription::declare(&session, prefix, &inbox)?;

        // The latest plan path, from the bridge's cache at once.
        let ib = inbox.clone();
        let plan = {
            use zenoh_ext::{AdvancedSubscriberBuilderExt, HistoryConfig};
            session
                .declare_subscriber(proto::plan_key(prefix))
                .history(HistoryConfig::default().max_samples(1))
                .callback(move |sample| {
                    let p = decode_plan(&sample);
                    ib.update(|st| match p {
                        Some(p) => st.plan = Some(Box::new(p)),
                        None => st.plans_refused += 1,
                    });
                })
                .wait()
                .map_err(zerr)?
        };

        let ib = inbox.clone();
        let bridge_key = proto::bridge_token_key(prefix);
        let daemon_key = proto::daemon_token_key(prefix);
        let alive = session
            .liveliness()
            .declare_subscriber(proto::alive_keys(prefix))
            .history(true)
            .callback(move |sample| {
                let up = sample.kind() == SampleKind::Put;
                let key = sample.key_expr().as_str();
                ib.update(|st| {
                    if key == bridge_key {
                        if up && !st.bridge {
                            if st.bridge_seen {
                                st.bridge_returns += 1;
                                st.resubscribe = true;
                            }
                            st.bridge_seen = true;
                        }
                        st.bridge = up;
                    } else if key == daemon_key {
                        st.daemon = up;
                    }
                });
            })
            .wait()
            .map_err(zerr)?;
        // The link itself: the bridge's token does not always blink when
        // Zenoh reconnects at once, a transport event does.
        let ib = inbox.clone();
        let transports = session
            .info()
            .transport_events_listener()
            .history(true)
            .callback(move |e| {
                let up = e.kind() == SampleKind::Put;
                ib.update(|st| {
                    if st.linked && !up {
                        st.link_drops += 1;
                    }
                    st.linked = up;
                });
            })
            .wait()
            .map_err(zerr)?;
        let zid = session.zid().to_string();
        let token_key = proto::client_token_key(prefix, &identity, &zid);
        let token = session
            .liveliness()
            .declare_token(&token_key)
            .wait()
            .map_err(zerr)?;
        let beat = Beat::start(session.clone(), token_key)?;
        Ok(Self {
            session,
            inbox,
            prefix: prefix.to_owned(),
            identity,
            endpoint: ep.locator,
            query_timeout: timeout.max(Duration::from_secs(1)),
            seen_generation: 0,
            _status: status,
            events,
            recheck_at: Some(Instant::now() + HISTORY_RECHECK),
            _plan: plan,
            _alive: alive,
            _transports: transports,
            _token: token,
            _beat: beat,
        })
    }

    /// Takes everything that arrived since the last call. After the
    /// bridge returned (a restart), subscribes to the events again first:
    /// the new subscription queries the restarted bridge's cache, which
    /// the old one would not (PROTOCOL.md, "Events").
    pub fn drain(&mut self) -> Drained {
        let returned = std::mem::take(&mut self.inbox.lock().resubscribe);
        let due = self.recheck_at.is_some_and(|t| Instant::now() >= t);
        if due {
            self.recheck_at = None;
        }
        let recheck = due && {
            let s = self.inbox.lock();
            s.continuity.history_owed() || s.continuity.missing() > 0
        };
        if returned || recheck {
            // On an error the old subscription goes on; the next return
            // retries.
            if let Ok(e) = EventSubscription::declare(&self.session, &self.prefix, &self.inbox) {
                self.events = e;
                // One recheck per return, none after a recheck.
                if returned {
                    self.recheck_at = Some(Instant::now() + HISTORY_RECHECK);
                }
            }
        }
        let mut s = self.inbox.lock();
        self.seen_generation = s.generation;
        let status = if std::mem::take(&mut s.status_new) {
            s.status
        } else {
            None
        };
        Drained {
            status,
            events: s.events.drain(..).collect(),
            replies: s.replies.drain(..).collect(),
            bad_samples: std::mem::take(&mut s.bad_samples),
            bridge_returns: std::mem::take(&mut s.bridge_returns),
            link_drops: std::mem::take(&mut s.link_drops),
        }
    }

    /// Blocks until something arrives after the last [`drain`](Self::drain), at most `d`.
    pub fn wait(&self, d: Duration) {
        let s = self.inbox.lock();
        let seen = self.seen_generation;
        let _ = self
            .inbox
            .cond
            .wait_timeout_while(s, d, |st| st.generation == seen);
    }

    /// How long ago the last status arrived.
    pub fn status_age(&self) -> Option<Duration> {
        self.inbox.lock().status_at.map(|t| t.elapsed())
    }

    /// Whether the session has a link to its router (the bridge) now.
    pub fn linked(&self) -> bool {
        self.inbox.lock().linked
    }

    /// Whether the bridge's and the daemon's liveliness tokens are visible.
    pub fn alive(&self) -> (bool, bool) {
        let s = self.inbox.lock();
        (s.bridge, s.daemon)
    }

    /// The plan paths this connection receives.
    pub(crate) fn plans(&self) -> RemotePlans {
        RemotePlans(self.inbox.clone())
    }

    /// Events of the daemon's current sequence this client never received
    /// (holes no later event filled), or Zenoh's count of samples it
    /// reported missed, whichever is more.
    pub fn missed_events(&self) -> u64 {
        let s = self.inbox.lock();
        s.continuity.missing().max(s.missed_events)
    }

    /// The holes in the events received: (instance, first seq, last seq).
    pub fn event_holes(&self) -> Vec<(u64, u64, u64)> {
        self.inbox.lock().continuity.holes()
    }

    /// How long a command query waits for its reply.
    pub fn query_timeout(&self) -> Duration {
        self.query_timeout
    }

    /// Sends `payload` as command `name` (a key chunk, e.g. `reorient`);
    /// its reply arrives in the inbox under `request_id`.
    pub fn send(&self, name: &str, payload: Vec<u8>, schema: &str, request_id: u64) -> Result<()> {
        let key = format!("{}/cmd/{}/{name}", self.prefix, self.identity);
        let end = QueryEnd {
            inbox: self.inbox.clone(),
            request_id,
            replied: AtomicBool::new(false),
        };
        self.session
            .get(key)
            .payload(payload)
            .encoding(Encoding::from(proto::encoding_of(schema)))
            .target(QueryTarget::BestMatching)
            .consolidation(ConsolidationMode::None)
            .timeout(self.query_timeout)
            .callback(move |reply| {
                let r = decode_reply(&reply);
                end.replied.store(true, Ordering::Release);
                end.inbox.update(|s| push_reply(s, end.request_id, r));
            })
            .wait()
            .map_err(zerr)
    }

    /// Sends raw bytes and waits for the reply (tools and tests).
    pub fn send_raw(
        &self,
        name: &str,
        payload: &[u8],
        schema: &str,
        timeout: Duration,
    ) -> Result<RawReply> {
        let key = format!("{}/cmd/{}/{name}", self.prefix, self.identity);
        let replies = self
            .session
            .get(key)
            .payload(payload.to_vec())
            .encoding(Encoding::from(proto::encoding_of(schema)))
            .consolidation(ConsolidationMode::None)
            .timeout(timeout)
            .wait()
            .map_err(zerr)?;
        let deadline = Instant::now() + timeout + Duration::from_millis(500);
        match replies.recv_deadline(deadline) {
            Ok(Some(r)) => match decode_reply(&r) {
                ReplyOutcome::Answer(a) => Ok(RawReply::Answer(a)),
                ReplyOutcome::Refused(r) => Ok(RawReply::Refused(r)),
                ReplyOutcome::Bad(why) => Err(RemoteError::BadReply(why)),
                ReplyOutcome::NoReply => Ok(RawReply::NoReply),
            },
            // Ok(None): deadline; Err: the query ended without replies.
            Ok(None) | Err(_) => Ok(RawReply::NoReply),
        }
    }
}
