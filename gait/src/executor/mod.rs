//! The per-tick controller (SPEC §6): advances a plan with the trajectory
//! generator, produces setpoints, checks every invariant, runs the goal
//! lifecycle and the gait state machine. Allocation-free per tick.
//!
//! # Gait state machine ([`Mode`])
//! ```text
//!   Holding ──goal──> Planning ──plan──> Moving ──last step──> Holding
//!      ^                 │  ^              │ goal/cancel/hold
//!      │                 │  └─── goal ─────┤
//!      │              no plan              v
//!      └────────────── (abort) ◄──────── Stopping ──at rest──> Planning (newer goal)
//!                                          │                   or Holding (cancel/hold)
//!   any ──fault──> SafeHold (a jerk-limited stop, then still) ──reset──> Holding
//! ```
//! Contact drift beyond tolerance stops the motion too, then re-bases the
//! estimate on the measurement and plans the goal again ([`recovery`]); so
//! does a measured state near an invariant's limit ([`guard`]).
//! A finger in flight finishes its placement or lift before a stop takes
//! effect; a stop elsewhere brakes along the current step's path, which is
//! valid everywhere (SPEC §6.4).
//!
//! # Planning off the control thread
//! The executor never plans. When it needs a plan it leaves a
//! [`PlanRequest`] ([`Executor::take_plan_request`]); whoever owns the
//! planner answers with [`Executor::deliver_plan`]. The executor keeps the
//! plan it is given and hands back the one it replaces, so that no plan is
//! ever freed on the control thread.

mod carrying;
mod command;
mod contact_watch;
pub mod correction;
pub mod feedback;
mod goal_slots;
mod goals;
mod grips;
pub mod guard;
pub mod lifecycle;
mod memo;
pub mod placement;
mod plant;
pub mod policy;
mod progress;
pub mod recovery;
pub mod runner;
mod tick_report;
pub mod tracking;
mod written;

use nalgebra::{UnitQuaternion, Vector3};

use crate::HandConfig;
use crate::config::{ConfigError, LimitsConfig};
use crate::grasp::grip;
use crate::hand::{InvariantChecker, InvariantReport, StateError};
use crate::hand_state::HandState;
use crate::planner::{Motion, Plan, PlanError, Setpoint, Step, StepKind};
use crate::sim::Measurement;
pub use command::{ExecutorAnswer, ExecutorCommand, GoalTarget, PlanRequest};
use feedback::{Feedback, NOT_A_FINGER};
pub use lifecycle::{ExecutorEvent, ExecutorEvents, FaultKind, GoalStage, Reason};
use policy::{Cause, Decision, FaultPolicy, Source};
use runner::StepRunner;
pub use tick_report::TickReport;
pub use written::WRITTEN;

/// The gait state machine's coarse state (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum Mode {
    /// At rest, grasp held, no goal running.
    Holding = 0,
    /// At rest, waiting for a plan.
    Planning = 1,
    /// Executing a plan step.
    Moving = 2,
    /// Braking to rest (a newer goal, cancel or hold).
    Stopping = 3,
    /// Fault: brakes to rest, then holds until reset.
    SafeHold = 4,
}

/// What to do once a stop comes to rest.
#[derive(Debug, Clone, Copy, PartialEq)]
enum AfterStop {
    /// Plan the pending goal.
    Replan,
    /// Hold; the active goal ends with this reason.
    Hold(Reason),
    /// Stay in safe hold.
    Fault,
    /// Plan the active goal again from the measured state (contact drift).
    Recover,
}

