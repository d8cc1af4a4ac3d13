//! The MuJoCo physics hand of the `gaitd` Python package
//! (`gaitd.plants.mujoco_plant`), checked without gaitd's plant
//! backend:
//!
//! - driven open loop by the setpoints of a `gaitctl plan` trace of the
//!   paper's scenario, it makes the object follow the plan; the independent
//!   MuJoCo oracle (`tests/oracles/mujoco/replay.py`) replays the same trace
//!   for comparison;
//! - its command line in lockstep over iceoryx2 (a stand-in playing the
//!   daemon's side) replays a plan bit for bit against the same plant run
//!   in-process.
//!
//! The traces are made with a weightless object (`[load] gravity = [0,0,0]`),
//! as for `mujoco_replay.rs`. Wall-clock figures (real-time factors) are
//! printed, never asserted.

mod python_support;

use gaitd_tests::{oracle_python, repo_root, workspace_bin};
use python_support::{Namespace, json_output, script};
use std::path::Path;
use std::process::Command;

/// `gaitctl plan <args> --config <weightless> --out <dir>/<name>.jsonl`.
fn plan(dir: &Path, name: &str, args: &[&str]) -> std::path::PathBuf {
    let cfg = dir.join("weightless.toml");
    std::fs::write(&cfg, "[load]\ngravity = [0.0, 0.0, 0.0]\n").unwrap();
    let trace = dir.join(format!("{name}.jsonl"));
    let out = Command::new(workspace_bin("gaitctl"))
        .arg("plan")
        .args(args)
        .arg("--config")
        .arg(&cfg)
        .arg("--out")
        .arg(&trace)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "gaitctl plan {args:?}:\n{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    trace
}

fn f(v: &serde_json::Value) -> f64 {
    v.as_f64().unwrap_or(f64::NAN)
}

#[test]
fn the_mujoco_plant_follows_the_papers_plan_open_loop() {
    let ns = Namespace::new("open-loop");
    let trace = plan(&ns.dir, "paper", &["--scenario", "paper"]);
    let t0 = std::time::Instant::now();
    let out = script("mujoco_open_loop.py")
        .arg("--trace")
        .arg(&trace)
        .arg("--config")
        .arg(ns.dir.join("weightless.toml"))
        .output()
        .unwrap();
    let wall = t0.elapsed().as_secs_f64();
    let v = json_output(&out, "mujoco_open_loop.py");
    let o = &v["orientation"];
    let forces = |key: &str| -> Vec<String> {
        let list = v["rest_force"][key].as_array().cloned().unwrap_or_default();
        list.iter().map(|x| format!("{:.5}", f(x))).collect()
    };
    println!(
        "MuJoCo plant, open loop, paper scenario ({:.1} s simulated): orientation error max {:.3}° \
         (t = {:.3} s) final {:.3}°; centre drift max {:.2} mm; net slip max {:.3} mm; \
         rest force {:?} N for grips {:?} N; real-time factor {:.1} (script {wall:.1} s); \
         feedback view {}",
        f(&v["simulated_s"]),
        f(&o["max_error_deg"]),
        f(&o["max_error_t"]),
        f(&o["final_error_deg"]),
        1e3 * f(&v["drift"]["max_m"]),
        1e3 * f(&v["slip"]["max_net_m"]),
        forces("measured"),
        forces("planned"),
        f(&v["real_time_factor"]),
        v["feedback"],
    );
    // The independent oracle on the same trace, for comparison (its own
    // verdict is asserted by mujoco_replay.rs).
    let report = ns.dir.join("oracle.json");
    let oracle = Command::new(oracle_python())
        .arg(repo_root().join("tests/oracles/mujoco/replay.py"))
        .arg(&trace)
        .args(["--mass", "0.1", "-q", "--report"])
        .arg(&report)
        .output()
        .unwrap();
    println!(
        "oracle replay.py on the same trace: {}",
        String::from_utf8_lossy(&oracle.stdout)
            .lines()
            .next()
            .unwrap_or("")
    );

    assert!(v["diverged"].is_null(), "diverged: {}", v["diverged"]);
    let lines = std::fs::read_to_string(&trace)
        .unwrap()
        .lines()
        .filter(|l| !l.trim().is_empty())
        .count();
    assert_eq!(
        v["samples"].as_u64(),
        Some(lines as u64 - 1),
        "the whole plan was driven"
    );
    assert!(f(&o["max_error_deg"]) < 1.0, "orientation error {o}");
    assert!(
        f(&o["final_error_deg"]) < 1.0,
        "final orientation error {o}"
    );
    assert!(
        f(&v["drift"]["max_m"]) < 0.005,
        "the object moved away (dropped?): {}",
        v["drift"]
    );
    assert!(
        f(&v["slip"]["max_net_m"]) < 0.0025,
        "slip {}",
        v["slip"]["max_net_m"]
    );
    for (i, s) in v["contact"]["missing_s"]
        .as_array()
        .unwrap()
        .iter()
        .enumerate()
    {
        assert!(f(s) < 0.01, "finger {i} lost a planned contact for {s} s");
    }
    for (i, s) in v["contact"]["unexpected_s"]
        .as_array()
        .unwrap()
        .iter()
        .enumerate()
    {
        assert!(f(s) < 0.05, "finger {i} touched while lifted for {s} s");
    }
    let measured = v["rest_force"]["measured"].as_array().unwrap();
    let planned = v["rest_force"]["planned"].as_array().unwrap();
    for (m, p) in measured.iter().zip(planned) {
        assert!(
            (f(m) / f(p) - 1.0).abs() < 1e-3,
            "at rest the contact carries {m} N, not the grip {p} N (preload)"
        );
    }
    assert!(
        f(&v["roll_error_max"]) < 1e-5,
        "integrated roll vs commanded: {}",
        v["roll_error_max"]
    );
}

