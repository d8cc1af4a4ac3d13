//! Schema versions (SPEC §7.3): a peer built against another payload
//! layout cannot open the services and gets a clear error instead of
//! misreading memory — naming both versions: the daemon's, from its
//! unversioned `version` service (LAYOUT.md, "Schema versions"), and its
//! own. The Rust client, `gaitctl` and the Python package say it alike.

mod python_support;

use gaitd_client::{Client, Error, Status};
use gaitd_tests::{TestDaemon, output_within};
use iceoryx2::prelude::*;
use iceoryx2::service::attribute::{AttributeKey, AttributeValue};
use iceoryx2::service::builder::publish_subscribe::PublishSubscribeOpenError;
use std::time::Duration;

/// The status as a hypothetical schema v9 would name it (same bytes).
#[derive(Debug, Clone, Copy, ZeroCopySend)]
#[repr(C)]
#[type_name("gaitd::Status.v9")]
struct StatusV9 {
    bytes: [u64; 175],
}
const _: () = assert!(size_of::<StatusV9>() == size_of::<Status>());

/// Same name as v8 but another layout (a field added without a version bump).
#[derive(Debug, Clone, Copy, ZeroCopySend)]
#[repr(C)]
#[type_name("gaitd::Status.v8")]
struct StatusGrown {
    bytes: [u64; 176],
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
    let v9 = n
        .service_builder(&status_service(&d))
        .publish_subscribe::<StatusV9>()
        .open();
    assert!(
        matches!(v9, Err(PublishSubscribeOpenError::IncompatibleTypes)),
        "{v9:?}"
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
fn a_daemon_without_a_version_service_is_named_v3_or_older() {
    // An "old daemon": its services carry schema v0 payload types, and it
    // has no `version` service (those came with v4).
    let d = TestDaemon::new("schema-old", "");
    std::fs::create_dir_all(&d.root).unwrap();
    let n = node(&d);
    let _old = n
        .service_builder(&ServiceName::new(&format!("{}/commands", d.prefix)).unwrap())
        .publish_subscribe::<CommandV0>()
        .create()
        .unwrap();
    let err = Client::connect(d.options().timeout(Duration::from_secs(2))).unwrap_err();
    assert!(matches!(err, Error::SchemaVersion { .. }), "{err:?}");
    let msg = err.to_string();
    assert!(
        msg.contains("the daemon speaks schema v3 or older") && msg.contains("this client v8"),
        "{msg}"
    );
}

/// A daemon of schema v9 as a v8 client meets it: a `version` service
/// that says so, and services whose type names a v8 client cannot open.
fn fake_v9_daemon(d: &TestDaemon, n: &Node<ipc::Service>) -> impl Sized {
    let key = |k: &str| AttributeKey::new(k.as_bytes()).unwrap();
    let value = |v: &str| AttributeValue::new(v.as_bytes()).unwrap();
    let spec = AttributeSpecifier::new()
        .define(&key(shm_schema::VERSION_ATTRIBUTE_SCHEMA), &value("9"))
        .unwrap()
        .define(
            &key(shm_schema::VERSION_ATTRIBUTE_BUILD),
            &value("gaitd 9.9.9"),
        )
        .unwrap();
    let version = n
        .service_builder(&ServiceName::new(&format!("{}/version", d.prefix)).unwrap())
        .event()
        .create_with_attributes(&spec)
        .unwrap();
    let status = n
        .service_builder(&status_service(d))
        .publish_subscribe::<StatusV9>()
        .create()
        .unwrap();
    (version, status)
}

#[test]
fn a_daemon_of_another_schema_is_named_with_both_versions() {
    let d = TestDaemon::new("schema-v9", "");
    std::fs::create_dir_all(&d.root).unwrap();
    let n = node(&d);
    let _daemon = fake_v9_daemon(&d, &n);
    let want = "the daemon speaks schema v9 (gaitd 9.9.9), this client v8";
    // The Rust client.
    let err = Client::connect(d.options().timeout(Duration::from_secs(2))).unwrap_err();
    assert!(matches!(err, Error::SchemaVersion { .. }), "{err:?}");
    assert!(err.to_string().contains(want), "{err}");
    // gaitctl.
    let out = output_within(d.gaitctl().arg("status"), Duration::from_secs(30));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(stderr.contains(want), "{stderr}");
    // The Python package.
    let code = format!(
        "from gaitd.client import Client, SchemaMismatch\n\
         try:\n    Client.connect(prefix={:?}, root_path={:?}, file_prefix={:?}, timeout=2)\n\
         except SchemaMismatch as e:\n    print(e)\n",
        d.prefix,
        format!("{}/", d.root.display()),
        d.file_prefix
    );
    let out = output_within(
        python_support::python().arg("-c").arg(code),
        Duration::from_secs(60),
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains(want),
        "{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn the_daemon_states_its_schema_and_build() {
    let d = TestDaemon::start("schema-version");
    let _c = d.client(); // the daemon is up (its version service first)
    let n = node(&d);
    let f = n
        .service_builder(&ServiceName::new(&format!("{}/version", d.prefix)).unwrap())
        .event()
        .open()
        .unwrap();
    let value = |k: &str| {
        f.attributes()
            .key_value(&AttributeKey::new(k.as_bytes()).unwrap(), 0)
            .map(|v| v.to_string())
    };
    assert_eq!(
        value(shm_schema::VERSION_ATTRIBUTE_SCHEMA).as_deref(),
        Some("8")
    );
    let build = value(shm_schema::VERSION_ATTRIBUTE_BUILD).unwrap();
    assert!(build.starts_with("gaitd "), "{build}");
}

#[test]
fn a_stale_service_of_another_schema_is_replaced_at_start() {
    // Left over from a daemon of another schema version, still held open.
    let mut d = TestDaemon::new("schema-stale", "");
    std::fs::create_dir_all(&d.root).unwrap();
    let n = node(&d);
    let stale = n
        .service_builder(&status_service(&d))
        .publish_subscribe::<StatusV9>()
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
