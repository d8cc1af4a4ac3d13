//! Planning on TriFingerPro's chains (SPEC §14): the one search with the
//! chain hand behind its boundary, holding the shipped tennis ball under
//! gravity. Every plan is checked here by the test's own reading of it:
//! the steps follow one another, the ball ends at the goal, and at fine
//! samples every finger's joints (closed-form IK verified by forward
//! kinematics) stay on one branch inside their limits with the contact on
//! the tip patch, while through every carry the tip centres are where the
//! test's own integration of the no-slip condition puts them (not the
//! planner's fit).
//!
//! The figures over many goals: `GAIT_CHAIN_GOALS=200 cargo test --release
//! -p gait --test chain_planning -- --nocapture chain_figures` (default 0:
//! the figures test only says how to run it; `GAIT_DUMP=1` prints each
//! goal's result as well).

mod chain_hand;
#[path = "../../kinematics/tests/common/mod.rs"]
mod common;

use common::q_dot;
use gait::planner::budget::{Budget, Halt, Stop};
use gait::planner::chains::planner::ChainPlanner;
use gait::planner::hand_model::Turn;
use gait::planner::route::RouteStep;
use gait::planner::{Motion, Plan, PlanError};
use gait::{FingerMode, HandState};
use nalgebra::{UnitQuaternion, Vector3};

use chain_hand::{planner, planner_with, start};
use common::LIMITS;

fn about(axis: Vector3<f64>, deg: f64) -> UnitQuaternion<f64> {
    UnitQuaternion::from_axis_angle(&nalgebra::Unit::new_normalize(axis), deg.to_radians())
}

/// What the test's own reading of a plan found.
#[derive(Debug, Default)]
struct Reading {
    /// Largest distance of a carried tip from the test's integration \[m\].
    off_law: f64,
    /// Tightest joint-limit margin beyond the chain's own \[rad\].
    joint: f64,
    /// Tightest tip-patch margin of a grasping finger \[rad\].
    patch: f64,
    samples: usize,
}

/// The test's reading of `plan` from `start` (module docs); panics at
/// the first thing wrong.
fn read(p: &ChainPlanner, start: &HandState, plan: &Plan) -> Reading {
    let hand = p.model().hand();
    let o = *hand.object();
    let mut r = Reading {
        joint: f64::INFINITY,
        patch: f64::INFINITY,
        ..Reading::default()
    };
    let mut q: [Vector3<f64>; 3] =
        std::array::from_fn(|k| hand.joints(k, &start.fingers[k].center, None).unwrap());
    let mut at = *start;
    for (i, st) in plan.steps.iter().enumerate() {
        assert!(
            (0..3).all(|k| (st.start.fingers[k].center - at.fingers[k].center).norm() < 1e-12)
                && st.start.object.angle_to(&at.object) < 1e-12,
            "step {i} does not start where the one before ends"
        );
        let len = st.dofs().length;
        let n = match st.motion {
            Motion::Carry { angle, .. } => (angle.to_degrees() * 4.0).ceil().max(1.0) as usize,
            Motion::Free(m) => (m.path.length() / 0.0005).ceil().max(1.0) as usize,
            _ => panic!("step {i}: {:?} is no chain motion", st.kind),
        };
        // The test's own carry: the no-slip condition, midpoint rule.
        let mut law = q;
        for s in 0..=n {
            let lam = s as f64 / n as f64;
            if s > 0
                && let Motion::Carry { axis, angle, .. } = st.motion
            {
                let h = angle / n as f64 / 20.0;
                for _ in 0..20 {
                    for (k, q) in law.iter_mut().enumerate() {
                        if st.start.fingers[k].mode == FingerMode::Grasping {
                            let c = hand.chain(k);
                            let mid = *q + q_dot(c, q, &o, &axis) * (h / 2.0);
                            *q += q_dot(c, &mid, &o, &axis) * h;
                        }
                    }
                }
            }
            let state = st.eval(&len.map(|l| l * lam), &[0.0; 3]).state;
            for k in 0..3 {
                let c = hand.chain(k);
                let f = &state.fingers[k];
                let next = hand
                    .nearest_branch(k, &f.center, &q[k])
                    .unwrap_or_else(|| panic!("step {i}: finger {k} out of reach"));
                let fk = c.forward(&next);
                assert!((fk.tip_centre() - o.centre - f.center).norm() < 1e-9);
                assert!(
                    (next - q[k]).amax() < 0.1,
                    "step {i}: finger {k} jumps {:.3} rad",
                    (next - q[k]).amax()
                );
                q[k] = next;
                for (j, l) in c.limits.iter().enumerate() {
                    r.joint = r
                        .joint
                        .min(q[k][j] - l.lower - c.margin)
                        .min(l.upper - q[k][j] - c.margin);
                }
                if f.mode == FingerMode::Grasping {
                    let u = -(fk.tip.rotation.transpose() * f.center.normalize());
                    r.patch = r.patch.min(c.patch.alpha - u.angle(c.patch.pole.as_ref()));
                    if matches!(st.motion, Motion::Carry { .. }) {
                        let want = c.forward(&law[k]).tip_centre() - o.centre;
                        r.off_law = r.off_law.max((want - f.center).norm());
                    }
                }
            }
            r.samples += 1;
        }
        at = st.eval(&len, &[0.0; 3]).state;
    }
    assert!(
        at.object.angle_to(&plan.goal) < 1e-9,
        "the ball ends {:.2e} rad from the goal",
        at.object.angle_to(&plan.goal)
    );
    assert!(r.joint >= 0.0, "a joint beyond its limit: {}", r.joint);
    assert!(r.patch >= LIMITS.margins.patch - 1e-6, "patch {}", r.patch);
    assert!(
        r.off_law < 1e-6,
        "a carried tip {:.2e} m off the law",
        r.off_law
    );
    r
}

