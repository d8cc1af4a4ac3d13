//! What can go wrong with a remote connection, each with what to check.

use super::protocol::Refusal;
use std::path::PathBuf;
use std::time::Duration;

/// Why a remote (bridge) call failed.
#[derive(Debug, thiserror::Error)]
pub enum RemoteError {
    /// The remote transport is not compiled in.
    #[error("this gaitd_client was built without the `remote` feature (Zenoh)")]
    NotBuilt,
    /// The endpoint does not parse.
    #[error(
        "bad bridge endpoint `{endpoint}`: {why} (expected quic/HOST:PORT, e.g. quic/127.0.0.1:7460, or tls/HOST:PORT)"
    )]
    BadEndpoint {
        /// As given.
        endpoint: String,
        /// What is wrong with it.
        why: &'static str,
    },
    /// A TLS file is missing or unusable.
    #[error("{what} {}: {why}", path.display())]
    TlsFile {
        /// Which file (`CA certificate`, `client certificate`, `client key`).
        what: &'static str,
        /// Its path.
        path: PathBuf,
        /// What is wrong.
        why: String,
    },
    /// The key prefix cannot be used in keys.
    #[error("key prefix `{0}`: non-empty chunks of [A-Za-z0-9._-] separated by /")]
    BadPrefix(String),
    /// The identity cannot be used in keys.
    #[error(
        "identity `{0}` cannot be used: 1-64 characters of [A-Za-z0-9._-] \
         (the certificate's common name, or --identity)"
    )]
    BadIdentity(String),
    /// Nothing accepts TCP connections at the endpoint.
    #[error("nothing listens at {endpoint} ({why}): is gaitd-bridge running there?")]
    Unreachable {
        /// The endpoint.
        endpoint: String,
        /// The socket error.
        why: String,
    },
    /// The TCP connection worked, the TLS session did not.
    #[error(
        "the bridge at {endpoint} refused the TLS session: its CA did not sign this \
         client's certificate, the certificate expired, or the bridge's certificate \
         does not match the host name ({why})"
    )]
    Handshake {
        /// The endpoint.
        endpoint: String,
        /// Zenoh's reason.
        why: String,
    },
    /// No QUIC session opened (QUIC cannot tell "nothing listens" from "the
    /// handshake failed" before its timeout).
    #[error(
        "no session with the bridge at {endpoint} ({why}): is gaitd-bridge running \
         there, did its CA sign this client's certificate (not expired), and does the \
         bridge's certificate name this host?"
    )]
    NoSession {
        /// The endpoint.
        endpoint: String,
        /// Zenoh's reason.
        why: String,
    },
    /// Connected, but no bridge is visible under the prefix.
    #[error(
        "connected to {endpoint} as `{identity}`, but no gaitd-bridge with key prefix \
         `{prefix}` answered within {waited:?}: wrong --prefix, or the bridge's access \
         control does not know this identity (no [[identity]] entry)"
    )]
    NoBridge {
        /// The endpoint.
        endpoint: String,
        /// Our identity.
        identity: String,
        /// The key prefix tried.
        prefix: String,
        /// How long we waited.
        waited: Duration,
    },
    /// The bridge is up but sees no daemon.
    #[error(
        "gaitd-bridge at {endpoint} is up, but no gaitd is running behind it (waited {waited:?})"
    )]
    NoDaemonBehindBridge {
        /// The endpoint.
        endpoint: String,
        /// How long we waited.
        waited: Duration,
    },
    /// The bridge refused a command before the daemon saw it.
    #[error("the bridge refused the command: {0}")]
    Refused(Refusal),
    /// The bridge sent something this client cannot decode.
    #[error("undecodable reply from the bridge: {0}")]
    BadReply(String),
    /// A command query ended without any reply although the bridge is up.
    #[error(
        "the bridge did not answer `{command}` from identity `{identity}` although it \
         is up: its access control does not let this identity send commands (a monitor \
         certificate?), or the daemon is overloaded (waited at most {waited:?})"
    )]
    NoAnswer {
        /// The command's key chunk.
        command: String,
        /// Our identity.
        identity: String,
        /// How long we waited.
        waited: Duration,
    },
    /// Zenoh itself failed.
    #[error("zenoh: {0}")]
    Zenoh(String),
}
