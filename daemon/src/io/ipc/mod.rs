//! The daemon's iceoryx2 services and ports (SPEC §7.3).
//!
//! The daemon creates every service, so its limits win; clients only open
//! them. Commands travel on a publish-subscribe service rather than
//! request-response because iceoryx2 0.10's `Server::receive` allocates an
//! `Arc` per request, which the loop thread must not do (checked by the
//! allocation test); answers go back on their own publish-subscribe service
//! and clients match them by `(client_id, request_id)`.
//!
//! Restart after a crash: a service still held open by clients of the dead
//! daemon is adopted when it is compatible (its dead ports were removed by
//! dead-node cleanup at node creation); an incompatible or corrupted one
//! (another schema version, other limits) is removed by force and created
//! anew, and its old clients must reconnect.
//!
//! Where the resources live (root path, file prefix, service prefix) is
//! resolved in `resolve.rs`.

mod resolve;

pub use resolve::{IpcOrigins, Origin, ResolvedIpc, resolve, resolve_explained};

use crate::config::DaemonConfig;
use iceoryx2::config::Config;
use iceoryx2::node::NodeBuilder;
use iceoryx2::port::listener::Listener;
use iceoryx2::port::notifier::Notifier;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::prelude::*;
use iceoryx2::service::builder::event::EventCreateError;
use iceoryx2::service::builder::publish_subscribe::PublishSubscribeCreateError;
use shm_schema::ipc::IpcSettingsError;
use shm_schema::{
    Answer, Command, EVENT_ID_DAEMON_DEAD, EVENT_ID_MAX, Event, PlanPath, PlantCommand,
    PlantMeasurement, ServiceNames, Status,
};
use tracing::{info, warn};

/// The iceoryx2 service type used everywhere (inter-process, not thread-safe ports).
pub type Ipc = ipc::Service;

/// Why the IPC setup failed. Messages name the service and what to check.
#[derive(Debug, thiserror::Error)]
pub enum IpcError {
    /// The settings (prefix, root path, file prefix) are unusable.
    #[error("ipc settings: {0}")]
    Settings(#[from] shm_schema::ipc::IpcSettingsError),
    /// One resolved setting is unusable; says where it came from.
    #[error("ipc settings: `{value}` ({origin}): {error}")]
    BadSetting {
        /// What is wrong.
        error: IpcSettingsError,
        /// The value.
        value: String,
        /// Where it came from.
        origin: Origin,
    },
    /// The iceoryx2 config file could not be loaded.
    #[error("cannot load iceoryx2 config {path}: {why}")]
    ConfigFile {
        /// Path as given.
        path: String,
        /// iceoryx2's error.
        why: String,
    },
    /// The root path could not be created.
    #[error("cannot create iceoryx2 root path {path}: {source}")]
    RootPath {
        /// The path.
        path: String,
        /// The OS error.
        source: std::io::Error,
    },
    /// The iceoryx2 node could not be created.
    #[error(
        "cannot create iceoryx2 node under {root}: {why} (is the root path writable by this user?)"
    )]
    Node {
        /// Root path.
        root: String,
        /// iceoryx2's error.
        why: String,
    },
    /// A service or port could not be created.
    #[error("service {service}: {why}")]
    Service {
        /// Service name.
        service: String,
        /// What failed.
        why: String,
    },
}

/// Creates the node `name` under `config` (cleaning up dead nodes of
/// earlier runs, which iceoryx2 does on node creation).
pub fn create_node(name: &str, config: &Config) -> Result<Node<Ipc>, IpcError> {
    let root = config.global.root_path().to_string();
    std::fs::create_dir_all(&root).map_err(|source| IpcError::RootPath {
        path: root.clone(),
        source,
    })?;
    let node_name = NodeName::new(name).map_err(|e| IpcError::Node {
        root: root.clone(),
        why: format!("bad node name {name}: {e:?}"),
    })?;
    let node = NodeBuilder::new()
        .name(&node_name)
        .config(config)
        // The daemon handles SIGTERM/SIGINT itself (signals module).
        .signal_handling_mode(SignalHandlingMode::Disabled)
        .create::<Ipc>()
        .map_err(|e| IpcError::Node {
            root,
            why: format!("{e:?}"),
        })?;
    let cleaned = node.try_cleanup_dead_nodes();
    if cleaned.cleanups > 0 {
        info!(
            nodes = cleaned.cleanups,
            "cleaned up dead iceoryx2 nodes of an earlier run"
        );
    }
    Ok(node)
}

