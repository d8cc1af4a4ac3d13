//! The reorientation planner (SPEC §4; paper §2, §3.2).
//!
//! From any state satisfying SPEC §1.3 to any goal orientation: reach a
//! two-finger force-closure grasp ([`start`]), then A* over rotation segments
//! about the goal's axis with gaits between them ([`search`]). If no gait is
//! possible (paper Theory 1 fails for the pair) or the search finds nothing,
//! first rotate about another axis to a state where it does ([`Planner::plan`]
//! tries a set of axes). The result is a list of primitive [`Step`]s with
//! exact start states ([`plan`]).
//!
//! Planning allocates and is not bounded by a tick: it never runs on the
//! control-loop thread (SPEC §4.3, §7.2). It is deterministic: the same state,
//! goal and configuration give the same plan, bit for bit.

pub mod candidates;
pub mod collision;
pub mod convert;
mod detour;
pub mod escape;
pub mod geometry;
mod goals;
pub mod load;
pub mod plan;
pub mod search;
pub mod start;
pub mod timing;
mod triple;
pub mod zigzag;

use nalgebra::{UnitQuaternion, Vector3};

pub use plan::{
    FreeMove, FreePath, Handover, MAX_DOFS, Motion, Setpoint, Step, StepDofs, StepKind, StepLimit,
};

use crate::config::{ConfigError, HandConfig};
use crate::state::{FingerMode, HandState};
use candidates::Candidates;
use convert::Builder;
use geometry::{Geometry, rotation};
use search::{Problem, Root, split};
use start::{Start, starts};
use timing::DurationModel;

/// Heuristic weight of the retry when the first search runs out of budget.
const GREEDY_WEIGHT: f64 = 3.0;

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
    /// The search (with every escape rotation) found no plan in its budget.
    #[error("no plan found within the search budget")]
    SearchExhausted,
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

/// Plan statistics (SPEC §11 plan quality).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PlanSummary {
    /// Place and Lift steps.
    pub gaits: u32,
    /// Finger substitutions among them (paper §2.1; [`crate::gaiting`]).
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
    /// Whether an escape rotation about another axis was needed.
    pub escaped: bool,
    /// Search nodes expanded (all searches).
    pub expansions: u32,
}

impl PlanSummary {
    /// Adds the counts, time and expansions of a plan that follows (the
    /// gaits' kinds and the goal angle are the caller's to recount).
    fn add(&mut self, o: &PlanSummary) {
        self.gaits += o.gaits;
        self.rotations += o.rotations;
        self.rolls += o.rolls;
        self.duration += o.duration;
        self.escaped |= o.escaped;
        self.expansions += o.expansions;
    }
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
}

impl Plan {
    /// The state after the last step (the start if there are none).
    pub fn end_state(&self) -> HandState {
        self.steps
            .last()
            .map_or(self.start, |s| s.eval(&s.dofs().length, &[0.0; 3]).state)
    }

    /// This plan followed by `next` (which starts where this one ends):
    /// one plan to `next`'s goal, its statistics summed.
    pub fn then(mut self, next: Plan) -> Plan {
        let s = &mut self.summary;
        s.add(&next.summary);
        s.goal_angle = self.start.object.angle_to(&next.goal);
        self.steps.extend(next.steps);
        (s.substitutions, s.rewinds) = count_finger_gaits(&self.steps);
        self.goal = next.goal;
        self
    }
}

/// The planner: configuration plus precomputed geometry. Cheap to share
/// read-only between threads.
#[derive(Debug, Clone)]
pub struct Planner {
    config: HandConfig,
    geom: Geometry,
    timing: DurationModel,
    /// The search's load test.
    load: load::PairLoad,
    /// The exact grip model a built plan is checked with.
    grip: crate::executor::grip::GripModel,
    /// Shared: a planner re-timed for other limits
    /// ([`Planner::with_limits`]) reuses the candidate grids.
    cand: std::sync::Arc<Candidates>,
    /// The start's zigzag rolls found so far (shared by clones; a
    /// re-timed planner gets its own: the legs depend on the timing).
    /// `None`: the start rolls a pair apart by one great-circle roll only
    /// (the cheap planning after a three-finger turn, [`triple`]).
    zigzags: Option<std::sync::Arc<zigzag::ZigzagCache>>,
    /// Whether a failed search is followed by the escapes (rotation and
    /// roll escapes, the unwind); not in the cheap planning after a
    /// three-finger turn ([`triple`]), an alternative to a plan in hand.
    escapes: bool,
}