/// The executor (module docs).
#[derive(Debug)]
pub struct Executor {
    limits: LimitsConfig,
    checker: InvariantChecker,
    feedback: Feedback,
    /// Invariants near their limit in the measured state ([`guard`]).
    guard: guard::LimitGuard,
    runner: StepRunner,
    /// The plan and how far along it ([`progress`]).
    progress: progress::Progress,
    phase: Mode,
    after_stop: AfterStop,
    /// A stop is wanted but the current step (a placement or lift) finishes
    /// first.
    stop_after_step: bool,
    /// The active goal, one waiting, the last ended, the plan request
    /// ([`goal_slots`]).
    goals: goal_slots::GoalSlots,
    setpoint: Setpoint,
    prev_setpoint: Setpoint,
    prev_measurement: Option<Measurement>,
    /// The last measurement as the plant sent it (`prev_measurement` is
    /// its [`tracking`] estimate), to tell a new one from a repeat.
    prev_raw: Option<Measurement>,
    /// Tick at which `prev_measurement` arrived.
    measured_at: u64,
    fault: Option<(FaultKind, u8)>,
    /// In safe hold: still braking along the interrupted step.
    braking: bool,
    /// Commanded object angular acceleration [rad/s²].
    object_acceleration: Vector3<f64>,
    /// Object moment of inertia (solid sphere) [kg m²].
    inertia: f64,
    /// Radius of the sphere of grasping fingertip centres, R + r \[m\].
    contact_radius: f64,
    /// The setpoints written, for the measurements that reflect them.
    written: written::Written,
    /// The correction of the commanded grasp ([`correction`]).
    correction: correction::Correction,
    /// The object's pose from a tracking system, smoothed ([`tracking`]).
    tracking: tracking::Tracking,
    /// Fingertips placed where the object is measured ([`placement`]).
    placement: placement::Placement,
    /// The control period \[s\].
    dt: f64,
    /// Grasping contacts the plant measures as missing.
    contacts: contact_watch::ContactWatch,
    events: ExecutorEvents,
    report: TickReport,
    tick: u64,
    /// Invariants of the last checked setpoint state.
    invariants: memo::Memo<HandState, Result<InvariantReport, StateError>>,
    /// The grip forces of the setpoint.
    grips: grips::Grips,
    /// The fingers that carry the load, and the handover between two
    /// such sets ([`carrying`]).
    carrying: carrying::Carrying,
    /// Epoch of the object estimate (bumped on every re-base).
    epoch: u32,
    /// A drift waiting for the motion to rest to re-base (module
    /// [`recovery`]).
    drift: Option<recovery::Drift>,
    /// Drifts recovered since the active goal started.
    replans: u32,
    /// What every detected cause leads to ([`policy`]).
    policy: FaultPolicy,
}

/// A still setpoint at `state`.
pub(crate) fn rest(state: HandState) -> Setpoint {
    Setpoint {
        state,
        object_rate: Vector3::zeros(),
        finger_velocity: [Vector3::zeros(); 3],
        finger_rate: [Vector3::zeros(); 3],
        estimate_epoch: 0,
    }
}

/// The fault a broken invariant is, and the finger it concerns.
fn invariant_fault(v: crate::hand::Violation) -> (FaultKind, u8) {
    use crate::hand::{Invariant as I, Subject};
    let finger = match v.subject {
        Subject::Finger(k) | Subject::Pair(k, _) => k,
        Subject::Grasp => NOT_A_FINGER,
    };
    let kind = match v.invariant {
        I::ForceClosure => FaultKind::ForceClosure,
        I::Workspace | I::FreeSpace | I::JointLimit => FaultKind::Workspace,
        I::Hemisphere | I::Roll | I::TipPatch => FaultKind::Fingertip,
        I::Collision | I::LinkClearance => FaultKind::Collision,
        I::Contact | I::Slip | I::Spin => FaultKind::Contact,
    };
    (kind, finger)
}

/// Which finger a step concerns, for events (255: none in particular).
fn step_finger(step: &Step) -> u8 {
    step.finger().map_or(NOT_A_FINGER, |f| f as u8)
}

impl Executor {
    /// An executor of the free-fingertip hand holding `start` still,
    /// ticking every `dt` seconds.
    pub fn new(config: &HandConfig, dt: f64, start: HandState) -> Result<Self, ConfigError> {
        Self::for_hand(config, None, dt, start)
    }

