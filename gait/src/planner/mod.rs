//! The reorientation planner (SPEC §4; paper §2, §3.2).
//!
//! # What it does, top to bottom
//! 1. **Check the request**: a finite goal, a finite start that is a
//!    force-closure grasp of two or three fingers and holds the load
//!    ([`PlanError`] says what is wrong otherwise).
//! 2. **State the progress**: the rotation still to do, from the start to
//!    an orientation goal or for a turn of a given size ([`goal`]).
//! 3. **Search**: one A* over grasps and the rotation left ([`search`]),
//!    whose actions — turns by two or three fingers, substitutions, lifts,
//!    tilts, detours, the hand's regrasps — and their order are listed in
//!    [`alternatives`]. It asks the hand everything through one trait,
//!    [`hand_model::HandModel`]; the paper's free fingertips implement it
//!    ([`fingertips`]).
//! 4. **Under one budget, in passes**: the search runs again with a more
//!    permissive load test, then with spinning contacts, only when the
//!    pass before proved it finds nothing ([`alternatives::PASSES`]). The
//!    caller's [`budget::Budget`] bounds all of it: expansions, and the
//!    caller's clock and cancel flag, polled before every expansion.
//! 5. **Certify**: the first plan found is built into steps ([`plan`]) and
//!    checked at every sample (SPEC §1.3, I1' exactly); a plan that fails
//!    is dropped and the search goes on.
//!
//! Every plan records its route (the actions, and the pass that found it)
//! and its effort ([`PlanSummary`]). Planning allocates and is bounded by
//! the budget, not by a tick: it never runs on the control-loop thread
//! (SPEC §7.2). With an expansion budget only, it is deterministic: the
//! same state, goal and configuration give the same plan, bit for bit.

pub mod alternatives;
pub mod budget;
pub mod candidates;
pub mod carry_path;
pub mod chains;
pub mod collision;
pub mod fingertips;
pub mod gaiting;
pub mod geometry;
pub mod goal;
pub mod hand_model;
pub mod load;
pub mod plan;
pub mod preview;
pub mod route;
pub mod search;
pub mod timing;
pub mod zigzag;

use nalgebra::{UnitQuaternion, Vector3};

pub use budget::{Budget, Effort, Halt, Stop, Unbounded};
pub use goal::rotation_to;
pub use plan::{
    FreeMove, FreePath, Handover, MAX_DOFS, Motion, Setpoint, Step, StepDofs, StepKind, StepLimit,
};
pub use route::Route;

use crate::config::{ConfigError, HandConfig};
use crate::hand_state::{FingerMode, HandState};
use alternatives::PASSES;
use fingertips::Fingertips;
use geometry::{Geometry, rotation};
use goal::{Course, Remaining};
use hand_model::HandModel;
use search::{NotFound, Params};
use timing::DurationModel;

/// Why no plan was returned.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, thiserror::Error)]
pub enum PlanError {
    /// The goal quaternion has a non-finite or zero component vector.
    #[error("goal orientation is not a finite non-zero quaternion")]
    InvalidGoal,
    /// The motion limits to time the plan with are not finite and positive.
    #[error("motion limits are not finite and positive")]
    InvalidLimits,
    /// The start state has a number that is not finite.
    #[error("start state contains a non-finite number")]
    NonFiniteState,
    /// Fewer than two fingers grasp, or the grasping fingers are not
    /// force-closure.
    #[error("start state is not a force-closure grasp")]
    NoGrasp,
    /// Three fingers grasp, no pair is force-closure, and no roll reaches a
    /// force-closure pair.
    #[error("no roll reaches a two-finger force-closure grasp from this three-finger grasp")]
    NoTwoFingerGrasp,
    /// The search proved that no plan exists at its resolution.
    #[error("no plan reaches the goal")]
    SearchExhausted,
    /// The planning budget (time or expansions) ran out before a plan was
    /// found.
    #[error("planning ran out of its budget (time or expansions) before it found a plan")]
    Timeout,
    /// The caller canceled the request while it was being planned.
    #[error("planning was canceled")]
    Canceled,
    /// A free finger could not travel without coming too close to another.
    #[error("finger {finger} cannot travel clear of the other fingertips")]
    Blocked {
        /// The finger.
        finger: usize,
    },
    /// No plan found keeps the load feasible (SPEC §1.3 I1': every grasp
    /// holds the weight, the acceleration torque and the disturbance with
    /// normal forces within `load.max_grip`); `start`: the start grasp
    /// itself cannot hold it.
    #[error("{}", if *start { "the start grasp cannot hold the load within load.max_grip" } else { "no plan keeps the load within load.max_grip" })]
    LoadInfeasible {
        /// Whether the start grasp already fails.
        start: bool,
    },
}

