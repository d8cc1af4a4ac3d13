//! daemon → remote clients: status (downsampled, latest value, dropped
//! rather than queued), events (advanced publisher: a cache for late
//! joiners, sequence numbers and heartbeats for miss detection), each
//! plan's path (advanced publisher caching the latest, for views), and the
//! daemon's liveliness token while a fresh status comes in.
//!
//! Runs on its own thread with its own `gaitd_client::Client` (iceoryx2
//! ports are bound to their thread). It wakes on every daemon status and
//! forwards the one that arrived when the period is due, so the forwarded
//! status is never older than one daemon period.

use crate::config::Config;
use gaitd_client::remote::protocol as proto;
use gaitd_client::{Client, ConnectOptions, DaemonState, Error, PlanPaths};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};
use zenoh::Wait;
use zenoh::bytes::Encoding;
use zenoh::qos::{CongestionControl, Priority};
use zenoh_ext::{AdvancedPublisherBuilderExt, CacheConfig, MissDetectionConfig};

/// How long one wait for a status lasts (bounds the reaction to a stop).
const WAIT: Duration = Duration::from_millis(200);
/// How long a connection attempt to the daemon lasts.
const CONNECT: Duration = Duration::from_millis(500);

/// The client options of the bridge's connections to gaitd.
pub fn local_options(cfg: &Config, node_name: &str) -> ConnectOptions {
    let g = &cfg.gaitd;
    let set = |s: &str| (!s.is_empty()).then(|| s.to_owned());
    let mut o = ConnectOptions::new().timeout(CONNECT).node_name(node_name);
    o.ipc.iceoryx2_config = set(&g.iceoryx2_config);
    o.ipc.service_prefix = set(&g.service_prefix);
    o.ipc.root_path = set(&g.root_path);
    o.ipc.file_prefix = set(&g.file_prefix);
    o
}

/// The bridge's publishers, declared before its liveliness token so that
/// a client that sees the bridge finds the event cache to query.
pub struct Publishers<'a> {
    session: &'a zenoh::Session,
    status: zenoh::pubsub::Publisher<'a>,
    events: zenoh_ext::AdvancedPublisher<'a>,
    plan: zenoh_ext::AdvancedPublisher<'a>,
}

impl<'a> Publishers<'a> {
    /// Declares the status and event publishers on `session`.
    pub fn declare(cfg: &Config, session: &'a zenoh::Session) -> anyhow::Result<Self> {
        let prefix = &cfg.zenoh.key_prefix;
        let status = session
            .declare_publisher(proto::status_key(prefix))
            .encoding(Encoding::from(proto::encoding_of(proto::STATUS_SCHEMA)))
            .congestion_control(CongestionControl::Drop)
            .priority(Priority::DataHigh)
            .express(true)
            .wait()
            .map_err(|e| {
                anyhow::anyhow!(
                    "declaring the status publisher: {}",
                    gaitd_client::remote::zenoh_text(e)
                )
            })?;
        let events = session
            .declare_publisher(proto::events_key(prefix))
            .encoding(Encoding::from(proto::encoding_of(proto::EVENT_SCHEMA)))
            .congestion_control(CongestionControl::Block)
            .cache(CacheConfig::default().max_samples(cfg.bridge.event_cache))
            .sample_miss_detection(
                MissDetectionConfig::default()
                    .heartbeat(Duration::from_millis(cfg.bridge.heartbeat_ms)),
            )
            .publisher_detection()
            .wait()
            .map_err(|e| {
                anyhow::anyhow!(
                    "declaring the event publisher: {}",
                    gaitd_client::remote::zenoh_text(e)
                )
            })?;
        // The latest path only: a view that joins mid-plan gets it.
        let plan = session
            .declare_publisher(proto::plan_key(prefix))
            .encoding(Encoding::from(proto::encoding_of(proto::PLAN_SCHEMA)))
            .congestion_control(CongestionControl::Block)
            .cache(CacheConfig::default().max_samples(1))
            .wait()
            .map_err(|e| {
                anyhow::anyhow!(
                    "declaring the plan path publisher: {}",
                    gaitd_client::remote::zenoh_text(e)
                )
            })?;
        Ok(Self {
            session,
            status,
            events,
            plan,
        })
    }
}

/// How often the latest plan path is sent again while nothing newer comes:
/// a view whose history query missed the bridge's cache (a query that
/// reached the bridge before its cache was declared to the client, or that
/// Zenoh dropped) has it within this time.
const PATH_REPEAT: Duration = Duration::from_secs(1);

