//! Opening the daemon's services (the daemon creates them; clients only
//! open them, SPEC §7.3).

use crate::error::{Error, Result};
use crate::options::ConnectOptions;
use iceoryx2::config::Config;
use iceoryx2::port::listener::Listener;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::prelude::*;
use iceoryx2::service::builder::event::EventOpenError;
use iceoryx2::service::builder::publish_subscribe::PublishSubscribeOpenError;
use shm_schema::ipc::IpcSettings;
use shm_schema::{Answer, Command, Event, SCHEMA_VERSION, ServiceNames, Status};
use std::time::{Duration, Instant};

/// The iceoryx2 service type.
pub type Ipc = ipc::Service;

/// How often `connect` looks again for services that do not exist yet.
const RETRY: Duration = Duration::from_millis(10);

/// One open connection: a node and its ports.
#[derive(Debug)]
pub(crate) struct Connection {
    pub commands: Publisher<Ipc, Command, ()>,
    pub answers: Subscriber<Ipc, Answer, ()>,
    pub status: Subscriber<Ipc, Status, ()>,
    pub events: Subscriber<Ipc, Event, ()>,
    pub listener: Listener<Ipc>,
    // Dropped last: the ports above first.
    _node: Node<Ipc>,
}

pub(crate) enum Attempt<T> {
    Done(T),
    Missing,
}

fn type_name<T: ZeroCopySend>() -> &'static str {
    // SAFETY: the derive returns a compile-time constant.
    unsafe { <T as ZeroCopySend>::type_name() }
}

pub(crate) fn open_pubsub<T>(node: &Node<Ipc>, name: &str) -> Result<Attempt<PubSubFactory<T>>>
where
    T: std::fmt::Debug + ZeroCopySend + Copy + 'static,
{
    let sn = ServiceName::new(name).map_err(|e| Error::Open {
        service: name.into(),
        why: format!("invalid service name: {e:?}"),
    })?;
    match node.service_builder(&sn).publish_subscribe::<T>().open() {
        Ok(f) => Ok(Attempt::Done(f)),
        Err(PublishSubscribeOpenError::DoesNotExist) => Ok(Attempt::Missing),
        Err(PublishSubscribeOpenError::IncompatibleTypes) => Err(Error::SchemaMismatch {
            service: name.into(),
            ours: type_name::<T>(),
            version: SCHEMA_VERSION,
        }),
        Err(e) => Err(Error::Open {
            service: name.into(),
            why: format!("{e:?}"),
        }),
    }
}

type PubSubFactory<T> = iceoryx2::service::port_factory::publish_subscribe::PortFactory<Ipc, T, ()>;

pub(crate) fn open_event(
    node: &Node<Ipc>,
    name: &str,
) -> Result<Attempt<iceoryx2::service::port_factory::event::PortFactory<Ipc>>> {
    let sn = ServiceName::new(name).map_err(|e| Error::Open {
        service: name.into(),
        why: format!("invalid service name: {e:?}"),
    })?;
    match node.service_builder(&sn).event().open() {
        Ok(f) => Ok(Attempt::Done(f)),
        Err(EventOpenError::DoesNotExist) => Ok(Attempt::Missing),
        Err(e) => Err(Error::Open {
            service: name.into(),
            why: format!("{e:?}"),
        }),
    }
}

/// The schema the daemon speaks, from its `version` service's attributes
/// (shm_schema `VERSION_ATTRIBUTE_SCHEMA`): `Done` when it is ours,
/// `Missing` when there is no such service (no daemon yet, or one of
/// schema v3 or older), the error naming both versions otherwise.
pub(crate) fn check_version(node: &Node<Ipc>, name: &str) -> Result<Attempt<()>> {
    use iceoryx2::service::attribute::AttributeKey;
    let Attempt::Done(f) = open_event(node, name)? else {
        return Ok(Attempt::Missing);
    };
    let value = |key: &str| {
        let key = AttributeKey::new(key.as_bytes()).ok()?;
        f.attributes().key_value(&key, 0).map(|v| v.to_string())
    };
    let schema = value(shm_schema::VERSION_ATTRIBUTE_SCHEMA);
    if schema.as_deref().and_then(|s| s.parse::<u32>().ok()) == Some(SCHEMA_VERSION) {
        return Ok(Attempt::Done(()));
    }
    let build = value(shm_schema::VERSION_ATTRIBUTE_BUILD).unwrap_or_else(|| "?".into());
    Err(Error::SchemaVersion {
        daemon: format!("v{} ({build})", schema.unwrap_or_else(|| "?".into())),
        ours: SCHEMA_VERSION,
    })
}

pub(crate) fn ipc_err(what: &'static str) -> impl Fn(&dyn std::fmt::Debug) -> Error {
    move |e| Error::Ipc {
        what,
        why: format!("{e:?}"),
    }
}