fn service_name(name: &str) -> Result<ServiceName, IpcError> {
    ServiceName::new(name).map_err(|e| IpcError::Service {
        service: name.to_owned(),
        why: format!("invalid service name: {e:?}"),
    })
}

fn err(service: &str, what: &str, e: impl std::fmt::Debug) -> IpcError {
    IpcError::Service {
        service: service.to_owned(),
        why: format!("{what}: {e:?}"),
    }
}

/// Creates a service, or adopts the one clients of a dead daemon still
/// hold, or replaces it when incompatible (see module docs).
fn create_or_adopt<F, E1, E2>(
    node: &Node<Ipc>,
    name: &str,
    pattern: MessagingPattern,
    create: impl Fn() -> Result<F, E1>,
    open: impl Fn() -> Result<F, E2>,
    already_exists: impl Fn(&E1) -> bool,
) -> Result<F, IpcError>
where
    E1: std::fmt::Debug,
    E2: std::fmt::Debug,
{
    match create() {
        Ok(f) => return Ok(f),
        Err(e) if !already_exists(&e) => return Err(err(name, "create", e)),
        Err(_) => {}
    }
    match open() {
        Ok(f) => {
            warn!(
                service = name,
                "adopted a service left by an earlier daemon (clients still attached)"
            );
            Ok(f)
        }
        Err(e) => {
            warn!(service = name, error = ?e, "service left by an earlier daemon is incompatible; removing it");
            let sn = service_name(name)?;
            // SAFETY: the daemon owns this prefix; clients of the old
            // service fail and reconnect.
            unsafe { node.force_remove_service(&sn, pattern) }
                .map_err(|e| err(name, "force remove", e))?;
            create().map_err(|e| err(name, "create after removal", e))
        }
    }
}

type PubSub<T> = iceoryx2::service::port_factory::publish_subscribe::PortFactory<Ipc, T, ()>;
type EventSvc = iceoryx2::service::port_factory::event::PortFactory<Ipc>;

/// An event service of the daemon's.
pub type EventService = EventSvc;

/// The `plan` service: each plan's path (the planner thread publishes).
pub type PlanPathService = PubSub<PlanPath>;

/// The daemon's services. iceoryx2 ports cannot move between threads but
/// services can: each thread builds its own ports from these.
#[derive(Debug)]
pub struct DaemonServices {
    /// The schema version and build, as attributes (held open while the
    /// daemon runs).
    pub version: EventSvc,
    /// client → daemon commands.
    pub commands: PubSub<Command>,
    /// Services the writer thread publishes on.
    pub out: OutServices,
    /// Plan paths (the planner thread publishes).
    pub plan: PlanPathService,
    /// plant → daemon services (an external plant only).
    pub plant_in: Option<PlantInServices>,
    /// Service names.
    pub names: ServiceNames,
}

/// The plant → daemon services: measurements and their wake-up.
#[derive(Debug)]
pub struct PlantInServices {
    /// Measurements.
    pub measurement: PubSub<PlantMeasurement>,
    /// "A measurement was published".
    pub measured: EventSvc,
}

/// The loop thread's plant ports: it receives measurements (and in
/// lockstep waits for their wake-up).
#[derive(Debug)]
pub struct PlantInPorts {
    /// Measurements.
    pub measurements: Subscriber<Ipc, PlantMeasurement, ()>,
    /// Their wake-ups.
    pub measured: Listener<Ipc>,
}

