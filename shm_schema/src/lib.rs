//! # shm_schema — what crosses process boundaries
//!
//! The payloads exchanged between `gaitd` and its clients over iceoryx2 shared
//! memory, and the service names (SPEC.md §7.3). This crate holds only plain
//! data: no maths, no nalgebra, so that a C or Python client can mirror it.

/// Version of the payload layout. It is part of every payload's type name, so
/// a client built against another version fails to open the services.
pub const SCHEMA_VERSION: u32 = 1;

/// Default service-name prefix (SPEC §7.3).
pub const DEFAULT_PREFIX: &str = "gaitd";

/// The services of one daemon instance, all under one prefix.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ServiceNames {
    /// Client → daemon goals and commands.
    pub goals: String,
    /// Daemon → clients status, latest value.
    pub status: String,
    /// Daemon → clients events, with history.
    pub events: String,
}

impl ServiceNames {
    /// Names under `prefix` (e.g. `"gaitd"` → `"gaitd/goals"`, …).
    pub fn new(prefix: &str) -> Self {
        Self {
            goals: format!("{prefix}/goals"),
            status: format!("{prefix}/status"),
            events: format!("{prefix}/events"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_share_the_prefix() {
        let n = ServiceNames::new("test-1");
        assert_eq!(n.goals, "test-1/goals");
        assert_eq!(n.status, "test-1/status");
        assert_eq!(n.events, "test-1/events");
    }
}
