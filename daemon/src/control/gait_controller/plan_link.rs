//! The executor's side of the planner thread: plan requests out, plans in,
//! replaced plans back to be freed off the loop (SPEC §7.2).
//!
//! Nothing is allocated or freed here: plans only move. A plan the retire
//! ring cannot take yet waits in a small fixed table for the next tick.

use super::goal_ids::GoalIds;
use super::{GaitPlannerLink, GoalPlanRequest};
use gait::executor::Executor;
use gait::planner::Plan;

/// Plan requests in flight (sequence number → executor goal).
const REQUEST_SLOTS: usize = 8;
/// Plans kept on the loop while the retire ring is full.
const RETIRE_SLOTS: usize = 4;

/// The planner link of the gait controller (module docs).
pub struct PlanShuttle {
    link: GaitPlannerLink,
    /// Sequence number and executor goal of each request in flight.
    requests: [(u64, u64); REQUEST_SLOTS],
    /// Plans waiting for room in the retire ring.
    retiring: [Option<Box<Plan>>; RETIRE_SLOTS],
    /// Plans leaked because the retire ring and `retiring` were full.
    leaked: u64,
    /// Requests submitted and not yet answered.
    in_flight: u32,
    /// Lockstep: every plan is delivered at the tick after its request, so
    /// a run is reproducible bit for bit (the plant waits for us anyway).
    /// The loop waits for it between ticks ([`PlanShuttle::awaits_reply`]).
    deterministic: bool,
}

impl std::fmt::Debug for PlanShuttle {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PlanShuttle")
            .field("leaked", &self.leaked)
            .finish()
    }
}

impl PlanShuttle {
    /// Over `link`.
    pub fn new(link: GaitPlannerLink) -> Self {
        Self {
            link,
            requests: [(0, 0); REQUEST_SLOTS],
            retiring: [const { None }; RETIRE_SLOTS],
            leaked: 0,
            in_flight: 0,
            deterministic: false,
        }
    }

    /// From now on every plan is delivered at the tick after its request
    /// (lockstep; see [`PlanShuttle::pump`]).
    pub fn deliver_deterministically(&mut self) {
        self.deterministic = true;
    }

    /// Lockstep: a request is in flight and its reply is not there yet, so
    /// the next tick should wait (the loop does, between ticks).
    pub fn awaits_reply(&self) -> bool {
        self.deterministic && self.in_flight > 0 && !self.link.reply_ready()
    }

    /// Plans leaked so far (expected 0: see [`PlanShuttle::retire`]).
    pub fn leaked(&self) -> u64 {
        self.leaked
    }

    /// Hands `plan` back to the planner thread to be freed there.
    pub fn retire(&mut self, plan: Option<Box<Plan>>) {
        let Some(plan) = plan else { return };
        if let Err(p) = self.link.retire(plan) {
            // Ring full: keep it for the next tick (never drop it here).
            match self.retiring.iter_mut().find(|slot| slot.is_none()) {
                Some(slot) => *slot = Some(p),
                None => {
                    // Cannot happen (the ring has room for every plan alive
                    // on this side, see `plan_thread::spawn`); should it, a
                    // leaked plan is a bounded loss, a free here is not.
                    Box::leak(p);
                    self.leaked += 1;
                }
            }
        }
    }

    /// Retries waiting retirements, submits the executor's plan request
    /// and delivers every finished plan to it. In lockstep plans are only
    /// delivered by the first pump of a tick (`at_tick_start`), which the
    /// loop held until they were ready: a plan requested at tick N arrives
    /// at tick N + 1 however fast the planner is. Never waits.
    pub fn pump(&mut self, exec: &mut Executor, ids: &GoalIds, at_tick_start: bool) {
        for k in 0..RETIRE_SLOTS {
            let p = self.retiring[k].take();
            self.retire(p);
        }
        if let Some(req) = exec.take_plan_request() {
            let wire = ids.wire(req.goal);
            match self.link.submit(GoalPlanRequest { request: req, wire }) {
                Ok(seq) => {
                    self.requests[(seq as usize) % REQUEST_SLOTS] = (seq, req.goal);
                    self.in_flight += 1;
                }
                // The planner is swamped: the goal fails rather than waits.
                Err(_) => exec.plan_unavailable(req.goal),
            }
        }
        // A request being planned for a goal that was canceled or preempted
        // meanwhile stops (the newest request for the goal the executor
        // waits for is the one wanted).
        let wanted = exec.planning_for().and_then(|goal| {
            self.requests
                .iter()
                .filter(|&&(seq, g)| g == goal && seq != 0)
                .map(|&(seq, _)| seq)
                .max()
        });
        self.link.want(wanted);
        if self.deterministic && !at_tick_start {
            return;
        }
        while let Some(reply) = self.link.poll() {
            self.in_flight = self.in_flight.saturating_sub(1);
            let (seq, goal) = self.requests[(reply.seq as usize) % REQUEST_SLOTS];
            if seq != reply.seq {
                // Its slot was reused: the goal is long gone.
                if let Ok(p) = reply.result {
                    self.retire(Some(p));
                }
                continue;
            }
            let old = exec.deliver_plan(goal, reply.result);
            self.retire(old);
        }
    }
}
