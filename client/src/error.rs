//! Client errors: what went wrong and what to check.

use shm_schema::UnknownCode;
use std::time::Duration;

/// Why a client call failed.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// No daemon answered within the timeout (services missing or no fresh status).
    #[error(
        "no gaitd running with prefix `{prefix}` under {root} (waited {waited:?}); \
         start it, or check GAITD_PREFIX / GAITD_IPC_ROOT / GAITD_IPC_FILE_PREFIX"
    )]
    NoDaemon {
        /// Service-name prefix tried.
        prefix: String,
        /// iceoryx2 root path tried.
        root: String,
        /// How long we waited.
        waited: Duration,
    },
    /// The daemon speaks another schema version (iceoryx2 refused the payload type).
    #[error(
        "schema mismatch on service `{service}`: this client speaks `{ours}` \
         (gaitd schema v{version}) but the running daemon uses another payload layout; \
         use a client built for the daemon's version"
    )]
    SchemaMismatch {
        /// The service that refused us.
        service: String,
        /// Our payload type name.
        ours: &'static str,
        /// Our schema version.
        version: u32,
    },
    /// The daemon speaks another schema version (its `version` service says
    /// which, or it has none: v3 or older).
    #[error(
        "the daemon speaks schema {daemon}, this client v{ours}: use a client built for \
         the daemon's schema (shm_schema/LAYOUT.md, \"Schema versions\", says what each \
         version changed)"
    )]
    SchemaVersion {
        /// The daemon's schema and build, e.g. `v5 (gaitd 0.2.0)`, or `v3 or
        /// older` (no `version` service).
        daemon: String,
        /// Our schema version.
        ours: u32,
    },
    /// A service exists but refused us for another reason (limits, permissions).
    #[error("cannot open service `{service}`: {why}")]
    Open {
        /// The service.
        service: String,
        /// iceoryx2's reason.
        why: String,
    },
    /// The IPC settings or the iceoryx2 config file are unusable.
    #[error("ipc settings: {0}")]
    Settings(String),
    /// An iceoryx2 call failed.
    #[error("iceoryx2 {what}: {why}")]
    Ipc {
        /// What we were doing.
        what: &'static str,
        /// iceoryx2's reason.
        why: String,
    },
    /// The daemon's command queue for this client is full; retry later.
    #[error("the daemon's command queue is full (too many commands in flight)")]
    Busy,
    /// Nothing arrived in time.
    #[error("timed out after {waited:?} waiting for {what}")]
    Timeout {
        /// What we waited for.
        what: &'static str,
        /// How long.
        waited: Duration,
    },
    /// The daemon sent bytes that do not decode (another build, or corruption).
    #[error("undecodable data from the daemon: {0}")]
    BadData(#[from] UnknownCode),
    /// A remote connection (through `gaitd-bridge`) failed.
    #[error(transparent)]
    Remote(#[from] crate::remote::RemoteError),
    /// A bad argument (e.g. a zero rotation axis).
    #[error("invalid argument: {0}")]
    Invalid(&'static str),
}

/// Result with [`Error`].
pub type Result<T> = std::result::Result<T, Error>;
