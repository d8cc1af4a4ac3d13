//! The executor on TriFingerPro's chains (SPEC §14): the chain planner's
//! plans run tick by tick on the kinematic hand, graded on the plant's
//! truth by the test's own reading of each finger (inverse kinematics on
//! the branch it is on, verified by forward kinematics, against the
//! limits and the tip patch stated here), the joints the executor
//! commands compared with that reading; and the per-tick check's chain
//! limits compared, on random grasps, with the test's own judgement.
//!
//! More chained goals: `GAIT_CHAIN_EXEC_GOALS=100 cargo test --release -p
//! gait --test executor_chains -- --nocapture chain_plans` (default 7
//! after the first turn); `GAIT_CHAIN_EXEC_DUMP=FILE` appends a line per
//! plan (planning time, effort, duration, gaits) to FILE,
//! `GAIT_CHAIN_EXEC_STATES=FILE` each goal's start state and goal.
//!
//! The numbers this test holds the hand to are TriFingerPro's (the
//! shipped URDF's soft limits, from `robot_properties_fingers`) and the
//! tests' margins: joints within [−0.33, 1.0], [0, 1.57], [−2.7, 0] rad
//! less 0.05 rad; the contact within 85° of the tip's pole, −z of the tip
//! frame (a 90° hemisphere less 5°); links 5 mm off the ball; every
//! motor's effort 0.396 N·m, which the contact force each grasping finger
//! is commanded to push with must not need (with the links' weight held).

mod chain_hand;
#[path = "../../kinematics/tests/common/mod.rs"]
mod common;

use gait::executor::{
    Executor, ExecutorAnswer, ExecutorCommand, ExecutorEvent, GoalStage, GoalTarget, Mode,
};
use gait::hand::{Invariant, InvariantChecker, Subject};
use gait::planner::chains::ChainHand;
use gait::planner::chains::planner::ChainPlanner;
use gait::sim::{KinematicHand, Plant};
use gait::{FingerMode, HandState};
use nalgebra::{Matrix3, Vector3};
use rand::Rng;

/// Soft joint limits \[rad\] of every TriFingerPro finger (upper, middle,
/// lower joint) and the margin kept inside them.
const LOWER: [f64; 3] = [-0.33, 0.0, -2.7];
const UPPER: [f64; 3] = [1.0, 1.57, 0.0];
const JOINT_MARGIN: f64 = 0.05;
/// The contact's largest angle from the tip's pole \[rad\]: 90° − 5°.
const PATCH: f64 = 85.0 * std::f64::consts::PI / 180.0;
/// Links off the ball \[m\].
const CLEARANCE: f64 = 0.005;
/// The ball and the tip \[m\].
const BALL: f64 = 0.0335;
const TIP: f64 = 0.010;
/// Every TriFingerPro motor's effort \[N·m\].
const EFFORT: f64 = 0.396;

/// The largest share of a motor's effort finger `k` at joints `q`,
/// touching at the outward normal `n`, needs to push the ball with the
/// force `force` while holding its links' weight: τ = J_mᵀ F + g, J_m the Jacobian
/// of the tip's material point at the contact by central differences of
/// forward kinematics, g the links' weight torques (the hand's own,
/// checked against the gradient of the links' potential energy in the
/// daemon's joint-command tests).
fn own_push_share(
    h: &ChainHand,
    k: usize,
    q: &Vector3<f64>,
    n: &Vector3<f64>,
    force: &Vector3<f64>,
) -> f64 {
    let chain = h.chain(k);
    let at = chain.forward(q);
    // The contact point in the tip frame: it moves with the tip.
    let local = at.tip.rotation.transpose() * (-n * TIP);
    let point = |q: &Vector3<f64>| {
        let s = chain.forward(q);
        s.tip_centre() + s.tip.rotation * local
    };
    let eps = 1e-6;
    let mut jm = Matrix3::zeros();
    for i in 0..3 {
        let mut dq = Vector3::zeros();
        dq[i] = eps;
        jm.set_column(i, &((point(&(q + dq)) - point(&(q - dq))) / (2.0 * eps)));
    }
    let tau = jm.transpose() * force + h.statics(k, q, n).bias;
    tau.amax() / EFFORT
}