impl PlantInServices {
    /// Creates the loop's ports (on the calling thread).
    pub fn ports(&self, names: &ServiceNames) -> Result<PlantInPorts, IpcError> {
        Ok(PlantInPorts {
            measurements: self
                .measurement
                .subscriber_builder()
                .buffer_size(PLANT_BUFFER)
                .create()
                .map_err(|e| err(&names.plant_measurement, "subscriber", e))?,
            measured: self
                .measured
                .listener_builder()
                .create()
                .map_err(|e| err(&names.plant_measured, "listener", e))?,
        })
    }
}

/// Samples a plant-service subscriber keeps: the loop reads every tick and
/// takes the newest, so a few are enough (safe overflow drops the oldest).
pub const PLANT_BUFFER: usize = 2;

/// The services of the daemon → clients direction.
#[derive(Debug)]
pub struct OutServices {
    /// Answers.
    pub answers: PubSub<Answer>,
    /// Status (latest value).
    pub status: PubSub<Status>,
    /// Events (with history).
    pub events: PubSub<Event>,
    /// Wake-ups.
    pub notify: EventSvc,
    /// daemon → plant services (an external plant only).
    pub plant: Option<PlantOutServices>,
}

/// The daemon → plant services: commands and their wake-up.
#[derive(Debug)]
pub struct PlantOutServices {
    /// Commands.
    pub command: PubSub<PlantCommand>,
    /// "A command was published".
    pub commanded: EventSvc,
}

/// The writer's plant ports.
#[derive(Debug)]
pub struct PlantOutPorts {
    /// Commands.
    pub command: Publisher<Ipc, PlantCommand, ()>,
    /// Their wake-up.
    pub commanded: Notifier<Ipc>,
}

/// The writer thread's ports (see `outbox`).
#[derive(Debug)]
pub struct OutPorts {
    /// Answers.
    pub answers: Publisher<Ipc, Answer, ()>,
    /// Status.
    pub status: Publisher<Ipc, Status, ()>,
    /// Events.
    pub events: Publisher<Ipc, Event, ()>,
    /// Wake-ups.
    pub notifier: Notifier<Ipc>,
    /// Plant commands (an external plant only).
    pub plant: Option<PlantOutPorts>,
}

impl OutServices {
    /// Creates the publishers and the notifier (on the calling thread).
    pub fn ports(&self, names: &ServiceNames) -> Result<OutPorts, IpcError> {
        let busy = "publisher (is another gaitd running with this prefix?)";
        Ok(OutPorts {
            answers: self
                .answers
                .publisher_builder()
                .max_loaned_samples(1)
                .create()
                .map_err(|e| err(&names.answers, busy, e))?,
            status: self
                .status
                .publisher_builder()
                .max_loaned_samples(1)
                .create()
                .map_err(|e| err(&names.status, busy, e))?,
            events: self
                .events
                .publisher_builder()
                .max_loaned_samples(1)
                .create()
                .map_err(|e| err(&names.events, busy, e))?,
            notifier: self.notify.notifier_builder().create().map_err(|e| {
                err(
                    &names.notify,
                    "notifier (is another gaitd running with this prefix?)",
                    e,
                )
            })?,
            plant: match &self.plant {
                None => None,
                Some(p) => Some(PlantOutPorts {
                    command: p
                        .command
                        .publisher_builder()
                        .max_loaned_samples(1)
                        .create()
                        .map_err(|e| err(&names.plant_command, busy, e))?,
                    commanded: p
                        .commanded
                        .notifier_builder()
                        .create()
                        .map_err(|e| err(&names.plant_commanded, busy, e))?,
                }),
            },
        })
    }
}

impl DaemonServices {
    /// The loop's command subscriber (on the calling thread).
    pub fn command_subscriber(
        &self,
        queue: usize,
    ) -> Result<Subscriber<Ipc, Command, ()>, IpcError> {
        self.commands
            .subscriber_builder()
            .buffer_size(queue)
            .create()
            .map_err(|e| {
                err(
                    &self.names.commands,
                    "subscriber (is another gaitd running with this prefix?)",
                    e,
                )
            })
    }
}

