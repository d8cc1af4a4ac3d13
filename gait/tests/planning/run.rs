//! Runs the executor against the kinematic hand with a synchronous planner,
//! checking every tick independently (SPEC §1.3) — the command the
//! controller wrote and, separately, the plant's true state after it — and
//! the setpoint stream's continuity.

use gait::executor::{Executor, ExecutorCommand, ExecutorEvent, GoalStage, Mode, TickReport};
use gait::hand::InvariantChecker;
use gait::planner::{Planner, Setpoint, StepKind};
use gait::sim::{KinematicHand, Measurement, Plant};
use gait::{HandConfig, HandState};
use nalgebra::Vector3;

use super::verify::{Checker, Violation};

/// Largest plausible change of a setpoint velocity per tick divided by dt
/// (a bound on Cartesian acceleration: limits × lever arms, generous).
pub const MAX_ACC: f64 = 30.0;
/// Same for the change of acceleration (jerk bound).
pub const MAX_JERK: f64 = 600.0;

/// Everything a run measured.
#[derive(Debug, Default)]
pub struct RunStats {
    pub ticks: u64,
    /// Invariant violations of the commanded state.
    pub violations: Vec<(u64, Violation)>,
    /// Slips in the commanded motion (equal arcs broken between ticks).
    pub slips: u64,
    /// Invariant violations of the plant's true state.
    pub plant_violations: Vec<(u64, Violation)>,
    /// Slips of the plant's true state between ticks.
    pub plant_slips: u64,
    pub discontinuities: Vec<(u64, &'static str, f64)>,
    pub goals: Vec<(u64, GoalStage)>,
    pub faults: u64,
    /// Contact drifts reported (each stops the motion and replans).
    pub drifts: u64,
    /// Invariants near their limit reported (likewise).
    pub near_limits: Vec<(gait::executor::FaultKind, u8)>,
    /// Steps reported as started in a tick that ended not moving (a step
    /// announced that never runs).
    pub unmoved_steps: Vec<(u64, StepKind)>,
}

/// The executor, its plant and planner, ticking together.
pub struct Rig {
    pub cfg: HandConfig,
    pub dt: f64,
    pub exec: Executor,
    pub plant: KinematicHand,
    pub planner: Planner,
    checker: Checker,
    slip: InvariantChecker,
    prev: Option<Setpoint>,
    prev_plant: Option<HandState>,
    prev_vel: Option<[Vector3<f64>; 4]>,
    prev_acc: Option<[Vector3<f64>; 4]>,
    pub stats: RunStats,
    /// A plan to answer the next request with ([`Rig::script`]).
    scripted: Option<gait::planner::Plan>,
}

fn velocities(sp: &Setpoint) -> [Vector3<f64>; 4] {
    [
        sp.object_rate,
        sp.finger_velocity[0],
        sp.finger_velocity[1],
        sp.finger_velocity[2],
    ]
}

impl Rig {
    pub fn new(cfg: HandConfig, start: HandState, dt: f64) -> Self {
        Self {
            exec: Executor::new(&cfg, dt, start).unwrap(),
            plant: KinematicHand::new(start, dt),
            planner: Planner::new(&cfg).unwrap(),
            checker: Checker::new(&cfg),
            slip: InvariantChecker::new(&cfg).unwrap(),
            cfg,
            dt,
            prev: None,
            prev_plant: None,
            prev_vel: None,
            prev_acc: None,
            stats: RunStats::default(),
            scripted: None,
        }
    }

    /// The next plan request is answered with `plan` instead of the
    /// planner's (a plan made by hand for what the test needs).
    pub fn script(&mut self, plan: gait::planner::Plan) {
        self.scripted = Some(plan);
    }

    /// One tick: read, tick, write, answer plan requests, check.
    pub fn tick(&mut self) -> TickReport {
        self.tick_measured(|_| {})
    }