impl Planner {
    /// Builds the planner for a configuration (validated here).
    pub fn new(config: &HandConfig) -> Result<Self, ConfigError> {
        config.validate()?;
        let geom = Geometry::new(config);
        Ok(Self {
            config: *config,
            geom,
            timing: DurationModel::new(config),
            load: load::PairLoad::new(config),
            grip: crate::executor::grip::GripModel::new(config),
            cand: std::sync::Arc::new(Candidates::new(&geom, config.planner.candidate_spacing_deg)),
            zigzags: Some(Default::default()),
            escapes: true,
        })
    }

    /// The same planner costing and timing plans under `limits` instead of
    /// the configured ones (a goal's motion-limit overrides, SPEC §7.3): the
    /// plan's cost is its execution time under the limits it is executed
    /// with (SPEC §4.3). Cheap: the candidate grids are shared; only the
    /// timing tables are rebuilt.
    pub fn with_limits(&self, limits: &crate::config::LimitsConfig) -> Result<Self, ConfigError> {
        let config = HandConfig {
            limits: *limits,
            ..self.config
        };
        config.validate()?;
        Ok(Self {
            config,
            geom: self.geom,
            timing: DurationModel::new(&config),
            load: load::PairLoad::new(&config),
            grip: crate::executor::grip::GripModel::new(&config),
            cand: self.cand.clone(),
            zigzags: Some(Default::default()),
            escapes: self.escapes,
        })
    }

    /// Model constants.
    pub fn geometry(&self) -> &Geometry {
        &self.geom
    }

    /// Step durations.
    pub fn timing(&self) -> &DurationModel {
        &self.timing
    }

    /// The search's load test (SPEC §1.3 I1').
    pub fn load(&self) -> &load::PairLoad {
        &self.load
    }

    /// The configuration.
    pub fn config(&self) -> &HandConfig {
        &self.config
    }

