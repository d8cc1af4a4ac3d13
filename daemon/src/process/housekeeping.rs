//! Housekeeping, off the real-time loop (SPEC §7.2), about once a second:
//!
//! - iceoryx2 dead-node cleanup (`try_cleanup_dead_nodes`, ~100 µs): frees
//!   the ports of crashed clients so they stop counting against the limits;
//! - client bookkeeping: how many client nodes are alive, logged when it
//!   changes, and how many dead ones were cleaned (the loop turns that into
//!   a `ClientsCleaned` event);
//! - reports what the loop only counts (missed periods, IPC errors, lost
//!   events) as rate-limited warnings — the loop itself never logs;
//! - `STATUS=` for systemd from the latest published status, which this
//!   thread reads like any client;
//! - a warning with the numbers when the grasp the hand starts (or is
//!   reset) in cannot hold the load (the status's `load_margin` < 0); on a
//!   chain hand, whose motors bound the grip before `load.max_grip` does,
//!   a note with the motors' push instead (plans use the torque box).
//!
//! It has its own iceoryx2 node (ports are not shared across threads).

use super::logging::RateLimit;
use crate::io::ipc::{Ipc, create_node, status_subscriber};
use crate::sys::sd_notify;
use crate::sys::shared::Shared;
use iceoryx2::config::Config;
use iceoryx2::identifiers::UniqueNodeId;
use iceoryx2::node::NodeView;
use iceoryx2::prelude::*;
use shm_schema::ipc::HOUSEKEEPING_NODE_NAME;
use shm_schema::{FaultCode, Phase, ServiceNames, Status};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};
use tracing::{info, warn};

/// What the housekeeping thread needs.
#[derive(Debug)]
pub struct HousekeepingSetup {
    /// iceoryx2 config shared with the daemon.
    pub config: Config,
    /// Service names.
    pub names: ServiceNames,
    /// The daemon node's id (not counted as a client).
    pub daemon_node: UniqueNodeId,
    /// Counters shared with the loop.
    pub shared: Arc<Shared>,
    /// Period.
    pub period: Duration,
    /// systemd notifier, if started by systemd.
    pub sd: Option<sd_notify::Notifier>,
    /// CPUs to pin this thread to.
    pub cpus: Vec<u32>,
    /// With an external plant: how long it may take to send its first
    /// valid measurement before that is warned about (`plant.connect_timeout_ms`).
    pub plant_connect_timeout: Option<Duration>,
    /// `[load]`, for the warning about a grasp that cannot hold it.
    pub load: gait::config::LoadConfig,
}

/// Handle of the running thread (stops it on `join` or drop).
pub type Housekeeping = crate::sys::worker::StoppableThread;

/// Starts the thread `gaitd-housekeeping`.
pub fn spawn(setup: HousekeepingSetup) -> std::io::Result<Housekeeping> {
    let stop = Arc::new(AtomicBool::new(false));
    let stop2 = stop.clone();
    let handle = std::thread::Builder::new()
        .name("gaitd-housekeeping".into())
        .spawn(move || run(setup, &stop2))?;
    Ok(Housekeeping::new(stop, handle))
}