/// Creates (or adopts, see module docs) every service under `prefix`.
pub fn create_services(
    node: &Node<Ipc>,
    cfg: &DaemonConfig,
    prefix: &str,
) -> Result<DaemonServices, IpcError> {
    let names = ServiceNames::new(prefix);
    let ipc = &cfg.ipc;
    let clients = ipc.max_clients as usize;
    // Clients, the daemon, its housekeeping node, and room for one
    // reconnecting client whose dead node is not yet cleaned up.
    let nodes = clients + 3;
    // First: a client that finds the other services finds this one too.
    let version = version_service(node, &names.version, nodes)?;

    let n = &names.commands;
    let sn = service_name(n)?;
    let build = || {
        node.service_builder(&sn)
            .publish_subscribe::<Command>()
            .max_publishers(clients)
            .max_subscribers(1)
            .max_nodes(nodes)
            .subscriber_max_buffer_size(ipc.command_queue as usize)
            // A full queue refuses the client's send instead of silently
            // dropping an older command.
            .enable_safe_overflow(false)
    };
    let commands = create_or_adopt(
        node,
        n,
        MessagingPattern::PublishSubscribe,
        || build().history_size(0).create(),
        || build().open(),
        |e| matches!(e, PublishSubscribeCreateError::AlreadyExists),
    )?;

    let answers = out_service::<Answer>(
        node,
        &names.answers,
        clients,
        nodes,
        0,
        ipc.answer_buffer as usize,
    )?;
    // One more reader: the daemon's housekeeping.
    let status = out_service::<Status>(node, &names.status, clients + 1, nodes, 1, 1)?;
    let events = out_service::<Event>(
        node,
        &names.events,
        clients,
        nodes,
        ipc.event_history as usize,
        ipc.event_buffer as usize,
    )?;
    // The latest plan's path; a view that opens later gets it at once.
    let plan = out_service::<PlanPath>(node, &names.plan, clients, nodes, 1, 1)?;

    let n = &names.notify;
    let sn = service_name(n)?;
    let build = || {
        node.service_builder(&sn)
            .event()
            .max_notifiers(1)
            .max_listeners(clients + 1)
            .max_nodes(nodes)
            .event_id_max_value(EVENT_ID_MAX)
            .notifier_dead_event(EventId::new(EVENT_ID_DAEMON_DEAD))
    };
    let notify = create_or_adopt(
        node,
        n,
        MessagingPattern::Event,
        || build().create(),
        || build().open(),
        |e| matches!(e, EventCreateError::AlreadyExists),
    )?;

    let (plant, plant_in) = if cfg.plant.external() {
        let (out, inp) = create_plant_services(node, &names)?;
        (Some(out), Some(inp))
    } else {
        (None, None)
    };
    Ok(DaemonServices {
        version,
        commands,
        out: OutServices {
            answers,
            status,
            events,
            notify,
            plant,
        },
        plan,
        plant_in,
        names,
    })
}

/// The daemon's build, as the `version` service states it.
pub const BUILD: &str = concat!("gaitd ", env!("CARGO_PKG_VERSION"));

/// The `version` event service (shm_schema `VERSION_ATTRIBUTE_SCHEMA`): no
/// payload, no ports; its attributes say which schema this daemon speaks.
/// One left by a daemon of another build is replaced.
fn version_service(node: &Node<Ipc>, name: &str, nodes: usize) -> Result<EventSvc, IpcError> {
    use iceoryx2::service::attribute::{AttributeKey, AttributeValue};
    let attr = |k: &str, v: &str| -> Result<(AttributeKey, AttributeValue), IpcError> {
        let bad = |e| err(name, "attribute", e);
        Ok((
            AttributeKey::new(k.as_bytes()).map_err(bad)?,
            AttributeValue::new(v.as_bytes()).map_err(bad)?,
        ))
    };
    let schema = attr(
        shm_schema::VERSION_ATTRIBUTE_SCHEMA,
        &shm_schema::SCHEMA_VERSION.to_string(),
    )?;
    let build = attr(shm_schema::VERSION_ATTRIBUTE_BUILD, BUILD)?;
    let spec = AttributeSpecifier::new()
        .define(&schema.0, &schema.1)
        .and_then(|s| s.define(&build.0, &build.1))
        .map_err(|e| err(name, "attributes", e))?;
    let verify = AttributeVerifier::new()
        .require(&schema.0, &schema.1)
        .and_then(|v| v.require(&build.0, &build.1))
        .map_err(|e| err(name, "attributes", e))?;
    let sn = service_name(name)?;
    let build = || {
        node.service_builder(&sn)
            .event()
            .max_notifiers(1)
            .max_listeners(1)
            .max_nodes(nodes)
    };
    create_or_adopt(
        node,
        name,
        MessagingPattern::Event,
        || build().create_with_attributes(&spec),
        || build().open_with_attributes(&verify),
        |e| matches!(e, EventCreateError::AlreadyExists),
    )
}