/// The joints' margin inside the stated limits (negative: outside).
fn own_joint_margin(q: &Vector3<f64>) -> f64 {
    (0..3)
        .map(|i| (q[i] - LOWER[i]).min(UPPER[i] - q[i]))
        .fold(f64::INFINITY, f64::min)
        - JOINT_MARGIN
}

/// The angle of the contact from the tip's pole: the contact point on
/// the tip is −n seen from the tip frame, the pole is −z.
fn own_patch_angle(tip: &Matrix3<f64>, n: &Vector3<f64>) -> f64 {
    let u = -(tip.transpose() * n);
    u.angle(&-Vector3::z())
}

/// The least distance of finger `k`'s link capsules (at `q`) from the
/// ball's surface, by 400 points along each capsule's axis.
fn own_clearance(h: &ChainHand, k: usize, q: &Vector3<f64>) -> f64 {
    let chain = h.chain(k);
    let s = chain.forward(q);
    let o = h.object().centre;
    let mut least = f64::INFINITY;
    for c in chain.capsules(&s).as_slice() {
        for i in 0..=400 {
            let x = c.a + (c.b - c.a) * (i as f64 / 400.0);
            least = least.min((x - o).norm() - c.radius - BALL);
        }
    }
    least
}

/// The test's reading of one finger of the plant's truth: its joints on
/// the branch nearest `before`, with the tip there by forward kinematics.
fn own_joints(
    h: &ChainHand,
    k: usize,
    center: &Vector3<f64>,
    before: &Vector3<f64>,
) -> Vector3<f64> {
    let q = h
        .nearest_branch(k, center, before)
        .unwrap_or_else(|| panic!("finger {k}: no branch reaches {center:?}"));
    let tip = h.chain(k).forward(&q).tip_centre();
    assert!(
        (tip - h.object().centre - center).norm() < 1e-9,
        "finger {k}: FK misses the tip"
    );
    q
}

/// What the reading of a run found.
#[derive(Debug)]
struct Tightest {
    joint: f64,
    patch: f64,
    /// The largest share of a motor's effort a commanded grip needed.
    effort: f64,
    /// Ticks of a grasping finger (each finger counted), and of those
    /// the ones whose grip the motors capped.
    grasping: u64,
    capped: u64,
    ticks: u64,
}

