//! `gaitd` command line: load the config, set up IPC and the process, run
//! the loop on the main thread (SPEC §7).
//!
//! Start-up order matters: services and ports first (so `READY=1` means
//! clients can connect), then memory locking (it locks the shared memory
//! just mapped), then the background threads (before the main thread turns
//! SCHED_FIFO, so they do not inherit it), then `READY=1` and the loop.

use anyhow::{Context, Result};
use clap::Parser;
use gaitd::control::gait_controller::{GaitController, GaitPlanner};
use gaitd::io::housekeeping::{self, HousekeepingSetup};
use gaitd::io::{ipc, outbox};
use gaitd::plant::external::ExternalPlant;
use gaitd::plant::ports::PlantInput;
use gaitd::process::config::{DEFAULT_CONFIG_PATH, DaemonConfig};
use gaitd::process::logging::{self, LogFormat};
use gaitd::process::{rt, sd_notify, signals};
use gaitd::realtime::clock::MonotonicClock;
use gaitd::realtime::runtime::{Runtime, Shared};
use iceoryx2::prelude::{LogLevel, set_log_level_from_env_or};
use shm_schema::ipc::DAEMON_NODE_NAME;
use std::sync::Arc;
use std::time::Duration;
use tracing::{info, warn};

/// gaitd: real-time finger-gaiting controller daemon.
#[derive(Parser, Debug)]
#[command(version, about)]
struct Args {
    /// Configuration file (TOML).
    #[arg(long, default_value = DEFAULT_CONFIG_PATH)]
    config: String,
    /// Validate the configuration file, print the effective configuration and exit.
    #[arg(long)]
    check_config: bool,
    /// Log format.
    #[arg(long, value_enum, default_value_t = LogFormat::Human)]
    log_format: LogFormat,
    /// Log level (`RUST_LOG` overrides it).
    #[arg(long, default_value = "info")]
    log_level: String,
}