/// The daemon's plan paths, forwarded: each new one at once, the latest
/// again every [`PATH_REPEAT`].
struct PathForwarder {
    paths: PlanPaths,
    /// Instance and sequence of the last path sent, and when.
    last: Option<((u64, u64), Instant)>,
}

impl PathForwarder {
    fn new(paths: PlanPaths) -> Self {
        Self { paths, last: None }
    }

    fn pump(&mut self, now: Instant, plan: &zenoh_ext::AdvancedPublisher<'_>) {
        let Ok(Some(p)) = self.paths.latest() else {
            return;
        };
        let id = (p.instance, p.sequence);
        let fresh = self.last.is_none_or(|(last, _)| last != id);
        if !fresh && self.last.is_some_and(|(_, at)| now < at + PATH_REPEAT) {
            return;
        }
        if fresh {
            tracing::info!(
                goal = p.goal_id,
                sequence = p.sequence,
                points = p.count,
                "forwarding a plan path"
            );
        }
        self.last = Some((id, now));
        if let Err(e) = plan.put(p.to_bytes().to_vec()).wait() {
            tracing::warn!("plan path publish: {e}");
        }
    }
}

/// Forwards until `stop` is set.
pub fn run(cfg: &Config, publishers: Publishers<'_>, stop: &AtomicBool) -> anyhow::Result<()> {
    let Publishers {
        session,
        status: status_pub,
        events: events_pub,
        plan: plan_pub,
    } = publishers;
    let mut paths: Option<PathForwarder> = None;
    let prefix = &cfg.zenoh.key_prefix;
    let period = cfg.status_period();
    let opts = local_options(cfg, "gaitd-bridge");
    let mut daemon: Option<Client> = None;
    let mut token: Option<zenoh::liveliness::LivelinessToken> = None;
    let mut next_due = Instant::now();
    let mut waiting_logged = false;
    let mut forwarded = 0u64;
    while !stop.load(Ordering::Acquire) {
        let Some(c) = daemon.as_mut() else {
            match Client::connect(opts.clone()) {
                Ok(c) => {
                    tracing::info!(
                        instance = format_args!("{:016x}", c.daemon_instance()),
                        "connected to gaitd"
                    );
                    waiting_logged = false;
                    paths = c
                        .plan_paths()
                        .map_err(|e| tracing::warn!("no plan paths: {e}"))
                        .ok()
                        .map(PathForwarder::new);
                    daemon = Some(c);
                }
                Err(e) => {
                    if !waiting_logged {
                        tracing::warn!("waiting for gaitd: {e}");
                        waiting_logged = true;
                    }
                    drop(token.take());
                    std::thread::sleep(WAIT);
                }
            }
            continue;
        };
        match c.wait_status(WAIT) {
            Ok(s) => {
                let now = Instant::now();
                let last = s.daemon_state == DaemonState::Stopped.code();
                if now >= next_due || last {
                    if let Err(e) = status_pub.put(s.to_bytes().to_vec()).wait() {
                        tracing::warn!("status publish: {e}");
                    }
                    forwarded += 1;
                    next_due += period;
                    if next_due <= now {
                        // Behind (a slow daemon or a stall): skip, never burst.
                        next_due = now + period;
                    }
                }
            }
            Err(Error::Timeout { .. }) => {}
            Err(e) => {
                tracing::warn!("gaitd connection: {e}");
                daemon = None;
                continue;
            }
        }
        match c.events() {
            Ok(events) => {
                for e in events {
                    if let Err(err) = events_pub.put(e.to_bytes().to_vec()).wait() {
                        tracing::warn!("event publish: {err}");
                    }
                }
            }
            Err(e) => tracing::warn!("events: {e}"),
        }
        if let Some(p) = paths.as_mut() {
            p.pump(Instant::now(), &plan_pub);
        }
        let alive = c.daemon_alive().unwrap_or(false);
        if alive && token.is_none() {
            match session
                .liveliness()
                .declare_token(proto::daemon_token_key(prefix))
                .wait()
            {
                Ok(t) => token = Some(t),
                Err(e) => tracing::warn!("daemon token: {e}"),
            }
        } else if !alive && token.is_some() {
            tracing::warn!("gaitd stopped publishing status; reconnecting");
            token = None;
            if let Err(e) = c.reconnect(CONNECT) {
                tracing::debug!("reconnect: {e}");
            }
            // A restarted daemon's plan service is a new one.
            paths = c.plan_paths().ok().map(PathForwarder::new);
        }
    }
    tracing::info!(forwarded, "status forwarding stopped");
    Ok(())
}