    /// An executor of the chain hand `hand` (SPEC §14) holding `start`
    /// still: every tick checked against the chain's limits as well
    /// ([`InvariantChecker::for_chains`]); `config` as the chain planner's
    /// model sets it (the hand's radii and friction). It runs the chain
    /// planner's plans (carries and free moves of the tip centres).
    pub fn for_chains(
        config: &HandConfig,
        hand: crate::planner::chains::ChainHand,
        dt: f64,
        start: HandState,
    ) -> Result<Self, ConfigError> {
        Self::for_hand(config, Some(hand), dt, start)
    }

    /// The executor of either hand: the free fingertips of `config`
    /// ([`Executor::new`]) or the chain hand `chains`
    /// ([`Executor::for_chains`]).
    pub fn for_hand(
        config: &HandConfig,
        chains: Option<crate::planner::chains::ChainHand>,
        dt: f64,
        start: HandState,
    ) -> Result<Self, ConfigError> {
        config.validate()?;
        let runner = StepRunner::new(dt).map_err(|_| ConfigError::OutOfRange {
            key: "control.tick_hz",
            value: 1.0 / dt,
            expected: "a finite positive rate",
        })?;
        let sp = rest(start);
        let guard = guard::LimitGuard::new(config, chains.as_ref());
        // The closed forms and the planar certificate decide every case the
        // conic test would (gait::hand docs); the conic solve allocates and
        // costs ~70 µs, so it stays off the tick.
        let mut checker = match chains {
            Some(hand) => InvariantChecker::for_chains(config, hand)?,
            None => InvariantChecker::new(config)?,
        };
        checker.set_conic_fallback(false);
        Ok(Self {
            limits: config.limits,
            checker,
            feedback: Feedback::new(&config.feedback, config.model.object_radius),
            guard,
            runner,
            progress: progress::Progress::default(),
            phase: Mode::Holding,
            after_stop: AfterStop::Hold(Reason::None),
            stop_after_step: false,
            goals: goal_slots::GoalSlots::default(),
            setpoint: sp,
            prev_setpoint: sp,
            prev_measurement: None,
            prev_raw: None,
            measured_at: 0,
            fault: None,
            braking: false,
            object_acceleration: Vector3::zeros(),
            inertia: 0.4 * config.load.object_mass * config.model.object_radius.powi(2),
            contact_radius: config.model.object_radius + config.model.fingertip_radius,
            written: written::Written::new(start),
            correction: correction::Correction::new(
                config.feedback.orientation_gain,
                config.feedback.max_correction_deg.to_radians(),
            ),
            tracking: tracking::Tracking::new(config.feedback.tracker_gain),
            placement: placement::Placement::new(
                config.feedback.max_place_offset,
                config.model.object_radius + config.model.fingertip_radius,
            ),
            dt,
            contacts: contact_watch::ContactWatch::new(
                config.feedback.contact_grace_ticks,
                config.feedback.min_contact_force,
            ),
            events: ExecutorEvents::default(),
            report: TickReport {
                tick: 0,
                setpoint: sp,
                phase: Mode::Holding,
                step_kind: None,
                goal: None,
                remaining_angle: 0.0,
                gaits: (0, 0),
                eta: 0.0,
                grip: [0.0; 3],
                grip_force: [Vector3::zeros(); 3],
                grip_capped: false,
                grip_peak: 0.0,
                load_margin: config.load.max_grip,
                force_closure: (false, 0.0),
                workspace_slack: [0.0; 3],
                tip_slack: [0.0; 3],
                link_slack: [None; 3],
                joints: [None; 3],
                fault: None,
            },
            tick: 0,
            invariants: memo::Memo::new(),
            grips: grips::Grips::new(grip::GripModel::new(config)),
            carrying: carrying::Carrying::new(grip::grasp_mask(&start)),
            epoch: 0,
            drift: None,
            replans: 0,
            policy: FaultPolicy {
                max_replans: config.feedback.max_replans,
            },
        })
    }

    /// The coarse phase.
    pub fn phase(&self) -> Mode {
        self.phase
    }

    /// The last setpoint.
    pub fn setpoint(&self) -> &Setpoint {
        &self.setpoint
    }

    /// The last tick's report.
    pub fn report(&self) -> &TickReport {
        &self.report
    }

    /// The plan being executed, if any.
    pub fn plan(&self) -> Option<&Plan> {
        self.progress.plan()
    }

