//! A hand outside the daemon (issue "Hands outside the daemon"): gaitd
//! with `[plant] kind = "shm"` and the kinematic hand in its own process
//! (`gaitctl plant sim`), every part a separate process.
//!
//! Graded on the plant's own measurement (the status's
//! `measured_object_q`, which is what the plant process reported), never
//! on the controller's command.

use gaitd_client::{Client, GoalSpec, GoalState, ReasonCode, Status, Verdict};
use gaitd_tests::{TestDaemon, TestPlant};
use shm_schema::{FaultCode, Phase, measured};
use std::time::{Duration, Instant};
use test_support::quat::angle;

const T: Duration = Duration::from_secs(5);
const LONG: Duration = Duration::from_secs(120);

/// A daemon with an external plant, `timing` as given.
fn daemon(tag: &str, timing: &str, extra: &str) -> TestDaemon {
    let mut d = TestDaemon::new(
        tag,
        &format!("[plant]\nkind = \"shm\"\ntiming = \"{timing}\"\n{extra}"),
    );
    d.spawn();
    d
}

/// Waits until the status says the controller holds a valid start state
/// (the plant's first measurement was taken).
fn wait_started(c: &mut Client, d: &TestDaemon, plant: &TestPlant) -> Status {
    let t0 = Instant::now();
    loop {
        let s = c.wait_status(T).unwrap();
        if s.fault == FaultCode::None.code() && s.phase == Phase::Hold.code() {
            return s;
        }
        assert!(
            t0.elapsed() < Duration::from_secs(20),
            "never started: fault {} phase {}\n--- gaitd ---\n{}\n--- plant ---\n{}",
            s.fault,
            s.phase,
            d.log(),
            plant.log()
        );
    }
}

/// The plant's measured orientation once the daemon holds still after `goal`.
fn run_goal(c: &mut Client, goal: &GoalSpec) -> (GoalState, ReasonCode, Status) {
    let t = c.reorient(goal, T).unwrap();
    assert_eq!(t.verdict, Verdict::Accepted);
    let o = c.wait_outcome(t.goal_id, LONG).unwrap();
    // A status of a later tick: the hand then holds still.
    let s = loop {
        let s = c.wait_status(T).unwrap();
        if s.tick > t.tick && s.goal.goal_id == t.goal_id && s.phase == Phase::Hold.code() {
            break s;
        }
    };
    (o.state, o.reason, s)
}

fn seeded_goals(n: usize, seed: u64) -> Vec<[f64; 4]> {
    // xorshift: a fixed sequence of Haar-random orientations.
    let mut x = seed;
    let mut u = || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        (x >> 11) as f64 / (1u64 << 53) as f64
    };
    (0..n)
        .map(|_| {
            let (u1, u2, u3) = (u(), u(), u());
            let tau = std::f64::consts::TAU;
            let (a, b) = ((1.0 - u1).sqrt(), u1.sqrt());
            [
                a * (tau * u2).sin(),
                a * (tau * u2).cos(),
                b * (tau * u3).sin(),
                b * (tau * u3).cos(),
            ]
        })
        .collect()
}

#[test]
fn the_paper_scenario_and_goals_on_an_out_of_process_kinematic_plant() {
    // The plant interface, not the load: a weightless object (under the
    // default load: planner_load.rs, python_plant_e2e.rs).
    let mut d = TestDaemon::new(
        "psim",
        "[load]\ngravity = [0.0, 0.0, 0.0]\n[plant]\nkind = \"shm\"\ntiming = \"lockstep\"\n",
    );
    d.spawn();
    let plant = TestPlant::sim(&d);
    let mut c = d.client();
    let s0 = wait_started(&mut c, &d, &plant);
    assert_eq!(s0.measured_mask & measured::OBJECT, measured::OBJECT);
    let start = s0.measured_object_q;
    let tau = std::f64::consts::TAU;
    for axis in [[0.0, 0.0, 1.0], [1.0, 0.0, 0.0]] {
        let (state, reason, s) = run_goal(&mut c, &GoalSpec::turn(axis, tau).unwrap());
        assert_eq!((state, reason), (GoalState::Succeeded, ReasonCode::Reached));
        let err = angle(s.measured_object_q, start);
        println!("full turn about {axis:?}: back at the start within {err:.1e} rad (measured)");
        assert!(err <= 1e-6, "full turn about {axis:?} ends {err:e} rad off");
        assert!(s.goal.gaits_done >= 4, "it gaited: {}", s.goal.gaits_done);
    }
    for (i, q) in seeded_goals(3, 0x9e37).into_iter().enumerate() {
        let (state, reason, s) = run_goal(&mut c, &GoalSpec::absolute(q));
        assert_eq!((state, reason), (GoalState::Succeeded, ReasonCode::Reached));
        let err = angle(s.measured_object_q, q);
        println!("goal {i}: {err:.1e} rad off (measured)");
        assert!(err <= 1e-6, "goal {i} ends {err:e} rad off");
    }
    assert_eq!(c.bad_samples(), 0);
}