#[test]
fn a_turn_the_three_fingers_reach_is_one_carry() {
    let p = planner();
    let s = start(p.model());
    let plan = p.plan(&s, &about(Vector3::z(), 30.0)).expect("planned");
    let r = read(&p, &s, &plan);
    eprintln!("30° about z: {:?}; {r:?}", plan.summary);
    assert_eq!(plan.summary.gaits, 0);
    assert_eq!(plan.steps.len(), 1);
    assert!(
        plan.steps
            .iter()
            .all(|st| matches!(st.motion, Motion::Carry { .. }))
    );
}

/// The paper's first turn, a full turn about z, on the chains: its third
/// quarter would begin in a grasp the second ended in from which no gait
/// goes on (three tips above the equator, none free to lift), so the
/// planner plans that quarter again and the rest in other pieces.
#[test]
fn a_full_turn_never_rests_in_a_grasp_no_gait_leaves() {
    let p = planner();
    let s = start(p.model());
    let mut never = gait::planner::budget::Unbounded;
    let mut budget = Budget::new(30_000, &mut never);
    let turn = gait::planner::Target::Turn {
        axis: Vector3::z(),
        angle: std::f64::consts::TAU,
    };
    let plan = p.plan_target(&s, &turn, &mut budget).expect("planned");
    let r = read(&p, &s, &plan);
    // The ball went once round z: its twist about z (the swing-twist
    // split of its orientation), followed sample by sample, adds up to
    // one turn.
    let twist = |q: &UnitQuaternion<f64>| 2.0 * q.k.atan2(q.w);
    let (mut about_z, mut last) = (0.0, twist(&s.object));
    for st in &plan.steps {
        let len = st.dofs().length;
        for i in 1..=50 {
            let t = twist(
                &st.eval(&len.map(|l| l * i as f64 / 50.0), &[0.0; 3])
                    .state
                    .object,
            );
            let d = t - last;
            about_z += d - std::f64::consts::TAU * (d / std::f64::consts::TAU).round();
            last = t;
        }
    }
    eprintln!(
        "a full turn about z: {} gaits, {:.1} s, {} expansions; joint margin {:.3} rad, \
         patch {:.3} rad; turned {:.1}° about z",
        plan.summary.gaits,
        plan.summary.duration,
        plan.summary.effort.expansions,
        r.joint,
        r.patch,
        about_z.to_degrees()
    );
    assert!((about_z - std::f64::consts::TAU).abs() < 1e-6, "{about_z}");
}

