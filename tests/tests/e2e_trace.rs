//! Goal traces recorded by the daemon (SPEC §8, §10): gaitd with
//! `[daemon] trace_dir` set and a client in another process. A goal that
//! succeeds leaves exactly one `gait-trajectory/1` file whose lines obey
//! the format's rules (t strictly increasing by dt, unit quaternions,
//! `contact` ⇔ touching, ending at the goal), and that trace replays in
//! MuJoCo with the same oracle as `gaitctl plan`'s exports.

use gaitd_client::{GoalSpec, GoalState, ReasonCode, Verdict};
use gaitd_tests::{TestDaemon, mujoco_replay};

mod rerun_support;
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};
use test_support::quat::angle;

const T: Duration = Duration::from_secs(10);
const LONG: Duration = Duration::from_secs(90);

/// A daemon recording traces into `<its dir>/traces` (removed with it).
fn traced_daemon(tag: &str, extra_config: &str) -> (TestDaemon, PathBuf) {
    let mut d = TestDaemon::new(tag, extra_config);
    let traces = d.record_traces();
    d.spawn();
    d.wait_ready(T);
    (d, traces)
}

/// Sends `target` (absolute, unit) and waits for success; returns the goal id.
fn reach(d: &TestDaemon, target: [f64; 4]) -> u64 {
    let mut c = d.client();
    let t = c.reorient(&GoalSpec::absolute(target), T).unwrap();
    assert_eq!(t.verdict, Verdict::Accepted);
    let o = c.wait_outcome(t.goal_id, LONG).unwrap();
    assert_eq!(
        (o.state, o.reason),
        (GoalState::Succeeded, ReasonCode::Reached),
        "{}",
        d.log()
    );
    t.goal_id
}

/// Waits (bounded) for the trace thread to finish the file; returns the
/// only trace in `dir`.
fn the_trace(d: &TestDaemon, dir: &Path) -> PathBuf {
    let t0 = Instant::now();
    loop {
        let files: Vec<PathBuf> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|x| x == "jsonl"))
            .collect();
        if !files.is_empty() {
            assert_eq!(files.len(), 1, "exactly one trace: {files:?}");
            return files[0].clone();
        }
        assert!(
            t0.elapsed() < T,
            "no trace written in {}:\n{}",
            dir.display(),
            d.log()
        );
        std::thread::sleep(Duration::from_millis(20));
    }
}

fn nums(v: &Value, n: usize, what: &str) -> Vec<f64> {
    let a = v
        .as_array()
        .unwrap_or_else(|| panic!("{what}: not an array"));
    assert_eq!(a.len(), n, "{what}");
    a.iter()
        .map(|x| x.as_f64().unwrap_or_else(|| panic!("{what}: not a number")))
        .collect()
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// Angle between two unit quaternions [rad] (either sign).
/// Checks the trace against SPEC §10; returns (header, ticks).
fn check_trace(path: &Path, goal_id: u64, target: [f64; 4]) -> (Value, usize) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let h: Value = serde_json::from_str(lines.next().expect("header")).unwrap();
    assert_eq!(h["format"], "gait-trajectory/1", "{h}");
    let num = |k: &str| h[k].as_f64().unwrap_or_else(|| panic!("header {k}: {h}"));
    let (big_r, r, dt) = (num("object_radius"), num("fingertip_radius"), num("dt"));
    assert!(big_r > 0.0 && r > 0.0 && num("mu") > 0.0 && dt > 0.0, "{h}");
    assert_eq!(h["goal_id"], goal_id, "{h}");
    assert_eq!(h["outcome"], "Succeeded", "{h}");
    assert_eq!(h["reason"], "Reached", "{h}");
    assert_eq!(h["incomplete"], false, "{h}");
    let mut last_t = f64::NEG_INFINITY;
    let mut last_q = Vec::new();
    let mut n = 0;
    let (mut touching, mut free) = (0, 0);
    for (i, l) in lines.enumerate() {
        let v: Value = serde_json::from_str(l).unwrap_or_else(|e| panic!("line {}: {e}", i + 2));
        let t = v["t"].as_f64().expect("t");
        if i > 0 {
            assert!(t > last_t, "line {}: t not increasing", i + 2);
            assert!(
                (t - last_t - dt).abs() < 1e-9,
                "line {}: step {} != dt {dt}",
                i + 2,
                t - last_t
            );
        }
        last_t = t;
        let q = nums(&v["object_q"], 4, "object_q");
        assert!((norm(&q) - 1.0).abs() < 1e-9, "line {}: |object_q|", i + 2);
        assert!(v["phase"].is_string());
        let fingers = v["fingers"].as_array().expect("fingers");
        assert_eq!(fingers.len(), 3);
        for f in fingers {
            let p = nums(&f["p"], 3, "p");
            let fq = nums(&f["q"], 4, "q");
            assert!((norm(&fq) - 1.0).abs() < 1e-9, "line {}: |q|", i + 2);
            let contact = f["contact"].as_bool().expect("contact");
            let grip = f["grip_force"].as_f64().expect("grip_force");
            assert!(f["roll"].as_f64().is_some());
            if contact {
                touching += 1;
                assert!(
                    (norm(&p) - (big_r + r)).abs() < 1e-6,
                    "line {}: contact but |p| = {} != R + r = {}",
                    i + 2,
                    norm(&p),
                    big_r + r
                );
            } else {
                free += 1;
                assert_eq!(grip, 0.0, "line {}: grip force without contact", i + 2);
            }
        }
        last_q = q;
        n += 1;
    }
    assert!(n > 100, "a goal takes more than 0.1 s ({n} ticks)");
    assert_eq!(h["ticks"], n, "{h}");
    assert!(
        touching > 0,
        "fingers touched ({touching} touching, {free} free)"
    );
    let last: [f64; 4] = last_q
        .as_slice()
        .try_into()
        .expect("four quaternion numbers");
    let err = angle(last, target);
    assert!(err < 1e-6, "trace ends {err} rad from the goal");
    (h, n)
}

