//! # gaitd_client — talk to a running gaitd
//!
//! Synchronous client library for gaitd (SPEC.md §8). Clients only open the
//! services the daemon created; the service names come from [`shm_schema`].

pub use shm_schema::{DEFAULT_PREFIX, SCHEMA_VERSION, ServiceNames};
