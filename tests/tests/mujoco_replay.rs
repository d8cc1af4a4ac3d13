//! Exported plans replay in an independent physics simulator (SPEC §10,
//! issue 4): `gaitctl plan` writes `gait-trajectory/1` traces of the
//! paper's scenario and of a few goals, and MuJoCo (tests/oracles/mujoco,
//! compliant fingertips, no gravity) checks that the object follows the
//! plan: orientation within 2° at all times and 1° at the end, centre
//! drift, slip and contact timing — replay.py's own thresholds.
//!
//! The replay runs without gravity, so the traces are made with a
//! weightless object (`[load] gravity = [0, 0, 0]`): the grip forces then
//! only hold the disturbance margin and accelerate the object, as in the
//! simulation. The object's mass is passed to the replay (`--mass`).

use gaitd_tests::{mujoco_replay, workspace_bin};
use std::process::Command;

fn replay(tag: &str, plan_args: &[&str]) {
    let dir = std::env::temp_dir().join(format!("gaitd-mujoco-{}-{tag}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
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