    /// Plans the rotation by `total` about `axis` to `goal`. For an
    /// orientation goal (`turn` false) a first rotation about another axis
    /// is allowed when that is quicker; a requested turn must turn that far,
    /// and when an escape is unavoidable it still makes its full turns
    /// (`rest_after_escape`).
    fn plan_about(
        &self,
        start: &HandState,
        goal: &UnitQuaternion<f64>,
        axis: Vector3<f64>,
        total: f64,
        turn: bool,
        spins: bool,
    ) -> Result<Plan, PlanError> {
        let detours = !turn;
        let full_turns = if turn {
            Some((axis, (total / std::f64::consts::TAU + 1e-9).floor()))
        } else {
            None
        };
        let goal = *goal;
        let n_grasp = start.grasping().1;
        if n_grasp < 2 {
            return Err(PlanError::NoGrasp);
        }
        let mut summary = PlanSummary {
            goal_angle: total,
            ..PlanSummary::default()
        };
        if total < 1e-12 {
            return Ok(Plan {
                start: *start,
                goal,
                steps: Vec::new(),
                summary,
            });
        }
        if n_grasp == 2 {
            let ([a, b], _) = split(start).ok_or(PlanError::NoGrasp)?;
            let (ca, cb) = (
                start.fingers[a].contact_normal(),
                start.fingers[b].contact_normal(),
            );
            if ca.dot(&cb) > self.geom.cos_fc + 1e-9 {
                return Err(PlanError::NoGrasp);
            }
        }
        // The start must hold the load (at rest) for anything to follow.
        if self.load.active()
            && !self
                .grip
                .carried_with(start, crate::grasp::Accel::None, 0b111)
                .feasible
        {
            return Err(PlanError::LoadInfeasible { start: true });
        }
        let starts = starts(
            &self.geom,
            &self.timing,
            &self.load,
            &self.grip,
            &self.config,
            self.zigzags.as_deref(),
            start,
            &axis,
            self.config.planner.pair_margin_deg.to_radians(),
        );
        if starts.is_empty() {
            return Err(if self.load.active() {
                PlanError::LoadInfeasible { start: false }
            } else {
                PlanError::NoTwoFingerGrasp
            });
        }
        // 1. Straight: search about the goal axis from every start.
        let roots: Vec<Root> = starts
            .iter()
            .enumerate()
            .map(|(i, s)| Root {
                hand: s.hand,
                cost: s.cost,
                tag: i,
            })
            .collect();
        // A greedier retry finds long plans the first budget misses.
        for weight in [self.config.planner.heuristic_weight, GREEDY_WEIGHT] {
            let mut problem = self.problem(axis, total);
            problem.heuristic_weight = weight;
            let Some(found) = problem.solve(&roots) else {
                summary.expansions += self.config.planner.max_expansions;
                continue;
            };
            summary.expansions += found.expansions as u32;
            let s = &starts[found.tag];
            if let Ok(plan) = self.build(start, &goal, s, None, &axis, &found.segments, summary) {
                if !detours {
                    return Ok(plan);
                }
                return Ok(self.detour(start, &goal, &starts, plan, &mut summary));
            }
        }
        if !self.escapes {
            return Err(PlanError::SearchExhausted);
        }
        // 2. Escape: rotate about another axis first, or roll a grasping
        //    finger, to a state from which gaits work (Theory 1, SPEC §4.3).
        summary.escaped = true;
        let mut last_err = PlanError::SearchExhausted;
        for s in &starts {
            match self.escape_from(start, &goal, s, full_turns, &mut summary) {
                Ok(plan) if detours => {
                    return Ok(self.detour(start, &goal, &starts, plan, &mut summary));
                }
                Ok(plan) => return Ok(plan),
                Err(e) => last_err = e,
            }
        }
        // 3. Still stuck (both contacts at their limits): place the free
        //    finger for a three-finger grasp, spin the other two back to roll
        //    zero, lift it again, and escape from there (escape::unwind).
        //    Not so under load: a contact spinning on the object has used
        //    its whole coupled cone for the spin's torsion (MuJoCo's
        //    elliptic cone alike) and the other two do not hold the weight
        //    (replayed with gravity, the object slid out during a spin).
        //    There the free finger is first only relocated (no spins);
        //    failing that, the two spin one at a time, each pushing along
        //    its normal only while the other two carry the rest
        //    (escape::unwind_loaded) — only when `spins`: [`Planner::plan`]
        //    tries every way without spins first.
        let plain = starts.iter().filter_map(|s| {
            let spin = !self.load.active();
            escape::unwind(
                &self.geom,
                &self.cand,
                &self.grip,
                &self.config,
                &s.hand,
                spin,
            )
            .map(|u| (s, u))
        });
        let loaded = starts
            .iter()
            .filter(|_| spins && self.load.active())
            .filter_map(|s| {
                escape::unwind_loaded(&self.geom, &self.cand, &self.grip, &self.config, &s.hand)
                    .map(|u| (s, u))
            });
        let unwinds = plain.chain(loaded);
        for (s, unwound) in unwinds {
            let mut s2 = s.clone();
            s2.actions.extend(unwound.actions);
            s2.hand = unwound.hand;
            let (axis2, total2) = rest_after_escape(&s2.hand.object, &goal, full_turns);
            let root = Root {
                hand: s2.hand,
                cost: 0.0,
                tag: 0,
            };
            if let Some(found) = self.problem(axis2, total2).solve(&[root]) {
                summary.expansions += found.expansions as u32;
                if let Ok(plan) =
                    self.build(start, &goal, &s2, None, &axis2, &found.segments, summary)
                {
                    return Ok(plan);
                }
            }
            match self.escape_from(start, &goal, &s2, full_turns, &mut summary) {
                Ok(plan) => return Ok(plan),
                Err(e) => last_err = e,
            }
        }
        // Under load, the search failing means no load-feasible plan.
        if self.load.active() && last_err == PlanError::SearchExhausted {
            last_err = PlanError::LoadInfeasible { start: false };
        }
        Err(last_err)
    }

