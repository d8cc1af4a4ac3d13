//! Schema versions (SPEC §7.3): a peer built against another payload
//! layout cannot open the services and gets a clear error instead of
//! misreading memory.

use gaitd_client::{Client, Error, Status};
use gaitd_tests::TestDaemon;
use iceoryx2::prelude::*;
use iceoryx2::service::builder::publish_subscribe::PublishSubscribeOpenError;
use std::time::Duration;

/// The status as a hypothetical schema v5 would name it (same bytes).
#[derive(Debug, Clone, Copy, ZeroCopySend)]
#[repr(C)]
#[type_name("gaitd::Status.v5")]
struct StatusV5 {
    bytes: [u64; 151],
}
const _: () = assert!(size_of::<StatusV5>() == size_of::<Status>());

/// Same name as v4 but another layout (a field added without a version bump).
#[derive(Debug, Clone, Copy, ZeroCopySend)]
#[repr(C)]
#[type_name("gaitd::Status.v4")]
struct StatusGrown {
    bytes: [u64; 152],
}

/// An old daemon's command type.
#[derive(Debug, Clone, Copy, ZeroCopySend)]
#[repr(C)]
#[type_name("gaitd::Command.v0")]
struct CommandV0 {
    kind: u32,
    pad: u32,
    goal: u64,
}

fn node(d: &TestDaemon) -> Node<ipc::Service> {
    let (config, _) = d.options().resolve().unwrap();
    NodeBuilder::new()
        .config(&config)
        .create::<ipc::Service>()
        .unwrap()
}

fn status_service(d: &TestDaemon) -> ServiceName {
    ServiceName::new(&format!("{}/status", d.prefix)).unwrap()
}

#[test]
fn another_schema_version_cannot_open_the_services() {
    let d = TestDaemon::start("schema-open");
    let _c = d.client(); // the daemon is up
    let n = node(&d);
    let v5 = n
        .service_builder(&status_service(&d))
        .publish_subscribe::<StatusV5>()
        .open();
    assert!(
        matches!(v5, Err(PublishSubscribeOpenError::IncompatibleTypes)),
        "{v5:?}"
    );
    let grown = n
        .service_builder(&status_service(&d))
        .publish_subscribe::<StatusGrown>()
        .open();
    assert!(
        matches!(grown, Err(PublishSubscribeOpenError::IncompatibleTypes)),
        "{grown:?}"
    );
    // The right type still opens.
    assert!(
        n.service_builder(&status_service(&d))
            .publish_subscribe::<Status>()
            .open()
            .is_ok()
    );
}

#[test]
fn the_client_library_reports_a_schema_mismatch_clearly() {
    // An "old daemon": its services carry schema v0 payload types.
    let d = TestDaemon::new("schema-old", "");
    std::fs::create_dir_all(&d.root).unwrap();
    let n = node(&d);
    let _old = n
        .service_builder(&ServiceName::new(&format!("{}/commands", d.prefix)).unwrap())
        .publish_subscribe::<CommandV0>()
        .create()
        .unwrap();
    let err = Client::connect(d.options().timeout(Duration::from_secs(2))).unwrap_err();
    assert!(matches!(err, Error::SchemaMismatch { .. }), "{err:?}");
    let msg = err.to_string();
    assert!(msg.contains("schema mismatch"), "{msg}");
    assert!(msg.contains(&format!("{}/commands", d.prefix)), "{msg}");
    assert!(msg.contains("gaitd::Command.v4"), "{msg}");
}

#[test]
fn a_stale_service_of_another_schema_is_replaced_at_start() {
    // Left over from a daemon of another schema version, still held open.
    let mut d = TestDaemon::new("schema-stale", "");
    std::fs::create_dir_all(&d.root).unwrap();
    let n = node(&d);
    let stale = n
        .service_builder(&status_service(&d))
        .publish_subscribe::<StatusV5>()
        .create()
        .unwrap();
    d.spawn();
    // A client racing the start-up could still open the stale service.
    d.wait_ready(Duration::from_secs(10));
    let mut c = d.client();
    let s = c.wait_status(Duration::from_secs(5)).unwrap();
    s.check().unwrap();
    let log = d.log();
    assert!(log.contains("is incompatible; removing it"), "{log}");
    drop(stale);
}
