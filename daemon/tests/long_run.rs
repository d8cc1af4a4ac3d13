//! Numerical health over a long run (SPEC §12: "no NaN ever leaves the
//! core; quaternions renormalised; long runs (10⁶ ticks, many goals) do
//! not drift"): the daemon's real loop (`Runtime`, the gait controller with
//! its planner thread, iceoryx2 ports, the writer thread) on the mock
//! clock for 10⁶ ticks of one continuous run — goals chained one after
//! another from wherever the last one left the object (absolute, relative,
//! full turns, preemptions mid-motion, cancels, holds).
//!
//! Checked on every status the client receives: every float finite, the
//! quaternions of unit norm, the measured object reported beside the
//! commanded one, no fault. On every goal, graded on the plant's true
//! state (the embedded hand's object, not the controller's setpoint): an
//! absolute goal that succeeds ends within 1e-6 rad of its target, a full
//! turn ends where the object truly was when it was sent (any drift would
//! accumulate over turns). No wall-clock assertions: mock time, and the
//! test waits for the planner thread.
//!
//! `GAITD_LONG_RUN_TICKS` changes the length (default 10⁶).

#[path = "support/ipc_rig.rs"]
mod ipc_rig;

use ipc_rig::{Namespace, gait_loop};
use nalgebra::{Quaternion, UnitQuaternion};
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use shm_schema::{Command, EventKind, FaultCode, GoalFrame, GoalState, Status};
use std::collections::BTreeMap;
use test_support::random;

