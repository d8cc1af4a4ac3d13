//! A configuration whose start grasp cannot hold the load (SPEC §1.3 I1')
//! is said so at `--check-config` and at start-up, with the numbers, and
//! the first status already shows a negative load margin — not only when
//! a goal is refused.
//!
//! The test's own bound: the paper's start grasp has three fingertips on
//! the equator, so every contact normal is horizontal and the weight m·g
//! (vertical) is carried by friction alone: Σ μ Nᵢ ≥ m g, hence the
//! largest normal force is at least m g / (3 μ), μ = tan(friction angle).

use gaitd_tests::TestDaemon;
use std::process::Command;
use std::time::{Duration, Instant};

const MASS: f64 = 10.0;
const G: f64 = 9.81;
/// `model.friction_angle_deg` of the default configuration, stated here.
const FRICTION_DEG: f64 = 20.0;
const MAX_GRIP: f64 = 20.0;

fn heavy() -> String {
    format!("[load]\nobject_mass = {MASS}\n")
}

/// The F* the text states (`… F* = <x> N …`).
fn stated_peak(text: &str) -> f64 {
    let at = text
        .find("F* = ")
        .unwrap_or_else(|| panic!("no F* in: {text}"));
    let rest = &text[at + 5..];
    let end = rest.find(' ').unwrap();
    rest[..end]
        .parse()
        .unwrap_or_else(|e| panic!("{e}: {text}"))
}

fn lower_bound() -> f64 {
    MASS * G / (3.0 * FRICTION_DEG.to_radians().tan())
}

#[test]
fn check_config_warns_when_the_start_grasp_cannot_hold_the_load() {
    let d = TestDaemon::new("heavy-check", &heavy());
    let out = Command::new(gaitd_tests::workspace_bin("gaitd"))
        .arg("--config")
        .arg(d.config_path())
        .arg("--check-config")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    // A valid configuration: it is the load that is too much for it.
    assert!(out.status.success(), "{err}");
    let line = err
        .lines()
        .find(|l| l.contains("cannot hold the load"))
        .unwrap_or_else(|| panic!("no warning:\n{err}"));
    assert!(line.starts_with("gaitd: warning:"), "{line}");
    let peak = stated_peak(line);
    println!("{line}");
    assert!(
        peak >= lower_bound(),
        "F* {peak} N below the friction bound {} N",
        lower_bound()
    );
    assert!(
        line.contains(&format!("load.max_grip = {MAX_GRIP} N")),
        "{line}"
    );
    assert!(line.contains("object_mass = 10 kg"), "{line}");
    // The default load says nothing.
    let light = TestDaemon::new("light-check", "");
    let out = Command::new(gaitd_tests::workspace_bin("gaitd"))
        .arg("--config")
        .arg(light.config_path())
        .arg("--check-config")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(!err.contains("cannot hold the load"), "{err}");
}

#[test]
fn start_up_warns_and_the_first_status_shows_the_negative_margin() {
    let mut d = TestDaemon::new("heavy-start", &heavy());
    d.spawn();
    let mut c = d.client();
    let s = c.wait_status(Duration::from_secs(5)).unwrap();
    assert!(
        s.load_margin < 0.0 && s.load_grip > MAX_GRIP,
        "load_grip {} N, load_margin {} N",
        s.load_grip,
        s.load_margin
    );
    assert!(s.load_grip >= lower_bound(), "{}", s.load_grip);
    let t0 = Instant::now();
    let line = loop {
        if let Some(l) = d.log().lines().find(|l| l.contains("cannot hold the load")) {
            break l.to_owned();
        }
        assert!(t0.elapsed() < Duration::from_secs(10), "{}", d.log());
        std::thread::sleep(Duration::from_millis(20));
    };
    assert!(line.contains("WARN"), "{line}");
    let peak = stated_peak(&line);
    assert!(
        (peak - s.load_grip).abs() <= 0.05 + 1e-3 * peak,
        "log {peak} N, status {} N",
        s.load_grip
    );
}