#[test]
fn a_goal_in_real_time_on_an_out_of_process_kinematic_plant() {
    // A loaded machine (the test suite runs in parallel) delays a real-time
    // plant by many periods now and then: a generous tolerance.
    let d = daemon(
        "prt",
        "realtime",
        "max_missed = 200\nstale_after_ms = 500\n",
    );
    let plant = TestPlant::sim(&d);
    let mut c = d.client();
    wait_started(&mut c, &d, &plant);
    let q = seeded_goals(1, 7)[0];
    let (state, reason, s) = run_goal(&mut c, &GoalSpec::absolute(q));
    assert_eq!((state, reason), (GoalState::Succeeded, ReasonCode::Reached));
    let err = angle(s.measured_object_q, q);
    assert!(err <= 1e-6, "ends {err:e} rad off");
}

/// Killed mid-goal: the loss is detected within `plant.max_missed` ticks
/// (real time), the hand goes to safe hold; a restarted plant plus a reset
/// make goals possible again.
#[test]
fn a_killed_plant_is_a_fault_and_a_restarted_one_resumes_after_reset() {
    let max_missed = 100;
    let d = daemon(
        "pkill",
        "realtime",
        &format!("max_missed = {max_missed}\nstale_after_ms = 1000\n"),
    );
    let mut plant = TestPlant::sim(&d);
    let mut c = d.client();
    wait_started(&mut c, &d, &plant);
    let t = c
        .reorient(&GoalSpec::turn([0.0, 0.0, 1.0], 3.0).unwrap(), T)
        .unwrap();
    // Mid-goal.
    let t0 = Instant::now();
    while c.wait_status(T).unwrap().goal.state != GoalState::Executing.code() {
        assert!(t0.elapsed() < Duration::from_secs(20), "never executing");
    }
    std::thread::sleep(Duration::from_millis(500));
    plant.kill();
    let o = c.wait_outcome(t.goal_id, LONG).unwrap();
    assert_eq!(
        (o.state, o.reason),
        (GoalState::Aborted, ReasonCode::FaultDetected)
    );
    let fault = c
        .events()
        .unwrap()
        .find(|e| e.kind() == Ok(gaitd_client::EventKind::Fault))
        .expect("a fault event");
    assert_eq!(fault.fault, FaultCode::PlantLost.code());
    let s = c.wait_status(T).unwrap();
    assert_eq!(s.phase, Phase::SafeHold.code());
    // Detected within the tolerated ticks of the last measurement.
    let late = fault.tick - s.measured_tick;
    println!("lost {late} ticks after the last measurement (tolerance {max_missed})");
    assert!(late <= max_missed + 2, "{late} ticks");
    // Goals are refused until reset.
    let refused = c
        .reorient(&GoalSpec::turn([0.0, 0.0, 1.0], 0.5).unwrap(), T)
        .unwrap();
    assert_eq!(refused.verdict, Verdict::Rejected(ReasonCode::Faulted));
    // A reset without a plant is refused.
    // A reset without a plant is refused: while braking because the hand
    // is not at rest, then because nothing is measured.
    let t0 = Instant::now();
    loop {
        match c.reset(T).unwrap() {
            Verdict::Rejected(ReasonCode::NotAtRest) => {}
            v => {
                assert_eq!(v, Verdict::Rejected(ReasonCode::NoFreshMeasurement));
                break;
            }
        }
        assert!(t0.elapsed() < Duration::from_secs(20), "still braking");
        std::thread::sleep(Duration::from_millis(50));
    }
    let plant = TestPlant::sim(&d);
    let t0 = Instant::now();
    loop {
        match c.reset(T).unwrap() {
            Verdict::Accepted => break,
            v => assert!(
                t0.elapsed() < Duration::from_secs(20),
                "reset refused: {v:?}\n{}",
                plant.log()
            ),
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    let q = seeded_goals(1, 11)[0];
    let (state, reason, s) = run_goal(&mut c, &GoalSpec::absolute(q));
    assert_eq!((state, reason), (GoalState::Succeeded, ReasonCode::Reached));
    assert!(angle(s.measured_object_q, q) <= 1e-6);
}

/// A plant that lies, stalls, loses a contact or faults: each is a fault
/// with its reason, naming the finger when the cause is one finger's (a
/// bad number of fingertip 1 or 2, contact 0 lost, fingertip 2 off its
/// setpoint), none otherwise; the hand goes to safe hold, and the daemon
/// keeps running. Flagged velocities are checked like every other number.
#[test]
fn lying_stalling_and_faulting_plants_are_faults_with_their_reasons() {
    use shm_schema::NO_FINGER;
    let cases = [
        ("nan", FaultCode::PlantInvalid, 1),
        ("non-unit", FaultCode::PlantInvalid, NO_FINGER),
        ("nan-omega", FaultCode::PlantInvalid, NO_FINGER),
        ("inf-tip-velocity", FaultCode::PlantInvalid, 2),
        ("backwards", FaultCode::PlantSequence, NO_FINGER),
        ("session", FaultCode::PlantSequence, NO_FINGER),
        ("contact", FaultCode::ContactLost, 0),
        ("stuck", FaultCode::StuckFinger, 2),
        ("fault", FaultCode::PlantFault, NO_FINGER),
        ("stall", FaultCode::PlantLost, NO_FINGER),
    ];
    for (lie, want, finger) in cases {
        let d = daemon(
            &format!("lie-{lie}"),
            "lockstep",
            "lockstep_timeout_ms = 300\n",
        );
        // A lockstep plant runs its good steps in milliseconds, quicker
        // than a client can be sure to see one; that the fault came after
        // them (not at start-up) is checked on the fault event's tick.
        let after = 300;
        let plant = TestPlant::fixture(&d, lie, after);
        let mut c = d.client();
        let t0 = Instant::now();
        let s = loop {
            let s = c.wait_status(T).unwrap();
            if s.fault != FaultCode::None.code() && s.fault != FaultCode::PlantWaiting.code() {
                break s;
            }
            assert!(
                t0.elapsed() < Duration::from_secs(20),
                "{lie}: no fault\n{}",
                d.log()
            );
        };
        assert_eq!(FaultCode::try_from(s.fault), Ok(want), "{lie}");
        assert_eq!(s.phase, Phase::SafeHold.code(), "{lie}");
        let e = c
            .events()
            .unwrap()
            .find(|e| e.kind() == Ok(gaitd_client::EventKind::Fault))
            .expect("a fault event");
        assert_eq!(e.fault, want.code(), "{lie}");
        assert_eq!(e.finger, finger, "{lie}: the fault's finger");
        assert!(
            e.tick >= after,
            "{lie}: faulted at tick {} before the plant's {after} good steps\n{}\n{}",
            e.tick,
            d.log(),
            plant.log()
        );
        assert_eq!(e.check(), Ok(()), "{lie}");
        if lie == "fault" {
            assert_eq!(
                e.count,
                u64::from(shm_schema::PlantFault::EmergencyStop.code())
            );
        }
        // Still serving.
        assert_eq!(c.hold(T).unwrap_or(Verdict::Accepted), Verdict::Accepted);
        drop(c);
        let mut d = d;
        assert!(d.running(), "{lie}: the daemon died\n{}", d.log());
        drop(plant);
    }
}

/// A plant whose first state breaks an invariant: refused with the
/// invariant's reason, nothing moves, goals are refused.
#[test]
fn a_plant_starting_in_an_invalid_state_is_refused_with_its_reason() {
    let d = daemon("pinvalid", "lockstep", "");
    let _plant = TestPlant::fixture(&d, "start-invalid", 0);
    let mut c = d.client();
    let t0 = Instant::now();
    let s = loop {
        let s = c.wait_status(T).unwrap();
        if s.fault != FaultCode::None.code() && s.fault != FaultCode::PlantWaiting.code() {
            break s;
        }
        assert!(t0.elapsed() < Duration::from_secs(20), "{}", d.log());
    };
    assert_eq!(
        FaultCode::try_from(s.fault),
        Ok(FaultCode::ForceClosureLost)
    );
    assert_eq!(s.phase, Phase::SafeHold.code());
    let t = c
        .reorient(&GoalSpec::turn([0.0, 0.0, 1.0], 0.5).unwrap(), T)
        .unwrap();
    assert_eq!(t.verdict, Verdict::Rejected(ReasonCode::Faulted));
    // The command it receives keeps it still: not enabled.
    let s2 = c.wait_status(T).unwrap();
    assert_eq!(s2.commanded_object_q, s.commanded_object_q);
}

/// Lockstep is reproducible bit for bit: a goal queued before the plant
/// starts is taken at the plant's first tick, its plan delivered at a fixed
/// tick, and two runs write the same trace (every line after the header,
/// which names the run).
#[test]
fn two_lockstep_runs_write_identical_traces() {
    let run = |i: u32| -> (Vec<String>, Vec<(u32, u64)>) {
        let traces = test_support::scratch_dir(&format!("e2e-det-{i}"));
        let d = daemon(
            &format!("det{i}"),
            "lockstep",
            &format!("[daemon]\ntrace_dir = \"{}\"\n", traces.display()),
        );
        let mut c = d.client();
        // Queued before the plant exists: handled at its first tick.
        let goal = GoalSpec::turn([0.3, -0.2, 1.0], 2.0).unwrap();
        let cmd = goal.to_command(c.client_id(), 1);
        let request = c.send_command(cmd).unwrap();
        let plant = TestPlant::sim(&d);
        let a = c.wait_answer(request, LONG).unwrap();
        assert_eq!(a.verdict(), Ok(Verdict::Accepted), "{}", plant.log());
        let o = c.wait_outcome(1, LONG).unwrap();
        assert_eq!(o.state, GoalState::Succeeded);
        // The ticks of the goal's transitions (plant time: the same in
        // both runs only if plans arrive at fixed ticks).
        let ticks = gaitd_tests::goal_transition_ticks(&mut c, 1);
        let lines = gaitd_tests::trace_lines(&traces);
        let _ = std::fs::remove_dir_all(&traces);
        (lines, ticks)
    };
    let ((a, ticks_a), (b, ticks_b)) = (run(0), run(1));
    println!("goal transitions (state, tick): {ticks_a:?}");
    assert!(
        ticks_a.len() >= 3,
        "accepted, planning, executing, succeeded: {ticks_a:?}"
    );
    assert_eq!(ticks_a, ticks_b, "the goal's transitions at the same ticks");
    assert!(a.len() > 1000, "a real motion: {} lines", a.len());
    assert_eq!(a.len(), b.len(), "same number of ticks");
    let first_diff = a.iter().zip(&b).position(|(x, y)| x != y);
    assert_eq!(first_diff, None, "traces differ from line {first_diff:?}");
}

/// A plant that never comes: the daemon waits in safe hold (nothing moves)
/// and the log says what to check once `plant.connect_timeout_ms` passed.
#[test]
fn a_plant_that_never_comes_is_reported() {
    let d = daemon(
        "pnone",
        "realtime",
        "connect_timeout_ms = 100\n[daemon]\nhousekeeping_period_ms = 100\n",
    );
    let mut c = d.client();
    let s = c.wait_status(T).unwrap();
    assert_eq!(FaultCode::try_from(s.fault), Ok(FaultCode::PlantWaiting));
    assert_eq!(s.phase, Phase::SafeHold.code());
    let t = c
        .reorient(&GoalSpec::turn([0.0, 0.0, 1.0], 0.5).unwrap(), T)
        .unwrap();
    assert_eq!(t.verdict, Verdict::Rejected(ReasonCode::Faulted));
    let t0 = Instant::now();
    while !d.log().contains("no plant has sent a valid measurement") {
        assert!(t0.elapsed() < Duration::from_secs(10), "{}", d.log());
        std::thread::sleep(Duration::from_millis(20));
    }
}
