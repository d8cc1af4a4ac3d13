//! # gaitd_client — talk to a running gaitd
//!
//! Synchronous client library for gaitd (SPEC.md §8): no async runtime,
//! every call takes a timeout, waiting blocks on the daemon's iceoryx2
//! notifications instead of spinning. Clients only open the services the
//! daemon created; payloads and service names come from [`shm_schema`].
//!
//! ```no_run
//! use gaitd_client::{Client, ConnectOptions, GoalSpec, Verdict};
//! use std::time::Duration;
//!
//! # fn main() -> gaitd_client::Result<()> {
//! let mut client = Client::connect(ConnectOptions::new().timeout(Duration::from_secs(2)))?;
//! let status = client.wait_status(Duration::from_millis(100))?;
//! println!("tick {} phase {:?}", status.tick, status.phase());
//!
//! // Rotate the object by 90° about the hand's z axis.
//! let goal = GoalSpec::axis_angle([0.0, 0.0, 1.0], std::f64::consts::FRAC_PI_2,
//!                                 gaitd_client::GoalFrame::Relative)?;
//! let ticket = client.reorient(&goal, Duration::from_millis(500))?;
//! match ticket.verdict {
//!     Verdict::Accepted => {
//!         let outcome = client.wait_outcome(ticket.goal_id, Duration::from_secs(30))?;
//!         println!("goal {} ended {:?} ({:?})", outcome.goal_id, outcome.state, outcome.reason);
//!     }
//!     Verdict::Rejected(reason) => println!("rejected: {reason}"),
//! }
//! # Ok(())
//! # }
//! ```
//!
//! Events (goal transitions, gait events, faults, overruns):
//!
//! ```no_run
//! # use gaitd_client::{Client, ConnectOptions};
//! # use std::time::Duration;
//! # fn main() -> gaitd_client::Result<()> {
//! # let mut client = Client::connect(ConnectOptions::new())?;
//! while let Some(e) = client.next_event(Duration::from_secs(1))? {
//!     println!("#{} {:?} goal {}", e.seq, e.kind(), e.goal_id);
//! }
//! # Ok(())
//! # }
//! ```
//!
//! A [`Client`] is bound to the thread that created it (iceoryx2 ports are
//! not `Send`); create one per thread that talks to the daemon.
//!
//! A remote daemon (another host, through `gaitd-bridge` over Zenoh with
//! mutual TLS) is reached with the same API: connect with
//! [`ConnectOptions::remote`] (feature `remote`, on by default; see
//! [`remote`]).
//!
//! ```no_run
//! use gaitd_client::{Client, ConnectOptions, TlsFiles};
//! # fn main() -> gaitd_client::Result<()> {
//! let tls = TlsFiles::in_dir("/etc/gaitd/pki", "operator-1");
//! let mut client = Client::connect(ConnectOptions::remote("quic/robot-1:7460", tls))?;
//! println!("tick {}", client.wait_status(std::time::Duration::from_secs(1))?.tick);
//! # Ok(())
//! # }
//! ```
//!
//! A daemon restart is handled: [`Client::command`] and the calls built on
//! it reconnect once when the daemon's status went stale; any caller can
//! also use [`Client::ensure_connected`] or [`Client::reconnect`].

#[cfg(feature = "cli")]
pub mod cli;
mod client;
mod connection;
pub mod describe;
mod error;
mod goal;
mod options;
mod plan_paths;
pub mod plant;
pub mod remote;
mod remote_options;

pub use client::{Client, GoalTicket, Outcome, monotonic_ns};
pub use error::{Error, Result};
pub use goal::{GoalSpec, quat_from_axis_angle};
pub use options::ConnectOptions;
pub use plan_paths::PlanPaths;
pub use remote::{RemoteError, RemoteOptions, TlsFiles};
pub use shm_schema::{
    self, Answer, Command, DEFAULT_PREFIX, DaemonState, Event, EventKind, FaultCode, FingerPhase,
    GoalFrame, GoalState, GraspState, LimitKind, LimitOrder, PathPoint, Phase, PlanPath,
    ReasonCode, SCHEMA_VERSION, ServiceNames, Status, Verdict,
};