fn main() -> Result<()> {
    let args = Args::parse();
    if args.config == DEFAULT_CONFIG_PATH && !std::path::Path::new(&args.config).exists() {
        anyhow::bail!(
            "no configuration at {} (the service's default): pass --config FILE, \
             e.g. `gaitd --config deploy/gaitd.toml` from the source tree, or install \
             the service with deploy/install.sh",
            args.config
        );
    }
    let cfg = DaemonConfig::load(&args.config)?;
    if args.check_config {
        // Print the effective values, derived defaults included.
        let mut shown = cfg.clone();
        shown.rt.writer_priority = Some(cfg.rt.writer_fifo_priority());
        println!("{}", toml::to_string_pretty(&shown)?);
        // Also resolve where the iceoryx2 resources will live (loads the
        // iceoryx2 config file if one is named, so a bad one fails here).
        let (_, ipc) = ipc::resolve(&cfg.ipc)?;
        eprintln!(
            "ipc: service prefix {}, iceoryx2 root {}, file prefix {}",
            ipc.service_prefix, ipc.root_path, ipc.file_prefix
        );
        eprintln!("config OK: {}", args.config);
        return Ok(());
    }
    logging::init(args.log_format, &args.log_level);
    // iceoryx2 prints its own diagnostics; keep them to real errors unless asked.
    set_log_level_from_env_or(LogLevel::Error);
    let stop = signals::install().context("installing SIGTERM/SIGINT handlers")?;

    let (ice_config, settings) = ipc::resolve(&cfg.ipc)?;
    let node = ipc::create_node(DAEMON_NODE_NAME, &ice_config)?;
    let daemon_node = *node.id();
    let services = ipc::create_services(&node, &cfg, &settings.service_prefix)?;
    let names = services.names.clone();
    let commands = services.command_subscriber(cfg.ipc.command_queue as usize)?;
    // An external plant's ports live on the loop thread (this one).
    let plant_ports = match &services.plant_in {
        Some(p) => Some(p.ports(&services.names)?),
        None => None,
    };
    let instance = gaitd::new_instance_id();
    let shared = Arc::new(Shared::default());
    // The writer rings the planner's doorbell after each tick, so the loop
    // never wakes the planner thread itself (planner module docs).
    let planner_bell = Arc::new(gaitd::control::planner::Doorbell::default());
    let (outbox, writer) = outbox::spawn(
        services.out,
        names.clone(),
        outbox::WriterSettings {
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
        prefix = %settings.service_prefix,
        root = %settings.root_path,
        file_prefix = %settings.file_prefix,
        tick_hz = cfg.control.tick_hz,
        "iceoryx2 services up"
    );

    if cfg.rt.lock_memory {
        match rt::lock_memory() {
            Ok(()) => info!("memory locked (mlockall)"),
            Err(e) => warn!("real-time: {e}; continuing without"),
        }
    }

    let sd = sd_notify::Notifier::from_env().context("connecting to $NOTIFY_SOCKET")?;
    let sd_status = sd_notify::Notifier::from_env().ok().flatten();
    let hk = housekeeping::spawn(HousekeepingSetup {
        config: ice_config.clone(),
        names,
        daemon_node,
        shared: shared.clone(),
        period: Duration::from_millis(cfg.daemon.housekeeping_period_ms.into()),
        sd: sd_status,
        cpus: cfg.rt.background_cpus.clone(),
    })
    .context("starting the housekeeping thread")?;

    // The planner thread, then the controller: planner + executor + the
    // embedded kinematic hand (SPEC §6.2, §7.2).
    let planner = gait::planner::Planner::new(&cfg.hand()).context("building the planner")?;
    let background = cfg.rt.background_cpus.clone();
    let (mut link, planner_thread) =
        gaitd::control::planner::spawn(GaitPlanner(planner), 4, move || {
            let _ = gaitd::process::rt::pin_current_thread(&background);
        })
        .context("starting the planner thread")?;
    link.wake_through(planner_bell);
    let dt = 1.0 / cfg.control.tick_hz;
    let mut controller = if cfg.plant.external() {
        let plant = ExternalPlant::new(instance, cfg.period_ns(), &cfg.plant);
        GaitController::new_external(&cfg.hand(), dt, link, plant)
    } else {
        GaitController::new(&cfg.hand(), dt, link)
    }
    .context("building the controller")?;
    // Goal traces (SPEC §8): the loop copies samples into a ring, the
    // trace thread formats and writes them.
    let tracer = if cfg.daemon.trace_dir.is_empty() {
        None
    } else {
        let (recorder, tracer) = gaitd::io::tracer::spawn(
            gaitd::io::tracer::TraceSettings {
                dir: cfg.daemon.trace_dir.clone().into(),
                instance,
                hand: cfg.hand(),
                dt: 1.0 / cfg.control.tick_hz,
                cpus: cfg.rt.background_cpus.clone(),
                keep: cfg.daemon.trace_keep as usize,
            },
            gaitd::io::tracer::DEFAULT_CAPACITY,
        )?;
        controller.set_trace(recorder);
        info!(dir = %cfg.daemon.trace_dir, "recording a trace of every goal");
        Some(tracer)
    };
    let mut runtime = Runtime::new(
        commands,
        outbox,
        controller,
        MonotonicClock,
        &cfg,
        instance,
        shared,
    );
    if let Some(p) = plant_ports {
        runtime.set_plant(PlantInput::new(p));
        info!(
            timing = ?cfg.plant.timing,
            "external plant: waiting for its first valid measurement"
        );
    }
    if let (Some(period), Some(_)) = (sd_notify::watchdog_period(), &sd) {
        let n = sd_notify::Notifier::from_env()?.context("NOTIFY_SOCKET vanished")?;
        runtime.set_watchdog(n, period.as_nanos() as u64 / 2);
        info!(
            ?period,
            "systemd watchdog fed from the loop every half period"
        );
    }

    // The main thread becomes the loop thread.
    if let Err(e) = rt::pin_current_thread(&cfg.rt.loop_cpus) {
        warn!(cpus = ?cfg.rt.loop_cpus, "real-time: cannot pin the loop thread: {e}; continuing unpinned");
    }
    let (loop_priority, writer_priority) = (cfg.rt.fifo_priority, cfg.rt.writer_fifo_priority());
    let fifo =
        rt::raise_loop_then_writer(loop_priority, writer_priority, rt::set_fifo_priority, |p| {
            writer.set_fifo_priority(p)
        });
    match fifo.loop_thread {
        Some(Ok(())) => info!(priority = loop_priority, "loop thread runs SCHED_FIFO"),
        Some(Err(e)) => warn!(
            priority = loop_priority,
            "real-time: SCHED_FIFO not permitted ({e}); loop and writer run with normal \
             scheduling (grant LimitRTPRIO/CAP_SYS_NICE)"
        ),
        None if cfg.rt.writer_priority.is_some_and(|p| p > 0) => warn!(
            "rt.writer_priority is ignored: the loop runs normal scheduling (rt.fifo_priority = 0)"
        ),
        None => {}
    }
    match fifo.writer {
        Some(Ok(())) => info!(priority = writer_priority, "writer thread runs SCHED_FIFO"),
        Some(Err(e)) => warn!(
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

    if let Some(sd) = &sd {
        let _ = sd.ready();
        let _ = sd.status("running");
    }
    info!(instance = format!("{instance:016x}"), "ready");
    let summary = runtime.run(stop);
    if let Some(sd) = &sd {
        let _ = sd.stopping();
    }
    info!(
        signal = signals::last_signal(),
        ticks = summary.ticks,
        missed = summary.overruns,
        at_rest = summary.at_rest,
        "stopped: final status published"
    );
    writer.join();
    if let Some(t) = tracer {
        t.join();
    }
    hk.join();
    drop(runtime);
    planner_thread.join();
    drop(services.commands);
    drop(node);
    Ok(())
}