    /// Index of the running step.
    pub fn step_index(&self) -> usize {
        self.progress.index()
    }

    /// Next queued event.
    pub fn pop_event(&mut self) -> Option<ExecutorEvent> {
        self.events.pop()
    }

    /// Events lost because nobody drained the queue.
    pub fn events_dropped(&self) -> u64 {
        self.events.dropped
    }

    /// The goal whose plan the executor waits for, if any.
    pub fn planning_for(&self) -> Option<u64> {
        if self.phase == Mode::Planning {
            self.goals.active().map(|g| g.id)
        } else {
            None
        }
    }

    /// The plan request left for the planner, if any.
    pub fn take_plan_request(&mut self) -> Option<PlanRequest> {
        self.goals.take_request()
    }

    /// Step trajectories the trajectory generator calculated on this
    /// thread (the loop's): steps whose plan brought no profile for them,
    /// and stops. A plan from [`PlanRequest::plan_within`] brings every
    /// step's.
    pub fn trajectory_calculations(&self) -> u64 {
        self.runner.calculations()
    }

    fn current_step(&self) -> Option<&Step> {
        self.progress.current()
    }

    fn begin_step(&mut self) {
        let active = self.goals.active();
        let limits = active.map_or(self.limits, |g| g.limits);
        let goal = active.map_or(0, |g| g.id);
        let index = self.progress.index() as u32;
        let Some((step, profile)) = self.progress.begin(self.dt, goal) else {
            return;
        };
        self.runner.start(step, &limits, profile);
        let event = ExecutorEvent::Step {
            id: goal,
            index,
            kind: step.kind,
            finger: step_finger(step),
        };
        self.events.push(event);
    }

    /// Carries out the [`policy`]'s decision for `cause` (about `finger`),
    /// seen this tick; `m` is the measurement it was seen in, if any.
    fn handle(&mut self, cause: Cause, finger: u8, m: Option<&Measurement>) {
        let recovering = self.drift.is_some();
        match self
            .policy
            .decide(cause, self.phase, self.replans, recovering)
        {
            Decision::Ignore => {}
            Decision::SafeHold => self.enter_fault(cause.kind, finger),
            Decision::Replan => match m {
                Some(m) => self.recover(cause.kind, finger, m),
                // Nothing measured to re-base on.
                None => self.enter_fault(cause.kind, finger),
            },
        }
    }

    /// Safe hold (only through [`Executor::handle`]'s decision).
    fn enter_fault(&mut self, kind: FaultKind, finger: u8) {
        if self.fault.is_some() {
            return;
        }
        self.fault = Some((kind, finger));
        self.events.push(ExecutorEvent::Fault { kind, finger });
        self.end_goal(GoalStage::Aborted, Reason::Fault);
        self.end_pending(GoalStage::Aborted, Reason::Fault);
        let moving = matches!(self.phase, Mode::Moving | Mode::Stopping);
        // A handover stops where it is: every touching finger carries.
        self.carrying.abandon_handover();
        self.phase = Mode::SafeHold;
        self.after_stop = AfterStop::Fault;
        self.stop_after_step = false;
        // Brake along the current path; if that is impossible the step's own
        // end (at rest) is used (StepRunner::stop).
        self.braking = moving && self.runner.stop().is_ok();
    }