/// Plan statistics (SPEC §11 plan quality), its route's pass and the
/// effort of finding it.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PlanSummary {
    /// Place and Lift steps.
    pub gaits: u32,
    /// Finger substitutions among them (paper §2.1; [`gaiting`]).
    pub substitutions: u32,
    /// Finger rewinds (their two or three substitutions are also counted).
    pub rewinds: u32,
    /// Rotate steps.
    pub rotations: u32,
    /// Roll steps.
    pub rolls: u32,
    /// Execution time at the configured limits, rest to rest per step \[s\].
    pub duration: f64,
    /// Angle of the rotation from start to goal \[rad\].
    pub goal_angle: f64,
    /// Whether the object first turned about another axis, or the grasp
    /// was changed on the still object, because no gait could follow
    /// (paper Theory 1), or a detour made the plan quicker.
    pub escaped: bool,
    /// The effort of finding it.
    pub effort: Effort,
}

/// A complete plan.
#[derive(Debug, Clone, PartialEq)]
pub struct Plan {
    /// The state it starts from.
    pub start: HandState,
    /// The goal object orientation.
    pub goal: UnitQuaternion<f64>,
    /// The primitive steps, in order.
    pub steps: Vec<Step>,
    /// Statistics.
    pub summary: PlanSummary,
    /// The actions the search chose and the pass that found them.
    pub route: Route,
    /// Each step's trajectory, calculated off the real-time thread for
    /// the limits and control period it runs with
    /// ([`timing::step_profiles`]; empty: the executor calculates each at
    /// the step's start).
    pub profiles: Vec<Option<timing::StepProfile>>,
}

impl Plan {
    /// The state after the last step (the start if there are none).
    pub fn end_state(&self) -> HandState {
        self.steps
            .last()
            .map_or(self.start, |s| s.eval(&s.dofs().length, &[0.0; 3]).state)
    }
}

/// What a request asks for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Target {
    /// The object at this orientation (any path).
    Orientation(UnitQuaternion<f64>),
    /// The object turned by `angle` about `axis` (hand frame): that far,
    /// full turns included.
    Turn {
        /// Axis (any length > 0).
        axis: Vector3<f64>,
        /// Angle \[rad\] (negative: the other way).
        angle: f64,
    },
}

/// What plans a goal for the executor, whichever hand it plans for: the
/// free fingertips' [`Planner`] or a chain hand's
/// [`chains::planner::ChainPlanner`].
pub trait GoalPlanner: Sized {
    /// The configuration it plans with (its motion limits and budget).
    fn config(&self) -> &HandConfig;
    /// The same planner under other motion limits (a goal's overrides).
    fn with_limits(&self, limits: &crate::config::LimitsConfig) -> Result<Self, ConfigError>;
    /// Plans `target` from `start` within `budget`.
    fn plan_target(
        &self,
        start: &HandState,
        target: &Target,
        budget: &mut Budget<'_>,
    ) -> Result<Plan, PlanError>;
}

impl GoalPlanner for Planner {
    fn config(&self) -> &HandConfig {
        &self.config
    }

    fn with_limits(&self, limits: &crate::config::LimitsConfig) -> Result<Self, ConfigError> {
        Planner::with_limits(self, limits)
    }

    fn plan_target(
        &self,
        start: &HandState,
        target: &Target,
        budget: &mut Budget<'_>,
    ) -> Result<Plan, PlanError> {
        self.plan_within(start, target, budget)
    }
}

/// The planner: configuration plus precomputed geometry. Cheap to share
/// read-only between threads.
#[derive(Debug, Clone)]
pub struct Planner {
    config: HandConfig,
    hand: Fingertips,
    params: Params,
}