    /// [`Rig::tick`] with the measurement passed through `edit` first (a
    /// sensor error the plant does not have).
    pub fn tick_measured(&mut self, edit: impl FnOnce(&mut Measurement)) -> TickReport {
        let mut m = self.plant.read();
        if let Some(m) = &mut m {
            edit(m);
        }
        let rep = *self.exec.tick(m.as_ref());
        self.plant.write(&rep.setpoint);
        if let Some(req) = self.exec.take_plan_request() {
            let plan = match self.scripted.take() {
                Some(p) => Ok(Box::new(p)),
                None => req.plan(&self.planner).map(Box::new),
            };
            drop(self.exec.deliver_plan(req.goal, plan));
        }
        while let Some(e) = self.exec.pop_event() {
            match e {
                ExecutorEvent::Goal { id, state, .. } if state.is_terminal() => {
                    self.stats.goals.push((id, state))
                }
                ExecutorEvent::Fault { .. } => self.stats.faults += 1,
                ExecutorEvent::Drift { .. } => self.stats.drifts += 1,
                ExecutorEvent::NearLimit { kind, finger, .. } => {
                    self.stats.near_limits.push((kind, finger))
                }
                // (After a plan delivered above, the executor moves now.)
                ExecutorEvent::Step { kind, .. } if self.exec.phase() != Mode::Moving => {
                    self.stats.unmoved_steps.push((rep.tick, kind))
                }
                _ => {}
            }
        }
        self.check(&rep);
        rep
    }

    fn check(&mut self, rep: &TickReport) {
        let t = rep.tick;
        self.stats.ticks += 1;
        let mut v = Vec::new();
        self.checker.check(&rep.setpoint.state, 0, &mut v);
        self.stats.violations.extend(v.into_iter().map(|x| (t, x)));
        // A re-based estimate (new epoch) is a change of belief, not motion.
        if let Some(prev) = &self.prev
            && prev.estimate_epoch == rep.setpoint.estimate_epoch
            && let Ok(slip) = self.slip.check_slip(&prev.state, &rep.setpoint.state)
            && !slip.ok()
        {
            self.stats.slips += 1;
        }
        // The plant's truth, checked on its own: what the hand really did.
        let truth = *self.plant.state();
        let mut v = Vec::new();
        self.checker.check(&truth, 0, &mut v);
        self.stats
            .plant_violations
            .extend(v.into_iter().map(|x| (t, x)));
        if let Some(prev) = &self.prev_plant
            && let Ok(slip) = self.slip.check_slip(prev, &truth)
            && !slip.ok()
        {
            self.stats.plant_slips += 1;
        }
        self.prev_plant = Some(truth);
        let vel = velocities(&rep.setpoint);
        if let Some(pv) = self.prev_vel {
            let acc: [Vector3<f64>; 4] = std::array::from_fn(|i| (vel[i] - pv[i]) / self.dt);
            for a in &acc {
                if a.norm() > MAX_ACC {
                    self.stats.discontinuities.push((t, "velocity", a.norm()));
                }
            }
            if let Some(pa) = self.prev_acc {
                for i in 0..4 {
                    let j = (acc[i] - pa[i]).norm() / self.dt;
                    if j > MAX_JERK {
                        self.stats.discontinuities.push((t, "acceleration", j));
                    }
                }
            }
            self.prev_acc = Some(acc);
        }
        self.prev_vel = Some(vel);
        self.prev = Some(rep.setpoint);
    }

    /// Sends a command.
    pub fn command(&mut self, c: ExecutorCommand) -> gait::executor::ExecutorAnswer {
        self.exec.command(c)
    }

    /// Ticks until the executor holds still (or `max` ticks).
    pub fn run_until_idle(&mut self, max: u64) -> u64 {
        let mut n = 0;
        loop {
            let r = self.tick();
            n += 1;
            if (r.phase == Mode::Holding || r.phase == Mode::SafeHold) && n > 1 {
                return n;
            }
            if n >= max {
                return n;
            }
        }
    }
}
