//! Where a remote gaitd is: a `gaitd-bridge` endpoint and this client's
//! certificate (plain data, compiled with or without the `remote` feature).

use std::path::{Path, PathBuf};
use std::time::Duration;

/// The three PEM files of mutual TLS: the private CA that signed the
/// bridge's certificate, and this client's certificate and key (signed by
/// the same CA; its common name is the client's identity).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TlsFiles {
    /// The CA certificate (PEM).
    pub ca: PathBuf,
    /// This client's certificate (PEM).
    pub cert: PathBuf,
    /// This client's private key (PEM).
    pub key: PathBuf,
}

impl TlsFiles {
    /// The three files by path.
    pub fn new(ca: impl Into<PathBuf>, cert: impl Into<PathBuf>, key: impl Into<PathBuf>) -> Self {
        Self {
            ca: ca.into(),
            cert: cert.into(),
            key: key.into(),
        }
    }

    /// The layout `deploy/gaitd-certs.sh` writes: `DIR/ca.pem`,
    /// `DIR/NAME.pem`, `DIR/NAME.key`.
    pub fn in_dir(dir: impl AsRef<Path>, name: &str) -> Self {
        let d = dir.as_ref();
        Self::new(
            d.join("ca.pem"),
            d.join(format!("{name}.pem")),
            d.join(format!("{name}.key")),
        )
    }
}

/// How to reach gaitd through `gaitd-bridge` over Zenoh.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RemoteOptions {
    /// The bridge's endpoint: `quic/HOST:PORT`, `tls/HOST:PORT` (TCP) or `HOST:PORT` (QUIC).
    pub endpoint: String,
    /// CA, certificate and key.
    pub tls: TlsFiles,
    /// The identity to use in keys; `None` = the certificate's common name
    /// (the bridge's access control only accepts that one anyway).
    pub identity: Option<String>,
    /// How long the bridge keeps this client's session (and its liveliness
    /// token) after the last sign of life: a dead client is noticed within
    /// about this long.
    pub lease: Duration,
}

impl RemoteOptions {
    /// An endpoint and the TLS files, identity from the certificate.
    pub fn new(endpoint: impl Into<String>, tls: TlsFiles) -> Self {
        Self {
            endpoint: endpoint.into(),
            tls,
            identity: None,
            lease: Duration::from_secs(3),
        }
    }
}