/// Runs goal `id` to its end on `plant`, reading every tick of the
/// plant's truth; `q` carries each finger's joints from tick to tick.
fn run_goal(
    exec: &mut Executor,
    plant: &mut KinematicHand,
    p: &ChainPlanner,
    id: u64,
    target: GoalTarget,
    q: &mut [Vector3<f64>; 3],
    t: &mut Tightest,
) -> GoalStage {
    let h = p.model().hand();
    let cmd = ExecutorCommand::Goal {
        id,
        target,
        limits: None,
    };
    assert_eq!(exec.command(cmd), ExecutorAnswer::Accepted);
    let mut end = None;
    for tick in 0..200_000u64 {
        let m = plant.read();
        let rep = *exec.tick(m.as_ref());
        plant.write(&rep.setpoint);
        if let Some(req) = exec.take_plan_request() {
            let t0 = std::time::Instant::now();
            let plan = req.plan(p).map(Box::new);
            dump_plan(id, t0.elapsed().as_secs_f64(), &plan);
            drop(exec.deliver_plan(req.goal, plan));
        }
        while let Some(e) = exec.pop_event() {
            match e {
                ExecutorEvent::Fault { kind, finger } => {
                    panic!("goal {id}, tick {tick}: fault {kind:?} finger {finger}")
                }
                ExecutorEvent::Goal { state, reason, .. } if state.is_terminal() => {
                    if state != GoalStage::Succeeded {
                        println!("goal {id}: {reason:?}");
                    }
                    end = Some(state)
                }
                _ => {}
            }
        }
        let truth = *plant.state();
        for (k, f) in truth.fingers.iter().enumerate() {
            let now = own_joints(h, k, &f.center, &q[k]);
            // The joints commanded: they put the tip where the setpoint
            // does, and (this plant follows the setpoint) where the plant
            // has it, on the branch the finger is on.
            let cmd = rep.joints[k].unwrap_or_else(|| panic!("goal {id}: finger {k} no joints"));
            let tip = h.chain(k).forward(&cmd).tip_centre() - h.object().centre;
            assert!(
                (tip - rep.setpoint.state.fingers[k].center).norm() < 1e-9,
                "goal {id}, tick {tick}: finger {k}'s joints miss its setpoint"
            );
            assert!(
                (cmd - now).amax() < 1e-9,
                "goal {id}, tick {tick}: finger {k} commanded {cmd:?}, read {now:?}"
            );
            let jump = (now - q[k]).amax();
            assert!(
                jump < 0.01,
                "goal {id}, tick {tick}: finger {k} jumped {jump} rad"
            );
            q[k] = now;
            let margin = own_joint_margin(&now);
            assert!(
                margin >= -1e-9,
                "goal {id}, tick {tick}: finger {k} joints {now:?}"
            );
            t.joint = t.joint.min(margin);
            if f.mode == FingerMode::Grasping {
                assert!(
                    (f.center.norm() - BALL - TIP).abs() < 1e-9,
                    "finger {k} off the ball"
                );
                let rot = h.chain(k).forward(&now).tip.rotation;
                let angle = own_patch_angle(&rot, &f.center.normalize());
                assert!(
                    angle <= PATCH + 1e-9,
                    "goal {id}, tick {tick}: finger {k} off its patch"
                );
                t.patch = t.patch.min(PATCH - angle);
                let n = f.center.normalize();
                let force = rep.grip_force[k];
                let share = own_push_share(h, k, &now, &n, &force);
                assert!(
                    share <= 1.0 + 1e-6,
                    "goal {id}, tick {tick}: finger {k}'s grip {force:?} N needs {share} of its effort",
                );
                // The normal force reported is the force's push along the
                // inward normal.
                assert!(
                    (force.dot(&-n).max(0.0) - rep.grip[k]).abs() < 1e-9,
                    "goal {id}, tick {tick}: finger {k}: force {force:?}, normal {}",
                    rep.grip[k]
                );
                t.effort = t.effort.max(share);
                t.grasping += 1;
                t.capped += u64::from(rep.grip_capped);
            }
        }
        t.ticks += 1;
        if end.is_some() && rep.phase == Mode::Holding {
            break;
        }
    }
    end.expect("the goal ended")
}

/// With `GAIT_CHAIN_EXEC_DUMP=FILE`, one line per plan request appended
/// to FILE: goal, planning seconds (this thread's wall clock), and the
/// plan's expansions, duration \[s\] and gaits, or its error.
fn dump_plan(
    id: u64,
    secs: f64,
    plan: &Result<Box<gait::planner::Plan>, gait::planner::PlanError>,
) {
    let Ok(path) = std::env::var("GAIT_CHAIN_EXEC_DUMP") else {
        return;
    };
    let line = match plan {
        Ok(p) => format!(
            "{id} ok {secs:.4} {} {:.3} {}\n",
            p.summary.effort.expansions, p.summary.duration, p.summary.gaits
        ),
        Err(e) => format!("{id} err {secs:.4} {e:?}\n"),
    };
    use std::io::Write;
    let mut f = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(path)
        .unwrap();
    f.write_all(line.as_bytes()).unwrap();
}

/// The executor of the shipped hand and its kinematic plant, holding
/// the start grasp, and each finger's joints there.
fn rig(p: &ChainPlanner) -> (Executor, KinematicHand, [Vector3<f64>; 3]) {
    let h = p.model().hand();
    let start = chain_hand::start(p.model());
    let exec = Executor::for_chains(p.model().config(), h.clone(), 1e-3, start).unwrap();
    let q = std::array::from_fn(|k| h.joints(k, &start.fingers[k].center, None).unwrap());
    (exec, KinematicHand::new(start, 1e-3), q)
}

