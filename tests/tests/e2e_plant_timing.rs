//! The timing contract with the plant (PLANT-GUIDE.md, "Timing
//! contract"), every part a process: a plant that steps on several times
//! without taking the daemon's commands (`plant_fixture --lie deaf`: it
//! repeats its last command, as TriFinger's driver repeats a late action)
//! is counted in the status and, at `plant.max_misses_in_row` misses in a
//! row, a fault (`PlantTiming`) with its event; an exact plant misses
//! nothing.

use gaitd_client::EventKind;
use gaitd_tests::{TestDaemon, TestPlant, wait_plant_started};
use shm_schema::{FaultCode, Phase};
use std::time::{Duration, Instant};

const T: Duration = Duration::from_secs(5);

#[test]
fn a_plant_that_repeats_commands_is_counted_then_faulted() {
    let mut d = TestDaemon::new(
        "timing-deaf",
        "[plant]\nkind = \"shm\"\ntiming = \"lockstep\"\nmax_misses_in_row = 3\n",
    );
    d.spawn();
    let plant = TestPlant::fixture(&d, "deaf", 300);
    let mut c = d.client();
    wait_plant_started(&mut c, &d, &plant);
    let t0 = Instant::now();
    let s = loop {
        let s = c.wait_status(T).unwrap();
        if s.fault != FaultCode::None.code() {
            break s;
        }
        assert!(
            t0.elapsed() < Duration::from_secs(20),
            "no fault\n{}",
            d.log()
        );
    };
    assert_eq!(FaultCode::try_from(s.fault), Ok(FaultCode::PlantTiming));
    assert_eq!(s.phase, Phase::SafeHold.code());
    let t = &s.timing;
    println!(
        "commands late {} repeated {}, measurements late {} repeated {}, misses in a row {} (max {})",
        t.plant_commands_late,
        t.plant_commands_repeated,
        t.plant_measurements_late,
        t.plant_measurements_repeated,
        t.plant_misses_in_row,
        t.plant_misses_in_row_max
    );
    assert!(t.plant_commands_repeated >= 3, "{t:?}");
    assert!(t.plant_misses_in_row_max >= 3, "{t:?}");
    // Lockstep: the daemon never runs ahead of the plant.
    assert_eq!((t.plant_commands_late, t.plant_measurements_late), (0, 0));
    let e = c
        .events()
        .unwrap()
        .find(|e| e.kind() == Ok(EventKind::Fault))
        .expect("a fault event");
    assert_eq!(e.fault, FaultCode::PlantTiming.code());
    assert!(d.running(), "{}", d.log());
}

#[test]
fn an_exact_lockstep_plant_misses_nothing() {
    let mut d = TestDaemon::new(
        "timing-exact",
        "[plant]\nkind = \"shm\"\ntiming = \"lockstep\"\n",
    );
    d.spawn();
    let plant = TestPlant::fixture(&d, "none", 0);
    let mut c = d.client();
    let s0 = wait_plant_started(&mut c, &d, &plant);
    // A second of plant time.
    let s = loop {
        let s = c.wait_status(T).unwrap();
        if s.tick > s0.tick + 1000 {
            break s;
        }
    };
    assert_eq!(s.fault, FaultCode::None.code());
    let t = &s.timing;
    assert_eq!(
        (
            t.plant_commands_late,
            t.plant_commands_repeated,
            t.plant_measurements_late,
            t.plant_measurements_repeated,
            t.plant_misses_in_row_max
        ),
        (0, 0, 0, 0, 0),
        "{t:?}"
    );
}