fn ticks() -> u64 {
    std::env::var("GAITD_LONG_RUN_TICKS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(1_000_000)
}

/// A Haar-random rotation in the wire's (w, x, y, z) order.
fn haar(rng: &mut ChaCha8Rng) -> [f64; 4] {
    let q = random::haar(rng);
    [q.w, q.i, q.j, q.k]
}

fn quat(q: [f64; 4]) -> UnitQuaternion<f64> {
    UnitQuaternion::from_quaternion(Quaternion::new(q[0], q[1], q[2], q[3]))
}

/// Every float of the status is finite, the quaternions are unit and the
/// workspace margins agree with the fingertip positions (β − angle(p, d_k)).
fn healthy(s: &Status, hand: &gait::HandConfig) -> Result<f64, String> {
    let mut floats: Vec<f64> = Vec::with_capacity(64);
    floats.extend(s.commanded_object_q);
    floats.extend(s.commanded_object_omega);
    floats.extend(s.measured_object_q);
    floats.extend([
        s.object_error,
        s.grasp_margin,
        s.goal.remaining_angle,
        s.goal.eta,
    ]);
    for f in &s.fingers {
        floats.extend(f.contact_hand);
        floats.extend(f.contact_object);
        floats.extend(f.commanded_tip_position);
        floats.extend(f.commanded_tip_orientation);
        floats.extend(f.measured_tip_position);
        floats.extend(f.measured_tip_orientation);
        floats.extend(f.tip_contact);
        floats.extend([
            f.roll,
            f.workspace_margin,
            f.commanded_normal_force,
            f.tip_error,
        ]);
    }
    let expected = shm_schema::measured::OBJECT | shm_schema::measured::TIPS;
    if s.measured_mask & expected != expected {
        return Err(format!("no measurement reported at tick {}", s.tick));
    }
    if let Some(i) = floats.iter().position(|x| !x.is_finite()) {
        return Err(format!("non-finite value #{i} at tick {}", s.tick));
    }
    let mut worst = 0.0f64;
    let quats = [&s.commanded_object_q, &s.measured_object_q]
        .into_iter()
        .chain(s.fingers.iter().map(|f| &f.commanded_tip_orientation))
        .chain(s.fingers.iter().map(|f| &f.measured_tip_orientation));
    for q in quats {
        let n = q.iter().map(|x| x * x).sum::<f64>().sqrt();
        worst = worst.max((n - 1.0).abs());
    }
    if worst > 1e-9 {
        return Err(format!(
            "quaternion norm off by {worst:e} at tick {}",
            s.tick
        ));
    }
    let m = &hand.model;
    for (k, f) in s.fingers.iter().enumerate() {
        let phi = m.finger_azimuth_deg[k].to_radians();
        let p = nalgebra::Vector3::from(f.commanded_tip_position);
        let d = nalgebra::Vector3::new(phi.cos(), phi.sin(), 0.0);
        let want = m.workspace_half_angle_deg.to_radians() - p.angle(&d);
        // acos-based angles near 0 are good to ~1e-8 rad.
        if (f.workspace_margin - want).abs() > 1e-7 {
            return Err(format!(
                "finger {k} workspace margin {} vs {want} at tick {}",
                f.workspace_margin, s.tick
            ));
        }
    }
    if s.fault != FaultCode::None.code() {
        return Err(format!("fault {} at tick {}", s.fault, s.tick));
    }
    Ok(worst)
}

/// The goal in flight and what to check when it ends.
#[derive(Debug, Clone, Copy)]
struct InFlight {
    id: u64,
    /// Absolute target, or where a full turn must come back to.
    target: Option<UnitQuaternion<f64>>,
    /// Active tick at which to interrupt it (preempt, cancel or hold).
    interrupt_at: Option<(u64, u32)>,
}

#[test]
fn a_million_ticks_of_goals_without_drift_or_nan() {
    let total = ticks();
    let ns = Namespace::new("l");
    let hand = ns.cfg.hand();
    let mut g = gait_loop(&ns, 45, |_| {});
    let mut rng = random::rng(0x10_6e_2a);
    let mut in_flight: Option<InFlight> = None;
    // The plant's true object orientation (the hand's, not the command).
    let truth = |g: &ipc_rig::GaitLoop| g.rt.controller().embedded().unwrap().state().object;
    let (mut goal_id, mut k, mut idle) = (0u64, 0u64, 0u64);
    let (mut active, mut loops) = (0u64, 0u64);
    let mut outcomes: BTreeMap<String, u64> = BTreeMap::new();
    let (mut worst_err, mut worst_norm, mut checked) = (0.0f64, 0.0f64, 0u64);
    let (mut statuses, mut turns_checked, mut gaits) = (0u64, 0u64, 0u64);
    let send_goal = |client: &ipc_rig::TestClient, goal_id: &mut u64, frame, q| {
        *goal_id += 1;
        client.send(Command::goal(5, *goal_id, frame, q));
        *goal_id
    };
    while active < total {
        loops += 1;
        // Next goal once the previous one ended and the hand rested a bit.
        if in_flight.is_none() && idle >= 20 {
            k += 1;
            let here = Some(truth(&g));
            let interrupt =
                |rng: &mut ChaCha8Rng, how| Some((active + rng.random_range(300..3000), how));
            in_flight = Some(match k % 6 {
                0 | 3 | 4 | 5 => {
                    let q = haar(&mut rng);
                    let id = send_goal(&g.client, &mut goal_id, GoalFrame::Absolute, q);
                    let how = (k % 6) as u32; // 3 preempt, 4 cancel, 5 hold
                    InFlight {
                        id,
                        target: Some(quat(q)),
                        interrupt_at: if how == 0 {
                            None
                        } else {
                            interrupt(&mut rng, how)
                        },
                    }
                }
                1 => InFlight {
                    id: send_goal(&g.client, &mut goal_id, GoalFrame::Relative, haar(&mut rng)),
                    target: None,
                    interrupt_at: None,
                },
                _ => {
                    let a: [f64; 3] = std::array::from_fn(|_| rng.random_range(-1.0..1.0));
                    let turn = [std::f64::consts::TAU, a[0], a[1], a[2] + 1e-3];
                    InFlight {
                        id: send_goal(&g.client, &mut goal_id, GoalFrame::AxisAngle, turn),
                        target: here,
                        interrupt_at: None,
                    }
                }
            });
        }
        // Interruptions mid-motion.
        if let Some(f) = in_flight.as_mut()
            && let Some((at, how)) = f.interrupt_at
            && active >= at
        {
            f.interrupt_at = None;
            match how {
                3 => {
                    let q = haar(&mut rng);
                    f.id = send_goal(&g.client, &mut goal_id, GoalFrame::Absolute, q);
                    f.target = Some(quat(q));
                }
                4 => g.client.send(Command::cancel(5, 0)),
                _ => g.client.send(Command::hold(5)),
            }
        }
        let (st, ev) = g.tick();
        for s in &st {
            worst_norm = worst_norm.max(healthy(s, &hand).unwrap_or_else(|e| panic!("{e}")));
            statuses += 1;
        }
        // Goal ends, from events or (when the loop outran the writer
        // thread and its ring dropped the event) from the status.
        let mut ends: Vec<(u64, GoalState, u64)> = Vec::new();
        for e in &ev {
            match e.kind() {
                Ok(EventKind::Fault) => panic!("fault event {e:?}"),
                Ok(EventKind::Place) => gaits += 1,
                Ok(EventKind::GoalTransition) => {
                    if let Ok(state) = GoalState::try_from(e.state)
                        && state.is_terminal()
                    {
                        *outcomes.entry(format!("{state:?}")).or_default() += 1;
                        ends.push((e.goal_id, state, e.tick));
                    }
                }
                _ => {}
            }
        }
        if let Some(s) = st.last()
            && let Ok(state) = s.goal_state()
            && state.is_terminal()
        {
            ends.push((s.goal.goal_id, state, s.tick));
        }
        for (id, state, tick) in ends {
            if let Some(f) = in_flight
                && f.id == id
            {
                // The hand holds still after a success and no new goal is
                // sent before this check: the plant's object now is where
                // the goal left it.
                if let (GoalState::Succeeded, Some(target)) = (state, f.target) {
                    let err = truth(&g).angle_to(&target);
                    assert!(err <= 1e-6, "goal ended {err:e} rad off (tick {tick})");
                    worst_err = worst_err.max(err);
                    checked += 1;
                    turns_checked += u64::from(k % 6 == 2);
                }
                in_flight = None;
                idle = 0;
            }
        }
        // Mock time runs on while the planner thread works in wall time.
        if !g.yield_to_planner() {
            active += 1;
            idle += 1;
        }
    }
    let dropped = g
        .shared
        .outbox_dropped
        .load(std::sync::atomic::Ordering::Relaxed);
    println!(
        "{active} ticks ({loops} in all), {dropped} messages dropped by the outbox, {goal_id} goals, outcomes {outcomes:?}, {gaits} placements; \
         {statuses} statuses checked, worst |q|-1 {worst_norm:.1e}; {checked} final orientations \
         checked ({turns_checked} full turns), worst error {worst_err:.1e} rad"
    );
    assert_eq!(
        g.rt.stats().overruns(),
        0,
        "mock time never misses a period"
    );
    assert_eq!(dropped, 0, "the writer kept up");
    assert!(goal_id >= total / 20_000, "many goals: {goal_id}");
    assert!(
        checked >= goal_id / 6 && turns_checked >= 1,
        "final errors checked: {checked} ({turns_checked} turns)"
    );
    // Status is latest-value and published by the writer thread while the
    // loop runs on: the client samples it rather than seeing every tick.
    assert!(statuses > total / 10, "statuses seen: {statuses}");
    g.finish();
}
