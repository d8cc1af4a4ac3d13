//! Recovering from a plant that misbehaved once, every part a process:
//! gaitd with `[plant] kind = "shm"` and `gaitctl plant sim`, which lies in
//! one measurement when it gets SIGUSR1 (`--lie-on-usr1`), in lockstep and
//! in real time.
//!
//! After the lie the daemon faults, as documented; the plant then measures
//! correctly again, and a reset must re-base on those measurements —
//! wherever the object is (here away from the start orientation, where
//! the controller's estimate and the measurement differ most).

use gaitd_client::{Client, GoalSpec, GoalState, ReasonCode, Verdict};
use gaitd_tests::{TestDaemon, TestPlant, wait_plant_started};
use shm_schema::{FaultCode, Phase};
use std::time::{Duration, Instant};
use test_support::quat::angle;

const T: Duration = Duration::from_secs(5);
const LONG: Duration = Duration::from_secs(60);

/// Runs `goal` to its end; returns the outcome.
fn run(c: &mut Client, goal: &GoalSpec) -> (GoalState, ReasonCode) {
    let t = c.reorient(goal, T).unwrap();
    assert_eq!(t.verdict, Verdict::Accepted);
    let o = c.wait_outcome(t.goal_id, LONG).unwrap();
    (o.state, o.reason)
}

/// Resets until accepted (a few ticks may pass before a fresh measurement
/// is there); every refusal on the way must be a transient one.
fn reset_until_accepted(c: &mut Client, d: &TestDaemon, plant: &TestPlant) {
    let t0 = Instant::now();
    let mut refused = Vec::new();
    loop {
        match c.reset(T).unwrap() {
            Verdict::Accepted => break,
            Verdict::Rejected(r) => refused.push(r),
        }
        assert!(
            t0.elapsed() < Duration::from_secs(10) && refused.len() < 50,
            "reset refused {} times: {refused:?}\n--- gaitd ---\n{}\n--- plant ---\n{}",
            refused.len(),
            d.log(),
            plant.log()
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    for r in &refused {
        assert!(
            matches!(r, ReasonCode::NoFreshMeasurement | ReasonCode::NotAtRest),
            "a reset refused for {r:?} before it was accepted: {refused:?}"
        );
    }
}

fn lie_once_then_reset(timing: &str, extra: &str) {
    // The plant interface, not the load: a weightless object.
    let mut d = TestDaemon::new(
        &format!("lie-once-{timing}"),
        &format!(
            "[load]\ngravity = [0.0, 0.0, 0.0]\n[plant]\nkind = \"shm\"\ntiming = \"{timing}\"\n{extra}"
        ),
    );
    d.spawn();
    let plant = TestPlant::sim_with(&d, &["--lie-on-usr1", "non-unit"]);
    let mut c = d.client();
    wait_plant_started(&mut c, &d, &plant);
    // Away from the start orientation.
    let turn = GoalSpec::turn([0.0, 0.0, 1.0], 0.6).unwrap();
    assert_eq!(
        run(&mut c, &turn),
        (GoalState::Succeeded, ReasonCode::Reached)
    );
    let before = c.wait_status(T).unwrap();
    assert_eq!(before.fault, FaultCode::None.code());
    // One measurement with a non-unit object quaternion (in real time a
    // newer one arriving in the same tick may supersede it: then again).
    let t0 = Instant::now();
    let mut lies = 0;
    let faulted = 'lie: loop {
        plant.signal(libc::SIGUSR1);
        lies += 1;
        let t1 = Instant::now();
        while t1.elapsed() < Duration::from_millis(100) {
            let s = c.wait_status(T).unwrap();
            if s.fault != FaultCode::None.code() {
                break 'lie s;
            }
        }
        assert!(
            t0.elapsed() < Duration::from_secs(10),
            "no fault\n{}\n--- plant ---\n{}",
            d.log(),
            plant.log()
        );
    };
    assert_eq!(
        FaultCode::try_from(faulted.fault),
        Ok(FaultCode::PlantInvalid),
        "{}",
        plant.log()
    );
    println!("{timing}: faulted after {lies} lie(s)");
    assert_eq!(faulted.phase, Phase::SafeHold.code());
    // The plant measures the truth again: measured = commanded.
    let s = c.wait_status(T).unwrap();
    let err = angle(s.measured_object_q, s.commanded_object_q);
    assert!(err < 1e-6, "measured {err:e} rad from commanded");
    reset_until_accepted(&mut c, &d, &plant);
    let t0 = Instant::now();
    let s = loop {
        let s = c.wait_status(T).unwrap();
        if s.fault == FaultCode::None.code() {
            break s;
        }
        assert!(
            t0.elapsed() < Duration::from_secs(10),
            "the reset was accepted but the fault {} stays\n{}",
            s.fault,
            d.log()
        );
    };
    assert_eq!(s.phase, Phase::Hold.code());
    // It holds where it was and goes on from there.
    assert!(angle(s.commanded_object_q, before.commanded_object_q) < 1e-6);
    let back = GoalSpec::absolute([1.0, 0.0, 0.0, 0.0]);
    assert_eq!(
        run(&mut c, &back),
        (GoalState::Succeeded, ReasonCode::Reached)
    );
    let s = c.wait_status(T).unwrap();
    assert!(angle(s.measured_object_q, [1.0, 0.0, 0.0, 0.0]) < 1e-6);
    assert!(d.running(), "{}", d.log());
}

#[test]
fn a_plant_that_lies_once_in_lockstep_is_reset_from_its_fresh_measurements() {
    lie_once_then_reset("lockstep", "");
}

#[test]
fn a_plant_that_lies_once_in_real_time_is_reset_from_its_fresh_measurements() {
    // A loaded machine delays a real-time plant now and then.
    lie_once_then_reset("realtime", "max_missed = 200\nstale_after_ms = 500\n");
}