    /// One control period (SPEC §6.1): check the measurement, advance the
    /// motion, check the invariants of the new setpoint, fill the report.
    /// `measurement` is what the plant reported this tick (`None`: nothing
    /// arrived). Allocation-free.
    pub fn tick(&mut self, measurement: Option<&Measurement>) -> &TickReport {
        self.tick += 1;
        let mut error = Vector3::zeros();
        // A measurement older than the setpoints kept counts as none.
        let measurement = measurement.filter(|m| (m.age as usize) < WRITTEN - 1);
        // The setpoint it reflects, to compare with; the previous
        // measurement is compared with the one it reflected (a measurement
        // held or repeated reflects the same setpoint: no motion expected).
        let age = measurement.map_or(0, |m| m.age as usize);
        let (cmd, adjusted) = self.written.at(age);
        let (prev_cmd, prev_adjusted) = *self.written.reflected();
        let offset = self.drift.map_or(UnitQuaternion::identity(), |d| d.offset);
        // The object as tracked: each sample against the plan of its own
        // tick, smoothed over samples ([`tracking`]); what follows sees that
        // estimate, the raw measurement is kept for telling a new one.
        let raw = measurement;
        let estimate = raw.map(|m| {
            let sampled = match m.object_age {
                0 => cmd,
                n => self.written.at(age + n as usize).0,
            };
            self.tracking
                .estimate(m, &cmd, &sampled, &offset, self.epoch)
        });
        let measurement = estimate.as_ref();
        if self.phase != Mode::SafeHold {
            match self.feedback.check(
                measurement,
                &cmd,
                &prev_cmd,
                self.prev_measurement.as_ref(),
                &offset,
                (&adjusted, &prev_adjusted),
            ) {
                Ok(err) => {
                    error = err;
                    // (Ok means a measurement arrived.)
                    let moving = self.phase == Mode::Moving;
                    if let Some(m) = measurement
                        && let Some((kind, finger)) =
                            self.guard.observe(moving, &mut self.checker, &cmd, m)
                    {
                        self.handle(Cause::new(kind, Source::NearLimit), finger, Some(m));
                    }
                }
                Err((kind, finger)) => {
                    self.handle(Cause::new(kind, Source::Measurement), finger, measurement)
                }
            }
        }
        let new_measurement = raw.is_some_and(|m| {
            self.prev_raw
                .is_none_or(|p| p.object != m.object || p.fingers != m.fingers)
        });
        if let Some(m) = raw {
            self.prev_raw = Some(*m);
        }
        if let Some(m) = measurement {
            self.check_contacts(&cmd, m);
            self.prev_measurement = Some(*m);
            self.written.set_reflected((cmd, adjusted));
            self.measured_at = self.tick;
        }
        // Only a hand under control corrects (not in safe hold), and only
        // on a new measurement (one held or repeated adds nothing).
        if self.phase != Mode::SafeHold && new_measurement {
            self.correction.update(&error, self.dt);
        } else {
            self.correction.freeze();
        }
        self.prev_setpoint = self.setpoint;
        self.advance();
        self.placement.update(
            &self.setpoint.state,
            measurement
                .filter(|m| m.is_finite())
                .and_then(|m| m.center.as_ref()),
            self.dt,
        );
        self.update_carrying();
        self.setpoint.estimate_epoch = self.epoch;
        self.remember_written();
        self.check_invariants();
        self.fill_report();
        &self.report
    }

    /// A grasping contact the plant measures as not touching (its flag, or
    /// a measured force below `feedback.min_contact_force`) for
    /// `feedback.contact_grace_ticks` ticks in a row is lost: a fault.
    fn check_contacts(&mut self, cmd: &HandState, m: &Measurement) {
        let lost = self.contacts.lost(cmd, m);
        for k in (0..lost.len()).filter(|&k| lost[k]) {
            let cause = Cause::new(FaultKind::ContactLost, Source::Measurement);
            self.handle(cause, k as u8, Some(m));
        }
    }