#[test]
fn the_mujoco_plant_replays_bit_for_bit_in_lockstep_over_iceoryx2() {
    let ns = Namespace::new("lockstep");
    let trace = plan(
        &ns.dir,
        "goal",
        &["--axis", "0,0,1", "--angle", "90", "--relative"],
    );
    let out = script("mujoco_lockstep_replay.py")
        .arg("--trace")
        .arg(&trace)
        .args(ns.args())
        .output()
        .unwrap();
    let v = json_output(&out, "mujoco_lockstep_replay.py");
    let rep = &v["plant_report"];
    println!(
        "lockstep over iceoryx2: {} exchanges, {:.0} per second; plant real-time factor {:.2}, \
         {:.0} µs compute per step; orientation error max {:.4}° final {:.4}°",
        v["exchanged"],
        f(&v["exchanges_per_s"]),
        f(&rep["real_time_factor"]),
        f(&rep["compute_us_per_step"]),
        f(&v["max_error_deg"]),
        f(&v["final_error_deg"]),
    );
    let samples = v["samples"].as_u64().unwrap();
    assert_eq!(v["exit_code"], 0, "plant exit: {}", v["stderr"]);
    assert_eq!(
        v["exchanged"].as_u64(),
        Some(samples - 1),
        "{}",
        v["stderr"]
    );
    assert_eq!(v["echo_errors"], 0, "measurement numbering or echo broken");
    assert_eq!(rep["rejected"], 0, "{}", rep["last_rejection"]);
    assert_eq!(rep["lockstep_timeouts"], 0);
    assert_eq!(rep["applied"].as_u64(), Some(samples - 1));
    assert_eq!(
        v["bitwise_mismatches"], 0,
        "the plant over iceoryx2 differs from the same plant in-process"
    );
    assert!(f(&v["max_error_deg"]) < 1.0 && f(&v["final_error_deg"]) < 1.0);
    assert!(f(&rep["max_object_drift_m"]) < 0.005);
}
