//! A daemon whose plant is gone, every part a process (gaitd with
//! `[plant] kind = "shm"`, `gaitctl plant sim` killed with SIGKILL), in
//! lockstep and in real time, killed mid-goal: every command still gets its
//! one answer, with a reason that says what is missing; in lockstep the
//! daemon keeps the plant's clock to the end (no jump to its own, no
//! overrun counted for the time it waited), through a SIGTERM, the stop it
//! cannot finish without the plant, and its final status.

use gaitd_client::{Client, DaemonState, EventKind, GoalSpec, ReasonCode, Status, Verdict};
use gaitd_tests::{TestDaemon, TestPlant, wait_plant_started};
use shm_schema::{FaultCode, Phase};
use std::time::{Duration, Instant};

const T: Duration = Duration::from_secs(5);

fn fault_status(c: &mut Client, want: FaultCode, d: &TestDaemon) -> Status {
    let t0 = Instant::now();
    loop {
        let s = c.wait_status(T).unwrap();
        if s.fault == want.code() {
            return s;
        }
        assert!(
            t0.elapsed() < Duration::from_secs(10),
            "no {want:?}: fault {}\n{}",
            s.fault,
            d.log()
        );
    }
}

fn plant_gone(timing: &str, extra: &str) {
    let mut d = TestDaemon::new(
        &format!("gone-{timing}"),
        &format!(
            "[load]\ngravity = [0.0, 0.0, 0.0]\n[plant]\nkind = \"shm\"\ntiming = \"{timing}\"\n{extra}"
        ),
    );
    d.spawn();
    let mut plant = TestPlant::sim(&d);
    let mut c = d.client();
    let started = wait_plant_started(&mut c, &d, &plant);
    // Killed mid-goal: the hand is moving, so the stop (the safe hold)
    // cannot finish without the plant.
    let t = c
        .reorient(&GoalSpec::turn([0.0, 0.0, 1.0], 3.0).unwrap(), T)
        .unwrap();
    assert_eq!(t.verdict, Verdict::Accepted);
    let t0 = Instant::now();
    while c.wait_status(T).unwrap().phase != Phase::Rotate.code() {
        assert!(t0.elapsed() < Duration::from_secs(20), "never rotating");
    }
    plant.kill();
    // As a client would: 0.5 s later, while a lockstep daemon still
    // waits for the plant (plant.lockstep_timeout_ms, 1 s).
    std::thread::sleep(Duration::from_millis(500));
    let reset = c.reset(T).expect("a reset is answered");
    assert!(
        matches!(
            reset,
            Verdict::Rejected(ReasonCode::NoFreshMeasurement | ReasonCode::NotAtRest)
        ),
        "{reset:?}"
    );
    let lost = fault_status(&mut c, FaultCode::PlantLost, &d);
    assert_eq!(lost.phase, Phase::SafeHold.code());
    // Goals, holds and resets are answered while it is gone.
    let goal = c
        .reorient(&GoalSpec::turn([0.0, 0.0, 1.0], 0.5).unwrap(), T)
        .expect("a goal is answered");
    assert_eq!(goal.verdict, Verdict::Rejected(ReasonCode::Faulted));
    assert_eq!(c.hold(T).expect("a hold is answered"), Verdict::Accepted);
    assert_eq!(
        c.reset(T).expect("a reset is answered"),
        Verdict::Rejected(ReasonCode::NoFreshMeasurement)
    );
    // Statuses keep coming (the daemon is alive), and a client sees why.
    let s = c.wait_status(T).unwrap();
    let age = gaitd_client::monotonic_ns().saturating_sub(s.publish_time_ns);
    assert!(age < 1_000_000_000, "stale status: {age} ns old");
    d.signal(libc::SIGTERM);
    let exit = d
        .wait(Duration::from_secs(10))
        .expect("exits after SIGTERM");
    assert!(exit.success(), "{exit:?}\n{}", d.log());
    let t0 = Instant::now();
    let last = loop {
        let s = c.latest_status().unwrap().unwrap();
        if s.daemon_state() == Ok(DaemonState::Stopped) {
            break s;
        }
        assert!(t0.elapsed() < T, "no final status\n{}", d.log());
        std::thread::sleep(Duration::from_millis(10));
    };
    let events: Vec<_> = c.events().unwrap().collect();
    let fault = events
        .iter()
        .find(|e| e.kind() == Ok(EventKind::Fault) && e.fault == FaultCode::PlantLost.code())
        .expect("a PlantLost event");
    let after: Vec<_> = events.iter().filter(|e| e.seq > fault.seq).collect();
    assert!(
        after
            .iter()
            .any(|e| e.kind() == Ok(EventKind::DaemonStopping)),
        "{events:?}"
    );
    if timing == "lockstep" {
        // Waiting for the plant is not a missed period (in real time a
        // loaded machine may miss real ones).
        for e in &events {
            assert_ne!(e.kind(), Ok(EventKind::Overrun), "{e:?}\n{events:?}");
        }
        // One clock: the plant's. Nothing ticks after the loss, so the loss
        // is the last plant time, and everything after it carries it.
        for e in &after {
            assert_eq!(e.time_ns, fault.time_ns, "{e:?}");
        }
        assert_eq!(last.time_ns, fault.time_ns);
        assert!(
            fault.time_ns < started.time_ns + 60_000_000_000,
            "plant time: {} ns",
            fault.time_ns
        );
        assert_eq!(last.timing.overruns, 0);
    } else {
        for w in events.windows(2) {
            assert!(w[1].time_ns >= w[0].time_ns, "{w:?}");
        }
        assert!(last.time_ns >= fault.time_ns);
    }
}

#[test]
fn a_lockstep_daemon_without_its_plant_answers_and_keeps_the_plant_clock() {
    plant_gone("lockstep", "");
}

#[test]
fn a_real_time_daemon_without_its_plant_answers_every_command() {
    // A loaded machine delays a real-time plant now and then.
    plant_gone("realtime", "max_missed = 200\nstale_after_ms = 500\n");
}