impl Planner {
    /// Builds the planner for a configuration (validated here).
    pub fn new(config: &HandConfig) -> Result<Self, ConfigError> {
        config.validate()?;
        let p = &config.planner;
        Ok(Self {
            config: *config,
            hand: Fingertips::new(config),
            params: Params {
                branching: p.branching as usize,
                detour_axes: fibonacci_sphere(p.detour_axes as usize),
                escape_axes: fibonacci_sphere(p.escape_axes as usize),
            },
        })
    }

    /// The same planner costing and timing plans under `limits` instead of
    /// the configured ones (a goal's motion-limit overrides, SPEC §7.3): the
    /// plan's cost is its execution time under the limits it is executed
    /// with (SPEC §4.3). Cheap: the candidate grids are shared.
    pub fn with_limits(&self, limits: &crate::config::LimitsConfig) -> Result<Self, ConfigError> {
        let config = HandConfig {
            limits: *limits,
            ..self.config
        };
        config.validate()?;
        Ok(Self {
            config,
            hand: self.hand.with_limits(limits),
            params: self.params.clone(),
        })
    }

    /// Model constants.
    pub fn geometry(&self) -> &Geometry {
        self.hand.geometry()
    }

    /// Step durations.
    pub fn timing(&self) -> &DurationModel {
        self.hand.timing()
    }

    /// The search's load test (SPEC §1.3 I1').
    pub fn load(&self) -> &load::PairLoad {
        self.hand.pair_load()
    }

    /// The configuration.
    pub fn config(&self) -> &HandConfig {
        &self.config
    }

    /// Does once, ahead of any goal, the work planning from `start` begins
    /// with that the goal barely changes, and keeps it (the hand's caches,
    /// shared by every clone of this planner): from three grasping fingers,
    /// the ways to roll each pair apart, here and after the tilts the
    /// search tries first — found by planning quarter turns about the
    /// hand's six axis directions. The daemon calls it for its start state
    /// on the planner thread at start-up (about 0.9 s of CPU at the
    /// defaults), so the first goal does not pay it. Plans are the same
    /// with or without it: the caches return what a search would.
    pub fn prepare(&self, start: &HandState) {
        if !state_finite(start) || start.grasping().1 != 3 {
            return;
        }
        let hand = self.hand.for_pass(true, PASSES[0].spins);
        let mut never = Unbounded;
        for lift in 0..3 {
            let _ = hand.regrasps(start, hand_model::RegraspFor::OpenPair { lift }, &mut never);
        }
        for k in 0..6 {
            let mut axis = Vector3::zeros();
            axis[k % 3] = if k < 3 { 1.0 } else { -1.0 };
            let _ = self.plan_rotation(start, &axis, std::f64::consts::FRAC_PI_2);
        }
    }

    /// Roll-apart paths searched so far by this planner and its clones
    /// (the rest came from what the hand kept).
    pub fn roll_apart_searches(&self) -> u64 {
        self.hand.zigzag_searches()
    }

    /// Plans from `start` to the object orientation `goal`, within the
    /// configured expansion budget (deterministic).
    pub fn plan(&self, start: &HandState, goal: &UnitQuaternion<f64>) -> Result<Plan, PlanError> {
        let mut never = Unbounded;
        let mut budget = Budget::new(self.config.planner.max_expansions, &mut never);
        self.plan_within(start, &Target::Orientation(*goal), &mut budget)
    }

    /// Plans a turn of the object by `angle` (any size, e.g. a full turn)
    /// about the hand-frame `axis`: the object turns that far, not just to
    /// the orientation it ends at. Within the configured expansion budget.
    pub fn plan_rotation(
        &self,
        start: &HandState,
        axis: &Vector3<f64>,
        angle: f64,
    ) -> Result<Plan, PlanError> {
        let mut never = Unbounded;
        let mut budget = Budget::new(self.config.planner.max_expansions, &mut never);
        let t = Target::Turn { axis: *axis, angle };
        self.plan_within(start, &t, &mut budget)
    }

