//! Gait events on the wire (SPEC §7.3: place, lift, roll, substitution,
//! rewind) from the daemon's real loop (mock clock, real iceoryx2 ports,
//! planner and writer threads): a goal whose plan contains a finger rewind
//! reports every substitution and the rewind, as the plan has them.

#[path = "support/ipc_rig.rs"]
mod ipc_rig;

use gait::planner::Planner;
use gait::{HandConfig, HandState};
use ipc_rig::{Namespace, gait_loop};
use nalgebra::{UnitQuaternion, Vector3};
use shm_schema::{Command, EventKind, GoalFrame, GoalState};

/// The first of a fixed list of goals whose plan from `start` has a
/// rewind, with that plan's (substitutions, rewinds). The daemon's planner
/// makes the same plan from the same state (SPEC §4.3: deterministic).
fn goal_with_a_rewind(start: &HandState) -> (UnitQuaternion<f64>, u32, u32) {
    let planner = Planner::new(&HandConfig::default()).unwrap();
    for i in 0..500 {
        let t = f64::from(i);
        let axis = Vector3::new((0.7 * t).sin(), (1.3 * t).cos(), (0.4 * t + 0.3).sin());
        let turn = UnitQuaternion::from_scaled_axis(axis.normalize() * (0.3 + (t * 0.61) % 2.8));
        let goal = turn * start.object;
        // (A goal the planner refuses is not the one.)
        let Ok(plan) = planner.plan(start, &goal) else {
            continue;
        };
        if plan.summary.rewinds > 0 {
            return (goal, plan.summary.substitutions, plan.summary.rewinds);
        }
    }
    panic!("no plan with a rewind among 500 goals");
}

/// Runs goal `id` to its end; returns the gait events it produced.
fn run_goal(
    g: &mut ipc_rig::GaitLoop,
    id: u64,
    target: &UnitQuaternion<f64>,
) -> Vec<shm_schema::Event> {
    let c = target.coords; // (i, j, k, w)
    g.client.send(Command::goal(
        9,
        id,
        GoalFrame::Absolute,
        [c.w, c.x, c.y, c.z],
    ));
    let mut gaits = Vec::new();
    for _ in 0..100_000 {
        let (_, ev) = g.tick();
        for e in ev {
            match e.kind() {
                Ok(EventKind::Fault) => panic!("fault {e:?}"),
                Ok(EventKind::GoalTransition) if e.goal_id == id => {
                    let s = GoalState::try_from(e.state).unwrap();
                    if s.is_terminal() {
                        assert_eq!(s, GoalState::Succeeded);
                        return gaits;
                    }
                }
                Ok(EventKind::GoalTransition) => {}
                Ok(_) if e.goal_id == id => gaits.push(e),
                _ => {}
            }
        }
        g.yield_to_planner();
    }
    panic!("goal {id} did not end");
}

#[test]
fn substitutions_and_rewinds_are_reported_as_planned() {
    let ns = Namespace::new("g");
    let mut g = gait_loop(&ns, 46, |_| {});
    // From the paper's start plans roll and substitute; rewinds come from
    // other grasps. Go to one first.
    let first = UnitQuaternion::from_scaled_axis(Vector3::new(0.4, -0.9, 0.2) * 1.5);
    run_goal(&mut g, 1, &first);
    let (target, substitutions, rewinds) = goal_with_a_rewind(&g.rt.controller().state());
    let ev = run_goal(&mut g, 2, &target);
    let count = |k: EventKind| ev.iter().filter(|e| e.kind() == Ok(k)).count() as u32;
    let (places, lifts) = (count(EventKind::Place), count(EventKind::Lift));
    assert_eq!(
        count(EventKind::Substitution),
        substitutions,
        "{places} places, {lifts} lifts"
    );
    assert_eq!(count(EventKind::Rewind), rewinds);
    let mut placed = None;
    for e in &ev {
        assert_eq!(e.client_id, 9);
        assert_eq!(e.check(), Ok(()), "{e:?}");
        if e.kind() == Ok(EventKind::Place) {
            placed = Some(e.finger);
        }
        if e.kind() == Ok(EventKind::Substitution) {
            // The finger that took over is the one placed last.
            let by = placed.expect("a Place before every Substitution");
            assert_eq!(e.count, 1 << by, "{e:?}");
            assert_ne!(e.finger, by);
        }
        if e.kind() == Ok(EventKind::Rewind) {
            assert!(e.finger < 3, "helper {}", e.finger);
            let relocated = e.count;
            assert!(relocated != 0 && relocated < 8, "{relocated:b}");
            assert_eq!(
                relocated & (1 << e.finger),
                0,
                "the helper is not relocated"
            );
        }
    }
    println!("{substitutions} substitutions, {rewinds} rewinds, {places} places, {lifts} lifts");
    g.finish();
}

#[test]
fn a_substitution_in_flight_when_a_goal_is_preempted_still_counts() {
    // The Lift that completes a substitution is under way when a new goal
    // arrives: the lift finishes (a gait is never left half done) and the
    // substitution is reported.
    let ns = Namespace::new("p");
    let mut g = gait_loop(&ns, 47, |_| {});
    let turn = UnitQuaternion::from_scaled_axis(Vector3::z() * 3.0);
    let c = turn.coords;
    g.client.send(Command::goal(
        9,
        1,
        GoalFrame::Absolute,
        [c.w, c.x, c.y, c.z],
    ));
    let mut placed = None;
    let mut preempted_at = None;
    let mut after = Vec::new();
    for t in 0..60_000 {
        let (_, ev) = g.tick();
        for e in ev {
            if preempted_at.is_some() {
                after.push(e);
                continue;
            }
            match e.kind() {
                Ok(EventKind::Fault) => panic!("fault {e:?}"),
                Ok(EventKind::Place) => placed = Some(e.finger),
                Ok(EventKind::Lift) if placed.is_some_and(|p| p != e.finger) => {
                    // A substitution's lift has begun: preempt it.
                    let home = UnitQuaternion::identity().coords;
                    g.client.send(Command::goal(
                        9,
                        2,
                        GoalFrame::Absolute,
                        [home.w, home.x, home.y, home.z],
                    ));
                    preempted_at = Some((t, e.finger));
                }
                _ => {}
            }
        }
        if after.iter().any(|e| {
            e.kind() == Ok(EventKind::GoalTransition)
                && e.goal_id == 2
                && GoalState::try_from(e.state).is_ok_and(GoalState::is_terminal)
        }) {
            break;
        }
        g.yield_to_planner();
    }
    let (_, lifting) = preempted_at.expect("no substitution began");
    let kinds: Vec<_> = after.iter().map(|e| e.kind()).collect();
    let preempted = after.iter().position(|e| {
        e.kind() == Ok(EventKind::GoalTransition)
            && e.goal_id == 1
            && GoalState::try_from(e.state) == Ok(GoalState::Preempted)
    });
    let substituted = after
        .iter()
        .position(|e| e.kind() == Ok(EventKind::Substitution) && e.finger == lifting);
    assert!(preempted.is_some(), "{kinds:?}");
    assert!(substituted.is_some(), "finger {lifting}: {kinds:?}");
    // The gait belongs to the goal it was begun for.
    let s = after[substituted.unwrap()];
    assert_eq!((s.goal_id, s.client_id), (1, 9));
    g.finish();
}
