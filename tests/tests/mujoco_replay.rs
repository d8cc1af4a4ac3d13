//! Exported plans replay in an independent physics simulator (SPEC §10):
//! `gaitctl plan` writes `gait-trajectory/1` traces of the
//! paper's scenario and of a few goals, and MuJoCo (tests/oracles/mujoco,
//! compliant fingertips, no gravity) checks that the object follows the
//! plan: orientation within 2° at all times and 1° at the end, centre
//! drift, slip and contact timing — replay.py's own thresholds.
//!
//! Without gravity the traces are made with a weightless object (`[load]
//! gravity = [0, 0, 0]`): the grip forces then only hold the disturbance
//! margin and accelerate the object, as in the simulation. The object's
//! mass is passed to the replay (`--mass`).
//!
//! With gravity (SPEC §1.3 I1', issue "Holding against gravity") the
//! traces are made with the default load (0.1 kg, g = 9.81 m/s² along −z)
//! and replayed with `--gravity` and the physical model of the trace's
//! own header: its `object_mass`, its `gravity` and its `mu_torsion` as
//! the scene's torsional friction — one model for planner and simulator.

use gaitd_tests::{mujoco_replay, oracle_python, repo_root, workspace_bin};
use std::path::Path;
use std::process::Command;

/// The replay's physics from the trace header: `--gravity`,
/// `--gravity-accel`, `--mass`, `--torsion`.
fn header_physics(trace: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(trace).unwrap();
    let header: serde_json::Value = serde_json::from_str(text.lines().next().unwrap()).unwrap();
    let num = |k: &str| {
        header[k]
            .as_f64()
            .unwrap_or_else(|| panic!("trace header without {k}"))
    };
    let g: Vec<f64> = header["gravity"]
        .as_array()
        .expect("trace header without gravity")
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    // The scene's gravity is along −z.
    assert!(
        g[0] == 0.0 && g[1] == 0.0 && g[2] < 0.0,
        "gravity {g:?} is not along -z"
    );
    vec![
        "--gravity".into(),
        "--gravity-accel".into(),
        (-g[2]).to_string(),
        "--mass".into(),
        num("object_mass").to_string(),
        "--torsion".into(),
        num("mu_torsion").to_string(),
    ]
}

/// Plans with the default load and replays with gravity (module docs).
fn replay_with_gravity(tag: &str, plan_args: &[&str]) {
    let dir = test_support::scratch_dir(&format!("mujoco-g-{tag}"));
    let trace = dir.join("trace.jsonl");
    let out = Command::new(workspace_bin("gaitctl"))
        .arg("plan")
        .args(plan_args)
        .arg("--out")
        .arg(&trace)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "gaitctl plan {plan_args:?}:\n{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    let physics = header_physics(&trace);
    let out = Command::new(oracle_python())
        .arg(repo_root().join("tests/oracles/mujoco/replay.py"))
        .arg(&trace)
        .args(&physics)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    println!("{tag}, gravity ({}):", physics.join(" "));
    // The verdict, then slip, normal forces and friction use per contact.
    for line in text.lines() {
        println!("  {line}");
    }
    std::fs::remove_dir_all(&dir).ok();
    assert!(
        out.status.success(),
        "MuJoCo replay of {tag} with gravity failed:\n{text}{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

fn replay(tag: &str, plan_args: &[&str]) {
    let dir = test_support::scratch_dir(&format!("mujoco-{tag}"));
    let cfg = dir.join("weightless.toml");
    std::fs::write(&cfg, "[load]\ngravity = [0.0, 0.0, 0.0]\n").unwrap();
    let trace = dir.join("trace.jsonl");
    let out = Command::new(workspace_bin("gaitctl"))
        .arg("plan")
        .args(plan_args)
        .arg("--config")
        .arg(&cfg)
        .arg("--out")
        .arg(&trace)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "gaitctl plan {plan_args:?}:\n{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    let out = mujoco_replay(&trace);
    let text = String::from_utf8_lossy(&out.stdout);
    println!("{tag}: {}", text.lines().next().unwrap_or(""));
    std::fs::remove_dir_all(&dir).ok();
    assert!(
        out.status.success(),
        "MuJoCo replay of {tag} failed:\n{text}{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn the_papers_scenario_replays_in_mujoco() {
    replay("paper", &["--scenario", "paper"]);
}

#[test]
fn random_goals_replay_in_mujoco() {
    for (i, q) in ["0.3,0.5,-0.2,0.8", "-0.6,0.1,0.7,0.3", "0.1,-0.9,0.3,-0.2"]
        .iter()
        .enumerate()
    {
        replay(&format!("goal{i}"), &["--quat", q]);
    }
}

#[test]
fn a_full_turn_about_z_from_the_papers_start_replays_with_gravity() {
    // The paper scenario's first goal.
    replay_with_gravity(
        "paper-z",
        &["--axis", "0,0,1", "--angle", "360", "--relative"],
    );
}

#[test]
fn random_goals_replay_with_gravity() {
    for (i, q) in [
        "0.3,0.5,-0.2,0.8",
        "-0.6,0.1,0.7,0.3",
        "0.1,-0.9,0.3,-0.2",
        "0.7,-0.1,-0.6,0.3",
        "0.2,0.2,-0.9,0.3",
    ]
    .iter()
    .enumerate()
    {
        replay_with_gravity(&format!("goal{i}"), &["--quat", q]);
    }
}
