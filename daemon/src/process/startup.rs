//! Start-up and shut-down of the daemon process, one function per step
//! (SPEC §7.1); `gaitd`'s `main` calls [`Daemon::start`] then
//! [`Daemon::run`].
//!
//! Start-up order matters: services and ports first (so `READY=1` means
//! clients can connect), then memory locking (it locks the shared memory
//! just mapped), then the background threads (before the main thread turns
//! SCHED_FIFO, so they do not inherit it), then `READY=1` and the loop.
//!
//! 1. [`open_ipc`]: the iceoryx2 node and services, the loop's command
//!    subscriber, and the writer thread with its publishers;
//! 2. [`lock_memory`];
//! 3. [`start_background`]: housekeeping, the planner thread and the
//!    controller, the trace thread;
//! 4. [`build_loop`]: the loop with its systemd watchdog;
//! 5. [`become_loop_thread`]: the main thread pinned, SCHED_FIFO (loop,
//!    then writer), precise timers, a pre-faulted stack;
//! 6. [`Daemon::run`]: `READY=1`, the loop until SIGTERM/SIGINT, then the
//!    threads joined in an order where nobody waits for a thread already
//!    gone: the writer (it publishes the final status), the trace and
//!    housekeeping threads, the loop's ports, the planner, the services,
//!    the node.

use crate::config::DaemonConfig;
use crate::control::gait_controller::hand_planner::HandPlanner;
use crate::control::gait_controller::{GaitController, GaitPlanner};
use crate::control::plan_thread::{self, PlannerThread};
use crate::io::ipc::{self, IpcError};
use crate::io::outbox::{self, Outbox, Writer, WriterSettings};
use crate::io::plan_paths::PathPublisher;
use crate::io::tracer::{self, TraceError, TraceSettings, TraceWriter};
use crate::plant::external::ExternalPlant;
use crate::plant::joints::JointLink;
use crate::plant::ports::PlantInput;
use crate::process::hand_setup::{HandSetup, HandSetupError};
use crate::process::housekeeping::{self, Housekeeping, HousekeepingSetup};
use crate::process::signals;
use crate::realtime::runtime::Runtime;
use crate::sys::clock::MonotonicClock;
use crate::sys::doorbell::Doorbell;
use crate::sys::shared::Shared;
use crate::sys::{rt, sd_notify};
use gait::planner::chains::planner::ChainPlanner;
use iceoryx2::config::Config;
use iceoryx2::node::Node;
use iceoryx2::port::subscriber::Subscriber;
use shm_schema::ipc::{DAEMON_NODE_NAME, IpcSettings};
use shm_schema::{Command, ServiceNames};
use std::sync::Arc;
use std::sync::atomic::AtomicBool;
use std::time::Duration;
use tracing::{info, warn};

/// The start-up log lines keep the target of the `gaitd` binary, where
/// they were logged before this module existed (`gaitd: ready` is what
/// scripts and the end-to-end tests wait for).
const LOG_TARGET: &str = "gaitd";

/// Plans queued for the planner thread at most.
const PLANNER_QUEUE: usize = 4;