/// Goals that need the fingers relocated (the ball turned further than
/// the start grasp reaches about the goal's axis): three of the figures'
/// Haar-random goals that plan within a few hundred expansions.
#[test]
fn gaits_turn_the_ball_further_than_one_grasp_reaches() {
    let p = planner();
    let s = start(p.model());
    let mut rng = common::rng(5);
    let draws: Vec<UnitQuaternion<f64>> = (0..30)
        .map(|_| test_support::random::haar(&mut rng))
        .collect();
    let goals = [draws[6], draws[26], draws[29]];
    for goal in goals {
        let plan = p.plan(&s, &goal).expect("planned");
        let r = read(&p, &s, &plan);
        eprintln!(
            "{:.0}°: {} gaits, {:.2} s, {} expansions; tips within {:.1e} m of the law, \
             joint margin {:.3} rad, patch {:.3} rad, {} samples",
            goal.angle().to_degrees(),
            plan.summary.gaits,
            plan.summary.duration,
            plan.summary.effort.expansions,
            r.off_law,
            r.joint,
            r.patch,
            r.samples
        );
        assert!(plan.summary.gaits >= 2, "no finger was relocated");
    }
}

/// A grasp a plan ended in (a random goal from the start grasp) from
/// which no finger can lift: no two of the three hold the ball at rest.
/// The three turn the ball first, about another axis, until a pair holds;
/// a search offering only turns towards the goal and tilts about the
/// pairs' chords finds nothing from here.
#[test]
fn a_grasp_no_finger_can_leave_turns_the_ball_until_one_can() {
    use gait::planner::hand_model::HandModel;
    let p = planner();
    let mut s = start(p.model());
    s.object = UnitQuaternion::new_normalize(nalgebra::Quaternion::new(
        0.3368213738855246,
        0.055370232527997915,
        0.6256552961874349,
        0.7014563064056638,
    ));
    let centres = [
        [
            0.02948333189637227,
            0.02137126393303011,
            0.023796054677049396,
        ],
        [
            0.038441938150756964,
            0.020358040652142584,
            -0.0001325594926309246,
        ],
        [
            -0.018185388107359073,
            -0.03884595086770485,
            0.007248017699246111,
        ],
    ];
    for (f, c) in s.fingers.iter_mut().zip(centres) {
        f.center = Vector3::from(c);
    }
    let m = p.model();
    for lose in 0..3 {
        let mut lifted = s;
        m.lift(&mut lifted, lose);
        assert!(!m.holds_at_rest(&lifted), "finger {lose} could lift");
    }
    let mut rng = common::rng(777);
    let goal = (0..15)
        .map(|_| test_support::random::haar(&mut rng))
        .last()
        .unwrap();
    let plan = p.plan(&s, &goal).expect("planned");
    let r = read(&p, &s, &plan);
    eprintln!(
        "{}: {} steps, {:.2} s; joint margin {:.3} rad, patch {:.3} rad",
        plan.route,
        plan.steps.len(),
        plan.summary.duration,
        r.joint,
        r.patch
    );
    assert!(
        matches!(
            plan.route.steps.first(),
            Some(RouteStep::Turn {
                why: Turn::Detour,
                fingers: 3,
                ..
            })
        ),
        "{}",
        plan.route
    );
}

