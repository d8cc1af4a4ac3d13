//! Where to find the daemon: service prefix and iceoryx2 namespace, or a
//! remote daemon's bridge.

use crate::error::{Error, Result};
use crate::remote_options::{RemoteOptions, TlsFiles};
use iceoryx2::config::Config;
use iceoryx2::prelude::{FilePath, SemanticString};
use shm_schema::ipc::{IpcRequest, IpcSettings};
use std::time::Duration;

/// Connection options. Unset values come from the environment
/// (`GAITD_PREFIX`, `GAITD_IPC_CONFIG`, `GAITD_IPC_ROOT`,
/// `GAITD_IPC_FILE_PREFIX`), then from the iceoryx2 config file, then the
/// defaults — exactly as the daemon resolves them.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ConnectOptions {
    /// The iceoryx2 namespace and service prefix.
    pub ipc: IpcRequest,
    /// How long `connect` waits for the daemon.
    pub timeout: Duration,
    /// A status older than this counts as "daemon not running".
    pub max_status_age: Duration,
    /// iceoryx2 node name of this client.
    pub node_name: String,
    /// Talk to a remote daemon through `gaitd-bridge` (Zenoh, mutual TLS)
    /// instead of iceoryx2; `ipc.service_prefix` is then the bridge's key
    /// prefix (default `gaitd`). Needs the `remote` feature.
    pub remote: Option<RemoteOptions>,
}

impl Default for ConnectOptions {
    fn default() -> Self {
        Self {
            ipc: IpcRequest::default(),
            timeout: Duration::from_secs(2),
            max_status_age: Duration::from_secs(1),
            node_name: "gaitd-client".into(),
            remote: None,
        }
    }
}

impl ConnectOptions {
    /// Defaults (environment and config resolved at connect time).
    pub fn new() -> Self {
        Self::default()
    }

    /// A remote daemon: the bridge at `endpoint` (`quic/HOST:PORT` or `tls/HOST:PORT`), with
    /// this client's TLS files (see [`TlsFiles::in_dir`]).
    pub fn remote(endpoint: impl Into<String>, tls: TlsFiles) -> Self {
        Self {
            remote: Some(RemoteOptions::new(endpoint, tls)),
            ..Self::default()
        }
    }

    /// The identity used in a remote client's keys (default: the
    /// certificate's common name). No effect on a local connection.
    pub fn identity(mut self, name: impl Into<String>) -> Self {
        if let Some(r) = &mut self.remote {
            r.identity = Some(name.into());
        }
        self
    }

    /// Service-name prefix (default `gaitd`); for a remote connection, the
    /// bridge's key prefix.
    pub fn prefix(mut self, prefix: impl Into<String>) -> Self {
        self.ipc.service_prefix = Some(prefix.into());
        self
    }

    /// iceoryx2 root path.
    pub fn root_path(mut self, path: impl Into<String>) -> Self {
        self.ipc.root_path = Some(path.into());
        self
    }

    /// iceoryx2 file prefix.
    pub fn file_prefix(mut self, prefix: impl Into<String>) -> Self {
        self.ipc.file_prefix = Some(prefix.into());
        self
    }

    /// iceoryx2 config file (the daemon's, e.g. /etc/gaitd/iceoryx2.toml).
    pub fn iceoryx2_config(mut self, path: impl Into<String>) -> Self {
        self.ipc.iceoryx2_config = Some(path.into());
        self
    }

    /// Connect timeout: how long `Client::connect` retries while the
    /// daemon's services are missing, still being created or full.
    pub fn timeout(mut self, t: Duration) -> Self {
        self.timeout = t;
        self
    }

    /// iceoryx2 node name.
    pub fn node_name(mut self, name: impl Into<String>) -> Self {
        self.node_name = name.into();
        self
    }

    /// The iceoryx2 config and resolved settings.
    pub fn resolve(&self) -> Result<(Config, IpcSettings)> {
        let req = self.ipc.clone().or_env(|k| std::env::var(k).ok());
        let file = match &req.iceoryx2_config {
            Some(path) => {
                let fp = FilePath::new(path.as_bytes())
                    .map_err(|e| Error::Settings(format!("iceoryx2 config path {path}: {e:?}")))?;
                Some(
                    Config::from_file(&fp)
                        .map_err(|e| Error::Settings(format!("iceoryx2 config {path}: {e:?}")))?,
                )
            }
            None => None,
        };
        // SAFETY: getuid has no preconditions.
        let uid = unsafe { libc::getuid() };
        let settings = req.resolve(
            file.as_ref(),
            uid,
            std::path::Path::new("/run/gaitd").is_dir(),
        );
        let mut config = file.unwrap_or_default();
        settings
            .apply(&mut config)
            .map_err(|e| Error::Settings(e.to_string()))?;
        Ok((config, settings))
    }
}