/// Why the daemon could not start. Each names the step that failed.
#[derive(Debug, thiserror::Error)]
pub enum StartupError {
    /// iceoryx2: settings, config file, root path, node, a service or port.
    #[error(transparent)]
    Ipc(#[from] IpcError),
    /// `$NOTIFY_SOCKET` is set but cannot be used.
    #[error("connecting to $NOTIFY_SOCKET: {0}")]
    NotifySocket(std::io::Error),
    /// `$NOTIFY_SOCKET` disappeared between two reads of the environment.
    #[error("$NOTIFY_SOCKET vanished")]
    NotifySocketGone,
    /// The housekeeping thread could not be started.
    #[error("starting the housekeeping thread: {0}")]
    Housekeeping(std::io::Error),
    /// The configured hand cannot be set up.
    #[error(transparent)]
    Hand(#[from] HandSetupError),
    /// The planner refused the model.
    #[error("building the planner: {0}")]
    Planner(gait::ConfigError),
    /// The planner thread could not be started.
    #[error("starting the planner thread: {0}")]
    PlannerThread(std::io::Error),
    /// The controller refused the model.
    #[error("building the controller: {0}")]
    Controller(gait::ConfigError),
    /// The trace thread could not be started.
    #[error(transparent)]
    Tracer(#[from] TraceError),
}

/// The client → daemon command service.
pub type CommandService =
    iceoryx2::service::port_factory::publish_subscribe::PortFactory<ipc::Ipc, Command, ()>;

/// Step 1's result: iceoryx2 is up and the writer publishes.
#[derive(Debug)]
pub struct IpcUp {
    /// The iceoryx2 config every node of the daemon uses.
    pub config: Config,
    /// Where the resources live.
    pub settings: IpcSettings,
    /// The daemon's node (dropped last).
    pub node: Node<ipc::Ipc>,
    /// The command service (dropped after the loop's subscriber).
    pub command_service: CommandService,
    /// The `version` service (held while the daemon runs).
    pub version_service: ipc::EventService,
    /// The service names.
    pub names: ServiceNames,
    /// The loop's command subscriber.
    pub commands: Subscriber<ipc::Ipc, Command, ()>,
    /// The loop's end of the writer.
    pub outbox: Outbox,
    /// The writer thread.
    pub writer: Writer,
    /// Counters shared by the loop and the other threads.
    pub shared: Arc<Shared>,
    /// The planner's doorbell, rung by the writer after each tick.
    pub planner_bell: Arc<Doorbell>,
    /// An external plant's ports for the loop thread (`[plant] kind = "shm"`).
    pub plant: Option<ipc::PlantInPorts>,
    /// The `plan` service, until the planner thread takes it.
    pub plan_service: Option<ipc::PlanPathService>,
}

/// Step 1: the node, every service, the loop's command subscriber and the
/// writer thread, which creates its publishers before this returns.
pub fn open_ipc(cfg: &DaemonConfig) -> Result<IpcUp, StartupError> {
    let (config, settings) = ipc::resolve(&cfg.ipc)?;
    let node = ipc::create_node(DAEMON_NODE_NAME, &config)?;
    let services = ipc::create_services(&node, cfg, &settings.service_prefix)?;
    let commands = services.command_subscriber(cfg.ipc.command_queue as usize)?;
    // An external plant's ports live on the loop thread (this one).
    let plant = match &services.plant_in {
        Some(p) => Some(p.ports(&services.names)?),
        None => None,
    };
    let shared = Arc::new(Shared::default());
    // The writer rings the planner's doorbell after each tick, so the loop
    // never wakes the planner thread itself (planner module docs).
    let planner_bell = Arc::new(Doorbell::default());
    let (outbox, writer) = outbox::spawn(
        services.out,
        services.names.clone(),
        WriterSettings {
            status_notify_every: cfg.daemon.status_notify_every.into(),
            // In lockstep the plant waits for each command: the loop wakes
            // the writer at once instead of at the next deadline.
            wake: if cfg.plant.lockstep() {
                outbox::WriterWake::Unpark
            } else {
                cfg.daemon.writer_wake
            },
            period: cfg.period_ns(),
            spin: cfg.writer_lead_ns(),
            cpus: cfg.rt.background_cpus.clone(),
            doorbells: vec![planner_bell.clone()],
        },
        shared.clone(),
    )?;
    info!(
        target: LOG_TARGET,
        prefix = %settings.service_prefix,
        root = %settings.root_path,
        file_prefix = %settings.file_prefix,
        tick_hz = cfg.control.tick_hz,
        "iceoryx2 services up"
    );
    Ok(IpcUp {
        config,
        settings,
        node,
        command_service: services.commands,
        version_service: services.version,
        names: services.names,
        commands,
        outbox,
        writer,
        shared,
        planner_bell,
        plant,
        plan_service: Some(services.plan),
    })
}

/// Step 2: `mlockall` when configured; a warning if not permitted.
pub fn lock_memory(cfg: &DaemonConfig) {
    if cfg.rt.lock_memory {
        match rt::lock_memory() {
            Ok(()) => info!(target: LOG_TARGET, "memory locked (mlockall)"),
            Err(e) => warn!(target: LOG_TARGET, "real-time: {e}; continuing without"),
        }
    }
}

/// Step 3's result: the threads beside the loop.
#[derive(Debug)]
pub struct Background {
    /// The controller the loop will run.
    pub controller: GaitController,
    /// Housekeeping.
    pub housekeeping: Housekeeping,
    /// The planner thread.
    pub planner: PlannerThread,
    /// The trace thread, when `[daemon] trace_dir` is set.
    pub tracer: Option<TraceWriter>,
}

/// Step 3: housekeeping, the planner thread and the controller (planner +
/// executor + the hand: embedded, or an external plant's link, SPEC §6.2,
/// §7.2), the trace thread.
pub fn start_background(
    cfg: &DaemonConfig,
    setup: &HandSetup,
    ipc: &mut IpcUp,
    instance: u64,
) -> Result<Background, StartupError> {
    let housekeeping = housekeeping::spawn(HousekeepingSetup {
        config: ipc.config.clone(),
        names: ipc.names.clone(),
        daemon_node: *ipc.node.id(),
        shared: ipc.shared.clone(),
        period: Duration::from_millis(cfg.daemon.housekeeping_period_ms.into()),
        // Housekeeping's STATUS= texts are best effort.
        sd: sd_notify::Notifier::from_env().ok().flatten(),
        cpus: cfg.rt.background_cpus.clone(),
        plant_connect_timeout: cfg
            .plant
            .external()
            .then(|| Duration::from_millis(cfg.plant.connect_timeout_ms.into())),
        load: setup.config.load,
    })
    .map_err(StartupError::Housekeeping)?;
    let hand = &setup.config;
    let gait_planner: HandPlanner = match &setup.chains {
        Some(model) => ChainPlanner::new(model.clone()).into(),
        None => gait::planner::Planner::new(hand)
            .map_err(StartupError::Planner)?
            .into(),
    };
    let cpus = cfg.rt.background_cpus.clone();
    // In lockstep the expansion budget alone bounds planning: a plan must
    // not depend on how fast this machine was.
    let budget =
        (!cfg.plant.lockstep()).then(|| Duration::from_secs_f64(hand.planner.budget_ms * 1e-3));
    // The planner's notes on its plans go to the trace headers (off the
    // loop), when traces are written.
    let notes = (!cfg.daemon.trace_dir.is_empty()).then(|| Arc::new(tracer::PlanNotes::default()));
    let mut planning = GaitPlanner::new(gait_planner, budget);
    // The controller starts from the configured hand's start (an external
    // plant's first measurement re-bases it, usually to the same grasp).
    planning.prepare_from(setup.start);
    if let Some(n) = &notes {
        planning.keep_notes(n.clone());
    }
    if let Some(service) = ipc.plan_service.take() {
        planning.publish_paths(PathPublisher::new(service, instance));
    }
    let (mut link, planner) = plan_thread::spawn(planning, PLANNER_QUEUE, move || {
        let _ = rt::pin_current_thread(&cpus);
    })
    .map_err(StartupError::PlannerThread)?;
    link.wake_through(ipc.planner_bell.clone());
    let dt = 1.0 / cfg.control.tick_hz;
    let chains = setup.chains.as_ref().map(|m| m.hand().clone());
    let mut controller = if cfg.plant.external() {
        let mut plant = ExternalPlant::new(instance, cfg.period_ns(), &cfg.plant);
        if let Some(h) = &chains {
            plant = plant.with_joints(JointLink::new(h.clone(), (&cfg.hand).into()));
        }
        GaitController::new_external(hand, (chains, setup.start), dt, link, plant)
    } else {
        GaitController::embedded_hand(hand, chains, setup.start, dt, link)
    }
    .map_err(StartupError::Controller)?;
    let tracer = start_tracer(cfg, hand, instance, &mut controller, notes)?;
    Ok(Background {
        controller,
        housekeeping,
        planner,
        tracer,
    })
}

/// Goal traces (SPEC §8), when configured: the loop copies samples into a
/// ring, the trace thread formats and writes them.
fn start_tracer(
    cfg: &DaemonConfig,
    hand: &gait::HandConfig,
    instance: u64,
    controller: &mut GaitController,
    plan_notes: Option<Arc<tracer::PlanNotes>>,
) -> Result<Option<TraceWriter>, StartupError> {
    if cfg.daemon.trace_dir.is_empty() {
        return Ok(None);
    }
    let (recorder, writer) = tracer::spawn(
        TraceSettings {
            dir: cfg.daemon.trace_dir.clone().into(),
            instance,
            hand: *hand,
            dt: 1.0 / cfg.control.tick_hz,
            cpus: cfg.rt.background_cpus.clone(),
            keep: cfg.daemon.trace_keep as usize,
            plan_notes,
            hand_description: cfg.hand.chains().then(|| {
                let path = cfg.dir.join(&cfg.hand.description);
                std::fs::canonicalize(&path)
                    .unwrap_or(path)
                    .display()
                    .to_string()
            }),
        },
        tracer::DEFAULT_CAPACITY,
    )?;
    controller.set_trace(recorder);
    info!(target: LOG_TARGET, dir = %cfg.daemon.trace_dir, "recording a trace of every goal");
    Ok(Some(writer))
}

/// The loop gaitd runs.
pub type DaemonLoop = Runtime<GaitController, MonotonicClock>;

/// What the loop thread reads and writes: commands, the writer's ring, the
/// shared counters, an external plant's ports.
pub type LoopPorts = (
    Subscriber<ipc::Ipc, Command, ()>,
    Outbox,
    Arc<Shared>,
    Option<ipc::PlantInPorts>,
);

/// Step 4: the loop on the real clock; with a systemd watchdog it sends
/// `WATCHDOG=1` itself every half period.
pub fn build_loop(
    cfg: &DaemonConfig,
    ports: LoopPorts,
    controller: GaitController,
    instance: u64,
    systemd: bool,
) -> Result<DaemonLoop, StartupError> {
    let (commands, outbox, shared, plant) = ports;
    let mut runtime = Runtime::new(
        commands,
        outbox,
        controller,
        MonotonicClock,
        cfg,
        instance,
        shared,
    );
    if let Some(p) = plant {
        runtime.set_plant(PlantInput::new(p));
        info!(
            target: LOG_TARGET,
            timing = ?cfg.plant.timing,
            "external plant: waiting for its first valid measurement"
        );
    }
    if let (Some(period), true) = (sd_notify::watchdog_period(), systemd) {
        let n = sd_notify::Notifier::from_env()
            .map_err(StartupError::NotifySocket)?
            .ok_or(StartupError::NotifySocketGone)?;
        runtime.set_watchdog(n, period.as_nanos() as u64 / 2);
        info!(
            target: LOG_TARGET,
            ?period,
            "systemd watchdog fed from the loop every half period"
        );
    }
    Ok(runtime)
}

/// Step 5: the calling (main) thread becomes the loop thread: pinned to
/// `rt.loop_cpus`, SCHED_FIFO (then the writer just below it), precise
/// timers, a pre-faulted stack. Anything refused is a warning.
pub fn become_loop_thread(cfg: &DaemonConfig, writer: &Writer) {
    if let Err(e) = rt::pin_current_thread(&cfg.rt.loop_cpus) {
        warn!(
            target: LOG_TARGET,
            cpus = ?cfg.rt.loop_cpus,
            "real-time: cannot pin the loop thread: {e}; continuing unpinned"
        );
    }
    let (loop_priority, writer_priority) = (cfg.rt.fifo_priority, cfg.rt.writer_fifo_priority());
    let fifo =
        rt::raise_loop_then_writer(loop_priority, writer_priority, rt::set_fifo_priority, |p| {
            writer.set_fifo_priority(p)
        });
    match fifo.loop_thread {
        Some(Ok(())) => {
            info!(target: LOG_TARGET, priority = loop_priority, "loop thread runs SCHED_FIFO")
        }
        Some(Err(e)) => warn!(
            target: LOG_TARGET,
            priority = loop_priority,
            "real-time: SCHED_FIFO not permitted ({e}); loop and writer run with normal \
             scheduling (grant LimitRTPRIO/CAP_SYS_NICE)"
        ),
        None if cfg.rt.writer_priority.is_some_and(|p| p > 0) => warn!(
            target: LOG_TARGET,
            "rt.writer_priority is ignored: the loop runs normal scheduling (rt.fifo_priority = 0)"
        ),
        None => {}
    }
    match fifo.writer {
        Some(Ok(())) => {
            info!(target: LOG_TARGET, priority = writer_priority, "writer thread runs SCHED_FIFO")
        }
        Some(Err(e)) => warn!(
            target: LOG_TARGET,
            priority = writer_priority,
            "real-time: SCHED_FIFO not permitted for the writer thread ({e}); it runs with \
             normal scheduling"
        ),
        None => {}
    }
    // Without SCHED_FIFO the kernel's default 50 µs timer slack would
    // delay every wake-up.
    rt::precise_timers();
    rt::prefault_stack(64 * 1024);
}

/// A started daemon, ready to run its loop on the calling thread.
pub struct Daemon {
    runtime: DaemonLoop,
    /// systemd notifier for `READY=1` and `STOPPING=1`.
    sd: Option<sd_notify::Notifier>,
    instance: u64,
    writer: Writer,
    tracer: Option<TraceWriter>,
    housekeeping: Housekeeping,
    planner: PlannerThread,
    command_service: CommandService,
    version_service: ipc::EventService,
    node: Node<ipc::Ipc>,
}

impl std::fmt::Debug for Daemon {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Daemon")
            .field("instance", &format_args!("{:016x}", self.instance))
            .finish_non_exhaustive()
    }
}

impl Daemon {
    /// Steps 1–5 (module docs); the calling thread becomes the loop thread.
    pub fn start(cfg: &DaemonConfig) -> Result<Self, StartupError> {
        let setup = HandSetup::load(cfg)?;
        let mut ipc = open_ipc(cfg)?;
        lock_memory(cfg);
        let sd = sd_notify::Notifier::from_env().map_err(StartupError::NotifySocket)?;
        let instance = crate::new_instance_id();
        let bg = start_background(cfg, &setup, &mut ipc, instance)?;
        let ports = (ipc.commands, ipc.outbox, ipc.shared, ipc.plant);
        let runtime = build_loop(cfg, ports, bg.controller, instance, sd.is_some())?;
        become_loop_thread(cfg, &ipc.writer);
        Ok(Self {
            runtime,
            sd,
            instance,
            writer: ipc.writer,
            tracer: bg.tracer,
            housekeeping: bg.housekeeping,
            planner: bg.planner,
            command_service: ipc.command_service,
            version_service: ipc.version_service,
            node: ipc.node,
        })
    }

    /// Step 6: `READY=1`, the loop until `stop` is set (SIGTERM/SIGINT),
    /// then the shut-down in order (module docs).
    pub fn run(mut self, stop: &AtomicBool) {
        if let Some(sd) = &self.sd {
            let _ = sd.ready();
            let _ = sd.status("running");
        }
        info!(target: LOG_TARGET, instance = format!("{:016x}", self.instance), "ready");
        let summary = self.runtime.run(stop);
        if let Some(sd) = &self.sd {
            let _ = sd.stopping();
        }
        info!(
            target: LOG_TARGET,
            signal = signals::last_signal(),
            ticks = summary.ticks,
            missed = summary.overruns,
            at_rest = summary.at_rest,
            plan_waits = summary.plan_waits,
            plan_wait_max_ms = summary.plan_wait_max as f64 * 1e-6,
            "stopped: final status published"
        );
        self.writer.join();
        if let Some(t) = self.tracer {
            t.join();
        }
        self.housekeeping.join();
        drop(self.runtime);
        self.planner.join();
        drop(self.command_service);
        drop(self.version_service);
        drop(self.node);
    }
}
