//! Where the daemon's plans take the hand: the `plan` service's
//! [`PlanPath`]s (SPEC §7.3), for views. A reader of its own, opened from a
//! connected [`Client`] when wanted, so that clients that do not draw
//! plans do not receive 30 KB per plan.

use crate::client::Client;
use crate::connection::{Attempt, Ipc, ipc_err, open_pubsub};
use crate::error::{Error, Result};
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::prelude::*;
use shm_schema::{PlanPath, ServiceNames};

/// Reads the daemon's plan paths (module docs).
#[derive(Debug)]
pub struct PlanPaths {
    subscriber: Subscriber<Ipc, PlanPath, ()>,
    latest: Option<PlanPath>,
    refused: u64,
    // Dropped last: the port above first.
    _node: Node<Ipc>,
}

impl Client {
    /// A reader of the daemon's plan paths (on a node of its own). The
    /// bridge does not forward them: a remote client gets
    /// [`Error::Invalid`].
    pub fn plan_paths(&self) -> Result<PlanPaths> {
        if self.is_remote() {
            return Err(Error::Invalid(
                "plan paths are published in shared memory only (the bridge does not forward them)",
            ));
        }
        let node = NodeBuilder::new()
            .config(self.iceoryx2_config())
            .signal_handling_mode(SignalHandlingMode::Disabled)
            .create::<Ipc>()
            .map_err(|e| ipc_err("node")(&e))?;
        let names = ServiceNames::new(&self.settings().service_prefix);
        let Attempt::Done(service) = open_pubsub::<PlanPath>(&node, &names.plan)? else {
            return Err(Error::Open {
                service: names.plan,
                why: "the daemon has no plan service".into(),
            });
        };
        let subscriber = service
            .subscriber_builder()
            .create()
            .map_err(|e| ipc_err("plan path subscriber")(&e))?;
        Ok(PlanPaths {
            subscriber,
            latest: None,
            refused: 0,
            _node: node,
        })
    }
}

impl PlanPaths {
    /// The newest valid path received so far (a path that fails
    /// [`PlanPath::checked`] is counted in [`PlanPaths::refused`] and
    /// skipped), without waiting.
    pub fn latest(&mut self) -> Result<Option<&PlanPath>> {
        while let Some(s) = self
            .subscriber
            .receive()
            .map_err(|e| ipc_err("plan path receive")(&e))?
        {
            let p = s.payload();
            if p.checked().is_ok() {
                self.latest = Some(*p);
            } else {
                self.refused += 1;
            }
        }
        Ok(self.latest.as_ref())
    }

    /// Paths received that failed their check.
    pub fn refused(&self) -> u64 {
        self.refused
    }
}
