//! Remote clients end to end, in one test binary (Zenoh links
//! once): gaitd, gaitd-bridge and the remote clients are separate
//! processes on loopback, talking Zenoh with mutual TLS.
//!
//! - [`goals`]: a goal succeeds, a cancel stops one, a late joiner gets the
//!   recent events; `gaitctl --remote` for status, reorient, hold, cancel,
//!   events;
//! - [`security`]: certificates from another CA and unknown identities are
//!   refused, a monitor cannot command (the daemon never sees it), bad
//!   bytes are rejected with a reason;
//! - [`reconnect`]: the bridge killed and restarted, the client resumes;
//! - [`cut`]: a link dropped with a command in flight: sent again,
//!   answered once;
//! - [`event_gaps`]: events published while the bridge restarts all reach
//!   a subscriber (its cache queried again), or are reported missing;
//! - [`lost`]: an operator killed while its goal runs, the bridge cancels it;
//! - [`operator_loss`]: the bridge restarted after its operator went, and
//!   an operator with a 10 s lease killed: both goals canceled within the
//!   bridge's own bounds;
//! - [`burst`]: a burst beyond an identity's rate limit is refused
//!   `RateLimited`, never `DaemonBusy`;
//! - [`cli`]: `gaitctl --remote watch` and `reset`, a monitor's reset
//!   refused, the TLS flags' mistakes as one-line messages;
//! - [`python`]: `gaitd.remote.RemoteClient` sends a goal and reads status;
//!   its link dropped with a command in flight, the daemon gets it once;
//! - [`view`]: `gaitd-view --remote` records the view of a turning object
//!   through the bridge.

mod burst;
mod cli;
mod cut;
mod event_gaps;
mod goals;
mod lost;
mod operator_loss;
mod python;
mod reconnect;
mod security;
mod support;
mod view;
