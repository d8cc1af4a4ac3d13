//! Remote clients: gaitd through `gaitd-bridge` over Zenoh, with mutual
//! TLS (SPEC §13).
//!
//! A [`Client`](crate::Client) connected with
//! [`ConnectOptions::remote`](crate::ConnectOptions::remote) has the same
//! API as a local one; the differences:
//!
//! - the `client_id` is the bridge's, derived from the certificate's common
//!   name ([`protocol::client_id_for`]); the one in a command is ignored;
//! - status arrives downsampled (the bridge's rate, e.g. 100 Hz) and its
//!   freshness is judged by arrival time (the daemon's clock is another
//!   host's);
//! - the bridge checks every command's bytes first: bytes that fail
//!   [`Command::validate`](shm_schema::Command::validate) are answered
//!   `Rejected` with the daemon's reason without reaching it, other
//!   refusals (rate limit, no daemon, …) are
//!   [`RemoteError::Refused`];
//! - a monitor identity's commands are dropped by the bridge's access
//!   control: they time out as [`RemoteError::NoAnswer`];
//! - reconnection after a bridge restart is Zenoh's (automatic); a daemon
//!   restart behind the bridge is the bridge's.
//!
//! [`protocol`] is the wire contract (keys, encodings, refusals), compiled
//! with or without the `remote` feature.

#[cfg(feature = "remote")]
pub mod continuity;
pub(crate) mod inflight;
pub mod protocol;
mod remote_error;
#[cfg(feature = "remote")]
pub mod tls;
#[cfg(feature = "remote")]
pub(crate) mod transport;

pub use crate::remote_options::{RemoteOptions, TlsFiles};
pub use remote_error::RemoteError;
#[cfg(feature = "remote")]
pub use transport::{RawReply, zenoh_text};