#[test]
fn chain_plans_run_to_their_goals_within_the_hands_limits() {
    let p = chain_hand::planner();
    let (mut exec, mut plant, mut q) = rig(&p);
    let mut t = Tightest {
        joint: f64::INFINITY,
        patch: f64::INFINITY,
        effort: 0.0,
        grasping: 0,
        capped: 0,
        ticks: 0,
    };
    let mut rng = common::rng(5);
    let (mut reached, mut restarts) = (0, 0);
    // A turn about a tilted axis, then random orientations from wherever
    // each ended.
    let mut targets = vec![GoalTarget::Rotation {
        axis: Vector3::new(1.0, -1.0, 2.0),
        angle: 100f64.to_radians(),
    }];
    let more = std::env::var("GAIT_CHAIN_EXEC_GOALS").map_or(7, |v| v.parse().expect("a count"));
    targets
        .extend((0..more).map(|_| GoalTarget::Orientation(test_support::random::haar(&mut rng))));
    for (i, target) in targets.iter().enumerate() {
        let from = plant.state().object;
        let goal = target.resolve(&from);
        let id = i as u64 + 1;
        if let Ok(path) = std::env::var("GAIT_CHAIN_EXEC_STATES") {
            // The goal's start and target, to replay one goal alone.
            use std::io::Write;
            let mut f = std::fs::OpenOptions::new()
                .create(true)
                .append(true)
                .open(path)
                .unwrap();
            writeln!(f, "{id} {:?} -> {:?}", plant.state(), goal).unwrap();
        }
        match run_goal(&mut exec, &mut plant, &p, id, *target, &mut q, &mut t) {
            GoalStage::Succeeded => {
                let err = plant.state().object.angle_to(&goal);
                assert!(err < 1e-6, "goal {id}: the ball is {err} rad from it");
                reached += 1;
            }
            // A goal the planner cannot plan ends with its reason, the
            // hand still where it was; where the grasp is one no plan
            // leaves, the hand is put back in its start grasp.
            other => {
                assert_eq!(exec.phase(), Mode::Holding, "goal {id}: {other:?}");
                (exec, plant, q) = rig(&p);
                restarts += 1;
            }
        }
    }
    println!(
        "{reached} of {} goals reached ({restarts} refused, the hand then back at its start) \
         in {} ticks; tightest joint margin {:.3} rad, patch {:.3} rad; grips need at most \
         {:.3} of a motor's effort, capped by the motors on {} of {} grasping-finger ticks",
        targets.len(),
        t.ticks,
        t.joint,
        t.patch,
        t.effort,
        t.capped,
        t.grasping
    );
    // Every goal either reached (and read above) or refused by the
    // planner with its reason; the planner's share from chained states is
    // measured elsewhere (14-finger-chains.md).
    assert!(reached >= targets.len() / 2, "{reached} reached");
}

/// Random states: each finger on a random normal of the ball or free
/// anywhere up to 15 cm from its centre (often out of reach), checked by a
/// fresh checker; every finger's joint-limit, tip-patch and
/// link-clearance verdict agrees with the test's own.
#[test]
fn the_tick_check_reports_the_chain_limits_the_test_finds() {
    let m = chain_hand::model();
    let h = m.hand();
    let cfg = *m.config();
    let mut rng = common::rng(17);
    let mut seen = [[0usize; 2]; 3];
    for _ in 0..600 {
        let mut s = HandState::paper_start(&cfg);
        for f in s.fingers.iter_mut() {
            let mut n = common::unit(&mut rng);
            // Mostly the upper half, where the fingers reach.
            n.z = n.z.abs() * if rng.random_bool(0.8) { 1.0 } else { -1.0 };
            if rng.random_bool(0.7) {
                f.mode = FingerMode::Grasping;
                f.center = n * (BALL + TIP);
            } else {
                // A free tip anywhere up to 15 cm out: often beyond reach.
                f.mode = FingerMode::Free;
                f.center = n * rng.random_range(BALL + TIP + 0.002..0.15);
            }
        }
        let mut checker = InvariantChecker::for_chains(&cfg, h.clone()).unwrap();
        let r = checker.check(&s).unwrap();
        let failed = |inv: Invariant, k: usize| {
            r.violations()
                .any(|v| v.invariant == inv && v.subject == Subject::Finger(k as u8))
        };
        let chosen = *checker.chain_limits().unwrap().joints();
        for (k, chosen) in chosen.iter().enumerate() {
            let target = h.object().centre + s.fingers[k].center;
            // The test's own: any closed-form branch with the tip there
            // inside the stated limits.
            let branches = kinematics::ClosedFormIk::new(h.chain(k))
                .unwrap()
                .branches(&target);
            let inside = branches.q[..branches.len].iter().any(|q| {
                (h.chain(k).forward(q).tip_centre() - target).norm() < 1e-9
                    && own_joint_margin(q) >= 0.0
            });
            assert_eq!(
                !failed(Invariant::JointLimit, k),
                inside,
                "finger {k} reach: {s:?}"
            );
            seen[0][inside as usize] += 1;
            let Some(q) = chosen.filter(|_| inside) else {
                continue;
            };
            let rot = h.chain(k).forward(&q).tip.rotation;
            let angle = own_patch_angle(&rot, &s.fingers[k].center.normalize());
            let grasping = s.fingers[k].mode == FingerMode::Grasping;
            if grasping && (angle - PATCH).abs() > 1e-9 {
                let on = angle <= PATCH;
                assert_eq!(
                    !failed(Invariant::TipPatch, k),
                    on,
                    "finger {k} patch {angle}"
                );
                seen[1][on as usize] += 1;
            }
            let clear = own_clearance(h, k, &q);
            if (clear - CLEARANCE).abs() > 1e-5 {
                let ok = clear >= CLEARANCE;
                assert_eq!(
                    !failed(Invariant::LinkClearance, k),
                    ok,
                    "finger {k} links {clear}"
                );
                seen[2][ok as usize] += 1;
            }
        }
    }
    println!(
        "(fail, pass) counts: reach {:?}, patch {:?}, links {:?}",
        seen[0], seen[1], seen[2]
    );
    for (what, c) in ["reach", "patch", "links"].iter().zip(seen) {
        assert!(
            c[0] >= 10 && c[1] >= 10,
            "{what}: too few of either verdict {c:?}"
        );
    }
}