impl Connection {
    /// Opens every service, retrying while they do not exist yet, until
    /// `deadline`.
    pub fn open(
        opts: &ConnectOptions,
        config: &Config,
        settings: &IpcSettings,
        deadline: Instant,
    ) -> Result<Self> {
        let names = ServiceNames::new(&settings.service_prefix);
        let no_daemon = || Error::NoDaemon {
            prefix: settings.service_prefix.clone(),
            root: settings.root_path.clone(),
            waited: opts.timeout,
        };
        // No root directory: no daemon ever ran in this namespace.
        if !std::path::Path::new(&settings.root_path).is_dir() {
            wait_for_dir(&settings.root_path, deadline).ok_or_else(no_daemon)?;
        }
        let node_name = NodeName::new(&opts.node_name)
            .map_err(|e| Error::Settings(format!("node name {}: {e:?}", opts.node_name)))?;
        let node = NodeBuilder::new()
            .name(&node_name)
            .config(config)
            .signal_handling_mode(SignalHandlingMode::Disabled)
            .create::<Ipc>()
            .map_err(|e| ipc_err("node")(&e))?;
        loop {
            let attempt = match Self::try_open(&node, &names) {
                // A daemon that is still creating its services (iceoryx2:
                // HangsInCreation, IsMarkedForDestruction) opens on a
                // later try; the last reason is the answer at the deadline.
                Err(Error::Open { .. }) if Instant::now() < deadline => {
                    std::thread::sleep(RETRY);
                    continue;
                }
                other => other?,
            };
            match attempt {
                Attempt::Done(ports) => {
                    let (commands, answers, status, events, listener) = ports;
                    return Ok(Self {
                        commands,
                        answers,
                        status,
                        events,
                        listener,
                        _node: node,
                    });
                }
                Attempt::Missing if Instant::now() >= deadline => return Err(no_daemon()),
                Attempt::Missing => std::thread::sleep(RETRY),
            }
        }
    }

    #[allow(clippy::type_complexity)]
    fn try_open(
        node: &Node<Ipc>,
        names: &ServiceNames,
    ) -> Result<
        Attempt<(
            Publisher<Ipc, Command, ()>,
            Subscriber<Ipc, Answer, ()>,
            Subscriber<Ipc, Status, ()>,
            Subscriber<Ipc, Event, ()>,
            Listener<Ipc>,
        )>,
    > {
        // Which schema first: the other services' type names would only
        // say "incompatible".
        let versioned = matches!(check_version(node, &names.version)?, Attempt::Done(()));
        let cmd = match open_pubsub::<Command>(node, &names.commands) {
            Ok(Attempt::Done(cmd)) => cmd,
            Ok(Attempt::Missing) => return Ok(Attempt::Missing),
            // Services of another layout and no `version` service: a
            // daemon from before it existed.
            Err(Error::SchemaMismatch { .. }) if !versioned => {
                return Err(Error::SchemaVersion {
                    daemon: "v3 or older (it has no version service)".into(),
                    ours: SCHEMA_VERSION,
                });
            }
            Err(e) => return Err(e),
        };
        let Attempt::Done(ans) = open_pubsub::<Answer>(node, &names.answers)? else {
            return Ok(Attempt::Missing);
        };
        let Attempt::Done(st) = open_pubsub::<Status>(node, &names.status)? else {
            return Ok(Attempt::Missing);
        };
        let Attempt::Done(ev) = open_pubsub::<Event>(node, &names.events)? else {
            return Ok(Attempt::Missing);
        };
        let Attempt::Done(no) = open_event(node, &names.notify)? else {
            return Ok(Attempt::Missing);
        };
        let commands = cmd
            .publisher_builder()
            // A full daemon queue refuses the send (Error::Busy) instead of
            // blocking this client.
            .backpressure_strategy(BackpressureStrategy::DiscardData)
            .max_loaned_samples(1)
            .create()
            .map_err(|e| open_err(&names.commands, e))?;
        let answers = ans
            .subscriber_builder()
            .create()
            .map_err(|e| open_err(&names.answers, e))?;
        let status = st
            .subscriber_builder()
            // Latest value only: `Client::pump` takes one sample per pass.
            .buffer_size(1)
            .create()
            .map_err(|e| open_err(&names.status, e))?;
        let events = ev
            .subscriber_builder()
            .create()
            .map_err(|e| open_err(&names.events, e))?;
        let listener = no
            .listener_builder()
            .create()
            .map_err(|e| open_err(&names.notify, e))?;
        Ok(Attempt::Done((commands, answers, status, events, listener)))
    }
}

pub(crate) fn open_err(service: &str, e: impl std::fmt::Debug) -> Error {
    Error::Open {
        service: service.into(),
        why: format!("{e:?} (too many clients? see [ipc] max_clients)"),
    }
}

pub(crate) fn wait_for_dir(path: &str, deadline: Instant) -> Option<()> {
    loop {
        if std::path::Path::new(path).is_dir() {
            return Some(());
        }
        if Instant::now() >= deadline {
            return None;
        }
        std::thread::sleep(RETRY);
    }
}