/// 90° about y: a few gaits, done in a few seconds.
fn target() -> [f64; 4] {
    [0.5f64.sqrt(), 0.0, 0.5f64.sqrt(), 0.0]
}

#[test]
fn a_goal_is_recorded_in_gait_trajectory_format() {
    let (d, dir) = traced_daemon("trace", "");
    let goal = reach(&d, target());
    let path = the_trace(&d, &dir);
    let name = path.file_name().unwrap().to_string_lossy().into_owned();
    assert!(name.ends_with(&format!("-goal-{goal}.jsonl")), "{name}");
    let (h, n) = check_trace(&path, goal, target());
    // The plan's route, effort and planning time, from the planner thread.
    let route = h["plan_route"]
        .as_str()
        .unwrap_or_else(|| panic!("no plan_route: {h}"));
    assert!(route.starts_with("pass 1"), "{route}");
    assert!(route.contains("turn"), "{route}");
    assert!(
        h["plan_effort"]["expansions"]
            .as_u64()
            .is_some_and(|e| e > 0),
        "{h}"
    );
    assert!(h["planning_ms"].as_f64().is_some_and(|t| t > 0.0), "{h}");
    // One INFO line per trace, never one per tick.
    let log = d.log();
    assert_eq!(log.matches("trace written").count(), 1, "{log}");
    assert!(log.contains(&format!("ticks={n}")), "{log}");
}