fn run(s: HousekeepingSetup, stop: &AtomicBool) {
    if let Err(e) = crate::sys::rt::pin_current_thread(&s.cpus) {
        warn!(cpus = ?s.cpus, error = %e, "cannot pin housekeeping thread");
    }
    let node = match create_node(HOUSEKEEPING_NODE_NAME, &s.config) {
        Ok(n) => n,
        Err(e) => {
            warn!(error = %e, "housekeeping disabled: cannot create its iceoryx2 node");
            return;
        }
    };
    let status = status_subscriber(&node, &s.names)
        .map_err(|e| warn!(error = %e, "housekeeping: no status subscription (no STATUS= texts)"))
        .ok();
    let mut overrun_limit = RateLimit::new(Duration::from_secs(10));
    let mut ipc_limit = RateLimit::new(Duration::from_secs(10));
    let mut event_limit = RateLimit::new(Duration::from_secs(10));
    let mut plant = PlantWatch::new(Instant::now());
    let mut load = LoadWatch { armed: true };
    let (mut last_overruns, mut last_ipc, mut last_dropped, mut last_clients) = (0, 0, 0, 0);
    while !stop.load(Ordering::Acquire) {
        let now = Instant::now();

        let c = node.try_cleanup_dead_nodes();
        // The count is stored before the cleanup is announced (release/
        // acquire with the loop): the status published with the
        // `ClientsCleaned` event already counts without the dead.
        let clients = count_clients(&s.config, s.daemon_node, node.id());
        s.shared.clients.store(clients, Ordering::Relaxed);
        if c.cleanups > 0 {
            info!(
                nodes = c.cleanups,
                "cleaned up dead iceoryx2 nodes (crashed clients)"
            );
            s.shared.cleaned.fetch_add(c.cleanups, Ordering::Release);
        }
        if c.failed_cleanups > 0 {
            warn!(
                nodes = c.failed_cleanups,
                "dead iceoryx2 nodes could not be cleaned up (permissions?)"
            );
        }
        if clients != last_clients {
            info!(clients, "client count changed");
            last_clients = clients;
        }

        let overruns = s.shared.overruns.load(Ordering::Relaxed);
        if overruns > last_overruns
            && let Some(suppressed) = overrun_limit.allow(now)
        {
            warn!(
                missed = overruns - last_overruns,
                total = overruns,
                suppressed,
                "control loop missed periods"
            );
            last_overruns = overruns;
        }
        let ipc = s.shared.ipc_errors.load(Ordering::Relaxed);
        if ipc > last_ipc
            && let Some(suppressed) = ipc_limit.allow(now)
        {
            warn!(
                errors = ipc - last_ipc,
                total = ipc,
                suppressed,
                "iceoryx2 send/receive errors on the loop"
            );
            last_ipc = ipc;
        }
        let dropped = s.shared.events_dropped.load(Ordering::Relaxed);
        if dropped > last_dropped
            && let Some(suppressed) = event_limit.allow(now)
        {
            warn!(
                lost = dropped - last_dropped,
                suppressed, "more events in one tick than the event queue holds"
            );
            last_dropped = dropped;
        }

        let mut latest = None;
        if let Some(sub) = &status {
            while let Ok(Some(sample)) = sub.receive() {
                latest = Some(*sample.payload());
            }
        }
        if let Some(st) = &latest {
            plant.observe(st, now, s.plant_connect_timeout);
            load.observe(st, &s.load);
        }
        if let (Some(sd), Some(st)) = (&s.sd, latest) {
            let t = &st.timing;
            let _ = sd.status(&format!(
                "tick {} | compute p99 {:.1} us max {:.1} us | jitter p99 {:.1} us | missed {} | clients {}",
                st.tick,
                t.compute_p99_ns as f64 / 1e3,
                t.compute_max_ns as f64 / 1e3,
                t.jitter_p99_ns as f64 / 1e3,
                t.overruns,
                st.clients
            ));
        }
        std::thread::park_timeout(s.period);
    }
}

/// The external plant as the status shows it, for the log (the loop
/// never logs): a plant that does not connect in time, and every change of
/// a plant fault.
struct PlantWatch {
    since: Instant,
    warned_waiting: bool,
    last_fault: u32,
}

impl PlantWatch {
    fn new(now: Instant) -> Self {
        Self {
            since: now,
            warned_waiting: false,
            last_fault: FaultCode::None.code(),
        }
    }

    fn observe(&mut self, st: &Status, now: Instant, connect_timeout: Option<Duration>) {
        let Some(timeout) = connect_timeout else {
            return;
        };
        let waiting = st.fault == FaultCode::PlantWaiting.code();
        if waiting && !self.warned_waiting && now.duration_since(self.since) > timeout {
            self.warned_waiting = true;
            warn!(
                waited = ?timeout,
                "no plant has sent a valid measurement yet: is it running with this \
                 daemon's [ipc] settings (gaitctl plant sim|mujoco --config <this file>)?"
            );
        }
        if st.fault != self.last_fault {
            let name = FaultCode::try_from(st.fault).map_or("unknown", FaultCode::name);
            match FaultCode::try_from(st.fault) {
                Ok(FaultCode::None) if !waiting => info!("plant: fault cleared"),
                Ok(FaultCode::PlantWaiting) => {}
                _ => warn!(fault = name, "plant: safe hold after a fault"),
            }
            if st.fault == FaultCode::None.code()
                && self.last_fault == FaultCode::PlantWaiting.code()
            {
                info!("plant: first valid measurement taken; the hand starts from it");
            }
            self.last_fault = st.fault;
        }
    }
}

/// The load margin of the grasp the hand holds once it starts, and again
/// after every fault is cleared: a negative one is warned about once.
struct LoadWatch {
    armed: bool,
}

impl LoadWatch {
    fn observe(&mut self, st: &Status, load: &gait::config::LoadConfig) {
        let holding = st.fault == FaultCode::None.code() && st.phase == Phase::Hold.code();
        if st.fault != FaultCode::None.code() {
            self.armed = true;
        } else if self.armed && holding {
            self.armed = false;
            let short = st.load_margin < 0.0;
            if short && st.hand == shm_schema::status::hand::CHAINS {
                // The motors, not load.max_grip, bound the closed-form grip.
                let (peak, margin) = (st.load_grip, st.load_margin);
                let note = super::load_check::capped_note(peak, margin, load.max_grip);
                info!("{note}");
            } else if short {
                let which = "the grasp the hand holds";
                warn!("{}", super::load_check::warning(which, st.load_grip, load));
            }
        }
    }
}

/// Alive nodes under `config` other than the daemon's two.
fn count_clients(config: &Config, daemon: UniqueNodeId, own: &UniqueNodeId) -> u32 {
    let mut n = 0;
    let _ = Node::<Ipc>::list(config, |state| {
        if let NodeState::Alive(v) = &state
            && *v.id() != daemon
            && v.id() != own
        {
            n += 1;
        }
        CallbackProgression::Continue
    });
    n
}