/// The four plant services (shm_schema `PLANT-GUIDE.md`): one plant, plus
/// room for a restarted plant while its dead predecessor is not yet
/// cleaned up, and one observer (a recorder or monitor).
fn create_plant_services(
    node: &Node<Ipc>,
    names: &ServiceNames,
) -> Result<(PlantOutServices, PlantInServices), IpcError> {
    // The daemon, the plant, a restarted plant, an observer, housekeeping.
    let nodes = 5;
    // Commands: a late or restarted plant gets the last one at once.
    let command =
        out_service::<PlantCommand>(node, &names.plant_command, 2, nodes, 1, PLANT_BUFFER)?;
    let sn = service_name(&names.plant_measurement)?;
    let build = || {
        node.service_builder(&sn)
            .publish_subscribe::<PlantMeasurement>()
            .max_publishers(2)
            .max_subscribers(2)
            .max_nodes(nodes)
            .history_size(0)
            .subscriber_max_buffer_size(PLANT_BUFFER)
            .enable_safe_overflow(true)
    };
    let measurement = create_or_adopt(
        node,
        &names.plant_measurement,
        MessagingPattern::PublishSubscribe,
        || build().create(),
        || build().open(),
        |e| matches!(e, PublishSubscribeCreateError::AlreadyExists),
    )?;
    let event = |name: &str, notifiers: usize, listeners: usize| {
        let sn = service_name(name)?;
        let build = || {
            node.service_builder(&sn)
                .event()
                .max_notifiers(notifiers)
                .max_listeners(listeners)
                .max_nodes(nodes)
                .event_id_max_value(EVENT_ID_MAX)
        };
        create_or_adopt(
            node,
            name,
            MessagingPattern::Event,
            || build().create(),
            || build().open(),
            |e| matches!(e, EventCreateError::AlreadyExists),
        )
    };
    let commanded = event(&names.plant_commanded, 1, 2)?;
    let measured = event(&names.plant_measured, 2, 1)?;
    Ok((
        PlantOutServices { command, commanded },
        PlantInServices {
            measurement,
            measured,
        },
    ))
}

/// A daemon → clients publish-subscribe service with one publisher.
fn out_service<T>(
    node: &Node<Ipc>,
    name: &str,
    subscribers: usize,
    nodes: usize,
    history: usize,
    buffer: usize,
) -> Result<PubSub<T>, IpcError>
where
    T: std::fmt::Debug + ZeroCopySend + Copy + 'static,
{
    let sn = service_name(name)?;
    let build = || {
        node.service_builder(&sn)
            .publish_subscribe::<T>()
            .max_publishers(1)
            .max_subscribers(subscribers)
            .max_nodes(nodes)
            .history_size(history)
            .subscriber_max_buffer_size(buffer)
            .enable_safe_overflow(true)
    };
    create_or_adopt(
        node,
        name,
        MessagingPattern::PublishSubscribe,
        || build().create(),
        || build().open(),
        |e| matches!(e, PublishSubscribeCreateError::AlreadyExists),
    )
}

