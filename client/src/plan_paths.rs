//! Where the daemon's plans take the hand: the `plan` service's
//! [`PlanPath`]s (SPEC §7.3), for views. A reader of its own, opened from a
//! connected [`Client`] when wanted, so that clients that do not draw
//! plans do not receive 30 KB per plan; through a bridge, the paths it
//! forwards (the latest one at once).

use crate::client::Client;
use crate::connection::{Attempt, Ipc, ipc_err, open_pubsub};
use crate::error::{Error, Result};
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::prelude::*;
use shm_schema::{PlanPath, ServiceNames};

/// Where the paths come from.
enum Source {
    /// The daemon's `plan` service, on a node of the reader's own
    /// (dropped after the port).
    Local {
        subscriber: Subscriber<Ipc, PlanPath, ()>,
        _node: Node<Ipc>,
    },
    /// A bridge.
    #[cfg(feature = "remote")]
    Remote(crate::remote::transport::RemotePlans),
}

impl std::fmt::Debug for Source {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Self::Local { .. } => "Local",
            #[cfg(feature = "remote")]
            Self::Remote(_) => "Remote",
        })
    }
}

/// Reads the daemon's plan paths (module docs).
#[derive(Debug)]
pub struct PlanPaths {
    source: Source,
    latest: Option<PlanPath>,
    refused: u64,
}

impl Client {
    /// A reader of the daemon's plan paths.
    pub fn plan_paths(&self) -> Result<PlanPaths> {
        #[cfg(feature = "remote")]
        if let Some(plans) = self.remote_plans() {
            return Ok(PlanPaths {
                source: Source::Remote(plans),
                latest: None,
                refused: 0,
            });
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
            source: Source::Local {
                subscriber,
                _node: node,
            },
            latest: None,
            refused: 0,
        })
    }
}

impl PlanPaths {
    /// The newest valid path received so far (a path that fails
    /// [`PlanPath::checked`] is counted in [`PlanPaths::refused`] and
    /// skipped), without waiting.
    pub fn latest(&mut self) -> Result<Option<&PlanPath>> {
        match &self.source {
            Source::Local { subscriber, .. } => {
                while let Some(s) = subscriber
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
            }
            #[cfg(feature = "remote")]
            Source::Remote(plans) => {
                let (latest, refused) = plans.latest();
                if latest.is_some() {
                    self.latest = latest;
                }
                self.refused = refused;
            }
        }
        Ok(self.latest.as_ref())
    }

    /// Paths received that failed their check.
    pub fn refused(&self) -> u64 {
        self.refused
    }
}