    /// Plans `target` from `start` within `budget` (module docs).
    pub fn plan_within(
        &self,
        start: &HandState,
        target: &Target,
        budget: &mut Budget<'_>,
    ) -> Result<Plan, PlanError> {
        if !state_finite(start) {
            return Err(PlanError::NonFiniteState);
        }
        // The orientations to reach in turn: the goal, or a turn's pieces.
        let course = Course::new(&start.object, target)?;
        self.check_start(start)?;
        let mut effort = Effort::default();
        let pieces = course.pieces;
        let mut at = *start;
        let (mut steps, mut route, mut pass) = (Vec::new(), Vec::new(), 0);
        for k in 1..=pieces {
            let to = course.piece(k);
            let rem = Remaining::orientation(&at.object, &to);
            if rem.reached() {
                continue;
            }
            let piece = Piece {
                first: k == 1,
                goes_on: k < pieces,
            };
            let (s, r, p) = self.search(&at, rem, piece, budget, &mut effort)?;
            at = s
                .last()
                .map_or(at, |st| st.eval(&st.dofs().length, &[0.0; 3]).state);
            steps.extend(s);
            route.extend(r);
            pass = pass.max(p);
        }
        Ok(assemble(
            start,
            course.goal,
            course.angle,
            join_turns(steps, &self.config.limits),
            Route {
                passes: &alternatives::PASSES,
                pass,
                steps: route,
            },
            effort,
        ))
    }

    /// The portfolio's passes for `rem` from `start` (module docs): the
    /// steps, the route and the pass that found them.
    fn search(
        &self,
        start: &HandState,
        rem: Remaining,
        piece: Piece,
        budget: &mut Budget<'_>,
        effort: &mut Effort,
    ) -> Result<(Vec<Step>, Vec<route::RouteStep>, usize), PlanError> {
        let mut best: Option<(search::Found<Fingertips>, usize, Fingertips)> = None;
        let mut last = NotFound::Exhausted {
            blocked: None,
            refused: false,
            pairs: false,
        };
        // What a pass searches with: its role, detours, spins.
        let searches_as = |p: &alternatives::Pass| {
            (
                p.role,
                piece.first || p.later_detours,
                p.spins && self.hand.load_active(),
            )
        };
        for (i, pass) in PASSES.iter().enumerate() {
            if PASSES[..i]
                .iter()
                .any(|p| searches_as(p) == searches_as(pass))
            {
                continue;
            }
            let detours = piece.first || pass.later_detours;
            let found = best.as_ref().map(|(f, _, _)| f.duration);
            let Some(mode) =
                search::Mode::for_pass(pass, found, budget.used(), detours, piece.goes_on)
            else {
                continue;
            };
            effort.passes += 1;
            let hand = self.hand.for_pass(true, pass.spins);
            match search::run(&hand, &self.params, mode, start, rem, budget, effort) {
                Ok(found) => best = Some((found, i, hand)),
                Err(NotFound::Halted(h)) if best.is_none() => {
                    return Err(match h {
                        Halt::OutOfBudget => PlanError::Timeout,
                        Halt::Canceled => PlanError::Canceled,
                    });
                }
                Err(NotFound::Halted(Halt::Canceled)) => return Err(PlanError::Canceled),
                Err(NotFound::Halted(Halt::OutOfBudget) | NotFound::Capped) => {}
                Err(e) if best.is_none() => last = e,
                Err(_) => {}
            }
        }
        if let Some((found, pass, hand)) = best {
            let route = Route::new(&alternatives::PASSES, pass, start, &hand, &found.actions);
            return Ok((found.steps, route.steps, pass));
        }
        Err(match last {
            NotFound::Exhausted {
                blocked: Some(finger),
                ..
            } => PlanError::Blocked { finger },
            NotFound::Exhausted { pairs: false, .. } if start.grasping().1 == 3 => {
                PlanError::NoTwoFingerGrasp
            }
            _ if self.hand.load_active() => PlanError::LoadInfeasible { start: false },
            _ => PlanError::SearchExhausted,
        })
    }

    /// The start must be a force-closure grasp that holds the load.
    fn check_start(&self, start: &HandState) -> Result<(), PlanError> {
        let (idx, n) = start.grasping();
        if n < 2 {
            return Err(PlanError::NoGrasp);
        }
        if n == 2 {
            let g = self.hand.geometry();
            let (ca, cb) = (
                start.fingers[idx[0]].contact_normal(),
                start.fingers[idx[1]].contact_normal(),
            );
            if ca.dot(&cb) > g.cos_fc + 1e-9 {
                return Err(PlanError::NoGrasp);
            }
        }
        if !self.hand.holds_at_rest(start) {
            return Err(PlanError::LoadInfeasible { start: true });
        }
        Ok(())
    }
}