/// A finger moved away from its grasp in 1 mm steps along random lines,
/// checked state after state by one checker (which keeps the branch the
/// finger is on): its joint-limit verdict agrees at every step with the
/// test's own, on the branch nearest the joints a step before (each
/// joint taken the 2π-turn nearest), inside the stated limits — as the
/// finger leaves them and, where it does, comes back.
#[test]
fn a_finger_moved_past_its_limits_is_reported_where_it_crosses() {
    let m = chain_hand::model();
    let h = m.hand();
    let start = chain_hand::start(&m);
    let mut rng = common::rng(23);
    let mut seen = [0usize; 2];
    for _ in 0..60 {
        let k = rng.random_range(0..3);
        // Away from the ball.
        let mut dir = common::unit(&mut rng);
        if dir.dot(&start.fingers[k].center) < 0.0 {
            dir = -dir;
        }
        let mut checker = InvariantChecker::for_chains(m.config(), h.clone()).unwrap();
        let mut s = start;
        s.fingers[k].mode = FingerMode::Free;
        let mut own = h.joints(k, &s.fingers[k].center, None).unwrap();
        for step in 1..=120 {
            let centre = start.fingers[k].center + dir * (0.001 * step as f64);
            s.fingers[k].center = centre;
            let r = checker.check(&s).unwrap();
            let target = h.object().centre + centre;
            let tau = std::f64::consts::TAU;
            let b = kinematics::ClosedFormIk::new(h.chain(k))
                .unwrap()
                .branches(&target);
            let Some(q) = b.q[..b.len]
                .iter()
                .filter(|q| (h.chain(k).forward(q).tip_centre() - target).norm() < 1e-9)
                .map(|q| q.zip_map(&own, |q, r| q + tau * ((r - q) / tau).round()))
                .min_by(|a, c| (a - own).norm().total_cmp(&(c - own).norm()))
            else {
                break; // out of reach entirely: the checker says so too
            };
            own = q;
            let margin = own_joint_margin(&q);
            if margin.abs() < 1e-9 {
                continue;
            }
            let failed = r.violations().any(|v| {
                v.invariant == Invariant::JointLimit && v.subject == Subject::Finger(k as u8)
            });
            assert_eq!(
                failed,
                margin < 0.0,
                "finger {k} step {step}: own margin {margin}"
            );
            seen[(margin >= 0.0) as usize] += 1;
        }
    }
    println!("(outside, inside) steps: {seen:?}");
    assert!(seen[0] >= 20 && seen[1] >= 20, "{seen:?}");
}
