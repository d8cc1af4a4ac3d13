//! Each plan's path on the `plan` service (shm_schema `PlanPath`), for
//! views: published by the planner thread as soon as a plan is made, never
//! by the loop. The points are where the executor will command the hand,
//! tick for tick, if nothing interrupts the plan
//! (`gait::planner::preview`).

use crate::io::ipc::{Ipc, PlanPathService};
use gait::planner::{Plan, preview};
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::update_connections::UpdateConnections;
use shm_schema::{PATH_POINTS, PathPoint, PlanPath};
use std::cell::RefCell;

thread_local! {
    /// The publisher, made on the thread that publishes (iceoryx2 ports
    /// stay on the thread that made them; services may move).
    static PORT: RefCell<Option<Publisher<Ipc, PlanPath, ()>>> = const { RefCell::new(None) };
}

/// Publishes plan paths (module docs).
#[derive(Debug)]
pub struct PathPublisher {
    service: PlanPathService,
    instance: u64,
    sequence: u64,
}

/// The wire form of `plan`'s path on a loop of period `dt` \[s\], made for
/// the client's goal `(client_id, goal_id)`, numbered `sequence`.
pub fn plan_path(
    plan: &Plan,
    dt: f64,
    (client_id, goal_id): (u64, u64),
    instance: u64,
    sequence: u64,
) -> PlanPath {
    let mut out = PlanPath {
        instance,
        goal_id,
        client_id,
        sequence,
        duration: preview::duration(plan, dt),
        ..PlanPath::default()
    };
    let points = preview::path_points(plan, dt, PATH_POINTS);
    out.count = points.len() as u32;
    for (slot, p) in out.points.iter_mut().zip(points) {
        let q = p.object.quaternion();
        *slot = PathPoint {
            t: p.t,
            object_q: [q.w, q.i, q.j, q.k],
            tip_position: p.tips.map(|c| [c.x, c.y, c.z]),
            touching: u32::from(p.touching),
            reserved: 0,
        };
    }
    out
}

impl PathPublisher {
    /// On `service`, for daemon instance `instance`.
    pub fn new(service: PlanPathService, instance: u64) -> Self {
        Self {
            service,
            instance,
            sequence: 0,
        }
    }

    /// Hands the latest path to subscribers that came since it was
    /// published (iceoryx2 delivers a service's history to new
    /// subscribers only when the publisher sends or is told to): a view
    /// that opens mid-plan gets it.
    pub fn connect_late_joiners(&self) {
        PORT.with(|port| {
            if let Some(p) = port.borrow().as_ref() {
                let _ = p.update_connections();
            }
        });
    }

    /// Publishes where `plan` takes the hand (see [`plan_path`]). False if
    /// it could not be sent (no port, no sample to loan): a view misses a
    /// path, nothing else does.
    pub fn publish(&mut self, plan: &Plan, dt: f64, goal: (u64, u64)) -> bool {
        self.sequence += 1;
        let path = plan_path(plan, dt, goal, self.instance, self.sequence);
        PORT.with(|port| {
            let mut port = port.borrow_mut();
            if port.is_none() {
                *port = self
                    .service
                    .publisher_builder()
                    .max_loaned_samples(1)
                    .create()
                    .map_err(|e| tracing::warn!(error = %e, "no plan path publisher"))
                    .ok();
            }
            let Some(p) = port.as_ref() else {
                return false;
            };
            match p.loan_uninit() {
                Ok(sample) => sample.write_payload(path).send().is_ok(),
                Err(_) => false,
            }
        })
    }
}