/// The plan of `steps` found by `route`, with its statistics.
pub(crate) fn assemble(
    start: &HandState,
    goal: UnitQuaternion<f64>,
    goal_angle: f64,
    steps: Vec<Step>,
    route: Route,
    effort: Effort,
) -> Plan {
    let mut s = PlanSummary {
        goal_angle,
        effort,
        ..PlanSummary::default()
    };
    for st in &steps {
        match st.kind {
            StepKind::Place | StepKind::Lift => s.gaits += 1,
            StepKind::Rotate if step_rotation_angle(st) == 0.0 => {}
            StepKind::Rotate => s.rotations += 1,
            StepKind::Roll => s.rolls += 1,
            StepKind::Transfer => {}
        }
        s.duration += st.duration;
    }
    (s.substitutions, s.rewinds) = count_finger_gaits(&steps);
    s.escaped = route.escaped();
    Plan {
        start: *start,
        goal,
        steps,
        summary: s,
        route,
        profiles: Vec::new(),
    }
}

/// Where one search sits in a goal: the whole goal, or a piece of a turn.
#[derive(Debug, Clone, Copy)]
struct Piece {
    /// The first (or only) piece: it may first turn about another axis.
    first: bool,
    /// More pieces follow: it must end with a pair grasping.
    goes_on: bool,
}

/// `steps` with each turn that continues the one before it (same axis, the
/// same grasp, nothing between: where two pieces of a long turn meet)
/// made one, so the object does not stop between them.
fn join_turns(steps: Vec<Step>, limits: &crate::config::LimitsConfig) -> Vec<Step> {
    let mut out: Vec<Step> = Vec::with_capacity(steps.len());
    for st in steps {
        if let (
            Some(prev),
            Motion::Rotate {
                axis,
                angle,
                free: None,
            },
        ) = (out.last_mut(), st.motion)
            && let Motion::Rotate {
                axis: a0,
                angle: t0,
                free: None,
            } = prev.motion
            && prev.handover.is_none()
            && st.handover.is_none()
            && (a0 - axis).norm() < 1e-12
            && t0 > 0.0
            && angle > 0.0
        {
            prev.motion = Motion::Rotate {
                axis,
                angle: t0 + angle,
                free: None,
            };
            prev.duration = prev.planned_duration(limits);
            continue;
        }
        out.push(st);
    }
    out
}

/// The angle of a Rotate step (0 for a still handover step).
fn step_rotation_angle(st: &Step) -> f64 {
    match st.motion {
        Motion::Rotate { angle, .. } | Motion::Carry { angle, .. } => angle,
        _ => 0.0,
    }
}

/// (substitutions, rewinds) in `steps`, as the executor will report them.
fn count_finger_gaits(steps: &[Step]) -> (u32, u32) {
    let mut tracker = crate::planner::gaiting::GaitTracker::new();
    let (mut substitutions, mut rewinds) = (0, 0);
    for st in steps {
        tracker.started(st.kind);
        let finger = st.finger().map_or(u8::MAX, |f| f as u8);
        let done = tracker.done(st.kind, finger);
        substitutions += u32::from(done.substitution.is_some());
        rewinds += u32::from(done.rewind.is_some());
    }
    (substitutions, rewinds)
}

fn state_finite(h: &HandState) -> bool {
    h.object.coords.iter().all(|x| x.is_finite())
        && h.fingers.iter().all(|f| {
            f.center.iter().all(|x| x.is_finite())
                && f.orientation.coords.iter().all(|x| x.is_finite())
                && f.roll.is_finite()
                && (f.mode == FingerMode::Free || f.center.norm() > 0.0)
        })
}

/// `n` roughly uniform unit vectors (Fibonacci lattice), deterministic.
pub fn fibonacci_sphere(n: usize) -> Vec<Vector3<f64>> {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..n)
        .map(|i| {
            let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
            let r = (1.0 - z * z).sqrt();
            let phi = golden * i as f64;
            Vector3::new(r * phi.cos(), r * phi.sin(), z)
        })
        .collect()
}

/// Convenience: the orientation reached by rotating `from` about a hand-frame
/// axis by an angle (for relative goals).
pub fn relative_goal(
    from: &UnitQuaternion<f64>,
    axis: &Vector3<f64>,
    angle: f64,
) -> UnitQuaternion<f64> {
    rotation(&axis.normalize(), angle) * from
}
