//! What a tick reports (SPEC §7.3): the status a client reads — phase,
//! goal, remaining turn, ETA on whole ticks, the commanded grip and the
//! load margin (SPEC §1.3 I1').

use super::*;
use crate::planner::timing::on_ticks;

/// Everything a status message needs after a tick (SPEC §7.3).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TickReport {
    /// Tick counter.
    pub tick: u64,
    /// The setpoint just computed.
    pub setpoint: Setpoint,
    /// Coarse phase.
    pub phase: Mode,
    /// Kind of the running step (if moving).
    pub step_kind: Option<StepKind>,
    /// Active or last goal: id, state, reason.
    pub goal: Option<(u64, GoalStage, Reason)>,
    /// Rotation still to make \[rad\]: while the plan runs, its remaining
    /// path length (the rotation angles of its steps left); before, the
    /// angle to the goal.
    pub remaining_angle: f64,
    /// Gaits (Place/Lift steps) done and planned for the goal.
    pub gaits: (u32, u32),
    /// Estimated time to the goal \[s\].
    pub eta: f64,
    /// Commanded normal force per finger \[N\] ([`grip`]).
    pub grip: [f64; 3],
    /// Commanded contact force on the object per finger: the load's share
    /// and the squeeze, normal and tangential (the grip's `force`; zero for
    /// a finger that carries nothing) \[N\]. A joint-level plant is sent it
    /// as torques J_pᵀ F.
    pub grip_force: [Vector3<f64>; 3],
    /// Whether the grip had to be capped at `load.max_grip` (the grasp
    /// cannot hold the load).
    pub grip_capped: bool,
    /// The largest normal force the load needs over every load scenario
    /// (weight, acceleration, any disturbance of the configured size:
    /// F*, SPEC §1.3 I1'); +∞ when no grip holds it \[N\].
    pub grip_peak: f64,
    /// Load margin `load.max_grip` − `grip_peak` \[N\]: ≥ 0 when the
    /// commanded grasp holds the load (I1'), negative (or −∞) when not.
    pub load_margin: f64,
    /// Force-closure flag and margin of the commanded grasp.
    pub force_closure: (bool, f64),
    /// Workspace slack per finger \[rad\] (negative: outside); on a chain
    /// hand, the joint-limit margin of the commanded state (SPEC §14.1).
    pub workspace_slack: [f64; 3],
    /// The commanded contact's margin on each fingertip \[rad\]: the
    /// hemisphere's (free fingertips) or the tip patch's beyond its margin
    /// (chains); 0 for a finger not grasping.
    pub tip_slack: [f64; 3],
    /// A chain hand's links off the object beyond the clearance, per
    /// finger \[m\] (`None` on free fingertips).
    pub link_slack: [Option<f64>; 3],
    /// A chain hand's commanded joints per finger \[rad\]: the joints that
    /// put each tip where `setpoint` writes it, on the branch nearest the
    /// joints commanded the tick before (SPEC §14.3). `None` for free
    /// fingertips, and for a finger no branch reaches (the check has
    /// faulted it).
    pub joints: [Option<Vector3<f64>>; 3],
    /// Active fault, if any.
    pub fault: Option<(FaultKind, u8)>,
}

impl Executor {
    /// Object rotation the plan still has to make from the running step's
    /// current position \[rad\].
    pub(super) fn planned_rotation_left(&self) -> f64 {
        self.progress.rotation_left(self.runner.state().position[0])
    }

    pub(super) fn fill_report(&mut self) {
        // How much the object still has to turn: along the plan while it
        // runs (a full turn counts in full), else the way to the goal.
        let remaining = match (self.phase, self.goals.active()) {
            (_, None) => 0.0,
            (Mode::Moving | Mode::Stopping, Some(_)) => self.planned_rotation_left(),
            (_, Some(g)) => match g.target {
                GoalTarget::Rotation { angle, .. } => angle.abs(),
                GoalTarget::Orientation(_) => g.end.angle_to(&self.setpoint.state.object),
            },
        };
        let r = &mut self.report;
        r.remaining_angle = remaining;
        r.tick = self.tick;
        // What is written to the plant: the plan, turned by the correction,
        // fingertips placed on the object where it is measured.
        r.setpoint = self.placement.apply(&self.correction.apply(&self.setpoint));
        r.phase = self.phase;
        r.step_kind = match self.phase {
            Mode::Moving | Mode::Stopping => self.progress.current().map(|s| s.kind),
            _ => None,
        };
        r.goal = self.goals.reported();
        r.gaits = self.progress.gaits();
        let hold_left = match (
            self.carrying.handover(),
            self.current_step().and_then(|s| s.handover),
        ) {
            (Some(h), _) => on_ticks(h.duration - h.elapsed, self.dt),
            (None, Some(h)) => on_ticks(h.duration, self.dt),
            (None, None) => 0.0,
        };
        let motion_left = on_ticks(self.runner.time_left(), self.dt);
        let r = &mut self.report;
        r.eta = match self.phase {
            Mode::Moving => self.progress.time_after_step() + motion_left + hold_left,
            Mode::Stopping => motion_left + hold_left,
            _ => 0.0,
        };
        r.fault = self.fault;
        self.command_joints();
        let motors = self.motors();
        let torque = self.object_acceleration * self.inertia;
        let g = self.grips.at(
            &self.setpoint.state,
            &torque,
            self.carrying.set(),
            self.carrying.blend(),
            motors.as_ref(),
        );
        let limit = motors.map_or(f64::INFINITY, |m| m.push_cap(&self.report.setpoint.state));
        let r = &mut self.report;
        r.grip = g.normal;
        r.grip_force = g.force;
        r.grip_capped = g.capped;
        r.grip_peak = g.peak;
        r.load_margin = limit.min(self.grips.max_grip()) - g.peak;
    }

    /// On a chain hand, each grasping finger's statics at the joints just
    /// commanded ([`grips::Motors`]); `None` on free fingertips
    /// (`load.max_grip` alone bounds their grip).
    fn motors(&self) -> Option<grips::Motors> {
        let hand = self.checker.chain_limits()?.hand();
        let r = &self.report;
        let statics = std::array::from_fn(|k| {
            let f = &r.setpoint.state.fingers[k];
            match (f.mode, r.joints[k].as_ref()) {
                (crate::hand_state::FingerMode::Grasping, Some(q)) => {
                    Some(hand.statics(k, q, &f.center.normalize()))
                }
                _ => None,
            }
        });
        Some(grips::Motors { statics })
    }

    /// A chain hand's joints for the tips just written (the report's
    /// `joints`): each finger on the branch nearest its joints a tick
    /// before, so that a finger moving along its path stays on its branch;
    /// a finger seen for the first time takes the branch the workspace
    /// test picks. Allocation-free.
    fn command_joints(&mut self) {
        let Some(chains) = self.checker.chain_limits() else {
            return;
        };
        let hand = chains.hand();
        let r = &mut self.report;
        for (k, f) in r.setpoint.state.fingers.iter().enumerate() {
            r.joints[k] = hand.follow(k, &f.center, r.joints[k].as_ref());
        }
    }
}

/// How long a step runs on ticks: its motion, then its handover, each to
/// whole periods (what the ETA counts: summing the planned durations
/// undercounts by about half a period per step).
pub(super) fn step_on_ticks(step: &Step, dt: f64) -> f64 {
    let hold = step.handover.map_or(0.0, |h| h.duration);
    on_ticks(step.duration - hold, dt) + on_ticks(hold, dt)
}