    /// Rotation and roll escapes from the state a start reaches, each
    /// followed by a search (budget halved: these are the rare hard cases).
    fn escape_from(
        &self,
        start: &HandState,
        goal: &UnitQuaternion<f64>,
        s: &Start,
        full_turns: Option<(Vector3<f64>, f64)>,
        summary: &mut PlanSummary,
    ) -> Result<Plan, PlanError> {
        let mut last_err = PlanError::SearchExhausted;
        let axes = fibonacci_sphere(self.config.planner.escape_axes as usize);
        let rotations =
            escape::rotation_escapes(&self.geom, &self.cand, &self.load, &s.hand, &axes, 8);
        let rolls =
            escape::roll_escapes(&self.geom, &self.cand, &self.load, &self.config, &s.hand, 2);
        let tries = rotations
            .into_iter()
            .map(Escape::Rotate)
            .chain(rolls.into_iter().map(|(f, p)| Escape::Roll(f, Box::new(p))));
        for esc in tries {
            let h = esc.apply(&s.hand);
            let (axis2, total2) = rest_after_escape(&h.object, goal, full_turns);
            let root = Root {
                hand: h,
                cost: 0.0,
                tag: 0,
            };
            let mut problem = self.problem(axis2, total2);
            problem.max_expansions = (problem.max_expansions / 2).max(1);
            let Some(found) = problem.solve(&[root]) else {
                summary.expansions += problem.max_expansions as u32;
                continue;
            };
            summary.expansions += found.expansions as u32;
            match self.build(
                start,
                goal,
                s,
                Some(&esc),
                &axis2,
                &found.segments,
                *summary,
            ) {
                Ok(plan) => return Ok(plan),
                Err(e) => last_err = e,
            }
        }
        Err(last_err)
    }

    fn problem(&self, axis: Vector3<f64>, total: f64) -> Problem<'_> {
        Problem {
            geom: &self.geom,
            timing: &self.timing,
            cand: &self.cand,
            load: &self.load,
            axis,
            total,
            branching: self.config.planner.branching as usize,
            heuristic_weight: self.config.planner.heuristic_weight,
            max_expansions: self.config.planner.max_expansions as usize,
        }
    }

    /// Paper Theory 1: some placement of the free finger is force-closure
    /// with one of the grasping fingers (and clear of both).
    pub fn theory1(&self, hand: &HandState, pair: [usize; 2], free: usize) -> bool {
        self.problem(Vector3::z(), 0.0).theory1(hand, pair, free)
    }

    #[allow(clippy::too_many_arguments)]
    fn build(
        &self,
        start: &HandState,
        goal: &UnitQuaternion<f64>,
        s: &Start,
        escape: Option<&Escape>,
        axis: &Vector3<f64>,
        segments: &[search::Segment],
        mut summary: PlanSummary,
    ) -> Result<Plan, PlanError> {
        let blocked = |b: convert::Blocked| PlanError::Blocked { finger: b.finger };
        let mut b = Builder::new(
            &self.geom,
            self.config.limits,
            self.config.load.handover_time,
            *start,
        );
        for a in &s.actions {
            b.prefix(a).map_err(blocked)?;
        }
        match escape {
            Some(Escape::Rotate((e_axis, e_angle))) => {
                let next = segments.first().and_then(first_place);
                b.rotate(e_axis, *e_angle, next).map_err(blocked)?;
            }
            Some(Escape::Roll(finger, path)) => b.roll_path(*finger, path),
            None => {}
        }
        for (i, seg) in segments.iter().enumerate() {
            for gait in &seg.gaits {
                match *gait {
                    search::Gait::Place {
                        finger,
                        contact,
                        roll,
                    } => b.place(finger, &contact, roll).map_err(blocked)?,
                    search::Gait::Lift { finger } => b.lift(finger),
                }
            }
            if seg.rotate > 0.0 {
                let next = segments.get(i + 1).and_then(first_place);
                b.rotate(axis, seg.rotate, next).map_err(blocked)?;
            }
        }
        for st in &b.steps {
            match st.kind {
                StepKind::Place | StepKind::Lift => summary.gaits += 1,
                StepKind::Rotate if step_rotation_angle(st) == 0.0 => {}
                StepKind::Rotate => summary.rotations += 1,
                StepKind::Roll => summary.rolls += 1,
                StepKind::Transfer => {}
            }
            summary.duration += st.duration;
        }
        (summary.substitutions, summary.rewinds) = count_finger_gaits(&b.steps);
        // The exact load check of every sample (SPEC §1.3 I1').
        if self.load.active() {
            load::check_steps(
                &self.grip,
                self.config.limits.object.acceleration,
                start,
                &b.steps,
            )
            .map_err(|_| PlanError::LoadInfeasible { start: false })?;
        }
        Ok(Plan {
            start: *start,
            goal: *goal,
            steps: b.steps,
            summary,
        })
    }
}