    /// Moves the setpoint one period along the running step.
    fn advance(&mut self) {
        let moving = match self.phase {
            Mode::Moving | Mode::Stopping => true,
            Mode::SafeHold => self.braking,
            Mode::Holding | Mode::Planning => false,
        };
        if !moving {
            self.setpoint = rest(self.setpoint.state);
            self.object_acceleration = Vector3::zeros();
            return;
        }
        if let Some(over) = self.carrying.advance_handover(self.dt) {
            // At rest while the grip passes; then the step ends.
            self.setpoint = rest(self.setpoint.state);
            self.object_acceleration = Vector3::zeros();
            if over {
                self.end_of_step(false);
            }
            return;
        }
        let status = match self.runner.advance() {
            Ok(s) => s,
            Err(_) => {
                let cause = Cause::new(FaultKind::Trajectory, Source::Trajectory);
                self.handle(cause, NOT_A_FINGER, None);
                self.braking = false;
                self.setpoint = rest(self.setpoint.state);
                return;
            }
        };
        let path = self.runner.state();
        self.object_acceleration = match self.current_step().map(|s| &s.motion) {
            Some(Motion::Rotate { axis, .. } | Motion::Carry { axis, .. }) => {
                axis * path.acceleration[0]
            }
            _ => Vector3::zeros(),
        };
        let Some(sp) = self
            .current_step()
            .map(|s| (s.eval(&path.position, &path.velocity), s.kind))
        else {
            self.setpoint = rest(self.setpoint.state);
            return;
        };
        let (setpoint, _) = sp;
        self.setpoint = setpoint;
        if status != otg::Progress::Finished {
            return;
        }
        // At rest: the end of the step, or of a stop.
        let stopped_early = self.runner.stopping();
        if !stopped_early && let Some(step) = self.current_step() {
            // Exactly the planned end state (the generator's last sample
            // may differ from the target in the last bits).
            let end = step.eval(&step.dofs().length, &[0.0; 3]).state;
            self.setpoint.state = end;
        }
        self.setpoint = rest(self.setpoint.state);
        if self.phase == Mode::SafeHold {
            self.braking = false;
            return;
        }
        if !stopped_early
            && let Some(h) = self.current_step().and_then(|s| s.handover)
            && h.duration > 0.0
        {
            // The motion is done; the grip passes before the step ends.
            self.object_acceleration = Vector3::zeros();
            self.carrying.begin_handover(&h);
            return;
        }
        self.end_of_step(stopped_early);
    }

    /// The running step has ended (at rest): count it, then stop or begin
    /// the next one.
    fn end_of_step(&mut self, stopped_early: bool) {
        let Some(kind) = self.current_step().map(|s| s.kind) else {
            return;
        };
        if !stopped_early {
            self.progress.finished(kind);
            let finger = self.current_step().map_or(NOT_A_FINGER, step_finger);
            self.events.push(ExecutorEvent::StepDone {
                id: self.progress.step_goal(),
                index: self.progress.index() as u32,
                kind,
                finger,
            });
        }
        // Stopping ends here whether the brake made it early, the step was
        // a gait finishing (`stop_after_step`) or braking would have
        // overshot the path so the step ran to its end: the next step is
        // never begun (nor announced).
        if self.phase == Mode::Stopping {
            self.finish_stop(self.after_stop);
            return;
        }
        if !self.progress.next() {
            self.end_goal(GoalStage::Succeeded, Reason::None);
            self.phase = Mode::Holding;
            return;
        }
        self.begin_step();
    }

    fn check_invariants(&mut self) {
        let checker = &mut self.checker;
        match self
            .invariants
            .get(self.setpoint.state, |s| checker.check(s))
        {
            Ok(r) => {
                self.report.force_closure =
                    (r.force_closure.check.pass, r.force_closure.check.slack);
                for (k, f) in r.fingers.iter().enumerate() {
                    self.report.workspace_slack[k] = f.workspace.slack;
                    self.report.tip_slack[k] = f.hemisphere.map_or(0.0, |c| c.slack);
                    self.report.link_slack[k] = f.links.map(|c| c.slack);
                }
                if let Some(v) = r.first_violation() {
                    let (kind, finger) = invariant_fault(v);
                    self.handle(Cause::new(kind, Source::ExecutorCommand), finger, None);
                }
            }
            Err(_) => {
                let cause = Cause::new(FaultKind::Contact, Source::ExecutorCommand);
                self.handle(cause, NOT_A_FINGER, None);
            }
        }
    }

    /// Keeps the carrying set ([`carrying`]) in step with the setpoint;
    /// the running step's handover names the finger that waits for it.
    fn update_carrying(&mut self) {
        let grasp = grip::grasp_mask(&self.setpoint.state);
        let moving = matches!(self.phase, Mode::Moving | Mode::Stopping);
        let pending = if moving {
            self.current_step()
                .and_then(|s| s.handover)
                .map_or(0, |h| h.take_mask())
        } else {
            0
        };
        self.carrying.update(grasp, moving, pending);
    }
}