/// Goals whose turn the start grasp cannot begin to make: finger 1 binds
/// and cannot lift (fingers 0 and 2 do not hold the ball as a pair), so
/// the others walk first — lifted and placed anew one at a time on the
/// still ball — until the three reach contacts from which they turn far.
/// Three of the figures' Haar-random goals; each plan read as all here.
/// The third (81°) is one walk of five moves and one turn: a search that
/// weighs a walk's end by its estimate alone, which counts the segment as
/// one gait, spends its budget before it gets there.
#[test]
fn fingers_walk_on_the_still_ball_to_a_grasp_that_turns_far() {
    let p = planner();
    let s = start(p.model());
    let mut rng = common::rng(5);
    let draws: Vec<UnitQuaternion<f64>> = (0..56)
        .map(|_| test_support::random::haar(&mut rng))
        .collect();
    for goal in [draws[22], draws[35], draws[55]] {
        let plan = p.plan(&s, &goal).expect("planned");
        let r = read(&p, &s, &plan);
        eprintln!(
            "{:.0}°: {} gaits, {:.2} s, {} expansions ({}); joint margin {:.3} rad",
            goal.angle().to_degrees(),
            plan.summary.gaits,
            plan.summary.duration,
            plan.summary.effort.expansions,
            plan.route,
            r.joint
        );
        // Somewhere the fingers were placed anew back to back, the ball
        // still: at least two placements between two turns.
        let walked = plan
            .route
            .steps
            .split(|s| matches!(s, RouteStep::Turn { .. }))
            .map(|still| {
                still
                    .iter()
                    .filter(|s| matches!(s, RouteStep::Place { .. }))
                    .count()
            })
            .max()
            .unwrap_or(0);
        assert!(
            walked >= 2,
            "at most {walked} fingers placed with the ball still"
        );
    }
}

/// A goal the greedy pass plans in a dozen expansions still gets the
/// improving pass's quicker plan: one finger moved, then one turn of 72°
/// (the greedy pass's plan moves two fingers and turns twice).
#[test]
fn a_plan_found_at_once_is_still_improved() {
    let p = planner();
    let s = start(p.model());
    let mut rng = common::rng(5);
    let goal = (0..52)
        .map(|_| test_support::random::haar(&mut rng))
        .last()
        .expect("goals");
    let plan = p.plan(&s, &goal).expect("planned");
    read(&p, &s, &plan);
    println!(
        "{} ({} expansions)",
        plan.route, plan.summary.effort.expansions
    );
    let turns = plan
        .route
        .steps
        .iter()
        .filter(|s| matches!(s, RouteStep::Turn { .. }))
        .count();
    assert_eq!((plan.summary.gaits, turns), (2, 1), "{}", plan.route);
}

/// Counts its polls; says cancel from poll `cancel_at` on (0: never), as
/// a cancel flag does.
struct Polls {
    n: u32,
    cancel_at: u32,
}

impl Stop for Polls {
    fn poll(&mut self) -> Option<Halt> {
        self.n += 1;
        (self.cancel_at > 0 && self.n >= self.cancel_at).then_some(Halt::Canceled)
    }
}

/// A walk can run hundreds of load tests: it asks the caller's stop
/// between them, not only when the search takes its next node, and a
/// cancel met anywhere ends planning without a plan.
#[test]
fn a_walk_asks_the_callers_stop_between_its_load_tests() {
    let p = planner();
    let s = start(p.model());
    let mut rng = common::rng(5);
    let goal = (0..56)
        .map(|_| test_support::random::haar(&mut rng))
        .last()
        .expect("drawn");
    let mut polls = Polls { n: 0, cancel_at: 0 };
    let max = 3000;
    let plan = p
        .plan_within(&s, &goal, &mut Budget::new(max, &mut polls))
        .expect("planned");
    // The search polls once per node it takes (expansions and deferred
    // evaluations); the walks' own polls come on top.
    let taken = plan.summary.effort.expansions + plan.summary.effort.evaluated;
    eprintln!("{} polls, {taken} nodes taken", polls.n);
    assert!(polls.n > taken + 10, "{} polls, {taken} nodes", polls.n);
    let total = polls.n;
    for cancel_at in (1..=total).step_by((total as usize / 12).max(1)) {
        let mut stop = Polls { n: 0, cancel_at };
        let r = p.plan_within(&s, &goal, &mut Budget::new(max, &mut stop));
        assert_eq!(
            r.err(),
            Some(PlanError::Canceled),
            "cancelled at poll {cancel_at}"
        );
    }
}