/// The daemon's trace replays in MuJoCo (compliant fingertips, no
/// gravity), as `gaitctl plan`'s do (`mujoco_replay.rs`): the daemon runs
/// with a weightless object so that its grip forces match the replay.
#[test]
fn a_recorded_goal_replays_in_mujoco() {
    let (d, dir) = traced_daemon("trace-mujoco", "[load]\ngravity = [0.0, 0.0, 0.0]\n");
    let goal = reach(&d, target());
    let path = the_trace(&d, &dir);
    check_trace(&path, goal, target());
    let out = mujoco_replay(&path);
    let text = String::from_utf8_lossy(&out.stdout);
    println!("daemon trace: {}", text.lines().next().unwrap_or(""));
    assert!(
        out.status.success(),
        "MuJoCo replay of the daemon's trace failed:\n{text}{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// A recorded goal opens in Rerun: the daemon's trace, converted to MCAP
/// (`gaitctl trace mcap`), is turned by `gaitd-view --replay … --save` into
/// a Rerun recording, which Rerun's own decoder reads back: a frame of the
/// object for every 1/30 s of the goal, the last one where the trace ends,
/// and the hand's and the plots' entities.
#[test]
fn a_recorded_goal_opens_in_rerun() {
    let (d, dir) = traced_daemon("trace-rrd", "");
    reach(&d, target());
    let jsonl = the_trace(&d, &dir);
    let mcap = d.dir.join("goal.mcap");
    let rrd = d.dir.join("goal.rrd");
    let out = d
        .gaitctl()
        .args(["trace", "mcap"])
        .arg(&jsonl)
        .arg("-o")
        .arg(&mcap)
        .output()
        .unwrap();
    assert!(out.status.success(), "{out:?}");
    let out = std::process::Command::new(gaitd_tests::workspace_bin("gaitd-view"))
        .arg("--replay")
        .arg(&mcap)
        .arg("--save")
        .arg(&rrd)
        .args(["--rate", "30"])
        .output()
        .unwrap();
    let said = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{said}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // The trace's own numbers.
    let text = std::fs::read_to_string(&jsonl).unwrap();
    let ticks: Vec<Value> = text
        .lines()
        .skip(1)
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    let t = |v: &Value| v["t"].as_f64().unwrap();
    let span = t(ticks.last().unwrap()) - t(&ticks[0]);
    let last_q = nums(&ticks.last().unwrap()["object_q"], 4, "object_q");

    let rec = rerun_support::read(&rrd);
    let frames = rec.object.len() as f64;
    println!(
        "{said}goal of {span:.3} s: {frames} object frames in the recording, entities {:?}",
        rec.entities
    );
    assert!(
        frames >= (span * 30.0).floor() && frames <= (span * 30.0).floor() + 2.0,
        "{frames} frames for {span} s at 30 per second"
    );
    let (_, q) = rec.object.iter().max_by_key(|(time, _)| *time).unwrap();
    // Rerun's quaternions are [x, y, z, w], f32.
    let dot = q[3] as f64 * last_q[0]
        + q[0] as f64 * last_q[1]
        + q[1] as f64 * last_q[2]
        + q[2] as f64 * last_q[3];
    assert!(
        1.0 - dot.abs() < 1e-6,
        "last object {q:?} vs trace {last_q:?}"
    );
    for e in [
        "world/object/ball",
        "world/tips/commanded",
        "world/contacts",
        "world/cones",
        "world/forces/commanded",
        "world/ahead/tips",
        "world/ahead/axes",
        "plots/margins/force_closure",
        "plots/goal/remaining_deg",
        "events",
    ] {
        assert!(rec.entities.contains(e), "no {e} in {:?}", rec.entities);
    }
    // A line in the events log for every change of the samples' phase
    // (also between two frames).
    let phases = ticks
        .iter()
        .map(|v| v["phase"].as_str().unwrap_or_default())
        .collect::<Vec<_>>();
    let changes = 1 + phases.windows(2).filter(|w| w[0] != w[1]).count();
    assert_eq!(rec.rows.get("events"), Some(&changes), "{phases:?}");
    // A trace has no measurements: nothing measured is drawn.
    assert!(!rec.entities.contains("world/tips/measured"));
}

/// The live view draws the path ahead of a running plan, from the
/// daemon's plan paths, also when it opens after the plan was made:
/// recorded with `gaitd-view --save` while a turn runs, read back with
/// Rerun's decoder.
#[test]
fn the_live_view_draws_the_path_ahead_of_a_running_plan() {
    let d = gaitd_tests::TestDaemon::start("view-ahead");
    let mut c = d.client();
    let t = c
        .reorient(
            &gaitd_client::GoalSpec::turn([0.0, 0.0, 1.0], 6.2).unwrap(),
            std::time::Duration::from_secs(5),
        )
        .unwrap();
    assert_eq!(t.verdict, gaitd_client::Verdict::Accepted);
    // The view opens mid-plan: the daemon published the path before.
    let t0 = std::time::Instant::now();
    while c
        .wait_status(std::time::Duration::from_secs(5))
        .unwrap()
        .goal
        .remaining_angle
        > 6.0
    {
        assert!(t0.elapsed().as_secs() < 30, "the goal does not move");
    }
    let rrd = d.dir.join("live.rrd");
    let out = std::process::Command::new(gaitd_tests::workspace_bin("gaitd-view"))
        .args(["--prefix", &d.prefix, "--ipc-root"])
        .arg(format!("{}/", d.root.display()))
        .args(["--ipc-file-prefix", &d.file_prefix, "--timeout", "10"])
        .args(["--rate", "10", "--report-every", "0", "--frames", "40"])
        .arg("--save")
        .arg(&rrd)
        .output()
        .unwrap();
    let said = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{said}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let rec = rerun_support::read(&rrd);
    let ahead = rec.rows.get("world/ahead/tips").copied().unwrap_or(0);
    println!("{said}live view: 40 frames, {ahead} with the path ahead");
    // 4 s of a turn of about 8 s, all while it executes.
    assert!(ahead >= 20, "{ahead} frames drew the path ahead");
    assert!(rec.entities.contains("world/ahead/axes"));
}