/// The angle of a Rotate step (0 for a still handover step).
fn step_rotation_angle(st: &Step) -> f64 {
    match st.motion {
        Motion::Rotate { angle, .. } => angle,
        _ => 0.0,
    }
}

/// (substitutions, rewinds) in `steps`, as the executor will report them.
fn count_finger_gaits(steps: &[Step]) -> (u32, u32) {
    let mut tracker = crate::gaiting::GaitTracker::new();
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

/// What a plan does first when gaits are impossible (module [`escape`]).
#[derive(Debug, Clone)]
enum Escape {
    /// Rotate the object about (axis, angle).
    Rotate((Vector3<f64>, f64)),
    /// Roll a finger along a path.
    Roll(usize, Box<crate::rolling::RollingPath>),
}

impl Escape {
    fn apply(&self, hand: &HandState) -> HandState {
        let mut h = *hand;
        match self {
            Escape::Rotate((axis, angle)) => search::rotate_hand(&mut h, axis, *angle),
            Escape::Roll(finger, path) => {
                let end = path.eval(path.length());
                h.fingers[*finger] = end.finger_state(&hand.object, path.geometry());
            }
        }
        h
    }
}

fn first_place(seg: &search::Segment) -> Option<(usize, Vector3<f64>, f64)> {
    match seg.gaits.first() {
        Some(&search::Gait::Place {
            finger,
            contact,
            roll,
        }) => Some((finger, contact, roll)),
        _ => None,
    }
}

/// Axis (unit) and angle in [0, π] of the hand-frame rotation taking `from`
/// to `to` (q_d = to · from⁻¹).
pub fn rotation_to(from: &UnitQuaternion<f64>, to: &UnitQuaternion<f64>) -> (Vector3<f64>, f64) {
    let d = to * from.inverse();
    match d.axis_angle() {
        Some((axis, angle)) if angle > 0.0 => (axis.into_inner(), angle),
        _ => (Vector3::z(), 0.0),
    }
}

/// The rotation left after an escape: the shortest one to `goal`, or, for
/// a requested turn of `n` ≥ 1 full turns about `k` (`full_turns`), the
/// same end orientation reached with `n` full turns added, turning the way
/// `k` points (the escape has moved the object off the axis, so the turn
/// cannot stay exactly about `k`; it must not become a no-op either).
fn rest_after_escape(
    from: &UnitQuaternion<f64>,
    goal: &UnitQuaternion<f64>,
    full_turns: Option<(Vector3<f64>, f64)>,
) -> (Vector3<f64>, f64) {
    let (a, t) = rotation_to(from, goal);
    match full_turns {
        Some((k, n)) if n >= 1.0 => {
            let turns = std::f64::consts::TAU * n;
            if a.dot(&k) >= 0.0 {
                (a, t + turns)
            } else {
                (-a, turns - t)
            }
        }
        _ => (a, t),
    }
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