/// A status subscriber for the daemon's own housekeeping thread (it reads
/// the status like a client, for `STATUS=` texts).
pub fn status_subscriber(
    node: &Node<Ipc>,
    names: &ServiceNames,
) -> Result<Subscriber<Ipc, Status, ()>, IpcError> {
    let sn = service_name(&names.status)?;
    let svc = node
        .service_builder(&sn)
        .publish_subscribe::<Status>()
        .open()
        .map_err(|e| err(&names.status, "open", e))?;
    let sub = svc
        .subscriber_builder()
        .buffer_size(1)
        .create()
        .map_err(|e| err(&names.status, "subscriber", e))?;
    Ok(sub)
}

#[cfg(test)]
mod tests {
    use super::*;
    use iceoryx2::service::port_factory::PortFactory;
    use iceoryx2::service::static_config::publish_subscribe::StaticConfig;
    use shm_schema::ipc::IpcSettings;

    /// `shm_schema/CLIENT-GUIDE.md` states the settings of the services the
    /// daemon creates with the default `[ipc]`: checked here against the
    /// services themselves, created in a namespace of this test's own.
    #[test]
    fn the_client_guide_states_the_service_settings() {
        let guide = include_str!("../../../../shm_schema/CLIENT-GUIDE.md");
        let cfg = DaemonConfig::default();
        let pid = std::process::id();
        let dir = std::env::temp_dir().join(format!("gaitd-ipc-guide-{pid}"));
        let settings = IpcSettings {
            service_prefix: format!("guide-{pid}"),
            root_path: format!("{}/iceoryx2/", dir.display()),
            file_prefix: format!("gguide{pid}_"),
        };
        let mut config = Config::default();
        settings.apply(&mut config).unwrap();
        let node = create_node("gaitd-guide-test", &config).unwrap();
        let s = create_services(&node, &cfg, &settings.service_prefix).unwrap();
        let row = |name: &str, payload: &str, c: &StaticConfig| {
            let overflow = if c.has_safe_overflow() { "yes" } else { "no" };
            format!(
                "| `<prefix>/{name}` | `{payload}` | {} | {} | {} | {} | {} | {overflow}",
                c.max_publishers(),
                c.max_subscribers(),
                c.max_nodes(),
                c.history_size(),
                c.subscriber_max_buffer_size()
            )
        };
        let n = s.out.notify.static_config();
        let v = s.version.static_config();
        let mut want = vec![
            format!(
                "| `<prefix>/version` | event | {} | {} | {} | {} | {} |",
                v.max_notifiers(),
                v.max_listeners(),
                v.max_nodes(),
                v.event_id_max_value(),
                v.notifier_dead_event().map_or(0, |e| e.as_value())
            ),
            row("commands", "Command", s.commands.static_config()),
            row("answers", "Answer", s.out.answers.static_config()),
            row("status", "Status", s.out.status.static_config()),
            row("events", "Event", s.out.events.static_config()),
            format!(
                "| `<prefix>/notify` | event | {} | {} | {} | {} | {} |",
                n.max_notifiers(),
                n.max_listeners(),
                n.max_nodes(),
                n.event_id_max_value(),
                n.notifier_dead_event().map_or(0, |e| e.as_value())
            ),
        ];
        let ipc = &cfg.ipc;
        want.push(format!(
            "(`max_clients` = N = {}, `command_queue` = {},\n`answer_buffer` = {}, \
             `event_history` = {}, `event_buffer` = {})",
            ipc.max_clients,
            ipc.command_queue,
            ipc.answer_buffer,
            ipc.event_history,
            ipc.event_buffer
        ));
        drop(s);
        drop(node);
        let _ = std::fs::remove_dir_all(&dir);
        if let Ok(shm) = std::fs::read_dir("/dev/shm") {
            for e in shm.flatten() {
                if e.file_name()
                    .to_string_lossy()
                    .starts_with(&settings.file_prefix)
                {
                    let _ = std::fs::remove_file(e.path());
                }
            }
        }
        for w in want {
            assert!(
                guide.contains(&w),
                "shm_schema/CLIENT-GUIDE.md is out of date: it should say\n{w}"
            );
        }
    }
}
