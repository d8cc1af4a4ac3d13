//! # gaitd-bridge — gaitd for remote clients, over Zenoh
//!
//! iceoryx2 is same-host only. The bridge runs beside gaitd, as the
//! daemon's user, and opens gaitd's services as an ordinary client (it never
//! touches the loop); on the other side it is a Zenoh router that remote
//! clients reach over mutual TLS (SPEC §13):
//!
//! - status → `P/status`, downsampled to `[bridge] status_rate_hz`, latest
//!   value, dropped rather than queued under congestion ([`forward`]);
//! - events → `P/events`, an advanced publisher with a cache for late
//!   joiners and miss detection ([`forward`]);
//! - commands ← queryable `P/cmd/<identity>/<command>`, replying the
//!   daemon's `Answer` or a refusal ([`commands`], [`checks`]); a request
//!   sent again after a dropped link gets the answer already given
//!   ([`answered`]);
//! - liveliness tokens `P/alive/bridge`, `P/alive/daemon` (while gaitd
//!   publishes), and the clients' `P/clients/<identity>/<session>`: when an
//!   operator's last session vanishes, `[bridge] on_client_lost` applies
//!   ([`presence`]);
//! - access control with default deny, generated from the `[[identity]]`
//!   list ([`session`]); the `client_id` comes from the identity, a
//!   per-identity token bucket limits commands ([`rate`]).
//!
//! Payloads are the exact `#[repr(C)]` bytes of `shm_schema/LAYOUT.md`
//! with their versioned type name as the encoding's schema;
//! [`gaitd_client::remote::protocol`] is the contract and
//! `bridge/PROTOCOL.md` describes it for other languages.

pub mod answered;
pub mod checks;
pub mod commands;
pub mod config;
pub mod forward;
pub mod presence;
pub mod rate;
pub mod session;