#[test]
fn a_start_the_hand_cannot_hold_or_reach_is_refused() {
    let p = planner();
    let s = start(p.model());
    let goal = about(Vector3::z(), 30.0);
    // Ten kilograms: no grasp within the motors' torques.
    let mut heavy = common::hand();
    heavy.object.mass = 10.0;
    assert_eq!(
        planner_with(&heavy).plan(&s, &goal).err(),
        Some(PlanError::LoadInfeasible { start: true })
    );
    // Finger 1's first joint kept away from where its tip is.
    let q1 = p
        .model()
        .hand()
        .joints(1, &s.fingers[1].center, None)
        .expect("reached");
    let mut narrow = common::hand();
    let l = &mut narrow.fingers[1].joints[0].limits;
    (l.lower, l.upper) = (q1[0] + 0.3, q1[0] + 0.6);
    assert_eq!(
        planner_with(&narrow).plan(&s, &goal).err(),
        Some(PlanError::Blocked { finger: 1 })
    );
    // A tip off the ball's surface.
    let mut off = s;
    off.fingers[2].center *= 1.1;
    assert_eq!(p.plan(&off, &goal).err(), Some(PlanError::NoGrasp));
    // Two fingers on one side: no force closure.
    let mut open = s;
    open.fingers[2].mode = FingerMode::Free;
    open.fingers[1].center = s.fingers[0].center;
    assert_eq!(p.plan(&open, &goal).err(), Some(PlanError::NoGrasp));
}

/// The figures over `GAIT_CHAIN_GOALS` Haar-random goals from the start:
/// planned share, planning time, time to goal, gaits, margins.
#[test]
fn chain_figures() {
    let n: usize = std::env::var("GAIT_CHAIN_GOALS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(0);
    if n == 0 {
        eprintln!("chain figures: set GAIT_CHAIN_GOALS=N (release build) to measure");
        return;
    }
    let p = planner();
    let s = start(p.model());
    let mut rng = common::rng(5);
    let (mut times, mut goals_t, mut gaits, mut refused) = (vec![], vec![], vec![], vec![]);
    let mut tight = (f64::INFINITY, f64::INFINITY, 0.0f64);
    for i in 0..n {
        let goal = test_support::random::haar(&mut rng);
        let clock = std::time::Instant::now();
        let plan = p.plan(&s, &goal);
        times.push(clock.elapsed().as_secs_f64() * 1e3);
        if std::env::var("GAIT_DUMP").is_ok() {
            let (a, t) = goal
                .axis_angle()
                .map_or((Vector3::z(), 0.0), |(a, t)| (a.into_inner(), t));
            eprintln!(
                "goal {i}: {:.3?} {:.0}°, {:.0} ms: {:?}",
                a.as_slice(),
                t.to_degrees(),
                times[i],
                plan.as_ref().map(|p| (
                    p.summary.gaits,
                    p.summary.duration,
                    p.summary.effort.expansions
                ))
            );
        }
        match plan {
            Ok(plan) => {
                let r = read(&p, &s, &plan);
                tight = (
                    tight.0.min(r.joint),
                    tight.1.min(r.patch),
                    tight.2.max(r.off_law),
                );
                goals_t.push(plan.summary.duration);
                gaits.push(plan.summary.gaits as f64);
            }
            Err(e) => refused.push((i, e)),
        }
    }
    let q = |v: &mut Vec<f64>, f: f64| {
        v.sort_by(f64::total_cmp);
        v.get(((v.len() as f64 - 1.0) * f).round() as usize)
            .copied()
            .unwrap_or(f64::NAN)
    };
    eprintln!(
        "chain figures, {n} goals: planned {} ({:.1} %), refused {refused:?}\n\
         planning ms p50 {:.0} / p99 {:.0} / max {:.0}\n\
         time to goal s median {:.2} / p95 {:.2} / max {:.2}; gaits median {:.0} / max {:.0}\n\
         tightest joint margin {:.3} rad, patch {:.3} rad; tips within {:.1e} m of the law",
        goals_t.len(),
        100.0 * goals_t.len() as f64 / n as f64,
        q(&mut times, 0.5),
        q(&mut times, 0.99),
        q(&mut times, 1.0),
        q(&mut goals_t, 0.5),
        q(&mut goals_t, 0.95),
        q(&mut goals_t, 1.0),
        q(&mut gaits, 0.5),
        q(&mut gaits, 1.0),
        tight.0,
        tight.1,
        tight.2
    );
}
